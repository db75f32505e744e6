// simplify(), smooth() and filter_components(): on meshes extracted from random fields and shared
// volumes, and on hand-built meshes where a naive collapse would pinch a tunnel or make two
// sheets cross, the result keeps the topology (mesh_topology), stays a manifold and stays
// embedded (mesh_geometry: no improper meeting, exactly).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include "cmc33/extract.hpp"
#include "cmc33/io.hpp"
#include "cmc33/mesh_ops.hpp"
#include "cmc33/topology.hpp"
#include "cmc33/verify.hpp"
#include "test_support.hpp"

namespace {

using namespace cmc33;

void expect_same_topology(const MeshTopology& a, const MeshTopology& b, const std::string& what)
{
    EXPECT_EQ(a.euler, b.euler) << what;
    EXPECT_EQ(a.components, b.components) << what;
    EXPECT_EQ(a.closed_components, b.closed_components) << what;
    EXPECT_EQ(a.b1, b.b1) << what;
    EXPECT_EQ(a.boundary_loops, b.boundary_loops) << what;
    EXPECT_EQ(b.nonmanifold_edges, 0) << what;
    EXPECT_EQ(b.nonmanifold_vertices, 0) << what;
    EXPECT_EQ(b.degenerate_triangles, 0) << what;
    EXPECT_EQ(a.oriented, b.oriented) << what;
}

/// Simplifies to 10 % and 2 %, smooths each 20 iterations: every result keeps the topology and
/// is embedded. Returns the 2 % mesh.
Mesh check_all(const Mesh& mesh, const std::string& what)
{
    const MeshTopology before = mesh_topology(mesh);
    EXPECT_EQ(before.nonmanifold_edges, 0) << what;
    EXPECT_TRUE(mesh_geometry(mesh).embedded()) << what;
    Mesh last;
    for (const double ratio : {0.1, 0.02}) {
        SimplifyOptions o;
        o.ratio = ratio;
        SimplifyStats st;
        const Mesh s = simplify(mesh, o, &st);
        const std::string w = what + " at " + std::to_string(ratio);
        expect_same_topology(before, mesh_topology(s), w);
        const MeshGeometry g = mesh_geometry(s);
        EXPECT_TRUE(g.embedded()) << w << ": " << g.intersecting_pairs << " intersecting pairs, "
                                  << g.coincident_vertices << " coincident, " << g.zero_area_triangles << " zero-area";
        EXPECT_LE(s.triangle_count(), mesh.triangle_count());
        SmoothOptions so;
        so.iterations = 20;
        const Mesh sm = smooth(s, so);
        expect_same_topology(before, mesh_topology(sm), w + " smoothed");
        const MeshGeometry gs = mesh_geometry(sm);
        EXPECT_TRUE(gs.embedded()) << w << " smoothed: " << gs.intersecting_pairs << " intersecting pairs";
        EXPECT_EQ(sm.triangle_count(), s.triangle_count());
        last = s;
    }
    return last;
}

TEST(Simplify, RandomFields)
{
    for (const FieldKind kind : {FieldKind::grid, FieldKind::closed, FieldKind::ties}) {
        for (std::int64_t n = 1; n <= 2; ++n) {
            const Volume v = random_field(kind, n, 40, 10);
            const Mesh m = extract(v, 0.0);
            if (m.triangle_count() == 0) continue;
            check_all(m, std::string(field_kind_name(kind)) + " " + std::to_string(n));
        }
    }
}

TEST(Simplify, SharedVolumes)
{
    struct Case {
        const char* file;
        double iso;
    };
    for (const Case c : {Case{"Bucky_32x32x32_uint8.nrrd", 100.5}, Case{"nucleon_41x41x41_uint8.nrrd", 100.5},
                         Case{"silicium_98x34x34_uint8.nrrd", 100.5}, Case{"HeadMRVolume_48x62x42_uint8.nrrd", 40.5}}) {
        const auto path = test::shared_volume(c.file);
        if (!path) GTEST_SKIP() << c.file << " not found";
        const Mesh m = extract(io::read_volume(*path), c.iso);
        check_all(m, c.file);
    }
}

TEST(Simplify, Deterministic)
{
    const Mesh m = extract(random_field(FieldKind::closed, 2, 7, 10), 0.0);
    SimplifyOptions o;
    o.ratio = 0.1;
    const Mesh a = simplify(m, o);
    const Mesh b = simplify(m, o);
    EXPECT_EQ(a.positions, b.positions);
    EXPECT_EQ(a.triangles, b.triangles);
}

/// A torus with a thin tube of `around` segments: collapsing along the tube pinches it unless the
/// link condition refuses.
Mesh torus(int along, int around, double big, double small)
{
    Mesh m;
    for (int i = 0; i < along; ++i)
        for (int j = 0; j < around; ++j) {
            const double u = 2 * std::numbers::pi * i / along, v = 2 * std::numbers::pi * j / around;
            m.positions.push_back(static_cast<float>((big + small * std::cos(v)) * std::cos(u)));
            m.positions.push_back(static_cast<float>((big + small * std::cos(v)) * std::sin(u)));
            m.positions.push_back(static_cast<float>(small * std::sin(v)));
        }
    auto id = [&](int i, int j) { return static_cast<std::uint32_t>(((i + along) % along) * around + (j + around) % around); };
    for (int i = 0; i < along; ++i)
        for (int j = 0; j < around; ++j) {
            for (const std::uint32_t x : {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j), id(i + 1, j + 1), id(i, j + 1)}) {
                m.triangles.push_back(x);
            }
        }
    return m;
}

TEST(Simplify, ThinTorusKeepsItsTunnel)
{
    const Mesh m = torus(200, 6, 10, 0.05);
    const MeshTopology before = mesh_topology(m);
    ASSERT_EQ(before.euler, 0);
    ASSERT_TRUE(mesh_geometry(m).embedded());
    SimplifyOptions o;
    o.target_triangles = 1; // as far as it goes
    SimplifyStats st;
    const Mesh s = simplify(m, o, &st);
    expect_same_topology(before, mesh_topology(s), "torus");
    EXPECT_TRUE(mesh_geometry(s).embedded());
    EXPECT_GT(st.refused_topology, 0); // the pinches a naive collapse would have made
    EXPECT_LT(s.triangle_count(), m.triangle_count() / 4);
}

/// Two wavy sheets, one a small offset of the other: a chord across a valley of the lower sheet
/// passes through the upper one, so collapses there must be refused.
Mesh close_sheets(int n, double gap)
{
    Mesh m;
    for (int s = 0; s < 2; ++s)
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                const double x = 6.0 * i / (n - 1), y = 6.0 * j / (n - 1);
                m.positions.push_back(static_cast<float>(x));
                m.positions.push_back(static_cast<float>(y));
                m.positions.push_back(static_cast<float>(std::sin(x * 2) * std::sin(y * 2) + s * gap));
            }
    for (int s = 0; s < 2; ++s)
        for (int i = 0; i + 1 < n; ++i)
            for (int j = 0; j + 1 < n; ++j) {
                auto id = [&](int a, int b) { return static_cast<std::uint32_t>(s * n * n + a * n + b); };
                for (const std::uint32_t x : {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j), id(i + 1, j + 1), id(i, j + 1)}) {
                    m.triangles.push_back(x);
                }
            }
    return m;
}

TEST(Simplify, CloseSheetsDoNotCross)
{
    const Mesh m = close_sheets(60, 0.02);
    const MeshTopology before = mesh_topology(m);
    ASSERT_EQ(before.components, 2);
    ASSERT_TRUE(mesh_geometry(m).embedded());
    SimplifyOptions o;
    o.ratio = 0.02;
    SimplifyStats st;
    const Mesh s = simplify(m, o, &st);
    expect_same_topology(before, mesh_topology(s), "sheets");
    const MeshGeometry g = mesh_geometry(s);
    EXPECT_TRUE(g.embedded()) << g.intersecting_pairs;
    EXPECT_GT(st.refused_intersection, 0); // crossings a naive collapse would have made
    SmoothOptions so;
    so.iterations = 20;
    SmoothStats sst;
    const Mesh sm = smooth(s, so, &sst);
    EXPECT_TRUE(mesh_geometry(sm).embedded());
    expect_same_topology(before, mesh_topology(sm), "sheets smoothed");
}

TEST(Simplify, MaxErrorStops)
{
    // a sphere of radius 8 (in cells): smooth, so small errors allow many collapses
    const Volume v = test::make_volume({24, 24, 24}, [](std::int64_t i, std::int64_t j, std::int64_t k) {
        return std::sqrt(static_cast<double>((i - 12) * (i - 12) + (j - 12) * (j - 12) + (k - 12) * (k - 12)));
    });
    const Mesh m = extract(v, 8.0);
    SimplifyOptions o;
    o.max_error = 0.5;
    SimplifyStats st;
    const Mesh s = simplify(m, o, &st);
    EXPECT_LE(st.max_quadric_error, 0.5);
    EXPECT_LT(s.triangle_count(), m.triangle_count() / 2);
    const HausdorffResult h = hausdorff_distance(m, s);
    EXPECT_LT(h.distance(), 0.5); // each new vertex is within the bound of the planes it merged
    expect_same_topology(mesh_topology(m), mesh_topology(s), "sphere");
}

/// The longest edge of the mesh's triangles.
double longest_edge(const Mesh& m)
{
    double longest = 0;
    for (std::size_t t = 0; t < m.triangle_count(); ++t)
        for (std::size_t i = 0; i < 3; ++i) {
            const std::uint32_t u = m.triangles[3 * t + i], w = m.triangles[3 * t + (i + 1) % 3];
            longest = std::max(longest, std::hypot(static_cast<double>(m.positions[3 * u] - m.positions[3 * w]),
                                                   static_cast<double>(m.positions[3 * u + 1] - m.positions[3 * w + 1]),
                                                   static_cast<double>(m.positions[3 * u + 2] - m.positions[3 * w + 2])));
        }
    return longest;
}

/// The largest distance from a used vertex of `from` to the surface `to`: each vertex becomes a
/// triangle of zero size, whose only Hausdorff sample is the vertex itself.
double vertices_to_surface(const Mesh& from, const Mesh& to)
{
    Mesh points;
    points.positions = from.positions;
    std::vector<std::uint8_t> used(from.vertex_count(), 0);
    for (const std::uint32_t v : from.triangles) used[v] = 1;
    for (std::uint32_t v = 0; v < from.vertex_count(); ++v)
        if (used[v]) points.triangles.insert(points.triangles.end(), {v, v, v});
    return hausdorff_distance(points, to).a_to_b;
}

TEST(Simplify, MaxDistanceKeepsTheSurfaceNear)
{
    // thin, curved sheets (a gyroid-like field): collapses by quadric error alone move some vertices
    // far from the input where the surface bends; the bound refuses them and the error stays small
    const Volume v = test::make_volume({28, 28, 28}, [](std::int64_t i, std::int64_t j, std::int64_t k) {
        const double x = 0.45 * static_cast<double>(i), y = 0.45 * static_cast<double>(j), z = 0.45 * static_cast<double>(k);
        return std::sin(x) * std::cos(y) + std::sin(y) * std::cos(z) + std::sin(z) * std::cos(x);
    });
    const Mesh m = extract(v, 0.3);
    SimplifyOptions o;
    o.ratio = 0.1;
    SimplifyStats free_stats, bound_stats;
    const Mesh free = simplify(m, o, &free_stats);
    o.max_distance = 0.15;
    const Mesh bound = simplify(m, o, &bound_stats);
    EXPECT_EQ(free_stats.refused_distance, 0);
    EXPECT_GT(bound_stats.refused_distance, 0);
    const HausdorffResult hf = hausdorff_distance(m, free), hb = hausdorff_distance(m, bound);
    EXPECT_GT(hf.distance(), 2 * o.max_distance) << "the field no longer tests the bound";
    // guaranteed: every input vertex within the bound of the output (rounding aside); a check of
    // only the input vertices merged into the collapsing edge lets some escape here (0.154)
    EXPECT_LE(vertices_to_surface(m, bound), o.max_distance + 1e-6);
    // The other samples follow from what is checked, the distance to a surface growing at most as
    // fast as the point moves: a point of an input triangle is within L / sqrt(3) of one of its
    // corners (L its longest edge; the equilateral triangle is the worst case); a point of an
    // output triangle within L / (2 sqrt(3)) of its corners, edge midpoints or centroid, each of
    // which was checked within the bound of the input when last moved (or is the input's own).
    EXPECT_LE(hb.a_to_b, o.max_distance + longest_edge(m) / std::sqrt(3.0) + 1e-6);
    EXPECT_LE(hb.b_to_a, o.max_distance + longest_edge(bound) / (2 * std::sqrt(3.0)) + 1e-6);
    expect_same_topology(mesh_topology(m), mesh_topology(bound), "gyroid, bounded");
    EXPECT_TRUE(mesh_geometry(bound).embedded());
    o.max_distance = -1;
    EXPECT_THROW(simplify(m, o), Error);
}

TEST(Simplify, NormalsRecomputed)
{
    ExtractOptions eo;
    eo.normals = true;
    const Mesh m = extract(random_field(FieldKind::closed, 1, 5, 12), 0.0, eo);
    ASSERT_TRUE(m.has_normals());
    SimplifyOptions o;
    o.ratio = 0.2;
    const Mesh s = simplify(m, o);
    ASSERT_EQ(s.normals.size(), s.positions.size());
    for (std::size_t v = 0; v < s.vertex_count(); ++v) {
        const double l = std::hypot(static_cast<double>(s.normals[3 * v]), static_cast<double>(s.normals[3 * v + 1]),
                                    static_cast<double>(s.normals[3 * v + 2]));
        EXPECT_NEAR(l, 1.0, 1e-5);
    }
}

TEST(Simplify, BadInput)
{
    Mesh m;
    m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    m.triangles = {0, 1, 5};
    EXPECT_THROW(simplify(m), Error);
    m.triangles = {0, 1, 2};
    m.positions[0] = std::nanf("");
    EXPECT_THROW(simplify(m), Error);
    SimplifyOptions o;
    o.ratio = 0;
    EXPECT_THROW(simplify(Mesh{}, o), Error);
    EXPECT_EQ(simplify(Mesh{}).triangle_count(), 0U);
}

TEST(Components, LargestAndMinSize)
{
    const Mesh m = close_sheets(10, 0.5); // two sheets of 162 triangles each
    Mesh a = m;
    // a third, small piece: one triangle
    const std::uint32_t base = static_cast<std::uint32_t>(a.vertex_count());
    a.positions.insert(a.positions.end(), {20, 0, 0, 21, 0, 0, 20, 1, 0});
    a.triangles.insert(a.triangles.end(), {base, base + 1, base + 2});
    std::int64_t dropped = 0;
    const Mesh l = filter_components(a, {true, 0}, &dropped);
    EXPECT_EQ(l.triangle_count(), 162U);
    EXPECT_EQ(dropped, 2);
    EXPECT_EQ(mesh_topology(l).components, 1);
    const Mesh k = filter_components(a, {false, 2}, &dropped);
    EXPECT_EQ(k.triangle_count(), 324U);
    EXPECT_EQ(dropped, 1);
    EXPECT_EQ(k.vertex_count(), m.vertex_count());
}

TEST(Hausdorff, KnownDistance)
{
    // a square and the same square lifted by 0.25
    Mesh a;
    a.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    a.triangles = {0, 1, 2, 0, 2, 3};
    Mesh b = a;
    for (std::size_t i = 2; i < b.positions.size(); i += 3) b.positions[i] = 0.25F;
    const HausdorffResult h = hausdorff_distance(a, b);
    EXPECT_DOUBLE_EQ(h.a_to_b, 0.25);
    EXPECT_DOUBLE_EQ(h.b_to_a, 0.25);
    EXPECT_NEAR(hausdorff_distance(a, a).distance(), 0.0, 1e-12);
}

} // namespace
