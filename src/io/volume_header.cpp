// What the volume formats' headers share: text (trimming, words, quoting in messages, numbers
// parsed whole-token), header values (dims, vectors, the frame, the payload's size), data file
// names beside a header, printf-style file patterns of image series, and samples written as text.

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "cmc33/io.hpp"
#include "byte_source.hpp"
#include "volume_formats.hpp"

namespace cmc33::io {
namespace detail {

// ---- messages and text ----------------------------------------------------------------------

namespace {

bool is_blank(char c) noexcept
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

} // namespace

std::string quote_bytes(std::string_view text, std::size_t max_chars)
{
    std::string out = "\"";
    const std::size_t n = std::min(text.size(), max_chars);
    for (std::size_t i = 0; i < n; ++i) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (c >= 0x20 && c < 0x7f && c != '"' && c != '\\') {
            out += static_cast<char>(c);
        } else {
            static constexpr char kHex[] = "0123456789abcdef";
            out += "\\x";
            out += kHex[c >> 4];
            out += kHex[c & 15];
        }
    }
    if (text.size() > n) out += "...";
    out += '"';
    return out;
}

std::string_view trim(std::string_view text) noexcept
{
    while (!text.empty() && is_blank(text.front())) text.remove_prefix(1);
    while (!text.empty() && is_blank(text.back())) text.remove_suffix(1);
    return text;
}

std::vector<std::string_view> split_words(std::string_view text)
{
    std::vector<std::string_view> words;
    std::size_t i = 0;
    while (i < text.size()) {
        while (i < text.size() && is_blank(text[i])) ++i;
        const std::size_t start = i;
        while (i < text.size() && !is_blank(text[i])) ++i;
        if (i > start) words.push_back(text.substr(start, i - start));
    }
    return words;
}

std::string normalize_blanks(std::string_view text)
{
    std::string out;
    for (std::string_view word : split_words(text)) {
        if (!out.empty()) out += ' ';
        out += word;
    }
    return out;
}

std::string lower_ascii(std::string_view text)
{
    std::string out(text);
    for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
}

bool equals_ignore_case(std::string_view a, std::string_view b) noexcept
{
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
        if (std::tolower(static_cast<unsigned char>(a[i])) !=
            std::tolower(static_cast<unsigned char>(b[i]))) {
            return false;
        }
    }
    return true;
}

std::string format_real(double value)
{
    std::array<char, 64> buffer{};
    const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
    return std::string(buffer.data(), result.ptr);
}

std::string dims_text(const Index3& dims)
{
    return str_cat(dims[0], 'x', dims[1], 'x', dims[2]);
}

namespace {

template <class T> std::string range_text()
{
    if constexpr (std::is_floating_point_v<T>) {
        return str_cat("+-", std::numeric_limits<T>::max());
    } else {
        return str_cat(+std::numeric_limits<T>::lowest(), "..", +std::numeric_limits<T>::max());
    }
}

std::string_view without_leading_plus(std::string_view token) noexcept
{
    if (token.size() > 1 && token[0] == '+' && token[1] != '-' && token[1] != '+')
        token.remove_prefix(1);
    return token;
}

enum class Parsed { ok, not_number, out_of_range };

/// A whole-token decimal of floating type F. Underflow gives the nearest value (0 or subnormal),
/// overflow is out_of_range.
template <class F> Parsed parse_floating(std::string_view token, F& value)
{
    token = without_leading_plus(token);
    const char* end = token.data() + token.size();
    F parsed{};
    const auto result = std::from_chars(token.data(), end, parsed, std::chars_format::general);
    if (result.ptr != end || token.empty()) return Parsed::not_number;
    if (result.ec == std::errc()) {
        value = parsed;
        return Parsed::ok;
    }
    if (result.ec != std::errc::result_out_of_range) return Parsed::not_number;
    // from_chars says out_of_range for underflow and overflow alike. The wider long double tells
    // them apart (a rare path); beyond even its range, the exponent's sign does.
    long double wide = 0;
    const auto again = std::from_chars(token.data(), end, wide, std::chars_format::general);
    if (again.ec == std::errc::result_out_of_range) {
        const std::size_t e = token.find_first_of("eE");
        if (e == std::string_view::npos || e + 1 >= token.size() || token[e + 1] != '-')
            return Parsed::out_of_range;
        wide = token.front() == '-' ? -0.0L : 0.0L;
    } else if (again.ec != std::errc()) {
        return Parsed::not_number;
    }
    if (!(std::fabs(wide) <= static_cast<long double>(std::numeric_limits<F>::max())))
        return Parsed::out_of_range;
    value = static_cast<F>(wide);
    return Parsed::ok;
}

Parsed parse_int64(std::string_view token, std::int64_t& value)
{
    token = without_leading_plus(token);
    const char* end = token.data() + token.size();
    std::int64_t parsed = 0;
    const auto result = std::from_chars(token.data(), end, parsed);
    if (result.ptr != end || token.empty()) return Parsed::not_number;
    if (result.ec == std::errc::result_out_of_range) return Parsed::out_of_range;
    if (result.ec != std::errc()) return Parsed::not_number;
    value = parsed;
    return Parsed::ok;
}

} // namespace

bool parse_real(std::string_view token, double& value)
{
    return parse_floating(token, value) == Parsed::ok;
}

std::string real_problem(std::string_view token)
{
    double value = 0;
    if (parse_floating(token, value) == Parsed::out_of_range)
        return "is out of the double range " + range_text<double>();
    return "is not a number";
}

bool parse_integer(std::string_view token, std::int64_t& value)
{
    return parse_int64(token, value) == Parsed::ok;
}

// ---- header values --------------------------------------------------------------------------

Index3 parse_dims(const std::vector<std::string_view>& words, const std::string& label,
                  std::string_view what)
{
    if (words.size() != 3) {
        throw Error(Status::bad_format, str_cat(label, ": ", what, " has ", words.size(),
                                                " values, expected 3 (samples along x, y, z)"));
    }
    Index3 dims{};
    for (std::size_t axis = 0; axis < 3; ++axis) {
        std::int64_t n = 0;
        const Parsed parsed = parse_int64(words[axis], n);
        if (parsed == Parsed::out_of_range && words[axis].front() != '-') {
            throw Error(Status::too_large,
                        str_cat(label, ": ", what, " value ", quote_bytes(words[axis]),
                                " is too large (more than 2^63 samples)"));
        }
        if (parsed != Parsed::ok || n <= 0) {
            throw Error(Status::bad_format,
                        str_cat(label, ": ", what, " value ", quote_bytes(words[axis]),
                                " is not a positive integer"));
        }
        dims[axis] = n;
    }
    return dims;
}

Vec3 parse_vec3(const std::vector<std::string_view>& words, const std::string& label,
                std::string_view what, bool positive)
{
    if (words.size() != 3) {
        throw Error(Status::bad_format,
                    str_cat(label, ": ", what, " has ", words.size(), " values, expected 3"));
    }
    Vec3 v{};
    for (std::size_t axis = 0; axis < 3; ++axis) {
        if (!parse_real(words[axis], v[axis])) {
            throw Error(Status::bad_format, str_cat(label, ": ", what, " value ",
                                                    quote_bytes(words[axis]), ' ',
                                                    real_problem(words[axis])));
        }
        if (!std::isfinite(v[axis])) {
            throw Error(Status::non_finite, str_cat(label, ": ", what, " value ",
                                                    quote_bytes(words[axis]), " is not finite"));
        }
        if (positive && !(v[axis] > 0)) {
            throw Error(Status::bad_format,
                        str_cat(label, ": ", what, " value ", quote_bytes(words[axis]),
                                " is not positive; spacings must be > 0"));
        }
    }
    return v;
}

void set_frame(Grid& grid, const std::array<Vec3, 3>& axes, const Vec3& scale, const std::string& label,
               std::string_view what)
{
    Mat3 d{};
    for (std::size_t a = 0; a < 3; ++a) {
        const Vec3& v = axes[a];
        const double norm = std::hypot(v[0], v[1], v[2]); // no underflow for tiny spacings
        if (!(norm > 0) || !std::isfinite(norm)) {
            throw Error(Status::bad_format,
                        str_cat(label, ": ", what, ": the vector of axis ", a + 1, " (", format_real(v[0]), ",",
                                format_real(v[1]), ",", format_real(v[2]),
                                ") has no length; expected a non-zero direction per axis"));
        }
        for (std::size_t r = 0; r < 3; ++r) d[r][a] = v[r] / norm;
        grid.spacing[a] = scale[a] * norm;
    }
    // |det| of unit columns is 1 for an orthogonal frame and 0 for axes in one plane
    if (!(std::fabs(determinant(d)) > 1e-6)) {
        throw Error(Status::bad_format,
                    str_cat(label, ": ", what, ": the axis vectors lie in one plane (a degenerate frame, "
                                               "determinant ",
                            determinant(d), "); expected three independent directions"));
    }
    grid.direction = d;
}

std::uint64_t payload_bytes(const Index3& dims, ScalarType type, const std::string& label)
{
    for (std::int64_t d : dims) {
        if (d < 2) {
            throw Error(Status::bad_format,
                        str_cat(label, ": sizes ", dims_text(dims),
                                ": an isosurface needs at least 2 samples on each axis"));
        }
    }
    std::uint64_t bytes = type_size(type);
    for (std::int64_t d : dims) {
        const auto n = static_cast<std::uint64_t>(d);
        if (bytes > std::numeric_limits<std::uint64_t>::max() / n) {
            throw Error(Status::too_large, str_cat(label, ": sizes ", dims_text(dims), " of ",
                                                   type_name(type), " samples overflow 64 bits"));
        }
        bytes *= n;
    }
    if (bytes > static_cast<std::uint64_t>(std::numeric_limits<std::ptrdiff_t>::max())) {
        throw Error(Status::too_large,
                    str_cat(label, ": sizes ", dims_text(dims), " of ", type_name(type),
                            " samples need ", bytes, " bytes, more than memory can address"));
    }
    return bytes;
}

std::string read_header_bytes(const ByteInput& file, std::string_view format)
{
    if (file.size() == 0) {
        throw Error(
            Status::truncated_file,
            str_cat(file.label(), ": the file is empty (0 bytes), expected a ", format, " header"));
    }
    return file.read_string(0, kMaxHeaderBytes);
}

std::filesystem::path resolve_data_file(const std::filesystem::path& header, std::string_view name)
{
    const std::filesystem::path data{std::string(name)};
    if (data.is_absolute()) return data;
    return header.parent_path() / data;
}

bool is_file_pattern(std::string_view value)
{
    const std::vector<std::string_view> words = split_words(value);
    if (words.size() < 4 || words.size() > 5 || words[0].find('%') == std::string_view::npos)
        return false;
    for (std::size_t i = 1; i < words.size(); ++i) {
        std::int64_t n = 0;
        if (!parse_integer(words[i], n)) return false;
    }
    return true;
}

namespace {

/// One printf integer conversion ("%05d" and the like), as parsed from a file pattern.
struct Conversion {
    bool left = false, zero = false, plus = false, space = false, is_unsigned = false;
    int width = 0;
    int precision = -1;
};

std::string format_int(int value, const Conversion& c)
{
    const bool negative = value < 0 && !c.is_unsigned;
    const std::uint64_t magnitude =
        c.is_unsigned ? static_cast<unsigned>(value)
                      : (negative ? std::uint64_t{0} - static_cast<std::uint64_t>(static_cast<std::int64_t>(value))
                                  : static_cast<std::uint64_t>(value));
    std::string digits = c.precision == 0 && magnitude == 0 ? std::string() : std::to_string(magnitude);
    if (c.precision > 0 && digits.size() < static_cast<std::size_t>(c.precision))
        digits.insert(0, static_cast<std::size_t>(c.precision) - digits.size(), '0');
    const std::string sign = negative ? "-" : c.is_unsigned ? "" : c.plus ? "+" : c.space ? " " : "";
    const std::size_t length = sign.size() + digits.size();
    const std::size_t pad = static_cast<std::size_t>(c.width) > length ? static_cast<std::size_t>(c.width) - length : 0;
    if (c.left) return sign + digits + std::string(pad, ' ');
    if (c.zero && c.precision < 0) return sign + std::string(pad, '0') + digits;
    return std::string(pad, ' ') + sign + digits;
}

} // namespace

std::vector<std::string> expand_file_pattern(std::string_view value, std::size_t max_names)
{
    const std::vector<std::string_view> words = split_words(value);
    std::int64_t first = 0, last = 0, step = 0;
    if (!is_file_pattern(value) || !parse_integer(words[1], first) || !parse_integer(words[2], last) ||
        !parse_integer(words[3], step) || step == 0) {
        return {};
    }
    constexpr std::int64_t kIntMin = std::numeric_limits<int>::min(), kIntMax = std::numeric_limits<int>::max();
    if (first < kIntMin || first > kIntMax || last < kIntMin || last > kIntMax) return {};
    // The format: literal text around exactly one integer conversion.
    const std::string_view format = words[0];
    std::string before, after;
    std::optional<Conversion> conversion;
    for (std::size_t i = 0; i < format.size(); ++i) {
        std::string& text = conversion ? after : before;
        if (format[i] != '%') {
            text += format[i];
            continue;
        }
        if (i + 1 < format.size() && format[i + 1] == '%') {
            text += '%';
            ++i;
            continue;
        }
        if (conversion) return {}; // a second conversion: not a pattern of one number
        Conversion c;
        std::size_t j = i + 1;
        for (; j < format.size() && std::string_view("-0+ ").find(format[j]) != std::string_view::npos; ++j) {
            c.left = c.left || format[j] == '-';
            c.zero = c.zero || format[j] == '0';
            c.plus = c.plus || format[j] == '+';
            c.space = c.space || format[j] == ' ';
        }
        const auto number = [&](int& out) {
            const std::size_t start = j;
            while (j < format.size() && j - start < 4 && std::isdigit(static_cast<unsigned char>(format[j]))) {
                out = out * 10 + (format[j] - '0');
                ++j;
            }
        };
        number(c.width);
        if (j < format.size() && format[j] == '.') {
            ++j;
            c.precision = 0;
            number(c.precision);
        }
        if (j >= format.size() || std::string_view("diu").find(format[j]) == std::string_view::npos) return {};
        c.is_unsigned = format[j] == 'u';
        conversion = c;
        i = j;
    }
    if (!conversion) return {};
    std::vector<std::string> names;
    for (std::int64_t n = first; (step > 0 ? n <= last : n >= last) && names.size() < max_names; n += step) {
        names.push_back(before + format_int(static_cast<int>(n), *conversion) + after);
        if (step > 0 ? n > kIntMax - step : n < kIntMin - step) break; // the next one is past any int
    }
    return names;
}


// ---- ASCII samples ------------------------------------------------------------------------

namespace {

template <class T>
std::size_t parse_ascii_typed(std::string_view text, T* out, std::int64_t count, ScalarType type,
                              const std::string& label)
{
    std::size_t pos = 0;
    const std::size_t size = text.size();
    for (std::int64_t i = 0; i < count; ++i) {
        while (pos < size && is_blank(text[pos])) ++pos;
        if (pos == size) {
            throw Error(Status::truncated_file,
                        str_cat(label, ": the header declares ", count,
                                " values but the data ends after ", i, " (file cut short?)"));
        }
        std::size_t end = pos;
        while (end < size && !is_blank(text[end])) ++end;
        const std::string_view token = text.substr(pos, end - pos);
        // The last value may end the file without a newline: the count is the evidence.
        if (end == size && i + 1 < count) {
            throw Error(Status::truncated_file, str_cat(label, ": the header declares ", count,
                                                        " values but the data ends after ", i + 1,
                                                        " (file cut short?)"));
        }
        Parsed parsed = Parsed::not_number;
        if constexpr (std::is_floating_point_v<T>) {
            parsed = parse_floating(token, out[i]);
        } else {
            std::int64_t n = 0;
            parsed = parse_int64(token, n);
            if (parsed == Parsed::ok) {
                if (n < static_cast<std::int64_t>(std::numeric_limits<T>::lowest()) ||
                    n > static_cast<std::int64_t>(std::numeric_limits<T>::max())) {
                    parsed = Parsed::out_of_range;
                } else {
                    out[i] = static_cast<T>(n);
                }
            } else if (parsed == Parsed::not_number) {
                double real = 0;
                if (parse_floating(token, real) == Parsed::ok) {
                    throw Error(Status::bad_format,
                                str_cat(label, ": value ", i + 1, " of ", count, ' ',
                                        quote_bytes(token), " is not an integer, expected ",
                                        type_name(type), " values"));
                }
            }
        }
        if (parsed == Parsed::out_of_range) {
            throw Error(Status::bad_format,
                        str_cat(label, ": value ", i + 1, " of ", count, ' ', quote_bytes(token),
                                " is out of the ", type_name(type), " range ", range_text<T>()));
        }
        if (parsed != Parsed::ok) {
            throw Error(Status::bad_format,
                        str_cat(label, ": value ", i + 1, " of ", count, ' ', quote_bytes(token),
                                " is not a number, expected ", type_name(type), " values"));
        }
        pos = end;
    }
    return pos;
}

} // namespace

std::size_t parse_ascii_samples(std::string_view text, Volume& volume, const std::string& label)
{
    return dispatch_scalar_type(volume.type(), [&](auto tag) {
        using T = decltype(tag);
        return parse_ascii_typed<T>(text, volume.samples<T>(), volume.sample_count(),
                                    volume.type(), label);
    });
}

} // namespace detail
} // namespace cmc33::io
