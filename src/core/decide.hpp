#pragma once
// The decisions of one cell: face tests, interior tests, and the policy of each method.
// Used by the extractor's counting pass and by analyze_cell(); `report` is null in the extractor.
//
// Values are differences to iso. The sign rule (design.md): a value >= 0 is above. It applies to
// samples, face saddles and the saddles of the sweeping slices alike.

#include <cmath>
#include <limits>

#include "cmc33/cell.hpp"
#include "cmc33/extract.hpp"
#include "core/cube.hpp"
#include "tables/mc33_tables.hpp"

namespace cmc33::detail {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Asymptotic decider (Nielson and Hamann 1991; Custodio et al. 2013, Eqs. 1-2) on an ambiguous
/// face: are its above corners joined? With A, C one diagonal and B, D the other, the saddle value
/// is (AC - BD) / (A + C - B - D); the denominator's sign is that of the above diagonal, so only the
/// numerator's sign is needed, and a saddle equal to iso counts as above.
inline bool face_joined(const double* v, int f, double* saddle = nullptr)
{
    const auto p = face_cycle(f);
    const double A = v[p[0]], B = v[p[1]], C = v[p[2]], D = v[p[3]];
    const double num = A * C - B * D;
    if (saddle) *saddle = num / (A + C - B - D);
    return A >= 0 ? num >= 0 : num <= 0;
}

/// The sweep of Chernyaev's interior test: planes perpendicular to `axis`, from the face holding
/// corner P (A0) to the opposite face. A, B, C, D are the four edges along the axis, A through P,
/// C through the corner diagonal to P on that face, so that C1 = P ^ 7.
struct Sweep {
    double A0, B0, C0, D0, A1, B1, C1, D1;

    Sweep(const double* v, int axis, int P)
    {
        const int u = axis == 0 ? 1 : 0, w = axis == 2 ? 1 : 2;
        const int p[4] = {P, flip(P, u), flip(flip(P, u), w), flip(P, w)};
        A0 = v[p[0]], B0 = v[p[1]], C0 = v[p[2]], D0 = v[p[3]];
        A1 = v[flip(p[0], axis)], B1 = v[flip(p[1], axis)], C1 = v[flip(p[2], axis)], D1 = v[flip(p[3], axis)];
    }
    // F(t) = A_t C_t - B_t D_t = a t^2 + b t + c   (Custodio et al. 2013, Eqs. 6-7, Appendix A)
    double a() const { return (A1 - A0) * (C1 - C0) - (B1 - B0) * (D1 - D0); }
    double b() const { return C0 * (A1 - A0) + A0 * (C1 - C0) - D0 * (B1 - B0) - B0 * (D1 - D0); }
    double c() const { return A0 * C0 - B0 * D0; }
    double F(double t) const { return at(A0, A1, t) * at(C0, C1, t) - at(B0, B1, t) * at(D0, D1, t); }
    static double at(double x0, double x1, double t) { return x0 + (x1 - x0) * t; }

    /// In the slice at height t, is the region of corner A joined to that of corner C? Both must
    /// have A0's sign; through B or D when one of them has it too, else by the slice's saddle
    /// (asymptotic decider, sign rule: a saddle equal to iso is above).
    bool slice_joins(double t) const
    {
        const bool s = A0 >= 0;
        const double a_t = at(A0, A1, t), b_t = at(B0, B1, t), c_t = at(C0, C1, t), d_t = at(D0, D1, t);
        if ((a_t >= 0) != s || (c_t >= 0) != s) return false;
        if ((b_t >= 0) == s || (d_t >= 0) == s) return true;
        const double num = a_t * c_t - b_t * d_t;
        return s ? num >= 0 : num > 0;
    }
    /// Saddle position (u along A->B, v along A->D) of the slice at t (Custodio et al., Eq. 9).
    bool saddle_inside(double t, std::array<double, 2>* where) const
    {
        const double a_t = at(A0, A1, t), b_t = at(B0, B1, t), c_t = at(C0, C1, t), d_t = at(D0, D1, t);
        const double den = a_t + c_t - b_t - d_t;
        if (den == 0) return false;
        const double u = (a_t - d_t) / den, v = (a_t - b_t) / den;
        if (where) *where = {u, v};
        return u > 0 && u < 1 && v > 0 && v < 1;
    }
};

/// Chernyaev's test (Custodio et al. 2013, Sec. 3.1): joined iff a < 0, t_max = -b/2a in (0, 1)
/// and the slice at t_max joins A and C (for the tunnel cases the slice's own sign pattern is read,
/// so condition (iii) F(t_max) > 0 becomes "the slice joins them").
inline bool chernyaev_joined(const Sweep& s, InteriorReport* r)
{
    const double a = s.a(), b = s.b();
    const double t_max = a != 0 ? -b / (2 * a) : kNaN;
    if (r) {
        r->a = a, r->b = b, r->c = s.c(), r->t_max = t_max;
        r->f_t_max = a != 0 ? s.F(t_max) : kNaN;
    }
    return a < 0 && t_max > 0 && t_max < 1 && s.slice_joins(t_max);
}

inline void roots(const Sweep& s, double* t1, double* t2)
{
    const double a = s.a(), b = s.b(), c = s.c();
    const double disc = b * b - 4 * a * c;
    if (a == 0 || disc < 0) {
        *t1 = *t2 = kNaN;
        return;
    }
    const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b)); // stable quadratic roots
    double r1 = q / a, r2 = q != 0 ? c / q : r1;
    if (r1 > r2) std::swap(r1, r2);
    *t1 = r1, *t2 = r2;
}

/// Lewiner et al.'s height: where the field crosses the reference edge (Custodio et al., Eq. 8).
inline double t_alt(const double* v, int edge)
{
    const double v0 = v[kEdgeCorners[edge][0]], v1 = v[kEdgeCorners[edge][1]];
    const double t = v0 / (v0 - v1);
    return t;
}

struct Decision {
    const Variant* variant;
    int tiling; ///< 0 no tunnel, 1 tunnel (13.5: facing the above corner), 2 (13.5: facing below)
    int subcase;
};

/// Decides one cell with `config` not 0 or 255.
inline Decision decide(const double* v, unsigned config, Method method, CellReport* report = nullptr)
{
    const unsigned amb = kAmbiguousFaces[config];
    unsigned bits = 0;
    if (method != Method::mc) {
        int i = 0;
        for (int f = 0; f < 6; ++f) {
            if (!((amb >> f) & 1u)) continue;
            double saddle = 0;
            if (face_joined(v, f, report ? &saddle : nullptr)) bits |= 1u << i;
            if (report) report->faces[f] = {true, saddle, ((bits >> i) & 1u) != 0, true};
            ++i;
        }
    } else if (report) {
        for (int f = 0; f < 6; ++f) {
            if ((amb >> f) & 1u) report->faces[f] = {true, 0, false, false};
        }
    }
    const Variant* var = &kVariants[kVariantOffset[config] + bits];
    Decision d{var, 0, var->subcase};
    if (var->test == kTestNone || method == Method::mc) return d;

    InteriorReport* r = report ? &report->interior : nullptr;
    const Sweep sweep(v, var->axis, var->corner);
    const Sweep lewiner(v, var->lewiner_axis, var->lewiner_corner);
    if (r) {
        r->tested = true;
        r->test = var->test == kTestTunnel ? "tunnel" : "13.5";
        r->axis = var->axis, r->corner_a = var->corner, r->corner_c = var->corner ^ 7;
        r->lewiner_axis = var->lewiner_axis, r->lewiner_corner = var->lewiner_corner;
        r->lewiner_edge = var->lewiner_edge;
        r->t_alt = t_alt(v, var->lewiner_edge);
        r->f_t_alt = lewiner.F(r->t_alt);
        roots(sweep, &r->t1, &r->t2);
    }
    const bool chernyaev = chernyaev_joined(sweep, r); // fills a, b, c, t_max for the report
    const int base = kBaseCase[config];
    bool tunnel = false;
    int tiling = 1;
    if (var->test == kTestTunnel) {
        if (method == Method::cmc33 || base == 4 || base == 10) {
            tunnel = chernyaev;
        } else {
            tunnel = lewiner.slice_joins(t_alt(v, var->lewiner_edge)); // 6, 7, 12: Lewiner's t_alt
        }
        if (method == Method::mc33_lewiner && var->lewiner_skips) {
            tunnel = false; // cases 10 and 12 with both faces joined: never tested (Sec. 5.4)
            if (r) r->skipped = true;
        }
    } else if (method == Method::cmc33) {
        // Algorithm 1 (Custodio et al. 2013, Sec. 6.1): both roots of F in (0,1) and both slice
        // saddles x_c(t1), x_c(t2) inside the face. Orientation (Sec. 6.1.1): the tunnel faces
        // the corner of the isolated diagonal whose sign the slice saddle has at (t1 + t2) / 2.
        double t1, t2;
        roots(sweep, &t1, &t2);
        std::array<double, 2> x1{kNaN, kNaN}, x2{kNaN, kNaN};
        const bool in1 = t1 > 0 && t1 < 1 && sweep.saddle_inside(t1, &x1);
        const bool in2 = t2 > 0 && t2 < 1 && sweep.saddle_inside(t2, &x2);
        if (r) r->saddle1 = x1, r->saddle2 = x2;
        tunnel = in1 && in2;
        if (tunnel) {
            const double tm = 0.5 * (t1 + t2);
            const double a_t = Sweep::at(sweep.A0, sweep.A1, tm), b_t = Sweep::at(sweep.B0, sweep.B1, tm);
            const double c_t = Sweep::at(sweep.C0, sweep.C1, tm), d_t = Sweep::at(sweep.D0, sweep.D1, tm);
            const double saddle = (a_t * c_t - b_t * d_t) / (a_t + c_t - b_t - d_t);
            tiling = saddle >= 0 ? 1 : 2;
        }
    } else {
        // mc33-lewiner on 13.5: condition (iii) at Lewiner's height, tunnel orientation never
        // tested (Custodio et al. Sec. 5.1.1, Appendix A).
        tunnel = lewiner.F(t_alt(v, var->lewiner_edge)) > 0;
    }
    if (r) r->tunnel = tunnel;
    if (!tunnel) return d;
    if (r && var->test == kTest13_5) {
        // tiling 1 faces the above corner of the isolated diagonal (corner or corner ^ 7)
        const int above = v[var->corner] >= 0 ? var->corner : var->corner ^ 7;
        r->tunnel_corner = tiling == 1 ? above : above ^ 7;
    }
    return {var, tiling, var->tunnel_subcase};
}

} // namespace cmc33::detail
