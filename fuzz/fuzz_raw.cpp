// libFuzzer target: headerless raw volumes from memory, with the options a user gives on the
// command line. The input's first line is "X Y Z TYPE ENDIAN HEADER_BYTES [SX SY SZ]" (dims,
// a type name for io::parse_type, "little" or "big", bytes to skip, spacings); the bytes after
// it are the file. A first line the harness cannot split is skipped; everything in it that the
// library checks (dims, type name, spacings, header bytes) reaches the library unchecked.

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "fuzz_common.hpp"

namespace {

std::vector<std::string_view> words(std::string_view line)
{
    std::vector<std::string_view> out;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && line[i] == ' ') ++i;
        const std::size_t start = i;
        while (i < line.size() && line[i] != ' ') ++i;
        if (i > start) out.push_back(line.substr(start, i - start));
    }
    return out;
}

template <class T> bool number(std::string_view word, T& value)
{
    const auto [ptr, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
    return ec == std::errc() && ptr == word.data() + word.size();
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string_view input(reinterpret_cast<const char*>(data), size);
    const std::size_t newline = input.find('\n');
    if (newline == std::string_view::npos) return 0;
    const std::vector<std::string_view> w = words(input.substr(0, newline));
    if (w.size() != 6 && w.size() != 9) return 0;

    cmc33::io::RawOptions options;
    for (std::size_t axis = 0; axis < 3; ++axis) {
        if (!number(w[axis], options.dims[axis])) return 0;
    }
    try {
        options.type = cmc33::io::parse_type(std::string(w[3]));
    } catch (const cmc33::Error& e) {
        // The option parser has no file to name; its message must still be one line.
        if (std::string(e.what()).find('\n') != std::string::npos) {
            cmc33::fuzz::bug("message is not one line", e.what());
        }
        return 0;
    }
    if (w[4] != "little" && w[4] != "big") return 0;
    options.endian = w[4] == "big" ? cmc33::io::Endian::big : cmc33::io::Endian::little;
    if (!number(w[5], options.header_bytes)) return 0;
    if (w.size() == 9) {
        for (std::size_t axis = 0; axis < 3; ++axis) {
            if (!number(w[6 + axis], options.spacing[axis])) return 0;
        }
    }
    const std::string_view file = input.substr(newline + 1);
    return cmc33::fuzz::run("fuzz.raw", [&] {
        return cmc33::io::read_volume_from_memory(file, cmc33::io::VolumeFormat::raw, "fuzz.raw",
                                                  options);
    });
}
