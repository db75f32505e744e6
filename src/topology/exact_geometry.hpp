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
#include <cstdint>

namespace cmc33::detail {

using Point3 = std::array<double, 3>;

/// Sign of det[a - d, b - d, c - d]: +1 when d lies below the plane of (a, b, c) as seen with
/// (a, b, c) counter-clockwise, i.e. on the side its right-handed normal does not point to.
int orient3d(const Point3& a, const Point3& b, const Point3& c, const Point3& d);

/// Sign of det[a - c, b - c] of the points projected on the plane that drops coordinate `drop`.
int orient2d(const Point3& a, const Point3& b, const Point3& c, int drop);

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

/// Counts of the predicate paths taken (for tests and profiling; per thread, not synchronised).
struct PredicateStats {
    std::int64_t filtered = 0; ///< decided by the floating-point filter
    std::int64_t expansion = 0; ///< decided by error-free transformations
    std::int64_t rational = 0; ///< decided by GMP
};
PredicateStats& predicate_stats() noexcept;

} // namespace cmc33::detail
