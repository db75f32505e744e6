// window() of passes.hpp: the planes a range's passes read, copied with x contiguous.
//
// The copy reads runs along the grid's smallest stride. Its planes are a cache line more than
// nx * ny samples apart: with planes exactly 2^n bytes apart, the writes of a run along z (one per
// plane) all fall into one cache set and evict each other (bonsai 256^3 uint8 in Fortran order,
// through cmc33.marching_cubes, one sample at a time: 0.50 s against 0.08 s with the padding;
// the tiles of copy_z_runs then took it to 0.05 s, C order 0.03 s).

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "cmc33/error.hpp"
#include "cmc33/passes.hpp"
#include "portability.hpp"
#include "sample_types.hpp"

namespace cmc33 {
namespace {

/// Transposes a square tile of 8 / S elements of S bytes, a row per word (element c of row r in
/// bits 8 S c .. 8 S (c + 1) - 1): afterwards row r holds what was column r. Swaps of ever larger
/// blocks between rows: 3 stages for bytes, each a shift, an xor and a mask per pair of rows.
template <std::size_t S> CMC33_ALWAYS_INLINE void transpose_tile(std::uint64_t (&rows)[8 / S])
{
    constexpr int n = 8 / S;
    for (int unit = 8 * S, step = 1; unit < 64; unit *= 2, step *= 2) {
        std::uint64_t mask = 0;
        for (int b = 0; b < 64; b += 2 * unit) mask |= ((std::uint64_t{1} << unit) - 1) << b;
        for (int r0 = 0; r0 < n; r0 += 2 * step) // rows r and r + step of each group of 2 step
            for (int r = r0; r < r0 + step; ++r) {
                const std::uint64_t t = ((rows[r] >> unit) ^ rows[r + step]) & mask;
                rows[r + step] ^= t;
                rows[r] ^= t << unit;
            }
    }
}

/// Planes [lo, hi) of a grid whose z samples are adjacent (stride 1: Fortran order) into `to`
/// (planes `plane` samples apart, rows nx apart), by tiles of n x n samples (n = 8 / sizeof(T))
/// along x and z transposed in 64-bit words: one load and one store per n samples instead of one
/// per sample. Samples past whole tiles go one by one. The runs kAhead samples on along x are
/// fetched ahead: they lie a plane of the grid apart, which the hardware does not fetch ahead
/// (docs/performance.md, "Python": Fortran order).
template <class T> void copy_z_runs(const GridView<T>& g, std::int64_t lo, std::int64_t hi, std::int64_t plane, T* to)
{
    constexpr std::int64_t n = 8 / sizeof(T);
    constexpr std::int64_t kAhead = 16; // runs (x) fetched ahead of the tile
    const std::int64_t nx = g.nx(), ny = g.ny(), planes = hi - lo, sx = g.strides[0], sy = g.strides[1];
    const std::int64_t tiled_x = nx - nx % n, tiled_z = planes - planes % n;
    for (std::int64_t j = 0; j < ny; ++j) {
        const T* row = g.data + j * sy + lo; // sample (0, j, lo)
        T* out = to + j * nx;
        for (std::int64_t i0 = 0; i0 < tiled_x; i0 += n) {
            for (std::int64_t i = i0 + kAhead; i < std::min(i0 + kAhead + n, nx); ++i) {
                CMC33_PREFETCH(row + i * sx);
                CMC33_PREFETCH(row + i * sx + planes - 1);
            }
            for (std::int64_t k0 = 0; k0 < tiled_z; k0 += n) {
                std::uint64_t words[n];
                for (std::int64_t r = 0; r < n; ++r) std::memcpy(&words[r], row + (i0 + r) * sx + k0, 8);
                transpose_tile<sizeof(T)>(words);
                for (std::int64_t r = 0; r < n; ++r) std::memcpy(out + (k0 + r) * plane + i0, &words[r], 8);
            }
            for (std::int64_t i = i0; i < i0 + n; ++i)
                for (std::int64_t k = tiled_z; k < planes; ++k) out[k * plane + i] = row[i * sx + k];
        }
        for (std::int64_t i = tiled_x; i < nx; ++i)
            for (std::int64_t k = 0; k < planes; ++k) out[k * plane + i] = row[i * sx + k];
    }
}

/// Planes [lo, hi) of a grid whose smallest stride is along z (`z_inner`) or y into `to` (planes
/// `plane` samples apart, rows nx apart): the (x, inner) squares transposed in tiles of n x n
/// samples (n a cache line's worth, at least 8), so that each line a tile reads (one per x) and
/// writes (one per inner sample) is used whole. x tiles outermost, then the rows of the third
/// axis, whose lines kAhead rows on are fetched ahead: a window of a few planes of a z-innermost
/// grid reads runs of a line or two, 2 KB and more apart, which the hardware does not fetch ahead
/// (docs/performance.md, "Python": Fortran order).
template <class T>
void copy_tiles(const GridView<T>& g, std::int64_t lo, std::int64_t hi, std::int64_t plane, T* to, bool z_inner)
{
    constexpr std::int64_t n = std::max<std::int64_t>(8, 64 / sizeof(T));
    constexpr std::int64_t kAhead = 4; // rows of the outer axis whose lines are fetched ahead
    const std::int64_t nx = g.nx(), ny = g.ny(), sx = g.strides[0], sy = g.strides[1], sz = g.strides[2];
    const std::int64_t inner_n = z_inner ? hi - lo : ny, outer_n = z_inner ? ny : hi - lo;
    const std::int64_t from_inner = z_inner ? sz : sy, to_inner = z_inner ? plane : nx;
    const std::int64_t from_outer = z_inner ? sy : sz, to_outer = z_inner ? nx : plane;
    const T* const first = g.data + lo * sz; // sample (0, 0, lo)
    for (std::int64_t i0 = 0; i0 < nx; i0 += n) {
        const std::int64_t i1 = std::min(i0 + n, nx);
        for (std::int64_t o = 0; o < outer_n; ++o) {
            const T* from = first + o * from_outer;
            T* out = to + o * to_outer;
            if (o + kAhead < outer_n) {
                for (std::int64_t i = i0; i < i1; ++i) {
                    CMC33_PREFETCH(from + kAhead * from_outer + i * sx);
                    CMC33_PREFETCH(from + kAhead * from_outer + i * sx + (inner_n - 1) * from_inner);
                }
            }
            for (std::int64_t a0 = 0; a0 < inner_n; a0 += n) {
                const std::int64_t a1 = std::min(a0 + n, inner_n);
                for (std::int64_t a = a0; a < a1; ++a)
                    for (std::int64_t i = i0; i < i1; ++i) out[a * to_inner + i] = from[i * sx + a * from_inner];
            }
        }
    }
}

} // namespace

template <class T> GridView<T> window(const GridView<T>& grid, std::int64_t k0, std::int64_t k1, Buffer<T>& buffer)
{
    const std::int64_t nx = grid.nx(), ny = grid.ny(), nz = grid.nz();
    if (!(0 <= k0 && k0 < k1 && k1 <= nz)) {
        throw Error(Status::invalid_argument, "window: planes [" + std::to_string(k0) + ", " + std::to_string(k1) +
                                                  ") are not a range of the grid's " + std::to_string(nz));
    }
    const std::int64_t lo = std::max<std::int64_t>(k0 - 1, 0), hi = std::min(k1 + 2, nz);
    const std::int64_t plane = nx * ny + detail::kWindowPad<T>;
    buffer.resize(static_cast<std::size_t>((hi - lo) * plane));
    T* const to = buffer.data();
    const std::int64_t sx = grid.strides[0], sy = grid.strides[1], sz = grid.strides[2];
    const std::int64_t ax = std::llabs(sx), ay = std::llabs(sy), az = std::llabs(sz);
    if (ax <= ay && ax <= az) {
        // x innermost (negative steps along x): each row a run
        for (std::int64_t k = lo; k < hi; ++k)
            for (std::int64_t j = 0; j < ny; ++j) {
                const T* from = grid.data + j * sy + k * sz;
                T* out = to + (k - lo) * plane + j * nx;
                for (std::int64_t i = 0; i < nx; ++i) out[i] = from[i * sx];
            }
    } else if (sz == 1 && sizeof(T) < 8 && std::endian::native == std::endian::little) {
        copy_z_runs(grid, lo, hi, plane, to);
    } else {
        copy_tiles(grid, lo, hi, plane, to, az <= ay);
    }
    // The view's data pointer stands for sample (0, 0, 0), which lies before the buffer (an
    // address computed as an integer): only planes lo .. hi - 1 are ever read through it.
    GridView<T> view = grid;
    const auto skip = static_cast<std::uintptr_t>(lo * plane) * sizeof(T);
    view.data = reinterpret_cast<const T*>(reinterpret_cast<std::uintptr_t>(to) - skip);
    view.strides = {1, nx, plane};
    return view;
}

#define CMC33_INSTANTIATE(T) template GridView<T> window<T>(const GridView<T>&, std::int64_t, std::int64_t, Buffer<T>&);
CMC33_FOR_EACH_SAMPLE_TYPE(CMC33_INSTANTIATE)
#undef CMC33_INSTANTIATE

} // namespace cmc33
