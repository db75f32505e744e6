// cmc33_pass_times: where one thread's extraction time goes, pass by pass (passes.hpp).
//
//   cmc33_pass_times VOLUME ISO [--repeat R=21] [--normals] [--method NAME=cmc33]
//
// The volume is one range [0, nz) on the calling thread, as extract() runs it with one thread.
// Each of R rounds times count(), then emit() into output allocated (and written once) before
// the clock starts, then emit() again at once:
//   count       the pass that reads every sample (classification, trim, case codes, decisions)
//   emit        the pass that writes the mesh, as extract() runs it after count
//   emit again  the same emit with the rows it reads still in cache: emit minus this is what
//               emit waits for memory
// Prints one JSON line of medians: {"count_seconds": s, "emit_seconds": s, "emit_again_seconds":
// s, "vertices": n, "triangles": n}. Exit codes: 0 measured, 1 the volume could not be read or
// extracted (one line on stderr), 2 usage.

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "cmc33/passes.hpp"

namespace {

constexpr const char* kUsage = "usage: cmc33_pass_times VOLUME ISO [--repeat R=21] [--normals] [--method NAME=cmc33]";

[[noreturn]] void usage(const std::string& why)
{
    std::fprintf(stderr, "cmc33_pass_times: %s (%s)\n", why.c_str(), kUsage);
    std::exit(2);
}

struct Times {
    std::vector<double> count, emit, again;
    std::int64_t vertices = 0, triangles = 0;
};

double seconds_since(std::chrono::steady_clock::time_point start)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

template <class T> void time_passes(const cmc33::GridView<T>& grid, double iso, const cmc33::ExtractOptions& options, Times& times)
{
    const auto start = std::chrono::steady_clock::now();
    cmc33::RangeCounts counted = cmc33::count(grid, iso, options, 0, grid.nz());
    times.count.push_back(seconds_since(start));
    std::vector<cmc33::RangeCounts> counts;
    counts.push_back(std::move(counted)); // not a copy of the rows (an initializer list copies)
    const std::vector<cmc33::RangeOffsets> offsets = cmc33::scan(counts, 0, 0);
    times.vertices = counts[0].vertex_count();
    times.triangles = counts[0].triangle_count();
    // written (not just reserved) before the clock starts: no page faults inside emit
    std::vector<float> positions(static_cast<std::size_t>(3 * times.vertices), 0.0f);
    std::vector<float> normals(options.normals ? positions.size() : 0, 0.0f);
    std::vector<std::uint32_t> triangles(static_cast<std::size_t>(3 * times.triangles), 0);
    cmc33::MeshSpans spans;
    spans.positions = positions.data();
    spans.normals = options.normals ? normals.data() : nullptr;
    spans.triangles = triangles.data();
    for (std::vector<double>* runs : {&times.emit, &times.again}) {
        const auto emit_start = std::chrono::steady_clock::now();
        cmc33::emit(grid, iso, options, counts[0], offsets[0], spans);
        runs->push_back(seconds_since(emit_start));
    }
}

double median(std::vector<double> runs)
{
    std::sort(runs.begin(), runs.end());
    return runs[runs.size() / 2];
}

} // namespace

int main(int argc, char** argv)
{
    if (argc >= 2 && (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0)) {
        std::printf("%s\nTimes count() and emit() (twice: as extract() runs it, then with the rows in cache) on one\n"
                    "thread over the whole volume. Prints one JSON line of medians over R rounds.\n",
                    kUsage);
        return 0;
    }
    if (argc < 3) usage("expected VOLUME and ISO");
    char* end = nullptr;
    const double iso = std::strtod(argv[2], &end);
    if (end == argv[2] || *end != '\0') usage(std::string("ISO \"") + argv[2] + "\" is not a number");
    int repeat = 21;
    cmc33::ExtractOptions options;
    options.threads = 1;
    for (int a = 3; a < argc; ++a) {
        if (std::strcmp(argv[a], "--normals") == 0) {
            options.normals = true;
        } else if (std::strcmp(argv[a], "--repeat") == 0 && a + 1 < argc) {
            const long r = std::strtol(argv[++a], &end, 10);
            if (*end != '\0' || r < 1 || r > 100000) usage(std::string("--repeat \"") + argv[a] + "\" is not an integer in [1, 100000]");
            repeat = static_cast<int>(r);
        } else if (std::strcmp(argv[a], "--method") == 0 && a + 1 < argc) {
            try {
                options.method = cmc33::parse_method(argv[++a]);
            } catch (const std::exception& e) {
                usage(e.what());
            }
        } else {
            usage(std::string("unknown or incomplete option \"") + argv[a] + "\"");
        }
    }
    std::optional<cmc33::Volume> volume;
    try {
        volume = cmc33::io::read_volume(argv[1]);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "cmc33_pass_times: %s\n", e.what()); // the reader's message names the file
        return 1;
    }
    Times times;
    try {
        for (int r = 0; r < repeat; ++r) volume->visit([&](const auto& grid) { time_passes(grid, iso, options, times); });
    } catch (const std::exception& e) {
        std::fprintf(stderr, "cmc33_pass_times: %s: %s\n", argv[1], e.what());
        return 1;
    }
    std::printf("{\"count_seconds\": %.6g, \"emit_seconds\": %.6g, \"emit_again_seconds\": %.6g, \"vertices\": %lld, "
                "\"triangles\": %lld}\n",
                median(times.count), median(times.emit), median(times.again), static_cast<long long>(times.vertices),
                static_cast<long long>(times.triangles));
    return 0;
}
