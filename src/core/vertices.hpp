#pragma once
// Vertex placement and normals of the range extractor (range_extractor.hpp): where an edge's
// crossing lies (placement.hpp's rule, never on a sample), where interior vertices go, the world
// position of a vertex in the grid's frame, and the normals from the field's gradient (central
// differences at the samples, the trilinear interpolant's where they vanish). Included by
// emit.cpp, which instantiates them.
//
// World coordinates (volume.hpp): x = origin + M * (i, j, k) with M = D * diag(spacing). A diagonal
// M (the usual axis-aligned frame, flips included) takes the per-axis multiply; only an oblique or
// permuted frame pays for the full product. Normals map the index-space gradient by M^-T; a
// mirroring frame (det M < 0) reverses every triangle so that the winding rule of
// docs/conventions.md holds in world space.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "placement.hpp"
#include "range_extractor.hpp"

namespace cmc33::detail {

template <class T>
CMC33_ALWAYS_INLINE double RangeExtractor<T>::crossing(T a, T b) const
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

template <class T>
double RangeExtractor<T>::min_crossing(const Index3& dims, const Vec3& origin, const Mat3& m)
{
    const double largest = largest_coordinate(dims, origin, m);
    const double shortest = shortest_edge(m);
    if (!(largest > 0) || !(shortest > 0) || !std::isfinite(largest)) return detail::kMinCrossing;
    const double ulp = std::ldexp(1.0, std::ilogb(largest) - 23);
    return std::clamp(16 * ulp / shortest, detail::kMinCrossing, 0.125);
}

template <class T>
CMC33_ALWAYS_INLINE void RangeExtractor<T>::write_position(std::int64_t i, std::int64_t j, std::int64_t k,
                                                           const double (&u)[3], float* out, bool zyx) const
{
    // the integer index first, then u: one rounding, as the larger grid's own extraction has
    const double x[3] = {static_cast<double>(i + offset_[0]) + u[0], static_cast<double>(j + offset_[1]) + u[1],
                         static_cast<double>(k + offset_[2]) + u[2]};
    float p[3];
    if (diagonal_) {
        for (std::size_t c = 0; c < 3; ++c) p[c] = static_cast<float>(g_.origin[c] + step_[c] * x[c]);
    } else {
        for (std::size_t c = 0; c < 3; ++c)
            p[c] = static_cast<float>(g_.origin[c] + (m_[c][0] * x[0] + m_[c][1] * x[1] + m_[c][2] * x[2]));
    }
    store(p, out, zyx);
}

template <class T>
double RangeExtractor<T>::gradient_scale(double largest_sample) const
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

template <class T>
std::array<double, 3> RangeExtractor<T>::gradient(std::int64_t i, std::int64_t j, std::int64_t k, double scale) const
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

template <class T>
CMC33_ALWAYS_INLINE std::array<double, 3> RangeExtractor<T>::edge_gradient(std::int64_t i, std::int64_t j, std::int64_t k, int axis,
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

template <class T>
double RangeExtractor<T>::difference(T hi, T lo, double scale)
{
    if constexpr (std::is_integral_v<T>) {
        using Wide = std::conditional_t<(sizeof(T) < 4), int, std::int64_t>;
        if (scale == 1) return static_cast<double>(static_cast<Wide>(hi) - static_cast<Wide>(lo));
    } else {
        if (scale == 1) return static_cast<double>(hi) - static_cast<double>(lo); // the same numbers
    }
    return scale * static_cast<double>(hi) - scale * static_cast<double>(lo);
}

template <class T>
CMC33_ALWAYS_INLINE bool RangeExtractor<T>::write_normal(float* out, std::array<double, 3> g, bool zyx) const
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

template <class T>
std::array<double, 3> RangeExtractor<T>::edge_cell_gradient(std::int64_t i, std::int64_t j, std::int64_t k, int axis, double t,
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

template <class T>
std::array<double, 3> RangeExtractor<T>::cell_gradient(const T (&value)[8], const double (&p)[3], double scale) const
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

template <class T>
std::array<double, 3> RangeExtractor<T>::fan_gradient(const T (&value)[8], const detail::Tiling& tl, int q,
                                                      const double (&pq)[3]) const
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

template <class T>
void RangeExtractor<T>::write_interior_vertices(std::int64_t i, std::int64_t j, std::int64_t k, const detail::Tiling& tl,
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
    for (int q = 0; q < tl.interior_count; ++q) {
        double p[3];
        detail::interior_position(detail::kInteriorMasks[tl.first_interior + q], crossing_at, p);
        const auto v = static_cast<std::size_t>(first + q - out.first_vertex);
        write_position(i, j, k, p, &out.positions[v * 3], out.zyx);
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
        if (out.vertex_edges) out.vertex_edges[v] = -1 - whole_cell(i, j, k);
        if (out.vertex_parameters) out.vertex_parameters[v] = -1.0f;
        if (e.ranges) e.ranges->interior_vertex(v, i, j, k);
        if (out.vertex_values) {
            double f = 0;
            for (int c = 0; c < 8; ++c) f += w[c] * static_cast<double>(value[c]);
            out.vertex_values[v] = static_cast<float>(f);
        }
    }
}

} // namespace cmc33::detail
