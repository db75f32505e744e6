#pragma once
// Internal: mesh_topology() of a mesh that is never held whole, from its slabs (the out-of-core
// extraction of `cmc33 extract --memory-limit` and the ranks of cmc33-mpi, src/slabs).
//
// The slabs are the ranges of sample planes of passes.hpp: slab s owns the vertex ids
// [first_vertex, first_vertex + vertex_count) and its triangles use its own vertices and the first
// vertices of slab s + 1 (the x/y edge vertices of the plane they share), never any other. Each
// slab is summed up on its own, given the triangles of slab s - 1 that may touch its vertices (the
// last cell layer of slab s - 1, its "ghost" layer); summaries of neighbouring runs of slabs
// merge, in any grouping (a chain for streaming, a tree over MPI ranks), into the summary of the
// whole mesh, whose finish() is mesh_topology() of the whole mesh.
//
// What each summary holds, and why it is enough:
//   - V, E, F, boundary, non-manifold and orientation counts: each vertex is judged by the slab
//     that owns it, whose triangles and ghost layer hold every triangle around it; each edge at
//     the owner of its smaller end (as mesh_topology() does). Sums over slabs.
//   - components, closed components and boundary loops: union-find over the slab's own triangles
//     (and over the boundary edges it counts). The components that reach a seam vertex are the
//     summary's nodes, with their labels on the seam vertices of its two outer sides; merging two
//     neighbouring runs unites the nodes that share a seam vertex and keeps as nodes only those
//     still on an outer side. The others are complete: they are counted (closed ones apart).
// A summary's size is that of its two outer seams, whatever the number of slabs it covers.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "cmc33/topology.hpp"
#include "cmc33/topology_export.hpp"

namespace cmc33::detail {

/// One slab: its own vertex ids, its triangles, and the ghost layer of the slab before it.
struct SlabTriangles {
    std::int64_t first_vertex = 0;
    std::int64_t vertex_count = 0;
    std::span<const std::uint32_t> triangles; ///< 3 global ids per triangle: own ids or the next slab's
    std::span<const std::uint32_t> below;     ///< triangles of the slab before that may use own ids (empty for the first)
};

class CMC33_TOPOLOGY_EXPORT SeamTopology {
public:
    /// The summary of one slab. @throws Error{invalid_argument} for a triangle of `triangles` with
    /// an id below first_vertex, or a triangle array that is not a multiple of 3.
    static SeamTopology of_slab(const SlabTriangles& slab);
    /// The summary of no slab (a range of no planes, an MPI rank with none): merging with it
    /// changes nothing.
    SeamTopology() = default;
    /// The summary of `lower` followed by `upper` (neighbouring runs of slabs, lower first).
    /// @throws Error{internal} if they do not fit (a boundary flag for a seam vertex the lower run
    /// does not have: the slabs were not neighbours).
    static SeamTopology merge(const SeamTopology& lower, const SeamTopology& upper);
    /// mesh_topology() of the mesh the summary covers (all of it: no slab before or after).
    MeshTopology finish() const;

    /// Bytes for sending to another process, and back.
    std::vector<std::byte> serialize() const;
    /// @throws Error{internal} for bytes that are not a serialized summary
    static SeamTopology deserialize(std::span<const std::byte> bytes);

private:
    /// Seam vertices of one outer side, sorted by id: the component and boundary-graph node each
    /// is in (-1: none), and on a lower side whether a boundary edge counted here flags the
    /// component that holds the vertex on the other side (used here by ghost triangles only).
    struct Side {
        std::vector<std::uint32_t> ids;
        std::vector<std::int32_t> component, loop;
        std::vector<std::uint8_t> flag;
    };
    std::int64_t vertices_ = 0, edges_ = 0, faces_ = 0, boundary_edges_ = 0, nonmanifold_edges_ = 0,
                 nonmanifold_vertices_ = 0, degenerate_ = 0;
    bool oriented_ = true;
    bool empty_ = true; ///< of no slab
    std::int64_t components_ = 0, closed_ = 0, loops_ = 0; ///< complete ones (not nodes)
    std::vector<std::uint8_t> node_boundary_;              ///< per component node: has a boundary edge
    std::int32_t loop_nodes_ = 0;
    Side lower_, upper_;
};

} // namespace cmc33::detail
