// extract(): Marching Cubes 33 in passes (docs/design.md, after VTK's Flying Edges), public in
// src/core/include/cmc33/passes.hpp, each over a range of sample planes [k0, k1):
//   1. count: per row of cells, the case code of each cell from the rows' above-flags (rows whose
//      samples are all on one side are skipped), the face and interior tests of the cells that
//      have them, and the number of vertices (crossed edges owned by the row's samples, interior
//      vertices) and triangles; a scan inside the range gives every row its first ids;
//   2. scan: consecutive ranges get consecutive first vertex and triangle ids;
//   3. emit: each crossed grid edge is owned by its lower sample and gets one vertex; every cell
//      writes its tiling's triangles and interior vertices at its row's offsets, finding edge
//      vertices by edge ownership (no hash map, no locks). Cells with a face or interior test
//      replay the decision count stored for them (one byte each, in the order count met them):
//      working memory is O(rows + tested cells + threads * nx * ny), not O(cells).
// extract() runs `threads` ranges as tasks; all writes land at offsets fixed by the scan, so the
// mesh is the same, byte for byte, for every thread count and every split.
//
// World coordinates (volume.hpp): x = origin + M * (i, j, k) with M = D * diag(spacing). A diagonal
// M (the usual axis-aligned frame, flips included) takes the per-axis multiply of old; only an
// oblique or permuted frame pays for the full product. Normals map the index-space gradient by
// M^-T; a mirroring frame (det M < 0) reverses every triangle so that the winding rule of
// docs/conventions.md holds in world space.

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <numeric>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/passes.hpp"
#include "classify.hpp"
#include "cube.hpp"
#include "decide.hpp"
#include "parallel.hpp"
#include "plural.hpp"
#include "placement.hpp"
#include "portability.hpp"
#include "refine.hpp"
#include "sample_types.hpp"
#include "mc33_tables.hpp"
#include "thread_pool.hpp"

namespace cmc33 {
namespace {

using detail::kEdgeCorners;

constexpr std::int64_t kCornerOffset[8][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                                              {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};

/// For each cell edge: which of the four sample rows around a cell row owns it (bit 0: j + 1, bit
/// 1: k + 1, the index into the ids of those rows), and its slot there relative to 3 * i (3 * x
/// offset + axis).
constexpr std::array<std::uint8_t, 12> kEdgeRow = [] {
    std::array<std::uint8_t, 12> r{};
    for (int q = 0; q < 12; ++q) {
        const int c = kEdgeCorners[q][0];
        r[static_cast<std::size_t>(q)] = static_cast<std::uint8_t>(kCornerOffset[c][1] + 2 * kCornerOffset[c][2]);
    }
    return r;
}();
constexpr std::array<std::uint8_t, 12> kEdgeSlot = [] {
    std::array<std::uint8_t, 12> s{};
    for (int q = 0; q < 12; ++q) {
        s[static_cast<std::size_t>(q)] = static_cast<std::uint8_t>(3 * kCornerOffset[kEdgeCorners[q][0]][0] + q / 4);
    }
    return s;
}();

/// A row's above-flags as 64-bit words (classify.hpp), with one zero word after the last so that
/// "the flag of sample i + 1" can read one word past any sample's.
using Word = std::uint64_t;

/// The set bits of a word. std::popcount is a call into libgcc for generic x86-64 (no POPCNT
/// instruction without -mpopcnt); this is the same count in a dozen inline operations.
CMC33_ALWAYS_INLINE int popcount(Word x)
{
    x = x - ((x >> 1) & 0x5555555555555555u);
    x = (x & 0x3333333333333333u) + ((x >> 2) & 0x3333333333333333u);
    x = (x + (x >> 4)) & 0x0f0f0f0f0f0f0f0fu;
    return static_cast<int>((x * 0x0101010101010101u) >> 56);
}

/// Word w of the row shifted down by one sample: bit b is the flag of sample 64 w + b + 1.
CMC33_ALWAYS_INLINE Word next_sample(const Word* m, std::int64_t w) { return m[w] >> 1 | m[w + 1] << 63; }

/// The above-flags of sample rows, for three consecutive slices at once (slice k lives in buffer
/// k mod 3): a pass over cell rows (j, k) reads slices k..k+2 at most. Each row is classified once
/// per thread, with its signs (detail::RowSigns): on demand through get() (emit), or in order by
/// count() itself (plane_words()), which saves get()'s bookkeeping.
class SliceMasks {
public:
    SliceMasks(std::int64_t nx, std::int64_t ny)
        : words_((nx + 63) / 64), stride_(words_ + 1), ny_(ny), bits_(static_cast<std::size_t>(3 * ny * stride_), 0),
          slice_of_(static_cast<std::size_t>(3 * ny), -1),
          signs_(static_cast<std::size_t>(3 * ny), detail::RowSigns::below)
    {
    }
    /// The words of row (j, k); `fresh` when they must be computed (then also set `signs`).
    CMC33_ALWAYS_INLINE Word* get(std::int64_t j, std::int64_t k, bool& fresh, detail::RowSigns*& signs)
    {
        const auto row = static_cast<std::size_t>((k % 3) * ny_ + j);
        fresh = slice_of_[row] != k;
        slice_of_[row] = k;
        signs = &signs_[row];
        return &bits_[row * static_cast<std::size_t>(stride_)];
    }
    /// Slice k's words (row j's at j * stride()) and signs, without get()'s bookkeeping: for
    /// count(), which classifies the rows of its planes itself, each once and in order (a
    /// SliceMasks is used one way or the other).
    Word* plane_words(std::int64_t k) { return &bits_[static_cast<std::size_t>((k % 3) * ny_ * stride_)]; }
    detail::RowSigns* plane_signs(std::int64_t k) { return &signs_[static_cast<std::size_t>((k % 3) * ny_)]; }
    std::int64_t stride() const { return stride_; }

private:
    std::int64_t words_, stride_, ny_;
    std::vector<Word> bits_;
    std::vector<std::int64_t> slice_of_;
    std::vector<detail::RowSigns> signs_;
};

/// Vertex ids of the edges owned by four sample rows, one slot per parity of (j, k): a cell row
/// (j, k) reads rows j..j+1 of slices k..k+1, which never share a slot, and the next cell row
/// along j finds two of them already filled. Each slot also keeps where its row's interior
/// vertices start. Only the slots of crossed edges are written (and read).
class IdRows {
public:
    explicit IdRows(std::int64_t nx) : ids_(4 * 3 * static_cast<std::size_t>(nx)), len_(3 * static_cast<std::size_t>(nx)) {}
    /// Slot s's ids start at base() + s * row_length(); row (j, k) has slot (j & 1) | (k & 1) << 1.
    const std::uint32_t* base() const noexcept { return ids_.data(); }
    std::size_t row_length() const noexcept { return len_; }
    /// Row (j, k); `fresh` when its slot held another row and must be filled.
    std::uint32_t* get(std::int64_t j, std::int64_t k, bool& fresh, std::int64_t*& interior_start)
    {
        const auto slot = static_cast<std::size_t>((j & 1) | (k & 1) << 1);
        fresh = key_[slot][0] != j || key_[slot][1] != k;
        key_[slot] = {j, k};
        interior_start = &interior_start_[slot];
        return &ids_[slot * len_];
    }

private:
    std::vector<std::uint32_t> ids_;
    std::size_t len_;
    std::array<std::int64_t, 2> key_[4] = {{-1, -1}, {-1, -1}, {-1, -1}, {-1, -1}};
    std::int64_t interior_start_[4] = {};
};

/// The edges owned by the samples of one word of a sample row that cross: x (from the row's flags
/// f), y (against the row at j + 1, fy) and z (against the row at k + 1, fz). At the grid's last
/// row or slice pass f itself for fy or fz: those edges do not exist and never cross. `x_valid`
/// clears the x edge of the row's last sample, which does not exist either.
struct EdgeWords {
    Word x, y, z;
    CMC33_ALWAYS_INLINE EdgeWords(const Word* f, const Word* fy, const Word* fz, std::int64_t w, Word x_valid)
        : x((f[w] ^ next_sample(f, w)) & x_valid), y(f[w] ^ fy[w]), z(f[w] ^ fz[w])
    {
    }
    Word any() const { return x | y | z; }
};

/// The crossed cells of one word of a cell row, from the flags of its four sample rows a (j, k),
/// b (j + 1, k), c (j, k + 1), d (j + 1, k + 1): a cell is crossed unless its 8 corners agree.
CMC33_ALWAYS_INLINE Word crossed_cells(const Word* a, const Word* b, const Word* c, const Word* d, std::int64_t w,
                                       Word cell_valid)
{
    const Word any = a[w] | b[w] | c[w] | d[w], all = a[w] & b[w] & c[w] & d[w];
    const Word any_next = (any >> 1) | (a[w + 1] | b[w + 1] | c[w + 1] | d[w + 1]) << 63;
    const Word all_next = (all >> 1) | (a[w + 1] & b[w + 1] & c[w + 1] & d[w + 1]) << 63;
    return (any | any_next) & ~(all & all_next) & cell_valid;
}

/// The case codes (bit c: corner c above, corner order of cube.hpp) of the cells of word w of a
/// cell row, from the flags of its four sample rows a (j, k), b (j + 1, k), c (j, k + 1),
/// d (j + 1, k + 1). The words are read once, into registers (stores of counts in between could
/// alias them).
struct CellCodes {
    Word lo[4], hi[4];
    CMC33_ALWAYS_INLINE CellCodes(const Word* a, const Word* b, const Word* c, const Word* d, std::int64_t w)
        : lo{a[w], b[w], c[w], d[w]}, hi{a[w + 1], b[w + 1], c[w + 1], d[w + 1]}
    {
    }
    /// The code of the cell at bit s.
    CMC33_ALWAYS_INLINE unsigned operator()(int s) const
    {
        if (s < 63) { // both corners of a row in its word
            return static_cast<unsigned>((lo[0] >> s & 3u) | (lo[1] >> s & 3u) << 2 | (lo[2] >> s & 3u) << 4 |
                                         (lo[3] >> s & 3u) << 6);
        }
        return static_cast<unsigned>((lo[0] >> 63) | (hi[0] & 1u) << 1 | (lo[1] >> 63) << 2 | (hi[1] & 1u) << 3 |
                                     (lo[2] >> 63) << 4 | (hi[2] & 1u) << 5 | (lo[3] >> 63) << 6 | (hi[3] & 1u) << 7);
    }
};

/// Words of valid bits: sample bits (below nx) or cell and x edge bits (below nx - 1).
std::vector<Word> valid_words(std::int64_t words, std::int64_t bits)
{
    std::vector<Word> v(static_cast<std::size_t>(words), 0);
    for (std::int64_t w = 0; w < words; ++w) {
        const std::int64_t n = std::clamp<std::int64_t>(bits - 64 * w, 0, 64);
        v[static_cast<std::size_t>(w)] = n == 64 ? ~Word{0} : (Word{1} << n) - 1;
    }
    return v;
}

constexpr std::uint32_t kNoVertex = std::numeric_limits<std::uint32_t>::max();

/// The largest |world coordinate| over the 8 corners of the box of a grid of `dims` samples in the
/// frame (origin, M) (every vertex lies in it).
double largest_coordinate(const Index3& dims, const Vec3& origin, const Mat3& m)
{
    double largest = 0;
    for (int corner = 0; corner < 8; ++corner) {
        double x[3];
        for (std::size_t a = 0; a < 3; ++a) x[a] = (corner >> a) & 1 ? static_cast<double>(dims[a] - 1) : 0.0;
        for (std::size_t r = 0; r < 3; ++r) {
            const double w = origin[r] + (m[r][0] * x[0] + m[r][1] * x[1] + m[r][2] * x[2]);
            largest = std::max(largest, std::fabs(w));
        }
    }
    return largest;
}
template <class T> double largest_coordinate(const GridView<T>& g)
{
    return largest_coordinate(g.dims, g.origin, frame_matrix(g.spacing, g.direction));
}

/// The shortest cell edge in world units: the length of M's shortest column.
double shortest_edge(const Mat3& m)
{
    double shortest = std::numeric_limits<double>::infinity();
    for (std::size_t a = 0; a < 3; ++a) {
        const double length = is_diagonal(m) ? std::fabs(m[a][a]) : std::hypot(m[0][a], m[1][a], m[2][a]);
        shortest = std::min(shortest, length);
    }
    return shortest;
}

/// The largest |sample| of planes [k_lo, k_hi] (for integer types, the type's bound).
/// @throws Error{non_finite} for NaN or infinite samples there, saying how many and the first
template <class T> double scan_samples(const GridView<T>& g, std::int64_t k_lo, std::int64_t k_hi)
{
    if constexpr (std::is_floating_point_v<T>) {
        double largest = 0;
        std::int64_t count = 0;
        Index3 first{-1, -1, -1};
        for (std::int64_t k = k_lo; k <= k_hi; ++k)
            for (std::int64_t j = 0; j < g.ny(); ++j)
                for (std::int64_t i = 0; i < g.nx(); ++i) {
                    const double v = std::fabs(static_cast<double>(g(i, j, k)));
                    if (!std::isfinite(v) && count++ == 0) first = {i, j, k};
                    largest = std::max(largest, v);
                }
        if (count > 0) {
            throw Error(Status::non_finite, counted(count, "sample") + (count == 1 ? " is" : " are") +
                                                " NaN or infinite, the first at (" +
                                                std::to_string(first[0]) + ", " + std::to_string(first[1]) + ", " +
                                                std::to_string(first[2]) + "); cmc33 needs finite samples");
        }
        return largest;
    } else {
        return std::max(std::fabs(static_cast<double>(std::numeric_limits<T>::lowest())),
                        static_cast<double>(std::numeric_limits<T>::max()));
    }
}

/// Progress over the planes of both passes, shared by extract()'s tasks: every task ticks once per
/// plane; whoever ticks when no other task is reporting, and at least kInterval after the last
/// report, calls the caller's callback. A false answer stops every task at its next plane.
class Ticker {
public:
    Ticker(const Progress& progress, std::int64_t total) : progress_(progress), total_(std::max<std::int64_t>(total, 1)) {}
    /// One plane done; false when the work is to stop.
    bool tick()
    {
        done_.fetch_add(1, std::memory_order_relaxed);
        if (!progress_) return true;
        if (cancelled_.load(std::memory_order_relaxed)) return false;
        std::unique_lock lock(mutex_, std::try_to_lock);
        if (!lock.owns_lock()) return true;
        const auto now = std::chrono::steady_clock::now();
        if (now - last_ < kInterval) return true;
        last_ = now;
        // read under the lock, so that the reported fractions never decrease
        const std::int64_t done = std::min(done_.load(std::memory_order_relaxed), total_);
        if (!progress_(static_cast<double>(done) / static_cast<double>(total_))) {
            cancelled_.store(true, std::memory_order_relaxed);
        }
        return !cancelled_.load(std::memory_order_relaxed);
    }
    bool cancelled() const { return cancelled_.load(std::memory_order_relaxed); }
    /// The final call, with 1 (not if the caller already stopped the work).
    void finish()
    {
        if (progress_ && !cancelled() && !progress_(1.0)) cancelled_.store(true, std::memory_order_relaxed);
    }

private:
    static constexpr std::chrono::milliseconds kInterval{20};
    const Progress& progress_;
    std::int64_t total_;
    std::atomic<std::int64_t> done_{0};
    std::atomic<bool> cancelled_{false};
    std::mutex mutex_;
    std::chrono::steady_clock::time_point last_{};
};

[[noreturn]] void throw_cancelled()
{
    throw Error(Status::cancelled, "extraction cancelled by the progress callback");
}

/// Runs task(0..n-1) on the caller's executor, or on the calling thread and the process's worker
/// pool (support/thread_pool.hpp), or when that is busy on one std::thread each (the first on the
/// calling thread); rethrows the first task's exception (by task index) once all have ended, so
/// the error does not depend on the executor's scheduling.
template <class Task> void run_tasks(int n, const Executor& executor, Task&& task)
{
    std::vector<std::exception_ptr> errors(static_cast<std::size_t>(n));
    const std::function<void(int)> guarded = [&](int t) {
        try {
            task(t);
        } catch (...) {
            errors[static_cast<std::size_t>(t)] = std::current_exception();
        }
    };
    if (executor) {
        executor(n, guarded);
    } else if (n == 1) {
        guarded(0);
    } else if (!detail::ThreadPool::instance().try_run(n, guarded)) {
        std::vector<std::thread> pool;
        pool.reserve(static_cast<std::size_t>(n - 1));
        try {
            for (int t = 1; t < n; ++t) pool.emplace_back(guarded, t);
        } catch (...) {
            for (auto& th : pool) th.join();
            throw Error(Status::too_large, "cannot start " + std::to_string(n) + " threads");
        }
        guarded(0);
        for (auto& th : pool) th.join();
    }
    for (auto& e : errors) {
        if (e) std::rethrow_exception(e);
    }
}

/// Runs work(r, t) for every range r of `order` (a permutation of 0..ranges-1) on n tasks t of
/// run_tasks, each taking the next range of `order` not yet taken, until none is left or the
/// ticker says stop; rethrows the error of the lowest range that failed, so that the error does
/// not depend on which thread ran which range.
template <class Work>
void for_each_range(int n, std::span<const int> order, const Executor& executor, const Ticker& ticker, Work&& work)
{
    const int ranges = static_cast<int>(order.size());
    std::vector<std::exception_ptr> errors(order.size());
    std::atomic<int> next{0};
    run_tasks(n, executor, [&](int task) {
        for (int taken = next.fetch_add(1); taken < ranges && !ticker.cancelled(); taken = next.fetch_add(1)) {
            const int r = order[static_cast<std::size_t>(taken)];
            try {
                work(r, task);
            } catch (...) {
                errors[static_cast<std::size_t>(r)] = std::current_exception();
            }
        }
    });
    for (auto& e : errors) {
        if (e) std::rethrow_exception(e);
    }
}

} // namespace

/// The passes of passes.hpp for one grid and isovalue: what does not depend on the range (the
/// frame, the sign rule, which configurations need the samples) is set up once and shared by the
/// ranges, which may run at the same time (every method is const).
template <class T> class RangeExtractor {
public:
    RangeExtractor(const GridView<T>& g, double iso, const ExtractOptions& opt)
        : g_(g), iso_(iso), threshold_(iso), method_(opt.method), nx_(g.nx()), ny_(g.ny()), nz_(g.nz()), sx_(g.strides[0]),
          words_((nx_ + 63) / 64), x_valid_(valid_words(words_, nx_ - 1)),
          m_(frame_matrix(g.spacing, g.direction)), diagonal_(is_diagonal(m_)), mirrored_(determinant(m_) < 0),
          delta_(min_crossing(g, m_)), variants_(detail::tables_of(opt.method))
    {
        for (std::size_t a = 0; a < 3; ++a) {
            step_[a] = diagonal_ ? m_[a][a] : 1.0;
            half_inverse_step_[a] = 0.5 / step_[a];
        }
        if (!diagonal_) normal_map_ = inverse_transpose(m_);
        for (unsigned code = 0; code < 256; ++code) {
            const detail::Variant& first = variants_[detail::kVariantOffset[code]];
            const bool tested = opt.method != Method::mc &&
                                (detail::kAmbiguousFaces[code] != 0 || first.test != detail::kTestNone);
            fixed_tiling_[code] = tested ? nullptr : &first.tilings[0];
            fixed_subcase_[code] = first.subcase;
        }
        build_short_tilings();
    }

    /// Gives every range the bound on |sample| of them all (which have read every sample).
    static void share_largest_sample(std::vector<RangeCounts>& counts)
    {
        double largest = 0;
        for (const RangeCounts& c : counts) largest = std::max(largest, c.largest_sample_);
        for (RangeCounts& c : counts) c.largest_sample_ = largest;
    }

    /// Whether `c` was counted on a grid with these rows.
    static bool same_rows(const RangeCounts& c, const GridView<T>& g)
    {
        const std::int64_t planes = std::min(c.k1_, g.nz() - 1) - c.k0_ + 1;
        return c.nx_ == g.nx() && c.ny_ == g.ny() && c.rows_.size() == static_cast<std::size_t>((c.k1_ - c.k0_) * g.ny()) &&
               (c.k1_ == g.nz() || c.seam_first_.size() == static_cast<std::size_t>(g.ny()) + 1) &&
               planes > 0;
    }

    /// Pass 1 on planes [k0, k1); `largest_sample` bounds |sample| on planes k0 - 1 .. k1 + 1.
    /// Stops early (returning partial counts) when the ticker says so.
    RangeCounts count(std::int64_t k0, std::int64_t k1, double largest_sample, Ticker* ticker) const
    {
        RangeCounts c;
        c.k0_ = k0, c.k1_ = k1, c.nx_ = nx_, c.ny_ = ny_, c.largest_sample_ = largest_sample;
        c.iso_ = iso_, c.method_ = method_;
        c.rows_.assign(static_cast<std::size_t>((k1 - k0) * ny_), {});
        Scratch s(nx_, ny_);
        // Each sample row is classified once, straight into its slice of s.masks: the rows of plane
        // k + 1 as cell row j reaches them (j + 1; row 0 before), those of the range's first plane
        // before it. Cell row (j, k) reads rows j, j + 1 of planes k, k + 1; a row past the grid
        // is (j, k) again, as in flags_around (no cell reads it then).
        const std::int64_t st = s.masks.stride();
        const auto classify_into = [&](std::int64_t j, std::int64_t k) {
            s.masks.plane_signs(k)[j] = classify(j, k, s.masks.plane_words(k) + j * st, s);
        };
        for (std::int64_t j = 0; j < ny_; ++j) classify_into(j, k0);
        for (std::int64_t k = k0; k < k1; ++k) {
            const bool top = k + 1 < nz_;
            if (top) classify_into(0, k + 1);
            const Word* const lower = s.masks.plane_words(k);
            const Word* const upper = top ? s.masks.plane_words(k + 1) : lower;
            const detail::RowSigns* const lower_signs = s.masks.plane_signs(k);
            const detail::RowSigns* const upper_signs = top ? s.masks.plane_signs(k + 1) : lower_signs;
            for (std::int64_t j = 0; j < ny_; ++j) {
                const bool next = j + 1 < ny_;
                if (top && next) classify_into(j + 1, k + 1);
                const std::int64_t j1 = next ? j + 1 : j;
                const bool corner = next && top; // (j + 1, k + 1) exists
                const Word* const rows[4] = {lower + j * st, lower + j1 * st, upper + j * st,
                                             corner ? upper + j1 * st : lower + j * st};
                const detail::RowSigns signs[4] = {lower_signs[j], lower_signs[j1], upper_signs[j],
                                                   corner ? upper_signs[j1] : lower_signs[j]};
                count_row(j, k, s, c, rows, signs);
            }
            if (ticker && !ticker->tick()) return c;
        }
        if (k1 < nz_) {
            // plane k1 is the next range's: its rows' x/y edge vertices come first there
            c.seam_first_.assign(static_cast<std::size_t>(ny_) + 1, 0);
            const Word* const seam = s.masks.plane_words(k1); // classified with plane k1 - 1
            for (std::int64_t j = 0; j < ny_; ++j) {
                const Word* f = seam + j * st;
                const Word* fy = j + 1 < ny_ ? f + st : f;
                std::uint32_t xy = 0;
                for (std::int64_t w = 0; w < words_; ++w) {
                    const EdgeWords e(f, fy, f, w, x_valid_[static_cast<std::size_t>(w)]);
                    xy += static_cast<std::uint32_t>(popcount(e.x) + popcount(e.y));
                }
                c.seam_first_[static_cast<std::size_t>(j) + 1] = c.seam_first_[static_cast<std::size_t>(j)] + xy;
            }
        }
        // every sample of planes k0..k1 has been classified, which also looked for non-finite ones
        if (s.scan.non_finite) scan_samples(g_, k0, std::min(k1, nz_ - 1)); // throws, naming the first
        // (for integer types, the type's bound: scan_samples reads nothing then)
        c.largest_sample_ = std::max(largest_sample, std::is_floating_point_v<T> ? s.scan.largest : scan_samples(g_, k0, k0));
        // the rows hold their counts; turn them into first ids (the numbering of passes.hpp)
        std::int64_t v = 0, t = 0;
        const auto first_id = [&v, k0, k1](std::uint32_t& count) {
            if (v >= static_cast<std::int64_t>(kNoVertex)) {
                throw Error(Status::too_large, "sample planes " + std::to_string(k0) + " to " + std::to_string(k1) +
                                                   " would have more vertices than 32-bit indices can address");
            }
            v += std::exchange(count, static_cast<std::uint32_t>(v));
        };
        for (std::int64_t k = k0; k < k1; ++k) {
            RangeCounts::Row* plane = &c.rows_[static_cast<std::size_t>((k - k0) * ny_)];
            for (std::int64_t j = 0; j < ny_; ++j) first_id(plane[j].xy_first);
            for (std::int64_t j = 0; j < ny_; ++j) first_id(plane[j].z_first);
            for (std::int64_t j = 0; j < ny_; ++j) t += std::exchange(plane[j].triangle_first, t);
        }
        c.vertices_ = v, c.triangles_ = t;
        return c;
    }

    /// Pass 3 (see passes.hpp).
    void emit(const RangeCounts& c, const RangeOffsets& off, const MeshSpans& out, Ticker* ticker) const
    {
        const std::int64_t k0 = c.k0_, k1 = c.k1_;
        const std::int64_t seam = c.seam_first_.empty() ? 0 : c.seam_first_.back();
        const std::int64_t next = off.first_vertex + c.vertices_;
        if (off.first_vertex < 0 || off.first_triangle < 0 ||
            next + seam > static_cast<std::int64_t>(kNoVertex)) {
            throw Error(Status::too_large, "the mesh would have vertex ids up to " + std::to_string(next + seam) +
                                               ", more than 32-bit indices can address");
        }
        if (!(c.iso_ == iso_) || c.method_ != method_) {
            // emit uses count's classification and decisions: they must be of this isovalue and method
            throw Error(Status::invalid_argument, "emit: the counts are of iso " + std::to_string(c.iso_) + ", method " +
                                                      std::string(method_name(c.method_)) + "; expected iso " +
                                                      std::to_string(iso_) + ", method " +
                                                      std::string(method_name(method_)) + ", as given to emit");
        }
        if ((c.vertices_ > 0 && out.positions == nullptr) || (c.triangles_ > 0 && out.triangles == nullptr)) {
            throw Error(Status::invalid_argument, "emit: MeshSpans needs positions and triangles");
        }
        const Emit e{c, off, out, gradient_scale(c.largest_sample_)};
        Scratch s(nx_, ny_);
        if (out.vertex_cell_ranges) s.ranges.emplace(nx_, ny_);
        std::size_t decision = 0; // the next of count's decisions
        bool finished = false;    // not stopped by the ticker
        switch (outputs_of(out)) {
        case Outputs::plain: finished = emit_planes<Outputs::plain>(e, s, ticker, decision); break;
        case Outputs::drop_in: finished = emit_planes<Outputs::drop_in>(e, s, ticker, decision); break;
        case Outputs::all: finished = emit_planes<Outputs::all>(e, s, ticker, decision); break;
        }
        if (!finished) return;
        if (decision != c.decisions_.size()) {
            throw Error(Status::internal, "emit met " + std::to_string(decision) + " cells with a face or interior test in planes " +
                                              std::to_string(k0) + " to " + std::to_string(k1) + ", count " +
                                              std::to_string(c.decisions_.size()) +
                                              ": the samples, isovalue or method differ between the passes, or a bug in cmc33");
        }
    }

private:
    /// emit() found other numbers than count() in row (j, k): the samples, the isovalue or the
    /// method changed between the passes, or a bug in cmc33. Thrown before writing outside the
    /// row's part of the output.
    [[noreturn]] static void throw_mismatch(const char* what, std::int64_t j, std::int64_t k)
    {
        throw Error(Status::internal, std::string("emit found other ") + what + " in sample row (" + std::to_string(j) +
                                          ", " + std::to_string(k) +
                                          ") than count did: the samples, isovalue or method differ between "
                                          "the passes, or a bug in cmc33");
    }

    /// Which of MeshSpans' outputs an instantiation of emit's row functions writes. plain:
    /// positions, triangles and normals, the usual output, without the extras' tests (they cost
    /// 2-4 % where not taken); drop_in: those in (z, y, x) with vertex_cell_ranges, scikit-image's
    /// (cmc33.marching_cubes); all: every extra, each tested at run time.
    enum class Outputs { plain, drop_in, all };
    static Outputs outputs_of(const MeshSpans& out)
    {
        if (out.vertex_edges || out.vertex_parameters || out.vertex_values || out.triangle_cells) return Outputs::all;
        if (out.vertex_cell_ranges && out.zyx) return Outputs::drop_in;
        return out.vertex_cell_ranges || out.zyx || out.reverse_winding ? Outputs::all : Outputs::plain;
    }

    /// MeshSpans::vertex_cell_ranges without a scatter: cell_range() of the crossed cells of two
    /// cell planes, k (the one emit is in) and k - 1, and an edge vertex's value the largest of
    /// its up to four cells'. Each plane has a row of nx + 1 floats per cell row, cell i at i + 1;
    /// entry 0 (cell -1) and entry nx (cell nx - 1) are 0 and never written. The other entries
    /// are not initialized: only crossed cells are read, all of them written first (a crossed
    /// edge's cells are all crossed); a plane's row holds the plane two before until then. Cells
    /// outside the grid or below the range read the zero row.
    class CellRangeRows {
    public:
        CellRangeRows(std::int64_t nx, std::int64_t ny)
            : len_(static_cast<std::size_t>(nx) + 1), ny_(ny)
        {
            ranges_.resize((2 * static_cast<std::size_t>(ny) + 1) * len_);
#ifndef NDEBUG
            // debug builds (the sanitizers' in CI) poison the rest: a cell read before it is
            // written would win every max, and the tests compare the values with their own
            std::fill(ranges_.begin(), ranges_.end(), std::numeric_limits<float>::infinity());
#endif
            for (std::size_t r = 0; r < 2 * static_cast<std::size_t>(ny); ++r) ranges_[r * len_] = ranges_[r * len_ + len_ - 1] = 0;
            std::fill(ranges_.end() - static_cast<std::ptrdiff_t>(len_), ranges_.end(), 0.0f);
        }
        float* row(std::int64_t j, std::int64_t k) noexcept
        {
            return &ranges_[(static_cast<std::size_t>(k & 1) * static_cast<std::size_t>(ny_) + static_cast<std::size_t>(j)) * len_];
        }
        const float* zero() const noexcept { return &ranges_[2 * static_cast<std::size_t>(ny_) * len_]; }

    private:
        std::size_t len_;
        std::int64_t ny_;
        Buffer<float> ranges_; // not zeroed: see above
    };

    /// The cell rows around sample row (j, k) in CellRangeRows: below[b] is cell row (j - 1 + b,
    /// k - 1), here[b] (j - 1 + b, k). `first_plane`: k is the range's first plane and not the
    /// grid's: the cells below are the previous range's, so its x and y edge vertices take
    /// edge_cell_range() instead.
    struct CellsAround {
        const float* below[2];
        const float* here[2];
        bool first_plane;
        /// The value of the vertex on the edge from sample i along `axis`: the largest range of
        /// the cells around the edge, (i, j - 1 .. j, k - 1 .. k) for x, (i - 1 .. i, j,
        /// k - 1 .. k) for y, (i - 1 .. i, j - 1 .. j, k) for z.
        template <int axis> float value(std::int64_t i) const noexcept
        {
            const auto c = static_cast<std::size_t>(i); // cell i - 1 at c, cell i at c + 1
            if constexpr (axis == 0) {
                return std::max(std::max(below[0][c + 1], below[1][c + 1]), std::max(here[0][c + 1], here[1][c + 1]));
            } else if constexpr (axis == 1) {
                return std::max(std::max(below[1][c], below[1][c + 1]), std::max(here[1][c], here[1][c + 1]));
            } else {
                return std::max(std::max(here[0][c], here[0][c + 1]), std::max(here[1][c], here[1][c + 1]));
            }
        }
    };

    /// One range's emit: its counts, offsets and output.
    struct Emit {
        const RangeCounts& c;
        const RangeOffsets& off;
        const MeshSpans& out;
        double gradient_scale;
        /// One past the range's last triangle id: a short tiling's fixed-size copy may write past
        /// its row's triangles into those of the range's next rows, which this thread writes
        /// later, but not past the range's (another thread's, or the end of the caller's output).
        std::int64_t copy_end() const { return off.first_triangle + c.triangles_; }
    };

    /// One thread's working memory: above-flags of three slices (3 nx ny / 8 bytes), vertex ids
    /// of four sample rows (emit), and what classifying the rows saw. emit classifies the rows it
    /// needs again rather than keeping count's: on a dense surface reading them back costs more
    /// than the vector compare, and on a sparse one it saves little.
    struct Scratch {
        Scratch(std::int64_t nx, std::int64_t ny) : masks(nx, ny), ids(nx) {}
        SliceMasks masks;
        IdRows ids;
        detail::RowScan scan;
        std::optional<CellRangeRows> ranges; ///< with MeshSpans::vertex_cell_ranges
    };

    /// The range-relative ids of row (j, k) of a range: x/y edge vertices [xy0, xy1), z edge and
    /// interior vertices [z0, v1), triangles [t0, t1); its trim range [lo, hi).
    struct RowSpan {
        std::int64_t xy0, xy1, z0, v1, t0, t1;
        std::int64_t lo, hi;
    };
    RowSpan span_of(const RangeCounts& c, std::int64_t j, std::int64_t k) const
    {
        const std::size_t r = static_cast<std::size_t>(j + (k - c.k0_) * ny_);
        const RangeCounts::Row& row = c.rows_[r];
        const RangeCounts::Row& first = c.rows_[static_cast<std::size_t>((k - c.k0_) * ny_)];
        const bool last_row = j + 1 == ny_;
        const bool last_plane = k + 1 == c.k1_;
        RowSpan s{};
        s.xy0 = row.xy_first;
        s.xy1 = last_row ? first.z_first : c.rows_[r + 1].xy_first;
        s.z0 = row.z_first;
        s.v1 = !last_row ? c.rows_[r + 1].z_first : last_plane ? c.vertices_ : c.rows_[r + 1].xy_first;
        s.t0 = row.triangle_first;
        s.t1 = !last_row ? c.rows_[r + 1].triangle_first : last_plane ? c.triangles_ : c.rows_[r + 1].triangle_first;
        s.lo = row.lo, s.hi = row.hi;
        return s;
    }

    /// emit()'s planes, row by row, with the outputs `kOut` says (one instantiation per kind of
    /// output, chosen once per range). Returns false when the ticker stopped it.
    template <Outputs kOut> bool emit_planes(const Emit& e, Scratch& s, Ticker* ticker, std::size_t& decision) const
    {
        const RangeCounts& c = e.c;
        for (std::int64_t k = c.k0_; k < c.k1_; ++k) {
            const RangeCounts::Row* plane = &c.rows_[static_cast<std::size_t>((k - c.k0_) * ny_)];
            for (std::int64_t j = 0; j < ny_; ++j) {
                // an empty trim range: no crossed edge or cell, so nothing to emit (most rows of a
                // CT volume; cheaper than span_of)
                if (plane[j].hi <= plane[j].lo) continue;
                const RowSpan r = span_of(c, j, k);
                if (r.v1 == r.xy0 && r.t1 == r.t0) continue;
                std::int64_t interior = 0;
                const std::uint32_t* ids = row_ids(j, k, s, e, interior);
                // the cells' ranges before the vertices, which take them from the cells around
                if (kOut != Outputs::plain && s.ranges && r.t1 != r.t0) write_cell_ranges(j, k, r, s);
                const Word* f[4];
                detail::RowSigns unused[4];
                flags_around(j, k, s, f, unused);
                if (r.xy0 != r.xy1 || r.z0 != r.v1) emit_row_vertices<kOut>(j, k, r, f, ids, s, e);
                std::int64_t vertex_end = interior, triangle_end = e.off.first_triangle + r.t0;
                if (r.t1 != r.t0) emit_row_cells<kOut>(j, k, r, f, s, e, vertex_end, triangle_end, decision);
                if (vertex_end != e.off.first_vertex + r.v1 || triangle_end != e.off.first_triangle + r.t1) {
                    throw_mismatch("vertices or triangles", j, k);
                }
            }
            if (ticker && !ticker->tick()) return false;
        }
        return true;
    }

    /// The cell rows around sample row (j, k) (CellsAround) in s.ranges.
    CellsAround cells_around(std::int64_t j, std::int64_t k, Scratch& s, const Emit& e) const
    {
        CellRangeRows& rows = *s.ranges;
        const auto cell_row = [&](std::int64_t cj, std::int64_t ck) {
            // cells outside the grid, and the previous range's plane (edge_cell_range() there)
            const bool exists = cj >= 0 && cj + 1 < ny_ && ck >= e.c.k0_ && ck + 1 < nz_;
            return exists ? rows.row(cj, ck) : rows.zero();
        };
        return {{cell_row(j - 1, k - 1), cell_row(j, k - 1)}, {cell_row(j - 1, k), cell_row(j, k)}, k == e.c.k0_ && k > 0};
    }

    /// cell_range() of the crossed cells of cell row (j, k) into its CellRangeRows row: where x
    /// is the array's contiguous axis, 8 cells at a time from the first crossed cell not yet
    /// done, in a loop the compiler vectorizes (a group may reach into the next word's cells,
    /// which that word computes again); else, and for the row's last cells, cell by cell.
    /// Unaligned groups of 8 measured best (docs/performance.md, "Python").
    void write_cell_ranges(std::int64_t j, std::int64_t k, const RowSpan& r, Scratch& s) const
    {
        // the narrowest type whose difference, rounded to float, is cell_range()'s: float for
        // float (rounding through double first is innocuous: 53 >= 2 * 24 + 2 bits), int for 8-
        // and 16-bit samples; these vectorize, Exact's int64 would not
        using Difference = std::conditional_t<std::is_same_v<T, float>, float,
                                              std::conditional_t<(sizeof(T) <= 2), int, Exact>>;
        float* ranges = s.ranges->row(j, k) + 1;
        const Word* f00 = flags(j, k, s);
        const Word* f10 = flags(j + 1, k, s);
        const Word* f01 = flags(j, k + 1, s);
        const Word* f11 = flags(j + 1, k + 1, s);
        const T* a = g_.data + g_.offset(0, j, k);
        const T* b = a + g_.strides[1];
        const T* c = a + g_.strides[2];
        const T* d = b + g_.strides[2];
        for (std::int64_t w = r.lo / 64; w < (r.hi + 63) / 64; ++w) {
            Word bits = crossed_cells(f00, f10, f01, f11, w, x_valid_[static_cast<std::size_t>(w)]);
            if (sx_ == 1) {
                while (bits != 0) {
                    const int first = std::countr_zero(bits);
                    const std::int64_t i = 64 * w + first;
                    if (i + 8 >= nx_) break; // the last cells read past the row: one by one
                    // cell_range()'s tree spelled out on the four rows: through a shared helper
                    // the loop stops vectorizing
                    for (std::int64_t q = i; q < i + 8; ++q) {
                        const T low = std::min(std::min(std::min(a[q], a[q + 1]), std::min(b[q], b[q + 1])),
                                               std::min(std::min(c[q], c[q + 1]), std::min(d[q], d[q + 1])));
                        const T high = std::max(std::max(std::max(a[q], a[q + 1]), std::max(b[q], b[q + 1])),
                                                std::max(std::max(c[q], c[q + 1]), std::max(d[q], d[q + 1])));
                        ranges[q] = static_cast<float>(static_cast<Difference>(high) - static_cast<Difference>(low));
                    }
                    bits &= ~(Word{0xff} << first);
                }
            }
            for (; bits != 0; bits &= bits - 1) {
                const std::int64_t i = 64 * w + std::countr_zero(bits);
                ranges[i] = static_cast<float>(cell_range(a + i * sx_));
            }
        }
    }

    T at(std::int64_t i, std::int64_t j, std::int64_t k) const { return g_.data[g_.offset(i, j, k)]; }

    /// Classifies row (j, k) into f; returns its signs.
    CMC33_ALWAYS_INLINE detail::RowSigns classify(std::int64_t j, std::int64_t k, Word* f, Scratch& s) const
    {
        return detail::classify_row(g_.data + g_.offset(0, j, k), nx_, sx_, threshold_, f, s.scan);
    }

    /// Above-flags of the samples of row (j, k), and the row's signs (emit, which reads rows out
    /// of order: each is classified when first asked for).
    CMC33_ALWAYS_INLINE const Word* flags(std::int64_t j, std::int64_t k, Scratch& s, detail::RowSigns& signs) const
    {
        bool fresh = false;
        detail::RowSigns* known = nullptr;
        Word* f = s.masks.get(j, k, fresh, known);
        if (fresh) *known = classify(j, k, f, s);
        signs = *known;
        return f;
    }
    const Word* flags(std::int64_t j, std::int64_t k, Scratch& s) const
    {
        detail::RowSigns unused{};
        return flags(j, k, s, unused);
    }

    /// The flags and signs of the sample rows around cell row (j, k): (j, k), (j + 1, k),
    /// (j, k + 1), (j + 1, k + 1); a row past the grid gets (j, k)'s (no cell reads it then).
    CMC33_ALWAYS_INLINE void flags_around(std::int64_t j, std::int64_t k, Scratch& s, const Word* (&f)[4],
                                          detail::RowSigns (&signs)[4]) const
    {
        f[0] = flags(j, k, s, signs[0]);
        f[1] = f[2] = f[3] = f[0];
        signs[1] = signs[2] = signs[3] = signs[0];
        if (j + 1 < ny_) f[1] = flags(j + 1, k, s, signs[1]);
        if (k + 1 < nz_) f[2] = flags(j, k + 1, s, signs[2]);
        if (j + 1 < ny_ && k + 1 < nz_) f[3] = flags(j + 1, k + 1, s, signs[3]);
    }

    /// Vertex ids of the edges owned by the samples of row (j, k): ids[3 * i + axis], kNoVertex
    /// where the edge does not cross or does not exist (or, in the next range's plane k1, for the z
    /// edges, which no cell of this range uses). `interior`: the id after the row's last z edge
    /// vertex, where the interior vertices of its cells begin.
    CMC33_ALWAYS_INLINE const std::uint32_t* row_ids(std::int64_t j, std::int64_t k, Scratch& s, const Emit& e, std::int64_t& interior) const
    {
        bool fresh = false;
        std::int64_t* end = nullptr;
        std::uint32_t* ids = s.ids.get(j, k, fresh, end);
        if (!fresh) {
            interior = *end;
            return ids;
        }
        if (k == e.c.k1_) {
            // the next range's first plane: its x/y edge ids follow this range's last vertex
            *end = interior = -1; // not this range's row: no vertex of it is written
            const std::int64_t seam0 = e.c.seam_first_[static_cast<std::size_t>(j)];
            if (seam0 == e.c.seam_first_[static_cast<std::size_t>(j) + 1]) return ids; // nothing crosses: never read
            const Word* f = flags(j, k, s);
            const Word* fy = j + 1 < ny_ ? flags(j + 1, k, s) : f;
            auto xy = static_cast<std::uint32_t>(e.off.first_vertex + e.c.vertices_ + seam0);
            for (std::int64_t w = 0; w < words_; ++w) {
                const EdgeWords edges(f, fy, f, w, x_valid_[static_cast<std::size_t>(w)]);
                for (Word bits = edges.x | edges.y; bits != 0; bits &= bits - 1) {
                    const int b = std::countr_zero(bits);
                    const std::int64_t i = 64 * w + b;
                    if ((edges.x >> b) & 1u) ids[3 * i] = xy++;
                    if ((edges.y >> b) & 1u) ids[3 * i + 1] = xy++;
                }
            }
            if (xy != e.off.first_vertex + e.c.vertices_ + e.c.seam_first_[static_cast<std::size_t>(j) + 1]) {
                throw_mismatch("x/y edge vertices of the next range's first plane", j, k);
            }
            return ids;
        }
        const RowSpan r = span_of(e.c, j, k);
        if (r.xy0 == r.xy1 && r.z0 == r.v1) {
            // no vertex: no crossed edge, so no cell reads these slots (and no flags are needed)
            *end = interior = e.off.first_vertex + r.z0;
            return ids;
        }
        const Word* f = flags(j, k, s);
        const Word* fy = j + 1 < ny_ ? flags(j + 1, k, s) : f;
        const Word* fz = k + 1 < nz_ ? flags(j, k + 1, s) : f;
        auto xy = static_cast<std::uint32_t>(e.off.first_vertex + r.xy0);
        auto z = static_cast<std::uint32_t>(e.off.first_vertex + r.z0);
        // outside the trim range [lo, hi) no edge crosses
        for (std::int64_t w = r.lo / 64; w < (r.hi + 63) / 64; ++w) {
            const EdgeWords edges(f, fy, fz, w, x_valid_[static_cast<std::size_t>(w)]);
            for (Word bits = edges.any(); bits != 0; bits &= bits - 1) {
                const int b = std::countr_zero(bits);
                std::uint32_t* slot = &ids[3 * (64 * w + b)];
                // branch-free (selects, not jumps): crossings are unpredictable on rough surfaces
                const auto cx = static_cast<std::uint32_t>((edges.x >> b) & 1u);
                const auto cy = static_cast<std::uint32_t>((edges.y >> b) & 1u);
                const auto cz = static_cast<std::uint32_t>((edges.z >> b) & 1u);
                slot[0] = xy;
                xy += cx;
                slot[1] = xy;
                xy += cy;
                slot[2] = z;
                z += cz;
            }
        }
        if (xy != e.off.first_vertex + r.xy1) throw_mismatch("x/y edge vertices", j, k);
        if (z > e.off.first_vertex + r.v1) throw_mismatch("z edge vertices", j, k);
        *end = interior = z;
        return ids;
    }

    /// Count's decision for crossed cell (i, j, k) with case code `code`, which has no fixed tiling: its
    /// tiling, its subcase, and as one byte for emit to replay, (face tests' bits << 2) | tiling
    /// (at most 6 ambiguous faces and 3 tilings).
    const detail::Tiling& decide_cell(std::int64_t i, std::int64_t j, std::int64_t k, unsigned code, int& subcase,
                                      std::uint8_t& decision) const
    {
        double raw[8];
        for (int c = 0; c < 8; ++c) {
            raw[c] = static_cast<double>(at(i + kCornerOffset[c][0], j + kCornerOffset[c][1], k + kCornerOffset[c][2]));
        }
        const detail::Decision d = detail::decide(raw, iso_, code, method_, variants_);
        subcase = d.subcase;
        decision = static_cast<std::uint8_t>(d.joined << 2 | static_cast<unsigned>(d.tiling));
        return d.variant->tilings[d.tiling];
    }

    /// Tilings of at most this many triangles are written a fixed 3 * kShortTiling ids at a time.
    static constexpr int kShortTiling = 4;

    /// short_count_ and short_offsets_: for the case codes whose fixed tiling has no interior
    /// vertex and at most kShortTiling triangles, where each id of their triangles sits in the
    /// four id rows of IdRows, so that emit_row_cells goes from a cell's code to its ids in two
    /// loads. The offsets are 16 bits, a table of 24 KiB that stays in the L1 cache better than
    /// 32-bit ones; grids wider than 7281 samples, where they would not fit, have none (every
    /// cell takes emit_cell()).
    void build_short_tilings()
    {
        short_count_.fill(-1);
        const std::int64_t length = 3 * nx_; // IdRows::row_length()
        // the largest offset: the last of the four id rows (3 = kEdgeRow's largest), the largest slot
        // (std::max_element: the WebAssembly build's libc++ 13 has no std::ranges::max_element)
        const std::int64_t largest = 3 * length + *std::max_element(kEdgeSlot.begin(), kEdgeSlot.end());
        if (largest > std::numeric_limits<std::uint16_t>::max()) return;
        short_offsets_.assign(4 * 256 * 3 * kShortTiling, 0);
        for (unsigned code = 0; code < 256; ++code) {
            const detail::Tiling* tl = fixed_tiling_[code];
            if (tl == nullptr || tl->interior_count != 0 || tl->triangle_count > kShortTiling) continue;
            short_count_[code] = static_cast<std::int8_t>(tl->triangle_count);
            const std::uint8_t* codes = &detail::kTriangleCodes[static_cast<std::size_t>(tl->first_triangle) * 3];
            for (unsigned parity = 0; parity < 4; ++parity)
                for (int q = 0; q < 3 * tl->triangle_count; ++q) {
                    // past the tiling the entries stay 0: slot 0's first id, always inside the rows
                    const std::size_t edge = codes[q];
                    short_offsets_[(parity * 256 + code) * 3 * kShortTiling + static_cast<std::size_t>(q)] =
                        static_cast<std::uint16_t>((parity ^ kEdgeRow[edge]) * length + kEdgeSlot[edge]);
                }
        }
    }

    /// kTriangleCodes followed by 3 * kShortTiling zeros, so that a short tiling's fixed-size copy
    /// stays inside the table (both table sets index it).
    static const std::vector<std::uint8_t>& padded_codes()
    {
        static const std::vector<std::uint8_t> table = [] {
            std::size_t n = 0;
            for (const detail::Variant* set : {detail::kVariants, detail::kLegacyVariants})
                for (unsigned v = 0; v < detail::kVariantOffset[256]; ++v)
                    for (const detail::Tiling& t : set[v].tilings) {
                        n = std::max<std::size_t>(n, (static_cast<std::size_t>(t.first_triangle) + t.triangle_count) * 3);
                    }
            std::vector<std::uint8_t> codes(detail::kTriangleCodes, detail::kTriangleCodes + n);
            codes.resize(n + 3 * kShortTiling, 0);
            return codes;
        }();
        return table;
    }

    /// The tiling a decision byte of decide_cell() names for case code `code`; null when the byte
    /// cannot be one of that code's (the samples changed between count and emit).
    const detail::Tiling* replay(unsigned code, std::uint8_t decision) const
    {
        const unsigned joined = decision >> 2u, tiling = decision & 3u;
        const unsigned variants = detail::kVariantOffset[code + 1] - detail::kVariantOffset[code];
        if (joined >= variants || tiling > 2) return nullptr;
        return &variants_[detail::kVariantOffset[code] + joined].tilings[tiling];
    }

    /// Counts row (j, k) into its Row of `c`: x/y edge vertices in xy_first, z edge and interior
    /// vertices in z_first, triangles in triangle_first (count() turns them into first ids).
    /// `rows` and `signs`: those of the sample rows around the cell row, as flags_around(j, k) gives them.
    CMC33_ALWAYS_INLINE void count_row(std::int64_t j, std::int64_t k, Scratch& s, RangeCounts& c,
                                       const Word* const (&rows)[4], const detail::RowSigns (&signs)[4]) const
    {
        // Trim: when the sample rows this row's edges and cells reach are all above or all below,
        // nothing crosses (most rows of a CT volume).
        const Word *f = rows[0], *fy = rows[1], *fz = rows[2], *fyz = rows[3];
        const bool cells = j + 1 < ny_ && k + 1 < nz_;
        if constexpr (std::is_floating_point_v<T>) {
            if (s.scan.non_finite) {
                // before any cell of these rows is decided (a NaN has no sign): name the first one
                scan_samples(g_, c.k0_, std::min(c.k1_, nz_ - 1));
            }
        }
        const detail::RowSigns first = signs[0]; // all four rows all above or all below: the counts stay 0
        if (first != detail::RowSigns::mixed && signs[1] == first && signs[2] == first && signs[3] == first) return;
        RangeCounts::Row& row = c.rows_[static_cast<std::size_t>(j + (k - c.k0_) * ny_)];
        std::uint32_t xy = 0, z = 0;
        std::int64_t interior = 0, triangles = 0;
        std::int64_t lo = nx_, hi = 0;
        for (std::int64_t w = 0; w < words_; ++w) {
            const Word x_valid = x_valid_[static_cast<std::size_t>(w)];
            const EdgeWords edges(f, fy, fz, w, x_valid);
            const Word crossed = cells ? crossed_cells(f, fy, fz, fyz, w, x_valid) : 0;
            const Word used = edges.any() | crossed; // samples whose edges or cells cross
            if (used == 0) continue;
            lo = std::min<std::int64_t>(lo, 64 * w + std::countr_zero(used));
            hi = 64 * w + 64 - std::countl_zero(used);
            xy += static_cast<std::uint32_t>(popcount(edges.x) + popcount(edges.y));
            z += static_cast<std::uint32_t>(popcount(edges.z));
            const CellCodes codes(f, fy, fz, fyz, w);
            for (Word bits = crossed; bits != 0; bits &= bits - 1) {
                const int b = std::countr_zero(bits);
                const unsigned code = codes(b);
                int subcase = fixed_subcase_[code];
                const detail::Tiling* tl = fixed_tiling_[code];
                if (tl == nullptr) {
                    std::uint8_t decision = 0;
                    tl = &decide_cell(64 * w + b, j, k, code, subcase, decision);
                    c.decisions_.push_back(decision);
                }
                interior += tl->interior_count;
                triangles += tl->triangle_count;
                ++c.stats_.cells_per_subcase[static_cast<std::size_t>(subcase)];
            }
        }
        if (hi > lo) row.lo = static_cast<std::int32_t>(lo), row.hi = static_cast<std::int32_t>(hi);
        row.xy_first = xy;
        row.z_first = static_cast<std::uint32_t>(z + interior); // < 16 nx < 2^32 (check_grid)
        row.triangle_first = triangles;
    }

    /// The crossing parameter of the edge from sample value a to b, in [delta, 1 - delta]
    /// (src/core/placement.hpp: never on a sample, so ties do not collapse triangles).
    double crossing(T a, T b) const
    {
        const double va = static_cast<double>(a), vb = static_cast<double>(b);
        const double d = vb - va; // ends differ in sign: vb != va
        if (std::isinf(d)) {
            // |vb - va| passes DBL_MAX (samples near +-1e308): the same ratio on halved values,
            // which cannot overflow; iso lies between va and vb, so |iso - va| <= |vb - va|
            return detail::clamp_crossing((0.5 * iso_ - 0.5 * va) / (0.5 * vb - 0.5 * va), delta_);
        }
        return detail::clamp_crossing((iso_ - va) / d, delta_);
    }

    /// delta of placement.hpp for this grid: 2^-10 of an edge, or more where the output floats
    /// cannot tell a point delta along an edge from the sample (16 units in the last place of the
    /// largest coordinate, at most 1/8 of an edge).
    static double min_crossing(const GridView<T>& g, const Mat3& m)
    {
        const double largest = largest_coordinate(g);
        const double shortest = shortest_edge(m);
        if (!(largest > 0) || !(shortest > 0) || !std::isfinite(largest)) return detail::kMinCrossing;
        const double ulp = std::ldexp(1.0, std::ilogb(largest) - 23);
        return std::clamp(16 * ulp / shortest, detail::kMinCrossing, 0.125);
    }

    /// The world position of index-space point x (the frame of volume.hpp), rounded to float, as
    /// (x, y, z) or with `zyx` (MeshSpans) as (z, y, x).
    CMC33_ALWAYS_INLINE void write_position(const double x[3], float* out, bool zyx) const
    {
        float p[3];
        if (diagonal_) {
            for (std::size_t c = 0; c < 3; ++c) p[c] = static_cast<float>(g_.origin[c] + step_[c] * x[c]);
        } else {
            for (std::size_t c = 0; c < 3; ++c)
                p[c] = static_cast<float>(g_.origin[c] + (m_[c][0] * x[0] + m_[c][1] * x[1] + m_[c][2] * x[2]));
        }
        store(p, out, zyx);
    }

    /// out = p, or p reversed (z, y, x) with `zyx`.
    CMC33_ALWAYS_INLINE static void store(const float p[3], float* out, bool zyx)
    {
        const std::size_t first = zyx ? 2 : 0;
        out[first] = p[0];
        out[1] = p[1];
        out[2 - first] = p[2];
    }

    /// Samples widened so that differences of two are exact: int64 for integer types, double else.
    using Exact = std::conditional_t<std::is_integral_v<T>, std::int64_t, double>;

    /// Largest minus smallest of the 8 samples of cell (i, j, k).
    Exact cell_range(std::int64_t i, std::int64_t j, std::int64_t k) const { return cell_range(g_.data + g_.offset(i, j, k)); }
    /// ... of the cell whose lowest corner sample is at p: pairs, then a tree, no branch.
    CMC33_ALWAYS_INLINE Exact cell_range(const T* p) const
    {
        const std::int64_t sy = g_.strides[1], sz = g_.strides[2];
        const T a0 = p[0], a1 = p[sx_], a2 = p[sy], a3 = p[sx_ + sy];
        const T a4 = p[sz], a5 = p[sx_ + sz], a6 = p[sy + sz], a7 = p[sx_ + sy + sz];
        const T lo = std::min(std::min(std::min(a0, a1), std::min(a2, a3)), std::min(std::min(a4, a5), std::min(a6, a7)));
        const T hi = std::max(std::max(std::max(a0, a1), std::max(a2, a3)), std::max(std::max(a4, a5), std::max(a6, a7)));
        return static_cast<Exact>(hi) - static_cast<Exact>(lo);
    }

    /// MeshSpans::vertex_cell_ranges of the vertex on the edge from sample (i, j, k) along `axis`:
    /// the largest cell_range() of the (up to four) cells around the edge.
    float edge_cell_range(std::int64_t i, std::int64_t j, std::int64_t k, int axis) const
    {
        const std::int64_t idx[3] = {i, j, k}, n[3] = {nx_, ny_, nz_};
        const auto b = static_cast<std::size_t>((axis + 1) % 3), c = static_cast<std::size_t>((axis + 2) % 3);
        Exact largest = 0;
        if (idx[b] >= 1 && idx[b] + 1 < n[b] && idx[c] >= 1 && idx[c] + 1 < n[c]) {
            // all four cells: the smallest and largest of the edge's 3 x 3 lines of two samples
            // along `axis`, then each cell's 2 x 2 of those (selects, no branches)
            const T* p = g_.data + g_.offset(i, j, k);
            const std::int64_t sa = g_.strides[static_cast<std::size_t>(axis)], sb = g_.strides[b], sc = g_.strides[c];
            T lo[3][3], hi[3][3];
            for (std::int64_t u = 0; u < 3; ++u)
                for (std::int64_t w = 0; w < 3; ++w) {
                    const T* q = p + (u - 1) * sb + (w - 1) * sc;
                    const T x = q[0], y = q[sa];
                    lo[u][w] = x < y ? x : y;
                    hi[u][w] = x < y ? y : x;
                }
            for (int u = 0; u < 2; ++u)
                for (int w = 0; w < 2; ++w) {
                    const T l = std::min(std::min(lo[u][w], lo[u + 1][w]), std::min(lo[u][w + 1], lo[u + 1][w + 1]));
                    const T h = std::max(std::max(hi[u][w], hi[u + 1][w]), std::max(hi[u][w + 1], hi[u + 1][w + 1]));
                    const Exact range = static_cast<Exact>(h) - static_cast<Exact>(l);
                    largest = range > largest ? range : largest;
                }
            return static_cast<float>(largest);
        }
        for (std::int64_t u = -1; u <= 0; ++u)
            for (std::int64_t w = -1; w <= 0; ++w) {
                std::int64_t cell[3] = {i, j, k};
                cell[b] += u;
                cell[c] += w;
                if (cell[b] < 0 || cell[b] + 1 >= n[b] || cell[c] < 0 || cell[c] + 1 >= n[c]) continue;
                largest = std::max(largest, cell_range(cell[0], cell[1], cell[2]));
            }
        return static_cast<float>(largest);
    }

    /// A power of two that keeps every scaled gradient, and its interpolation between two samples,
    /// finite: 1 unless the samples or the map to world gradients are near the double range.
    /// (Scaling by a power of two is exact, so ranges with different bounds give the same normals.)
    double gradient_scale(double largest_sample) const
    {
        double map = 0; // largest factor from an index difference to a world gradient component
        for (std::size_t r = 0; r < 3; ++r) {
            if (diagonal_) {
                map = std::max(map, 1 / std::fabs(step_[r]));
            } else {
                map = std::max(map, std::fabs(normal_map_[r][0]) + std::fabs(normal_map_[r][1]) +
                                        std::fabs(normal_map_[r][2]));
            }
        }
        if (!(largest_sample > 0) || !(map > 0) || !std::isfinite(map)) return 1;
        // |gradient component| <= 2 * largest * map, its interpolation 3 times that: 2^3
        const int exponent = std::ilogb(largest_sample) + std::ilogb(map) + 5;
        return exponent > 1000 ? std::ldexp(1.0, 1000 - exponent) : 1.0;
    }

    /// The gradient at sample (i, j, k) by central differences (one-sided at the border), in world
    /// coordinates for a diagonal frame, in index coordinates otherwise (write_normal maps it),
    /// times `scale`.
    std::array<double, 3> gradient(std::int64_t i, std::int64_t j, std::int64_t k, double scale) const
    {
        std::array<double, 3> grad{};
        const T* p = g_.data + g_.offset(i, j, k);
        const std::int64_t idx[3] = {i, j, k};
        const std::int64_t n[3] = {nx_, ny_, nz_};
        for (std::size_t axis = 0; axis < 3; ++axis) {
            const std::int64_t stride = g_.strides[axis];
            const std::int64_t lo = idx[axis] > 0 ? -stride : 0, hi = idx[axis] + 1 < n[axis] ? stride : 0;
            // 1 / (2 step) inside, 1 / step at the border: a multiply, not a divide, per component
            const double inverse = lo != 0 && hi != 0 ? half_inverse_step_[axis] : 2 * half_inverse_step_[axis];
            grad[axis] = (scale * static_cast<double>(p[hi]) - scale * static_cast<double>(p[lo])) * inverse;
        }
        return grad;
    }

    /// The gradient at parameter t of the edge from sample (i, j, k) along `axis`: its ends'
    /// gradients (gradient()) mixed linearly. Where both ends have all six neighbours (nearly
    /// every vertex) the same numbers come from one bounds check and, for integer samples, exact
    /// differences in their own arithmetic.
    CMC33_ALWAYS_INLINE std::array<double, 3> edge_gradient(std::int64_t i, std::int64_t j, std::int64_t k, int axis,
                                                            double t, double scale) const
    {
        const std::int64_t idx[3] = {i, j, k}, n[3] = {nx_, ny_, nz_};
        bool inside = true;
        for (int a = 0; a < 3; ++a) inside &= idx[a] >= 1 && idx[a] + 1 + (a == axis) < n[a];
        std::array<double, 3> ga{}, gb{};
        if (inside) {
            const T* p = g_.data + g_.offset(i, j, k);
            const T* q = p + g_.strides[static_cast<std::size_t>(axis)];
            for (std::size_t c = 0; c < 3; ++c) {
                const std::int64_t st = g_.strides[c];
                ga[c] = difference(p[st], p[-st], scale) * half_inverse_step_[c];
                gb[c] = difference(q[st], q[-st], scale) * half_inverse_step_[c];
            }
        } else {
            ga = gradient(i, j, k, scale);
            gb = gradient(i + (axis == 0), j + (axis == 1), k + (axis == 2), scale);
        }
        return {ga[0] + t * (gb[0] - ga[0]), ga[1] + t * (gb[1] - ga[1]), ga[2] + t * (gb[2] - ga[2])};
    }

    /// scale * hi - scale * lo, as gradient() computes it: for integers at scale 1 (always, but
    /// for frames near the double range) the exact difference.
    static double difference(T hi, T lo, double scale)
    {
        if constexpr (std::is_integral_v<T>) {
            using Wide = std::conditional_t<(sizeof(T) < 4), int, std::int64_t>;
            if (scale == 1) return static_cast<double>(static_cast<Wide>(hi) - static_cast<Wide>(lo));
        } else {
            if (scale == 1) return static_cast<double>(hi) - static_cast<double>(lo); // the same numbers
        }
        return scale * static_cast<double>(hi) - scale * static_cast<double>(lo);
    }

    /// The vertices of the crossed edges owned by row (j, k) (its span `r`, its rows of flags as
    /// emit_planes found them), at the ids row_ids gave them; the outputs of MeshSpans that `kOut`
    /// says.
    template <Outputs kOut>
    void emit_row_vertices(std::int64_t j, std::int64_t k, const RowSpan& r, const Word* const (&rows)[4],
                           const std::uint32_t* ids, Scratch& s, const Emit& e) const
    {
        const Word *f = rows[0], *fy = rows[1], *fz = rows[2];
        CellsAround cells{};
        if constexpr (kOut != Outputs::plain) {
            if (s.ranges) cells = cells_around(j, k, s, e);
        }
        for (std::int64_t w = r.lo / 64; w < (r.hi + 63) / 64; ++w) {
            // an axis at a time: on rough surfaces which of a sample's edges cross is unpredictable
            const EdgeWords edges(f, fy, fz, w, x_valid_[static_cast<std::size_t>(w)]);
            emit_axis_vertices<0, kOut>(edges.x, w, j, k, ids, cells, e);
            emit_axis_vertices<1, kOut>(edges.y, w, j, k, ids, cells, e);
            emit_axis_vertices<2, kOut>(edges.z, w, j, k, ids, cells, e);
        }
    }

    /// The vertices of the crossed edges along `axis` of samples 64 w + b of row (j, k), b a bit of
    /// `crossed`.
    template <int axis, Outputs kOut>
    CMC33_ALWAYS_INLINE void emit_axis_vertices(Word crossed, std::int64_t w, std::int64_t j, std::int64_t k,
                                                const std::uint32_t* ids, const CellsAround& cells, const Emit& e) const
    {
        for (Word bits = crossed; bits != 0; bits &= bits - 1) {
            const std::int64_t i = 64 * w + std::countr_zero(bits);
            emit_edge_vertex<axis, kOut>(i, j, k, ids[3 * i + axis], cells, e);
        }
    }

    /// The vertex `id` on the edge from sample (i, j, k) along `axis`; `cells` (CellsAround) only
    /// with vertex_cell_ranges.
    template <int axis, Outputs kOut>
    CMC33_ALWAYS_INLINE void emit_edge_vertex(std::int64_t i, std::int64_t j, std::int64_t k, std::uint32_t id,
                                              const CellsAround& cells, const Emit& e) const
    {
        const MeshSpans& out = e.out;
        const std::int64_t end[3] = {i + (axis == 0), j + (axis == 1), k + (axis == 2)};
        const T a = at(i, j, k), b = at(end[0], end[1], end[2]);
        const double t = crossing(a, b);
        const double p[3] = {static_cast<double>(i), static_cast<double>(j), static_cast<double>(k)};
        double x[3];
        for (int c = 0; c < 3; ++c) x[c] = p[c] + (c == axis ? t : 0.0);
        const auto v = static_cast<std::size_t>(std::int64_t{id} - out.first_vertex);
        const bool zyx = kOut == Outputs::drop_in || (kOut == Outputs::all && out.zyx);
        write_position(x, &out.positions[v * 3], zyx);
        if (out.normals && !write_normal(&out.normals[v * 3], edge_gradient(i, j, k, axis, t, e.gradient_scale), zyx)) {
            // central differences cancel (alternating samples): the interpolant's own gradient,
            // never 0 on a crossed edge
            write_normal(&out.normals[v * 3], edge_cell_gradient(i, j, k, axis, t, e.gradient_scale), zyx);
        }
        if constexpr (kOut != Outputs::plain) {
            if (kOut == Outputs::drop_in || out.vertex_cell_ranges) {
                // x and y edges of the range's first plane: the cells below are the previous range's
                out.vertex_cell_ranges[v] = axis != 2 && cells.first_plane ? edge_cell_range(i, j, k, axis)
                                                                          : cells.template value<axis>(i);
            }
        }
        if constexpr (kOut == Outputs::all) {
            if (out.vertex_edges) out.vertex_edges[v] = 3 * (i + nx_ * (j + ny_ * k)) + axis;
            if (out.vertex_parameters) out.vertex_parameters[v] = static_cast<float>(t);
            if (out.vertex_values) {
                const double va = static_cast<double>(a), vb = static_cast<double>(b);
                out.vertex_values[v] = static_cast<float>(va + t * (vb - va));
            }
        }
    }

    /// Normals point from above to below: along minus the world gradient. `zyx` as in write_position.
    /// False (and (0, 0, 0) written) where g is 0: the caller then falls back to another gradient.
    CMC33_ALWAYS_INLINE bool write_normal(float* out, std::array<double, 3> g, bool zyx) const
    {
        if (!diagonal_) {
            const Mat3& n = normal_map_;
            g = {n[0][0] * g[0] + n[0][1] * g[1] + n[0][2] * g[2], n[1][0] * g[0] + n[1][1] * g[1] + n[1][2] * g[2],
                 n[2][0] * g[0] + n[2][1] * g[1] + n[2][2] * g[2]};
        }
        double len = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
        if (!(len > 0) || !std::isfinite(len)) {
            // the squares overflow (or underflow): divide by the largest component first
            const double big = std::max({std::fabs(g[0]), std::fabs(g[1]), std::fabs(g[2])});
            if (big > 0 && std::isfinite(big)) {
                for (double& c : g) c /= big;
                len = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
            }
        }
        if (!(len > 0)) {
            out[0] = out[1] = out[2] = 0.0f; // no direction here: the caller falls back
            return false;
        }
        const double minus_inverse = -1 / len; // one divide, then multiplies
        float n[3];
        for (std::size_t c = 0; c < 3; ++c) n[c] = static_cast<float>(g[c] * minus_inverse);
        store(n, out, zyx);
        return true;
    }

    /// The gradient of the trilinear interpolant at parameter t of the edge from sample (i, j, k)
    /// along `axis`, in the cell on the edge's upper side of each other axis (the lower side at the
    /// grid's last sample), scaled as gradient(). Its `axis` component is b - a: never 0 on a
    /// crossed edge, so a normal always has a direction.
    std::array<double, 3> edge_cell_gradient(std::int64_t i, std::int64_t j, std::int64_t k, int axis, double t,
                                             double scale) const
    {
        const std::int64_t idx[3] = {i, j, k}, n[3] = {nx_, ny_, nz_};
        const T* p = g_.data + g_.offset(i, j, k);
        const T* q = p + g_.strides[static_cast<std::size_t>(axis)];
        std::array<double, 3> grad{};
        for (std::size_t c = 0; c < 3; ++c) {
            const double inverse = 2 * half_inverse_step_[c];
            if (static_cast<int>(c) == axis) {
                grad[c] = difference(*q, *p, scale) * inverse;
                continue;
            }
            const std::int64_t st = idx[c] + 1 < n[c] ? g_.strides[c] : -g_.strides[c];
            const double sign = st > 0 ? 1.0 : -1.0;
            const double da = difference(p[st], p[0], scale), db = difference(q[st], q[0], scale);
            grad[c] = sign * (da + t * (db - da)) * inverse;
        }
        return grad;
    }

    /// The cells of cell row (j, k) (its span `r`, its four rows of flags as emit_planes found
    /// them): interior vertices from id `vertex` on and triangles from id `tri` on; both are left
    /// one past the last written. Cells with a test take the next of count's decisions, from
    /// `decision` on. The outputs of MeshSpans that `kOut` says.
    template <Outputs kOut>
    void emit_row_cells(std::int64_t j, std::int64_t k, const RowSpan& r, const Word* const (&rows)[4], Scratch& s,
                        const Emit& e, std::int64_t& vertex, std::int64_t& tri, std::size_t& decision) const
    {
        // the edge ids of the four sample rows around the cell row: (j,k), (j+1,k), (j,k+1), (j+1,k+1)
        std::int64_t unused = 0;
        const std::uint32_t* ids[4] = {row_ids(j, k, s, e, unused), row_ids(j + 1, k, s, e, unused),
                                       row_ids(j, k + 1, s, e, unused), row_ids(j + 1, k + 1, s, e, unused)};
        // cube edge q of the cell at i has its vertex id at edge_ids[q][3 * i]
        // (codes 12.. are interior vertices, never looked up here; their entries point into the
        // rows too, so that the fixed-width copy of a short tiling below may read the codes past
        // its end: it writes them into ids that the next cells overwrite)
        const std::uint32_t* edge_ids[12 + detail::kMaxInteriorVertices];
        for (std::size_t q = 0; q < 12; ++q) edge_ids[q] = ids[kEdgeRow[q]] + kEdgeSlot[q];
        for (std::size_t q = 12; q < std::size(edge_ids); ++q) edge_ids[q] = ids[0];
        const Word *f00 = rows[0], *f10 = rows[1], *f01 = rows[2], *f11 = rows[3];
        const MeshSpans& out = e.out;
        const std::int64_t copy_end = e.copy_end();
        const std::uint8_t* const padded_table = padded_codes().data();
        const bool flip = kOut != Outputs::plain ? mirrored_ != out.reverse_winding : mirrored_;
        // the short tilings' offsets for this row's parity: from `id_base` (IdRows' slot 0)
        // (none on grids too wide for them: short_count_ is then -1 for every code)
        const std::uint16_t* const short_offsets =
            short_offsets_.empty() ? nullptr
                                   : short_offsets_.data() + static_cast<std::size_t>((j & 1) | (k & 1) << 1) * 256 * 3 * kShortTiling;
        const std::uint32_t* const id_base = s.ids.base();
        tri = e.off.first_triangle + r.t0;
        // The case codes come from the same flags as the edge ids of row_ids, so a tiling's edges
        // are crossed edges, whose slots row_ids wrote.
        for (std::int64_t w = r.lo / 64; w < (r.hi + 63) / 64; ++w) {
          const CellCodes cell_codes(f00, f10, f01, f11, w);
          for (Word bits = crossed_cells(f00, f10, f01, f11, w, x_valid_[static_cast<std::size_t>(w)]); bits != 0;
               bits &= bits - 1) {
            const int bit = std::countr_zero(bits);
            const std::int64_t i = 64 * w + bit;
            const unsigned code = cell_codes(bit);
            const auto t0 = static_cast<std::size_t>(tri - out.first_triangle);
            std::uint32_t* o = &out.triangles[t0 * 3];
            int count = short_count_[code]; // triangles written
            if (count >= 0 && tri + kShortTiling <= copy_end) {
                // most cells: a fixed short tiling, 3 * kShortTiling ids, the ones past the
                // tiling overwritten by the next cells (no loop whose length the branch
                // predictor has to guess); copy_end bounds the triangles
                const std::uint16_t* offset = short_offsets + static_cast<std::size_t>(code) * 3 * kShortTiling;
                const std::uint32_t* at = id_base + 3 * i;
                for (int q = 0; q < 3 * kShortTiling; ++q) o[q] = at[offset[q]];
            } else {
                count = emit_cell(i, j, k, code, edge_ids, padded_table, r, e, tri, o, vertex, decision);
            }
            if (flip) {
                for (int q = 0; q < 3 * count; q += 3) std::swap(o[q + 1], o[q + 2]);
            }
            if constexpr (kOut == Outputs::all) {
                if (out.triangle_cells) {
                    const std::int64_t cell = i + nx_ * (j + ny_ * k);
                    for (int q = 0; q < count; ++q) out.triangle_cells[t0 + static_cast<std::size_t>(q)] = cell;
                }
            }
            tri += count;
          }
        }
    }

    /// The triangles of cell (i, j, k) (case code `code`) from `o` on (triangle id `tri`), and its
    /// interior vertices from id `vertex` on (then moved past them), unless its tiling is a short
    /// fixed one (the caller's); tested cells replay count's next decision. Returns the number of
    /// triangles.
    int emit_cell(std::int64_t i, std::int64_t j, std::int64_t k, unsigned code, const std::uint32_t* const* edge_ids,
                  const std::uint8_t* padded_table, const RowSpan& r, const Emit& e,
                  std::int64_t tri, std::uint32_t* o, std::int64_t& vertex, std::size_t& decision) const
    {
        const std::vector<std::uint8_t>& decisions = e.c.decisions_;
        const detail::Tiling* tl = fixed_tiling_[code];
        if (tl == nullptr) {
            tl = decision < decisions.size() ? replay(code, decisions[decision]) : nullptr;
            ++decision;
        }
        if (tl == nullptr || vertex + tl->interior_count > e.off.first_vertex + r.v1 ||
            tri + tl->triangle_count > e.off.first_triangle + r.t1) {
            throw_mismatch("cells", j, k); // before writing past the row's part of the output
        }
        const std::uint8_t* codes = &detail::kTriangleCodes[static_cast<std::size_t>(tl->first_triangle) * 3];
        const int n = 3 * tl->triangle_count;
        if (tl->interior_count == 0) {
            if (tl->triangle_count <= kShortTiling && tri + kShortTiling <= e.copy_end()) {
                // as for the fixed short tilings in emit_row_cells
                const std::uint8_t* padded = &padded_table[static_cast<std::size_t>(tl->first_triangle) * 3];
                for (int q = 0; q < 3 * kShortTiling; ++q) o[q] = edge_ids[padded[q]][3 * i];
            } else {
                for (int q = 0; q < n; ++q) o[q] = edge_ids[codes[q]][3 * i];
            }
        } else {
            const std::int64_t first_interior = vertex;
            write_interior_vertices(i, j, k, *tl, vertex, e);
            vertex += tl->interior_count;
            for (int q = 0; q < n; ++q) {
                const int v = codes[q];
                o[q] = v < 12 ? edge_ids[v][3 * i] : static_cast<std::uint32_t>(first_interior + (v - 12));
            }
        }
        return tl->triangle_count;
    }

    /// The gradient of the cell's trilinear interpolant (corner samples `value`) at unit point p,
    /// scaled as gradient().
    std::array<double, 3> cell_gradient(const T (&value)[8], const double (&p)[3], double scale) const
    {
        std::array<double, 3> grad{};
        for (std::size_t a = 0; a < 3; ++a) {
            double sum = 0;
            for (int c = 0; c < 8; ++c) {
                if ((c >> a) & 1) continue; // each pair of corners along axis a once
                const int d = c | (1 << a);
                double w = 1; // the pair's weight: the other two axes' linear factors
                for (std::size_t b = 0; b < 3; ++b) {
                    if (b != a) w *= ((c >> b) & 1) ? p[b] : 1 - p[b];
                }
                sum += w * difference(value[d], value[c], scale);
            }
            grad[a] = sum * 2 * half_inverse_step_[a];
        }
        return grad;
    }

    /// Minus the area-weighted normal of the tiling's triangles around its interior vertex q (unit
    /// point pq), as a gradient for write_normal(): where the interpolant itself is flat there (a
    /// critical point), the surface still has a side. Triangles wind with their normals toward the
    /// below side (mc33_tables.hpp), in index space; M^-T takes them to world space as it does
    /// gradients.
    std::array<double, 3> fan_gradient(const T (&value)[8], const detail::Tiling& tl, int q, const double (&pq)[3]) const
    {
        double crossings[12][3]; // the crossed edges' points (interior_position reads only those)
        for (int edge = 0; edge < 12; ++edge) {
            const int a = kEdgeCorners[edge][0], b = kEdgeCorners[edge][1];
            const bool crossed = (static_cast<double>(value[a]) >= iso_) != (static_cast<double>(value[b]) >= iso_);
            const double t = crossed ? crossing(value[a], value[b]) : 0.5;
            for (int c = 0; c < 3; ++c) crossings[edge][c] = static_cast<double>(kCornerOffset[a][c]) + (c == edge / 4 ? t : 0.0);
        }
        const auto point = [&](int code, double (&x)[3]) {
            if (code == 12 + q) {
                for (int c = 0; c < 3; ++c) x[c] = pq[c];
            } else if (code < 12) {
                for (int c = 0; c < 3; ++c) x[c] = crossings[code][c];
            } else {
                detail::interior_position(detail::kInteriorMasks[tl.first_interior + (code - 12)], crossings, x);
            }
        };
        const std::uint8_t* codes = &detail::kTriangleCodes[static_cast<std::size_t>(tl.first_triangle) * 3];
        std::array<double, 3> sum{};
        for (int f = 0; f < tl.triangle_count; ++f) {
            const std::uint8_t* t = codes + 3 * f;
            if (t[0] != 12 + q && t[1] != 12 + q && t[2] != 12 + q) continue;
            double a[3], b[3], c[3];
            point(t[0], a);
            point(t[1], b);
            point(t[2], c);
            const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
            sum[0] += u[1] * w[2] - u[2] * w[1];
            sum[1] += u[2] * w[0] - u[0] * w[2];
            sum[2] += u[0] * w[1] - u[1] * w[0];
        }
        for (std::size_t a = 0; a < 3; ++a) sum[a] *= -2 * half_inverse_step_[a];
        return sum;
    }

    /// The interior vertices of cell (i, j, k)'s tiling, ids from `first` on, placed by
    /// placement.hpp from the cell's crossings; normals interpolate the corners' gradients.
    void write_interior_vertices(std::int64_t i, std::int64_t j, std::int64_t k, const detail::Tiling& tl,
                                 std::int64_t first, const Emit& e) const
    {
        const MeshSpans& out = e.out;
        T value[8];
        for (int c = 0; c < 8; ++c) value[c] = at(i + kCornerOffset[c][0], j + kCornerOffset[c][1], k + kCornerOffset[c][2]);
        double crossing_at[12][3]; // only the needed edges' are written and read
        unsigned needed = 0;
        for (int q = 0; q < tl.interior_count; ++q) {
            const unsigned code = detail::kInteriorMasks[tl.first_interior + q];
            if (!(code & detail::kRadialBit)) {
                needed |= code & 0xfffu; // an edge mask
            } else if ((code & 31u) < detail::kCornerPoint) {
                needed |= 1u << (code & 31u); // a tube vertex over that edge's crossing
            }
        }
        for (unsigned left = needed; left != 0; left &= left - 1) { // set bits: no branch per edge
            const int edge = std::countr_zero(left);
            const int a = kEdgeCorners[edge][0], b = kEdgeCorners[edge][1];
            const double t = crossing(value[a], value[b]);
            for (int c = 0; c < 3; ++c)
                crossing_at[edge][c] = static_cast<double>(kCornerOffset[a][c]) + (c == edge / 4 ? t : 0.0);
        }
        std::array<double, 3> grad[8];
        if (out.normals) {
            const bool inside = i >= 1 && j >= 1 && k >= 1 && i + 2 < nx_ && j + 2 < ny_ && k + 2 < nz_;
            for (int c = 0; c < 8; ++c) {
                const std::int64_t ci = i + kCornerOffset[c][0], cj = j + kCornerOffset[c][1], ck = k + kCornerOffset[c][2];
                if (!inside) {
                    grad[c] = gradient(ci, cj, ck, e.gradient_scale);
                    continue;
                }
                // every corner has its six neighbours: gradient()'s numbers with one bounds check
                const T* p = g_.data + g_.offset(ci, cj, ck);
                for (std::size_t a = 0; a < 3; ++a) {
                    const std::int64_t st = g_.strides[a];
                    grad[c][a] = difference(p[st], p[-st], e.gradient_scale) * half_inverse_step_[a];
                }
            }
        }
        const double base[3] = {static_cast<double>(i), static_cast<double>(j), static_cast<double>(k)};
        for (int q = 0; q < tl.interior_count; ++q) {
            double p[3];
            detail::interior_position(detail::kInteriorMasks[tl.first_interior + q], crossing_at, p);
            const auto v = static_cast<std::size_t>(first + q - out.first_vertex);
            const double x[3] = {base[0] + p[0], base[1] + p[1], base[2] + p[2]};
            write_position(x, &out.positions[v * 3], out.zyx);
            double w[8];
            if (out.normals || out.vertex_values) detail::trilinear_weights(p, w);
            if (out.normals) {
                std::array<double, 3> n{};
                for (int c = 0; c < 8; ++c)
                    for (std::size_t a = 0; a < 3; ++a) n[a] += w[c] * grad[c][a];
                if (!write_normal(&out.normals[v * 3], n, out.zyx) &&
                    !write_normal(&out.normals[v * 3], cell_gradient(value, p, e.gradient_scale), out.zyx)) {
                    write_normal(&out.normals[v * 3], fan_gradient(value, tl, q, p), out.zyx);
                }
            }
            if (out.vertex_edges) out.vertex_edges[v] = -1 - (i + nx_ * (j + ny_ * k));
            if (out.vertex_parameters) out.vertex_parameters[v] = -1.0f;
            if (out.vertex_cell_ranges) out.vertex_cell_ranges[v] = static_cast<float>(cell_range(i, j, k));
            if (out.vertex_values) {
                double f = 0;
                for (int c = 0; c < 8; ++c) f += w[c] * static_cast<double>(value[c]);
                out.vertex_values[v] = static_cast<float>(f);
            }
        }
    }

    const GridView<T>& g_;
    double iso_;
    detail::Threshold<T> threshold_;
    Method method_;
    std::int64_t nx_, ny_, nz_, sx_;
    std::int64_t words_;               ///< words of a row's flags
    std::vector<Word> x_valid_;        ///< bits of the x edges and cells 0..nx-2
    Mat3 m_;                  ///< index to world: M = D * diag(spacing)
    bool diagonal_, mirrored_; ///< M diagonal; det M < 0 (triangles are reversed)
    double step_[3] = {};      ///< the diagonal of M when diagonal_, else 1 (see gradient())
    double half_inverse_step_[3] = {}; ///< 1 / (2 step_), central differences' factor
    Mat3 normal_map_{};        ///< M^-T, for a non-diagonal M
    double delta_; ///< crossings lie in [delta_, 1 - delta_] of their edge
    /// The method's table set (detail::tables_of): chosen once here, so the passes' loops read one
    /// pointer and nothing in them depends on the method
    const detail::Variant* variants_;
    /// Per case code: its one tiling, or null when the method decides the cell (face or interior
    /// tests); and its subcase then.
    std::array<const detail::Tiling*, 256> fixed_tiling_{};
    std::array<std::uint8_t, 256> fixed_subcase_{};
    /// build_short_tilings(): per case code its short tiling's triangle count, or -1; per parity
    /// of the cell row and code, 3 * kShortTiling offsets into IdRows
    std::array<std::int8_t, 256> short_count_{};
    std::vector<std::uint16_t> short_offsets_;
};

namespace {

/// Checks the grid and isovalue: everything but the samples.
template <class T> void check_grid(const GridView<T>& g, double iso)
{
    if (!std::isfinite(iso)) {
        throw Error(Status::non_finite, "isovalue " + std::to_string(iso) + " is not a finite number");
    }
    for (int a = 0; a < 3; ++a) {
        if (g.dims[static_cast<std::size_t>(a)] < 2) {
            throw Error(Status::invalid_argument, "grid has " + std::to_string(g.dims[static_cast<std::size_t>(a)]) +
                                                      " samples along " + "xyz"[a] +
                                                      "; an isosurface needs at least 2 on each axis");
        }
    }
    if (g.data == nullptr) throw Error(Status::invalid_argument, "grid view has no samples (a null data pointer)");
    const Mat3 m = frame_matrix(g.spacing, g.direction);
    for (std::size_t r = 0; r < 3; ++r) {
        const bool finite = std::isfinite(g.origin[r]) && std::isfinite(m[r][0]) && std::isfinite(m[r][1]) &&
                            std::isfinite(m[r][2]);
        if (!finite) throw Error(Status::non_finite, "the grid's origin, spacing or direction is not finite");
    }
    if (!(std::fabs(determinant(m)) > 0)) {
        throw Error(Status::invalid_argument,
                    "the grid's frame is degenerate (det of direction * spacing is 0); expected three "
                    "independent axes");
    }
    const double largest = largest_coordinate(g);
    if (!std::isfinite(static_cast<float>(largest))) {
        char text[200];
        std::snprintf(text, sizeof text, "world coordinates up to %.4g do not fit the output's 32-bit floats "
                                         "(at most %.4g); scale the spacing or origin down", largest,
                      static_cast<double>(std::numeric_limits<float>::max()));
        throw Error(Status::too_large, text);
    }
    if (const double steps = float_steps_per_cell(g.dims, g.spacing, g.origin, g.direction); steps < kMinFloatStepsPerCell) {
        char text[400];
        std::snprintf(text, sizeof text,
                      "world coordinates up to %.6g leave 32-bit floats %.3g steps across a cell, too few to keep the "
                      "mesh embedded (at least %g needed); move the origin nearer 0, or write double-precision "
                      "positions (cmc33 extract --positions double)",
                      largest, steps, kMinFloatStepsPerCell);
        throw Error(Status::too_large, text);
    }
    // a row's vertex count (3 nx edge vertices + at most 12 interior ones per cell) is kept in 32
    // bits, which keeps the counting loops vectorised and RangeCounts at 24 bytes a row
    constexpr std::int64_t kMaxRow = std::numeric_limits<std::uint32_t>::max() / 16;
    if (g.nx() > kMaxRow) {
        throw Error(Status::too_large, "grid has " + std::to_string(g.nx()) + " samples along x; the extractor handles at most " +
                                           std::to_string(kMaxRow) + " per row");
    }
}

std::string range_text(std::int64_t k0, std::int64_t k1)
{
    return "[" + std::to_string(k0) + ", " + std::to_string(k1) + ")";
}

} // namespace

/// The passes run on the grid as it is; cmc33-paper may refine it first.
static void check_passes_method(const ExtractOptions& options, const char* pass)
{
    if (options.method == Method::cmc33_paper) {
        throw Error(Status::invalid_argument, std::string(pass) +
                                                  ": method cmc33-paper refines the grid first (Custodio et al. 2013, "
                                                  "Sec. 6.2), which the passes cannot; use extract(), or another method");
    }
}

template <class T>
RangeCounts count(const GridView<T>& grid, double iso, const ExtractOptions& options, std::int64_t k0, std::int64_t k1)
{
    check_passes_method(options, "count");
    check_grid(grid, iso);
    if (!(0 <= k0 && k0 < k1 && k1 <= grid.nz())) {
        throw Error(Status::invalid_argument, "count: sample planes " + range_text(k0, k1) + "; expected 0 <= k0 < k1 <= " +
                                                  std::to_string(grid.nz()) + " (the grid's nz)");
    }
    // count reads planes k0..k1 (checking them as it goes); emit's normals also read k0 - 1 and k1 + 1
    double largest = 0;
    if (k0 > 0) largest = scan_samples(grid, k0 - 1, k0 - 1);
    if (k1 + 1 < grid.nz()) largest = std::max(largest, scan_samples(grid, k1 + 1, k1 + 1));
    return RangeExtractor<T>(grid, iso, options).count(k0, k1, largest, nullptr);
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

template <class T>
void emit(const GridView<T>& grid, double iso, const ExtractOptions& options, const RangeCounts& counts,
          const RangeOffsets& offsets, const MeshSpans& out)
{
    check_passes_method(options, "emit");
    check_grid(grid, iso);
    if (counts.k1() > grid.nz() || counts.k0() >= counts.k1() || !RangeExtractor<T>::same_rows(counts, grid)) {
        throw Error(Status::invalid_argument, "emit: the counts of planes " + range_text(counts.k0(), counts.k1()) +
                                                  " are not of this grid (" + std::to_string(grid.nx()) + "x" +
                                                  std::to_string(grid.ny()) + "x" + std::to_string(grid.nz()) +
                                                  "); expected counts from count() on the same grid");
    }
    RangeExtractor<T>(grid, iso, options).emit(counts, offsets, out, nullptr);
}

template <class T> Mesh extract(const GridView<T>& grid, double iso, const ExtractOptions& options, ExtractStats* stats)
{
    if (options.method == Method::cmc33_paper) {
        check_grid(grid, iso);
        scan_samples(grid, 0, grid.nz() - 1); // refine.cpp decides cells before any pass has read them
        return detail::extract_refined(grid, iso, options, stats);
    }
    return detail::extract_passes(grid, iso, options, stats);
}

template <class T>
Mesh detail::extract_passes(const GridView<T>& grid, double iso, const ExtractOptions& options, ExtractStats* stats)
{
    check_grid(grid, iso);
    const std::int64_t nz = grid.nz();
    const RangeExtractor<T> extractor(grid, iso, options);
    const int n = static_cast<int>(std::clamp<std::int64_t>(detail::resolve_threads(options.threads), 1, nz));
    // More ranges than threads, taken in turn by whichever thread is free: a surface is seldom
    // spread evenly over the planes. Ranges of at least 8 planes keep the planes read twice (at
    // the ranges' ends) few; the mesh is the same for every split. Where x is not the contiguous
    // axis, each range is read through a window() (passes.hpp) of about 4 MiB (at least 3 planes).
    const std::int64_t window_planes = window_range_planes(grid);
    std::int64_t split = n == 1 ? 1 : std::clamp<std::int64_t>(nz / 8, n, 8 * std::int64_t{n});
    if (window_planes > 0) split = std::max(split, (nz + window_planes - 1) / window_planes);
    const int ranges = static_cast<int>(std::min<std::int64_t>(split, std::numeric_limits<int>::max()));
    const auto first_plane = [nz, ranges](int r) { return nz * r / ranges; };
    // runs work on the extractor of range r: `extractor`, or one on the range's window in task t's
    // buffer (an extractor's tables take microseconds, a window's copy milliseconds)
    std::vector<Buffer<T>> windows(static_cast<std::size_t>(window_planes > 0 ? n : 0));
    const auto with_extractor = [&](int r, int t, const auto& work) {
        if (window_planes == 0) return work(extractor);
        const GridView<T> view = window(grid, first_plane(r), first_plane(r + 1), windows[static_cast<std::size_t>(t)]);
        return work(RangeExtractor<T>(view, iso, options));
    };
    Ticker ticker(options.progress, 2 * nz);

    std::vector<int> order(static_cast<std::size_t>(ranges));
    std::iota(order.begin(), order.end(), 0);
    std::vector<RangeCounts> counts(static_cast<std::size_t>(ranges));
    try {
        for_each_range(n, order, options.executor, ticker, [&](int r, int t) {
            counts[static_cast<std::size_t>(r)] = with_extractor(r, t, [&](const RangeExtractor<T>& x) {
                return x.count(first_plane(r), first_plane(r + 1), 0.0, &ticker);
            });
        });
    } catch (const Error& e) {
        // a range names its own non-finite samples: say how many the whole grid has, and the first
        if (e.status() == Status::non_finite) scan_samples(grid, 0, nz - 1);
        throw;
    }
    if (ticker.cancelled()) throw_cancelled();
    RangeExtractor<T>::share_largest_sample(counts);
    const std::vector<RangeOffsets> offsets = scan(counts);
    const std::int64_t nv = offsets.back().first_vertex + counts.back().vertex_count();
    const std::int64_t nt = offsets.back().first_triangle + counts.back().triangle_count();
    if (nv >= static_cast<std::int64_t>(kNoVertex)) {
        throw Error(Status::too_large, "the mesh would have " + std::to_string(nv) +
                                           " vertices, more than 32-bit indices can address");
    }
    Mesh mesh;
    mesh.positions.resize(static_cast<std::size_t>(nv) * 3);
    if (options.normals) mesh.normals.resize(static_cast<std::size_t>(nv) * 3);
    mesh.triangles.resize(static_cast<std::size_t>(nt) * 3);
    MeshSpans out;
    out.positions = mesh.positions.data();
    out.triangles = mesh.triangles.data();
    out.normals = options.normals ? mesh.normals.data() : nullptr;
    // largest first (bonsai, 2 threads: the plane order left one thread idle for most of a large range)
    for_each_range(n, emit_order(counts), options.executor, ticker, [&](int r, int t) {
        with_extractor(r, t, [&](const RangeExtractor<T>& x) {
            x.emit(counts[static_cast<std::size_t>(r)], offsets[static_cast<std::size_t>(r)], out, &ticker);
        });
    });
    if (ticker.cancelled()) throw_cancelled();
    ticker.finish();
    if (ticker.cancelled()) throw_cancelled(); // false to the final 1 stops too: no mesh
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

double float_steps_per_cell(const Index3& dims, const Vec3& spacing, const Vec3& origin, const Mat3& direction)
{
    const Mat3 m = frame_matrix(spacing, direction);
    // ulp[r]: the float spacing of world component r at its largest |value| over the box
    double ulp[3] = {0, 0, 0};
    for (std::size_t r = 0; r < 3; ++r) {
        double largest = 0;
        for (int corner = 0; corner < 8; ++corner) {
            double w = origin[r];
            for (std::size_t a = 0; a < 3; ++a) w += (corner >> a) & 1 ? m[r][a] * static_cast<double>(dims[a] - 1) : 0.0;
            largest = std::max(largest, std::fabs(w));
        }
        if (!std::isfinite(largest)) return 0;
        if (largest > 0) ulp[r] = std::ldexp(1.0, std::ilogb(largest) - 23);
    }
    // rounding component r moves a point by up to ulp[r]; M^-1 says how far that is in cells
    const Mat3 inverse_t = inverse_transpose(m); // inverse_t[r][a] = M^-1[a][r]
    double steps = std::numeric_limits<double>::infinity();
    for (std::size_t a = 0; a < 3; ++a) {
        double cells = 0;
        for (std::size_t r = 0; r < 3; ++r) cells += std::fabs(inverse_t[r][a]) * ulp[r];
        if (!std::isfinite(cells)) return 0;
        if (cells > 0) steps = std::min(steps, 1 / cells);
    }
    return steps;
}

Mesh extract(const Volume& volume, double iso, const ExtractOptions& options, ExtractStats* stats)
{
    return volume.visit([&](auto view) { return extract(view, iso, options, stats); });
}

#define CMC33_INSTANTIATE(T)                                                                                    \
    template Mesh extract<T>(const GridView<T>&, double, const ExtractOptions&, ExtractStats*);                       \
    template Mesh detail::extract_passes<T>(const GridView<T>&, double, const ExtractOptions&, ExtractStats*);        \
    template RangeCounts count<T>(const GridView<T>&, double, const ExtractOptions&, std::int64_t, std::int64_t);      \
    template void emit<T>(const GridView<T>&, double, const ExtractOptions&, const RangeCounts&, const RangeOffsets&, \
                          const MeshSpans&);
CMC33_FOR_EACH_SAMPLE_TYPE(CMC33_INSTANTIATE)
#undef CMC33_INSTANTIATE

} // namespace cmc33
