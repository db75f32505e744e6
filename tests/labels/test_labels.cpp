// label_surfaces() (src/labels): random label fields of 5^3 to 9^3 samples with 2, 3 and 4 labels
// checked from the mesh alone (label_checks.cpp), determinism, the frame, selection and bad input.

#include <gtest/gtest.h>

#include <cstring>
#include <iostream>
#include <string>

#include "cmc33/error.hpp"
#include "cmc33/labels.hpp"
#include "cmc33/topology.hpp"
#include "label_checks.hpp"

namespace {

using namespace cmc33;
using label_checks::Counts;

Counts sweep(int labels, int fields, bool smooth)
{
    Counts c;
    for (int n = 0; n < fields; ++n) {
        const std::int64_t size = 5 + n % 5;
        const Volume v = label_checks::random_labels(size, labels, static_cast<std::uint64_t>(n), smooth);
        label_checks::check_field(v, c,
                                  std::to_string(labels) + " labels, " + (smooth ? "smooth" : "i.i.d.") + " field " +
                                      std::to_string(n) + " (" + std::to_string(size) + "^3)");
    }
    std::cout << labels << " labels, " << (smooth ? "smooth" : "i.i.d.") << ": " << c.fields << " fields, "
              << c.label_surfaces << " label surfaces; not closed " << c.not_closed << ", not manifold "
              << c.not_manifold << " (" << c.nonmanifold_edges << " edges, " << c.nonmanifold_vertices
              << " vertices), not oriented " << c.not_oriented << ", not embedded " << c.not_embedded
              << ", union not watertight " << c.union_not_watertight << ", union not embedded " << c.union_not_embedded
              << ", repeated triangles " << c.duplicate_triangles << ", two-label mismatches " << c.two_label_mismatch
              << ", topology mismatches " << c.topology_mismatch << (c.first_failure.empty() ? "" : "; first: ")
              << c.first_failure << "\n";
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
}

TEST(Labels, TwoLabelFieldsAreTheIndicatorsLevelSet)
{
    for (const bool smooth : {false, true}) {
        const Counts c = sweep(2, 200, smooth);
        expect_guarantees(c);
        EXPECT_EQ(c.two_label_mismatch, 0) << c.first_failure;
        EXPECT_EQ(c.topology_mismatch, 0) << c.first_failure;
    }
}

// Three and four labels: closed, oriented, embedded and watertight; the non-manifold surfaces
// (a label meeting itself at a cell centre, docs/labels.md) are counted, not failed.
TEST(Labels, ThreeAndFourLabelFields)
{
    for (const int labels : {3, 4})
        for (const bool smooth : {false, true}) {
            Counts c = sweep(labels, 75, smooth);
            c.not_manifold = 0; // counted, not failed (see above)
            expect_guarantees(c);
        }
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
}

// The cell pass runs on z-ranges welded afterwards: every thread count gives the same bytes,
// including more threads than cell layers and a rotated frame.
TEST(Labels, SameOutputForEveryThreadCount)
{
    for (const int labels : {2, 4})
        for (const bool smooth : {false, true})
            for (const std::uint64_t seed : {1U, 2U}) {
                Volume v = label_checks::random_labels(9, labels, seed, smooth);
                if (seed == 2) v.set_direction({{{0.6, 0.8, 0}, {-0.8, 0.6, 0}, {0, 0, 1}}});
                LabelOptions o;
                o.threads = 1;
                const LabelSurfaces one = label_surfaces(v, o);
                EXPECT_GT(one.interfaces.triangle_count(), 0U);
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

TEST(Labels, UniformAndFlatVolumes)
{
    Volume v(ScalarType::u8, {5, 5, 5});
    EXPECT_EQ(label_surfaces(v).interfaces.triangle_count(), 0U);
    Volume flat(ScalarType::u16, {5, 5, 1});
    flat.samples<std::uint16_t>()[3] = 2;
    EXPECT_EQ(label_surfaces(flat).interfaces.triangle_count(), 0U);
}

} // namespace
