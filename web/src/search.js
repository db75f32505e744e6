// Random cells and fields, and searches over them that classify with the library itself
// (analyzeCell): nothing here decides a case. Shared by the page (its "random" buttons) and by
// tools/find-cells.mjs, which found the committed presets of Figs. 8 and 9.

/** A seeded generator of uniform numbers in [0, 1) (mulberry32), so that a seed names a field. */
export function generator(seed) {
  let a = seed >>> 0;
  return () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

/** Values in [-1, 1] rounded to 4 decimals, as the paper prints its cells. */
export function randomValues(random, count) {
  const out = new Float64Array(count);
  for (let i = 0; i < count; ++i) out[i] = Math.round((2 * random() - 1) * 1e4) / 1e4;
  return out;
}

/** The subcases in which a cell holds a tunnel. */
export const TUNNEL_SUBCASES = new Set(['4.1.2', '6.1.2', '7.4.2', '10.1.2', '12.1.2', '13.5.2']);

/** The 8 corner values of cell (i, j, k) of an n^3 field (x fastest), in the library's corner order. */
export function cellValues(field, n, i, j, k) {
  const out = new Float64Array(8);
  for (let c = 0; c < 8; ++c) {
    const x = i + (c & 1), y = j + ((c >> 1) & 1), z = k + ((c >> 2) & 1);
    out[c] = field[(z * n + y) * n + x];
  }
  return out;
}

/**
 * Face-adjacent pairs of cells of an n^3 field that both hold a tunnel under `method`, as
 * [{a: [i, j, k], b: [i, j, k], axis, subcases: [s, s]}].
 */
export function neighbouringTunnels(cmc33, field, n, iso, method) {
  const m = n - 1;
  const subcase = new Map();
  const at = (i, j, k) => {
    const key = (k * m + j) * m + i;
    if (!subcase.has(key)) subcase.set(key, cmc33.analyzeCell(cellValues(field, n, i, j, k), iso, method).subcase);
    return subcase.get(key);
  };
  const pairs = [];
  for (let k = 0; k < m; ++k)
    for (let j = 0; j < m; ++j)
      for (let i = 0; i < m; ++i) {
        if (!TUNNEL_SUBCASES.has(at(i, j, k))) continue;
        const next = [[i + 1, j, k], [i, j + 1, k], [i, j, k + 1]];
        next.forEach(([x, y, z], axis) => {
          if (x < m && y < m && z < m && TUNNEL_SUBCASES.has(at(x, y, z))) {
            pairs.push({ a: [i, j, k], b: [x, y, z], axis, subcases: [at(i, j, k), at(x, y, z)] });
          }
        });
      }
  return pairs;
}

/** The first seed from `seed` on whose random 5^3 field two neighbouring cells hold tunnels (cmc33). */
export function findTunnelField(cmc33, seed, limit = 200000) {
  for (let s = seed; s < seed + limit; ++s) {
    const field = randomValues(generator(s), 125);
    const pairs = neighbouringTunnels(cmc33, field, 5, 0, 'cmc33');
    if (pairs.length > 0) return { seed: s, field, pairs };
  }
  return null;
}

/**
 * A case-6 cell of Fig. 9: a tunnel (6.1.2) that mc33-lewiner's height t_alt misses because it
 * falls outside (t1, t2), where F < 0. The first such cell drawn from `seed` on.
 */
export function findCase6Cell(cmc33, seed, limit = 5000000) {
  const random = generator(seed);
  for (let n = 0; n < limit; ++n) {
    const v = randomValues(random, 8);
    const r = cmc33.analyzeCell(v, 0, 'cmc33');
    if (r.subcase !== '6.1.2') continue;
    const legacy = cmc33.analyzeCell(v, 0, 'mc33-lewiner');
    const i = legacy.interior;
    if (legacy.subcase === '6.1.1' && (i.tAlt < i.t1 || i.tAlt > i.t2)) return { seed, draws: n + 1, values: v };
  }
  return null;
}
