// mesh_geometry() on hand-built meshes whose answers are known by construction, the exact
// predicates of src/topology/exact_geometry.hpp against GMP rationals on near-degenerate input,
// and the bucketed pair search against a brute-force search over all pairs.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include <gmpxx.h>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/topology.hpp"
#include "cmc33/verify.hpp"
#include "exact_geometry.hpp"

namespace {

using cmc33::Mesh;
using cmc33::mesh_geometry;
using cmc33::MeshGeometry;
using cmc33::MeshGeometryOptions;
using cmc33::detail::Point3;
using P = std::array<float, 3>;
using Pairs = std::vector<std::array<std::int64_t, 2>>;

Mesh make_mesh(const std::vector<P>& points, const std::vector<std::uint32_t>& triangles)
{
    Mesh m;
    for (const P& p : points) m.positions.insert(m.positions.end(), p.begin(), p.end());
    m.triangles.assign(triangles.begin(), triangles.end());
    return m;
}

/// Two (or more) triangles given by their corners, no vertex shared by index.
Mesh soup(const std::vector<std::array<P, 3>>& triangles)
{
    Mesh m;
    for (const auto& t : triangles)
        for (const P& p : t) {
            m.triangles.push_back(static_cast<std::uint32_t>(m.vertex_count()));
            m.positions.insert(m.positions.end(), p.begin(), p.end());
        }
    return m;
}

MeshGeometry geometry(const Mesh& m, int threads = 1)
{
    MeshGeometryOptions o;
    o.threads = threads;
    o.examples = 1u << 20; // all of them
    return mesh_geometry(m, o);
}

float up(float x) { return std::nextafter(x, std::numeric_limits<float>::infinity()); }
float down(float x) { return std::nextafter(x, -std::numeric_limits<float>::infinity()); }

// t1 is the reference triangle of most tests: the right triangle of legs 2 in the plane z = 0.
const std::array<P, 3> kT1{{{0, 0, 0}, {2, 0, 0}, {0, 2, 0}}};

/// t1 and u as a soup: the single pair (0, 1) is reported iff `meets`.
void expect_pair(const std::array<P, 3>& u, bool meets, const char* what)
{
    SCOPED_TRACE(what);
    const MeshGeometry g = geometry(soup({kT1, u}));
    EXPECT_EQ(g.intersecting_pairs, meets ? 1 : 0);
    EXPECT_EQ(g.intersection_examples, (meets ? Pairs{{0, 1}} : Pairs{}));
    EXPECT_EQ(g.zero_area_triangles, 0);
    // the order of the triangles does not matter
    const MeshGeometry swapped = geometry(soup({u, kT1}));
    EXPECT_EQ(swapped.intersecting_pairs, g.intersecting_pairs);
}

// ------------------------------------------------------------------------------------------------
// Disjoint corners

TEST(MeshGeometry, CrossingTriangles)
{
    // in the plane x = y, through (0.5, 0.5, 0) inside t1
    expect_pair({{{0.5f, 0.5f, -1}, {0.5f, 0.5f, 1}, {3, 3, 0}}}, true, "crossing");
    expect_pair({{{0.5f, 0.5f, 1}, {0.5f, 0.5f, 3}, {3, 3, 2}}}, false, "lifted above");
    // crossing t1's edge y = 0 only outside it (x = 3)
    expect_pair({{{3, 0, -1}, {3, 0, 1}, {4, 1, 0}}}, false, "beside");
    const MeshGeometry g = geometry(soup({kT1, {{{0.5f, 0.5f, -1}, {0.5f, 0.5f, 1}, {3, 3, 0}}}}));
    EXPECT_FALSE(g.embedded());
    EXPECT_EQ(g.coincident_vertices, 0);
    EXPECT_EQ(g.positions, 6);
}

TEST(MeshGeometry, TouchingAtAVertexInTheInterior)
{
    expect_pair({{{0.5f, 0.5f, 0}, {1, 0.5f, 1}, {0.5f, 1, 1}}}, true, "vertex on t1");
    // one float ulp above the plane (the smallest denormal): no contact
    expect_pair({{{0.5f, 0.5f, up(0.0f)}, {1, 0.5f, 1}, {0.5f, 1, 1}}}, false, "one ulp above");
    // one ulp below, the other corners above: the triangle crosses t1
    expect_pair({{{0.5f, 0.5f, down(0.0f)}, {1, 0.5f, 1}, {0.5f, 1, 1}}}, true, "one ulp below");
}

TEST(MeshGeometry, TouchingAtAVertexOnAnEdge)
{
    expect_pair({{{1, 0, 0}, {1, -1, 1}, {1, 1, 1}}}, true, "vertex on the edge y = 0");
    expect_pair({{{1, down(0.0f), 0}, {1, -1, 1}, {1, 1, 1}}}, false, "one ulp outside the edge");
    // on the hypotenuse x + y = 2, at (1, 1) exactly and one ulp beyond
    expect_pair({{{1, 1, 0}, {2, 2, 1}, {1, 2, 1}}}, true, "vertex on the hypotenuse");
    expect_pair({{{1, up(1.0f), 0}, {2, 2, 1}, {1, 2, 1}}}, false, "one ulp beyond the hypotenuse");
    // a vertex one ulp beyond t1's corner (2, 0, 0) (at the corner itself it would weld with it)
    expect_pair({{{up(2.0f), 0, 0}, {3, -1, 1}, {3, 1, 1}}}, false, "one ulp beyond a corner");
}

TEST(MeshGeometry, EdgeTouchingEdgeAtOnePoint)
{
    // u lies in the plane x = 1; its edge from (1, -1, -1) to (1, 1, 1) crosses t1's edge y = 0
    // at (1, 0, 0); the rest of u meets z = 0 only at y < 0
    expect_pair({{{1, -1, -1}, {1, 1, 1}, {1, -2, 2}}}, true, "edge on edge");
    expect_pair({{{1, -1.25f, -1}, {1, 0.75f, 1}, {1, -2.25f, 2}}}, false, "shifted off the edge");
    // u in the plane x = y meets z = 0 along its edge from (1, 1, 0) to (3, 3, 0), which touches
    // t1's hypotenuse at its endpoint (1, 1, 0) only
    expect_pair({{{1, 1, 0}, {3, 3, 0}, {2, 2, 1}}}, true, "edge on the line x = y, touching the hypotenuse");
    expect_pair({{{1, up(1.0f), 0}, {3, 3, 0}, {2, 2, 1}}}, false, "the same, one ulp beyond");
}

TEST(MeshGeometry, CoplanarDisjointCorners)
{
    expect_pair({{{0.5f, 0.5f, 0}, {3, 0.5f, 0}, {0.5f, 3, 0}}}, true, "coplanar overlap");
    expect_pair({{{0.25f, 0.25f, 0}, {1, 0.25f, 0}, {0.25f, 1, 0}}}, true, "coplanar, inside");
    expect_pair({{{-1, -1, 0}, {5, -1, 0}, {-1, 5, 0}}}, true, "coplanar, containing");
    expect_pair({{{2, 2, 0}, {3, 2, 0}, {2, 3, 0}}}, false, "coplanar, apart");
    // the hypotenuse x + y = 2 against a parallel edge one ulp away
    expect_pair({{{up(2.0f), 0, 0}, {up(2.0f), 2, 0}, {0, up(2.0f), 0}}}, false, "coplanar, one ulp apart");
    expect_pair({{{2, 0.5f, 0}, {2, 2, 0}, {0.5f, 2, 0}}}, false, "coplanar, corner region beyond");
    expect_pair({{{1.5f, 0.5f, 0}, {2, 2, 0}, {0.5f, 1.5f, 0}}}, true, "coplanar, edge on hypotenuse");
}

// ------------------------------------------------------------------------------------------------
// A shared edge

TEST(MeshGeometry, SharedEdgeFlatQuadIsEmbedded)
{
    const Mesh quad = make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}, {0, 1, 3, 0, 3, 2});
    const MeshGeometry g = geometry(quad);
    EXPECT_TRUE(g.embedded());
    EXPECT_EQ(g.intersecting_pairs, 0);
    EXPECT_EQ(g.welded.faces, 2);
    EXPECT_EQ(g.welded.boundary_edges, 4);
}

TEST(MeshGeometry, SharedEdgeFoldOverIsReported)
{
    // (0, 1, 2) and (1, 0, 3): consistently oriented, but 3 = (1, 1, 0) lies on the same side of
    // the shared edge as 2 = (0, 1, 0): the second triangle folds over onto the first.
    const Mesh fold = make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}, {0, 1, 2, 1, 0, 3});
    const MeshGeometry g = geometry(fold);
    EXPECT_EQ(g.intersecting_pairs, 1);
    EXPECT_EQ(g.intersection_examples, (Pairs{{0, 1}}));
    EXPECT_FALSE(g.embedded());
    EXPECT_TRUE(g.welded.oriented); // the topology alone cannot see it

    // lifted by one ulp out of the plane: a (very flat) hinge, which is fine
    const Mesh hinge = make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, up(0.0f)}}, {0, 1, 2, 1, 0, 3});
    EXPECT_TRUE(geometry(hinge).embedded());
    // an ordinary hinge
    const Mesh open = make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.5f, -1, 1}}, {0, 1, 2, 1, 0, 3});
    EXPECT_TRUE(geometry(open).embedded());
}

TEST(MeshGeometry, SharedEdgeThroughWeldedPositions)
{
    // the fold of the previous test with no index shared: welding makes the edge shared
    const Mesh fold = soup({{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}}, {{{1, 0, 0}, {0, 0, 0}, {1, 1, 0}}}});
    const MeshGeometry g = geometry(fold);
    EXPECT_EQ(g.intersecting_pairs, 1);
    EXPECT_EQ(g.coincident_vertices, 4);
    EXPECT_EQ(g.positions, 4);
    const Mesh quad = soup({{{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}}}, {{{0, 0, 0}, {1, 1, 0}, {0, 1, 0}}}});
    const MeshGeometry q = geometry(quad);
    EXPECT_EQ(q.intersecting_pairs, 0);
    EXPECT_EQ(q.coincident_vertices, 4);
    EXPECT_FALSE(q.embedded());
    EXPECT_EQ(q.welded.edges, 5);
    EXPECT_EQ(q.welded.components, 1);
}

// ------------------------------------------------------------------------------------------------
// One shared corner

TEST(MeshGeometry, SharedCornerCoplanar)
{
    // the shared corner is the origin, welded from two vertices of the soup
    expect_pair({{{0, 0, 0}, {3, 1, 0}, {1, 3, 0}}}, true, "overlapping angles");
    expect_pair({{{0, 0, 0}, {0.5f, 0.25f, 0}, {0.25f, 0.5f, 0}}}, true, "inside the angle, small");
    expect_pair({{{0, 0, 0}, {-2, 0, 0}, {0, -2, 0}}}, false, "opposite quadrant (edges on opposite rays)");
    expect_pair({{{0, 0, 0}, {0, -2, 0}, {2, -1, 0}}}, false, "adjacent quadrant, touching only at the corner");
    // u's angle covers t1's: the edges at the corner run inside the other triangle
    expect_pair({{{0, 0, 0}, {3, -1, 0}, {-1, 3, 0}}}, true, "containing angle");
}

TEST(MeshGeometry, SharedCornerEdgeAlongEdge)
{
    // u's edge from the corner runs along t1's edge y = 0: they share the segment [0, 1] x {0}
    expect_pair({{{0, 0, 0}, {1, 0, 0}, {0, -1, 1}}}, true, "non-coplanar, edge along edge (shorter)");
    expect_pair({{{0, 0, 0}, {3, 0, 0}, {0, -1, 1}}}, true, "non-coplanar, edge along edge (longer)");
    expect_pair({{{0, 0, 0}, {1, 0, 0}, {1, -1, 0}}}, true, "coplanar, other side, edge along edge");
    // the same direction but pointing away (x < 0): only the corner
    expect_pair({{{0, 0, 0}, {-1, 0, 0}, {0, -1, 1}}}, false, "edge along the opposite ray");
    // one ulp off the line of t1's edge: only the corner
    expect_pair({{{0, 0, 0}, {1, down(0.0f), 0}, {1, -1, 0}}}, false, "coplanar, one ulp off the edge");
}

TEST(MeshGeometry, SharedCornerNonCoplanar)
{
    // the edge opposite the corner pierces t1 at (0.5, 0.5, 0)
    expect_pair({{{0, 0, 0}, {0.5f, 0.5f, 1}, {0.5f, 0.5f, -1}}}, true, "opposite edge pierces");
    expect_pair({{{0, 0, 0}, {0.5f, 0.5f, 1}, {1, 0.25f, 1}}}, false, "above, touching at the corner");
    // an edge at the corner runs inside t1 (to (0.5, 0.5, 0)) before leaving the plane
    expect_pair({{{0, 0, 0}, {0.5f, 0.5f, 0}, {0, 0, 1}}}, true, "edge at the corner inside t1");
    // u meets z = 0 in a segment from the corner along (1, 1, 0) to (1.5, 1.5, 0): it cuts t1
    // from the corner and leaves through the hypotenuse; its opposite edge misses t1
    expect_pair({{{0, 0, 0}, {1, 2, -1}, {2, 1, 1}}}, true, "cut from the corner through the hypotenuse");
    expect_pair({{{0, 0, 0}, {-1, -1, 1}, {-1, -1, -1}}}, false, "in a plane through the corner, outside");
}

// ------------------------------------------------------------------------------------------------
// Duplicates and coincident vertices

TEST(MeshGeometry, DuplicatedTriangle)
{
    const std::vector<P> pts{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    for (const auto& tris : {std::vector<std::uint32_t>{0, 1, 2, 0, 1, 2}, std::vector<std::uint32_t>{0, 1, 2, 0, 2, 1},
                             std::vector<std::uint32_t>{0, 1, 2, 1, 2, 0}}) {
        const MeshGeometry g = geometry(make_mesh(pts, tris));
        EXPECT_EQ(g.intersecting_pairs, 1);
        EXPECT_EQ(g.intersection_examples, (Pairs{{0, 1}}));
        EXPECT_EQ(g.coincident_vertices, 0);
    }
    // the same positions under other indices
    const Mesh copy = soup({{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}}, {{{0, 1, 0}, {1, 0, 0}, {0, 0, 0}}}});
    const MeshGeometry g = geometry(copy);
    EXPECT_EQ(g.intersecting_pairs, 1);
    EXPECT_EQ(g.coincident_vertices, 6);
    EXPECT_EQ(g.positions, 3);
    EXPECT_EQ(g.welded.vertices, 3);
    EXPECT_EQ(g.welded.edges, 3);
    EXPECT_EQ(g.welded.faces, 2);
    EXPECT_TRUE(g.welded.closed); // the welded pair is a (degenerate) closed surface
}

TEST(MeshGeometry, DuplicatedTriangleInAClosedSurface)
{
    // cube corners v = x | y << 1 | z << 2, two triangles per face, outward
    std::vector<P> pts;
    for (int v = 0; v < 8; ++v) pts.push_back({float(v & 1), float(v >> 1 & 1), float(v >> 2 & 1)});
    std::vector<std::uint32_t> tris{0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
                                    2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
    const MeshGeometry cube = geometry(make_mesh(pts, tris));
    EXPECT_TRUE(cube.embedded());
    EXPECT_EQ(cube.welded.euler, 2);
    EXPECT_TRUE(cube.welded.closed);
    EXPECT_TRUE(cube.welded.oriented);
    tris.insert(tris.end(), {3, 2, 0}); // triangle 0 again, reversed
    const MeshGeometry g = geometry(make_mesh(pts, tris));
    EXPECT_EQ(g.intersecting_pairs, 1);
    EXPECT_EQ(g.intersection_examples, (Pairs{{0, 12}}));
}

TEST(MeshGeometry, CoincidentVerticesAndWelding)
{
    // two triangles of separate components touching at the origin
    const Mesh m = soup({{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}}, {{{0, 0, 0}, {-1, 0, 0}, {0, -1, 0}}}});
    const MeshGeometry g = geometry(m);
    EXPECT_EQ(g.coincident_vertices, 2);
    EXPECT_EQ(g.positions, 5);
    EXPECT_EQ(g.intersecting_pairs, 0); // after welding they share the corner, and only it
    EXPECT_EQ(g.zero_area_triangles, 0);
    EXPECT_FALSE(g.embedded());
    EXPECT_EQ(cmc33::mesh_topology(m).components, 2);
    EXPECT_EQ(g.welded.components, 1);
    EXPECT_EQ(g.welded.vertices, 5);
    EXPECT_EQ(g.welded.nonmanifold_vertices, 1); // two fans at the origin

    // groups of 3 and 2, plus an unused vertex at a used position (not counted)
    Mesh n = soup({{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}},
                   {{{0, 0, 0}, {-1, 0, 0}, {0, -1, 0}}},
                   {{{0, 0, 0}, {1, 0, 0}, {0, 0, 1}}},
                   {{{5, 5, 5}, {6, 5, 5}, {5, 6, 5}}}});
    n.positions.insert(n.positions.end(), {0, 0, 0, 5, 5, 5});
    const MeshGeometry h = geometry(n);
    EXPECT_EQ(h.coincident_vertices, 5); // origin 3 times, (1, 0, 0) twice
    EXPECT_EQ(h.positions, 9);
    EXPECT_EQ(h.intersecting_pairs, 0);
    EXPECT_EQ(h.welded.components, 2);
}

TEST(MeshGeometry, NegativeZeroWeldsWithPositiveZero)
{
    const float nz = -0.0f;
    ASSERT_TRUE(std::signbit(nz));
    // a flat quad whose diagonal corner (0, 0, 0) is written once as +0 and once as -0
    const Mesh m = make_mesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {nz, nz, nz}, {0, 1, nz}},
                             {0, 1, 2, 3, 2, 4});
    const MeshGeometry g = geometry(m);
    EXPECT_EQ(g.coincident_vertices, 2);
    EXPECT_EQ(g.positions, 4);
    EXPECT_EQ(g.intersecting_pairs, 0);
    EXPECT_EQ(g.zero_area_triangles, 0);
    EXPECT_EQ(g.welded.vertices, 4);
    EXPECT_EQ(g.welded.edges, 5);
    EXPECT_EQ(g.welded.boundary_edges, 4);
    EXPECT_EQ(g.welded.components, 1);
    EXPECT_EQ(g.welded.euler, 1);
    // the fold over that edge is found through the -0 corner too
    const Mesh fold = make_mesh({{0, 0, 0}, {1, 1, 0}, {0, 1, 0}, {nz, 0, nz}, {1, 1, nz}, {0, 0.5f, 0}},
                                {0, 1, 2, 4, 3, 5});
    EXPECT_EQ(geometry(fold).intersecting_pairs, 1);
}

// ------------------------------------------------------------------------------------------------
// Zero-area triangles

TEST(MeshGeometry, CollinearTriangles)
{
    const MeshGeometry diag = geometry(soup({{{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}}}}));
    EXPECT_EQ(diag.zero_area_triangles, 1);
    EXPECT_FALSE(diag.embedded());
    const MeshGeometry off = geometry(soup({{{{0, 0, 0}, {1, 1, 1}, {2, 2, up(2.0f)}}}}));
    EXPECT_EQ(off.zero_area_triangles, 0);
    EXPECT_TRUE(off.embedded());

    // large coordinates: a + k (1, 2, 3) with a = 2^20 (ulp 1/8 there), exact; then one ulp off
    const float a = 1048576.0f;
    const MeshGeometry big = geometry(soup({{{{a, a, a}, {a + 1, a + 2, a + 3}, {a + 2, a + 4, a + 6}}}}));
    EXPECT_EQ(big.zero_area_triangles, 1);
    const MeshGeometry big_off = geometry(soup({{{{a, a, a}, {a + 1, a + 2, a + 3}, {a + 2, a + 4, up(a + 6)}}}}));
    EXPECT_EQ(big_off.zero_area_triangles, 0);
    // collinear with a middle corner of very different exponent: (t, 2t, 3t), t = 2^-100, 1, 2^60
    const float t0 = std::ldexp(1.0f, -100), t2 = std::ldexp(1.0f, 60);
    EXPECT_EQ(geometry(soup({{{{t0, 2 * t0, 3 * t0}, {1, 2, 3}, {t2, 2 * t2, 3 * t2}}}})).zero_area_triangles, 1);
    EXPECT_EQ(geometry(soup({{{{t0, 2 * t0, up(3 * t0)}, {1, 2, 3}, {t2, 2 * t2, 3 * t2}}}})).zero_area_triangles, 0);

    // a repeated index, and two corners that weld
    EXPECT_EQ(geometry(make_mesh({{0, 0, 0}, {1, 0, 0}}, {0, 1, 1})).zero_area_triangles, 1);
    EXPECT_EQ(geometry(soup({{{{0, 0, 0}, {1, 0, 0}, {0, 0, 0}}}})).zero_area_triangles, 1);
    EXPECT_EQ(geometry(soup({{{{-0.0f, 0, 0}, {1, 0, 0}, {0, 0, -0.0f}}}})).zero_area_triangles, 1);
}

TEST(MeshGeometry, ZeroAreaTrianglesAreNotPairedWithOthers)
{
    // a segment-like triangle piercing t1: counted as zero-area, not as an intersecting pair
    // (the same choice as CGAL's self_intersections, which has no box for a degenerate face)
    const MeshGeometry g = geometry(soup({kT1, {{{0.5f, 0.5f, -1}, {0.5f, 0.5f, 0}, {0.5f, 0.5f, 1}}}}));
    EXPECT_EQ(g.zero_area_triangles, 1);
    EXPECT_EQ(g.intersecting_pairs, 0);
    EXPECT_FALSE(g.embedded());
}

// ------------------------------------------------------------------------------------------------
// Closed surfaces

Mesh octahedron()
{
    // corners +x -x +y -y +z -z; faces outward (counter-clockwise seen from outside)
    return make_mesh({{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}},
                     {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5});
}

TEST(MeshGeometry, ClosedOctahedron)
{
    const MeshGeometry g = geometry(octahedron());
    EXPECT_TRUE(g.embedded());
    EXPECT_EQ(g.positions, 6);
    EXPECT_EQ(g.welded.euler, 2);
    EXPECT_TRUE(g.welded.closed);
    EXPECT_TRUE(g.welded.oriented);
    EXPECT_EQ(g.welded.components, 1);

    // a small triangle through face 0 (+x +y +z, centroid (1/3, 1/3, 1/3)) only
    Mesh pierced = octahedron();
    const float c = 1.0f / 3;
    for (float v : {c - 0.05f, c - 0.05f, c - 0.05f, c + 0.05f, c + 0.05f, c + 0.05f, c + 0.05f, c - 0.05f, c + 0.04f})
        pierced.positions.push_back(v);
    pierced.triangles.insert(pierced.triangles.end(), {6, 7, 8});
    const MeshGeometry p = geometry(pierced);
    EXPECT_EQ(p.intersecting_pairs, 1);
    EXPECT_EQ(p.intersection_examples, (Pairs{{0, 8}}));

    // the apex +z pushed through the bottom to (1.5, 0, -2): the bottom apex (0, 0, -1) is then
    // outside the pyramid of the top faces, which cross the bottom ones (straight down to
    // (0, 0, -2) the top pyramid would hold the bottom one and meet it only at the equator)
    Mesh bent = octahedron();
    bent.positions[3 * 4 + 0] = 1.5f;
    bent.positions[3 * 4 + 2] = -2;
    const MeshGeometry b = geometry(bent);
    EXPECT_GT(b.intersecting_pairs, 0);
    EXPECT_EQ(b.welded.euler, 2); // same topology
}

// ------------------------------------------------------------------------------------------------
// The pair search against all pairs

/// Every pair, each tested by the exact test of exact_geometry.hpp after an independent weld.
Pairs brute_force_pairs(const Mesh& m)
{
    std::map<std::array<float, 3>, std::uint32_t> ids;
    std::vector<Point3> points;
    std::vector<std::uint32_t> welded(m.vertex_count());
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
        const std::array<float, 3> p{m.positions[3 * v] + 0.0f, m.positions[3 * v + 1] + 0.0f,
                                     m.positions[3 * v + 2] + 0.0f};
        const auto [it, inserted] = ids.emplace(p, static_cast<std::uint32_t>(points.size()));
        if (inserted) points.push_back({double(p[0]), double(p[1]), double(p[2])});
        welded[v] = it->second;
    }
    const std::size_t n = m.triangle_count();
    std::vector<std::array<std::uint32_t, 3>> tri(n);
    std::vector<bool> ok(n);
    for (std::size_t t = 0; t < n; ++t) {
        for (std::size_t i = 0; i < 3; ++i) tri[t][i] = welded[m.triangles[3 * t + i]];
        const auto& c = tri[t];
        ok[t] = c[0] != c[1] && c[1] != c[2] && c[0] != c[2] &&
                !cmc33::detail::collinear(points[c[0]], points[c[1]], points[c[2]]);
    }
    Pairs out;
    for (std::size_t s = 0; s < n; ++s) {
        if (!ok[s]) continue;
        for (std::size_t t = s + 1; t < n; ++t) {
            if (!ok[t]) continue;
            // shared corners first, in the same order
            std::array<std::uint32_t, 3> a{}, b{};
            std::size_t shared = 0, na = 0, nb = 0;
            std::array<std::uint32_t, 3> rest_a{}, rest_b{};
            for (std::uint32_t x : tri[s]) {
                if (std::find(tri[t].begin(), tri[t].end(), x) != tri[t].end())
                    a[shared++] = x;
                else
                    rest_a[na++] = x;
            }
            for (std::uint32_t x : tri[t])
                if (std::find(tri[s].begin(), tri[s].end(), x) == tri[s].end()) rest_b[nb++] = x;
            b = a;
            for (std::size_t i = 0; i < na; ++i) a[shared + i] = rest_a[i];
            for (std::size_t i = 0; i < nb; ++i) b[shared + i] = rest_b[i];
            bool meets = shared == 3;
            if (!meets) {
                const std::array<Point3, 3> pa{points[a[0]], points[a[1]], points[a[2]]};
                const std::array<Point3, 3> pb{points[b[0]], points[b[1]], points[b[2]]};
                meets = cmc33::detail::triangles_meet_improperly(pa, pb, static_cast<int>(shared));
            }
            if (meets) out.push_back({static_cast<std::int64_t>(s), static_cast<std::int64_t>(t)});
        }
    }
    return out;
}

/// Triangles with corners on a lattice of step 1/8 in [0, 4)^3, sizes up to `size` lattice
/// steps: many exact coincidences, coplanarities, touchings and boxes meeting at cell borders.
Mesh lattice_soup(int count, int size, std::uint32_t seed)
{
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> base(0, 31), step(-size, size);
    Mesh m;
    for (int t = 0; t < count; ++t) {
        const int x = base(rng), y = base(rng), z = base(rng);
        for (int i = 0; i < 3; ++i) {
            m.triangles.push_back(static_cast<std::uint32_t>(m.vertex_count()));
            for (int c : {x, y, z}) m.positions.push_back(static_cast<float>(c + (i == 0 ? 0 : step(rng))) / 8);
        }
    }
    return m;
}

void expect_same(const MeshGeometry& a, const MeshGeometry& b)
{
    EXPECT_EQ(a.positions, b.positions);
    EXPECT_EQ(a.coincident_vertices, b.coincident_vertices);
    EXPECT_EQ(a.zero_area_triangles, b.zero_area_triangles);
    EXPECT_EQ(a.intersecting_pairs, b.intersecting_pairs);
    EXPECT_EQ(a.intersection_examples, b.intersection_examples);
    EXPECT_EQ(a.welded.euler, b.welded.euler);
    EXPECT_EQ(a.welded.components, b.welded.components);
    EXPECT_EQ(a.welded.edges, b.welded.edges);
    EXPECT_EQ(a.welded.nonmanifold_edges, b.welded.nonmanifold_edges);
}

TEST(MeshGeometry, PairSearchFindsEveryPairOfALatticeSoup)
{
    for (std::uint32_t seed = 1; seed <= 3; ++seed) {
        SCOPED_TRACE(seed);
        const Mesh m = lattice_soup(1500, 3, seed);
        const Pairs expected = brute_force_pairs(m);
        const MeshGeometry g = geometry(m, 1);
        EXPECT_EQ(g.intersection_examples, expected);
        EXPECT_EQ(g.intersecting_pairs, static_cast<std::int64_t>(expected.size()));
        EXPECT_GT(g.intersecting_pairs, 100); // the soup is dense: the test means something
        EXPECT_GT(g.zero_area_triangles, 0);
        EXPECT_GT(g.coincident_vertices, 0);
    }
}

TEST(MeshGeometry, PairSearchWithOneLargeTriangleAmongSmallOnes)
{
    // the grid spacing follows the mean triangle: a large triangle spans many cells
    Mesh m = lattice_soup(2000, 1, 7);
    for (float v : {0.0f, 0.0f, 0.0f, 4.0f, 0.0f, 4.0f, 0.0f, 4.0f, 4.0f}) m.positions.push_back(v);
    const auto n = static_cast<std::uint32_t>(m.vertex_count());
    m.triangles.insert(m.triangles.end(), {n - 3, n - 2, n - 1});
    const Pairs expected = brute_force_pairs(m);
    const MeshGeometry g = geometry(m, 2);
    EXPECT_EQ(g.intersection_examples, expected);
    const auto last = static_cast<std::int64_t>(m.triangle_count() - 1);
    EXPECT_GT(std::count_if(expected.begin(), expected.end(), [&](const auto& p) { return p[1] == last; }), 10);
}

TEST(MeshGeometry, ThreadCountDoesNotChangeTheResult)
{
    // extracted surfaces with every 7th vertex moved (crossings) and a lattice soup
    std::vector<Mesh> meshes;
    const cmc33::Volume field = cmc33::random_field(cmc33::FieldKind::grid, 1, 11, 24);
    Mesh surface = cmc33::extract(field, 0.0, cmc33::ExtractOptions{cmc33::Method::mc, false, 1});
    ASSERT_GT(surface.triangle_count(), 5000u);
    for (std::size_t v = 0; v < surface.vertex_count(); v += 7) surface.positions[3 * v + 1] += 0.7f;
    meshes.push_back(std::move(surface));
    meshes.push_back(lattice_soup(6000, 2, 99));
    for (const Mesh& m : meshes) {
        const MeshGeometry one = geometry(m, 1);
        EXPECT_GT(one.intersecting_pairs, 50);
        ASSERT_GE(one.intersection_examples.size(), 5u);
        for (int threads : {2, 3, 8}) {
            SCOPED_TRACE(threads);
            expect_same(one, geometry(m, threads));
        }
        // the examples are the smallest pairs, whatever the thread count
        MeshGeometryOptions few;
        few.examples = 5;
        for (int threads : {1, 2, 8}) {
            few.threads = threads;
            const MeshGeometry g = mesh_geometry(m, few);
            const auto& all = one.intersection_examples;
            EXPECT_EQ(g.intersection_examples, Pairs(all.begin(), all.begin() + 5));
            EXPECT_EQ(g.intersecting_pairs, one.intersecting_pairs);
        }
    }
}

// ------------------------------------------------------------------------------------------------
// Exactness: the predicates against GMP rationals

mpq_class q(double x) { return mpq_class(x); }

int orient3d_reference(const Point3& a, const Point3& b, const Point3& c, const Point3& d)
{
    mpq_class m[3][3];
    const Point3* rows[3] = {&a, &b, &c};
    for (std::size_t r = 0; r < 3; ++r)
        for (std::size_t k = 0; k < 3; ++k) m[r][k] = q((*rows[r])[k]) - q(d[k]);
    const mpq_class det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                          m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                          m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    return sgn(det);
}

int orient2d_reference(const Point3& a, const Point3& b, const Point3& c, int drop)
{
    const std::size_t u = drop == 0 ? 1 : 0, v = drop == 2 ? 1 : 2;
    const mpq_class det = (q(a[u]) - q(c[u])) * (q(b[v]) - q(c[v])) - (q(a[v]) - q(c[v])) * (q(b[u]) - q(c[u]));
    return sgn(det);
}

TEST(MeshGeometryPredicates, SignConvention)
{
    // d below the plane z = 0 of the counter-clockwise (seen from +z) triangle abc: +1
    EXPECT_EQ(cmc33::detail::orient3d({1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {0, 0, -1}), 1);
    EXPECT_EQ(cmc33::detail::orient3d({1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {0, 0, 1}), -1);
    EXPECT_EQ(cmc33::detail::orient3d({1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {5, 7, 0}), 0);
    EXPECT_EQ(cmc33::detail::orient2d({1, 0, 9}, {0, 1, 9}, {0, 0, 9}, 2), 1);
    EXPECT_EQ(cmc33::detail::orient2d({0, 1, 9}, {1, 0, 9}, {0, 0, 9}, 2), -1);
}

/// A float one ulp away from x, or x itself, at random.
float jiggle(float x, std::mt19937_64& rng)
{
    switch (rng() % 4) {
    case 0: return up(x);
    case 1: return down(x);
    default: return x;
    }
}

TEST(MeshGeometryPredicates, Orient3dMatchesRationalsOnNearCoplanarPoints)
{
    std::mt19937_64 rng(20240611);
    auto& stats = cmc33::detail::predicate_stats();
    const cmc33::detail::PredicateStats before = stats;
    std::int64_t zeros = 0, checked = 0;
    for (int it = 0; it < 100000; ++it) {
        const int family = it % 4;
        std::array<Point3, 4> p{};
        // families 0-2: four points on a plane through the origin (z = a x + b y, or z = 2x - y/2)
        // given exactly in floats, a third of them then moved by one ulp per coordinate at random
        const int a = static_cast<int>(rng() % 3) - 1, b = static_cast<int>(rng() % 3) - 1;
        const double base = 1048576.0; // 2^20
        for (auto& pt : p) {
            float x = 0, y = 0, z = 0;
            if (family == 0) { // small integers: exact degeneracies everywhere
                x = static_cast<float>(static_cast<int>(rng() % 9) - 4);
                y = static_cast<float>(static_cast<int>(rng() % 9) - 4);
                z = static_cast<float>(a) * x + static_cast<float>(b) * y;
            } else if (family == 1) { // large coordinates close together: 2^20 + k/4, exact, and
                // z = a x + b y < 2^22 in steps of 1/4, exact too
                x = static_cast<float>(base + static_cast<double>(rng() % 64) / 4);
                y = static_cast<float>(base + static_cast<double>(rng() % 64) / 4);
                z = static_cast<float>(a) * x + static_cast<float>(b) * y;
            } else if (family == 2) { // exponents from 2^-60 to 2^60 on the plane z = 2x - y/2
                const int e = static_cast<int>(rng() % 121) - 60;
                x = std::ldexp(static_cast<float>(rng() % 4096 + 1), e - 12);
                y = std::ldexp(static_cast<float>(rng() % 4096 + 1), static_cast<int>(rng() % 121) - 72);
                // 2x - y/2 fits a float only when the exponents allow; if not, y = 0 and z = 2x
                const double zd = 2.0 * static_cast<double>(x) - 0.5 * static_cast<double>(y);
                z = static_cast<float>(zd);
                if (static_cast<double>(z) != zd) {
                    y = 0;
                    z = 2 * x;
                }
            } else { // random floats of mixed exponents, not coplanar in general
                x = std::ldexp(static_cast<float>(rng() % 16777216), static_cast<int>(rng() % 80) - 64);
                y = std::ldexp(static_cast<float>(rng() % 16777216), static_cast<int>(rng() % 80) - 64);
                z = std::ldexp(static_cast<float>(rng() % 16777216), static_cast<int>(rng() % 80) - 64);
            }
            if (rng() % 3 == 0) {
                x = jiggle(x, rng);
                y = jiggle(y, rng);
                z = jiggle(z, rng);
            }
            pt = {double(x), double(y), double(z)};
        }
        const int expected = orient3d_reference(p[0], p[1], p[2], p[3]);
        const int got = cmc33::detail::orient3d(p[0], p[1], p[2], p[3]);
        ASSERT_EQ(got, expected) << "iteration " << it << " points " << p[0][0] << ' ' << p[0][1] << ' ' << p[0][2]
                                 << " | " << p[1][0] << ' ' << p[1][1] << ' ' << p[1][2] << " | " << p[2][0] << ' '
                                 << p[2][1] << ' ' << p[2][2] << " | " << p[3][0] << ' ' << p[3][1] << ' ' << p[3][2];
        // orientation flips with an odd permutation
        ASSERT_EQ(cmc33::detail::orient3d(p[1], p[0], p[2], p[3]), -expected) << "iteration " << it;
        for (int drop = 0; drop < 3; ++drop)
            ASSERT_EQ(cmc33::detail::orient2d(p[0], p[1], p[2], drop), orient2d_reference(p[0], p[1], p[2], drop))
                << "iteration " << it << " drop " << drop;
        zeros += expected == 0;
        ++checked;
    }
    const cmc33::detail::PredicateStats after = stats;
    // every path was taken, and degenerate cases were common
    EXPECT_GT(after.filtered - before.filtered, 1000);
    EXPECT_GT(after.expansion - before.expansion, 1000);
    EXPECT_GT(after.rational - before.rational, 100);
    EXPECT_GT(zeros, checked / 10);
}

TEST(MeshGeometryPredicates, CoplanarTrianglesWithLargeCoordinates)
{
    // the plane z = x + y through points near (1e6, 1e6, 2e6), in steps of 1/8 (exact)
    const double a = 1000000.0;
    auto pt = [&](double dx, double dy) { return P{float(a + dx), float(a + dy), float(2 * a + dx + dy)}; };
    // a fold-over across the shared edge (0, 1): third corners on the same side
    const std::vector<P> pts{pt(0, 0), pt(1, 0.125), pt(0.25, 1), pt(0.875, 0.75), pt(0.5, -1)};
    for (const P& p : pts) ASSERT_EQ(double(p[2]) - double(p[0]) - double(p[1]), 0.0) << "not exact";
    const std::array<Point3, 4> d{Point3{double(pts[0][0]), double(pts[0][1]), double(pts[0][2])}, Point3{double(pts[1][0]), double(pts[1][1]), double(pts[1][2])},
                                  Point3{double(pts[2][0]), double(pts[2][1]), double(pts[2][2])}, Point3{double(pts[3][0]), double(pts[3][1]), double(pts[3][2])}};
    ASSERT_EQ(orient3d_reference(d[0], d[1], d[2], d[3]), 0);
    auto& stats = cmc33::detail::predicate_stats();
    const auto before = stats;
    EXPECT_EQ(cmc33::detail::orient3d(d[0], d[1], d[2], d[3]), 0);
    EXPECT_EQ(stats.filtered, before.filtered); // the filter could not decide it
    EXPECT_EQ(geometry(make_mesh(pts, {0, 1, 2, 1, 0, 3})).intersecting_pairs, 1); // fold
    EXPECT_EQ(geometry(make_mesh(pts, {0, 1, 2, 1, 0, 4})).intersecting_pairs, 0); // proper
    // corner 3 moved off the plane by one ulp in z: a hinge, no overlap
    std::vector<P> lifted = pts;
    lifted[3][2] = up(lifted[3][2]);
    const Point3 l3{double(lifted[3][0]), double(lifted[3][1]), double(lifted[3][2])};
    ASSERT_NE(orient3d_reference(d[0], d[1], d[2], l3), 0);
    EXPECT_EQ(cmc33::detail::orient3d(d[0], d[1], d[2], l3), orient3d_reference(d[0], d[1], d[2], l3));
    EXPECT_EQ(geometry(make_mesh(lifted, {0, 1, 2, 1, 0, 3})).intersecting_pairs, 0);
    // disjoint corners, coplanar: a small triangle inside the first one, and one ulp above it
    std::vector<P> inner = pts;
    for (const P& p : {pt(0.25, 0.25), pt(0.5, 0.375), pt(0.375, 0.5)}) inner.push_back(p);
    EXPECT_EQ(geometry(make_mesh(inner, {0, 1, 2, 5, 6, 7})).intersecting_pairs, 1);
    for (std::size_t i = 5; i < 8; ++i) inner[i][2] = up(inner[i][2]);
    EXPECT_EQ(geometry(make_mesh(inner, {0, 1, 2, 5, 6, 7})).intersecting_pairs, 0);
}

TEST(MeshGeometryPredicates, VeryDifferentExponentsTakeTheRationalPath)
{
    // points on the plane z = x, coordinates from 2^-100 to 2^100: their differences are not
    // exact in double, so only GMP can settle the sign
    const double s = std::ldexp(1.0, -100), l = std::ldexp(1.0, 100);
    const Point3 a{s, 0, s}, b{l, s, l}, c{1, l, 1}, d{l + std::ldexp(1.0, 77), 3 * s, l + std::ldexp(1.0, 77)};
    ASSERT_EQ(orient3d_reference(a, b, c, d), 0);
    auto& stats = cmc33::detail::predicate_stats();
    const auto before = stats;
    EXPECT_EQ(cmc33::detail::orient3d(a, b, c, d), 0);
    EXPECT_EQ(stats.rational, before.rational + 1);
    // d one float ulp off the plane, either way
    for (float dz : {up(static_cast<float>(d[2])), down(static_cast<float>(d[2]))}) {
        const Point3 e{d[0], d[1], double(dz)};
        const int expected = orient3d_reference(a, b, c, e);
        ASSERT_NE(expected, 0);
        EXPECT_EQ(cmc33::detail::orient3d(a, b, c, e), expected);
    }
    // a tiny corner against a huge triangle: touching exactly, or one ulp away
    const auto f = [](double x) { return static_cast<float>(x); };
    const std::array<P, 3> huge{{{f(-l), f(-l), f(-l)}, {f(l), f(-l), f(l)}, {0, f(l), 0}}}; // plane z = x
    const std::array<P, 3> tiny_on{{{f(s), 0, f(s)}, {f(2 * s), f(s), f(5 * s)}, {f(s), f(2 * s), f(5 * s)}}};
    const std::array<P, 3> tiny_off{{{f(s), 0, up(f(s))}, {f(2 * s), f(s), f(5 * s)}, {f(s), f(2 * s), f(5 * s)}}};
    const auto r0 = stats.rational;
    EXPECT_EQ(geometry(soup({huge, tiny_on})).intersecting_pairs, 1);
    EXPECT_EQ(geometry(soup({huge, tiny_off})).intersecting_pairs, 0);
    EXPECT_GT(stats.rational, r0);
}

TEST(MeshGeometryPredicates, SegmentMeetsTriangle)
{
    const Point3 a{0, 0, 0}, b{2, 0, 0}, c{0, 2, 0};
    using cmc33::detail::segment_meets_triangle;
    EXPECT_TRUE(segment_meets_triangle({0.5, 0.5, -1}, {0.5, 0.5, 1}, a, b, c));
    EXPECT_TRUE(segment_meets_triangle({0.5, 0.5, 0}, {0.5, 0.5, 1}, a, b, c));  // endpoint on it
    EXPECT_TRUE(segment_meets_triangle({1, 1, -1}, {1, 1, 1}, a, b, c));         // through the hypotenuse
    EXPECT_FALSE(segment_meets_triangle({1, double(up(1.0f)), -1}, {1, double(up(1.0f)), 1}, a, b, c));
    EXPECT_TRUE(segment_meets_triangle({-1, 0, 0}, {3, 0, 0}, a, b, c));         // along an edge
    EXPECT_TRUE(segment_meets_triangle({-1, 1, 0}, {3, 1, 0}, a, b, c));         // across, coplanar
    EXPECT_FALSE(segment_meets_triangle({-1, -1, 0}, {3, -1, 0}, a, b, c));      // coplanar, outside
    EXPECT_FALSE(segment_meets_triangle({0.5, 0.5, 1}, {0.5, 0.5, 2}, a, b, c)); // above
}

// ------------------------------------------------------------------------------------------------
// Errors and trivial inputs

TEST(MeshGeometry, EmptyMeshAndErrors)
{
    const MeshGeometry empty = geometry(Mesh{});
    EXPECT_TRUE(empty.embedded());
    EXPECT_EQ(empty.positions, 0);
    EXPECT_EQ(empty.welded.faces, 0);

    Mesh bad_index = make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 3});
    EXPECT_THROW(mesh_geometry(bad_index), cmc33::Error);
    Mesh bad_count = make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1});
    EXPECT_THROW(mesh_geometry(bad_count), cmc33::Error);
    Mesh nan = make_mesh({{0, 0, 0}, {1, 0, 0}, {0, std::numeric_limits<float>::quiet_NaN(), 0}}, {0, 1, 2});
    EXPECT_THROW(mesh_geometry(nan), cmc33::Error);
    Mesh inf = make_mesh({{0, 0, 0}, {1, 0, 0}, {0, std::numeric_limits<float>::infinity(), 0}}, {0, 1, 2});
    EXPECT_THROW(mesh_geometry(inf), cmc33::Error);
}

} // namespace
