#pragma once
/// @file drop_in.hpp
/// The extraction behind cmc33.marching_cubes: the library's public passes (cmc33/passes.hpp)
/// writing straight into the buffers handed to numpy, and what scikit-image's function returns
/// beside the mesh (per-vertex values, a cell mask, the winding of gradient_direction).

#include <cstdint>

#include "binding.hpp"
#include "cmc33/mesh.hpp"

namespace cmc33::python {

/// The four arrays of marching_cubes; the buffers may be longer than the counts (a mask drops
/// triangles and vertices in place).
struct DropInMesh {
    Buffer<float> positions; ///< 3 per vertex
    Buffer<float> normals;   ///< 3 per vertex, unit
    Buffer<float> values;    ///< 1 per vertex
    Buffer<std::uint32_t> triangles;
    std::int64_t vertex_count = 0;
    std::int64_t triangle_count = 0;
};

/// One flag per cell of the grid, non-zero where the cell is kept: cell (i, j, k) (lowest corner
/// sample (i, j, k)) at data[i * strides[0] + j * strides[1] + k * strides[2]].
struct CellMask {
    const std::uint8_t* data = nullptr;
    Index3 dims{0, 0, 0}; ///< the grid's dims minus 1
    Index3 strides{0, 0, 0};
    bool operator()(std::int64_t i, std::int64_t j, std::int64_t k) const noexcept
    {
        return data[i * strides[0] + j * strides[1] + k * strides[2]] != 0;
    }
};

struct DropInOptions {
    Method method = Method::cmc33;
    bool descent = true;            ///< wind triangles as scikit-image's gradient_direction='descent'
    const CellMask* mask = nullptr; ///< keep only the triangles of these cells
    int threads = 0;                ///< 0: all cores; the arrays are the same for every count
};

/// The mesh of extract() with normals, its positions and normals in the array's axis order
/// (z, y, x: columns 0 and 2 swapped), and per vertex the largest value range (largest minus
/// smallest corner sample) of the kept cells whose triangles use it: what scikit-image returns
/// as `values`. Swapping two coordinates mirrors the mesh, so extract()'s triangles, which wind
/// counter-clockwise around the normals, wind clockwise in the array's order: scikit-image's
/// 'descent'; 'ascent' reverses them. Stops between ranges of sample planes once control says so
/// (Error{cancelled}); reports the fraction done through it.
/// @throws Error from the passes; Error{too_large} beyond 32-bit vertex ids
DropInMesh extract_drop_in(const Samples& samples, const Frame& frame, double iso, const DropInOptions& options,
                           Control& control);

} // namespace cmc33::python
