// libFuzzer target: VTK XML ImageData (.vti) from memory. The first byte chooses --array: 0 the
// default (the active Scalars, or the only array), else "density".

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    if (size == 0) return 0;
    cmc33::io::ReadOptions options;
    if (data[0] % 2 == 1) options.array = "density";
    const std::string_view bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
    return cmc33::fuzz::run("fuzz.vti", [&] {
        return cmc33::io::read_volume_from_memory(bytes, cmc33::io::VolumeFormat::vti, "fuzz.vti", std::nullopt, {}, options);
    });
}
