// What the tests share: where things are, the native CLI's answers, and the sweep fixture.
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

export const ROOT = fileURLToPath(new URL('../..', import.meta.url));
export const WEB = path.join(ROOT, process.env.CMC33_WEB_OUT ?? 'build/web');
export const CLI = process.env.CMC33_CLI ?? path.join(ROOT, 'build/cli/cmc33');
export const SHARED = path.resolve(ROOT, '../shared/data/volumes');
export const BUCKY = path.join(ROOT, 'data/Bucky_32x32x32_uint8.nrrd');

/** `cmc33 extract FILE --iso ISO --method M --json` of the native CLI, parsed. */
export function cliExtract(file, iso, method) {
  const out = execFileSync(CLI, ['extract', file, '--iso', String(iso), '--method', method, '--json', '--threads', '1', '--quiet'], {
    encoding: 'utf8',
    maxBuffer: 1 << 26,
  });
  return JSON.parse(out);
}

/** The CLI's topology in the page's names (the numbers the page shows). */
export function cliCounts(json) {
  const t = json.topology;
  return {
    vertices: json.vertices,
    triangles: json.triangles,
    euler: t.euler,
    b0: t.betti[0],
    b1: t.betti[1],
    b2: t.betti[2],
    boundaryLoops: t.boundary_loops,
    nonManifoldEdges: t.nonmanifold_edges,
  };
}

/**
 * A sweep data file in the shape `cmc33 sweep` writes (docs/figures/*.json), made from the CLI's
 * extract --json over a few isovalues of `file` with every method; written to a fresh folder.
 * Returns {dir, name, sweep}.
 */
export function makeSweepFixture(file, isos, methods) {
  const rows = [];
  let first = null;
  for (const iso of isos) {
    for (const method of methods) {
      const json = cliExtract(file, iso, method);
      first ??= json;
      const c = cliCounts(json);
      rows.push({
        iso, method, vertices: c.vertices, triangles: c.triangles, euler: c.euler, b0: c.b0, b1: c.b1, b2: c.b2,
        boundary_loops: c.boundaryLoops, non_manifold_edges: c.nonManifoldEdges, expected: null,
      });
    }
  }
  const dims = first.input.dims;
  const sweep = {
    volume: path.relative(ROOT, file), dims, type: first.input.type,
    cells: (dims[0] - 1) * (dims[1] - 1) * (dims[2] - 1), methods, rows,
  };
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'cmc33-sweep-'));
  const name = `${path.basename(file).replace(/\.[^.]+$/, '')}-sweep.json`;
  fs.writeFileSync(path.join(dir, name), JSON.stringify(sweep));
  return { dir, name, sweep };
}
