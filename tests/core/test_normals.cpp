// Normals where the central-difference gradient cancels (alternating samples, symmetric cells):
// every normal is unit length and on the side its triangles face (the area-weighted sum of their
// normals), in the identity frame and in mirrored and oblique ones. And world coordinates far from
// the origin: extract() refuses a frame whose floats cannot keep the mesh embedded, rather than
// returning a collapsed mesh.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <string>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/topology.hpp"
#include "test_support.hpp"

namespace {

using cmc33::ExtractOptions;
using cmc33::Mat3;
using cmc33::Mesh;
using cmc33::Vec3;
using cmc33::Volume;

struct NormalFaults {
    std::size_t not_unit = 0;   ///< |n| not 1 (a (0, 0, 0) normal among them)
    std::size_t against = 0;    ///< n . (sum of the vertex's triangles' area normals) <= 0
};

NormalFaults normal_faults(const Mesh& m)
{
    std::vector<std::array<double, 3>> faces(m.vertex_count(), {0, 0, 0});
    const auto p = [&](std::uint32_t v, int c) { return static_cast<double>(m.positions[3 * v + static_cast<std::size_t>(c)]); };
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
        const std::uint32_t a = m.triangles[3 * t], b = m.triangles[3 * t + 1], c = m.triangles[3 * t + 2];
        const double u[3] = {p(b, 0) - p(a, 0), p(b, 1) - p(a, 1), p(b, 2) - p(a, 2)};
        const double w[3] = {p(c, 0) - p(a, 0), p(c, 1) - p(a, 1), p(c, 2) - p(a, 2)};
        const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
        for (const std::uint32_t v : {a, b, c})
            for (int k = 0; k < 3; ++k) faces[v][static_cast<std::size_t>(k)] += n[k];
    }
    NormalFaults f;
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
        const double n[3] = {static_cast<double>(m.normals[3 * v]), static_cast<double>(m.normals[3 * v + 1]),
                             static_cast<double>(m.normals[3 * v + 2])};
        if (std::fabs(std::hypot(n[0], n[1], n[2]) - 1) > 1e-5) ++f.not_unit;
        if (n[0] * faces[v][0] + n[1] * faces[v][1] + n[2] * faces[v][2] <= 0) ++f.against;
    }
    return f;
}

Mesh with_normals(const Volume& v, double iso, const Vec3& spacing = {1, 1, 1}, const Mat3& direction = cmc33::kIdentity3)
{
    ExtractOptions opt;
    opt.normals = true;
    return v.visit([&](auto view) {
        view.spacing = spacing;
        view.direction = direction;
        return cmc33::extract(view, iso, opt);
    });
}

const Mat3 kMirror = {{{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
// a rotation about (1, 1, 1) by 40 degrees, then a shear: oblique and not orthogonal
const Mat3 kOblique = {{{0.8440, -0.3893, 0.3689}, {0.4370, 0.8948, -0.0912}, {-0.3114, 0.2184, 0.9250}}};

TEST(Normals, AlternatingSamplesAlongXGiveUnitNormalsFacingTheirTriangles)
{
    // x % 2 at 0.5: every central difference along x is 0, and so is the whole gradient
    const Volume v = cmc33::test::make_volume({6, 6, 6}, [](auto i, auto, auto) { return static_cast<double>(i % 2); });
    for (const Mat3& d : {cmc33::kIdentity3, kMirror, kOblique}) {
        const Mesh m = with_normals(v, 0.5, {0.7, 1.3, 2.1}, d);
        ASSERT_GT(m.vertex_count(), 0u);
        const NormalFaults f = normal_faults(m);
        EXPECT_EQ(f.not_unit, 0u);
        EXPECT_EQ(f.against, 0u);
    }
}

TEST(Normals, CheckerboardsGiveUnitNormalsFacingTheirTriangles)
{
    // (i + j + k) % 2 and (i + j) % 2: ambiguous faces everywhere, interior vertices of tunnels
    // at points where the corners' gradients cancel
    const Volume three = cmc33::test::make_volume({6, 6, 6}, [](auto i, auto j, auto k) { return static_cast<double>((i + j + k) % 2); });
    const Volume two = cmc33::test::make_volume({5, 6, 4}, [](auto i, auto j, auto) { return static_cast<double>((i + j) % 2); });
    for (const Volume* v : {&three, &two})
        for (const Mat3& d : {cmc33::kIdentity3, kMirror, kOblique}) {
            const Mesh m = with_normals(*v, 0.5, {1, 1, 1}, d);
            ASSERT_GT(m.vertex_count(), 0u);
            const NormalFaults f = normal_faults(m);
            EXPECT_EQ(f.not_unit, 0u);
            EXPECT_EQ(f.against, 0u);
        }
}

TEST(Normals, EverySingleCellConfigurationHasUnitNormals)
{
    // the 256 sign patterns of one cell, at values -1 and 1 and at -1 and 3 (asymmetric)
    for (const double high : {1.0, 3.0})
        for (int code = 1; code < 255; ++code) {
            const Volume v = cmc33::test::make_volume({2, 2, 2}, [&](auto i, auto j, auto k) {
                return (code >> (i | j << 1 | k << 2)) & 1 ? high : -1.0;
            });
            const Mesh m = with_normals(v, 0);
            EXPECT_EQ(normal_faults(m).not_unit, 0u) << "case code " << code << ", high " << high;
        }
}

TEST(WorldPrecision, FloatStepsPerCellFollowTheLargestCoordinate)
{
    // origin 0: the largest coordinate is the box's far corner (31), ulp 2^-19
    EXPECT_DOUBLE_EQ(cmc33::float_steps_per_cell({32, 32, 32}, {1, 1, 1}, {0, 0, 0}, cmc33::kIdentity3), 0x1p19);
    // 4e6 (2^21 <= x < 2^22): ulp 0.25, 4 steps across a unit cell
    EXPECT_DOUBLE_EQ(cmc33::float_steps_per_cell({32, 32, 32}, {1, 1, 1}, {5e5, 4e6, 0}, cmc33::kIdentity3), 4);
    // spacing 0.01 at 1e6 (ulp 1/16): less than one step
    EXPECT_LT(cmc33::float_steps_per_cell({32, 32, 32}, {0.01, 0.01, 0.01}, {1e6, 1e6, 1e6}, cmc33::kIdentity3), 1);
    // a CT in millimetres: x and y within 128 mm (ulp 2^-16) in 0.5 mm cells, 32768 steps; z up
    // to 1000 mm (ulp 2^-14) in 1 mm cells, 16384
    EXPECT_DOUBLE_EQ(cmc33::float_steps_per_cell({512, 512, 300}, {0.5, 0.5, 1}, {-128, -128, -1000}, cmc33::kIdentity3),
                     16384);
    // huge cells along x only: x is resolved as finely as its cells are large
    EXPECT_GT(cmc33::float_steps_per_cell({13, 11, 9}, {1e37, 1, 1}, {0, 0, 0}, cmc33::kIdentity3), 1e5);
}

TEST(WorldPrecision, ExtractRefusesAFrameWhoseFloatsCannotKeepTheMeshEmbedded)
{
    Volume v = cmc33::test::make_volume({8, 8, 8}, [](auto i, auto j, auto k) {
        return std::hypot(static_cast<double>(i) - 3.5, static_cast<double>(j) - 3.5, static_cast<double>(k) - 3.5);
    });
    v.set_origin({5e5, 4e6, 0});
    try {
        (void)cmc33::extract(v, 2.5);
        FAIL() << "expected Error{too_large}";
    } catch (const cmc33::Error& e) {
        EXPECT_EQ(e.status(), cmc33::Status::too_large);
        EXPECT_NE(std::string(e.what()).find("steps across a cell"), std::string::npos) << e.what();
    }
    // the same grid at origin 0 is embedded, and so is its exact translate in double precision
    v.set_origin({0, 0, 0});
    const Mesh m = cmc33::extract(v, 2.5);
    EXPECT_TRUE(cmc33::mesh_geometry(m).embedded());
    // the edge of the rule: 128 steps (origin 1e5 with unit cells: ulp 2^-7) is kept
    v.set_origin({1e5, 1e5, 0});
    EXPECT_TRUE(cmc33::mesh_geometry(cmc33::extract(v, 2.5)).embedded());
}

} // namespace
