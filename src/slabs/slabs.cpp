// Extraction of a range of planes slab by slab (contract in slabs.hpp).

#include "slabs.hpp"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cctype>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <limits>
#include <mutex>
#include <numeric>
#include <thread>
#include <type_traits>
#include <utility>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "cmc33/error.hpp"
#include "cmc33/mesh.hpp"
#include "cmc33/passes.hpp"
#include "grid_check.hpp"
#include "mesh_formats.hpp"
#include "parallel.hpp"
#include "plural.hpp"

namespace cmc33::slabs {

namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// Planes a slab's buffer holds beyond its own on each side: emit() reads one for normals, and
/// the neighbouring cell layers the slab emits for its analysis read one more.
constexpr std::int64_t kHalo = 2;

/// Bytes per vertex and per triangle of a slab while it is emitted, written and analysed: the
/// mesh arrays (12 per vertex for positions, 12 more for normals; 12 per triangle), and for the
/// analysis, per vertex and triangle of the slab with the cell layers on either side, the combined
/// copy and the working memory of mesh_geometry() (welded points, boxes, bucket entries) and
/// SeamTopology (peak RSS on uniform noise, the most triangles per cell: about 60 per vertex and
/// 150 per triangle), with a margin; without the analysis, the arrays and a margin.
constexpr std::uint64_t kBytesPerVertex = 80, kBytesPerTriangle = 190;
constexpr std::uint64_t kBytesPerVertexBare = 18, kBytesPerTriangleBare = 18;
/// Bytes of the limit left for the process itself (code, libraries, stacks, the allocator's own).
constexpr std::uint64_t kProcessBytes = std::uint64_t{12} << 20;

std::uint64_t pieces(std::uint64_t bytes, std::size_t piece) { return (bytes + piece - 1) / piece; }

/// A window of the volume: planes [lo, hi) held in a buffer.
struct Window {
    std::int64_t lo = 0, hi = 0;
};

/// Reads windows in order through two buffers: the next one while the caller works on the
/// current one. Planes the next window shares with the current one are copied, not read again,
/// so a compressed stream is inflated once per pass.
class PlaneStream {
public:
    PlaneStream(io::detail::PlaneReader& reader, std::vector<Window> windows, std::byte* const buffers[2])
        : reader_(reader), windows_(std::move(windows)), plane_(reader.layout().plane_bytes()),
          buffers_{buffers[0], buffers[1]}, thread_([this] { load_all(); })
    {
    }
    ~PlaneStream()
    {
        {
            const std::lock_guard<std::mutex> lock(mutex_);
            stop_ = true;
        }
        changed_.notify_all();
        thread_.join();
    }
    PlaneStream(const PlaneStream&) = delete;
    PlaneStream& operator=(const PlaneStream&) = delete;

    /// Planes read from the file so far (after the last window: all of them).
    std::int64_t planes_read()
    {
        const std::lock_guard<std::mutex> lock(mutex_);
        return planes_read_;
    }
    /// The planes of the next window; the previous window's buffer is given back.
    const std::byte* next()
    {
        std::unique_lock<std::mutex> lock(mutex_);
        ++current_;
        changed_.notify_all();
        changed_.wait(lock, [&] { return loaded_ > current_ || error_; });
        if (loaded_ <= current_) std::rethrow_exception(error_);
        return buffers_[current_ % 2];
    }

private:
    void load_all()
    {
        try {
            for (std::size_t i = 0; i < windows_.size(); ++i) {
                {
                    // window i overwrites the buffer of window i - 2: wait until the caller left it
                    std::unique_lock<std::mutex> lock(mutex_);
                    changed_.wait(lock, [&] { return stop_ || i < 2 || current_ >= static_cast<std::int64_t>(i) - 1; });
                    if (stop_) return;
                }
                const std::int64_t planes = load(i);
                const std::lock_guard<std::mutex> lock(mutex_);
                planes_read_ += planes;
                loaded_ = static_cast<std::int64_t>(i) + 1;
                changed_.notify_all();
            }
        } catch (...) {
            const std::lock_guard<std::mutex> lock(mutex_);
            error_ = std::current_exception();
            changed_.notify_all();
        }
    }
    /// Fills window i's buffer; returns the number of planes read from the file.
    std::int64_t load(std::size_t i)
    {
        const Window w = windows_[i];
        std::byte* out = buffers_[i % 2];
        std::int64_t from = w.lo;
        if (i > 0) {
            const Window p = windows_[i - 1];
            const std::int64_t shared_end = std::min(p.hi, w.hi);
            if (w.lo >= p.lo && w.lo < shared_end) {
                std::memcpy(out, buffers_[(i - 1) % 2] + static_cast<std::uint64_t>(w.lo - p.lo) * plane_,
                            static_cast<std::size_t>(static_cast<std::uint64_t>(shared_end - w.lo) * plane_));
                from = shared_end;
            }
        }
        if (from >= w.hi) return 0;
        reader_.read(from, w.hi, out + static_cast<std::uint64_t>(from - w.lo) * plane_);
        return w.hi - from;
    }

    io::detail::PlaneReader& reader_;
    std::vector<Window> windows_;
    std::uint64_t plane_;
    std::byte* buffers_[2];
    std::mutex mutex_;
    std::condition_variable changed_;
    std::int64_t current_ = -1, loaded_ = 0;
    std::int64_t planes_read_ = 0;
    bool stop_ = false;
    std::exception_ptr error_;
    std::thread thread_; // last: started once the rest is set up
};

/// A slab of planes [a, b) and what its count found.
struct Slab {
    std::int64_t a = 0, b = 0;
    std::int64_t vertices = 0, triangles = 0;
};

/// The windows of the plan and the slabs in each.
struct Part {
    Window window;
    std::vector<Slab> slabs;
};

template <class T> GridView<T> window_view(const std::byte* buffer, const Window& w, const io::detail::Grid& g)
{
    // The view's data pointer stands for sample (0, 0, 0), which lies before the buffer: only the
    // window's planes are ever read through it (passes.hpp says which planes each pass reads).
    const std::uint64_t skip = static_cast<std::uint64_t>(w.lo) * static_cast<std::uint64_t>(g.dims[0]) *
                               static_cast<std::uint64_t>(g.dims[1]) * sizeof(T);
    const auto* data = reinterpret_cast<const T*>(reinterpret_cast<std::uintptr_t>(buffer) - skip);
    return GridView<T>::dense(data, g.dims, g.spacing, g.origin, g.direction);
}

void add_stats(ExtractStats& to, const ExtractStats& from)
{
    for (std::size_t s = 0; s < to.cells_per_subcase.size(); ++s) to.cells_per_subcase[s] += from.cells_per_subcase[s];
}

/// Non-finite samples of planes [a, b): how many, and the first (z, then y, then x).
template <class T> void scan_non_finite(const GridView<T>& g, std::int64_t a, std::int64_t b, RangeTotals& t)
{
    if constexpr (std::is_floating_point_v<T>) {
        for (std::int64_t k = a; k < b; ++k)
            for (std::int64_t j = 0; j < g.ny(); ++j)
                for (std::int64_t i = 0; i < g.nx(); ++i) {
                    if (std::isfinite(g(i, j, k))) continue;
                    if (t.non_finite++ == 0) t.first_non_finite = {i, j, k};
                }
    }
}

/// Stages a range's vertex and face records and writes them in pieces.
class RecordWriter {
public:
    RecordWriter(ByteSink* sink, const PlyLayout& layout, std::int64_t first_vertex, std::int64_t first_triangle,
                 std::size_t piece)
        : sink_(sink), vertices_(layout.vertex_offset(first_vertex), sink ? piece : 0),
          faces_(layout.face_offset(first_triangle), sink ? piece : 0)
    {
    }
    void vertices(const float* positions, const float* normals, std::size_t n)
    {
        if (!sink_) return;
        std::byte record[24];
        const std::size_t size = normals ? 24 : 12;
        for (std::size_t v = 0; v < n; ++v) {
            std::memcpy(record, positions + 3 * v, 12);
            if (normals) std::memcpy(record + 12, normals + 3 * v, 12);
            if constexpr (std::endian::native == std::endian::big) swap_words(record, size / 4);
            append(vertices_, record, size);
        }
    }
    void faces(const std::uint32_t* triangles, std::size_t n)
    {
        if (!sink_) return;
        std::byte record[13];
        record[0] = std::byte{3};
        for (std::size_t t = 0; t < n; ++t) {
            std::memcpy(record + 1, triangles + 3 * t, 12);
            if constexpr (std::endian::native == std::endian::big) swap_words(record + 1, 3);
            append(faces_, record, 13);
        }
    }
    void flush()
    {
        if (!sink_) return;
        write(vertices_);
        write(faces_);
    }

private:
    /// One stream of records: the next file offset and the bytes staged for it.
    struct Stage {
        Stage(std::uint64_t offset, std::size_t piece) : at(offset), bytes(piece) {}
        std::uint64_t at;
        std::vector<std::byte> bytes;
        std::size_t used = 0;
    };
    static void swap_words(std::byte* p, std::size_t n)
    {
        for (std::size_t w = 0; w < n; ++w) std::reverse(p + 4 * w, p + 4 * w + 4);
    }
    void append(Stage& s, const std::byte* record, std::size_t n)
    {
        if (s.bytes.size() - s.used >= n) { // the usual case
            std::memcpy(s.bytes.data() + s.used, record, n);
            s.used += n;
            if (s.used == s.bytes.size()) write(s);
            return;
        }
        // a record straddling two pieces: the pieces are cut by bytes, not records
        while (n > 0) {
            const std::size_t k = std::min(s.bytes.size() - s.used, n);
            std::memcpy(s.bytes.data() + s.used, record, k);
            s.used += k, record += k, n -= k;
            if (s.used == s.bytes.size()) write(s);
        }
    }
    void write(Stage& s)
    {
        if (s.used == 0) return;
        sink_->write_at(s.at, std::span<const std::byte>(s.bytes.data(), s.used));
        s.at += s.used;
        s.used = 0;
    }
    ByteSink* sink_;
    Stage vertices_, faces_;
};

/// Own vertices' twins among the vertices of the slab and of the layers on either side: the
/// vertex range [first, first + count) of `positions` (3 floats per vertex, all the slab's
/// combined vertices in id order) is the slab's own.
void count_twins(const std::vector<float>& positions, std::size_t first, std::size_t count, GeometryPart& part)
{
    const std::size_t n = positions.size() / 3;
    std::vector<std::uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    const auto key = [&](std::uint32_t v) {
        const float* p = &positions[3 * static_cast<std::size_t>(v)];
        return std::array<float, 3>{p[0], p[1], p[2]};
    };
    // equal floats (-0 == +0) are one position, as mesh_geometry() welds them
    const auto less = [](const std::array<float, 3>& a, const std::array<float, 3>& b) {
        for (std::size_t c = 0; c < 3; ++c) {
            if (a[c] < b[c]) return true;
            if (b[c] < a[c]) return false;
        }
        return false;
    };
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
        const auto ka = key(a), kb = key(b);
        return less(ka, kb) || (!less(kb, ka) && a < b);
    });
    for (std::size_t i = 0; i < n;) {
        std::size_t j = i + 1;
        while (j < n && !less(key(order[i]), key(order[j]))) ++j;
        for (std::size_t k = i; k < j; ++k) {
            const std::size_t v = order[k];
            if (v < first || v >= first + count) continue;
            if (j - i > 1) ++part.coincident_vertices;
            if (k == i) ++part.positions; // the smallest id of its position
        }
        i = j;
    }
}

} // namespace

// ---- PlyLayout ------------------------------------------------------------------------------

PlyLayout::PlyLayout(std::uint64_t vertex_count, std::uint64_t triangle_count, bool normals)
    : vertices(vertex_count), triangles(triangle_count),
      // as write_ply(): a mesh without vertices has no normals to declare
      vertex_bytes(normals && vertex_count > 0 ? io::detail::kPlyNormalVertexBytes : io::detail::kPlyVertexBytes)
{
    header_bytes = header().size();
}

std::string PlyLayout::header() const { return io::detail::ply_header(vertices, triangles, normals(), false); }

std::uint64_t PlyLayout::face_offset(std::int64_t t) const
{
    return header_bytes + vertices * vertex_bytes + static_cast<std::uint64_t>(t) * io::detail::kPlyFaceBytes;
}

std::size_t piece_bytes(std::uint64_t memory_limit)
{
    constexpr std::uint64_t kLargest = std::uint64_t{16} << 20, kSmallest = std::uint64_t{64} << 10;
    return static_cast<std::size_t>(memory_limit == 0 ? kLargest : std::clamp(memory_limit / 32, kSmallest, kLargest));
}

std::int64_t write_count(std::int64_t vertices, std::int64_t triangles, bool normals, std::size_t piece)
{
    const std::uint64_t v = static_cast<std::uint64_t>(vertices) *
                            (normals ? io::detail::kPlyNormalVertexBytes : io::detail::kPlyVertexBytes);
    const std::uint64_t t = static_cast<std::uint64_t>(triangles) * io::detail::kPlyFaceBytes;
    return static_cast<std::int64_t>(pieces(v, piece) + pieces(t, piece));
}

// ---- GeometryPart ---------------------------------------------------------------------------

void GeometryPart::add(const GeometryPart& other)
{
    positions += other.positions;
    coincident_vertices += other.coincident_vertices;
    zero_area_triangles += other.zero_area_triangles;
    intersecting_pairs += other.intersecting_pairs;
    examples.insert(examples.end(), other.examples.begin(), other.examples.end());
    std::sort(examples.begin(), examples.end());
    examples.erase(std::unique(examples.begin(), examples.end()), examples.end());
    if (examples.size() > kExamples) examples.resize(kExamples);
}

MeshGeometry finish_geometry(const GeometryPart& whole, const MeshTopology& topology, bool& welded_known)
{
    MeshGeometry g;
    g.positions = whole.positions;
    g.coincident_vertices = whole.coincident_vertices;
    g.zero_area_triangles = whole.zero_area_triangles;
    g.intersecting_pairs = whole.intersecting_pairs;
    g.intersection_examples = whole.examples;
    // welding by position changes nothing when no two vertices share one
    welded_known = whole.coincident_vertices == 0;
    if (welded_known) g.welded = topology;
    return g;
}

// ---- RangeRun -------------------------------------------------------------------------------

struct RangeRun::Impl {
    io::detail::PlaneReader& reader;
    double iso;
    SlabOptions opt;
    std::int64_t k0, k1, nz;
    io::detail::Grid grid;
    std::uint64_t plane_bytes;
    int threads;
    std::uint64_t mesh_budget = 0; ///< bytes for one slab's mesh and its analysis; 0: no limit
    std::vector<Part> parts;
    std::unique_ptr<std::byte[]> buffers[2];
    bool kept = false;             ///< one window, still in buffers[0] after the count pass
    std::vector<std::vector<RangeCounts>> kept_counts; ///< its slabs' counts (per thread)
    double progress_done = 0;

    Impl(io::detail::PlaneReader& r, double i, SlabOptions o, std::int64_t a, std::int64_t b)
        : reader(r), iso(i), opt(std::move(o)), k0(a), k1(b), nz(r.layout().grid.dims[2]), grid(r.layout().grid),
          plane_bytes(r.layout().plane_bytes()), threads(thread_count(opt.extract.threads))
    {
        if (!(0 <= k0 && k0 <= k1 && k1 <= nz)) {
            throw Error(Status::invalid_argument, "slabs: planes [" + std::to_string(k0) + ", " + std::to_string(k1) +
                                                      ") are not within the volume's " + std::to_string(nz));
        }
        plan();
    }

    Window window_of(std::int64_t a, std::int64_t b) const { return {std::max<std::int64_t>(a - kHalo, 0), std::min(b + kHalo + 1, nz)}; }

    /// Slabs of as many planes as the budget allows.
    void plan()
    {
        if (k0 == k1) return;
        std::int64_t planes = k1 - k0;
        if (opt.memory_limit > 0) {
            const std::uint64_t limit = opt.memory_limit;
            // per plane of a slab: its samples twice (two buffers) and 24 bytes per sample row of counts
            const std::uint64_t per_plane = 2 * plane_bytes + 24 * static_cast<std::uint64_t>(grid.dims[1]);
            // the extractor's working memory per thread: flags of three slices, ids of four rows
            const std::uint64_t scratch = static_cast<std::uint64_t>(threads) *
                                          (3 * static_cast<std::uint64_t>(grid.dims[1]) * (static_cast<std::uint64_t>(grid.dims[0]) / 8 + 16) +
                                           48 * static_cast<std::uint64_t>(grid.dims[0]));
            const std::uint64_t fixed = 2 * (2 * kHalo + 1) * plane_bytes + scratch + 2 * piece_bytes(limit);
            // samples and counts take at most half of the limit, the mesh the rest
            const std::uint64_t samples = limit / 2;
            if (samples < fixed + per_plane) {
                throw Error(Status::too_large,
                            "--memory-limit " + std::to_string(limit) + " bytes is too small for planes of " +
                                std::to_string(grid.dims[0]) + "x" + std::to_string(grid.dims[1]) + " " +
                                std::string(type_name(grid.type)) + " samples: a slab of one plane needs " +
                                std::to_string(2 * (fixed + per_plane)) + " bytes (half for samples, half for the mesh)");
            }
            planes = std::clamp<std::int64_t>(static_cast<std::int64_t>((samples - fixed) / per_plane), 1, k1 - k0);
            // the mesh has what the samples leave: small planes leave it most of the limit
            const std::uint64_t used = fixed + static_cast<std::uint64_t>(planes) * per_plane;
            mesh_budget = limit - used - std::min(kProcessBytes, (limit - used) / 4);
        }
        if (opt.max_slab_planes > 0) planes = std::min(planes, opt.max_slab_planes);
        const std::int64_t count = (k1 - k0 + planes - 1) / planes;
        for (std::int64_t s = 0; s < count; ++s) {
            const std::int64_t a = k0 + (k1 - k0) * s / count, b = k0 + (k1 - k0) * (s + 1) / count;
            parts.push_back({window_of(a, b), {{a, b, 0, 0}}});
        }
        std::int64_t largest = 0;
        for (const Part& p : parts) largest = std::max(largest, p.window.hi - p.window.lo);
        const std::uint64_t bytes = static_cast<std::uint64_t>(largest) * plane_bytes;
        for (int b = 0; b < (parts.size() > 1 ? 2 : 1); ++b) buffers[b].reset(new std::byte[std::max<std::uint64_t>(bytes, 1)]);
    }

    void tick(std::int64_t planes)
    {
        progress_done += static_cast<double>(planes);
        if (opt.progress) opt.progress(progress_done / static_cast<double>(2 * std::max<std::int64_t>(k1 - k0, 1)));
    }

    template <class T> std::vector<RangeCounts> count_threads(const GridView<T>& g, std::int64_t a, std::int64_t b) const
    {
        const int n = static_cast<int>(std::min<std::int64_t>(threads, b - a));
        std::vector<RangeCounts> counts(static_cast<std::size_t>(n));
        detail::parallel_chunks(n, n, [&](int, std::int64_t first, std::int64_t last) {
            for (std::int64_t t = first; t < last; ++t) {
                counts[static_cast<std::size_t>(t)] =
                    cmc33::count(g, iso, opt.extract, a + (b - a) * t / n, a + (b - a) * (t + 1) / n);
            }
        });
        return counts;
    }

    /// Bytes of slab s's mesh and, with the analysis, of its work on the slab and the cell
    /// layers around it (emit_slab: the layer below is analysed with the slab, the one above
    /// lends its vertices).
    template <class T> std::uint64_t estimate(const GridView<T>& g, const Slab& s) const
    {
        const std::uint64_t v = (opt.analyse ? kBytesPerVertex : kBytesPerVertexBare) + (opt.extract.normals ? 18 : 0);
        const std::uint64_t t = opt.analyse ? kBytesPerTriangle : kBytesPerTriangleBare;
        auto vertices = static_cast<std::uint64_t>(s.vertices), triangles = static_cast<std::uint64_t>(s.triangles);
        if (opt.analyse) {
            const auto layer = [&](std::int64_t k) {
                try {
                    const RangeCounts c = cmc33::count(g, iso, opt.extract, k, k + 1);
                    return std::array<std::uint64_t, 2>{static_cast<std::uint64_t>(c.vertex_count()),
                                                        static_cast<std::uint64_t>(c.triangle_count())};
                } catch (const Error& e) {
                    // a non-finite sample beyond the slab is the next slab's to report
                    if (e.status() != Status::non_finite) throw;
                    return std::array<std::uint64_t, 2>{0, 0};
                }
            };
            if (s.a > 0) {
                const auto below = layer(s.a - 1);
                vertices += below[0], triangles += below[1];
            }
            if (s.b < nz) {
                const auto above = layer(s.b);
                vertices += above[0], triangles += above[1] / 8; // its triangles are only held, 12 bytes each
            }
        }
        return vertices * v + triangles * t;
    }

    /// Cuts slab [a, b) until each piece's mesh fits the budget; appends the pieces to `out`.
    template <class T> void fit(const GridView<T>& g, Slab s, std::vector<Slab>& out) const
    {
        const std::uint64_t need = mesh_budget == 0 ? 0 : estimate(g, s);
        if (need <= mesh_budget) {
            out.push_back(s);
            return;
        }
        if (s.b - s.a == 1) {
            throw Error(Status::too_large, "the mesh of sample plane " + std::to_string(s.a) + " alone (" +
                                               std::to_string(s.vertices) + " vertices, " + std::to_string(s.triangles) +
                                               " triangles) needs about " + std::to_string(need) +
                                               " bytes, more than --memory-limit leaves for the mesh (" +
                                               std::to_string(mesh_budget) + "); raise --memory-limit");
        }
        const std::int64_t m = s.a + (s.b - s.a) / 2;
        const RangeCounts lower = cmc33::count(g, iso, opt.extract, s.a, m);
        Slab l{s.a, m, lower.vertex_count(), lower.triangle_count()};
        Slab u{m, s.b, s.vertices - l.vertices, s.triangles - l.triangles};
        fit(g, l, out);
        fit(g, u, out);
    }

    template <class T> RangeTotals count_pass()
    {
        RangeTotals totals;
        totals.slabs = 0;
        if (parts.empty()) return totals;
        std::vector<Window> windows;
        for (const Part& p : parts) windows.push_back(p.window);
        std::byte* const bufs[2] = {buffers[0].get(), buffers[parts.size() > 1 ? 1 : 0].get()};
        PlaneStream stream(reader, windows, bufs);
        bool counting = true; // until a non-finite sample: then only those are counted
        for (Part& p : parts) {
            Clock::time_point t = Clock::now();
            const GridView<T> g = window_view<T>(stream.next(), p.window, grid);
            totals.wait_seconds += since(t);
            t = Clock::now();
            Slab s = p.slabs.front();
            if (counting) {
                try {
                    const std::vector<RangeCounts> counts = count_threads(g, s.a, s.b);
                    for (const RangeCounts& c : counts) {
                        s.vertices += c.vertex_count();
                        s.triangles += c.triangle_count();
                        totals.sample_bound = std::max(totals.sample_bound, c.sample_bound());
                        add_stats(totals.stats, c.stats());
                    }
                    if (parts.size() == 1) kept_counts.push_back(counts);
                } catch (const Error& e) {
                    // a range names its own non-finite samples: count them all, as extract() does
                    if (e.status() != Status::non_finite) throw;
                    // count reads planes a - 1 .. b + 1: is it a sample at all (and not
                    // the isovalue or the frame)?
                    RangeTotals around;
                    scan_non_finite(g, std::max<std::int64_t>(s.a - 1, 0), std::min(s.b + 2, nz), around);
                    if (around.non_finite == 0) throw;
                    counting = false;
                    kept_counts.clear();
                }
            }
            if (!counting) {
                scan_non_finite(g, s.a, s.b, totals); // only the own planes: each is counted once
            } else {
                p.slabs.clear();
                fit(g, s, p.slabs);
                if (p.slabs.size() > 1) kept_counts.clear();
                totals.vertices += s.vertices;
                totals.triangles += s.triangles;
            }
            totals.count_seconds += since(t);
            tick(s.b - s.a);
        }
        kept = parts.size() == 1 && !kept_counts.empty();
        for (const Part& p : parts) totals.slabs += static_cast<std::int64_t>(p.slabs.size());
        totals.planes_read = stream.planes_read();
        return totals;
    }

    template <class T>
    RangeResult emit_pass(std::int64_t first_vertex, std::int64_t first_triangle, double bound, const PlyLayout& layout,
                          ByteSink* sink)
    {
        RangeResult result;
        RecordWriter writer(sink, layout, first_vertex, first_triangle, piece_bytes(opt.memory_limit));
        std::int64_t fv = first_vertex, ft = first_triangle;
        std::unique_ptr<PlaneStream> stream;
        if (!kept && !parts.empty()) {
            std::vector<Window> windows;
            for (const Part& p : parts) windows.push_back(p.window);
            std::byte* const bufs[2] = {buffers[0].get(), buffers[parts.size() > 1 ? 1 : 0].get()};
            stream = std::make_unique<PlaneStream>(reader, windows, bufs);
        }
        for (const Part& p : parts) {
            const Clock::time_point t = Clock::now();
            const GridView<T> g = window_view<T>(stream ? stream->next() : buffers[0].get(), p.window, grid);
            result.wait_seconds += since(t);
            for (const Slab& s : p.slabs) {
                std::vector<RangeCounts> counts = kept ? std::move(kept_counts.front()) : count_threads(g, s.a, s.b);
                emit_slab(g, s, counts, fv, ft, bound, writer, result);
                if (opt.memory_limit > 0) release_memory();
                fv += s.vertices;
                ft += s.triangles;
            }
            tick(p.slabs.back().b - p.slabs.front().a);
        }
        const Clock::time_point t = Clock::now();
        writer.flush();
        result.write_seconds += since(t);
        if (stream) result.planes_read = stream->planes_read();
        kept = false;
        kept_counts.clear();
        return result;
    }

    /// Hands back to the system what a slab's mesh and analysis freed: blocks kept by the mesh
    /// allocator for sizes the next slab may not ask for, and free pages glibc keeps in its heaps
    /// (fragmented by the analysis, they held more and more of them from slab to slab).
    static void release_memory() noexcept
    {
        detail::release_kept_buffers();
#if defined(__GLIBC__)
        malloc_trim(0);
#endif
    }

    /// A cell layer beside a slab, for its analysis.
    struct Layer {
        std::vector<float> positions;
        std::vector<std::uint32_t> triangles;
    };

    /// The geometric check of slab s by the grid's structure (grid_check.hpp), with the pairs of
    /// its first cell layer and the layer below (the layer above is the next slab's); false when
    /// the structure does not decide (a corner outside its cell, coincident vertices), and then
    /// the general check runs.
    template <class T>
    bool structured_geometry(const GridView<T>& g, const Slab& s, std::int64_t fv, std::int64_t ft,
                             const std::vector<float>& positions, const std::vector<std::uint32_t>& triangles,
                             const std::vector<std::int64_t>& slab_layers, const Layer& below, const Layer& above,
                             RangeResult& result) const
    {
        if (slab_layers.size() != static_cast<std::size_t>(s.b - s.a) + 1) return false;
        const std::int64_t below_v = static_cast<std::int64_t>(below.positions.size() / 3);
        const std::int64_t below_t = static_cast<std::int64_t>(below.triangles.size() / 3);
        const bool has_below = s.a > 0;
        std::vector<float> points;
        points.reserve(below.positions.size() + positions.size() + above.positions.size());
        points.insert(points.end(), below.positions.begin(), below.positions.end());
        points.insert(points.end(), positions.begin(), positions.end());
        points.insert(points.end(), above.positions.begin(), above.positions.end());
        std::vector<std::uint32_t> ids;
        ids.reserve(below.triangles.size() + triangles.size());
        ids.insert(ids.end(), below.triangles.begin(), below.triangles.end());
        ids.insert(ids.end(), triangles.begin(), triangles.end());
        std::vector<std::int64_t> layer_first;
        if (has_below) layer_first.push_back(0);
        for (const std::int64_t first : slab_layers) layer_first.push_back(below_t + first);
        detail::LayeredTriangles layers;
        layers.dims = g.dims;
        layers.origin = g.origin;
        layers.frame = frame_matrix(g.spacing, g.direction);
        layers.positions = {points.data(), points.size()};
        layers.first_vertex = fv - below_v;
        layers.triangles = {ids.data(), ids.size()};
        layers.first_triangle = ft - below_t;
        layers.layer_first = {layer_first.data(), layer_first.size()};
        layers.k0 = has_below ? s.a - 1 : s.a;
        detail::GridCheckOptions o;
        o.threads = thread_count(opt.extract.threads);
        o.examples = 0;
        detail::GridGeometry alone; // the layer below by itself: its own slab's
        if (has_below && below_t > 0) {
            layers.layer_first = {layer_first.data(), 2};
            alone = detail::grid_geometry(layers, 1, o);
            layers.layer_first = {layer_first.data(), layer_first.size()};
        }
        // the examples that count: pairs with a slab triangle
        o.examples = GeometryPart::kExamples + static_cast<std::size_t>(alone.intersecting_pairs);
        detail::GridGeometry all = detail::grid_geometry(layers, static_cast<std::int64_t>(layer_first.size()) - 1, o);
        if (!all.decided()) return false;
        GeometryPart part;
        part.positions = static_cast<std::int64_t>(positions.size() / 3); // no two at one position
        part.zero_area_triangles = all.zero_area_triangles - alone.zero_area_triangles;
        part.intersecting_pairs = all.intersecting_pairs - alone.intersecting_pairs;
        for (const auto& pair : all.examples)
            if (pair[1] >= ft && part.examples.size() < GeometryPart::kExamples) part.examples.push_back(pair);
        result.geometry.add(part);
        return true;
    }

    template <class T>
    void emit_slab(const GridView<T>& g, const Slab& s, std::vector<RangeCounts>& counts, std::int64_t fv, std::int64_t ft,
                   double bound, RecordWriter& writer, RangeResult& result) const
    {
        Clock::time_point started = Clock::now();
        for (RangeCounts& c : counts) c.share_sample_bound(bound);
        const std::vector<RangeOffsets> offsets = scan(counts, fv, ft);
        std::int64_t nv = 0, nt = 0;
        for (const RangeCounts& c : counts) nv += c.vertex_count(), nt += c.triangle_count();
        if (nv != s.vertices || nt != s.triangles) {
            throw Error(Status::internal, "planes " + std::to_string(s.a) + " to " + std::to_string(s.b) +
                                              " counted other vertices or triangles the second time (was the file "
                                              "changed while it was read?)");
        }
        const auto v = static_cast<std::size_t>(nv), t = static_cast<std::size_t>(nt);
        std::vector<float> positions(3 * v), normals(opt.extract.normals ? 3 * v : 0);
        std::vector<std::uint32_t> triangles(3 * t);
        detail::parallel_chunks(static_cast<std::int64_t>(counts.size()), static_cast<int>(counts.size()),
                                [&](int, std::int64_t begin, std::int64_t end) {
                                    for (std::int64_t r = begin; r < end; ++r) {
                                        const auto i = static_cast<std::size_t>(r);
                                        const auto dv = static_cast<std::size_t>(offsets[i].first_vertex - fv);
                                        const auto dt = static_cast<std::size_t>(offsets[i].first_triangle - ft);
                                        MeshSpans out;
                                        out.positions = positions.data() + 3 * dv;
                                        out.normals = opt.extract.normals ? normals.data() + 3 * dv : nullptr;
                                        out.triangles = triangles.data() + 3 * dt;
                                        out.first_vertex = offsets[i].first_vertex;
                                        out.first_triangle = offsets[i].first_triangle;
                                        cmc33::emit(g, iso, opt.extract, counts[i], offsets[i], out);
                                    }
                                });
        // triangles of cell layer s.a + i from the slab's first, for the structured check
        std::vector<std::int64_t> layer_first;
        layer_first.reserve(static_cast<std::size_t>(s.b - s.a) + 2);
        for (std::size_t i = 0; i < counts.size(); ++i)
            for (std::int64_t k = counts[i].k0(); k < counts[i].k1(); ++k)
                layer_first.push_back(offsets[i].first_triangle - ft + counts[i].plane_first_triangle(k));
        layer_first.push_back(nt);
        counts.clear();
        result.emit_seconds += since(started);
        started = Clock::now();
        writer.vertices(positions.data(), opt.extract.normals ? normals.data() : nullptr, v);
        normals = {};
        writer.faces(triangles.data(), t);
        result.write_seconds += since(started);
        if (!opt.analyse) return;
        started = Clock::now();

        // The cell layers on either side, emitted here from the buffer's outer planes.
        const auto layer = [&](std::int64_t k, std::int64_t first_v, std::int64_t first_t, bool before) {
            RangeCounts c = cmc33::count(g, iso, opt.extract, k, k + 1);
            c.share_sample_bound(bound);
            Layer l{std::vector<float>(3 * static_cast<std::size_t>(c.vertex_count())),
                    std::vector<std::uint32_t>(3 * static_cast<std::size_t>(c.triangle_count()))};
            const RangeOffsets off{before ? first_v - c.vertex_count() : first_v, before ? first_t - c.triangle_count() : first_t};
            MeshSpans out;
            out.positions = l.positions.data();
            out.triangles = l.triangles.data();
            out.first_vertex = off.first_vertex;
            out.first_triangle = off.first_triangle;
            cmc33::emit(g, iso, opt.extract, c, off, out);
            return l;
        };
        const Layer below = s.a > 0 ? layer(s.a - 1, fv, ft, true) : Layer{};
        const Layer above = s.b < nz ? layer(s.b, fv + nv, ft + nt, false) : Layer{};

        const detail::SeamTopology topology =
            detail::SeamTopology::of_slab(detail::SlabTriangles{fv, nv, triangles, below.triangles});
        result.topology = detail::SeamTopology::merge(result.topology, topology);

        if (structured_geometry(g, s, fv, ft, positions, triangles, layer_first, below, above, result)) {
            result.analyse_seconds += since(started);
            return;
        }

        // Geometry: the combined mesh of the layer below and the slab, ids from `base`.
        const std::size_t below_v = below.positions.size() / 3, below_t = below.triangles.size() / 3;
        const std::int64_t base = fv - static_cast<std::int64_t>(below_v);
        Mesh combined;
        combined.positions.reserve(below.positions.size() + positions.size() + above.positions.size());
        combined.positions.insert(combined.positions.end(), below.positions.begin(), below.positions.end());
        combined.positions.insert(combined.positions.end(), positions.begin(), positions.end());
        combined.positions.insert(combined.positions.end(), above.positions.begin(), above.positions.end());
        GeometryPart part;
        {
            std::vector<float> all(combined.positions.begin(), combined.positions.end());
            count_twins(all, below_v, v, part);
        }
        combined.triangles.resize(below.triangles.size() + triangles.size());
        std::transform(below.triangles.begin(), below.triangles.end(), combined.triangles.begin(),
                       [base](std::uint32_t id) { return static_cast<std::uint32_t>(id - base); });
        std::transform(triangles.begin(), triangles.end(), combined.triangles.begin() + static_cast<std::ptrdiff_t>(below.triangles.size()),
                       [base](std::uint32_t id) { return static_cast<std::uint32_t>(id - base); });
        triangles = {};
        positions = {};
        MeshGeometry under;
        if (below_t > 0) {
            Mesh layer_mesh;
            std::uint32_t largest = 0;
            for (std::size_t i = 0; i < below.triangles.size(); ++i) largest = std::max(largest, combined.triangles[i]);
            layer_mesh.positions.assign(combined.positions.begin(), combined.positions.begin() + 3 * (static_cast<std::ptrdiff_t>(largest) + 1));
            layer_mesh.triangles.assign(combined.triangles.begin(), combined.triangles.begin() + static_cast<std::ptrdiff_t>(below.triangles.size()));
            under = mesh_geometry(layer_mesh, MeshGeometryOptions{opt.extract.threads, 0});
        }
        // the examples that count: pairs with a slab triangle (combined order is global order)
        const auto wanted = GeometryPart::kExamples + static_cast<std::size_t>(under.intersecting_pairs);
        const MeshGeometry all = mesh_geometry(combined, MeshGeometryOptions{opt.extract.threads, wanted});
        part.zero_area_triangles = all.zero_area_triangles - under.zero_area_triangles;
        part.intersecting_pairs = all.intersecting_pairs - under.intersecting_pairs;
        const std::int64_t tri_base = ft - static_cast<std::int64_t>(below_t);
        for (const auto& pair : all.intersection_examples) {
            if (pair[1] < static_cast<std::int64_t>(below_t)) continue; // both in the layer below: its own slab's
            if (part.examples.size() < GeometryPart::kExamples) part.examples.push_back({tri_base + pair[0], tri_base + pair[1]});
        }
        result.geometry.add(part);
        result.analyse_seconds += since(started);
    }
};

RangeRun::RangeRun(io::detail::PlaneReader& reader, double iso, SlabOptions options, std::int64_t k0, std::int64_t k1)
    : impl_(std::make_unique<Impl>(reader, iso, std::move(options), k0, k1))
{
}

RangeRun::~RangeRun() = default;

RangeTotals RangeRun::count()
{
    return dispatch_scalar_type(impl_->grid.type, [&](auto tag) {
        using T = decltype(tag);
        return impl_->count_pass<T>();
    });
}

RangeResult RangeRun::emit(std::int64_t first_vertex, std::int64_t first_triangle, double sample_bound,
                           const PlyLayout& layout, ByteSink* sink)
{
    return dispatch_scalar_type(impl_->grid.type, [&](auto tag) {
        using T = decltype(tag);
        return impl_->emit_pass<T>(first_vertex, first_triangle, sample_bound, layout, sink);
    });
}

// ---- helpers --------------------------------------------------------------------------------

std::array<std::int64_t, 2> rank_planes(std::int64_t nz, int rank, int ranks)
{
    return {nz * rank / ranks, nz * (rank + 1) / ranks};
}

std::uint64_t parse_size(const std::string& text)
{
    std::size_t i = 0;
    std::uint64_t value = 0;
    bool digits = false;
    for (; i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])); ++i) {
        const auto d = static_cast<std::uint64_t>(text[i] - '0');
        if (value > (std::numeric_limits<std::uint64_t>::max() - d) / 10) digits = false, i = text.size() + 1;
        if (i > text.size()) break;
        value = value * 10 + d;
        digits = true;
    }
    std::string unit = i <= text.size() ? text.substr(std::min(i, text.size())) : "?";
    for (char& c : unit) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    if (unit.size() >= 2 && unit.substr(unit.size() - 2) == "IB") unit.resize(unit.size() - 2);
    else if (unit.size() >= 1 && unit.back() == 'B') unit.pop_back();
    int shift = -1;
    if (unit.empty()) shift = 0;
    if (unit == "K") shift = 10;
    if (unit == "M") shift = 20;
    if (unit == "G") shift = 30;
    if (unit == "T") shift = 40;
    if (!digits || shift < 0 || value == 0 || value > (std::numeric_limits<std::uint64_t>::max() >> shift)) {
        throw Error(Status::invalid_argument,
                    "memory size '" + text + "' is not a size; expected a whole number > 0 of bytes, or with k, M, G or T "
                                             "(powers of 1024), like 256M or 2G");
    }
    return value << shift;
}

std::string non_finite_message(std::int64_t count, const Index3& first)
{
    return counted(count, "sample") + (count == 1 ? " is" : " are") + " NaN or infinite, the first at (" +
           std::to_string(first[0]) + ", " + std::to_string(first[1]) + ", " + std::to_string(first[2]) +
           "); cmc33 needs finite samples";
}

} // namespace cmc33::slabs
