// extract() on whole grids: analytic surfaces, ties on integer data, determinism across thread
// counts, typed and strided views, errors, and agreement with the independent field topology.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/topology.hpp"
#include "test_support.hpp"

namespace {

using cmc33::ExtractOptions;
using cmc33::Method;
using cmc33::Volume;

const Method kMethods[] = {Method::cmc33, Method::mc33_lewiner, Method::mc, Method::chernyaev};

/// Methods with the embedded table set: manifold and embedded by construction. The others use
/// Chernyaev's tubes, which lie in a cell face and meet a neighbour's there (Custodio et al. 2013,
/// Sec. 5.2): tests/core/test_paper.cpp shows those flaws.
bool embedded_tubes(Method m)
{
    return m == Method::cmc33 || m == Method::mc;
}

Volume sphere(int n, double r)
{
    const double c = (n - 1) / 2.0;
    return cmc33::test::make_volume({n, n, n}, [&](auto i, auto j, auto k) {
        return std::sqrt((i - c) * (i - c) + (j - c) * (j - c) + (k - c) * (k - c)) - r;
    });
}

Volume torus(int n, double major, double minor)
{
    const double c = (n - 1) / 2.0;
    return cmc33::test::make_volume({n, n, n}, [&](auto i, auto j, auto k) {
        const double x = i - c, y = j - c, z = k - c;
        const double q = std::sqrt(x * x + y * y) - major;
        return std::sqrt(q * q + z * z) - minor;
    });
}

Volume noise(cmc33::Index3 dims, std::uint64_t seed)
{
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    return cmc33::test::make_volume(dims, [&](auto, auto, auto) { return u(rng); });
}

void expect_closed_manifold(const cmc33::Mesh& mesh, std::int64_t euler, std::int64_t components)
{
    const auto t = cmc33::mesh_topology(mesh);
    EXPECT_EQ(t.nonmanifold_edges, 0);
    EXPECT_EQ(t.nonmanifold_vertices, 0);
    EXPECT_EQ(t.boundary_edges, 0);
    EXPECT_EQ(t.degenerate_triangles, 0);
    EXPECT_TRUE(t.oriented);
    EXPECT_EQ(t.euler, euler);
    EXPECT_EQ(t.components, components);
    EXPECT_EQ(t.vertices, static_cast<std::int64_t>(mesh.vertex_count())); // no unused vertex
}

TEST(Extract, SphereAndTorusForEveryMethod)
{
    for (Method m : kMethods) {
        SCOPED_TRACE(std::string(cmc33::method_name(m)));
        expect_closed_manifold(cmc33::extract(sphere(24, 8.3), 0.0, {m}), 2, 1);
        expect_closed_manifold(cmc33::extract(torus(32, 9.0, 3.7), 0.0, {m}), 0, 1);
    }
}

TEST(Extract, NormalsPointFromAboveToBelow)
{
    const Volume v = sphere(20, 6.5); // above = outside the sphere, so normals point inwards
    ExtractOptions opt;
    opt.normals = true;
    const cmc33::Mesh mesh = cmc33::extract(v, 0.0, opt);
    ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
    const double c = 9.5;
    for (std::size_t i = 0; i < mesh.vertex_count(); ++i) {
        const double n[3] = {double(mesh.normals[3 * i]), double(mesh.normals[3 * i + 1]), double(mesh.normals[3 * i + 2])};
        const double p[3] = {double(mesh.positions[3 * i]), double(mesh.positions[3 * i + 1]), double(mesh.positions[3 * i + 2])};
        EXPECT_NEAR(std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), 1.0, 1e-5);
        EXPECT_LT(n[0] * (p[0] - c) + n[1] * (p[1] - c) + n[2] * (p[2] - c), 0.0);
    }
    // and triangles wind counter-clockwise around those normals
    double agree = 0;
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        const auto at = [&](const cmc33::Buffer<float>& xs, std::size_t corner, int k) {
            return static_cast<double>(xs[3 * mesh.triangles[3 * t + corner] + static_cast<std::size_t>(k)]);
        };
        double u[3], w[3], n[3];
        for (int k = 0; k < 3; ++k) {
            u[k] = at(mesh.positions, 1, k) - at(mesh.positions, 0, k);
            w[k] = at(mesh.positions, 2, k) - at(mesh.positions, 0, k);
            n[k] = at(mesh.normals, 0, k);
        }
        const double g[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
        agree += (g[0] * n[0] + g[1] * n[1] + g[2] * n[2]) > 0;
    }
    EXPECT_EQ(agree, static_cast<double>(mesh.triangle_count()));
}

TEST(Extract, WorldCoordinatesFollowSpacingAndOrigin)
{
    Volume v = sphere(16, 5.2);
    v.set_spacing({0.5, 2.0, 1.5});
    v.set_origin({10, -3, 7});
    const cmc33::Mesh a = cmc33::extract(sphere(16, 5.2), 0.0);
    const cmc33::Mesh b = cmc33::extract(v, 0.0);
    ASSERT_EQ(a.positions.size(), b.positions.size());
    for (std::size_t i = 0; i < a.positions.size(); i += 3) {
        EXPECT_FLOAT_EQ(b.positions[i], static_cast<float>(10 + 0.5 * static_cast<double>(a.positions[i])));
        EXPECT_FLOAT_EQ(b.positions[i + 1], static_cast<float>(-3 + 2.0 * static_cast<double>(a.positions[i + 1])));
        EXPECT_FLOAT_EQ(b.positions[i + 2], static_cast<float>(7 + 1.5 * static_cast<double>(a.positions[i + 2])));
    }
    EXPECT_EQ(a.triangles, b.triangles);
}

TEST(Extract, ByteIdenticalForEveryThreadCount)
{
    for (const Volume& v : {noise({23, 17, 19}, 7), torus(30, 8, 3)}) {
        for (Method m : kMethods) {
            ExtractOptions opt{m, true, 1};
            const cmc33::Mesh one = cmc33::extract(v, 0.0, opt);
            for (int threads : {2, 7}) {
                opt.threads = threads;
                const cmc33::Mesh many = cmc33::extract(v, 0.0, opt);
                EXPECT_EQ(one.positions, many.positions);
                EXPECT_EQ(one.normals, many.normals);
                EXPECT_EQ(one.triangles, many.triangles);
            }
        }
    }
}

TEST(Extract, ReusedMeshBlocksHoldNoTraceOfTheirLastMesh)
{
    // Buffer keeps freed blocks of 1 to 16 MiB for the next allocation of their size
    // (src/base/buffer.cpp): a mesh written into a block another mesh left dirty is the same
    const Volume v = sphere(160, 72.0);
    const ExtractOptions opt{Method::cmc33, true, 2};
    const cmc33::Mesh first = cmc33::extract(v, 0.0, opt);
    ASSERT_GE(first.positions.size() * sizeof(float), std::size_t{1} << 20); // a large block
    std::vector<const void*> freed;
    {
        cmc33::Mesh dirty = cmc33::extract(v, 0.0, opt);
        std::fill(dirty.positions.begin(), dirty.positions.end(), std::numeric_limits<float>::quiet_NaN());
        std::fill(dirty.normals.begin(), dirty.normals.end(), -7.0f);
        std::fill(dirty.triangles.begin(), dirty.triangles.end(), 0xdeadbeefu);
        freed = {dirty.positions.data(), dirty.normals.data(), dirty.triangles.data()};
    }
    const cmc33::Mesh again = cmc33::extract(v, 0.0, opt);
    // the new mesh's arrays are in the blocks the dirty one freed (in some order)
    for (const void* p : {static_cast<const void*>(again.positions.data()), static_cast<const void*>(again.normals.data()),
                          static_cast<const void*>(again.triangles.data())}) {
        EXPECT_NE(std::find(freed.begin(), freed.end(), p), freed.end());
    }
    EXPECT_EQ(first.positions, again.positions);
    EXPECT_EQ(first.normals, again.normals);
    EXPECT_EQ(first.triangles, again.triangles);
}

TEST(Extract, IntegerTiesHaveNoHolesAndNoNonManifoldEdges)
{
    // uint8 samples drawn from {60, 80, 100} at iso 80: a third of the samples equal iso.
    std::mt19937_64 rng(3);
    for (int trial = 0; trial < 20; ++trial) {
        Volume v(cmc33::ScalarType::u8, {12, 11, 10});
        std::uint8_t* p = v.samples<std::uint8_t>();
        for (std::int64_t i = 0; i < v.sample_count(); ++i) p[i] = static_cast<std::uint8_t>(60 + 20 * (rng() % 3));
        for (Method m : kMethods) {
            const cmc33::Mesh mesh = cmc33::extract(v, 80.0, {m});
            const auto t = cmc33::mesh_topology(mesh);
            if (embedded_tubes(m)) {
                EXPECT_EQ(t.nonmanifold_edges, 0);
                EXPECT_EQ(t.nonmanifold_vertices, 0);
            }
            EXPECT_EQ(t.degenerate_triangles, 0);
            EXPECT_TRUE(t.oriented);
            // boundary edges only on the volume's outer faces
            const auto on_box = [&](std::uint32_t id) {
                const float* q = &mesh.positions[3 * id];
                return q[0] == 0 || q[0] == 11 || q[1] == 0 || q[1] == 10 || q[2] == 0 || q[2] == 9;
            };
            std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
            for (std::size_t f = 0; f < mesh.triangle_count(); ++f)
                for (int s = 0; s < 3; ++s) {
                    const auto a = mesh.triangles[3 * f + s], b = mesh.triangles[3 * f + (s + 1) % 3];
                    edges.emplace_back(std::min(a, b), std::max(a, b));
                }
            std::sort(edges.begin(), edges.end());
            for (std::size_t e = 0; e < edges.size(); ++e) {
                const bool single = (e == 0 || edges[e - 1] != edges[e]) && (e + 1 == edges.size() || edges[e + 1] != edges[e]);
                if (single) {
                    EXPECT_TRUE(on_box(edges[e].first) && on_box(edges[e].second));
                }
            }
            // the same as iso a hair lower on float data (the sign rule)
            Volume f(cmc33::ScalarType::f32, v.dims());
            for (std::int64_t i = 0; i < v.sample_count(); ++i) f.samples<float>()[i] = p[i];
            const auto tf = cmc33::mesh_topology(cmc33::extract(f, 80.0 - 1e-3, {m}));
            EXPECT_EQ(tf.euler, t.euler);
            EXPECT_EQ(tf.components, t.components);
            EXPECT_EQ(tf.faces, t.faces);
        }
    }
}

// Ties in space (docs/conventions.md, "Geometry"): the mesh of every method with embedded tubes is
// embedded, and every method's vertices keep at least delta = 2^-10 of an edge away from every
// sample; welding by position changes nothing.
TEST(Extract, TiesAreEmbeddedAndStayOffTheSamples)
{
    std::mt19937_64 rng(11);
    for (int trial = 0; trial < 30; ++trial) {
        Volume v(cmc33::ScalarType::u8, {9, 8, 7}, {0.5, 1, 2}, {-3, 0, 10});
        std::uint8_t* p = v.samples<std::uint8_t>();
        for (std::int64_t i = 0; i < v.sample_count(); ++i) p[i] = static_cast<std::uint8_t>(78 + rng() % 5); // 78..82
        for (Method m : kMethods) {
            const cmc33::Mesh mesh = cmc33::extract(v, 80.0, {m});
            const cmc33::MeshGeometry g = cmc33::mesh_geometry(mesh);
            const auto t = cmc33::mesh_topology(mesh);
            EXPECT_EQ(g.coincident_vertices, 0);
            EXPECT_EQ(g.zero_area_triangles, 0);
            EXPECT_EQ(g.welded.euler, t.euler);
            EXPECT_EQ(g.welded.components, t.components);
            if (embedded_tubes(m)) {
                EXPECT_EQ(g.intersecting_pairs, 0) << cmc33::method_name(m);
                EXPECT_EQ(g.welded.nonmanifold_edges, 0);
            }
            for (std::size_t q = 0; q < mesh.vertex_count(); ++q) {
                // grid coordinates; the distance to the nearest sample along each axis
                const double x[3] = {(static_cast<double>(mesh.positions[3 * q]) + 3.0) / 0.5,
                                     static_cast<double>(mesh.positions[3 * q + 1]) / 1.0,
                                     (static_cast<double>(mesh.positions[3 * q + 2]) - 10.0) / 2.0};
                double off = 0;
                for (double c : x) off = std::max(off, std::fabs(c - std::round(c)));
                ASSERT_GE(off, 0x1p-10 * 0.999) << "vertex " << q << " sits on a sample";
            }
        }
    }
}

// A sample exactly at the isovalue whose neighbours are all below is a component of its own (the
// sign rule counts it as above): a closed surface around it, delta of an edge away, not a point.
TEST(Extract, ABumpExactlyAtTheIsovalueIsATinyClosedSurface)
{
    Volume v(cmc33::ScalarType::u8, {3, 3, 3});
    std::uint8_t* p = v.samples<std::uint8_t>();
    for (std::int64_t i = 0; i < 27; ++i) p[i] = 60;
    p[13] = 80; // the centre
    const cmc33::Mesh mesh = cmc33::extract(v, 80.0);
    expect_closed_manifold(mesh, 2, 1);
    EXPECT_EQ(mesh.vertex_count(), 6u);
    for (std::size_t q = 0; q < mesh.vertex_count(); ++q) {
        double d = 0;
        for (int c = 0; c < 3; ++c) d += std::fabs(static_cast<double>(mesh.positions[3 * q + static_cast<std::size_t>(c)]) - 1.0);
        EXPECT_DOUBLE_EQ(d, 0x1p-10);
    }
    EXPECT_TRUE(cmc33::mesh_geometry(mesh).embedded());
    const cmc33::FieldTopology f = cmc33::field_topology(v, 80.0);
    EXPECT_EQ(f.b0, 1);
    EXPECT_EQ(f.euler, 2);
}

// Tunnels on random grids: every tube is embedded, whatever the crossings (here pushed to the ends
// of their edges by values of very different magnitudes).
TEST(Extract, TubesAreEmbeddedForExtremeCrossings)
{
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(-1, 1);
    std::int64_t tubes = 0;
    for (int trial = 0; trial < 400; ++trial) {
        const Volume v = cmc33::test::make_volume({5, 5, 5}, [&](auto, auto, auto) {
            const double x = u(rng);
            return (x < 0 ? -1 : 1) * std::pow(10.0, -5 * std::fabs(u(rng)));
        });
        cmc33::ExtractStats stats;
        const cmc33::Mesh mesh = cmc33::extract(v, 0.0, {}, &stats);
        for (const char* name : {"4.1.2", "6.1.2", "7.4.2", "10.1.2", "12.1.2", "13.5.2"})
            for (int s = 0; s < cmc33::kSubcaseCount; ++s)
                if (cmc33::subcase_name(s) == name) tubes += stats.cells_per_subcase[static_cast<std::size_t>(s)];
        const cmc33::MeshGeometry g = cmc33::mesh_geometry(mesh);
        ASSERT_TRUE(g.embedded()) << "trial " << trial << ": " << g.intersecting_pairs << " intersecting pairs";
    }
    EXPECT_GT(tubes, 100);
}

TEST(Extract, TypedAndStridedViewsGiveTheSameMesh)
{
    std::mt19937_64 rng(11);
    Volume u8(cmc33::ScalarType::u8, {9, 8, 7}), f64(cmc33::ScalarType::f64, {9, 8, 7});
    for (std::int64_t i = 0; i < u8.sample_count(); ++i) {
        const auto x = static_cast<std::uint8_t>(rng() % 200);
        u8.samples<std::uint8_t>()[i] = x;
        f64.samples<double>()[i] = x;
    }
    const cmc33::Mesh a = cmc33::extract(u8, 99.5), b = cmc33::extract(f64, 99.5);
    EXPECT_EQ(a.positions, b.positions);
    EXPECT_EQ(a.triangles, b.triangles);
    // a sub-block view of a larger array, no copy
    std::vector<double> big(20 * 20 * 20, 500.0);
    for (int k = 0; k < 7; ++k)
        for (int j = 0; j < 8; ++j)
            for (int i = 0; i < 9; ++i) big[static_cast<std::size_t>((i + 3) + 20 * ((j + 2) + 20 * (k + 1)))] = f64.samples<double>()[i + 9 * (j + 8 * k)];
    cmc33::GridView<double> view{&big[3 + 20 * (2 + 20 * 1)], {9, 8, 7}, {1, 20, 400}, {1, 1, 1}, {0, 0, 0}};
    const cmc33::Mesh c = cmc33::extract(view, 99.5);
    EXPECT_EQ(a.positions, c.positions);
    EXPECT_EQ(a.triangles, c.triangles);
}

// Ties in float data ({60, 80, 100} at 80, and the same halved at 40) are settled by the exact
// integer path after the filter gives up: the same tilings as the uint8 grid, so the same
// triangles, and the same positions up to the halving.
TEST(Extract, FloatTiesAreDecidedLikeTheirIntegerGrid)
{
    std::mt19937_64 rng(17);
    const std::uint8_t values[3] = {60, 80, 100};
    for (int g = 0; g < 20; ++g) {
        Volume u8(cmc33::ScalarType::u8, {9, 8, 7}), f32(cmc33::ScalarType::f32, {9, 8, 7});
        Volume half(cmc33::ScalarType::f32, {9, 8, 7});
        for (std::int64_t i = 0; i < u8.sample_count(); ++i) {
            const std::uint8_t x = values[rng() % 3];
            u8.samples<std::uint8_t>()[i] = x;
            f32.samples<float>()[i] = x;
            half.samples<float>()[i] = x / 2.0f;
        }
        const cmc33::Mesh a = cmc33::extract(u8, 80.0), b = cmc33::extract(f32, 80.0), c = cmc33::extract(half, 40.0);
        ASSERT_EQ(a.triangles, b.triangles) << "grid " << g;
        ASSERT_EQ(a.positions, b.positions) << "grid " << g;
        ASSERT_EQ(a.triangles, c.triangles) << "grid " << g;
        EXPECT_EQ(cmc33::mesh_topology(b).nonmanifold_edges, 0) << "grid " << g;
    }
}

TEST(Extract, RejectsNonFiniteAndTooSmallGrids)
{
    Volume v(cmc33::ScalarType::f32, {4, 4, 4});
    v.samples<float>()[5] = std::numeric_limits<float>::quiet_NaN();
    v.samples<float>()[9] = std::numeric_limits<float>::infinity();
    try {
        cmc33::extract(v, 0.0);
        FAIL() << "no error";
    } catch (const cmc33::Error& e) {
        EXPECT_EQ(e.status(), cmc33::Status::non_finite);
        EXPECT_NE(std::string(e.what()).find("2 samples"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("(1, 1, 0)"), std::string::npos) << e.what();
    }
    EXPECT_THROW(cmc33::extract(sphere(5, 1), std::nan("")), cmc33::Error);
    EXPECT_THROW(cmc33::extract(Volume(cmc33::ScalarType::u8, {1, 5, 5}), 1.0), cmc33::Error);

    // a NaN in a cell with face and interior tests (f = i + j + k - 10 has ambiguous cells once a
    // sample is NaN): refused before any decision reaches it (GMP raised SIGFPE on NaN), for every
    // method and thread count
    Volume d(cmc33::ScalarType::f64, {6, 5, 20});
    double* x = d.samples<double>();
    for (std::int64_t k = 0; k < 20; ++k)
        for (std::int64_t j = 0; j < 5; ++j)
            for (std::int64_t i = 0; i < 6; ++i) x[i + 6 * (j + 5 * k)] = static_cast<double>(i + j + k) - 10.0;
    x[3 + 6 * (2 + 5 * 7)] = std::numeric_limits<double>::quiet_NaN();
    for (const cmc33::Method method : {cmc33::Method::cmc33, cmc33::Method::mc33_lewiner, cmc33::Method::mc}) {
        for (const int threads : {1, 3}) {
            cmc33::ExtractOptions opt;
            opt.method = method;
            opt.threads = threads;
            try {
                cmc33::extract(d, 0.5, opt);
                FAIL() << "no error";
            } catch (const cmc33::Error& e) {
                EXPECT_EQ(e.status(), cmc33::Status::non_finite);
                EXPECT_NE(std::string(e.what()).find("(3, 2, 7)"), std::string::npos) << e.what();
            }
        }
    }
}

// The mesh of cmc33 has the topology of the trilinear interpolant's level set; the earlier
// methods do not always (Custodio et al. 2013). Compared with the independent field topology.
TEST(Extract, RandomGridsMatchTheFieldTopology)
{
    int mismatches[4] = {0, 0, 0, 0};
    int undetermined = 0;
    for (std::uint64_t seed = 0; seed < 400; ++seed) {
        const Volume v = noise({5, 5, 5}, 1000 + seed);
        const auto field = cmc33::field_topology(v, 0.0);
        if (!field.determined) {
            ++undetermined;
            continue;
        }
        for (int m = 0; m < 4; ++m) {
            const auto t = cmc33::mesh_topology(cmc33::extract(v, 0.0, {kMethods[m]}));
            if (kMethods[m] == Method::cmc33) {
                EXPECT_EQ(t.nonmanifold_edges, 0);
                EXPECT_EQ(t.nonmanifold_vertices, 0);
            }
            const bool match = t.euler == field.euler && t.components == field.b0 && t.b1 == field.b1 &&
                               t.closed_components == field.b2 && t.boundary_loops == field.boundary_loops;
            mismatches[m] += !match;
            if (kMethods[m] == Method::cmc33) {
                EXPECT_TRUE(match) << "seed " << 1000 + seed;
            }
        }
    }
    EXPECT_LE(undetermined, 4);
    EXPECT_EQ(mismatches[0], 0);
    EXPECT_GT(mismatches[2], 0) << "classic Marching Cubes should disagree on random grids";
}

} // namespace

namespace {

/// The mesh of `v` at `iso` has the field's topology and is a manifold.
::testing::AssertionResult matches_field(const Volume& v, double iso)
{
    const cmc33::Mesh mesh = cmc33::extract(v, iso);
    const cmc33::MeshTopology t = cmc33::mesh_topology(mesh);
    const cmc33::FieldTopology f = cmc33::field_topology(v, iso);
    if (!f.determined) return ::testing::AssertionFailure() << "field undetermined: " << f.why;
    if (t.nonmanifold_edges != 0 || t.nonmanifold_vertices != 0) return ::testing::AssertionFailure() << "non-manifold";
    if (t.euler != f.euler || t.components != f.b0 || t.b1 != f.b1 || t.closed_components != f.b2 ||
        t.boundary_loops != f.boundary_loops) {
        return ::testing::AssertionFailure() << "mesh chi " << t.euler << " b0 " << t.components << " loops "
                                             << t.boundary_loops << ", field chi " << f.euler << " b0 " << f.b0
                                             << " loops " << f.boundary_loops;
    }
    return ::testing::AssertionSuccess();
}

} // namespace

// Near-ties that rounding cannot settle: samples k/3, k/5, k/10 as doubles (an exact zero such as
// 1/3 - 2/3 + 1/3 rounds to 1e-17), and float samples against an isovalue float cannot hold (0.1).
// Every sign is decided exactly (filtered, then GMP), as the verifier decides it.
TEST(Extract, DecimalNearTiesMatchTheFieldTopology)
{
    std::mt19937_64 rng(2026);
    for (int den : {3, 5, 10}) {
        std::uniform_int_distribution<int> pick(-den, den);
        for (int g = 0; g < 400; ++g) {
            Volume v(cmc33::ScalarType::f64, {5, 5, 5});
            for (std::int64_t i = 0; i < v.sample_count(); ++i) v.samples<double>()[i] = pick(rng) / static_cast<double>(den);
            ASSERT_TRUE(matches_field(v, 0.0)) << "den " << den << " grid " << g;
        }
    }
    std::uniform_int_distribution<int> tenths(-5, 7);
    for (int g = 0; g < 400; ++g) {
        Volume v(cmc33::ScalarType::f32, {5, 5, 5});
        for (std::int64_t i = 0; i < v.sample_count(); ++i) v.samples<float>()[i] = static_cast<float>(tenths(rng)) / 10.0f;
        ASSERT_TRUE(matches_field(v, 0.1)) << "float grid " << g;
    }
}

// Integer samples take an exact 128-bit path when |sample - iso| <= 2^15 (after scaling a
// half-integer isovalue by 2), and the filtered path otherwise: both against the verifier, on
// few distinct values (many exact ties) and on wide ones.
TEST(Extract, IntegerDataMatchesTheFieldTopologyOnBothExactPaths)
{
    std::mt19937_64 rng(33);
    std::uniform_int_distribution<int> narrow(77, 83), wide(-100000, 100000);
    for (int g = 0; g < 300; ++g) {
        Volume u8(cmc33::ScalarType::u8, {5, 5, 5});
        Volume i32(cmc33::ScalarType::i32, {5, 5, 5});
        for (std::int64_t i = 0; i < u8.sample_count(); ++i) {
            u8.samples<std::uint8_t>()[i] = static_cast<std::uint8_t>(narrow(rng));
            i32.samples<std::int32_t>()[i] = wide(rng);
        }
        ASSERT_TRUE(matches_field(u8, 80.0)) << "uint8 grid " << g;
        ASSERT_TRUE(matches_field(u8, 80.5)) << "uint8 grid " << g << " at 80.5";
        ASSERT_TRUE(matches_field(u8, 80.3)) << "uint8 grid " << g << " at 80.3";
        ASSERT_TRUE(matches_field(i32, 0.0)) << "int32 grid " << g;
    }
}

// Rows wider than 7281 samples have no short tilings (their 16-bit offsets would not fit): every
// cell takes the general path; on both sides of that width the mesh has the field's topology.
TEST(Extract, GridsTooWideForShortTilingsMatchTheFieldTopology)
{
    std::mt19937_64 rng(7281);
    std::uniform_int_distribution<int> narrow(77, 83);
    for (const std::int64_t nx : {7281, 7282, 8000}) {
        Volume u8(cmc33::ScalarType::u8, {nx, 3, 3});
        for (std::int64_t i = 0; i < u8.sample_count(); ++i) u8.samples<std::uint8_t>()[i] = static_cast<std::uint8_t>(narrow(rng));
        EXPECT_TRUE(matches_field(u8, 80.5)) << "nx " << nx;
        EXPECT_TRUE(matches_field(u8, 80.0)) << "nx " << nx << " at 80";
    }
}

// Values so small that the verifier's products underflow (1e-100^4): the extractor's exact
// decisions do not care about scale (same mesh topology as the grid scaled by 2^332), and the
// verifier must either say "undetermined" or agree, never silently lose an underflowed product.
TEST(Extract, TinyValuesAreDecidedLikeTheirRescaledGrid)
{
    std::mt19937_64 rng(5);
    std::uniform_int_distribution<int> pick(-2, 2);
    int determined = 0;
    for (int g = 0; g < 300; ++g) {
        Volume tiny(cmc33::ScalarType::f64, {5, 5, 5}), rescaled(cmc33::ScalarType::f64, {5, 5, 5});
        for (std::int64_t i = 0; i < tiny.sample_count(); ++i) {
            tiny.samples<double>()[i] = pick(rng) / 3.0 * 1e-100;
            rescaled.samples<double>()[i] = std::ldexp(tiny.samples<double>()[i], 332);
        }
        ASSERT_TRUE(matches_field(rescaled, 0.0)) << "grid " << g;
        const cmc33::MeshTopology a = cmc33::mesh_topology(cmc33::extract(tiny, 0.0));
        const cmc33::MeshTopology b = cmc33::mesh_topology(cmc33::extract(rescaled, 0.0));
        EXPECT_EQ(a.euler, b.euler);
        EXPECT_EQ(a.components, b.components);
        EXPECT_EQ(a.boundary_loops, b.boundary_loops);
        const cmc33::FieldTopology f = cmc33::field_topology(tiny, 0.0);
        if (f.determined) {
            ++determined;
            EXPECT_TRUE(matches_field(tiny, 0.0)) << "grid " << g;
        }
    }
    RecordProperty("determined_tiny_grids", determined);
}
