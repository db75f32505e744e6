// libFuzzer target: a label map's names and colours from bytes in memory, read both as a colour
// table (3D Slicer, FreeSurfer, ITK-SNAP lines) and as a 3D Slicer segmentation's NRRD header.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    cmc33::fuzz::run("fuzz.ctbl", [&] { return cmc33::io::parse_colour_table(bytes, "fuzz.ctbl"); });
    return cmc33::fuzz::run("fuzz.seg.nrrd", [&] { return cmc33::io::parse_segment_names(bytes, "fuzz.seg.nrrd"); });
}
