// Bundles the page (src/main.js, three, uPlot and the styles) into OUT/app.js and OUT/app.css
// and copies index.html; the module (cmc33.mjs, cmc33.wasm) is built by CMake and copied beside
// them by scripts/build-web.sh. Usage: node build.mjs OUT
import * as esbuild from 'esbuild';
import fs from 'node:fs';
import path from 'node:path';

const out = path.resolve(process.argv[2] ?? '../build/web');
fs.mkdirSync(out, { recursive: true });
await esbuild.build({
  entryPoints: { app: 'src/main.js' },
  bundle: true,
  format: 'esm',
  target: ['chrome100', 'firefox100', 'safari15'],
  minify: true,
  sourcemap: true,
  outdir: out,
  external: ['./cmc33.mjs'],
  logLevel: 'warning',
});
fs.copyFileSync('index.html', path.join(out, 'index.html'));
