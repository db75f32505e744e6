// The checks of grid_checks.hpp, and float_steps_per_cell() (extract.hpp), which they use.

#include "grid_checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <type_traits>

#include "cmc33/error.hpp"
#include "plural.hpp"
#include "sample_types.hpp"

namespace cmc33 {
namespace detail {

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
double shortest_edge(const Mat3& m)
{
    double shortest = std::numeric_limits<double>::infinity();
    for (std::size_t a = 0; a < 3; ++a) {
        const double length = is_diagonal(m) ? std::fabs(m[a][a]) : std::hypot(m[0][a], m[1][a], m[2][a]);
        shortest = std::min(shortest, length);
    }
    return shortest;
}

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

#define CMC33_INSTANTIATE(T)                                                                                    \
    template double scan_samples<T>(const GridView<T>&, std::int64_t, std::int64_t);                           \
    template void check_grid<T>(const GridView<T>&, double);
CMC33_FOR_EACH_SAMPLE_TYPE(CMC33_INSTANTIATE)
#undef CMC33_INSTANTIATE

} // namespace detail

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

} // namespace cmc33
