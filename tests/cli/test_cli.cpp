// Runs the real `cmc33` executable (CMC33_EXE) and checks its output, files and exit codes.

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "cmc33/extract.hpp"
#include "cmc33/io.hpp"
#include "cmc33/version.hpp"
#include "cmc33/volume.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace cmc33 {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using test::cli::parse;
using test::cli::quote;
using test::cli::expect_usage_error;
using test::cli::files_in;
using test::cli::Result;
using test::cli::run;

/// One line naming `name` (test::cli::expect_failure).
void expect_failure(const Result& r, const std::string& name) { test::cli::expect_failure(r, {name}); }

/// One line containing `part` (test::cli::expect_usage_error).
void expect_usage_error(const Result& r, const std::string& part) { test::cli::expect_usage_error(r, {part}); }

// The sphere |x - c| = 6.2 as the level set f = -3.8 of f = |x - c| - 10: a negative isovalue, on a
// 20^3 grid, centre off the samples so that no sample equals the isovalue.
constexpr const char* kIso = "-3.8";

double sphere_field(std::int64_t i, std::int64_t j, std::int64_t k)
{
    const double x = static_cast<double>(i) - 9.5, y = static_cast<double>(j) - 9.3, z = static_cast<double>(k) - 9.1;
    return std::sqrt(x * x + y * y + z * z) - 10;
}

Volume sphere_volume() { return test::make_volume({20, 20, 20}, sphere_field); }

fs::path write_sphere(const fs::path& dir, const std::string& name = "sphere.nrrd")
{
    const fs::path path = dir / name;
    io::write_volume(sphere_volume(), path);
    return path;
}

// ---- conventions ------------------------------------------------------------------------------

TEST(Cli, VersionAndHelp)
{
    const Result v = run("--version");
    EXPECT_EQ(v.code, 0);
    EXPECT_EQ(v.out, "cmc33 " CMC33_VERSION_STRING "\n");

    const Result h = run("--help");
    EXPECT_EQ(h.code, 0);
    for (const char* command : {"extract", "info", "topo", "cell"}) {
        EXPECT_NE(h.out.find(command), std::string::npos) << command;
        const Result c = run(std::string(command) + " --help");
        EXPECT_EQ(c.code, 0) << command;
        EXPECT_NE(c.out.find("Example"), std::string::npos) << command << ":\n" << c.out;
        EXPECT_NE(c.out.find("cmc33 " + std::string(command) + " "), std::string::npos) << command;
    }
}

TEST(Cli, UsageErrorsExitTwo)
{
    const fs::path dir = test::temp_dir();
    const std::string sphere = quote(write_sphere(dir).string());
    expect_usage_error(run(""));
    expect_usage_error(run("frobnicate"));
    expect_usage_error(run("--frobnicate"));
    expect_usage_error(run("extract " + sphere + " --iso 1 --frobnicate"));
    expect_usage_error(run("extract " + sphere));                        // --iso missing
    expect_usage_error(run("extract --iso 1"));                          // INPUT missing
    expect_usage_error(run("extract " + sphere + " --iso"));             // value missing
    expect_usage_error(run("extract " + sphere + " --iso abc"));         // not a number
    expect_usage_error(run("extract " + sphere + " --iso 1 --method marching"));
    expect_usage_error(run("extract " + sphere + " --iso 1 --threads -1"));
    expect_usage_error(run("extract " + sphere + " --iso 1 --repeat 0"));
    expect_usage_error(run("extract " + sphere + " --iso 1 --dims 20 20 20 --type double"));
    expect_usage_error(run("extract " + sphere + " --iso 1 -o " + quote((dir / "m.obj").string()) + " --ascii"));
    expect_usage_error(run("cell 1 2 3 4 5 6 7"));
    expect_usage_error(run("cell 1 2 3 4 5 6 7 8 9"));
    expect_usage_error(run("cell 1 2 3 4 5 6 7 x"));
    expect_usage_error(run("cell 1 2 3 4 5 6 7 8 --method marching"));
    expect_usage_error(run("topo"));
    EXPECT_FALSE(fs::exists(dir / "m.obj"));
}

// ---- extract ----------------------------------------------------------------------------------

TEST(Cli, ExtractEveryMeshFormatAndTopoAgrees)
{
    const fs::path dir = test::temp_dir();
    const std::string sphere = quote(write_sphere(dir).string());
    for (const std::string name : {"m.ply", "m.obj", "m.stl", "m.off", "ascii.ply"}) {
        SCOPED_TRACE(name);
        const fs::path out = dir / name;
        const Result e = run("extract " + sphere + " -i " + kIso + " -o " + quote(out.string()) + " --json" +
                             (name == "ascii.ply" ? " --ascii" : ""));
        ASSERT_EQ(e.code, 0) << e.err;
        EXPECT_EQ(e.err, "");
        ASSERT_TRUE(fs::exists(out));
        const json ej = parse(e);
        EXPECT_EQ(ej["output"], out.string());

        const Result t = run("topo " + quote(out.string()) + " --json");
        ASSERT_EQ(t.code, 0) << t.err;
        const json tj = parse(t);
        EXPECT_EQ(tj["vertices"], ej["vertices"]);
        EXPECT_EQ(tj["faces"], ej["triangles"]);
        EXPECT_EQ(tj["euler"], 2);
        EXPECT_EQ(tj["betti"], json({1, 0, 1}));
        EXPECT_EQ(tj["edges"].get<std::int64_t>(), ej["vertices"].get<std::int64_t>() + ej["triangles"].get<std::int64_t>() - 2);
        for (const char* key : {"euler", "betti", "components", "boundary_edges", "boundary_loops", "nonmanifold_edges",
                                "nonmanifold_vertices", "closed", "oriented"}) {
            EXPECT_EQ(tj[key], ej["topology"][key]) << key;
        }

        const Result text = run("topo " + quote(out.string()));
        ASSERT_EQ(text.code, 0) << text.err;
        EXPECT_NE(text.out.find(std::to_string(ej["vertices"].get<int>()) + " vertices"), std::string::npos) << text.out;
        EXPECT_NE(text.out.find("euler 2"), std::string::npos) << text.out;
    }
    EXPECT_NE(test::read_file(dir / "ascii.ply").find("format ascii"), std::string::npos);
}

TEST(Cli, ExtractJsonHasEveryKey)
{
    const fs::path dir = test::temp_dir();
    const fs::path sphere = write_sphere(dir);
    const Result r = run("extract " + quote(sphere.string()) + " --iso " + kIso + " --json --threads 2");
    ASSERT_EQ(r.code, 0) << r.err;
    const json j = parse(r);
    ASSERT_TRUE(j.is_object());
    EXPECT_EQ(j["input"]["file"], sphere.string());
    EXPECT_EQ(j["input"]["dims"], json({20, 20, 20}));
    EXPECT_EQ(j["input"]["type"], "double");
    EXPECT_EQ(j["input"]["spacing"], json({1, 1, 1}));
    EXPECT_EQ(j["input"]["origin"], json({0, 0, 0}));
    EXPECT_DOUBLE_EQ(j["iso"].get<double>(), -3.8);
    EXPECT_EQ(j["method"], "cmc33");
    EXPECT_GT(j["vertices"].get<int>(), 100);
    EXPECT_GT(j["triangles"].get<int>(), 200);
    // a closed triangulated sphere: F = 2V - 4
    EXPECT_EQ(j["triangles"].get<int>(), 2 * j["vertices"].get<int>() - 4);
    EXPECT_GE(j["seconds"].get<double>(), 0.0);
    ASSERT_EQ(j["runs_seconds"].size(), 1u);
    EXPECT_EQ(j["runs_seconds"][0], j["seconds"]);
    EXPECT_EQ(j["threads"], 2);
    EXPECT_TRUE(j["output"].is_null());
    const json& t = j["topology"];
    EXPECT_EQ(t["euler"], 2);
    EXPECT_EQ(t["betti"], json({1, 0, 1}));
    EXPECT_EQ(t["components"], 1);
    EXPECT_EQ(t["boundary_edges"], 0);
    EXPECT_EQ(t["boundary_loops"], 0);
    EXPECT_EQ(t["nonmanifold_edges"], 0);
    EXPECT_EQ(t["nonmanifold_vertices"], 0);
    EXPECT_EQ(t["closed"], true);
    EXPECT_EQ(t["oriented"], true);
    const json& s = j["subcases"];
    ASSERT_TRUE(s.is_object());
    // Every subcase but "0": extract counts the cells the surface crosses, and no such cell is
    // of subcase 0 (all corners on one side).
    EXPECT_EQ(s.size(), static_cast<std::size_t>(kSubcaseCount - 1));
    EXPECT_FALSE(s.contains("0"));
    std::int64_t cells = 0;
    for (int i = 1; i < kSubcaseCount; ++i) {
        const std::string name(subcase_name(i));
        ASSERT_TRUE(s.contains(name)) << name;
        cells += s[name].get<std::int64_t>();
    }
    EXPECT_GT(cells, 0);
    EXPECT_GT(s["1"].get<std::int64_t>() + s["2"].get<std::int64_t>() + s["5"].get<std::int64_t>(), 0);
}

TEST(Cli, ExtractSummaryLineAndRepeat)
{
    const fs::path dir = test::temp_dir();
    const std::string sphere = quote(write_sphere(dir).string());
    const Result r = run("extract " + sphere + " -i " + kIso + " -o " + quote((dir / "s.ply").string()));
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
    for (const char* part : {"sphere.nrrd: 20x20x20 double", "iso -3.8", "cmc33: ", " vertices, ", " triangles in ",
                             "euler 2", "components 1", "boundary edges 0", "non-manifold edges 0", "s.ply)"}) {
        EXPECT_NE(r.out.find(part), std::string::npos) << part << " not in " << r.out;
    }

    const Result rep = run("extract " + sphere + " -i " + kIso + " --repeat 3 --json --method mc33-lewiner");
    ASSERT_EQ(rep.code, 0) << rep.err;
    const json j = parse(rep);
    ASSERT_EQ(j["runs_seconds"].size(), 3u);
    std::vector<double> runs = j["runs_seconds"].get<std::vector<double>>();
    std::sort(runs.begin(), runs.end());
    EXPECT_DOUBLE_EQ(j["seconds"].get<double>(), runs[1]);
    EXPECT_EQ(j["method"], "mc33-lewiner");
}

/// A double as the command line prints it (the shortest text that reads back the same)
std::string num_text(double value)
{
    char text[64];
    return std::string(text, std::to_chars(text, text + sizeof text, value).ptr);
}

TEST(Cli, ExtractEmptyMeshSaysWhy)
{
    // An isovalue on the wrong scale gives an empty mesh: still written and reported (exit 0), with
    // a note on stderr naming the samples' range, so that it is not mistaken for a flat result.
    const fs::path dir = test::temp_dir();
    const std::string sphere = quote(write_sphere(dir).string());
    const Result out = run("extract " + sphere + " -i 100 --json -o " + quote((dir / "e.ply").string()));
    ASSERT_EQ(out.code, 0) << out.err;
    EXPECT_EQ(parse(out)["triangles"].get<std::int64_t>(), 0);
    EXPECT_TRUE(fs::exists(dir / "e.ply"));
    const auto [lo, hi] = cmc33::value_range(sphere_volume());
    EXPECT_NE(out.err.find("cmc33: note: "), std::string::npos) << out.err;
    EXPECT_NE(out.err.find("the mesh is empty: the isovalue 100 is outside the samples' range [" + num_text(lo) + ", " +
                           num_text(hi) + "]"),
              std::string::npos)
        << out.err;
    // at the smallest sample every sample counts as above: inside the range, and still empty
    const Result at_min = run("extract " + sphere + " -i " + num_text(lo));
    ASSERT_EQ(at_min.code, 0) << at_min.err;
    EXPECT_NE(at_min.err.find("no cell has samples on both sides of the isovalue " + num_text(lo)), std::string::npos)
        << at_min.err;
    const Result full = run("extract " + sphere + " -i " + kIso);
    ASSERT_EQ(full.code, 0) << full.err;
    EXPECT_EQ(full.err.find("the mesh is empty"), std::string::npos) << full.err;
}

TEST(Cli, ExtractNoTopology)
{
    const fs::path dir = test::temp_dir();
    const std::string sphere = quote(write_sphere(dir).string());
    const Result r = run("extract " + sphere + " -i " + kIso + " --no-topology --json");
    ASSERT_EQ(r.code, 0) << r.err;
    const json j = parse(r);
    EXPECT_TRUE(j["topology"].is_null());
    EXPECT_GT(j["triangles"].get<std::int64_t>(), 0);
    const Result line = run("extract " + sphere + " -i " + kIso + " --no-topology");
    ASSERT_EQ(line.code, 0) << line.err;
    EXPECT_EQ(line.out.find("euler"), std::string::npos) << line.out;
}

TEST(Cli, ExtractProgressOnlyWhenAskedOrOnATerminal)
{
    const fs::path dir = test::temp_dir();
    const std::string sphere = quote(write_sphere(dir).string());
    const Result plain = run("extract " + sphere + " -i " + kIso); // stderr is not a terminal here
    ASSERT_EQ(plain.code, 0) << plain.err;
    EXPECT_EQ(plain.err, "");
    const Result forced = run("extract " + sphere + " -i " + kIso + " --progress");
    ASSERT_EQ(forced.code, 0) << forced.err;
    EXPECT_EQ(forced.out.substr(0, forced.out.find(" in ")), plain.out.substr(0, plain.out.find(" in "))) << forced.out;
    EXPECT_EQ(std::count(forced.out.begin(), forced.out.end(), '\n'), 1) << forced.out; // just the summary line
    EXPECT_EQ(forced.err.rfind("extracting the mesh: ", 0), 0u) << forced.err;
    EXPECT_NE(forced.err.find("extracting the mesh: 100%, "), std::string::npos) << forced.err;
    const Result quiet = run("extract " + sphere + " -i " + kIso + " --quiet");
    ASSERT_EQ(quiet.code, 0) << quiet.err;
    EXPECT_EQ(quiet.err, "");
    expect_usage_error(run("extract " + sphere + " -i " + kIso + " --quiet --progress"), "excludes");
}

TEST(Cli, ExtractHeaderlessRaw)
{
    const fs::path dir = test::temp_dir();
    const json from_nrrd = parse(run("extract " + quote(write_sphere(dir).string()) + " -i " + kIso + " --json"));
    const fs::path raw = write_sphere(dir, "sphere.raw");
    const Result r = run("extract " + quote(raw.string()) + " -i " + kIso +
                         " --dims 20 20 20 --type double --spacing 1 1 1 --endian little --header-bytes 0 --json");
    ASSERT_EQ(r.code, 0) << r.err;
    const json j = parse(r);
    EXPECT_EQ(j["vertices"], from_nrrd["vertices"]);
    EXPECT_EQ(j["triangles"], from_nrrd["triangles"]);
    EXPECT_EQ(j["input"]["type"], "double");
    expect_usage_error(run("extract " + quote(raw.string()) + " -i 1"));              // no --dims/--type
    expect_usage_error(run("extract " + quote(raw.string()) + " -i 1 --dims 20 20 20")); // no --type
    // the raw file is too short for these dimensions
    expect_failure(run("extract " + quote(raw.string()) + " -i 1 --dims 40 40 40 --type double"), "sphere.raw");
}

TEST(Cli, ExtractFailuresExitOneNamingTheFile)
{
    const fs::path dir = test::temp_dir();
    const fs::path sphere = write_sphere(dir);

    const fs::path missing = dir / "missing.nrrd";
    expect_failure(run("extract " + quote(missing.string()) + " -i 1"), "missing.nrrd");

    const std::string whole = test::read_file(sphere);
    const fs::path truncated = dir / "truncated.nrrd";
    test::write_file(truncated, whole.substr(0, whole.size() - 100));
    expect_failure(run("extract " + quote(truncated.string()) + " -i " + kIso), "truncated.nrrd");

    Volume nan_volume(ScalarType::f32, {4, 4, 4});
    nan_volume.samples<float>()[21] = std::numeric_limits<float>::quiet_NaN();
    const fs::path nan_file = dir / "nan.nrrd";
    io::write_volume(nan_volume, nan_file);
    expect_failure(run("extract " + quote(nan_file.string()) + " -i 0.5"), "nan.nrrd");

    expect_failure(run("extract " + quote(sphere.string()) + " --iso nan"), "sphere.nrrd");
    expect_failure(run("extract " + quote(sphere.string()) + " --iso inf"), "sphere.nrrd");

    // The output is checked before the input is even read: the message is about the output.
    const Result bad_ext = run("extract " + quote(missing.string()) + " -i 1 -o " + quote((dir / "mesh.xyz").string()));
    expect_failure(bad_ext, "mesh.xyz");
    EXPECT_NE(bad_ext.err.find(".ply"), std::string::npos) << bad_ext.err;

    const fs::path no_dir = dir / "no" / "such" / "dir" / "mesh.ply";
    expect_failure(run("extract " + quote(sphere.string()) + " -i " + kIso + " -o " + quote(no_dir.string())), "mesh.ply");
    EXPECT_FALSE(fs::exists(dir / "no"));

    // The target is a directory: nothing is written, nothing is left behind.
    fs::create_directory(dir / "taken.ply");
    const std::vector<std::string> before = files_in(dir);
    expect_failure(run("extract " + quote(sphere.string()) + " -i " + kIso + " -o " + quote((dir / "taken.ply").string())),
                   "taken.ply");
    EXPECT_EQ(files_in(dir), before);
    EXPECT_TRUE(fs::is_empty(dir / "taken.ply"));

    expect_failure(run("topo " + quote((dir / "missing.ply").string())), "missing.ply");
    expect_failure(run("topo " + quote(sphere.string())), "sphere.nrrd"); // not a mesh extension
    expect_failure(run("info " + quote(truncated.string())), "truncated.nrrd");
}

// ---- info -------------------------------------------------------------------------------------

TEST(Cli, InfoPrintsDimsRangeAndHistogram)
{
    const fs::path dir = test::temp_dir();
    const fs::path sphere = write_sphere(dir);
    const auto [lo, hi] = value_range(sphere_volume());

    const Result r = run("info " + quote(sphere.string()));
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("20x20x20 double"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("values "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("--iso "), std::string::npos) << r.out;

    const Result jr = run("info " + quote(sphere.string()) + " --json");
    ASSERT_EQ(jr.code, 0) << jr.err;
    const json j = parse(jr);
    EXPECT_EQ(j["dims"], json({20, 20, 20}));
    EXPECT_EQ(j["type"], "double");
    EXPECT_DOUBLE_EQ(j["min"].get<double>(), lo);
    EXPECT_DOUBLE_EQ(j["max"].get<double>(), hi);
    EXPECT_EQ(j["non_finite"]["count"], 0);
    ASSERT_EQ(j["histogram"].size(), 16u);
    std::int64_t total = 0;
    for (const json& bin : j["histogram"]) total += bin["count"].get<std::int64_t>();
    EXPECT_EQ(total, 8000);
    EXPECT_DOUBLE_EQ(j["histogram"][0]["lo"].get<double>(), lo);
    EXPECT_DOUBLE_EQ(j["histogram"][15]["hi"].get<double>(), hi);
    ASSERT_FALSE(j["candidate_isovalues"].empty());
    for (const json& c : j["candidate_isovalues"]) {
        EXPECT_GT(c["iso"].get<double>(), lo);
        EXPECT_LT(c["iso"].get<double>(), hi);
    }

    // NaN samples are counted, not refused
    Volume v(ScalarType::f32, {3, 3, 3});
    v.samples<float>()[5] = std::numeric_limits<float>::infinity();
    v.samples<float>()[7] = 2.5f;
    io::write_volume(v, dir / "inf.nrrd");
    const Result bad = run("info " + quote((dir / "inf.nrrd").string()) + " --json");
    ASSERT_EQ(bad.code, 0) << bad.err;
    const json bj = parse(bad);
    EXPECT_EQ(bj["non_finite"]["count"], 1);
    EXPECT_EQ(bj["non_finite"]["first"], json({2, 1, 0}));
    EXPECT_EQ(bj["max"], 2.5);
}

// ---- cell -------------------------------------------------------------------------------------

TEST(Cli, CellOneCorner)
{
    const Result r = run("cell 1 0 0 0 0 0 0 0 --iso 0.5 --json");
    ASSERT_EQ(r.code, 0) << r.err;
    const json j = parse(r);
    EXPECT_EQ(j["config"], 1);
    EXPECT_EQ(j["base_case"], 1);
    EXPECT_EQ(j["subcase"], "1");
    ASSERT_EQ(j["mesh"]["triangles"].size(), 1u);
    ASSERT_EQ(j["mesh"]["vertices"].size(), 3u);
    EXPECT_EQ(j["mesh"]["vertices"][0], json({0.5, 0, 0}));
    EXPECT_EQ(j["topology"]["euler"], 1);
    EXPECT_EQ(j["topology"]["components"], 1);
    EXPECT_EQ(j["topology"]["boundary_loops"], 1);
    ASSERT_EQ(j["faces"].size(), 6u);
    for (const json& f : j["faces"]) {
        for (const char* key : {"ambiguous", "saddle", "joined", "used"}) EXPECT_TRUE(f.contains(key)) << key;
        EXPECT_EQ(f["ambiguous"], false);
    }
    EXPECT_EQ(j["interior"]["tested"], false);

    const Result text = run("cell 1 0 0 0 0 0 0 0 -i 0.5");
    ASSERT_EQ(text.code, 0) << text.err;
    EXPECT_NE(text.out.find("subcase 1\n"), std::string::npos) << text.out;
    EXPECT_NE(text.out.find("1 triangle "), std::string::npos) << text.out;
}

TEST(Cli, CellNegativeValuesAndInteriorTest)
{
    // case 13 (corners 1 2 4 7 above): every face ambiguous, the 13.5 interior test runs
    for (const std::string values : {"-0.5 0.2 0.3 -0.4 0.6 -0.1 -0.7 0.8", "-.5 .2 .3 -.4 .6 -.1 -.7 .8"}) {
        SCOPED_TRACE(values);
        const Result r = run("cell " + values + " --json");
        ASSERT_EQ(r.code, 0) << r.err;
        const json j = parse(r);
        EXPECT_EQ(j["config"], 2 + 4 + 16 + 128);
        EXPECT_EQ(j["base_case"], 13);
        EXPECT_EQ(j["values"][0], -0.5);
        for (const json& f : j["faces"]) {
            EXPECT_EQ(f["ambiguous"], true);
            EXPECT_EQ(f["used"], true);
            EXPECT_TRUE(f["saddle"].is_number());
        }
        const json& in = j["interior"];
        for (const char* key : {"tested", "test", "axis", "corner_a", "corner_c", "a", "b", "c", "t1", "t2", "t_max",
                                "f_t_max", "lewiner_axis", "lewiner_corner", "lewiner_edge", "t_alt", "f_t_alt",
                                "saddle1", "saddle2", "skipped", "tunnel", "tunnel_corner"}) {
            EXPECT_TRUE(in.contains(key)) << key;
        }
        EXPECT_EQ(in["tested"], true);
        EXPECT_EQ(in["test"], "13.5");
        EXPECT_EQ(in["corner_c"].get<int>(), in["corner_a"].get<int>() ^ 7);
        EXPECT_GT(j["mesh"]["triangles"].size(), 0u);
        for (const char* key : {"euler", "betti", "boundary_loops", "components"}) {
            EXPECT_TRUE(j["topology"].contains(key)) << key;
        }
    }
    // options may come first; values may then follow
    const Result first = run("cell --iso -0.25 --method mc -0.5 1 1 1 1 1 1 1");
    ASSERT_EQ(first.code, 0) << first.err;
    EXPECT_NE(first.out.find("method mc, iso -0.25"), std::string::npos) << first.out;
    expect_failure(run("cell 1 1 1 1 1 1 1 nan"), "corner 7");
}

TEST(Cli, CellWritesItsMesh)
{
    const fs::path dir = test::temp_dir();
    const fs::path out = dir / "cell.off";
    const Result r = run("cell 1 1 0 0 0 0 0 0 --iso 0.5 -o " + quote(out.string())); // case 2
    ASSERT_EQ(r.code, 0) << r.err;
    ASSERT_TRUE(fs::exists(out));
    const json t = parse(run("topo " + quote(out.string()) + " --json"));
    EXPECT_EQ(t["vertices"], 4);
    EXPECT_EQ(t["faces"], 2);
    EXPECT_EQ(t["components"], 1);
    EXPECT_EQ(t["boundary_loops"], 1);
}

// ---- shared volumes ---------------------------------------------------------------------------

void expect_manifold_mc(const std::string& file, const std::string& iso)
{
    const auto path = test::shared_volume(file);
    if (!path) GTEST_SKIP() << file << " not found (../shared absent)";
    const Result r = run("extract " + quote(path->string()) + " --iso " + iso + " --method mc --json");
    ASSERT_EQ(r.code, 0) << r.err;
    const json j = parse(r);
    EXPECT_GT(j["triangles"].get<std::int64_t>(), 10000);
    EXPECT_EQ(j["topology"]["nonmanifold_edges"], 0);
    EXPECT_EQ(j["topology"]["nonmanifold_vertices"], 0);
    EXPECT_EQ(j["input"]["dims"], json({256, 256, 256}));
}

TEST(CliShared, AneurismMcIsManifold) { expect_manifold_mc("aneurism_256x256x256_uint8.nrrd", "80"); }
TEST(CliShared, BonsaiMcIsManifold) { expect_manifold_mc("bonsai_256x256x256_uint8.nrrd", "40"); }

// ---- reliability (issue 9): usage errors that used to pass --------------------------------------

TEST(CliReliability, BadNumbersAndNamesAreUsageErrorsBeforeAnyWork)
{
    const fs::path dir = test::temp_dir();
    const std::string sphere = quote(write_sphere(dir).string());
    const std::string out = quote((dir / "m.ply").string());
    // An empty or partial number was read as 0 or as its prefix (an unset shell variable).
    expect_usage_error(run("extract " + sphere + " --iso ''"), "--iso: expected a number, got an empty value");
    expect_usage_error(run("extract " + sphere + " --iso 12abc"), "got '12abc'");
    expect_usage_error(run("extract " + sphere + " --iso 0x10"), "got '0x10'");
    expect_usage_error(run("cell 1 0 0 0 0 0 0 '' --iso 0.5"), "expected a number");
    expect_usage_error(run("cell 1 0 0 0 0 0 0 0 --iso 1.5x"), "got '1.5x'");
    // -o "" exited 0 and wrote nothing.
    expect_usage_error(run("extract " + sphere + " --iso " + kIso + " -o ''"), "--output: expected a mesh file name");
    expect_usage_error(run("cell 1 0 0 0 0 0 0 0 -o ''"), "--output");
    // Negative values read as 64-bit garbage, or accepted.
    expect_usage_error(run("extract " + sphere + " --iso 1 --dims 20 20 20 --type double --header-bytes -1"),
                       "--header-bytes: expected a whole number >= 0, got '-1'");
    expect_usage_error(run("verify --cells 5 --seed -1"), "--seed: expected a whole number >= 0, got '-1'");
    expect_usage_error(run("verify --cells -5"), "--cells: expected a whole number >= 0, got '-5'");
    expect_usage_error(run("verify --cells 5 --max-failures -1"), "--max-failures");
    expect_usage_error(run("dataset " + quote((dir / "d").string()) + " --seed -1"), "--seed");
    expect_usage_error(run("dataset " + quote((dir / "d").string()) + " --grids 1.5"), "--grids");
    // Thread counts that the OS refuses midway are refused at once.
    expect_usage_error(run("verify --cells 5 --threads 100000"), "--threads: expected a whole number from 0 to 1024");
    expect_usage_error(run("dataset " + quote((dir / "d").string()) + " --threads 100000"), "from 0 to 1024");
    expect_usage_error(run("extract " + sphere + " --iso 1 --threads 1025"), "from 0 to 1024");
    EXPECT_FALSE(fs::exists(dir / "d"));
    // Normals that OFF and STL cannot hold were dropped silently.
    for (const char* name : {"m.stl", "m.off", "M.STL"}) {
        expect_usage_error(run("extract " + sphere + " --iso " + kIso + " --normals -o " + quote((dir / name).string())),
                           "OFF/STL cannot store normals; use .ply or .obj");
        EXPECT_FALSE(fs::exists(dir / name)) << name;
    }
    ASSERT_EQ(run("extract " + sphere + " --iso " + kIso + " --normals -o " + out).code, 0);
    // Other names that cannot be empty.
    expect_usage_error(run("dataset ''"), "OUT: expected a folder name");
    expect_usage_error(run("verify --dataset ''"), "--dataset");
    expect_usage_error(run("verify --cells 5 --failures ''"), "--failures");
    EXPECT_EQ(files_in(dir), (std::vector<std::string>{"m.ply", "sphere.nrrd"}));
}

TEST(CliReliability, UnwritableOutputFolderFailsBeforeReading)
{
    const fs::path dir = test::temp_dir();
    // The input does not even exist: the message is about the output folder, so it came first.
    const std::string missing = quote((dir / "missing.nrrd").string());
    const Result r = run("extract " + missing + " --iso 1 -o /proc/cmc33-mesh.ply");
    expect_failure(r, "/proc");
    EXPECT_NE(r.err.find("not writable"), std::string::npos) << r.err;
    if (::geteuid() != 0) { // root writes into a 0555 folder
        const fs::path locked = dir / "locked";
        fs::create_directory(locked);
        fs::permissions(locked, fs::perms::owner_read | fs::perms::owner_exec);
        const Result l = run("extract " + missing + " --iso 1 -o " + quote((locked / "m.ply").string()));
        fs::permissions(locked, fs::perms::owner_all);
        expect_failure(l, locked.string());
        EXPECT_TRUE(fs::is_empty(locked));
    }
}

// ---- reliability: data loss ------------------------------------------------------------------

TEST(CliReliability, ExtractNeverOverwritesItsInput)
{
    const fs::path dir = test::temp_dir();
    // A headerless raw volume may have any name, a mesh extension too.
    const std::string bytes = std::string(7, '\0') + std::string(1, '\xc8');
    test::write_file(dir / "v.ply", bytes);
    fs::create_symlink(dir / "v.ply", dir / "link.ply");
    fs::create_hard_link(dir / "v.ply", dir / "hard.obj");
    const std::string in = quote((dir / "v.ply").string()) + " --dims 2 2 2 --type uint8 --iso 100";
    for (const fs::path& out : {dir / "v.ply", dir / "." / "v.ply", dir / "link.ply", dir / "hard.obj"}) {
        SCOPED_TRACE(out.string());
        expect_usage_error(run("extract " + in + " -o " + quote(out.string())), "is the input");
        EXPECT_EQ(test::read_file(dir / "v.ply"), bytes);
    }
    EXPECT_TRUE(fs::is_symlink(dir / "link.ply"));
    EXPECT_EQ(files_in(dir), (std::vector<std::string>{"hard.obj", "link.ply", "v.ply"}));
    ASSERT_EQ(run("extract " + in + " -o " + quote((dir / "m.ply").string())).code, 0);
}

TEST(CliReliability, DatasetNeverWritesIntoAForeignFolder)
{
    const fs::path dir = test::temp_dir();
    const fs::path mine = dir / "mine";
    fs::create_directory(mine);
    test::write_file(mine / "README.txt", "my notes");
    const std::string counts = " --cells 20 --grids 3 --closed 2";
    // The current folder, named "." or (before) "": refused, the file untouched.
    for (const std::string out : {"mine", "."}) {
        SCOPED_TRACE(out);
        const Result r = run("dataset " + out + counts, out == "." ? "cd " + quote(mine.string()) + " && "
                                                                  : "cd " + quote(dir.string()) + " && ");
        expect_failure(r, out);
        EXPECT_NE(r.err.find("holds no dataset"), std::string::npos) << r.err;
        EXPECT_EQ(files_in(mine), std::vector<std::string>{"README.txt"});
        EXPECT_EQ(test::read_file(mine / "README.txt"), "my notes");
    }
    // A previous dataset is replaced; a file added to it makes it foreign.
    const fs::path ds = dir / "ds";
    ASSERT_EQ(run("dataset " + quote(ds.string()) + counts).code, 0);
    ASSERT_EQ(run("dataset " + quote(ds.string()) + " --cells 4 --grids 1 --closed 0").code, 0);
    EXPECT_EQ(files_in(ds), (std::vector<std::string>{"README.txt", "cells", "grids", "manifest.tsv"}));
    EXPECT_EQ(files_in(ds / "cells").size(), 4u);
    test::write_file(ds / "grids" / "mine.nrrd", "x");
    const Result again = run("dataset " + quote(ds.string()) + counts);
    expect_failure(again, "grids/mine.nrrd");
    EXPECT_TRUE(fs::exists(ds / "grids" / "mine.nrrd"));
    EXPECT_EQ(files_in(ds / "cells").size(), 4u);
}

TEST(CliReliability, DatasetThatFailsLateLeavesNothing)
{
    // ulimit -f 1 (512-byte blocks): the 2x2x2 cells fit, the first 5x5x5 grid does not; with
    // SIGXFSZ ignored its write fails with EFBIG, after the cells were written.
    const fs::path dir = test::temp_dir();
    const std::string limit = "ulimit -f 1 && trap '' XFSZ && ";
    const fs::path fresh = dir / "fresh";
    const Result r = run("dataset " + quote(fresh.string()) + " --cells 50 --grids 5 --closed 0 --threads 2", limit);
    expect_failure(r, "fresh");
    EXPECT_FALSE(fs::exists(fresh)); // made by the run, so removed with what it held
    const fs::path empty = dir / "empty";
    fs::create_directory(empty);
    expect_failure(run("dataset " + quote(empty.string()) + " --cells 50 --grids 5 --closed 0", limit), "empty");
    EXPECT_TRUE(fs::is_empty(empty)); // there before: kept, and empty again
}

// ---- reliability: small things -----------------------------------------------------------------

TEST(CliReliability, NoTopologyHelpAndAnEmptyMeshIsOriented)
{
    const Result help = run("extract --help");
    EXPECT_NE(help.out.find("--no-topology "), std::string::npos) << help.out;
    EXPECT_EQ(help.out.find("{false}"), std::string::npos) << help.out;
    const fs::path dir = test::temp_dir();
    const Result r = run("extract " + quote(write_sphere(dir).string()) + " --iso 1000 --json");
    ASSERT_EQ(r.code, 0) << r.err;
    const json j = parse(r);
    EXPECT_EQ(j["triangles"], 0);
    EXPECT_EQ(j["topology"]["oriented"], true);
    EXPECT_EQ(j["topology"]["closed"], false);
}

// ---- frames and extreme values (issue #9, items 1 and 3) -------------------------------------

TEST(CliFrames, InfoPrintsTheFrameAndExtractMirrorsTheWinding)
{
    const fs::path dir = test::temp_dir();
    Volume v = sphere_volume();
    v.set_spacing({1, 1, 3});
    v.set_direction(Mat3{{{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}}});
    v.set_space("left-posterior-superior");
    const fs::path lps = dir / "lps.nrrd";
    io::write_volume(v, lps);
    const Result r = run("info " + quote(lps.string()));
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("spacing (1, 1, 3)"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("space left-posterior-superior\n"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("directions (world direction of +i, +j, +k): i (-1, 0, 0) j (0, 1, 0) k (0, 0, 1)"),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("mirrored"), std::string::npos) << r.out;
    const json j = parse(run("info " + quote(lps.string()) + " --json"));
    EXPECT_EQ(j["direction"], json({{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}}));
    EXPECT_EQ(j["mirrored"], true);
    EXPECT_EQ(j["space"], "left-posterior-superior");
    // the identity frame prints no direction line
    const Result plain = run("info " + quote(write_sphere(dir).string()));
    EXPECT_EQ(plain.out.find("directions"), std::string::npos) << plain.out;

    // the mesh is in world coordinates (x <= 0), closed and oriented
    const fs::path mesh = dir / "lps.ply";
    const Result e = run("extract " + quote(lps.string()) + " -i " + kIso + " -o " + quote(mesh.string()) + " --json");
    ASSERT_EQ(e.code, 0) << e.err;
    const json ej = parse(e);
    EXPECT_EQ(ej["topology"]["oriented"], true);
    EXPECT_EQ(ej["topology"]["euler"], 2);
    const Mesh m = io::read_mesh(mesh);
    for (std::size_t i = 0; i < m.positions.size(); i += 3) ASSERT_LE(m.positions[i], 0.0f);
}

TEST(CliExtreme, DoublesSpanningTheWholeRange)
{
    const fs::path dir = test::temp_dir();
    // +-1e308 in an ambiguous pattern: differences overflow
    Volume v(ScalarType::f64, {4, 4, 4});
    for (std::int64_t i = 0; i < v.sample_count(); ++i) {
        v.samples<double>()[i] = ((i * 7 + i / 4 + i / 16) % 3 == 0 ? -1 : 1) * 1e308 * (1 + 0.01 * static_cast<double>(i % 5));
    }
    v.samples<double>()[0] = -std::numeric_limits<double>::max();
    v.samples<double>()[1] = std::numeric_limits<double>::max();
    const fs::path file = dir / "huge.nrrd";
    io::write_volume(v, file);

    const Result info = run("info " + quote(file.string()));
    ASSERT_EQ(info.code, 0) << info.err;
    EXPECT_EQ(info.out.find("nan"), std::string::npos) << info.out;
    EXPECT_EQ(info.out.find("inf"), std::string::npos) << info.out;
    const json ij = parse(run("info " + quote(file.string()) + " --json"));
    std::int64_t total = 0;
    for (const json& bin : ij["histogram"]) {
        total += bin["count"].get<std::int64_t>();
        EXPECT_TRUE(bin["lo"].is_number()) << bin;
    }
    EXPECT_EQ(total, 64);

    const fs::path mesh = dir / "huge.ply";
    const Result e = run("extract " + quote(file.string()) + " -i 0 --normals -o " + quote(mesh.string()));
    ASSERT_EQ(e.code, 0) << e.err;
    const Mesh m = io::read_mesh(mesh);
    ASSERT_GT(m.vertex_count(), 0u);
    for (std::size_t i = 0; i < m.vertex_count(); ++i) {
        const double n = std::hypot(double(m.normals[3 * i]), double(m.normals[3 * i + 1]), double(m.normals[3 * i + 2]));
        ASSERT_NEAR(n, 1.0, 1e-5) << "vertex " << i;
        // edge vertices (one coordinate off the grid) sit near the middle of their edges: the
        // values are of equal size and opposite signs, so no crossing is snapped to a corner
        int off_grid = 0;
        double frac = 0;
        for (std::size_t k = 0; k < 3; ++k) {
            const double x = static_cast<double>(m.positions[3 * i + k]), f = x - std::floor(x);
            if (f != 0) ++off_grid, frac = f;
        }
        if (off_grid == 1) {
            ASSERT_GT(std::min(frac, 1 - frac), 0.3) << "vertex " << i;
        }
    }

    // a face with every value near +-1e308: its saddle is printed, not -nan
    const Result cell = run("cell 1e308 -1e308 -1e308 1e308 -1.5e308 1.7e308 1.7e308 -1.5e308");
    ASSERT_EQ(cell.code, 0) << cell.err;
    EXPECT_EQ(cell.out.find("nan"), std::string::npos) << cell.out;
    EXPECT_NE(cell.out.find("ambiguous, saddle 0,"), std::string::npos) << cell.out;
    // and the interior test's numbers (case 13 at 1e308): roots and t_max, no NaN
    const Result tunnel = run("cell -0.5e308 0.2e308 0.3e308 -0.4e308 0.6e308 -0.1e308 -0.7e308 0.8e308");
    ASSERT_EQ(tunnel.code, 0) << tunnel.err;
    EXPECT_EQ(tunnel.out.find("nan"), std::string::npos) << tunnel.out;
    EXPECT_NE(tunnel.out.find("t_max = -b/2a = 0.3676471"), std::string::npos) << tunnel.out;
}

TEST(CliExtreme, CoordinatesBeyondFloatAreRefusedNamingTheFile)
{
    const fs::path dir = test::temp_dir();
    Volume v = sphere_volume();
    v.set_spacing({1e300, 1, 1});
    const fs::path file = dir / "wide.nrrd";
    io::write_volume(v, file);
    const fs::path mesh = dir / "wide.ply";
    const Result r = run("extract " + quote(file.string()) + " -i " + kIso + " -o " + quote(mesh.string()));
    expect_failure(r, "wide.nrrd");
    EXPECT_NE(r.err.find("32-bit floats"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(mesh));
}

} // namespace
} // namespace cmc33
