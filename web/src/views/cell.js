// Cell explorer: eight corner values, the method's decisions on them (cmc33's analyze_cell), the
// interior test's sweep as plots (Figs. 4, 6, 9), and the chosen triangulation beside the densely
// sampled level set of the trilinear interpolant.
import { el, fmt, parseNumber } from '../state.js';
import { linePlot, saddlePath } from '../plots.js';
import { Viewer, surface, boxEdges, markers, COLORS } from '../viewer.js';
import { SUBCASE_CELLS, APPENDIX_A, FIG9_CASE6, PAPER_NAMES } from '../presets.js';
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

/** The address's cell= as up to 8 texts, and what is wrong with it (a list, empty if nothing). */
function addressCell(text) {
  const parts = text.split(',');
  const problems = [];
  if (parts.length !== 8) {
    problems.push(`cell=${text}: ${parts.length} value${parts.length === 1 ? '' : 's'}; 8 were expected, separated by commas, ` +
      `in the library's corner order (${PAPER_NAMES.join(', ')})${parts.length > 8 ? `; the fields hold the first 8` : ''}.`);
  }
  parts.slice(0, 8).forEach((t, c) => {
    const { error } = parseNumber(t);
    if (error) problems.push(`cell=: corner ${c} (${PAPER_NAMES[c]}) ${error}.`);
  });
  return { texts: parts.slice(0, 8), problems };
}

export function cellView(root, cmc33, state, setState, report = () => {}) {
  const methods = cmc33.methods();
  let texts = APPENDIX_A.map(String);
  if (state.cell !== undefined) {
    const a = addressCell(state.cell);
    texts = Array.from({ length: 8 }, (_, c) => a.texts[c] ?? '');
    a.problems.forEach(report);
  }
  let values = texts.map((t) => parseNumber(t).value ?? NaN);
  const isoText = state.iso ?? '0';
  let iso = parseNumber(isoText).value ?? NaN;
  if (state.iso !== undefined && !Number.isFinite(iso)) report(`iso=: ${parseNumber(isoText).error}.`);
  let method = 'cmc33';
  if (state.method !== undefined) {
    if (methods.includes(state.method)) method = state.method;
    else report(`method=${state.method}: no such method; the methods are ${methods.join(', ')}. cmc33 is used.`);
  }

  const presetSelect = el('select', { id: 'cell-preset' }, el('option', { value: '' }, 'choose a cell…'),
    presets().map((p) => el('option', { value: p.id }, p.label)));
  const methodSelect = el('select', { id: 'cell-method' }, methods.map((m) => el('option', { value: m }, m)));
  methodSelect.value = method;
  const isoInput = el('input', { id: 'cell-iso', type: 'text', inputmode: 'decimal', value: isoText, style: 'width:6rem', 'aria-describedby': 'cell-iso-error' });
  const isoError = el('span', { class: 'field-error', id: 'cell-iso-error' });
  const randomButton = el('button', { id: 'cell-random' }, 'random cell');

  const sliders = [], numbers = [], signs = [], fieldErrors = [];
  const cornerRows = texts.map((t, c) => {
    const v = values[c];
    sliders[c] = el('input', { type: 'range', min: -1, max: 1, step: 0.0001, value: Number.isFinite(v) ? v : 0, 'aria-label': `corner ${c} (${PAPER_NAMES[c]}) slider` });
    numbers[c] = el('input', { type: 'text', inputmode: 'decimal', value: t, id: `corner-${c}`, 'aria-label': `corner ${PAPER_NAMES[c]} (${c})`, 'aria-describedby': `corner-${c}-error`, dataset: { paper: PAPER_NAMES[c] } });
    signs[c] = el('span');
    fieldErrors[c] = el('span', { class: 'field-error', id: `corner-${c}-error` });
    sliders[c].addEventListener('input', () => {
      numbers[c].value = sliders[c].value;
      refresh();
    });
    numbers[c].addEventListener('change', () => refresh());
    return el('div', { class: 'corner' },
      el('label', { for: `corner-${c}` }, el('b', { class: 'paper-name' }, PAPER_NAMES[c]), ` corner ${c} (${cornerXYZ(c).join(',')}) `, signs[c]),
      sliders[c], numbers[c], fieldErrors[c]);
  });

  const claim = el('p', { class: 'claim', id: 'cell-claim' });
  const summary = el('div', { id: 'cell-summary' });
  const faces = el('table', { id: 'cell-faces' });
  const interior = el('div', { id: 'cell-interior' });
  const plotF = el('div', { id: 'cell-plot-f' }), plotSaddle = el('div', { id: 'cell-plot-saddle' }), plotLewiner = el('div', { id: 'cell-plot-lewiner' });
  const pathCanvas = el('canvas', { class: 'path', width: 260, height: 260 });
  const plotsBox = el('div', { class: 'row', id: 'cell-plots' }, plotF, plotLewiner, plotSaddle, el('div', {}, el('div', {}, 'slice saddle x_c(t): black where f(x_c) ≥ iso'), pathCanvas));
  const viewerBox = el('div', { class: 'viewer', id: 'cell-viewer' });

  root.append(
    el('h2', {}, 'Cell explorer'),
    claim,
    el('div', { class: 'row' },
      el('div', { class: 'panel controls' },
        el('h3', {}, 'Corner values'),
        el('div', {}, el('label', {}, 'preset ', presetSelect), randomButton),
        el('div', {}, el('label', {}, 'method ', methodSelect), el('label', {}, 'isovalue ', isoInput), isoError),
        el('p', { class: 'hint' }, 'A0 … D1 name the corners as the paper\'s Appendix A table does (base z = 0: A0, B0, C0, D0 going round; top: A1 … D1), so its values can be typed in as printed (+0.2864, −0.0639).'),
        ...cornerRows),
      el('div', { class: 'panel' }, el('h3', {}, 'Decisions'), summary, faces, interior)),
    el('div', { class: 'row' }, el('div', { class: 'panel' }, el('h3', {}, 'The cell in 3D'), viewerBox), el('div', { class: 'panel' }, el('h3', {}, 'Interior test: the sweep'), plotsBox)),
  );

  const viewer = new Viewer(viewerBox, { width: 640, height: 360, legend: '' });
  const plots = [];

  presetSelect.addEventListener('change', () => {
    const p = presets().find((q) => q.id === presetSelect.value);
    if (p) {
      p.values.forEach((v, c) => (numbers[c].value = String(v)));
      isoInput.value = '0';
      refresh();
    }
  });
  randomButton.addEventListener('click', () => {
    randomValues(generator((Math.random() * 2 ** 32) >>> 0), 8).forEach((v, c) => (numbers[c].value = String(v)));
    refresh();
  });
  methodSelect.addEventListener('change', () => {
    method = methodSelect.value;
    refresh();
  });
  isoInput.addEventListener('change', () => refresh());

  /** Reads the fields: each is marked beside it when it is not a number; false if any is not. */
  function readFields() {
    let ok = true;
    const read = (input, error, name) => {
      const r = parseNumber(input.value);
      error.textContent = r.error ? `${name} ${r.error}` : '';
      input.setAttribute('aria-invalid', r.error ? 'true' : 'false');
      if (r.error) ok = false;
      return r.error ? NaN : r.value;
    };
    values = numbers.map((input, c) => read(input, fieldErrors[c], PAPER_NAMES[c]));
    iso = read(isoInput, isoError, 'the isovalue');
    return ok;
  }

  function clearResults(message) {
    for (const p of plots.splice(0)) p.destroy();
    claim.textContent = CLAIMS.default;
    summary.replaceChildren(el('p', { class: 'error', id: 'cell-invalid' }, message));
    faces.replaceChildren();
    interior.replaceChildren();
    plotsBox.style.display = 'none';
    viewer.show([]);
    document.body.dataset.ready = 'cell invalid';
  }

  function refresh() {
    if (!readFields()) {
      const bad = [...numbers.map((_, c) => (fieldErrors[c].textContent ? PAPER_NAMES[c] : null)), isoError.textContent ? 'the isovalue' : null].filter(Boolean);
      clearResults(`No decision: ${bad.join(', ')} ${bad.length === 1 ? 'is' : 'are'} not a number (see beside the field${bad.length === 1 ? '' : 's'}).`);
      return;
    }
    values.forEach((v, c) => {
      if (Number(sliders[c].value) !== v) sliders[c].value = Math.max(-1, Math.min(1, v));
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
      ['sweep', `along ${AXES[i.axis]} from the tested corner ${i.cornerA} (this sweep's A0) to ${i.cornerC} (its C1)`],
      ['F(t) = a t² + b t + c', `a = ${fmt(i.a)}, b = ${fmt(i.b)}, c = ${fmt(i.c)}`],
      ['t_max = −b/2a', `${fmt(i.tMax)}, F(t_max) = ${fmt(i.fTMax)}`],
      ['roots of F', `t1 = ${fmt(i.t1)}, t2 = ${fmt(i.t2)}`],
      ['t_alt (Lewiner)', `${fmt(i.tAlt)} on edge ${i.lewinerEdge} (sweep along ${AXES[i.lewinerAxis]} from ${i.lewinerCorner}), F(t_alt) = ${fmt(i.fTAlt)}`],
    ];
    if (i.test === '13.5') lines.push(['slice saddles', `x_c(t1) = (${fmt(i.saddle1[0])}, ${fmt(i.saddle1[1])}), x_c(t2) = (${fmt(i.saddle2[0])}, ${fmt(i.saddle2[1])})`]);
    lines.push(['decision', i.skipped ? 'not tested (mc33-lewiner skips this branch)' : i.tunnel ? `tunnel${i.tunnelCorner >= 0 ? `, facing corner ${i.tunnelCorner}` : ''}` : 'no tunnel']);
    interior.replaceChildren(el('table', { id: 'cell-interior-table' }, lines.map(([k, v]) => el('tr', {}, el('td', {}, k), el('td', { style: 'text-align:left' }, v)))));

    const s = cmc33.sweep(new Float64Array(values), iso, i.axis, i.cornerA, 400);
    const marks = [
      { x: i.t1, label: 't1', color: '#2a9d4b' },
      { x: i.t2, label: 't2', color: '#2a9d4b' },
      { x: i.tMax, label: 't_max', color: '#d9534f' },
    ];
    const den0 = s.den[0], den1 = s.den[s.den.length - 1];
    const tA = den0 !== den1 ? den0 / (den0 - den1) : NaN;
    plots.push(linePlot(plotF, {
      title: `F(t) = A_t C_t − B_t D_t, along ${AXES[i.axis]} from corner ${i.cornerA}`,
      x: s.t, series: [{ label: 'F(t)', values: s.F }], markers: marks, xLabel: 't', xRange: [0, 1],
    }));
    // t_alt is a height of Lewiner et al.'s own sweep (its axis and tested corner), so it is drawn
    // on that sweep's F, on its own t axis, never on the plot above
    const lewiner = cmc33.sweep(new Float64Array(values), iso, i.lewinerAxis, i.lewinerCorner, 400);
    const same = i.lewinerAxis === i.axis && i.lewinerCorner === i.cornerA;
    plots.push(linePlot(plotLewiner, {
      title: `Lewiner's sweep: along ${AXES[i.lewinerAxis]} from corner ${i.lewinerCorner}${same ? ' (the same sweep)' : ''}`,
      x: lewiner.t,
      series: [{ label: 'F_Lewiner(t)', values: lewiner.F, color: '#e08a00' }],
      markers: [{ x: i.tAlt, label: `t_alt, F = ${fmt(i.fTAlt)}`, color: '#e08a00', y: i.fTAlt }],
      xLabel: 't (Lewiner\'s sweep)', xRange: [0, 1],
    }));
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
    window.cmc33Page.cell = { F: plots[0], lewiner: plots[1], saddle: plots[2] }; // for the browser tests
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

  refresh();
  return { destroy() { for (const p of plots) p.destroy(); viewer.renderer.dispose(); } };
}
