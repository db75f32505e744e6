// mesh_geometry() against CGAL (test-only dependency): the meshes cmc33::extract makes from random
// 5^3 grids and tie grids with every method, and the same meshes broken on purpose.
//
// Three CGAL references, all with CGAL::Exact_predicates_exact_constructions_kernel (exact
// predicates and exact constructions; float coordinates convert to it exactly):
//
//  A. soup: every pair of non-degenerate triangles (CGAL::collinear) of the welded mesh whose
//     boxes meet. With no shared corner: CGAL::do_intersect of the closed triangles. With shared
//     corners: the pair meets improperly iff CGAL::intersection(Triangle_3, Triangle_3), computed
//     exactly, is not exactly the shared corner (one) or the shared edge (two); the construction
//     is skipped when a plane settles it (one shared corner: the other triangle's two other
//     corners strictly on one side of the first's plane; a shared edge: not coplanar). The same
//     triangle twice always meets improperly. This is our definition evaluated by CGAL's code,
//     organised differently from both ours and B; it takes any input (duplicates, non-manifold,
//     inconsistent orientation).
//
//  B. CGAL::Polygon_mesh_processing::self_intersections() on a CGAL::Surface_mesh built from the
//     mesh welded by exact position. How it works (CGAL 5.5.1,
//     CGAL/Polygon_mesh_processing/self_intersections.h, self_intersections_impl and
//     do_faces_intersect):
//       - a face whose three points are collinear (CGAL::collinear, exact) is reported as the
//         pair (f, f) and gets no box, so it is never tested against other faces (the header's
//         own "tiny fixme"); we do the same: zero-area triangles are counted, not paired;
//       - faces adjacent through a halfedge (sharing an edge) intersect iff the four points are
//         coplanar and the two third corners lie on the same side of the edge
//         (coplanar_orientation == POSITIVE): our shared-edge rule;
//       - faces sharing a vertex (descriptor, not position) intersect iff the edge of either
//         opposite the shared vertex meets the other triangle (do_intersect(Triangle_3,
//         Segment_3)). That is equivalent to ours: two triangles sharing corner v meet beyond v
//         iff they share a segment from v, whose far end, where it leaves the first of the two
//         triangles, lies on that triangle's edge opposite v;
//       - other pairs whose boxes meet: do_intersect(Triangle_3, Triangle_3) of the closed
//         triangles (touching at a point counts), as ours.
//     Adjacency there comes from the halfedge graph, so B applies only where the welded mesh is
//     a valid Surface_mesh. A face that repeats a (welded) vertex is left out and counted as
//     zero-area (CGAL's collinear(p, p, q) would call it degenerate too); add_face() refuses a
//     face reusing a halfedge (an edge with the same direction in two faces: inconsistent
//     orientation, duplicates, non-manifold edges) and some non-manifold vertices. Such meshes are skipped by B and counted (the 5.5.1
//     header has no triangle-soup variant of self_intersections); A covers them.
//
//  C. The same function on the mesh as given (not welded), where CGAL sees coincident vertices
//     as distinct: it then reports something iff the mesh is not embedded in our sense (two
//     vertices at one position are either in one triangle, which is then degenerate, or in two
//     triangles that touch there without sharing a CGAL vertex, which CGAL reports).
//
// A and B compare the exact set of improperly meeting pairs and the number of zero-area
// triangles; C compares embedded(). Every comparison must agree on every mesh.

#include <gtest/gtest.h>

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/intersections.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <iterator>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "cmc33/extract.hpp"
#include "cmc33/topology.hpp"
#include "cmc33/verify.hpp"

namespace {

using K = CGAL::Exact_predicates_exact_constructions_kernel;
using Point = K::Point_3;
using Segment = K::Segment_3;
using Triangle = K::Triangle_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
using Pairs = std::vector<std::array<std::int64_t, 2>>;
using cmc33::Mesh;

struct Reference {
    std::int64_t zero_area = 0;
    Pairs pairs; ///< sorted, smaller triangle first
};

struct Welded {
    std::vector<std::array<float, 3>> points;
    std::vector<std::uint32_t> id; ///< per vertex of the mesh
};

Welded weld(const Mesh& m)
{
    Welded w;
    std::map<std::array<float, 3>, std::uint32_t> ids;
    w.id.resize(m.vertex_count());
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
        // + 0.0f: -0 becomes +0
        const std::array<float, 3> p{m.positions[3 * v] + 0.0f, m.positions[3 * v + 1] + 0.0f,
                                     m.positions[3 * v + 2] + 0.0f};
        const auto [it, inserted] = ids.emplace(p, static_cast<std::uint32_t>(w.points.size()));
        if (inserted) w.points.push_back(p);
        w.id[v] = it->second;
    }
    return w;
}

Point to_point(const std::array<float, 3>& p) { return Point(p[0], p[1], p[2]); }

std::array<std::uint32_t, 3> corners(const Mesh& m, const std::vector<std::uint32_t>& id, std::size_t t)
{
    return {id[m.triangles[3 * t]], id[m.triangles[3 * t + 1]], id[m.triangles[3 * t + 2]]};
}

/// Sharing corners, triangles s and t meet only there when a plane separates them: for one
/// shared corner, t's other corners strictly on one side of s's plane (or the other way round);
/// for a shared edge, non-coplanar triangles (two planes meet in the edge's line only). Saves
/// the exact construction on most adjacent pairs.
bool proper_by_a_plane(const std::array<std::uint32_t, 3>& s, const std::array<std::uint32_t, 3>& t,
                       const std::vector<Point>& pts, std::size_t shared)
{
    auto others = [](const std::array<std::uint32_t, 3>& x, const std::array<std::uint32_t, 3>& y) {
        std::vector<std::uint32_t> out;
        for (std::uint32_t v : x)
            if (std::find(y.begin(), y.end(), v) == y.end()) out.push_back(v);
        return out;
    };
    const auto os = others(s, t), ot = others(t, s);
    if (shared == 2) return !CGAL::coplanar(pts[s[0]], pts[s[1]], pts[s[2]], pts[ot[0]]);
    auto one_side = [&](const std::array<std::uint32_t, 3>& x, const std::vector<std::uint32_t>& y) {
        const auto a = CGAL::orientation(pts[x[0]], pts[x[1]], pts[x[2]], pts[y[0]]);
        return a != CGAL::COPLANAR && a == CGAL::orientation(pts[x[0]], pts[x[1]], pts[x[2]], pts[y[1]]);
    };
    return one_side(s, ot) || one_side(t, os);
}

/// Reference A (see the top of the file).
Reference soup_reference(const Mesh& m)
{
    const Welded w = weld(m);
    std::vector<Point> pts;
    for (const auto& p : w.points) pts.push_back(to_point(p));
    const std::size_t n = m.triangle_count();
    std::vector<std::array<std::uint32_t, 3>> tri(n);
    std::vector<bool> proper(n);
    std::vector<std::array<float, 6>> box(n);
    Reference r;
    for (std::size_t t = 0; t < n; ++t) {
        tri[t] = corners(m, w.id, t);
        const auto& c = tri[t];
        proper[t] = c[0] != c[1] && c[1] != c[2] && c[0] != c[2] && !CGAL::collinear(pts[c[0]], pts[c[1]], pts[c[2]]);
        r.zero_area += !proper[t];
        for (std::size_t k = 0; k < 3; ++k) {
            box[t][k] = std::min({w.points[c[0]][k], w.points[c[1]][k], w.points[c[2]][k]});
            box[t][k + 3] = std::max({w.points[c[0]][k], w.points[c[1]][k], w.points[c[2]][k]});
        }
    }
    for (std::size_t s = 0; s < n; ++s) {
        if (!proper[s]) continue;
        const Triangle ts(pts[tri[s][0]], pts[tri[s][1]], pts[tri[s][2]]);
        for (std::size_t t = s + 1; t < n; ++t) {
            if (!proper[t]) continue;
            bool apart = false;
            for (std::size_t k = 0; k < 3; ++k) apart = apart || box[s][k + 3] < box[t][k] || box[t][k + 3] < box[s][k];
            if (apart) continue;
            std::vector<std::uint32_t> shared;
            for (std::uint32_t x : tri[s])
                if (std::find(tri[t].begin(), tri[t].end(), x) != tri[t].end()) shared.push_back(x);
            const Triangle tt(pts[tri[t][0]], pts[tri[t][1]], pts[tri[t][2]]);
            bool improper = shared.size() == 3;
            if (shared.empty()) {
                improper = CGAL::do_intersect(ts, tt);
            } else if (!improper && !proper_by_a_plane(tri[s], tri[t], pts, shared.size())) {
                const auto meet = CGAL::intersection(ts, tt);
                if (meet) {
                    improper = true;
                    if (const Point* p = boost::get<Point>(&*meet)) {
                        for (std::uint32_t x : shared) improper = improper && *p != pts[x];
                    } else if (const Segment* g = boost::get<Segment>(&*meet)) {
                        if (shared.size() == 2) {
                            const Segment e(pts[shared[0]], pts[shared[1]]);
                            improper = !(*g == e || *g == e.opposite());
                        }
                    }
                }
            }
            if (improper) r.pairs.push_back({static_cast<std::int64_t>(s), static_cast<std::int64_t>(t)});
        }
    }
    return r;
}

/// References B (welded) and C (as given); nullopt when the mesh is not a valid Surface_mesh.
std::optional<Reference> pmp_reference(const Mesh& m, bool welded)
{
    std::vector<std::uint32_t> id(m.vertex_count());
    std::vector<std::array<float, 3>> points;
    if (welded) {
        Welded w = weld(m);
        id = std::move(w.id);
        points = std::move(w.points);
    } else {
        for (std::size_t v = 0; v < m.vertex_count(); ++v) {
            id[v] = static_cast<std::uint32_t>(v);
            points.push_back({m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]});
        }
    }
    SurfaceMesh sm;
    std::vector<SurfaceMesh::Vertex_index> vertex;
    for (const auto& p : points) vertex.push_back(sm.add_vertex(to_point(p)));
    Reference r;
    std::vector<std::int64_t> triangle_of_face;
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
        const auto c = corners(m, id, t);
        if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2]) {
            ++r.zero_area; // not representable; CGAL's collinear() would say degenerate
            continue;
        }
        const auto f = sm.add_face(vertex[c[0]], vertex[c[1]], vertex[c[2]]);
        if (f == SurfaceMesh::null_face()) return std::nullopt;
        if (triangle_of_face.size() <= static_cast<std::size_t>(f.idx())) triangle_of_face.resize(f.idx() + 1, -1);
        triangle_of_face[f.idx()] = static_cast<std::int64_t>(t);
    }
    std::vector<std::pair<SurfaceMesh::Face_index, SurfaceMesh::Face_index>> found;
    CGAL::Polygon_mesh_processing::self_intersections(sm, std::back_inserter(found));
    for (const auto& [f, g] : found) {
        const std::int64_t a = triangle_of_face[f.idx()], b = triangle_of_face[g.idx()];
        if (a == b)
            ++r.zero_area;
        else
            r.pairs.push_back({std::min(a, b), std::max(a, b)});
    }
    std::sort(r.pairs.begin(), r.pairs.end());
    return r;
}

cmc33::MeshGeometry ours(const Mesh& m)
{
    cmc33::MeshGeometryOptions o;
    o.threads = 1;
    o.examples = 1u << 20;
    return cmc33::mesh_geometry(m, o);
}

// ------------------------------------------------------------------------------------------------
// Breaking meshes on purpose

std::array<float, 3> vertex_at(const Mesh& m, std::size_t v)
{
    return {m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]};
}

std::vector<std::uint32_t> neighbours(const Mesh& m, std::uint32_t v)
{
    std::vector<std::uint32_t> out;
    for (std::size_t t = 0; t < m.triangle_count(); ++t)
        for (std::size_t i = 0; i < 3; ++i)
            if (m.triangles[3 * t + i] == v)
                for (std::size_t j = 1; j < 3; ++j) out.push_back(m.triangles[3 * t + (i + j) % 3]);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

std::uint32_t random_used_vertex(const Mesh& m, std::mt19937& rng)
{
    return m.triangles[std::uniform_int_distribution<std::size_t>(0, m.triangles.size() - 1)(rng)];
}

/// (a) a vertex moved past one of its neighbours: v' = w + s (w - v), s in [0.3, 1.5].
Mesh moved_across(Mesh m, std::mt19937& rng)
{
    const std::uint32_t v = random_used_vertex(m, rng);
    const auto nb = neighbours(m, v);
    const std::uint32_t w = nb[std::uniform_int_distribution<std::size_t>(0, nb.size() - 1)(rng)];
    const float s = std::uniform_real_distribution<float>(0.3f, 1.5f)(rng);
    for (std::size_t k = 0; k < 3; ++k) {
        const float from = m.positions[3 * v + k], past = m.positions[3 * w + k];
        m.positions[3 * v + k] = past + s * (past - from);
    }
    return m;
}

/// (b) a triangle repeated with the opposite orientation. Returns the triangle.
std::size_t add_reversed_duplicate(Mesh& m, std::mt19937& rng)
{
    const std::size_t t = std::uniform_int_distribution<std::size_t>(0, m.triangle_count() - 1)(rng);
    m.triangles.insert(m.triangles.end(), {m.triangles[3 * t], m.triangles[3 * t + 2], m.triangles[3 * t + 1]});
    return t;
}

/// (c) a vertex moved onto another one (a neighbour or any vertex, alternately).
Mesh made_coincident(Mesh m, std::mt19937& rng, bool neighbour)
{
    const std::uint32_t v = random_used_vertex(m, rng);
    std::uint32_t w = v;
    if (neighbour) {
        const auto nb = neighbours(m, v);
        w = nb[std::uniform_int_distribution<std::size_t>(0, nb.size() - 1)(rng)];
    } else {
        while (w == v) w = random_used_vertex(m, rng);
    }
    for (std::size_t k = 0; k < 3; ++k) m.positions[3 * v + k] = m.positions[3 * w + k];
    return m;
}

/// (e) every coordinate rounded to a multiple of 1/steps: coincident vertices, zero-area
/// triangles, coplanar overlaps and touching at points and edges, all exact.
Mesh snapped(Mesh m, float steps)
{
    for (float& x : m.positions) x = std::round(x * steps) / steps;
    return m;
}

double area(const Mesh& m, std::size_t t)
{
    const auto a = vertex_at(m, m.triangles[3 * t]), b = vertex_at(m, m.triangles[3 * t + 1]),
               c = vertex_at(m, m.triangles[3 * t + 2]);
    double u[3], w[3];
    for (std::size_t k = 0; k < 3; ++k) {
        u[k] = static_cast<double>(b[k]) - static_cast<double>(a[k]);
        w[k] = static_cast<double>(c[k]) - static_cast<double>(a[k]);
    }
    const double x = u[1] * w[2] - u[2] * w[1], y = u[2] * w[0] - u[0] * w[2], z = u[0] * w[1] - u[1] * w[0];
    return 0.5 * std::sqrt(x * x + y * y + z * z);
}

/// (d) a shrunken copy of the smallest proper triangle, translated so that its most transverse
/// edge passes through the centroid of the largest triangle. Returns the large triangle, or -1
/// when no edge is transverse enough.
std::int64_t add_piercing_copy(Mesh& m)
{
    std::size_t small = 0, large = 0;
    double small_area = 1e300, large_area = 0;
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
        const double a = area(m, t);
        if (a > 1e-6 && a < small_area) small_area = a, small = t;
        if (a > large_area) large_area = a, large = t;
    }
    std::array<std::array<double, 3>, 3> s{}, l{};
    for (std::size_t i = 0; i < 3; ++i)
        for (std::size_t k = 0; k < 3; ++k) {
            s[i][k] = static_cast<double>(m.positions[3 * m.triangles[3 * small + i] + k]);
            l[i][k] = static_cast<double>(m.positions[3 * m.triangles[3 * large + i] + k]);
        }
    std::array<double, 3> c{}, e1{}, e2{}, n{};
    for (std::size_t k = 0; k < 3; ++k) {
        c[k] = (l[0][k] + l[1][k] + l[2][k]) / 3;
        e1[k] = l[1][k] - l[0][k];
        e2[k] = l[2][k] - l[0][k];
    }
    n = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const double nn = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    // inradius of the large triangle = 2 area / perimeter
    double perimeter = 0;
    for (std::size_t i = 0; i < 3; ++i) {
        const auto& p = l[i];
        const auto& q = l[(i + 1) % 3];
        perimeter += std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
    }
    const double inradius = 2 * large_area / perimeter;
    std::size_t best = 0;
    double best_cos = 0, diameter = 0;
    for (std::size_t i = 0; i < 3; ++i) {
        const auto& p = s[i];
        const auto& q = s[(i + 1) % 3];
        const double d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
        const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        diameter = std::max(diameter, len);
        const double cosine = std::fabs(d[0] * n[0] + d[1] * n[1] + d[2] * n[2]) / (len * nn);
        if (cosine > best_cos) best_cos = cosine, best = i;
    }
    if (best_cos < 0.2) return -1;
    const double shrink = std::min(1.0, 0.3 * inradius / diameter);
    std::array<double, 3> mid{};
    for (std::size_t k = 0; k < 3; ++k) mid[k] = (s[best][k] + s[(best + 1) % 3][k]) / 2;
    const auto base = static_cast<std::uint32_t>(m.vertex_count());
    for (std::size_t i = 0; i < 3; ++i)
        for (std::size_t k = 0; k < 3; ++k)
            m.positions.push_back(static_cast<float>(c[k] + shrink * (s[i][k] - mid[k])));
    m.triangles.insert(m.triangles.end(), {base, base + 1, base + 2});
    return static_cast<std::int64_t>(large);
}

bool has_pair(const Pairs& pairs, std::int64_t a, std::int64_t b)
{
    return std::binary_search(pairs.begin(), pairs.end(), std::array<std::int64_t, 2>{std::min(a, b), std::max(a, b)});
}

// ------------------------------------------------------------------------------------------------

struct Tally {
    int meshes = 0, soup_compared = 0, soup_agreed = 0;
    int welded_compared = 0, welded_agreed = 0, welded_skipped = 0, welded_with_pairs = 0;
    int raw_compared = 0, raw_agreed = 0, raw_skipped = 0;
    int not_embedded = 0;
    std::int64_t pairs = 0, zero_area = 0;
};

/// Compares a mesh with references A, B and C; returns whether CGAL found a problem in it
/// (A's pairs or zero-area triangles, or C's report).
bool compare(const Mesh& m, const std::string& what, Tally& tally)
{
    SCOPED_TRACE(what);
    const cmc33::MeshGeometry g = ours(m);
    ++tally.meshes;
    tally.not_embedded += !g.embedded();
    tally.pairs += g.intersecting_pairs;
    tally.zero_area += g.zero_area_triangles;
    EXPECT_EQ(g.intersecting_pairs, static_cast<std::int64_t>(g.intersection_examples.size()));

    const Reference a = soup_reference(m);
    ++tally.soup_compared;
    EXPECT_EQ(g.intersection_examples, a.pairs);
    EXPECT_EQ(g.zero_area_triangles, a.zero_area);
    tally.soup_agreed += g.intersection_examples == a.pairs && g.zero_area_triangles == a.zero_area;
    bool cgal_found = !a.pairs.empty() || a.zero_area > 0;

    if (const auto b = pmp_reference(m, true)) {
        ++tally.welded_compared;
        tally.welded_with_pairs += !b->pairs.empty();
        EXPECT_EQ(g.intersection_examples, b->pairs);
        EXPECT_EQ(g.zero_area_triangles, b->zero_area);
        tally.welded_agreed += g.intersection_examples == b->pairs && g.zero_area_triangles == b->zero_area;
    } else {
        ++tally.welded_skipped;
    }
    if (const auto c = pmp_reference(m, false)) {
        ++tally.raw_compared;
        const bool reported = !c->pairs.empty() || c->zero_area > 0;
        EXPECT_EQ(reported, !g.embedded());
        tally.raw_agreed += reported == !g.embedded();
        cgal_found = cgal_found || reported;
    } else {
        ++tally.raw_skipped;
    }
    return cgal_found;
}

TEST(GeometryCgal, ExtractedAndBrokenMeshesAgree)
{
    constexpr int kSeeds = 30;
    const std::array methods{cmc33::Method::cmc33, cmc33::Method::mc33_lewiner, cmc33::Method::mc};
    Tally extracted, broken;
    std::array<int, 5> made{}, detected_ours{}, detected_cgal{};
    std::mt19937 rng(5);
    for (const auto kind : {cmc33::FieldKind::grid, cmc33::FieldKind::ties}) {
        for (int n = 1; n <= kSeeds; ++n) {
            const cmc33::Volume field = cmc33::random_field(kind, n, 2024);
            for (const auto method : methods) {
                const Mesh m = cmc33::extract(field, 0.0, cmc33::ExtractOptions{method, false, 1});
                const std::string name = std::string(cmc33::field_kind_name(kind)) + "-" + std::to_string(n) + " " +
                                         std::string(cmc33::method_name(method));
                compare(m, name, extracted);
                if (m.triangle_count() < 8) continue;
                {
                    const Mesh e = snapped(m, n % 2 == 0 ? 4.0f : 16.0f);
                    ++made[4];
                    detected_cgal[4] += compare(e, name + " snapped", broken);
                    detected_ours[4] += !ours(e).embedded();
                }
                if (method != cmc33::Method::cmc33) continue;
                // the broken variants, of the cmc33 meshes
                {
                    const Mesh a = moved_across(m, rng);
                    ++made[0];
                    detected_cgal[0] += compare(a, name + " moved", broken);
                    detected_ours[0] += !ours(a).embedded();
                }
                {
                    Mesh b = m;
                    const auto t = static_cast<std::int64_t>(add_reversed_duplicate(b, rng));
                    ++made[1];
                    detected_cgal[1] += compare(b, name + " duplicate", broken);
                    const auto g = ours(b);
                    const auto copy = static_cast<std::int64_t>(b.triangle_count() - 1);
                    detected_ours[1] += has_pair(g.intersection_examples, t, copy);
                }
                {
                    const Mesh c = made_coincident(m, rng, n % 2 == 0);
                    ++made[2];
                    detected_cgal[2] += compare(c, name + " coincident", broken);
                    detected_ours[2] += ours(c).coincident_vertices >= 2;
                }
                {
                    Mesh d = m;
                    const std::int64_t large = add_piercing_copy(d);
                    if (large >= 0) {
                        ++made[3];
                        detected_cgal[3] += compare(d, name + " pierced", broken);
                        const auto g = ours(d);
                        const auto copy = static_cast<std::int64_t>(d.triangle_count() - 1);
                        detected_ours[3] += has_pair(g.intersection_examples, large, copy);
                    }
                }
            }
        }
    }
    for (const auto* t : {&extracted, &broken}) {
        std::cout << (t == &extracted ? "extracted" : "broken") << ": meshes " << t->meshes << ", not embedded "
                  << t->not_embedded << ", intersecting pairs " << t->pairs << ", zero-area " << t->zero_area
                  << "; CGAL soup (A) agreed " << t->soup_agreed << "/" << t->soup_compared
                  << "; self_intersections welded (B) agreed " << t->welded_agreed << "/" << t->welded_compared
                  << " (skipped " << t->welded_skipped << ", with pairs " << t->welded_with_pairs << ")"
                  << "; self_intersections as given (C) agreed " << t->raw_agreed << "/" << t->raw_compared
                  << " (skipped " << t->raw_skipped << ")\n";
    }
    const char* names[5] = {"moved", "duplicate", "coincident", "pierced", "snapped"};
    for (int i = 0; i < 5; ++i)
        std::cout << names[i] << ": made " << made[i] << ", found by mesh_geometry " << detected_ours[i] << ", by CGAL "
                  << detected_cgal[i] << "\n";

    // enough meshes went through self_intersections itself, including non-embedded ones
    EXPECT_GE(extracted.welded_compared + broken.welded_compared, 200);
    EXPECT_GE(broken.raw_compared, 50);
    EXPECT_GE(broken.welded_with_pairs, 50);
    // the broken ones are caught by both (moving a vertex need not make triangles cross)
    for (int i : {1, 2, 3}) {
        EXPECT_EQ(detected_ours[i], made[i]) << names[i];
        EXPECT_EQ(detected_cgal[i], made[i]) << names[i];
    }
    EXPECT_GE(made[3], kSeeds);
    EXPECT_GE(detected_ours[0], made[0] / 3);
    EXPECT_EQ(detected_cgal[0], detected_ours[0]);
    EXPECT_GE(detected_ours[4], made[4] / 2); // rounding makes most meshes degenerate somewhere
    EXPECT_EQ(detected_cgal[4], detected_ours[4]);
}

TEST(GeometryCgal, HandBuiltCasesAgree)
{
    // the typical cases of test_mesh_geometry.cpp, against references A and B
    using P = std::array<float, 3>;
    auto pair = [](const std::array<P, 3>& t, const std::array<P, 3>& u) {
        Mesh m;
        for (const auto* tri : {&t, &u})
            for (const P& p : *tri) {
                m.triangles.push_back(static_cast<std::uint32_t>(m.vertex_count()));
                m.positions.insert(m.positions.end(), p.begin(), p.end());
            }
        return m;
    };
    const std::array<P, 3> t1{{{0, 0, 0}, {2, 0, 0}, {0, 2, 0}}};
    const float tiny = std::nextafter(0.0f, 1.0f);
    const std::vector<std::array<P, 3>> others{
        {{{0.5f, 0.5f, -1}, {0.5f, 0.5f, 1}, {3, 3, 0}}},  {{{0.5f, 0.5f, 0}, {1, 0.5f, 1}, {0.5f, 1, 1}}},
        {{{0.5f, 0.5f, tiny}, {1, 0.5f, 1}, {0.5f, 1, 1}}}, {{{1, 0, 0}, {1, -1, 1}, {1, 1, 1}}},
        {{{1, -1, -1}, {1, 1, 1}, {1, -2, 2}}},             {{{0.5f, 0.5f, 0}, {3, 0.5f, 0}, {0.5f, 3, 0}}},
        {{{2, 2, 0}, {3, 2, 0}, {2, 3, 0}}},                {{{0, 0, 0}, {3, 1, 0}, {1, 3, 0}}},
        {{{0, 0, 0}, {-2, 0, 0}, {0, -2, 0}}},              {{{0, 0, 0}, {1, 0, 0}, {0, -1, 1}}},
        {{{0, 0, 0}, {1, 0, 0}, {1, -1, 0}}},               {{{0, 0, 0}, {-1, 0, 0}, {0, -1, 1}}},
        {{{0, 0, 0}, {0.5f, 0.5f, 1}, {0.5f, 0.5f, -1}}},   {{{0, 0, 0}, {0.5f, 0.5f, 1}, {1, 0.25f, 1}}},
        {{{0, 0, 0}, {1, 2, -1}, {2, 1, 1}}},               {{{2, 0, 0}, {0, 0, 0}, {1, -1, 0}}},
        {{{2, 0, 0}, {0, 0, 0}, {1, 1, 0}}},                {{{2, 0, 0}, {0, 0, 0}, {1, 1, tiny}}},
    };
    Tally tally;
    int meeting = 0;
    for (std::size_t i = 0; i < others.size(); ++i) {
        const Mesh m = pair(t1, others[i]);
        compare(m, "case " + std::to_string(i), tally);
        meeting += ours(m).intersecting_pairs > 0;
    }
    EXPECT_EQ(tally.welded_compared, static_cast<int>(others.size()));
    EXPECT_EQ(meeting, 11);
}

} // namespace
