// Writes OUT/volumes/index.json and OUT/figures/index.json, the lists the page offers, reading each
// bundled volume with the library itself (its dims and type), and copies into OUT/figures/ the
// sweep data files of FIGURES (docs/figures/*.json) that the figures view opens, and only those:
// every data file the build ships opens in the page (src/sweeps.js decides).
//   node --no-experimental-fetch web/tools/index.mjs build/web [docs/figures]
import fs from 'node:fs';
import path from 'node:path';
import { loadNode } from '../test/load-node.mjs';
import { sweepsOf } from '../src/sweeps.js';

const out = path.resolve(process.argv[2] ?? 'build/web');
const source = process.argv[3] ? path.resolve(process.argv[3]) : null;
const cmc33 = await loadNode(out);

const volumes = [];
const vdir = path.join(out, 'volumes');
for (const name of fs.existsSync(vdir) ? fs.readdirSync(vdir).sort() : []) {
  if (!/\.(nrrd|mha|vtk)$/i.test(name)) continue; // one-file volumes only
  const v = cmc33.Volume.read(fs.readFileSync(path.join(vdir, name)), name, {});
  volumes.push({ name, dims: v.dims(), type: v.type(), bytes: fs.statSync(path.join(vdir, name)).size });
  v.delete();
}
volumes.sort((a, b) => a.bytes - b.bytes);
fs.writeFileSync(path.join(vdir, 'index.json'), JSON.stringify(volumes, null, 1));

const figures = [];
const fdir = path.join(out, 'figures');
const from = source ?? fdir;
for (const name of fs.existsSync(from) ? fs.readdirSync(from).sort() : []) {
  if (!name.endsWith('.json') || name === 'index.json') continue;
  let sweeps;
  try {
    sweeps = sweepsOf(JSON.parse(fs.readFileSync(path.join(from, name), 'utf8')), name);
  } catch (e) {
    console.log(`index: ${name} is not shipped: ${e.message}`);
    if (!source) fs.rmSync(path.join(fdir, name));
    continue;
  }
  if (source) {
    fs.mkdirSync(fdir, { recursive: true });
    fs.copyFileSync(path.join(from, name), path.join(fdir, name));
  }
  const label = sweeps.length === 1 ? sweeps[0].label : `${name}: ${sweeps.map((s) => s.name).join(', ')}`;
  figures.push({ file: `figures/${name}`, label, volume: sweeps[0].name, rows: sweeps.reduce((n, s) => n + s.sweep.rows.length, 0), volumes: sweeps.map((s) => s.name), methods: sweeps[0].sweep.methods });
}
if (figures.length || fs.existsSync(fdir)) {
  fs.mkdirSync(fdir, { recursive: true });
  fs.writeFileSync(path.join(fdir, 'index.json'), JSON.stringify(figures, null, 1));
}
console.log(`index: ${volumes.length} volumes, ${figures.length} sweep data files`);
