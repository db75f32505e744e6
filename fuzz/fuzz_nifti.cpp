// libFuzzer target: NIfTI-1 or NIfTI-2 from memory: a .nii (gzip-compressed or not), or a .hdr and
// its .img. The first byte chooses the frame (0-3, or 4 for none); the rest up to the first "\0IMG\0" is the
// file, and what follows that marker is the pair's .img (whose presence names the file .hdr).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    if (size == 0) return 0;
    cmc33::io::ReadOptions options;
    if (data[0] % 5 != 4) options.frame = data[0] % 5; // 4: no frame given
    std::string_view bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
    std::optional<std::string_view> image;
    constexpr std::string_view kMarker("\0IMG\0", 5);
    if (const std::size_t at = bytes.find(kMarker); at != std::string_view::npos) {
        image = bytes.substr(at + kMarker.size());
        bytes = bytes.substr(0, at);
    }
    const cmc33::io::MemoryFiles files = [&](std::string_view name) -> std::optional<std::string_view> {
        return name == "fuzz.img" ? image : std::nullopt;
    };
    const std::string label = image ? "fuzz.hdr" : "fuzz.nii";
    return cmc33::fuzz::run(label, [&] {
        return cmc33::io::read_volume_from_memory(bytes, cmc33::io::VolumeFormat::nifti, label, std::nullopt, files, options);
    });
}
