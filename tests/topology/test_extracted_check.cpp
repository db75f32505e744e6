// check_extracted_mesh(), the structured check of an extracted mesh, against the general
// mesh_topology() and mesh_geometry(): the same numbers on every mesh, extracted or broken on
// purpose (a moved vertex, a flipped triangle, a duplicated triangle, two vertices at one
// position), for every method, frame and thread count.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/io.hpp"
#include "cmc33/topology.hpp"
#include "cmc33/verify.hpp"

namespace {

using namespace cmc33;

struct Extracted {
    Mesh mesh;
    ExtractStats stats;
    Volume volume;
    ExtractedGrid grid() const
    {
        return {volume.dims(), volume.spacing(), volume.origin(), volume.direction(), stats.plane_first_vertex,
                stats.plane_first_triangle};
    }
};

Extracted extracted(Volume volume, double iso, Method method = Method::cmc33)
{
    Extracted e;
    ExtractOptions options;
    options.method = method;
    options.threads = 2;
    e.mesh = extract(volume, iso, options, &e.stats);
    e.volume = std::move(volume);
    return e;
}

void expect_same_topology(const MeshTopology& a, const MeshTopology& b)
{
    EXPECT_EQ(a.vertices, b.vertices);
    EXPECT_EQ(a.edges, b.edges);
    EXPECT_EQ(a.faces, b.faces);
    EXPECT_EQ(a.euler, b.euler);
    EXPECT_EQ(a.components, b.components);
    EXPECT_EQ(a.closed_components, b.closed_components);
    EXPECT_EQ(a.b1, b.b1);
    EXPECT_EQ(a.boundary_edges, b.boundary_edges);
    EXPECT_EQ(a.boundary_loops, b.boundary_loops);
    EXPECT_EQ(a.nonmanifold_edges, b.nonmanifold_edges);
    EXPECT_EQ(a.nonmanifold_vertices, b.nonmanifold_vertices);
    EXPECT_EQ(a.degenerate_triangles, b.degenerate_triangles);
    EXPECT_EQ(a.closed, b.closed);
    EXPECT_EQ(a.oriented, b.oriented);
}

/// The structured check gives the general functions' numbers; returns whether it was structured.
bool expect_agrees(const Mesh& mesh, const ExtractedGrid& grid, int threads = 2)
{
    MeshCheckOptions options;
    options.threads = threads;
    const MeshCheck check = check_extracted_mesh(mesh, grid, options);
    const MeshTopology topology = mesh_topology(mesh);
    const MeshGeometry geometry = mesh_geometry(mesh, MeshGeometryOptions{threads, 8});
    expect_same_topology(check.topology, topology);
    EXPECT_EQ(check.geometry.positions, geometry.positions);
    EXPECT_EQ(check.geometry.coincident_vertices, geometry.coincident_vertices);
    EXPECT_EQ(check.geometry.zero_area_triangles, geometry.zero_area_triangles);
    EXPECT_EQ(check.geometry.intersecting_pairs, geometry.intersecting_pairs);
    EXPECT_EQ(check.geometry.intersection_examples, geometry.intersection_examples);
    expect_same_topology(check.geometry.welded, geometry.welded);
    return check.structured;
}

TEST(ExtractedCheck, AgreesWithTheGeneralChecksOnRandomFieldsForEveryMethod)
{
    int structured = 0, meshes = 0;
    for (int kind = 0; kind < kFieldKindCount; ++kind)
        for (Method method : {Method::cmc33, Method::mc, Method::chernyaev, Method::mc33_lewiner})
            for (std::int64_t n = 1; n <= 12; ++n) {
                SCOPED_TRACE(std::string(field_kind_name(static_cast<FieldKind>(kind))) + " " +
                             std::string(method_name(method)) + " " + std::to_string(n));
                Extracted e = extracted(random_field(static_cast<FieldKind>(kind), n, 7, 5 + static_cast<int>(n % 5)), 0.0, method);
                ++meshes;
                if (expect_agrees(e.mesh, e.grid())) ++structured;
                if (method == Method::cmc33) {
                    MeshCheckOptions o;
                    EXPECT_TRUE(check_extracted_mesh(e.mesh, e.grid(), o).structured); // embedded: no fallback
                }
            }
    EXPECT_GT(structured, meshes / 2);
}

TEST(ExtractedCheck, AgreesInObliqueFramesAndWithAnyThreadCount)
{
    Volume v = random_field(FieldKind::grid, 3, 11, 24);
    const double c = std::cos(0.4), s = std::sin(0.4);
    v.set_direction({{{c, 0, s}, {0.1, 1, 0}, {-s, 0, c}}}); // sheared and rotated
    v.set_spacing({0.7, 1.3, 2.1});
    v.set_origin({-120.5, 33.25, 900});
    Extracted e = extracted(std::move(v), 0.0);
    ASSERT_GT(e.mesh.triangle_count(), 5000u);
    for (int threads : {1, 2, 3, 8}) {
        SCOPED_TRACE(threads);
        EXPECT_TRUE(expect_agrees(e.mesh, e.grid(), threads));
    }
}

TEST(ExtractedCheck, AgreesOnTheBuckyball)
{
    for (double iso : {20.0, 80.0, 127.5, 200.0}) {
        SCOPED_TRACE(iso);
        Extracted e = extracted(io::read_volume(CMC33_SOURCE_DIR "/data/Bucky_32x32x32_uint8.nrrd"), iso);
        EXPECT_TRUE(expect_agrees(e.mesh, e.grid()));
    }
}

/// A noise field's mesh (many triangles, many near-ties) for the broken-mesh tests.
Extracted noise_mesh()
{
    Extracted e = extracted(random_field(FieldKind::grid, 5, 3, 20), 0.0);
    EXPECT_GT(e.mesh.triangle_count(), 2000u);
    return e;
}

TEST(ExtractedCheck, FindsAVertexMovedWithinItsCellsAndOneMovedFarAway)
{
    for (float shift : {0.15f, 0.6f, 5.0f}) {
        SCOPED_TRACE(shift);
        Extracted e = noise_mesh();
        std::mt19937 random(17);
        for (int moved = 0; moved < 6; ++moved) {
            const std::size_t v = random() % e.mesh.vertex_count();
            e.mesh.positions[3 * v + random() % 3] += (moved % 2 ? shift : -shift);
        }
        const bool structured = expect_agrees(e.mesh, e.grid());
        if (shift > 1) {
            EXPECT_FALSE(structured); // a corner outside its cell: the general checks ran
        }
    }
}

TEST(ExtractedCheck, FindsAFlippedTriangle)
{
    Extracted e = noise_mesh();
    std::swap(e.mesh.triangles[3 * 100 + 1], e.mesh.triangles[3 * 100 + 2]);
    EXPECT_TRUE(expect_agrees(e.mesh, e.grid()));
    MeshCheckOptions o;
    EXPECT_FALSE(check_extracted_mesh(e.mesh, e.grid(), o).topology.oriented);
}

TEST(ExtractedCheck, FindsADuplicatedTriangle)
{
    Extracted e = noise_mesh();
    const std::size_t t = e.mesh.triangle_count() / 2;
    // the copy goes right after the original, in the same cell layer
    std::vector<std::uint32_t> tri(e.mesh.triangles.begin(), e.mesh.triangles.end());
    tri.insert(tri.begin() + static_cast<std::ptrdiff_t>(3 * t + 3), tri.begin() + static_cast<std::ptrdiff_t>(3 * t),
               tri.begin() + static_cast<std::ptrdiff_t>(3 * t + 3));
    e.mesh.triangles.assign(tri.begin(), tri.end());
    for (auto& first : e.stats.plane_first_triangle)
        if (first > static_cast<std::int64_t>(t)) ++first;
    EXPECT_TRUE(expect_agrees(e.mesh, e.grid()));
    MeshCheckOptions o;
    const MeshCheck check = check_extracted_mesh(e.mesh, e.grid(), o);
    EXPECT_GT(check.geometry.intersecting_pairs, 0);
    EXPECT_GT(check.topology.nonmanifold_edges, 0);
}

TEST(ExtractedCheck, FindsTwoVerticesAtOnePosition)
{
    Extracted e = noise_mesh();
    // a vertex of triangle 50 moved onto the next corner's position
    const std::uint32_t a = e.mesh.triangles[150], b = e.mesh.triangles[151];
    for (int k = 0; k < 3; ++k) e.mesh.positions[3 * a + static_cast<std::size_t>(k)] = e.mesh.positions[3 * b + static_cast<std::size_t>(k)];
    EXPECT_FALSE(expect_agrees(e.mesh, e.grid())); // welding needs the general check
    EXPECT_GT(mesh_geometry(e.mesh).coincident_vertices, 0);
}

/// The cell whose box holds triangle t's centroid (the grid's spacing is 1, its origin 0).
std::array<int, 3> cell_of(const Mesh& m, std::size_t t)
{
    const std::uint32_t* c = &m.triangles[3 * t];
    std::array<int, 3> cell{};
    for (std::size_t k = 0; k < 3; ++k)
        cell[k] = static_cast<int>(std::floor((m.positions[3 * c[0] + k] + m.positions[3 * c[1] + k] + m.positions[3 * c[2] + k]) / 3));
    return cell;
}

/// `e`'s mesh with a copy of vertex u as vertex u + 1 (in u's plane; the ids after it move up by
/// one, the triangles keep their vertices), and the grid that says so.
struct WithCopy {
    const Extracted& original;
    Mesh mesh;
    std::vector<std::int64_t> first_vertex;
    ExtractedGrid grid() const
    {
        ExtractedGrid g = original.grid();
        g.plane_first_vertex = first_vertex;
        return g;
    }
};

WithCopy with_copy_of(const Extracted& e, std::uint32_t u)
{
    const Mesh& m = e.mesh;
    WithCopy c{e, m, e.stats.plane_first_vertex};
    c.mesh.positions.clear();
    c.mesh.normals.clear();
    for (std::uint32_t v = 0; v < m.vertex_count(); ++v) {
        for (std::size_t k = 0; k < 3; ++k) c.mesh.positions.push_back(m.positions[3 * v + k]);
        if (v == u)
            for (std::size_t k = 0; k < 3; ++k) c.mesh.positions.push_back(m.positions[3 * v + k]);
    }
    for (std::uint32_t& v : c.mesh.triangles)
        if (v > u) ++v;
    for (auto& f : c.first_vertex)
        if (f > static_cast<std::int64_t>(u)) ++f;
    return c;
}

TEST(ExtractedCheck, FindsAVertexSplitBetweenNeighbouringCells)
{
    // the triangles of one cell around an edge's vertex given a copy of it (a mesh not welded
    // there): the two ids meet only on the contact of neighbouring cells, where the structured
    // check must see them
    const Extracted original = noise_mesh();
    const Mesh& m = original.mesh;
    int split = 0;
    for (std::size_t t0 = 0; t0 < m.triangle_count() && split < 6; t0 += 193) {
        const std::uint32_t u = m.triangles[3 * t0];
        const std::array<int, 3> cell = cell_of(m, t0);
        WithCopy broken = with_copy_of(original, u);
        bool elsewhere = false; // u stays in a triangle of another cell
        for (std::size_t t = 0; t < m.triangle_count(); ++t)
            for (std::size_t q = 0; q < 3; ++q) {
                if (m.triangles[3 * t + q] != u) continue;
                if (cell_of(m, t) == cell) {
                    broken.mesh.triangles[3 * t + q] = u + 1;
                } else {
                    elsewhere = true;
                }
            }
        if (!elsewhere) continue;
        SCOPED_TRACE("vertex " + std::to_string(u));
        EXPECT_FALSE(expect_agrees(broken.mesh, broken.grid())); // welding needs the general check
        ++split;
    }
    EXPECT_EQ(split, 6);
}

TEST(ExtractedCheck, FindsCoincidentVerticesInCollapsedTriangles)
{
    // A triangle collapsed onto two ids (repeated corners). (a) (u', u', u) with u' a copy of u,
    // in a cell where no other triangle uses u: the two ids at one position meet in that
    // triangle only. (b) (u, u, w') with w' a copy of w, where a neighbouring cell's triangle
    // has the edge u w on the contact: that triangle's trace holds u twice, which is not the
    // other's trace {u, w}.
    const Extracted original = noise_mesh();
    const Mesh& m = original.mesh;
    const std::size_t n = m.triangle_count();
    std::vector<std::vector<std::size_t>> uses(m.vertex_count());
    for (std::size_t t = 0; t < n; ++t)
        for (std::size_t q = 0; q < 3; ++q) uses[m.triangles[3 * t + q]].push_back(t);
    const auto used_in_cell = [&](std::uint32_t v, const std::array<int, 3>& cell) {
        int count = 0;
        for (std::size_t t : uses[v]) count += cell_of(m, t) == cell ? 1 : 0;
        return count;
    };
    int lone = 0, traced = 0;
    for (std::size_t t = 0; t < n && (lone < 3 || traced < 3); ++t) {
        const std::array<int, 3> cell = cell_of(m, t);
        for (std::size_t q = 0; q < 3; ++q) {
            const std::uint32_t u = m.triangles[3 * t + q];
            if (lone < 3 && used_in_cell(u, cell) == 1 && uses[u].size() > 1) {
                WithCopy broken = with_copy_of(original, u);
                broken.mesh.triangles[3 * t] = broken.mesh.triangles[3 * t + 1] = u + 1;
                broken.mesh.triangles[3 * t + 2] = u;
                SCOPED_TRACE("(a) triangle " + std::to_string(t));
                EXPECT_FALSE(expect_agrees(broken.mesh, broken.grid()));
                ++lone;
            }
            const std::uint32_t w = m.triangles[3 * t + (q + 1) % 3];
            if (traced >= 3 || used_in_cell(w, cell) != 1) continue;
            // a triangle of another cell with the edge u w
            bool shared = false;
            for (std::size_t s : uses[u])
                if (s != t && cell_of(m, s) != cell)
                    for (std::size_t r = 0; r < 3; ++r) shared |= m.triangles[3 * s + r] == w;
            if (!shared) continue;
            WithCopy broken = with_copy_of(original, w);
            const std::uint32_t uu = u > w ? u + 1 : u;
            broken.mesh.triangles[3 * t] = broken.mesh.triangles[3 * t + 1] = uu;
            broken.mesh.triangles[3 * t + 2] = w + 1;
            SCOPED_TRACE("(b) triangle " + std::to_string(t));
            EXPECT_FALSE(expect_agrees(broken.mesh, broken.grid()));
            ++traced;
        }
    }
    EXPECT_EQ(lone, 3);
    EXPECT_EQ(traced, 3);
}

TEST(ExtractedCheck, AMeshThatDoesNotFitTheLayoutGetsTheGeneralChecks)
{
    Extracted e = noise_mesh();
    std::vector<std::int64_t> wrong = e.stats.plane_first_vertex;
    for (std::size_t k = 1; k + 1 < wrong.size(); ++k) wrong[k] += 3; // planes said to start later than they do
    ExtractedGrid grid = e.grid();
    grid.plane_first_vertex = wrong;
    EXPECT_FALSE(expect_agrees(e.mesh, grid));
    grid = e.grid();
    grid.plane_first_triangle = {}; // no layout (cmc33_paper's refined grid)
    EXPECT_FALSE(expect_agrees(e.mesh, grid));
    // the triangles of two layers swapped: ids outside a slab's reach
    Extracted f = noise_mesh();
    std::vector<std::uint32_t> tri(f.mesh.triangles.begin(), f.mesh.triangles.end());
    std::swap_ranges(tri.begin(), tri.begin() + 30, tri.end() - 30);
    f.mesh.triangles.assign(tri.begin(), tri.end());
    EXPECT_FALSE(expect_agrees(f.mesh, f.grid()));
}

TEST(ExtractedCheck, ProgressEndsAtOneAndFalseCancels)
{
    Extracted e = noise_mesh();
    MeshCheckOptions o;
    double last = -1;
    bool increasing = true;
    o.progress = [&](double f) {
        increasing = increasing && f >= last;
        last = f;
        return true;
    };
    EXPECT_TRUE(check_extracted_mesh(e.mesh, e.grid(), o).structured);
    EXPECT_TRUE(increasing);
    EXPECT_EQ(last, 1.0);
    o.progress = [](double) { return false; };
    try {
        (void)check_extracted_mesh(e.mesh, e.grid(), o);
        ADD_FAILURE() << "no exception";
    } catch (const Error& error) {
        EXPECT_EQ(error.status(), Status::cancelled);
    }
}

TEST(ExtractedCheck, TheLayoutIsThePlanesOfThePasses)
{
    Extracted e = noise_mesh();
    const auto nz = static_cast<std::size_t>(e.volume.dims()[2]);
    ASSERT_EQ(e.stats.plane_first_vertex.size(), nz + 1);
    ASSERT_EQ(e.stats.plane_first_triangle.size(), nz + 1);
    EXPECT_EQ(e.stats.plane_first_vertex.back(), static_cast<std::int64_t>(e.mesh.vertex_count()));
    EXPECT_EQ(e.stats.plane_first_triangle.back(), static_cast<std::int64_t>(e.mesh.triangle_count()));
    EXPECT_EQ(e.stats.plane_first_triangle[nz - 1], e.stats.plane_first_triangle[nz]); // no cells above the last plane
    // cmc33_paper where it does not refine (test_paper.cpp checks there is none where it does)
    Extracted p = extracted(random_field(FieldKind::grid, 5, 3, 8), 0.0, Method::cmc33_paper);
    ASSERT_EQ(p.stats.refinement_planes, 0);
    EXPECT_EQ(p.stats.plane_first_vertex.size(), static_cast<std::size_t>(p.volume.dims()[2]) + 1);
    EXPECT_TRUE(expect_agrees(p.mesh, p.grid()));
}

} // namespace
