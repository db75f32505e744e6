// The stress test: its random fields, its verdicts on the three methods, its determinism, and
// that it catches meshes broken on purpose.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cmc33/cell.hpp"
#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/io.hpp"
#include "cmc33/topology.hpp"
#include "cmc33/verify.hpp"
#include "test_support.hpp"

namespace cmc33 {
namespace {

std::array<double, 8> corners(const Volume& cell)
{
    std::array<double, 8> v{};
    for (int c = 0; c < 8; ++c)
        v[static_cast<std::size_t>(c)] = static_cast<double>(cell.samples<float>()[c]);
    return v;
}

std::vector<float> samples(const Volume& v)
{
    const float* p = v.samples<float>();
    return std::vector<float>(p, p + v.sample_count());
}

std::vector<std::string> lines_of(const std::filesystem::path& path)
{
    std::ifstream in(path);
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
}

std::vector<std::string> split(const std::string& line, char sep = '\t')
{
    std::vector<std::string> out;
    std::stringstream s(line);
    for (std::string field; std::getline(s, field, sep);) out.push_back(field);
    return out;
}

/// Every count of two reports, for equality checks.
std::vector<std::int64_t> numbers(const VerifyReport& r)
{
    std::vector<std::int64_t> n(r.fields.begin(), r.fields.end());
    for (const MethodReport& m : r.methods) {
        n.insert(n.end(), {m.checked, m.matched, m.mismatched, m.undetermined, m.nonmanifold,
                           m.unoriented, m.not_embedded, m.errors, m.failures_written});
        n.insert(n.end(), m.checked_by_kind.begin(), m.checked_by_kind.end());
        n.insert(n.end(), m.mismatched_by_kind.begin(), m.mismatched_by_kind.end());
        n.insert(n.end(), m.fields_per_subcase.begin(), m.fields_per_subcase.end());
        n.insert(n.end(), m.mismatches_per_subcase.begin(), m.mismatches_per_subcase.end());
    }
    return n;
}

int subcase_index(std::string_view name)
{
    for (int s = 0; s < kSubcaseCount; ++s) {
        if (subcase_name(s) == name) return s;
    }
    return -1;
}

// ------------------------------------------------------------------------------------------------
// Random fields

TEST(RandomFields, SameItemSameSamplesWhateverTheOrder)
{
    const std::vector<float> a = samples(random_field(FieldKind::grid, 7, 42));
    (void)random_field(FieldKind::grid, 8, 42);
    (void)random_field(FieldKind::cell, 7, 42);
    EXPECT_EQ(samples(random_field(FieldKind::grid, 7, 42)), a);
    EXPECT_NE(samples(random_field(FieldKind::grid, 7, 43)), a);
    EXPECT_NE(samples(random_field(FieldKind::grid, 8, 42)), a);
    EXPECT_NE(samples(random_field(FieldKind::closed, 7, 42)), a);
}

TEST(RandomFields, GridsAreUniformInMinusOneToOne)
{
    double sum = 0, lo = 1, hi = -1;
    std::int64_t count = 0;
    for (std::int64_t n = 1; n <= 200; ++n) {
        const Volume v = random_field(FieldKind::grid, n, 1, 5);
        ASSERT_EQ(v.dims(), (Index3{5, 5, 5}));
        ASSERT_EQ(v.type(), ScalarType::f32);
        for (float x : samples(v)) {
            sum += static_cast<double>(x);
            lo = std::min(lo, static_cast<double>(x));
            hi = std::max(hi, static_cast<double>(x));
            ++count;
        }
    }
    EXPECT_GE(lo, -1.0);
    EXPECT_LE(hi, 1.0);
    EXPECT_LT(lo, -0.99);
    EXPECT_GT(hi, 0.99);
    EXPECT_NEAR(sum / static_cast<double>(count), 0.0,
                0.03); // 25,000 samples: sd of the mean 0.004
}

TEST(RandomFields, ClosedGridsHaveNegativeBoundaryAndClosedSurfaces)
{
    for (std::int64_t n = 1; n <= 50; ++n) {
        const Volume v = random_field(FieldKind::closed, n, 3, 6);
        const GridView<float> g = v.view<float>();
        bool interior_above = false;
        for (std::int64_t k = 0; k < 6; ++k) {
            for (std::int64_t j = 0; j < 6; ++j) {
                for (std::int64_t i = 0; i < 6; ++i) {
                    const bool boundary = i == 0 || j == 0 || k == 0 || i == 5 || j == 5 || k == 5;
                    if (boundary) {
                        ASSERT_LE(g(i, j, k), -0.1f);
                        ASSERT_GE(g(i, j, k), -1.0f);
                    } else {
                        interior_above = interior_above || g(i, j, k) >= 0;
                    }
                }
            }
        }
        const FieldTopology t = field_topology(v, 0.0);
        ASSERT_TRUE(t.determined) << t.why;
        EXPECT_EQ(t.boundary_loops, 0);
        EXPECT_EQ(t.b0, t.b2) << "every component is closed";
        EXPECT_EQ(t.b0 > 0, interior_above);
    }
}

TEST(RandomFields, CellsCoverEveryConfigurationAndSubcase)
{
    std::array<int, kSubcaseCount> per_subcase{};
    std::set<unsigned> configs;
    std::set<std::string> distributions;
    for (std::int64_t n = 1; n <= 20000; ++n) {
        const CellReport r =
            analyze_cell(corners(random_field(FieldKind::cell, n, 1)), 0.0, Method::cmc33);
        ++per_subcase[static_cast<std::size_t>(r.subcase)];
        configs.insert(r.config);
        distributions.insert(std::string(cell_distribution_name(n)));
    }
    EXPECT_EQ(configs.size(), 256u);
    EXPECT_EQ(distributions.size(), 8u);
    for (int s = 0; s < kSubcaseCount; ++s) {
        // Measured with seed 1: the rarest are 10.1.2 (23), 6.1.2 (45) and 12.1.2 (59).
        EXPECT_GE(per_subcase[static_cast<std::size_t>(s)], 10) << "subcase " << subcase_name(s);
    }
}

TEST(RandomFields, RejectsBadArguments)
{
    EXPECT_THROW((void)random_field(FieldKind::grid, 0, 1), Error);
    EXPECT_THROW((void)random_field(FieldKind::grid, 1, 1, 1), Error);
    EXPECT_THROW((void)random_field(FieldKind::closed, 1, 1, 2), Error);
    EXPECT_NO_THROW((void)random_field(FieldKind::grid, 1, 1, 2));
    EXPECT_EQ(field_name(FieldKind::closed, 42), "closed-000042");
    EXPECT_EQ(field_name(FieldKind::cell, 1234567), "cell-1234567");
}

// ------------------------------------------------------------------------------------------------
// The verdicts

TEST(Verify, Cmc33MatchesEverywhereAndTheFlawedMethodsDoNot)
{
    VerifyOptions o;
    o.methods = {Method::cmc33, Method::mc33_lewiner, Method::mc};
    o.cells = 3000;
    o.grids = 500;
    o.closed = 200;
    o.seed = 1;
    o.threads = 2;
    std::int64_t last_done = -1, calls = 0;
    o.progress = [&](const VerifyProgress& p) {
        EXPECT_GE(p.done, last_done);
        EXPECT_EQ(p.total, 3700);
        last_done = p.done;
        ++calls;
    };
    const VerifyReport r = verify(o);
    EXPECT_EQ(last_done, 3700);
    EXPECT_GE(calls, 1);
    EXPECT_EQ(r.fields, (std::array<std::int64_t, 4>{3000, 500, 200, 0}));
    EXPECT_EQ(r.threads, 2);
    ASSERT_EQ(r.methods.size(), 3u);

    const MethodReport& c = r.methods[0];
    EXPECT_EQ(c.name, "cmc33");
    EXPECT_EQ(c.checked + c.undetermined, 3700);
    EXPECT_LT(c.undetermined, 10);
    EXPECT_EQ(c.mismatched, 0);
    EXPECT_EQ(c.nonmanifold, 0);
    EXPECT_EQ(c.unoriented, 0);
    EXPECT_EQ(c.errors, 0);
    EXPECT_EQ(c.matched, c.checked);
    EXPECT_TRUE(r.methods[0].fields_per_subcase[static_cast<std::size_t>(subcase_index("13.5.2"))] >
                0);

    for (std::size_t m = 1; m < 3; ++m) {
        const MethodReport& f = r.methods[m];
        SCOPED_TRACE(f.name);
        EXPECT_EQ(f.checked, c.checked);
        EXPECT_GT(f.mismatched, 10);
        EXPECT_GT(f.mismatched_by_kind[0], 0) << "cells";
        EXPECT_GT(f.mismatched_by_kind[1], 0) << "grids";
        EXPECT_EQ(f.matched + f.mismatched, f.checked);
        // Only subcases with a face or interior test can go wrong.
        for (int s = 0; s < kSubcaseCount; ++s) {
            if (subcase_name(s).find('.') == std::string_view::npos) {
                EXPECT_EQ(f.mismatches_per_subcase[static_cast<std::size_t>(s)], 0)
                    << subcase_name(s);
            }
        }
    }
    // Classic MC has one tiling per configuration: it never reports a tunnel or 13.5.
    EXPECT_EQ(r.methods[2].fields_per_subcase[static_cast<std::size_t>(subcase_index("4.1.2"))], 0);
    EXPECT_GT(r.methods[2].mismatched, r.methods[1].mismatched);
    EXPECT_FALSE(r.passed());
    EXPECT_GT(r.rate(FieldKind::cell), 0);
}

TEST(Verify, SameSeedSameReportWithOneOrThreeThreads)
{
    const auto dir = test::temp_dir();
    VerifyOptions o;
    o.methods = {Method::mc33_lewiner, Method::mc};
    o.cells = 1500;
    o.grids = 150;
    o.closed = 50;
    o.seed = 77;
    o.max_failures = 5;
    o.threads = 1;
    o.failures_dir = dir / "one";
    const VerifyReport one = verify(o);
    o.threads = 3;
    o.failures_dir = dir / "three";
    const VerifyReport three = verify(o);
    EXPECT_EQ(one.threads, 1);
    EXPECT_EQ(three.threads, 3);
    EXPECT_EQ(numbers(one), numbers(three));
    EXPECT_GT(one.methods[1].mismatched, 0);
    EXPECT_EQ(one.failures_written, 10);

    // The same failures, in the same order, with the same files.
    std::vector<std::string> a = lines_of(dir / "one" / "failures.tsv"),
                             b = lines_of(dir / "three" / "failures.tsv");
    ASSERT_EQ(a.size(), 11u);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        const std::string one_dir = (dir / "one").string(), three_dir = (dir / "three").string();
        std::string x = a[i], y = b[i];
        for (std::size_t p; (p = x.find(one_dir)) != std::string::npos;)
            x.replace(p, one_dir.size(), "DIR");
        for (std::size_t p; (p = y.find(three_dir)) != std::string::npos;)
            y.replace(p, three_dir.size(), "DIR");
        EXPECT_EQ(x, y);
    }
    o.seed = 78;
    o.failures_dir.clear();
    EXPECT_NE(numbers(verify(o)), numbers(one)) << "another seed, other fields";
}

TEST(Verify, FailuresReproduce)
{
    const auto dir = test::temp_dir() / "failures";
    VerifyOptions o;
    o.methods = {Method::cmc33, Method::mc};
    o.cells = 400;
    o.grids = 40;
    o.threads = 2;
    o.max_failures = 6;
    o.failures_dir = dir;
    const VerifyReport r = verify(o);
    EXPECT_EQ(r.failures_dir, dir);
    EXPECT_EQ(r.methods[0].failures_written, 0);
    EXPECT_EQ(r.methods[1].failures_written, 6);
    const std::vector<std::string> lines = lines_of(dir / "failures.tsv");
    ASSERT_EQ(lines.size(), 7u);
    EXPECT_EQ(split(lines[0]).size(), 19u);
    std::int64_t previous = 0;
    for (std::size_t i = 1; i < lines.size(); ++i) {
        const std::vector<std::string> f = split(lines[i]);
        ASSERT_EQ(f.size(), 19u) << lines[i];
        EXPECT_EQ(f[1], "mc");
        EXPECT_EQ(f[2], "cell") << "the first failures in order are cells";
        // The field file reproduces the expected invariants, the mesh file the obtained ones.
        const Volume v = io::read_volume(f[0]);
        const FieldTopology t = field_topology(v, 0.0);
        EXPECT_EQ(std::to_string(t.euler) + " " + std::to_string(t.b0) + " " +
                      std::to_string(t.b1) + " " + std::to_string(t.b2) + " " +
                      std::to_string(t.boundary_loops),
                  f[4] + " " + f[5] + " " + f[6] + " " + f[7] + " " + f[8]);
        const std::filesystem::path stem = std::filesystem::path(f[0]).stem();
        const MeshTopology m = mesh_topology(io::read_mesh(dir / (stem.string() + "-mc.ply")));
        EXPECT_EQ(std::to_string(m.euler) + " " + std::to_string(m.components) + " " +
                      std::to_string(m.b1) + " " + std::to_string(m.closed_components) + " " +
                      std::to_string(m.boundary_loops),
                  f[9] + " " + f[10] + " " + f[11] + " " + f[12] + " " + f[13]);
        EXPECT_FALSE(topology_matches(m, t));
        // It is the same extraction again, and the same subcase.
        ExtractOptions e;
        e.method = Method::mc;
        EXPECT_EQ(mesh_topology(extract(v, 0.0, e)).euler, m.euler);
        EXPECT_EQ(f[3], subcase_name(analyze_cell(corners(v), 0.0, Method::mc).subcase));
        EXPECT_NE(f[16].find("cmc33 extract '" + f[0] + "' --iso 0 --method mc --json"),
                  std::string::npos);
        EXPECT_EQ(f[17].rfind("cmc33 cell ", 0), 0u);
        EXPECT_NE(f[17].find(" --method mc"), std::string::npos);
        // cell numbers increase: the failures kept are the first ones
        const std::int64_t n = std::stoll(stem.string().substr(5));
        EXPECT_GT(n, previous);
        previous = n;
    }
    // Nothing written, not even the folder, when nothing fails.
    const auto clean = test::temp_dir() / "clean";
    o.methods = {Method::cmc33};
    o.failures_dir = clean;
    const VerifyReport ok = verify(o);
    EXPECT_TRUE(ok.passed());
    EXPECT_TRUE(ok.failures_dir.empty());
    EXPECT_FALSE(std::filesystem::exists(clean));
}

TEST(Verify, RejectsBadOptions)
{
    VerifyOptions o;
    o.cells = -1;
    EXPECT_THROW((void)verify(o), Error);
    o.cells = 1;
    o.methods = {};
    EXPECT_THROW((void)verify(o), Error);
    o.methods = {Method::mc, Method::mc};
    EXPECT_THROW((void)verify(o), Error);
    o.methods = {Method::mc};
    o.grids = 1;
    o.size = 1;
    try {
        (void)verify(o);
        FAIL() << "size 1 accepted";
    } catch (const Error& e) {
        EXPECT_EQ(e.status(), Status::invalid_argument);
        EXPECT_NE(std::string(e.what()).find("size 1"), std::string::npos) << e.what();
    }
    o.size = 2;
    o.closed = 1;
    EXPECT_THROW((void)verify(o), Error) << "closed grids need size >= 3";
    o.size = 3;
    EXPECT_NO_THROW((void)verify(o));
}

// ------------------------------------------------------------------------------------------------
// The verifier catches broken meshes

/// A grid whose surface has several components (found among the first closed fields).
Volume field_with_components(int at_least, FieldTopology& topology)
{
    for (std::int64_t n = 1;; ++n) {
        Volume v = random_field(FieldKind::closed, n, 1, 6);
        topology = field_topology(v, 0.0);
        if (topology.determined && topology.b0 >= at_least) return v;
    }
}

TEST(VerifyCatches, ADroppedTriangle)
{
    FieldTopology t;
    const Volume v = field_with_components(1, t);
    Mesh mesh = extract(v, 0.0);
    ASSERT_TRUE(topology_matches(mesh_topology(mesh), t));
    ASSERT_TRUE(is_manifold(mesh_topology(mesh)));
    mesh.triangles.resize(mesh.triangles.size() - 3);
    const MeshTopology broken = mesh_topology(mesh);
    EXPECT_EQ(broken.boundary_loops, t.boundary_loops + 1);
    EXPECT_FALSE(topology_matches(broken, t));
}

TEST(VerifyCatches, AClosedTunnel)
{
    // Custodio et al. 2013, Appendix A: a 13.5.2 cell that MC33 takes for 13.5.1.
    const std::array<double, 8> values{0.2864,  -0.0639, -0.1692, 0.6568,
                                       -0.2384, 0.9486,  0.1075,  -0.5049};
    const Volume v =
        test::make_volume({2, 2, 2}, [&](std::int64_t i, std::int64_t j, std::int64_t k) {
            return values[static_cast<std::size_t>(i | j << 1 | k << 2)];
        });
    const FieldTopology t = field_topology(v, 0.0);
    ASSERT_TRUE(t.determined) << t.why;
    EXPECT_EQ(analyze_cell(values, 0.0, Method::cmc33).subcase, subcase_index("13.5.2"));
    EXPECT_EQ(analyze_cell(values, 0.0, Method::mc33_lewiner).subcase, subcase_index("13.5.1"));
    ExtractOptions o;
    const MeshTopology right = mesh_topology(extract(v, 0.0, o));
    EXPECT_TRUE(topology_matches(right, t));
    EXPECT_TRUE(is_manifold(right));
    o.method = Method::mc33_lewiner;
    const MeshTopology wrong = mesh_topology(extract(v, 0.0, o));
    EXPECT_TRUE(is_manifold(wrong)) << "a wrong mesh can be a perfectly good manifold";
    EXPECT_FALSE(topology_matches(wrong, t));
    EXPECT_NE(wrong.b1, t.b1);
}

TEST(VerifyCatches, TwoPiecesWelded)
{
    FieldTopology t;
    const Volume v = field_with_components(2, t);
    Mesh mesh = extract(v, 0.0);
    const MeshTopology before = mesh_topology(mesh);
    ASSERT_TRUE(topology_matches(before, t));
    // Component of every vertex, by flooding over triangles.
    const std::size_t n = mesh.vertex_count();
    std::vector<std::size_t> label(n);
    for (std::size_t i = 0; i < n; ++i) label[i] = i;
    for (bool changed = true; changed;) {
        changed = false;
        for (std::size_t q = 0; q < mesh.triangles.size(); q += 3) {
            const std::size_t m = std::min({label[mesh.triangles[q]], label[mesh.triangles[q + 1]],
                                            label[mesh.triangles[q + 2]]});
            for (std::size_t c = 0; c < 3; ++c) {
                if (label[mesh.triangles[q + c]] != m) {
                    label[mesh.triangles[q + c]] = m;
                    changed = true;
                }
            }
        }
    }
    const std::uint32_t a = mesh.triangles[0];
    std::uint32_t b = a;
    for (std::uint32_t index : mesh.triangles) {
        if (label[index] != label[a]) {
            b = index;
            break;
        }
    }
    ASSERT_NE(a, b);
    for (std::uint32_t& index : mesh.triangles) {
        if (index == b) index = a; // weld b into a
    }
    const MeshTopology after = mesh_topology(mesh);
    EXPECT_EQ(after.components, before.components - 1);
    EXPECT_FALSE(topology_matches(after, t) && is_manifold(after));
    EXPECT_FALSE(is_manifold(after)) << "two fans meet at the welded vertex";
}

TEST(VerifyCatches, ADuplicatedTriangle)
{
    FieldTopology t;
    const Volume v = field_with_components(1, t);
    Mesh mesh = extract(v, 0.0);
    mesh.triangles.insert(mesh.triangles.end(), mesh.triangles.begin(), mesh.triangles.begin() + 3);
    const MeshTopology broken = mesh_topology(mesh);
    EXPECT_GT(broken.nonmanifold_edges, 0);
    EXPECT_FALSE(is_manifold(broken));
}

TEST(VerifyCatches, NothingAgainstAnUndeterminedField)
{
    FieldTopology t;
    const Volume v = field_with_components(1, t);
    const MeshTopology m = mesh_topology(extract(v, 0.0));
    ASSERT_TRUE(topology_matches(m, t));
    t.determined = false;
    EXPECT_FALSE(topology_matches(m, t));
}

} // namespace
} // namespace cmc33
