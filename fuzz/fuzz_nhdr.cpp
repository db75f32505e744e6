// libFuzzer target: a detached NRRD header (.nhdr) and its data file, from memory. The input is the header, a NUL byte,
// then the data file's bytes; every data file name the header gives resolves to them, except
// "missing.raw", which is absent (to exercise that error).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    // Not a structured binding: clang 14 cannot capture those in the lambdas below.
    const auto parts =
        cmc33::fuzz::split_at_nul(std::string_view(reinterpret_cast<const char*>(data), size));
    const std::string_view header = parts.first;
    const std::optional<std::string_view> data_file = parts.second;
    const cmc33::io::MemoryFiles files = [&](std::string_view name) -> std::optional<std::string_view> {
        if (name == "missing.raw") return std::nullopt;
        return data_file;
    };
    return cmc33::fuzz::run("fuzz.nhdr", [&] {
        return cmc33::io::read_volume_from_memory(header, cmc33::io::VolumeFormat::nrrd, "fuzz.nhdr",
                                                  std::nullopt, files);
    });
}
