// Exact predicates and triangle intersection tests (contract in exact_geometry.hpp).

#include "exact_geometry.hpp"

#include <cmath>
#include <cstddef>
#include <limits>

#if !defined(CMC33_WITH_GMP) || CMC33_WITH_GMP
#include <gmpxx.h>
#else
#include "cmc33/error.hpp"
#include "expansion.hpp"
#endif

namespace cmc33::detail {
namespace {

constexpr double kEps = kUnitRoundoff; // u = 2^-53

int sign_of(double x) { return (x > 0) - (x < 0); }

/// a - b exactly as hi + lo (Knuth's two-sum on a and -b).
void two_diff(double a, double b, double& hi, double& lo)
{
    hi = a - b;
    const double bv = a - hi;
    const double av = hi + bv;
    lo = (a - av) + (bv - b);
}

void two_sum(double a, double b, double& hi, double& lo)
{
    hi = a + b;
    const double bv = hi - a;
    const double av = hi - bv;
    lo = (a - av) + (b - bv);
}

/// The exact sign of the sum of n doubles, or 2 when distillation did not settle it.
/// Each pass replaces the terms by error-free two-sums that leave the exact sum unchanged and
/// gather it in the last term; once that term outweighs all the others, it has the sum's sign.
int sign_of_sum(double* x, std::size_t n)
{
    for (int pass = 0; pass < 64; ++pass) {
        for (std::size_t i = 1; i < n; ++i) two_sum(x[i], x[i - 1], x[i], x[i - 1]);
        double rest = 0;
        for (std::size_t i = 0; i + 1 < n; ++i) rest += std::fabs(x[i]);
        const double last = std::fabs(x[n - 1]);
        if (rest == 0) return sign_of(x[n - 1]);
        // rest is computed with n - 1 roundings: true rest <= rest * (1 + 2 n u)
        if (last > rest * (1 + 2 * static_cast<double>(n) * kEps)) return sign_of(x[n - 1]);
    }
    return 2;
}

/// x * y * z as four exact terms (inputs are differences of floats: no underflow can occur).
void triple_product(double x, double y, double z, double* out)
{
    const double p = x * y;
    const double e = std::fma(x, y, -p);
    out[0] = p * z;
    out[1] = std::fma(p, z, -out[0]);
    out[2] = e * z;
    out[3] = std::fma(e, z, -out[2]);
}

bool exact_differences(const double* a, const double* b, double* out, int n)
{
    for (int i = 0; i < n; ++i) {
        double lo = 0;
        two_diff(a[i], b[i], out[i], lo);
        if (lo != 0) return false;
    }
    return true;
}

#if !defined(CMC33_WITH_GMP) || CMC33_WITH_GMP
using Exact = mpq_class;
int exact_sign(const mpq_class& q) { return sgn(q); }
#else
// Without GMP (the WebAssembly build): Shewchuk expansions. Mesh coordinates are floats, whose
// degree-3 products stay far from the expansions' underflow; should they not, say so.
using Exact = Expansion;
int exact_sign(const Expansion& x)
{
    if (x.lost()) {
        throw Error(Status::internal, "an exact geometric predicate left the range of this build's expansions "
                                      "(coordinates far beyond the float range); a build with GMP decides it");
    }
    return x.sign();
}
#endif

int orient3d_rational(const Point3& a, const Point3& b, const Point3& c, const Point3& d)
{
    Exact m[3][3];
    const Point3* rows[3] = {&a, &b, &c};
    for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) {
            const auto kk = static_cast<std::size_t>(k);
            m[r][k] = Exact((*rows[r])[kk]) - Exact(d[kk]);
        }
    const Exact det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                      m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                      m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    return exact_sign(det);
}

int orient2d_rational(double ax, double ay, double bx, double by, double cx, double cy)
{
    const Exact det = (Exact(ax) - Exact(cx)) * (Exact(by) - Exact(cy)) - (Exact(ay) - Exact(cy)) * (Exact(bx) - Exact(cx));
    return exact_sign(det);
}

} // namespace

PredicateStats& predicate_stats() noexcept { return g_predicate_stats; }

int orient3d_exact(const Point3& a, const Point3& b, const Point3& c, const Point3& d)
{
    // four points with one coordinate equal (a flat of a grid-aligned surface): a zero column
    for (std::size_t k = 0; k < 3; ++k) {
        if (a[k] == d[k] && b[k] == d[k] && c[k] == d[k]) {
            ++g_predicate_stats.expansion;
            return 0;
        }
    }
    double da[3], db[3], dc[3];
    if (exact_differences(a.data(), d.data(), da, 3) && exact_differences(b.data(), d.data(), db, 3) &&
        exact_differences(c.data(), d.data(), dc, 3)) {
        double terms[24];
        triple_product(da[0], db[1], dc[2], terms + 0);
        triple_product(-da[0], db[2], dc[1], terms + 4);
        triple_product(db[0], dc[1], da[2], terms + 8);
        triple_product(-db[0], dc[2], da[1], terms + 12);
        triple_product(dc[0], da[1], db[2], terms + 16);
        triple_product(-dc[0], da[2], db[1], terms + 20);
        const int s = sign_of_sum(terms, 24);
        if (s != 2) {
            ++g_predicate_stats.expansion;
            return s;
        }
    }
    ++g_predicate_stats.rational;
    return orient3d_rational(a, b, c, d);
}

int orient2d_exact(const Point3& a, const Point3& b, const Point3& c, int drop)
{
    const auto u = static_cast<std::size_t>(drop == 0 ? 1 : 0), v = static_cast<std::size_t>(drop == 2 ? 1 : 2);
    const double acx = a[u] - c[u], acy = a[v] - c[v], bcx = b[u] - c[u], bcy = b[v] - c[v];
    const double l = acx * bcy, r = acy * bcx;
    const double det = l - r;
    const double pa[2] = {a[u], a[v]}, pb[2] = {b[u], b[v]}, pc[2] = {c[u], c[v]};
    double dac[2], dbc[2];
    if (exact_differences(pa, pc, dac, 2) && exact_differences(pb, pc, dbc, 2)) {
        // both products exact (collinear points of a grid-aligned mesh, typically): l - r has
        // the sign of the exact determinant, rounding or not
        if (std::fma(acx, bcy, -l) == 0 && std::fma(acy, bcx, -r) == 0) {
            ++g_predicate_stats.expansion;
            return sign_of(det);
        }
        double terms[4];
        terms[0] = dac[0] * dbc[1];
        terms[1] = std::fma(dac[0], dbc[1], -terms[0]);
        terms[2] = -(dac[1] * dbc[0]);
        terms[3] = -std::fma(dac[1], dbc[0], terms[2]);
        const int s = sign_of_sum(terms, 4);
        if (s != 2) {
            ++g_predicate_stats.expansion;
            return s;
        }
    }
    ++g_predicate_stats.rational;
    return orient2d_rational(a[u], a[v], b[u], b[v], c[u], c[v]);
}

bool collinear(const Point3& a, const Point3& b, const Point3& c)
{
    return orient2d(a, b, c, 0) == 0 && orient2d(a, b, c, 1) == 0 && orient2d(a, b, c, 2) == 0;
}

int projection_axis(const Point3& a, const Point3& b, const Point3& c)
{
    for (int drop = 2; drop > 0; --drop)
        if (orient2d(a, b, c, drop) != 0) return drop;
    return 0;
}

namespace {

/// q lies on the closed segment ab, given that a, b, q are collinear.
bool on_segment(const Point3& a, const Point3& b, const Point3& q)
{
    for (std::size_t k = 0; k < 3; ++k) {
        if (q[k] < std::fmin(a[k], b[k]) || q[k] > std::fmax(a[k], b[k])) return false;
    }
    return true;
}

/// Closed segments pq and ab meet, all four points in one plane (projected by `drop`).
bool segments_meet_2d(const Point3& p, const Point3& q, const Point3& a, const Point3& b, int drop)
{
    const int o1 = orient2d(p, q, a, drop), o2 = orient2d(p, q, b, drop);
    const int o3 = orient2d(a, b, p, drop), o4 = orient2d(a, b, q, drop);
    if (o1 * o2 < 0 && o3 * o4 < 0) return true;
    return (o1 == 0 && on_segment(p, q, a)) || (o2 == 0 && on_segment(p, q, b)) || (o3 == 0 && on_segment(a, b, p)) ||
           (o4 == 0 && on_segment(a, b, q));
}

bool point_in_triangle_2d(const Point3& p, const Point3& a, const Point3& b, const Point3& c, int drop)
{
    const int s = orient2d(a, b, c, drop);
    return orient2d(a, b, p, drop) * s >= 0 && orient2d(b, c, p, drop) * s >= 0 && orient2d(c, a, p, drop) * s >= 0;
}

/// Closed segment pq and closed triangle abc in one plane.
bool segment_meets_triangle_2d(const Point3& p, const Point3& q, const Point3& a, const Point3& b, const Point3& c)
{
    const int drop = projection_axis(a, b, c);
    return point_in_triangle_2d(p, a, b, c, drop) || point_in_triangle_2d(q, a, b, c, drop) ||
           segments_meet_2d(p, q, a, b, drop) || segments_meet_2d(p, q, b, c, drop) || segments_meet_2d(p, q, c, a, drop);
}

/// Segment v->a leaves v into triangle (v, c, d) — which holds when a is in the plane of the
/// triangle and inside the closed angle at v (the triangle covers a neighbourhood of v in it).
bool edge_enters_at_shared_corner(const Point3& v, const Point3& a, const Point3& c, const Point3& d)
{
    if (orient3d(v, c, d, a) != 0) return false;
    const int drop = projection_axis(v, c, d);
    const int s = orient2d(v, c, d, drop);
    return orient2d(v, c, a, drop) * s >= 0 && orient2d(v, a, d, drop) * s >= 0;
}

bool triangles_meet(const std::array<Point3, 3>& t, const std::array<Point3, 3>& u)
{
    // separated by a plane of one of them: all corners of the other strictly on one side
    for (int pass = 0; pass < 2; ++pass) {
        const auto& x = pass == 0 ? t : u;
        const auto& y = pass == 0 ? u : t;
        const int s0 = orient3d(x[0], x[1], x[2], y[0]), s1 = orient3d(x[0], x[1], x[2], y[1]),
                  s2 = orient3d(x[0], x[1], x[2], y[2]);
        if ((s0 > 0 && s1 > 0 && s2 > 0) || (s0 < 0 && s1 < 0 && s2 < 0)) return false;
    }
    // two closed triangles meet iff an edge of one meets the other
    for (int i = 0; i < 3; ++i) {
        const auto a = static_cast<std::size_t>(i), b = static_cast<std::size_t>((i + 1) % 3);
        if (segment_meets_triangle(t[a], t[b], u[0], u[1], u[2])) return true;
        if (segment_meets_triangle(u[a], u[b], t[0], t[1], t[2])) return true;
    }
    return false;
}

} // namespace

bool segment_meets_triangle(const Point3& p, const Point3& q, const Point3& a, const Point3& b, const Point3& c)
{
    const int op = orient3d(a, b, c, p), oq = orient3d(a, b, c, q);
    if (op == 0 && oq == 0) return segment_meets_triangle_2d(p, q, a, b, c);
    if (op * oq > 0) return false;
    // the segment meets the plane in one point; the line pq passes through the closed triangle iff
    // it sees the three edges turning the same way
    const int s1 = orient3d(p, q, a, b), s2 = orient3d(p, q, b, c), s3 = orient3d(p, q, c, a);
    return (s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0);
}

namespace {

/// The coordinate to drop when projecting triangle t: its normal's largest component (rounding may
/// pick another; every projection gives a valid test below, this one a non-degenerate picture).
int dominant_axis(const std::array<Point3, 3>& t)
{
    const double e[2][3] = {{t[1][0] - t[0][0], t[1][1] - t[0][1], t[1][2] - t[0][2]},
                            {t[2][0] - t[0][0], t[2][1] - t[0][1], t[2][2] - t[0][2]}};
    const double n[3] = {std::fabs(e[0][1] * e[1][2] - e[0][2] * e[1][1]), std::fabs(e[0][2] * e[1][0] - e[0][0] * e[1][2]),
                         std::fabs(e[0][0] * e[1][1] - e[0][1] * e[1][0])};
    return n[0] >= n[1] && n[0] >= n[2] ? 0 : n[1] >= n[2] ? 1 : 2;
}

/// Projected along `drop`, x lies strictly on one side of the line pq and y and z strictly on the
/// other. Then the plane through p and q parallel to the dropped axis separates: a triangle with
/// corners p, q (or p), x and one with p, q (or p), y, z meet only in what they share.
bool split_by_line(const Point3& p, const Point3& q, const Point3& x, const Point3& y, const Point3& z, int drop)
{
    const int s = orient2d(p, q, x, drop);
    return s != 0 && orient2d(p, q, y, drop) == -s && orient2d(p, q, z, drop) == -s;
}

} // namespace

bool triangles_meet_improperly(const std::array<Point3, 3>& t, const std::array<Point3, 3>& u, int shared)
{
    // The usual case of a curved surface first, by the filters alone: the rest of one triangle
    // strictly on one side of the other's plane, which then holds only what they share.
    if (shared == 2 && orient3d_filter(t[0], t[1], t[2], u[2]) != 0) return false;
    if (shared == 1) {
        for (int pass = 0; pass < 2; ++pass) {
            const auto& x = pass == 0 ? t : u;
            const auto& y = pass == 0 ? u : t;
            const int s = orient3d_filter(x[0], x[1], x[2], y[1]);
            if (s != 0 && orient3d_filter(x[0], x[1], x[2], y[2]) == s) return false;
        }
    }
    // Then filtered 2D orientations, which settle coplanar neighbours (flat parts of a surface)
    // without exact arithmetic: a line through the shared corners that has the rest of t strictly
    // on one side and the rest of u strictly on the other.
    if (shared == 2 && split_by_line(t[0], t[1], t[2], u[2], u[2], dominant_axis(t))) return false;
    if (shared == 1) {
        const int drop = dominant_axis(t);
        if (split_by_line(t[0], t[1], t[2], u[1], u[2], drop) || split_by_line(t[0], t[2], t[1], u[1], u[2], drop) ||
            split_by_line(u[0], u[1], u[2], t[1], t[2], drop) || split_by_line(u[0], u[2], u[1], t[1], t[2], drop))
            return false;
    }
    if (shared == 0) return triangles_meet(t, u);
    if (shared == 1) {
        // t = (v, a, b), u = (v, c, d): the convex set t ∩ u holds v; it holds more iff an
        // opposite edge meets the other triangle or an edge at v runs into the other triangle.
        const Point3 &v = t[0], &a = t[1], &b = t[2], &c = u[1], &d = u[2];
        // the usual case first: one triangle's other corners strictly on one side of the other's
        // plane, which then holds only v of it
        for (int pass = 0; pass < 2; ++pass) {
            const int s0 = pass == 0 ? orient3d(v, a, b, c) : orient3d(v, c, d, a);
            if (s0 == 0) continue;
            if ((pass == 0 ? orient3d(v, a, b, d) : orient3d(v, c, d, b)) == s0) return false;
        }
        return segment_meets_triangle(a, b, v, c, d) || segment_meets_triangle(c, d, v, a, b) ||
               edge_enters_at_shared_corner(v, a, c, d) || edge_enters_at_shared_corner(v, b, c, d) ||
               edge_enters_at_shared_corner(v, c, a, b) || edge_enters_at_shared_corner(v, d, a, b);
    }
    // shared edge (t[0], t[1]): two planes through one line meet only in it, so the triangles
    // overlap only when coplanar with their third corners on the same side of the edge
    if (orient3d(t[0], t[1], t[2], u[2]) != 0) return false;
    const int drop = projection_axis(t[0], t[1], t[2]);
    return orient2d(t[0], t[1], t[2], drop) * orient2d(t[0], t[1], u[2], drop) > 0;
}

} // namespace cmc33::detail
