// The real volumes in ../shared/data/volumes read with the dims, type, spacing and value range
// their README gives (skipped when shared/ is absent). The value ranges pin the byte order: CThead
// is big-endian and gzip, a wrong swap would show values far outside 0..3272.

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "cmc33/io.hpp"
#include "test_support.hpp"

namespace cmc33::io {
namespace {

struct SharedVolume {
    std::string file;
    Index3 dims;
    ScalarType type;
    Vec3 spacing;
    std::optional<std::pair<double, double>> range; // where the README states it
};

const std::vector<SharedVolume>& shared_volumes()
{
    using R = std::pair<double, double>;
    static const std::vector<SharedVolume> volumes{
        {"aneurism_256x256x256_uint8.nrrd",
         {256, 256, 256},
         ScalarType::u8,
         {1, 1, 1},
         std::nullopt},
        {"bonsai_256x256x256_uint8.nrrd", {256, 256, 256}, ScalarType::u8, {1, 1, 1}, std::nullopt},
        {"engine_256x256x128_uint8.nrrd", {256, 256, 128}, ScalarType::u8, {1, 1, 1}, std::nullopt},
        {"tooth_103x94x161_uint8.nrrd", {103, 94, 161}, ScalarType::u8, {1, 1, 1}, std::nullopt},
        {"nucleon_41x41x41_uint8.nrrd", {41, 41, 41}, ScalarType::u8, {1, 1, 1}, std::nullopt},
        {"silicium_98x34x34_uint8.nrrd", {98, 34, 34}, ScalarType::u8, {1, 1, 1}, std::nullopt},
        {"CThead_256x256x113_uint16.nrrd", {256, 256, 113}, ScalarType::u16, {1, 1, 2}, R{0, 3272}},
        {"headsq_quarter_64x64x93_uint16.nrrd",
         {64, 64, 93},
         ScalarType::u16,
         {3.2, 3.2, 1.5},
         R{0, 3926}},
        {"ironProt_68x68x68_uint8.nrrd", {68, 68, 68}, ScalarType::u8, {1, 1, 1}, std::nullopt},
        {"neghip_66x66x66_uint8.nrrd", {66, 66, 66}, ScalarType::u8, {1, 1, 1}, std::nullopt},
        {"Bucky_32x32x32_uint8.nrrd", {32, 32, 32}, ScalarType::u8, {1, 1, 1}, std::nullopt},
        {"HeadMRVolume_48x62x42_uint8.nrrd", {48, 62, 42}, ScalarType::u8, {4, 4, 4}, std::nullopt},
        {"mri_head_256x256x256_uint8.nrrd",
         {256, 256, 256},
         ScalarType::u8,
         {1, 1, 1},
         std::nullopt},
        {"LIDC2_256x256x133_uint8.nrrd",
         {256, 256, 133},
         ScalarType::u8,
         {1.40625, 1.40625, 2.5},
         std::nullopt},
        {"stent_128x128x256_int16.nrrd", {128, 128, 256}, ScalarType::i16, {1, 1, 1}, R{0, 2000}},
        {"walnut_128x96x114_uint16.nrrd", {128, 96, 114}, ScalarType::u16, {1, 1, 1}, R{0, 22526}},
        {"stagbeetle_138x138x82_uint16.nrrd",
         {138, 138, 82},
         ScalarType::u16,
         {1, 1, 1},
         R{0, 2716}},
        {"Cranium_256x256x108_int16.nrrd",
         {256, 256, 108},
         ScalarType::i16,
         {0.9570312, 0.9570312, 1.5},
         R{-1024, 2986}},
        {"ch2_181x217x181_uint8.nrrd", {181, 217, 181}, ScalarType::u8, {1, 1, 1}, std::nullopt},
    };
    return volumes;
}

TEST(VolumeShared, EveryVolumeReadsAsTheReadmeSays)
{
    int found = 0;
    for (const SharedVolume& expected : shared_volumes()) {
        const auto path = test::shared_volume(expected.file);
        if (!path) continue;
        ++found;
        SCOPED_TRACE(expected.file);
        const Volume v = read_volume(*path);
        EXPECT_EQ(v.dims(), expected.dims);
        EXPECT_EQ(v.type(), expected.type) << type_name(v.type());
        for (std::size_t axis = 0; axis < 3; ++axis) {
            EXPECT_NEAR(v.spacing()[axis], expected.spacing[axis], 1e-6) << "axis " << axis;
        }
        EXPECT_EQ(v.origin(), (Vec3{0, 0, 0}));
        const auto [lo, hi] = value_range(v);
        if (expected.range) {
            EXPECT_EQ(lo, expected.range->first);
            EXPECT_EQ(hi, expected.range->second);
        } else {
            EXPECT_LT(lo, hi); // not a constant (e.g. all-zero) volume
        }
    }
    if (found == 0) GTEST_SKIP() << "shared/data/volumes is not beside the repository";
}

} // namespace
} // namespace cmc33::io
