// extract() on a volume of more than 2^31 samples (1300^3 uint8, 2.2 GB): every sample offset,
// row index and vertex counter past 2^31 must be 64-bit. The shape is known analytically, so the
// topology is checked without field_topology (which would take minutes on 2.2 G cells):
// a bumpy sphere holding six ball-shaped cavities and one torus-shaped cavity, each a closed
// surface: components 1 + 6 + 1 = 8, Euler 2 * 7 + 0 = 14.
// Label slow; skipped when MemAvailable is under kNeededBytes (scripts/large_volume.sh runs it).

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cmc33/extract.hpp"
#include "cmc33/topology.hpp"
#include "cmc33/volume.hpp"

namespace {

using cmc33::GridView;
using cmc33::Mesh;

constexpr std::int64_t kN = 1300; // samples per axis: 2,197,000,000 > 2^31
constexpr double kCentre = 649.5;
constexpr double kRadius = 590;   // outer sphere, plus bumps of kBump: stays 50 samples off the faces
constexpr double kBump = 8;
constexpr double kBallRadius = 30; // cavities centred on the x axis at kCentre +- 150, 300, 450
constexpr double kTorusMajor = 200, kTorusMinor = 25; // cavity around the x axis, in the plane x = kCentre
constexpr double kSlope = 4; // sample units per unit of distance: the surface is 8 samples thick
/// The volume (2.2 GB), the mesh and mesh_topology's working memory, with room to spare.
constexpr std::int64_t kNeededBytes = std::int64_t{6} << 30;

/// MemAvailable of /proc/meminfo in bytes, or -1 if unknown.
std::int64_t available_memory()
{
    std::ifstream in("/proc/meminfo");
    std::string key;
    std::int64_t kib = 0;
    std::string unit;
    while (in >> key >> kib) {
        std::getline(in, unit);
        if (key == "MemAvailable:") return kib * 1024;
    }
    return -1;
}

/// Signed distance, positive inside the solid (inside the sphere, outside every cavity); exact
/// enough near each surface, clamped far from all of them by the caller.
struct Shape {
    std::vector<double> bump_x = table(), bump_y = table(), bump_z = table();

    static std::vector<double> table()
    {
        std::vector<double> t(static_cast<std::size_t>(kN));
        for (std::int64_t i = 0; i < kN; ++i) t[static_cast<std::size_t>(i)] = std::sin(static_cast<double>(i) / 40.0);
        return t;
    }

    double operator()(std::int64_t i, std::int64_t j, std::int64_t k) const
    {
        const double x = static_cast<double>(i) - kCentre, y = static_cast<double>(j) - kCentre,
                     z = static_cast<double>(k) - kCentre;
        const double rho2 = y * y + z * z; // squared distance to the x axis
        const double bump = kBump * bump_x[static_cast<std::size_t>(i)] * bump_y[static_cast<std::size_t>(j)] *
                            bump_z[static_cast<std::size_t>(k)];
        double d = kRadius + bump - std::sqrt(x * x + rho2);
        if (rho2 < 64.0 * 64.0) {
            for (double b : {-450.0, -300.0, -150.0, 150.0, 300.0, 450.0}) {
                d = std::min(d, std::sqrt((x - b) * (x - b) + rho2) - kBallRadius);
            }
        }
        if (std::fabs(x) < 64.0) {
            const double q = std::sqrt(rho2) - kTorusMajor;
            d = std::min(d, std::sqrt(q * q + x * x) - kTorusMinor);
        }
        return d;
    }
};

/// Above (>= 128, iso 127.5) exactly where the signed distance is >= 0; no sample equals the iso.
std::uint8_t sample(double d)
{
    return static_cast<std::uint8_t>(std::clamp(std::floor(128.0 + kSlope * d), 0.0, 255.0));
}

/// x and y grid edges of slice k whose samples lie on both sides of 127.5.
std::int64_t crossings_in_slice(const std::uint8_t* v, std::int64_t k)
{
    std::int64_t n = 0;
    const std::uint8_t* s = v + k * kN * kN;
    for (std::int64_t j = 0; j < kN; ++j)
        for (std::int64_t i = 0; i < kN; ++i) {
            const bool a = s[i + kN * j] >= 128;
            if (i + 1 < kN && a != (s[i + 1 + kN * j] >= 128)) ++n;
            if (j + 1 < kN && a != (s[i + kN * (j + 1)] >= 128)) ++n;
        }
    return n;
}

double seconds_since(std::chrono::steady_clock::time_point start)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

TEST(LargeVolume, MoreThan2To31CellsHaveTheAnalyticTopologyAndConsistentIndices)
{
    const std::int64_t available = available_memory();
    if (available >= 0 && available < kNeededBytes) {
        GTEST_SKIP() << "needs about " << (kNeededBytes >> 30) << " GiB of available memory, /proc/meminfo says "
                     << (available >> 20) << " MiB";
    }
    static_assert(kN * kN * kN > (std::int64_t{1} << 31));
    static_assert((kN - 1) * (kN - 1) * (kN - 1) > (std::int64_t{1} << 31));

    auto start = std::chrono::steady_clock::now();
    cmc33::Volume volume(cmc33::ScalarType::u8, {kN, kN, kN});
    std::uint8_t* v = volume.samples<std::uint8_t>();
    {
        const Shape shape;
        auto fill = [&](std::int64_t k0, std::int64_t k1) {
            for (std::int64_t k = k0; k < k1; ++k)
                for (std::int64_t j = 0; j < kN; ++j)
                    for (std::int64_t i = 0; i < kN; ++i) v[i + kN * (j + kN * k)] = sample(shape(i, j, k));
        };
        std::thread half(fill, 0, kN / 2);
        fill(kN / 2, kN);
        half.join();
    }
    const double fill_seconds = seconds_since(start);

    cmc33::ExtractOptions options;
    options.threads = 2;
    start = std::chrono::steady_clock::now();
    Mesh mesh = cmc33::extract(volume, 127.5, options);
    const double extract_seconds = seconds_since(start);

    // Indices: all below the vertex count, and every vertex used (mesh_topology counts used ones).
    const std::size_t nv = mesh.vertex_count(), nt = mesh.triangle_count();
    ASSERT_GT(nt, 0u);
    const std::uint32_t largest = *std::max_element(mesh.triangles.begin(), mesh.triangles.end());
    EXPECT_LT(largest, nv);

    start = std::chrono::steady_clock::now();
    const cmc33::MeshTopology t = cmc33::mesh_topology(mesh);
    const double topology_seconds = seconds_since(start);
    EXPECT_EQ(t.vertices, static_cast<std::int64_t>(nv));
    EXPECT_EQ(t.faces, static_cast<std::int64_t>(nt));
    EXPECT_EQ(t.components, 8);
    EXPECT_EQ(t.closed_components, 8);
    EXPECT_EQ(t.euler, 14);
    EXPECT_EQ(t.b1, 2); // the torus
    EXPECT_EQ(t.boundary_edges, 0);
    EXPECT_EQ(t.nonmanifold_edges, 0);
    EXPECT_EQ(t.nonmanifold_vertices, 0);
    EXPECT_EQ(t.degenerate_triangles, 0);
    EXPECT_TRUE(t.oriented);

    // Positions: the sphere reaches within one sample of its analytic extent on every axis, so the
    // last slices (sample offsets past 2^31) were read and placed where they belong.
    for (std::size_t axis = 0; axis < 3; ++axis) {
        float lo = std::numeric_limits<float>::infinity(), hi = -lo;
        for (std::size_t p = axis; p < mesh.positions.size(); p += 3) {
            lo = std::min(lo, mesh.positions[p]);
            hi = std::max(hi, mesh.positions[p]);
        }
        SCOPED_TRACE(axis);
        EXPECT_GT(lo, kCentre - kRadius - kBump - 1);
        EXPECT_LT(hi, kCentre + kRadius + kBump + 1);
        EXPECT_LT(lo, kCentre - kRadius + kBump + 1);
        EXPECT_GT(hi, kCentre + kRadius - kBump - 1);
    }

    // Two strided sub-box views, slices [0, 650] and [650, 1299]: their cells partition the grid's,
    // so the triangles add up exactly, and the vertices too once the x and y edges of the shared
    // slice 650 (in both views) are counted once.
    const std::int64_t cut = kN / 2;
    const auto whole = GridView<std::uint8_t>::dense(v, {kN, kN, kN});
    GridView<std::uint8_t> lower = whole, upper = whole;
    lower.dims[2] = cut + 1;
    upper.data = v + whole.offset(0, 0, cut);
    upper.dims[2] = kN - cut;
    upper.origin[2] = static_cast<double>(cut);
    const std::size_t triangles = nt, vertices = nv;
    const std::int64_t shared = crossings_in_slice(v, cut);
    mesh = Mesh{}; // room for the halves
    const Mesh a = cmc33::extract(lower, 127.5, options);
    const Mesh b = cmc33::extract(upper, 127.5, options);
    EXPECT_EQ(a.triangle_count() + b.triangle_count(), triangles);
    EXPECT_EQ(static_cast<std::int64_t>(a.vertex_count() + b.vertex_count()) - shared, static_cast<std::int64_t>(vertices));

    std::cout << "large volume: " << kN << "^3 uint8 (" << kN * kN * kN << " samples), fill " << fill_seconds
              << " s, extract (2 threads) " << extract_seconds << " s, mesh_topology " << topology_seconds << " s: "
              << vertices << " vertices, " << triangles << " triangles, euler " << t.euler << ", components "
              << t.components << ", b1 " << t.b1 << ", boundary edges " << t.boundary_edges
              << ", non-manifold edges " << t.nonmanifold_edges << '\n';
}

} // namespace
