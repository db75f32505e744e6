// Neighbouring tunnels (Fig. 8): a random 5^3 field in which two cells that share a face both hold a
// tunnel. Chernyaev's tables put a triangle in that face for each tunnel, and the two meet in
// non-manifold edges; cmc33's tables keep every tunnel off the cell faces. Every method of the
// library is run on the field; the page compares each mesh with the field's own topology.
import { el } from '../state.js';
import { Viewer, surface, boxEdges, segments, quad, COLORS } from '../viewer.js';
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

export function tunnelsView(root, cmc33, state, setState) {
  const methods = cmc33.methods();
  let seed = Number.isInteger(Number(state.seed)) ? Number(state.seed) : FIG8_SEED;
  const claim = el('p', { class: 'claim' },
    'Fig. 8 of the paper: "when neighbor voxels have tunnels in their interiors, and share an ambiguous, coplanar face, ' +
    'the end result will be non-manifold edges". Below, every method of the library extracts the same 5³ field. ' +
    'The two cells with tunnels are drawn solid (the rest of the surface faint), their shared face is purple, and non-manifold edges (more than two ' +
    'triangles) are drawn in pink. The last columns compare each mesh with the topology of the trilinear field ' +
    'itself (cmc33::field_topology, which shares no code with the extractor).');
  const info = el('div', { id: 'tunnels-info' });
  const table = el('table', { id: 'tunnels-table' });
  const next = el('button', { id: 'tunnels-next' }, 'another random field');
  const viewerBox = el('div', { class: 'viewer', id: 'tunnels-viewer', style: 'width:1000px;height:420px' });
  root.append(el('h2', {}, 'Neighbouring tunnels'), claim, el('div', { class: 'panel' }, info, next), el('div', { class: 'panel' }, table), viewerBox);
  const viewer = new Viewer(viewerBox, { width: 1000, height: 420 });

  next.addEventListener('click', () => {
    const found = findTunnelField(cmc33, seed + 1);
    if (found) {
      seed = found.seed;
      render();
    }
  });

  function render() {
    setState({ view: 'tunnels', seed });
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
      const objects = [];
      methods.forEach((m, k) => {
        const offset = [k * (N + 1.5), 0, 0];
        const mesh = takeMesh(volume.extract(0, m), { nonManifold: true });
        const t = mesh.topology;
        const same = t.euler === expected.euler && t.b0 === expected.b0 && t.b1 === expected.b1 && t.b2 === expected.b2 && t.boundaryLoops === expected.boundaryLoops;
        const subs = pair ? [pair.a, pair.b].map(([i, j, kk]) => cmc33.analyzeCell(cellValues(field, N, i, j, kk), 0, m).subcase) : [];
        rows.push(el('tr', { dataset: { method: m } },
          el('td', {}, m), el('td', {}, subs.join(', ') || '—'), el('td', {}, String(mesh.triangleCount)),
          el('td', { class: t.nonManifoldEdges > 0 ? 'bad' : '' }, String(t.nonManifoldEdges)),
          el('td', {}, `${t.euler}`), el('td', {}, `${t.b0}, ${t.b1}, ${t.b2}`), el('td', {}, String(t.boundaryLoops)),
          el('td', { class: same ? 'good' : 'bad' }, same ? 'equal' : 'differs')));
        // the two cells' triangles opaque, the rest of the field faint, so that the tunnels show
        const [inside, outside] = pair ? split(mesh, pair) : [mesh.triangles, new Uint32Array(0)];
        if (inside.length) objects.push(surface(mesh.positions, inside, { color: COLORS.surface, offset }));
        if (outside.length) objects.push(surface(mesh.positions, outside, { color: 0x9aa5b1, opacity: 0.18, offset }));
        objects.push(boxEdges(offset, [offset[0] + N - 1, N - 1, N - 1], 0xbbbbbb));
        const ends = [];
        for (let e = 0; e < mesh.nonManifoldEdges.length; e += 2) {
          const p = (v) => [0, 1, 2].map((a) => mesh.positions[3 * v + a] + offset[a]);
          ends.push([p(mesh.nonManifoldEdges[e]), p(mesh.nonManifoldEdges[e + 1])]);
        }
        if (ends.length) objects.push(segments(ends, COLORS.bad, 0.04));
        if (pair) {
          for (const c of [pair.a, pair.b]) objects.push(boxEdges(c.map((x, a) => x + offset[a]), c.map((x, a) => x + 1 + offset[a]), 0x333333));
          const a = pair.axis, u = (a + 1) % 3, w = (a + 2) % 3;
          const corner = (du, dw) => {
            const p = pair.b.slice();
            p[u] += du;
            p[w] += dw;
            return p.map((x, i) => x + offset[i]);
          };
          objects.push(quad([corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)], COLORS.extra, 0.35));
        }
      });
      table.replaceChildren(
        el('tr', {}, el('th', {}, 'method'), el('th', {}, 'the two cells'), el('th', {}, 'triangles'), el('th', {}, 'non-manifold edges'),
          el('th', {}, 'χ'), el('th', {}, 'b0, b1, b2'), el('th', {}, 'boundary loops'), el('th', {}, 'vs. trilinear field')),
        ...rows,
      );
      viewer.show(objects, { refit: true });
      viewer.legend ??= viewerBox.appendChild(el('div', { class: 'legend' }));
      viewer.legend.textContent = `left to right: ${methods.join(', ')}`;
      document.body.dataset.ready = `tunnels ${seed}`;
    } finally {
      volume.delete();
    }
  }

  render();
  return { destroy() { viewer.renderer.dispose(); } };
}

