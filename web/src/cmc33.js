// The WebAssembly module (cmc33.mjs + cmc33.wasm beside the page) and the few conversions the
// page needs around it. The module's own API is in web/wasm/bindings.cpp; this file adds no
// computation, only the copies that leave its memory: a Mesh's typed arrays are views of the
// module's memory, which a later allocation may move, so they are copied once here and the
// Mesh freed.
import createCmc33 from './cmc33.mjs';

let modulePromise = null;
export function loadModule() {
  modulePromise ??= createCmc33();
  return modulePromise;
}

/** Copies a Mesh out of the module's memory and frees it: {positions, triangles, topology, ...}. */
export function takeMesh(mesh, { topology = true, components = false, nonManifold = false } = {}) {
  try {
    const out = {
      positions: mesh.positions().slice(),
      triangles: mesh.triangles().slice(),
      vertexCount: mesh.vertexCount(),
      triangleCount: mesh.triangleCount(),
    };
    if (topology) out.topology = mesh.topology();
    if (components) out.components = mesh.components().slice();
    if (nonManifold) out.nonManifoldEdges = mesh.nonManifoldEdges().slice();
    return out;
  } finally {
    mesh.delete();
  }
}
