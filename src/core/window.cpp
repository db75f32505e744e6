// window() of passes.hpp: the planes a range's passes read, copied with x contiguous.
//
// The copy reads runs along the grid's smallest stride. Its planes are a cache line more than
// nx * ny samples apart: with planes exactly 2^n bytes apart, the writes of a run along z (one per
// plane) all fall into one cache set and evict each other (bonsai 256^3 uint8 in Fortran order,
// through cmc33.marching_cubes: 0.50 s against 0.04 s with the padding).

#include <algorithm>
#include <cstdint>
#include <cstdlib>

#include "cmc33/error.hpp"
#include "cmc33/passes.hpp"
#include "sample_types.hpp"

namespace cmc33 {

template <class T> GridView<T> window(const GridView<T>& grid, std::int64_t k0, std::int64_t k1, Buffer<T>& buffer)
{
    const std::int64_t nx = grid.nx(), ny = grid.ny(), nz = grid.nz();
    if (!(0 <= k0 && k0 < k1 && k1 <= nz)) {
        throw Error(Status::invalid_argument, "window: planes [" + std::to_string(k0) + ", " + std::to_string(k1) +
                                                  ") are not a range of the grid's " + std::to_string(nz));
    }
    const std::int64_t lo = std::max<std::int64_t>(k0 - 1, 0), hi = std::min(k1 + 2, nz);
    const std::int64_t plane = nx * ny + std::max<std::int64_t>(64 / static_cast<std::int64_t>(sizeof(T)), 1);
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
    } else if (az <= ay) {
        // z innermost (Fortran order): each (i, j) a run along z, 8 rows j at a time, whose lines
        // in every plane stay in cache while i runs
        for (std::int64_t j0 = 0; j0 < ny; j0 += 8)
            for (std::int64_t i = 0; i < nx; ++i)
                for (std::int64_t j = j0; j < std::min(j0 + 8, ny); ++j) {
                    const T* from = grid.data + i * sx + j * sy + lo * sz;
                    T* out = to + j * nx + i;
                    for (std::int64_t k = 0; k < hi - lo; ++k) out[k * plane] = from[k * sz];
                }
    } else {
        // y innermost: each (i, k) a run along y
        for (std::int64_t k = lo; k < hi; ++k)
            for (std::int64_t i = 0; i < nx; ++i) {
                const T* from = grid.data + i * sx + k * sz;
                T* out = to + (k - lo) * plane + i;
                for (std::int64_t j = 0; j < ny; ++j) out[j * nx] = from[j * sy];
            }
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
