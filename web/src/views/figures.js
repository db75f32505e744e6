// The real-data figures (Figs. 13 and 14) from a sweep data file (docs/figures/*.json, written by
// `cmc33 sweep`; its shape: {volume, dims, type, cells, methods, rows: [{iso, method, vertices,
// triangles, euler, b0, b1, b2, boundary_loops, non_manifold_edges, expected}]}), or a file of
// several such sweeps ({volumes: [{sweep, ...}]}, as scripts/paper/fig14_nonmanifold.py writes).
// Hovering shows an isovalue's counts; clicking one extracts that mesh here, in the page.
import { el } from '../state.js';
import { linePlot, color } from '../plots.js';
import { sweepsOf } from '../sweeps.js';
import { Viewer, surface } from '../viewer.js';
import { takeMesh } from '../cmc33.js';

async function dataFiles() {
  try {
    const response = await fetch('figures/index.json');
    return response.ok ? await response.json() : [];
  } catch {
    return [];
  }
}

/** The sweep's rows as per-method series over the sorted isovalues (null where a row is missing). */
export function seriesOf(sweep) {
  const isos = [...new Set(sweep.rows.map((r) => r.iso))].sort((a, b) => a - b);
  const methods = sweep.methods.length ? sweep.methods : [...new Set(sweep.rows.map((r) => r.method))];
  const byMethod = Object.fromEntries(methods.map((m) => [m, isos.map(() => null)]));
  const at = new Map(isos.map((v, i) => [v, i]));
  for (const r of sweep.rows) if (byMethod[r.method]) byMethod[r.method][at.get(r.iso)] = r;
  return { isos, methods, byMethod };
}

export function figuresView(root, cmc33, state, setState, report = () => {}) {
  let file = state.data ?? '';
  let part = state.part ?? '';
  let method = state.method ?? 'cmc33';
  let pick = Number(state.pick);
  let sweep = null, sweeps = [], volume = null, volumeName = '';
  const plots = [];

  const claim13 = el('p', { class: 'claim' },
    'Fig. 13 of the paper: the number of connected components a method finds minus the number C-MC33 finds, ' +
    'as the isovalue sweeps the aneurysm; left VTK (classic Marching Cubes), which finds up to 2400 more, right MC33, ' +
    'a few more for most isovalues. Here the library\'s classic Marching Cubes (mc) on the left and its MC33 ' +
    'methods on the right, each b0(method) − b0(cmc33), from the sweep data file; each plot has its own scale.');
  const claim14 = el('p', { class: 'claim' },
    'Fig. 14: MC33\'s triangulation table leaves non-manifold edges where two neighbouring tunnels share a face ' +
    '("one case per 10⁷ voxels"). Here, the non-manifold edges of each method\'s mesh at each isovalue.');
  const select = el('select', { id: 'figures-select' }, el('option', { value: '' }, 'sweep data…'));
  const partSelect = el('select', { id: 'figures-part', hidden: true });
  const about = el('div', { id: 'figures-about' });
  const hover = el('div', { id: 'figure-hover' });
  const fig13vtk = el('div', { id: 'fig13-vtk' }), fig13mc33 = el('div', { id: 'fig13-mc33' }), fig14 = el('div', { id: 'fig14' });
  const error = el('div', { class: 'error', id: 'figures-error' });
  const methodSelect = el('select', { id: 'figures-method' });
  const picked = el('div', { id: 'figures-picked' });
  const viewerBox = el('div', { class: 'viewer', id: 'figures-viewer', style: 'width:640px;height:420px' });
  root.append(
    el('h2', {}, 'Real data'),
    el('div', { class: 'panel' }, select, ' ', partSelect, about, error),
    el('div', { class: 'panel' }, el('h3', {}, 'Fig. 13: extra components'), claim13,
      el('div', { class: 'row' }, el('div', {}, el('h4', {}, 'classic Marching Cubes (VTK\'s algorithm: mc) − cmc33'), fig13vtk),
        el('div', {}, el('h4', {}, 'MC33 − cmc33'), fig13mc33))),
    el('div', { class: 'row' }, el('div', { class: 'panel' }, el('h3', {}, 'Fig. 14: non-manifold edges'), claim14, fig14),
      el('div', { class: 'panel' }, hover)),
    el('div', { class: 'row' }, el('div', { class: 'panel' }, el('label', {}, 'method ', methodSelect), picked), viewerBox),
  );
  const viewer = new Viewer(viewerBox, { width: 640, height: 420 });
  for (const m of cmc33.methods()) methodSelect.append(el('option', { value: m }, m));
  methodSelect.value = cmc33.methods().includes(method) ? method : 'cmc33';
  methodSelect.addEventListener('change', () => {
    method = methodSelect.value;
    if (Number.isFinite(pick) && sweep) extractAt(pick);
  });

  dataFiles().then((list) => {
    for (const f of list) select.append(el('option', { value: f.file }, f.label ?? `${f.volume} (${f.rows} rows)`));
    if (!file && list.length) file = list[0].file;
    if (file && !list.some((f) => f.file === file)) select.append(el('option', { value: file }, file));
    if (file) {
      select.value = file;
      load(file);
    } else {
      about.textContent = 'No sweep data in this build (docs/figures/*.json; `cmc33 sweep` writes them).';
      document.body.dataset.ready = 'figures none';
    }
  });
  select.addEventListener('change', () => {
    if (!select.value) return;
    file = select.value;
    part = '';
    pick = NaN;
    load(file);
  });
  partSelect.addEventListener('change', () => {
    part = partSelect.value;
    pick = NaN;
    choose();
  });

  function save() {
    setState({ view: 'figures', data: file, part: sweeps.length > 1 ? part : undefined, pick: Number.isFinite(pick) ? pick : undefined, method });
  }

  /** Forgets the shown sweep: its description, plots, counts and mesh (before a load, or when one fails). */
  function clear() {
    for (const p of plots.splice(0)) p.destroy();
    sweep = null;
    volume?.delete();
    volume = null;
    about.textContent = '';
    error.textContent = '';
    for (const box of [fig13vtk, fig13mc33, fig14]) box.replaceChildren();
    hover.textContent = 'hover over a plot to see an isovalue\'s counts; click to extract that mesh';
    picked.replaceChildren();
    viewer.show([]);
    window.cmc33Page.figures = null;
  }

  async function load(url) {
    clear();
    sweeps = [];
    partSelect.hidden = true;
    try {
      const response = await fetch(url);
      if (!response.ok) throw new Error(`${url}: ${response.status} ${response.statusText || 'not found'}; a sweep data file of this build (figures/*.json) was expected`);
      let json;
      try {
        json = await response.json();
      } catch (e) {
        throw new Error(`${url}: not JSON (${e.message}); a sweep data file as \`cmc33 sweep\` writes was expected`);
      }
      sweeps = sweepsOf(json, url);
    } catch (e) {
      error.textContent = e.message;
      // a file the address names: said at the top too, and the address is kept as given
      if (url === state.data) report(`data=${url}: ${e.message.replace(`${url}: `, '')}`);
      else save();
      document.body.dataset.ready = `figures error ${url}`;
      return;
    }
    partSelect.replaceChildren(...sweeps.map((s) => el('option', { value: s.name }, s.label)));
    partSelect.hidden = sweeps.length < 2;
    if (part && !sweeps.some((s) => s.name === part)) {
      report(`part=${part}: ${url} has no sweep of that volume; it has ${sweeps.map((s) => s.name).join(', ')}.`);
      part = '';
    }
    part ||= sweeps[0].name;
    partSelect.value = part;
    await choose();
  }

  async function choose() {
    const keep = pick;
    clear();
    pick = keep;
    sweep = sweeps.find((s) => s.name === part).sweep;
    save();
    volumeName = sweep.volume.split('/').pop();
    about.textContent = `${volumeName}: ${sweep.dims.join('×')} ${sweep.type}, ${sweep.cells} cells; ${sweep.rows.length} rows, methods ${sweep.methods.join(', ')}.`;
    draw();
    if (Number.isFinite(pick)) await extractAt(pick);
    document.body.dataset.ready = `figures ${file}${sweeps.length > 1 ? ` ${part}` : ''}`;
  }

  function draw() {
    const { isos, methods, byMethod } = seriesOf(sweep);
    const reference = byMethod.cmc33;
    const showHover = (i) => {
      if (i === null || i === undefined) return;
      hover.replaceChildren(
        el('div', {}, el('b', {}, `iso ${isos[i]}`), ' (click to extract)'),
        el('table', { id: 'figure-hover-table' },
          el('tr', {}, el('th', {}, 'method'), el('th', {}, 'b0'), el('th', {}, 'b0 − b0(cmc33)'), el('th', {}, 'non-manifold edges'), el('th', {}, 'triangles'), el('th', {}, 'χ'), el('th', {}, 'expected b0')),
          ...methods.map((m) => {
            const r = byMethod[m][i];
            return el('tr', { dataset: { method: m } }, el('td', {}, m), el('td', {}, r ? String(r.b0) : '—'),
              el('td', {}, r && reference?.[i] ? String(r.b0 - reference[i].b0) : '—'), el('td', {}, r ? String(r.non_manifold_edges) : '—'),
              el('td', {}, r ? String(r.triangles) : '—'), el('td', {}, r ? String(r.euler) : '—'), el('td', {}, r?.expected ? String(r.expected.b0) : '—'));
          })),
      );
    };
    const onClick = (i) => extractAt(isos[i]);
    const extra = (group) => group.map((m) => ({ label: `${m} − cmc33`, values: byMethod[m].map((r, i) => (r && reference[i] ? r.b0 - reference[i].b0 : NaN)), color: color(methods.indexOf(m)), points: true }));
    const common = { x: isos, xLabel: 'isovalue', yLabel: 'extra components', width: 470, height: 260, onCursor: showHover, onClick };
    // Fig. 13's two plots: classic MC's thousands would flatten MC33's few to a line at 0
    const vtk = methods.filter((m) => m === 'mc');
    const mc33 = methods.filter((m) => m !== 'cmc33' && m !== 'mc');
    let plotVtk = null, plotMc33 = null;
    if (!reference) {
      fig13vtk.textContent = fig13mc33.textContent = 'This sweep has no cmc33 rows to compare with.';
    } else {
      if (vtk.length) plots.push((plotVtk = linePlot(fig13vtk, { ...common, series: extra(vtk) })));
      else fig13vtk.textContent = 'This sweep has no mc rows.';
      if (mc33.length) plots.push((plotMc33 = linePlot(fig13mc33, { ...common, series: extra(mc33) })));
      else fig13mc33.textContent = 'This sweep has no MC33 rows (mc33-lewiner, chernyaev, ...).';
    }
    const plot14 = linePlot(fig14, {
      ...common,
      series: methods.map((m) => ({ label: m, values: byMethod[m].map((r) => (r ? r.non_manifold_edges : NaN)), color: color(methods.indexOf(m)), points: true })),
      yLabel: 'non-manifold edges',
    });
    plots.push(plot14);
    // for the browser tests: the plots' own data, which must be the sweep file's numbers
    window.cmc33Page.figures = { isos, methods, fig13vtk: plotVtk, fig13mc33: plotMc33, fig14: plot14 };
  }

  async function extractAt(value) {
    pick = value;
    save();
    const shown = sweep;
    try {
      if (!volume) {
        picked.textContent = `loading volumes/${volumeName}…`;
        const response = await fetch(`volumes/${volumeName}`);
        if (!response.ok) throw new Error(`volumes/${volumeName}: not bundled with this build (${response.status})`);
        const bytes = new Uint8Array(await response.arrayBuffer());
        if (sweep !== shown) return; // another sweep was chosen meanwhile
        volume = cmc33.Volume.read(bytes, volumeName, {});
      }
      const t0 = performance.now();
      const mesh = takeMesh(volume.extract(value, method));
      const ms = performance.now() - t0;
      const row = sweep.rows.find((r) => r.iso === value && r.method === method);
      picked.replaceChildren(
        el('div', { id: 'figures-picked-text' }, `iso ${value}, ${method}: ${mesh.triangleCount} triangles, b0 ${mesh.topology.b0}, χ ${mesh.topology.euler}, ` +
          `${mesh.topology.nonManifoldEdges} non-manifold edges, in ${ms.toFixed(1)} ms`),
        row ? el('div', { class: row.triangles === mesh.triangleCount && row.b0 === mesh.topology.b0 ? 'good' : 'bad' },
          `sweep data: ${row.triangles} triangles, b0 ${row.b0}`) : el('div', {}, `no ${method} row in the sweep data at this isovalue`),
      );
      viewer.show([surface(mesh.positions, mesh.triangles)], { refit: true });
    } catch (e) {
      picked.replaceChildren(el('div', { class: 'error' }, e.message));
    }
  }

  return { destroy() { volume?.delete(); for (const p of plots) p.destroy(); viewer.renderer.dispose(); } };
}
