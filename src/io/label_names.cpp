// Names and colours of a label map's labels: from a 3D Slicer segmentation's NRRD header
// (.seg.nrrd: "SegmentN_Name:=", "SegmentN_Color:=", "SegmentN_LabelValue:=", "SegmentN_Layer:="
// key/value pairs, slicer.readthedocs.io, developer guide, "Segmentation labelmap file format") or
// from a colour table: 3D Slicer's and FreeSurfer's "value name R G B [A]" lines, or ITK-SNAP's
// label descriptions "value R G B A visible mesh \"name\"".

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "volume_formats.hpp"

namespace cmc33::io {
namespace {

using detail::quote_bytes;
using detail::str_cat;
using detail::trim;

/// Colour tables and headers larger than this are refused (FreeSurfer's full table is 0.1 MiB).
constexpr std::size_t kMaxTableBytes = std::size_t{16} << 20;

/// The readers' integer and number parsers (volume_formats.hpp), as optionals; numbers finite.
std::optional<std::int64_t> parse_integer(std::string_view text)
{
    std::int64_t value = 0;
    return detail::parse_integer(text, value) ? std::optional(value) : std::nullopt;
}

std::optional<double> parse_number(std::string_view text)
{
    double value = 0;
    return detail::parse_real(text, value) && std::isfinite(value) ? std::optional(value) : std::nullopt;
}

/// The lines of `text` (LF or CR LF).
std::vector<std::string_view> lines_of(std::string_view text)
{
    std::vector<std::string_view> lines;
    while (!text.empty()) {
        const std::size_t end = text.find('\n');
        std::string_view line = text.substr(0, end);
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        lines.push_back(line);
        if (end == std::string_view::npos) break;
        text.remove_prefix(end + 1);
    }
    return lines;
}

struct Token {
    std::string text;
    bool quoted = false;
};

/// Blank-separated words; a word in double quotes may hold blanks. Nullopt for an unclosed quote.
std::optional<std::vector<Token>> tokens_of(std::string_view line)
{
    std::vector<Token> tokens;
    std::size_t i = 0;
    const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f'; };
    while (i < line.size()) {
        if (blank(line[i])) {
            ++i;
            continue;
        }
        Token t;
        if (line[i] == '"') {
            const std::size_t close = line.find('"', i + 1);
            if (close == std::string_view::npos) return std::nullopt;
            t.text = std::string(line.substr(i + 1, close - i - 1));
            t.quoted = true;
            i = close + 1;
        } else {
            const std::size_t start = i;
            while (i < line.size() && !blank(line[i])) ++i;
            t.text = std::string(line.substr(start, i - start));
        }
        tokens.push_back(std::move(t));
    }
    return tokens;
}

/// A colour channel 0..255 as a fraction.
std::optional<float> channel_255(std::string_view text)
{
    const std::optional<std::int64_t> v = parse_integer(text);
    if (!v || *v < 0 || *v > 255) return std::nullopt;
    return static_cast<float>(static_cast<double>(*v) / 255.0);
}

std::string read_text_file(const std::filesystem::path& path, const char* what)
{
    const std::string label = path.string();
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec) throw Error(Status::io_error, str_cat(label, ": cannot read the ", what, " (", ec.message(), ")"));
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(Status::io_error, str_cat(label, ": cannot open the ", what));
    std::string text(static_cast<std::size_t>(std::min<std::uintmax_t>(size, kMaxTableBytes + 1)), '\0');
    in.read(text.data(), static_cast<std::streamsize>(text.size()));
    text.resize(static_cast<std::size_t>(in.gcount()));
    if (in.bad()) throw Error(Status::io_error, str_cat(label, ": cannot read the ", what));
    return text;
}

/// NRRD's escapes in a key/value pair's value: \n and \\ (teem's format definition).
std::string unescape_nrrd_value(std::string_view value)
{
    std::string out;
    for (std::size_t i = 0; i < value.size(); ++i) {
        if (value[i] == '\\' && i + 1 < value.size() && (value[i + 1] == 'n' || value[i + 1] == '\\')) {
            out += value[i + 1] == 'n' ? '\n' : '\\';
            ++i;
        } else {
            out += value[i];
        }
    }
    return out;
}

} // namespace

std::vector<LabelName> parse_colour_table(std::string_view text, const std::string& label)
{
    if (text.size() > kMaxTableBytes) {
        throw Error(Status::bad_format, str_cat(label, ": a colour table of more than ", kMaxTableBytes >> 20,
                                                " MiB; expected a text file of one label per line"));
    }
    std::vector<LabelName> table;
    std::map<std::int64_t, std::size_t> line_of_value;
    std::size_t line_number = 0;
    for (const std::string_view raw : lines_of(text)) {
        ++line_number;
        const std::string_view line = trim(raw);
        if (line.empty() || line.front() == '#') continue;
        const auto bad = [&](const std::string& why) {
            return Error(Status::bad_format,
                         str_cat(label, ": line ", line_number, ' ', quote_bytes(line), ' ', why,
                                 "; expected \"value name [R G B [A]]\" (3D Slicer, FreeSurfer; 0-255) or "
                                 "\"value R G B A visible mesh \\\"name\\\"\" (ITK-SNAP)"));
        };
        const std::optional<std::vector<Token>> tokens = tokens_of(line);
        if (!tokens) throw bad("has a quote that is not closed");
        const std::vector<Token>& t = *tokens;
        LabelName entry;
        const std::optional<std::int64_t> value = t.empty() ? std::nullopt : parse_integer(t[0].text);
        if (!value || t[0].quoted) throw bad("does not start with an integer label value");
        entry.value = *value;
        if (t.size() == 8 && t[7].quoted) {
            // ITK-SNAP: R G B 0-255, A 0-1, visibility and mesh flags, the name in quotes
            std::array<float, 3> colour{};
            for (std::size_t k = 0; k < 3; ++k) {
                const std::optional<float> c = channel_255(t[1 + k].text);
                if (!c) throw bad("has a colour channel that is not an integer from 0 to 255");
                colour[k] = *c;
            }
            const std::optional<double> alpha = parse_number(t[4].text);
            if (!alpha || *alpha < 0 || *alpha > 1) throw bad("has an opacity that is not a number from 0 to 1");
            entry.colour = colour;
            entry.name = t[7].text;
        } else if (t.size() == 2 || t.size() == 5 || t.size() == 6) {
            entry.name = t[1].text;
            if (t.size() >= 5) {
                std::array<float, 3> colour{};
                for (std::size_t k = 0; k < 3; ++k) {
                    const std::optional<float> c = channel_255(t[2 + k].text);
                    if (!c) throw bad("has a colour channel that is not an integer from 0 to 255");
                    colour[k] = *c;
                }
                if (t.size() == 6 && !channel_255(t[5].text)) throw bad("has an alpha that is not an integer from 0 to 255");
                entry.colour = colour;
            }
        } else {
            throw bad(str_cat("has ", t.size(), t.size() == 1 ? " word" : " words"));
        }
        if (entry.name.empty()) throw bad("has an empty name");
        if (const auto [at, inserted] = line_of_value.emplace(entry.value, line_number); !inserted) {
            throw Error(Status::bad_format, str_cat(label, ": label ", entry.value, " is named twice (lines ",
                                                    at->second, " and ", line_number,
                                                    "); expected one line per label value"));
        }
        table.push_back(std::move(entry));
    }
    if (table.empty()) {
        throw Error(Status::bad_format,
                    str_cat(label, ": no label in the colour table; expected lines \"value name [R G B [A]]\" "
                                   "or ITK-SNAP's \"value R G B A visible mesh \\\"name\\\"\""));
    }
    return table;
}

std::vector<LabelName> read_colour_table(const std::filesystem::path& path)
{
    return parse_colour_table(read_text_file(path, "colour table"), path.string());
}

std::vector<LabelName> parse_segment_names(std::string_view header, const std::string& label)
{
    if (!header.starts_with("NRRD000")) return {};
    struct Segment {
        std::optional<std::string> name;
        std::optional<std::array<float, 3>> colour;
        std::optional<std::int64_t> value;
        std::int64_t layer = 0;
    };
    std::map<std::int64_t, Segment> segments;
    std::size_t line_number = 0;
    for (const std::string_view line : lines_of(header)) {
        ++line_number;
        if (trim(line).empty()) break; // the header ends at the first empty line
        const std::size_t pair = line.find(":=");
        if (pair == std::string_view::npos || !line.starts_with("Segment")) continue;
        const std::string_view key = line.substr(0, pair);
        const std::size_t underscore = key.find('_');
        if (underscore == std::string_view::npos) continue;
        const std::optional<std::int64_t> index = parse_integer(key.substr(7, underscore - 7));
        if (!index) continue; // Segmentation_... and the like
        const std::string_view field = key.substr(underscore + 1);
        const std::string value = unescape_nrrd_value(line.substr(pair + 2));
        const auto bad = [&](const char* expected) {
            return Error(Status::bad_format, str_cat(label, ": line ", line_number, ' ', quote_bytes(line), " is not ",
                                                     expected, " (3D Slicer's segmentation fields)"));
        };
        Segment& s = segments[*index];
        if (field == "Name") {
            s.name = value;
        } else if (field == "LabelValue") {
            s.value = parse_integer(trim(value));
            if (!s.value) throw bad("an integer label value");
        } else if (field == "Layer") {
            const std::optional<std::int64_t> layer = parse_integer(trim(value));
            if (!layer || *layer < 0) throw bad("a layer number from 0");
            s.layer = *layer;
        } else if (field == "Color") {
            const std::vector<std::string_view> words = detail::split_words(value);
            std::array<float, 3> colour{};
            bool ok = words.size() == 3;
            for (std::size_t k = 0; ok && k < 3; ++k) {
                const std::optional<double> c = parse_number(words[k]);
                ok = c && *c >= 0 && *c <= 1;
                if (ok) colour[k] = static_cast<float>(*c);
            }
            if (!ok) throw bad("a colour of three numbers from 0 to 1");
            s.colour = colour;
        }
    }
    std::vector<LabelName> names;
    std::map<std::int64_t, std::int64_t> segment_of_value;
    for (const auto& [index, s] : segments) {
        // a segment of another layer (overlapping segments: a 4-D file) or without a value names nothing here
        if (!s.value || s.layer != 0) continue;
        if (const auto [at, inserted] = segment_of_value.emplace(*s.value, index); !inserted) {
            throw Error(Status::bad_format, str_cat(label, ": segments ", at->second, " and ", index,
                                                    " both have label value ", *s.value,
                                                    " in layer 0; expected one segment per value"));
        }
        names.push_back(LabelName{*s.value, s.name.value_or(std::string()), s.colour});
    }
    return names;
}

std::vector<LabelName> read_segment_names(const std::filesystem::path& volume)
{
    std::error_code ec;
    if (!std::filesystem::is_regular_file(volume, ec)) return {}; // a DICOM folder, say
    std::ifstream in(volume, std::ios::binary);
    if (!in) throw Error(Status::io_error, str_cat(volume.string(), ": cannot open the volume"));
    std::string head(detail::kMaxHeaderBytes, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(in.gcount()));
    return parse_segment_names(head, volume.string());
}

} // namespace cmc33::io
