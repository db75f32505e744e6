// The stress test shows each flaw of Custodio et al. 2013 (C13) where the paper puts it, and no
// other: on single cells, chernyaev's topology goes wrong only in case 13.5 (Issue I) and
// mc33-lewiner's only in cases 6, 7, 10, 12 and 13 (Issues III, IV and I); on the paper's random
// 5x5x5 grids both legacy methods give non-manifold meshes (Issue II, Sec. 5.2), and their
// non-manifold meshes are exactly those not embedded (two tubes meeting in a face); cmc33-paper
// (C13's C-MC33, with the Sec. 6.2 refinement) and cmc33 match everywhere. Label stress: a few
// seconds in Release on 2 cores.

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "cmc33/verify.hpp"

namespace {

using namespace cmc33;

TEST(PaperClaims, EachFlawWhereThePaperPutsIt)
{
    VerifyOptions o;
    o.methods = {Method::cmc33, Method::cmc33_paper, Method::chernyaev, Method::mc33_lewiner};
    o.cells = 20000;
    o.grids = 6000;
    o.ties = 1000;
    o.seed = 1;
    o.threads = 2;
    const VerifyReport r = verify(o);
    ASSERT_EQ(r.methods.size(), 4u);
    for (const MethodReport& m : r.methods) {
        SCOPED_TRACE(m.name);
        EXPECT_EQ(m.undetermined, 0);
        EXPECT_EQ(m.errors, 0);
        // the subcases whose cells may mismatch, by the base case of the subcase's name
        std::set<std::string> allowed_cases;
        if (m.method == Method::chernyaev) allowed_cases = {"13"};
        if (m.method == Method::mc33_lewiner) allowed_cases = {"6", "7", "10", "12", "13"};
        for (int s = 0; s < kSubcaseCount; ++s) {
            const std::string name(subcase_name(s));
            const std::string base = name.substr(0, name.find('.'));
            const auto i = static_cast<std::size_t>(s);
            if (!allowed_cases.count(base)) {
                EXPECT_EQ(m.cell_topology_mismatches_per_subcase[i], 0) << "subcase " << name;
            }
            if (m.method == Method::chernyaev && base == "13" && name.rfind("13.5", 0) != 0) {
                EXPECT_EQ(m.cell_topology_mismatches_per_subcase[i], 0) << "subcase " << name;
            }
        }
        if (m.method == Method::cmc33 || m.method == Method::cmc33_paper) {
            EXPECT_EQ(m.mismatched, 0);
            EXPECT_EQ(m.topology_mismatched, 0);
            EXPECT_EQ(m.nonmanifold, 0);
            continue;
        }
        EXPECT_GT(m.topology_mismatched_by_kind[0], 0) << "cells";
        EXPECT_GT(m.nonmanifold, 0) << "no two tunnels met in a face";
        EXPECT_EQ(m.nonmanifold, m.not_embedded);
    }
    const MethodReport& chernyaev = r.methods[2];
    const MethodReport& lewiner = r.methods[3];
    const auto cells = [](const MethodReport& m, const char* name) {
        for (int s = 0; s < kSubcaseCount; ++s)
            if (subcase_name(s) == name) return m.cell_topology_mismatches_per_subcase[static_cast<std::size_t>(s)];
        return std::int64_t{-1};
    };
    EXPECT_GT(cells(chernyaev, "13.5.1"), 0);
    // Issue III: the tunnels t_alt misses; Issue IV: cases 10 and 12 with both faces joined
    for (const char* name : {"6.1.1", "7.4.1", "10.1.1", "12.1.1", "13.5.1"}) EXPECT_GT(cells(lewiner, name), 0) << name;
}

} // namespace
