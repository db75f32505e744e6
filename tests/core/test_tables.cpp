// Properties of every generated tiling, checked from the definitions (not from the generator):
// vertices on crossed edges only, boundary = the face arcs each used once, inner edges used twice
// in opposite directions, no triangle edge inside a cell face except an arc, arcs oriented with the
// above side on the right seen from outside, Euler characteristic = discs (+0 per tube).

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <map>
#include <set>
#include <string>
#include <utility>

#include "cube.hpp"
#include "mc33_tables.hpp"
#include "test_support.hpp"

namespace {

using namespace cmc33::detail;

bool above(unsigned config, int c) { return ((config >> c) & 1u) != 0; }
bool crossed(unsigned config, int e) { return above(config, kEdgeCorners[e][0]) != above(config, kEdgeCorners[e][1]); }

std::array<int, 2> edge_faces(int e)
{
    std::array<int, 2> out{};
    int n = 0;
    for (int f = 0; f < 6; ++f) {
        const auto p = face_cycle(f);
        int hits = 0;
        for (int c : p) hits += (c == kEdgeCorners[e][0] || c == kEdgeCorners[e][1]);
        if (hits == 2) out[static_cast<std::size_t>(n++)] = f;
    }
    return out;
}

bool share_face(int a, int b)
{
    for (int fa : edge_faces(a))
        for (int fb : edge_faces(b))
            if (fa == fb) return true;
    return false;
}

int edge_between(int a, int b)
{
    for (int e = 0; e < 12; ++e)
        if ((kEdgeCorners[e][0] == a && kEdgeCorners[e][1] == b) || (kEdgeCorners[e][0] == b && kEdgeCorners[e][1] == a)) return e;
    return -1;
}

/// The arcs on face f (unordered pairs of crossed edges) given whether its above corners join.
std::set<std::pair<int, int>> face_arcs(unsigned config, int f, bool joined)
{
    std::set<std::pair<int, int>> arcs;
    const auto p = face_cycle(f);
    std::vector<int> edges;
    for (int i = 0; i < 4; ++i) {
        const int e = edge_between(p[static_cast<std::size_t>(i)], p[static_cast<std::size_t>((i + 1) % 4)]);
        if (crossed(config, e)) edges.push_back(e);
    }
    if (edges.size() == 2) arcs.insert({std::min(edges[0], edges[1]), std::max(edges[0], edges[1])});
    if (edges.size() == 4) {
        // cut off the corners of the sign that is not joined
        for (int i = 0; i < 4; ++i) {
            const int c = p[static_cast<std::size_t>(i)];
            if (above(config, c) == joined) continue;
            const int e1 = edge_between(c, p[static_cast<std::size_t>((i + 1) % 4)]);
            const int e2 = edge_between(c, p[static_cast<std::size_t>((i + 3) % 4)]);
            arcs.insert({std::min(e1, e2), std::max(e1, e2)});
        }
    }
    return arcs;
}

std::array<double, 3> mid(int e)
{
    std::array<double, 3> m{};
    for (int c = 0; c < 3; ++c) m[static_cast<std::size_t>(c)] = 0.5 * (((kEdgeCorners[e][0] >> c) & 1) + ((kEdgeCorners[e][1] >> c) & 1));
    return m;
}

/// Checks every tiling of one table set. `legacy`: kLegacyVariants, whose tubes may have chords
/// inside an ambiguous face (Chernyaev's style) and have no interior vertices.
void check_table_set(const Variant* table, bool legacy)
{
    int checked = 0;
    for (unsigned config = 1; config < 255; ++config) {
        const unsigned amb = kAmbiguousFaces[config];
        const int k = __builtin_popcount(amb);
        for (unsigned bits = 0; bits < (1u << k); ++bits) {
            std::set<std::pair<int, int>> arcs;
            std::map<std::pair<int, int>, int> arc_face;
            int i = 0;
            for (int f = 0; f < 6; ++f) {
                bool joined = false;
                if ((amb >> f) & 1u) joined = ((bits >> i++) & 1u) != 0;
                for (auto a : face_arcs(config, f, joined)) {
                    arcs.insert(a);
                    arc_face[a] = f;
                }
            }
            const Variant& var = table[kVariantOffset[config] + bits];
            const int tilings = var.test == kTestNone ? 1 : var.test == kTestTunnel ? 2 : 3;
            for (int t = 0; t < tilings; ++t) {
                SCOPED_TRACE("config " + std::to_string(config) + " bits " + std::to_string(bits) + " tiling " + std::to_string(t));
                const Tiling& tl = var.tilings[t];
                ASSERT_GT(tl.triangle_count, 0);
                ASSERT_LE(tl.interior_count, kMaxInteriorVertices);
                std::map<std::pair<int, int>, int> directed;
                std::set<int> verts;
                for (int q = 0; q < tl.triangle_count; ++q) {
                    const std::uint8_t* tri = &kTriangleCodes[(tl.first_triangle + q) * 3];
                    for (int s = 0; s < 3; ++s) {
                        const int a = tri[s], b = tri[(s + 1) % 3];
                        ASSERT_NE(a, b);
                        if (a < 12) {
                            ASSERT_TRUE(crossed(config, a)) << "vertex on uncrossed edge " << a;
                        }
                        ASSERT_LT(a, 12 + tl.interior_count);
                        verts.insert(a);
                        ++directed[{a, b}];
                        if (a < 12 && b < 12 && share_face(a, b) && !arcs.count({std::min(a, b), std::max(a, b)})) {
                            // only a legacy tube lies in a face, and only in an ambiguous one
                            ASSERT_TRUE(legacy && t > 0) << "chord inside a face " << a << "-" << b;
                            bool in_ambiguous = false;
                            for (int f : edge_faces(a))
                                for (int g : edge_faces(b)) in_ambiguous |= f == g && ((amb >> f) & 1u) != 0;
                            ASSERT_TRUE(in_ambiguous) << "legacy chord " << a << "-" << b << " outside the ambiguous faces";
                        }
                    }
                }
                int edges = 0;
                for (const auto& [e, n] : directed) {
                    ASSERT_EQ(n, 1) << "directed edge used twice";
                    const auto rev = directed.find({e.second, e.first});
                    if (rev == directed.end()) {
                        const std::pair<int, int> key{std::min(e.first, e.second), std::max(e.first, e.second)};
                        ASSERT_TRUE(arcs.count(key)) << "boundary edge " << e.first << "-" << e.second << " is not an arc";
                        // orientation: seen from outside face f, the above side is on the right
                        const int f = arc_face[key];
                        const auto pa = mid(e.first), pb = mid(e.second);
                        std::array<double, 3> toward{0, 0, 0};
                        int n_above = 0;
                        for (int c : face_cycle(f)) {
                            if (!above(config, c)) continue;
                            // only the corners on the arc's side: the nearest above corner(s)
                            ++n_above;
                            for (int x = 0; x < 3; ++x) toward[static_cast<std::size_t>(x)] += (c >> x) & 1;
                        }
                        const std::array<double, 3> m{(pa[0] + pb[0]) / 2, (pa[1] + pb[1]) / 2, (pa[2] + pb[2]) / 2};
                        std::array<double, 3> w{}, d{};
                        for (int x = 0; x < 3; ++x) {
                            w[static_cast<std::size_t>(x)] = toward[static_cast<std::size_t>(x)] / n_above - m[static_cast<std::size_t>(x)];
                            d[static_cast<std::size_t>(x)] = pb[static_cast<std::size_t>(x)] - pa[static_cast<std::size_t>(x)];
                        }
                        std::array<double, 3> normal{0, 0, 0};
                        normal[static_cast<std::size_t>(f / 2)] = f % 2 ? 1 : -1;
                        const double cross_dot = (d[1] * w[2] - d[2] * w[1]) * normal[0] + (d[2] * w[0] - d[0] * w[2]) * normal[1] +
                                                 (d[0] * w[1] - d[1] * w[0]) * normal[2];
                        // with two diagonal above corners the centroid is the face centre; use the
                        // cut-off corner side instead (checked through the non-ambiguous faces below)
                        if (n_above != 2 || !((kAmbiguousFaces[config] >> f) & 1u)) {
                            ASSERT_LT(cross_dot, 0) << "arc " << e.first << "->" << e.second << " on face " << f << " is reversed";
                        }
                        ++edges; // boundary edge
                    } else if (e.first < e.second) {
                        ++edges;
                    }
                }
                for (const auto& a : arcs) {
                    ASSERT_EQ(directed.count(a) + directed.count({a.second, a.first}), 1u) << "arc used " << a.first << "-" << a.second;
                }
                // Euler characteristic: each disc 1, each tube 0
                const int euler = static_cast<int>(verts.size()) - edges + tl.triangle_count;
                int loops = 0;
                {
                    std::map<int, int> next;
                    for (const auto& [e, n] : directed)
                        if (!directed.count({e.second, e.first})) next[e.first] = e.second;
                    std::set<int> seen;
                    for (const auto& [s, unused] : next) {
                        (void)unused;
                        if (seen.count(s)) continue;
                        ++loops;
                        for (int x = s; !seen.count(x); x = next[x]) seen.insert(x);
                    }
                }
                EXPECT_EQ(euler, t == 0 ? loops : loops - 2);
                if (legacy && t > 0) {
                    EXPECT_EQ(tl.interior_count, 0) << "a legacy tube joins the loops directly";
                }
                ++checked;
            }
        }
    }
    EXPECT_GT(checked, 700);
}

TEST(Tables, EveryTilingIsAManifoldPatchBoundedByTheFaceArcs)
{
    check_table_set(kVariants, false);
}

TEST(Tables, EveryLegacyTilingIsAManifoldPatchBoundedByTheFaceArcs)
{
    check_table_set(kLegacyVariants, true);
}

/// Faces f such that a triangle of the tiling has its three vertices on edges of f.
unsigned faces_holding_a_triangle(const Tiling& tl)
{
    unsigned faces = 0;
    for (int q = 0; q < tl.triangle_count; ++q) {
        const std::uint8_t* tri = &kTriangleCodes[(tl.first_triangle + q) * 3];
        if (tri[0] >= 12 || tri[1] >= 12 || tri[2] >= 12) continue;
        for (int f : edge_faces(tri[0]))
            for (int g : edge_faces(tri[1]))
                for (int h : edge_faces(tri[2]))
                    if (f == g && g == h) faces |= 1u << f;
    }
    return faces;
}

// The two sets differ exactly in the tubes (Issue II of Custodio et al. 2013): the legacy tube of
// every tunnel subcase that crosses an ambiguous face lies in that face (Fig. 8, bottom: "each has
// a face that is coplanar to the voxel faces"); 4.1.2, whose tube runs along the cell's diagonal
// and crosses no ambiguous face, never does; no other tiling of either set lies in a face.
TEST(Tables, LegacyTubesLieInAFaceWhereTheEmbeddedOnesNeverDo)
{
    std::map<std::string, int> in_face, tubes;
    for (unsigned config = 0; config < 256; ++config) {
        for (unsigned v = kVariantOffset[config]; v < kVariantOffset[config + 1]; ++v) {
            const Variant& e = kVariants[v];
            const Variant& l = kLegacyVariants[v];
            const auto decisions = [](const Variant& x) {
                return std::array<int, 9>{x.subcase, x.tunnel_subcase, x.test, x.axis, x.corner, x.lewiner_axis,
                                          x.lewiner_corner, x.lewiner_edge, x.lewiner};
            };
            ASSERT_EQ(decisions(e), decisions(l)) << "variant " << v << ": the decisions' fields differ";
            const int tilings = e.test == kTestNone ? 1 : e.test == kTestTunnel ? 2 : 3;
            for (int t = 0; t < 3; ++t) {
                EXPECT_EQ(faces_holding_a_triangle(e.tilings[t]), 0u) << "variant " << v;
                if (t == 0 || t >= tilings) {
                    const auto same = [](const Tiling& a, const Tiling& b) {
                        return a.triangle_count == b.triangle_count && a.interior_count == b.interior_count &&
                               a.first_triangle == b.first_triangle && a.first_interior == b.first_interior;
                    };
                    EXPECT_TRUE(same(e.tilings[t], l.tilings[t])) << "variant " << v << " tiling " << t;
                    continue;
                }
                const std::string name = std::string(kSubcaseNames[e.tunnel_subcase]);
                const unsigned faces = faces_holding_a_triangle(l.tilings[t]);
                EXPECT_EQ(faces & ~static_cast<unsigned>(kAmbiguousFaces[config]), 0u) << "variant " << v;
                ++tubes[name];
                in_face[name] += faces != 0;
            }
        }
    }
    for (const char* name : {"6.1.2", "7.4.2", "10.1.2", "12.1.2", "13.5.2"}) {
        EXPECT_GT(tubes[name], 0) << name;
        EXPECT_EQ(in_face[name], tubes[name]) << name << ": every legacy tube crosses its ambiguous face in it";
    }
    EXPECT_GT(tubes["4.1.2"], 0);
    EXPECT_EQ(in_face["4.1.2"], 0);
}

TEST(Tables, BaseCasesFollowTheSignConfigurationCounts)
{
    // Each base case covers a fixed number of the 256 configurations (rotations and complement).
    std::array<int, 15> count{};
    for (int c = 0; c < 256; ++c) ++count[kBaseCase[c]];
    const std::array<int, 15> expected{2, 16, 24, 24, 8, 48, 48, 16, 6, 8, 6, 12, 24, 2, 12};
    EXPECT_EQ(count, expected);
}

TEST(Tables, GeneratedFileIsCurrent)
{
#ifndef CMC33_PYTHON
    FAIL() << "no Python 3 was found when configuring, so " CMC33_GENERATED " cannot be checked against "
           << CMC33_GENERATOR << ": install python3 and configure again";
#else
    const auto out = cmc33::test::temp_dir() / "tables.cpp";
    const std::string cmd = std::string(CMC33_PYTHON) + " " + CMC33_GENERATOR + " > " + out.string() + " 2>/dev/null";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    EXPECT_EQ(cmc33::test::read_file(out), cmc33::test::read_file(CMC33_GENERATED))
        << "src/tables/mc33_tables.cpp differs from what tools/gen_tables/gen_tables.py writes: regenerate it";
#endif
}

} // namespace
