// The structured geometric check (contract in grid_check.hpp).
//
// Layers are processed in blocks, one task per block, whichever thread is free. A block builds, per
// layer, the list of its triangles sorted by cell (row j, then i), with each triangle's box and
// whether it is proper (distinct corners, not collinear); then walks the cells of each layer in
// order and tests every pair of the cell, and of the cell with its 13 neighbours that come after
// it (the next cell of the row, three of the next row, nine of the next layer), whose boxes meet.
// Results are kept per block and summed in block order: the same numbers for any thread count.
//
// In an axis-aligned frame most pairs of neighbouring cells are settled without a predicate. When
// both triangles lie in their cells' closed boxes (checked on the floats), they can meet only where
// the boxes do, in the contact (a face, an edge or a corner); and a triangle that lies on one side
// of a plane meets it in the convex hull of its corners on that plane. So each meets the contact in
// the hull of its corners that lie on it exactly (its trace): if a trace is empty the pair is
// disjoint, and if one trace is a subset of the other (by vertex id) the pair meets in what it
// shares. The other pairs take the exact test.

#include "grid_check.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <limits>
#include <mutex>
#include <string>
#include <thread>
#include <utility>

#include "cmc33/error.hpp"
#include "exact_geometry.hpp"
#include "portability.hpp"

namespace cmc33::detail {
namespace {

/// A triangle's bounding box: its corners' floats, exactly.
struct Box {
    std::array<float, 3> lo, hi;
};

bool boxes_meet(const Box& a, const Box& b)
{
    return !(a.hi[0] < b.lo[0] || b.hi[0] < a.lo[0] || a.hi[1] < b.lo[1] || b.hi[1] < a.lo[1] || a.hi[2] < b.lo[2] ||
             b.hi[2] < a.lo[2]);
}

/// One triangle of a layer, as the pair walk needs it.
struct Placed {
    std::int64_t cell;     ///< j * (nx - 1) + i
    std::int64_t triangle; ///< index into LayeredTriangles::triangles
    std::array<std::uint32_t, 3> ids; ///< its corners' vertex ids
    Box box;
    bool proper;
    /// Whether its corners lie in its cell's closed box (axis-aligned frames only); then `on[v]`
    /// says which of the cell's faces corner v lies on: bit 2a for the face at the cell's lower
    /// plane along axis a, bit 2a + 1 for the upper one.
    bool boxed = false;
    std::array<std::uint8_t, 3> on{};
    /// Bit offset_bit(d) set when the triangle may meet the contact with the neighbour at offset d:
    /// a corner lies on it (boxed), or always (not boxed).
    std::uint32_t touches = ~std::uint32_t{0};
    bool operator<(const Placed& o) const { return cell != o.cell ? cell < o.cell : triangle < o.triangle; }
};

/// The bit of neighbour offset d (one step or none per axis) in Placed::touches.
constexpr unsigned offset_bit(int dx, int dy, int dz)
{
    return static_cast<unsigned>((dx + 1) + 3 * (dy + 1) + 9 * (dz + 1));
}

/// The faces (Placed::on bits) of a cell that hold its contact with the cell at offset d.
constexpr unsigned contact_faces(int dx, int dy, int dz)
{
    const int d[3] = {dx, dy, dz};
    unsigned faces = 0;
    for (unsigned axis = 0; axis < 3; ++axis)
        if (d[axis] != 0) faces |= 1u << (2 * axis + (d[axis] > 0 ? 1 : 0));
    return faces;
}

/// For each set of faces a corner lies on (Placed::on), the offsets whose contact holds it.
constexpr std::array<std::uint32_t, 64> kContactsOf = [] {
    std::array<std::uint32_t, 64> table{};
    for (unsigned on = 0; on < 64; ++on)
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const unsigned need = contact_faces(dx, dy, dz);
                    if (need != 0 && (on & need) == need) table[on] |= 1u << offset_bit(dx, dy, dz);
                }
    return table;
}();

/// The triangles of one layer sorted by cell, with where each row of cells starts.
struct Layer {
    std::vector<Placed> placed;
    std::vector<std::uint32_t> cell_start; ///< per cell j * (nx - 1) + i its first entry, and the end
};

} // namespace

void for_each_block(std::int64_t blocks, int threads, const std::function<void(std::int64_t, const std::atomic<bool>&)>& body,
                    const std::function<bool()>& tick)
{
    std::atomic<std::int64_t> next{0};
    std::atomic<std::int64_t> finished{0};
    std::atomic<bool> stop{false};
    // the calling thread waits for the last block on this, not by polling: a sleep's latency
    // would be paid at the end of every check
    std::mutex waiting;
    std::condition_variable woken;
    const auto wake = [&] {
        const std::lock_guard<std::mutex> lock(waiting);
        woken.notify_all();
    };
    const auto take = [&] {
        for (std::int64_t b; !stop.load(std::memory_order_relaxed) && (b = next++) < blocks;) {
            body(b, stop);
            if (++finished == blocks) wake();
        }
    };
    const int helpers = static_cast<int>(std::min<std::int64_t>(threads, blocks)) - 1;
    std::vector<std::exception_ptr> errors(static_cast<std::size_t>(std::max(helpers, 0)) + 1);
    std::vector<std::thread> pool;
    for (int t = 0; t < helpers; ++t) {
        pool.emplace_back([&, t] {
            try {
                take();
            } catch (...) {
                errors[static_cast<std::size_t>(t) + 1] = std::current_exception();
                stop = true;
                wake();
            }
        });
    }
    bool cancelled = false;
    try {
        // the calling thread takes blocks too, and asks `tick` between them and while it waits
        for (std::int64_t b; !stop.load(std::memory_order_relaxed) && (b = next++) < blocks;) {
            body(b, stop);
            ++finished;
            if (!tick()) {
                cancelled = true;
                stop = true;
            }
        }
        while (!stop.load() && finished.load() < blocks) {
            {
                std::unique_lock<std::mutex> lock(waiting);
                woken.wait_for(lock, std::chrono::milliseconds(10),
                               [&] { return stop.load() || finished.load() >= blocks; });
            }
            if (!tick()) {
                cancelled = true;
                stop = true;
            }
        }
    } catch (...) {
        errors[0] = std::current_exception();
        stop = true;
    }
    for (auto& th : pool) th.join();
    for (auto& e : errors)
        if (e) std::rethrow_exception(e);
    if (cancelled || !tick()) throw Error(Status::cancelled, "the mesh check was cancelled");
}

namespace {

class Checker {
public:
    Checker(const LayeredTriangles& mesh, std::int64_t own, const GridCheckOptions& options)
        : m_(mesh), own_(own), options_(options)
    {
        cells_x_ = m_.dims[0] - 1;
        cells_y_ = m_.dims[1] - 1;
        // index = M^-1 (p - origin); M^-1 is the transpose of inverse_transpose(M)
        const Mat3 it = inverse_transpose(m_.frame);
        for (std::size_t r = 0; r < 3; ++r)
            for (std::size_t c = 0; c < 3; ++c) to_index_[r][c] = it[c][r];
        set_planes();
    }

    GridGeometry run()
    {
        validate();
        const std::int64_t layers = own_;
        GridGeometry total;
        if (layers <= 0) return total;
        const int threads = std::max(1, options_.threads);
        // blocks of a few layers: enough of them to balance threads, few enough that the layer
        // each block builds twice (its last one's neighbour) stays cheap
        const std::int64_t blocks = std::clamp<std::int64_t>(layers / 4, 1, 16 * std::int64_t{threads});
        std::vector<GridGeometry> parts(static_cast<std::size_t>(blocks));
        std::atomic<std::int64_t> done{0};
        for_each_block(
            blocks, threads,
            [&](std::int64_t b, const std::atomic<bool>& stop) {
                const std::int64_t z0 = layers * b / blocks, z1 = layers * (b + 1) / blocks;
                parts[static_cast<std::size_t>(b)] = check_block(z0, z1, stop, done);
            },
            [&] { return !options_.progress || options_.progress(done.load()); });
        for (GridGeometry& p : parts) {
            total.zero_area_triangles += p.zero_area_triangles;
            total.intersecting_pairs += p.intersecting_pairs;
            total.strays += p.strays;
            total.coincident += p.coincident;
            total.examples.insert(total.examples.end(), p.examples.begin(), p.examples.end());
        }
        std::sort(total.examples.begin(), total.examples.end());
        if (total.examples.size() > options_.examples) total.examples.resize(options_.examples);
        return total;
    }

private:
    void validate() const
    {
        const std::size_t needed = static_cast<std::size_t>(own_ + 1);
        if (own_ < 0 || m_.layer_first.size() < needed || m_.triangles.size() % 3 != 0 || m_.dims[0] < 2 ||
            m_.dims[1] < 2 || m_.dims[2] < 2) {
            throw Error(Status::invalid_argument, "grid_geometry: the layers do not describe the triangles");
        }
        for (std::size_t i = 0; i + 1 < m_.layer_first.size(); ++i) {
            if (m_.layer_first[i] < 0 || m_.layer_first[i] > m_.layer_first[i + 1] ||
                static_cast<std::size_t>(m_.layer_first[i + 1]) > m_.triangles.size() / 3) {
                throw Error(Status::invalid_argument, "grid_geometry: layer " + std::to_string(i) +
                                                          " does not lie within the triangles");
            }
        }
    }

    /// point() of vertex v, checked: an id among the positions, finite coordinates.
    CMC33_ALWAYS_INLINE Point3 position(std::uint32_t v) const
    {
        const std::int64_t local = static_cast<std::int64_t>(v) - m_.first_vertex;
        if (local < 0 || static_cast<std::size_t>(3 * local + 2) >= m_.positions.size()) [[unlikely]]
            refuse_vertex(v, false);
        const float* p = &m_.positions[static_cast<std::size_t>(3 * local)];
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) [[unlikely]]
            refuse_vertex(v, true);
        return point(v);
    }

    /// position()'s errors, out of the loop that calls it.
    [[noreturn]] CMC33_NOINLINE void refuse_vertex(std::uint32_t v, bool not_finite) const
    {
        if (not_finite) {
            throw Error(Status::invalid_argument, "grid_geometry: vertex " + std::to_string(v) +
                                                      " has a coordinate that is not a finite number");
        }
        throw Error(Status::invalid_argument, "grid_geometry: vertex " + std::to_string(v) + " is not among the " +
                                                  std::to_string(m_.positions.size() / 3) + " positions given");
    }

    /// The position of a vertex that build() has already checked.
    Point3 point(std::uint32_t v) const
    {
        // + 0.0 turns -0 into +0, as mesh_geometry() welds them
        const float* p = &m_.positions[static_cast<std::size_t>(3 * (static_cast<std::int64_t>(v) - m_.first_vertex))];
        return {static_cast<double>(p[0]) + 0.0, static_cast<double>(p[1]) + 0.0, static_cast<double>(p[2]) + 0.0};
    }

    Point3 index_of(const Point3& p) const
    {
        const double d[3] = {p[0] - m_.origin[0], p[1] - m_.origin[1], p[2] - m_.origin[2]};
        if (axis_aligned_) return {to_index_[0][0] * d[0], to_index_[1][1] * d[1], to_index_[2][2] * d[2]};
        Point3 q{};
        for (std::size_t r = 0; r < 3; ++r) q[r] = to_index_[r][0] * d[0] + to_index_[r][1] * d[1] + to_index_[r][2] * d[2];
        return q;
    }

    const std::uint32_t* corners(std::int64_t t) const { return &m_.triangles[static_cast<std::size_t>(3 * t)]; }

    /// The grid's planes in world coordinates, as extract() rounds them (origin + step * index, to
    /// float), for an axis-aligned frame whose planes strictly increase or decrease; otherwise
    /// none, and every pair takes the exact test.
    void set_planes()
    {
        for (std::size_t r = 0; r < 3; ++r)
            for (std::size_t c = 0; c < 3; ++c)
                if (r != c && m_.frame[r][c] != 0) return;
        std::array<std::vector<float>, 3> planes;
        for (std::size_t a = 0; a < 3; ++a) {
            const double step = m_.frame[a][a];
            if (!std::isfinite(step) || step == 0) return;
            auto& p = planes[a];
            p.resize(static_cast<std::size_t>(m_.dims[a]));
            for (std::size_t i = 0; i < p.size(); ++i) {
                p[i] = static_cast<float>(m_.origin[a] + step * static_cast<double>(i));
                if (!std::isfinite(p[i])) return;
                // strictly monotone: cells that are not neighbours have disjoint boxes
                if (i > 0 && !(step > 0 ? p[i - 1] < p[i] : p[i - 1] > p[i])) return;
            }
        }
        planes_ = std::move(planes);
        axis_aligned_ = true;
    }

    /// The cell [c, c + 1) of `cells` along an axis that holds index coordinate x, the nearest one
    /// for x outside them (0 for NaN).
    static std::int64_t cell_at(double x, std::int64_t cells)
    {
        if (!(x >= 1)) return 0;
        if (x >= static_cast<double>(cells - 1)) return cells - 1;
        return static_cast<std::int64_t>(x); // x >= 1: truncation is floor
    }

    /// Whether corners p of cell (i, j, k) lie in its closed box; if so, sets `on` (see Placed).
    bool place_in_box(const std::array<Point3, 3>& p, std::int64_t i, std::int64_t j, std::int64_t k,
                      std::array<std::uint8_t, 3>& on) const
    {
        const std::int64_t cell[3] = {i, j, k};
        unsigned bits[3] = {0, 0, 0};
        bool in = true;
        // without branches on the comparisons, whose outcomes follow no pattern
        for (std::size_t a = 0; a < 3; ++a) {
            const auto at = static_cast<std::size_t>(cell[a]);
            if (at + 1 >= planes_[a].size()) return false;
            const double low = static_cast<double>(planes_[a][at]), high = static_cast<double>(planes_[a][at + 1]);
            const double lo = low < high ? low : high, hi = low < high ? high : low; // both finite
            for (std::size_t v = 0; v < 3; ++v) {
                const double x = p[v][a];
                in &= (x >= lo) & (x <= hi);
                bits[v] |= static_cast<unsigned>(x == low) << (2 * a) | static_cast<unsigned>(x == high) << (2 * a + 1);
            }
        }
        for (std::size_t v = 0; v < 3; ++v) on[v] = static_cast<std::uint8_t>(bits[v]);
        return in;
    }

    /// Layer z's triangles (z relative to k0), placed in their cells; counts strays, coincident
    /// corners of one triangle and (when `own`) zero-area triangles into `out`.
    void build(std::int64_t z, bool own, Layer& layer, GridGeometry& out) const
    {
        const std::int64_t t0 = m_.layer_first[static_cast<std::size_t>(z)];
        const std::int64_t t1 = m_.layer_first[static_cast<std::size_t>(z) + 1];
        layer.placed.clear();
        layer.placed.reserve(static_cast<std::size_t>(t1 - t0));
        const double kz = static_cast<double>(m_.k0 + z);
        for (std::int64_t t = t0; t < t1; ++t) {
            const std::uint32_t* c = corners(t);
            const std::array<Point3, 3> p{position(c[0]), position(c[1]), position(c[2])};
            Point3 q[3];
            double cx = 0, cy = 0;
            for (int v = 0; v < 3; ++v) {
                q[v] = index_of(p[static_cast<std::size_t>(v)]);
                cx += q[v][0];
                cy += q[v][1];
            }
            const std::int64_t ci = cell_at(cx / 3, cells_x_), cj = cell_at(cy / 3, cells_y_);
            // written in place: a copy built on the stack field by field and then stored whole
            // stalls on every triangle (its wide loads wait for the narrow stores)
            Placed& e = layer.placed.emplace_back();
            e.cell = cj * cells_x_ + ci;
            e.triangle = t;
            e.ids = {c[0], c[1], c[2]};
            if (axis_aligned_) e.boxed = place_in_box(p, ci, cj, m_.k0 + z, e.on);
            if (e.boxed) e.touches = kContactsOf[e.on[0]] | kContactsOf[e.on[1]] | kContactsOf[e.on[2]];
            // a triangle in its cell's box is within the margin too
            bool inside = e.boxed;
            if (!inside) {
                const double lo[3] = {static_cast<double>(ci) - kCellMargin, static_cast<double>(cj) - kCellMargin,
                                      kz - kCellMargin};
                inside = true;
                for (int v = 0; v < 3; ++v)
                    for (std::size_t a = 0; a < 3; ++a) {
                        // NaN-safe: a corner that compares false is outside
                        if (!(q[v][a] >= lo[a] && q[v][a] <= lo[a] + 1 + 2 * kCellMargin)) inside = false;
                    }
            }
            const bool repeated = c[0] == c[1] || c[1] == c[2] || c[0] == c[2];
            e.proper = !repeated && !collinear(p[0], p[1], p[2]);
            if (own) {
                if (!inside) ++out.strays;
                // distinct ids at one position, in a collapsed triangle too
                for (int v = 0; v < 3; ++v) {
                    const auto a = static_cast<std::size_t>(v), b = static_cast<std::size_t>((v + 1) % 3);
                    if (c[a] != c[b] && p[a] == p[b]) ++out.coincident;
                }
                if (!e.proper) ++out.zero_area_triangles;
            }
            for (std::size_t a = 0; a < 3; ++a) {
                // the doubles hold floats exactly
                e.box.lo[a] = static_cast<float>(std::min({p[0][a], p[1][a], p[2][a]}));
                e.box.hi[a] = static_cast<float>(std::max({p[0][a], p[1][a], p[2][a]}));
            }
        }
        // extract() writes triangles cell by cell: nearly sorted already
        if (!std::is_sorted(layer.placed.begin(), layer.placed.end())) std::sort(layer.placed.begin(), layer.placed.end());
        const std::int64_t cells = cells_x_ * cells_y_;
        if (layer.placed.size() >= std::numeric_limits<std::uint32_t>::max()) {
            throw Error(Status::too_large, "grid_geometry: a cell layer holds more triangles than 32-bit offsets count");
        }
        layer.cell_start.resize(static_cast<std::size_t>(cells) + 1);
        // cells (previous one's, this one's] start where this one's entries do: filled in runs,
        // as most cells are empty
        auto* start = layer.cell_start.data();
        std::int64_t filled = 0; // cell_start[0, filled) is set
        for (std::size_t at = 0; at < layer.placed.size(); ++at) {
            const std::int64_t c = layer.placed[at].cell;
            if (c < filled) continue;
            std::fill(start + filled, start + c + 1, static_cast<std::uint32_t>(at));
            filled = c + 1;
        }
        std::fill(start + filled, start + cells + 1, static_cast<std::uint32_t>(layer.placed.size()));
    }

    /// The corners of a boxed triangle that lie on a contact (faces `need` of its cell): the hull
    /// of their points is where it meets the contact. n = -1 for a triangle that is not boxed.
    struct Trace {
        std::uint32_t ids[3];
        int n;
    };
    static constexpr std::size_t kTracedGroup = 16;

    void trace(const Placed& p, unsigned need, Trace& t) const
    {
        t.n = -1;
        if (!p.boxed) return;
        t.n = 0;
        for (std::size_t v = 0; v < 3; ++v) { // without branches, as in place_in_box()
            t.ids[t.n] = p.ids[v];
            t.n += (p.on[v] & need) == need ? 1 : 0;
        }
    }

    /// Whether every id of x is one of y's.
    static bool within(const Trace& x, const Trace& y)
    {
        for (int u = 0; u < x.n; ++u) {
            const std::uint32_t id = x.ids[u];
            bool found = false;
            for (int w = 0; w < y.n; ++w) found = found || y.ids[w] == id;
            if (!found) return false;
        }
        return true;
    }

    /// test_neighbours()'s first decisions on two boxed triangles' traces: a pair with an empty
    /// trace is disjoint, and one whose trace lies within the other's meets in what they share.
    static bool settled(const Trace& a, const Trace& b)
    {
        if (a.n < 0 || b.n < 0) return false;
        return a.n == 0 || b.n == 0 || within(a, b) || within(b, a);
    }

    /// Tests the pair (a, b) of triangles of neighbouring cells, given their traces on the contact
    /// of their cells (trace()); counts what it finds into `out`. Its caller has passed over the
    /// settled pairs (settled(): a trace within the other meets in the hull of what it shares;
    /// distinct ids at one position lie in both traces, in one triangle, which build() counts).
    void test_neighbours(const Placed& a, const Placed& b, const Trace& ta, const Trace& tb, GridGeometry& out) const
    {
        if (ta.n < 0 || tb.n < 0) return test_pair(a, b, out);
        const int na = ta.n, nb = tb.n;
        const std::uint32_t* trace_a = ta.ids;
        const std::uint32_t* trace_b = tb.ids;
        int common = 0; // proper triangles below: no id repeated
        for (int x = 0; x < na; ++x) common += std::find(trace_b, trace_b + nb, trace_a[x]) != trace_b + nb ? 1 : 0;
        for (int x = 0; x < na; ++x)
            for (int y = 0; y < nb; ++y)
                if (trace_a[x] != trace_b[y] && point(trace_a[x]) == point(trace_b[y])) ++out.coincident;
        if (!a.proper || !b.proper) return;
        // two points of distinct ids: they meet only if the points coincide, counted above
        if (na == 1 && nb == 1) return;
        // segment pq against segment qr, or point p against segment qr: not collinear, they meet
        // only in q, or not at all
        if (nb == 2 && (na == 1 || (na == 2 && common == 1))) {
            std::uint32_t p = trace_a[0];
            if (na == 2 && (p == trace_b[0] || p == trace_b[1])) p = trace_a[1];
            if (!collinear(point(p), point(trace_b[0]), point(trace_b[1]))) return;
        } else if (na == 2 && nb == 1) {
            if (!collinear(point(trace_b[0]), point(trace_a[0]), point(trace_a[1]))) return;
        }
        test_pair(a, b, out, false);
    }

    /// Tests the pair (a, b) of different triangles; counts what it finds into `out` (coincident
    /// corners too, unless the caller has). The rare path of the pair walk: not inlined, so that
    /// the walk's loops stay small.
    CMC33_NOINLINE void test_pair(const Placed& a, const Placed& b, GridGeometry& out, bool count_coincident = true) const
    {
        if (!boxes_meet(a.box, b.box)) return;
        const std::uint32_t* a_ids = a.ids.data();
        const std::uint32_t* b_ids = b.ids.data();
        const std::array<Point3, 3> a_points{point(a_ids[0]), point(a_ids[1]), point(a_ids[2])};
        const std::array<Point3, 3> b_points{point(b_ids[0]), point(b_ids[1]), point(b_ids[2])};
        // corners of b that a has too (by id), and distinct ids at one position
        int match[3] = {-1, -1, -1};
        int shared = 0;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                const auto ui = static_cast<std::size_t>(i), uj = static_cast<std::size_t>(j);
                if (a_ids[ui] == b_ids[uj]) {
                    match[i] = j;
                    ++shared;
                } else if (count_coincident && a_points[ui] == b_points[uj]) {
                    ++out.coincident;
                }
            }
        if (!a.proper || !b.proper) return;
        // shared corners first, in the same order in both
        std::array<Point3, 3> pa{}, pb{};
        int at = 0;
        bool used[3] = {false, false, false};
        for (int i = 0; i < 3; ++i)
            if (match[i] >= 0) {
                pa[static_cast<std::size_t>(at)] = a_points[static_cast<std::size_t>(i)];
                pb[static_cast<std::size_t>(at)] = b_points[static_cast<std::size_t>(match[i])];
                used[match[i]] = true;
                ++at;
            }
        for (int i = 0, ka = at, kb = at; i < 3; ++i) {
            if (match[i] < 0) pa[static_cast<std::size_t>(ka++)] = a_points[static_cast<std::size_t>(i)];
            if (!used[i]) pb[static_cast<std::size_t>(kb++)] = b_points[static_cast<std::size_t>(i)];
        }
        const bool meets = shared == 3 || triangles_meet_improperly(pa, pb, shared);
        if (!meets) return;
        ++out.intersecting_pairs;
        const std::int64_t x = m_.first_triangle + a.triangle, y = m_.first_triangle + b.triangle;
        out.examples.push_back({std::min(x, y), std::max(x, y)});
        if (out.examples.size() > 4 * options_.examples + 64) {
            std::sort(out.examples.begin(), out.examples.end());
            out.examples.resize(options_.examples);
        }
    }

    /// Entries of `layer` in cell (i, j), none outside the grid.
    std::pair<const Placed*, const Placed*> cell_of(const Layer& layer, std::int64_t i, std::int64_t j) const
    {
        if (j < 0 || j >= cells_y_ || i < 0 || i >= cells_x_) return {nullptr, nullptr};
        const auto c = static_cast<std::size_t>(j * cells_x_ + i);
        return {layer.placed.data() + layer.cell_start[c], layer.placed.data() + layer.cell_start[c + 1]};
    }

    /// Every pair of `own` (layer z) with itself and with `above` (layer z + 1, or null).
    void walk(const Layer& own, const Layer* above, GridGeometry& out) const
    {
        const auto& placed = own.placed;
        for (std::size_t g = 0; g < placed.size();) {
            std::size_t h = g + 1;
            while (h < placed.size() && placed[h].cell == placed[g].cell) ++h;
            const std::int64_t cell = placed[g].cell, j = cell / cells_x_, i = cell % cells_x_;
            std::uint32_t group_touches = 0;
            for (std::size_t a = g; a < h; ++a) group_touches |= placed[a].touches;
            // the neighbour at offset d: only the pairs whose traces on the contact are both
            // non-empty can meet (test_neighbours)
            const auto with = [&](const Layer& layer, int di, int dj, int dk) {
                const std::uint32_t bit_a = 1u << offset_bit(di, dj, dk), bit_b = 1u << offset_bit(-di, -dj, -dk);
                if ((group_touches & bit_a) == 0) return;
                const unsigned need_a = contact_faces(di, dj, dk), need_b = contact_faces(-di, -dj, -dk);
                const auto range = cell_of(layer, i + di, j + dj);
                // the group's traces once, not once per pair: most pairs are settled by them
                const bool traced = h - g <= kTracedGroup;
                Trace traces[kTracedGroup], ta, tb;
                if (traced)
                    for (std::size_t a = g; a < h; ++a) trace(placed[a], need_a, traces[a - g]);
                for (const Placed* b = range.first; b != range.second; ++b) {
                    if ((b->touches & bit_b) == 0) continue;
                    trace(*b, need_b, tb);
                    for (std::size_t a = g; a < h; ++a) {
                        if ((placed[a].touches & bit_a) == 0) continue;
                        if (!traced) trace(placed[a], need_a, ta);
                        const Trace& x = traced ? traces[a - g] : ta;
                        if (!settled(x, tb)) test_neighbours(placed[a], *b, x, tb, out);
                    }
                }
            };
            for (std::size_t a = g; a < h; ++a)
                for (std::size_t b = a + 1; b < h; ++b) test_pair(placed[a], placed[b], out);
            // the cells after this one: (i + 1, j), (i - 1 .. i + 1, j + 1), and the nine above
            with(own, 1, 0, 0);
            for (int di = -1; di <= 1; ++di) with(own, di, 1, 0);
            if (above) {
                for (int dj = -1; dj <= 1; ++dj)
                    for (int di = -1; di <= 1; ++di) with(*above, di, dj, 1);
            }
            g = h;
        }
    }

    GridGeometry check_block(std::int64_t z0, std::int64_t z1, const std::atomic<bool>& stop,
                             std::atomic<std::int64_t>& done) const
    {
        GridGeometry out;
        Layer current, next;
        build(z0, true, current, out);
        const std::int64_t available = static_cast<std::int64_t>(m_.layer_first.size()) - 1;
        for (std::int64_t z = z0; z < z1; ++z) {
            if (stop.load(std::memory_order_relaxed)) break;
            const bool has_above = z + 1 < available;
            if (has_above) build(z + 1, z + 1 < z1, next, out);
            walk(current, has_above ? &next : nullptr, out);
            std::swap(current, next);
            ++done;
        }
        return out;
    }

    const LayeredTriangles& m_;
    std::int64_t own_;
    GridCheckOptions options_;
    std::int64_t cells_x_ = 1, cells_y_ = 1;
    Mat3 to_index_{};
    bool axis_aligned_ = false;
    std::array<std::vector<float>, 3> planes_; ///< set_planes()
};

} // namespace

GridGeometry grid_geometry(const LayeredTriangles& mesh, std::int64_t own, const GridCheckOptions& options)
{
    return Checker(mesh, own, options).run();
}

} // namespace cmc33::detail
