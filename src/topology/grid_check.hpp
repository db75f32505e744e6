#pragma once
// Internal: the geometric checks of mesh_geometry() for a mesh extract() made, using the grid it
// came from (contract of the public check in topology.hpp, check_extracted_mesh()).
//
// Every triangle of cell layer k is given to the cell (i, j, k) that holds its centroid in index
// space, and its corners are checked to lie in that cell grown by kCellMargin on every side. When
// they all do, two triangles of cells that are not neighbours (26-neighbourhood) are at least
// 1 - 2 * kCellMargin apart in index space and cannot meet; so only pairs of one cell or of
// neighbouring cells are tested, each pair once, with the exact tests of exact_geometry.hpp.
// A corner outside its cell's margin (a "stray": a moved vertex, or a mesh that is not laid out
// as extract() lays it out), or two vertices at one position (which the welded topology would
// need), ends the structured check: the caller then runs the general mesh_geometry().

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "cmc33/topology_export.hpp"
#include "cmc33/volume.hpp"

namespace cmc33::detail {

/// How far outside its cell a triangle's corner may lie, in cells (index units).
inline constexpr double kCellMargin = 0.25;

/// Cell layers of a mesh and the frame of their grid. Triangle ids and vertex ids are global;
/// `positions` holds vertex ids [first_vertex, first_vertex + positions.size() / 3).
struct LayeredTriangles {
    Index3 dims{};                 ///< samples of the grid (cells: dims - 1)
    Vec3 origin{};
    Mat3 frame = kIdentity3;       ///< index to world: column a is the world step along axis a
    std::span<const float> positions;
    std::int64_t first_vertex = 0;
    std::span<const std::uint32_t> triangles; ///< 3 global vertex ids per triangle
    std::int64_t first_triangle = 0;          ///< global id of the first triangle of `triangles`
    /// Layer k0 + i holds triangles [layer_first[i], layer_first[i + 1]) of `triangles`.
    std::span<const std::int64_t> layer_first;
    std::int64_t k0 = 0;           ///< the cell layer (z) of the first layer
};

/// What the structured check found in the layers it owns.
struct GridGeometry {
    std::int64_t zero_area_triangles = 0; ///< own triangles with a repeated corner or collinear corners
    std::int64_t intersecting_pairs = 0;  ///< pairs with at least one own triangle, the other own or in the layer above
    std::vector<std::array<std::int64_t, 2>> examples; ///< smallest pairs (global ids, smaller first)
    std::int64_t strays = 0;     ///< triangles with a corner outside their cell's margin
    std::int64_t coincident = 0; ///< pairs of distinct vertex ids found at one position
    /// Whether the counts above are mesh_geometry()'s: no stray and no coincident vertices.
    bool decided() const noexcept { return strays == 0 && coincident == 0; }
};

struct GridCheckOptions {
    int threads = 1;
    std::size_t examples = 8;
    /// Called with the number of layers done so far (from the calling thread); false: stop
    /// (grid_geometry then throws Error{cancelled}).
    std::function<bool(std::int64_t layers_done)> progress;
};

/// Runs body(b, stop) for b in [0, blocks) on up to `threads` threads (the calling one among them),
/// each block once, whichever thread is free. The calling thread calls tick() between its blocks
/// and while it waits; tick() false stops the others (`stop` turns true) and throws
/// Error{cancelled}. An exception in a body stops the others and is rethrown.
CMC33_TOPOLOGY_EXPORT void for_each_block(std::int64_t blocks, int threads,
                                          const std::function<void(std::int64_t, const std::atomic<bool>&)>& body,
                                          const std::function<bool()>& tick);

/// The structured check of layers [0, own) of `mesh`: pairs within them and with the layer
/// after them (layer `own`, which `mesh` must then hold, and which is read only).
/// @throws Error{invalid_argument} for a vertex id outside the positions, non-finite positions.
CMC33_TOPOLOGY_EXPORT GridGeometry grid_geometry(const LayeredTriangles& mesh, std::int64_t own,
                                                 const GridCheckOptions& options);

} // namespace cmc33::detail
