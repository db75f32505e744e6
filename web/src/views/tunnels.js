// Neighbouring tunnels (Fig. 8): a random 5^3 field in which two cells that share a face both hold a
// tunnel. Chernyaev's tables put a triangle in that face for each tunnel, and the two meet in
// non-manifold edges; cmc33's tables keep every tunnel off the cell faces. Every method of the
// library is run on the field; the page compares each mesh with the field's own topology, and
// shows, zoomed on the two cells as the paper's figure does, the trilinear level set, one method's
// mesh and cmc33's side by side.
import { el } from '../state.js';
import { Viewer, surface, boxEdges, segments, quad, linkCameras, COLORS } from '../viewer.js';
import { generator, randomValues, neighbouringTunnels, findTunnelField, cellValues } from '../search.js';
import { FIG8_SEED } from '../presets.js';
import { takeMesh } from '../cmc33.js';

const N = 5;

/** The mesh's triangles whose centroid lies in the pair's two cells, and the others. */
function split(mesh, pair) {
  const lo = pair.a.map((x, i) => Math.min(x, pair.b[i])), hi = pair.a.map((x, i) => Math.max(x, pair.b[i]) + 1);
  const inside = [], outside = [];
  const t = mesh.triangles, p = mesh.positions;
  for (let f = 0; f < t.length; f += 3) {
    let ok = true;
    for (let a = 0; a < 3; ++a) {
      const c = (p[3 * t[f] + a] + p[3 * t[f + 1] + a] + p[3 * t[f + 2] + a]) / 3;
      ok &&= c > lo[a] && c < hi[a];
    }
    (ok ? inside : outside).push(t[f], t[f + 1], t[f + 2]);
  }
  return [new Uint32Array(inside), new Uint32Array(outside)];
}

const TRUTH_STEPS = 40;

export function tunnelsView(root, cmc33, state, setState, report = () => {}) {
  const methods = cmc33.methods();
  let seed = FIG8_SEED;
  if (state.seed !== undefined) {
    if (/^\d+$/.test(state.seed)) seed = Number(state.seed);
    else report(`seed=${state.seed}: not a seed; a whole number ≥ 0 was expected. Seed ${FIG8_SEED} (the paper's figure) is shown.`);
  }
  let chosen = state.method;
  if (chosen !== undefined && !methods.includes(chosen)) {
    report(`method=${chosen}: no such method; the methods are ${methods.join(', ')}.`);
    chosen = undefined;
  }
  let whole = state.whole === '1';
  const claim = el('p', { class: 'claim' },
    'Fig. 8 of the paper: "when neighbor voxels have tunnels in their interiors, and share an ambiguous, coplanar face, ' +
    'the end result will be non-manifold edges". Every method of the library extracts the same random 5³ field (the table). ' +
    'Below, zoomed on the two cells with tunnels as in the paper: the level set of the trilinear field itself (sampled), ' +
    'a method\'s mesh, and cmc33\'s. The shared face is purple, non-manifold edges (more than two triangles) pink. ' +
    'The last columns of the table compare each mesh with the topology of the trilinear field (cmc33::field_topology, ' +
    'which shares no code with the extractor).');
  const info = el('div', { id: 'tunnels-info' });
  const table = el('table', { id: 'tunnels-table' });
  const next = el('button', { id: 'tunnels-next' }, 'another random field');
  const methodSelect = el('select', { id: 'tunnels-method' }, methods.filter((m) => m !== 'cmc33').map((m) => el('option', { value: m }, m)));
  const wholeBox = el('input', { type: 'checkbox', id: 'tunnels-whole' });
  wholeBox.checked = whole;
  const titles = [el('h4', {}), el('h4', {}), el('h4', {})];
  const boxes = [0, 1, 2].map((k) => el('div', { class: 'viewer', id: `tunnels-viewer-${k}` }));
  root.append(el('h2', {}, 'Neighbouring tunnels'), claim, el('div', { class: 'panel' }, info, next), el('div', { class: 'panel' }, table),
    el('div', { class: 'panel' },
      el('div', { class: 'controls' }, el('label', {}, 'middle: ', methodSelect), el('label', {}, wholeBox, ' the rest of the field (faint)')),
      el('div', { class: 'row', id: 'tunnels-viewers' }, boxes.map((b, k) => el('div', {}, titles[k], b))),
      el('p', { class: 'hint' }, 'The three views turn together: drag to rotate them, the wheel (or a pinch) zooms, a right-drag pans.')));
  const viewers = boxes.map((b) => new Viewer(b, { width: 380, height: 340 }));
  linkCameras(viewers); // the three turn together

  next.addEventListener('click', () => {
    const found = findTunnelField(cmc33, seed + 1);
    if (found) {
      seed = found.seed;
      chosen = undefined;
      render();
    }
  });
  methodSelect.addEventListener('change', () => {
    chosen = methodSelect.value;
    render();
  });
  wholeBox.addEventListener('change', () => {
    whole = wholeBox.checked;
    render();
  });

  /** The objects of one pane: the pair's triangles solid (the rest faint if asked), face, cells, non-manifold edges. */
  function pane(mesh, pair) {
    const objects = [];
    const [inside, outside] = pair ? split(mesh, pair) : [mesh.triangles, new Uint32Array(0)];
    if (inside.length) objects.push(surface(mesh.positions, inside, { color: COLORS.surface }));
    if (whole && outside.length) objects.push(surface(mesh.positions, outside, { color: 0x9aa5b1, opacity: 0.18 }));
    const ends = [];
    for (let e = 0; mesh.nonManifoldEdges && e < mesh.nonManifoldEdges.length; e += 2) {
      const p = (v) => [0, 1, 2].map((a) => mesh.positions[3 * v + a]);
      ends.push([p(mesh.nonManifoldEdges[e]), p(mesh.nonManifoldEdges[e + 1])]);
    }
    if (ends.length) objects.push(segments(ends, COLORS.bad, 0.025));
    return objects;
  }

  function frame(pair) {
    const objects = [boxEdges([0, 0, 0], [N - 1, N - 1, N - 1], 0xdddddd)];
    if (!pair) return objects;
    for (const c of [pair.a, pair.b]) objects.push(boxEdges(c, c.map((x) => x + 1), 0x333333));
    const a = pair.axis, u = (a + 1) % 3, w = (a + 2) % 3;
    const corner = (du, dw) => {
      const p = pair.b.slice();
      p[u] += du;
      p[w] += dw;
      return p;
    };
    objects.push(quad([corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)], COLORS.extra, 0.4));
    return objects;
  }

  function render() {
    const field = randomValues(generator(seed), N * N * N);
    const pairs = neighbouringTunnels(cmc33, field, N, 0, 'cmc33');
    const volume = cmc33.Volume.fromValues(field, N, N, N);
    let expected;
    try {
      expected = volume.fieldTopology(0);
      const pair = pairs[0];
      info.replaceChildren(
        el('div', {}, `Field: seed ${seed} (values uniform in [−1, 1], rounded to 4 decimals), isovalue 0. `),
        pair
          ? el('div', { id: 'tunnels-pair' }, `Cells (${pair.a}) and (${pair.b}) share the face at ${'xyz'[pair.axis]} = ${pair.b[pair.axis]}; cmc33 finds tunnels in both (${pair.subcases.join(' and ')}).`)
          : el('div', {}, 'No two neighbouring cells hold tunnels in this field.'),
        el('div', {}, `The trilinear field's level set: Euler characteristic ${expected.euler}, b0 ${expected.b0}, b1 ${expected.b1}, b2 ${expected.b2}, ${expected.boundaryLoops} boundary loops.`),
      );
      const rows = [];
      const meshes = {};
      for (const m of methods) {
        const mesh = takeMesh(volume.extract(0, m), { nonManifold: true });
        meshes[m] = mesh;
        const t = mesh.topology;
        const same = t.euler === expected.euler && t.b0 === expected.b0 && t.b1 === expected.b1 && t.b2 === expected.b2 && t.boundaryLoops === expected.boundaryLoops;
        const subs = pair ? [pair.a, pair.b].map(([i, j, kk]) => cmc33.analyzeCell(cellValues(field, N, i, j, kk), 0, m).subcase) : [];
        rows.push(el('tr', { dataset: { method: m } },
          el('td', {}, m), el('td', {}, subs.join(', ') || '—'), el('td', {}, String(mesh.triangleCount)),
          el('td', { class: t.nonManifoldEdges > 0 ? 'bad' : '' }, String(t.nonManifoldEdges)),
          el('td', {}, `${t.euler}`), el('td', {}, `${t.b0}, ${t.b1}, ${t.b2}`), el('td', {}, String(t.boundaryLoops)),
          el('td', { class: same ? 'good' : 'bad' }, same ? 'equal' : 'differs')));
      }
      table.replaceChildren(
        el('tr', {}, el('th', {}, 'method'), el('th', {}, 'the two cells'), el('th', {}, 'triangles'), el('th', {}, 'non-manifold edges'),
          el('th', {}, 'χ'), el('th', {}, 'b0, b1, b2'), el('th', {}, 'boundary loops'), el('th', {}, 'vs. trilinear field')),
        ...rows,
      );
      // the middle pane: the reader's method, else a Chernyaev-table method that is non-manifold here (as the paper's MC33)
      const others = methods.filter((m) => m !== 'cmc33');
      const middle = chosen ?? ['chernyaev', 'mc33-lewiner', ...others].find((m) => others.includes(m) && meshes[m].topology.nonManifoldEdges > 0) ?? (others.includes('mc33-lewiner') ? 'mc33-lewiner' : others[0]);
      methodSelect.value = middle;
      // the trilinear level set of the two cells, sampled, in the field's coordinates
      const truth = { positions: new Float32Array(0), triangles: new Uint32Array(0) };
      if (pair) {
        const parts = [pair.a, pair.b].map((c) => {
          const t = takeMesh(cmc33.trilinearSurface(cellValues(field, N, ...c), 0, TRUTH_STEPS), { topology: false });
          for (let v = 0; v < t.positions.length; v += 3) for (let a = 0; a < 3; ++a) t.positions[v + a] += c[a];
          return t;
        });
        truth.positions = new Float32Array([...parts[0].positions, ...parts[1].positions]);
        const shift = parts[0].positions.length / 3;
        truth.triangles = new Uint32Array([...parts[0].triangles, ...Array.from(parts[1].triangles, (v) => v + shift)]);
      }
      const panes = [
        ['the trilinear level set', truth.triangles.length ? [surface(truth.positions, truth.triangles, { color: COLORS.truth })] : []],
        [`${middle}: ${meshes[middle].topology.nonManifoldEdges} non-manifold edges`, pane(meshes[middle], pair)],
        [`cmc33: ${meshes.cmc33.topology.nonManifoldEdges} non-manifold edges`, pane(meshes.cmc33, pair)],
      ];
      panes.forEach(([title, objects], k) => {
        titles[k].textContent = title;
        viewers[k].show([...frame(pair), ...objects]);
        if (pair) viewers[k].fitBox(pair.a.map((x, i) => Math.min(x, pair.b[i])), pair.a.map((x, i) => Math.max(x, pair.b[i]) + 1));
        else viewers[k].fit();
      });
      setState({ view: 'tunnels', seed, method: chosen, whole: whole ? 1 : undefined });
      window.cmc33Page.tunnels = { pair, middle, viewers };
      document.body.dataset.ready = `tunnels ${seed} ${middle}`;
    } finally {
      volume.delete();
    }
  }

  render();
  return { destroy() { for (const v of viewers) v.renderer.dispose(); } };
}
