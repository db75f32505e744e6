// label_surfaces() on segmentations made from the shared volumes by thresholds (tissue classes):
// the checks of label_checks.cpp.

#include <gtest/gtest.h>

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

void check_volume(const std::string& file, const std::vector<double>& thresholds)
{
    const auto path = test::shared_volume(file);
    if (!path) {
        GTEST_SKIP() << file << " not found";
    }
    const Volume seg = classes(io::read_volume(*path), thresholds);
    label_checks::Counts c;
    label_checks::check_field(seg, c, file);
    std::cout << file << ": " << c.label_surfaces << " label surfaces; not manifold " << c.not_manifold << " ("
              << c.nonmanifold_edges << " edges, " << c.nonmanifold_vertices << " vertices)"
              << ", not closed " << c.not_closed << ", not oriented " << c.not_oriented << ", not embedded "
              << c.not_embedded << ", union not watertight " << c.union_not_watertight << ", union not embedded "
              << c.union_not_embedded << ", repeated " << c.duplicate_triangles << ", two-label mismatch "
              << c.two_label_mismatch << ", topology mismatch " << c.topology_mismatch << "\n";
    EXPECT_EQ(c.not_closed + c.not_oriented + c.not_embedded + c.union_not_watertight + c.union_not_embedded +
                  c.duplicate_triangles + c.two_label_mismatch + c.topology_mismatch + c.not_manifold,
              0)
        << c.first_failure;
}

TEST(LabelsVolumes, ToothThreeClasses)
{
    check_volume("tooth_103x94x161_uint8.nrrd", {100, 190});
}
TEST(LabelsVolumes, ToothTwoClasses)
{
    check_volume("tooth_103x94x161_uint8.nrrd", {120});
}
TEST(LabelsVolumes, CTheadThreeClasses)
{
    check_volume("CThead_256x256x113_uint16.nrrd", {600, 1400});
}

} // namespace
