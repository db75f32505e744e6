// cmc33.marching_cubes's extraction: count, scan and emit (cmc33/passes.hpp) over ranges of sample
// planes, the ranges taken by `threads` threads in turn. emit writes the array's axis order, the
// winding of gradient_direction and scikit-image's values itself (MeshSpans::zyx,
// reverse_winding, vertex_cell_ranges). With a mask, values count only the kept cells: each range,
// once emitted and while its triangles are in cache, gets its values from its triangles' cells
// and marks the masked cells' triangles; then those triangles and the vertices no kept triangle
// uses are dropped, in place.

#include "drop_in.hpp"

#include <algorithm>
#include <functional>
#include <limits>
#include <numeric>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "cmc33/passes.hpp"

namespace cmc33::python {
namespace {

// A stop request (Ctrl-C) is answered between ranges of sample planes, once the ranges running
// end: plan_ranges cuts them to at most this many samples (64 planes of 512^2), so that the wait
// stays short however few threads there are.
constexpr std::int64_t kStopSamples = std::int64_t{64} << 18;
constexpr std::uint32_t kDropped = std::numeric_limits<std::uint32_t>::max();

/// run_ranges() (passes.hpp) reporting from + share * (fraction of the ranges done) to control,
/// and stopping once control says so.
void run_controlled(int threads, std::span<const int> order, Control& control, double from, double share,
                    const std::function<void(int range, int thread)>& job)
{
    cmc33::run_ranges(threads, order, job, [&](double done) { return control.keep_going(from + share * done); });
}

template <class T> class DropIn {
public:
    DropIn(const GridView<T>& g, double iso, const DropInOptions& o) : g_(g), iso_(iso), o_(o)
    {
        options_.method = o.method;
        options_.normals = true;
    }

    DropInMesh run(Control& control)
    {
        const RangePlan plan = plan_ranges(g_, o_.threads, kStopSamples);
        const int n = plan.threads;
        const auto plane = [&plan](int r) { return plan.first_planes[static_cast<std::size_t>(r)]; };
        // where x is not the contiguous axis (Fortran order), each range is read through a
        // window() of about 4 MiB (passes.hpp), one buffer per thread
        std::vector<Buffer<T>> windows(static_cast<std::size_t>(plan.window_planes > 0 ? n : 0));
        const auto grid_of = [&](int r, int thread) {
            if (plan.window_planes == 0) return g_;
            return window(g_, plane(r), plane(r + 1), windows[static_cast<std::size_t>(thread)]);
        };

        std::vector<int> order(static_cast<std::size_t>(plan.ranges()));
        std::iota(order.begin(), order.end(), 0);
        std::vector<RangeCounts> counts(order.size());
        run_controlled(n, order, control, 0, 0.5, [&](int r, int thread) {
            counts[static_cast<std::size_t>(r)] = count(grid_of(r, thread), iso_, options_, plane(r), plane(r + 1));
        });
        const MeshLayout layout = lay_out(counts);
        const std::vector<RangeOffsets>& offsets = layout.offsets;
        const std::int64_t nv = layout.vertex_count, nt = layout.triangle_count;
        DropInMesh m;
        m.positions.resize(static_cast<std::size_t>(nv) * 3);
        m.normals.resize(static_cast<std::size_t>(nv) * 3);
        m.values.resize(static_cast<std::size_t>(nv));
        m.triangles.resize(static_cast<std::size_t>(nt) * 3);
        m.vertex_count = nv;
        m.triangle_count = nt;
        std::vector<std::vector<SeamValue>> seams(counts.size());
        // with a mask, per thread, the cells of its range's triangles, reused from range to range
        // (fresh memory for every range would cost a page fault per 4 KiB of it)
        std::vector<Buffer<std::int64_t>> cells(static_cast<std::size_t>(o_.mask ? n : 0));
        run_controlled(n, emit_order(counts), control, 0.5, 0.5, [&](int r, int thread) {
            const auto i = static_cast<std::size_t>(r);
            const GridView<T> g = grid_of(r, thread);
            if (o_.mask) {
                emit_masked_range(g, counts[i], offsets[i], m, cells[static_cast<std::size_t>(thread)], seams[i]);
            } else {
                emit(g, iso_, options_, counts[i], offsets[i], spans(m, offsets[i]));
            }
        });
        for (const std::vector<SeamValue>& seam : seams)
            for (const SeamValue& s : seam) m.values[s.vertex] = std::max(m.values[s.vertex], s.value);
        if (o_.mask) compact(m);
        return m;
    }

private:
    /// A value for a vertex of the next range, set once every range is done.
    struct SeamValue {
        std::uint32_t vertex;
        float value;
    };

    /// Where emit writes the range at `at` of m: positions and normals in the array's axis order,
    /// triangles wound as gradient_direction says; without a mask also the values.
    MeshSpans spans(DropInMesh& m, const RangeOffsets& at) const
    {
        const auto fv = static_cast<std::size_t>(at.first_vertex);
        const auto ft = static_cast<std::size_t>(at.first_triangle);
        MeshSpans out;
        out.positions = m.positions.data() + 3 * fv;
        out.normals = m.normals.data() + 3 * fv;
        out.triangles = m.triangles.data() + 3 * ft;
        if (!o_.mask) out.vertex_cell_ranges = m.values.data() + fv;
        out.zyx = true;
        // extract()'s triangles wind counter-clockwise around the normals in (x, y, z); written as
        // (z, y, x), a mirror image, they wind clockwise: scikit-image's 'descent'
        out.reverse_winding = !o_.descent;
        out.first_vertex = at.first_vertex;
        out.first_triangle = at.first_triangle;
        return out;
    }

    /// Emits one range into m with a mask and finishes its part: values from the kept cells,
    /// masked triangles marked.
    void emit_masked_range(const GridView<T>& g, const RangeCounts& c, const RangeOffsets& at, DropInMesh& m,
                           Buffer<std::int64_t>& cells, std::vector<SeamValue>& seam) const
    {
        const auto fv = static_cast<std::size_t>(at.first_vertex);
        const auto ft = static_cast<std::size_t>(at.first_triangle);
        const auto nv = static_cast<std::size_t>(c.vertex_count());
        const auto nt = static_cast<std::size_t>(c.triangle_count());
        cells.resize(nt); // the range's triangles' cells (emit writes them all)
        MeshSpans out = spans(m, at);
        out.triangle_cells = cells.data();
        emit(g, iso_, options_, c, at, out);

        // scikit-image's values: per vertex, the largest range among the kept cells whose
        // triangles use it. This range's triangles also use the next range's first plane:
        // those go to `seam`, so that no two ranges write one value.
        float* values = m.values.data();
        std::fill(values + fv, values + fv + nv, 0.0f);
        // Every triangle computes its cell's range, also when the triangle before it had the same
        // cell: a branch on "same cell as before" would mispredict about every other triangle,
        // and the samples are in cache.
        std::uint32_t* t = m.triangles.data() + 3 * ft;
        Decoder decode(g_.nx(), g_.ny());
        for (std::size_t f = 0; f < nt; ++f, t += 3) {
            const Index3 at_cell = decode(cells[f]);
            if (!(*o_.mask)(at_cell[0], at_cell[1], at_cell[2])) {
                t[0] = kDropped;
                continue;
            }
            const float range = static_cast<float>(cell_range(g_.data + g_.offset(at_cell[0], at_cell[1], at_cell[2])));
            for (std::size_t k = 0; k < 3; ++k) {
                const std::uint32_t v = t[k];
                if (v - fv < nv) {
                    values[v] = std::max(values[v], range);
                } else {
                    seam.push_back({v, range});
                }
            }
        }
    }

    /// (i, j, k) of a cell index i + nx * (j + ny * k). Triangles come cell row by cell row, so
    /// the row of the previous index is kept and the divisions are done once per row.
    class Decoder {
    public:
        Decoder(std::int64_t nx, std::int64_t ny) noexcept : nx_(nx), ny_(ny) {}
        Index3 operator()(std::int64_t index) noexcept
        {
            if (index < first_ || index >= first_ + nx_) {
                const std::int64_t row = index / nx_;
                first_ = row * nx_;
                j_ = row % ny_;
                k_ = row / ny_;
            }
            return {index - first_, j_, k_};
        }

    private:
        std::int64_t nx_, ny_, first_ = std::numeric_limits<std::int64_t>::min() / 2, j_ = 0, k_ = 0;
    };

    /// Largest minus smallest corner sample of the cell whose lowest corner is at p.
    double cell_range(const T* p) const noexcept
    {
        const std::int64_t sx = g_.strides[0], sy = g_.strides[1], sz = g_.strides[2];
        // pairs, then a tree: no branch (std::minmax_element's would mispredict on noisy data)
        const T a0 = p[0], a1 = p[sx], a2 = p[sy], a3 = p[sx + sy];
        const T a4 = p[sz], a5 = p[sx + sz], a6 = p[sy + sz], a7 = p[sx + sy + sz];
        const T lo = std::min(std::min(std::min(a0, a1), std::min(a2, a3)), std::min(std::min(a4, a5), std::min(a6, a7)));
        const T hi = std::max(std::max(std::max(a0, a1), std::max(a2, a3)), std::max(std::max(a4, a5), std::max(a6, a7)));
        return static_cast<double>(hi) - static_cast<double>(lo);
    }

    /// Drops the marked triangles and the vertices no kept triangle uses, keeping the order of
    /// both, in place (a vertex only moves to a lower id).
    static void compact(DropInMesh& m)
    {
        const auto nv = static_cast<std::size_t>(m.vertex_count);
        const auto nt = static_cast<std::size_t>(m.triangle_count);
        std::uint32_t* t = m.triangles.data();
        std::vector<std::uint32_t> id(nv, kDropped);
        for (std::size_t f = 0; f < nt; ++f) {
            if (t[3 * f] == kDropped) continue;
            for (std::size_t c = 0; c < 3; ++c) id[t[3 * f + c]] = 0;
        }
        std::uint32_t kept_vertices = 0;
        for (std::size_t v = 0; v < nv; ++v) {
            if (id[v] == kDropped) continue;
            const std::size_t to = kept_vertices;
            id[v] = kept_vertices++;
            for (std::size_t c = 0; c < 3; ++c) {
                m.positions[3 * to + c] = m.positions[3 * v + c];
                m.normals[3 * to + c] = m.normals[3 * v + c];
            }
            m.values[to] = m.values[v];
        }
        std::size_t kept_triangles = 0;
        for (std::size_t f = 0; f < nt; ++f) {
            if (t[3 * f] == kDropped) continue;
            for (std::size_t c = 0; c < 3; ++c) t[3 * kept_triangles + c] = id[t[3 * f + c]];
            ++kept_triangles;
        }
        m.vertex_count = kept_vertices;
        m.triangle_count = static_cast<std::int64_t>(kept_triangles);
    }

    const GridView<T> g_;
    const double iso_;
    const DropInOptions o_;
    ExtractOptions options_;
};

} // namespace

DropInMesh extract_drop_in(const Samples& samples, const Frame& frame, double iso, const DropInOptions& options,
                           Control& control)
{
    if (options.mask) {
        for (std::size_t a = 0; a < 3; ++a) {
            if (options.mask->dims[a] != samples.dims[a] - 1) {
                throw Error(Status::invalid_argument, "the cell mask has " + std::to_string(options.mask->dims[a]) +
                                                          " cells along " + "xyz"[a] + "; expected " +
                                                          std::to_string(samples.dims[a] - 1));
            }
        }
    }
    return visit(samples, frame, [&](const auto& grid) { return DropIn(grid, iso, options).run(control); });
}

} // namespace cmc33::python
