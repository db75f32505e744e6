// Loads the built module (cmc33.mjs + cmc33.wasm) under Node, for the tests and tools outside the
// browser. Emscripten 3.1.6's ES module reads its .wasm with fetch and expects CommonJS globals
// under Node: give it the bytes and those globals (and run node with --no-experimental-fetch).
import fs from 'node:fs';
import path from 'node:path';
import { createRequire } from 'node:module';
import { pathToFileURL } from 'node:url';

export async function loadNode(dir) {
  const root = path.resolve(dir);
  globalThis.__dirname ??= root;
  globalThis.require ??= createRequire(import.meta.url);
  const { default: create } = await import(pathToFileURL(path.join(root, 'cmc33.mjs')).href);
  return create({ wasmBinary: fs.readFileSync(path.join(root, 'cmc33.wasm')) });
}
