#pragma once
// Internal: exact geometric predicates on points whose coordinates are doubles (in practice the
// floats of a mesh file, converted exactly), and the triangle intersection tests built on them.
//
// Every predicate returns the exact sign of its determinant:
//   1. a floating-point filter: the determinant in doubles with a bound on its rounding error;
//   2. when the bound cannot decide (near-degenerate or exactly degenerate input, e.g. coplanar
//      triangles of a flat surface): the coordinate differences are checked to be exact in double
//      (they are for floats whose exponents differ by at most 28), each product is split into
//      exact terms with fma (error-free transformations), and the sum of those terms is settled by
//      repeated error-free summation (distillation) until its sign is certain;
//   3. otherwise, GMP rationals.
// Written for cmc33 from the definitions (Shewchuk 1997 for the filter idea; Ogita, Rump and
// Oishi 2005 for error-free summation); no code is taken from either.
//
// Triangle tests treat triangles as closed sets. A triangle is given by three points; all tests
// assume non-degenerate triangles (non-collinear corners): callers check degeneracy first.

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace cmc33::detail {

using Point3 = std::array<double, 3>;

/// Counts of the predicate paths taken (for tests and profiling; per thread, not synchronised).
struct PredicateStats {
    std::int64_t filtered = 0; ///< decided by the floating-point filter
    std::int64_t expansion = 0; ///< decided by error-free transformations
    std::int64_t rational = 0; ///< decided by GMP
};
PredicateStats& predicate_stats() noexcept;

/// This thread's counts (inline so that the filters, inline below, count without a call).
inline thread_local PredicateStats g_predicate_stats;

inline constexpr double kUnitRoundoff = 0x1p-53;

/// orient3d's sign when the floating-point filter decides it, else 0 (undecided, not "coplanar").
inline int orient3d_filter(const Point3& a, const Point3& b, const Point3& c, const Point3& d)
{
    const double adx = a[0] - d[0], ady = a[1] - d[1], adz = a[2] - d[2];
    const double bdx = b[0] - d[0], bdy = b[1] - d[1], bdz = b[2] - d[2];
    const double cdx = c[0] - d[0], cdy = c[1] - d[1], cdz = c[2] - d[2];
    const double m1 = bdy * cdz, m2 = bdz * cdy, m3 = cdy * adz, m4 = cdz * ady, m5 = ady * bdz, m6 = adz * bdy;
    const double det = adx * (m1 - m2) + bdx * (m3 - m4) + cdx * (m5 - m6);
    const double permanent = std::fabs(adx) * (std::fabs(m1) + std::fabs(m2)) + std::fabs(bdx) * (std::fabs(m3) + std::fabs(m4)) +
                             std::fabs(cdx) * (std::fabs(m5) + std::fabs(m6));
    // Each of the six terms carries at most 7 roundings relative to its size (three differences,
    // two products, the inner difference, the sums): 8u of the permanent bounds the error.
    const double bound = 8.5 * kUnitRoundoff * permanent;
    return (det > bound) - (-det > bound);
}

/// orient2d's sign (below) when the floating-point filter decides it, else 0.
inline int orient2d_filter(const Point3& a, const Point3& b, const Point3& c, int drop)
{
    const auto u = static_cast<std::size_t>(drop == 0 ? 1 : 0), v = static_cast<std::size_t>(drop == 2 ? 1 : 2);
    const double l = (a[u] - c[u]) * (b[v] - c[v]), r = (a[v] - c[v]) * (b[u] - c[u]);
    const double det = l - r;
    const double bound = 4.5 * kUnitRoundoff * (std::fabs(l) + std::fabs(r));
    return (det > bound) - (-det > bound);
}

/// orient3d past its filter: error-free transformations, then rationals.
int orient3d_exact(const Point3& a, const Point3& b, const Point3& c, const Point3& d);
/// orient2d past its filter.
int orient2d_exact(const Point3& a, const Point3& b, const Point3& c, int drop);

/// Sign of det[a - d, b - d, c - d]: +1 when d lies below the plane of (a, b, c) as seen with
/// (a, b, c) counter-clockwise, i.e. on the side its right-handed normal does not point to.
inline int orient3d(const Point3& a, const Point3& b, const Point3& c, const Point3& d)
{
    if (const int s = orient3d_filter(a, b, c, d)) {
        ++g_predicate_stats.filtered;
        return s;
    }
    return orient3d_exact(a, b, c, d);
}

/// Sign of det[a - c, b - c] of the points projected on the plane that drops coordinate `drop`.
inline int orient2d(const Point3& a, const Point3& b, const Point3& c, int drop)
{
    if (const int s = orient2d_filter(a, b, c, drop)) {
        ++g_predicate_stats.filtered;
        return s;
    }
    return orient2d_exact(a, b, c, drop);
}

/// True iff a, b, c are collinear (the triangle has zero area), exactly.
bool collinear(const Point3& a, const Point3& b, const Point3& c);

/// The coordinate whose dropping keeps triangle (a, b, c) non-degenerate in 2D (it exists for a
/// non-degenerate triangle).
int projection_axis(const Point3& a, const Point3& b, const Point3& c);

/// Closed segment pq meets closed triangle abc.
bool segment_meets_triangle(const Point3& p, const Point3& q, const Point3& a, const Point3& b, const Point3& c);

/// How two non-degenerate triangles relate, given how many corners they share (0, 1 or 2; shared
/// corners are equal points, listed first: for one shared corner t[0] == u[0]; for two, t[0] ==
/// u[0] and t[1] == u[1]). True iff they meet anywhere other than in what they share.
bool triangles_meet_improperly(const std::array<Point3, 3>& t, const std::array<Point3, 3>& u, int shared);

} // namespace cmc33::detail
