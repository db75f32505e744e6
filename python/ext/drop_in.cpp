// cmc33.marching_cubes's extraction: count, scan and emit (cmc33/passes.hpp) over ranges of sample
// planes, the ranges taken by `threads` threads in turn. Each range, once emitted and while its
// vertices are in cache, gets its values and its winding. A mask then drops the triangles of
// masked cells and the vertices no kept triangle uses, in place.

#include "drop_in.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <functional>
#include <limits>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "cmc33/passes.hpp"

namespace cmc33::python {
namespace {

// Ranges of about 16 sample planes: the stop flag is read between ranges, so a 512^2 plane range
// ends a Ctrl-C wait in tens of milliseconds, while the planes a range reads twice (its ends) stay
// a small share. At least 4 ranges per thread, as extract() does, for uneven surfaces.
constexpr std::int64_t kPlanesPerRange = 16;
constexpr std::int64_t kMinRanges = 32;
constexpr std::uint32_t kDropped = std::numeric_limits<std::uint32_t>::max();

/// Runs job(r) for r in [0, ranges) on n threads (the calling one among them), each range taken by
/// whichever thread is free. No range starts once control says stop or a job has thrown; then the
/// error of the lowest range that threw is rethrown, or Error{cancelled}. Reports the fraction
/// from + share * (ranges done / ranges) to control.
void run_ranges(int n, int ranges, Control& control, double from, double share, const std::function<void(int)>& job)
{
    std::atomic<int> next{0}, done{0};
    std::atomic<bool> failed{false};
    std::vector<std::exception_ptr> errors(static_cast<std::size_t>(ranges));
    const auto work = [&] {
        for (int r = next.fetch_add(1); r < ranges; r = next.fetch_add(1)) {
            if (failed.load(std::memory_order_relaxed) || control.stopped()) return;
            try {
                job(r);
            } catch (...) {
                errors[static_cast<std::size_t>(r)] = std::current_exception();
                failed.store(true, std::memory_order_relaxed);
            }
            control.keep_going(from + share * (done.fetch_add(1) + 1) / ranges);
        }
    };
    {
        std::vector<std::jthread> pool;
        for (int t = 1; t < n; ++t) pool.emplace_back(work);
        work();
    }
    for (const std::exception_ptr& e : errors) {
        if (e) std::rethrow_exception(e);
    }
    if (control.stopped()) throw Error(Status::cancelled, "extraction cancelled by the progress callback");
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
        const std::int64_t nz = g_.nz();
        const int n = static_cast<int>(std::clamp<std::int64_t>(resolve_threads(o_.threads), 1, nz));
        const int ranges = static_cast<int>(
            std::min(nz, std::clamp<std::int64_t>(nz / kPlanesPerRange, n, std::max<std::int64_t>(4 * n, kMinRanges))));
        const auto plane = [&](int r) { return nz * r / ranges; };

        std::vector<RangeCounts> counts(static_cast<std::size_t>(ranges));
        run_ranges(n, ranges, control, 0, 0.5, [&](int r) {
            counts[static_cast<std::size_t>(r)] = count(g_, iso_, options_, plane(r), plane(r + 1));
        });
        const std::vector<RangeOffsets> offsets = scan(counts);
        const std::int64_t nv = offsets.back().first_vertex + counts.back().vertex_count();
        const std::int64_t nt = offsets.back().first_triangle + counts.back().triangle_count();
        if (nv >= static_cast<std::int64_t>(kDropped)) {
            throw Error(Status::too_large, "the mesh would have " + std::to_string(nv) +
                                               " vertices, more than 32-bit indices can address");
        }
        DropInMesh m;
        m.positions.resize(static_cast<std::size_t>(nv) * 3);
        m.normals.resize(static_cast<std::size_t>(nv) * 3);
        m.values.resize(static_cast<std::size_t>(nv));
        m.triangles.resize(static_cast<std::size_t>(nt) * 3);
        m.vertex_count = nv;
        m.triangle_count = nt;
        run_ranges(n, ranges, control, 0.5, 0.5, [&](int r) {
            emit_range(counts[static_cast<std::size_t>(r)], offsets[static_cast<std::size_t>(r)], m);
        });
        if (o_.mask) compact(m);
        return m;
    }

private:
    /// Emits one range into m and finishes its part: values, winding, masked triangles marked.
    void emit_range(const RangeCounts& c, const RangeOffsets& at, DropInMesh& m) const
    {
        const auto fv = static_cast<std::size_t>(at.first_vertex);
        const auto ft = static_cast<std::size_t>(at.first_triangle);
        const auto nv = static_cast<std::size_t>(c.vertex_count());
        const auto nt = static_cast<std::size_t>(c.triangle_count());
        // the range's own edge ids and triangle cells: a few bytes per vertex of one range at a time
        std::vector<std::int64_t> edges(nv);
        std::vector<std::int64_t> cells(o_.mask ? nt : 0);
        MeshSpans out;
        out.positions = m.positions.data() + 3 * fv;
        out.normals = m.normals.data() + 3 * fv;
        out.triangles = m.triangles.data() + 3 * ft;
        out.vertex_edges = edges.data();
        out.triangle_cells = o_.mask ? cells.data() : nullptr;
        out.first_vertex = at.first_vertex;
        out.first_triangle = at.first_triangle;
        emit(g_, iso_, options_, c, at, out);

        for (std::size_t v = 0; v < nv; ++v) m.values[fv + v] = vertex_value(edges[v]);
        std::uint32_t* t = m.triangles.data() + 3 * ft;
        if (o_.descent) {
            for (std::size_t f = 0; f < nt; ++f) std::swap(t[3 * f + 1], t[3 * f + 2]);
        }
        if (o_.mask) {
            for (std::size_t f = 0; f < nt; ++f) {
                const Index3 cell = decode(cells[f]);
                if (!(*o_.mask)(cell[0], cell[1], cell[2])) t[3 * f] = kDropped;
            }
        }
    }

    Index3 decode(std::int64_t index) const noexcept
    {
        const std::int64_t nx = g_.nx(), ny = g_.ny();
        return {index % nx, (index / nx) % ny, index / (nx * ny)};
    }

    /// Largest minus smallest corner sample of cell (i, j, k).
    double cell_range(std::int64_t i, std::int64_t j, std::int64_t k) const noexcept
    {
        const T* p = g_.data + g_.offset(i, j, k);
        const std::int64_t sx = g_.strides[0], sy = g_.strides[1], sz = g_.strides[2];
        const T corners[8] = {p[0], p[sx], p[sy], p[sx + sy], p[sz], p[sx + sz], p[sy + sz], p[sx + sy + sz]};
        const auto [lo, hi] = std::minmax_element(std::begin(corners), std::end(corners));
        return static_cast<double>(*hi) - static_cast<double>(*lo);
    }

    /// scikit-image's value of a vertex: the largest cell_range of the kept cells that use it
    /// (an interior vertex: its cell; an edge vertex: the up to four cells around its edge).
    float vertex_value(std::int64_t edge) const noexcept
    {
        if (edge < 0) {
            const Index3 c = decode(-1 - edge);
            return static_cast<float>(cell_range(c[0], c[1], c[2]));
        }
        const auto axis = static_cast<std::size_t>(edge % 3);
        const Index3 s = decode(edge / 3);
        const std::size_t p = (axis + 1) % 3, q = (axis + 2) % 3; // the axes across the edge
        double best = 0;
        for (std::int64_t a = 0; a < 2; ++a)
            for (std::int64_t b = 0; b < 2; ++b) {
                Index3 c = s;
                c[p] -= a;
                c[q] -= b;
                if (c[p] < 0 || c[q] < 0 || c[p] > g_.dims[p] - 2 || c[q] > g_.dims[q] - 2) continue;
                if (o_.mask && !(*o_.mask)(c[0], c[1], c[2])) continue;
                best = std::max(best, cell_range(c[0], c[1], c[2]));
            }
        return static_cast<float>(best);
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
