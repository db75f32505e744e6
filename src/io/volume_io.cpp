// Volume I/O: the choice of format by extension, and what the formats share: header values,
// size checks, reading samples (raw, compressed, ASCII) into a volume, writing samples.

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "cmc33/io.hpp"
#include "atomic_file.hpp"
#include "byte_source.hpp"
#include "volume_formats.hpp"
#include "dicom.hpp"
#include "tiff.hpp"

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

// ---- samples --------------------------------------------------------------------------------

namespace {

Volume allocate(const Grid& grid, const std::string& label)
{
    try {
        Volume volume(grid.type, grid.dims, grid.spacing, grid.origin);
        volume.set_direction(grid.direction);
        volume.set_space(grid.space);
        volume.set_frame_source(grid.frame_source);
        return volume;
    } catch (const Error& e) {
        throw Error(e.status(), label + ": " + e.what());
    }
}

std::string declared(const Grid& grid, std::uint64_t bytes)
{
    return str_cat("header declares ", dims_text(grid.dims), ' ', type_name(grid.type), " (", bytes,
                   " bytes)");
}

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

namespace {

/// The bytes of a file of `size` bytes after the samples' offset.
/// @throws Error{truncated_file} when the offset lies beyond the end
std::uint64_t bytes_after_offset(std::uint64_t size, const Storage& storage, const std::string& label)
{
    if (storage.offset > size) {
        throw Error(Status::truncated_file,
                    str_cat(label, ": the samples should start at byte ", storage.offset,
                            " but the file has only ", size, " bytes (file cut short?)"));
    }
    return size - storage.offset;
}

} // namespace

std::uint64_t check_raw_samples(const ByteInput& file, const Grid& grid, const Storage& storage,
                                const std::string& label)
{
    const std::uint64_t bytes = payload_bytes(grid.dims, grid.type, label);
    const std::uint64_t size = file.size();
    const std::uint64_t available = bytes_after_offset(size, storage, label);
    if (available < bytes) {
        throw Error(Status::truncated_file,
                    str_cat(label, ": ", declared(grid, bytes), " but only ", available,
                            " bytes follow byte ", storage.offset,
                            " (file cut short, or wrong sizes?)"));
    }
    if (available > bytes && !storage.at_end && storage.check_trailing) {
        throw Error(Status::bad_format,
                    str_cat(label, ": ", declared(grid, bytes), " but ", available,
                            " bytes follow byte ", storage.offset, ": ", available - bytes,
                            " more after the samples (wrong sizes, or data appended?)"));
    }
    return storage.at_end ? size - bytes : storage.offset;
}

std::uint64_t check_compressed_samples(const ByteInput& file, const Grid& grid, const Storage& storage,
                                       const std::string& label)
{
    const std::uint64_t bytes = payload_bytes(grid.dims, grid.type, label);
    const std::uint64_t size = file.size();
    const std::uint64_t available = bytes_after_offset(size, storage, label);
    std::uint64_t stream = available;
    if (storage.stored_size) {
        if (*storage.stored_size > available) {
            throw Error(Status::truncated_file,
                        str_cat(label, ": the header declares ", *storage.stored_size,
                                " compressed bytes but only ", available, " follow byte ",
                                storage.offset,
                                " (file cut short, or wrong compressed size?)"));
        }
        stream = *storage.stored_size;
    }
    // Nothing of the declared size is allocated unless the stream could hold it, and then
    // only as much as the stream really yields.
    const std::uint64_t inflated = storage.skip_inflated + bytes;
    check_inflate_bound(stream, inflated,
                        label, storage.skip_inflated == 0
                                   ? declared(grid, bytes)
                                   : str_cat(declared(grid, bytes), " after ",
                                             storage.skip_inflated, " skipped bytes (",
                                             inflated, " in all)"));
    return stream;
}

void check_after_stream(const ByteInput& file, const Storage& storage, std::uint64_t stream, const std::string& label)
{
    const std::uint64_t available = file.size() - storage.offset;
    if (stream < available && storage.check_trailing) {
        throw Error(Status::bad_format,
                    str_cat(label, ": the header declares ", stream,
                            " compressed bytes but ", available, " follow byte ",
                            storage.offset, ": ", available - stream,
                            " more after the stream (wrong compressed size?)"));
    }
}

Volume read_samples(const ByteInput& file, const Grid& grid, const Storage& storage,
                    const std::string& label, std::uint64_t* end)
{
    const std::uint64_t bytes = payload_bytes(grid.dims, grid.type, label);
    const std::uint64_t size = file.size();
    const std::uint64_t available = bytes_after_offset(size, storage, label);
    const std::size_t width = type_size(grid.type);

    switch (storage.encoding) {
    case Encoding::raw: {
        const std::uint64_t offset = check_raw_samples(file, grid, storage, label);
        Volume volume = allocate(grid, label);
        file.read(offset, volume.bytes(), volume.byte_size());
        to_native(volume.bytes(), static_cast<std::size_t>(volume.sample_count()), width,
                  storage.endian);
        if (end) *end = offset + bytes;
        return volume;
    }
    case Encoding::compressed: {
        const std::uint64_t stream = check_compressed_samples(file, grid, storage, label);
        const std::string compressed = file.read_string(storage.offset, stream);
        std::unique_ptr<std::byte[]> samples = inflate_exact(
            compressed, storage.skip_inflated, static_cast<std::size_t>(bytes), label);
        check_after_stream(file, storage, stream, label);
        to_native(samples.get(), static_cast<std::size_t>(bytes / width), width, storage.endian);
        if (end) *end = storage.offset + stream;
        try {
            Volume volume(grid.type, grid.dims, grid.spacing, grid.origin, std::move(samples));
            volume.set_direction(grid.direction);
            volume.set_space(grid.space);
            volume.set_frame_source(grid.frame_source);
            return volume;
        } catch (const Error& e) {
            throw Error(e.status(), label + ": " + e.what());
        }
    }
    case Encoding::ascii: {
        // Each value takes at least two bytes (a digit and a blank), the last one at least one:
        // check before allocating.
        const auto count = static_cast<std::uint64_t>(grid.dims[0]) *
                           static_cast<std::uint64_t>(grid.dims[1]) *
                           static_cast<std::uint64_t>(grid.dims[2]);
        if (count > available / 2 + 1) {
            throw Error(Status::truncated_file,
                        str_cat(label, ": the header declares ", dims_text(grid.dims), " = ", count,
                                " ASCII values but only ", available,
                                " bytes of data follow; each value takes at "
                                "least 2 (file cut short, or wrong sizes?)"));
        }
        const std::string text = file.read_string(storage.offset, available);
        Volume volume = allocate(grid, label);
        const std::size_t stop = parse_ascii_samples(text, volume, label);
        if (storage.check_trailing) {
            const std::size_t extra = text.find_first_not_of(" \t\n\r\v\f", stop);
            if (extra != std::string::npos) {
                throw Error(Status::bad_format,
                            str_cat(label, ": the header declares ", count,
                                    " values but more follow: ",
                                    quote_bytes(split_words(std::string_view(text).substr(
                                                    extra, 64)).front()),
                                    " at byte ", storage.offset + extra,
                                    " (wrong sizes, or data appended?)"));
            }
        }
        if (end) *end = storage.offset + stop;
        return volume;
    }
    }
    throw Error(Status::internal, label + ": unknown sample encoding");
}

void write_samples(std::ostream& out, const Volume& volume, Endian endian)
{
    const std::size_t width = type_size(volume.type());
    const auto* data = reinterpret_cast<const char*>(volume.bytes());
    const std::size_t total = volume.byte_size();
    if (width == 1 || endian == native_endian()) {
        out.write(data, static_cast<std::streamsize>(total));
        return;
    }
    constexpr std::size_t kBlock = std::size_t{1} << 20; // a multiple of every sample size
    std::vector<std::byte> block(std::min(total, kBlock));
    for (std::size_t done = 0; done < total;) {
        const std::size_t n = std::min(kBlock, total - done);
        std::memcpy(block.data(), data + done, n);
        swap_bytes(block.data(), n / width, width);
        out.write(reinterpret_cast<const char*>(block.data()), static_cast<std::streamsize>(n));
        done += n;
    }
}

} // namespace detail

// ---- public API -----------------------------------------------------------------------------

ScalarType parse_type(const std::string& name)
{
    struct Name {
        std::string_view text;
        ScalarType type;
    };
    static constexpr std::array<Name, 16> kNames{{
        {"int8", ScalarType::i8},
        {"uint8", ScalarType::u8},
        {"int16", ScalarType::i16},
        {"uint16", ScalarType::u16},
        {"int32", ScalarType::i32},
        {"uint32", ScalarType::u32},
        {"float", ScalarType::f32},
        {"double", ScalarType::f64},
        {"char", ScalarType::i8},
        {"uchar", ScalarType::u8},
        {"short", ScalarType::i16},
        {"ushort", ScalarType::u16},
        {"int", ScalarType::i32},
        {"uint", ScalarType::u32},
        {"float32", ScalarType::f32},
        {"float64", ScalarType::f64},
    }};
    const std::string key = detail::lower_ascii(detail::trim(name));
    for (const Name& n : kNames) {
        if (n.text == key) return n.type;
    }
    throw Error(Status::invalid_argument,
                "unknown sample type " + detail::quote_bytes(name) +
                    "; expected one of int8, uint8, int16, uint16, int32, uint32, float, double "
                    "(or char, uchar, short, ushort, int, uint, float32, float64)");
}

namespace {

/// x.hdr beside x.img when it holds a NIfTI header (a NIfTI pair named by its data file).
std::optional<std::filesystem::path> nifti_pair_header(const std::filesystem::path& path)
{
    if (detail::lower_extension(path) != ".img") return std::nullopt;
    for (const char* ext : {".hdr", ".HDR"}) {
        std::filesystem::path header = path;
        header.replace_extension(ext);
        std::error_code ec;
        if (!std::filesystem::is_regular_file(header, ec)) continue;
        try {
            const detail::InputFile file(header, header.string());
            if (detail::sniff_volume_format(file) == VolumeFormat::nifti) return header;
        } catch (const Error&) {
        }
    }
    return std::nullopt;
}

/// The format the content of `path` shows (NIfTI, .npy, .vti), or nullopt (also when unreadable).
std::optional<VolumeFormat> sniffed_format(const std::filesystem::path& path)
{
    try {
        std::error_code ec;
        if (!std::filesystem::is_regular_file(path, ec)) return std::nullopt;
        const detail::InputFile file(path, path.string());
        return detail::sniff_volume_format(file);
    } catch (const Error&) {
        return std::nullopt;
    }
}

/// NIfTI, .npy and .vti, read by content; `open_data` serves a NIfTI pair's .img.
Volume read_sniffed(VolumeFormat format, const detail::ByteInput& file, const detail::OpenDataFile& open_data,
                    const ReadOptions& options)
{
    switch (format) {
    case VolumeFormat::nifti: return detail::read_nifti(file, open_data, options);
    case VolumeFormat::npy: return detail::read_npy(file, options);
    case VolumeFormat::vti: return detail::read_vti(file, options);
    default: break;
    }
    throw Error(Status::internal, file.label() + ": not a format read by content");
}

} // namespace

bool has_volume_header(const std::filesystem::path& path)
{
    const std::string ext = detail::lower_extension(path);
    if (ext == ".nrrd" || ext == ".nhdr" || ext == ".mhd" || ext == ".mha" || ext == ".vtk" || ext == ".nii" ||
        ext == ".hdr" || ext == ".npy" || ext == ".vti" || detail::lower_ascii(path.filename().string()).ends_with(".nii.gz")) {
        return true;
    }
    return nifti_pair_header(path) || sniffed_format(path) || detail::image_input(path) != detail::ImageInput::none;
}

std::vector<std::filesystem::path> volume_files(const std::filesystem::path& path)
{
    // a DICOM or TIFF folder: the files in it that are read
    if (auto files = detail::image_input_files(path)) return std::move(*files);
    std::vector<std::filesystem::path> files{path};
    const std::string ext = detail::lower_extension(path);
    // a NIfTI pair: the header and its data file <stem>.img, whichever of them was named
    if (const auto header = nifti_pair_header(path)) {
        files.push_back(*header);
        return files;
    }
    if (ext == ".hdr" || sniffed_format(path) == VolumeFormat::nifti) {
        std::filesystem::path image = path;
        image.replace_extension(".img");
        if (image != path) files.push_back(image);
        return files;
    }
    const bool nrrd = ext == ".nrrd" || ext == ".nhdr";
    if (!nrrd && ext != ".mhd" && ext != ".mha") return files; // VTK and raw files hold their samples
    std::string head;
    try {
        const detail::InputFile file(path, path.string());
        head = file.read_string(0, detail::kMaxHeaderBytes);
    } catch (const Error&) {
        return files; // read_volume() fails on this file before it opens any other
    }
    const std::vector<std::string> names =
        nrrd ? detail::nrrd_data_file_names(head) : detail::metaimage_data_file_names(head);
    for (const std::string& name : names) files.push_back(detail::resolve_data_file(path, name));
    return files;
}

Volume read_volume(const std::filesystem::path& path, const std::optional<RawOptions>& raw, const ReadOptions& options)
{
    // DICOM and TIFF: folders, and files told by their marks (dicom.cpp)
    if (auto image = detail::read_image_input(path, options)) return std::move(*image);
    // a NIfTI pair named by its .img: read through its header
    if (const auto header = nifti_pair_header(path)) return read_volume(*header, raw, options);
    const std::string label = path.string();
    const std::string ext = detail::lower_extension(path);
    const detail::InputFile file(path, label);
    // Data files are named relative to the header's folder.
    const detail::OpenDataFile open_data = [&](std::string_view name) {
        const std::filesystem::path data = detail::resolve_data_file(path, name);
        return std::make_unique<detail::InputFile>(data, label + ": data file " + data.string());
    };
    // by content first (magic bytes), then by extension
    if (const auto format = detail::sniff_volume_format(file)) return read_sniffed(*format, file, open_data, options);
    if (ext == ".nii" || ext == ".hdr" || detail::lower_ascii(path.filename().string()).ends_with(".nii.gz")) return detail::read_nifti(file, open_data, options);
    if (ext == ".npy") return detail::read_npy(file, options);
    if (ext == ".vti") return detail::read_vti(file, options);
    if (ext == ".nrrd" || ext == ".nhdr") return detail::read_nrrd(file, open_data, ext == ".nhdr");
    if (ext == ".mhd" || ext == ".mha") return detail::read_metaimage(file, open_data);
    if (ext == ".vtk") return detail::read_vtk(file);
    return detail::read_raw(file, raw);
}

Volume read_volume_from_memory(std::string_view bytes, VolumeFormat format,
                               const std::string& label, const std::optional<RawOptions>& raw,
                               const MemoryFiles& data_files, const ReadOptions& options)
{
    const detail::MemoryInput input(bytes, label);
    const detail::OpenDataFile open_data =
        [&](std::string_view name) -> std::unique_ptr<detail::ByteInput> {
        const std::string data_label = label + ": data file " + std::string(name);
        const std::optional<std::string_view> data =
            data_files ? data_files(name) : std::optional<std::string_view>();
        if (!data) {
            throw Error(Status::io_error,
                        data_label + ": no such file among the data files given in memory");
        }
        return std::make_unique<detail::MemoryInput>(*data, data_label);
    };
    switch (format) {
    case VolumeFormat::nrrd: return detail::read_nrrd(input, open_data, false);
    case VolumeFormat::metaimage: return detail::read_metaimage(input, open_data);
    case VolumeFormat::vtk: return detail::read_vtk(input);
    case VolumeFormat::raw: break;
    case VolumeFormat::dicom: return detail::read_dicom_memory(bytes, label, options);
    case VolumeFormat::tiff: return detail::read_tiff_memory(bytes, label, options);
    case VolumeFormat::nifti:
    case VolumeFormat::npy:
    case VolumeFormat::vti: return read_sniffed(format, input, open_data, options);
    }
    return detail::read_raw(input, raw);
}

void write_volume(const Volume& volume, const std::filesystem::path& path)
{
    const std::string label = path.string();
    if (volume.bytes() == nullptr || volume.sample_count() <= 0) {
        throw Error(Status::invalid_argument,
                    label + ": cannot write an empty volume (it holds no samples)");
    }
    for (std::size_t axis = 0; axis < 3; ++axis) {
        if (!std::isfinite(volume.spacing()[axis]) || !std::isfinite(volume.origin()[axis])) {
            throw Error(Status::non_finite,
                        detail::str_cat(label,
                                        ": cannot write a volume whose spacing or origin "
                                        "is not finite (axis ",
                                        axis, ")"));
        }
        if (!(volume.spacing()[axis] > 0)) {
            throw Error(Status::invalid_argument,
                        detail::str_cat(label, ": cannot write spacing ", volume.spacing()[axis],
                                        " on axis ", axis, "; spacings must be > 0"));
        }
    }
    const std::string ext = detail::lower_extension(path);
    if (ext == ".nrrd" || ext == ".nhdr") {
        detail::write_nrrd(volume, path, ext == ".nhdr");
    } else if (ext == ".mhd" || ext == ".mha") {
        detail::write_metaimage(volume, path, ext == ".mha");
    } else if (ext == ".vtk") {
        detail::write_vtk(volume, path);
    } else if (ext == ".raw") {
        detail::write_raw(volume, path);
    } else {
        throw Error(Status::unsupported_format,
                    label + ": cannot write volume format " +
                        (ext.empty() ? "(no extension)" : "\"" + ext + "\"") +
                        "; accepted extensions: .nrrd .nhdr .mhd .mha .vtk .raw");
    }
}

} // namespace cmc33::io
