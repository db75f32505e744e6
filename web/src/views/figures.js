// The real-data figures (Figs. 13 and 14) from a sweep data file (docs/figures/*.json, written by
// `cmc33 sweep`; its shape: {volume, dims, type, cells, methods, rows: [{iso, method, vertices,
// triangles, euler, b0, b1, b2, boundary_loops, non_manifold_edges, expected}]}). Hovering shows an
// isovalue's counts; clicking one extracts that mesh here, in the page.
import { el } from '../state.js';
import { linePlot, color } from '../plots.js';
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

export function figuresView(root, cmc33, state, setState) {
  let file = state.data ?? '';
  let method = state.method ?? 'cmc33';
  let pick = Number(state.pick);
  let sweep = null, volume = null, volumeName = '';
  const plots = [];

  const claim13 = el('p', { class: 'claim' },
    'Fig. 13 of the paper: the number of connected components each method finds minus the number C-MC33 finds, ' +
    'as the isovalue sweeps the aneurysm. VTK (classic Marching Cubes) finds up to 2400 more; MC33 a few more for most ' +
    'isovalues. Here each method of the library is one curve, b0(method) − b0(cmc33), from the sweep data file.');
  const claim14 = el('p', { class: 'claim' },
    'Fig. 14: MC33\'s triangulation table leaves non-manifold edges where two neighbouring tunnels share a face ' +
    '("one case per 10⁷ voxels"). Here, the non-manifold edges of each method\'s mesh at each isovalue.');
  const select = el('select', { id: 'figures-select' }, el('option', { value: '' }, 'sweep data…'));
  const about = el('div', { id: 'figures-about' });
  const hover = el('div', { id: 'figure-hover' }, 'hover over a plot to see an isovalue\'s counts; click to extract that mesh');
  const fig13 = el('div', { id: 'fig13' }), fig14 = el('div', { id: 'fig14' });
  const error = el('div', { class: 'error', id: 'figures-error' });
  const methodSelect = el('select', { id: 'figures-method' });
  const picked = el('div', { id: 'figures-picked' });
  const viewerBox = el('div', { class: 'viewer', id: 'figures-viewer', style: 'width:640px;height:420px' });
  root.append(
    el('h2', {}, 'Real data'),
    el('div', { class: 'panel' }, select, about, error),
    el('div', { class: 'row' }, el('div', { class: 'panel' }, el('h3', {}, 'Fig. 13: extra components'), claim13, fig13),
      el('div', { class: 'panel' }, el('h3', {}, 'Fig. 14: non-manifold edges'), claim14, fig14)),
    el('div', { class: 'panel' }, hover),
    el('div', { class: 'row' }, el('div', { class: 'panel' }, el('label', {}, 'method ', methodSelect), picked), viewerBox),
  );
  const viewer = new Viewer(viewerBox, { width: 640, height: 420 });
  for (const m of cmc33.methods()) methodSelect.append(el('option', { value: m }, m));
  methodSelect.value = cmc33.methods().includes(method) ? method : 'cmc33';
  methodSelect.addEventListener('change', () => {
    method = methodSelect.value;
    if (Number.isFinite(pick)) extractAt(pick);
  });

  dataFiles().then((list) => {
    for (const f of list) select.append(el('option', { value: f.file }, `${f.volume} (${f.rows} rows)`));
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
    pick = NaN;
    load(file);
  });

  function save() {
    setState({ view: 'figures', data: file, pick: Number.isFinite(pick) ? pick : undefined, method });
  }

  async function load(url) {
    error.textContent = '';
    save();
    try {
      const response = await fetch(url);
      if (!response.ok) throw new Error(`${url}: ${response.status} ${response.statusText}`);
      sweep = await response.json();
    } catch (e) {
      error.textContent = e.message;
      return;
    }
    volumeName = sweep.volume.split('/').pop();
    about.textContent = `${volumeName}: ${sweep.dims.join('×')} ${sweep.type}, ${sweep.cells} cells; ${sweep.rows.length} rows, methods ${sweep.methods.join(', ')}.`;
    draw();
    if (Number.isFinite(pick)) await extractAt(pick);
    document.body.dataset.ready = `figures ${url}`;
  }

  function draw() {
    for (const p of plots.splice(0)) p.destroy();
    const { isos, methods, byMethod } = seriesOf(sweep);
    const reference = byMethod.cmc33;
    const others = methods.filter((m) => m !== 'cmc33');
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
    if (reference) {
      plots.push(linePlot(fig13, {
        x: isos,
        series: others.map((m) => ({ label: `${m} − cmc33`, values: byMethod[m].map((r, i) => (r && reference[i] ? r.b0 - reference[i].b0 : NaN)), color: color(methods.indexOf(m)), points: true })),
        xLabel: 'isovalue', yLabel: 'extra components', width: 520, height: 280, onCursor: showHover, onClick,
      }));
    } else {
      fig13.textContent = 'This sweep has no cmc33 rows to compare with.';
    }
    plots.push(linePlot(fig14, {
      x: isos,
      series: methods.map((m) => ({ label: m, values: byMethod[m].map((r) => (r ? r.non_manifold_edges : NaN)), color: color(methods.indexOf(m)), points: true })),
      xLabel: 'isovalue', yLabel: 'non-manifold edges', width: 520, height: 280, onCursor: showHover, onClick,
    }));
    // for the browser tests: the plots' own data, which must be the sweep file's numbers
    window.cmc33Page.figures = { isos, methods, fig13: plots.length === 2 ? plots[0] : null, fig14: plots[plots.length - 1] };
  }

  async function extractAt(value) {
    pick = value;
    save();
    try {
      if (!volume) {
        picked.textContent = `loading volumes/${volumeName}…`;
        const response = await fetch(`volumes/${volumeName}`);
        if (!response.ok) throw new Error(`volumes/${volumeName}: not bundled with this build (${response.status})`);
        volume = cmc33.Volume.read(new Uint8Array(await response.arrayBuffer()), volumeName, {});
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

