// label_surfaces() (src/labels): random label fields of 5^3 to 9^3 samples with 2, 3 and 4 labels
// checked from the mesh alone (label_checks.cpp), determinism, the frame, selection and bad input.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/labels.hpp"
#include "cmc33/topology.hpp"
#include "label_checks.hpp"

namespace {

using namespace cmc33;
using label_checks::Counts;

Counts sweep(int labels, int fields, bool smooth, double sigma = 0)
{
    Counts c;
    for (int n = 0; n < fields; ++n) {
        const std::int64_t size = 5 + n % 5;
        const Volume v = label_checks::random_labels(size, labels, static_cast<std::uint64_t>(n), smooth);
        label_checks::check_field(v, c,
                                  std::to_string(labels) + " labels, " + (smooth ? "smooth" : "i.i.d.") + " field " +
                                      std::to_string(n) + " (" + std::to_string(size) + "^3)" +
                                      (sigma > 0 ? ", sigma " + std::to_string(sigma) : ""),
                                  sigma);
    }
    std::cout << labels << " labels, " << (smooth ? "smooth" : "i.i.d.") << ", sigma " << sigma << ": " << c.fields
              << " fields, " << c.label_surfaces << " label surfaces; not closed " << c.not_closed << ", not manifold "
              << c.not_manifold << " (" << c.nonmanifold_edges << " edges, " << c.nonmanifold_vertices
              << " vertices), not oriented " << c.not_oriented << ", not embedded " << c.not_embedded
              << ", union not watertight " << c.union_not_watertight << ", union not embedded " << c.union_not_embedded
              << ", repeated triangles " << c.duplicate_triangles << ", two-label mismatches " << c.two_label_mismatch
              << ", topology mismatches " << c.topology_mismatch << " of " << c.two_label_compared
              << ", Euler characteristics not the labels' " << c.euler_mismatch
              << ", Betti numbers or loops not the labels' " << c.betti_mismatch << " of " << c.betti_compared
              << (c.first_failure.empty() ? "" : "; first: ") << c.first_failure << "\n";
    return c;
}

void expect_guarantees(const Counts& c)
{
    EXPECT_EQ(c.not_closed, 0) << c.first_failure;
    EXPECT_EQ(c.not_manifold, 0) << c.first_failure;
    EXPECT_EQ(c.not_oriented, 0) << c.first_failure;
    EXPECT_EQ(c.union_not_watertight, 0) << c.first_failure;
    EXPECT_EQ(c.union_not_embedded, 0) << c.first_failure;
    EXPECT_EQ(c.not_embedded, 0) << c.first_failure;
    EXPECT_EQ(c.duplicate_triangles, 0) << c.first_failure;
    EXPECT_EQ(c.euler_mismatch, 0) << c.first_failure;
    EXPECT_EQ(c.betti_mismatch, 0) << c.first_failure;
}

TEST(Labels, TwoLabelFieldsAreTheIndicatorsLevelSet)
{
    for (const bool smooth : {false, true}) {
        const Counts c = sweep(2, 200, smooth);
        expect_guarantees(c);
        EXPECT_EQ(c.betti_compared, 2 * c.fields); // every label's Betti numbers from the labels
        EXPECT_EQ(c.two_label_mismatch, 0) << c.first_failure;
        EXPECT_EQ(c.topology_mismatch, 0) << c.first_failure;
    }
}

// Three and four labels: closed, manifold, oriented, embedded and watertight (cells where a
// label's part of the surface is not one disk take a core, docs/labels.md).
TEST(Labels, ThreeAndFourLabelFields)
{
    for (const int labels : {3, 4})
        for (const bool smooth : {false, true}) {
            const Counts c = sweep(labels, 75, smooth);
            expect_guarantees(c);
            EXPECT_EQ(c.betti_compared, c.label_surfaces); // every label's Betti numbers from the labels
        }
}

// Smooth labels, two of them: the filtered indicators sum to 1, so each label's surface is the
// extraction of the lower label's filtered indicator at 0.5 and has that field's topology.
TEST(Labels, SmoothTwoLabelFieldsAreTheFilteredIndicatorsLevelSet)
{
    for (const double sigma : {0.6, 1.2})
        for (const bool smooth : {false, true}) {
            const Counts c = sweep(2, 60, smooth, sigma);
            expect_guarantees(c);
            EXPECT_EQ(c.two_label_mismatch, 0) << c.first_failure;
            EXPECT_EQ(c.topology_mismatch, 0) << c.first_failure;
            EXPECT_GT(c.two_label_compared, 40); // the rest have a sample within rounding of a tie
        }
}

// Smooth labels, three and four: the same guarantees as without smoothing.
TEST(Labels, SmoothThreeAndFourLabelFields)
{
    for (const int labels : {3, 4})
        for (const bool smooth : {false, true})
            for (const double sigma : {0.6, 1.5}) expect_guarantees(sweep(labels, 30, smooth, sigma));
}

// A label thinner than the filter vanishes: a voxel of 2 inside 1 leaves only 1, and no surface.
TEST(Labels, SmoothRemovesALabelThinnerThanTheFilter)
{
    Volume v(ScalarType::i32, {7, 7, 7});
    std::int32_t* s = v.samples<std::int32_t>();
    std::fill(s, s + v.sample_count(), 1);
    s[3 + 7 * (3 + 7 * 3)] = 2;
    LabelOptions o;
    EXPECT_EQ(label_surfaces(v, o).present, (std::vector<std::int64_t>{1, 2}));
    o.smooth = 1.5;
    const LabelSurfaces smoothed = label_surfaces(v, o);
    EXPECT_EQ(smoothed.present, (std::vector<std::int64_t>{1}));
    EXPECT_EQ(smoothed.interfaces.triangle_count(), 0U);
    // a block of 3^3 stays, rounded: its crossings move off the edges' midpoints
    for (std::int64_t k = 2; k <= 4; ++k)
        for (std::int64_t j = 2; j <= 4; ++j)
            for (std::int64_t i = 2; i <= 4; ++i) s[i + 7 * (j + 7 * k)] = 2;
    o.smooth = 0.8;
    const LabelSurfaces block = label_surfaces(v, o);
    EXPECT_EQ(block.present, (std::vector<std::int64_t>{1, 2}));
    const MeshTopology t = mesh_topology(label_surface(block, 2));
    EXPECT_EQ(t.components, 1);
    EXPECT_EQ(t.euler, 2);
    bool off_midpoint = false;
    for (const float x : block.interfaces.positions)
        off_midpoint = off_midpoint || std::fabs(x * 2 - std::round(x * 2)) > 1e-3F;
    EXPECT_TRUE(off_midpoint);
}

TEST(Labels, SmoothSigmaMustBeFiniteAndPositive)
{
    const Volume v = label_checks::random_labels(5, 3, 1, false);
    for (const double sigma : {-1.0, std::nan(""), HUGE_VAL}) {
        LabelOptions o;
        o.smooth = sigma;
        try {
            label_surfaces(v, o);
            FAIL() << sigma;
        } catch (const Error& e) {
            EXPECT_EQ(e.status(), Status::invalid_argument);
            EXPECT_NE(std::string(e.what()).find("smooth"), std::string::npos) << e.what();
        }
    }
}

// The label surfaces of one cell (corners x fastest, then y, then z), the guarantees checked.
LabelSurfaces one_cell(const std::array<std::int32_t, 8>& corners, const std::string& what)
{
    Volume v(ScalarType::i32, {2, 2, 2});
    std::copy(corners.begin(), corners.end(), v.samples<std::int32_t>());
    Counts c;
    label_checks::check_field(v, c, what);
    expect_guarantees(c);
    return label_surfaces(v);
}

// One cell whose label 1 holds two opposite corners, (0, 0, 0) and (1, 1, 1): its part of the
// cell's surface is two pieces, so the cell is cut around a core that label 1 takes (one piece,
// not two cones pinched at the centre); labels 2 and 3 each hold one piece.
TEST(Labels, ACoreJoinsALabelOfTwoPieces)
{
    const LabelSurfaces s = one_cell({1, 2, 2, 3, 2, 3, 3, 1}, "two pieces of label 1");
    EXPECT_EQ(s.cells_many_labels, 1);
    EXPECT_EQ(s.cells_with_core, 1);
    for (const std::int64_t l : {1, 2, 3}) EXPECT_EQ(mesh_topology(label_surface(s, l)).components, 1) << l;
}

// A cell where every label is one disk on the cell's surface keeps the cone from the centre.
TEST(Labels, NoCoreWhereEveryLabelIsOneDisk)
{
    const LabelSurfaces s = one_cell({1, 1, 2, 2, 1, 1, 3, 3}, "three slabs");
    EXPECT_EQ(s.cells_many_labels, 1);
    EXPECT_EQ(s.cells_with_core, 0);
}

TEST(Labels, Deterministic)
{
    const Volume v = label_checks::random_labels(9, 4, 7, false);
    const LabelSurfaces a = label_surfaces(v), b = label_surfaces(v);
    ASSERT_EQ(a.interfaces.positions.size(), b.interfaces.positions.size());
    ASSERT_EQ(a.interfaces.triangles.size(), b.interfaces.triangles.size());
    EXPECT_EQ(
        std::memcmp(a.interfaces.positions.data(), b.interfaces.positions.data(), a.interfaces.positions.size() * 4),
        0);
    EXPECT_TRUE(a.interfaces.triangles == b.interfaces.triangles);
    EXPECT_EQ(a.front, b.front);
    EXPECT_EQ(a.behind, b.behind);
}

void expect_same(const LabelSurfaces& a, const LabelSurfaces& b, const std::string& what)
{
    ASSERT_EQ(a.interfaces.positions.size(), b.interfaces.positions.size()) << what;
    EXPECT_EQ(
        std::memcmp(a.interfaces.positions.data(), b.interfaces.positions.data(), a.interfaces.positions.size() * 4), 0)
        << what;
    EXPECT_TRUE(a.interfaces.triangles == b.interfaces.triangles) << what;
    EXPECT_EQ(a.front, b.front) << what;
    EXPECT_EQ(a.behind, b.behind) << what;
    EXPECT_EQ(a.present, b.present) << what;
    EXPECT_EQ(a.selected, b.selected) << what;
    EXPECT_EQ(a.cells_two_labels, b.cells_two_labels) << what;
    EXPECT_EQ(a.cells_many_labels, b.cells_many_labels) << what;
    EXPECT_EQ(a.cells_with_core, b.cells_with_core) << what;
    ASSERT_EQ(a.interfaces.normals.size(), b.interfaces.normals.size()) << what;
    EXPECT_EQ(std::memcmp(a.interfaces.normals.data(), b.interfaces.normals.data(), a.interfaces.normals.size() * 4), 0)
        << what;
    for (const std::int64_t l : a.selected) {
        const Mesh ma = label_surface(a, l), mb = label_surface(b, l);
        ASSERT_EQ(ma.normals.size(), mb.normals.size()) << what << ", label " << l;
        EXPECT_EQ(std::memcmp(ma.normals.data(), mb.normals.data(), ma.normals.size() * 4), 0)
            << what << ", label " << l;
    }
}

// The cell pass runs on z-ranges welded afterwards: every thread count gives the same bytes,
// including more threads than cell layers and a rotated frame, normals included.
TEST(Labels, SameOutputForEveryThreadCount)
{
    for (const int labels : {2, 4})
        for (const bool smooth : {false, true})
            for (const std::uint64_t seed : {1U, 2U}) {
                Volume v = label_checks::random_labels(9, labels, seed, smooth);
                if (seed == 2) v.set_direction({{{0.6, 0.8, 0}, {-0.8, 0.6, 0}, {0, 0, 1}}});
                LabelOptions o;
                o.smooth = smooth ? 1.0 : 0.0; // and filtered labels
                o.threads = 1;
                o.normals = true;
                const LabelSurfaces one = label_surfaces(v, o);
                EXPECT_GT(one.interfaces.triangle_count(), 0U);
                EXPECT_TRUE(one.interfaces.has_normals());
                for (const int threads : {2, 3, 5, 8, 20}) {
                    o.threads = threads;
                    expect_same(one, label_surfaces(v, o),
                                std::to_string(labels) + " labels, seed " + std::to_string(seed) + ", " +
                                    std::to_string(threads) + " threads");
                }
            }
}

// More than 8 labels selected: label_surface() reads the index by label, which gives the meshes a
// scan of every triangle gives.
TEST(Labels, IndexByLabelGivesTheScansSurfaces)
{
    const Volume v = label_checks::random_labels(9, 12, 5, true);
    const LabelSurfaces indexed = label_surfaces(v);
    ASSERT_GT(indexed.selected.size(), 8U);
    ASSERT_EQ(indexed.by_label_start.size(), indexed.selected.size() + 1);
    LabelSurfaces scanned = indexed;
    scanned.by_label.clear();
    scanned.by_label_start.clear();
    for (const std::int64_t l : indexed.selected) {
        const Mesh a = label_surface(indexed, l), b = label_surface(scanned, l);
        EXPECT_GT(a.triangle_count(), 0U) << l;
        EXPECT_TRUE(a.triangles == b.triangles) << l;
        EXPECT_TRUE(a.positions == b.positions) << l;
    }
}

TEST(Labels, SelectionAndBackground)
{
    Volume v = label_checks::random_labels(7, 4, 3, true);
    const LabelSurfaces all = label_surfaces(v); // background 0 is not present: every label
    EXPECT_EQ(all.present, (std::vector<std::int64_t>{1, 2, 3, 4}));
    EXPECT_EQ(all.selected, all.present);
    LabelOptions o;
    o.background = 1;
    EXPECT_EQ(label_surfaces(v, o).selected, (std::vector<std::int64_t>{2, 3, 4}));
    o.labels = parse_label_ranges("1,3-4");
    const LabelSurfaces some = label_surfaces(v, o);
    EXPECT_EQ(some.selected, (std::vector<std::int64_t>{1, 3, 4}));
    // the partition does not depend on the selection: label 3's surface is the same
    const Mesh a = label_surface(all, 3), b = label_surface(some, 3);
    EXPECT_EQ(a.triangle_count(), b.triangle_count());
    EXPECT_EQ(mesh_topology(a).euler, mesh_topology(b).euler);
    EXPECT_EQ(label_surface(some, 2).triangle_count(), 0U);
}

TEST(Labels, ParseRanges)
{
    EXPECT_TRUE(parse_label_ranges("all").empty());
    EXPECT_EQ(parse_label_ranges("1,3,7"), (LabelRanges{{1, 1}, {3, 3}, {7, 7}}));
    EXPECT_EQ(parse_label_ranges("2-9"), (LabelRanges{{2, 9}}));
    EXPECT_EQ(parse_label_ranges("-5--1,4"), (LabelRanges{{-5, -1}, {4, 4}}));
    for (const char* bad : {"", "1,", "a", "3-1", "1-", "1.5", "1,,2"}) {
        EXPECT_THROW(parse_label_ranges(bad), Error) << bad;
    }
}

TEST(Labels, FloatSamplesAreRefused)
{
    const Volume v(ScalarType::f32, {4, 4, 4});
    try {
        label_surfaces(v);
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(e.status(), Status::unsupported_format);
        EXPECT_NE(std::string(e.what()).find("integer"), std::string::npos);
    }
}

TEST(Labels, WorldFrame)
{
    Volume v = label_checks::random_labels(6, 3, 11, true);
    const LabelSurfaces index = label_surfaces(v);
    v.set_spacing({0.5, 2, 1});
    v.set_origin({10, -3, 1});
    v.set_direction({{{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}); // a mirror: windings reverse, orientation stays
    const LabelSurfaces world = label_surfaces(v);
    ASSERT_EQ(index.interfaces.vertex_count(), world.interfaces.vertex_count());
    for (std::size_t i = 0; i < index.interfaces.vertex_count(); ++i) {
        EXPECT_EQ(world.interfaces.positions[3 * i],
                  static_cast<float>(10 - 0.5 * static_cast<double>(index.interfaces.positions[3 * i])));
        EXPECT_EQ(world.interfaces.positions[3 * i + 1],
                  static_cast<float>(-3 + 2 * static_cast<double>(index.interfaces.positions[3 * i + 1])));
    }
    for (const std::int64_t l : world.selected) {
        EXPECT_TRUE(mesh_topology(label_surface(world, l)).oriented);
    }
}

using Vec = std::array<double, 3>;

Vec face_normal(const Mesh& m, std::size_t t)
{
    Vec a{}, b{};
    for (std::size_t k = 0; k < 3; ++k) {
        const auto at = [&](std::size_t c) { return static_cast<double>(m.positions[3 * m.triangles[3 * t + c] + k]); };
        a[k] = at(1) - at(0);
        b[k] = at(2) - at(0);
    }
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

double dot(const Vec& a, const Vec& b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

struct NormalCounts {
    std::int64_t vertices = 0;  ///< label surfaces' vertices checked
    std::int64_t faint = 0;     ///< where the faces' sum is under a tenth of their areas (pinches)
    std::int64_t two_label = 0; ///< label surfaces' vertices that only two labels share
};

// Every normal of `m` finite and unit, and on the side of the area-weighted sum of its faces'
// normals (as the test computes it) wherever that sum is not vanishing against the areas.
void expect_unit_and_with_the_faces(const Mesh& m, const std::string& what, NormalCounts& counts)
{
    ASSERT_EQ(m.normals.size(), m.positions.size()) << what;
    std::vector<Vec> sum(m.vertex_count(), Vec{0, 0, 0});
    std::vector<double> area(m.vertex_count(), 0);
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
        const Vec n = face_normal(m, t);
        for (std::size_t c = 0; c < 3; ++c) {
            const std::uint32_t v = m.triangles[3 * t + c];
            for (std::size_t k = 0; k < 3; ++k) sum[v][k] += n[k];
            area[v] += std::sqrt(dot(n, n));
        }
    }
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
        const Vec n{static_cast<double>(m.normals[3 * v]), static_cast<double>(m.normals[3 * v + 1]),
                    static_cast<double>(m.normals[3 * v + 2])};
        ASSERT_TRUE(std::isfinite(n[0]) && std::isfinite(n[1]) && std::isfinite(n[2])) << what << ", vertex " << v;
        ASSERT_NEAR(std::sqrt(dot(n, n)), 1.0, 1e-6) << what << ", vertex " << v;
        ++counts.vertices;
        const double l = std::sqrt(dot(sum[v], sum[v]));
        if (l < 0.1 * area[v]) ++counts.faint;
        if (l > 1e-6 * area[v]) {
            EXPECT_GT(dot(n, sum[v]) / l, 0.9999) << what << ", vertex " << v;
        }
    }
}

// label_surface()'s vertex i is the interface's vertex from[i] (its triangles in interface order,
// the second and third corners swapped where the label is in front).
std::vector<std::uint32_t> interface_vertices(const LabelSurfaces& s, std::int64_t label, const Mesh& m)
{
    std::vector<std::uint32_t> from(m.vertex_count());
    std::size_t i = 0;
    for (std::size_t t = 0; t < s.interfaces.triangle_count(); ++t) {
        if (s.front[t] != label && s.behind[t] != label) continue;
        const bool in_front = s.front[t] == label;
        const std::uint32_t* c = &s.interfaces.triangles[3 * t];
        from[m.triangles[3 * i]] = c[0];
        from[m.triangles[3 * i + 1]] = c[in_front ? 2 : 1];
        from[m.triangles[3 * i + 2]] = c[in_front ? 1 : 2];
        ++i;
    }
    return from;
}

// Normals (LabelOptions::normals): unit and finite everywhere, on the faces' side; at a vertex only
// two labels share, the two surfaces' normals are exact negations and the interface's is the lower
// label's (pointing into the higher, the front); in a rotated, mirroring and scaled frame too.
TEST(Labels, Normals)
{
    NormalCounts counts;
    for (const int labels : {2, 3, 4})
        for (const bool smooth : {false, true})
            for (const std::uint64_t seed : {1U, 2U, 3U}) {
                Volume v = label_checks::random_labels(static_cast<std::int64_t>(5 + seed), labels, seed, smooth);
                if (seed == 2) v.set_direction({{{0.6, 0.8, 0}, {-0.8, 0.6, 0}, {0, 0, 1}}});
                if (seed == 3) {
                    v.set_direction({{{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}}});
                    v.set_spacing({0.5, 2, 1});
                }
                const std::string what = std::to_string(labels) + " labels, " + (smooth ? "smooth" : "i.i.d.") +
                                         ", seed " + std::to_string(seed);
                LabelOptions o;
                o.normals = true;
                const LabelSurfaces s = label_surfaces(v, o);
                const Mesh& all = s.interfaces;
                ASSERT_GT(all.triangle_count(), 0U) << what;
                expect_unit_and_with_the_faces(all, what + ", interfaces", counts);
                // the labels at each interface vertex
                std::vector<std::vector<std::int64_t>> around(all.vertex_count());
                for (std::size_t t = 0; t < all.triangle_count(); ++t) {
                    EXPECT_GT(s.front[t], s.behind[t]) << what << ", triangle " << t;
                    for (std::size_t c = 0; c < 3; ++c)
                        for (const std::int64_t l : {s.front[t], s.behind[t]}) {
                            auto& a = around[all.triangles[3 * t + c]];
                            if (std::find(a.begin(), a.end(), l) == a.end()) a.push_back(l);
                        }
                }
                // each two-label vertex's normal in the lower label's surface, then in the higher's
                std::vector<std::array<float, 3>> lower(all.vertex_count());
                std::vector<char> seen(all.vertex_count(), 0);
                for (const std::int64_t l : s.selected) {
                    const Mesh m = label_surface(s, l);
                    expect_unit_and_with_the_faces(m, what + ", label " + std::to_string(l), counts);
                    const std::vector<std::uint32_t> from = interface_vertices(s, l, m);
                    for (std::size_t i = 0; i < m.vertex_count(); ++i) {
                        const std::uint32_t u = from[i];
                        if (around[u].size() != 2) continue;
                        const std::array<float, 3> n{m.normals[3 * i], m.normals[3 * i + 1], m.normals[3 * i + 2]};
                        if (l == std::min(around[u][0], around[u][1])) {
                            lower[u] = n;
                            seen[u] = 1;
                            for (std::size_t k = 0; k < 3; ++k)
                                EXPECT_EQ(n[k], all.normals[3 * u + k]) << what << ", vertex " << u;
                            continue;
                        }
                        ASSERT_TRUE(seen[u]) << what << ", vertex " << u;
                        ++counts.two_label;
                        for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(n[k], -lower[u][k]) << what << ", vertex " << u;
                    }
                }
            }
    std::cout << counts.vertices << " label surface and interface vertices, " << counts.faint
              << " where the faces' normals nearly cancel, " << counts.two_label << " shared by two labels\n";
    EXPECT_GT(counts.two_label, 1000);
}

// Without LabelOptions::normals nothing has normals.
TEST(Labels, NoNormalsUnlessAsked)
{
    const Volume v = label_checks::random_labels(7, 3, 4, true);
    const LabelSurfaces s = label_surfaces(v);
    EXPECT_FALSE(s.interfaces.has_normals());
    for (const std::int64_t l : s.selected) EXPECT_FALSE(label_surface(s, l).has_normals());
}

TEST(Labels, UniformAndFlatVolumes)
{
    Volume v(ScalarType::u8, {5, 5, 5});
    EXPECT_EQ(label_surfaces(v).interfaces.triangle_count(), 0U);
    Volume flat(ScalarType::u16, {5, 5, 1});
    flat.samples<std::uint16_t>()[3] = 2;
    EXPECT_EQ(label_surfaces(flat).interfaces.triangle_count(), 0U);
}

} // namespace
