// The verification dataset (cli/dataset): written files, manifest, and verify_dataset in-process
// and with an external command (the real cmc33 executable).

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "cmc33/topology.hpp"
#include "cmc33/verify.hpp"
#include "dataset.hpp"
#include "test_support.hpp"

namespace cmc33::cli {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> lines_of(const fs::path& path)
{
    std::ifstream in(path);
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
}

std::vector<std::int64_t> numbers(const MethodReport& m)
{
    std::vector<std::int64_t> n{m.checked,      m.matched,     m.mismatched,
                                m.undetermined, m.nonmanifold, m.errors};
    n.insert(n.end(), m.checked_by_kind.begin(), m.checked_by_kind.end());
    n.insert(n.end(), m.mismatched_by_kind.begin(), m.mismatched_by_kind.end());
    n.insert(n.end(), m.fields_per_subcase.begin(), m.fields_per_subcase.end());
    n.insert(n.end(), m.mismatches_per_subcase.begin(), m.mismatches_per_subcase.end());
    return n;
}

constexpr std::int64_t kCells = 50, kGrids = 20, kClosed = 10;

/// Writes a small dataset (seed 5) into `dir`.
fs::path small_dataset(const fs::path& dir, std::int64_t cells = kCells,
                       std::int64_t grids = kGrids, std::int64_t closed = kClosed)
{
    DatasetOptions o;
    o.cells = cells;
    o.grids = grids;
    o.closed = closed;
    o.seed = 5;
    o.threads = 2;
    (void)write_dataset(dir, o);
    return dir;
}

TEST(Dataset, WritesFilesManifestAndReadme)
{
    const fs::path dir = small_dataset(test::temp_dir() / "dataset");
    const std::vector<std::string> lines = lines_of(dir / "manifest.tsv");
    ASSERT_FALSE(lines.empty());
    EXPECT_EQ(lines[0], "file\tiso\teuler\tb0\tb1\tb2\tboundary_loops\tsubcase");
    const std::vector<ManifestEntry> entries = read_manifest(dir);
    EXPECT_EQ(entries.size() + 1, lines.size());
    EXPECT_GE(entries.size(),
              static_cast<std::size_t>(kCells + kGrids + kClosed - 3)); // undetermined are rare
    EXPECT_EQ(entries.front().file, "cells/cell-000001.nrrd");
    EXPECT_EQ(entries.front().line, 2);
    EXPECT_TRUE(fs::exists(dir / "README.txt"));
    EXPECT_NE(test::read_file(dir / "README.txt").find("counts as above"), std::string::npos);
    for (const ManifestEntry& e : entries) {
        SCOPED_TRACE(e.file);
        const Volume v = io::read_volume(dir / e.file);
        EXPECT_EQ(v.type(), ScalarType::f32);
        const FieldTopology t = field_topology(v, e.iso);
        ASSERT_TRUE(t.determined);
        EXPECT_EQ(t.euler, e.expected.euler);
        EXPECT_EQ(t.b0, e.expected.b0);
        EXPECT_EQ(t.b1, e.expected.b1);
        EXPECT_EQ(t.b2, e.expected.b2);
        EXPECT_EQ(t.boundary_loops, e.expected.boundary_loops);
        const bool cell = e.file.rfind("cells/", 0) == 0;
        EXPECT_EQ(e.subcase != "-", cell);
        if (e.file.rfind("closed/", 0) == 0) {
            EXPECT_EQ(e.expected.boundary_loops, 0);
        }
    }
    // The folder must be new, empty or a previous dataset: one foreign file and it is refused,
    // naming the file, and nothing is written or removed.
    test::write_file(dir / "README-mine.txt", "my notes");
    const std::size_t files_before = static_cast<std::size_t>(
        std::distance(fs::recursive_directory_iterator(dir), fs::recursive_directory_iterator()));
    try {
        (void)write_dataset(dir, DatasetOptions{});
        ADD_FAILURE() << "no exception";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("README-mine.txt"), std::string::npos) << e.what();
    }
    EXPECT_EQ(static_cast<std::size_t>(std::distance(fs::recursive_directory_iterator(dir),
                                                     fs::recursive_directory_iterator())),
              files_before);
    EXPECT_EQ(test::read_file(dir / "README-mine.txt"), "my notes");
    // Not a folder, and an empty name (it would mean the current folder).
    EXPECT_THROW((void)write_dataset(dir / "README-mine.txt", DatasetOptions{}), Error);
    EXPECT_THROW((void)write_dataset("", DatasetOptions{}), Error);
}

TEST(Dataset, ReplacesAPreviousDatasetAndNothingElse)
{
    const fs::path dir = small_dataset(test::temp_dir() / "dataset");
    // Written again with other counts: the old files are gone, the new ones all there.
    small_dataset(dir, 5, 3, 0);
    const std::vector<ManifestEntry> entries = read_manifest(dir);
    std::size_t files = 0;
    for (const auto& e : fs::recursive_directory_iterator(dir)) files += e.is_regular_file() ? 1 : 0;
    EXPECT_EQ(files, entries.size() + 2); // + manifest.tsv and README.txt
    EXPECT_FALSE(fs::exists(dir / "closed"));
    EXPECT_FALSE(fs::exists(dir / "cells" / "cell-000050.nrrd"));
    // A file the manifest does not list makes it not a dataset any more.
    test::write_file(dir / "cells" / "extra.nrrd", "x");
    EXPECT_THROW(small_dataset(dir, 5, 3, 0), Error);
    EXPECT_TRUE(fs::exists(dir / "cells" / "extra.nrrd"));
    // A leftover of a killed run (its hidden temporary folder) is removed, not refused.
    fs::remove(dir / "cells" / "extra.nrrd");
    fs::create_directory(dir / ".cmc33-dataset-tmp99999999");
    test::write_file(dir / ".cmc33-dataset-tmp99999999" / "x.nrrd", "x");
    small_dataset(dir, 5, 3, 0);
    EXPECT_FALSE(fs::exists(dir / ".cmc33-dataset-tmp99999999"));
}

TEST(Dataset, AFailureLeavesNothingBehind)
{
    // The folder's parent is a file: creating it fails at once.
    const fs::path base = test::temp_dir();
    test::write_file(base / "file", "x");
    EXPECT_THROW(small_dataset(base / "file" / "dataset"), Error);
    // A write that fails midway: tests/cli (CliDataset.LateFailureLeavesNothing, with ulimit -f).
}

TEST(Dataset, VerifiedInProcessLikeTheRandomRun)
{
    const fs::path dir = small_dataset(test::temp_dir() / "dataset");
    DatasetVerifyOptions o;
    o.methods = {Method::cmc33, Method::mc};
    o.threads = 2;
    const VerifyReport r = verify_dataset(dir, o);
    const auto entries = static_cast<std::int64_t>(read_manifest(dir).size());
    ASSERT_EQ(r.methods.size(), 2u);
    EXPECT_EQ(r.methods[0].checked, entries);
    EXPECT_EQ(r.methods[0].matched, entries);
    EXPECT_EQ(r.methods[0].nonmanifold, 0);
    EXPECT_GT(r.methods[1].mismatched, 0);

    // The same fields as verify() with the dataset's seed, so the same verdicts.
    VerifyOptions v;
    v.methods = o.methods;
    v.cells = kCells;
    v.grids = kGrids;
    v.closed = kClosed;
    v.seed = 5;
    const VerifyReport random = verify(v);
    if (random.methods[0].undetermined == 0) {
        EXPECT_EQ(numbers(r.methods[0]), numbers(random.methods[0]));
        EXPECT_EQ(numbers(r.methods[1]), numbers(random.methods[1]));
    }
}

TEST(Dataset, ExternalCommandsAreJudgedLikeInProcess)
{
    const fs::path dir = small_dataset(test::temp_dir() / "dataset");
    DatasetVerifyOptions in_process;
    in_process.methods = {Method::cmc33};
    const VerifyReport expected = verify_dataset(dir, in_process);

    const std::string cli = CMC33_CLI;
    DatasetVerifyOptions o;
    o.threads = 2;
    o.command = "'" + cli + "' extract {in} --iso {iso} -o {out}";
    const VerifyReport r = verify_dataset(dir, o);
    ASSERT_EQ(r.methods.size(), 1u);
    EXPECT_EQ(r.methods[0].name, "command");
    EXPECT_TRUE(r.methods[0].external);
    EXPECT_EQ(r.methods[0].errors, 0);
    EXPECT_EQ(numbers(r.methods[0]), numbers(expected.methods[0]));

    // The same through OBJ files, and a method chosen on the command line (fewer files: each
    // one starts a process).
    const fs::path few = small_dataset(dir.parent_path() / "few", 16, 4, 0);
    o.command = "'" + cli + "' extract {in} --iso {iso} --method mc -o {out}.obj";
    in_process.methods = {Method::mc};
    const VerifyReport mc = verify_dataset(few, o);
    const VerifyReport mc_expected = verify_dataset(few, in_process);
    EXPECT_EQ(mc.methods[0].checked, 20);
    EXPECT_EQ(mc.methods[0].errors, 0);
    EXPECT_EQ(mc.methods[0].mismatched, mc_expected.methods[0].mismatched);
    EXPECT_GT(mc.methods[0].mismatched, 0);
    // Subcases of a command are cmc33's, so only the totals compare with in-process mc.
    EXPECT_EQ(mc.methods[0].mismatched_by_kind, mc_expected.methods[0].mismatched_by_kind);
}

TEST(Dataset, FailingCommandsAreMismatchesWithAReason)
{
    const fs::path dir = small_dataset(test::temp_dir() / "dataset");
    const fs::path failures = dir.parent_path() / "failures";
    DatasetVerifyOptions o;
    o.threads = 2;
    o.max_failures = 3;
    o.failures_dir = failures;
    o.command = "echo 'no mesh today' >&2; exit 3; {in} {out}";
    const VerifyReport r = verify_dataset(dir, o);
    const auto entries = static_cast<std::int64_t>(read_manifest(dir).size());
    EXPECT_EQ(r.methods[0].checked, entries);
    EXPECT_EQ(r.methods[0].mismatched, entries);
    EXPECT_EQ(r.methods[0].errors, entries);
    const std::vector<std::string> lines = lines_of(failures / "failures.tsv");
    ASSERT_EQ(lines.size(), 4u);
    EXPECT_NE(lines[1].find("exited with status 3"), std::string::npos) << lines[1];
    EXPECT_NE(lines[1].find("no mesh today"), std::string::npos) << lines[1];
    EXPECT_NE(lines[1].find("cell-000001.nrrd"), std::string::npos) << lines[1];

    // A command that succeeds but writes nothing.
    o.command = "true {in} {out}";
    o.failures_dir.clear();
    const VerifyReport silent = verify_dataset(dir, o);
    EXPECT_EQ(silent.methods[0].errors, entries);
}

TEST(Dataset, CommandTemplates)
{
    const ExternalCommand c =
        expand_command("tool {in} --iso {iso} -o {out}", "/d/it's here.nrrd", -0.5, "/tmp/o");
    EXPECT_EQ(c.shell, "tool '/d/it'\\''s here.nrrd' --iso -0.5 -o '/tmp/o.ply'");
    EXPECT_EQ(c.output, fs::path("/tmp/o.ply"));
    const ExternalCommand obj =
        expand_command("tool {in} {out}.obj && echo {out}.obj", "a.nrrd", 80, "/tmp/o");
    EXPECT_EQ(obj.shell, "tool 'a.nrrd' '/tmp/o'.obj && echo '/tmp/o'.obj");
    EXPECT_EQ(obj.output, fs::path("/tmp/o.obj"));
    EXPECT_EQ(expand_command("t {in} {out}.offset", "a", 0, "o").output, fs::path("o.ply"));
    EXPECT_THROW((void)expand_command("tool {out}", "a", 0, "o"), Error);
    EXPECT_THROW((void)expand_command("tool {in}", "a", 0, "o"), Error);
}

TEST(Dataset, BrokenManifestLinesAreNamed)
{
    const fs::path dir = test::temp_dir();
    const std::string header = "file\tiso\teuler\tb0\tb1\tb2\tboundary_loops\tsubcase\n";
    const std::string good = "cells/cell-000001.nrrd\t0\t1\t1\t0\t0\t1\t1\n";
    auto error_of = [&](const std::string& text) -> std::string {
        test::write_file(dir / "manifest.tsv", text);
        try {
            (void)read_manifest(dir);
        } catch (const Error& e) {
            EXPECT_EQ(e.status(), Status::bad_format) << e.what();
            return e.what();
        }
        return "no error";
    };
    const std::string where = (dir / "manifest.tsv").string();
    EXPECT_NE(error_of(header + good + "cells/cell-000002.nrrd\t0\t1\t1\n")
                  .find(where + ":3: expected 8 tab-separated columns"),
              std::string::npos);
    EXPECT_NE(error_of(header + good + good + "grids/g.nrrd\t0\tone\t1\t0\t0\t1\t-\n")
                  .find(where + ":4: euler \"one\""),
              std::string::npos);
    EXPECT_NE(error_of(header + "x.nrrd\tnan\t1\t1\t0\t0\t1\t-\n").find(":2: iso \"nan\""),
              std::string::npos);
    EXPECT_NE(error_of(header + "x.nrrd\t0\t1\t1\t0\t0\t-1\t-\n").find(":2: boundary_loops \"-1\""),
              std::string::npos);
    EXPECT_NE(error_of(header + "x.nrrd\t0\t2\t1\t0\t0\t1\t-\n")
                  .find(":2: b0 - b1 + b2 = 1 differs from euler 2"),
              std::string::npos);
    EXPECT_NE(error_of(header + "x.nrrd\t0\t1\t1\t0\t0\t1\t13.7\n").find(":2: subcase \"13.7\""),
              std::string::npos);
    EXPECT_NE(error_of(header + "../x.nrrd\t0\t1\t1\t0\t0\t1\t-\n").find(":2: file \"../x.nrrd\""),
              std::string::npos);
    EXPECT_NE(error_of("file,iso\n" + good).find(":1: expected the header line"),
              std::string::npos);
    EXPECT_NE(error_of("").find("is empty"), std::string::npos);
    // Comments, blank lines and CRLF are fine.
    test::write_file(dir / "manifest.tsv", header + "# a comment\n\n" +
                                               "cells/cell-000001.nrrd\t0\t1\t1\t0\t0\t1\t1\r\n");
    ASSERT_EQ(read_manifest(dir).size(), 1u);
    EXPECT_EQ(read_manifest(dir)[0].line, 4);
    // verify_dataset: an empty list, and a listed file that is missing.
    test::write_file(dir / "manifest.tsv", header);
    EXPECT_THROW((void)verify_dataset(dir, DatasetVerifyOptions{}), Error);
    test::write_file(dir / "manifest.tsv", header + good);
    try {
        (void)verify_dataset(dir, DatasetVerifyOptions{});
        FAIL() << "missing file accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("cell-000001.nrrd"), std::string::npos) << e.what();
    }
}

} // namespace
} // namespace cmc33::cli
