// label_surfaces() on segmentations made from the shared volumes by thresholds (tissue classes):
// the checks of label_checks.cpp; and the aneurism's connected components, each a label.

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <vector>

#include "cmc33/io.hpp"
#include "cmc33/labels.hpp"
#include "label_checks.hpp"
#include "test_support.hpp"

namespace {

using namespace cmc33;

// Class c of a sample is the number of thresholds at or below its value.
Volume classes(const Volume& v, const std::vector<double>& thresholds)
{
    Volume out(ScalarType::i32, v.dims(), v.spacing(), v.origin());
    std::int32_t* s = out.samples<std::int32_t>();
    v.visit([&](const auto& g) {
        std::int64_t n = 0;
        for (std::int64_t k = 0; k < g.nz(); ++k)
            for (std::int64_t j = 0; j < g.ny(); ++j)
                for (std::int64_t i = 0; i < g.nx(); ++i) {
                    int c = 0;
                    for (const double t : thresholds) c += static_cast<double>(g(i, j, k)) >= t ? 1 : 0;
                    s[n++] = c;
                }
    });
    return out;
}

// The connected components (through faces) of the samples at or above `iso`, numbered 1, 2, ... in
// the order of their first sample; 0 elsewhere.
Volume components(const Volume& v, double iso)
{
    Volume out = classes(v, {iso}); // 1 at or above iso: a sample no component has reached yet
    std::int32_t* s = out.samples<std::int32_t>();
    const Index3 n = out.dims();
    std::vector<std::int64_t> stack;
    std::int32_t id = 1; // components take 2, 3, ... while 1 means "not reached"
    for (std::int64_t start = 0; start < out.sample_count(); ++start) {
        if (s[start] != 1) continue;
        s[start] = ++id;
        stack.push_back(start);
        while (!stack.empty()) {
            const std::int64_t at = stack.back();
            stack.pop_back();
            const Index3 p{at % n[0], at / n[0] % n[1], at / (n[0] * n[1])};
            const Index3 step{1, n[0], n[0] * n[1]};
            for (std::size_t axis = 0; axis < 3; ++axis) {
                for (const std::int64_t d : {-1, 1}) {
                    if (p[axis] + d < 0 || p[axis] + d >= n[axis]) continue;
                    const std::int64_t to = at + d * step[axis];
                    if (s[to] != 1) continue;
                    s[to] = id;
                    stack.push_back(to);
                }
            }
        }
    }
    for (std::int64_t i = 0; i < out.sample_count(); ++i) s[i] = s[i] == 0 ? 0 : s[i] - 1;
    return out;
}

void check_segmentation(const std::string& file, const Volume& seg, double sigma = 0)
{
    label_checks::Counts c;
    label_checks::check_field(seg, c, file, sigma);
    std::cout << file << ": " << c.label_surfaces << " label surfaces; not manifold " << c.not_manifold << " ("
              << c.nonmanifold_edges << " edges, " << c.nonmanifold_vertices << " vertices)"
              << ", not closed " << c.not_closed << ", not oriented " << c.not_oriented << ", not embedded "
              << c.not_embedded << ", union not watertight " << c.union_not_watertight << ", union not embedded "
              << c.union_not_embedded << ", repeated " << c.duplicate_triangles << ", two-label mismatch "
              << c.two_label_mismatch << ", topology mismatch " << c.topology_mismatch << " (of "
              << c.two_label_compared << " compared), Euler characteristic not the labels' " << c.euler_mismatch
              << ", Betti numbers or loops not the labels' " << c.betti_mismatch << " (of " << c.betti_compared
              << ")\n";
    EXPECT_EQ(c.not_closed + c.not_oriented + c.not_embedded + c.union_not_watertight + c.union_not_embedded +
                  c.duplicate_triangles + c.two_label_mismatch + c.topology_mismatch + c.not_manifold +
                  c.euler_mismatch + c.betti_mismatch,
              0)
        << c.first_failure;
}

void check_volume(const std::string& file, const std::vector<double>& thresholds, double sigma = 0)
{
    const auto path = test::shared_volume(file);
    if (!path) {
        GTEST_SKIP() << file << " not found";
    }
    check_segmentation(file + (sigma > 0 ? ", smoothed" : ""), classes(io::read_volume(*path), thresholds), sigma);
}

TEST(LabelsVolumes, ToothThreeClasses)
{
    check_volume("tooth_103x94x161_uint8.nrrd", {100, 190});
}
TEST(LabelsVolumes, ToothTwoClasses)
{
    check_volume("tooth_103x94x161_uint8.nrrd", {120});
}
// smooth labels (LabelOptions::smooth): the same checks (two classes are compared with the
// extraction of the filtered indicator only where no sample or face saddle is within rounding of
// the tie, which a real volume's many samples rarely allow)
TEST(LabelsVolumes, ToothThreeClassesSmoothed)
{
    check_volume("tooth_103x94x161_uint8.nrrd", {100, 190}, 1.0);
}
TEST(LabelsVolumes, ToothTwoClassesSmoothed)
{
    check_volume("tooth_103x94x161_uint8.nrrd", {120}, 1.5);
}
TEST(LabelsVolumes, CTheadThreeClasses)
{
    check_volume("CThead_256x256x113_uint16.nrrd", {600, 1400});
}
TEST(LabelsVolumes, BonsaiThreeClasses)
{
    check_volume("bonsai_256x256x256_uint8.nrrd", {40.5, 150.5});
}
// the vessels' ~1,300 connected components at 80.5, each a label
TEST(LabelsVolumes, AneurismComponents)
{
    const std::string file = "aneurism_256x256x256_uint8.nrrd";
    const auto path = test::shared_volume(file);
    if (!path) {
        GTEST_SKIP() << file << " not found";
    }
    const Volume seg = components(io::read_volume(*path), 80.5);
    std::int32_t most = 0;
    for (std::int64_t i = 0; i < seg.sample_count(); ++i) most = std::max(most, seg.samples<std::int32_t>()[i]);
    EXPECT_GT(most, 1000);
    check_segmentation(file + " components", seg);
}

} // namespace
