// A NIfTI-1 pair named by either of its files: x.hdr + x.img, and the compressed x.hdr.gz +
// x.img.gz nibabel writes. Reading the data file alone goes through its header, and volume_files()
// lists the data file the reader opens, so the CLI never writes over it.

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "cmc33/io.hpp"
#include "test_support.hpp"

namespace {

namespace fs = std::filesystem;
namespace io = cmc33::io;
using cmc33::Volume;

/// A little-endian NIfTI-1 pair header ("ni1") for 3x3x2 float32 samples, qform and sform unset.
std::string pair_header()
{
    return cmc33::test::nifti1_header({.dims = {3, 3, 2}, .magic = "ni1"});
}

std::string pair_samples()
{
    std::string bytes;
    for (int i = 0; i < 18; ++i) {
        const float v = static_cast<float>(i);
        bytes.append(reinterpret_cast<const char*>(&v), 4);
    }
    return bytes;
}

class NiftiPair : public ::testing::Test {
protected:
    void SetUp() override
    {
        dir_ = fs::temp_directory_path() / ("cmc33-nifti-pair-" + std::to_string(::getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    fs::path dir_;
};

TEST_F(NiftiPair, PlainPairByEitherFile)
{
    cmc33::test::write_file(dir_ / "x.hdr", pair_header());
    cmc33::test::write_file(dir_ / "x.img", pair_samples());
    for (const char* name : {"x.hdr", "x.img"}) {
        SCOPED_TRACE(name);
        const Volume v = io::read_volume(dir_ / name);
        EXPECT_EQ(v.samples<float>()[17], 17.0f);
    }
    const std::vector<fs::path> by_header = io::volume_files(dir_ / "x.hdr");
    ASSERT_EQ(by_header.size(), 2u);
    EXPECT_EQ(by_header[1], dir_ / "x.img");
    const std::vector<fs::path> by_image = io::volume_files(dir_ / "x.img");
    ASSERT_EQ(by_image.size(), 2u);
    EXPECT_EQ(by_image[1], dir_ / "x.hdr");
}

TEST_F(NiftiPair, CompressedPairByEitherFile)
{
    cmc33::test::write_file(dir_ / "x.hdr.gz", cmc33::test::gzip_bytes(pair_header()));
    cmc33::test::write_file(dir_ / "x.img.gz", cmc33::test::gzip_bytes(pair_samples()));
    for (const char* name : {"x.hdr.gz", "x.img.gz"}) {
        SCOPED_TRACE(name);
        EXPECT_TRUE(io::has_volume_header(dir_ / name));
        const Volume v = io::read_volume(dir_ / name);
        EXPECT_EQ(v.dims()[2], 2);
        EXPECT_EQ(v.samples<float>()[17], 17.0f);
    }
    // the data file the reader opens, not x.hdr.img
    const std::vector<fs::path> by_header = io::volume_files(dir_ / "x.hdr.gz");
    ASSERT_EQ(by_header.size(), 2u);
    EXPECT_EQ(by_header[1], dir_ / "x.img.gz");
    const std::vector<fs::path> by_image = io::volume_files(dir_ / "x.img.gz");
    ASSERT_EQ(by_image.size(), 2u);
    EXPECT_EQ(by_image[1], dir_ / "x.hdr.gz");
}

TEST_F(NiftiPair, SingleFilesNameNoDataFile)
{
    const std::string single = cmc33::test::nifti1_header({.dims = {3, 3, 2}}) + pair_samples();
    cmc33::test::write_file(dir_ / "s.nii", single);
    cmc33::test::write_file(dir_ / "s.nii.gz", cmc33::test::gzip_bytes(single));
    for (const char* name : {"s.nii", "s.nii.gz"}) {
        SCOPED_TRACE(name);
        EXPECT_EQ(io::volume_files(dir_ / name), std::vector<fs::path>{dir_ / name});
        EXPECT_EQ(io::read_volume(dir_ / name).samples<float>()[17], 17.0f);
    }
}

} // namespace
