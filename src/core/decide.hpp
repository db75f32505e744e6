#pragma once
// The decisions of one cell: face tests, interior tests, and the policy of each method: a pure
// kernel (no report, no strings), used by the extractor's passes and by analyze_cell(), which
// derives its report from the Decision (cell.cpp).
//
// Values are differences to iso. The sign rule (docs/conventions.md): a value >= 0 is above. It applies to
// samples, face saddles and the saddles of the sweeping slices alike.
//
// Every decision is the sign of a polynomial (degree <= 6) in the eight values. It is computed
// exactly: first in double arithmetic with a running error bound (Filtered); when a sign is within
// its bound (a tie, or a near-tie such as decimal data whose exact sum is 0 but rounds to 1e-17),
// the cell is decided again exactly on the same doubles: in 128-bit integers when the values are
// small multiples of a power of two (integer-valued floats, halves, quarters: the common ties,
// decided without allocating), else in rational arithmetic (GMP's mpq_class; in a build without
// GMP, CMC33_WITH_GMP=0 such as the WebAssembly one, in Shewchuk expansions, see decide_expansion).
// Nothing throws but that build's expansions out of range: an unsettled sign raises a per-thread
// flag that decide() reads once per cell.
// So the extractor and the verifier, which decides exactly too, see the same field.

#if !defined(CMC33_WITH_GMP) || CMC33_WITH_GMP
#include <gmpxx.h>
#endif

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <type_traits>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cube.hpp"
#include "expansion.hpp"
#include "mc33_tables.hpp"
#include "portability.hpp"

namespace cmc33::detail {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Raised by a Filtered sign that rounding cannot settle (the sign then returned is 0, and the
/// decision is discarded); decide() lowers it and starts over exactly.
inline thread_local bool filter_uncertain = false;

/// A double and a bound on its distance to the exact value of the same expression. Each operation
/// adds its own rounding (relative 2^-50, a few times the unit roundoff, so that rounding in the
/// bound's own arithmetic is covered) and, for products, the smallest subnormal (underflow).
/// Overflow gives inf or NaN, whose sign is never trusted.
struct Filtered {
    double v = 0, e = 0;
    Filtered() = default;
    constexpr Filtered(double x) : v(x) {} // NOLINT: exact conversion
    Filtered(double x, double err) : v(x), e(err) {}
    static constexpr double kRel = 0x1p-50;
    friend Filtered operator+(Filtered a, Filtered b)
    {
        const double s = a.v + b.v;
        return {s, a.e + b.e + std::abs(s) * kRel};
    }
    friend Filtered operator-(Filtered a, Filtered b)
    {
        const double s = a.v - b.v;
        return {s, a.e + b.e + std::abs(s) * kRel};
    }
    friend Filtered operator*(Filtered a, Filtered b)
    {
        const double p = a.v * b.v;
        return {p, std::abs(a.v) * b.e + std::abs(b.v) * a.e + a.e * b.e + std::abs(p) * kRel +
                       std::numeric_limits<double>::denorm_min()};
    }
};

inline int sgn(double v) { return v > 0 ? 1 : v < 0 ? -1 : 0; }
inline int sgn(const Filtered& f)
{
    if (f.v > f.e) return 1;
    if (-f.v > f.e) return -1;
    if (!(f.v == 0 && f.e == 0)) filter_uncertain = true;
    return 0;
}
#if !defined(CMC33_WITH_GMP) || CMC33_WITH_GMP
inline int sgn(const mpq_class& q) { return mpq_sgn(q.get_mpq_t()); }
#endif
/// Raised by the sign of an Expansion that under- or overflowed (decide_expansion throws then).
inline thread_local bool expansion_lost = false;
inline int sgn(const Expansion& x)
{
    if (x.lost()) expansion_lost = true;
    return x.sign();
}

/// Exact for small integers: with |value - iso| <= 2^15 every polynomial of a decision stays below
/// 2^111 (the largest, P^2 - Q^2 disc of Algorithm 1, is at most 2^14 * |v|^6), far inside 2^127.
#if CMC33_HAS_INT128
inline int sgn(Int128 x) { return x > 0 ? 1 : x < 0 ? -1 : 0; }
#endif
inline constexpr double kSmallInteger = 32768.0;

/// 2^k (k <= 8) such that iso * 2^k and every sample * 2^k are integers with
/// |sample - iso| * 2^k <= 2^15, or 0. Integer data at an integer or half-integer isovalue takes
/// this exact path; scaling every value by 2^k changes no sign (the decisions are homogeneous).
inline double small_integer_scale(const double* raw, double iso)
{
    for (double scale = 1; scale <= 256; scale *= 2) {
        const double s_iso = iso * scale;
        if (s_iso != std::floor(s_iso)) continue;
        for (int q = 0; q < 8; ++q) {
            const double x = raw[q] * scale;
            if (x != std::floor(x) || std::abs(x - s_iso) > kSmallInteger) return 0;
        }
        return scale;
    }
    return 0;
}

/// Asymptotic decider (Nielson and Hamann 1991; Custodio et al. 2013, Eqs. 1-2) on an ambiguous
/// face: are its above corners joined? With A, C one diagonal and B, D the other, the saddle value
/// is (AC - BD) / (A + C - B - D); the denominator's sign is that of the above diagonal, so only the
/// numerator's sign is needed, and a saddle equal to iso counts as above.
template <class R> bool face_joined(const R* v, bool a_above, int f)
{
    const auto p = face_cycle(f);
    const R& A = v[p[0]];
    const R& B = v[p[1]];
    const R& C = v[p[2]];
    const R& D = v[p[3]];
    const int num = sgn(A * C - B * D);
    return a_above ? num >= 0 : num <= 0;
}

/// face_joined in Filtered arithmetic, written out for the case decide_in has: the four values are
/// w = fl(sample - iso) of exact doubles (relative error at most 2^-53 each). Then AC - BD is off by
/// at most about 4 * 2^-53 (|AC| + |BD|) plus underflow, bounded here by 2^-49 (|AC| + |BD|) + 2^-1072.
/// Eight operations instead of Filtered's two dozen, and no branch (a face's answer is a coin toss
/// on rough data); an unsettled sign sets `uncertain`.
inline bool face_joined_filtered(const double* w, bool a_above, int f, bool& uncertain)
{
    const auto p = face_cycle(f);
    const double ac = w[p[0]] * w[p[2]], bd = w[p[1]] * w[p[3]], d = ac - bd;
    const double bound = (std::abs(ac) + std::abs(bd)) * 0x1p-49 + 0x1p-1072;
    const bool positive = d > bound, negative = -d > bound;
    uncertain |= !(positive | negative);
    return (a_above & !negative) | (!a_above & !positive); // sign rule: a zero saddle is above
}

/// The double x (an integer for R = Int128) as an R. Int128 takes the one-instruction conversion
/// through 64 bits where x fits (the values of the integer path always do), not libgcc's.
template <class R> R exact(double x)
{
#if CMC33_HAS_INT128
    if constexpr (std::is_same_v<R, Int128>) {
        if (std::abs(x) < 0x1p62) return static_cast<Int128>(static_cast<long long>(x));
    }
#endif
    return R(x);
}

/// A number x + eps * y with eps > 0 infinitesimal, compared lexicographically. The interior tests
/// run on these with every value v - iso given as (v - iso) + eps: that is the level set at
/// iso - eps, exactly the sign rule, so exact ties (integer data at an integer isovalue) are decided
/// as the verifier sees them. Products drop eps^2: F's eps^2 terms cancel, and t_max is linear in eps.
template <class R> struct EpsT {
    using Real = R;
    static constexpr bool kHasEps = true;
    R x{}, y{};
    friend EpsT operator+(const EpsT& a, const EpsT& b) { return {a.x + b.x, a.y + b.y}; }
    friend EpsT operator-(const EpsT& a, const EpsT& b) { return {a.x - b.x, a.y - b.y}; }
    friend EpsT operator*(const EpsT& a, const EpsT& b) { return {a.x * b.x, a.x * b.y + a.y * b.x}; }
    friend EpsT operator*(double k, const EpsT& a) { return {exact<R>(k) * a.x, exact<R>(k) * a.y}; }
    int sign() const
    {
        const int s = sgn(x);
        return s != 0 ? s : sgn(y);
    }
    bool above() const { return sign() >= 0; } // the sign rule: zero counts as above
};

/// EpsT without its eps part, for a first, cheaper pass in filtered arithmetic: where no sign is 0
/// the eps terms decide nothing, and the answer is EpsT's (the x parts are the same numbers). A sign
/// that is 0, or that rounding cannot settle, raises filter_uncertain: the caller then decides with
/// EpsT. (y is always 0, for the few places that read it after a sign of 0 has been raised.)
template <class R> struct NoEps {
    using Real = R;
    static constexpr bool kHasEps = false;
    R x{};
    static constexpr R y = R(0.0);
    NoEps() = default;
    NoEps(const R& x_, const R& /*eps part, dropped*/) : x(x_) {}
    friend NoEps operator+(const NoEps& a, const NoEps& b) { return {a.x + b.x}; }
    friend NoEps operator-(const NoEps& a, const NoEps& b) { return {a.x - b.x}; }
    friend NoEps operator*(const NoEps& a, const NoEps& b) { return {a.x * b.x}; }
    friend NoEps operator*(double k, const NoEps& a) { return {R(k) * a.x}; }
    int sign() const
    {
        const int s = sgn(x);
        if (s == 0) filter_uncertain = true;
        return s;
    }
    bool above() const { return sign() >= 0; }

private:
    NoEps(const R& x_) : x(x_) {} // NOLINT: from an operation's result
};

/// The sweep of Chernyaev's interior test: planes perpendicular to `axis`, from the face holding
/// corner P (A0) to the opposite face. A, B, C, D are the four edges along the axis, A through P,
/// C through the corner diagonal to P on that face, so that C1 = P ^ 7.
template <class Num> struct SweepT {
    Num A0, B0, C0, D0, A1, B1, C1, D1;

    SweepT(const Num* v, int axis, int P)
    {
        const int u = axis == 0 ? 1 : 0, w = axis == 2 ? 1 : 2;
        const int p[4] = {P, flip(P, u), flip(flip(P, u), w), flip(P, w)};
        A0 = v[p[0]], B0 = v[p[1]], C0 = v[p[2]], D0 = v[p[3]];
        A1 = v[flip(p[0], axis)], B1 = v[flip(p[1], axis)], C1 = v[flip(p[2], axis)], D1 = v[flip(p[3], axis)];
    }
    // F(t) = A_t C_t - B_t D_t = a t^2 + b t + c   (Custodio et al. 2013, Eqs. 6-7, Appendix A)
    Num a() const { return (A1 - A0) * (C1 - C0) - (B1 - B0) * (D1 - D0); }
    Num b() const { return C0 * (A1 - A0) + A0 * (C1 - C0) - D0 * (B1 - B0) - B0 * (D1 - D0); }
    Num c() const { return A0 * C0 - B0 * D0; }
    static Num at(Num x0, Num x1, Num t) { return x0 + (x1 - x0) * t; }
    Num F(Num t) const { return at(A0, A1, t) * at(C0, C1, t) - at(B0, B1, t) * at(D0, D1, t); }
    Num den(Num t) const { return at(A0, A1, t) + at(C0, C1, t) - at(B0, B1, t) - at(D0, D1, t); }
};
using Sweep = SweepT<double>;

/// In the slice at height t, is the region of corner A joined to that of corner C? Both must have
/// A0's sign; through B or D when one of them has it too, else by the slice's saddle (asymptotic
/// decider; a saddle equal to iso is above).
template <class E> bool slice_joins(const SweepT<E>& s, const E& t)
{
    using S = SweepT<E>;
    const bool above = s.A0.above();
    const E a_t = S::at(s.A0, s.A1, t), b_t = S::at(s.B0, s.B1, t);
    const E c_t = S::at(s.C0, s.C1, t), d_t = S::at(s.D0, s.D1, t);
    if (a_t.above() != above || c_t.above() != above) return false;
    if (b_t.above() == above || d_t.above() == above) return true;
    const int num = (a_t * c_t - b_t * d_t).sign();
    return above ? num >= 0 : num > 0;
}

/// Chernyaev's test (Custodio et al. 2013, Sec. 3.1): joined iff a < 0, t_max = -b/2a in (0, 1)
/// and the slice at t_max joins A and C (for the tunnel cases the slice's own sign pattern is read,
/// so condition (iii) F(t_max) > 0 becomes "the slice joins them").
/// Nothing is divided: with a < 0, sign(X(t_max)) = sign((X1 - X0) b - 2a X0) and
/// F(t_max) = (4ac - b^2) / 4a has the sign of b^2 - 4ac. On data with exact ties (integers,
/// dyadic fractions) these are exact, so a zero is a true zero and the eps terms decide it.
template <class E> bool chernyaev_joined(const SweepT<E>& s)
{
    const E a = s.a(), b = s.b(), c = s.c(); // a carries no eps: it is made of differences
    if (sgn(a.x) >= 0) return false;
    if (b.sign() <= 0 || (2.0 * a + b).sign() >= 0) return false; // t_max outside (0, 1)
    const E two_a = 2.0 * a;
    const auto above_at_max = [&](const E& x0, const E& x1) { return ((x1 - x0) * b - two_a * x0).above(); };
    const bool joined_sign = s.A0.above();
    if (above_at_max(s.A0, s.A1) != joined_sign || above_at_max(s.C0, s.C1) != joined_sign) return false;
    if (above_at_max(s.B0, s.B1) == joined_sign || above_at_max(s.D0, s.D1) == joined_sign) return true;
    // F(t_max): b^2 - 4ac to first order in eps, and its eps^2 term b.y^2 when both vanish
    const E g = b * b - 4.0 * (a * c);
    const int f = g.sign() != 0 ? g.sign() : (sgn(b.y) != 0 ? 1 : 0);
    return joined_sign ? f >= 0 : f > 0;
}

/// Sign of P + Q sqrt(D), D >= 0, without rounding a square root: compare P^2 with Q^2 D. When
/// D is an infinitesimal eps * D.y, sqrt(D) ~ sqrt(eps) outweighs any eps term.
template <class E> int sign_p_plus_q_sqrt(const E& P, const E& Q, const E& D)
{
    if (sgn(D.x) == 0) {
        if constexpr (!E::kHasEps) {
            filter_uncertain = true; // D is its eps part: EpsT decides
            return 0;
        }
        if (sgn(P.x) != 0) return sgn(P.x);
        if (sgn(Q.x) != 0 && sgn(D.y) > 0) return sgn(Q.x);
        return P.sign() != 0 ? P.sign() : Q.sign();
    }
    const int sp = P.sign(), sq = Q.sign();
    if (sq == 0) return sp;
    if (sp == 0 || sp == sq) return sq;
    const int cmp = (P * P - (Q * Q) * D).sign();
    return cmp > 0 ? sp : cmp < 0 ? sq : 0;
}

/// Sign of l0 + l1 t at the root t = (-b + sigma sqrt(disc)) / 2a of F (a != 0).
template <class E> int sign_at_root(const E& l0, const E& l1, const E& a, const E& b, const E& disc, int sigma)
{
    const E P = 2.0 * (a * l0) - l1 * b;
    const E Q = static_cast<double>(sigma) * l1;
    return sign_p_plus_q_sqrt(P, Q, disc) * (sgn(a.x) > 0 ? 1 : -1);
}

/// Algorithm 1 (Custodio et al. 2013, Sec. 6.1): 13.5.2 iff both roots t1, t2 of F lie in (0, 1)
/// and both slice saddles x_c(t1), x_c(t2) (Eq. 9) lie inside the face. Returns 0 for 13.5.1, else
/// the sign (+1, -1) of the slice saddle at (t1 + t2) / 2: the tunnel faces the isolated corner of
/// that sign (Sec. 6.1.1). Every quantity is linear in t and is evaluated at the roots exactly
/// (sign_at_root), so ties in the data cannot be decided by rounding.
template <class E> int algorithm1(const SweepT<E>& s)
{
    using R = typename E::Real;
    const E a = s.a(), b = s.b(), c = s.c();
    if (sgn(a.x) == 0) return 0; // F is at most linear: one root
    const E disc = b * b - 4.0 * (a * c);
    if (disc.sign() <= 0) return 0; // no real roots, or a double root even below iso
    const E one{R(1), R(0)}, zero{R(0), R(0)};
    const E dA = s.A1 - s.A0, dB = s.B1 - s.B0, dC = s.C1 - s.C0, dD = s.D1 - s.D0;
    for (int sigma : {-1, 1}) {
        const auto sg = [&](const E& l0, const E& l1) { return sign_at_root(l0, l1, a, b, disc, sigma); };
        if (sg(zero, one) <= 0 || sg(one, zero - one) <= 0) return 0; // root in (0, 1)
        // saddle (u, v) = (A - D, A - B) / den inside: A - D, C - B, A - B, C - D all of den's sign
        const int sd = sg(s.A0 + s.C0 - s.B0 - s.D0, dA + dC - dB - dD);
        if (sd == 0 || sg(s.A0 - s.D0, dA - dD) != sd || sg(s.C0 - s.B0, dC - dB) != sd ||
            sg(s.A0 - s.B0, dA - dB) != sd || sg(s.C0 - s.D0, dC - dD) != sd) {
            return 0;
        }
    }
    // At the midpoint t = -b / 2a: F = -disc / 4a, and den's sign from 2a den0 - den1 b.
    const int f_sign = -(sgn(a.x) > 0 ? 1 : -1);
    const E den0 = s.A0 + s.C0 - s.B0 - s.D0, den1 = dA + dC - dB - dD;
    const int den_sign = (2.0 * (a * den0) - den1 * b).sign() * (sgn(a.x) > 0 ? 1 : -1);
    return f_sign * den_sign >= 0 ? 1 : -1;
}

/// Chernyaev's own test applied to case 13.5, as his algorithm does (Custodio et al. 2013, Sec. 3.1
/// and 5.1, Issue I): joined iff (i) a < 0, (ii) t_max = -b/2a in (0, 1) and (iii) F(t_max) > 0,
/// on the sweep of Appendix A. For case 13 the premise of these conditions (both end faces'
/// saddles below, the saddle's denominator positive) does not hold, so they can err either way;
/// that is the point of reproducing them. With a < 0, F(t_max) = (4ac - b^2)/4a has the sign of
/// b^2 - 4ac; a zero counts as "not > 0".
template <class E> bool chernyaev_13_5(const SweepT<E>& s)
{
    const E a = s.a(), b = s.b(), c = s.c();
    if (sgn(a.x) >= 0) return false;                                // (i)
    if (b.sign() <= 0 || (2.0 * a + b).sign() >= 0) return false;   // (ii)
    return (b * b - 4.0 * (a * c)).sign() > 0;                      // (iii)
}

/// Lewiner et al.'s height: where the field crosses the reference edge (Custodio et al., Eq. 8).
inline double t_alt(const double* v, int edge)
{
    const double v0 = v[kEdgeCorners[edge][0]], v1 = v[kEdgeCorners[edge][1]];
    const double t = v0 / (v0 - v1);
    return t;
}

/// Algorithm 2 of Custodio et al. 2013 (Sec. 6.4), generalised to every variant with an interior
/// ambiguity (cases 4, 6, 7, 10, 12 and 13.5): the face tests have chosen `var`; the interior test
/// decides whether the tunnel is there, and for 13.5 which way it faces (tiling 1: the above
/// corner of the isolated diagonal, 2: the below one; 0: no tunnel). Under cmc33 (and cmc33-paper)
/// every branch is tested, lines 16-20 of Algorithm 2 included (cases 10 and 12 with both faces
/// joined); the legacy policy of mc33-lewiner is read from the variant (Variant::lewiner);
/// chernyaev tests every branch with t_max, and 13.5 with his three conditions (chernyaev_13_5),
/// its tunnel always facing the above corner: Chernyaev does not orient it (Sec. 5.1.1).
template <class E> int algorithm2(const Variant& var, const E* ve, const double* v, Method method)
{
    using R = typename E::Real;
    if (method == Method::chernyaev && var.test == kTest13_5) {
        return chernyaev_13_5(SweepT<E>(ve, var.axis, var.corner)) ? 1 : 0;
    }
    if (method == Method::mc33_lewiner) {
        if (var.lewiner & kLewinerSkips) return 0; // Issue IV: never tested
        if (var.lewiner & kLewinerTAlt) {
            // Issue III: the slice at Lewiner's t_alt (Eq. 8) instead of t_max; for 13.5 condition
            // (iii) there, its orientation never tested (Sec. 5.1.1, Appendix A)
            const double t = t_alt(v, var.lewiner_edge);
            if (var.test == kTest13_5) return Sweep(v, var.lewiner_axis, var.lewiner_corner).F(t) > 0 ? 1 : 0;
            const SweepT<E> lw(ve, var.lewiner_axis, var.lewiner_corner);
            return slice_joins(lw, E{R(t), R(0.0)}) ? 1 : 0;
        }
    }
    const SweepT<E> sweep(ve, var.axis, var.corner);
    if (var.test == kTestTunnel) return chernyaev_joined(sweep) ? 1 : 0;
    const int orientation = algorithm1(sweep); // 13.5 under cmc33
    return orientation == 0 ? 0 : orientation > 0 ? 1 : 2;
}

struct Decision {
    const Variant* variant;
    int tiling; ///< 0 no tunnel, 1 tunnel (13.5: facing the above corner), 2 (13.5: facing below)
    int subcase;
    unsigned joined; ///< the face tests: bit i for the i-th ambiguous face of the configuration
};

/// decide() in the number type R (Filtered: may raise filter_uncertain; the others: exact), with
/// the interior tests in E (EpsT<R>, or NoEps<R> for a first filtered pass). `raw` are the corner
/// samples, `v` the same minus iso rounded to double (their signs, and mc33-lewiner's t_alt); the
/// decisions use raw - iso computed in R. The variant is taken from `table` (kVariants or
/// kLegacyVariants: the same decisions, other tubes).
template <class R, class E = EpsT<R>>
Decision decide_in(const double* raw, double iso, const double* v, unsigned config, Method method, const Variant* table)
{
    R w[8];
    for (int q = 0; q < 8; ++q) w[q] = exact<R>(raw[q]) - exact<R>(iso);
    const unsigned amb = kAmbiguousFaces[config];
    unsigned bits = 0;
    if (method != Method::mc) {
        int i = 0;
        bool uncertain = false;
        for (unsigned faces = amb; faces != 0; faces &= faces - 1, ++i) {
            const int f = std::countr_zero(faces);
            const bool a_above = v[face_cycle(f)[0]] >= 0;
            bool joined = false;
            if constexpr (std::is_same_v<R, Filtered>) {
                joined = face_joined_filtered(v, a_above, f, uncertain); // v = fl(raw - iso): its premise
            } else {
                joined = face_joined<R>(w, a_above, f);
            }
            bits |= static_cast<unsigned>(joined) << i;
        }
        if (uncertain) filter_uncertain = true;
    }
    const Variant* var = &table[kVariantOffset[config] + bits];
    if (var->test == kTestNone || method == Method::mc) return {var, 0, var->subcase, bits};
    E ve[8];
    for (int q = 0; q < 8; ++q) ve[q] = E{w[q], R(1.0)};
    const int tiling = algorithm2<E>(*var, ve, v, method);
    return {var, tiling, tiling != 0 ? var->tunnel_subcase : var->subcase, bits};
}

/// decide_in<Expansion>: the exact decision without GMP. The decisions are homogeneous polynomials
/// (degree <= 6) in the values minus iso, so all samples and iso are first scaled by one power of
/// two that brings the largest magnitude just below 1: exact, sign-preserving, and it keeps every
/// product away from overflow, and from underflow unless the nine numbers' magnitudes lie more than
/// about 2^100 apart (a degree-6 product of the smallest then falls below 2^-969: 1e-30 beside 1
/// at a near-tie). There the expansions lose exactness, and this throws rather than return a
/// decision that might be wrong.
inline Decision decide_expansion(const double* raw, double iso, const double* v, unsigned config, Method method,
                                 const Variant* table = kVariants)
{
    double largest = std::abs(iso);
    for (int q = 0; q < 8; ++q) largest = std::max(largest, std::abs(raw[q]));
    int exponent = 0;
    (void)std::frexp(largest, &exponent); // largest in [2^(exponent-1), 2^exponent)
    double scaled[8];
    bool exact = true;
    for (int q = 0; q < 8; ++q) {
        scaled[q] = std::ldexp(raw[q], -exponent);
        exact = exact && std::ldexp(scaled[q], exponent) == raw[q];
    }
    const double scaled_iso = std::ldexp(iso, -exponent);
    exact = exact && std::ldexp(scaled_iso, exponent) == iso;
    expansion_lost = false;
    const Decision d = decide_in<Expansion>(scaled, scaled_iso, v, config, method, table);
    if (!exact || expansion_lost) {
        expansion_lost = false;
        throw Error(Status::internal, "a cell's decision needs exact arithmetic beyond this build's range (corner values "
                                      "and isovalue whose magnitudes lie more than about 2^100 apart, at a near-tie); "
                                      "a build with GMP decides it");
    }
    return d;
}

/// Decides one cell with `config` not 0 or 255: first in filtered double arithmetic without the
/// eps terms, which settles nearly every cell of data without ties; where a sign is 0 or rounding
/// could change it, again exactly: in 128-bit integers when the samples and iso are small
/// multiples of a power of two (integer data, and integer-valued floats such as CT stored as
/// float32: their ties cost what integer data's do), else in filtered arithmetic with the eps
/// terms and then in rationals. A corner equal to iso is a 0 sign the filter cannot settle: such
/// cells of integer data go straight to the integers. The filter comes first because it is the
/// cheaper of the two on cells without ties (docs/performance.md).
/// `raw`: the eight corner samples (corner order of cube.hpp). `table`: the method's table set
/// (tables_of(method)); Decision::variant points into it.
inline Decision decide(const double* raw, double iso, unsigned config, Method method, const Variant* table = kVariants)
{
    double v[8];
    bool corner_tie = false;
    for (int q = 0; q < 8; ++q) {
        v[q] = raw[q] - iso;
        corner_tie |= v[q] == 0;
    }
#if CMC33_HAS_INT128
    // mc33-lewiner's t_alt is a fraction: that method always takes the floating-point path
    const double scale = method != Method::mc33_lewiner ? small_integer_scale(raw, iso) : 0;
#else
    const double scale = 0;
#endif
    // first without eps terms (on data without ties no sign is 0), then with them
    if (scale == 0 || !corner_tie) {
        filter_uncertain = false;
        const Decision quick = decide_in<Filtered, NoEps<Filtered>>(raw, iso, v, config, method, table);
        if (!filter_uncertain) return quick;
        filter_uncertain = false;
    }
#if CMC33_HAS_INT128
    if (scale != 0) {
        double scaled[8];
        for (int q = 0; q < 8; ++q) scaled[q] = raw[q] * scale;
        return decide_in<Int128>(scaled, iso * scale, v, config, method, table);
    }
#endif
    const Decision filtered = decide_in<Filtered>(raw, iso, v, config, method, table);
    if (!filter_uncertain) return filtered;
    filter_uncertain = false;
#if !defined(CMC33_WITH_GMP) || CMC33_WITH_GMP
    return decide_in<mpq_class>(raw, iso, v, config, method, table);
#else
    return decide_expansion(raw, iso, v, config, method, table);
#endif
}

/// The table set of a method: Chernyaev's tubes for the methods that reproduce Custodio et al.
/// 2013 (chernyaev, mc33-lewiner, cmc33-paper), embedded tubes for cmc33 and mc.
inline const Variant* tables_of(Method method)
{
    const bool legacy = method == Method::chernyaev || method == Method::mc33_lewiner || method == Method::cmc33_paper;
    return legacy ? kLegacyVariants : kVariants;
}

} // namespace cmc33::detail
