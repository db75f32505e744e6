// Google Benchmark timings of field_topology() (the verifier's independent topology of the
// trilinear interpolant) on random grids: the rate of the verification suite's random campaigns.
// Items per second are grids per second; the figures per machine are in docs/performance.md.

#include <benchmark/benchmark.h>

#include <cstdint>
#include <random>
#include <vector>

#include "cmc33/topology.hpp"

namespace {

/// field_topology() on `kGrids` random n x n x n grids of samples in [-1, 1] at iso 0, in turn.
void field_topology_random(benchmark::State& state)
{
    constexpr std::size_t kGrids = 1000;
    const auto n = static_cast<std::int64_t>(state.range(0));
    const cmc33::Index3 dims{n, n, n};
    const auto samples_per_grid = static_cast<std::size_t>(n * n * n);
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<double> samples(samples_per_grid * kGrids);
    for (double& x : samples) x = u(rng);
    std::size_t g = 0;
    std::int64_t undetermined = 0;
    for (auto _ : state) {
        const auto t = cmc33::field_topology(cmc33::GridView<double>::dense(samples.data() + samples_per_grid * g, dims), 0.0);
        benchmark::DoNotOptimize(t.b0);
        undetermined += t.determined ? 0 : 1;
        g = (g + 1) % kGrids;
    }
    state.SetItemsProcessed(state.iterations());
    state.counters["undetermined"] = static_cast<double>(undetermined);
}

BENCHMARK(field_topology_random)->Arg(2)->Arg(5)->Unit(benchmark::kMicrosecond);

} // namespace
