#pragma once
/// @file topology.hpp
/// Topology of meshes, and the topology a level set of the trilinear interpolant must have.

#include <cstdint>
#include <string>

#include "cmc33/mesh.hpp"
#include "cmc33/volume.hpp"

namespace cmc33 {

/// Combinatorial invariants of a triangle mesh. Vertices no triangle uses are not counted.
/// For a manifold mesh (no non-manifold edges or vertices) b0 - b1 + b2 = euler, so
/// b1 = b0 + b2 - euler; b2 counts components without boundary edges.
struct MeshTopology {
    std::int64_t vertices = 0;  ///< V: vertices used by at least one triangle
    std::int64_t edges = 0;     ///< E: distinct undirected edges
    std::int64_t faces = 0;     ///< F: triangles
    std::int64_t euler = 0;     ///< V - E + F
    std::int64_t components = 0;        ///< b0: connected components (through shared vertices)
    std::int64_t closed_components = 0; ///< b2: components with no boundary edge
    std::int64_t b1 = 0;                ///< b0 + b2 - euler
    std::int64_t boundary_edges = 0;    ///< edges with exactly one triangle
    std::int64_t boundary_loops = 0;    ///< cycles formed by boundary edges
    std::int64_t nonmanifold_edges = 0; ///< edges with more than two triangles
    std::int64_t nonmanifold_vertices = 0; ///< vertices whose triangles form more than one fan
    std::int64_t degenerate_triangles = 0; ///< triangles that repeat a vertex index
    bool closed = false;   ///< no boundary edge (and at least one triangle)
    bool oriented = false; ///< every edge with two triangles is used once in each direction (true without triangles)
};

/// @throws Error{invalid_argument} if an index is not below the vertex count or the triangle array
/// is not a multiple of 3.
/// Cost: O(F) time and about 24 bytes per triangle of working memory.
MeshTopology mesh_topology(const Mesh& mesh);

/// Invariants of S = {x : f(x) = iso} inside the grid's box, f the piecewise-trilinear
/// interpolant of the samples, computed from the samples alone (no mesh, nothing shared with the
/// extractor). The sign rule applies: a value equal to iso counts as above, i.e. S is the level
/// set at iso - epsilon. Every decision (face saddles, interior connectivity by a sweep of the
/// cell, see src/topology/field_topology.cpp) is made exactly, so ties and near-ties are settled.
/// `determined` is false only when the exact arithmetic lost range (values - iso with magnitudes
/// beyond about 2^+-200) or the independent refinement cross-check disagreed with the exact
/// analysis (a bug); the numbers are then meaningless and `why` says which cell and why.
struct FieldTopology {
    bool determined = false;
    std::string why;
    std::int64_t euler = 0;
    std::int64_t b0 = 0;
    std::int64_t b1 = 0;
    std::int64_t b2 = 0;
    std::int64_t boundary_loops = 0; ///< closed curves where S meets the box's faces
};

struct FieldTopologyOptions {
    /// Cross-check each cell with two or more loops by adaptive 2x2x2 refinement down to
    /// 1/max_refinement of a cell (at most 1024; below 2, no cross-check). Near-ties never settle
    /// by refinement; there the exact analysis stands alone.
    int max_refinement = 256;
};

template <class T>
FieldTopology field_topology(const GridView<T>& grid, double iso, const FieldTopologyOptions& options = {});
FieldTopology field_topology(const Volume& volume, double iso, const FieldTopologyOptions& options = {});

} // namespace cmc33
