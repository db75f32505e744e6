// The sweep data files the figures view reads (docs/figures/*.json): one sweep as `cmc33 sweep`
// writes it ({volume, dims, type, cells, methods, rows: [...]}) or several ({volumes: [{sweep, ...}]},
// as scripts/paper/fig14_nonmanifold.py writes). Shared by the page and tools/index.mjs, which
// copies into the build only the files this accepts.

const ROW_FIELDS = ['iso', 'method', 'triangles', 'b0', 'non_manifold_edges'];

/** What is wrong with `sweep` as one sweep, or null. */
function sweepProblem(sweep) {
  if (!sweep || typeof sweep !== 'object') return 'not an object';
  if (typeof sweep.volume !== 'string') return 'no "volume" (the volume file\'s name)';
  if (!Array.isArray(sweep.dims) || sweep.dims.length !== 3) return 'no "dims" [nx, ny, nz]';
  if (!Array.isArray(sweep.methods)) return 'no "methods" list';
  if (!Array.isArray(sweep.rows) || sweep.rows.length === 0) return 'no "rows"';
  const bad = sweep.rows.findIndex((r) => !r || ROW_FIELDS.some((f) => r[f] === undefined));
  if (bad >= 0) return `row ${bad} lacks one of ${ROW_FIELDS.join(', ')}`;
  return null;
}

/**
 * The sweeps of a data file, [{name, label, sweep}] (name: the volume's file name), or an Error
 * naming the file, what is wrong and what was expected.
 */
export function sweepsOf(json, file) {
  const expected = 'a sweep data file was expected: {volume, dims, methods, rows: [{iso, method, b0, non_manifold_edges, ...}]} as `cmc33 sweep` writes, or {volumes: [{sweep}, ...]}';
  const entry = (sweep) => {
    const name = sweep.volume.split('/').pop();
    return { name, label: `${name} (${sweep.rows.length} rows)`, sweep };
  };
  if (json && Array.isArray(json.rows)) {
    const problem = sweepProblem(json);
    if (problem) throw new Error(`${file}: ${problem}; ${expected}`);
    return [entry(json)];
  }
  if (json && Array.isArray(json.volumes)) {
    if (json.volumes.length === 0) throw new Error(`${file}: "volumes" is empty; ${expected}`);
    return json.volumes.map((v, k) => {
      const problem = sweepProblem(v?.sweep);
      if (problem) throw new Error(`${file}: volumes[${k}].sweep: ${problem}; ${expected}`);
      return entry(v.sweep);
    });
  }
  const keys = json && typeof json === 'object' ? Object.keys(json).slice(0, 6).join(', ') : typeof json;
  throw new Error(`${file}: neither "rows" nor "volumes" (it has ${keys}); ${expected}`);
}
