#pragma once
/// @file topology.hpp
/// Topology of meshes, and the topology a level set of the trilinear interpolant must have.

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "cmc33/mesh.hpp"
#include "cmc33/volume.hpp"
#include "cmc33/topology_export.hpp"

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
CMC33_TOPOLOGY_EXPORT MeshTopology mesh_topology(const Mesh& mesh);

/// The mesh as it sits in space. Positions are compared exactly (the floats of the mesh), and
/// every test is an exact predicate, so nothing here depends on a tolerance.
/// Embedded means: no two vertices at one position, no triangle with collinear corners, and no
/// two triangles meeting anywhere except along an edge they share or at a corner they share
/// (overlaps, crossings and touching at a point all count). Then welding the vertices by
/// position (an STL round trip, MeshLab's or trimesh's merge) changes nothing.
struct MeshGeometry {
    std::int64_t positions = 0;            ///< distinct positions among vertices used by a triangle
    std::int64_t coincident_vertices = 0;  ///< used vertices whose position another used vertex has too
    std::int64_t zero_area_triangles = 0;  ///< corners collinear or at one position (after welding)
    std::int64_t intersecting_pairs = 0;   ///< pairs of triangles meeting improperly (see above)
    /// Up to MeshGeometryOptions::examples intersecting pairs (triangle indices, smaller first),
    /// smallest first.
    std::vector<std::array<std::int64_t, 2>> intersection_examples;
    MeshTopology welded; ///< mesh_topology() of the mesh welded by exact position
    bool embedded() const noexcept
    {
        return coincident_vertices == 0 && zero_area_triangles == 0 && intersecting_pairs == 0;
    }
};

struct MeshGeometryOptions {
    int threads = 0;           ///< 0: all cores. The result does not depend on it.
    std::size_t examples = 8;  ///< how many intersecting pairs to list
};

/// @throws Error{invalid_argument} for indices out of range or non-finite positions.
/// Cost: O(F log F) time (a sort of triangles into buckets of a uniform grid sized by the mean
/// triangle, then exact tests of the pairs whose boxes overlap); memory about 40 bytes per
/// triangle. A 2-million-triangle surface takes about a second.
CMC33_TOPOLOGY_EXPORT MeshGeometry mesh_geometry(const Mesh& mesh, const MeshGeometryOptions& options = {});

/// The grid a mesh was extracted from, and where extract() put each sample plane's vertices and each
/// cell layer's triangles (ExtractStats::plane_first_vertex and plane_first_triangle).
struct ExtractedGrid {
    Index3 dims{};
    Vec3 spacing{1, 1, 1};
    Vec3 origin{0, 0, 0};
    Mat3 direction = kIdentity3;
    /// dims[2] + 1 entries each: vertices of sample plane k are [first_vertex[k], first_vertex[k + 1]),
    /// triangles of cell layer k are [first_triangle[k], first_triangle[k + 1]).
    std::span<const std::int64_t> plane_first_vertex, plane_first_triangle;
};

/// mesh_topology() and mesh_geometry() of an extracted mesh.
struct MeshCheck {
    MeshTopology topology;
    MeshGeometry geometry;
    /// True when the grid's structure decided (see check_extracted_mesh()); false when the mesh was
    /// not laid out as the grid says, or had coincident vertices or a corner outside its cell, and
    /// the general mesh_topology() and mesh_geometry() ran instead. The numbers are the same.
    bool structured = false;
};

struct MeshCheckOptions {
    int threads = 0;          ///< 0: all cores. The result does not depend on it.
    std::size_t examples = 8; ///< how many intersecting pairs to list
    /// Optional: called with the fraction done; false stops the check (Error{cancelled}).
    std::function<bool(double fraction)> progress;
};

/// The numbers of mesh_topology() and mesh_geometry() for a mesh extract() made from `grid`,
/// computed with the grid's structure: every triangle of cell layer k lies in a cell of that layer
/// (checked: each corner within a quarter cell of it), so only triangles of one cell or of
/// neighbouring cells can meet, and each vertex's triangles lie in its plane's layer and the one
/// below. Both checks run slab by slab of planes, in parallel, in memory proportional to a slab
/// (the topology's slabs merge at their seams as the out-of-core extraction's do). Exact
/// predicates decide every pair whose boxes meet. A mesh that does not fit the layout, a corner
/// outside its cell or two vertices at one position send the check to the general functions.
/// @throws Error{invalid_argument} as mesh_geometry() does; Error{cancelled} if progress said stop.
/// Cost: O(F) time; memory O(F / slabs).
CMC33_TOPOLOGY_EXPORT MeshCheck check_extracted_mesh(const Mesh& mesh, const ExtractedGrid& grid,
                                                     const MeshCheckOptions& options = {});

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
CMC33_TOPOLOGY_EXPORT FieldTopology field_topology(const GridView<T>& grid, double iso, const FieldTopologyOptions& options = {});
CMC33_TOPOLOGY_EXPORT FieldTopology field_topology(const Volume& volume, double iso, const FieldTopologyOptions& options = {});

} // namespace cmc33
