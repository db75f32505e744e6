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
