// Volumes (Fig. 12): a NRRD / MetaImage / VTK / NIfTI / .npy / .vti file dropped on the page or one
// of the bundled ones, extracted in its own world frame (the file's origin, spacing and direction),
// an isovalue picked on its histogram, extracted in the browser by any method (and a second one
// beside it), its components coloured as in Fig. 12 (the largest yellow, the others purple), its
// topology and the time taken. The Fig. 12 link opens the aneurism at iso 78 with mc33-lewiner
// beside cmc33, seen as the zoom of docs/figures/fig12_render.png.
import { el, fmt, parseNumber } from '../state.js';
import { histogramPlot } from '../plots.js';
import { Viewer, surface, linkCameras } from '../viewer.js';
import { takeMesh } from '../cmc33.js';
import fig12 from '../../../docs/figures/fig12_render.json';

// headers and single-file volumes, then the files a page build cannot read but names (TIFF, DICOM)
const HEADER_NAMES = /\.(nrrd|nhdr|mha|mhd|vtk|nii|nii\.gz|hdr|hdr\.gz|npy|vti)$/i;
const OTHER_NAMES = /\.(tiff?|dcm)$/i;
const VOLUME_EXTENSIONS = '.nrrd, .nhdr, .mha, .mhd, .vtk, .nii, .nii.gz, .hdr, .npy or .vti';
const FIELD_TOPOLOGY_LIMIT = 20e6; // samples: the trilinear field's topology is computed without asking below this
const FIG12_VOLUME = 'aneurism_256x256x256_uint8.nrrd';
export const FIG12_LINK = `#view=volume&volume=${FIG12_VOLUME}&iso=${fig12.iso}&method=mc33-lewiner&compare=cmc33&zoom=fig12`;
// the zoom of docs/figures/fig12_render.png (scripts/paper/fig12_render.py): looking at the piece
// mc33-lewiner cuts off the vessel tree from 90 voxels in front and 40 above, a 30° view, and only
// a slab of 60 voxels around it drawn
const FIG12_ZOOM = { focus: fig12.focus, position: [fig12.focus[0], fig12.focus[1] - 90, fig12.focus[2] + 40], fov: 30, slab: 30 };

async function bundledVolumes() {
  try {
    const response = await fetch('volumes/index.json');
    return response.ok ? await response.json() : [];
  } catch {
    return [];
  }
}

/** The volume's world frame, as `cmc33 info` names it: "; frame: RAS, from sform (code 2: aligned)". */
function frameText(volume) {
  const words = { right: 'R', left: 'L', anterior: 'A', posterior: 'P', superior: 'S', inferior: 'I' };
  const space = volume.space();
  const code = space.split('-').map((w) => words[w.toLowerCase()] ?? '').join('');
  const parts = [];
  if (space) parts.push(code.length === 3 ? code : space);
  if (volume.frameSource()) parts.push(`from ${volume.frameSource()}`);
  const spacing = volume.spacing(), origin = volume.origin();
  const moved = origin.some((x) => x !== 0) || spacing.some((x) => x !== 1) ||
    volume.direction().some((row, r) => row.some((x, c) => x !== (r === c ? 1 : 0)));
  if (!moved && !parts.length) return '';
  if (moved) parts.push(`origin ${origin.map((x) => fmt(x)).join(' ')}, spacing ${spacing.map((x) => fmt(x)).join(' ')}`);
  return `; frame: ${parts.join(', ')}`;
}

export function volumeView(root, cmc33, state, setState, report = () => {}) {
  const methods = cmc33.methods();
  let method = 'cmc33';
  if (state.method !== undefined) {
    if (methods.includes(state.method)) method = state.method;
    else report(`method=${state.method}: no such method; the methods are ${methods.join(', ')}. cmc33 is used.`);
  }
  let compare = '';
  if (state.compare !== undefined) {
    if (methods.includes(state.compare)) compare = state.compare;
    else report(`compare=${state.compare}: no such method; the methods are ${methods.join(', ')}.`);
  }
  let iso = NaN;
  if (state.iso !== undefined) {
    const r = parseNumber(state.iso);
    if (r.error) report(`iso=: ${r.error}; the middle of the volume's values is used.`);
    else iso = r.value;
  }
  let zoom = state.zoom === 'fig12';
  if (state.zoom !== undefined && !zoom) report(`zoom=${state.zoom}: the only zoom is fig12 (that of docs/figures/fig12_render.png).`);
  let name = state.volume ?? '';
  let colouring = state.colour === 'all' ? 'all' : 'main';
  let volume = null, plot = null, field = null, fieldIso = NaN;
  let lastMeshes = [];

  const fig12Link = el('a', { href: FIG12_LINK, id: 'volume-fig12' }, `Fig. 12: the aneurism at iso ${fig12.iso}, mc33-lewiner beside cmc33, zoomed as in the docs' figure`);
  const claim = el('p', { class: 'claim' },
    'Fig. 12 of the paper: on the aneurysm, VTK\'s Marching Cubes and MC33 break the main artery into extra ' +
    'components (purple) that C-MC33 keeps joined to it (yellow). Here the library runs in the page on any ' +
    'volume: pick one or drop a .nrrd / .nhdr (+ data file) / .mha / .mhd (+ .raw) / .vtk / .nii / .nii.gz / .hdr (+ .img) / ' +
    '.npy / .vti file (the mesh is placed in the file\'s world frame), choose an isovalue ' +
    'on the histogram, and compare two methods side by side. The topology numbers are the mesh\'s (cmc33::mesh_topology); ' +
    '"trilinear field" is what the level set must have (cmc33::field_topology, computed from the samples alone). ');
  const select = el('select', { id: 'volume-select' }, el('option', { value: '' }, 'bundled volumes…'));
  const fileInput = el('input', { type: 'file', multiple: true, id: 'volume-file' });
  const drop = el('div', { class: 'drop', id: 'volume-drop' }, 'drop a volume file here (with its data file if the header is detached), or ', fileInput);
  const methodSelect = el('select', { id: 'volume-method' }, methods.map((m) => el('option', { value: m }, m)));
  methodSelect.value = method;
  const compareSelect = el('select', { id: 'volume-compare' }, el('option', { value: '' }, 'nothing'), methods.map((m) => el('option', { value: m }, m)));
  compareSelect.value = compare;
  const isoInput = el('input', { id: 'volume-iso', type: 'text', inputmode: 'decimal', style: 'width:7rem', value: state.iso ?? '', 'aria-describedby': 'volume-iso-error' });
  const isoError = el('span', { class: 'field-error', id: 'volume-iso-error' });
  const colourSelect = el('select', { id: 'volume-colour' }, el('option', { value: 'main' }, 'largest yellow, others purple'), el('option', { value: 'all' }, 'a colour per component'));
  colourSelect.value = colouring;
  const zoomButton = el('button', { id: 'volume-zoom', title: 'the camera of docs/figures/fig12_render.png\'s bottom row' }, 'zoom as the docs\' Fig. 12');
  const wholeButton = el('button', { id: 'volume-whole' }, 'whole volume');
  const extractButton = el('button', { id: 'volume-extract' }, 'extract');
  const about = el('div', { id: 'volume-about' });
  const histBox = el('div', { id: 'volume-histogram' });
  const result = el('div', { id: 'volume-result' });
  const error = el('div', { class: 'error', id: 'volume-error', role: 'alert' });
  const titles = [el('h4', { id: 'volume-title-0' }), el('h4', { id: 'volume-title-1' })];
  const boxes = [el('div', { class: 'viewer', id: 'volume-viewer' }), el('div', { class: 'viewer', id: 'volume-viewer-2' })];
  const second = el('div', { id: 'volume-second' }, titles[1], boxes[1]);
  root.append(
    el('h2', {}, 'Volumes'),
    claim,
    el('p', {}, fig12Link),
    el('div', { class: 'row' },
      el('div', { class: 'panel controls', style: 'width:440px' },
        el('div', {}, select), drop, about, histBox,
        el('div', {}, el('label', {}, 'isovalue ', isoInput), el('label', {}, 'method ', methodSelect), extractButton), isoError,
        el('div', {}, el('label', {}, 'beside it ', compareSelect), el('label', {}, 'colours ', colourSelect)),
        el('div', {}, zoomButton, ' ', wholeButton),
        error, result),
      el('div', { class: 'row', id: 'volume-viewers' }, el('div', {}, titles[0], boxes[0]), second)),
  );
  const viewers = boxes.map((b) => new Viewer(b, { width: 600, height: 480 }));
  linkCameras(viewers);
  second.hidden = !compare;

  bundledVolumes().then((list) => {
    for (const v of list) select.append(el('option', { value: v.name }, `${v.name} (${v.dims.join('×')} ${v.type})`));
    if (name && list.some((v) => v.name === name)) select.value = name;
    if (!list.some((v) => v.name === FIG12_VOLUME)) fig12Link.replaceWith(el('span', { class: 'hint' }, `(Fig. 12 needs ${FIG12_VOLUME}, which this build does not bundle: scripts/build-web.sh copies it from ../shared/data/volumes.)`));
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
  compareSelect.addEventListener('change', () => {
    compare = compareSelect.value;
    second.hidden = !compare;
    extract();
  });
  isoInput.addEventListener('change', () => {
    const r = parseNumber(isoInput.value);
    isoError.textContent = r.error ? `the isovalue ${r.error}` : '';
    isoInput.setAttribute('aria-invalid', r.error ? 'true' : 'false');
    if (r.error) return;
    iso = r.value;
    plot?.setIso(iso);
    extract();
  });
  colourSelect.addEventListener('change', () => {
    colouring = colourSelect.value;
    lastMeshes.forEach((m, k) => showMesh(k, m));
    save();
  });
  zoomButton.addEventListener('click', () => {
    zoom = true;
    placeCamera();
    save();
  });
  wholeButton.addEventListener('click', () => {
    zoom = false;
    placeCamera();
    save();
  });
  extractButton.addEventListener('click', () => extract());

  function save() {
    setState({
      view: 'volume', volume: name.startsWith('file:') ? undefined : name, iso: Number.isFinite(iso) ? iso : undefined, method,
      compare: compare || undefined, zoom: zoom ? 'fig12' : undefined, colour: colouring === 'all' ? 'all' : undefined,
    });
  }

  /** Forgets the volume shown: its description, histogram, counts and meshes (a load failed, or another begins). */
  function forget() {
    volume?.delete();
    volume = null;
    field = null;
    lastMeshes = [];
    about.textContent = '';
    plot?.destroy();
    plot = null;
    histBox.replaceChildren();
    result.replaceChildren();
    titles.forEach((t) => (t.textContent = ''));
    for (const v of viewers) v.show([]);
  }

  function failed(message) {
    forget();
    error.textContent = message;
    document.body.dataset.ready = 'volume error';
  }

  async function loadBundled(file) {
    forget();
    error.textContent = '';
    about.textContent = `loading ${file}…`;
    let bytes;
    try {
      const response = await fetch(`volumes/${file}`);
      if (!response.ok) throw new Error(`volumes/${file}: ${response.status} ${response.statusText || ''}; one of the bundled volumes (the list above) was expected`);
      bytes = new Uint8Array(await response.arrayBuffer());
    } catch (e) {
      failed(e.message);
      return;
    }
    open(file, bytes, {});
  }

  async function loadFiles(files) {
    forget();
    error.textContent = '';
    // the header of a detached pair first; TIFF and DICOM by name too, so that the module can say
    // it has no reader for them (a DICOM slice often has no extension: a lone file is tried as it is)
    const header = files.find((f) => HEADER_NAMES.test(f.name)) ?? files.find((f) => OTHER_NAMES.test(f.name)) ??
      (files.length === 1 ? files[0] : undefined);
    if (!header) {
      failed(`${files.map((f) => f.name).join(', ')}: no volume file among them (expected one of ${VOLUME_EXTENSIONS})`);
      return;
    }
    const data = {};
    for (const f of files) if (f !== header) data[f.name] = new Uint8Array(await f.arrayBuffer());
    open(`file:${header.name}`, new Uint8Array(await header.arrayBuffer()), data);
  }

  function open(label, bytes, data) {
    forget();
    const shown = label.replace(/^file:/, '');
    try {
      const t0 = performance.now();
      volume = cmc33.Volume.read(bytes, shown, data);
      const readMs = performance.now() - t0;
      name = label;
      // the docs' zoom is a place in the aneurism
      zoomButton.disabled = label !== FIG12_VOLUME;
      if (zoomButton.disabled && zoom) {
        zoom = false;
        report(`zoom=fig12: the docs' Fig. 12 zoom is a place in ${FIG12_VOLUME}, not in ${shown}; the whole volume is shown.`);
      }
      const histogram = volume.histogram(256);
      about.textContent = `${shown}: ${volume.dims().join('×')} ${volume.type()}, values ${fmt(histogram.min)} … ${fmt(histogram.max)} (read in ${readMs.toFixed(0)} ms)${frameText(volume)}`;
      if (!Number.isFinite(iso) || iso < histogram.min || iso > histogram.max) iso = Number(((histogram.min + histogram.max) / 2).toPrecision(4));
      isoInput.value = iso;
      isoError.textContent = '';
      isoInput.setAttribute('aria-invalid', 'false');
      plot = histogramPlot(histBox, { ...histogram, iso, onPick: (v) => {
        iso = Number(v.toPrecision(4));
        isoInput.value = iso;
        plot.setIso(iso);
        extract();
      } });
      extract(true);
    } catch (e) {
      // the library's messages start with the file's name already
      failed(e.message.startsWith(`${shown}: `) ? e.message : `${shown}: ${e.message}`);
    }
  }

  function extract(refit = false) {
    save();
    if (!volume || !Number.isFinite(iso)) return;
    error.textContent = '';
    try {
      const shownMethods = compare ? [method, compare] : [method];
      const meshes = shownMethods.map((m) => {
        const t0 = performance.now();
        const raw = volume.extract(iso, m);
        const ms = performance.now() - t0;
        const mesh = takeMesh(raw, { components: true });
        mesh.ms = ms;
        mesh.method = m;
        return mesh;
      });
      lastMeshes = meshes;
      const dims = volume.dims();
      const samples = dims[0] * dims[1] * dims[2];
      if (fieldIso !== iso || !field) {
        field = samples <= FIELD_TOPOLOGY_LIMIT ? volume.fieldTopology(iso) : null;
        fieldIso = iso;
      }
      const same = (t) => field && field.determined && field.euler === t.euler && field.b0 === t.b0 && field.b1 === t.b1 && field.b2 === t.b2 && field.boundaryLoops === t.boundaryLoops;
      const row = (label, key) => el('tr', { dataset: { key } }, el('td', {}, label),
        ...meshes.map((m, k) => el('td', { class: k === 0 ? 'value' : 'value-2' }, String(m.topology[key]))),
        el('td', {}, field && key in field ? String(field[key]) : ''));
      const [first] = meshes;
      result.replaceChildren(
        el('p', { id: 'volume-time' }, `${first.vertexCount} vertices, `, el('b', { id: 'volume-triangles' }, String(first.triangleCount)), ` triangles in `,
          el('b', { id: 'volume-ms' }, first.ms.toFixed(1)), ` ms (${method}, WebAssembly, one thread)`,
          meshes[1] ? `; ${compare}: ${meshes[1].triangleCount} triangles in ${meshes[1].ms.toFixed(1)} ms` : ''),
        el('table', { id: 'volume-topology' },
          el('tr', {}, el('th', {}, ''), ...meshes.map((m) => el('th', {}, m.method)), el('th', {}, 'trilinear field')),
          row('Euler characteristic χ', 'euler'),
          row('b0 components', 'b0'),
          row('b1 tunnels', 'b1'),
          row('b2 closed components', 'b2'),
          row('boundary loops', 'boundaryLoops'),
          row('non-manifold edges', 'nonManifoldEdges'),
          row('non-manifold vertices', 'nonManifoldVertices')),
        ...meshes.map((m, k) => el('p', { id: k === 0 ? 'volume-verdict' : 'volume-verdict-2', class: field ? (same(m.topology) ? 'good' : 'bad') : '' },
          field ? `${m.method}: ${same(m.topology) ? 'the mesh has the topology of the trilinear level set' : 'the mesh differs from the trilinear level set'}`
            : 'trilinear field not computed (volume over 20 million samples)')),
      );
      meshes.forEach((m, k) => {
        titles[k].textContent = `${m.method}: ${m.topology.b0} components`;
        showMesh(k, m);
      });
      if (refit || zoom) placeCamera();
      document.body.dataset.ready = `volume ${name} ${iso} ${method}${compare ? ` ${compare}` : ''}`;
    } catch (e) {
      error.textContent = `iso ${iso}, ${method}: ${e.message}`;
    }
  }

  /** The camera: the docs' Fig. 12 zoom, or the whole mesh. */
  function placeCamera() {
    for (const v of viewers) {
      if (zoom) v.look(FIG12_ZOOM.focus, FIG12_ZOOM.position, FIG12_ZOOM);
      else v.fit();
    }
  }

  function showMesh(k, mesh) {
    const colors = new Float32Array(mesh.vertexCount * 3);
    const palette = (c) => {
      if (colouring === 'main') return c === 0 ? [0.93, 0.78, 0.25] : [0.55, 0.3, 0.82];
      const h = (c * 0.618034) % 1;
      const f = (n) => {
        const x = (n + h * 6) % 6;
        return 0.35 + 0.55 * Math.max(0, Math.min(1, Math.abs(x - 3) - 1));
      };
      return [f(0), f(4), f(2)];
    };
    for (let v = 0; v < mesh.vertexCount; ++v) colors.set(palette(mesh.components[v]), 3 * v);
    viewers[k].show(mesh.triangleCount ? [surface(mesh.positions, mesh.triangles, { colors })] : []);
  }

  if (name && !name.startsWith('file:')) loadBundled(name);
  else document.body.dataset.ready = 'volume';
  return { destroy() { volume?.delete(); plot?.destroy(); for (const v of viewers) v.renderer.dispose(); } };
}
