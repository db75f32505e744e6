// Writes OUT/volumes/index.json and OUT/figures/index.json, the lists the page offers, reading each
// bundled volume with the library itself (its dims and type) and each sweep file's header.
//   node --no-experimental-fetch web/tools/index.mjs build/web
import fs from 'node:fs';
import path from 'node:path';
import { loadNode } from '../test/load-node.mjs';

const out = path.resolve(process.argv[2] ?? 'build/web');
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
for (const name of fs.existsSync(fdir) ? fs.readdirSync(fdir).sort() : []) {
  if (!name.endsWith('.json') || name === 'index.json') continue;
  const sweep = JSON.parse(fs.readFileSync(path.join(fdir, name), 'utf8'));
  if (!Array.isArray(sweep.rows)) continue; // not a sweep data file
  figures.push({ file: `figures/${name}`, volume: path.basename(sweep.volume), rows: sweep.rows.length, methods: sweep.methods });
}
if (figures.length || fs.existsSync(fdir)) {
  fs.mkdirSync(fdir, { recursive: true });
  fs.writeFileSync(path.join(fdir, 'index.json'), JSON.stringify(figures, null, 1));
}
console.log(`index: ${volumes.length} volumes, ${figures.length} sweep data files`);
