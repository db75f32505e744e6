// The slab engine (src/slabs/slabs.hpp) run as MPI ranks would run it, one range after another in
// one process: for every number of ranges, slab size and memory limit, the bytes written are
// write_mesh()'s bytes of extract()'s mesh, and the merged topology and geometry are
// mesh_topology() and mesh_geometry() of that mesh. Volumes: the bundled Bucky (ties at iso 100),
// noise with ties, a compressed big-endian NRRD, double samples near the range (normals' shared
// bound), mirrored and oblique frames; every method, with and without normals.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/io.hpp"
#include "cmc33/topology.hpp"
#include "mesh_formats.hpp"
#include "plane_reader.hpp"
#include "slabs.hpp"
#include "test_support.hpp"

namespace cmc33::slabs {
namespace {

class MemorySink final : public ByteSink {
public:
    explicit MemorySink(std::string& file) : file_(file) {}
    void write_at(std::uint64_t offset, std::span<const std::byte> bytes) override
    {
        ASSERT_LE(offset + bytes.size(), file_.size()) << "a write past the end of the file";
        std::memcpy(file_.data() + offset, bytes.data(), bytes.size());
        ++writes;
    }
    std::int64_t writes = 0;

private:
    std::string& file_;
};

struct Output {
    std::string file;
    MeshTopology topology;
    MeshGeometry geometry;
    bool welded_known = false;
    RangeTotals totals;
};

/// The volume at `path` extracted by `ranks` ranges, each with its own reader, as cmc33-mpi does.
Output run_ranges(const std::filesystem::path& path, double iso, const SlabOptions& options, int ranks)
{
    const io::detail::VolumeLayout layout = io::detail::describe_volume(path);
    const std::int64_t nz = layout.grid.dims[2];
    std::vector<std::unique_ptr<io::detail::PlaneReader>> readers;
    std::vector<std::unique_ptr<RangeRun>> runs;
    std::vector<RangeTotals> totals;
    Output out;
    for (int r = 0; r < ranks; ++r) {
        const auto planes = rank_planes(nz, r, ranks);
        readers.push_back(std::make_unique<io::detail::PlaneReader>(layout));
        runs.push_back(std::make_unique<RangeRun>(*readers.back(), iso, options, planes[0], planes[1]));
        totals.push_back(runs.back()->count());
        out.totals.vertices += totals.back().vertices;
        out.totals.triangles += totals.back().triangles;
        out.totals.sample_bound = std::max(out.totals.sample_bound, totals.back().sample_bound);
        out.totals.slabs += totals.back().slabs;
    }
    const PlyLayout ply(static_cast<std::uint64_t>(out.totals.vertices), static_cast<std::uint64_t>(out.totals.triangles),
                        options.extract.normals);
    out.file.assign(ply.file_bytes(), '\x55');
    std::memcpy(out.file.data(), ply.header().data(), ply.header_bytes);
    MemorySink sink(out.file);
    std::int64_t fv = 0, ft = 0;
    std::vector<detail::SeamTopology> topologies;
    GeometryPart geometry;
    for (int r = 0; r < ranks; ++r) {
        const std::int64_t before = sink.writes;
        const RangeResult result = runs[static_cast<std::size_t>(r)]->emit(fv, ft, out.totals.sample_bound, ply, &sink);
        const RangeTotals& t = totals[static_cast<std::size_t>(r)];
        EXPECT_EQ(sink.writes - before, write_count(t.vertices, t.triangles, options.extract.normals, piece_bytes(options.memory_limit)));
        topologies.push_back(result.topology);
        geometry.add(result.geometry);
        fv += t.vertices;
        ft += t.triangles;
    }
    // a binomial tree, as over MPI ranks
    for (std::size_t step = 1; step < topologies.size(); step *= 2)
        for (std::size_t i = 0; i + step < topologies.size(); i += 2 * step)
            topologies[i] = detail::SeamTopology::merge(topologies[i], topologies[i + step]);
    out.topology = topologies.front().finish();
    out.geometry = finish_geometry(geometry, out.topology, out.welded_known);
    return out;
}

/// write_mesh()'s bytes, mesh_topology() and mesh_geometry() of extract()'s mesh.
struct Expected {
    std::string file;
    MeshTopology topology;
    MeshGeometry geometry;
};

Expected expected_of(const std::filesystem::path& path, double iso, const ExtractOptions& options)
{
    const Volume v = io::read_volume(path);
    const Mesh m = extract(v, iso, options);
    std::ostringstream ply;
    io::detail::write_ply(m, ply, false); // what write_mesh() writes to a .ply
    return {ply.str(), mesh_topology(m), mesh_geometry(m, MeshGeometryOptions{1, GeometryPart::kExamples})};
}

void expect_same(const Output& got, const Expected& want, const std::string& what, bool analysed = true)
{
    EXPECT_TRUE(got.file == want.file) << what << ": " << got.file.size() << " bytes against " << want.file.size();
    if (!analysed) return;
    EXPECT_EQ(got.topology.euler, want.topology.euler) << what;
    EXPECT_EQ(got.topology.components, want.topology.components) << what;
    EXPECT_EQ(got.topology.closed_components, want.topology.closed_components) << what;
    EXPECT_EQ(got.topology.b1, want.topology.b1) << what;
    EXPECT_EQ(got.topology.boundary_edges, want.topology.boundary_edges) << what;
    EXPECT_EQ(got.topology.boundary_loops, want.topology.boundary_loops) << what;
    EXPECT_EQ(got.topology.nonmanifold_edges, want.topology.nonmanifold_edges) << what;
    EXPECT_EQ(got.topology.nonmanifold_vertices, want.topology.nonmanifold_vertices) << what;
    EXPECT_EQ(got.topology.oriented, want.topology.oriented) << what;
    EXPECT_EQ(got.geometry.positions, want.geometry.positions) << what;
    EXPECT_EQ(got.geometry.coincident_vertices, want.geometry.coincident_vertices) << what;
    EXPECT_EQ(got.geometry.zero_area_triangles, want.geometry.zero_area_triangles) << what;
    EXPECT_EQ(got.geometry.intersecting_pairs, want.geometry.intersecting_pairs) << what;
    EXPECT_EQ(got.geometry.intersection_examples, want.geometry.intersection_examples) << what;
    if (got.welded_known) {
        EXPECT_EQ(got.geometry.welded.euler, want.geometry.welded.euler) << what;
    }
}

std::filesystem::path bucky()
{
    return std::filesystem::path(CMC33_SOURCE_DIR) / "data" / "Bucky_32x32x32_uint8.nrrd";
}

/// The running test's folder, made empty once per test.
std::filesystem::path test_dir()
{
    static std::string test_name;
    static std::filesystem::path dir;
    const std::string current = testing::UnitTest::GetInstance()->current_test_info()->name();
    if (current != test_name) test_name = current, dir = test::temp_dir();
    return dir;
}

/// A volume written to the test's folder.
std::filesystem::path written(const Volume& v, const std::string& name)
{
    const auto path = test_dir() / name;
    io::write_volume(v, path);
    return path;
}

TEST(Slabs, EveryRankCountAndSlabSizeWritesExtractsBytes)
{
    std::mt19937_64 rng(3);
    std::uniform_int_distribution<int> few(0, 4);
    Volume ties = test::make_volume({14, 11, 17}, [&](auto, auto, auto) { return static_cast<double>(few(rng)); });
    struct Case {
        std::filesystem::path path;
        double iso;
    };
    const std::vector<Case> cases{{bucky(), 100}, {bucky(), 100.5}, {written(ties, "ties.nrrd"), 2}};
    for (const Case& c : cases) {
        for (const Method method : {Method::cmc33, Method::mc33_lewiner, Method::mc}) {
            for (const bool normals : {false, true}) {
                if (normals && method != Method::cmc33) continue; // time under the sanitizers
                ExtractOptions ex;
                ex.method = method;
                ex.normals = normals;
                ex.threads = 2;
                const Expected want = expected_of(c.path, c.iso, ex);
                // (ranks, planes per slab): one slab per rank, slabs of one plane, and between
                for (const auto& [ranks, planes] : {std::pair<int, std::int64_t>{1, 0}, {2, 1}, {3, 3}, {4, 0}, {7, 1}}) {
                    {
                        SlabOptions opt;
                        opt.extract = ex;
                        opt.max_slab_planes = planes;
                        // the topology and geometry where slabs are thin (the most seams)
                        opt.analyse = planes == 1;
                        const std::string what = c.path.filename().string() + " iso " + std::to_string(c.iso) + " " +
                                                 std::string(method_name(method)) + (normals ? " normals" : "") + ", " +
                                                 std::to_string(ranks) + " ranks, slabs of " + std::to_string(planes);
                        expect_same(run_ranges(c.path, c.iso, opt, ranks), want, what, opt.analyse);
                        if (testing::Test::HasFailure()) return;
                    }
                }
            }
        }
    }
}

TEST(Slabs, FramesCompressionAndTheDoubleRange)
{
    std::mt19937_64 rng(8);
    std::uniform_real_distribution<double> u(-1, 1);
    Volume oblique = test::make_volume({9, 8, 13}, [&](auto, auto, auto) { return u(rng); }, {0.5, 1, 2}, {3, -1, 2});
    const double c = std::cos(0.3), s = std::sin(0.3);
    oblique.set_direction({{{c, -s, 0}, {s, c, 0}, {0, 0, 1}}});
    Volume mirrored = test::make_volume({10, 7, 12}, [&](auto, auto, auto) { return u(rng); });
    mirrored.set_direction({{{1, 0, 0}, {0, -1, 0}, {0, 0, 1}}});
    // samples near the double range in the last planes: every range needs the shared bound
    Volume huge = test::make_volume({6, 5, 12}, [](std::int64_t i, std::int64_t j, std::int64_t k) {
        return k >= 9 ? ((i + j + k) % 2 ? 1.5e308 : -1.5e308)
                      : static_cast<double>((i * 7 + j * 3 + k * 5) % 11 - 5) * 1e-310 + 1e-311 * static_cast<double>(i);
    });
    struct Case {
        std::filesystem::path path;
        double iso;
    };
    std::vector<Case> cases{{written(oblique, "oblique.nrrd"), 0.1}, {written(mirrored, "mirrored.mha"), 0},
                            {written(huge, "huge.vtk"), 0}};
    // gzip, big-endian, with gzip members one after the other (each range inflates from the start)
    const auto gz = test_dir() / "gzip.nrrd";
    {
        Volume g = test::make_volume({11, 9, 14}, [&](auto, auto, auto) { return u(rng); });
        std::string big(g.byte_size(), '\0');
        for (std::size_t i = 0; i < big.size(); i += 8)
            for (std::size_t b = 0; b < 8; ++b) big[i + b] = reinterpret_cast<const char*>(g.bytes())[i + 7 - b];
        test::write_file(gz, "NRRD0004\ntype: double\ndimension: 3\nsizes: 11 9 14\nendian: big\nencoding: gzip\n\n" +
                                 test::gzip_bytes(big.substr(0, 300)) + test::gzip_bytes(big.substr(300)));
    }
    cases.push_back({gz, 0.05});
    for (const Case& k : cases) {
        ExtractOptions ex;
        ex.normals = true;
        ex.threads = 1;
        const Expected want = expected_of(k.path, k.iso, ex);
        for (const int ranks : {1, 2, 3, 5}) {
            SlabOptions opt;
            opt.extract = ex;
            opt.max_slab_planes = 4;
            expect_same(run_ranges(k.path, k.iso, opt, ranks), want, k.path.filename().string() + ", " + std::to_string(ranks) + " ranks");
            if (testing::Test::HasFailure()) return;
        }
    }
}

TEST(Slabs, MemoryLimitCutsSlabsByTheirMeshAndRefusesWhatCannotFit)
{
    // a sphere in large planes: slabs are cut by planes (samples) and by mesh size alike
    Volume sphere(ScalarType::u8, {120, 110, 40});
    std::uint8_t* p = sphere.samples<std::uint8_t>();
    for (std::int64_t k = 0; k < 40; ++k)
        for (std::int64_t j = 0; j < 110; ++j)
            for (std::int64_t i = 0; i < 120; ++i) {
                const double r = std::hypot(static_cast<double>(i) - 60, static_cast<double>(j) - 55, 3.0 * (static_cast<double>(k) - 20));
                p[i + 120 * (j + 110 * k)] = static_cast<std::uint8_t>(std::min(255.0, std::round(r)));
            }
    const auto path = written(sphere, "sphere.nrrd");
    ExtractOptions ex;
    ex.threads = 2;
    const Expected want = expected_of(path, 40.5, ex);
    // the smaller limit leaves one plane's mesh with the cell layers on either side and its analysis
    for (const std::uint64_t limit : {std::uint64_t{2} << 20, std::uint64_t{64} << 20}) {
        SlabOptions opt;
        opt.extract = ex;
        opt.memory_limit = limit;
        const Output run = run_ranges(path, 40.5, opt, 2);
        expect_same(run, want, "memory limit " + std::to_string(limit));
        if (limit < (std::uint64_t{3} << 20)) {
            EXPECT_GT(run.totals.slabs, 10) << "limit " << limit;
        }
    }
    SlabOptions tiny;
    tiny.extract = ex;
    tiny.memory_limit = 200 << 10;
    try {
        (void)run_ranges(path, 40.5, tiny, 1);
        ADD_FAILURE() << "a limit below one plane's needs was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("--memory-limit 204800 bytes is too small"), std::string::npos) << e.what();
    }
}

TEST(Slabs, NonFiniteSamplesAreCountedOverEveryRange)
{
    Volume v = test::make_volume({6, 5, 20}, [](auto i, auto j, auto k) { return static_cast<double>(i + j + k) - 10; });
    double* d = v.samples<double>();
    // far from the surface (every other corner of their cells is above): cells of case 1, which
    // need no decision on the non-finite value
    d[3 + 6 * (2 + 5 * 10)] = std::numeric_limits<double>::quiet_NaN();
    d[1 + 6 * (4 + 5 * 15)] = std::numeric_limits<double>::infinity();
    d[2 + 6 * (0 + 5 * 16)] = std::numeric_limits<double>::quiet_NaN();
    const auto path = written(v, "nan.nrrd");
    std::string extract_message;
    try {
        (void)extract(io::read_volume(path), 0.5);
    } catch (const Error& e) {
        extract_message = e.what();
    }
    ASSERT_NE(extract_message.find("3 samples are NaN"), std::string::npos) << extract_message;
    for (const int ranks : {1, 3}) {
        const io::detail::VolumeLayout layout = io::detail::describe_volume(path);
        RangeTotals all;
        for (int r = 0; r < ranks; ++r) {
            io::detail::PlaneReader reader(layout);
            SlabOptions opt;
            opt.max_slab_planes = 2;
            const auto planes = rank_planes(20, r, ranks);
            const RangeTotals t = RangeRun(reader, 0.5, opt, planes[0], planes[1]).count();
            if (t.non_finite > 0 && all.non_finite == 0) all.first_non_finite = t.first_non_finite;
            all.non_finite += t.non_finite;
        }
        EXPECT_EQ(non_finite_message(all.non_finite, all.first_non_finite), extract_message) << ranks << " ranks";
    }
}

TEST(Slabs, SizesParse)
{
    EXPECT_EQ(parse_size("256M"), std::uint64_t{256} << 20);
    EXPECT_EQ(parse_size("2g"), std::uint64_t{2} << 30);
    EXPECT_EQ(parse_size("512KiB"), std::uint64_t{512} << 10);
    EXPECT_EQ(parse_size("1000"), 1000u);
    EXPECT_EQ(parse_size("3TB"), std::uint64_t{3} << 40);
    for (const char* bad : {"", "M", "0", "-5M", "1.5G", "12X", "99999999999999999999", "20000000T"}) {
        EXPECT_THROW((void)parse_size(bad), Error) << bad;
    }
}

} // namespace
} // namespace cmc33::slabs
