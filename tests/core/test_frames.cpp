// extract() in world frames (volume.hpp): flipped, permuted and oblique direction matrices give
// the identity-frame mesh moved by the frame, with normals mapped and the winding reversed when
// the frame mirrors; and samples near +-1e308, whose differences overflow, give the same mesh as
// the grid scaled down by 2^-1000 exactly.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/topology.hpp"
#include "test_support.hpp"

namespace {

using cmc33::ExtractOptions;
using cmc33::GridView;
using cmc33::Mat3;
using cmc33::Mesh;
using cmc33::Vec3;
using cmc33::Volume;

/// Two blobs and a saddle region: ambiguous faces and interior tests, not symmetric in any axis.
Volume blobs()
{
    return cmc33::test::make_volume({13, 11, 9}, [](auto i, auto j, auto k) {
        const double x = static_cast<double>(i), y = static_cast<double>(j), z = static_cast<double>(k);
        const double a = std::hypot(x - 4.2, y - 4.7, z - 3.9) - 3.1;
        const double b = std::hypot(x - 8.9, y - 5.6, z - 4.4) - 2.7;
        return std::min(a, b) + 0.35 * std::sin(1.3 * x + 0.7 * y - 0.4 * z);
    });
}

Mesh extract_in(const Volume& v, const Vec3& spacing, const Vec3& origin, const Mat3& direction)
{
    const GridView<double> g = GridView<double>::dense(v.samples<double>(), v.dims(), spacing, origin, direction);
    ExtractOptions opt;
    opt.normals = true;
    return cmc33::extract(g, 0.0, opt);
}

/// Triangles whose winding agrees with their first vertex's normal (counter-clockwise seen from
/// the side the normal points to), as a fraction of all triangles.
double winding_agreement(const Mesh& mesh)
{
    std::size_t agree = 0;
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        const auto at = [&](const cmc33::Buffer<float>& xs, std::size_t corner, std::size_t k) {
            return static_cast<double>(xs[3 * mesh.triangles[3 * t + corner] + k]);
        };
        double u[3], w[3], n[3];
        for (std::size_t k = 0; k < 3; ++k) {
            u[k] = at(mesh.positions, 1, k) - at(mesh.positions, 0, k);
            w[k] = at(mesh.positions, 2, k) - at(mesh.positions, 0, k);
            n[k] = at(mesh.normals, 0, k);
        }
        const double g[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
        agree += (g[0] * n[0] + g[1] * n[1] + g[2] * n[2]) > 0;
    }
    return static_cast<double>(agree) / static_cast<double>(mesh.triangle_count());
}

void expect_same_topology(const Mesh& a, const Mesh& b)
{
    const cmc33::MeshTopology ta = cmc33::mesh_topology(a), tb = cmc33::mesh_topology(b);
    EXPECT_EQ(ta.euler, tb.euler);
    EXPECT_EQ(ta.components, tb.components);
    EXPECT_EQ(ta.boundary_loops, tb.boundary_loops);
    EXPECT_EQ(ta.nonmanifold_edges, 0);
    EXPECT_TRUE(ta.oriented);
    EXPECT_TRUE(tb.oriented);
}

/// b's triangles are a's with every winding reversed.
void expect_reversed(const Mesh& a, const Mesh& b)
{
    ASSERT_EQ(a.triangles.size(), b.triangles.size());
    for (std::size_t t = 0; t < a.triangles.size(); t += 3) {
        ASSERT_EQ(b.triangles[t], a.triangles[t]) << "triangle " << t / 3;
        ASSERT_EQ(b.triangles[t + 1], a.triangles[t + 2]) << "triangle " << t / 3;
        ASSERT_EQ(b.triangles[t + 2], a.triangles[t + 1]) << "triangle " << t / 3;
    }
}

TEST(Frames, AFlippedAxisMirrorsTheMeshAndReversesItsTriangles)
{
    const Volume v = blobs();
    const Vec3 spacing{1, 1, 3};
    const Mesh a = extract_in(v, spacing, {0, 0, 0}, cmc33::kIdentity3);
    const Mesh b = extract_in(v, spacing, {0, 0, 0}, Mat3{{{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}}});
    ASSERT_GT(a.triangle_count(), 100u);
    ASSERT_EQ(a.positions.size(), b.positions.size());
    for (std::size_t i = 0; i < a.positions.size(); i += 3) {
        // x -> -x exactly; the normal's x too (the gradient is divided by -1 * spacing)
        EXPECT_EQ(b.positions[i], -a.positions[i]);
        EXPECT_EQ(b.positions[i + 1], a.positions[i + 1]);
        EXPECT_EQ(b.positions[i + 2], a.positions[i + 2]);
        EXPECT_EQ(b.normals[i], -a.normals[i]);
        EXPECT_EQ(b.normals[i + 1], a.normals[i + 1]);
        EXPECT_EQ(b.normals[i + 2], a.normals[i + 2]);
    }
    expect_reversed(a, b);
    expect_same_topology(a, b);
    // the orientation rule of docs/conventions.md holds in world space in both
    EXPECT_GT(winding_agreement(a), 0.98);
    EXPECT_GT(winding_agreement(b), 0.98);
}

TEST(Frames, PermutedAxesPermuteTheMesh)
{
    const Volume v = blobs();
    const Vec3 spacing{0.5, 2, 1.25};
    const Mesh a = extract_in(v, spacing, {0, 0, 0}, cmc33::kIdentity3);
    // world = (index y, index z, index x) scaled: a cyclic permutation (det +1) and a swap (det -1)
    const Mat3 cyclic{{{0, 1, 0}, {0, 0, 1}, {1, 0, 0}}};
    const Mat3 swap{{{0, 1, 0}, {1, 0, 0}, {0, 0, 1}}};
    for (const Mat3& p : {cyclic, swap}) {
        const bool mirror = cmc33::determinant(p) < 0;
        SCOPED_TRACE(mirror ? "swap" : "cyclic");
        const Vec3 origin{3, -4, 5};
        const Mesh b = extract_in(v, spacing, origin, p);
        ASSERT_EQ(a.positions.size(), b.positions.size());
        for (std::size_t i = 0; i < a.positions.size(); i += 3) {
            for (std::size_t r = 0; r < 3; ++r) {
                // row r of p picks one axis: world r = origin r + a's coordinate on that axis
                std::size_t c = 0;
                while (p[r][c] == 0) ++c;
                EXPECT_NEAR(b.positions[i + r], origin[r] + static_cast<double>(a.positions[i + c]), 2e-6);
                EXPECT_NEAR(b.normals[i + r], a.normals[i + c], 1e-6);
            }
        }
        if (mirror) {
            expect_reversed(a, b);
        } else {
            EXPECT_EQ(a.triangles, b.triangles);
        }
        expect_same_topology(a, b);
        EXPECT_GT(winding_agreement(b), 0.98);
    }
}

TEST(Frames, AnObliqueFrameRotatesTheMeshAndItsNormals)
{
    const Volume v = blobs();
    const Vec3 spacing{1, 2, 0.5};
    const Vec3 origin{-7, 2.5, 11};
    const double c = std::cos(std::numbers::pi / 6), s = std::sin(std::numbers::pi / 6);
    const Mat3 r{{{c, -s, 0}, {s, c, 0}, {0, 0, 1}}}; // 30 degrees about z
    const Mesh a = extract_in(v, spacing, {0, 0, 0}, cmc33::kIdentity3);
    const Mesh b = extract_in(v, spacing, origin, r);
    ASSERT_EQ(a.positions.size(), b.positions.size());
    for (std::size_t i = 0; i < a.positions.size(); i += 3) {
        for (std::size_t row = 0; row < 3; ++row) {
            double p = origin[row], n = 0;
            for (std::size_t k = 0; k < 3; ++k) {
                p += r[row][k] * static_cast<double>(a.positions[i + k]);
                n += r[row][k] * static_cast<double>(a.normals[i + k]); // a rotation keeps normals
            }
            EXPECT_NEAR(b.positions[i + row], p, 1e-4);
            EXPECT_NEAR(b.normals[i + row], n, 1e-5);
        }
    }
    EXPECT_EQ(a.triangles, b.triangles); // det > 0: same winding
    expect_same_topology(a, b);
    EXPECT_GT(winding_agreement(b), 0.98);
}

TEST(Frames, TheGeneralPathAgreesWithTheDiagonalOne)
{
    // an off-diagonal entry of 1e-300 changes no coordinate but takes the full product M * p and
    // the M^-T normals; the identity takes the per-axis multiply
    const Volume v = blobs();
    const Vec3 spacing{0.3, 1.7, 2.9}, origin{1e3, -2e-3, 5};
    Mat3 almost = cmc33::kIdentity3;
    almost[0][1] = 1e-300;
    const Mesh a = extract_in(v, spacing, origin, cmc33::kIdentity3);
    const Mesh b = extract_in(v, spacing, origin, almost);
    ASSERT_EQ(a.positions.size(), b.positions.size());
    for (std::size_t i = 0; i < a.positions.size(); ++i) {
        EXPECT_FLOAT_EQ(a.positions[i], b.positions[i]);
        EXPECT_NEAR(a.normals[i], b.normals[i], 1e-6);
    }
    EXPECT_EQ(a.triangles, b.triangles);
}

TEST(Frames, DegenerateOrNonFiniteFramesAreRefused)
{
    const Volume v = blobs();
    const auto refuse = [&](const Vec3& spacing, const Vec3& origin, const Mat3& d, const std::string& words) {
        try {
            extract_in(v, spacing, origin, d);
            ADD_FAILURE() << "no error for " << words;
        } catch (const cmc33::Error& e) {
            EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        }
    };
    refuse({1, 1, 1}, {0, 0, 0}, Mat3{{{1, 1, 0}, {0, 0, 0}, {0, 0, 1}}}, "degenerate");
    refuse({1, 1, 1}, {std::nan(""), 0, 0}, cmc33::kIdentity3, "not finite");
}

// ---- extreme values -----------------------------------------------------------------------------

TEST(ExtremeValues, SamplesNearTheDoubleLimitGiveTheirScaledGridsMesh)
{
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int g = 0; g < 40; ++g) {
        Volume huge(cmc33::ScalarType::f64, {6, 5, 5}), scaled(cmc33::ScalarType::f64, {6, 5, 5});
        for (std::int64_t i = 0; i < huge.sample_count(); ++i) {
            huge.samples<double>()[i] = u(rng) * 1.7e308; // differences reach 3.4e308: overflow
            scaled.samples<double>()[i] = std::ldexp(huge.samples<double>()[i], -1000);
        }
        for (double iso : {0.0, 0.3e308}) {
            SCOPED_TRACE("grid " + std::to_string(g) + " iso " + std::to_string(iso));
            ExtractOptions opt;
            opt.normals = true;
            cmc33::ExtractStats sa, sb;
            const Mesh a = cmc33::extract(huge, iso, opt, &sa);
            const Mesh b = cmc33::extract(scaled, std::ldexp(iso, -1000), opt, &sb);
            // the same decisions (exact on both), the same crossings (scaled by 2^-1 or not at all)
            EXPECT_EQ(sa.cells_per_subcase, sb.cells_per_subcase);
            ASSERT_EQ(a.triangles, b.triangles);
            ASSERT_EQ(a.positions.size(), b.positions.size());
            for (std::size_t i = 0; i < a.positions.size(); ++i) {
                ASSERT_EQ(a.positions[i], b.positions[i]) << "coordinate " << i;
                ASSERT_NEAR(a.normals[i], b.normals[i], 1e-6) << "normal coordinate " << i;
            }
            for (std::size_t i = 0; i < a.normals.size(); i += 3) {
                const double len = std::hypot(double(a.normals[i]), double(a.normals[i + 1]), double(a.normals[i + 2]));
                ASSERT_NEAR(len, 1.0, 1e-5) << "vertex " << i / 3; // no zero normals
            }
        }
    }
}

TEST(ExtremeValues, NormalsSurviveSquaresThatOverflow)
{
    // gradients of 1e200 per unit: their squares pass the double range
    const Volume v = cmc33::test::make_volume({8, 8, 8}, [](auto i, auto j, auto k) {
        return 1e200 * (static_cast<double>(i) + 0.5 * static_cast<double>(j) - 0.25 * static_cast<double>(k) - 3.3);
    });
    ExtractOptions opt;
    opt.normals = true;
    const Mesh m = cmc33::extract(v, 0.0, opt);
    ASSERT_GT(m.vertex_count(), 0u);
    const double len = std::sqrt(1 + 0.25 + 0.0625);
    for (std::size_t i = 0; i < m.normals.size(); i += 3) {
        ASSERT_NEAR(m.normals[i], -1 / len, 1e-6);
        ASSERT_NEAR(m.normals[i + 1], -0.5 / len, 1e-6);
        ASSERT_NEAR(m.normals[i + 2], 0.25 / len, 1e-6);
    }
}

TEST(ExtremeValues, WorldCoordinatesBeyondFloatAreRefusedBeforeWork)
{
    Volume v = blobs();
    v.set_spacing({1e300, 1, 1});
    try {
        cmc33::extract(v, 0.0);
        ADD_FAILURE() << "no error";
    } catch (const cmc33::Error& e) {
        EXPECT_EQ(e.status(), cmc33::Status::too_large);
        EXPECT_NE(std::string(e.what()).find("32-bit floats"), std::string::npos) << e.what();
    }
    // within float range: fine
    v.set_spacing({1e37, 1, 1});
    const Mesh m = cmc33::extract(v, 0.0);
    for (float x : m.positions) ASSERT_TRUE(std::isfinite(x));
}

} // namespace
