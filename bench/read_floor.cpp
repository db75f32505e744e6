// cmc33_read_floor: the time one core needs to read a volume's bytes from memory, the floor under
// any extractor that reads every sample once. For bench/run_bench.py.
//
//   cmc33_read_floor BYTES [--repeat R=21] [--large MiB=1024]
//
// Two figures, both from summing 64-bit words (so that the compiler cannot drop the reads):
//   hot   the median time to read a buffer of BYTES that has just been read (in cache when it fits:
//         the best case, as for a volume an extractor reads right after loading it)
//   cold  BYTES divided by the bandwidth of reading a buffer of --large MiB, larger than every
//         cache (the median of R passes over it)
// Prints one JSON line: {"bytes": n, "hot_seconds": s, "cold_seconds": s, "large_bytes": n,
// "large_gb_per_s": x}. Exit codes: 0 measured, 1 the buffers could not be allocated, 2 usage.

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>
#include <vector>

namespace {

/// The sum of the words, 4 lanes wide so that it runs at load speed.
[[gnu::noinline]] std::uint64_t sum(const std::uint64_t* p, std::size_t n)
{
    std::uint64_t a = 0, b = 0, c = 0, d = 0;
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4) a += p[i], b += p[i + 1], c += p[i + 2], d += p[i + 3];
    for (; i < n; ++i) a += p[i];
    return a + b + c + d;
}

double median_seconds(const std::vector<std::uint64_t>& buffer, int repeat, std::uint64_t& sink)
{
    std::vector<double> runs;
    for (int r = 0; r < repeat; ++r) {
        const auto start = std::chrono::steady_clock::now();
        sink += sum(buffer.data(), buffer.size());
        runs.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    std::sort(runs.begin(), runs.end());
    return runs[runs.size() / 2];
}

[[noreturn]] void usage(const std::string& why)
{
    std::fprintf(stderr, "cmc33_read_floor: %s (usage: cmc33_read_floor BYTES [--repeat R] [--large MiB])\n", why.c_str());
    std::exit(2);
}

long long number(const char* text, const char* what, long long lo, long long hi)
{
    char* end = nullptr;
    const long long v = std::strtoll(text, &end, 10);
    if (end == text || *end != '\0' || v < lo || v > hi) {
        usage(std::string(what) + " \"" + text + "\" is not an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    }
    return v;
}

} // namespace

int main(int argc, char** argv)
{
    if (argc >= 2 && (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0)) {
        std::puts("usage: cmc33_read_floor BYTES [--repeat R=21] [--large MiB=1024]\n"
                  "Times reading BYTES from memory by one core: hot (a buffer of BYTES, read again) and cold\n"
                  "(at the bandwidth of a buffer of --large MiB, larger than the caches). Prints one JSON line.");
        return 0;
    }
    if (argc < 2) usage("expected BYTES");
    const long long bytes = number(argv[1], "BYTES", 8, 1LL << 40);
    int repeat = 21;
    long long large_mib = 1024;
    for (int a = 2; a < argc; a += 2) {
        if (a + 1 >= argc) usage(std::string(argv[a]) + " needs a value");
        if (std::strcmp(argv[a], "--repeat") == 0) {
            repeat = static_cast<int>(number(argv[a + 1], "--repeat", 1, 10000));
        } else if (std::strcmp(argv[a], "--large") == 0) {
            large_mib = number(argv[a + 1], "--large", 64, 1 << 20);
        } else {
            usage(std::string("unknown argument \"") + argv[a] + "\"");
        }
    }
    std::uint64_t sink = 0;
    try {
        std::vector<std::uint64_t> volume(static_cast<std::size_t>(bytes) / 8, 1);
        const double hot = median_seconds(volume, repeat, sink);
        volume = {};
        std::vector<std::uint64_t> large(static_cast<std::size_t>(large_mib) << 17, 1);
        const double large_seconds = median_seconds(large, std::max(3, repeat / 4), sink);
        const double bandwidth = static_cast<double>(large.size() * 8) / large_seconds;
        std::printf("{\"bytes\": %lld, \"hot_seconds\": %.9g, \"cold_seconds\": %.9g, \"large_bytes\": %lld, "
                    "\"large_gb_per_s\": %.4g, \"checksum\": %llu}\n",
                    bytes, hot, static_cast<double>(bytes) / bandwidth, large_mib << 20, bandwidth / 1e9,
                    static_cast<unsigned long long>(sink % 1000));
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "cmc33_read_floor: cannot allocate %lld + %lld MiB\n", bytes, large_mib);
        return 1;
    }
    return 0;
}
