// The TIFF reader against tifffile, an independent writer (tests/io/write_tiff.py): ImageJ stacks
// and hyperstacks, OME-TIFF, strips and tiles, deflate, big-endian, BigTIFF, float32, a folder of
// numbered slices, and the stacks that must be refused in one line.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/io.hpp"
#include "test_support.hpp"
#include "tiff.hpp"

namespace cmc33 {
namespace {

namespace fs = std::filesystem;

/// The samples as doubles, x fastest.
std::vector<double> as_doubles(const Volume& volume)
{
    return dispatch_scalar_type(volume.type(), [&](auto tag) {
        using T = decltype(tag);
        const T* p = volume.samples<T>();
        return std::vector<double>(p, p + volume.sample_count());
    });
}

const fs::path& stacks_dir()
{
    static const fs::path dir = test::run_writer(CMC33_SYSTEM_PYTHON, CMC33_WRITE_TIFF, "cmc33_test_tiff_");
    return dir;
}

class Tiff : public ::testing::Test {
protected:
    void SetUp() override
    {
        if (!io::detail::tiff_supported()) GTEST_SKIP() << "this build has no TIFF reader (libtiff not found)";
        ASSERT_FALSE(stacks_dir().empty()) << "write_tiff.py failed: needs python3-tifffile and python3-numpy";
    }
    static Volume read(const std::string& name, const io::ReadOptions& options = {})
    {
        return io::read_volume(stacks_dir() / name, std::nullopt, options);
    }
    static std::string error_of(const std::string& name, const io::ReadOptions& options = {})
    {
        try {
            (void)read(name, options);
        } catch (const Error& e) {
            return e.what();
        }
        return "(no error)";
    }
};

/// The samples are tifffile's volume[z, y, x], the spacing the one the case declares, and the
/// mesh is the index-space mesh scaled by it.
void check_against_tifffile(const Volume& volume, const std::string& name)
{
    std::ifstream in(stacks_dir() / (name + ".json"));
    const nlohmann::json want = nlohmann::json::parse(in);
    for (std::size_t a = 0; a < 3; ++a) {
        EXPECT_EQ(volume.dims()[a], want["dims"][a].get<std::int64_t>()) << name;
        EXPECT_NEAR(volume.spacing()[a], want["spacing"][a].get<double>(), 1e-6) << name;
    }
    const auto& values = want["values"];
    ASSERT_EQ(values.size(), static_cast<std::size_t>(volume.sample_count()));
    Volume reference(ScalarType::f64, volume.dims());
    double* ref = reference.samples<double>();
    const std::vector<double> got = as_doubles(volume);
    for (std::size_t i = 0; i < values.size(); ++i) {
        ASSERT_NEAR(got[i], values[i].get<double>(), 1e-6 * (1 + std::fabs(got[i]))) << name << " sample " << i;
        ref[i] = got[i];
    }
    double lo = ref[0], hi = ref[0];
    for (std::size_t i = 0; i < values.size(); ++i) lo = std::min(lo, ref[i]), hi = std::max(hi, ref[i]);
    const double iso = lo + 0.6 * (hi - lo) + 0.25;
    const Mesh mesh = extract(volume, iso);
    const Mesh index_mesh = extract(reference, iso);
    ASSERT_GT(mesh.triangle_count(), 0u) << name;
    ASSERT_EQ(mesh.triangle_count(), index_mesh.triangle_count()) << name;
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        for (std::size_t a = 0; a < 3; ++a) {
            const double world = want["spacing"][a].get<double>() * static_cast<double>(index_mesh.positions[3 * v + a]);
            ASSERT_NEAR(static_cast<double>(mesh.positions[3 * v + a]), world, 1e-5 * (1 + std::fabs(world))) << name;
        }
    }
}

TEST_F(Tiff, ImageJStackWithSpacing) { check_against_tifffile(read("imagej.tif"), "imagej"); }
TEST_F(Tiff, TiledDeflateFloat32)
{
    const Volume v = read("float.tif");
    EXPECT_EQ(v.type(), ScalarType::f32);
    check_against_tifffile(v, "float");
}
TEST_F(Tiff, BigEndianStripsInt16) { check_against_tifffile(read("strips.tif"), "strips"); }
TEST_F(Tiff, BigTiffInt32) { check_against_tifffile(read("big.tif"), "big"); }
TEST_F(Tiff, OmeTiffPhysicalSize) { check_against_tifffile(read("ome.ome.tif"), "ome"); }

TEST_F(Tiff, HyperstackFrames)
{
    io::ReadOptions options;
    options.frame = 1;
    check_against_tifffile(read("frames.tif", options), "frames1");
    const std::string e = error_of("frames.tif");
    EXPECT_NE(e.find("3 time frames; choose one with --frame N (0 to 2)"), std::string::npos) << e;
    options.frame = 3;
    EXPECT_NE(error_of("frames.tif", options).find("--frame 3 is out of range"), std::string::npos);
}

TEST_F(Tiff, FolderSortedNumerically)
{
    check_against_tifffile(read("folder"), "folder");
    EXPECT_EQ(io::volume_files(stacks_dir() / "folder").size(), 7u);
    EXPECT_TRUE(io::is_tiff_input(stacks_dir() / "folder"));
}

TEST_F(Tiff, SpacingOptionReplacesTheFiles)
{
    io::ReadOptions options;
    options.spacing = Vec3{2, 3, 4};
    const Volume v = read("imagej.tif", options);
    EXPECT_EQ(v.spacing(), (Vec3{2, 3, 4}));
}

TEST_F(Tiff, RefusedStacksNameTheProblem)
{
    std::string e = error_of("gap");
    EXPECT_NE(e.find("missing slice 4 between s_003.tif and s_005.tif"), std::string::npos) << e;
    e = error_of("sizes");
    EXPECT_NE(e.find("a2.tif holds 5x9"), std::string::npos) << e;
    e = error_of("rgb.tif");
    EXPECT_NE(e.find("3 samples per pixel (RGB)"), std::string::npos) << e;
    e = error_of("channels.tif");
    EXPECT_NE(e.find("2 channels"), std::string::npos) << e;
    for (const std::string name : {"gap", "sizes", "rgb.tif", "channels.tif"}) {
        EXPECT_EQ(error_of(name).find('\n'), std::string::npos) << name;
    }
}

TEST_F(Tiff, CutFilesAreRefusedNotCrashed)
{
    const std::string bytes = test::read_file(stacks_dir() / "strips.tif");
    for (std::size_t cut : {std::size_t{8}, bytes.size() / 3, bytes.size() / 2, bytes.size() - 1}) {
        try {
            (void)io::read_volume_from_memory(std::string_view(bytes).substr(0, cut), io::VolumeFormat::tiff, "cut.tif");
        } catch (const Error& e) {
            EXPECT_EQ(std::string(e.what()).rfind("cut.tif: ", 0), 0u) << e.what();
        }
    }
}

} // namespace
} // namespace cmc33
