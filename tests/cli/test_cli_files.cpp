// The files a command reads and writes, through the real `cmc33` executable (CMC33_EXE): a data
// file a volume's header names is an input, never overwritten; NRRD axes of channels are refused;
// rewriting an output keeps its mode, owner and symbolic links, and names of any valid length work.

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "cli_run.hpp"
#include "test_support.hpp"

namespace cmc33 {
namespace {

namespace fs = std::filesystem;
using test::cli::quote;
using test::cli::ball_samples;
using test::cli::expect_usage_error;
using test::cli::Result;
using test::cli::run;

/// Every file under `dir` (recursively, links not followed) with its bytes ("-> TARGET" for a link).
void snapshot_into(const fs::path& root, const fs::path& dir, std::map<std::string, std::string>& files)
{
    for (const auto& e : fs::directory_iterator(dir)) {
        const std::string name = e.path().lexically_relative(root).string();
        const fs::file_status st = fs::symlink_status(e.path());
        if (fs::is_symlink(st)) {
            files[name] = "-> " + fs::read_symlink(e.path()).string();
        } else if (fs::is_directory(st)) {
            files[name] = "(folder)";
            snapshot_into(root, e.path(), files);
        } else {
            files[name] = test::read_file(e.path());
        }
    }
}

std::map<std::string, std::string> snapshot(const fs::path& dir)
{
    std::map<std::string, std::string> files;
    snapshot_into(dir, dir, files);
    return files;
}

constexpr const char* kNrrdFields = "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 8 8 8\nencoding: raw\n";
constexpr const char* kMetaFields = "NDims = 3\nDimSize = 8 8 8\nElementType = MET_UCHAR\n";

std::string extract(const fs::path& input, const fs::path& output, const std::string& more = "")
{
    return "extract " + quote(input.string()) + " --iso 100 --quiet -o " + quote(output.string()) + more;
}

// ---- item: data files are inputs ---------------------------------------------------------------

TEST(CliFiles, ADataFileIsAnInputUnderEveryName)
{
    const fs::path dir = test::temp_dir();
    const std::string samples = ball_samples();
    test::write_file(dir / "samples.ply", samples);
    test::write_file(dir / "vol.nhdr", std::string(kNrrdFields) + "data file: samples.ply\n");
    test::write_file(dir / "vol.mhd", std::string(kMetaFields) + "ElementDataFile = samples.ply\n");
    fs::create_hard_link(dir / "samples.ply", dir / "hard.obj");
    fs::create_symlink("samples.ply", dir / "soft.stl");
    fs::create_directory(dir / "sub");
    const auto before = snapshot(dir);
    for (const fs::path& header : {dir / "vol.nhdr", dir / "vol.mhd"}) {
        for (const fs::path& out : {dir / "samples.ply", dir / "." / "samples.ply", dir / "sub" / ".." / "samples.ply",
                                    dir / "hard.obj", dir / "soft.stl"}) {
            SCOPED_TRACE(header.string() + " -o " + out.string());
            expect_usage_error(
                run(extract(header, out)),
                {out.string() + " is ", "a data file of the input " + header.string(), "never replaces what it reads"});
            // --memory-limit reads slab by slab from the same data file.
            if (out.extension() == ".ply") {
                expect_usage_error(run(extract(header, out, " --memory-limit 1M")), {"a data file of the input"});
            }
            EXPECT_EQ(snapshot(dir), before);
        }
    }
    // A spelling relative to the working folder.
    expect_usage_error(run(extract("vol.nhdr", "./samples.ply"), "cd " + quote(dir.string()) + " && "),
                       {"./samples.ply is samples.ply under another name, a data file of the input vol.nhdr"});
    EXPECT_EQ(snapshot(dir), before);
    // Another output is written, and the samples stay.
    for (const fs::path& header : {dir / "vol.nhdr", dir / "vol.mhd"}) {
        const Result ok = run(extract(header, dir / "mesh.ply"));
        EXPECT_EQ(ok.code, 0) << ok.err;
        EXPECT_TRUE(fs::is_regular_file(dir / "mesh.ply"));
        EXPECT_EQ(test::read_file(dir / "samples.ply"), samples);
    }
}

TEST(CliFiles, DataFilesInOtherFoldersAndThroughLinks)
{
    const fs::path dir = test::temp_dir();
    fs::create_directories(dir / "h");
    fs::create_directories(dir / "d");
    test::write_file(dir / "d" / "s.ply", ball_samples());
    test::write_file(dir / "h" / "vol.nhdr", std::string(kNrrdFields) + "data file: ../d/s.ply\n");
    test::write_file(dir / "h" / "abs.nhdr",
                     std::string(kNrrdFields) + "data file: " + (dir / "d" / "s.ply").string() + "\n");
    // A header reached through a link: its data file is named relative to the link's folder, as read.
    fs::create_directories(dir / "l");
    fs::create_symlink(dir / "h" / "vol.nhdr", dir / "l" / "link.nhdr");
    fs::create_symlink("../d/s.ply", dir / "h" / "s-link.ply");
    const auto before = snapshot(dir);
    for (const fs::path& header : {dir / "h" / "vol.nhdr", dir / "h" / "abs.nhdr", dir / "l" / "link.nhdr"}) {
        for (const fs::path& out : {dir / "d" / "s.ply", dir / "h" / "s-link.ply"}) {
            SCOPED_TRACE(header.string() + " -o " + out.string());
            expect_usage_error(run(extract(header, out)), {"a data file of the input " + header.string()});
            EXPECT_EQ(snapshot(dir), before);
        }
    }
}

TEST(CliFiles, ListAndPatternDataFilesAreInputsToo)
{
    const fs::path dir = test::temp_dir();
    const std::string plane(64, '\x07');
    for (const std::string name : {"z0.ply", "z1.ply", "slice003.ply", "slice005.ply", "m1.obj"}) {
        test::write_file(dir / name, plane);
    }
    test::write_file(dir / "list.nhdr", std::string(kNrrdFields) + "data file: LIST 2\nz0.ply\nz1.ply\n");
    test::write_file(dir / "pattern.nhdr", std::string(kNrrdFields) + "data file: slice%03d.ply 1 7 2 2\n");
    test::write_file(dir / "list.mhd", std::string(kMetaFields) + "ElementDataFile = LIST\nz0.ply\nz1.ply\n");
    test::write_file(dir / "pattern.mhd", std::string(kMetaFields) + "ElementDataFile = m%d.obj 0 7 1\n");
    const auto before = snapshot(dir);
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"list.nhdr", "z1.ply"}, {"pattern.nhdr", "slice005.ply"}, {"list.mhd", "z0.ply"}, {"pattern.mhd", "m1.obj"}};
    for (const auto& [header, out] : cases) {
        SCOPED_TRACE(header + " -o " + out);
        expect_usage_error(run(extract(dir / header, dir / out)), {"a data file of the input"});
        EXPECT_EQ(snapshot(dir), before);
        // These forms are not read: another output fails on them with exit 1, and nothing is written.
        expect_failure(run(extract(dir / header, dir / "new.ply")), {(dir / header).string(), "not supported"});
        EXPECT_EQ(snapshot(dir), before);
    }
}

// ---- item: channels ----------------------------------------------------------------------------

TEST(CliFiles, NrrdChannelsAreRefused)
{
    const fs::path dir = test::temp_dir();
    struct Case {
        std::string dimension, sizes, kinds, fact;
        std::size_t samples;
    };
    const std::vector<Case> cases = {
        {"3", "3 8 8", "RGB-color space space", "axis 0 (size 3) is \"RGB-color\"", 192},
        {"3", "8 8 3", "domain domain 3-vector", "axis 2 (size 3) is \"3-vector\"", 192},
        {"3", "2 8 8", "complex domain domain", "axis 0 (size 2) is \"complex\"", 128},
        {"3", "4 8 8", "list domain domain", "axis 0 (size 4) is \"list\"", 256},
        {"4", "3 8 8 8", "RGB-color space space space", "axis 0 (size 3) is \"RGB-color\"", 1536},
        {"4", "8 8 8 2", "space space space vector", "axis 3 (size 2) is \"vector\"", 1024},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.kinds);
        const fs::path in = dir / "in.nrrd";
        test::write_file(in, "NRRD0004\ntype: uint8\ndimension: " + c.dimension + "\nsizes: " + c.sizes +
                                 "\nkinds: " + c.kinds + "\nencoding: raw\n\n" + std::string(c.samples, '\x64'));
        expect_failure(run(extract(in, dir / "out.ply")), {in.string() + ": kinds ", c.fact, "not a spatial axis"});
        EXPECT_FALSE(fs::exists(dir / "out.ply"));
        const Result info = run("info " + quote(in.string()));
        EXPECT_EQ(info.code, 1) << info.err;
    }
    // Spatial kinds are meshed.
    test::write_file(dir / "ok.nrrd", std::string(kNrrdFields) + "kinds: space space space\n\n" + ball_samples());
    const Result ok = run(extract(dir / "ok.nrrd", dir / "out.ply"));
    EXPECT_EQ(ok.code, 0) << ok.err;
    // MetaImage: channels were refused already.
    test::write_file(dir / "rgb.mha", std::string(kMetaFields) +
                                          "ElementNumberOfChannels = 3\nElementDataFile = LOCAL\n" +
                                          std::string(1536, '\x64'));
    expect_failure(run(extract(dir / "rgb.mha", dir / "rgb.ply")), {"ElementNumberOfChannels = 3"});
    EXPECT_FALSE(fs::exists(dir / "rgb.ply"));
}

// ---- item: rewriting an output -----------------------------------------------------------------

struct FileStatus {
    unsigned mode = 0;
    std::uint32_t uid = 0, gid = 0;
};

FileStatus status_of(const fs::path& path)
{
    struct stat st {};
    EXPECT_EQ(::stat(path.c_str(), &st), 0) << path;
    return {static_cast<unsigned>(st.st_mode & 07777), st.st_uid, st.st_gid};
}

TEST(CliFiles, RewritingKeepsModeAndOwner)
{
    const fs::path dir = test::temp_dir();
    test::write_file(dir / "v.nrrd", std::string(kNrrdFields) + "\n" + ball_samples());
    for (const unsigned mode : {0600u, 0640u, 0664u}) {
        SCOPED_TRACE(mode);
        test::write_file(dir / "m.ply", "old");
        ::chmod((dir / "m.ply").c_str(), mode);
        const Result r = run(extract(dir / "v.nrrd", dir / "m.ply"));
        EXPECT_EQ(r.code, 0) << r.err;
        EXPECT_NE(test::read_file(dir / "m.ply"), "old");
        EXPECT_EQ(status_of(dir / "m.ply").mode, mode);
    }
    if (::geteuid() == 0) {
        // Root gives the new file the old one's owner and group.
        ASSERT_EQ(::chown((dir / "m.ply").c_str(), 4321, 8765), 0);
        ::chmod((dir / "m.ply").c_str(), 0640);
        for (const std::string more : {"", " --memory-limit 1M"}) {
            const Result r = run(extract(dir / "v.nrrd", dir / "m.ply", more));
            EXPECT_EQ(r.code, 0) << r.err;
            const FileStatus s = status_of(dir / "m.ply");
            EXPECT_EQ(s.uid, 4321u);
            EXPECT_EQ(s.gid, 8765u);
            EXPECT_EQ(s.mode, 0640u);
        }
    }
    EXPECT_EQ(snapshot(dir).size(), 2u); // v.nrrd and m.ply: no temporary left
}

TEST(CliFiles, ReadOnlyOutputs)
{
    const fs::path dir = test::temp_dir();
    test::write_file(dir / "v.nrrd", std::string(kNrrdFields) + "\n" + ball_samples());
    test::write_file(dir / "ro.ply", "old");
    ::chmod((dir / "ro.ply").c_str(), 0444);
    if (::geteuid() == 0) {
        // Root may write a read-only file, as with `>` in a shell: it stays read-only.
        const Result r = run(extract(dir / "v.nrrd", dir / "ro.ply"));
        EXPECT_EQ(r.code, 0) << r.err;
        EXPECT_NE(test::read_file(dir / "ro.ply"), "old");
        EXPECT_EQ(status_of(dir / "ro.ply").mode, 0444u);
        return;
    }
    const auto before = snapshot(dir);
    for (const std::string more : {"", " --memory-limit 1M"}) {
        expect_failure(run(extract(dir / "v.nrrd", dir / "ro.ply", more)),
                       {(dir / "ro.ply").string() + ": cannot write: it is not writable", "mode 0444"});
        EXPECT_EQ(snapshot(dir), before);
    }
}

TEST(CliFiles, ReadOnlyOutputsForAnotherUser)
{
    // The refusal above, seen by a user other than root: where this test runs as root, through setpriv.
    if (::geteuid() != 0 || !fs::exists("/usr/bin/setpriv")) GTEST_SKIP() << "runs as root with setpriv";
    const fs::path dir = test::temp_dir();
    for (fs::path p = dir; p != p.root_path(); p = p.parent_path()) {
        if ((fs::status(p).permissions() & fs::perms::others_exec) == fs::perms::none) {
            GTEST_SKIP() << p << " is closed to other users";
        }
    }
    test::write_file(dir / "v.nrrd", std::string(kNrrdFields) + "\n" + ball_samples());
    test::write_file(dir / "ro.ply", "old");
    ::chmod((dir / "ro.ply").c_str(), 0444);
    ::chmod(dir.c_str(), 0777);
    const auto before = snapshot(dir);
    const std::string nobody = "setpriv --reuid=65534 --regid=65534 --clear-groups ";
    expect_failure(run(extract(dir / "v.nrrd", dir / "ro.ply"), nobody),
                   {(dir / "ro.ply").string() + ": cannot write: it is not writable (Permission denied, mode 0444)"});
    EXPECT_EQ(snapshot(dir), before);
    // A writable file of root's in a folder anyone may write: the new file is the writer's, same mode.
    test::write_file(dir / "rw.ply", "old");
    ::chmod((dir / "rw.ply").c_str(), 0666);
    const Result r = run(extract(dir / "v.nrrd", dir / "rw.ply"), nobody);
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(status_of(dir / "rw.ply").mode, 0666u);
    EXPECT_EQ(status_of(dir / "rw.ply").uid, 65534u);
}

TEST(CliFiles, SymbolicLinksAreWrittenThrough)
{
    const fs::path dir = test::temp_dir();
    test::write_file(dir / "v.nrrd", std::string(kNrrdFields) + "\n" + ball_samples());
    fs::create_directories(dir / "elsewhere");
    test::write_file(dir / "elsewhere" / "t.ply", "old");
    ::chmod((dir / "elsewhere" / "t.ply").c_str(), 0600);
    fs::create_symlink("elsewhere/t.ply", dir / "link.ply");
    for (const std::string more : {"", " --memory-limit 1M"}) {
        const Result r = run(extract(dir / "v.nrrd", dir / "link.ply", more));
        EXPECT_EQ(r.code, 0) << r.err;
        EXPECT_TRUE(fs::is_symlink(dir / "link.ply"));
        EXPECT_EQ(fs::read_symlink(dir / "link.ply"), "elsewhere/t.ply");
        EXPECT_EQ(test::read_file(dir / "elsewhere" / "t.ply").substr(0, 3), "ply");
        EXPECT_EQ(status_of(dir / "elsewhere" / "t.ply").mode, 0600u);
        test::write_file(dir / "elsewhere" / "t.ply", "old");
    }
    // A dangling link: its target is made.
    fs::create_symlink("elsewhere/new.ply", dir / "dangling.ply");
    const Result made = run(extract(dir / "v.nrrd", dir / "dangling.ply"));
    EXPECT_EQ(made.code, 0) << made.err;
    EXPECT_TRUE(fs::is_symlink(dir / "dangling.ply"));
    EXPECT_TRUE(fs::is_regular_file(dir / "elsewhere" / "new.ply"));
    // ... unless its folder is missing; a loop; a device: refused before any work, nothing written.
    fs::create_symlink("missing/x.ply", dir / "lost.ply");
    fs::create_symlink("loop2.ply", dir / "loop1.ply");
    fs::create_symlink("loop1.ply", dir / "loop2.ply");
    fs::create_symlink("/dev/null", dir / "null.ply");
    const auto before = snapshot(dir);
    expect_failure(run(extract(dir / "v.nrrd", dir / "lost.ply")),
                   {(dir / "lost.ply").string() + ": cannot write: it is a symbolic link to", "does not exist"});
    expect_failure(run(extract(dir / "v.nrrd", dir / "loop1.ply")), {"(a loop?)"});
    expect_failure(run(extract(dir / "v.nrrd", dir / "null.ply")), {"its target /dev/null is not a regular file"});
    EXPECT_EQ(snapshot(dir), before);
    EXPECT_TRUE(fs::is_character_file("/dev/null"));
}

TEST(CliFiles, OutputNamesOfEveryValidLength)
{
    const fs::path dir = test::temp_dir();
    test::write_file(dir / "v.nrrd", std::string(kNrrdFields) + "\n" + ball_samples());
    for (const std::size_t length : {200u, 243u, 250u, 255u}) {
        SCOPED_TRACE(length);
        const fs::path out = dir / (std::string(length - 4, 'x') + ".ply");
        for (const std::string more : {"", "", " --memory-limit 1M"}) { // the second run replaces the first's file
            const Result r = run(extract(dir / "v.nrrd", out, more));
            EXPECT_EQ(r.code, 0) << r.err;
            EXPECT_TRUE(fs::is_regular_file(out));
        }
        fs::remove(out);
    }
    // One byte more is the operating system's limit: refused with its reason.
    const fs::path too_long = dir / (std::string(252, 'x') + ".ply");
    expect_failure(run(extract(dir / "v.nrrd", too_long)), {too_long.string() + ": cannot write: File name too long"});
    EXPECT_EQ(snapshot(dir).size(), 1u);
}

} // namespace
} // namespace cmc33
