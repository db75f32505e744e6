// The DICOM reader against pydicom, an independent writer (tests/io/write_dicom.py): shuffled slice
// files with misleading InstanceNumbers, oblique and sheared frames, non-square pixels, rescale,
// BitsStored 12, the native and RLE transfer syntaxes, an Enhanced CT, and the broken series that
// must be refused in one line naming the files or positions.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <initializer_list>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/io.hpp"
#include "dicom.hpp"
#include "dicom_scan.hpp"
#include "test_support.hpp"

namespace cmc33 {
namespace {

namespace fs = std::filesystem;
using namespace std::string_literals;

/// The series write_dicom.py writes, once for the whole suite.
const fs::path& series_dir()
{
    static const fs::path dir = test::run_writer(CMC33_SYSTEM_PYTHON, CMC33_WRITE_DICOM, "cmc33_test_dicom_");
    return dir;
}

class Dicom : public ::testing::Test {
protected:
    void SetUp() override
    {
        if (!io::detail::dicom_supported()) GTEST_SKIP() << "this build has no DICOM reader (GDCM not found)";
        ASSERT_FALSE(series_dir().empty()) << "write_dicom.py failed: needs python3-pydicom and python3-numpy";
    }
    static fs::path path(const std::string& name) { return series_dir() / name; }
    static Volume read(const std::string& name, const std::string& series = {})
    {
        io::ReadOptions options;
        options.series = series;
        return io::read_volume(path(name), std::nullopt, options);
    }
    static std::string error_of(const std::string& name, const std::string& series = {})
    {
        try {
            (void)read(name, series);
        } catch (const Error& e) {
            return e.what();
        }
        return "(no error)";
    }
};

/// The samples as doubles, x fastest.
std::vector<double> as_doubles(const Volume& volume)
{
    return dispatch_scalar_type(volume.type(), [&](auto tag) {
        using T = decltype(tag);
        const T* p = volume.samples<T>();
        return std::vector<double>(p, p + volume.sample_count());
    });
}

nlohmann::json expected(const std::string& name)
{
    std::ifstream in(series_dir() / (name + ".json"));
    return nlohmann::json::parse(in);
}

/// The volume's frame and samples are those pydicom reads back, and every mesh vertex lies where
/// pydicom's frame puts the same index-space point.
void check_against_pydicom(const Volume& volume, const std::string& name)
{
    const nlohmann::json want = expected(name);
    for (std::size_t a = 0; a < 3; ++a) EXPECT_EQ(volume.dims()[a], want["dims"][a].get<std::int64_t>()) << name;
    const Mat3 m = frame_matrix(volume.spacing(), volume.direction());
    for (std::size_t a = 0; a < 3; ++a) {
        // DS values carry about 6 decimals: positions and cosines agree to that
        EXPECT_NEAR(volume.origin()[a], want["origin"][a].get<double>(), 1e-6) << name;
        for (std::size_t r = 0; r < 3; ++r) {
            EXPECT_NEAR(m[r][a], want["axes"][a][r].get<double>(), 1e-6) << name << " axis " << a << " row " << r;
        }
    }
    const auto& values = want["values"];
    ASSERT_EQ(values.size(), static_cast<std::size_t>(volume.sample_count()));
    Volume reference(ScalarType::f64, volume.dims());
    double* ref = reference.samples<double>();
    const std::vector<double> got = as_doubles(volume);
    for (std::size_t i = 0; i < values.size(); ++i) {
        ref[i] = values[i].get<double>();
        ASSERT_NEAR(got[i], ref[i], 1e-4 * (1 + std::fabs(ref[i]))) << name << " sample " << i;
    }
    // The mesh in the reader's frame against the mesh in index space mapped by pydicom's frame.
    double lo = ref[0], hi = ref[0];
    for (std::size_t i = 0; i < values.size(); ++i) lo = std::min(lo, ref[i]), hi = std::max(hi, ref[i]);
    const double iso = lo + 0.6 * (hi - lo) + 0.25; // between samples, a closed surface inside
    const Mesh mesh = extract(volume, iso);
    const Mesh index_mesh = extract(reference, iso);
    ASSERT_GT(mesh.triangle_count(), 0u) << name;
    ASSERT_EQ(mesh.vertex_count(), index_mesh.vertex_count()) << name;
    ASSERT_EQ(mesh.triangle_count(), index_mesh.triangle_count()) << name;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) ASSERT_EQ(mesh.triangles[t], index_mesh.triangles[t]) << name;
    double extent = 0;
    for (std::size_t a = 0; a < 3; ++a) extent = std::max(extent, std::fabs(want["origin"][a].get<double>()));
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        for (std::size_t r = 0; r < 3; ++r) {
            double world = want["origin"][r].get<double>();
            for (std::size_t a = 0; a < 3; ++a) {
                world += want["axes"][a][r].get<double>() * static_cast<double>(index_mesh.positions[3 * v + a]);
            }
            // float precision: a few float steps of the coordinates' magnitude
            ASSERT_NEAR(static_cast<double>(mesh.positions[3 * v + r]), world, 4e-6 * (extent + 20)) << name << " vertex " << v;
        }
    }
}

TEST_F(Dicom, ObliqueRescaledShuffledSeriesMatchesPydicom)
{
    const Volume v = read("oblique");
    EXPECT_EQ(v.type(), ScalarType::i16); // stored int16 minus 1024 fits int16
    EXPECT_EQ(v.space(), "left-posterior-superior");
    check_against_pydicom(v, "oblique");
}

TEST_F(Dicom, NonSquarePixelsPutRowSpacingOnY)
{
    // PixelSpacing 0.9\0.6: 0.9 between rows (along the column cosine, y), 0.6 between columns (x)
    const Volume v = read("oblique");
    EXPECT_NEAR(v.spacing()[0], 0.6, 1e-12);
    EXPECT_NEAR(v.spacing()[1], 0.9, 1e-12);
    EXPECT_NEAR(v.spacing()[2], 1.25, 1e-5);
}

TEST_F(Dicom, WholeSlopeStaysInteger)
{
    const Volume v = read("slope2");
    EXPECT_EQ(v.type(), ScalarType::i16);
    check_against_pydicom(v, "slope2");
}

TEST_F(Dicom, SlopePerSliceGivesFloat)
{
    const Volume v = read("perslice");
    EXPECT_EQ(v.type(), ScalarType::f32);
    check_against_pydicom(v, "perslice");
}

TEST_F(Dicom, GantryTiltIsAShearedFrame)
{
    const Volume v = read("tilt");
    check_against_pydicom(v, "tilt");
    // the slice axis is not the normal of the rows and columns
    EXPECT_GT(std::fabs(v.direction()[1][2]), 0.2);
}

TEST_F(Dicom, BitsStored12DropsTheBitsAboveAndExtendsTheSign)
{
    const Volume v = read("bits12");
    check_against_pydicom(v, "bits12");
}

TEST_F(Dicom, TransferSyntaxes)
{
    check_against_pydicom(read("bigendian"), "bigendian");
    check_against_pydicom(read("implicit"), "implicit");
    check_against_pydicom(read("rle"), "rle");
}

TEST_F(Dicom, EnhancedMultiFrameFile)
{
    check_against_pydicom(read("enhanced.dcm"), "enhanced");
}

TEST_F(Dicom, TwoSeriesAreListedAndSeriesPicks)
{
    const std::string e = error_of("two");
    EXPECT_NE(e.find("2 DICOM series"), std::string::npos) << e;
    EXPECT_NE(e.find("--series"), std::string::npos) << e;
    EXPECT_NE(e.find("1.2.826.0.1.3680043.38.1"), std::string::npos) << e;
    EXPECT_NE(e.find("1.2.826.0.1.3680043.38.2"), std::string::npos) << e;
    EXPECT_NE(e.find("\"Soft\""), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    const Volume bone = read("two", "1.2.826.0.1.3680043.38.1");
    const Volume soft = read("two", "1.2.826.0.1.3680043.38.2");
    EXPECT_NEAR(bone.spacing()[2], 1, 1e-9);
    EXPECT_NEAR(soft.spacing()[2], 2, 1e-9);
    const std::string unknown = error_of("two", "1.2.3");
    EXPECT_NE(unknown.find("no series \"1.2.3\""), std::string::npos) << unknown;
    const std::vector<io::DicomSeries> list = io::detail::list_dicom_series(path("two"));
    ASSERT_EQ(list.size(), 2u);
    EXPECT_EQ(list[0].description, "Bone");
    EXPECT_EQ(list[1].dims, (Index3{5, 4, 3}));
    EXPECT_NEAR(list[1].spacing[2], 2, 1e-9);
}

TEST_F(Dicom, BrokenSeriesAreRefusedNamingWhere)
{
    std::string e = error_of("missing");
    EXPECT_NE(e.find("missing slice"), std::string::npos) << e;
    EXPECT_NE(e.find("s2.dcm at 4 mm"), std::string::npos) << e;
    EXPECT_NE(e.find("s4.dcm at 8 mm"), std::string::npos) << e;
    e = error_of("duplicate");
    EXPECT_NE(e.find("duplicate slice position (0, 0, 6)"), std::string::npos) << e;
    EXPECT_NE(e.find("s3.dcm"), std::string::npos) << e;
    EXPECT_NE(e.find("s4.dcm"), std::string::npos) << e;
    e = error_of("uneven");
    EXPECT_NE(e.find("non-uniform slice spacing: 1.5 mm"), std::string::npos) << e;
    e = error_of("mixed");
    EXPECT_NE(e.find("mixed slice sizes"), std::string::npos) << e;
    EXPECT_NE(e.find("5x4"), std::string::npos) << e;
    EXPECT_NE(e.find("6x4"), std::string::npos) << e;
    e = error_of("rgb");
    EXPECT_NE(e.find("3 samples per pixel (RGB)"), std::string::npos) << e;
    for (const std::string name : {"missing", "duplicate", "uneven", "mixed", "rgb"}) {
        EXPECT_EQ(error_of(name).find('\n'), std::string::npos) << name;
    }
}

TEST_F(Dicom, FolderFilesAreInputs)
{
    const std::vector<fs::path> files = io::volume_files(path("oblique"));
    ASSERT_EQ(files.size(), 6u); // the six slice files
    for (const fs::path& f : files) EXPECT_EQ(f.parent_path(), path("oblique"));
}

TEST_F(Dicom, NotDicomIsRefusedNamingTheFile)
{
    const fs::path dir = test::temp_dir() / "notdicom";
    fs::create_directories(dir);
    test::write_file(dir / "a.dcm", std::string(200, 'x'));
    try {
        (void)io::read_volume(dir, std::nullopt, io::ReadOptions{});
        FAIL() << "read";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("a.dcm: not a DICOM file"), std::string::npos) << e.what();
    }
}

// ---- the element structure, checked before GDCM parses (src/io/dicom_scan.cpp) --------------

/// Builds DICOM Part 10 bytes: preamble, "DICM", a file meta group naming `syntax`, then elements
/// in Explicit VR Little Endian appended with the helpers.
class DicomBytes {
public:
    explicit DicomBytes(const std::string& syntax = "1.2.840.10008.1.2.1")
    {
        bytes_.assign(128, '\0');
        bytes_ += "DICM";
        std::string uid = syntax;
        if (uid.size() % 2) uid += '\0';
        element(0x0002, 0x0010, "UI", uid);
    }
    /// An element with a 16- or 32-bit length field as its VR has (PS3.5 7.1.2).
    DicomBytes& element(std::uint16_t group, std::uint16_t elem, const char* vr, const std::string& value)
    {
        return header(group, elem, vr, static_cast<std::uint32_t>(value.size())).raw(value);
    }
    /// Only the header: a declared length that the bytes need not follow.
    DicomBytes& header(std::uint16_t group, std::uint16_t elem, const char* vr, std::uint32_t length)
    {
        u16(group).u16(elem);
        bytes_ += vr;
        const std::string v(vr);
        if (v == "OB" || v == "OW" || v == "SQ" || v == "UN" || v == "UT" || v == "UC" || v == "UR" || v == "OF" || v == "OD" ||
            v == "OL" || v == "OV" || v == "SV" || v == "UV") {
            u16(0).u32(length);
        } else {
            u16(static_cast<std::uint16_t>(length));
        }
        return *this;
    }
    /// An item or delimiter tag (FFFE,xxxx) with its 32-bit length.
    DicomBytes& item(std::uint16_t elem, std::uint32_t length) { return u16(0xFFFE).u16(elem).u32(length); }
    DicomBytes& raw(const std::string& b)
    {
        bytes_ += b;
        return *this;
    }
    DicomBytes& u16(std::uint16_t v)
    {
        bytes_ += static_cast<char>(v & 0xff);
        bytes_ += static_cast<char>(v >> 8);
        return *this;
    }
    DicomBytes& u32(std::uint32_t v) { return u16(static_cast<std::uint16_t>(v & 0xffff)).u16(static_cast<std::uint16_t>(v >> 16)); }
    const std::string& bytes() const { return bytes_; }

private:
    std::string bytes_;
};

/// A 2x2 16-bit image with every attribute the reader needs but a second slice.
DicomBytes image()
{
    DicomBytes d;
    d.element(0x0008, 0x0060, "CS", "CT")
        .element(0x0020, 0x000e, "UI", "1.2.3.4\0"s)
        .element(0x0020, 0x0032, "DS", "0\\0\\0 ")
        .element(0x0020, 0x0037, "DS", "1\\0\\0\\0\\1\\0 ")
        .header(0x0028, 0x0010, "US", 2).u16(2)
        .header(0x0028, 0x0011, "US", 2).u16(2)
        .header(0x0028, 0x0100, "US", 2).u16(16)
        .header(0x0028, 0x0101, "US", 2).u16(16)
        .header(0x0028, 0x0102, "US", 2).u16(15)
        .header(0x0028, 0x0103, "US", 2).u16(0)
        .element(0x7fe0, 0x0010, "OW", std::string(8, '\x01'));
    return d;
}

/// The error reading `bytes` from memory as "mem.dcm" ("(no error)" if it reads).
std::string memory_error(const std::string& bytes)
{
    try {
        (void)io::read_volume_from_memory(bytes, io::VolumeFormat::dicom, "mem.dcm");
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

class DicomScan : public ::testing::Test {
protected:
    void SetUp() override
    {
        if (!io::detail::dicom_supported()) GTEST_SKIP() << "this build has no DICOM reader (GDCM not found)";
    }
    /// The message is one line naming the file and holding every one of `parts`.
    static void expect_error(const std::string& bytes, std::initializer_list<std::string> parts)
    {
        const std::string m = memory_error(bytes);
        EXPECT_EQ(m.rfind("mem.dcm: ", 0), 0u) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
        for (const std::string& p : parts) EXPECT_NE(m.find(p), std::string::npos) << "missing \"" << p << "\" in: " << m;
    }
};

TEST_F(DicomScan, TheReferenceImageGetsPastTheScan)
{
    // one slice: refused by the reader for that reason, after GDCM parsed it
    EXPECT_NE(memory_error(image().bytes()).find("the series has 1 slice"), std::string::npos) << memory_error(image().bytes());
}

TEST_F(DicomScan, DeclaredLengthBeyondTheFile)
{
    DicomBytes d = image();
    d.header(0x0042, 0x0011, "OB", 0xFFFFFFF0u).raw(std::string(16, 'x'));
    expect_error(d.bytes(), {"(0042,0011)", "value length 4294967280 passes the end of the file (16 bytes remain)", "at byte "});
}

TEST_F(DicomScan, DeclaredLengthBeyondItsItem)
{
    DicomBytes d;
    d.header(0x0008, 0x1140, "SQ", 0xFFFFFFFFu).item(0xE000, 12).header(0x0008, 0x1150, "UI", 40).raw("1.2\0"s).item(0xE0DD, 0);
    expect_error(d.bytes(), {"(0008,1150)", "value length 40 passes the end of the enclosing item (4 bytes remain)"});
}

TEST_F(DicomScan, SequencesNestedTooDeep)
{
    DicomBytes d;
    const int levels = io::detail::kMaxDicomNesting + 2;
    for (int i = 0; i < levels; ++i) d.header(0x0008, 0x1140, "SQ", 0xFFFFFFFFu).item(0xE000, 0xFFFFFFFFu);
    for (int i = 0; i < levels; ++i) d.item(0xE00D, 0).item(0xE0DD, 0);
    expect_error(d.bytes(), {"(0008,1140)", "sequences nested more than 32 deep"});
}

TEST_F(DicomScan, UndefinedLengthOnANonSequence)
{
    DicomBytes d = image();
    d.header(0x0040, 0xa160, "UT", 0xFFFFFFFFu).raw("abcd");
    expect_error(d.bytes(), {"(0040,a160)", "undefined value length (FFFFFFFFH) on VR UT"});
}

TEST_F(DicomScan, VrOtherThanTheDictionarys)
{
    // GDCM's typed accessors assert on such a VR (found by fuzzing)
    expect_error(DicomBytes().header(0x0028, 0x0103, "SS", 2).u16(1).bytes(), {"(0028,0103)", "VR SS; expected US"});
}

TEST_F(DicomScan, MalformedRleIsRefusedBeforeDecoding)
{
    // GDCM's RLE decoder reads past its input on bad segment offsets (found by fuzzing)
    const auto rle = [](std::uint32_t segments, std::uint32_t offset, const std::string& data) {
        DicomBytes d("1.2.840.10008.1.2.5");
        d.element(0x0008, 0x0060, "CS", "CT")
            .header(0x0028, 0x0010, "US", 2).u16(2)
            .header(0x0028, 0x0011, "US", 2).u16(2)
            .header(0x0028, 0x0100, "US", 2).u16(8)
            .header(0x7fe0, 0x0010, "OB", 0xFFFFFFFFu).item(0xE000, 0).item(0xE000, static_cast<std::uint32_t>(64 + data.size()));
        d.u32(segments).u32(offset);
        for (int i = 0; i < 14; ++i) d.u32(0);
        return d.raw(data).item(0xE0DD, 0).bytes();
    };
    EXPECT_EQ(memory_error(rle(1, 64, "\x03" "abcd\0"s)).find("RLE"), std::string::npos); // one literal run of 4: 2x2 bytes
    expect_error(rle(1, 200, "\x03" "abcd\0"s), {"RLE frame 1", "segment 1 spans bytes 200 to 70 of the 70-byte fragment"});
    expect_error(rle(2, 64, "\x03" "abcd\0"s), {"RLE frame 1", "2 segments; expected 1"});
    expect_error(rle(1, 64, "\x05" "abcdef\0"s), {"RLE frame 1", "segment 1 runs past 4 of its 4 bytes"});
    expect_error(rle(1, 64, "\x01" "ab\0"s), {"RLE frame 1", "segment 1 ends after 2 of its 4 bytes"});
}

TEST_F(DicomScan, BadVrOddLengthAndStrayDelimiters)
{
    expect_error(DicomBytes().header(0x0008, 0x0060, "QQ", 2).raw("CT").bytes(), {"(0008,0060)", "VR \"QQ\""});
    expect_error(DicomBytes().element(0x0008, 0x0060, "CS", "CTX").bytes(), {"(0008,0060)", "odd value length 3"});
    expect_error(DicomBytes().item(0xE0DD, 0).bytes(), {"(fffe,e0dd)", "a Sequence Delimitation Item among data elements"});
    expect_error(DicomBytes().header(0x0028, 0x0010, "US", 4).u32(0).header(0x0028, 0x0011, "US", 3).raw("abc").bytes(),
                 {"(0028,0011)", "odd value length 3"});
}

TEST_F(DicomScan, EncapsulatedPixelData)
{
    // RLE: the Basic Offset Table, one fragment, no delimiter
    DicomBytes d("1.2.840.10008.1.2.5");
    d.header(0x7fe0, 0x0010, "OB", 0xFFFFFFFFu).item(0xE000, 0).item(0xE000, 4).raw("abcd");
    expect_error(d.bytes(), {"encapsulated Pixel Data", "without its Sequence Delimitation Item"});
    // a fragment longer than the file
    DicomBytes e("1.2.840.10008.1.2.5");
    e.header(0x7fe0, 0x0010, "OB", 0xFFFFFFFFu).item(0xE000, 0).item(0xE000, 1000).raw("abcd");
    expect_error(e.bytes(), {"(fffe,e000)", "value length 1000 passes the end of the file"});
    // native syntax with undefined-length Pixel Data
    DicomBytes f;
    f.header(0x7fe0, 0x0010, "OB", 0xFFFFFFFFu).item(0xE000, 0).item(0xE0DD, 0);
    expect_error(f.bytes(), {"(7fe0,0010)", "undefined length in a native transfer syntax"});
}

TEST_F(DicomScan, DeflatedAndUnknownSyntaxesAreRefusedByName)
{
    expect_error(DicomBytes("1.2.840.10008.1.2.1.99").bytes(), {"Deflated Explicit VR Little Endian"});
    expect_error(DicomBytes("1.2.3.4").bytes(), {"transfer syntax \"1.2.3.4\" is not read"});
}

TEST_F(DicomScan, TruncatedFilesGiveOneLine)
{
    const std::string whole = image().bytes();
    for (std::size_t cut : {std::size_t{0}, std::size_t{100}, std::size_t{131}, std::size_t{133}, std::size_t{140}, std::size_t{160},
                            whole.size() / 2, whole.size() - 9, whole.size() - 3, whole.size() - 1}) {
        SCOPED_TRACE(cut);
        const std::string m = memory_error(whole.substr(0, cut));
        EXPECT_EQ(m.rfind("mem.dcm: ", 0), 0u) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
    // every prefix: an error, never a crash
    for (std::size_t cut = 0; cut < whole.size(); ++cut) EXPECT_NE(memory_error(whole.substr(0, cut)), "(no error)") << cut;
}

TEST_F(DicomScan, CompressedPixelDataMustHoldTheDeclaredSamples)
{
    DicomBytes d("1.2.840.10008.1.2.5");
    d.element(0x0008, 0x0060, "CS", "CT")
        .header(0x0028, 0x0010, "US", 2).u16(60000)
        .header(0x0028, 0x0011, "US", 2).u16(60000)
        .header(0x0028, 0x0100, "US", 2).u16(16)
        .header(0x7fe0, 0x0010, "OB", 0xFFFFFFFFu).item(0xE000, 0).item(0xE000, 64).raw(std::string(64, '\0')).item(0xE0DD, 0);
    expect_error(d.bytes(), {"60000x60000 pixels", "the compressed Pixel Data holds 64", "at most 1024 times"});
}

} // namespace
} // namespace cmc33
