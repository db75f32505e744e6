#pragma once
/// @file mesh_ops.hpp
/// Simplification, smoothing and component filtering of triangle meshes that keep what cmc33
/// guarantees: the topology (Euler characteristic, Betti numbers, components, boundary loops), a
/// manifold, and an embedding (no two triangles meet improperly, checked with exact predicates).

#include <cstdint>
#include <functional>
#include <limits>
#include <string>

#include "cmc33/mesh.hpp"
#include "cmc33/topology.hpp"
#include "cmc33/mesh_ops_export.hpp"

namespace cmc33 {

struct SimplifyOptions {
    /// Stop at this many triangles or fewer (0: no count target).
    std::int64_t target_triangles = 0;
    /// Stop at ratio * triangles of the input (used when target_triangles is 0; 1: no target).
    double ratio = 1.0;
    /// Stop before a collapse whose quadric error (the sum of squared distances of the new vertex
    /// to the planes of the input triangles merged into it) exceeds max_error squared, world units.
    double max_error = std::numeric_limits<double>::infinity();
    /// A distance bound, world units (infinity: none). Guaranteed: every input vertex (of a
    /// triangle) ends within it of the output surface: each is assigned to a triangle within it,
    /// and a collapse is refused when those of the triangles it changes cannot all find a new one.
    /// Sampled: a collapse is also refused when the new vertex, a new triangle's centroid or the
    /// midpoint of a new edge would be farther than this from the input triangles at the input
    /// vertices merged into the new triangles' corners or assigned to the changed triangles. Every
    /// output vertex, centroid and edge midpoint has been so checked (or is the input's own), so a
    /// point of an output triangle is within the bound plus its longest edge / (2 sqrt 3) of the
    /// input, and a point of an input triangle within the bound plus its longest edge / sqrt 3 of
    /// the output.
    double max_distance = std::numeric_limits<double>::infinity();
    /// Optional: called with the fraction done; false stops (Error{cancelled}).
    std::function<bool(double fraction)> progress;
};

struct SimplifyStats {
    std::int64_t collapses = 0;          ///< edges collapsed
    std::int64_t refused_topology = 0;   ///< refused by the link condition or a locked vertex
    std::int64_t refused_flip = 0;       ///< refused: a triangle would turn by more than 90 degrees or vanish
    std::int64_t refused_intersection = 0; ///< refused: a new triangle would meet another improperly
    std::int64_t refused_distance = 0;   ///< refused by the distance bound (max_distance; checked first)
    double max_quadric_error = 0;        ///< the largest quadric error of a collapse done (world units, square-rooted)
};

/// Edge collapses ordered by quadric error (Garland and Heckbert 1997), each refused when it would
/// change the topology (link condition, Dey et al. 1999; boundary edges kept in their loops; a
/// component reduced to a tetrahedron stops), make the mesh non-manifold, turn a triangle by more
/// than 90 degrees, or make two triangles meet improperly (exact predicates, tested against every
/// triangle near the new ones). Deterministic. Vertices on non-manifold edges or at non-manifold
/// vertices of the input are never moved. Normals are recomputed if the input had normals.
/// @throws Error{invalid_argument} for indices out of range, non-finite positions or bad options.
CMC33_MESH_OPS_EXPORT Mesh simplify(const Mesh& mesh, const SimplifyOptions& options = {}, SimplifyStats* stats = nullptr);

struct SmoothOptions {
    int iterations = 10;      ///< Taubin lambda|mu pairs
    double lambda = 0.5;      ///< shrinking step
    double mu = -0.53;        ///< inflating step (|mu| > lambda)
    int halvings = 3;         ///< a move that fails a check is halved up to this many times, then undone
    std::function<bool(double fraction)> progress;
};

struct SmoothStats {
    std::int64_t moves = 0;     ///< vertex moves done (whole or shortened)
    std::int64_t shortened = 0; ///< moves done after halving
    std::int64_t undone = 0;    ///< moves refused after every halving
};

/// Taubin's lambda|mu smoothing (Taubin 1995) with uniform umbrella weights. Boundary vertices and
/// vertices at non-manifold places stay. Each vertex move is checked as a collapse is (no triangle
/// turned by more than 90 degrees or of zero area, no improper meeting, exactly and locally); a
/// move that fails is halved up to `halvings` times, then undone. Connectivity never changes.
CMC33_MESH_OPS_EXPORT Mesh smooth(const Mesh& mesh, const SmoothOptions& options = {}, SmoothStats* stats = nullptr);

struct ComponentFilter {
    bool largest = false;        ///< keep only the component with the most triangles (the first on ties)
    std::int64_t min_triangles = 0; ///< drop components with fewer triangles
};

/// Components by edge connectivity (triangles sharing an edge, vertices welded by index). Unused
/// vertices are dropped; the order of what is kept does not change.
CMC33_MESH_OPS_EXPORT Mesh filter_components(const Mesh& mesh, const ComponentFilter& filter, std::int64_t* dropped_components = nullptr);

/// Two-sided Hausdorff distance estimated by sampling. Samples on a mesh: every used vertex, each
/// triangle's centroid, and points of a regular barycentric grid on each triangle whose longest
/// edge exceeds `spacing` (ceil(longest / spacing) subdivisions). Each sample's distance to the
/// other mesh is exact point-to-triangle distance to its nearest triangle (found with a uniform
/// grid of triangles). spacing <= 0: the mean edge length of `a`.
struct HausdorffResult {
    double a_to_b = 0;  ///< max over samples of a of the distance to b
    double b_to_a = 0;
    double mean_a_to_b = 0;
    double mean_b_to_a = 0;
    std::int64_t samples_a = 0, samples_b = 0;
    double distance() const noexcept { return a_to_b > b_to_a ? a_to_b : b_to_a; }
};
CMC33_MESH_OPS_EXPORT HausdorffResult hausdorff_distance(const Mesh& a, const Mesh& b, double spacing = 0, int threads = 0);

/// Before and after: mesh_topology() and mesh_geometry() of each, and the Hausdorff distance.
struct MeshOpsReport {
    MeshTopology topology_before, topology_after;
    MeshGeometry geometry_before, geometry_after;
    HausdorffResult hausdorff;
    /// Same topology: euler, components, closed components, b1, boundary loops, manifoldness.
    CMC33_MESH_OPS_EXPORT bool topology_same() const noexcept;
};
CMC33_MESH_OPS_EXPORT MeshOpsReport compare_meshes(const Mesh& before, const Mesh& after, int threads = 0);

} // namespace cmc33
