// One cell per subcase of Chernyaev's table (33 with case 0), found by sampling random corner values
// (seed 12345, values rounded to 4 decimals), and the paper's Appendix A cell. Each is checked for
// its classification and for the topology of its cell mesh (pieces, tunnels, boundary loops), and
// against the independent field topology of the trilinear interpolant.

#include <gtest/gtest.h>

#include <array>
#include <random>
#include <string>

#include "cmc33/cell.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/topology.hpp"
#include "decide.hpp"

namespace {

using cmc33::Method;

struct SubcaseCell {
    const char* subcase;
    std::array<double, 8> values; // corner c = x | y << 1 | z << 2, iso 0
    int pieces;                   // connected components of the cell's surface
    int loops;                    // boundary loops on the cell's faces
    int euler;                    // discs count 1, a tube 0
};

// pieces, loops and euler follow from the subcase: discs and at most one tube.
const SubcaseCell kCells[] = {
    {"0", {0.5317, 0.7010, 0.9482, 0.6659, 0.7452, 0.1762, 0.4380, 0.3470}, 0, 0, 0},
    {"1", {-0.1988, -0.7703, -0.7795, -0.1932, -0.6732, -0.8048, -0.5454, 0.9540}, 1, 1, 1},
    {"2", {-0.0026, -0.4118, 0.4057, 0.1602, 0.0642, 0.0240, 0.0200, 0.9870}, 1, 1, 1},
    {"3.1", {-0.2327, -0.0854, -0.3162, 0.4400, -0.3419, -0.7246, 0.0031, -0.3379}, 2, 2, 2},
    {"3.2", {-0.0002, -0.2009, -0.9766, -0.9238, -0.0040, 0.0125, 0.4926, -0.0057}, 1, 1, 1},
    {"4.1.1", {0.3616, -0.3415, 0.9535, 0.3142, 0.7429, 0.9067, -0.6130, 0.9805}, 2, 2, 2},
    {"4.1.2", {-0.6154, 0.7225, 0.4645, 0.0002, 0.0410, 0.0688, 0.0039, -0.4095}, 1, 2, 0},
    {"5", {-0.5045, -0.9492, -0.7949, -0.3033, -0.9926, 0.8862, 0.4134, 0.8455}, 1, 1, 1},
    {"6.1.1", {-0.0002, 0.0603, -0.6175, -0.0063, -0.2231, 0.0341, 0.4292, -0.2287}, 2, 2, 2},
    {"6.1.2", {0.1748, -0.3576, -0.0245, 0.1224, 0.0087, 0.2759, -0.8171, 0.0887}, 1, 2, 0},
    {"6.2", {-0.1605, 0.6082, 0.1973, -0.9931, -0.0234, 0.7644, 0.8685, 0.9714}, 1, 1, 1},
    {"7.1", {0.8578, -0.5430, -0.2909, 0.0522, -0.9585, 0.2240, -0.1888, -0.9332}, 3, 3, 3},
    {"7.2", {-0.3034, 0.3042, 0.0610, -0.2797, 0.7565, -0.8370, -0.0090, -0.3145}, 2, 2, 2},
    {"7.3", {-0.6667, 0.3983, 0.5502, -0.2583, -0.2921, -0.7773, -0.4311, 0.3511}, 1, 1, 1},
    {"7.4.1", {-0.6202, -0.0677, 0.8842, -0.2189, 0.6209, -0.6749, -0.1143, 0.8826}, 2, 2, 2},
    {"7.4.2", {-0.9352, 0.9028, 0.7868, -0.8390, 0.1196, 0.9082, -0.8395, 0.6102}, 1, 2, 0},
    {"8", {0.0511, 0.1198, -0.2995, -0.2004, 0.7825, 0.0255, -0.1083, -0.5524}, 1, 1, 1},
    {"9", {-0.9821, -0.2623, -0.1884, 0.7357, -0.8866, 0.8393, 0.3622, 0.6170}, 1, 1, 1},
    {"10.1.1", {0.5000, 0.2006, -0.9890, -0.6626, -0.8201, -0.4716, 0.3721, 0.8519}, 2, 2, 2},
    {"10.1.2", {-0.4791, 0.2380, -0.3342, 0.8620, 0.2732, -0.1325, 0.3106, -0.7881}, 1, 2, 0},
    {"10.2", {-0.4392, 0.8234, 0.5408, -0.4475, -0.8529, 0.0899, 0.8222, -0.7127}, 1, 1, 1},
    {"11", {-0.1952, 0.9683, -0.7189, -0.1203, 0.7911, 0.3520, 0.9332, -0.1763}, 1, 1, 1},
    {"12.1.1", {-0.2847, -0.1991, 0.3788, 0.1195, 0.1489, -0.5846, -0.9427, 0.3778}, 2, 2, 2},
    {"12.1.2", {-0.5456, -0.0141, 0.0305, 0.5212, -0.0002, 0.0176, 0.0208, -0.2444}, 1, 2, 0},
    {"12.2", {0.6795, 0.8006, -0.1763, -0.1555, -0.0155, 0.0311, 0.0450, -0.6844}, 1, 1, 1},
    {"12.3", {-0.1706, 0.0947, 0.0000, -0.7332, -0.0182, -0.0220, 0.1086, 0.6085}, 1, 1, 1},
    {"13.1", {-0.6407, 0.9218, 0.7240, -0.9493, 0.9017, -0.5099, -0.5456, 0.7477}, 4, 4, 4},
    {"13.2", {-0.4585, 0.4908, 0.6669, -0.0007, 0.0529, -0.0325, -0.2256, 0.3132}, 3, 3, 3},
    {"13.3", {0.1367, -0.2094, -0.6925, 0.0159, -0.4815, 0.7533, 0.5699, -0.8555}, 2, 2, 2},
    {"13.4", {0.6716, -0.3500, -0.4786, 0.8929, -0.9164, 0.3722, 0.3423, -0.2675}, 1, 1, 1},
    {"13.5.1", {-0.6723, 0.6373, 0.4887, -0.2070, 0.1784, -0.7379, -0.3857, 0.5953}, 3, 3, 3},
    {"13.5.2", {0.5678, -0.0628, -0.5713, 0.7048, -0.8223, 0.4365, 0.7174, -0.9254}, 2, 3, 1},
    {"14", {-0.0024, -0.5892, 0.2448, 0.0085, -0.0251, 0.0267, -0.5351, 0.0003}, 1, 1, 1},
};

cmc33::FieldTopology field_of(const std::array<double, 8>& v, double iso)
{
    const auto view = cmc33::GridView<double>::dense(v.data(), {2, 2, 2});
    return cmc33::field_topology(view, iso);
}

class Subcase : public ::testing::TestWithParam<SubcaseCell> {};

TEST_P(Subcase, ClassificationAndCellTopology)
{
    const SubcaseCell& cell = GetParam();
    const cmc33::CellReport r = cmc33::analyze_cell(cell.values, 0.0, Method::cmc33);
    EXPECT_EQ(cmc33::subcase_name(r.subcase), cell.subcase);
    const cmc33::MeshTopology t = cmc33::mesh_topology(r.mesh);
    EXPECT_EQ(t.components, cell.pieces);
    EXPECT_EQ(t.boundary_loops, cell.loops);
    EXPECT_EQ(t.euler, cell.euler);
    EXPECT_EQ(t.nonmanifold_edges, 0);
    EXPECT_EQ(t.nonmanifold_vertices, 0);
    EXPECT_EQ(t.degenerate_triangles, 0);
    if (r.mesh.triangle_count() > 0) {
        EXPECT_TRUE(t.oriented);
    }
    // The independent verifier agrees with the cell mesh (one cell: the box is the cell).
    const cmc33::FieldTopology f = field_of(cell.values, 0.0);
    ASSERT_TRUE(f.determined) << f.why;
    EXPECT_EQ(f.euler, t.euler);
    EXPECT_EQ(f.b0, t.components);
    EXPECT_EQ(f.boundary_loops, t.boundary_loops);
}

INSTANTIATE_TEST_SUITE_P(AllSubcases, Subcase, ::testing::ValuesIn(kCells), [](const auto& p) {
    std::string name = std::string("s") + p.param.subcase;
    for (char& c : name) c = c == '.' ? '_' : c;
    return name;
});

TEST(Subcase, EverySubcaseIsCovered)
{
    EXPECT_EQ(std::size(kCells), static_cast<std::size_t>(cmc33::kSubcaseCount));
    for (int s = 0; s < cmc33::kSubcaseCount; ++s) EXPECT_EQ(cmc33::subcase_name(s), kCells[s].subcase);
}

// Custodio et al. 2013, Appendix A. Its A0..D0 lie on the bottom face in cyclic order and A1..D1
// above them: A0 -> corner 0, B0 -> 1, C0 -> 3, D0 -> 2, A1 -> 4, B1 -> 5, C1 -> 7, D1 -> 6.
const std::array<double, 8> kAppendixA{0.2864, -0.0639, -0.1692, 0.6568, -0.2384, 0.9486, 0.1075, -0.5049};

TEST(AppendixA, Cmc33FindsTheTunnel)
{
    const cmc33::CellReport r = cmc33::analyze_cell(kAppendixA, 0.0, Method::cmc33);
    EXPECT_EQ(r.base_case, 13);
    EXPECT_EQ(cmc33::subcase_name(r.subcase), "13.5.2");
    EXPECT_TRUE(r.interior.tunnel);
    // Algorithm 1: both roots of F in (0, 1), both slice saddles inside the face
    EXPECT_GT(r.interior.t1, 0.0);
    EXPECT_LT(r.interior.t2, 1.0);
    for (double x : {r.interior.saddle1[0], r.interior.saddle1[1], r.interior.saddle2[0], r.interior.saddle2[1]}) {
        EXPECT_GT(x, 0.0);
        EXPECT_LT(x, 1.0);
    }
    const cmc33::MeshTopology t = cmc33::mesh_topology(r.mesh);
    const cmc33::FieldTopology f = field_of(kAppendixA, 0.0);
    ASSERT_TRUE(f.determined) << f.why;
    EXPECT_EQ(t.euler, f.euler);
    EXPECT_EQ(t.components, f.b0);
    EXPECT_EQ(t.components, 2); // a tunnel and a separate disc
    EXPECT_EQ(t.euler, 1);
}

TEST(AppendixA, LewinerMissesItByBothRoutes)
{
    const cmc33::CellReport r = cmc33::analyze_cell(kAppendixA, 0.0, Method::mc33_lewiner);
    EXPECT_EQ(cmc33::subcase_name(r.subcase), "13.5.1");
    // Chernyaev's route: a = 0.3296 > 0, so condition (i) fails. (The paper prints b = -0.4886 and
    // c = 0.1701; its own corner values give b = -0.4884 and c = 0.1773.)
    EXPECT_NEAR(r.interior.a, 0.3296, 2e-4);
    EXPECT_GT(r.interior.a, 0.0);
    EXPECT_NEAR(r.interior.b, -0.4886, 5e-4);
    EXPECT_NEAR(r.interior.c, 0.1773, 1e-4);
    // Lewiner's route: t_alt = A0 / (A0 - A1) = 0.1756, F(t_alt) = -0.0007 < 0: condition (iii) fails.
    EXPECT_NEAR(r.interior.t_alt, 0.1756, 2e-4);
    EXPECT_NEAR(r.interior.f_t_alt, -0.0007, 1e-4);
    EXPECT_LT(r.interior.f_t_alt, 0.0);
    EXPECT_FALSE(r.interior.tunnel);
}

TEST(AppendixA, ChernyaevMissesItByConditionI)
{
    // Issue I: on case 13.5 Chernyaev's own conditions run on the sweep of Appendix A; a > 0 fails (i)
    const cmc33::CellReport r = cmc33::analyze_cell(kAppendixA, 0.0, Method::chernyaev);
    EXPECT_EQ(cmc33::subcase_name(r.subcase), "13.5.1");
    EXPECT_NEAR(r.interior.a, 0.3296, 2e-4);
    EXPECT_FALSE(r.interior.tunnel);
    EXPECT_FALSE(r.interior.skipped);
}

// chernyaev is cmc33's policy but for case 13.5 (Issue I): on random cells the two decide alike
// everywhere else, including the joined branch of cases 10 and 12 that mc33-lewiner skips. In 13.5
// Chernyaev's conditions err both ways (C13 Sec. 5.1: 13.5.2 taken for 13.5.1 and the reverse),
// and where they do the field's topology (independent of the kernel) sides with cmc33.
TEST(Methods, ChernyaevDiffersFromCmc33OnlyInCase13_5)
{
    std::mt19937_64 rng(1995);
    std::uniform_real_distribution<double> u(-1, 1);
    int case13_5 = 0, missed = 0, invented = 0, joined_branch = 0;
    for (int n = 0; n < 300000; ++n) {
        std::array<double, 8> v{};
        unsigned config = 0;
        // case-13 configurations with magnitudes near one level (where 13.5.2 lives), and uniform cells
        const bool near = n % 2 == 0;
        const double level = 0.2 + 0.8 * std::abs(u(rng));
        for (int c = 0; c < 8; ++c) {
            const int sign = near ? (((0x69u >> c) & 1u) ? 1 : -1) : 0;
            v[static_cast<std::size_t>(c)] = near ? sign * level * (1 + 0.3 * u(rng)) : u(rng);
            config |= static_cast<unsigned>(v[static_cast<std::size_t>(c)] >= 0) << c;
        }
        if (config == 0 || config == 255) continue;
        const auto ours = cmc33::detail::decide(v.data(), 0.0, config, Method::cmc33);
        const auto his = cmc33::detail::decide(v.data(), 0.0, config, Method::chernyaev, cmc33::detail::kLegacyVariants);
        joined_branch += (ours.variant->lewiner & cmc33::detail::kLewinerSkips) != 0;
        if (ours.variant->test != cmc33::detail::kTest13_5) {
            ASSERT_EQ(ours.subcase, his.subcase) << "config " << config;
            ASSERT_EQ(ours.tiling, his.tiling) << "config " << config;
            continue;
        }
        ++case13_5;
        if (ours.subcase == his.subcase) continue;
        const cmc33::FieldTopology f = field_of(v, 0.0);
        ASSERT_TRUE(f.determined) << f.why;
        // 13.5.2 is one tube and a disc (euler 1); 13.5.1 three discs (euler 3)
        EXPECT_EQ(f.euler, ours.tiling != 0 ? 1 : 3);
        missed += ours.tiling != 0;
        invented += ours.tiling == 0;
    }
    EXPECT_GT(case13_5, 1000);
    EXPECT_GT(joined_branch, 100);
    EXPECT_GT(missed, 0) << "13.5.2 taken for 13.5.1";
    EXPECT_GT(invented, 0) << "13.5.1 taken for 13.5.2";
}

TEST(Methods, McNeverTestsAndLewinerSkipsTheJoinedBranch)
{
    // Case 10 with both faces joined: cmc33 tests the interior, mc33-lewiner does not (Sec. 5.4).
    int skipped = 0;
    for (const auto& cell : kCells) {
        const auto mc = cmc33::analyze_cell(cell.values, 0.0, Method::mc);
        EXPECT_FALSE(mc.interior.tested);
        for (const auto& f : mc.faces) EXPECT_FALSE(f.used);
        const auto neg = cell.values;
        std::array<double, 8> flipped{};
        for (int c = 0; c < 8; ++c) flipped[static_cast<std::size_t>(c)] = -neg[static_cast<std::size_t>(c)] - 1e-9;
        const auto lw = cmc33::analyze_cell(flipped, 0.0, Method::mc33_lewiner);
        skipped += lw.interior.skipped;
    }
    EXPECT_GE(skipped, 1); // the complement of 10.1.x / 12.1.x lands on the joined branch
}

// Algorithm 2 of the paper (Sec. 6.4, case 10; the same holds for case 12): with both ambiguous
// faces joined, cmc33 runs the interior test (lines 16-20, which the original implementation
// replaced by "case 10.1.1") and finds x.1.2 where the field has a tunnel; mc33-lewiner never tests
// and always answers x.1.1. The kernel (detail::algorithm2 through detail::decide) is checked
// against the independent field topology on random cells of that branch.
TEST(Algorithm2, TheJoinedBranchOfCases10And12IsTestedByCmc33AndSkippedByLewiner)
{
    std::mt19937_64 rng(2013);
    std::uniform_real_distribution<double> u(-1, 1);
    int branch = 0, tunnels = 0;
    for (int n = 0; n < 400000 && branch < 400; ++n) {
        std::array<double, 8> v{};
        unsigned config = 0;
        for (int c = 0; c < 8; ++c) {
            v[static_cast<std::size_t>(c)] = u(rng);
            config |= static_cast<unsigned>(v[static_cast<std::size_t>(c)] >= 0) << c;
        }
        const int base = cmc33::detail::kBaseCase[config];
        if (base != 10 && base != 12) continue;
        const cmc33::detail::Decision d = cmc33::detail::decide(v.data(), 0.0, config, Method::cmc33);
        if (!(d.variant->lewiner & cmc33::detail::kLewinerSkips)) continue;
        ++branch;
        const cmc33::CellReport lw = cmc33::analyze_cell(v, 0.0, Method::mc33_lewiner);
        EXPECT_TRUE(lw.interior.skipped);
        EXPECT_FALSE(lw.interior.tunnel);
        EXPECT_EQ(lw.subcase, d.variant->subcase); // x.1.1 always
        const cmc33::CellReport ours = cmc33::analyze_cell(v, 0.0, Method::cmc33);
        EXPECT_EQ(ours.subcase, d.subcase);
        EXPECT_EQ(ours.interior.tunnel, d.tiling != 0);
        tunnels += d.tiling != 0;
        // the tunnel is there exactly when the trilinear level set in the cell is a tube
        const cmc33::FieldTopology f = field_of(v, 0.0);
        ASSERT_TRUE(f.determined) << f.why;
        EXPECT_EQ(f.euler == 0, d.tiling != 0) << "case " << base << " config " << config;
        EXPECT_EQ(cmc33::mesh_topology(ours.mesh).euler, f.euler);
    }
    EXPECT_GE(branch, 100) << "too few cells on the joined branch";
    EXPECT_GT(tunnels, 0) << "no x.1.2 found: the branch would look untested";
    EXPECT_LT(tunnels, branch) << "only x.1.2 found";
}

// analyze_cell's mesh is extract() of the cell as a 2x2x2 grid: the same code, so the same bytes.
TEST(AnalyzeCell, ItsMeshIsExtractOfTheCell)
{
    for (const auto& cell : kCells) {
        for (const Method m : {Method::cmc33, Method::mc33_lewiner, Method::mc, Method::chernyaev}) {
            const cmc33::CellReport r = cmc33::analyze_cell(cell.values, 0.0, m);
            cmc33::ExtractOptions o;
            o.method = m;
            o.threads = 1;
            cmc33::ExtractStats stats;
            const cmc33::Mesh e =
                cmc33::extract(cmc33::GridView<double>::dense(cell.values.data(), {2, 2, 2}), 0.0, o, &stats);
            EXPECT_EQ(r.mesh.positions, e.positions) << cell.subcase;
            EXPECT_EQ(r.mesh.triangles, e.triangles) << cell.subcase;
            if (r.config != 0 && r.config != 255) {
                EXPECT_EQ(stats.cells_per_subcase[static_cast<std::size_t>(r.subcase)], 1) << cell.subcase;
            }
        }
    }
}

} // namespace
