#pragma once
/// @file passes.hpp
/// extract() as three public passes over ranges of sample planes, for callers that own the output
/// memory (a numpy array, a vtkPoints, a memory-mapped file), split the volume into pieces (MPI
/// ranks, out-of-core slabs) or run their own threads:
///
///     count(grid, iso, options, k0, k1)  -> RangeCounts   what range [k0, k1) will write
///     scan(counts, first ids)            -> RangeOffsets  where each range writes
///     emit(grid, iso, options, counts, offsets, spans)    writes it
///
/// **Ownership.** A range [k0, k1) of sample planes (0 <= k0 < k1 <= nz) owns every grid edge whose
/// lower end lies in a plane k0 <= k < k1 (the x and y edges of those planes, and the z edges from
/// plane k to k + 1) and every cell whose lowest corner does. Plane k1 is shared with the next
/// range: its edges and their vertices belong to that range; the triangles of this range's last
/// slab of cells (k1 - 1) use them. Ranges that cover [0, nz) without overlap therefore produce
/// every vertex and triangle of extract() exactly once.
///
/// **Numbering.** Vertex ids run plane by plane: in plane k, first the vertices of the x and y
/// edges of every sample row (rows by j, samples by i, x before y), then per row the vertices of
/// the z edges followed by the interior vertices of the row's cells. Triangles run cell row by cell
/// row, cells by i. So the ids of plane k1's x and y edges, which this range's last triangles use,
/// depend only on the samples of plane k1 and on the next range's first vertex id: consecutive
/// ranges must have consecutive ids (scan() gives them), i.e. the next range starts at
/// offsets.first_vertex + counts.vertex_count().
///
/// The composition over any split, with any offsets, gives the same bytes as extract() shifted by
/// the offsets (tests/core/test_passes.cpp). emit replays count's decisions (kept in RangeCounts)
/// and classifies the samples again: it refuses counts of another grid, isovalue or method, and
/// checks that it writes exactly what count counted (Error{internal} otherwise, before writing
/// outside the range's part). The samples must not change between the passes.

#include <algorithm>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "cmc33/extract.hpp"
#include "cmc33/mesh.hpp"
#include "cmc33/volume.hpp"
#include "cmc33/core_export.hpp"

/// Marks the functions of this header: experimental, their signatures may change in a minor
/// release (extract() and the other headers' API do not). A consumer that defines
/// CMC33_WARN_EXPERIMENTAL before including cmc33 gets a warning at every use, to find them.
#ifdef CMC33_WARN_EXPERIMENTAL
#define CMC33_EXPERIMENTAL [[deprecated("experimental cmc33 API (passes.hpp): it may change in a minor release")]]
#else
#define CMC33_EXPERIMENTAL
#endif

namespace cmc33 {

namespace detail {
template <class T> class RangeExtractor; // src/core/range_extractor.hpp

/// What a RangeCounts holds: read and written by the passes alone (src/core/count.cpp, emit.cpp),
/// its layout may change in any release.
struct RangeTable {
    struct Row { // 24 bytes: vertex ids fit 32 bits (a range's count is checked), triangles may not
        std::int64_t triangle_first = 0;
        std::uint32_t xy_first = 0; ///< first id of the row's x/y edge vertices (range-relative)
        std::uint32_t z_first = 0;  ///< first id of its z edge vertices, then its cells' interior ones
        std::int32_t lo = 0, hi = 0; ///< samples [lo, hi) own every crossed edge and cell of the row
    };
    std::int64_t k0 = 0, k1 = 0, nx = 0, ny = 0;
    std::int64_t vertices = 0, triangles = 0;
    double largest_sample = 0; ///< bound on |sample| near the range (normals' scaling)
    double iso = 0;            ///< the isovalue and method counted (emit checks them)
    Method method = Method::cmc33;
    /// (k1 - k0) * ny rows, row (j, k) at j + (k - k0) * ny. A Buffer (mesh.hpp), as the mesh is: its
    /// megabytes (1.5 MiB for 256^3) come in huge pages, kept for the next count of the same size.
    Buffer<Row> rows;
    std::vector<std::int64_t> seam_first; ///< plane k1's rows: first x/y edge vertex (next range's ids)
    /// One byte per cell with a face or interior test, in the order count met them: its decision,
    /// which emit replays instead of deciding again
    std::vector<std::uint8_t> decisions;
    ExtractStats stats{};
};
} // namespace detail

/// What count() found in one range: the number of vertices and triangles, and per sample row the
/// numbers emit() needs to place them. Opaque apart from the accessors; 24 bytes per sample row and
/// one per cell with a face or interior test (its decision, which emit() replays).
class RangeCounts {
public:
    std::int64_t k0() const noexcept { return t_.k0; }
    std::int64_t k1() const noexcept { return t_.k1; }
    std::int64_t vertex_count() const noexcept { return t_.vertices; }
    std::int64_t triangle_count() const noexcept { return t_.triangles; }
    /// Crossed cells of the range per subcase (see subcase_name()).
    const ExtractStats& stats() const noexcept { return t_.stats; }
    /// A bound on |sample| over the planes the range read, which scales emit()'s gradients when
    /// samples come near the double range. extract() gives every range the largest bound of them
    /// all; ranges counted apart (MPI ranks, out-of-core slabs) get extract()'s normals byte for
    /// byte by doing the same: share_sample_bound(the largest sample_bound() of all ranges).
    double sample_bound() const noexcept { return t_.largest_sample; }
    /// The first vertex of sample plane k and the first triangle of cell layer k, counted from the
    /// range's first (k0 <= k < k1).
    std::int64_t plane_first_vertex(std::int64_t k) const noexcept { return row(k).xy_first; }
    std::int64_t plane_first_triangle(std::int64_t k) const noexcept { return row(k).triangle_first; }
    /// Raises the bound to `bound` (never lowers it: a lower bound could overflow the gradients).
    void share_sample_bound(double bound) noexcept
    {
        t_.largest_sample = bound > t_.largest_sample ? bound : t_.largest_sample;
    }

private:
    template <class T> friend class detail::RangeExtractor;
    const detail::RangeTable::Row& row(std::int64_t k) const noexcept
    {
        return t_.rows[static_cast<std::size_t>((k - t_.k0) * t_.ny)];
    }
    detail::RangeTable t_;
};

/// Where a range's vertices and triangles go in the caller's numbering.
struct RangeOffsets {
    std::int64_t first_vertex = 0;
    std::int64_t first_triangle = 0;
};

/// Output memory the caller owns. Element 0 of the vertex arrays holds vertex `first_vertex` of the
/// global numbering and element 0 of the triangle arrays triangle `first_triangle`, so a range (or
/// an MPI rank) can be given just its slice of a larger output; emit() writes the ids in
/// [offsets.first_vertex, + counts.vertex_count()) and the triangles in
/// [offsets.first_triangle, + counts.triangle_count()). Null arrays are not written. The members
/// after `normals` (the extras: VTK filters' point data, scikit-image's values, Dask blocks) are
/// experimental, as the functions of this header are.
struct MeshSpans {
    float* positions = nullptr;          ///< 3 per vertex, world coordinates (required)
    std::uint32_t* triangles = nullptr;  ///< 3 per triangle, global vertex ids (required)
    float* normals = nullptr;            ///< 3 per vertex, unit; computed only when not null
    /// Per vertex, for interpolating other point data (a VTK filter's needs): the grid edge of an
    /// edge vertex, 3 * (i + nx * (j + ny * k)) + axis for the edge from sample (i, j, k) along axis;
    /// for an interior vertex -1 - c, c = i + nx * (j + ny * k) the lowest corner of its cell
    /// (indices and nx, ny of the larger grid with whole_dims).
    std::int64_t* vertex_edges = nullptr;
    /// Per vertex: an edge vertex's parameter t in (0, 1) along its edge, from the edge's lower
    /// sample (value a) to its upper one (b); -1 for an interior vertex.
    float* vertex_parameters = nullptr;
    /// Per vertex: the trilinear interpolant of the samples at the vertex (close to iso: crossings
    /// are kept delta away from samples, docs/conventions.md "Geometry").
    float* vertex_values = nullptr;
    /// Per triangle: the cell it lies in, i + nx * (j + ny * k) of the cell's lowest corner (the
    /// larger grid's with whole_dims).
    std::int64_t* triangle_cells = nullptr;
    /// Per vertex: the largest range of samples (largest minus smallest of a cell's 8) among the
    /// cells whose triangles use the vertex: for an edge vertex every cell of the grid around its
    /// edge (each of them is crossed there), for an interior vertex its own cell. This is
    /// scikit-image's `values` of marching_cubes; it depends on the grid alone, so every range
    /// writes just its own vertices'.
    float* vertex_cell_ranges = nullptr;
    /// Write positions and normals as (z, y, x) instead of (x, y, z): the axis order of a C-ordered
    /// (numpy) array whose last axis is x. Nothing else changes (the winding stays that of x, y, z).
    bool zyx = false;
    /// Wind every triangle the other way round (normals are not changed).
    bool reverse_winding = false;
    std::int64_t first_vertex = 0;   ///< global id of element 0 of the vertex arrays
    std::int64_t first_triangle = 0; ///< global id of element 0 of the triangle arrays
    /// For a grid that is a block of a larger one (a chunk of a Dask array, cmc33.dask): the
    /// larger grid's index of this grid's sample (0, 0, 0). The grid's origin, spacing and
    /// direction are then the larger grid's; positions are written at the larger grid's index
    /// (origin + M * (index_offset + (i, j, k) + u), the sum in double as extract() of the larger
    /// grid sums it) and vertex_edges and triangle_cells number the larger grid's edges and cells,
    /// so that a block writes its vertices' bytes as extract() of the whole writes them. Normals
    /// read this grid's samples: equal to the whole's where each vertex's edge ends have their
    /// neighbours in the block. Zero (with whole_dims zero): the grid is the whole.
    Index3 index_offset{0, 0, 0};
    /// The larger grid's samples, with index_offset: its box (origin and M) sets how far crossings
    /// stay from the samples (docs/conventions.md, "Geometry"), as it does for extract() of it.
    /// Zero: the grid's own dims (index_offset must then be zero).
    Index3 whole_dims{0, 0, 0};
};

/// Pass 1 on sample planes [k0, k1): classifies and decides every cell the range owns and counts
/// its vertices and triangles. Reads sample planes k0 .. min(k1, nz - 1). Single-threaded: run
/// ranges in parallel for threads (options.threads, progress and executor are not used here).
/// @throws Error{invalid_argument} unless 0 <= k0 < k1 <= nz, or for the grid errors of extract()
template <class T>
CMC33_EXPERIMENTAL CMC33_CORE_EXPORT RangeCounts count(const GridView<T>& grid, double iso,
                                                       const ExtractOptions& options, std::int64_t k0, std::int64_t k1);

/// Pass 2: consecutive offsets for ranges in order, starting at the given ids.
CMC33_EXPERIMENTAL CMC33_CORE_EXPORT std::vector<RangeOffsets> scan(std::span<const RangeCounts> ranges,
                                                                    std::int64_t first_vertex = 0,
                                                                    std::int64_t first_triangle = 0);

/// The order in which threads should take ranges for emit: their indices, largest first (by
/// vertices and triangles, what emit's time follows), ties in index order. The last ranges taken
/// are then small, and the threads end nearly together however the surface is spread.
CMC33_EXPERIMENTAL CMC33_CORE_EXPORT std::vector<int> emit_order(std::span<const RangeCounts> ranges);

/// Pass 3: writes the range's vertices (positions, and normals etc. where `out` has arrays for them)
/// and triangles into `out`. `counts` must come from count() on the same grid, iso and method.
/// Reads planes k0 - 1 .. min(k1 + 1, nz - 1) (the outer two only for normals' central
/// differences). Single-threaded (options.threads, progress and executor are not used here).
/// @throws Error{internal} if the cells decided differently than in count() (a bug); Error{too_large}
///         if a vertex id passes 2^32 - 2
template <class T>
CMC33_EXPERIMENTAL CMC33_CORE_EXPORT void emit(const GridView<T>& grid, double iso, const ExtractOptions& options,
                                               const RangeCounts& counts, const RangeOffsets& offsets,
                                               const MeshSpans& out);

/// What the ranges of one mesh need between count() and emit(), as extract() does it.
struct MeshLayout {
    std::vector<RangeOffsets> offsets; ///< scan()'s, from ids 0
    std::int64_t vertex_count = 0;     ///< the mesh's
    std::int64_t triangle_count = 0;
};

/// Ranges that together cover a grid's planes [0, nz), in order: raises every range's sample
/// bound to the largest of them (share_sample_bound(), so that emit()'s normals are extract()'s
/// whatever the split), then scan()s them from 0.
/// @throws Error{too_large} if the mesh has more vertices than 32-bit ids can address; scan()'s
CMC33_EXPERIMENTAL CMC33_CORE_EXPORT MeshLayout lay_out(std::span<RangeCounts> ranges);

namespace detail {
/// window()'s planes are this many samples longer than nx * ny: a cache line (see window.cpp).
template <class T> inline constexpr std::int64_t kWindowPad = 64 / static_cast<std::int64_t>(sizeof(T));
} // namespace detail

/// count() and emit() read a grid an x row at a time. Where x is not the grid's contiguous axis (a
/// Fortran-ordered array: each sample of a row in its own cache line), copying the planes a range
/// reads into x-contiguous order first is several times faster; window() makes that copy for
/// range [k0, k1): planes max(k0 - 1, 0) .. min(k1 + 1, nz - 1) (what count and emit read) into
/// `buffer` (resized as needed: reuse it from range to range), and returns a view of them with the
/// grid's dims, indices and frame. count() and emit() of that range give the same bytes through
/// the view as through `grid`; no other plane may be read through it. The buffer holds
/// (planes) * (nx * ny + 64 / sizeof(T)) samples (the planes padded by a cache line).
/// @throws Error{invalid_argument} unless 0 <= k0 < k1 <= nz
template <class T>
CMC33_EXPERIMENTAL CMC33_CORE_EXPORT GridView<T> window(const GridView<T>& grid, std::int64_t k0, std::int64_t k1,
                                                       Buffer<T>& buffer);

/// For callers that run the passes over ranges: 0 when count() and emit() read `grid` best in
/// place (its x samples adjacent, stride 1), else the most planes a range may have for its
/// window() to stay within `bytes` (at least 1; a window holds up to 3 planes more).
template <class T>
CMC33_EXPERIMENTAL std::int64_t window_range_planes(const GridView<T>& grid,
                                                    std::int64_t bytes = std::int64_t{4} << 20) noexcept
{
    if (grid.strides[0] == 1 || grid.nx() < 2) return 0;
    const std::int64_t plane = (grid.nx() * grid.ny() + detail::kWindowPad<T>) * static_cast<std::int64_t>(sizeof(T));
    return std::max<std::int64_t>(bytes / plane - 3, 1);
}

/// Experimental. How extract() splits a grid into ranges of sample planes and threads, for
/// callers that run count() and emit() over ranges on threads themselves (run_ranges()).
struct RangePlan {
    int threads = 1; ///< thread_count(threads), at most one per range
    /// ranges() + 1 entries from 0 to nz: range r is sample planes [first_planes[r], first_planes[r + 1])
    std::vector<std::int64_t> first_planes;
    /// window_range_planes(grid): 0 when count() and emit() read the grid in place; else each
    /// range reads it through a window(), one buffer per thread, and has at most this many planes
    std::int64_t window_planes = 0;
    int ranges() const noexcept { return static_cast<int>(first_planes.size()) - 1; }
};

/// Experimental. extract()'s plan: thread_count(threads) threads, at most nz; one range for one
/// thread, else about nz / 8 ranges, at least one and at most 8 per thread (more ranges than
/// threads, taken in turn, end the threads together when the surface is spread unevenly over the
/// planes; ranges of 8 planes or more keep the planes read twice, at their ends, few). Ranges are
/// then cut finer, evenly, until each has at most window_planes planes (if not 0) and at most
/// `max_range_samples` samples (if not 0; at least one plane): run_ranges() starts no range once
/// asked to stop, so this bounds the wait for a stop. The mesh is the same for every plan.
template <class T>
CMC33_EXPERIMENTAL CMC33_CORE_EXPORT RangePlan plan_ranges(const GridView<T>& grid, int threads,
                                                           std::int64_t max_range_samples = 0);

/// Experimental. The loop extract() runs its passes with: work(r, task) for every range r of
/// `order` (the ranges' indices, each once: 0, 1, ... for count(), emit_order() for emit()) on
/// `threads` tasks of `executor` (empty: the calling thread and the process's worker pool, as
/// extract()), each task taking the next range of `order` when it is free. After each range,
/// progress(ranges done / ranges), as ExtractOptions::progress is called (from a task's thread,
/// never two calls at once, at most every few milliseconds); once it returns false no range
/// starts. Every range that starts ends; then the error of the lowest range that threw is
/// rethrown (the same whichever thread ran what), else Error{cancelled} if progress said stop.
CMC33_EXPERIMENTAL CMC33_CORE_EXPORT void run_ranges(int threads, std::span<const int> order,
                                  const std::function<void(int range, int task)>& work, const Progress& progress = {},
                                  const Executor& executor = {});

} // namespace cmc33
