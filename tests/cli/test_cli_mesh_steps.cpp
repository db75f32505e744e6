// The steps after a mesh is made (cli/mesh_steps): `cmc33 simplify` on a mesh file, and the same
// options on `cmc33 extract`, which run them on the mesh it has just checked.

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <string>

#include "cmc33/io.hpp"
#include "cmc33/topology.hpp"
#include "cmc33/volume.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace cmc33 {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::cli::expect_usage_error;
using test::cli::parse;
using test::cli::quote;
using test::cli::Result;
using test::cli::run;

/// Gyroid-like sheets in a 24^3 box: tunnels, and a boundary on the box.
fs::path write_sheets(const fs::path& dir)
{
    const Volume v = test::make_volume({24, 24, 24}, [](std::int64_t i, std::int64_t j, std::int64_t k) {
        const double x = 0.45 * static_cast<double>(i), y = 0.45 * static_cast<double>(j), z = 0.45 * static_cast<double>(k);
        return std::sin(x) * std::cos(y) + std::sin(y) * std::cos(z) + std::sin(z) * std::cos(x);
    });
    const fs::path path = dir / "sheets.nrrd";
    io::write_volume(v, path);
    return path;
}

void expect_same(const json& a, const json& b, const std::string& what)
{
    for (const char* key : {"euler", "components", "closed_components", "boundary_loops", "nonmanifold_edges",
                            "nonmanifold_vertices"}) {
        EXPECT_EQ(a[key], b[key]) << what << ": " << key;
    }
}

TEST(CliMeshSteps, ExtractSimplifiesTheCheckedMeshAndWritesTheResult)
{
    const fs::path dir = test::temp_dir();
    const std::string volume = quote(write_sheets(dir).string());
    const fs::path out = dir / "small.ply";
    const Result r = run("extract " + volume + " -i 0.3 --normals --ratio 0.2 --smooth 3 --json -o " + quote(out.string()));
    ASSERT_EQ(r.code, 0) << r.err;
    const json j = parse(r);
    ASSERT_TRUE(j.contains("simplify")) << r.out;
    const json& s = j["simplify"];
    // the counts at the top are the extraction's, the file holds the result
    EXPECT_GT(j["triangles"].get<std::int64_t>(), 4 * s["triangles_out"].get<std::int64_t>());
    EXPECT_TRUE(s["topology_same"].get<bool>());
    expect_same(j["topology"], s["topology_after"], "extraction against result");
    EXPECT_GT(s["collapses"].get<std::int64_t>(), 0);
    EXPECT_EQ(s["smooth"]["iterations"], 3);
    EXPECT_TRUE(s["geometry_after"]["embedded"].get<bool>());
    EXPECT_GT(s["hausdorff"]["distance"].get<double>(), 0);
    const Mesh written = io::read_mesh(out);
    EXPECT_EQ(static_cast<std::int64_t>(written.triangle_count()), s["triangles_out"].get<std::int64_t>());
    EXPECT_TRUE(written.has_normals());
    // an independent look at the file: `cmc33 topo` finds the extraction's topology, embedded
    const Result t = run("topo " + quote(out.string()) + " --json");
    ASSERT_EQ(t.code, 0) << t.err;
    const json tj = parse(t);
    expect_same(j["topology"], tj, "extraction against the file");
    EXPECT_TRUE(tj["geometry"]["embedded"].get<bool>()) << t.out;

    // the summary line says what ran after the extraction
    const Result line = run("extract " + volume + " -i 0.3 --ratio 0.2");
    ASSERT_EQ(line.code, 0) << line.err;
    EXPECT_NE(line.out.find("; then "), std::string::npos) << line.out;
    EXPECT_NE(line.out.find("topology kept"), std::string::npos) << line.out;
}

TEST(CliMeshSteps, ExtractAndSimplifyAgreeOnTheSameMesh)
{
    // extract --ratio R is extract, then simplify --ratio R of the file: the same bytes
    const fs::path dir = test::temp_dir();
    const std::string volume = quote(write_sheets(dir).string());
    const fs::path full = dir / "full.ply", direct = dir / "direct.ply", after = dir / "after.ply";
    ASSERT_EQ(run("extract " + volume + " -i 0.3 -o " + quote(full.string())).code, 0);
    ASSERT_EQ(run("extract " + volume + " -i 0.3 --ratio 0.3 --largest -o " + quote(direct.string())).code, 0);
    const Result s = run("simplify " + quote(full.string()) + " --ratio 0.3 --largest --json -o " + quote(after.string()));
    ASSERT_EQ(s.code, 0) << s.err;
    EXPECT_EQ(test::read_file(direct), test::read_file(after));
    EXPECT_TRUE(parse(s)["topology_same"].get<bool>());
}

TEST(CliMeshSteps, CombinationsThatCannotWorkAreUsageErrors)
{
    const fs::path dir = test::temp_dir();
    const std::string volume = quote(write_sheets(dir).string());
    const std::string out = " -o " + quote((dir / "m.ply").string());
    // the steps start from the check's topology, and need the whole mesh
    expect_usage_error(run("extract " + volume + " -i 0.3 --ratio 0.5 --no-topology" + out));
    expect_usage_error(run("extract " + volume + " -i 0.3 --smooth 2 --memory-limit 64M" + out));
    expect_usage_error(run("extract " + volume + " -i 0.3 --ratio 0.5 --triangles 100" + out));
    expect_usage_error(run("extract " + volume + " -i 0.3 --max-distance 0.2" + out)); // bounds nothing
    expect_usage_error(run("extract " + volume + " -i 0.3 --ratio 0" + out));
    EXPECT_FALSE(fs::exists(dir / "m.ply"));
    const fs::path mesh = dir / "in.ply";
    ASSERT_EQ(run("extract " + volume + " -i 0.3 -o " + quote(mesh.string())).code, 0);
    expect_usage_error(run("simplify " + quote(mesh.string()) + out));               // nothing to do
    expect_usage_error(run("simplify " + quote(mesh.string()) + " --max-distance 0.2" + out));
    EXPECT_FALSE(fs::exists(dir / "m.ply"));
}

} // namespace
} // namespace cmc33
