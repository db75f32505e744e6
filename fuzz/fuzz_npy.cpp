// libFuzzer target: a NumPy .npy file from memory. The first byte chooses the frame of a 4-D stack
// (0-3, or 4 for none); the rest is the file.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    if (size == 0) return 0;
    cmc33::io::ReadOptions options;
    if (data[0] % 5 != 4) options.frame = data[0] % 5; // 4: no frame given
    const std::string_view bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
    return cmc33::fuzz::run("fuzz.npy", [&] {
        return cmc33::io::read_volume_from_memory(bytes, cmc33::io::VolumeFormat::npy, "fuzz.npy", std::nullopt, {}, options);
    });
}
