// `cmc33 extract --memory-limit` and `cmc33 info --memory-limit` (the real executable, CMC33_EXE):
// the same file, the same numbers and the same messages as without the limit, for every format,
// method and limit; usage errors for what cannot stream; nothing left behind on failure.

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "cmc33/io.hpp"
#include "cmc33/volume.hpp"
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

/// The keys that do not depend on time, threads or the limit.
void expect_same_json(const json& a, const json& b, const std::string& what)
{
    for (const char* key : {"input", "iso", "method", "normals", "vertices", "triangles", "output", "topology", "subcases"}) {
        EXPECT_EQ(a[key], b[key]) << what << ": " << key;
    }
    json ga = a["geometry"], gb = b["geometry"];
    if (gb.is_object() && gb["welded"].is_null()) ga.erase("welded"), gb.erase("welded");
    EXPECT_EQ(ga, gb) << what << ": geometry";
}

fs::path bucky() { return fs::path(CMC33_SOURCE_DIR) / "data" / "Bucky_32x32x32_uint8.nrrd"; }

Volume noise_f32(Index3 dims, std::uint64_t seed)
{
    Volume v(ScalarType::f32, dims, {0.5, 1, 1.5}, {2, 3, -1});
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> u(-1, 1);
    float* p = v.samples<float>();
    for (std::int64_t i = 0; i < v.sample_count(); ++i) p[i] = u(rng);
    return v;
}

TEST(CliSlabs, ExtractWritesTheSameFileForEveryFormatMethodAndLimit)
{
    const fs::path dir = test::temp_dir();
    const Volume noise = noise_f32({23, 19, 31}, 4);
    struct Case {
        fs::path input;
        std::string iso, raw;
    };
    std::vector<Case> cases{{bucky(), "100", ""}};
    for (const char* name : {"noise.nrrd", "noise.mha", "noise.vtk", "noise.nhdr"}) {
        io::write_volume(noise, dir / name);
        cases.push_back({dir / name, "0.05", ""});
    }
    io::write_volume(noise, dir / "noise.raw");
    cases.push_back({dir / "noise.raw", "-0.1", " --dims 23 19 31 --type float"});
    if (const auto ct = test::shared_volume("CThead_256x256x113_uint16.nrrd")) {
        cases.push_back({*ct, "650", " --no-topology"}); // gzip, big-endian; its topology costs minutes under ASan
    }
    for (const Case& c : cases) {
        const bool bucky_case = c.input == bucky();
        // every method and two limits on Bucky; the formats with cmc33 and one limit (time under the sanitizers)
        for (const char* method : {"cmc33", "mc33-lewiner", "mc"}) {
            if (!bucky_case && std::string(method) != "cmc33") continue;
            const std::string common = quote(c.input.string()) + c.raw + " -i " + c.iso + " --method " + method + " --normals --json";
            const Result whole = run("extract " + common + " -o " + quote((dir / "whole.ply").string()));
            ASSERT_EQ(whole.code, 0) << whole.err;
            for (const char* limit : {"6M", "64M"}) {
                if (!bucky_case && std::string(limit) != "6M") continue;
                const std::string what = c.input.filename().string() + " " + method + " " + limit;
                const Result slabs = run("extract " + common + " -o " + quote((dir / "slabs.ply").string()) +
                                         " --memory-limit " + limit + " --threads 2");
                ASSERT_EQ(slabs.code, 0) << what << ": " << slabs.err;
                EXPECT_TRUE(test::read_file(dir / "whole.ply") == test::read_file(dir / "slabs.ply")) << what;
                json a = parse(whole), b = parse(slabs);
                a["output"] = b["output"] = nullptr;
                expect_same_json(a, b, what);
                EXPECT_GE(b["slabs"].get<int>(), 1) << what;
            }
        }
    }
    // the summary line is the same but for the time
    const auto line = [](std::string s) { return s.substr(0, s.find(" in ")) + s.substr(s.find(" s;")); };
    const Result a = run("extract " + quote(bucky().string()) + " -i 100.5");
    const Result b = run("extract " + quote(bucky().string()) + " -i 100.5 --memory-limit 1M");
    ASSERT_EQ(a.code, 0);
    ASSERT_EQ(b.code, 0) << b.err;
    EXPECT_EQ(line(a.out), line(b.out));
    // an empty mesh says so on stderr, slab by slab as in memory (exit 0: it is a valid result)
    const Result empty = run("extract " + quote(bucky().string()) + " -i 1000 --memory-limit 1M");
    ASSERT_EQ(empty.code, 0) << empty.err;
    EXPECT_NE(empty.err.find("the mesh is empty: no cell has samples on both sides of the isovalue 1000"), std::string::npos)
        << empty.err;
    EXPECT_EQ(b.err.find("the mesh is empty"), std::string::npos) << b.err;
}

TEST(CliSlabs, WhatCannotStreamIsAUsageError)
{
    const fs::path dir = test::temp_dir();
    const std::string in = quote(bucky().string()) + " -i 100 --memory-limit 8M ";
    for (const std::string& extra : {"-o " + quote((dir / "m.obj").string()), "-o " + quote((dir / "m.ply").string()) + " --ascii",
                                     std::string("--repeat 2")}) {
        const Result r = run("extract " + in + extra);
        EXPECT_EQ(r.code, 2) << extra << ": " << r.err;
        EXPECT_NE(r.err.find("--memory-limit"), std::string::npos) << r.err;
    }
    for (const char* size : {"12X", "0", "-1M", "1.5G"}) {
        const Result r = run("extract " + quote(bucky().string()) + " -i 100 --memory-limit " + size);
        EXPECT_EQ(r.code, 2) << size << ": " << r.err;
        const Result i = run("info " + quote(bucky().string()) + " --memory-limit " + size);
        EXPECT_EQ(i.code, 2) << size << ": " << i.err;
    }
    EXPECT_TRUE(fs::is_empty(dir));
}

TEST(CliSlabs, FailuresAreOneLineNamingTheFileAndLeaveNothing)
{
    const fs::path dir = test::temp_dir();
    // too small for one plane
    const Result small = run("extract " + quote(bucky().string()) + " -i 100 --memory-limit 4k -o " + quote((dir / "m.ply").string()));
    EXPECT_EQ(small.code, 1);
    EXPECT_NE(small.err.find("Bucky_32x32x32_uint8.nrrd: --memory-limit 4096 bytes is too small"), std::string::npos) << small.err;
    // a compressed stream cut short: the same message as without the limit
    std::string cut = "NRRD0004\ntype: float\ndimension: 3\nsizes: 23 19 31\nendian: little\nencoding: gzip\n\n";
    const Volume noise = noise_f32({23, 19, 31}, 5);
    const std::string gz = test::gzip_bytes(std::string(reinterpret_cast<const char*>(noise.bytes()), noise.byte_size()));
    test::write_file(dir / "cut.nrrd", cut + gz.substr(0, gz.size() * 2 / 3));
    const Result whole = run("extract " + quote((dir / "cut.nrrd").string()) + " -i 0 -o " + quote((dir / "m.ply").string()));
    const Result slabs = run("extract " + quote((dir / "cut.nrrd").string()) + " -i 0 --memory-limit 1M -o " +
                             quote((dir / "m.ply").string()));
    EXPECT_EQ(whole.code, 1);
    EXPECT_EQ(slabs.code, 1);
    EXPECT_EQ(slabs.err, whole.err);
    EXPECT_EQ(std::count(slabs.err.begin(), slabs.err.end(), '\n'), 1) << slabs.err;
    // non-finite samples (away from the surface: cells that need no decision): counted over all slabs
    Volume v = test::make_volume({8, 7, 30}, [](auto i, auto j, auto k) { return static_cast<double>(i + j + k) - 10; });
    double* d = v.samples<double>();
    d[3 + 8 * (2 + 7 * 14)] = std::numeric_limits<double>::quiet_NaN();
    d[5 + 8 * (6 + 7 * 25)] = -std::numeric_limits<double>::infinity();
    io::write_volume(v, dir / "nan.nrrd");
    const Result a = run("extract " + quote((dir / "nan.nrrd").string()) + " -i 0.5");
    const Result b = run("extract " + quote((dir / "nan.nrrd").string()) + " -i 0.5 --memory-limit 600k");
    EXPECT_EQ(a.code, 1);
    EXPECT_NE(a.err.find("2 samples are NaN or infinite, the first at (3, 2, 14)"), std::string::npos) << a.err;
    EXPECT_EQ(b.err, a.err);
    std::vector<std::string> left;
    for (const auto& e : fs::directory_iterator(dir)) left.push_back(e.path().filename().string());
    std::sort(left.begin(), left.end());
    EXPECT_EQ(left, (std::vector<std::string>{"cut.nrrd", "nan.nrrd"}));
}

TEST(CliSlabs, InfoPrintsTheSameSlabBySlab)
{
    const fs::path dir = test::temp_dir();
    Volume v = noise_f32({31, 17, 40}, 6);
    v.samples<float>()[100] = std::numeric_limits<float>::quiet_NaN();
    io::write_volume(v, dir / "f.nrrd");
    Volume s(ScalarType::i16, {30, 20, 25});
    std::mt19937_64 rng(1);
    std::uniform_int_distribution<int> u(-3000, 2000);
    for (std::int64_t i = 0; i < s.sample_count(); ++i) s.samples<std::int16_t>()[i] = static_cast<std::int16_t>(u(rng));
    io::write_volume(s, dir / "s.mha");
    std::vector<fs::path> inputs{dir / "f.nrrd", dir / "s.mha", bucky()};
    if (const auto ct = test::shared_volume("CThead_256x256x113_uint16.nrrd")) inputs.push_back(*ct);
    for (const fs::path& in : inputs) {
        for (const char* json_flag : {"", " --json"}) {
            const Result a = run("info " + quote(in.string()) + json_flag);
            const Result b = run("info " + quote(in.string()) + json_flag + " --memory-limit 64k");
            ASSERT_EQ(a.code, 0) << a.err;
            EXPECT_EQ(b.code, 0) << b.err;
            EXPECT_EQ(a.out, b.out) << in;
        }
    }
}

} // namespace
} // namespace cmc33
