// The page in a real browser (Debian's chromium, headless, driven by puppeteer-core), served from
// build/web by a plain static server: what a reader sees must be the library's answers. Screenshots
// of every view go to build/web-screenshots/ (CI keeps them).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { serve, launch } from './harness.mjs';
import { WEB, ROOT, SHARED, BUCKY, cliExtract, cliCounts, makeSweepFixture } from './common.mjs';
import { SUBCASE_CELLS, APPENDIX_A } from '../src/presets.js';

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
    let ink = 0;
    const colours = new Set();
    for (let i = 0; i < data.length; i += 4) {
      if (Math.max(255 - data[i], 255 - data[i + 1], 255 - data[i + 2]) > 40) ++ink;
      colours.add((data[i] >> 4) << 8 | (data[i + 1] >> 4) << 4 | (data[i + 2] >> 4));
    }
    return { ink: ink / (data.length / 4), colours: colours.size };
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

test('neighbouring tunnels: every method, against the field topology', async () => {
  await open('#view=tunnels', (r) => r?.startsWith('tunnels '));
  const rows = await page.$$eval('#tunnels-table tr[data-method]', (trs) => trs.map((tr) => [tr.dataset.method, ...[...tr.children].map((td) => td.textContent)]));
  const methods = await page.evaluate(() => window.cmc33Page.module.methods());
  assert.deepEqual(rows.map((r) => r[0]), methods);
  assert.equal(rows.find((r) => r[0] === 'cmc33').at(-1), 'equal');
  assert.equal(rows.find((r) => r[0] === 'cmc33')[4], '0'); // no non-manifold edge
  assert.match(await text('#tunnels-pair'), /tunnels in both/);
  const stats = await pixels('#tunnels-viewer canvas', 'tunnels-3d.png');
  assert.ok(stats.ink > 0.02, `3D view not blank: ${JSON.stringify(stats)}`);
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

test('the figures plot the sweep data\'s numbers; hover shows them; a click extracts that mesh', async () => {
  const { sweep, name } = fixture;
  await open(`#view=figures&data=fixture/${name}`, (r) => r?.startsWith('figures '));
  const { isos, row, plotted } = await checkPlots(sweep);
  assert.ok(plotted.fig13.slice(1).flat().some((d) => d !== 0), 'the methods differ somewhere on this sweep');

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

/** The plots' data of the figures view must be the sweep file's numbers. */
async function checkPlots(sweep) {
  const plotted = await page.evaluate(() => ({ fig13: window.cmc33Page.figures.fig13?.data ?? null, fig14: window.cmc33Page.figures.fig14.data }));
  const isos = [...new Set(sweep.rows.map((r) => r.iso))].sort((a, b) => a - b);
  const row = (iso, m) => sweep.rows.find((r) => r.iso === iso && r.method === m);
  const value = (r, f) => (r ? f(r) : null);
  if (sweep.methods.includes('cmc33')) {
    assert.deepEqual(plotted.fig13, [isos, ...sweep.methods.filter((m) => m !== 'cmc33').map((m) => isos.map((v) => (row(v, m) && row(v, 'cmc33') ? row(v, m).b0 - row(v, 'cmc33').b0 : null)))]);
  }
  assert.deepEqual(plotted.fig14, [isos, ...sweep.methods.map((m) => isos.map((v) => value(row(v, m), (r) => r.non_manifold_edges)))]);
  return { isos, row, plotted };
}

test('every sweep data file of the build (docs/figures/*.json) is plotted with its own numbers', async (t) => {
  const list = JSON.parse(fs.readFileSync(path.join(WEB, 'figures/index.json'), 'utf8'));
  if (list.length === 0) t.skip('no docs/figures/*.json in this build yet (the sweep of the paper branch writes them)');
  for (const entry of list) {
    const sweep = JSON.parse(fs.readFileSync(path.join(WEB, entry.file), 'utf8'));
    await open(`#view=figures&data=${entry.file}`, (r) => r?.startsWith('figures '));
    await checkPlots(sweep);
  }
});

test('no console error or uncaught exception on any view', async () => {
  for (const hash of ['#view=cell', '#view=tunnels', '#view=volume', '#view=figures']) await open(hash);
  assert.deepEqual(problems, []);
});
