// Cell explorer: eight corner values, the method's decisions on them (cmc33's analyze_cell), the
// interior test's sweep as plots (Figs. 4, 6, 9), and the chosen triangulation beside the densely
// sampled level set of the trilinear interpolant.
import { el, fmt } from '../state.js';
import { linePlot, saddlePath } from '../plots.js';
import { Viewer, surface, boxEdges, markers, COLORS } from '../viewer.js';
import { SUBCASE_CELLS, APPENDIX_A, FIG9_CASE6 } from '../presets.js';
import { generator, randomValues } from '../search.js';
import { takeMesh } from '../cmc33.js';

const FACE_NAMES = ['x = 0', 'x = 1', 'y = 0', 'y = 1', 'z = 0', 'z = 1'];
const AXES = ['x', 'y', 'z'];
const cornerXYZ = (c) => [c & 1, (c >> 1) & 1, (c >> 2) & 1];
const TRUTH_STEPS = 40;

function presets() {
  return [
    ...SUBCASE_CELLS.map((p) => ({ id: `subcase-${p.name}`, label: `subcase ${p.name}`, values: p.values })),
    { id: 'appendix-a', label: 'Appendix A (13.5.2; MC33 says 13.5.1)', values: APPENDIX_A },
    { id: 'fig9', label: 'Fig. 9: case 6 tunnel that t_alt misses', values: FIG9_CASE6 },
  ];
}

const CLAIMS = {
  default:
    'Each cell is decided as the paper prescribes: the asymptotic decider on every ambiguous face, ' +
    'Chernyaev\'s test at t_max for the interior of cases 4, 6, 7, 10, 12, and Algorithm 1 for case 13.5. ' +
    'The left cube shows the triangles of the chosen method, the right one the level set of the ' +
    'trilinear interpolant itself, sampled on a 40³ grid: where their topology differs, the method is wrong.',
  13: 'Fig. 6 and Appendix A: for case 13.5 the sign of a alone does not tell a tunnel (13.5.2) from three sheets (13.5.1): ' +
    'the slice saddle x_c(t) jumps at the asymptote t_a, where den(t) changes sign. cmc33 asks instead whether both roots ' +
    't1, t2 of F and both saddles x_c(t1), x_c(t2) lie inside the cell (Algorithm 1); MC33 tests a < 0 and, in Lewiner\'s ' +
    'implementation, F(t_alt) > 0.',
  6: 'Fig. 9: Lewiner et al.\'s MC33 cuts the cell at t_alt, where the field crosses a chosen edge, and tests F(t_alt) > 0. ' +
    'When t_alt falls outside (t1, t2), F(t_alt) < 0 and the tunnel is missed; the test at t_max = −b/2a finds it.',
};

export function cellView(root, cmc33, state, setState) {
  const methods = cmc33.methods();
  let values = (state.cell ?? APPENDIX_A.join(',')).split(',').map(Number);
  if (values.length !== 8 || values.some((v) => !Number.isFinite(v))) values = APPENDIX_A.slice();
  let iso = Number.isFinite(Number(state.iso)) ? Number(state.iso) : 0;
  let method = methods.includes(state.method) ? state.method : 'cmc33';

  const presetSelect = el('select', { id: 'cell-preset' }, el('option', { value: '' }, 'choose a cell…'),
    presets().map((p) => el('option', { value: p.id }, p.label)));
  const methodSelect = el('select', { id: 'cell-method' }, methods.map((m) => el('option', { value: m }, m)));
  methodSelect.value = method;
  const isoInput = el('input', { id: 'cell-iso', type: 'number', step: 'any', value: iso, style: 'width:6rem' });
  const randomButton = el('button', { id: 'cell-random' }, 'random cell');

  const sliders = [], numbers = [], signs = [];
  const cornerRows = values.map((v, c) => {
    sliders[c] = el('input', { type: 'range', min: -1, max: 1, step: 0.0001, value: v, 'aria-label': `corner ${c} slider` });
    numbers[c] = el('input', { type: 'number', step: 'any', value: v, id: `corner-${c}`, 'aria-label': `corner ${c}` });
    signs[c] = el('span');
    sliders[c].addEventListener('input', () => setCorner(c, Number(sliders[c].value)));
    numbers[c].addEventListener('change', () => setCorner(c, Number(numbers[c].value)));
    return el('div', { class: 'corner' }, el('span', {}, `corner ${c} (${cornerXYZ(c).join(',')}) `, signs[c]), sliders[c], numbers[c]);
  });

  const claim = el('p', { class: 'claim', id: 'cell-claim' });
  const summary = el('div', { id: 'cell-summary' });
  const faces = el('table', { id: 'cell-faces' });
  const interior = el('div', { id: 'cell-interior' });
  const plotF = el('div'), plotSaddle = el('div');
  const pathCanvas = el('canvas', { class: 'path', width: 260, height: 260 });
  const plotsBox = el('div', { class: 'row', id: 'cell-plots' }, plotF, plotSaddle, el('div', {}, el('div', {}, 'slice saddle x_c(t): black where f(x_c) ≥ iso'), pathCanvas));
  const viewerBox = el('div', { class: 'viewer', id: 'cell-viewer' });

  root.append(
    el('h2', {}, 'Cell explorer'),
    claim,
    el('div', { class: 'row' },
      el('div', { class: 'panel controls' },
        el('h3', {}, 'Corner values'),
        el('div', {}, el('label', {}, 'preset ', presetSelect), randomButton),
        el('div', {}, el('label', {}, 'method ', methodSelect), el('label', {}, 'isovalue ', isoInput)),
        ...cornerRows),
      el('div', { class: 'panel' }, el('h3', {}, 'Decisions'), summary, faces, interior)),
    el('div', { class: 'row' }, el('div', { class: 'panel' }, el('h3', {}, 'The cell in 3D'), viewerBox), el('div', { class: 'panel' }, el('h3', {}, 'Interior test: the sweep'), plotsBox)),
  );

  const viewer = new Viewer(viewerBox, { width: 640, height: 360, legend: '' });
  const plots = [];

  presetSelect.addEventListener('change', () => {
    const p = presets().find((q) => q.id === presetSelect.value);
    if (p) {
      values = p.values.slice();
      iso = 0;
      isoInput.value = 0;
      refresh(true);
    }
  });
  randomButton.addEventListener('click', () => {
    values = Array.from(randomValues(generator((Math.random() * 2 ** 32) >>> 0), 8));
    refresh(true);
  });
  methodSelect.addEventListener('change', () => {
    method = methodSelect.value;
    refresh(false);
  });
  isoInput.addEventListener('change', () => {
    if (Number.isFinite(Number(isoInput.value))) iso = Number(isoInput.value);
    refresh(false);
  });

  function setCorner(c, v) {
    if (!Number.isFinite(v)) return;
    values[c] = v;
    refresh(false);
  }

  function refresh(syncInputs) {
    values.forEach((v, c) => {
      if (syncInputs || Number(numbers[c].value) !== v) numbers[c].value = v;
      if (syncInputs || Number(sliders[c].value) !== v) sliders[c].value = Math.max(-1, Math.min(1, v));
      const above = v >= iso;
      signs[c].textContent = above ? '+' : '−';
      signs[c].className = above ? 'sign-above' : 'sign-below';
    });
    setState({ view: 'cell', cell: values.join(','), iso: iso === 0 ? undefined : iso, method });
    let report;
    try {
      report = cmc33.analyzeCell(new Float64Array(values), iso, method);
    } catch (e) {
      summary.replaceChildren(el('p', { class: 'error' }, e.message));
      return;
    }
    claim.textContent = CLAIMS[report.baseCase] ?? CLAIMS.default;
    showSummary(report);
    showFaces(report);
    showInterior(report);
    show3d(report);
    document.body.dataset.ready = `cell ${report.subcase} ${method}`;
  }

  function showSummary(r) {
    const above = [...Array(8).keys()].filter((c) => (r.config >> c) & 1);
    summary.replaceChildren(
      el('div', {}, 'sign configuration ', el('span', { class: 'mono', id: 'cell-config' }, r.config.toString(2).padStart(8, '0')),
        ` (${r.config}; corners above: ${above.join(', ') || 'none'})`),
      el('div', {}, 'base case ', el('span', { class: 'big', id: 'cell-case' }, String(r.baseCase)),
        ' · subcase ', el('span', { class: 'big', id: 'cell-subcase' }, r.subcase), ` with ${method}`),
      el('div', {}, `${r.triangles.length / 3} triangles, ${r.topology.b0} piece(s), Euler characteristic ${r.topology.euler}`),
    );
  }

  function showFaces(r) {
    faces.replaceChildren(
      el('tr', {}, el('th', {}, 'face'), el('th', {}, 'ambiguous'), el('th', {}, 'saddle value − iso'), el('th', {}, 'above corners joined')),
      ...r.faces.map((f, i) =>
        el('tr', { dataset: { face: i } }, el('td', {}, FACE_NAMES[i]), el('td', {}, f.ambiguous ? 'yes' : 'no'),
          el('td', {}, f.ambiguous && f.used ? fmt(f.saddle + 0) : '—'),
          el('td', {}, !f.ambiguous ? '—' : !f.used ? 'not tested (mc)' : f.joined ? 'joined' : 'separated'))),
    );
  }

  function showInterior(r) {
    for (const p of plots.splice(0)) p.destroy();
    const i = r.interior;
    if (!i.tested) {
      interior.replaceChildren(el('p', {}, 'No interior test: the face tests decide this subcase.'));
      plotsBox.style.display = 'none';
      return;
    }
    plotsBox.style.display = '';
    const lines = [
      ['test', i.test === 'tunnel' ? 'tunnel (Chernyaev, at t_max)' : '13.5 (Algorithm 1)'],
      ['sweep', `along ${AXES[i.axis]} from corner A0 = ${i.cornerA} to C1 = ${i.cornerC}`],
      ['F(t) = a t² + b t + c', `a = ${fmt(i.a)}, b = ${fmt(i.b)}, c = ${fmt(i.c)}`],
      ['t_max = −b/2a', `${fmt(i.tMax)}, F(t_max) = ${fmt(i.fTMax)}`],
      ['roots of F', `t1 = ${fmt(i.t1)}, t2 = ${fmt(i.t2)}`],
      ['t_alt (Lewiner)', `${fmt(i.tAlt)} on edge ${i.lewinerEdge} (sweep along ${AXES[i.lewinerAxis]} from ${i.lewinerCorner}), F(t_alt) = ${fmt(i.fTAlt)}`],
    ];
    if (i.test === '13.5') lines.push(['slice saddles', `x_c(t1) = (${fmt(i.saddle1[0])}, ${fmt(i.saddle1[1])}), x_c(t2) = (${fmt(i.saddle2[0])}, ${fmt(i.saddle2[1])})`]);
    lines.push(['decision', i.skipped ? 'not tested (mc33-lewiner skips this branch)' : i.tunnel ? `tunnel${i.tunnelCorner >= 0 ? `, facing corner ${i.tunnelCorner}` : ''}` : 'no tunnel']);
    interior.replaceChildren(el('table', { id: 'cell-interior-table' }, lines.map(([k, v]) => el('tr', {}, el('td', {}, k), el('td', { style: 'text-align:left' }, v)))));

    const s = cmc33.sweep(new Float64Array(values), iso, i.axis, i.cornerA, 400);
    const series = [{ label: 'F(t)', values: s.F }];
    const lewinerSweep = i.lewinerAxis !== i.axis || i.lewinerCorner !== i.cornerA;
    if (lewinerSweep) series.push({ label: 'F(t), Lewiner\'s sweep', values: cmc33.sweep(new Float64Array(values), iso, i.lewinerAxis, i.lewinerCorner, 400).F });
    const den0 = s.den[0], den1 = s.den[s.den.length - 1];
    const tA = den0 !== den1 ? den0 / (den0 - den1) : NaN;
    const marks = [
      { x: i.t1, label: 't1', color: '#2a9d4b' },
      { x: i.t2, label: 't2', color: '#2a9d4b' },
      { x: i.tMax, label: 't_max', color: '#d9534f' },
      { x: i.tAlt, label: 't_alt', color: '#e08a00' },
    ];
    plots.push(linePlot(plotF, { title: 'F(t) = A_t C_t − B_t D_t', x: s.t, series, markers: marks, xLabel: 't', xRange: [0, 1] }));
    const bound = Math.max(...Array.from(s.F, Math.abs)) * 4 || 1;
    const clipped = Array.from(s.saddle, (v) => (Math.abs(v) > bound ? NaN : v));
    plots.push(linePlot(plotSaddle, {
      title: 'f(x_c(t)): the slice saddle\'s value',
      x: s.t,
      series: [{ label: 'f(x_c(t))', values: clipped, color: '#3b6fb6' }],
      markers: [...marks.slice(0, 2), { x: tA, label: 't_a', color: '#8a4fd1' }],
      xLabel: 't',
      xRange: [0, 1],
    }));
    saddlePath(pathCanvas, {
      u: s.u, v: s.v, saddle: s.saddle,
      marks: [{ u: i.saddle1[0], v: i.saddle1[1], label: 'x_c(t1)', color: '#2a9d4b' }, { u: i.saddle2[0], v: i.saddle2[1], label: 'x_c(t2)', color: '#2a9d4b' }],
    });
  }

  function show3d(r) {
    const cornerColors = values.map((v) => (v >= iso ? COLORS.above : COLORS.below));
    const corners = [...Array(8).keys()].map(cornerXYZ);
    const objects = [boxEdges([0, 0, 0], [1, 1, 1]), markers(corners, cornerColors, 0.035)];
    if (r.triangles.length > 0) objects.push(surface(new Float32Array(r.positions), new Uint32Array(r.triangles), { color: COLORS.surface }));
    const shift = 1.6;
    objects.push(boxEdges([shift, 0, 0], [shift + 1, 1, 1]), markers(corners.map(([x, y, z]) => [x + shift, y, z]), cornerColors, 0.035));
    try {
      const truth = takeMesh(cmc33.trilinearSurface(new Float64Array(values), iso, TRUTH_STEPS), { topology: false });
      if (truth.triangles.length > 0) objects.push(surface(truth.positions, truth.triangles, { color: COLORS.truth, opacity: 0.55, offset: [shift, 0, 0] }));
    } catch (e) {
      console.warn(e.message);
    }
    viewer.legend ??= viewerBox.appendChild(el('div', { class: 'legend' }));
    viewer.legend.textContent = `left: ${method}'s triangles · right: the trilinear level set (${TRUTH_STEPS}³ samples) · red corners above iso`;
    viewer.show(objects);
  }

  refresh(true);
  return { destroy() { for (const p of plots) p.destroy(); viewer.renderer.dispose(); } };
}
