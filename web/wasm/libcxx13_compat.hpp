#pragma once
// Forced into every translation unit of the WebAssembly build (CMakeLists.txt, under EMSCRIPTEN):
// what the library uses of C++17/20 and the libc++ 13 of Debian's emscripten 3.1.6 lacks:
// std::from_chars and std::to_chars for floating point, and std::bit_cast. Each is written on the
// C library (strtod and snprintf, in the "C" locale of a WebAssembly module) with the standard's
// contract: from_chars takes no leading space, '+' or hex prefix, and leaves the value alone when
// out of range; to_chars writes the shortest decimal that reads back to the same value. Compiled
// away where the library has them.

#if defined(__cplusplus) && defined(__EMSCRIPTEN__)
#include <version> // _LIBCPP_VERSION
#if defined(_LIBCPP_VERSION) && _LIBCPP_VERSION < 14000

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <system_error>

namespace cmc33_libcxx13 {

template <class F> F read(const char* text, char** end)
{
    if constexpr (sizeof(F) == sizeof(float)) {
        return std::strtof(text, end);
    } else if constexpr (sizeof(F) == sizeof(double)) {
        return std::strtod(text, end);
    } else {
        return std::strtold(text, end);
    }
}

template <class F> std::from_chars_result from_chars(const char* first, const char* last, F& value)
{
    std::string text(first, last);
    std::size_t digits = text.empty() || text[0] != '-' ? 0 : 1;
    if (digits >= text.size() || !(text[digits] == '.' || (text[digits] >= '0' && text[digits] <= '9') ||
                                   text[digits] == 'i' || text[digits] == 'I' || text[digits] == 'n' || text[digits] == 'N')) {
        return {first, std::errc::invalid_argument};
    }
    if (text.size() > digits + 1 && text[digits] == '0' && (text[digits + 1] == 'x' || text[digits + 1] == 'X')) {
        text.resize(digits + 1); // no hex in chars_format::general: "0x1p3" reads as 0
    }
    errno = 0;
    char* end = nullptr;
    const F parsed = read<F>(text.c_str(), &end);
    if (end == text.c_str()) return {first, std::errc::invalid_argument};
    const char* ptr = first + (end - text.c_str());
    if (errno == ERANGE) return {ptr, std::errc::result_out_of_range};
    value = parsed;
    return {ptr, std::errc()};
}

template <class F> std::to_chars_result to_chars(char* first, char* last, F value)
{
    char buffer[64];
    int n = 0;
    for (int precision = 1; precision <= 21; ++precision) {
        n = std::snprintf(buffer, sizeof buffer, "%.*Lg", precision, static_cast<long double>(value));
        char* end = nullptr;
        if (read<F>(buffer, &end) == value || value != value) break;
    }
    if (n < 0 || n > last - first) return {last, std::errc::value_too_large};
    std::memcpy(first, buffer, static_cast<std::size_t>(n));
    return {first + n, std::errc()};
}

} // namespace cmc33_libcxx13

namespace std {
inline from_chars_result from_chars(const char* f, const char* l, float& v, chars_format = chars_format::general)
{
    return cmc33_libcxx13::from_chars(f, l, v);
}
inline from_chars_result from_chars(const char* f, const char* l, double& v, chars_format = chars_format::general)
{
    return cmc33_libcxx13::from_chars(f, l, v);
}
inline from_chars_result from_chars(const char* f, const char* l, long double& v, chars_format = chars_format::general)
{
    return cmc33_libcxx13::from_chars(f, l, v);
}
inline to_chars_result to_chars(char* f, char* l, float v) { return cmc33_libcxx13::to_chars(f, l, v); }
inline to_chars_result to_chars(char* f, char* l, double v) { return cmc33_libcxx13::to_chars(f, l, v); }
inline to_chars_result to_chars(char* f, char* l, long double v) { return cmc33_libcxx13::to_chars(f, l, v); }
template <class To, class From> constexpr To bit_cast(const From& from) noexcept { return __builtin_bit_cast(To, from); }
} // namespace std

#endif
#endif
