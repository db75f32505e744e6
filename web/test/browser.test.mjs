// The page in a real browser (Debian's chromium, headless, driven by puppeteer-core), served from
// build/web by a plain static server: what a reader sees must be the library's answers. Screenshots
// of every view go to build/web-screenshots/ (CI keeps them).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { serve, launch } from './harness.mjs';
import { WEB, ROOT, SHARED, BUCKY, cliExtract, cliCounts, makeSweepFixture } from './common.mjs';
import { SUBCASE_CELLS, APPENDIX_A, PAPER_NAMES } from '../src/presets.js';

const SHOTS = path.join(ROOT, 'build/web-screenshots');
const ANEURISM = path.join(SHARED, 'aneurism_256x256x256_uint8.nrrd');
let server, browser, page, fixture;
const problems = []; // console errors and uncaught exceptions, over every test

before(async () => {
  fs.mkdirSync(SHOTS, { recursive: true });
  fixture = makeSweepFixture(BUCKY, [40, 60, 80, 100, 120, 140, 160], ['cmc33', 'mc33-lewiner', 'mc']);
  server = await serve(WEB, { '/fixture/': fixture.dir });
  browser = await launch();
  page = await browser.newPage();
  page.on('console', (m) => {
    if (m.type() === 'error') problems.push(`console: ${m.text()}`);
  });
  page.on('pageerror', (e) => problems.push(`page: ${e.message}`));
  page.on('requestfailed', (r) => problems.push(`request failed: ${r.url()}`));
});

after(async () => {
  await browser?.close();
  await server?.close();
  if (fixture) fs.rmSync(fixture.dir, { recursive: true, force: true });
});

/** Loads the page afresh at `hash` and waits until the view says it is ready. */
async function open(hash, ready = (r) => Boolean(r)) {
  await page.goto('about:blank');
  await page.goto(`${server.url}index.html${hash}`, { waitUntil: 'load' });
  await page.waitForFunction(`(${ready.toString()})(document.body.dataset.ready)`, { timeout: 60000 });
}

const text = (selector) => page.$eval(selector, (e) => e.textContent.trim());

/**
 * target.screenshot(options) (target: the page or an element), once more if the capture stalls.
 * Headless chromium's capture can wait on an idle compositor until the protocol times out (seen
 * once in CI: the first full-page shot of the run, 180 s, where the same test takes under a second
 * otherwise); that stall says nothing about the page. A screencast started and stopped wakes the
 * compositor, then the capture is tried once more; a second stall fails the test.
 */
async function screenshot(target, options) {
  try {
    return await target.screenshot(options);
  } catch (e) {
    if (!/timed out/i.test(String(e?.message))) throw e;
    console.warn(`screenshot ${options.path}: ${e.message}; waking the compositor and trying once more`);
    const session = await page.createCDPSession();
    await session.send('Page.startScreencast', { format: 'jpeg', quality: 10 });
    await new Promise((r) => setTimeout(r, 500));
    await session.send('Page.stopScreencast');
    await session.detach();
    return target.screenshot(options);
  }
}

/** Pixel statistics of a screenshot of `selector`, decoded by the browser: share of non-white pixels, colours. */
async function pixels(selector, file) {
  const shot = await screenshot(await page.$(selector), { path: path.join(SHOTS, file) });
  return page.evaluate(async (b64) => {
    const bitmap = await createImageBitmap(await (await fetch(`data:image/png;base64,${b64}`)).blob());
    const canvas = new OffscreenCanvas(bitmap.width, bitmap.height);
    const ctx = canvas.getContext('2d');
    ctx.drawImage(bitmap, 0, 0);
    const { data } = ctx.getImageData(0, 0, bitmap.width, bitmap.height);
    let ink = 0, pink = 0, purple = 0, yellow = 0;
    const colours = new Set();
    for (let i = 0; i < data.length; i += 4) {
      const r = data[i], g = data[i + 1], b = data[i + 2];
      if (Math.max(255 - r, 255 - g, 255 - b) > 40) ++ink;
      if (r > 200 && g < 90 && b > 100 && b < 200) ++pink; // the non-manifold edges (#ff1493)
      if (b - g > 30 && r - g > 10 && r < 235) ++purple; // the extra components, the shared face
      if (r - b > 60 && g - b > 40) ++yellow; // the largest component, the tunnels' surface
      colours.add((r >> 4) << 8 | (g >> 4) << 4 | (b >> 4));
    }
    const n = data.length / 4;
    return { ink: ink / n, colours: colours.size, pink: pink / n, purple: purple / n, yellow: yellow / n };
  }, Buffer.from(shot).toString('base64'));
}

test('Appendix A: the link opens 13.5.1 with mc33-lewiner; cmc33 says 13.5.2', async () => {
  const cell = APPENDIX_A.join(',');
  await open(`#cell=${cell}&method=mc33-lewiner`, (r) => r?.startsWith('cell '));
  assert.equal(await text('#cell-subcase'), '13.5.1');
  assert.equal(await page.$eval('#cell-method', (e) => e.value), 'mc33-lewiner');
  await screenshot(page, { path: path.join(SHOTS, 'cell-appendix-a-mc33-lewiner.png'), fullPage: true });
  await page.select('#cell-method', 'cmc33');
  await page.waitForFunction(() => document.querySelector('#cell-subcase')?.textContent === '13.5.2');
  assert.match(page.url(), /method=cmc33/); // the state follows in the fragment
  assert.match(await text('#cell-interior'), /t1 = 0\.635/);
  await screenshot(page, { path: path.join(SHOTS, 'cell-appendix-a-cmc33.png'), fullPage: true });
  const stats = await pixels('#cell-viewer canvas', 'cell-3d.png');
  assert.ok(stats.ink > 0.03 && stats.colours > 20, `3D view not blank: ${JSON.stringify(stats)}`);
});

test('every subcase preset shows its subcase', async () => {
  await open('#view=cell', (r) => r?.startsWith('cell '));
  for (const cell of SUBCASE_CELLS) {
    await page.select('#cell-preset', `subcase-${cell.name}`);
    await page.waitForFunction((name) => document.querySelector('#cell-subcase')?.textContent === name, { timeout: 10000 }, cell.name);
    const fragment = decodeURIComponent(new URL(page.url()).hash);
    assert.ok(fragment.includes(`cell=${cell.values.map(Number).join(',')}`), fragment);
  }
});

test('a corner typed in changes the decision (Appendix A corner 7 made positive)', async () => {
  await open(`#cell=${APPENDIX_A.join(',')}`, (r) => r?.startsWith('cell '));
  assert.equal(await text('#cell-subcase'), '13.5.2');
  await page.$eval('#corner-7', (e) => {
    e.value = '0.5';
    e.dispatchEvent(new Event('change'));
  });
  await page.waitForFunction(() => document.querySelector('#cell-subcase')?.textContent !== '13.5.2');
  const want = await page.evaluate((v) => window.cmc33Page.module.analyzeCell(new Float64Array(v), 0, 'cmc33').subcase, [...APPENDIX_A.slice(0, 7), 0.5]);
  assert.equal(await text('#cell-subcase'), want);
  assert.equal(await text('#cell-case'), String(await page.evaluate((v) => window.cmc33Page.module.analyzeCell(new Float64Array(v), 0, 'cmc33').baseCase, [...APPENDIX_A.slice(0, 7), 0.5])));
});

/** The cell view's fragment as the page holds it. */
const hashNow = () => page.evaluate(() => location.hash);

/** Types `value` into the field `selector` as a reader does (select all, type, leave the field). */
async function typeInto(selector, value) {
  await page.click(selector, { clickCount: 3 });
  await page.keyboard.press('Backspace');
  if (value) await page.type(selector, value);
  await page.keyboard.press('Tab');
}

test('a bad corner value is named beside its field; the reader\'s text and the address are kept', async () => {
  await open(`#cell=${APPENDIX_A.join(',')}`, (r) => r?.startsWith('cell '));
  const address = await hashNow();
  const cases = [
    ['abc', /^C0 “abc” is not a number; a decimal such as −0\.2384 or 2\.5e-3 was expected$/],
    ['', /^C0 is empty; a number was expected/],
    ['1e400', /^C0 “1e400” is beyond the largest double .*a finite number was expected$/],
  ];
  for (const [typed, message] of cases) {
    await typeInto('#corner-3', typed);
    await page.waitForFunction(() => document.body.dataset.ready === 'cell invalid');
    assert.match(await text('#corner-3-error'), message, typed);
    assert.equal(await page.$eval('#corner-3', (e) => e.value), typed, 'the reader\'s text stays in the field');
    assert.equal(await page.$eval('#corner-3', (e) => e.getAttribute('aria-invalid')), 'true');
    assert.match(await text('#cell-invalid'), /^No decision: C0 is not a number/);
    assert.equal(await hashNow(), address, 'the address keeps the last valid cell');
  }
  await typeInto('#corner-3', '+0.6568');
  await page.waitForFunction(() => document.querySelector('#cell-subcase')?.textContent === '13.5.2');
  assert.equal(await text('#corner-3-error'), '');
  assert.equal(await hashNow(), address);
  // the isovalue is read the same way
  await typeInto('#cell-iso', 'zero');
  await page.waitForFunction(() => document.body.dataset.ready === 'cell invalid');
  assert.match(await text('#cell-iso-error'), /^the isovalue “zero” is not a number/);
  assert.equal(await hashNow(), address);
});

test('a link with 7 or 9 values, NaN or an unknown view says what is wrong at the top and keeps the address', async () => {
  const seven = APPENDIX_A.slice(0, 7).join(','), nine = [...APPENDIX_A, 0.5].join(',');
  const withNaN = [...APPENDIX_A.slice(0, 3), 'NaN', ...APPENDIX_A.slice(4)].join(',');
  const cases = [
    [`#cell=${nine}`, [/cell=.*: 9 values; 8 were expected.*the fields hold the first 8/], 'cell 13.5.2 cmc33'],
    [`#cell=${withNaN}&method=mc34&iso=x`, [/corner 3 \(C0\) “NaN” is not a number/, /method=mc34: no such method/, /iso=: “x” is not a number/], 'cell invalid'],
    ['#view=nonsense', [/view=nonsense: there is no such view; the views are cell, tunnels, volume, figures/], 'cell 13.5.2 cmc33'],
    ['#view=volume&volume=Bucky_32x32x32_uint8.nrrd&iso=abc', [/iso=: “abc” is not a number/], 'volume Bucky_32x32x32_uint8.nrrd'],
    [`#cell=${seven}`, [/cell=.*: 7 values; 8 were expected, separated by commas/], 'cell invalid'],
  ];
  for (const [hash, messages, ready] of cases) {
    await open(hash, (r) => Boolean(r) && r !== 'volume');
    assert.ok((await page.evaluate(() => document.body.dataset.ready)).startsWith(ready), hash);
    assert.equal(await page.$eval('#address-problems', (e) => e.hidden), false, hash);
    for (const message of messages) assert.match(await text('#address-problems'), message, hash);
    assert.equal(await hashNow(), hash, 'the address is kept');
  }
  // 7 values (the last case): the fields hold them, the eighth is named as missing beside its field
  assert.equal(await page.$eval('#corner-6', (e) => e.value), String(APPENDIX_A[6]));
  assert.match(await text('#corner-7-error'), /^C1 is empty/);
  // once the reader completes the cell, the page works and the address follows it again
  await typeInto('#corner-7', '-0.5049');
  await page.waitForFunction(() => document.querySelector('#cell-subcase')?.textContent === '13.5.2');
  assert.equal(await page.$eval('#address-problems', (e) => e.hidden), true);
  assert.equal(decodeURIComponent(await hashNow()), `#view=cell&cell=${APPENDIX_A.join(',')}&method=cmc33`);
});

test('the corners carry the paper\'s names: its Appendix A table typed in as printed gives 13.5.2', async () => {
  await open(`#cell=${SUBCASE_CELLS[0].values.join(',')}`, (r) => r?.startsWith('cell '));
  assert.equal(await text('#cell-subcase'), '0');
  // the table as the paper prints it (Appendix A), typed into the field labelled with each name
  const table = { A0: '+0.2864', A1: '-0.2384', B0: '-0.0639', B1: '+0.9486', C0: '+0.6568', C1: '-0.5049', D0: '-0.1692', D1: '+0.1075' };
  const labels = await page.$$eval('.corner label', (ls) => ls.map((l) => l.textContent));
  labels.forEach((l, c) => assert.ok(l.startsWith(PAPER_NAMES[c]), l));
  const entries = Object.entries(table);
  // seven filled in at once (the page reads every field when one changes), the last typed key by key
  await page.evaluate((pairs) => {
    for (const [name, value] of pairs) document.querySelector(`.corner input[data-paper=${name}]`).value = value;
  }, entries.slice(0, 7));
  await typeInto(`.corner input[data-paper=${entries[7][0]}]`, entries[7][1]);
  await page.waitForFunction(() => document.querySelector('#cell-subcase')?.textContent === '13.5.2');
  assert.ok(decodeURIComponent(await hashNow()).includes(`cell=${APPENDIX_A.join(',')}`), await hashNow());
});

test('t_alt is marked on Lewiner\'s own sweep, not on F(t) (Appendix A: t_alt 0.1756, F(t_alt) −0.0007)', async () => {
  await open(`#cell=${APPENDIX_A.join(',')}`, (r) => r?.startsWith('cell '));
  const got = await page.evaluate((values) => {
    const { F, lewiner } = window.cmc33Page.cell;
    const m = window.cmc33Page.module;
    const i = m.analyzeCell(new Float64Array(values), 0, 'cmc33').interior;
    return {
      fMarks: F.markers.map((k) => k.label), lewinerMarks: lewiner.markers.map((k) => ({ label: k.label, x: k.x, y: k.y })),
      lewinerF: lewiner.data[1], want: Array.from(m.sweep(new Float64Array(values), 0, i.lewinerAxis, i.lewinerCorner, 400).F),
      F: F.data[1], wantF: Array.from(m.sweep(new Float64Array(values), 0, i.axis, i.cornerA, 400).F),
      titles: [F.root.querySelector('.u-title').textContent, lewiner.root.querySelector('.u-title').textContent],
    };
  }, APPENDIX_A);
  assert.deepEqual(got.fMarks, ['t1', 't2', 't_max']);
  assert.equal(got.lewinerMarks.length, 1);
  assert.match(got.lewinerMarks[0].label, /^t_alt/);
  // the paper prints t_alt = A0 / (A0 - A1) = 0.1075 / 0.6124 = 0.17554 as 0.1756, and F(t_alt) = -0.0007
  assert.ok(Math.abs(got.lewinerMarks[0].x - 0.1756) < 1e-4, got.lewinerMarks[0].x);
  assert.ok(Math.abs(got.lewinerMarks[0].y + 0.0007) < 1e-4, got.lewinerMarks[0].y);
  assert.deepEqual(got.lewinerF, got.want);
  assert.deepEqual(got.F, got.wantF);
  assert.notDeepEqual(got.lewinerF, got.F, 'Appendix A: Lewiner\'s sweep is another one');
  assert.match(got.titles[1], /^Lewiner's sweep: along [xyz] from corner \d$/);
  await screenshot(await page.$('#cell-plots'), { path: path.join(SHOTS, 'cell-sweeps.png') });
});

test('neighbouring tunnels: every method, against the field topology', async () => {
  await open('#view=tunnels', (r) => r?.startsWith('tunnels '));
  const rows = await page.$$eval('#tunnels-table tr[data-method]', (trs) => trs.map((tr) => [tr.dataset.method, ...[...tr.children].map((td) => td.textContent)]));
  const methods = await page.evaluate(() => window.cmc33Page.module.methods());
  assert.deepEqual(rows.map((r) => r[0]), methods);
  assert.equal(rows.find((r) => r[0] === 'cmc33').at(-1), 'equal');
  assert.equal(rows.find((r) => r[0] === 'cmc33')[4], '0'); // no non-manifold edge
  assert.match(await text('#tunnels-pair'), /tunnels in both/);
  // Fig. 8 zoomed on the two cells: the trilinear level set, a method that is non-manifold here, cmc33
  const view = await page.evaluate(() => {
    const { pair, middle, viewers } = window.cmc33Page.tunnels;
    // the shared face's share of each view, from the viewer's own camera
    const a = pair.axis, u = (a + 1) % 3, w = (a + 2) % 3;
    const corners = [[0, 0], [1, 0], [1, 1], [0, 1]].map(([du, dw]) => {
      const p = pair.b.slice();
      p[u] += du;
      p[w] += dw;
      return p;
    });
    const shares = viewers.map((v) => {
      const V = v.camera.position.constructor;
      const q = corners.map((c) => new V(...c).project(v.camera));
      let area = 0;
      for (let i = 0; i < 4; ++i) area += q[i].x * q[(i + 1) % 4].y - q[(i + 1) % 4].x * q[i].y;
      return Math.abs(area) / 2 / 4; // NDC spans 2 x 2
    });
    return { middle, shares, titles: [...document.querySelectorAll('#tunnels-viewers h4')].map((h) => h.textContent), hint: document.querySelector('#tunnels-viewers .hint3d').textContent };
  });
  const middleRow = rows.find((r) => r[0] === view.middle);
  assert.ok(Number(middleRow[4]) > 0, `the middle view shows a method with non-manifold edges here: ${middleRow}`);
  assert.deepEqual(view.titles, ['the trilinear level set', `${view.middle}: ${middleRow[4]} non-manifold edges`, 'cmc33: 0 non-manifold edges']);
  for (const share of view.shares) assert.ok(share > 0.05, `the shared face fills ${(100 * share).toFixed(1)}% of a view (zoomed on the two cells)`);
  assert.match(view.hint, /drag: rotate.*zoom/);
  const shots = [];
  for (let k = 0; k < 3; ++k) shots.push(await pixels(`#tunnels-viewer-${k} canvas`, `tunnels-3d-${k}.png`));
  assert.ok(shots.every((st) => st.ink > 0.05), JSON.stringify(shots));
  assert.ok(shots[1].pink > 0.0005, `the non-manifold edges show in the middle view: ${JSON.stringify(shots[1])}`);
  assert.equal(shots[2].pink, 0, 'none in cmc33\'s');
  assert.ok(shots.every((st) => st.purple > 0.008), `the shared face shows: ${JSON.stringify(shots)}`);
  await screenshot(page, { path: path.join(SHOTS, 'tunnels.png'), fullPage: true });
});

async function volumeCounts() {
  return page.evaluate(() => {
    const cell = (key) => Number(document.querySelector(`#volume-topology tr[data-key=${key}] .value`).textContent);
    return {
      vertices: Number(document.querySelector('#volume-time').textContent.split(' ')[0]),
      triangles: Number(document.querySelector('#volume-triangles').textContent),
      euler: cell('euler'), b0: cell('b0'), b1: cell('b1'), b2: cell('b2'), boundaryLoops: cell('boundaryLoops'), nonManifoldEdges: cell('nonManifoldEdges'),
    };
  });
}

test('a volume extracted in the page has the CLI\'s triangles and topology (Bucky, every method)', async () => {
  for (const method of ['cmc33', 'mc33-lewiner', 'mc']) {
    await open(`#view=volume&volume=Bucky_32x32x32_uint8.nrrd&iso=100&method=${method}`, (r) => r?.startsWith('volume Bucky'));
    assert.deepEqual(await volumeCounts(), cliCounts(cliExtract(BUCKY, 100, method)), method);
  }
  const stats = await pixels('#volume-viewer canvas', 'volume-bucky-3d.png');
  assert.ok(stats.ink > 0.03 && stats.colours > 20, `3D view not blank: ${JSON.stringify(stats)}`);
});

test('aneurism at iso 80.5 with cmc33: in under a second, the CLI\'s counts', { skip: !fs.existsSync(ANEURISM) && 'no ../shared/data/volumes' }, async () => {
  await open('#view=volume&volume=aneurism_256x256x256_uint8.nrrd&iso=80.5&method=cmc33', (r) => r?.startsWith('volume aneurism'));
  const ms = Number(await text('#volume-ms'));
  assert.ok(ms < 1000, `${ms} ms`);
  assert.deepEqual(await volumeCounts(), cliCounts(cliExtract(ANEURISM, 80.5, 'cmc33')));
  assert.match(await text('#volume-verdict'), /has the topology of the trilinear level set/);
  await screenshot(page, { path: path.join(SHOTS, 'volume-aneurism.png'), fullPage: true });
  const stats = await pixels('#volume-viewer canvas', 'volume-aneurism-3d.png');
  assert.ok(stats.ink > 0.03, `3D view not blank: ${JSON.stringify(stats)}`);
  console.log(`# aneurism 80.5 cmc33 in the page: ${ms} ms`);
});

test('a volume dropped on the page (file input) is read and extracted', async () => {
  await open('#view=volume', (r) => r === 'volume');
  const input = await page.$('#volume-file');
  await input.uploadFile(BUCKY);
  await page.waitForFunction(() => document.body.dataset.ready?.startsWith('volume file:Bucky'));
  const iso = Number(await page.$eval('#volume-iso', (e) => e.value));
  assert.deepEqual(await volumeCounts(), cliCounts(cliExtract(BUCKY, iso, 'cmc33')));
});

test('a NIfTI, a .npy and a .vti dropped on the page are read in their frame and extracted; a TIFF gets a message', async () => {
  // the fuzz corpus's seeds: one byte of the fuzz target's options, then the file
  const corpus = (f) => {
    const file = path.join(fixture.dir, path.basename(f));
    fs.writeFileSync(file, fs.readFileSync(path.join(ROOT, 'fuzz/corpus', f)).subarray(1));
    return file;
  };
  for (const [name, frame] of [['nifti/n1_gz.nii.gz', /frame: RAS, from (sform|qform)/], ['nifti/n2_sform.nii', /frame: RAS, from sform/],
    ['npy/array_1_f8_F.npy', /values/], ['vti/image_4_appended_zlib.vti', /frame: from Origin, Spacing/]]) {
    await open('#view=volume', (r) => r === 'volume');
    await (await page.$('#volume-file')).uploadFile(corpus(name));
    const base = path.basename(name);
    await page.waitForFunction((b) => document.body.dataset.ready?.startsWith(`volume file:${b}`) || document.body.dataset.ready === 'volume error', {}, base);
    assert.equal(await text('#volume-error'), '', name);
    assert.match(await text('#volume-about'), frame, name);
    const iso = Number(await page.$eval('#volume-iso', (e) => e.value));
    assert.deepEqual(await volumeCounts(), cliCounts(cliExtract(corpus(name), iso, 'cmc33')), name);
  }
  await open('#view=volume', (r) => r === 'volume');
  await (await page.$('#volume-file')).uploadFile(corpus('tiff/uint8.tif'));
  await page.waitForFunction(() => document.body.dataset.ready === 'volume error');
  assert.match(await text('#volume-error'), /^uint8\.tif: a TIFF file, which this page cannot read: its WebAssembly build has no TIFF reader/);
});

test('a failed file load clears the previous volume\'s description, histogram, counts and mesh', async () => {
  await open('#view=volume&volume=Bucky_32x32x32_uint8.nrrd&iso=100', (r) => r?.startsWith('volume Bucky'));
  assert.match(await text('#volume-about'), /^Bucky/);
  const broken = path.join(fixture.dir, 'broken.nrrd');
  fs.writeFileSync(broken, 'NRRD0004\ntype: float\ndimension: 3\nsizes: 4 4\nencoding: raw\n\n');
  await (await page.$('#volume-file')).uploadFile(broken);
  await page.waitForFunction(() => document.body.dataset.ready === 'volume error');
  assert.match(await text('#volume-error'), /^broken\.nrrd: ./);
  assert.equal(await text('#volume-about'), '');
  assert.equal(await page.$eval('#volume-histogram', (e) => e.children.length), 0);
  assert.equal(await text('#volume-result'), '');
  const stats = await pixels('#volume-viewer canvas', 'volume-failed-3d.png');
  assert.ok(stats.ink < 0.01, `no mesh left on screen: ${JSON.stringify(stats)}`);
  // and a bundled volume that is not there (chromium logs the 404 as a console error, which is not the page's)
  const before = problems.length;
  await open('#view=volume&volume=nothing.nrrd', (r) => r === 'volume error');
  assert.match(await text('#volume-error'), /^volumes\/nothing\.nrrd: 404 .*one of the bundled volumes/);
  problems.push(...problems.splice(before).filter((p) => !/status of 404/.test(p)));
});

test('Fig. 12: the link opens the aneurism at iso 78, mc33-lewiner beside cmc33, zoomed as the docs\' figure', { skip: !fs.existsSync(ANEURISM) && 'no ../shared/data/volumes' }, async () => {
  const fig12 = JSON.parse(fs.readFileSync(path.join(ROOT, 'docs/figures/fig12_render.json'), 'utf8'));
  assert.equal(fig12.iso, 78);
  await open('#view=volume', (r) => r === 'volume');
  const href = await page.$eval('#volume-fig12', (a) => a.getAttribute('href'));
  await open(href, (r) => r?.startsWith('volume aneurism'));
  assert.equal(await page.evaluate(() => document.body.dataset.ready), 'volume aneurism_256x256x256_uint8.nrrd 78 mc33-lewiner cmc33');
  const columns = await page.evaluate(() => [...document.querySelectorAll('#volume-topology th')].map((th) => th.textContent));
  assert.deepEqual(columns, ['', 'mc33-lewiner', 'cmc33', 'trilinear field']);
  // the components and triangles of docs/figures/fig12_render.json (the docs' figure, made by the CLI)
  const b0 = await page.evaluate(() => [...document.querySelectorAll('#volume-topology tr[data-key=b0] td')].slice(1, 3).map((td) => Number(td.textContent)));
  assert.deepEqual(b0, [fig12.methods['mc33-lewiner'].components, fig12.methods.cmc33.components]);
  assert.equal(Number(await text('#volume-triangles')), fig12.methods['mc33-lewiner'].triangles);
  // the docs' zoom: both cameras look at the piece mc33-lewiner cuts off
  const cameras = await page.evaluate(() => [...document.querySelectorAll('#volume-viewers canvas')].length);
  assert.equal(cameras, 2);
  const left = await pixels('#volume-viewer canvas', 'volume-fig12-mc33-lewiner.png');
  const right = await pixels('#volume-viewer-2 canvas', 'volume-fig12-cmc33.png');
  assert.ok(left.yellow > 0.05 && right.yellow > 0.05, `the main vessel shows: ${JSON.stringify({ left, right })}`);
  // the branch mc33-lewiner cuts off (purple) is part of cmc33's main vessel (yellow)
  assert.ok(left.purple > right.purple + 0.005, `more purple for mc33-lewiner: ${JSON.stringify({ left, right })}`);
  await screenshot(page, { path: path.join(SHOTS, 'volume-fig12.png'), fullPage: true });
});

test('the figures plot the sweep data\'s numbers; hover shows them; a click extracts that mesh', async () => {
  const { sweep, name } = fixture;
  await open(`#view=figures&data=fixture/${name}`, (r) => r?.startsWith('figures '));
  const { isos, row, plotted } = await checkPlots(sweep);
  assert.ok([...plotted.fig13vtk.slice(1), ...plotted.fig13mc33.slice(1)].flat().some((d) => d !== 0), 'the methods differ somewhere on this sweep');

  const k = 3;
  const at = await page.evaluate((iso) => {
    const u = window.cmc33Page.figures.fig14;
    const rect = u.over.getBoundingClientRect();
    return { x: rect.left + u.valToPos(iso, 'x'), y: rect.top + rect.height / 2 };
  }, isos[k]);
  await page.mouse.move(at.x, at.y);
  await page.waitForFunction((iso) => document.querySelector('#figure-hover')?.textContent.includes(`iso ${iso}`), {}, isos[k]);
  const hovered = await page.$$eval('#figure-hover-table tr[data-method]', (trs) => trs.map((tr) => [tr.dataset.method, Number(tr.children[1].textContent), Number(tr.children[4].textContent)]));
  assert.deepEqual(hovered, sweep.methods.map((m) => [m, row(isos[k], m).b0, row(isos[k], m).triangles]));
  await screenshot(page, { path: path.join(SHOTS, 'figures.png'), fullPage: true });

  await page.mouse.click(at.x, at.y);
  await page.waitForFunction(() => document.querySelector('#figures-picked-text'), { timeout: 30000 });
  assert.match(await text('#figures-picked-text'), new RegExp(`^iso ${isos[k]}, cmc33: ${row(isos[k], 'cmc33').triangles} triangles, b0 ${row(isos[k], 'cmc33').b0},`));
  assert.match(page.url(), new RegExp(`pick=${isos[k]}`));
  const stats = await pixels('#figures-viewer canvas', 'figures-3d.png');
  assert.ok(stats.ink > 0.02, `3D view not blank: ${JSON.stringify(stats)}`);
});

/** The plots' data of the figures view must be the sweep file's numbers: Fig. 13 as two plots (mc; the MC33 methods). */
async function checkPlots(sweep) {
  const plotted = await page.evaluate(() => {
    const f = window.cmc33Page.figures;
    return { fig13vtk: f.fig13vtk?.data ?? null, fig13mc33: f.fig13mc33?.data ?? null, fig14: f.fig14.data,
      labels13vtk: f.fig13vtk?.series.slice(1).map((s) => s.label) ?? [], labels13mc33: f.fig13mc33?.series.slice(1).map((s) => s.label) ?? [] };
  });
  const isos = [...new Set(sweep.rows.map((r) => r.iso))].sort((a, b) => a - b);
  const row = (iso, m) => sweep.rows.find((r) => r.iso === iso && r.method === m);
  const value = (r, f) => (r ? f(r) : null);
  const extra = (m) => isos.map((v) => (row(v, m) && row(v, 'cmc33') ? row(v, m).b0 - row(v, 'cmc33').b0 : null));
  if (sweep.methods.includes('cmc33')) {
    const vtk = sweep.methods.filter((m) => m === 'mc');
    const mc33 = sweep.methods.filter((m) => m !== 'mc' && m !== 'cmc33');
    assert.deepEqual(plotted.fig13vtk, vtk.length ? [isos, ...vtk.map(extra)] : null);
    assert.deepEqual(plotted.fig13mc33, mc33.length ? [isos, ...mc33.map(extra)] : null);
    assert.deepEqual(plotted.labels13mc33, mc33.map((m) => `${m} − cmc33`));
  }
  assert.deepEqual(plotted.fig14, [isos, ...sweep.methods.map((m) => isos.map((v) => value(row(v, m), (r) => r.non_manifold_edges)))]);
  return { isos, row, plotted };
}

test('every data file the build ships opens in the figures view, each of its sweeps with its own numbers', async () => {
  const dir = path.join(WEB, 'figures');
  const list = JSON.parse(fs.readFileSync(path.join(dir, 'index.json'), 'utf8'));
  const shipped = fs.readdirSync(dir).filter((f) => f.endsWith('.json') && f !== 'index.json').map((f) => `figures/${f}`).sort();
  assert.deepEqual(list.map((e) => e.file).sort(), shipped, 'every shipped file is listed, and only those');
  assert.ok(shipped.includes('figures/fig14_nonmanifold.json'), 'the Fig. 14 data of docs/figures is shipped');
  const before = problems.length;
  for (const file of shipped) {
    const json = JSON.parse(fs.readFileSync(path.join(WEB, file), 'utf8'));
    const sweeps = json.volumes ? json.volumes.map((v) => v.sweep) : [json];
    for (const sweep of sweeps) {
      const part = path.basename(sweep.volume);
      const hash = `#view=figures&data=${file}${json.volumes ? `&part=${part}` : ''}`;
      await open(hash, (r) => r?.startsWith('figures '));
      assert.equal(await text('#figures-error'), '', hash);
      assert.match(await text('#figures-about'), new RegExp(`^${part.replace(/\./g, '\\.')}: `));
      await checkPlots(sweep);
    }
  }
  // the link of the issue, without part=: the file's first sweep
  await open('#view=figures&data=figures/fig14_nonmanifold.json', (r) => r?.startsWith('figures '));
  assert.match(await text('#figures-about'), /^Cranium_256x256x108_int16\.nrrd: /);
  assert.deepEqual(problems.slice(before), []);
});

test('Fig. 13 is two plots: mc against cmc33, and MC33 against cmc33 on a scale of its own', async () => {
  const file = 'figures/fig13_components.json';
  const sweep = JSON.parse(fs.readFileSync(path.join(WEB, file), 'utf8'));
  await open(`#view=figures&data=${file}`, (r) => r?.startsWith('figures '));
  const { plotted } = await checkPlots(sweep);
  assert.deepEqual(plotted.labels13vtk, ['mc − cmc33']);
  const scales = await page.evaluate(() => ({ vtk: window.cmc33Page.figures.fig13vtk.scales.y, mc33: window.cmc33Page.figures.fig13mc33.scales.y }));
  const mcMax = Math.max(...plotted.fig13vtk[1]), mc33Max = Math.max(...plotted.fig13mc33.slice(1).flat());
  assert.ok(mcMax > 1000, `mc finds thousands more components somewhere (${mcMax})`);
  // the MC33 plot's axis spans the MC33 differences, not mc's thousands
  assert.ok(scales.mc33.max >= mc33Max && scales.mc33.max < 2 * mc33Max + 10, JSON.stringify({ scales, mc33Max }));
  assert.ok(scales.vtk.max >= mcMax, JSON.stringify(scales));
  await screenshot(page, { path: path.join(SHOTS, 'figures-fig13.png'), fullPage: true });
});

test('a failed sweep load clears the previous sweep\'s description and plots', async () => {
  const { name } = fixture;
  await open(`#view=figures&data=fixture/${name}`, (r) => r?.startsWith('figures '));
  assert.notEqual(await text('#figures-about'), '');
  const before = problems.length;
  await page.evaluate(() => {
    const select = document.querySelector('#figures-select');
    select.append(new Option('missing', 'figures/missing.json'));
    select.value = 'figures/missing.json';
    select.dispatchEvent(new Event('change'));
  });
  await page.waitForFunction(() => document.body.dataset.ready === 'figures error figures/missing.json');
  assert.match(await text('#figures-error'), /^figures\/missing\.json: 404 .*a sweep data file/);
  assert.equal(await text('#figures-about'), '');
  assert.equal(await page.$$eval('#fig13-vtk canvas, #fig13-mc33 canvas, #fig14 canvas', (c) => c.length), 0);
  assert.equal(await page.evaluate(() => window.cmc33Page.figures), null);
  // a link to a file that is not there: said at the top too, and the address is kept
  const link = '#view=figures&data=figures/nothing.json';
  await open(link, (r) => r?.startsWith('figures error'));
  assert.match(await text('#address-problems'), /data=figures\/nothing\.json: 404 .*a sweep data file of this build/);
  assert.equal(await hashNow(), link);
  // the 404s are the point here: chromium logs them as console errors, which are not the page's
  const others = problems.splice(before).filter((p) => !/status of 404/.test(p));
  problems.push(...others);
});

test('at phone width (390 px) no view overflows sideways', async () => {
  await page.setViewport({ width: 390, height: 844 });
  try {
    const views = [
      ['cell', `#cell=${[...APPENDIX_A, 0.5].join(',')}`], // with the banner of a wrong address too
      ['tunnels', '#view=tunnels'],
      ['volume', '#view=volume&volume=Bucky_32x32x32_uint8.nrrd&iso=100&compare=mc'],
      ['figures', '#view=figures&data=figures/fig13_components.json'],
    ];
    for (const [name, hash] of views) {
      await open(hash, (r) => Boolean(r) && r !== 'volume');
      const widths = await page.evaluate(() => {
        const wide = [...document.querySelectorAll('body *')].filter((e) => e.getBoundingClientRect().right > innerWidth + 0.5 && e.offsetParent !== null)
          .map((e) => `${e.tagName.toLowerCase()}${e.id ? `#${e.id}` : ''}.${e.className}`);
        return { scroll: document.documentElement.scrollWidth, inner: innerWidth, wide: wide.slice(0, 5) };
      });
      assert.ok(widths.scroll <= widths.inner, `${name}: the page is ${widths.scroll} px wide in a ${widths.inner} px screen: ${widths.wide.join(', ')}`);
      await screenshot(page, { path: path.join(SHOTS, `phone-${name}.png`), fullPage: true });
    }
  } finally {
    await page.setViewport({ width: 1400, height: 1100 });
  }
});

test('opened as a file (file://), the page says it needs a server and gives the command', async () => {
  const local = await browser.newPage(); // its console errors (the refused module) are expected
  try {
    await local.goto(`file://${path.join(WEB, 'index.html')}#view=tunnels`, { waitUntil: 'load' });
    await local.waitForSelector('#not-served', { timeout: 10000 });
    const said = await local.$eval('#not-served', (e) => e.textContent);
    assert.match(said, /needs a web server/);
    assert.ok(said.includes(`python3 -m http.server -d '${WEB}' 8033`), said);
    assert.ok(said.includes('http://localhost:8033/#view=tunnels'), said);
    await screenshot(local, { path: path.join(SHOTS, 'file-url.png') });
  } finally {
    await local.close();
  }
});

test('no console error or uncaught exception on any view', async () => {
  for (const hash of ['#view=cell', '#view=tunnels', '#view=volume', '#view=figures']) await open(hash);
  assert.deepEqual(problems, []);
});
