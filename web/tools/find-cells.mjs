// Finds the cells of Figs. 8 and 9 the page opens with (web/src/presets.js records them):
//   node --no-experimental-fetch web/tools/find-cells.mjs build/web
// with the module built (scripts/build-web.sh). Everything is classified by the library.
import { loadNode } from '../test/load-node.mjs';
import { findCase6Cell, findTunnelField } from '../src/search.js';

const cmc33 = await loadNode(process.argv[2] ?? 'build/web');
const fig9 = findCase6Cell(cmc33, 9);
console.log('Fig. 9 case 6 cell:', fig9 && Array.from(fig9.values).join(','), fig9 && `(seed ${fig9.seed}, draw ${fig9.draws})`);
const fig8 = findTunnelField(cmc33, 8);
console.log('Fig. 8 field: seed', fig8?.seed, JSON.stringify(fig8?.pairs));
