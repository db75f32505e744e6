// extract(): Marching Cubes 33 in passes (docs/architecture.md, after VTK's Flying Edges), public in
// src/core/include/cmc33/passes.hpp, each over a range of sample planes [k0, k1):
//   1. count (count.cpp): per cell row its cells' case codes, decisions, vertices and triangles;
//   2. scan: consecutive ranges get consecutive first vertex and triangle ids;
//   3. emit (emit.cpp): vertices and triangles at the ids the scan fixed, no locks;
// working memory is O(rows + tested cells + threads * nx * ny), not O(cells). extract() runs the
// ranges as tasks (schedule.hpp); all writes land at offsets fixed by the scan, so the mesh is the
// same, byte for byte, for every thread count and every split.

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/passes.hpp"
#include "grid_checks.hpp"
#include "range_extractor.hpp"
#include "refine.hpp"
#include "sample_types.hpp"
#include "schedule.hpp"

namespace cmc33 {

/// The one coordinator: check the input, refine the grid for cmc33-paper, run the passes as ranges
/// (extract_passes), map a refined mesh back to the grid.
template <class T> Mesh extract(const GridView<T>& grid, double iso, const ExtractOptions& options, ExtractStats* stats)
{
    if (options.method != Method::cmc33_paper) return detail::extract_passes(grid, iso, options, stats);
    detail::check_grid(grid, iso);
    detail::scan_samples(grid, 0, grid.nz() - 1); // the refinement decides cells before any pass reads them
    const std::optional<detail::Refinement> refined = detail::Refinement::of(grid, iso);
    if (!refined) {
        Mesh mesh = detail::extract_passes(grid, iso, options, stats);
        if (stats) stats->refinement_planes = 0;
        return mesh;
    }
    ExtractOptions on_refined = options;
    on_refined.normals = false; // from the original samples, in map_back
    Mesh mesh = detail::extract_passes(refined->view(), refined->iso(), on_refined, stats);
    if (stats) {
        stats->refinement_planes = refined->planes();
        // the layout is the refined grid's, which the caller does not have
        stats->plane_first_vertex.clear();
        stats->plane_first_triangle.clear();
    }
    refined->map_back(grid, options.normals, mesh);
    return mesh;
}

template <class T>
Mesh detail::extract_passes(const GridView<T>& grid, double iso, const ExtractOptions& options, ExtractStats* stats)
{
    detail::check_grid(grid, iso);
    const std::int64_t nz = grid.nz();
    const detail::RangeExtractor<T> extractor(grid, iso, options);
    // The ranges (plan_ranges): more than threads, taken in turn by whichever thread is free;
    // where x is not the contiguous axis, each read through a window() (passes.hpp)
    const RangePlan plan = plan_ranges(grid, options.threads);
    const int n = plan.threads;
    const auto first_plane = [&plan](int r) { return plan.first_planes[static_cast<std::size_t>(r)]; };
    // runs work on the extractor of range r: `extractor`, or one on the range's window in task t's
    // buffer (an extractor's tables take microseconds, a window's copy milliseconds)
    std::vector<Buffer<T>> windows(static_cast<std::size_t>(plan.window_planes > 0 ? n : 0));
    const auto with_extractor = [&](int r, int t, const auto& work) {
        if (plan.window_planes == 0) return work(extractor);
        const GridView<T> view = window(grid, first_plane(r), first_plane(r + 1), windows[static_cast<std::size_t>(t)]);
        return work(detail::RangeExtractor<T>(view, iso, options));
    };
    detail::Ticker ticker(options.progress, 2 * nz);

    std::vector<int> order(static_cast<std::size_t>(plan.ranges()));
    std::iota(order.begin(), order.end(), 0);
    std::vector<RangeCounts> counts(order.size());
    try {
        detail::for_each_range(n, order, options.executor, ticker, [&](int r, int t) {
            counts[static_cast<std::size_t>(r)] = with_extractor(r, t, [&](const detail::RangeExtractor<T>& x) {
                return x.count(first_plane(r), first_plane(r + 1), 0.0, &ticker);
            });
        });
    } catch (const Error& e) {
        // a range names its own non-finite samples: say how many the whole grid has, and the first
        if (e.status() == Status::non_finite) detail::scan_samples(grid, 0, nz - 1);
        throw;
    }
    if (ticker.cancelled()) detail::throw_cancelled();
    const MeshLayout layout = lay_out(counts);
    const std::vector<RangeOffsets>& offsets = layout.offsets;
    const std::int64_t nv = layout.vertex_count, nt = layout.triangle_count;
    Mesh mesh;
    mesh.positions.resize(static_cast<std::size_t>(nv) * 3);
    if (options.normals) mesh.normals.resize(static_cast<std::size_t>(nv) * 3);
    mesh.triangles.resize(static_cast<std::size_t>(nt) * 3);
    MeshSpans out;
    out.positions = mesh.positions.data();
    out.triangles = mesh.triangles.data();
    out.normals = options.normals ? mesh.normals.data() : nullptr;
    // largest first (bonsai, 2 threads: the plane order left one thread idle for most of a large range)
    detail::for_each_range(n, emit_order(counts), options.executor, ticker, [&](int r, int t) {
        with_extractor(r, t, [&](const detail::RangeExtractor<T>& x) {
            x.emit(counts[static_cast<std::size_t>(r)], offsets[static_cast<std::size_t>(r)], out, &ticker);
        });
    });
    if (ticker.cancelled()) detail::throw_cancelled();
    ticker.finish();
    if (ticker.cancelled()) detail::throw_cancelled(); // false to the final 1 stops too: no mesh
    if (stats) {
        *stats = {};
        for (const RangeCounts& c : counts)
            for (std::size_t i = 0; i < static_cast<std::size_t>(kSubcaseCount); ++i) {
                stats->cells_per_subcase[i] += c.stats().cells_per_subcase[i];
            }
        stats->plane_first_vertex.reserve(static_cast<std::size_t>(nz) + 1);
        stats->plane_first_triangle.reserve(static_cast<std::size_t>(nz) + 1);
        for (std::size_t r = 0; r < counts.size(); ++r) {
            for (std::int64_t k = counts[r].k0(); k < counts[r].k1(); ++k) {
                stats->plane_first_vertex.push_back(offsets[r].first_vertex + counts[r].plane_first_vertex(k));
                stats->plane_first_triangle.push_back(offsets[r].first_triangle + counts[r].plane_first_triangle(k));
            }
        }
        stats->plane_first_vertex.push_back(nv);
        stats->plane_first_triangle.push_back(nt);
    }
    return mesh;
}

Mesh extract(const Volume& volume, double iso, const ExtractOptions& options, ExtractStats* stats)
{
    return volume.visit([&](auto view) { return extract(view, iso, options, stats); });
}

#define CMC33_INSTANTIATE(T)                                                                                    \
    template Mesh extract<T>(const GridView<T>&, double, const ExtractOptions&, ExtractStats*);                       \
    template Mesh detail::extract_passes<T>(const GridView<T>&, double, const ExtractOptions&, ExtractStats*);
CMC33_FOR_EACH_SAMPLE_TYPE(CMC33_INSTANTIATE)
#undef CMC33_INSTANTIATE

} // namespace cmc33
