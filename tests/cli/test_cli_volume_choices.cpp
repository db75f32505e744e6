// --frame, --array and --series through the real `cmc33` executable (CMC33_EXE): given for a format
// that has no use for them (NRRD, MetaImage, VTK legacy, raw, and each of the others' neighbours)
// they are a usage error, never silently ignored; for the formats that read them they still work.
// And a compressed NIfTI pair's data file x.img.gz is an input, never overwritten.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "cli_run.hpp"
#include "cmc33/io.hpp"
#include "test_support.hpp"

namespace cmc33 {
namespace {

namespace fs = std::filesystem;
using test::cli::quote;
using test::cli::ball_samples;
using test::cli::expect_usage_error;
using test::cli::Result;
using test::cli::run;

/// A version-1 .npy of the ball, uint8 [z, y, x] in C order.
std::string ball_npy()
{
    std::string header = "{'descr': '|u1', 'fortran_order': False, 'shape': (8, 8, 8), }";
    while ((10 + header.size() + 1) % 64 != 0) header += ' ';
    header += '\n';
    std::string bytes("\x93NUMPY\x01\x00", 8);
    bytes += static_cast<char>(header.size() & 0xff);
    bytes += static_cast<char>(header.size() >> 8);
    return bytes + header + ball_samples();
}

/// A little-endian NIfTI-1 header of the ball (uint8, 8^3); "ni1" for a pair, else "n+1".
std::string ball_nifti_header(bool pair)
{
    return test::nifti1_header({.dims = {8, 8, 8}, .datatype = 2, .magic = pair ? "ni1" : "n+1"});
}

std::string info(const fs::path& input, const std::string& more)
{
    return "info " + quote(input.string()) + " --json " + more;
}

TEST(CliVolumeChoices, RefusedWhereTheFormatHasNoUseForThem)
{
    const fs::path dir = test::temp_dir();
    const std::string samples = ball_samples();
    test::write_file(dir / "vol.nrrd",
                     "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 8 8 8\nencoding: raw\n\n" + samples);
    test::write_file(dir / "vol.mha", "NDims = 3\nDimSize = 8 8 8\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n" + samples);
    io::write_volume(test::make_volume({8, 8, 8}, [](std::int64_t, std::int64_t, std::int64_t) { return 1.0; }),
                     dir / "vol.vtk");
    test::write_file(dir / "vol.raw", samples);
    test::write_file(dir / "vol.npy", ball_npy());
    test::write_file(dir / "vol.nii", ball_nifti_header(false) + samples);

    const std::string raw = " --dims 8 8 8 --type uint8";
    struct Case {
        fs::path input;
        std::string more; // what the format needs besides
        std::vector<std::string> refused;
    };
    const std::vector<Case> cases = {
        {dir / "vol.nrrd", "", {"--frame 0", "--array a", "--series 1.2.3"}},
        {dir / "vol.mha", "", {"--frame 0", "--array a", "--series 1.2.3"}},
        {dir / "vol.vtk", "", {"--frame 0", "--array a", "--series 1.2.3"}},
        {dir / "vol.raw", raw, {"--frame 0", "--array a", "--series 1.2.3"}},
        {dir / "vol.npy", "", {"--array a", "--series 1.2.3"}},
        {dir / "vol.nii", "", {"--array a", "--series 1.2.3"}},
    };
    for (const Case& c : cases) {
        for (const std::string& option : c.refused) {
            SCOPED_TRACE(c.input.string() + " " + option);
            const std::string name = option.substr(0, option.find(' '));
            expect_usage_error(run(info(c.input, c.more + " " + option)), {name + " is for ", c.input.string()});
            expect_usage_error(run("extract " + quote(c.input.string()) + c.more + " " + option + " --iso 100 --quiet -o " +
                                   quote((dir / "m.ply").string())),
                               {name + " is for "});
            EXPECT_FALSE(fs::exists(dir / "m.ply"));
        }
    }
    // the formats that read them still take them
    for (const fs::path& input : {dir / "vol.npy", dir / "vol.nii"}) {
        SCOPED_TRACE(input.string());
        const Result ok = run(info(input, "--frame 0"));
        EXPECT_EQ(ok.code, 0) << ok.err;
    }
    // and without them, every one is read
    for (const Case& c : cases) {
        SCOPED_TRACE(c.input.string());
        const Result ok = run(info(c.input, c.more));
        EXPECT_EQ(ok.code, 0) << ok.err;
    }
}

TEST(CliVolumeChoices, CompressedPairDataFileIsAnInput)
{
    const fs::path dir = test::temp_dir();
    const std::string samples = ball_samples();
    test::write_file(dir / "x.hdr.gz", test::gzip_bytes(ball_nifti_header(true)));
    test::write_file(dir / "x.img.gz", test::gzip_bytes(samples));
    const std::string image = test::read_file(dir / "x.img.gz");
    // a mesh name that is the data file under another name
    fs::create_symlink("x.img.gz", dir / "soft.ply");
    fs::create_hard_link(dir / "x.img.gz", dir / "hard.stl");
    for (const char* input : {"x.hdr.gz", "x.img.gz"}) {
        SCOPED_TRACE(input);
        // read by either name, --frame taken as NIfTI's
        const Result ok = run(info(dir / input, "--frame 0"));
        EXPECT_EQ(ok.code, 0) << ok.err;
        // never written over
        for (const char* output : {"soft.ply", "hard.stl"}) {
            SCOPED_TRACE(output);
            expect_usage_error(run("extract " + quote((dir / input).string()) + " --iso 100 --quiet -o " +
                                   quote((dir / output).string())),
                               {"never replaces what it reads"});
            EXPECT_EQ(test::read_file(dir / "x.img.gz"), image);
        }
    }
}

} // namespace
} // namespace cmc33
