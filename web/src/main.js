// The page: loads the module, shows the view the URL fragment names, keeps the fragment current.
// What is wrong in an address (an unknown view, a cell of 7 values, ...) is said at the top of the
// view, and the address is left as the reader gave it until they change something on the page.
import 'uplot/dist/uPlot.min.css';
import './style.css';
import { loadModule } from './cmc33.js';
import { readState, writeState, el } from './state.js';
import { cellView } from './views/cell.js';
import { tunnelsView } from './views/tunnels.js';
import { volumeView } from './views/volume.js';
import { figuresView } from './views/figures.js';

const VIEWS = { cell: cellView, tunnels: tunnelsView, volume: volumeView, figures: figuresView };

window.cmc33Page = { ready: false };
let current = null;
let own = ''; // the fragment this page wrote last: not a navigation

function show(cmc33) {
  const state = readState();
  const banner = el('div', { id: 'address-problems', class: 'error banner', role: 'alert', hidden: true });
  const problems = [];
  const report = (message) => {
    problems.push(message);
    banner.replaceChildren(el('b', {}, 'This address is not what the page expected; it is kept as it is until you change something below.'),
      el('ul', {}, problems.map((p) => el('li', {}, p))));
    banner.hidden = false;
  };
  let view = state.view;
  if (!VIEWS[view]) {
    report(`view=${view}: there is no such view; the views are ${Object.keys(VIEWS).join(', ')}. The cell explorer is shown.`);
    view = 'cell';
  }
  for (const a of document.querySelectorAll('nav a')) a.classList.toggle('active', a.dataset.view === view);
  current?.destroy();
  const main = document.getElementById('main');
  main.replaceChildren(banner);
  const body = el('div', { id: 'view' });
  main.append(body);
  delete document.body.dataset.ready;
  // the reader acted on the page: from now on the address follows the page's state again
  let acted = false;
  const act = () => {
    acted = true;
  };
  for (const type of ['input', 'change', 'click']) body.addEventListener(type, act, { capture: true });
  current = VIEWS[view](body, cmc33, state, (next) => {
    if (problems.length && !acted) return;
    writeState(next);
    own = location.hash;
    if (problems.length) {
      problems.length = 0;
      banner.hidden = true;
    }
  }, report);
}

async function start() {
  let cmc33;
  try {
    cmc33 = await loadModule();
  } catch (e) {
    if (location.protocol === 'file:') throw e; // index.html already says the page needs a server
    document.getElementById('main').textContent = `The WebAssembly module did not load: ${e.message ?? e}`;
    throw e;
  }
  window.cmc33Page.module = cmc33;
  document.getElementById('version').textContent = `cmc33 ${cmc33.version()} (WebAssembly)`;
  window.addEventListener('hashchange', () => {
    if (location.hash !== own) show(cmc33);
  });
  show(cmc33);
  window.cmc33Page.ready = true;
}

start();
