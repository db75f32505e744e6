// The public passes of passes.hpp (count, scan, emit_order, emit): the range extractor
// (range_extractor.hpp) behind checks of what the caller hands it; and how extract() runs them
// (lay_out, plan_ranges, run_ranges), which callers running the passes themselves share.

#include <algorithm>
#include <cstdint>
#include <limits>
#include <numeric>
#include <span>
#include <string>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/passes.hpp"
#include "bit_rows.hpp"
#include "grid_checks.hpp"
#include "parallel.hpp"
#include "range_extractor.hpp"
#include "sample_types.hpp"
#include "schedule.hpp"

namespace cmc33 {

namespace {

std::string range_text(std::int64_t k0, std::int64_t k1)
{
    return "[" + std::to_string(k0) + ", " + std::to_string(k1) + ")";
}

/// The passes run on the grid as it is; cmc33-paper may refine it first.
void check_passes_method(const ExtractOptions& options, const char* pass)
{
    if (options.method == Method::cmc33_paper) {
        throw Error(Status::invalid_argument, std::string(pass) +
                                                  ": method cmc33-paper refines the grid first (Custodio et al. 2013, "
                                                  "Sec. 6.2), which the passes cannot; use extract(), or another method");
    }
}

std::string index_text(const Index3& v)
{
    return "(" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ", " + std::to_string(v[2]) + ")";
}

/// MeshSpans' place of the grid in a larger one: none (both zero), or inside it.
void check_block(const Index3& dims, const MeshSpans& out)
{
    const bool whole = out.whole_dims == Index3{0, 0, 0};
    bool inside = true;
    for (std::size_t a = 0; a < 3; ++a) {
        inside &= whole ? out.index_offset[a] == 0
                        : out.index_offset[a] >= 0 && out.index_offset[a] <= out.whole_dims[a] - dims[a];
    }
    if (!inside) {
        throw Error(Status::invalid_argument, "emit: MeshSpans places the grid of " + index_text(dims) + " samples at index_offset " +
                                                  index_text(out.index_offset) + " in whole_dims " + index_text(out.whole_dims) +
                                                  "; expected 0 <= index_offset <= whole_dims - dims, or both zero");
    }
}

} // namespace

template <class T>
RangeCounts count(const GridView<T>& grid, double iso, const ExtractOptions& options, std::int64_t k0, std::int64_t k1)
{
    check_passes_method(options, "count");
    detail::check_grid(grid, iso);
    if (!(0 <= k0 && k0 < k1 && k1 <= grid.nz())) {
        throw Error(Status::invalid_argument, "count: sample planes " + range_text(k0, k1) + "; expected 0 <= k0 < k1 <= " +
                                                  std::to_string(grid.nz()) + " (the grid's nz)");
    }
    // count reads planes k0..k1 (checking them as it goes); emit's normals also read k0 - 1 and k1 + 1
    double largest = 0;
    if (k0 > 0) largest = detail::scan_samples(grid, k0 - 1, k0 - 1);
    if (k1 + 1 < grid.nz()) largest = std::max(largest, detail::scan_samples(grid, k1 + 1, k1 + 1));
    return detail::RangeExtractor<T>(grid, iso, options).count(k0, k1, largest, nullptr);
}

std::vector<RangeOffsets> scan(std::span<const RangeCounts> ranges, std::int64_t first_vertex, std::int64_t first_triangle)
{
    std::vector<RangeOffsets> offsets;
    offsets.reserve(ranges.size());
    for (std::size_t r = 0; r < ranges.size(); ++r) {
        if (r > 0 && ranges[r].k0() != ranges[r - 1].k1()) {
            throw Error(Status::invalid_argument, "scan: range " + std::to_string(r) + " starts at plane " +
                                                      std::to_string(ranges[r].k0()) + "; expected " +
                                                      std::to_string(ranges[r - 1].k1()) +
                                                      ", where the range before it ends");
        }
        offsets.push_back({first_vertex, first_triangle});
        first_vertex += ranges[r].vertex_count();
        first_triangle += ranges[r].triangle_count();
    }
    return offsets;
}

std::vector<int> emit_order(std::span<const RangeCounts> ranges)
{
    std::vector<int> order(ranges.size());
    std::iota(order.begin(), order.end(), 0);
    const auto size_of = [ranges](int r) {
        const RangeCounts& c = ranges[static_cast<std::size_t>(r)];
        return c.vertex_count() + c.triangle_count();
    };
    std::stable_sort(order.begin(), order.end(), [&size_of](int a, int b) { return size_of(a) > size_of(b); });
    return order;
}

MeshLayout lay_out(std::span<RangeCounts> ranges)
{
    double bound = 0;
    for (const RangeCounts& c : ranges) bound = std::max(bound, c.sample_bound());
    for (RangeCounts& c : ranges) c.share_sample_bound(bound);
    MeshLayout layout;
    layout.offsets = scan(ranges);
    if (!ranges.empty()) {
        layout.vertex_count = layout.offsets.back().first_vertex + ranges.back().vertex_count();
        layout.triangle_count = layout.offsets.back().first_triangle + ranges.back().triangle_count();
    }
    if (layout.vertex_count >= static_cast<std::int64_t>(detail::kNoVertex)) {
        throw Error(Status::too_large, "the mesh would have " + std::to_string(layout.vertex_count) +
                                           " vertices, more than 32-bit indices can address");
    }
    return layout;
}

template <class T> RangePlan plan_ranges(const GridView<T>& grid, int threads, std::int64_t max_range_samples)
{
    const std::int64_t nz = grid.nz();
    RangePlan plan;
    plan.threads = detail::threads_for(threads, nz);
    plan.window_planes = window_range_planes(grid);
    const std::int64_t n = plan.threads;
    std::int64_t ranges = n == 1 ? 1 : std::clamp<std::int64_t>(nz / 8, n, 8 * n);
    const auto at_most = [&](std::int64_t planes) {
        if (planes > 0) ranges = std::max(ranges, (nz + planes - 1) / planes);
    };
    at_most(plan.window_planes);
    if (max_range_samples > 0) at_most(std::max<std::int64_t>(max_range_samples / std::max<std::int64_t>(grid.nx() * grid.ny(), 1), 1));
    ranges = std::clamp<std::int64_t>(ranges, 1, std::numeric_limits<int>::max() - 1);
    plan.first_planes.resize(static_cast<std::size_t>(ranges) + 1);
    for (std::int64_t r = 0; r <= ranges; ++r) plan.first_planes[static_cast<std::size_t>(r)] = nz * r / ranges;
    return plan;
}

void run_ranges(int threads, std::span<const int> order, const std::function<void(int range, int task)>& work,
                const Progress& progress, const Executor& executor)
{
    detail::Ticker ticker(progress, static_cast<std::int64_t>(order.size()));
    detail::for_each_range(std::max(threads, 1), order, executor, ticker, [&](int r, int task) {
        work(r, task);
        ticker.tick();
    });
    if (ticker.cancelled()) detail::throw_cancelled();
}

template <class T>
void emit(const GridView<T>& grid, double iso, const ExtractOptions& options, const RangeCounts& counts,
          const RangeOffsets& offsets, const MeshSpans& out)
{
    check_passes_method(options, "emit");
    detail::check_grid(grid, iso);
    if (counts.k1() > grid.nz() || counts.k0() >= counts.k1() || !detail::RangeExtractor<T>::same_rows(counts, grid)) {
        throw Error(Status::invalid_argument, "emit: the counts of planes " + range_text(counts.k0(), counts.k1()) +
                                                  " are not of this grid (" + std::to_string(grid.nx()) + "x" +
                                                  std::to_string(grid.ny()) + "x" + std::to_string(grid.nz()) +
                                                  "); expected counts from count() on the same grid");
    }
    check_block(grid.dims, out);
    detail::RangeExtractor<T>(grid, iso, options, {out.index_offset, out.whole_dims}).emit(counts, offsets, out, nullptr);
}

#define CMC33_INSTANTIATE(T)                                                                                    \
    template RangeCounts count<T>(const GridView<T>&, double, const ExtractOptions&, std::int64_t, std::int64_t);      \
    template void emit<T>(const GridView<T>&, double, const ExtractOptions&, const RangeCounts&, const RangeOffsets&, \
                          const MeshSpans&);                                                                  \
    template RangePlan plan_ranges<T>(const GridView<T>&, int, std::int64_t);
CMC33_FOR_EACH_SAMPLE_TYPE(CMC33_INSTANTIATE)
#undef CMC33_INSTANTIATE

} // namespace cmc33
