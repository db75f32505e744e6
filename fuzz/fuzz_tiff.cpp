// libFuzzer target: one TIFF file from memory, through libtiff's client I/O on the project's
// bounded reads (pages, ImageJ and OME descriptions, strips and tiles, sample checks).

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    return cmc33::fuzz::run("fuzz.tif", [&] {
        return cmc33::io::read_volume_from_memory(bytes, cmc33::io::VolumeFormat::tiff, "fuzz.tif");
    });
}
