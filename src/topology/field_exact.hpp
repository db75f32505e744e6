#pragma once
// Exact signs of small polynomials in double inputs, for the field-topology verifier only
// (src/topology/field_*.cpp). Two number types share one interface, so that every predicate is
// written once, as a template, and evaluated twice at most:
//  - Approx: a double with a rigorous bound on its error (a floating-point filter). Cheap.
//  - Expansion: an exact sum of non-overlapping doubles (J. R. Shewchuk, "Adaptive precision
//    floating-point arithmetic and fast robust geometric predicates", DCG 18, 1997, Sec. 2).
// exact_sign() tries Approx and falls back to Expansion only when the filter cannot decide, which
// in practice means a true tie (a value exactly at the isovalue, common with integer data) or a
// near-tie. Expansions are exact as long as no product underflows below 2^-969 or overflows; when
// that happens they set `lost()`, and the verifier reports the cell as undetermined.

#include <cmath>

#include "expansion.hpp"

namespace cmc33::topology::detail {

// Exact sums of doubles (src/support/expansion.hpp; core uses them too where GMP is absent).
using cmc33::detail::Expansion;
using cmc33::detail::two_sum_tail;

// ---------------------------------------------------------------------------------------------
// Approx: value v with |true - v| <= e. Each operation adds its own rounding error (at most
// 2^-53 |result| for round-to-nearest) and kTiny for a possible underflow. The bounds themselves
// are computed in floating point; the few ulps they may lose over a predicate (< 2^-46 relative
// for the ~30 operations of the largest one) are covered by the factor in filter_sign().
struct Approx {
    double v = 0.0;
    double e = 0.0;
};

inline constexpr double kUnitRoundoff = 0x1p-53;
inline constexpr double kTiny = 0x1p-1022;

inline Approx operator+(Approx x, Approx y) noexcept
{
    const double s = x.v + y.v;
    return {s, x.e + y.e + kUnitRoundoff * std::fabs(s) + kTiny};
}
inline Approx operator-(Approx x, Approx y) noexcept
{
    const double s = x.v - y.v;
    return {s, x.e + y.e + kUnitRoundoff * std::fabs(s) + kTiny};
}
inline Approx operator*(Approx x, Approx y) noexcept
{
    const double p = x.v * y.v;
    return {p, std::fabs(x.v) * y.e + std::fabs(y.v) * x.e + x.e * y.e +
                   kUnitRoundoff * std::fabs(p) + kTiny};
}

/// +1 or -1 when the bound excludes zero, 0 when the filter cannot decide (NaN and infinity
/// included: every comparison with them is false).
inline int filter_sign(Approx x) noexcept
{
    const double bound = x.e * (1.0 + 0x1p-40);
    if (x.v > bound) return 1;
    if (x.v < -bound) return -1;
    return 0;
}

/// Tells the caller that an exact evaluation lost precision (see Expansion::lost()).
struct Numerics {
    bool lost = false;
};

/// Sign of the polynomial computed by `expr`, a generic lambda `[&]<class Num>() -> Num`:
/// evaluated with Approx first and with Expansion when the filter cannot decide.
template <class Expr> int exact_sign(const Expr& expr, Numerics& numerics)
{
    const int s = filter_sign(expr.template operator()<Approx>());
    if (s != 0) return s;
    const Expansion x = expr.template operator()<Expansion>();
    if (x.lost()) numerics.lost = true;
    return x.sign();
}

} // namespace cmc33::topology::detail
