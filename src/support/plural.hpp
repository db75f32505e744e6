#pragma once
// A count and its noun for messages: "1 sample", "2 samples", "0 vertices". One helper for the
// library's messages and the CLI's output, so that no line says "1 samples".

#include <concepts>
#include <string>
#include <string_view>

namespace cmc33 {

/// "n singular" when n is 1, else "n plural" (default: singular + "s"; give irregular plurals,
/// e.g. counted(n, "vertex", "vertices")).
template <std::integral N> std::string counted(N n, std::string_view singular, std::string_view plural = {})
{
    std::string text = std::to_string(n);
    text += ' ';
    if (n == 1) {
        text += singular;
    } else if (plural.empty()) {
        text += singular;
        text += 's';
    } else {
        text += plural;
    }
    return text;
}

} // namespace cmc33
