// The page's state lives in the URL fragment (#view=cell&cell=...&method=...): a link opens a
// view exactly. A fragment with cell= and no view= opens the cell explorer, as the README's links do.

export function readState() {
  const params = new URLSearchParams(location.hash.replace(/^#/, ''));
  const state = Object.fromEntries(params.entries());
  if (!state.view) state.view = state.cell ? 'cell' : state.volume ? 'volume' : state.data ? 'figures' : 'cell';
  return state;
}

/** Replaces the fragment with `state` (no history entry per slider step, no re-render). */
export function writeState(state) {
  const params = new URLSearchParams();
  for (const [k, v] of Object.entries(state)) if (v !== undefined && v !== null && v !== '') params.set(k, String(v));
  const hash = '#' + params.toString().replaceAll('%2C', ',');
  if (hash !== location.hash) history.replaceState(null, '', hash);
}

/** A number as the page shows it: 4 significant digits, NaN as an em dash. */
export function fmt(x, digits = 4) {
  if (x === undefined || x === null || Number.isNaN(x)) return '—';
  if (!Number.isFinite(x)) return x > 0 ? '∞' : '−∞';
  if (Number.isInteger(x) && Math.abs(x) < 1e9) return String(x);
  return Number(x.toPrecision(digits)).toString();
}

/** An element from a tag, attributes and children (strings or nodes). */
export function el(tag, attrs = {}, ...children) {
  const node = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === 'class') node.className = v;
    else if (k.startsWith('on')) node.addEventListener(k.slice(2), v);
    else if (k === 'dataset') Object.assign(node.dataset, v);
    else if (v !== undefined && v !== null && v !== false) node.setAttribute(k, v === true ? '' : v);
  }
  for (const c of children.flat()) if (c !== undefined && c !== null) node.append(c);
  return node;
}

/**
 * A number the reader typed (or the address holds): decimal or exponent notation, a leading + or
 * the typographic minus (−, as the paper and this page print it) allowed. Returns {value} or
 * {error}, the error naming what was read and what was expected.
 */
export function parseNumber(text) {
  const raw = String(text ?? '');
  const s = raw.trim().replace(/^\u2212/, '-');
  if (s === '') return { error: 'is empty; a number was expected, e.g. −0.2384' };
  if (!/^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$/.test(s)) return { error: `“${raw}” is not a number; a decimal such as −0.2384 or 2.5e-3 was expected` };
  const value = Number(s);
  if (!Number.isFinite(value)) return { error: `“${raw}” is beyond the largest double (about 1.8e308); a finite number was expected` };
  return { value };
}
