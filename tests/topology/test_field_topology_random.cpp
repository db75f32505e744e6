// Throughput of field_topology on the random benchmarks of the verification suite (printed, not
// asserted: CI machines differ). Targets: >= 2,000 random 5x5x5 grids/s and >= 20,000 random
// single cells/s per core, in an optimised build.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <iostream>
#include <random>
#include <vector>

#include "cmc33/topology.hpp"

namespace cmc33 {
namespace {

struct Rate {
    double per_second = 0.0;
    std::int64_t undetermined = 0;
    std::int64_t components = 0;
};

Rate measure(Index3 dims, int count, std::uint64_t seed)
{
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const auto n = static_cast<std::size_t>(dims[0] * dims[1] * dims[2]);
    std::vector<double> samples(n * static_cast<std::size_t>(count));
    for (double& x : samples) x = u(rng);
    Rate rate;
    const auto start = std::chrono::steady_clock::now();
    for (int g = 0; g < count; ++g) {
        const auto t = field_topology(
            GridView<double>::dense(samples.data() + n * static_cast<std::size_t>(g), dims), 0.0);
        rate.undetermined += t.determined ? 0 : 1;
        rate.components += t.b0;
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    rate.per_second = count / seconds;
    return rate;
}

TEST(FieldTopologySpeed, RandomGridsAndCells)
{
    const Rate grids = measure({5, 5, 5}, 2000, 1);
    const Rate cells = measure({2, 2, 2}, 20000, 2);
    std::cout << "[ speed ] random 5x5x5 grids: " << static_cast<std::int64_t>(grids.per_second)
              << " /s\n";
    std::cout << "[ speed ] random single cells: " << static_cast<std::int64_t>(cells.per_second)
              << " /s\n";
    ::testing::Test::RecordProperty("grids_per_second", static_cast<int>(grids.per_second));
    ::testing::Test::RecordProperty("cells_per_second", static_cast<int>(cells.per_second));
    EXPECT_EQ(grids.undetermined, 0);
    EXPECT_EQ(cells.undetermined, 0);
    EXPECT_GT(grids.components, 0);
}

} // namespace
} // namespace cmc33
