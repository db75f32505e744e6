// What reading a volume touches and what writing a file replaces: io::volume_files() (every data
// file a header names, for the CLI's rule that an output is never an input), NRRD axes that hold
// channels rather than places, and the atomic writer on existing files (mode, owner, symbolic
// links, read-only files, devices, names of the longest length).

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "atomic_file.hpp"
#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "test_support.hpp"
#include "volume_formats.hpp"

namespace cmc33::io {
namespace {

namespace fs = std::filesystem;
using test::read_file;
using test::temp_dir;
using test::write_file;

std::vector<fs::path> paths(const fs::path& dir, const std::vector<std::string>& names)
{
    std::vector<fs::path> out;
    for (const std::string& name : names) out.push_back(dir / name);
    return out;
}

/// The Error `f` throws (a failure if none): its status and message.
Error error_of(const std::function<void()>& f)
{
    try {
        f();
    } catch (const Error& e) {
        return e;
    }
    ADD_FAILURE() << "no error";
    return Error(Status::internal, "no error");
}

void expect_contains(const std::string& text, const std::string& part)
{
    EXPECT_NE(text.find(part), std::string::npos) << "no '" << part << "' in: " << text;
}

// ---- volume_files ---------------------------------------------------------------------------

constexpr const char* kNrrdFields = "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n";
constexpr const char* kMetaFields = "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\n";

TEST(VolumeFiles, NrrdSingleDataFileRelativeToTheHeader)
{
    const fs::path dir = temp_dir();
    fs::create_directory(dir / "h");
    write_file(dir / "h" / "v.nhdr", std::string(kNrrdFields) + "data file: ../d/samples.raw\n");
    EXPECT_EQ(volume_files(dir / "h" / "v.nhdr"),
              (std::vector<fs::path>{dir / "h" / "v.nhdr", dir / "h" / "../d/samples.raw"}));
    // The old one-word spelling, blanks around the name, an attached .nrrd with a data file.
    write_file(dir / "a.nrrd", std::string(kNrrdFields) + "datafile:   s.raw  \n\n");
    EXPECT_EQ(volume_files(dir / "a.nrrd"), paths(dir, {"a.nrrd", "s.raw"}));
    // An absolute name stays absolute.
    write_file(dir / "abs.nhdr", std::string(kNrrdFields) + "data file: /some/where.raw\n");
    EXPECT_EQ(volume_files(dir / "abs.nhdr"), (std::vector<fs::path>{dir / "abs.nhdr", "/some/where.raw"}));
    // A name relative to the working folder when the header has no folder.
    const fs::path cwd = fs::current_path();
    fs::current_path(dir);
    EXPECT_EQ(volume_files("abs.nhdr"), (std::vector<fs::path>{"abs.nhdr", "/some/where.raw"}));
    EXPECT_EQ(volume_files("a.nrrd"), (std::vector<fs::path>{"a.nrrd", "s.raw"}));
    fs::current_path(cwd);
}

TEST(VolumeFiles, NrrdListAndPatternForms)
{
    const fs::path dir = temp_dir();
    write_file(dir / "list.nhdr", std::string(kNrrdFields) + "data file: LIST 2\nz0.raw\n\n  z1.raw \n");
    EXPECT_EQ(volume_files(dir / "list.nhdr"), paths(dir, {"list.nhdr", "z0.raw", "z1.raw"}));
    write_file(dir / "pattern.nhdr", std::string(kNrrdFields) + "data file: slice%03d.raw 1 5 2 2\n");
    EXPECT_EQ(volume_files(dir / "pattern.nhdr"),
              paths(dir, {"pattern.nhdr", "slice001.raw", "slice003.raw", "slice005.raw"}));
    // Fields after the empty line that ends a header are samples, not fields.
    write_file(dir / "attached.nrrd", std::string(kNrrdFields) + "\ndata file: x.raw\n");
    EXPECT_EQ(volume_files(dir / "attached.nrrd"), paths(dir, {"attached.nrrd"}));
}

TEST(VolumeFiles, MetaImageForms)
{
    const fs::path dir = temp_dir();
    write_file(dir / "one.mhd", std::string(kMetaFields) + "ElementDataFile = one.raw\n");
    EXPECT_EQ(volume_files(dir / "one.mhd"), paths(dir, {"one.mhd", "one.raw"}));
    write_file(dir / "local.mha", std::string(kMetaFields) + "ElementDataFile = LOCAL\n" + std::string(8, '\0'));
    EXPECT_EQ(volume_files(dir / "local.mha"), paths(dir, {"local.mha"}));
    write_file(dir / "list.mhd", std::string(kMetaFields) + "elementdatafile = LIST\na.raw\nb.raw\n");
    EXPECT_EQ(volume_files(dir / "list.mhd"), paths(dir, {"list.mhd", "a.raw", "b.raw"}));
    write_file(dir / "pattern.mhd", std::string(kMetaFields) + "ElementDataFile = s%d.raw 3 1 -1\n");
    EXPECT_EQ(volume_files(dir / "pattern.mhd"), paths(dir, {"pattern.mhd", "s3.raw", "s2.raw", "s1.raw"}));
}

TEST(VolumeFiles, OnlyThePathWhenNoHeaderNamesAnotherFile)
{
    const fs::path dir = temp_dir();
    EXPECT_EQ(volume_files(dir / "missing.nhdr"), paths(dir, {"missing.nhdr"}));
    write_file(dir / "v.raw", std::string(8, '\0'));
    EXPECT_EQ(volume_files(dir / "v.raw"), paths(dir, {"v.raw"}));
    write_file(dir / "v.vtk", "# vtk DataFile Version 3.0\nx\nBINARY\n");
    EXPECT_EQ(volume_files(dir / "v.vtk"), paths(dir, {"v.vtk"}));
    fs::create_directory(dir / "folder.nhdr");
    EXPECT_EQ(volume_files(dir / "folder.nhdr"), paths(dir, {"folder.nhdr"}));
}

TEST(VolumeFiles, PatternExpansion)
{
    using detail::expand_file_pattern;
    EXPECT_EQ(expand_file_pattern("%03d.raw 8 10 1", 100), (std::vector<std::string>{"008.raw", "009.raw", "010.raw"}));
    EXPECT_EQ(expand_file_pattern("a%%b%-3dc 1 1 1", 100), (std::vector<std::string>{"a%b1  c"}));
    EXPECT_EQ(expand_file_pattern("%+.2i -1 1 1", 100), (std::vector<std::string>{"-01", "+00", "+01"}));
    EXPECT_EQ(expand_file_pattern("%4d 5 5 1", 100), (std::vector<std::string>{"   5"}));
    EXPECT_EQ(expand_file_pattern("%u 0 9 1", 3), (std::vector<std::string>{"0", "1", "2"}));
    // Not one integer conversion, no step, or beyond an int: no names (read_volume refuses them).
    EXPECT_TRUE(expand_file_pattern("%s 1 2 1", 100).empty());
    EXPECT_TRUE(expand_file_pattern("%d%d 1 2 1", 100).empty());
    EXPECT_TRUE(expand_file_pattern("%n 1 2 1", 100).empty());
    EXPECT_TRUE(expand_file_pattern("%d 1 2 0", 100).empty());
    EXPECT_TRUE(expand_file_pattern("%d 1 5000000000 1", 100).empty());
    EXPECT_TRUE(expand_file_pattern("%d 5 1 1", 100).empty());
    // The last int is reached without overflow.
    EXPECT_EQ(expand_file_pattern("%d 2147483646 2147483647 1", 100).size(), 2u);
}

// ---- NRRD axes that are channels --------------------------------------------------------------

std::string nrrd_with_kinds(const std::string& dimension, const std::string& sizes, const std::string& kinds,
                            std::size_t samples)
{
    return "NRRD0004\ntype: uint8\ndimension: " + dimension + "\nsizes: " + sizes + "\nkinds: " + kinds +
           "\nencoding: raw\n\n" + std::string(samples, '\x05');
}

TEST(VolumeKinds, NonSpatialAxesAreRefusedNamingTheAxis)
{
    const fs::path dir = temp_dir();
    struct Case {
        std::string dimension, sizes, kinds;
        std::size_t axis;
        std::string kind, size;
    };
    const std::vector<Case> cases = {
        {"3", "3 4 5", "RGB-color space space", 0, "RGB-color", "3"},
        {"3", "4 5 3", "domain domain 3-vector", 2, "3-vector", "3"},
        {"3", "2 4 5", "complex domain domain", 0, "complex", "2"},
        {"3", "6 4 5", "list domain domain", 0, "list", "6"},
        {"3", "4 6 5", "space vector space", 1, "vector", "6"},
        {"3", "4 4 5", "rgba-color space space", 0, "rgba-color", "4"},
        {"4", "3 4 5 6", "RGB-color space space space", 0, "RGB-color", "3"},
        {"4", "4 5 6 3", "space space space 3-vector", 3, "3-vector", "3"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.kinds);
        std::size_t samples = 1;
        for (char ch : c.sizes) samples *= ch >= '0' && ch <= '9' ? static_cast<std::size_t>(ch - '0') : 1;
        const fs::path path = dir / "channels.nrrd";
        write_file(path, nrrd_with_kinds(c.dimension, c.sizes, c.kinds, samples));
        const Error e = error_of([&] { (void)read_volume(path); });
        EXPECT_EQ(e.status(), Status::unsupported_format);
        const std::string msg = e.what();
        EXPECT_EQ(msg.rfind(path.string() + ": kinds ", 0), 0u) << msg;
        expect_contains(msg, "axis " + std::to_string(c.axis) + " (size " + c.size + ") is \"" + c.kind + "\"");
        expect_contains(msg, "not a spatial axis");
        expect_contains(msg, "unu slice -a " + std::to_string(c.axis) + " -p 0");
        // The same from memory (the fuzzed path).
        EXPECT_THROW((void)read_volume_from_memory(read_file(path), VolumeFormat::nrrd, "m.nrrd"), Error);
    }
}

TEST(VolumeKinds, DomainKindsAreRead)
{
    const fs::path dir = temp_dir();
    for (const std::string kinds :
         {"domain domain domain", "space space space", "space space time", "??? none domain", "Domain SPACE space"}) {
        SCOPED_TRACE(kinds);
        write_file(dir / "v.nrrd", nrrd_with_kinds("3", "2 3 4", kinds, 24));
        const Volume v = read_volume(dir / "v.nrrd");
        EXPECT_EQ(v.dims(), (Index3{2, 3, 4}));
    }
    // One kind per axis.
    write_file(dir / "v.nrrd", nrrd_with_kinds("3", "2 3 4", "domain domain", 24));
    const Error e = error_of([&] { (void)read_volume(dir / "v.nrrd"); });
    EXPECT_EQ(e.status(), Status::bad_format);
    expect_contains(e.what(), "has 2 kinds, expected 3");
}

// ---- the atomic writer on existing files -------------------------------------------------------

void write_text(const fs::path& path, const std::string& text)
{
    detail::write_atomically(path, [&](std::ostream& out) { out << text; });
}

TEST(AtomicWrite, KeepsTheModeOfTheFileItReplaces)
{
    const fs::path dir = temp_dir();
    for (const fs::perms mode : {fs::perms(0600), fs::perms(0640), fs::perms(0664), fs::perms(0400)}) {
        write_file(dir / "f.ply", "old");
        fs::permissions(dir / "f.ply", mode);
        if (mode == fs::perms(0400) && ::geteuid() != 0) {
            // Read-only for this user: refused, as a shell's `>` refuses it, and left as it was.
            const Error e = error_of([&] { write_text(dir / "f.ply", "new"); });
            EXPECT_EQ(e.status(), Status::io_error);
            expect_contains(e.what(), "is not writable");
            expect_contains(e.what(), "mode 0400");
            EXPECT_EQ(read_file(dir / "f.ply"), "old");
        } else {
            write_text(dir / "f.ply", "new");
            EXPECT_EQ(read_file(dir / "f.ply"), "new");
            EXPECT_EQ(fs::status(dir / "f.ply").permissions() & fs::perms::all, mode);
        }
        fs::permissions(dir / "f.ply", fs::perms(0600));
        fs::remove(dir / "f.ply");
    }
    // A new file: 0666 less the umask, as any program's.
    const ::mode_t mask = ::umask(022);
    write_text(dir / "new.ply", "x");
    ::umask(mask);
    EXPECT_EQ(fs::status(dir / "new.ply").permissions() & fs::perms::all, fs::perms(0644));
    for (const auto& entry : fs::directory_iterator(dir)) EXPECT_EQ(entry.path().filename(), "new.ply");
}

TEST(AtomicWrite, KeepsOwnerAndGroupAsRoot)
{
    if (::geteuid() != 0) GTEST_SKIP() << "giving a file to another owner takes root";
    const fs::path dir = temp_dir();
    write_file(dir / "f.obj", "old");
    ASSERT_EQ(::chown((dir / "f.obj").c_str(), 4321, 8765), 0) << std::strerror(errno);
    ::chmod((dir / "f.obj").c_str(), 0640);
    write_text(dir / "f.obj", "new");
    struct stat st {};
    ASSERT_EQ(::stat((dir / "f.obj").c_str(), &st), 0);
    EXPECT_EQ(st.st_uid, 4321u);
    EXPECT_EQ(st.st_gid, 8765u);
    EXPECT_EQ(st.st_mode & 07777, 0640u);
    EXPECT_EQ(read_file(dir / "f.obj"), "new");
}

TEST(AtomicWrite, WritesThroughSymbolicLinks)
{
    const fs::path dir = temp_dir();
    fs::create_directories(dir / "a");
    fs::create_directories(dir / "b");
    write_file(dir / "b" / "target.ply", "old");
    fs::permissions(dir / "b" / "target.ply", fs::perms(0640));
    fs::create_symlink("../b/target.ply", dir / "a" / "link.ply");
    fs::create_symlink("a/link.ply", dir / "chain.ply");
    write_text(dir / "chain.ply", "new");
    EXPECT_TRUE(fs::is_symlink(dir / "chain.ply"));
    EXPECT_TRUE(fs::is_symlink(dir / "a" / "link.ply"));
    EXPECT_EQ(read_file(dir / "b" / "target.ply"), "new");
    EXPECT_EQ(fs::status(dir / "b" / "target.ply").permissions() & fs::perms::all, fs::perms(0640));
    // A dangling link: its target is created, as a shell's `>` does.
    fs::create_symlink("b/made.ply", dir / "dangling.ply");
    write_text(dir / "dangling.ply", "made");
    EXPECT_TRUE(fs::is_symlink(dir / "dangling.ply"));
    EXPECT_EQ(read_file(dir / "b" / "made.ply"), "made");
    // ... unless its folder does not exist.
    fs::create_symlink("nowhere/x.ply", dir / "lost.ply");
    const Error lost = error_of([&] { write_text(dir / "lost.ply", "x"); });
    EXPECT_EQ(lost.status(), Status::io_error);
    expect_contains(lost.what(), (dir / "lost.ply").string() + ": cannot write, folder " + (dir / "nowhere").string() +
                                     " does not exist");
    expect_contains(lost.what(), "symbolic link to " + (dir / "nowhere/x.ply").string());
    // A loop.
    fs::create_symlink("loop2.ply", dir / "loop1.ply");
    fs::create_symlink("loop1.ply", dir / "loop2.ply");
    const Error loop = error_of([&] { write_text(dir / "loop1.ply", "x"); });
    expect_contains(loop.what(), "symbolic links to follow (a loop?)");
    // No temporary left anywhere.
    for (const fs::path& folder : {dir, dir / "a", dir / "b"})
        for (const auto& entry : fs::directory_iterator(folder))
            EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
}

TEST(AtomicWrite, NeverReplacesDevicesOrDirectories)
{
    const fs::path dir = temp_dir();
    fs::create_symlink("/dev/null", dir / "null.ply");
    const Error device = error_of([&] { write_text(dir / "null.ply", "x"); });
    EXPECT_EQ(device.status(), Status::io_error);
    expect_contains(device.what(), "its target /dev/null is not a regular file");
    EXPECT_TRUE(fs::is_character_file("/dev/null"));
    fs::create_directory(dir / "d.ply");
    const Error folder = error_of([&] { write_text(dir / "d.ply", "x"); });
    expect_contains(folder.what(), "cannot write: it is a directory");
}

TEST(AtomicWrite, NamesOfTheLongestLength)
{
    const fs::path dir = temp_dir();
    for (const std::size_t length : {243u, 250u, 255u}) {
        SCOPED_TRACE(length);
        const std::string name = std::string(length - 4, 'n') + ".ply";
        write_text(dir / name, "a");
        write_text(dir / name, "b"); // replacing it too
        EXPECT_EQ(read_file(dir / name), "b");
        fs::remove(dir / name);
    }
    // Multi-byte characters are not cut in the middle: after "x", byte 64 is the second of one.
    std::string accents = "x";
    while (accents.size() < 200) accents += "\xc3\xa9"; // é
    const std::string temp_name = detail::temporary_beside(dir / (accents + ".ply")).filename().string();
    EXPECT_LE(temp_name.size(), 1 + detail::kTemporaryNameBytes + 30);
    EXPECT_EQ(temp_name.find(".tmp"), detail::kTemporaryNameBytes);
    EXPECT_EQ(temp_name.substr(0, 64), "." + accents.substr(0, 63));
    EXPECT_TRUE(fs::is_empty(dir));
}

TEST(AtomicWrite, ALeftoverTemporaryOfThisPidIsReplaced)
{
    // A killed process with this pid left the name the next temporary takes.
    const fs::path dir = temp_dir();
    const std::string name = detail::temporary_beside(dir / "m.ply").filename().string(); // .m.ply.tmpPID-N
    const std::size_t dash = name.rfind('-');
    const std::string next = name.substr(0, dash + 1) + std::to_string(std::stoul(name.substr(dash + 1)) + 1);
    write_file(dir / next, "stale");
    write_text(dir / "m.ply", "new");
    EXPECT_EQ(read_file(dir / "m.ply"), "new");
    EXPECT_FALSE(fs::exists(dir / next));
}

TEST(AtomicWrite, ACreateFailureSaysWhy)
{
    // No file can be made in /proc, not even by root.
    const Error proc = error_of([&] { write_text("/proc/m.ply", "x"); });
    EXPECT_EQ(proc.status(), Status::io_error);
    const std::string msg = proc.what();
    EXPECT_EQ(msg.rfind("/proc/m.ply: cannot create a file in /proc (", 0), 0u) << msg;
    EXPECT_GT(msg.size(), std::string("/proc/m.ply: cannot create a file in /proc ()").size()) << msg;
    if (::geteuid() == 0) return; // root may create files in a read-only folder
    const fs::path dir = temp_dir();
    fs::create_directory(dir / "ro");
    fs::permissions(dir / "ro", fs::perms(0555));
    const Error e = error_of([&] { write_text(dir / "ro" / "m.ply", "x"); });
    fs::permissions(dir / "ro", fs::perms(0755));
    EXPECT_EQ(e.status(), Status::io_error);
    expect_contains(e.what(), "cannot create a file in " + (dir / "ro").string() + " (Permission denied)");
}

} // namespace
} // namespace cmc33::io
