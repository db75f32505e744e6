// The NIfTI, .npy and .vti readers on bytes built here: every cut refused, the frame of a sheared
// sform reproduced, header variants read, and what is refused named. The files written by nibabel,
// numpy and VTK are checked against those libraries' coordinates in tests/io/independent_writers.py.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "test_support.hpp"

namespace {

using cmc33::Error;
using cmc33::Status;
using cmc33::Volume;
namespace io = cmc33::io;

/// A little-endian single-file NIfTI-1 of 3x3x2 float32 samples (0, 1, 2, ...), sform code 2.
std::string nifti1(const std::array<std::array<float, 4>, 3>& srow, int frames = 1)
{
    std::vector<std::int16_t> dims{3, 3, 2};
    if (frames > 1) dims.push_back(static_cast<std::int16_t>(frames));
    std::string bytes = cmc33::test::nifti1_header({.dims = dims, .srow = srow});
    for (int i = 0; i < 18 * frames; ++i) {
        const float v = static_cast<float>(i);
        bytes.append(reinterpret_cast<const char*>(&v), 4);
    }
    return bytes;
}

constexpr std::array<std::array<float, 4>, 3> kSheared{
    {{0.9f, 0.2f, 0.1f, -40.5f}, {-0.15f, 1.1f, 0.3f, 12.25f}, {0.05f, -0.25f, -1.3f, 7.0f}}};

Volume read_nifti(const std::string& bytes, io::ReadOptions options = {})
{
    return io::read_volume_from_memory(bytes, io::VolumeFormat::nifti, "t.nii", std::nullopt, {}, options);
}

TEST(VolumeNifti, ShearedSformIsReproduced)
{
    const Volume v = read_nifti(nifti1(kSheared));
    EXPECT_EQ(v.space(), "right-anterior-superior");
    EXPECT_EQ(v.frame_source(), "sform (code 2: aligned anatomy)");
    for (std::size_t r = 0; r < 3; ++r) {
        EXPECT_DOUBLE_EQ(v.origin()[r], static_cast<double>(kSheared[r][3]));
        for (std::size_t c = 0; c < 3; ++c)
            EXPECT_NEAR(v.direction()[r][c] * v.spacing()[c], static_cast<double>(kSheared[r][c]), 1e-15);
    }
    EXPECT_EQ(v.samples<float>()[17], 17.0f);
}

TEST(VolumeNifti, EveryCutAndAnExtraByteAreRefused)
{
    const std::string whole = nifti1(kSheared);
    for (std::size_t n = 0; n < whole.size(); ++n) {
        SCOPED_TRACE(n);
        EXPECT_THROW(read_nifti(whole.substr(0, n)), Error);
    }
    try {
        read_nifti(whole + '\0');
        FAIL() << "an extra byte was accepted";
    } catch (const Error& e) {
        EXPECT_EQ(e.status(), Status::bad_format);
        EXPECT_NE(std::string(e.what()).find("1 more bytes after them"), std::string::npos) << e.what();
    }
}

TEST(VolumeNifti, FramesAreChosenAndAnalyzeIsNamed)
{
    const std::string four = nifti1(kSheared, 3);
    EXPECT_THROW(read_nifti(four), Error);
    io::ReadOptions second;
    second.frame = 2;
    EXPECT_EQ(read_nifti(four, second).samples<float>()[0], 36.0f);
    second.frame = 3;
    EXPECT_THROW(read_nifti(four, second), Error);
    std::string analyze = nifti1(kSheared);
    std::memset(analyze.data() + 344, 0, 4);
    try {
        read_nifti(analyze);
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(e.status(), Status::unsupported_format);
        EXPECT_NE(std::string(e.what()).find("ANALYZE 7.5"), std::string::npos) << e.what();
    }
}

std::string npy(const std::string& dict, const std::string& data)
{
    std::string header = dict;
    while ((10 + header.size() + 1) % 64 != 0) header += ' ';
    header += '\n';
    std::string bytes("\x93NUMPY\x01\x00", 8);
    bytes += static_cast<char>(header.size() & 0xff);
    bytes += static_cast<char>(header.size() >> 8);
    return bytes + header + data;
}

TEST(VolumeNpy, HeaderVariantsAndOrders)
{
    std::string data;
    for (int i = 0; i < 8; ++i) data += static_cast<char>(i);
    // Python 2's long sizes; Fortran order is transposed: element [z, y, x] at z + 2 (y + 2 x)
    const Volume c = io::read_volume_from_memory(npy("{'descr': '|u1', 'fortran_order': False, 'shape': (2L, 2L, 2L), }", data),
                                                 io::VolumeFormat::npy, "c.npy");
    const Volume f = io::read_volume_from_memory(npy("{\"descr\": \"|u1\", \"fortran_order\": True, \"shape\": (2, 2, 2)}", data),
                                                 io::VolumeFormat::npy, "f.npy");
    EXPECT_EQ(c.samples<std::uint8_t>()[1], 1); // x = 1
    EXPECT_EQ(f.samples<std::uint8_t>()[1], 4); // x = 1 is the slowest in the file
    EXPECT_EQ(f.samples<std::uint8_t>()[4], 1); // z = 1 is the fastest in the file
    for (const char* bad : {"{'descr': '|b1', 'fortran_order': False, 'shape': (2, 2, 2)}",
                            "{'descr': '<c8', 'fortran_order': False, 'shape': (2, 2, 2)}",
                            "{'descr': '|u1', 'fortran_order': False, 'shape': (8,)}",
                            "{'descr': '|u1', 'fortran_order': maybe, 'shape': (2, 2, 2)}"}) {
        SCOPED_TRACE(bad);
        EXPECT_THROW(io::read_volume_from_memory(npy(bad, data), io::VolumeFormat::npy, "b.npy"), Error);
    }
}

TEST(VolumeVti, ArraysAreChosenByNameOrScalars)
{
    const std::string vti = R"(<?xml version="1.0"?>
<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian">
<ImageData WholeExtent="1 2 0 1 0 1" Origin="0 0 0" Spacing="2 1 1" Direction="0 -1 0 1 0 0 0 0 1">
<Piece Extent="1 2 0 1 0 1"><PointData>
<DataArray type="Float32" Name="a" format="ascii">0 1 2 3 4 5 6 7</DataArray>
<DataArray type="Int16" Name="b" format="ascii">10 11 12 13 14 15 16 17</DataArray>
</PointData></Piece></ImageData></VTKFile>
)";
    try {
        io::read_volume_from_memory(vti, io::VolumeFormat::vti, "t.vti");
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("\"a\", \"b\""), std::string::npos) << e.what();
    }
    io::ReadOptions b;
    b.array = "b";
    const Volume v = io::read_volume_from_memory(vti, io::VolumeFormat::vti, "t.vti", std::nullopt, {}, b);
    EXPECT_EQ(v.type(), cmc33::ScalarType::i16);
    EXPECT_EQ(v.samples<std::int16_t>()[7], 17);
    // extent from i = 1: the origin moves one step along the direction of i, (0, 1, 0), times 2
    EXPECT_DOUBLE_EQ(v.origin()[1], 2.0);
    EXPECT_DOUBLE_EQ(v.direction()[1][0], 1.0);
    EXPECT_DOUBLE_EQ(v.spacing()[0], 2.0);
}

} // namespace
