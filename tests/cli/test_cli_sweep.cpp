// `cmc33 sweep`: its rows equal single `cmc33 extract --json` runs, for every method, its output
// has the documented shape, and its mistakes are one-line errors.

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "cmc33/io.hpp"
#include "cmc33/verify.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace cmc33 {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using test::cli::parse;
using test::cli::quote;
using test::cli::Result;
using test::cli::run;

const std::string kMethods = "cmc33,cmc33-paper,chernyaev,mc33-lewiner,mc";

/// The sweep of `volume` at `isos` with the five methods, compared row by row with extract --json.
void expect_rows_equal_extract(const std::string& volume, const std::string& isos, int expected_rows)
{
    const Result s = run("sweep " + quote(volume) + " --iso " + isos + " --methods " + kMethods + " --json --threads 2");
    ASSERT_EQ(s.code, 0) << s.err;
    const json j = parse(s);
    ASSERT_EQ(j["rows"].size(), static_cast<std::size_t>(expected_rows));
    for (const json& row : j["rows"]) {
        const std::string method = row["method"];
        const double iso = row["iso"];
        SCOPED_TRACE(method + " at " + std::to_string(iso));
        char iso_text[40];
        std::snprintf(iso_text, sizeof iso_text, "%.17g", iso);
        const Result e = run("extract " + quote(volume) + " --iso " + iso_text + " --method " + method + " --json --threads 1");
        ASSERT_EQ(e.code, 0) << e.err;
        const json x = parse(e);
        EXPECT_EQ(row["vertices"], x["vertices"]);
        EXPECT_EQ(row["triangles"], x["triangles"]);
        const json& t = x["topology"];
        EXPECT_EQ(row["euler"], t["euler"]);
        EXPECT_EQ(row["b0"], t["betti"][0]);
        EXPECT_EQ(row["b1"], t["betti"][1]);
        EXPECT_EQ(row["b2"], t["betti"][2]);
        EXPECT_EQ(row["boundary_loops"], t["boundary_loops"]);
        EXPECT_EQ(row["non_manifold_edges"], t["nonmanifold_edges"]);
        if (method == "cmc33") {
            // the field's topology, which cmc33's mesh has
            ASSERT_TRUE(row["expected"].is_object());
            EXPECT_EQ(row["expected"]["euler"], t["euler"]);
            EXPECT_EQ(row["expected"]["b0"], t["betti"][0]);
            EXPECT_EQ(row["expected"]["b1"], t["betti"][1]);
            EXPECT_EQ(row["expected"]["b2"], t["betti"][2]);
        } else {
            EXPECT_TRUE(row["expected"].is_null());
        }
    }
}

#ifdef CMC33_SWEEP_REAL_VOLUMES // test_cli_sweep_volumes, label slow (Release-speed)
TEST(CliSweepVolumes, RowsEqualSingleExtractionsOnAneurism)
{
    const auto path = test::shared_volume("aneurism_256x256x256_uint8.nrrd");
    if (!path) GTEST_SKIP() << "../shared/data/volumes is not beside the repository";
    // at 80 Chernyaev's tunnels meet in a face and cmc33-paper splits a slab
    expect_rows_equal_extract(path->string(), "79.5:80.5:0.5", 15);
}
#else

TEST(CliSweep, RowsEqualSingleExtractionsOnTheBundledVolume)
{
    expect_rows_equal_extract(std::string(CMC33_SOURCE_DIR) + "/data/Bucky_32x32x32_uint8.nrrd", "40:160:60", 15);
}

// A random 5x5x5 grid of the paper (verify's grid 26 of seed 1) where two tunnels share a face:
// the legacy methods' non-manifold edges and cmc33-paper's refinement are in the rows too.
TEST(CliSweep, RowsEqualSingleExtractionsWhereTunnelsShareAFace)
{
    const fs::path file = test::temp_dir() / "grid26.nrrd";
    io::write_volume(random_field(FieldKind::grid, 26, 1, 5), file);
    expect_rows_equal_extract(file.string(), "-0.1:0.1:0.05", 25);
    const json j = parse(run("sweep " + quote(file.string()) + " --iso 0:0:1 --methods chernyaev,cmc33-paper --json"));
    EXPECT_GT(j["rows"][0]["non_manifold_edges"].get<int>(), 0);
    EXPECT_EQ(j["rows"][1]["non_manifold_edges"], 0);
}


TEST(CliSweep, OutputShapeThreadsAndCsv)
{
    const std::string bucky = quote(std::string(CMC33_SOURCE_DIR) + "/data/Bucky_32x32x32_uint8.nrrd");
    const Result one = run("sweep " + bucky + " -i 90:110:10 --json --threads 1");
    ASSERT_EQ(one.code, 0) << one.err;
    const auto j = nlohmann::ordered_json::parse(one.out); // the keys in the order printed
    std::vector<std::string> keys;
    for (const auto& [k, v] : j.items()) keys.push_back(k);
    EXPECT_EQ(keys, (std::vector<std::string>{"volume", "dims", "type", "cells", "methods", "rows"}));
    EXPECT_EQ(j["dims"], nlohmann::ordered_json::array({32, 32, 32}));
    EXPECT_EQ(j["type"], "uint8");
    EXPECT_EQ(j["cells"], 31 * 31 * 31);
    EXPECT_EQ(j["methods"], nlohmann::ordered_json::array({"cmc33", "chernyaev", "mc33-lewiner", "mc"}));
    ASSERT_EQ(j["rows"].size(), 12u);
    std::vector<std::string> row_keys;
    for (const auto& [k, v] : j["rows"][0].items()) row_keys.push_back(k);
    EXPECT_EQ(row_keys, (std::vector<std::string>{"iso", "method", "vertices", "triangles", "euler", "b0", "b1", "b2",
                                                  "boundary_loops", "non_manifold_edges", "expected"}));
    EXPECT_EQ(j["rows"][4]["iso"], 100.0);
    EXPECT_EQ(j["rows"][4]["method"], "cmc33");
    // the same for any number of threads
    EXPECT_EQ(run("sweep " + bucky + " -i 90:110:10 --json --threads 3").out, one.out);
    // decimal steps give the decimal isovalues
    const json d = parse(run("sweep " + bucky + " -i 100:100.3:0.1 --methods mc --json --no-expected"));
    ASSERT_EQ(d["rows"].size(), 4u);
    EXPECT_EQ(d["rows"][3]["iso"], 100.3);
    const Result csv = run("sweep " + bucky + " -i 100:100:1 --methods cmc33,mc --csv");
    ASSERT_EQ(csv.code, 0) << csv.err;
    EXPECT_EQ(csv.out.substr(0, csv.out.find('\n')),
              "iso,method,vertices,triangles,euler,b0,b1,b2,boundary_loops,non_manifold_edges,expected_euler,"
              "expected_b0,expected_b1,expected_b2");
    EXPECT_NE(csv.out.find("\n100,mc,"), std::string::npos) << csv.out;
}

TEST(CliSweep, MistakesAreOneLineErrors)
{
    const std::string bucky = quote(std::string(CMC33_SOURCE_DIR) + "/data/Bucky_32x32x32_uint8.nrrd");
    for (const std::string bad : {"10:5:1", "10:20", "10:20:0", "a:20:1", "10:20:1:2", "0:1e9:1e-3"}) {
        const Result r = run("sweep " + bucky + " --iso " + bad);
        EXPECT_EQ(r.code, 2) << bad;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 2) << r.err; // the message and the --help hint
        EXPECT_NE(r.err.find("--iso " + bad), std::string::npos) << r.err;
    }
    EXPECT_EQ(run("sweep " + bucky + " -i 1:2:1 --json --csv").code, 2);
    EXPECT_EQ(run("sweep " + bucky + " -i 1:2:1 --methods marching").code, 2);
    EXPECT_EQ(run("sweep " + bucky + " -i 1:2:1 --methods mc,mc").code, 2);
    const Result missing = run("sweep /nonexistent.nrrd -i 1:2:1");
    EXPECT_EQ(missing.code, 1);
    EXPECT_NE(missing.err.find("/nonexistent.nrrd"), std::string::npos) << missing.err;
    EXPECT_EQ(run("sweep --help").code, 0);
    EXPECT_NE(run("sweep --help").out.find("Examples:"), std::string::npos);
}

#endif

} // namespace
} // namespace cmc33
