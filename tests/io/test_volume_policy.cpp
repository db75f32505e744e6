// The trailing-data policy of the volume readers (docs/formats.md), the in-memory API, bounded
// memory on headers that lie about their size (#9 item 5), and the small reader messages of
// #9 item 9. Each check goes through read_volume() (files) and, where it matters, through
// read_volume_from_memory(), which share one code path.

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "cmc33/io.hpp"
#include "test_support.hpp"

namespace cmc33::io {
namespace {

using test::gzip_bytes;
using test::temp_dir;
using test::write_file;
using test::zlib_bytes;

/// `f` must throw Error with `status` and a one-line message starting with `label` + ": " and
/// containing every fact.
void expect_error(const std::function<void()>& f, Status status, const std::string& label,
                  std::initializer_list<std::string_view> facts)
{
    try {
        f();
        ADD_FAILURE() << "no error for " << label;
    } catch (const Error& e) {
        const std::string msg = e.what();
        EXPECT_EQ(e.status(), status) << msg;
        EXPECT_EQ(msg.rfind(label + ": ", 0), 0u) << "does not start with the label: " << msg;
        EXPECT_EQ(msg.find('\n'), std::string::npos) << "not one line: " << msg;
        for (std::string_view fact : facts) {
            EXPECT_NE(msg.find(fact), std::string::npos) << "lacks \"" << fact << "\": " << msg;
        }
    }
}

void expect_file_error(const std::filesystem::path& path, const std::string& content, Status status,
                       std::initializer_list<std::string_view> facts)
{
    SCOPED_TRACE(path.filename().string());
    write_file(path, content);
    expect_error([&] { read_volume(path); }, status, path.string(), facts);
}

const std::string kSamples16(16, '\x01'); // 2x2x2 uint16, any byte order
const std::string kNrrd = "NRRD0004\ntype: uint16\ndimension: 3\nsizes: 2 2 2\nendian: little\n";
const std::string kMhd = "NDims = 3\nDimSize = 2 2 2\nElementType = MET_USHORT\n";
const std::string kVtk = "# vtk DataFile Version 3.0\nt\nBINARY\nDATASET STRUCTURED_POINTS\n"
                         "DIMENSIONS 2 2 2\nPOINT_DATA 8\nSCALARS s unsigned_short\n";

// ---- count mismatches: more than declared ---------------------------------------------------

TEST(VolumePolicy, BytesAfterRawSamplesAreAnError)
{
    const auto dir = temp_dir();
    expect_file_error(dir / "a.nrrd", kNrrd + "encoding: raw\n\n" + kSamples16 + "\n",
                      Status::bad_format,
                      {"(16 bytes) but 17 bytes follow byte", "1 more after the samples"});
    expect_file_error(dir / "a.mha", kMhd + "ElementDataFile = LOCAL\n" + kSamples16 + "xyz",
                      Status::bad_format, {"3 more after the samples"});
    // Detached data files: the data file is named, the header starts the message.
    write_file(dir / "d.raw", kSamples16 + "tail");
    expect_file_error(dir / "d.nhdr", kNrrd + "encoding: raw\ndata file: d.raw\n",
                      Status::bad_format,
                      {"d.nhdr: data file " + (dir / "d.raw").string(), "4 more after the samples"});
    expect_file_error(dir / "d.mhd", kMhd + "ElementDataFile = d.raw\n", Status::bad_format,
                      {"d.mhd: data file", "4 more after the samples"});
    // byte skip -1 / HeaderSize -1: the samples are the last bytes; what precedes is skipped.
    write_file(dir / "end.nrrd", kNrrd + "encoding: raw\nbyte skip: -1\n\nxx" + kSamples16);
    EXPECT_NO_THROW(read_volume(dir / "end.nrrd"));
    write_file(dir / "end.mhd", kMhd + "HeaderSize = -1\nElementDataFile = d.raw\n");
    EXPECT_NO_THROW(read_volume(dir / "end.mhd"));
}

TEST(VolumePolicy, VtkMayContinueWithAttributesButNotWithSamples)
{
    const auto dir = temp_dir();
    // VTK writes a line end after binary samples, and further attributes may follow.
    write_file(dir / "nl.vtk", kVtk + kSamples16 + "\n");
    EXPECT_NO_THROW(read_volume(dir / "nl.vtk"));
    write_file(dir / "attr.vtk", kVtk + kSamples16 + "\nVECTORS v float\n" + std::string(96, '\0'));
    EXPECT_NO_THROW(read_volume(dir / "attr.vtk"));
    write_file(dir / "meta.vtk", kVtk + kSamples16 + "\nMETADATA\nINFORMATION 0\n\n");
    EXPECT_NO_THROW(read_volume(dir / "meta.vtk"));
    expect_file_error(dir / "more.vtk", kVtk + kSamples16 + "\x01\x02", Status::bad_format,
                      {"after the 8 samples POINT_DATA declares", "at byte",
                       "more samples than declared"});
}

TEST(VolumePolicy, CompressedStreamsEndWhereDeclared)
{
    const auto dir = temp_dir();
    const std::string z = zlib_bytes(kSamples16);
    expect_file_error(dir / "z.mha",
                      kMhd + "CompressedData = True\nCompressedDataSize = " +
                          std::to_string(z.size()) + "\nElementDataFile = LOCAL\n" + z + "junk",
                      Status::bad_format, {"4 more after the stream"});
    // Zero padding after a gzip stream stays accepted (tape blocks; gzip itself ignores it).
    write_file(dir / "pad.nrrd", kNrrd + "encoding: gzip\n\n" + gzip_bytes(kSamples16) +
                                     std::string(512, '\0'));
    EXPECT_NO_THROW(read_volume(dir / "pad.nrrd"));
    expect_file_error(dir / "junk.nrrd", kNrrd + "encoding: gzip\n\n" + gzip_bytes(kSamples16) + "x",
                      Status::bad_format, {"not zero padding"});
}

// ---- ASCII: the count is the evidence -------------------------------------------------------

TEST(VolumePolicy, AsciiWithoutFinalNewlineIsReadAndExtraValuesAreRefused)
{
    const auto dir = temp_dir();
    const std::string nrrd =
        "NRRD0004\ntype: short\ndimension: 3\nsizes: 2 2 2\nencoding: ascii\n\n";
    write_file(dir / "a.nrrd", nrrd + "1 2 3 4\n5 6 7 -8");
    const Volume v = read_volume(dir / "a.nrrd");
    EXPECT_EQ(v.samples<std::int16_t>()[7], -8);
    write_file(dir / "b.nrrd", nrrd + "1 2 3 4\n5 6 7 -8\r\n\n  \t");
    EXPECT_NO_THROW(read_volume(dir / "b.nrrd"));
    expect_file_error(dir / "c.nrrd", nrrd + "1 2 3 4 5 6 7 8 9 10\n", Status::bad_format,
                      {"declares 8 values but more follow: \"9\" at byte"});
    expect_file_error(dir / "d.nrrd", nrrd + "1 2 3 4 5 6 7\n", Status::truncated_file,
                      {"declares 8 values but the data ends after 7"});
}

// ---- the in-memory API ----------------------------------------------------------------------

TEST(VolumePolicy, MemoryReadsMatchFileReads)
{
    const auto dir = temp_dir();
    const std::string nrrd = kNrrd + "encoding: gzip\nspacings: 1 2 3\n\n" + gzip_bytes(kSamples16);
    write_file(dir / "m.nrrd", nrrd);
    const Volume from_file = read_volume(dir / "m.nrrd");
    const Volume from_memory = read_volume_from_memory(nrrd, VolumeFormat::nrrd, "m.nrrd");
    EXPECT_EQ(from_memory.dims(), from_file.dims());
    EXPECT_EQ(from_memory.spacing(), from_file.spacing());
    EXPECT_EQ(std::memcmp(from_memory.bytes(), from_file.bytes(), from_file.byte_size()), 0);

    // A detached header and its data file, both in memory.
    const std::string header = kMhd + "ElementSpacing = 1 1 2\nElementDataFile = ct.raw\n";
    const MemoryFiles files = [&](std::string_view name) -> std::optional<std::string_view> {
        if (name == "ct.raw") return std::string_view(kSamples16);
        return std::nullopt;
    };
    const Volume mhd = read_volume_from_memory(header, VolumeFormat::metaimage, "ct.mhd",
                                               std::nullopt, files);
    EXPECT_EQ(mhd.spacing(), (Vec3{1, 1, 2}));
    expect_error(
        [&] {
            read_volume_from_memory(kMhd + "ElementDataFile = other.raw\n", VolumeFormat::metaimage,
                                    "ct.mhd", std::nullopt, files);
        },
        Status::io_error, "ct.mhd", {"data file other.raw", "no such file"});
    expect_error([&] { read_volume_from_memory(kNrrd + "encoding: raw\ndata file: x.raw\n",
                                               VolumeFormat::nrrd, "n.nhdr"); },
                 Status::io_error, "n.nhdr", {"data file x.raw"});

    RawOptions raw;
    raw.dims = {2, 2, 2};
    raw.type = ScalarType::u16;
    raw.endian = Endian::big;
    const Volume r = read_volume_from_memory(kSamples16, VolumeFormat::raw, "v.raw", raw);
    EXPECT_EQ(r.samples<std::uint16_t>()[0], 0x0101);
    expect_error([&] { read_volume_from_memory(kSamples16 + "x", VolumeFormat::raw, "v.raw", raw); },
                 Status::invalid_argument, "v.raw", {"holds 17 bytes", "16 bytes"});
    expect_error([&] { read_volume_from_memory("", VolumeFormat::vtk, "e.vtk"); },
                 Status::truncated_file, "e.vtk", {"empty"});
}

// ---- bounded memory on lying headers (#9 item 5) --------------------------------------------

/// Deterministic bytes that do not compress.
std::string noise(std::size_t size, std::uint64_t seed)
{
    std::string out(size, '\0');
    for (std::size_t i = 0; i < size; i += 8) {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        std::memcpy(out.data() + i, &seed, std::min<std::size_t>(8, size - i));
    }
    return out;
}

/// A gzip member header, then `body` as the deflate data (random bytes: corrupt soon).
std::string gzip_header_then(const std::string& body)
{
    return std::string("\x1f\x8b\x08\x00\x00\x00\x00\x00\x00\x03", 10) + body;
}

std::string float_nrrd(int n, const std::string& stream)
{
    const std::string s = std::to_string(n);
    return "NRRD0004\ntype: float\ndimension: 3\nsizes: " + s + " " + s + " " + s +
           "\nendian: little\nencoding: gzip\n\n" + stream;
}

std::int64_t status_kib(const char* field)
{
    std::ifstream status("/proc/self/status");
    std::string line;
    while (std::getline(status, line)) {
        if (line.rfind(field, 0) == 0) return std::stoll(line.substr(std::strlen(field)));
    }
    return -1;
}

struct ChildRead {
    std::string message;   ///< the Error's message, or "no error"
    std::int64_t peak_kib; ///< growth of the peak resident size while reading
};

/// Reads `path` in a forked child (so that the peak resident size measures this read alone) and
/// reports the error message and how much the peak resident size grew.
ChildRead read_in_child(const std::filesystem::path& path)
{
    int fds[2];
    if (::pipe(fds) != 0) return {"pipe failed", -1};
    const pid_t pid = ::fork();
    if (pid == 0) {
        ::close(fds[0]);
        // Reset the peak to the current size (Linux >= 4.0); otherwise measure from the
        // inherited peak, which can only make the growth look smaller.
        if (std::FILE* f = std::fopen("/proc/self/clear_refs", "w")) {
            std::fputs("5", f);
            std::fclose(f);
        }
        const std::int64_t before = std::max(status_kib("VmHWM:"), status_kib("VmRSS:"));
        std::string message = "no error";
        try {
            read_volume(path);
        } catch (const Error& e) {
            message = e.what();
        } catch (const std::exception& e) {
            message = std::string("not a cmc33::Error: ") + e.what();
        }
        const std::string report = std::to_string(status_kib("VmHWM:") - before) + " " + message;
        const ssize_t written = ::write(fds[1], report.data(), report.size());
        ::_exit(written == static_cast<ssize_t>(report.size()) ? 0 : 1);
    }
    ::close(fds[1]);
    std::string report;
    char buffer[4096];
    ssize_t n = 0;
    while ((n = ::read(fds[0], buffer, sizeof buffer)) > 0) report.append(buffer, static_cast<std::size_t>(n));
    ::close(fds[0]);
    int status = 0;
    ::waitpid(pid, &status, 0);
    const std::size_t space = report.find(' ');
    if (!WIFEXITED(status) || space == std::string::npos) return {"child failed: " + report, -1};
    return {report.substr(space + 1), std::stoll(report.substr(0, space))};
}

constexpr std::int64_t kMiB = 1024;

TEST(VolumePolicy, LyingGzipHeaderCostsOnlyWhatTheStreamHolds)
{
    const auto dir = temp_dir();
    // 4 MB of corrupt deflate data declaring 1000^3 floats (4 GB): 3.9 GB peak before the fix.
    write_file(dir / "corrupt.nrrd", float_nrrd(1000, gzip_header_then(noise(4 << 20, 1))));
    ChildRead r = read_in_child(dir / "corrupt.nrrd");
    EXPECT_NE(r.message.find("corrupt compressed data"), std::string::npos) << r.message;
    EXPECT_GE(r.peak_kib, 0) << r.message;
    EXPECT_LT(r.peak_kib, 200 * kMiB);

    // A valid 4 MB stream (stored noise) that holds 4 MB but declares 4 GB.
    write_file(dir / "short.nrrd", float_nrrd(1000, gzip_bytes(noise(4 << 20, 2))));
    r = read_in_child(dir / "short.nrrd");
    EXPECT_NE(r.message.find("the compressed stream holds only 4194304 bytes but the header "
                             "declares 4000000000"),
              std::string::npos)
        << r.message;
    EXPECT_GE(r.peak_kib, 0) << r.message;
    EXPECT_LT(r.peak_kib, 200 * kMiB);

    // 40 MB declaring 2000^3 floats (32 GB): the corruption is named, not "cannot allocate".
    write_file(dir / "big.nrrd", float_nrrd(2000, gzip_header_then(noise(40 << 20, 3))));
    r = read_in_child(dir / "big.nrrd");
    EXPECT_NE(r.message.find("corrupt compressed data near byte"), std::string::npos) << r.message;
    EXPECT_EQ(r.message.find("cannot allocate"), std::string::npos) << r.message;
    EXPECT_LT(r.peak_kib, 400 * kMiB);
}

// ---- messages (#9 item 9) -------------------------------------------------------------------

TEST(VolumePolicy, MessagesSayWhatIsWrongOnce)
{
    const auto dir = temp_dir();
    // The inflate bound used to print "(N bytes) (N bytes)".
    try {
        write_file(dir / "bomb.nrrd", float_nrrd(1000, gzip_bytes("tiny")));
        read_volume(dir / "bomb.nrrd");
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("(4000000000 bytes), which cannot come out of the"), std::string::npos)
            << msg;
        EXPECT_EQ(msg.find("bytes) ("), std::string::npos) << msg;
    }
    // 1e999 is a number, out of range.
    expect_file_error(dir / "r.mha",
                      kMhd + "ElementSpacing = 1 1e999 1\nElementDataFile = LOCAL\n" + kSamples16,
                      Status::bad_format, {"\"1e999\" is out of the double range"});
    expect_file_error(dir / "r.nrrd",
                      kNrrd + "encoding: raw\nspace directions: (1,0,0) (0,-1e400,0) (0,0,1)\n\n" +
                          kSamples16,
                      Status::bad_format, {"\"-1e400\" is out of the double range"});
    expect_file_error(dir / "x.mha", kMhd + "ElementSpacing = 1 abc 1\nElementDataFile = LOCAL\n",
                      Status::bad_format, {"\"abc\" is not a number"});
    // DimSize errors name the header, even when the samples are in a data file.
    write_file(dir / "d.raw", kSamples16);
    const std::string name = (dir / "dims.mhd").string();
    write_file(dir / "dims.mhd",
               "NDims = 3\nDimSize = 2 1 2\nElementType = MET_USHORT\nElementDataFile = d.raw\n");
    try {
        read_volume(dir / "dims.mhd");
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()),
                  name + ": sizes 2x1x2: an isosurface needs at least 2 samples on each axis");
    }
    // permuted and oblique "space directions" are frames, read since the frames work
    // (tests/io/test_volume_frames.cpp); only degenerate ones are refused there
}

} // namespace
} // namespace cmc33::io
