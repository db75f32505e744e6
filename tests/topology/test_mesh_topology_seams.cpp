// SeamTopology (src/topology/seam_topology.hpp): meshes cut into the slabs of passes.hpp, each
// summed up alone with the ghost layer of the slab before it, merged in any grouping (a chain from
// either end, a balanced tree, through serialization), give mesh_topology() of the whole mesh. The
// meshes: extracted ones with every method (classic MC leaves holes: boundary loops across
// seams), ties, noise, and extracted meshes broken on purpose (flipped, duplicated and degenerate
// triangles) so that non-manifold edges, orientation and degenerate counts cross seams too.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "cmc33/extract.hpp"
#include "cmc33/io.hpp"
#include "cmc33/passes.hpp"
#include "cmc33/topology.hpp"
#include "seam_topology.hpp"
#include "test_support.hpp"

namespace cmc33 {
namespace {

using detail::SeamTopology;
using detail::SlabTriangles;

struct Slab {
    std::int64_t first_vertex = 0, vertex_count = 0;
    std::int64_t k0 = 0, k1 = 0;
    std::vector<std::uint32_t> triangles; ///< global ids
};

/// The slabs [b[s], b[s + 1]) of the mesh of `v` at `iso`.
std::vector<Slab> slabs_of(const Volume& v, double iso, Method method, const std::vector<std::int64_t>& b)
{
    ExtractOptions opt;
    opt.method = method;
    return v.visit([&](auto g) {
        std::vector<RangeCounts> counts;
        for (std::size_t s = 0; s + 1 < b.size(); ++s) counts.push_back(count(g, iso, opt, b[s], b[s + 1]));
        const std::vector<RangeOffsets> off = scan(counts);
        std::vector<Slab> out;
        for (std::size_t s = 0; s < counts.size(); ++s) {
            Slab slab{off[s].first_vertex, counts[s].vertex_count(), b[s], b[s + 1], {}};
            std::vector<float> positions(3 * static_cast<std::size_t>(counts[s].vertex_count()));
            slab.triangles.assign(3 * static_cast<std::size_t>(counts[s].triangle_count()), 0u);
            MeshSpans spans;
            spans.positions = positions.data();
            spans.triangles = slab.triangles.data();
            spans.first_vertex = off[s].first_vertex;
            spans.first_triangle = off[s].first_triangle;
            emit(g, iso, opt, counts[s], off[s], spans);
            out.push_back(std::move(slab));
        }
        return out;
    });
}

Mesh whole(const std::vector<Slab>& slabs)
{
    Mesh m;
    std::int64_t nv = 0;
    for (const Slab& s : slabs) {
        m.triangles.insert(m.triangles.end(), s.triangles.begin(), s.triangles.end());
        nv = s.first_vertex + s.vertex_count;
    }
    m.positions.resize(3 * static_cast<std::size_t>(nv));
    return m;
}

/// The ghost layer of slab s: slab s - 1's triangles that use one of slab s's vertices, or all
/// of slab s - 1's triangles (`all`): anything more than the layer must not change the result.
std::vector<std::uint32_t> ghost(const std::vector<Slab>& slabs, std::size_t s, bool all)
{
    std::vector<std::uint32_t> g;
    if (s == 0) return g;
    const Slab& p = slabs[s - 1];
    for (std::size_t t = 0; t < p.triangles.size(); t += 3) {
        const bool touches = std::any_of(&p.triangles[t], &p.triangles[t] + 3,
                                         [&](std::uint32_t id) { return id >= slabs[s].first_vertex; });
        if (all || touches) g.insert(g.end(), &p.triangles[t], &p.triangles[t] + 3);
    }
    return g;
}

std::vector<SeamTopology> summaries(const std::vector<Slab>& slabs, bool all)
{
    std::vector<SeamTopology> out;
    for (std::size_t s = 0; s < slabs.size(); ++s) {
        const std::vector<std::uint32_t> below = ghost(slabs, s, all);
        out.push_back(SeamTopology::of_slab(SlabTriangles{slabs[s].first_vertex, slabs[s].vertex_count,
                                                          slabs[s].triangles, below}));
    }
    return out;
}

SeamTopology chain_up(const std::vector<SeamTopology>& s)
{
    SeamTopology r = s.front();
    for (std::size_t i = 1; i < s.size(); ++i) r = SeamTopology::merge(r, s[i]);
    return r;
}

SeamTopology chain_down(const std::vector<SeamTopology>& s)
{
    SeamTopology r = s.back();
    for (std::size_t i = s.size() - 1; i-- > 0;) r = SeamTopology::merge(s[i], r);
    return r;
}

/// A binomial tree as over MPI ranks, each summary sent as bytes.
SeamTopology tree(std::vector<SeamTopology> s)
{
    for (std::size_t step = 1; step < s.size(); step *= 2) {
        for (std::size_t i = 0; i + step < s.size(); i += 2 * step) {
            const std::vector<std::byte> bytes = s[i + step].serialize();
            s[i] = SeamTopology::merge(s[i], SeamTopology::deserialize(bytes));
        }
    }
    return s.front();
}

void expect_equal(const MeshTopology& a, const MeshTopology& b, const std::string& what)
{
    EXPECT_EQ(a.vertices, b.vertices) << what;
    EXPECT_EQ(a.edges, b.edges) << what;
    EXPECT_EQ(a.faces, b.faces) << what;
    EXPECT_EQ(a.euler, b.euler) << what;
    EXPECT_EQ(a.components, b.components) << what;
    EXPECT_EQ(a.closed_components, b.closed_components) << what;
    EXPECT_EQ(a.b1, b.b1) << what;
    EXPECT_EQ(a.boundary_edges, b.boundary_edges) << what;
    EXPECT_EQ(a.boundary_loops, b.boundary_loops) << what;
    EXPECT_EQ(a.nonmanifold_edges, b.nonmanifold_edges) << what;
    EXPECT_EQ(a.nonmanifold_vertices, b.nonmanifold_vertices) << what;
    EXPECT_EQ(a.degenerate_triangles, b.degenerate_triangles) << what;
    EXPECT_EQ(a.closed, b.closed) << what;
    EXPECT_EQ(a.oriented, b.oriented) << what;
}

void check_all_groupings(const std::vector<Slab>& slabs, const std::string& what)
{
    const MeshTopology expected = mesh_topology(whole(slabs));
    for (const bool all : {false, true}) {
        const std::vector<SeamTopology> s = summaries(slabs, all);
        const std::string w = what + (all ? ", whole slab as ghost" : ", ghost layer");
        expect_equal(chain_up(s).finish(), expected, w + ", chain up");
        expect_equal(chain_down(s).finish(), expected, w + ", chain down");
        expect_equal(tree(s).finish(), expected, w + ", tree");
    }
}

std::vector<std::vector<std::int64_t>> splits(std::int64_t nz, std::uint64_t seed)
{
    std::vector<std::vector<std::int64_t>> out{{0, nz}, {0, nz / 2, nz}};
    std::vector<std::int64_t> each;
    for (std::int64_t k = 0; k <= nz; ++k) each.push_back(k);
    out.push_back(each);
    std::mt19937_64 rng(seed);
    for (int trial = 0; trial < 4; ++trial) {
        std::vector<std::int64_t> b{0, nz};
        for (int cut = 0; cut < 5; ++cut) b.push_back(std::uniform_int_distribution<std::int64_t>(1, nz - 1)(rng));
        std::sort(b.begin(), b.end());
        b.erase(std::unique(b.begin(), b.end()), b.end());
        out.push_back(b);
    }
    return out;
}

Volume bucky() { return io::read_volume(std::filesystem::path(CMC33_SOURCE_DIR) / "data" / "Bucky_32x32x32_uint8.nrrd"); }

Volume noise(Index3 dims, std::uint64_t seed)
{
    std::mt19937_64 rng(seed);
    std::uniform_int_distribution<int> u(0, 4); // few values: many ties at iso 2
    return test::make_volume(dims, [&](auto, auto, auto) { return static_cast<double>(u(rng)); });
}

TEST(SeamTopology, ExtractedMeshesInAnySlabsAndAnyGroupingGiveMeshTopology)
{
    struct Case {
        Volume volume;
        double iso;
        const char* name;
    };
    std::vector<Case> cases;
    cases.push_back({bucky(), 100.5, "bucky 100.5"});
    cases.push_back({bucky(), 100, "bucky 100 (ties)"});
    cases.push_back({noise({13, 11, 17}, 3), 2, "noise with ties"});
    cases.push_back({noise({9, 12, 10}, 4), 1.5, "noise"});
    for (const Case& c : cases) {
        for (const Method method : {Method::cmc33, Method::mc33_lewiner, Method::mc}) {
            for (const auto& b : splits(c.volume.dims()[2], 7)) {
                const std::string what = std::string(c.name) + " " + std::string(method_name(method)) + ", " +
                                         std::to_string(b.size() - 1) + " slabs";
                check_all_groupings(slabs_of(c.volume, c.iso, method, b), what);
                if (testing::Test::HasFailure()) return;
            }
        }
    }
}

TEST(SeamTopology, BrokenMeshesGiveMeshTopologyToo)
{
    const Volume v = noise({12, 10, 14}, 11);
    std::mt19937_64 rng(5);
    for (int trial = 0; trial < 20; ++trial) {
        const std::vector<std::int64_t> b = splits(14, 100 + static_cast<std::uint64_t>(trial))[3 + trial % 4];
        std::vector<Slab> slabs = slabs_of(v, 2, Method::cmc33, b);
        for (Slab& s : slabs) {
            const std::size_t n = s.triangles.size() / 3;
            if (n == 0) continue;
            std::uniform_int_distribution<std::size_t> pick(0, n - 1);
            for (int k = 0; k < 3; ++k) { // flipped: orientation and, as pairs, non-manifold edges
                const std::size_t t = pick(rng);
                std::swap(s.triangles[3 * t + 1], s.triangles[3 * t + 2]);
            }
            for (int k = 0; k < 2; ++k) { // duplicated: edges with four triangles
                const std::size_t t = pick(rng);
                const std::uint32_t tri[3] = {s.triangles[3 * t], s.triangles[3 * t + 1], s.triangles[3 * t + 2]};
                s.triangles.insert(s.triangles.end(), tri, tri + 3);
            }
            { // degenerate, and removed: holes whose boundary loops may cross seams
                const std::size_t t = pick(rng);
                s.triangles[3 * t + 2] = s.triangles[3 * t];
                const std::size_t u = pick(rng);
                s.triangles.erase(s.triangles.begin() + static_cast<std::ptrdiff_t>(3 * u),
                                  s.triangles.begin() + static_cast<std::ptrdiff_t>(3 * u + 3));
            }
        }
        check_all_groupings(slabs, "broken mesh, trial " + std::to_string(trial));
        if (testing::Test::HasFailure()) return;
    }
}

/// `triangles` over vertices [0, nv) as slabs cut at `cuts`, each triangle in the slab of its
/// smallest id (the cuts must leave its other ids in that slab or the next).
std::vector<Slab> cut_into_slabs(const std::vector<std::uint32_t>& triangles, std::uint32_t nv,
                                 const std::vector<std::uint32_t>& cuts)
{
    std::vector<std::uint32_t> b{0};
    b.insert(b.end(), cuts.begin(), cuts.end());
    b.push_back(nv);
    std::vector<Slab> slabs;
    for (std::size_t s = 0; s + 1 < b.size(); ++s) slabs.push_back(Slab{b[s], b[s + 1] - b[s], 0, 0, {}});
    for (std::size_t t = 0; t < triangles.size(); t += 3) {
        const std::uint32_t low = std::min({triangles[t], triangles[t + 1], triangles[t + 2]});
        std::size_t s = 0;
        while (s + 1 < slabs.size() && low >= b[s + 1]) ++s;
        slabs[s].triangles.insert(slabs[s].triangles.end(), &triangles[t], &triangles[t] + 3);
    }
    return slabs;
}

// Most vertices are settled without sorting their ring (every edge used twice, once each way; at
// most 16 triangles): a vertex where two closed fans meet, a fan of more triangles, and a flipped
// triangle, which such a vertex has not, must count as mesh_topology() counts them.
TEST(SeamTopology, RingsOfManyOrPinchedOrFlippedFansGiveMeshTopology)
{
    // two tetrahedra sharing vertex 0: every edge used twice, two fans at vertex 0
    std::vector<std::uint32_t> pinched{0, 1, 2, 0, 2, 3, 0, 3, 1, 1, 3, 2, 0, 4, 5, 0, 5, 6, 0, 6, 4, 4, 6, 5};
    // a bipyramid over a 20-gon (vertices 0..19, apexes 20 and 21): 20 triangles at each apex
    std::vector<std::uint32_t> bipyramid;
    for (std::uint32_t i = 0; i < 20; ++i) {
        const std::uint32_t j = (i + 1) % 20;
        bipyramid.insert(bipyramid.end(), {20, i, j, 21, j, i});
    }
    const auto flipped = [](std::vector<std::uint32_t> t, std::size_t which) {
        std::swap(t[3 * which + 1], t[3 * which + 2]);
        return t;
    };
    using Cuts = std::vector<std::vector<std::uint32_t>>;
    const Cuts pinched_cuts{{}, {1}, {3}, {4}}, bipyramid_cuts{{}, {10}, {19}, {20}};
    const struct {
        std::vector<std::uint32_t> triangles;
        std::uint32_t nv;
        const Cuts& cuts;
        const char* what;
    } cases[] = {{pinched, 7, pinched_cuts, "pinched"},
                 {flipped(pinched, 5), 7, pinched_cuts, "pinched, one triangle flipped"},
                 {bipyramid, 22, bipyramid_cuts, "bipyramid"},
                 {flipped(bipyramid, 7), 22, bipyramid_cuts, "bipyramid, one triangle flipped"}};
    for (const auto& c : cases) {
        for (const std::vector<std::uint32_t>& cuts : c.cuts) {
            std::string w = std::string(c.what) + ", cut at";
            for (const std::uint32_t x : cuts) w += " " + std::to_string(x);
            check_all_groupings(cut_into_slabs(c.triangles, c.nv, cuts), w);
        }
    }
    const MeshTopology t = SeamTopology::of_slab(SlabTriangles{0, 7, pinched, {}}).finish();
    EXPECT_EQ(t.nonmanifold_vertices, 1);
    EXPECT_EQ(t.nonmanifold_edges, 0);
    EXPECT_TRUE(t.oriented);
}

TEST(SeamTopology, SharedVolumesInSlabs)
{
    for (const char* name : {"neghip_66x66x66_uint8.nrrd", "HeadMRVolume_48x62x42_uint8.nrrd"}) {
        const auto path = test::shared_volume(name);
        if (!path) GTEST_SKIP() << "../shared/data/volumes not found";
        const Volume v = io::read_volume(*path);
        const std::int64_t nz = v.dims()[2];
        check_all_groupings(slabs_of(v, 40.5, Method::cmc33, {0, 5, nz / 2, nz / 2 + 1, nz}), name);
    }
}

TEST(SeamTopology, DamagedBytesAndTrianglesOutsideTheSlabAreRefused)
{
    const std::vector<Slab> slabs = slabs_of(bucky(), 100.5, Method::cmc33, {0, 16, 32});
    const SeamTopology s = SeamTopology::of_slab({slabs[1].first_vertex, slabs[1].vertex_count, slabs[1].triangles, {}});
    std::vector<std::byte> bytes = s.serialize();
    EXPECT_NO_THROW((void)SeamTopology::deserialize(bytes));
    bytes.pop_back();
    EXPECT_THROW((void)SeamTopology::deserialize(bytes), Error);
    // slab 0's triangles do not belong to a slab that starts at slab 1's first vertex
    EXPECT_THROW((void)SeamTopology::of_slab({slabs[1].first_vertex, slabs[1].vertex_count, slabs[0].triangles, {}}),
                 Error);
}

} // namespace
} // namespace cmc33
