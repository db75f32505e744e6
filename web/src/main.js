// The page: loads the module, shows the view the URL fragment names, keeps the fragment current.
import 'uplot/dist/uPlot.min.css';
import './style.css';
import { loadModule } from './cmc33.js';
import { readState, writeState } from './state.js';
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
  const view = VIEWS[state.view] ? state.view : 'cell';
  for (const a of document.querySelectorAll('nav a')) a.classList.toggle('active', a.dataset.view === view);
  current?.destroy();
  const main = document.getElementById('main');
  main.replaceChildren();
  delete document.body.dataset.ready;
  current = VIEWS[view](main, cmc33, state, (next) => {
    writeState(next);
    own = location.hash;
  });
}

async function start() {
  let cmc33;
  try {
    cmc33 = await loadModule();
  } catch (e) {
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
