// libFuzzer target: one DICOM file from memory (the single-file path: a multi-frame image), the
// project's code around GDCM (headers, grouping, sorting, frame, rescale, sample checks).

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    return cmc33::fuzz::run("fuzz.dcm", [&] {
        return cmc33::io::read_volume_from_memory(bytes, cmc33::io::VolumeFormat::dicom, "fuzz.dcm");
    });
}
