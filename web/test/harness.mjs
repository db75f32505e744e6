// For the browser tests: a plain static file server on 127.0.0.1 (the page needs nothing more), and
// Debian's chromium driven by puppeteer-core, headless, with WebGL through SwiftShader (no GPU).
import http from 'node:http';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import puppeteer from 'puppeteer-core';

const TYPES = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript', '.css': 'text/css', '.json': 'application/json', '.wasm': 'application/wasm', '.map': 'application/json', '.png': 'image/png' };

/** Serves `root` (and `mounts`: URL prefix -> folder) read-only; resolves to {url, close}. */
export function serve(root, mounts = {}) {
  const server = http.createServer((req, res) => {
    const url = decodeURIComponent(new URL(req.url, 'http://x').pathname);
    let base = root, rel = url;
    for (const [prefix, dir] of Object.entries(mounts)) {
      if (url.startsWith(prefix)) {
        base = dir;
        rel = url.slice(prefix.length - 1);
      }
    }
    const file = path.join(base, path.normalize(rel === '/' ? '/index.html' : rel));
    if (!file.startsWith(path.resolve(base)) || !fs.existsSync(file) || fs.statSync(file).isDirectory()) {
      res.writeHead(404).end('not found');
      return;
    }
    res.writeHead(200, { 'content-type': TYPES[path.extname(file)] ?? 'application/octet-stream' });
    fs.createReadStream(file).pipe(res);
  });
  return new Promise((resolve) => {
    server.listen(0, '127.0.0.1', () => resolve({ url: `http://127.0.0.1:${server.address().port}/`, close: () => new Promise((r) => server.close(r)) }));
  });
}

export const CHROMIUM = process.env.CMC33_CHROMIUM ?? '/usr/bin/chromium';

/** Headless chromium in a fresh profile; the flags keep it off the network it cannot reach. */
export async function launch() {
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'cmc33-chromium-'));
  const browser = await puppeteer.launch({
    executablePath: CHROMIUM,
    headless: true,
    userDataDir: profile,
    args: [
      '--headless=new', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync',
      '--disable-dev-shm-usage', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
      '--window-size=1400,1100',
    ],
    defaultViewport: { width: 1400, height: 1100 },
    // a CDP call that has not answered in 90 s has stalled (the longest the tests make, a wait for a
    // view to be ready, gives up at 60 s); puppeteer's default would wait 180 s
    protocolTimeout: 90000,
  });
  const close = browser.close.bind(browser);
  browser.close = async () => {
    await close();
    fs.rmSync(profile, { recursive: true, force: true });
  };
  return browser;
}
