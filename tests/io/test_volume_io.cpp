// Volume I/O that must work: round trips of every type through every format, hand-written files
// in the variants real writers produce (big-endian, gzip, zlib, ASCII, detached, skips), the
// choice of format by extension, and parse_type.

#include <gtest/gtest.h>


#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "cmc33/io.hpp"
#include "test_support.hpp"

namespace cmc33::io {
namespace {

using test::read_file;
using test::gzip_bytes;
using test::temp_dir;
using test::zlib_bytes;
using test::write_file;

// ---- building files -------------------------------------------------------------------------


/// The bytes of `values` in the given byte order.
template <class T> std::string bytes_of(const std::vector<T>& values, Endian endian)
{
    std::string out;
    for (T v : values) {
        unsigned char b[sizeof(T)];
        std::memcpy(b, &v, sizeof(T));
        const bool reverse = (endian == Endian::big) != (std::endian::native == std::endian::big);
        for (std::size_t i = 0; i < sizeof(T); ++i)
            out += static_cast<char>(b[reverse ? sizeof(T) - 1 - i : i]);
    }
    return out;
}

template <class T> std::vector<T> samples_of(const Volume& v)
{
    const T* p = v.samples<T>();
    return std::vector<T>(p, p + v.sample_count());
}

template <class T> std::vector<T> ramp(std::size_t n, T first, T step)
{
    std::vector<T> values;
    for (std::size_t i = 0; i < n; ++i)
        values.push_back(static_cast<T>(first + static_cast<T>(i) * step));
    return values;
}

// ---- round trips ----------------------------------------------------------------------------

/// Non-trivial samples: the type's extremes, negative values, non-integer floats.
template <class T> Volume sample_volume()
{
    Volume v(scalar_type_of<T>(), {5, 4, 3}, {0.1, 2.5, 1.0 / 3.0}, {-12.75, 1e-3, 7.0 / 3.0});
    T* p = v.samples<T>();
    const std::int64_t n = v.sample_count();
    for (std::int64_t i = 0; i < n; ++i) {
        if constexpr (std::is_floating_point_v<T>) {
            p[i] = static_cast<T>(static_cast<double>(i) * 0.37 - 7.1);
        } else {
            // Wraps modulo 2^bits (well defined since C++20): covers the whole range.
            p[i] = static_cast<T>(static_cast<std::uint64_t>(i) * 2654435761u + 12345u);
        }
    }
    p[0] = std::numeric_limits<T>::lowest();
    p[1] = std::numeric_limits<T>::max();
    p[2] = 0;
    p[3] = std::is_signed_v<T> ? static_cast<T>(-1) : static_cast<T>(1);
    if constexpr (std::is_floating_point_v<T>) {
        p[4] = std::numeric_limits<T>::denorm_min();
        p[5] = static_cast<T>(-0.0);
        p[6] = static_cast<T>(1.0 / 3.0);
    }
    return v;
}

void expect_same(const Volume& a, const Volume& b, bool same_place)
{
    EXPECT_EQ(a.type(), b.type());
    EXPECT_EQ(a.dims(), b.dims());
    if (same_place) {
        EXPECT_EQ(a.spacing(), b.spacing());
        EXPECT_EQ(a.origin(), b.origin());
    }
    ASSERT_EQ(a.byte_size(), b.byte_size());
    EXPECT_EQ(std::memcmp(a.bytes(), b.bytes(), a.byte_size()), 0) << "samples differ";
}

template <class T> void round_trip_all_formats()
{
    SCOPED_TRACE(std::string(type_name(scalar_type_of<T>())));
    const auto dir = temp_dir();
    const Volume v = sample_volume<T>();
    for (const char* name : {"v.nrrd", "v_nhdr.nhdr", "v_mhd.mhd", "v.mha", "v.vtk"}) {
        SCOPED_TRACE(name);
        write_volume(v, dir / name);
        expect_same(read_volume(dir / name), v, true);
    }
    // Raw: no header; the spacing comes from the options, the origin is 0.
    write_volume(v, dir / "v.raw");
    RawOptions options;
    options.dims = v.dims();
    options.type = v.type();
    options.spacing = {0.5, 0.25, 4};
    options.endian = std::endian::native == std::endian::big ? Endian::big : Endian::little;
    const Volume raw = read_volume(dir / "v.raw", options);
    expect_same(raw, v, false);
    EXPECT_EQ(raw.spacing(), options.spacing);
    EXPECT_EQ(raw.origin(), (Vec3{0, 0, 0}));
    EXPECT_EQ(std::filesystem::file_size(dir / "v.raw"), v.byte_size());

    // Detached headers put their samples beside them; no temporary file is left behind.
    std::set<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(dir))
        names.insert(entry.path().filename().string());
    EXPECT_EQ(names, (std::set<std::string>{"v.nrrd", "v_nhdr.nhdr", "v_nhdr.raw", "v_mhd.mhd",
                                            "v_mhd.raw", "v.mha", "v.vtk", "v.raw"}));
}

TEST(VolumeRoundTrip, Int8)
{
    round_trip_all_formats<std::int8_t>();
}
TEST(VolumeRoundTrip, UInt8)
{
    round_trip_all_formats<std::uint8_t>();
}
TEST(VolumeRoundTrip, Int16)
{
    round_trip_all_formats<std::int16_t>();
}
TEST(VolumeRoundTrip, UInt16)
{
    round_trip_all_formats<std::uint16_t>();
}
TEST(VolumeRoundTrip, Int32)
{
    round_trip_all_formats<std::int32_t>();
}
TEST(VolumeRoundTrip, UInt32)
{
    round_trip_all_formats<std::uint32_t>();
}
TEST(VolumeRoundTrip, Float)
{
    round_trip_all_formats<float>();
}
TEST(VolumeRoundTrip, Double)
{
    round_trip_all_formats<double>();
}

TEST(VolumeRoundTrip, ExtensionCaseIsIgnored)
{
    const auto dir = temp_dir();
    const Volume v = sample_volume<std::uint16_t>();
    write_volume(v, dir / "UPPER.NRRD");
    expect_same(read_volume(dir / "UPPER.NRRD"), v, true);
}

TEST(VolumeRoundTrip, OverwritesAnExistingFile)
{
    const auto dir = temp_dir();
    write_file(dir / "v.nrrd", "old content");
    const Volume v = sample_volume<float>();
    write_volume(v, dir / "v.nrrd");
    expect_same(read_volume(dir / "v.nrrd"), v, true);
}

// ---- what the writers put in the files ------------------------------------------------------

TEST(VolumeWriters, NrrdHeaderIsValidNrrd)
{
    const auto dir = temp_dir();
    Volume v(ScalarType::u16, {2, 3, 4}, {0.5, 1, 2}, {1, -2, 3.25});
    v.samples<std::uint16_t>()[0] = 0x0102;
    write_volume(v, dir / "a.nrrd");
    const std::string file = read_file(dir / "a.nrrd");
    EXPECT_EQ(file.rfind("NRRD0004\n", 0), 0u);
    for (const char* line :
         {"\ntype: uint16\n", "\ndimension: 3\n", "\nsizes: 2 3 4\n", "\nendian: little\n",
          "\nencoding: raw\n", "\nspace dimension: 3\n",
          "\nspace directions: (0.5,0,0) (0,1,0) (0,0,2)\n", "\nspace origin: (1,-2,3.25)\n"}) {
        EXPECT_NE(file.find(line), std::string::npos) << line;
    }
    const std::size_t data = file.find("\n\n") + 2;
    EXPECT_EQ(file.size() - data, v.byte_size());
    EXPECT_EQ(file.substr(data, 2), std::string("\x02\x01", 2)); // little-endian
}

TEST(VolumeWriters, VtkIsBigEndianStructuredPoints)
{
    const auto dir = temp_dir();
    Volume v(ScalarType::u16, {2, 2, 2}, {1, 2, 3}, {4, 5, 6});
    v.samples<std::uint16_t>()[0] = 0x0102;
    write_volume(v, dir / "a.vtk");
    const std::string file = read_file(dir / "a.vtk");
    EXPECT_EQ(file.rfind("# vtk DataFile Version", 0), 0u);
    for (const char* line : {"\nBINARY\n", "\nDATASET STRUCTURED_POINTS\n", "\nDIMENSIONS 2 2 2\n",
                             "\nSPACING 1 2 3\n", "\nORIGIN 4 5 6\n", "\nPOINT_DATA 8\n",
                             "\nSCALARS scalars unsigned_short 1\n"}) {
        EXPECT_NE(file.find(line), std::string::npos) << line;
    }
    const std::size_t data = file.find("LOOKUP_TABLE default\n") + 21;
    EXPECT_EQ(file.size() - data, v.byte_size());
    EXPECT_EQ(file.substr(data, 2), std::string("\x01\x02", 2)); // big-endian
}

TEST(VolumeWriters, MetaImageHeaders)
{
    const auto dir = temp_dir();
    Volume v(ScalarType::i16, {2, 2, 3}, {0.25, 0.5, 1.5}, {-1, 0, 1});
    write_volume(v, dir / "a.mhd");
    const std::string mhd = read_file(dir / "a.mhd");
    for (const char* line :
         {"ObjectType = Image\n", "NDims = 3\n", "DimSize = 2 2 3\n", "ElementType = MET_SHORT\n",
          "ElementSpacing = 0.25 0.5 1.5\n", "Offset = -1 0 1\n",
          "BinaryDataByteOrderMSB = False\n", "ElementDataFile = a.raw\n"}) {
        EXPECT_NE(mhd.find(line), std::string::npos) << line;
    }
    EXPECT_EQ(std::filesystem::file_size(dir / "a.raw"), v.byte_size());
    write_volume(v, dir / "b.mha");
    const std::string mha = read_file(dir / "b.mha");
    EXPECT_EQ(mha.size() - (mha.find("ElementDataFile = LOCAL\n") + 24), v.byte_size());
}

TEST(VolumeWriters, SpacingAndOriginAreWrittenExactly)
{
    const auto dir = temp_dir();
    // Values that need 17 significant digits.
    const Vec3 spacing{0.1 + 0.2, std::nextafter(1.0, 2.0), 1e-300};
    const Vec3 origin{-std::numeric_limits<double>::max(), 1.0 / 7.0,
                      -std::numeric_limits<double>::denorm_min()};
    Volume v(ScalarType::u8, {2, 2, 2}, spacing, origin);
    for (const char* name : {"a.nrrd", "a.nhdr", "a.mhd", "a.mha", "a.vtk"}) {
        write_volume(v, dir / name);
        const Volume back = read_volume(dir / name);
        EXPECT_EQ(back.spacing(), spacing) << name;
        EXPECT_EQ(back.origin(), origin) << name;
    }
}

// ---- hand-written files ---------------------------------------------------------------------

// A volume of several MiB sits in memory advised for 2 MiB pages from the first whole 2 MiB
// block inside its buffer to the last (Volume's own allocation, and the inflate buffer as it
// grows): a fresh one is zeros to its last byte, and raw and gzip files fill every byte.
TEST(VolumeReaders, LargeVolumesAreZeroedAndReadWhole)
{
    const Index3 dims{257, 129, 83}; // 2,751,699 float samples: 10.5 MiB, not whole 2 MiB blocks
    Volume v(ScalarType::f32, dims);
    const std::byte* bytes = v.bytes();
    EXPECT_EQ(std::count(bytes, bytes + v.byte_size(), std::byte{0}), static_cast<std::ptrdiff_t>(v.byte_size()));
    float* p = v.samples<float>();
    for (std::int64_t i = 0; i < v.sample_count(); ++i) p[i] = static_cast<float>(i % 1013) * 0.5f - 7.0f;
    const auto dir = temp_dir();
    write_volume(v, dir / "large.nrrd");
    expect_same(read_volume(dir / "large.nrrd"), v, true);
    const std::string raw(reinterpret_cast<const char*>(v.bytes()), v.byte_size());
    write_file(dir / "large_gzip.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 257 129 83\n"
                                        "endian: " + std::string(std::endian::native == std::endian::big ? "big" : "little") +
                                        "\nencoding: gzip\n\n" + gzip_bytes(raw));
    expect_same(read_volume(dir / "large_gzip.nrrd"), v, false);
}

TEST(VolumeReaders, NrrdBigEndian)
{
    const auto dir = temp_dir();
    const std::vector<std::uint16_t> values = ramp<std::uint16_t>(24, 1000, 257);
    write_file(dir / "be.nrrd",
               "NRRD0004\n# a comment\ntype: unsigned short\ndimension: 3\nsizes: 2 3 4\n"
               "endian: big\nencoding: raw\nspacings: 0.5 0.5 2\nkinds: domain domain domain\n"
               "note:=anything: goes\n\n" +
                   bytes_of(values, Endian::big));
    const Volume v = read_volume(dir / "be.nrrd");
    EXPECT_EQ(v.type(), ScalarType::u16);
    EXPECT_EQ(v.dims(), (Index3{2, 3, 4}));
    EXPECT_EQ(v.spacing(), (Vec3{0.5, 0.5, 2}));
    EXPECT_EQ(v.origin(), (Vec3{0, 0, 0}));
    EXPECT_EQ(samples_of<std::uint16_t>(v), values);
}

TEST(VolumeReaders, NrrdGzipWithSpaceDirectionsAndOrigin)
{
    const auto dir = temp_dir();
    const std::vector<std::int16_t> values = ramp<std::int16_t>(60, -3000, 97);
    write_file(dir / "gz.nrrd",
               "NRRD0005\ntype: short\ndimension: 3\nspace: left-posterior-superior\n"
               "sizes: 3 4 5\nspace directions: (0.75,0,0) ( 0, 0.75 ,0 ) (0,0,-2.5)\n"
               "endian: little\nencoding: gzip\nspace origin: (-10.5, 20, 1e2)\n\n" +
                   gzip_bytes(bytes_of(values, Endian::little)));
    const Volume v = read_volume(dir / "gz.nrrd");
    EXPECT_EQ(v.type(), ScalarType::i16);
    EXPECT_EQ(v.dims(), (Index3{3, 4, 5}));
    EXPECT_EQ(v.spacing(), (Vec3{0.75, 0.75, 2.5})); // the norms of the directions
    EXPECT_EQ(v.direction(), (Mat3{{{1, 0, 0}, {0, 1, 0}, {0, 0, -1}}})); // and their signs
    EXPECT_EQ(v.space(), "left-posterior-superior");
    EXPECT_EQ(v.origin(), (Vec3{-10.5, 20, 100}));
    EXPECT_EQ(samples_of<std::int16_t>(v), values);
}

TEST(VolumeReaders, NrrdGzipByteSkipCountsInflatedBytes)
{
    const auto dir = temp_dir();
    const std::vector<std::uint8_t> values = ramp<std::uint8_t>(8, 10, 3);
    write_file(dir / "skip.nrrd",
               "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: gz\n"
               "byte skip: 5\n\n" +
                   gzip_bytes("HELLO" + bytes_of(values, Endian::little)));
    EXPECT_EQ(samples_of<std::uint8_t>(read_volume(dir / "skip.nrrd")), values);
}

TEST(VolumeReaders, NrrdGzipMembersAndZeroPadding)
{
    const auto dir = temp_dir();
    const std::vector<std::uint8_t> values = ramp<std::uint8_t>(8, 200, 7);
    const std::string data = bytes_of(values, Endian::little);
    const std::string header =
        "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: gzip\n\n";
    // Two gzip members one after the other (as `cat a.gz b.gz` makes), then zero padding.
    write_file(dir / "members.nrrd", header + gzip_bytes(data.substr(0, 3)) +
                                         gzip_bytes(data.substr(3)) + std::string(7, '\0'));
    EXPECT_EQ(samples_of<std::uint8_t>(read_volume(dir / "members.nrrd")), values);
}

TEST(VolumeReaders, NrrdAscii)
{
    const auto dir = temp_dir();
    write_file(dir / "a.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 2 2\nencoding: text\n"
                               "endian: big\n\n1.5 -2.25e1\n+3 4\n\t5 6e-3   -0 1e-45\n");
    const Volume v = read_volume(dir / "a.nrrd");
    const std::vector<float> expected{1.5f, -22.5f, 3.f, 4.f, 5.f, 6e-3f, -0.f, 1e-45f};
    EXPECT_EQ(samples_of<float>(v), expected);

    // Underflow gives 0 or a subnormal (also beyond long double's range); the largest double is
    // kept.
    write_file(dir / "c.nrrd",
               "NRRD0004\ntype: double\ndimension: 3\nsizes: 2 2 2\nencoding: ascii\n\n"
               "1e-400 -1e-5000 4.9e-324 1.7976931348623157e308 -2.5 nan -inf 0.1\n");
    const Volume c = read_volume(dir / "c.nrrd");
    const double* d = c.samples<double>();
    EXPECT_EQ(d[0], 0.0);
    EXPECT_EQ(d[1], 0.0);
    EXPECT_TRUE(std::signbit(d[1]));
    EXPECT_EQ(d[2], std::numeric_limits<double>::denorm_min());
    EXPECT_EQ(d[3], std::numeric_limits<double>::max());
    EXPECT_EQ(d[4], -2.5);
    EXPECT_TRUE(std::isnan(d[5]));
    EXPECT_EQ(d[6], -std::numeric_limits<double>::infinity());
    EXPECT_EQ(d[7], 0.1);

    write_file(dir / "b.nrrd",
               "NRRD0004\ntype: signed char\ndimension: 3\nsizes: 2 2 2\nencoding: ascii\n\n"
               "-128 127 0 -1\n1 2 3 4\n");
    EXPECT_EQ(samples_of<std::int8_t>(read_volume(dir / "b.nrrd")),
              (std::vector<std::int8_t>{-128, 127, 0, -1, 1, 2, 3, 4}));
}

TEST(VolumeReaders, NrrdCrlfAndExtraBlanks)
{
    const auto dir = temp_dir();
    const std::vector<std::int32_t> values = ramp<std::int32_t>(8, -4, 100000);
    write_file(dir / "crlf.nrrd",
               "NRRD0004\r\ntype:   signed   int  \r\ndimension:3\r\nsizes:   2  2\t 2\r\n"
               "space  origin: (1,2,3)\r\nendian: little\r\nencoding: raw\r\n\r\n" +
                   bytes_of(values, Endian::little));
    const Volume v = read_volume(dir / "crlf.nrrd");
    EXPECT_EQ(v.origin(), (Vec3{1, 2, 3}));
    EXPECT_EQ(samples_of<std::int32_t>(v), values);
}

TEST(VolumeReaders, NrrdDetachedWithLineAndByteSkip)
{
    const auto dir = temp_dir();
    std::filesystem::create_directories(dir / "sub");
    const std::vector<std::uint32_t> values = ramp<std::uint32_t>(8, 4000000000u, 1);
    write_file(dir / "sub" / "data.bin",
               "first line\nsecond\n" + std::string("XYZ") + bytes_of(values, Endian::big));
    write_file(dir / "d.nhdr",
               "NRRD0004\ntype: uint\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nendian: big\n"
               "data file: sub/data.bin\nline skip: 2\nbyte skip: 3\n");
    EXPECT_EQ(samples_of<std::uint32_t>(read_volume(dir / "d.nhdr")), values);

    // byte skip -1: the samples are the last bytes of the data file.
    write_file(dir / "end.nhdr",
               "NRRD0004\ntype: uint32\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nendian: big\n"
               "datafile: sub/data.bin\nbyte skip: -1");
    EXPECT_EQ(samples_of<std::uint32_t>(read_volume(dir / "end.nhdr")), values);
}

TEST(VolumeReaders, NrrdEveryTypeSpelling)
{
    const auto dir = temp_dir();
    const std::vector<std::pair<std::string, ScalarType>> spellings{
        {"signed char", ScalarType::i8},
        {"int8", ScalarType::i8},
        {"int8_t", ScalarType::i8},
        {"uchar", ScalarType::u8},
        {"unsigned char", ScalarType::u8},
        {"uint8", ScalarType::u8},
        {"uint8_t", ScalarType::u8},
        {"short", ScalarType::i16},
        {"short int", ScalarType::i16},
        {"signed short", ScalarType::i16},
        {"signed short int", ScalarType::i16},
        {"int16", ScalarType::i16},
        {"int16_t", ScalarType::i16},
        {"ushort", ScalarType::u16},
        {"unsigned short", ScalarType::u16},
        {"unsigned short int", ScalarType::u16},
        {"uint16", ScalarType::u16},
        {"uint16_t", ScalarType::u16},
        {"int", ScalarType::i32},
        {"signed int", ScalarType::i32},
        {"int32", ScalarType::i32},
        {"int32_t", ScalarType::i32},
        {"uint", ScalarType::u32},
        {"unsigned int", ScalarType::u32},
        {"uint32", ScalarType::u32},
        {"uint32_t", ScalarType::u32},
        {"float", ScalarType::f32},
        {"double", ScalarType::f64},
    };
    int i = 0;
    for (const auto& [spelling, type] : spellings) {
        const auto path = dir / ("t" + std::to_string(i++) + ".nrrd");
        write_file(path, "NRRD0004\ntype: " + spelling +
                             "\ndimension: 3\nsizes: 2 2 2\nendian: little\n"
                             "encoding: raw\n\n" +
                             std::string(8 * type_size(type), '\x01'));
        EXPECT_EQ(read_volume(path).type(), type) << spelling;
    }
}

TEST(VolumeReaders, MhdBigEndianWithDataFile)
{
    const auto dir = temp_dir();
    const std::vector<float> values{0.5f, -1.25f, 3e10f, -0.f, 1e-30f, 7.f,
                                    8.f,  9.f,    10.f,  11.f, 12.f,   13.f};
    write_file(dir / "be.raw", bytes_of(values, Endian::big));
    write_file(dir / "be.mhd",
               "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = True\n"
               "CompressedData = False\nTransformMatrix = 1 0 0 0 1 0 0 0 1\nOffset = 1.5 -2 3\n"
               "CenterOfRotation = 0 0 0\nAnatomicalOrientation = RAI\n"
               "ElementSpacing = 0.3 0.4 0.5\nDimSize = 2 3 2\nElementType = MET_FLOAT\n"
               "ElementDataFile = be.raw\n");
    const Volume v = read_volume(dir / "be.mhd");
    EXPECT_EQ(v.dims(), (Index3{2, 3, 2}));
    EXPECT_EQ(v.spacing(), (Vec3{0.3, 0.4, 0.5}));
    EXPECT_EQ(v.origin(), (Vec3{1.5, -2, 3}));
    EXPECT_EQ(samples_of<float>(v), values);
}

TEST(VolumeReaders, MhdHeaderSizeAndAliases)
{
    const auto dir = temp_dir();
    const std::vector<std::uint16_t> values = ramp<std::uint16_t>(8, 60000, 11);
    write_file(dir / "d.dat", "0123456789" + bytes_of(values, Endian::little));
    write_file(dir / "a.mhd",
               "NDims = 3\nDimSize = 2 2 2\nElementType = MET_USHORT\nElementSize = 2 2 2\n"
               "Position = 7 8 9\nElementByteOrderMSB = False\nHeaderSize = 10\n"
               "ElementDataFile = d.dat\n");
    Volume v = read_volume(dir / "a.mhd");
    EXPECT_EQ(v.spacing(), (Vec3{2, 2, 2}));
    EXPECT_EQ(v.origin(), (Vec3{7, 8, 9}));
    EXPECT_EQ(samples_of<std::uint16_t>(v), values);

    write_file(dir / "b.mhd",
               "NDims = 3\nDimSize = 2 2 2\nElementType = MET_USHORT\nHeaderSize = -1\n"
               "ElementDataFile = d.dat\n");
    EXPECT_EQ(samples_of<std::uint16_t>(read_volume(dir / "b.mhd")), values);
}

TEST(VolumeReaders, MhaCompressed)
{
    const auto dir = temp_dir();
    const std::vector<double> values = ramp<double>(27, -1.0 / 3.0, 0.125);
    const std::string header =
        "ObjectType = Image\nNDims = 3\nDimSize = 3 3 3\nElementType = MET_DOUBLE\n"
        "ElementSpacing = 1 1 1\nCompressedData = True\n";
    const std::string stream = zlib_bytes(bytes_of(values, Endian::little));
    write_file(dir / "sized.mha", header + "CompressedDataSize = " + std::to_string(stream.size()) +
                                      "\nElementDataFile = LOCAL\n" + stream);
    EXPECT_EQ(samples_of<double>(read_volume(dir / "sized.mha")), values);
    write_file(dir / "unsized.mha", header + "ElementDataFile = LOCAL\n" + stream);
    EXPECT_EQ(samples_of<double>(read_volume(dir / "unsized.mha")), values);
    // A gzip stream is accepted too, and big-endian samples.
    write_file(dir / "gzip.mha", header +
                                     "BinaryDataByteOrderMSB = True\nElementDataFile = LOCAL\n" +
                                     gzip_bytes(bytes_of(values, Endian::big)));
    EXPECT_EQ(samples_of<double>(read_volume(dir / "gzip.mha")), values);
}

TEST(VolumeReaders, VtkAscii)
{
    const auto dir = temp_dir();
    write_file(dir / "a.vtk",
               "# vtk DataFile Version 2.0\nsome title\nASCII\n\nDATASET STRUCTURED_POINTS\n"
               "DIMENSIONS 2 2 2\nORIGIN -1 -2.5 3\nSPACING 0.5 1 2\nPOINT_DATA 8\n"
               "SCALARS density short\nLOOKUP_TABLE default\n-32768 32767 0 1\n2 3\n4\n5\n");
    const Volume v = read_volume(dir / "a.vtk");
    EXPECT_EQ(v.type(), ScalarType::i16);
    EXPECT_EQ(v.dims(), (Index3{2, 2, 2}));
    EXPECT_EQ(v.spacing(), (Vec3{0.5, 1, 2}));
    EXPECT_EQ(v.origin(), (Vec3{-1, -2.5, 3}));
    EXPECT_EQ(samples_of<std::int16_t>(v),
              (std::vector<std::int16_t>{-32768, 32767, 0, 1, 2, 3, 4, 5}));

    // No LOOKUP_TABLE line, ASPECT_RATIO, and other attributes after the scalars.
    write_file(dir / "b.vtk",
               "# vtk DataFile Version 3.0\nt\nascii\nDATASET STRUCTURED_POINTS\n"
               "DIMENSIONS 2 2 2\nASPECT_RATIO 3 3 3\nPOINT_DATA 8\nSCALARS s float 1\n"
               "0.5 1.5 2.5 3.5 4.5 5.5 6.5 7.5\nVECTORS v float\n1 2 3\n");
    const Volume b = read_volume(dir / "b.vtk");
    EXPECT_EQ(b.spacing(), (Vec3{3, 3, 3}));
    EXPECT_EQ(samples_of<float>(b), ramp<float>(8, 0.5f, 1.f));
}

TEST(VolumeReaders, VtkBinaryWithoutLookupTable)
{
    const auto dir = temp_dir();
    const std::vector<std::int32_t> values = ramp<std::int32_t>(8, -100000, 33333);
    write_file(dir / "b.vtk", "# vtk DataFile Version 3.0\nt\nBINARY\nDATASET STRUCTURED_POINTS\n"
                              "DIMENSIONS 2 2 2\nPOINT_DATA 8\nSCALARS s vtktypeint32 1\n" +
                                  bytes_of(values, Endian::big));
    EXPECT_EQ(samples_of<std::int32_t>(read_volume(dir / "b.vtk")), values);
}

TEST(VolumeReaders, RawWithHeaderBytesAndEndian)
{
    const auto dir = temp_dir();
    const std::vector<std::int16_t> values = ramp<std::int16_t>(12, -6, 1000);
    write_file(dir / "v.bin", "HEADER" + bytes_of(values, Endian::big));
    RawOptions options;
    options.dims = {3, 2, 2};
    options.type = ScalarType::i16;
    options.spacing = {1, 2, 3};
    options.endian = Endian::big;
    options.header_bytes = 6;
    const Volume v = read_volume(dir / "v.bin", options);
    EXPECT_EQ(v.dims(), (Index3{3, 2, 2}));
    EXPECT_EQ(v.spacing(), (Vec3{1, 2, 3}));
    EXPECT_EQ(samples_of<std::int16_t>(v), values);
}

// ---- names ----------------------------------------------------------------------------------

TEST(VolumeNames, HasVolumeHeader)
{
    for (const char* name :
         {"a.nrrd", "a.nhdr", "a.mhd", "a.mha", "a.vtk", "dir.x/A.NRRD", "b.MHA"}) {
        EXPECT_TRUE(has_volume_header(name)) << name;
    }
    for (const char* name :
         {"a.raw", "a.bin", "a.dat", "a", "nrrd", "a.nrrd.gz", "a.ply", ".vtk.x"}) {
        EXPECT_FALSE(has_volume_header(name)) << name;
    }
}

TEST(VolumeNames, ParseType)
{
    const std::vector<std::pair<std::string, ScalarType>> names{
        {"int8", ScalarType::i8},     {"uint8", ScalarType::u8},   {"int16", ScalarType::i16},
        {"uint16", ScalarType::u16},  {"int32", ScalarType::i32},  {"uint32", ScalarType::u32},
        {"float", ScalarType::f32},   {"double", ScalarType::f64}, {"char", ScalarType::i8},
        {"uchar", ScalarType::u8},    {"short", ScalarType::i16},  {"ushort", ScalarType::u16},
        {"int", ScalarType::i32},     {"uint", ScalarType::u32},   {"float32", ScalarType::f32},
        {"float64", ScalarType::f64},
    };
    for (const auto& [name, type] : names) {
        EXPECT_EQ(parse_type(name), type) << name;
        EXPECT_EQ(parse_type(std::string(type_name(type))), type); // type_name() reads back
    }
    for (const char* bad : {"", "int64", "uint64", "long", "half", "float16", "int 8", "u8x"}) {
        try {
            parse_type(bad);
            ADD_FAILURE() << "accepted " << bad;
        } catch (const Error& e) {
            EXPECT_EQ(e.status(), Status::invalid_argument);
            const std::string msg = e.what();
            EXPECT_NE(msg.find(std::string("\"") + bad + "\""), std::string::npos) << msg;
            for (const char* valid :
                 {"int8", "uint8", "int16", "uint16", "int32", "uint32", "float", "double"}) {
                EXPECT_NE(msg.find(valid), std::string::npos) << msg;
            }
        }
    }
}

} // namespace
} // namespace cmc33::io
