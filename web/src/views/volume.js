// Volumes (Fig. 12): a NRRD / MetaImage / VTK file dropped on the page or one of the bundled ones,
// an isovalue picked on its histogram, extracted in the browser by any method, its components
// coloured as in Fig. 12 (the largest yellow, the others purple), its topology and the time taken.
import { el, fmt } from '../state.js';
import { histogramPlot } from '../plots.js';
import { Viewer, surface } from '../viewer.js';
import { takeMesh } from '../cmc33.js';

const FIELD_TOPOLOGY_LIMIT = 20e6; // samples: the trilinear field's topology is computed without asking below this

async function bundledVolumes() {
  try {
    const response = await fetch('volumes/index.json');
    return response.ok ? await response.json() : [];
  } catch {
    return [];
  }
}

export function volumeView(root, cmc33, state, setState) {
  const methods = cmc33.methods();
  let method = methods.includes(state.method) ? state.method : 'cmc33';
  let iso = Number(state.iso);
  let name = state.volume ?? '';
  let colouring = state.colour === 'all' ? 'all' : 'main';
  let volume = null, histogram = null, plot = null, lastMesh = null;

  const claim = el('p', { class: 'claim' },
    'Fig. 12 of the paper: on the aneurysm, VTK\'s Marching Cubes and MC33 break the main artery into extra ' +
    'components (purple) that C-MC33 keeps joined to it (yellow). Here the library runs in the page on any ' +
    'volume: pick one or drop a .nrrd / .nhdr (+ data file) / .mha / .mhd (+ .raw) / .vtk file, choose an isovalue ' +
    'on the histogram, and compare the methods. The topology numbers are the mesh\'s (cmc33::mesh_topology); ' +
    '"trilinear field" is what the level set must have (cmc33::field_topology, computed from the samples alone).');
  const select = el('select', { id: 'volume-select' }, el('option', { value: '' }, 'bundled volumes…'));
  const fileInput = el('input', { type: 'file', multiple: true, id: 'volume-file' });
  const drop = el('div', { class: 'drop', id: 'volume-drop' }, 'drop a volume file here (with its data file if the header is detached), or ', fileInput);
  const methodSelect = el('select', { id: 'volume-method' }, methods.map((m) => el('option', { value: m }, m)));
  methodSelect.value = method;
  const isoInput = el('input', { id: 'volume-iso', type: 'number', step: 'any', style: 'width:7rem' });
  const colourSelect = el('select', { id: 'volume-colour' }, el('option', { value: 'main' }, 'largest yellow, others purple'), el('option', { value: 'all' }, 'a colour per component'));
  colourSelect.value = colouring;
  const extractButton = el('button', { id: 'volume-extract' }, 'extract');
  const about = el('div', { id: 'volume-about' });
  const histBox = el('div', { id: 'volume-histogram' });
  const result = el('div', { id: 'volume-result' });
  const error = el('div', { class: 'error', id: 'volume-error' });
  const viewerBox = el('div', { class: 'viewer', id: 'volume-viewer', style: 'width:760px;height:520px' });
  root.append(
    el('h2', {}, 'Volumes'),
    claim,
    el('div', { class: 'row' },
      el('div', { class: 'panel controls', style: 'width:440px' },
        el('div', {}, select), drop, about, histBox,
        el('div', {}, el('label', {}, 'isovalue ', isoInput), el('label', {}, 'method ', methodSelect), extractButton),
        el('div', {}, el('label', {}, 'colours ', colourSelect)),
        error, result),
      viewerBox),
  );
  const viewer = new Viewer(viewerBox, { width: 760, height: 520 });

  bundledVolumes().then((list) => {
    for (const v of list) select.append(el('option', { value: v.name }, `${v.name} (${v.dims.join('×')} ${v.type})`));
    if (name && list.some((v) => v.name === name)) select.value = name;
  });

  select.addEventListener('change', () => select.value && loadBundled(select.value));
  fileInput.addEventListener('change', () => loadFiles([...fileInput.files]));
  drop.addEventListener('dragover', (e) => {
    e.preventDefault();
    drop.classList.add('over');
  });
  drop.addEventListener('dragleave', () => drop.classList.remove('over'));
  drop.addEventListener('drop', (e) => {
    e.preventDefault();
    drop.classList.remove('over');
    loadFiles([...e.dataTransfer.files]);
  });
  methodSelect.addEventListener('change', () => {
    method = methodSelect.value;
    extract();
  });
  isoInput.addEventListener('change', () => {
    iso = Number(isoInput.value);
    plot?.setIso(iso);
    extract();
  });
  colourSelect.addEventListener('change', () => {
    colouring = colourSelect.value;
    if (lastMesh) showMesh(lastMesh);
    save();
  });
  extractButton.addEventListener('click', () => extract());

  function save() {
    setState({ view: 'volume', volume: name.startsWith('file:') ? undefined : name, iso: Number.isFinite(iso) ? iso : undefined, method, colour: colouring === 'all' ? 'all' : undefined });
  }

  async function loadBundled(file) {
    error.textContent = '';
    about.textContent = `loading ${file}…`;
    const response = await fetch(`volumes/${file}`);
    if (!response.ok) {
      error.textContent = `volumes/${file}: ${response.status} ${response.statusText}`;
      return;
    }
    open(file, new Uint8Array(await response.arrayBuffer()), {});
  }

  async function loadFiles(files) {
    error.textContent = '';
    const header = files.find((f) => /\.(nrrd|nhdr|mha|mhd|vtk)$/i.test(f.name));
    if (!header) {
      error.textContent = `${files.map((f) => f.name).join(', ')}: no .nrrd, .nhdr, .mha, .mhd or .vtk file among them`;
      return;
    }
    const data = {};
    for (const f of files) if (f !== header) data[f.name] = new Uint8Array(await f.arrayBuffer());
    open(`file:${header.name}`, new Uint8Array(await header.arrayBuffer()), data);
  }

  function open(label, bytes, data) {
    volume?.delete();
    volume = null;
    try {
      const t0 = performance.now();
      volume = cmc33.Volume.read(bytes, label.replace(/^file:/, ''), data);
      const readMs = performance.now() - t0;
      name = label;
      histogram = volume.histogram(256);
      about.textContent = `${label.replace(/^file:/, '')}: ${volume.dims().join('×')} ${volume.type()}, values ${fmt(histogram.min)} … ${fmt(histogram.max)} (read in ${readMs.toFixed(0)} ms)`;
      if (!Number.isFinite(iso) || iso < histogram.min || iso > histogram.max) iso = Number(((histogram.min + histogram.max) / 2).toPrecision(4));
      isoInput.value = iso;
      plot?.destroy();
      histBox.replaceChildren();
      plot = histogramPlot(histBox, { ...histogram, iso, onPick: (v) => {
        iso = Number(v.toPrecision(4));
        isoInput.value = iso;
        plot.setIso(iso);
        extract();
      } });
      extract(true);
    } catch (e) {
      error.textContent = e.message;
    }
  }

  function extract(refit = false) {
    save();
    if (!volume || !Number.isFinite(iso)) return;
    error.textContent = '';
    try {
      const t0 = performance.now();
      const raw = volume.extract(iso, method);
      const ms = performance.now() - t0;
      const mesh = takeMesh(raw, { components: true });
      mesh.ms = ms;
      lastMesh = mesh;
      const t = mesh.topology;
      const dims = volume.dims();
      const samples = dims[0] * dims[1] * dims[2];
      let field = null;
      if (samples <= FIELD_TOPOLOGY_LIMIT) field = volume.fieldTopology(iso);
      const same = field && field.determined && field.euler === t.euler && field.b0 === t.b0 && field.b1 === t.b1 && field.b2 === t.b2 && field.boundaryLoops === t.boundaryLoops;
      const row = (label, key, value, expected) => el('tr', { dataset: { key } }, el('td', {}, label), el('td', { class: 'value' }, String(value)), el('td', {}, expected === undefined ? '' : String(expected)));
      result.replaceChildren(
        el('p', { id: 'volume-time' }, `${mesh.vertexCount} vertices, `, el('b', { id: 'volume-triangles' }, String(mesh.triangleCount)), ` triangles in `,
          el('b', { id: 'volume-ms' }, ms.toFixed(1)), ` ms (${method}, WebAssembly, one thread)`),
        el('table', { id: 'volume-topology' },
          el('tr', {}, el('th', {}, ''), el('th', {}, 'mesh'), el('th', {}, 'trilinear field')),
          row('Euler characteristic χ', 'euler', t.euler, field?.euler),
          row('b0 components', 'b0', t.b0, field?.b0),
          row('b1 tunnels', 'b1', t.b1, field?.b1),
          row('b2 closed components', 'b2', t.b2, field?.b2),
          row('boundary loops', 'boundaryLoops', t.boundaryLoops, field?.boundaryLoops),
          row('non-manifold edges', 'nonManifoldEdges', t.nonManifoldEdges),
          row('non-manifold vertices', 'nonManifoldVertices', t.nonManifoldVertices)),
        el('p', { id: 'volume-verdict', class: field ? (same ? 'good' : 'bad') : '' },
          field ? (same ? 'the mesh has the topology of the trilinear level set' : 'the mesh differs from the trilinear level set') : 'trilinear field not computed (volume over 20 million samples)'),
      );
      showMesh(mesh, refit);
      document.body.dataset.ready = `volume ${name} ${iso} ${method}`;
    } catch (e) {
      error.textContent = e.message;
    }
  }

  function showMesh(mesh, refit = false) {
    const colors = new Float32Array(mesh.vertexCount * 3);
    const palette = (k) => {
      if (colouring === 'main') return k === 0 ? [0.93, 0.78, 0.25] : [0.55, 0.3, 0.82];
      const h = (k * 0.618034) % 1;
      const f = (n) => {
        const x = (n + h * 6) % 6;
        return 0.35 + 0.55 * Math.max(0, Math.min(1, Math.abs(x - 3) - 1));
      };
      return [f(0), f(4), f(2)];
    };
    for (let v = 0; v < mesh.vertexCount; ++v) colors.set(palette(mesh.components[v]), 3 * v);
    viewer.show(mesh.triangleCount ? [surface(mesh.positions, mesh.triangles, { colors })] : [], { refit });
  }

  if (name && !name.startsWith('file:')) loadBundled(name);
  else document.body.dataset.ready = 'volume';
  return { destroy() { volume?.delete(); plot?.destroy(); viewer.renderer.dispose(); } };
}
