// What a newcomer meets (issue #35, items 6 and 9): info's hints and bins inside the data at the
// precision it needs, malformed mesh faces reported as such on their line, messages without
// library names, usage conflicts as exit 2, counts in the right number, files named "-x", and
// the documentation's JSON order.

#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <regex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "cmc33/io.hpp"
#include "cmc33/volume.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace cmc33 {
namespace {

namespace fs = std::filesystem;
using ordered = nlohmann::ordered_json;
using nlohmann::json;
using test::cli::parse;
using test::cli::quote;
using test::cli::Result;
using test::cli::run;

/// Exit `code`, one line "cmc33: ..." (and the --help hint for usage errors) holding `text`.
void expect_message(const Result& r, int code, const std::string& text)
{
    EXPECT_EQ(r.code, code) << r.err;
    EXPECT_EQ(r.err.rfind("cmc33: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), code == 2 ? 2 : 1) << r.err;
    EXPECT_NE(r.err.find(text), std::string::npos) << "expected \"" << text << "\" in: " << r.err;
}

/// No "1 <plural>" anywhere in `text`: a count of one takes the singular.
void expect_singular_after_one(const std::string& text)
{
    static const std::regex wrong(R"((^|[^0-9.e+-])1 (samples|bytes|vertices|triangles|edges|faces|cells|grids|ties|)"
                                  R"(threads|fields|meshes|failures|positions|numbers|tie grids|closed grids|)"
                                  R"(coincident vertices|zero-area triangles|intersecting triangle pairs|vertex indices)\b)");
    std::smatch m;
    EXPECT_FALSE(std::regex_search(text, m, wrong)) << "\"" << m.str() << "\" in:\n" << text;
}

fs::path write_text(const fs::path& path, const std::string& text)
{
    test::write_file(path, text);
    return path;
}

// ---- info: hints and bins --------------------------------------------------------------------

struct RangeCase {
    const char* name;
    ScalarType type;
    std::function<double(std::int64_t)> value; ///< of sample n of 64
};

/// The histogram lines of `info`'s text: the two edges of each bin as printed.
std::vector<std::pair<std::string, std::string>> bin_edges(const std::string& out)
{
    std::vector<std::pair<std::string, std::string>> edges;
    static const std::regex line(R"(^  \[ *([^,]+), *([^)\]]+)[)\]])");
    std::istringstream in(out);
    for (std::string l; std::getline(in, l);) {
        std::smatch m;
        if (std::regex_search(l, m, line)) edges.emplace_back(m[1].str(), m[2].str());
    }
    return edges;
}

Volume volume_of(const RangeCase& c)
{
    Volume v(c.type, {4, 4, 4});
    dispatch_scalar_type(c.type, [&](auto tag) {
        using T = decltype(tag);
        for (std::int64_t n = 0; n < 64; ++n) v.samples<T>()[n] = static_cast<T>(c.value(n));
    });
    return v;
}

TEST(CliMessages, InfoHintsAndBinsStayInsideTheDataAtItsPrecision)
{
    const fs::path dir = test::temp_dir();
    const auto wave = [](std::int64_t n) { return static_cast<double>((n * 37) % 64) / 63.0; }; // 0..1, shuffled
    const std::vector<RangeCase> cases = {
        {"offset_float", ScalarType::f32, [&](std::int64_t n) { return 12345 + 3 * wave(n); }},
        {"narrow_double", ScalarType::f64, [&](std::int64_t n) { return 1000 + 0.009 * wave(n); }},
        {"far_narrow", ScalarType::f64, [&](std::int64_t n) { return 1e16 + 2.0 * static_cast<double>(n); }},
        {"tiny", ScalarType::f64, [&](std::int64_t n) { return 1e-30 * wave(n); }},
        {"negative", ScalarType::f32, [&](std::int64_t n) { return -300 - 0.06 * wave(n); }},
        {"negative_narrow", ScalarType::f64, [&](std::int64_t n) { return -5 - 1e-12 * wave(n); }},
        {"huge", ScalarType::f64, [&](std::int64_t n) { return n < 32 ? -1.7e308 : n == 40 ? 1.0 : 1.7e308; }},
        {"int16_offset", ScalarType::i16, [&](std::int64_t n) { return 12345 + n % 4; }},
        {"uint8_two_values", ScalarType::u8, [&](std::int64_t n) { return n == 5 ? 1 : 0; }},
        {"uint32_full", ScalarType::u32, [&](std::int64_t n) { return n % 2 ? 4294967295.0 : 0.0; }},
        {"int8_negative", ScalarType::i8, [&](std::int64_t n) { return -128 + n % 3; }},
    };
    for (const RangeCase& c : cases) {
        SCOPED_TRACE(c.name);
        const fs::path file = dir / (std::string(c.name) + ".nrrd");
        io::write_volume(volume_of(c), file);
        const Result jr = run("info " + quote(file.string()) + " --json");
        ASSERT_EQ(jr.code, 0) << jr.err;
        const json j = parse(jr);
        const double lo = j["min"].get<double>(), hi = j["max"].get<double>();
        ASSERT_LT(lo, hi);
        ASSERT_FALSE(j["candidate_isovalues"].empty());
        for (const json& cand : j["candidate_isovalues"]) {
            const double iso = cand["iso"].get<double>();
            EXPECT_GT(iso, lo) << cand; // a sample equal to iso counts as above: iso = min has no surface
            EXPECT_LE(iso, hi) << cand;
            if (c.type != ScalarType::f32 && c.type != ScalarType::f64) {
                EXPECT_EQ(iso, std::round(iso)) << cand;
            }
            // and an extraction there finds a surface
            const Result e = run("extract " + quote(file.string()) + " --iso " + cand["iso"].dump() + " --json --no-topology");
            ASSERT_EQ(e.code, 0) << e.err;
            EXPECT_GT(parse(e)["triangles"].get<std::int64_t>(), 0) << cand;
        }
        const Result r = run("info " + quote(file.string()));
        ASSERT_EQ(r.code, 0) << r.err;
        const auto edges = bin_edges(r.out);
        ASSERT_EQ(edges.size(), 16u) << r.out;
        for (std::size_t b = 0; b < edges.size(); ++b) {
            // each bin's edges, printed, tell it apart (not 16 bins "[1000, 1000)")
            EXPECT_NE(edges[b].first, edges[b].second) << "bin " << b << " of\n" << r.out;
        }
        // the hint's isovalues are the JSON's, printed in full
        for (const json& cand : j["candidate_isovalues"]) {
            const double iso = cand["iso"].get<double>();
            const std::regex hint(R"(--iso (\S+) )");
            bool found = false;
            for (auto it = std::sregex_iterator(r.out.begin(), r.out.end(), hint); it != std::sregex_iterator(); ++it) {
                found = found || std::strtod((*it)[1].str().c_str(), nullptr) == iso;
            }
            EXPECT_TRUE(found) << iso << " not in\n" << r.out;
        }
        // read slab by slab: the same text
        const Result slabs = run("info " + quote(file.string()) + " --memory-limit 1k");
        ASSERT_EQ(slabs.code, 0) << slabs.err;
        EXPECT_EQ(slabs.out, r.out);
    }
    // the quoted cases: no --iso 12350 for 12345..12348, and the narrow bins' first edge
    const Result offset = run("info " + quote((dir / "offset_float.nrrd").string()));
    EXPECT_EQ(offset.out.find("--iso 12350"), std::string::npos) << offset.out;
    const Result narrow = run("info " + quote((dir / "narrow_double.nrrd").string()));
    const auto narrow_edges = bin_edges(narrow.out);
    ASSERT_EQ(narrow_edges.size(), 16u) << narrow.out;
    EXPECT_EQ(narrow_edges[1], std::make_pair(std::string("1000.0006"), std::string("1000.0011"))) << narrow.out;
}

TEST(CliMessages, InfoOnEqualSamplesShowsOneBin)
{
    const fs::path dir = test::temp_dir();
    for (const ScalarType type : {ScalarType::f64, ScalarType::u16}) {
        Volume v(type, {3, 3, 3});
        dispatch_scalar_type(type, [&](auto tag) {
            using T = decltype(tag);
            std::fill(v.samples<T>(), v.samples<T>() + 27, static_cast<T>(1000.5));
        });
        const fs::path file = dir / "flat.nrrd";
        io::write_volume(v, file);
        const std::string value = type == ScalarType::f64 ? "1000.5" : "1000";
        const Result r = run("info " + quote(file.string()));
        ASSERT_EQ(r.code, 0) << r.err;
        EXPECT_NE(r.out.find("histogram: every finite sample is " + value + "\n"), std::string::npos) << r.out;
        const auto edges = bin_edges(r.out);
        ASSERT_EQ(edges.size(), 1u) << r.out;
        EXPECT_EQ(edges[0].first, value);
        EXPECT_EQ(edges[0].second, value);
        EXPECT_NE(r.out.find("no isosurface"), std::string::npos) << r.out;
        const json j = parse(run("info " + quote(file.string()) + " --json"));
        ASSERT_EQ(j["histogram"].size(), 1u) << j;
        EXPECT_EQ(j["histogram"][0]["count"], 27);
        EXPECT_EQ(j["histogram"][0]["lo"], j["histogram"][0]["hi"]);
        EXPECT_TRUE(j["candidate_isovalues"].empty());
    }
}

// ---- malformed faces --------------------------------------------------------------------------

const std::string kPlyHeader = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                               "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
const std::string kTriangle = "0 0 0\n1 0 0\n0 1 0\n";

TEST(CliMessages, FacesOfTooFewIndicesAreReportedOnTheirLine)
{
    const fs::path dir = test::temp_dir();
    struct Case {
        std::string file, text, message;
    };
    const std::vector<Case> cases = {
        {"two.off", "OFF\n3 1 0\n" + kTriangle + "2 0 1\n", "two.off: line 6: face 0 has 2 vertices; expected at least 3"},
        {"zero.off", "OFF\n3 1 0\n" + kTriangle + "0\n", "zero.off: line 6: face 0 has 0 vertices; expected at least 3"},
        {"one.off", "OFF\n# c\n3 1 0\n" + kTriangle + "1 2\n", "one.off: line 7: face 0 has 1 vertex; expected at least 3"},
        {"short.off", "OFF\n3 1 0\n" + kTriangle + "3 0 1\n", "short.off: line 6: face 0 lists 2 of its 3 vertex indices"},
        {"two.ply", kPlyHeader + kTriangle + "2 0 1\n", "two.ply: line 13: face 0 has 2 vertex indices; expected at least 3"},
        {"zero.ply", kPlyHeader + kTriangle + "0\n", "zero.ply: line 13: face 0 has 0 vertex indices; expected at least 3"},
        {"one.ply", kPlyHeader + kTriangle + "1 2\n", "one.ply: line 13: face 0 has 1 vertex index; expected at least 3"},
        {"two.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n", "two.obj: line 3: a face with 2 vertices; expected at least 3"},
        {"bare.obj", "v 0 0 0\n\nf\n", "bare.obj: line 3: a face with 0 vertices; expected at least 3"},
        {"early.obj", "v 0 0 0\nf 1 2 3\n", "early.obj: line 2: vertex index 2 but only 1 vertex is defined before this face"},
        // a file that is short indeed still says so
        {"cut.off", "OFF\n3 3 0\n" + kTriangle + "3 0 1 2\n", "cut.off: line 7: the file ends after 1 of 3 faces"},
    };
    for (const Case& c : cases) {
        const Result r = run("topo " + quote(write_text(dir / c.file, c.text).string()));
        expect_message(r, 1, c.message);
        EXPECT_EQ(r.err.find("bytes"), std::string::npos) << r.err; // not a size check
    }
    // a file too short for its counts says so, its counts in the right number
    expect_message(run("topo " + quote(write_text(dir / "empty.off", "OFF\n1 1 0\n").string())), 1,
                   "empty.off: line 3: the counts declare 1 vertex and 1 face (at least 8 bytes) but only 0 bytes follow");
    // binary PLY: the face with two indices is named
    std::string ply = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                      "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n";
    const float xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    ply.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
    const auto add_face = [&](std::vector<std::int32_t> ids) {
        ply += static_cast<char>(ids.size());
        ply.append(reinterpret_cast<const char*>(ids.data()), ids.size() * sizeof(std::int32_t));
    };
    add_face({0, 1, 2});
    add_face({0, 1});
    expect_message(run("topo " + quote(write_text(dir / "binary.ply", ply).string())), 1,
                   "binary.ply: face 1 has 2 vertex indices; expected at least 3");
}

// ---- messages ---------------------------------------------------------------------------------

TEST(CliMessages, TopoNamesTheWayAroundAGeometryItCannotCheck)
{
    const fs::path mesh = write_text(test::temp_dir() / "nan.ply", kPlyHeader + "0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n");
    const Result r = run("topo " + quote(mesh.string()));
    expect_message(r, 1, "nan.ply: cannot check the mesh in space: vertex 1 has a coordinate that is not a finite number");
    EXPECT_NE(r.err.find("--no-geometry"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("mesh_geometry"), std::string::npos) << r.err;
    const Result topology = run("topo " + quote(mesh.string()) + " --no-geometry");
    ASSERT_EQ(topology.code, 0) << topology.err;
    EXPECT_NE(topology.out.find("3 vertices, 3 edges, 1 face\n"), std::string::npos) << topology.out;
}

TEST(CliMessages, VtkLookupTableInAnyCaseIsNotSamples)
{
    const fs::path dir = test::temp_dir();
    for (const std::string keyword : {"LOOKUP_TABLE", "lookup_table", "Lookup_Table"}) {
        const fs::path file =
            write_text(dir / "lut.vtk", "# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 2\n"
                                        "SPACING 1 1 1\nORIGIN 0 0 0\nPOINT_DATA 8\nSCALARS v float 1\n" +
                                            keyword + " default\n0 1 2 3 4 5 6 7\n");
        const Result r = run("info " + quote(file.string()) + " --json");
        ASSERT_EQ(r.code, 0) << keyword << ": " << r.err;
        const json j = parse(r);
        EXPECT_EQ(j["min"], 0) << keyword;
        EXPECT_EQ(j["max"], 7) << keyword;
    }
}

TEST(CliMessages, VerifyCommandTemplateMayHoldAComment)
{
    const fs::path dir = test::temp_dir();
    const fs::path data = dir / "data";
    const Result made = run("dataset " + quote(data.string()) + " --cells 3 --grids 1 --closed 0 --ties 0 --threads 1");
    ASSERT_EQ(made.code, 0) << made.err;
    const std::string command = std::string(CMC33_EXE) + " extract {in} --iso {iso} -o {out} --quiet # cmc33 itself";
    const Result r = run("verify --dataset " + quote(data.string()) + " --cmd " + quote(command) + " --quiet --json");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    const json j = parse(r);
    ASSERT_EQ(j["methods"].size(), 1u) << j;
    EXPECT_EQ(j["methods"][0]["matched"], 4) << j;
    EXPECT_EQ(j["methods"][0]["errors"], 0) << j;
}

TEST(CliMessages, PaperMethodSlabByslabIsAUsageConflict)
{
    const fs::path dir = test::temp_dir();
    io::write_volume(test::make_volume({4, 4, 4}, [](auto i, auto j, auto k) { return static_cast<double>(i + j + k); }),
                     dir / "v.nrrd");
    const Result r = run("extract " + quote((dir / "v.nrrd").string()) + " --iso 4.5 --method cmc33-paper --memory-limit 1M -o " +
                         quote((dir / "m.ply").string()));
    expect_message(r, 2, "--method cmc33-paper does not combine with --memory-limit");
    EXPECT_EQ(r.err.find("extract()"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "m.ply"));
    // the other methods still work slab by slab
    EXPECT_EQ(run("extract " + quote((dir / "v.nrrd").string()) + " --iso 4.5 --method chernyaev --memory-limit 1M").code, 0);
}

TEST(CliMessages, CountsOfOneAreSingular)
{
    const fs::path dir = test::temp_dir();
    // one corner above: one triangle
    io::write_volume(test::make_volume({2, 2, 2}, [](auto i, auto j, auto k) { return i + j + k == 0 ? 1.0 : 0.0; }),
                     dir / "corner.nrrd");
    const Result e = run("extract " + quote((dir / "corner.nrrd").string()) + " --iso 0.5 -o " + quote((dir / "t.ply").string()));
    ASSERT_EQ(e.code, 0) << e.err;
    EXPECT_NE(e.out.find(": 3 vertices, 1 triangle in "), std::string::npos) << e.out;
    expect_singular_after_one(e.out);
    const Result t = run("topo " + quote((dir / "t.ply").string()));
    ASSERT_EQ(t.code, 0) << t.err;
    EXPECT_NE(t.out.find("3 vertices, 3 edges, 1 face\n"), std::string::npos) << t.out;
    expect_singular_after_one(t.out);
    const Result v = run("verify --cells 1 --grids 1 --threads 1 --quiet");
    ASSERT_EQ(v.code, 0) << v.err;
    EXPECT_NE(v.out.find(" 1 cell ("), std::string::npos) << v.out;
    EXPECT_NE(v.out.find(" 1 thread, "), std::string::npos) << v.out;
    expect_singular_after_one(v.out);
    const Result d = run("dataset " + quote((dir / "d").string()) + " --cells 1 --grids 1 --closed 0 --ties 1 --threads 1");
    ASSERT_EQ(d.code, 0) << d.err;
    EXPECT_NE(d.out.find("wrote 1 cell, 1 grid, 0 closed grids and 1 tie grid to "), std::string::npos) << d.out;
    expect_singular_after_one(d.out);
    // the readers' messages too
    expect_message(run("topo " + quote(write_text(dir / "v.off", "OFF\n1 0 0\n0      \n").string())), 1,
                   "vertex 0 has 1 number; expected 3");
    // one NaN sample, in memory and slab by slab
    io::write_volume(test::make_volume({3, 3, 3}, [](auto i, auto j, auto k) {
                         return i == 1 && j == 2 && k == 0 ? std::numeric_limits<double>::quiet_NaN() : 0.0;
                     }),
                     dir / "nan.nrrd");
    for (const char* limit : {"", " --memory-limit 64M"}) {
        const Result n = run("extract " + quote((dir / "nan.nrrd").string()) + " --iso 0.5" + limit);
        EXPECT_EQ(n.code, 1);
        EXPECT_NE(n.err.find("1 sample is NaN or infinite, the first at (1, 2, 0)"), std::string::npos) << limit << n.err;
        expect_singular_after_one(n.err);
    }
    // and the check itself catches what it is for
    EXPECT_NONFATAL_FAILURE(expect_singular_after_one("a.raw: 2x2x2 (1 samples, 8 bytes)"), "1 samples");
}

TEST(CliMessages, FileNamedLikeAnOption)
{
    const fs::path dir = test::temp_dir();
    io::write_volume(test::make_volume({3, 3, 3}, [](auto i, auto, auto) { return static_cast<double>(i); }), dir / "-x.nrrd");
    const std::string cd = "cd " + quote(dir.string()) + " && ";
    const Result bare = run("info -x.nrrd", cd);
    expect_message(bare, 2, "-x.nrrd is not an option of cmc33 info; if it is a file, put it after \"--\"");
    EXPECT_EQ(bare.err.find("INPUT is required"), std::string::npos) << bare.err;
    const Result dashes = run("info --json -- -x.nrrd", cd);
    ASSERT_EQ(dashes.code, 0) << dashes.err;
    EXPECT_EQ(parse(dashes)["max"], 2);
    EXPECT_EQ(run("info ./-x.nrrd", cd).code, 0);
    expect_message(run("extract -x.nrrd --iso 0.5", cd), 2, "-x.nrrd is not an option of cmc33 extract");
    expect_message(run("topo -m.ply"), 2, "-m.ply is not an option of cmc33 topo");
    // options, negative numbers and values are not taken for files
    expect_message(run("info a.nrrd --jsn"), 2, "--jsn is not an option of cmc33 info");
    EXPECT_EQ(run("cell -0.5 -1 1 1 1 1 1 -1e3 --json").code, 0);
    EXPECT_EQ(run("info --json -- " + quote((dir / "-x.nrrd").string())).code, 0);
}

TEST(CliMessages, ReadmeLibraryExampleNamesABadNumber)
{
    const std::string volume = (fs::path(CMC33_SOURCE_DIR) / "data" / "Bucky_32x32x32_uint8.nrrd").string();
    const std::string out = (test::temp_dir() / "m.ply").string();
    // the example is not cmc33 (which run() starts): through the shell directly
    for (const std::string iso : {"abc", "12abc", ""}) {
        const std::string err_file = (test::temp_dir() / "err").string();
        const std::string command = quote(CMC33_EXAMPLE) + " " + quote(volume) + " " + quote(iso) + " " + quote(out) + " 2>" + quote(err_file);
        const int status = std::system(command.c_str());
        ASSERT_TRUE(WIFEXITED(status));
        EXPECT_EQ(WEXITSTATUS(status), 2) << iso;
        const std::string err = test::read_file(err_file);
        EXPECT_EQ(err, "ISO \"" + iso + "\" is not a number\n");
    }
}

/// The keys of the first table after `heading` in docs/cli.md whose rows start "| `key`".
std::vector<std::string> documented_keys(const std::string& heading)
{
    std::ifstream in(fs::path(CMC33_SOURCE_DIR) / "docs" / "cli.md");
    std::vector<std::string> keys;
    bool seen = false, table = false;
    static const std::regex key(R"(`([a-z_]+)`)");
    for (std::string line; std::getline(in, line);) {
        if (!seen) {
            seen = line.rfind(heading, 0) == 0;
            continue;
        }
        if (line.rfind("| key |", 0) == 0) {
            table = true;
            continue;
        }
        if (!table) continue;
        if (line.rfind("|", 0) != 0) break;
        const std::string first = line.substr(0, line.find('|', 1));
        for (auto it = std::sregex_iterator(first.begin(), first.end(), key); it != std::sregex_iterator(); ++it) {
            keys.push_back((*it)[1].str());
        }
    }
    return keys;
}

TEST(CliMessages, ExtractJsonKeysInTheDocumentedOrder)
{
    const std::vector<std::string> documented = documented_keys("## `cmc33 extract`");
    ASSERT_GE(documented.size(), 10u);
    const Result r = run("extract " + quote((fs::path(CMC33_SOURCE_DIR) / "data" / "Bucky_32x32x32_uint8.nrrd").string()) +
                         " --iso 100 --json");
    ASSERT_EQ(r.code, 0) << r.err;
    const ordered j = ordered::parse(r.out);
    std::vector<std::string> printed;
    for (auto it = j.begin(); it != j.end(); ++it) printed.push_back(it.key());
    // the documented keys first, in the table's order (keys a mode adds come after them)
    ASSERT_GE(printed.size(), documented.size());
    EXPECT_EQ(std::vector<std::string>(printed.begin(), printed.begin() + static_cast<std::ptrdiff_t>(documented.size())),
              documented);
    std::vector<std::string> input_keys;
    for (auto it = j["input"].begin(); it != j["input"].end(); ++it) input_keys.push_back(it.key());
    EXPECT_EQ(input_keys, (std::vector<std::string>{"file", "dims", "type", "spacing", "origin", "direction", "mirrored", "space"}));
}

TEST(CliMessages, ConventionsNameTheMethodsThatAreEmbedded)
{
    std::ifstream in(fs::path(CMC33_SOURCE_DIR) / "docs" / "conventions.md");
    std::stringstream text;
    text << in.rdbuf();
    const std::string doc = text.str();
    EXPECT_EQ(doc.find("every method, the mesh is embedded"), std::string::npos);
    const std::string claim = "`cmc33`, `cmc33-paper` and `mc`, the mesh is embedded";
    ASSERT_NE(doc.find(claim), std::string::npos);
    // those three: never a mesh that is not embedded
    const Result r = run("verify --method cmc33,cmc33-paper,mc --cells 3000 --grids 300 --quiet --json");
    ASSERT_EQ(r.code == 0 || r.code == 1, true) << r.err; // mc mismatches topologically, by design
    const json report = parse(r); // kept: a range-for over a member of a temporary reads freed memory
    ASSERT_TRUE(report.contains("methods")) << r.out;
    for (const json& m : report["methods"]) EXPECT_EQ(m["not_embedded"], 0) << m["method"];
}

} // namespace
} // namespace cmc33
