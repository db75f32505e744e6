#pragma once
// What extract() and the public passes check of their input before any pass runs: the grid (its
// frame, its size, what 32-bit float positions can hold) and the isovalue, and the samples
// themselves (finite), with one-line errors naming what is wrong.

#include <cstdint>

#include "cmc33/extract.hpp"

namespace cmc33::detail {

/// The largest |world coordinate| over the 8 corners of the box of a grid of `dims` samples in the
/// frame (origin, M) (every vertex lies in it).
double largest_coordinate(const Index3& dims, const Vec3& origin, const Mat3& m);
template <class T> double largest_coordinate(const GridView<T>& g)
{
    return largest_coordinate(g.dims, g.origin, frame_matrix(g.spacing, g.direction));
}

/// The shortest cell edge in world units: the length of M's shortest column.
double shortest_edge(const Mat3& m);

/// The largest |sample| of planes [k_lo, k_hi] (for integer types, the type's bound).
/// @throws Error{non_finite} for NaN or infinite samples there, saying how many and the first
template <class T> double scan_samples(const GridView<T>& g, std::int64_t k_lo, std::int64_t k_hi);

/// Checks the grid and isovalue: everything but the samples.
/// @throws Error{non_finite, invalid_argument, too_large} naming what is wrong
template <class T> void check_grid(const GridView<T>& g, double iso);

} // namespace cmc33::detail
