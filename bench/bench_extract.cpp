// cmc33_bench: Google Benchmark timings of cmc33::extract on synthetic volumes made in memory.
//
// Every (volume, method, threads) combination is one benchmark named
// extract/<volume>/<method>/threads:<n>. Time is wall-clock (the extractor runs its own threads),
// items/s is grid cells per second, and the counters give the mesh's size. Standard Google
// Benchmark flags apply, e.g. --benchmark_filter=sines --benchmark_repetitions=5.

#include <benchmark/benchmark.h>

#include <cstdint>
#include <exception>
#include <iostream>
#include <memory>
#include <string>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/volume.hpp"
#include "synthetic_fields.hpp"

namespace {

struct Field {
    std::string name;
    double iso = 0;
    std::shared_ptr<const cmc33::Volume> volume; // made once, shared by the field's benchmarks
};

std::int64_t cell_count(const cmc33::Volume& volume)
{
    const cmc33::Index3& d = volume.dims();
    return (d[0] - 1) * (d[1] - 1) * (d[2] - 1);
}

void run_extract(benchmark::State& state, const Field& field, cmc33::Method method, int threads)
{
    const cmc33::ExtractOptions options{method, false, threads};
    std::size_t vertices = 0, triangles = 0;
    for (auto _ : state) {
        cmc33::Mesh mesh = cmc33::extract(*field.volume, field.iso, options);
        benchmark::DoNotOptimize(mesh.positions.data());
        benchmark::DoNotOptimize(mesh.triangles.data());
        benchmark::ClobberMemory();
        vertices = mesh.vertex_count();
        triangles = mesh.triangle_count();
        state.PauseTiming(); // freeing the mesh is not part of the extraction
        mesh = cmc33::Mesh{};
        state.ResumeTiming();
    }
    state.SetItemsProcessed(state.iterations() * cell_count(*field.volume));
    state.counters["triangles"] = benchmark::Counter(static_cast<double>(triangles));
    state.counters["vertices"] = benchmark::Counter(static_cast<double>(vertices));
}

void register_benchmarks()
{
    constexpr std::int64_t kSmooth = 192; // 7.0 M cells
    constexpr std::int64_t kNoise = 128;  // 2.1 M cells, nearly all of them crossed
    auto sines = std::make_shared<const cmc33::Volume>(cmc33::bench::make_sines(kSmooth));
    auto sines_u8 = std::make_shared<const cmc33::Volume>(cmc33::bench::to_uint8_sines(*sines));
    auto noise = std::make_shared<const cmc33::Volume>(cmc33::bench::make_noise(kNoise, 1));
    const Field fields[] = {
        {"sines" + std::to_string(kSmooth) + "_f32", 0.0, sines},
        {"sines" + std::to_string(kSmooth) + "_u8", cmc33::bench::kSinesU8Iso, sines_u8},
        {"noise" + std::to_string(kNoise) + "_f32", 0.0, noise},
    };
    const cmc33::Method methods[] = {cmc33::Method::cmc33, cmc33::Method::mc33_lewiner, cmc33::Method::mc};
    for (const Field& field : fields) {
        for (cmc33::Method method : methods) {
            for (int threads : {1, 2}) {
                const std::string name = "extract/" + field.name + "/" + std::string(cmc33::method_name(method)) +
                                         "/threads:" + std::to_string(threads);
                benchmark::RegisterBenchmark(name.c_str(),
                                             [field, method, threads](benchmark::State& state) {
                                                 run_extract(state, field, method, threads);
                                             })
                    ->Unit(benchmark::kMillisecond)
                    ->UseRealTime();
            }
        }
    }
}

} // namespace

int main(int argc, char** argv)
{
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 2;
    try {
        register_benchmarks();
        benchmark::RunSpecifiedBenchmarks();
    } catch (const std::exception& e) {
        std::cerr << "cmc33_bench: " << e.what() << '\n';
        return 1;
    }
    benchmark::Shutdown();
    return 0;
}
