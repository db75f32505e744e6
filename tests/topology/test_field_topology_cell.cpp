// Inside the field-topology verifier: exact arithmetic, the loop table, the exact interior
// analysis against the refinement and against a brute-force digital count.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <random>
#include <vector>

#include "cmc33/topology.hpp"
#include "field_cell.hpp"
#include "field_exact.hpp"

namespace cmc33::topology::detail {
namespace {

// ----------------------------------------------------------------------------------------------
// Exact arithmetic

template <class Num> Num make(double x);
template <> Approx make<Approx>(double x)
{
    return {x, 0.0};
}
template <> Expansion make<Expansion>(double x)
{
    return Expansion(x);
}

TEST(FieldExact, ExpansionsAreExactWhereDoublesRound)
{
    const Expansion big(1e16);
    const Expansion one(1.0);
    EXPECT_EQ(((big + one) - big).sign(), 1);
    EXPECT_EQ(((big + one) - big - one).sign(), 0);
    EXPECT_EQ(Expansion::difference(0.1, 0.1).sign(), 0);
    EXPECT_EQ(Expansion::difference(1.0, 1.0 + 0x1p-52).sign(), -1);
    // 0.1 - 0.3 + 0.2 in doubles is not 0, but as the exact sum of these three doubles it is
    // whatever their binary values make it: compare with the exact integer mantissa sum.
    const Expansion x = Expansion(0.1) - Expansion(0.3) + Expansion(0.2);
    EXPECT_EQ(x.sign(),
              1); // 0.1 + 0.2 rounds up in binary: 0.1000...055 + 0.2000...011 > 0.299...989
}

TEST(FieldExact, PolynomialIdentitiesVanishExactly)
{
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
    std::uniform_int_distribution<int> exponent(-40, 40);
    for (int trial = 0; trial < 2000; ++trial) {
        const double a = std::ldexp(mantissa(rng), exponent(rng));
        const double b = std::ldexp(mantissa(rng), exponent(rng));
        const double c = std::ldexp(mantissa(rng), exponent(rng));
        const Expansion ea(a), eb(b), ec(c);
        const Expansion square =
            (ea + eb) * (ea + eb) - ea * ea - Expansion(2.0) * ea * eb - eb * eb;
        EXPECT_EQ(square.sign(), 0) << a << " " << b;
        const Expansion assoc = (ea * eb) * ec - ea * (eb * ec);
        EXPECT_EQ(assoc.sign(), 0);
        const Expansion diff = Expansion::difference(a, c) * Expansion::difference(b, c) - ea * eb +
                               ec * (ea + eb) - ec * ec;
        EXPECT_EQ(diff.sign(), 0);
        EXPECT_FALSE(diff.lost());
    }
}

__extension__ typedef __int128 Int128; // exact products of 40-bit integers

TEST(FieldExact, SignsMatchIntegerArithmetic)
{
    // a*b - c*d on 40-bit integers: doubles round the products, __int128 does not.
    std::mt19937_64 rng(2);
    std::uniform_int_distribution<std::int64_t> u(-(std::int64_t{1} << 40), std::int64_t{1} << 40);
    for (int trial = 0; trial < 5000; ++trial) {
        const std::int64_t a = u(rng), b = u(rng), c = u(rng);
        const std::int64_t d = trial % 2 == 0 ? u(rng) : a; // make ties when c == b
        const std::int64_t cc = trial % 4 == 1 ? b : c;
        const Int128 exact = static_cast<Int128>(a) * b - static_cast<Int128>(cc) * d;
        const int want = exact > 0 ? 1 : (exact < 0 ? -1 : 0);
        Numerics numerics;
        const auto da = static_cast<double>(a), db = static_cast<double>(b);
        const auto dc = static_cast<double>(cc), dd = static_cast<double>(d);
        const int got = exact_sign(
            [&]<class Num>() {
                return make<Num>(da) * make<Num>(db) - make<Num>(dc) * make<Num>(dd);
            },
            numerics);
        ASSERT_EQ(got, want) << a << " " << b << " " << cc << " " << d;
        EXPECT_FALSE(numerics.lost);
    }
}

TEST(FieldExact, OverflowIsReportedAsLost)
{
    Numerics numerics;
    const int s = exact_sign(
        [&]<class Num>() {
            return make<Num>(1e300) * make<Num>(1e300) - make<Num>(1e300) * make<Num>(1e300);
        },
        numerics);
    (void)s;
    EXPECT_TRUE(numerics.lost);
}

// ----------------------------------------------------------------------------------------------
// Loops on the cell boundary

int loops_of(unsigned code, unsigned bits)
{
    return cell_loops(code, bits).loops;
}

TEST(FieldCellLoops, KnownConfigurations)
{
    EXPECT_EQ(loops_of(0x00, 0), 0);
    EXPECT_EQ(loops_of(0x01, 0), 1);       // one corner
    EXPECT_EQ(loops_of(0x03, 0), 1);       // one edge
    EXPECT_EQ(loops_of(0x81, 0), 2);       // opposite corners 0, 7
    EXPECT_EQ(loops_of(0x09, 0), 2);       // 0, 3 diagonal on the bottom face, separated
    EXPECT_EQ(loops_of(0x09, 1u << 4), 1); // ... joined by the bottom face
    EXPECT_EQ(loops_of(0x69, 0), 4);       // case 13, every above corner cut off
    EXPECT_EQ(loops_of(0x69, 63), 4);      // case 13, every below corner cut off
    EXPECT_EQ(ambiguous_faces(0x69), 63u);
    EXPECT_EQ(ambiguous_faces(0x81), 0u);
    EXPECT_EQ(ambiguous_faces(0x09), 1u << 4);
}

TEST(FieldCellLoops, ComplementSwapsTheFaceDecisions)
{
    for (unsigned code = 0; code < 256; ++code) {
        const unsigned ambiguous = ambiguous_faces(code);
        ASSERT_EQ(ambiguous_faces(255u - code), ambiguous);
        for (unsigned bits = 0; bits < 64; ++bits) {
            if ((bits & ~ambiguous) != 0) continue;
            const CellLoops& a = cell_loops(code, bits);
            const CellLoops& b = cell_loops(255u - code, ambiguous & ~bits);
            ASSERT_EQ(a.loops, b.loops) << code << " " << bits;
            for (int e = 0; e < 12; ++e) {
                for (int f = 0; f < 12; ++f) {
                    if (a.loop_of_edge[e] < 0 || a.loop_of_edge[f] < 0) continue;
                    ASSERT_EQ(a.loop_of_edge[e] == a.loop_of_edge[f],
                              b.loop_of_edge[e] == b.loop_of_edge[f]);
                }
            }
        }
    }
}

TEST(FieldCellLoops, EveryCrossedEdgeIsOnExactlyTwoArcs)
{
    for (unsigned code = 0; code < 256; ++code) {
        const unsigned ambiguous = ambiguous_faces(code);
        for (unsigned bits = 0; bits < 64; ++bits) {
            if ((bits & ~ambiguous) != 0) continue;
            int uses[12] = {};
            for (int f = 0; f < 6; ++f) {
                int arcs[2][2];
                const int n = face_arcs(code, f, ((bits >> f) & 1u) != 0, arcs);
                for (int a = 0; a < n; ++a) {
                    ++uses[arcs[a][0]];
                    ++uses[arcs[a][1]];
                }
            }
            const unsigned crossed = crossed_edges(code);
            for (int e = 0; e < 12; ++e)
                ASSERT_EQ(uses[e], ((crossed >> e) & 1u) ? 2 : 0) << code << " " << e;
        }
    }
}

// ----------------------------------------------------------------------------------------------
// Interior analysis

CellInput random_cell(std::mt19937_64& rng, int flavour)
{
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::uniform_real_distribution<double> mag(-3.0, 0.0);
    CellInput in;
    const unsigned pattern =
        flavour == 1 ? 0x69u : (flavour == 2 ? 0x81u : (flavour == 3 ? 0x18u : 0u));
    for (int c = 0; c < 8; ++c) {
        if (flavour == 0) {
            in.v[c] = u(rng);
        } else {
            in.v[c] = (((pattern >> c) & 1u) ? 1.0 : -1.0) * std::pow(10.0, mag(rng));
        }
    }
    return in;
}

TEST(FieldCellInterior, ExactAnalysisAgreesWithRefinementOnRandomCells)
{
    std::mt19937_64 rng(42);
    int analysed = 0;
    int checked = 0;
    int tubes = 0;
    for (int trial = 0; trial < 24000; ++trial) {
        const CellInput in = random_cell(rng, trial % 4);
        Numerics numerics;
        const unsigned code = cell_code(in);
        const unsigned bits = face_decisions(in, code, numerics);
        if (cell_loops(code, bits).loops < 2) continue;
        const CellPieces p = cell_pieces(in, code, bits, 256, numerics);
        ASSERT_EQ(p.status, CellPieces::Status::ok)
            << "trial " << trial << ": euler " << p.euler << " vs " << p.refined_euler
            << ", pieces " << p.pieces << " vs " << p.refined_pieces;
        ++analysed;
        checked += p.cross_checked ? 1 : 0;
        tubes += p.pieces < p.loops ? 1 : 0;
    }
    std::cout << "[ info ] cells with >= 2 loops: " << analysed
              << ", settled by refinement: " << checked << ", with a tube: " << tubes << "\n";
    EXPECT_GT(analysed, 9000);
    EXPECT_GT(tubes, 600);
    EXPECT_GE(checked * 1000, analysed * 995); // all but near-ties settle by r = 256
}

TEST(FieldCellInterior, RefinementNeedsDepthOnlyNearTies)
{
    // Corners 0 and 7 above (1 and 0.7), the rest at -d: a tube for small d, two discs for large
    // d. Find the threshold with the exact analysis, then look just below it.
    auto in_for = [](double d) {
        CellInput in;
        for (int c = 0; c < 8; ++c) in.v[c] = c == 0 ? 1.0 : (c == 7 ? 0.7 : -d);
        return in;
    };
    auto exact_pieces = [](const CellInput& in) {
        Numerics numerics;
        const CellPieces p = cell_pieces(in, cell_code(in), 0, 0, numerics);
        EXPECT_EQ(p.status, CellPieces::Status::ok);
        return p.pieces;
    };
    double lo = 0.1;
    double hi = 0.9;
    ASSERT_EQ(exact_pieces(in_for(lo)), 1);
    ASSERT_EQ(exact_pieces(in_for(hi)), 2);
    for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (exact_pieces(in_for(mid)) == 1 ? lo : hi) = mid;
    }
    Numerics numerics;
    const CellInput near = in_for(lo - 1e-4);
    EXPECT_FALSE(refine_cell(near, 4, numerics).resolved);
    const RefinedCell deep = refine_cell(near, 1024, numerics);
    ASSERT_TRUE(deep.resolved);
    EXPECT_EQ(deep.pieces, 1);
    EXPECT_EQ(deep.euler, 0);
    const RefinedCell apart = refine_cell(in_for(hi + 1e-4), 1024, numerics);
    ASSERT_TRUE(apart.resolved);
    EXPECT_EQ(apart.pieces, 2);
    EXPECT_EQ(apart.euler, 2);
    EXPECT_FALSE(numerics.lost);
}

TEST(FieldCellInterior, ALineOfCriticalPointsAtIsoIsDecidedExactly)
{
    // 9 (x - 1/3)(y - 1/3), constant in z: a vertical line of saddles at x = y = 1/3 exactly at
    // iso 0. By the sign rule the saddles are above: the above corners (0,0) and (1,1) are joined,
    // and S is two sheets, each a disc around one below column. Every sub-box that meets the line
    // keeps two loops, so refinement never settles; the exact analysis does.
    CellInput in;
    const double bottom[4] = {1.0, -2.0, -2.0, 4.0};
    for (int c = 0; c < 8; ++c) in.v[c] = bottom[c & 3];
    Numerics numerics;
    EXPECT_FALSE(refine_cell(in, 1024, numerics).resolved);
    const unsigned code = cell_code(in);
    const unsigned bits = face_decisions(in, code, numerics);
    EXPECT_EQ(bits, (1u << 4) | (1u << 5)); // top and bottom faces: saddle value 0 counts as above
    const CellPieces p = cell_pieces(in, code, bits, 1024, numerics);
    EXPECT_EQ(p.status, CellPieces::Status::ok);
    EXPECT_FALSE(p.cross_checked);
    EXPECT_EQ(p.loops, 2);
    EXPECT_EQ(p.pieces, 2);
    EXPECT_EQ(p.euler, 2);
    EXPECT_FALSE(numerics.lost);
}

TEST(FieldCellInterior, PointAndSliceSignsAreExactAtTies)
{
    CellInput in;
    for (int c = 0; c < 8; ++c) in.v[c] = (c == 0 || c == 7) ? 3.0 : -1.0;
    Numerics numerics;
    // Centre: (3 + 3 - 6) / 8 = 0 exactly.
    EXPECT_EQ(point_sign(in, 1, 1, 1, 1, numerics), 0);
    // Slice z = 1/2: corner values 1, -1, -1, 1: numerator 1 - 1 = 0.
    EXPECT_EQ(slice_numerator_sign(in, 2, 0.5, numerics), 0);
    EXPECT_EQ(slice_numerator_sign(in, 2, 0.25, numerics), -1);
    in.iso = 0.1; // a value that is not a binary fraction
    in.v[0] = 0.1;
    EXPECT_EQ(point_sign(in, 0, 0, 0, 3, numerics), 0);
    EXPECT_FALSE(numerics.lost);
}

// A brute-force count independent of everything above: sample the cell on a fine lattice with
// plain doubles and count 6-connected components of the above and below samples; the pieces are
// U + L - 1 (a tree). Digital connectivity can miss a passage thinner than the lattice, so a
// coarse mismatch is recounted on a finer lattice; only a mismatch that persists is a failure.
int digital_pieces(const CellInput& in, int r)
{
    const int n = r + 1;
    std::vector<signed char> side(static_cast<std::size_t>(n * n * n));
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const double fx = x / static_cast<double>(r), fy = y / static_cast<double>(r),
                             fz = z / static_cast<double>(r);
                double v = 0.0;
                for (int c = 0; c < 8; ++c) {
                    v += ((c & 1) ? fx : 1 - fx) * ((c & 2) ? fy : 1 - fy) *
                         ((c & 4) ? fz : 1 - fz) * in.v[c];
                }
                side[static_cast<std::size_t>(x + n * (y + n * z))] = v >= in.iso ? 1 : 0;
            }
    std::vector<int> label(side.size(), -1);
    std::vector<int> stack;
    int components = 0;
    for (std::size_t s = 0; s < side.size(); ++s) {
        if (label[s] >= 0) continue;
        label[s] = components;
        stack.assign(1, static_cast<int>(s));
        while (!stack.empty()) {
            const int p = stack.back();
            stack.pop_back();
            const int x = p % n, y = (p / n) % n, z = p / (n * n);
            const int nb[6][3] = {{x - 1, y, z}, {x + 1, y, z}, {x, y - 1, z},
                                  {x, y + 1, z}, {x, y, z - 1}, {x, y, z + 1}};
            for (const auto& q : nb) {
                if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= n || q[1] >= n || q[2] >= n) {
                    continue;
                }
                const auto qi = static_cast<std::size_t>(q[0] + n * (q[1] + n * q[2]));
                if (label[qi] < 0 && side[qi] == side[s]) {
                    label[qi] = components;
                    stack.push_back(static_cast<int>(qi));
                }
            }
        }
        ++components;
    }
    return components - 1;
}

TEST(FieldCellInterior, PiecesMatchABruteForceDigitalCount)
{
    std::mt19937_64 rng(9);
    int compared = 0;
    int coarse_mismatches = 0;
    for (int trial = 0; trial < 1200 && compared < 300; ++trial) {
        const CellInput in = random_cell(rng, trial % 4);
        Numerics numerics;
        const unsigned code = cell_code(in);
        if (code == 0 || code == 255) continue;
        const unsigned bits = face_decisions(in, code, numerics);
        const CellLoops& loops = cell_loops(code, bits);
        const int pieces = loops.loops < 2 ? 1 : cell_pieces(in, code, bits, 0, numerics).pieces;
        ++compared;
        if (digital_pieces(in, 32) == pieces) continue;
        ++coarse_mismatches;
        EXPECT_EQ(digital_pieces(in, 128), pieces) << "trial " << trial;
    }
    std::cout << "[ info ] digital oracle: " << coarse_mismatches << " of " << compared
              << " cells needed the finer lattice\n";
    EXPECT_EQ(compared, 300);
    EXPECT_LE(coarse_mismatches, 10);
}

} // namespace
} // namespace cmc33::topology::detail
