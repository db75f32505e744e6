// mesh_topology(): invariants of small meshes whose numbers are known by hand.

#include <gtest/gtest.h>

#include <cstdint>
#include <algorithm>
#include <initializer_list>
#include <random>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/topology.hpp"

namespace {

using cmc33::Mesh;
using cmc33::mesh_topology;
using cmc33::MeshTopology;

// Positions do not matter to topology: every vertex sits at the origin.
Mesh make_mesh(std::size_t vertex_count, std::initializer_list<std::uint32_t> triangles)
{
    Mesh mesh;
    mesh.positions.assign(3 * vertex_count, 0.0f);
    mesh.triangles = triangles;
    return mesh;
}

void append(Mesh& mesh, const Mesh& other)
{
    const auto shift = static_cast<std::uint32_t>(mesh.vertex_count());
    mesh.positions.insert(mesh.positions.end(), other.positions.begin(), other.positions.end());
    for (std::uint32_t i : other.triangles) mesh.triangles.push_back(i + shift);
}

// Outward-oriented (counter-clockwise seen from outside).
Mesh tetrahedron()
{
    return make_mesh(4, {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3});
}

// Cube with corners v = x | y << 1 | z << 2, two triangles per face, outward.
Mesh cube()
{
    return make_mesh(8, {
                            0, 2, 3, 0, 3, 1, // z = 0
                            4, 5, 7, 4, 7, 6, // z = 1
                            0, 1, 5, 0, 5, 4, // y = 0
                            2, 6, 7, 2, 7, 3, // y = 1
                            0, 4, 6, 0, 6, 2, // x = 0
                            1, 3, 7, 1, 7, 5, // x = 1
                        });
}

// n x m grid of quads; `wrap_u`/`wrap_v` close it into a cylinder or a torus.
Mesh grid(std::uint32_t n, std::uint32_t m, bool wrap_u, bool wrap_v)
{
    const std::uint32_t nu = wrap_u ? n : n + 1, nv = wrap_v ? m : m + 1;
    Mesh mesh;
    mesh.positions.assign(3 * static_cast<std::size_t>(nu) * nv, 0.0f);
    auto id = [&](std::uint32_t i, std::uint32_t j) { return (j % nv) * nu + i % nu; };
    mesh.triangles.reserve(6 * static_cast<std::size_t>(n) * m);
    for (std::uint32_t j = 0; j < m; ++j) {
        for (std::uint32_t i = 0; i < n; ++i) {
            const std::uint32_t a = id(i, j), b = id(i + 1, j);
            const std::uint32_t c = id(i + 1, j + 1), d = id(i, j + 1);
            mesh.triangles.insert(mesh.triangles.end(), {a, b, c, a, c, d});
        }
    }
    return mesh;
}

void expect_counts(const MeshTopology& t, std::int64_t v, std::int64_t e, std::int64_t f)
{
    EXPECT_EQ(t.vertices, v);
    EXPECT_EQ(t.edges, e);
    EXPECT_EQ(t.faces, f);
    EXPECT_EQ(t.euler, v - e + f);
}

TEST(MeshTopology, Tetrahedron)
{
    const MeshTopology t = mesh_topology(tetrahedron());
    expect_counts(t, 4, 6, 4);
    EXPECT_EQ(t.euler, 2);
    EXPECT_EQ(t.components, 1);
    EXPECT_EQ(t.b1, 0);
    EXPECT_EQ(t.closed_components, 1);
    EXPECT_EQ(t.boundary_edges, 0);
    EXPECT_EQ(t.boundary_loops, 0);
    EXPECT_EQ(t.nonmanifold_edges, 0);
    EXPECT_EQ(t.nonmanifold_vertices, 0);
    EXPECT_EQ(t.degenerate_triangles, 0);
    EXPECT_TRUE(t.closed);
    EXPECT_TRUE(t.oriented);
}

TEST(MeshTopology, TriangulatedCube)
{
    const MeshTopology t = mesh_topology(cube());
    expect_counts(t, 8, 18, 12);
    EXPECT_EQ(t.euler, 2);
    EXPECT_EQ(t.components, 1);
    EXPECT_EQ(t.closed_components, 1);
    EXPECT_EQ(t.b1, 0);
    EXPECT_TRUE(t.closed);
    EXPECT_TRUE(t.oriented);
    EXPECT_EQ(t.nonmanifold_vertices, 0);
}

TEST(MeshTopology, TorusGrid)
{
    const MeshTopology t = mesh_topology(grid(6, 5, true, true));
    expect_counts(t, 30, 90, 60);
    EXPECT_EQ(t.euler, 0);
    EXPECT_EQ(t.components, 1);
    EXPECT_EQ(t.closed_components, 1);
    EXPECT_EQ(t.b1, 2);
    EXPECT_EQ(t.boundary_edges, 0);
    EXPECT_TRUE(t.closed);
    EXPECT_TRUE(t.oriented);
    EXPECT_EQ(t.nonmanifold_edges, 0);
    EXPECT_EQ(t.nonmanifold_vertices, 0);
}

TEST(MeshTopology, CylinderHasTwoBoundaryLoops)
{
    const MeshTopology t = mesh_topology(grid(8, 3, true, false));
    expect_counts(t, 32, 8 * 3 + 8 * 4 + 8 * 3, 48);
    EXPECT_EQ(t.euler, 0);
    EXPECT_EQ(t.boundary_edges, 16);
    EXPECT_EQ(t.boundary_loops, 2);
    EXPECT_EQ(t.closed_components, 0);
    EXPECT_EQ(t.b1, 1);
    EXPECT_FALSE(t.closed);
    EXPECT_TRUE(t.oriented);
}

TEST(MeshTopology, TwoDisjointSpheres)
{
    Mesh mesh = tetrahedron();
    append(mesh, cube());
    const MeshTopology t = mesh_topology(mesh);
    expect_counts(t, 12, 24, 16);
    EXPECT_EQ(t.euler, 4);
    EXPECT_EQ(t.components, 2);
    EXPECT_EQ(t.closed_components, 2);
    EXPECT_EQ(t.b1, 0);
    EXPECT_TRUE(t.closed);
    EXPECT_TRUE(t.oriented);
}

TEST(MeshTopology, SquareWithHole)
{
    // 3 x 3 quads on a 4 x 4 vertex grid, the middle quad removed: an annulus.
    Mesh full = grid(3, 3, false, false);
    Mesh mesh;
    mesh.positions = full.positions;
    for (std::size_t q = 0; q < 9; ++q) {
        if (q == 4) continue;
        mesh.triangles.insert(mesh.triangles.end(), full.triangles.begin() + 6 * q,
                              full.triangles.begin() + 6 * q + 6);
    }
    const MeshTopology t = mesh_topology(mesh);
    // E: 24 grid edges minus the removed quad's diagonal, 16 triangles.
    expect_counts(t, 16, 32, 16);
    EXPECT_EQ(t.euler, 0);
    EXPECT_EQ(t.boundary_edges, 16); // 12 outside, 4 around the hole
    EXPECT_EQ(t.boundary_loops, 2);
    EXPECT_EQ(t.components, 1);
    EXPECT_EQ(t.closed_components, 0);
    EXPECT_EQ(t.b1, 1);
    EXPECT_FALSE(t.closed);
    EXPECT_TRUE(t.oriented);
    EXPECT_EQ(t.nonmanifold_vertices, 0);
}

TEST(MeshTopology, SingleTriangle)
{
    const MeshTopology t = mesh_topology(make_mesh(3, {0, 1, 2}));
    expect_counts(t, 3, 3, 1);
    EXPECT_EQ(t.euler, 1);
    EXPECT_EQ(t.boundary_edges, 3);
    EXPECT_EQ(t.boundary_loops, 1);
    EXPECT_EQ(t.components, 1);
    EXPECT_EQ(t.closed_components, 0);
    EXPECT_EQ(t.b1, 0);
    EXPECT_FALSE(t.closed);
    EXPECT_TRUE(t.oriented); // no interior edge contradicts it
}

TEST(MeshTopology, MoebiusStrip)
{
    // Rungs (t_i, b_i), i = 0..4; quad i joins rung i to rung i + 1, the last one to the
    // flipped first rung (b_0, t_0).
    const std::uint32_t n = 5;
    Mesh mesh;
    mesh.positions.assign(3 * 2 * n, 0.0f);
    for (std::uint32_t i = 0; i < n; ++i) {
        const std::uint32_t t0 = 2 * i, b0 = 2 * i + 1;
        std::uint32_t t1 = 2 * (i + 1), b1 = 2 * (i + 1) + 1;
        if (i + 1 == n) {
            t1 = 1;
            b1 = 0;
        }
        mesh.triangles.insert(mesh.triangles.end(), {t0, b0, b1, t0, b1, t1});
    }
    const MeshTopology t = mesh_topology(mesh);
    expect_counts(t, 10, 20, 10);
    EXPECT_EQ(t.euler, 0);
    EXPECT_EQ(t.boundary_edges, 10);
    EXPECT_EQ(t.boundary_loops, 1); // the Moebius strip has a single boundary circle
    EXPECT_EQ(t.components, 1);
    EXPECT_EQ(t.b1, 1);
    EXPECT_EQ(t.nonmanifold_edges, 0);
    EXPECT_EQ(t.nonmanifold_vertices, 0);
    EXPECT_FALSE(t.oriented);
}

TEST(MeshTopology, FlippedTriangleInClosedMesh)
{
    Mesh mesh = cube();
    std::swap(mesh.triangles[1], mesh.triangles[2]);
    const MeshTopology t = mesh_topology(mesh);
    expect_counts(t, 8, 18, 12);
    EXPECT_TRUE(t.closed);
    EXPECT_FALSE(t.oriented);
    EXPECT_EQ(t.nonmanifold_edges, 0);
}

TEST(MeshTopology, ThreeTrianglesOnOneEdge)
{
    const MeshTopology t = mesh_topology(make_mesh(5, {0, 1, 2, 1, 0, 3, 0, 1, 4}));
    expect_counts(t, 5, 7, 3);
    EXPECT_EQ(t.nonmanifold_edges, 1);
    EXPECT_EQ(t.boundary_edges, 6);
    EXPECT_EQ(t.boundary_loops, 1);
    EXPECT_EQ(t.nonmanifold_vertices, 0); // all three triangles meet along the edge at 0 and at 1
    EXPECT_EQ(t.components, 1);
    EXPECT_FALSE(t.closed);
}

TEST(MeshTopology, TwoTetrahedraSharingAVertex)
{
    Mesh mesh = tetrahedron();
    // Second tetrahedron on vertices 0, 4, 5, 6.
    mesh.positions.resize(3 * 7, 0.0f);
    for (std::uint32_t i : {0u, 2u, 1u, 0u, 1u, 3u, 0u, 3u, 2u, 1u, 2u, 3u}) {
        mesh.triangles.push_back(i == 0 ? 0 : i + 3);
    }
    const MeshTopology t = mesh_topology(mesh);
    expect_counts(t, 7, 12, 8);
    EXPECT_EQ(t.euler, 3);
    EXPECT_EQ(t.nonmanifold_vertices, 1);
    EXPECT_EQ(t.nonmanifold_edges, 0);
    EXPECT_EQ(t.components, 1);
    EXPECT_EQ(t.closed_components, 1);
    EXPECT_TRUE(t.closed);
    EXPECT_TRUE(t.oriented);
}

TEST(MeshTopology, BowtieOfTwoTriangles)
{
    const MeshTopology t = mesh_topology(make_mesh(5, {0, 1, 2, 0, 3, 4}));
    expect_counts(t, 5, 6, 2);
    EXPECT_EQ(t.nonmanifold_vertices, 1);
    EXPECT_EQ(t.boundary_edges, 6);
    EXPECT_EQ(t.boundary_loops, 1); // the two triangles' boundaries touch at vertex 0
    EXPECT_EQ(t.components, 1);
}

TEST(MeshTopology, DegenerateTriangleIsIgnored)
{
    Mesh mesh = tetrahedron();
    mesh.positions.resize(3 * 5, 0.0f);
    // Vertex 4 is used by degenerate triangles only.
    mesh.triangles.insert(mesh.triangles.end(), {0, 0, 1, 4, 2, 4});
    const MeshTopology t = mesh_topology(mesh);
    EXPECT_EQ(t.degenerate_triangles, 2);
    expect_counts(t, 4, 6, 4);
    EXPECT_TRUE(t.closed);
    EXPECT_TRUE(t.oriented);
}

TEST(MeshTopology, UnreferencedVerticesAreNotCounted)
{
    Mesh mesh = tetrahedron();
    mesh.positions.insert(mesh.positions.begin(), 9, 1.0f); // three unused vertices first
    for (std::uint32_t& i : mesh.triangles) i += 3;
    mesh.positions.resize(mesh.positions.size() + 6, 2.0f); // and two after
    const MeshTopology t = mesh_topology(mesh);
    expect_counts(t, 4, 6, 4);
    EXPECT_EQ(t.components, 1);
    EXPECT_EQ(t.closed_components, 1);
    EXPECT_EQ(t.euler, 2);
}

TEST(MeshTopology, EmptyMesh)
{
    const MeshTopology t = mesh_topology(Mesh{});
    expect_counts(t, 0, 0, 0);
    EXPECT_EQ(t.components, 0);
    EXPECT_EQ(t.closed_components, 0);
    EXPECT_EQ(t.b1, 0);
    EXPECT_FALSE(t.closed);
    EXPECT_TRUE(t.oriented); // no edge is run the wrong way: trivially oriented

    const MeshTopology only_points = mesh_topology(make_mesh(4, {}));
    EXPECT_EQ(only_points.vertices, 0);
    EXPECT_FALSE(only_points.closed);
}

TEST(MeshTopology, OnlyDegenerateTriangles)
{
    const MeshTopology t = mesh_topology(make_mesh(3, {0, 1, 1, 2, 2, 2}));
    EXPECT_EQ(t.degenerate_triangles, 2);
    expect_counts(t, 0, 0, 0);
    EXPECT_FALSE(t.closed);
    EXPECT_TRUE(t.oriented); // like an empty mesh
}

TEST(MeshTopology, RejectsOutOfRangeIndex)
{
    try {
        mesh_topology(make_mesh(3, {0, 1, 2, 0, 2, 7}));
        FAIL() << "no exception";
    } catch (const cmc33::Error& e) {
        EXPECT_EQ(e.status(), cmc33::Status::invalid_argument);
        EXPECT_NE(std::string(e.what()).find("triangle 1 uses vertex 7"), std::string::npos)
            << e.what();
    }
    Mesh ragged = make_mesh(3, {0, 1, 2, 0});
    EXPECT_THROW(mesh_topology(ragged), cmc33::Error);
}

TEST(MeshTopology, DuplicatedTriangleMakesEdgesTwiceUsedSameWay)
{
    // The same triangle twice: a closed "pillow" of zero volume, each edge run the same way twice.
    const MeshTopology t = mesh_topology(make_mesh(3, {0, 1, 2, 0, 1, 2}));
    expect_counts(t, 3, 3, 2);
    EXPECT_TRUE(t.closed);
    EXPECT_FALSE(t.oriented);
    EXPECT_EQ(t.closed_components, 1);

    const MeshTopology pillow = mesh_topology(make_mesh(3, {0, 1, 2, 0, 2, 1}));
    EXPECT_TRUE(pillow.oriented);
    EXPECT_EQ(pillow.euler, 2);
}

// A disc made of `count` triangles around vertex 0 (rim vertices first + 1 .. first + count).
void add_fan(Mesh& mesh, std::uint32_t first, std::uint32_t count)
{
    mesh.positions.resize(std::max<std::size_t>(mesh.positions.size(), 3 * (first + count)), 0.0f);
    for (std::uint32_t i = 0; i < count; ++i) {
        mesh.triangles.insert(mesh.triangles.end(), {0, first + i, first + (i + 1) % count});
    }
}

TEST(MeshTopology, HighDegreeFans)
{
    Mesh disc = make_mesh(1, {});
    add_fan(disc, 1, 40); // the centre has 40 triangles: more than the insertion-sort limit
    const MeshTopology t = mesh_topology(disc);
    expect_counts(t, 41, 80, 40);
    EXPECT_EQ(t.euler, 1);
    EXPECT_EQ(t.boundary_edges, 40);
    EXPECT_EQ(t.boundary_loops, 1);
    EXPECT_EQ(t.nonmanifold_vertices, 0);
    EXPECT_TRUE(t.oriented);

    Mesh two_discs = disc;
    add_fan(two_discs, 41, 30); // a second disc touching the first at its centre
    const MeshTopology u = mesh_topology(two_discs);
    expect_counts(u, 71, 140, 70);
    EXPECT_EQ(u.nonmanifold_vertices, 1);
    EXPECT_EQ(u.boundary_loops, 2);
    EXPECT_EQ(u.components, 1);
    EXPECT_EQ(u.nonmanifold_edges, 0);
}

TEST(MeshTopology, IndependentOfVertexAndTriangleOrder)
{
    const Mesh torus = grid(20, 15, true, true);
    Mesh scrambled = torus;
    std::vector<std::uint32_t> perm(torus.vertex_count());
    for (std::uint32_t i = 0; i < perm.size(); ++i) perm[i] = i;
    std::mt19937 rng(12345);
    std::shuffle(perm.begin(), perm.end(), rng);
    std::vector<std::uint32_t> order(torus.triangle_count());
    for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
    std::shuffle(order.begin(), order.end(), rng);
    for (std::size_t t = 0; t < order.size(); ++t) {
        for (int c = 0; c < 3; ++c) {
            scrambled.triangles[3 * t + c] = perm[torus.triangles[3 * order[t] + (c + t) % 3]];
        }
    }
    const MeshTopology a = mesh_topology(torus), b = mesh_topology(scrambled);
    expect_counts(b, a.vertices, a.edges, a.faces);
    EXPECT_EQ(b.components, 1);
    EXPECT_EQ(b.b1, 2);
    EXPECT_TRUE(b.closed);
    EXPECT_TRUE(b.oriented); // rotating a triangle's corners keeps its orientation
}

// Timing-free scaling check: ~1M triangles must still give exact numbers (and run well under 2 s).
TEST(MeshTopology, LargeTorusGrid)
{
    const std::uint32_t n = 1000, m = 500;
    const MeshTopology t = mesh_topology(grid(n, m, true, true));
    expect_counts(t, std::int64_t{n} * m, 3 * std::int64_t{n} * m, 2 * std::int64_t{n} * m);
    EXPECT_EQ(t.euler, 0);
    EXPECT_EQ(t.components, 1);
    EXPECT_EQ(t.closed_components, 1);
    EXPECT_EQ(t.b1, 2);
    EXPECT_TRUE(t.closed);
    EXPECT_TRUE(t.oriented);
    EXPECT_EQ(t.nonmanifold_edges, 0);
    EXPECT_EQ(t.nonmanifold_vertices, 0);
}

} // namespace
