#pragma once
// Shared by the libFuzzer targets: run one reader on one input. cmc33::Error is the expected
// outcome for bad bytes; anything else is a bug, reported by aborting (libFuzzer saves the input):
// another exception type escapes and aborts, a message that is not one line starting with the
// label aborts, a result that breaks the reader's contract aborts. Crashes, sanitizer reports,
// leaks and hangs are caught by libFuzzer itself.

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/io.hpp"

namespace cmc33::fuzz {

[[noreturn]] inline void bug(const char* what, const std::string& detail)
{
    std::fprintf(stderr, "cmc33 fuzz: %s: %s\n", what, detail.c_str());
    std::abort();
}

inline void check_message(const Error& error, const std::string& label)
{
    const std::string message = error.what();
    if (message.rfind(label + ": ", 0) != 0) bug("message does not start with the label", message);
    if (message.find('\n') != std::string::npos) bug("message is not one line", message);
    if (message.size() <= label.size() + 2) bug("message says nothing", message);
}

inline void check_volume(const Volume& v)
{
    for (std::int64_t d : v.dims()) {
        if (d < 2) bug("volume axis below 2 samples", std::to_string(d));
    }
    if (v.bytes() == nullptr) bug("volume without samples", "");
    // Touch the first and last sample: ASan sees a buffer shorter than byte_size().
    volatile std::byte first = v.bytes()[0];
    volatile std::byte last = v.bytes()[v.byte_size() - 1];
    (void)first;
    (void)last;
}

inline void check_mesh(const Mesh& m)
{
    if (m.positions.size() % 3 != 0) bug("positions not a multiple of 3", "");
    if (!m.normals.empty() && m.normals.size() != m.positions.size()) bug("normals size", "");
    if (m.triangles.size() % 3 != 0) bug("triangles not a multiple of 3", "");
    const std::size_t n = m.vertex_count();
    for (std::uint32_t index : m.triangles) {
        if (index >= n) bug("triangle index out of range", std::to_string(index));
    }
}

inline void check_label_names(const std::vector<io::LabelName>& names)
{
    std::set<std::int64_t> values;
    for (const io::LabelName& n : names) {
        if (!values.insert(n.value).second) bug("a label value named twice", std::to_string(n.value));
        if (!n.colour) continue;
        for (const float c : *n.colour) {
            if (!(c >= 0 && c <= 1)) bug("a colour channel outside [0, 1]", std::to_string(c));
        }
    }
}

/// Runs `read` (which returns a Volume, a Mesh or label names); an Error must carry a proper message.
template <class Read> int run(const std::string& label, Read&& read)
{
    try {
        auto result = std::forward<Read>(read)();
        if constexpr (std::is_same_v<decltype(result), Volume>) {
            check_volume(result);
        } else if constexpr (std::is_same_v<decltype(result), std::vector<io::LabelName>>) {
            check_label_names(result);
        } else {
            check_mesh(result);
        }
    } catch (const Error& e) {
        check_message(e, label);
    }
    return 0;
}

/// Splits `bytes` at its first NUL: a header, then the bytes of the data file it names (headers
/// are text, so a NUL cannot belong to one). Without a NUL, there is no data file.
inline std::pair<std::string_view, std::optional<std::string_view>> split_at_nul(std::string_view bytes)
{
    const std::size_t nul = bytes.find('\0');
    if (nul == std::string_view::npos) return {bytes, std::nullopt};
    return {bytes.substr(0, nul), bytes.substr(nul + 1)};
}

} // namespace cmc33::fuzz
