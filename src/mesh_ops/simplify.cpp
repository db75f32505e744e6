// simplify(): quadric-ordered edge collapses that keep topology, manifoldness and embedding.
//
// Quadrics: Garland and Heckbert 1997, "Surface Simplification Using Quadric Error Metrics": each
// input triangle's plane adds its squared-distance form to its three corners; a boundary edge adds
// the plane through it perpendicular to its triangle, so boundaries keep their shape. A collapse
// of edge ab puts the kept vertex at the cheaper of two points: the minimum of Qa + Qb on the
// segment ab, and its minimum nearest ab's midpoint with the directions of small curvature left
// out (minimum_near). The plain 3D optimum is ill-conditioned on the flat and cylindrical patches
// a marching cubes mesh is made of and can land far from both stars, where the embedding check
// refuses it; the second point moves only along well-determined directions, so it finds corners
// and creases the segment misses (a quarter lower mean distance to the input on bonsai).
//
// Topology: the link condition (Dey, Edelsbrunner, Guha and Nekhayev 1999) with the boundary coned
// off by a virtual vertex: for interior edge ab with opposite corners c and d, the common
// neighbours of a and b must be exactly {c, d}, and triangles acd and bcd must not both exist (a
// tetrahedron, the smallest closed component); an interior edge between two boundary vertices is
// refused (it would pinch); a boundary edge's endpoints must have only its opposite corner c in
// common, and a boundary loop of three edges is kept. An interior vertex collapsing onto a
// boundary vertex goes to the boundary vertex's position.

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <string>

#include "cmc33/error.hpp"
#include "cmc33/mesh_ops.hpp"
#include "work_mesh.hpp"

namespace cmc33 {

namespace {

using mesh_ops::Pos;
using mesh_ops::Refusal;
using mesh_ops::Tri;
using mesh_ops::V3;
using mesh_ops::WorkMesh;

/// Symmetric 4x4 form: a00 a01 a02 a03 a11 a12 a13 a22 a23 a33.
struct Quadric {
    std::array<double, 10> q{};
    void add_plane(double nx, double ny, double nz, double d, double w)
    {
        q[0] += w * nx * nx; q[1] += w * nx * ny; q[2] += w * nx * nz; q[3] += w * nx * d;
        q[4] += w * ny * ny; q[5] += w * ny * nz; q[6] += w * ny * d;
        q[7] += w * nz * nz; q[8] += w * nz * d;
        q[9] += w * d * d;
    }
    Quadric& operator+=(const Quadric& o)
    {
        for (std::size_t i = 0; i < 10; ++i) q[i] += o.q[i];
        return *this;
    }
    double eval(double x, double y, double z) const
    {
        return q[0] * x * x + 2 * q[1] * x * y + 2 * q[2] * x * z + 2 * q[3] * x + q[4] * y * y + 2 * q[5] * y * z +
               2 * q[6] * y + q[7] * z * z + 2 * q[8] * z + q[9];
    }
};

double cost_at(const Quadric& q, const Pos& p)
{
    return q.eval(static_cast<double>(p[0]), static_cast<double>(p[1]), static_cast<double>(p[2]));
}

/// The minimum of q nearest the midpoint of the edge x .. x + e: the normal equations solved with
/// the eigenvalues below 1e-3 of the largest left out (Lindstrom 2000, "Out-of-core simplification
/// of large polygonal models"), so that along flat and cylindrical directions the point stays at
/// the midpoint. False when it lands farther from the midpoint than the edge is long.
bool minimum_near(const Quadric& quadric, const double x[3], const double e[3], Pos& out)
{
    const auto& s = quadric.q;
    double a[3][3] = {{s[0], s[1], s[2]}, {s[1], s[4], s[5]}, {s[2], s[5], s[7]}};
    double v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}; // eigenvectors, by column
    for (int sweep = 0; sweep < 12; ++sweep) {         // cyclic Jacobi rotations
        const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        const double diagonal = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        if (off <= 1e-30 * diagonal) break;
        for (int p = 0; p < 2; ++p)
            for (int r = p + 1; r < 3; ++r) {
                if (a[p][r] == 0) continue;
                const double theta = (a[r][r] - a[p][p]) / (2 * a[p][r]);
                const double t = (theta >= 0 ? 1 : -1) / (std::abs(theta) + std::sqrt(theta * theta + 1));
                const double cs = 1 / std::sqrt(t * t + 1), sn = t * cs;
                for (int k = 0; k < 3; ++k) {
                    const double kp = a[k][p], kr = a[k][r];
                    a[k][p] = cs * kp - sn * kr;
                    a[k][r] = sn * kp + cs * kr;
                }
                for (int k = 0; k < 3; ++k) {
                    const double pk = a[p][k], rk = a[r][k];
                    a[p][k] = cs * pk - sn * rk;
                    a[r][k] = sn * pk + cs * rk;
                }
                for (int k = 0; k < 3; ++k) {
                    const double kp = v[k][p], kr = v[k][r];
                    v[k][p] = cs * kp - sn * kr;
                    v[k][r] = sn * kp + cs * kr;
                }
            }
    }
    const double largest = std::max({std::abs(a[0][0]), std::abs(a[1][1]), std::abs(a[2][2])});
    if (!(largest > 0)) return false;
    const double m[3] = {x[0] + 0.5 * e[0], x[1] + 0.5 * e[1], x[2] + 0.5 * e[2]};
    // half the gradient at the midpoint: A m + b
    const double g[3] = {s[0] * m[0] + s[1] * m[1] + s[2] * m[2] + s[3], s[1] * m[0] + s[4] * m[1] + s[5] * m[2] + s[6],
                         s[2] * m[0] + s[5] * m[1] + s[7] * m[2] + s[8]};
    double step[3] = {0, 0, 0};
    for (int i = 0; i < 3; ++i) {
        const double lambda = a[i][i];
        if (lambda < 1e-3 * largest) continue;
        const double along = -(v[0][i] * g[0] + v[1][i] * g[1] + v[2][i] * g[2]) / lambda;
        for (int k = 0; k < 3; ++k) step[k] += along * v[k][i];
    }
    const double moved = step[0] * step[0] + step[1] * step[1] + step[2] * step[2];
    if (!(moved <= e[0] * e[0] + e[1] * e[1] + e[2] * e[2])) return false;
    for (int k = 0; k < 3; ++k) out[static_cast<std::size_t>(k)] = static_cast<float>(m[k] + step[k]);
    return true;
}

struct Candidate {
    double cost;
    std::uint32_t a, b;   ///< a < b
    std::uint32_t va, vb; ///< versions of a and b when computed
    Pos p;
    bool operator<(const Candidate& o) const // for a min-heap: "greater" means popped later
    {
        if (cost != o.cost) return cost > o.cost;
        if (a != o.a) return a > o.a;
        return b > o.b;
    }
};

struct Simplifier {
    WorkMesh m;
    std::vector<Quadric> quadric;
    std::vector<std::uint32_t> version;
    std::priority_queue<Candidate> heap;
    SimplifyStats stats;
    /// With a distance bound: the input's vertices and triangles; per vertex the input vertices
    /// merged into it (a list through cluster_next from the vertex itself to cluster_tail,
    /// kNone-terminated); and per live triangle the input vertices assigned to it (a list from
    /// assigned_first through assigned_next), each within the bound of that triangle.
    double max_distance_sq = std::numeric_limits<double>::infinity();
    std::vector<V3> input;
    std::vector<Tri> input_tri;
    std::vector<std::uint32_t> input_star_first, input_star; ///< per input vertex its input triangles
    /// per input triangle: its centroid and (radius + bound)^2, the radius the farthest corner's
    /// distance from it; a point farther from the centroid is beyond the bound of the triangle
    std::vector<std::array<double, 4>> input_ball;
    std::vector<std::uint32_t> cluster_next, cluster_tail;
    std::vector<std::uint32_t> assigned_first, assigned_next;
    static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

    Simplifier(const Mesh& mesh, double max_distance) : m(mesh), quadric(m.pos.size()), version(m.pos.size(), 0)
    {
        if (std::isfinite(max_distance)) {
            max_distance_sq = max_distance * max_distance;
            input.reserve(m.pos.size());
            cluster_tail.reserve(m.pos.size());
            for (std::size_t v = 0; v < m.pos.size(); ++v) {
                input.push_back(point(m.pos[v]));
                cluster_tail.push_back(static_cast<std::uint32_t>(v));
            }
            cluster_next.assign(m.pos.size(), kNone);
            input_tri = m.tri;
            input_star_first.assign(m.pos.size() + 1, 0);
            for (const Tri& t : input_tri)
                for (const std::uint32_t v : t) ++input_star_first[v + 1];
            for (std::size_t v = 0; v < m.pos.size(); ++v) input_star_first[v + 1] += input_star_first[v];
            input_star.resize(input_star_first.back());
            std::vector<std::uint32_t> fill(input_star_first.begin(), input_star_first.end() - 1);
            for (std::size_t t = 0; t < input_tri.size(); ++t)
                for (const std::uint32_t v : input_tri[t]) input_star[fill[v]++] = static_cast<std::uint32_t>(t);
            // each input vertex starts on a triangle of its own star (distance 0); unused ones on none
            assigned_first.assign(m.tri.size(), kNone);
            assigned_next.assign(m.pos.size(), kNone);
            for (std::size_t v = 0; v < m.pos.size(); ++v) {
                if (m.vtris[v].empty()) continue;
                const std::uint32_t t = m.vtris[v].front();
                assigned_next[v] = assigned_first[t];
                assigned_first[t] = static_cast<std::uint32_t>(v);
            }
            input_tri_mark.assign(input_tri.size(), 0);
            input_ball.resize(input_tri.size());
            for (std::size_t t = 0; t < input_tri.size(); ++t) {
                const V3 &x = input[input_tri[t][0]], &y = input[input_tri[t][1]], &z = input[input_tri[t][2]];
                const V3 o{(x[0] + y[0] + z[0]) / 3, (x[1] + y[1] + z[1]) / 3, (x[2] + y[2] + z[2]) / 3};
                const double r = std::sqrt(std::max({mesh_ops::dot(mesh_ops::sub(x, o), mesh_ops::sub(x, o)),
                                                     mesh_ops::dot(mesh_ops::sub(y, o), mesh_ops::sub(y, o)),
                                                     mesh_ops::dot(mesh_ops::sub(z, o), mesh_ops::sub(z, o))}));
                input_ball[t] = {o[0], o[1], o[2], (r + max_distance) * (r + max_distance)};
            }
        }
        for (std::size_t t = 0; t < m.tri.size(); ++t) {
            const Tri& c = m.tri[t];
            const Pos& a = m.pos[c[0]];
            const Pos& b = m.pos[c[1]];
            const Pos& d = m.pos[c[2]];
            double n[3], e1[3], e2[3];
            for (int k = 0; k < 3; ++k) {
                e1[k] = static_cast<double>(b[k]) - static_cast<double>(a[k]);
                e2[k] = static_cast<double>(d[k]) - static_cast<double>(a[k]);
            }
            n[0] = e1[1] * e2[2] - e1[2] * e2[1];
            n[1] = e1[2] * e2[0] - e1[0] * e2[2];
            n[2] = e1[0] * e2[1] - e1[1] * e2[0];
            const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            if (!(len > 0)) continue;
            for (double& x : n) x /= len;
            const double off = -(n[0] * static_cast<double>(a[0]) + n[1] * static_cast<double>(a[1]) + n[2] * static_cast<double>(a[2]));
            for (const std::uint32_t v : c) quadric[v].add_plane(n[0], n[1], n[2], off, 1);
            // boundary edges: a plane through the edge, perpendicular to the triangle
            for (int i = 0; i < 3; ++i) {
                const std::uint32_t u = c[static_cast<std::size_t>(i)];
                const std::uint32_t w = c[static_cast<std::size_t>((i + 1) % 3)];
                if (!m.boundary[u] || !m.boundary[w] || edge_triangles(u, w) != 1) continue;
                double e[3], q[3];
                for (int k = 0; k < 3; ++k) e[k] = static_cast<double>(m.pos[w][k]) - static_cast<double>(m.pos[u][k]);
                q[0] = e[1] * n[2] - e[2] * n[1];
                q[1] = e[2] * n[0] - e[0] * n[2];
                q[2] = e[0] * n[1] - e[1] * n[0];
                const double ql = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
                if (!(ql > 0)) continue;
                for (double& x : q) x /= ql;
                const double qo = -(q[0] * static_cast<double>(m.pos[u][0]) + q[1] * static_cast<double>(m.pos[u][1]) +
                                    q[2] * static_cast<double>(m.pos[u][2]));
                quadric[u].add_plane(q[0], q[1], q[2], qo, 1);
                quadric[w].add_plane(q[0], q[1], q[2], qo, 1);
            }
        }
    }

    int edge_triangles(std::uint32_t u, std::uint32_t w) const
    {
        int n = 0;
        for (const std::uint32_t t : m.vtris[u]) {
            const Tri& c = m.tri[t];
            if (c[0] == w || c[1] == w || c[2] == w) ++n;
        }
        return n;
    }

    /// Cost and position of collapsing edge ab.
    Candidate evaluate(std::uint32_t a, std::uint32_t b) const
    {
        Candidate c{0, std::min(a, b), std::max(a, b), 0, 0, {}};
        c.va = version[c.a];
        c.vb = version[c.b];
        Quadric q = quadric[a];
        q += quadric[b];
        if (m.boundary[a] != m.boundary[b]) {
            c.p = m.boundary[a] ? m.pos[a] : m.pos[b];
        } else {
            const Pos& pa = m.pos[c.a];
            const Pos& pb = m.pos[c.b];
            double x[3], e[3];
            for (int k = 0; k < 3; ++k) {
                x[k] = static_cast<double>(pa[k]);
                e[k] = static_cast<double>(pb[k]) - x[k];
            }
            // Q(x + t e) = Q(x) + 2 t (e.A x + e.b) + t^2 e.A e
            const auto& s = q.q;
            const double ax[3] = {s[0] * x[0] + s[1] * x[1] + s[2] * x[2] + s[3], s[1] * x[0] + s[4] * x[1] + s[5] * x[2] + s[6],
                                  s[2] * x[0] + s[5] * x[1] + s[7] * x[2] + s[8]};
            const double ae[3] = {s[0] * e[0] + s[1] * e[1] + s[2] * e[2], s[1] * e[0] + s[4] * e[1] + s[5] * e[2],
                                  s[2] * e[0] + s[5] * e[1] + s[7] * e[2]};
            const double lin = e[0] * ax[0] + e[1] * ax[1] + e[2] * ax[2];
            const double quad = e[0] * ae[0] + e[1] * ae[1] + e[2] * ae[2];
            // flat along the edge (every t costs the same): the midpoint keeps triangles even
            double t = 0.5;
            if (quad > 1e-12 * (std::abs(lin) + 1e-300)) t = std::clamp(-lin / quad, 0.0, 1.0);
            for (int k = 0; k < 3; ++k) c.p[static_cast<std::size_t>(k)] = static_cast<float>(x[k] + t * e[k]);
            Pos free;
            if (minimum_near(q, x, e, free) && cost_at(q, free) < cost_at(q, c.p)) c.p = free;
        }
        c.cost = std::max(0.0, cost_at(q, c.p));
        return c;
    }

    void push_edges_of(std::uint32_t v)
    {
        std::uint32_t seen[64];
        int n = 0;
        for (const std::uint32_t t : m.vtris[v]) {
            for (const std::uint32_t w : m.tri[t]) {
                if (w == v || std::find(seen, seen + n, w) != seen + n) continue;
                if (n < 64) seen[n++] = w;
                heap.push(evaluate(v, w));
            }
        }
    }

    void seed()
    {
        for (std::uint32_t v = 0; v < m.pos.size(); ++v) {
            for (const std::uint32_t t : m.vtris[v]) {
                for (const std::uint32_t w : m.tri[t]) {
                    // each edge once, from its triangle where it runs from the smaller index
                    if (w > v) {
                        const Tri& c = m.tri[t];
                        int i = 0;
                        while (c[static_cast<std::size_t>(i)] != v) ++i;
                        if (c[static_cast<std::size_t>((i + 1) % 3)] == w || edge_triangles(v, w) == 1) {
                            heap.push(evaluate(v, w));
                        }
                    }
                }
            }
        }
    }

    /// The neighbours of v (sorted).
    void neighbours(std::uint32_t v, std::vector<std::uint32_t>& out) const
    {
        out.clear();
        for (const std::uint32_t t : m.vtris[v])
            for (const std::uint32_t w : m.tri[t])
                if (w != v) out.push_back(w);
        std::sort(out.begin(), out.end());
        out.erase(std::unique(out.begin(), out.end()), out.end());
    }

    bool has_triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) const
    {
        for (const std::uint32_t t : m.vtris[a]) {
            const Tri& x = m.tri[t];
            const bool hb = x[0] == b || x[1] == b || x[2] == b;
            const bool hc = x[0] == c || x[1] == c || x[2] == c;
            if (hb && hc) return true;
        }
        return false;
    }

    static V3 point(const Pos& p)
    {
        return {static_cast<double>(p[0]), static_cast<double>(p[1]), static_cast<double>(p[2])};
    }

    std::vector<std::array<V3, 3>> new_corners_; ///< the corners of new_tris_, the moved vertex at its new place
    std::vector<std::array<double, 4>> new_ball_; ///< per new triangle: its centroid and the farthest corner's distance
    std::vector<std::uint32_t> moving_;         ///< input vertices assigned to triangles the collapse changes or removes
    std::vector<std::uint32_t> moving_to_;      ///< per moving_ vertex: its nearest new triangle (index into new_tris_)
    std::vector<std::uint32_t> near_input_;     ///< input triangles the new triangles' samples are compared with
    std::vector<std::uint32_t> input_tri_mark;
    std::uint32_t input_tri_stamp = 0;

    void add_star_of_cluster(std::uint32_t v)
    {
        for (std::uint32_t q = v; q != kNone; q = cluster_next[q]) add_star(q);
    }
    void add_star(std::uint32_t q)
    {
        for (std::uint32_t i = input_star_first[q]; i < input_star_first[q + 1]; ++i) {
            const std::uint32_t t = input_star[i];
            if (input_tri_mark[t] == input_tri_stamp) continue;
            input_tri_mark[t] = input_tri_stamp;
            near_input_.push_back(t);
        }
    }

    /// Whether the collapse of b into a (a at p), whose triangles are new_tris_, keeps the surface
    /// within the bound of the input.
    ///
    /// Guaranteed (input to output): every input vertex stays within the bound of the live triangle
    /// it is assigned to. Those assigned to a triangle the collapse changes or removes must each find
    /// a new triangle within the bound (they move to the nearest one), else the collapse is refused;
    /// the other triangles do not move, so their input vertices stay near.
    ///
    /// Sampled (output to input): the new vertex, each new triangle's centroid and the midpoints of
    /// its edges at the new vertex (every other edge of the mesh was sampled when last made) must
    /// each lie within the bound of an input triangle of the local set: the stars of the input
    /// vertices above, and of the input vertices merged into a, b and the other corners of the new
    /// triangles. Points between the samples, and input triangles outside that set, are not looked at.
    bool within_bound(std::uint32_t a, std::uint32_t b, const Pos& p)
    {
        if (!std::isfinite(max_distance_sq)) return true;
        const V3 c = point(p);
        new_corners_.clear();
        new_ball_.clear();
        for (const Tri& t : new_tris_) {
            std::array<V3, 3> x{};
            for (std::size_t i = 0; i < 3; ++i) x[i] = t[i] == a ? c : point(m.pos[t[i]]);
            new_corners_.push_back(x);
            const V3 o{(x[0][0] + x[1][0] + x[2][0]) / 3, (x[0][1] + x[1][1] + x[2][1]) / 3, (x[0][2] + x[1][2] + x[2][2]) / 3};
            double r = 0;
            for (const V3& y : x) r = std::max(r, mesh_ops::dot(mesh_ops::sub(y, o), mesh_ops::sub(y, o)));
            new_ball_.push_back({o[0], o[1], o[2], std::sqrt(r)});
        }
        // input to output: each input vertex of a changed or removed triangle finds a new one near it
        moving_.clear();
        moving_to_.clear();
        for (const auto* list : {&changed_, &shared_})
            for (const std::uint32_t t : *list)
                for (std::uint32_t q = assigned_first[t]; q != kNone; q = assigned_next[q]) moving_.push_back(q);
        const double just_over = std::nextafter(max_distance_sq, std::numeric_limits<double>::infinity());
        for (const std::uint32_t q : moving_) {
            // the nearest (the first of equals) within the bound; a triangle whose ball is not
            // nearer than the best so far is skipped
            double best = just_over;
            std::uint32_t at = kNone;
            for (std::size_t i = 0; i < new_corners_.size(); ++i) {
                const auto& ball = new_ball_[i];
                const double off = std::sqrt(mesh_ops::dot(mesh_ops::sub(input[q], {ball[0], ball[1], ball[2]}),
                                                           mesh_ops::sub(input[q], {ball[0], ball[1], ball[2]}))) - ball[3];
                if (off > 0 && off * off >= best) continue;
                const auto& x = new_corners_[i];
                const double d = mesh_ops::point_triangle_sq(input[q], x[0], x[1], x[2]);
                if (d < best) {
                    best = d;
                    at = static_cast<std::uint32_t>(i);
                }
            }
            if (at == kNone) return false;
            moving_to_.push_back(at);
        }
        // output to input: samples of the new triangles against the local input triangles
        if (++input_tri_stamp == 0) {
            std::fill(input_tri_mark.begin(), input_tri_mark.end(), 0U);
            input_tri_stamp = 1;
        }
        near_input_.clear();
        for (const std::uint32_t q : moving_) add_star(q);
        add_star_of_cluster(a);
        add_star_of_cluster(b);
        for (const Tri& t : new_tris_)
            for (const std::uint32_t v : t)
                if (v != a) add_star_of_cluster(v);
        // the scan starts where the last sample found its triangle: neighbouring samples tend to
        // share one (the answer does not depend on the order)
        std::size_t hint = 0;
        const auto near = [&](const V3& x) {
            const std::size_t n = near_input_.size();
            for (std::size_t k = 0; k < n; ++k) {
                const std::size_t j = hint + k < n ? hint + k : hint + k - n;
                const auto& ball = input_ball[near_input_[j]];
                const double dx = x[0] - ball[0], dy = x[1] - ball[1], dz = x[2] - ball[2];
                if (dx * dx + dy * dy + dz * dz > ball[3]) continue;
                const Tri& t = input_tri[near_input_[j]];
                if (mesh_ops::point_triangle_sq(x, input[t[0]], input[t[1]], input[t[2]]) <= max_distance_sq) {
                    hint = j;
                    return true;
                }
            }
            return false;
        };
        if (!near(c)) return false;
        for (const auto& t : new_corners_) {
            const V3 &x = t[0], &y = t[1], &z = t[2];
            if (!near({(x[0] + y[0] + z[0]) / 3, (x[1] + y[1] + z[1]) / 3, (x[2] + y[2] + z[2]) / 3})) return false;
            // the midpoints of its edges at the new vertex (the third edge is an old one)
            for (const V3& w : t) {
                if (w == c) continue;
                if (!near({(w[0] + c[0]) / 2, (w[1] + c[1]) / 2, (w[2] + c[2]) / 2})) return false;
            }
        }
        return true;
    }

    std::vector<std::uint32_t> na_, nb_, common_, shared_, changed_;
    std::vector<Tri> new_tris_;

    /// Link condition and boundary rules for collapsing b into a.
    bool topology_ok(std::uint32_t a, std::uint32_t b)
    {
        if (m.locked[a] || m.locked[b]) return false;
        shared_.clear();
        for (const std::uint32_t t : m.vtris[a]) {
            const Tri& c = m.tri[t];
            if (c[0] == b || c[1] == b || c[2] == b) shared_.push_back(t);
        }
        if (shared_.empty() || shared_.size() > 2) return false;
        std::uint32_t opp[2] = {0, 0};
        for (std::size_t i = 0; i < shared_.size(); ++i)
            for (const std::uint32_t w : m.tri[shared_[i]])
                if (w != a && w != b) opp[i] = w;
        neighbours(a, na_);
        neighbours(b, nb_);
        common_.clear();
        std::set_intersection(na_.begin(), na_.end(), nb_.begin(), nb_.end(), std::back_inserter(common_));
        if (shared_.size() == 2) {
            if (m.boundary[a] && m.boundary[b]) return false;
            if (common_.size() != 2) return false;
            if (has_triangle(a, opp[0], opp[1]) && has_triangle(b, opp[0], opp[1])) return false;
            return true;
        }
        // boundary edge
        if (common_.size() != 1) return false;
        const std::uint32_t c = opp[0];
        if (edge_triangles(a, c) == 1 && edge_triangles(b, c) == 1) return false; // a loop of three
        return true;
    }

    /// Tries the collapse: b merges into a, a moves to p. False (and nothing changed) if refused.
    bool try_collapse(std::uint32_t a, std::uint32_t b, const Pos& p)
    {
        if (!topology_ok(a, b)) {
            ++stats.refused_topology;
            return false;
        }
        changed_.clear();
        new_tris_.clear();
        for (const std::uint32_t v : {a, b}) {
            for (const std::uint32_t t : m.vtris[v]) {
                if (std::find(shared_.begin(), shared_.end(), t) != shared_.end()) continue;
                if (v == a && std::find(changed_.begin(), changed_.end(), t) != changed_.end()) continue;
                Tri c = m.tri[t];
                for (auto& w : c)
                    if (w == b) w = a;
                changed_.push_back(t);
                new_tris_.push_back(c);
            }
        }
        // the distance bound first: a few point-triangle distances, cheaper than the exact checks
        if (!within_bound(a, b, p)) {
            ++stats.refused_distance;
            return false;
        }
        const Refusal r = m.check(changed_, new_tris_, a, p, shared_);
        if (r == Refusal::flip) ++stats.refused_flip;
        if (r == Refusal::intersection) ++stats.refused_intersection;
        if (r != Refusal::none) return false;
        // apply
        for (const std::uint32_t t : shared_) {
            m.grid.remove(t);
            m.alive[t] = 0;
            --m.alive_count;
            for (const std::uint32_t w : m.tri[t]) {
                auto& list = m.vtris[w];
                list.erase(std::find(list.begin(), list.end(), t));
            }
        }
        for (std::size_t i = 0; i < changed_.size(); ++i) m.grid.remove(changed_[i]);
        for (const std::uint32_t t : m.vtris[b]) m.vtris[a].push_back(t);
        m.vtris[b].clear();
        m.vtris[b].shrink_to_fit();
        m.pos[a] = p;
        for (std::size_t i = 0; i < changed_.size(); ++i) {
            m.tri[changed_[i]] = new_tris_[i];
            m.grid.insert(changed_[i], m.corners(changed_[i]));
        }
        quadric[a] += quadric[b];
        if (!cluster_next.empty()) {
            cluster_next[cluster_tail[a]] = b;
            cluster_tail[a] = cluster_tail[b];
            for (const std::uint32_t t : shared_) assigned_first[t] = kNone;
            for (const std::uint32_t t : changed_) assigned_first[t] = kNone;
            for (std::size_t i = 0; i < moving_.size(); ++i) {
                const std::uint32_t t = changed_[moving_to_[i]];
                assigned_next[moving_[i]] = assigned_first[t];
                assigned_first[t] = moving_[i];
            }
        }
        ++version[a];
        ++version[b];
        ++stats.collapses;
        return true;
    }
};

} // namespace

Mesh simplify(const Mesh& mesh, const SimplifyOptions& options, SimplifyStats* stats_out)
{
    if (!(options.ratio > 0 && options.ratio <= 1)) {
        throw Error(Status::invalid_argument, "simplify: ratio must be in (0, 1], got " + std::to_string(options.ratio));
    }
    if (options.target_triangles < 0) throw Error(Status::invalid_argument, "simplify: target triangles must be >= 0");
    if (std::isnan(options.max_error) || options.max_error < 0) {
        throw Error(Status::invalid_argument, "simplify: max error must be >= 0");
    }
    if (std::isnan(options.max_distance) || options.max_distance < 0) {
        throw Error(Status::invalid_argument, "simplify: max distance must be >= 0");
    }
    Simplifier s(mesh, options.max_distance);
    const std::int64_t start = s.m.alive_count;
    // no count target (ratio 1): the error bound alone stops it; with neither, nothing is done
    std::int64_t target = options.target_triangles > 0 ? options.target_triangles
                          : options.ratio < 1          ? static_cast<std::int64_t>(std::ceil(options.ratio * static_cast<double>(start)))
                          : std::isinf(options.max_error) ? start
                                                          : 0;
    const double max_cost = std::isinf(options.max_error) ? options.max_error : options.max_error * options.max_error;
    std::int64_t since_progress = 0;
    // When the queue runs dry, every edge is tried again: refusals are local, and the
    // neighbourhood of a refused edge may have changed since (at most a few rounds).
    for (int round = 0; round < 4 && s.m.alive_count > target; ++round) {
        const std::int64_t before = s.stats.collapses;
        s.seed();
        while (!s.heap.empty() && s.m.alive_count > target) {
            const Candidate c = s.heap.top();
            s.heap.pop();
            if (c.va != s.version[c.a] || c.vb != s.version[c.b]) continue; // stale
            if (s.m.vtris[c.a].empty() || s.m.vtris[c.b].empty()) continue;
            if (c.cost > max_cost) {
                target = s.m.alive_count; // the error bound stops it
                break;
            }
            // keep the boundary vertex when one is on the boundary (the candidate's position is its)
            std::uint32_t keep = c.a, gone = c.b;
            if (s.m.boundary[c.b] && !s.m.boundary[c.a]) std::swap(keep, gone);
            if (s.try_collapse(keep, gone, c.p)) {
                s.stats.max_quadric_error = std::max(s.stats.max_quadric_error, std::sqrt(c.cost));
                s.push_edges_of(keep);
                s.m.maybe_rebuild_grid();
            }
            if (options.progress && ++since_progress >= 4096) {
                since_progress = 0;
                const double f = static_cast<double>(start - s.m.alive_count) / static_cast<double>(std::max<std::int64_t>(1, start - target));
                if (!options.progress(std::min(1.0, f))) throw Error(Status::cancelled, "simplify: cancelled");
            }
        }
        s.heap = {};
        if (s.stats.collapses == before) break;
    }
    if (stats_out) *stats_out = s.stats;
    return s.m.to_mesh(mesh.has_normals());
}

} // namespace cmc33
