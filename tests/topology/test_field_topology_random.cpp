// field_topology() decides every random grid and cell of the verification suite's campaigns (no
// undetermined case on 2,000 random 5x5x5 grids and 20,000 random single cells). Its speed is
// bench/bench_topology.cpp's.

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "cmc33/topology.hpp"

namespace cmc33 {
namespace {

struct Counts {
    std::int64_t undetermined = 0;
    std::int64_t components = 0;
};

Counts decide(Index3 dims, int count, std::uint64_t seed)
{
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const auto n = static_cast<std::size_t>(dims[0] * dims[1] * dims[2]);
    std::vector<double> samples(n * static_cast<std::size_t>(count));
    for (double& x : samples) x = u(rng);
    Counts counts;
    for (int g = 0; g < count; ++g) {
        const auto t = field_topology(GridView<double>::dense(samples.data() + n * static_cast<std::size_t>(g), dims), 0.0);
        counts.undetermined += t.determined ? 0 : 1;
        counts.components += t.b0;
    }
    return counts;
}

TEST(FieldTopology, EveryRandomGridAndCellIsDetermined)
{
    const Counts grids = decide({5, 5, 5}, 2000, 1);
    const Counts cells = decide({2, 2, 2}, 20000, 2);
    EXPECT_EQ(grids.undetermined, 0);
    EXPECT_EQ(cells.undetermined, 0);
    EXPECT_GT(grids.components, 0);
    EXPECT_GT(cells.components, 0);
}

} // namespace
} // namespace cmc33
