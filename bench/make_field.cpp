// cmc33_make_field: writes the benchmark's synthetic volumes (bench/synthetic_fields.hpp) to a
// file through the library's volume writer, so every tool of bench/run_bench.py reads the same
// samples.
//
//   cmc33_make_field sines OUT.nrrd [N=512]            float32 N^3, iso 0: a large smooth surface
//   cmc33_make_field noise OUT.nrrd [N=128] [--seed S]  float32 N^3 uniform in [-1, 1), iso 0
//   cmc33_make_field sphere OUT.nrrd [N=256]           float32 N^3 distance to the centre - N/3
//   cmc33_make_field ties OUT.nrrd [N=128] [--seed S] [--uint8]  {60, 80, 100} as float32 (or uint8)
//
// Exit codes: 0 written, 1 the volume could not be made or written, 2 usage error.

#include <charconv>
#include <cstdint>
#include <exception>
#include <iostream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "synthetic_fields.hpp"

namespace {

constexpr std::int64_t kMaxSize = 2048; // 2048^3 float samples are 32 GiB

constexpr const char* kUsage =
    "usage: cmc33_make_field sines OUT [N=512]\n"
    "       cmc33_make_field noise OUT [N=128] [--seed S=1]\n"
    "       cmc33_make_field sphere OUT [N=256]\n"
    "       cmc33_make_field ties OUT [N=128] [--seed S=1] [--uint8]\n"
    "Writes an N^3 volume, float32 (ties --uint8: uint8), 2 <= N <= 2048, in the format of OUT's extension (.nrrd, .nhdr,\n"
    ".mhd, .mha, .vtk, .raw):\n"
    "  sines  f = sin(a x + 0.3) + sin(a y + 0.3) + sin(a z + 0.3), a = 2 pi * 8 / N (8 periods\n"
    "         per axis); at iso 0 a large smooth surface\n"
    "  noise  samples uniform in [-1, 1) from std::mt19937_64(S); at iso 0 nearly every cell is\n"
    "         crossed\n"
    "  sphere f = distance to the grid's centre - N / 3; at iso 0 one sphere\n"
    "  ties   samples drawn from {60, 80, 100} (std::mt19937_64(S)), float32 or with --uint8 the\n"
    "         same numbers as uint8; at iso 80 ties everywhere\n";

struct UsageError {
    std::string message;
};

template <class T> T parse_integer(std::string_view text, std::string_view what, T min, T max)
{
    T value{};
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc{} || end != text.data() + text.size() || value < min || value > max) {
        throw UsageError{std::string(what) + " \"" + std::string(text) + "\" is not an integer in [" +
                         std::to_string(min) + ", " + std::to_string(max) + "]"};
    }
    return value;
}

int run(const std::vector<std::string_view>& args)
{
    if (args.size() == 1 && (args[0] == "-h" || args[0] == "--help")) {
        std::cout << kUsage;
        return 0;
    }
    if (args.size() < 2) throw UsageError{"expected a field name (sines, noise, sphere or ties) and an output file"};
    const std::string_view kind = args[0];
    if (kind != "sines" && kind != "noise" && kind != "sphere" && kind != "ties") {
        throw UsageError{"unknown field \"" + std::string(kind) + "\"; expected sines, noise, sphere or ties"};
    }
    const std::string out(args[1]);
    std::int64_t n = kind == "sines" ? 512 : kind == "noise" || kind == "ties" ? 128 : 256;
    std::uint64_t seed = 1;
    bool have_n = false, as_uint8 = false;
    for (std::size_t i = 2; i < args.size(); ++i) {
        if (args[i] == "--seed") {
            if (kind != "noise" && kind != "ties") throw UsageError{"--seed applies to the noise and ties fields only"};
            if (i + 1 == args.size()) throw UsageError{"--seed needs a value"};
            seed = parse_integer<std::uint64_t>(args[++i], "--seed", 0, UINT64_MAX);
        } else if (args[i] == "--uint8") {
            if (kind != "ties") throw UsageError{"--uint8 applies to the ties field only"};
            as_uint8 = true;
        } else if (!have_n && !args[i].starts_with("-")) {
            n = parse_integer<std::int64_t>(args[i], "N", 2, kMaxSize);
            have_n = true;
        } else {
            throw UsageError{"unexpected argument \"" + std::string(args[i]) + "\""};
        }
    }
    if (!cmc33::io::has_volume_header(out) && !out.ends_with(".raw")) {
        throw UsageError{"OUT \"" + out + "\" has no volume extension; expected .nrrd, .nhdr, .mhd, .mha, .vtk or .raw"};
    }
    const cmc33::Volume volume = kind == "sines"   ? cmc33::bench::make_sines(n)
                                 : kind == "noise" ? cmc33::bench::make_noise(n, seed)
                                 : kind == "ties"  ? cmc33::bench::make_ties(n, seed, !as_uint8)
                                                   : cmc33::bench::make_sphere(n);
    cmc33::io::write_volume(volume, out);
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    try {
        return run(std::vector<std::string_view>(argv + 1, argv + argc));
    } catch (const UsageError& e) {
        std::cerr << "cmc33_make_field: " << e.message << " (try --help)\n";
        return 2;
    } catch (const std::exception& e) {
        std::cerr << "cmc33_make_field: " << e.what() << '\n';
        return 1;
    }
}
