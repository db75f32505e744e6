// describe_volume() and PlaneReader (src/io/plane_reader.hpp): every format's samples read a range
// of planes at a time are the bytes read_volume() gives, in any order of ranges; a file that
// read_volume() refuses is refused with the same message, at the latest when the plane that shows
// the fault is read.

#include <gtest/gtest.h>

#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "plane_reader.hpp"
#include "test_support.hpp"

namespace cmc33::io {
namespace {

using detail::describe_volume;
using detail::PlaneReader;

/// A volume of `type` whose samples differ from plane to plane and row to row.
Volume sample_volume(ScalarType type, Index3 dims)
{
    Volume v(type, dims, {0.5, 1, 2}, {1, -2, 3});
    v.visit([&](auto view) {
        using T = std::remove_const_t<std::remove_pointer_t<decltype(view.data)>>;
        auto* data = const_cast<T*>(view.data);
        for (std::int64_t n = 0; n < v.sample_count(); ++n) data[n] = static_cast<T>((n * 37 + n / 11) % 101);
    });
    return v;
}

/// Reads every plane through `reader` as ranges [0, a), [a, b), [b, nz) (in the order given),
/// and returns the bytes in plane order.
std::string read_by_ranges(PlaneReader& reader, const std::vector<std::pair<std::int64_t, std::int64_t>>& ranges)
{
    const auto plane = static_cast<std::size_t>(reader.layout().plane_bytes());
    std::string out(plane * static_cast<std::size_t>(reader.layout().grid.dims[2]), '\0');
    for (const auto& [k0, k1] : ranges) {
        reader.read(k0, k1, reinterpret_cast<std::byte*>(out.data() + static_cast<std::size_t>(k0) * plane));
    }
    return out;
}

std::string bytes_of(const Volume& v) { return std::string(reinterpret_cast<const char*>(v.bytes()), v.byte_size()); }

/// The error message of f(), or "" if it does not throw.
template <class F> std::string message_of(F&& f)
{
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

struct Format {
    const char* file;
    std::optional<RawOptions> raw;
};

TEST(VolumePlanes, EveryWrittenFormatReadsByPlanesAsWhole)
{
    const auto dir = test::temp_dir();
    for (const ScalarType type : {ScalarType::u8, ScalarType::i16, ScalarType::f32, ScalarType::f64}) {
        const Volume v = sample_volume(type, {5, 4, 7});
        RawOptions raw;
        raw.dims = v.dims();
        raw.type = type;
        for (const Format& f : {Format{"v.nrrd", {}}, Format{"v.nhdr", {}}, Format{"v.mha", {}}, Format{"v.mhd", {}},
                                Format{"v.vtk", {}}, Format{"v.raw", raw}}) {
            SCOPED_TRACE(std::string(f.file) + " " + std::string(type_name(type)));
            const auto path = dir / f.file;
            write_volume(v, path);
            const Volume whole = read_volume(path, f.raw);
            PlaneReader reader(describe_volume(path, f.raw));
            EXPECT_EQ(reader.layout().grid.dims, whole.dims());
            EXPECT_EQ(reader.layout().grid.type, whole.type());
            EXPECT_EQ(reader.layout().grid.spacing, whole.spacing());
            EXPECT_EQ(reader.layout().grid.origin, whole.origin());
            EXPECT_EQ(reader.layout().grid.direction, whole.direction());
            EXPECT_EQ(read_by_ranges(reader, {{0, 2}, {2, 3}, {3, 7}}), bytes_of(whole));
            EXPECT_EQ(read_by_ranges(reader, {{4, 7}, {0, 4}}), bytes_of(whole));
        }
    }
}

/// NRRD headers for the encodings write_volume() does not write.
std::string nrrd_header(const char* type, const char* encoding, const char* endian, const char* extra = "")
{
    return std::string("NRRD0004\ntype: ") + type + "\ndimension: 3\nsizes: 5 4 7\nendian: " + endian +
           "\nencoding: " + encoding + "\n" + extra + "\n";
}

TEST(VolumePlanes, GzipBigEndianAsciiAndSkipsReadAsWhole)
{
    const auto dir = test::temp_dir();
    const Volume v = sample_volume(ScalarType::u16, {5, 4, 7});
    std::string big = bytes_of(v);
    for (std::size_t i = 0; i + 1 < big.size(); i += 2) std::swap(big[i], big[i + 1]);
    std::string ascii;
    for (std::int64_t n = 0; n < v.sample_count(); ++n) ascii += std::to_string(v.samples<std::uint16_t>()[n]) + "\n";
    const std::string gz = test::gzip_bytes(big);
    struct File {
        const char* name;
        std::string bytes;
    };
    const std::vector<File> files{
        {"big.nrrd", nrrd_header("uint16", "raw", "big") + big},
        {"gzip.nrrd", nrrd_header("uint16", "gzip", "big") + gz},
        // two gzip members one after the other, then zero padding
        {"members.nrrd", nrrd_header("uint16", "gzip", "big") + test::gzip_bytes(big.substr(0, 100)) +
                             test::gzip_bytes(big.substr(100)) + std::string(7, '\0')},
        {"skip.nrrd", nrrd_header("uint16", "gzip", "big", "byte skip: 6\n") + test::gzip_bytes("sixby" + std::string(1, 'x') + big)},
        {"tail.nrrd", nrrd_header("uint16", "raw", "big", "byte skip: -1\n") + "junk before" + big},
        {"text.nrrd", nrrd_header("uint16", "ascii", "big") + ascii},
        {"zlib.mha", "ObjectType = Image\nNDims = 3\nDimSize = 5 4 7\nElementType = MET_USHORT\n"
                     "BinaryDataByteOrderMSB = True\nCompressedData = True\nElementDataFile = LOCAL\n" +
                         test::zlib_bytes(big)},
    };
    for (const File& f : files) {
        SCOPED_TRACE(f.name);
        test::write_file(dir / f.name, f.bytes);
        const Volume whole = read_volume(dir / f.name);
        ASSERT_EQ(bytes_of(whole), bytes_of(v));
        PlaneReader reader(describe_volume(dir / f.name));
        EXPECT_EQ(read_by_ranges(reader, {{0, 1}, {1, 5}, {5, 7}}), bytes_of(v));
        // backwards: a compressed stream starts over
        EXPECT_EQ(read_by_ranges(reader, {{6, 7}, {3, 6}, {0, 3}}), bytes_of(v));
    }
}

TEST(VolumePlanes, HeaderAndSizeFaultsAreFoundBeforeAnyPlaneWithReadVolumesMessage)
{
    const auto dir = test::temp_dir();
    const Volume v = sample_volume(ScalarType::u8, {5, 4, 7});
    const std::string samples = bytes_of(v);
    const std::vector<std::pair<const char*, std::string>> files{
        {"short.nrrd", nrrd_header("uint8", "raw", "little") + samples.substr(0, samples.size() - 1)},
        {"long.nrrd", nrrd_header("uint8", "raw", "little") + samples + "x"},
        {"bad.nrrd", "NRRD0004\ntype: uint8\ndimension: 2\nsizes: 5 4\nencoding: raw\n\n" + samples},
    };
    for (const auto& file : files) { // not a structured binding: clang 14 lambdas cannot capture those
        SCOPED_TRACE(file.first);
        const auto path = dir / file.first;
        test::write_file(path, file.second);
        const std::string expected = message_of([&] { (void)read_volume(path); });
        ASSERT_FALSE(expected.empty());
        EXPECT_EQ(message_of([&] { (void)describe_volume(path); }), expected);
    }
    EXPECT_NE(message_of([&] { (void)describe_volume(dir / "missing.nrrd"); }).find("missing.nrrd: cannot open"),
              std::string::npos);
}

TEST(VolumePlanes, StreamFaultsSurfaceWhenTheirPlaneIsReadWithReadVolumesMessage)
{
    const auto dir = test::temp_dir();
    const Volume v = sample_volume(ScalarType::u8, {5, 4, 7});
    const std::string gz = test::gzip_bytes(bytes_of(v));
    std::string corrupt = gz;
    corrupt[gz.size() / 2] = static_cast<char>(corrupt[gz.size() / 2] ^ 0x55);
    const std::vector<std::pair<const char*, std::string>> files{
        {"tiny.nrrd", nrrd_header("uint8", "gzip", "little") + "\x1f\x8b"},
        {"cut.nrrd", nrrd_header("uint8", "gzip", "little") + gz.substr(0, gz.size() - 12)},
        {"corrupt.nrrd", nrrd_header("uint8", "gzip", "little") + corrupt},
        {"more.nrrd", nrrd_header("uint8", "gzip", "little") + test::gzip_bytes(bytes_of(v) + "x")},
        {"junk.nrrd", nrrd_header("uint8", "gzip", "little") + gz + "junk"},
        {"trail.mha", "NDims = 3\nDimSize = 5 4 7\nElementType = MET_UCHAR\nCompressedData = True\n"
                      "CompressedDataSize = " + std::to_string(gz.size()) + "\nElementDataFile = LOCAL\n" + gz + "x"},
    };
    for (const auto& file : files) {
        SCOPED_TRACE(file.first);
        const auto path = dir / file.first;
        test::write_file(path, file.second);
        const std::string expected = message_of([&] { (void)read_volume(path); });
        ASSERT_FALSE(expected.empty());
        std::string got = message_of([&] {
            PlaneReader reader(describe_volume(path));
            std::vector<std::byte> plane(static_cast<std::size_t>(reader.layout().plane_bytes()) * 7);
            for (std::int64_t k = 0; k < 7; ++k) reader.read(k, k + 1, plane.data());
        });
        EXPECT_EQ(got, expected);
    }
}

TEST(VolumePlanes, SharedVolumesReadByPlanesAsWhole)
{
    for (const char* name : {"CThead_256x256x113_uint16.nrrd", "HeadMRVolume_48x62x42_uint8.nrrd"}) {
        const auto path = test::shared_volume(name);
        if (!path) GTEST_SKIP() << "../shared/data/volumes not found";
        SCOPED_TRACE(name);
        const Volume whole = read_volume(*path);
        PlaneReader reader(describe_volume(*path));
        const std::int64_t nz = whole.dims()[2];
        EXPECT_EQ(read_by_ranges(reader, {{0, nz / 3}, {nz / 3, nz - 1}, {nz - 1, nz}}), bytes_of(whole));
    }
}

} // namespace
} // namespace cmc33::io
