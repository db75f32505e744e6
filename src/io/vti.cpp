// VTK XML ImageData (.vti), from VTK's description of its XML file formats: <VTKFile
// type="ImageData" byte_order header_type compressor>, <ImageData WholeExtent Origin Spacing
// Direction>, one <Piece>, <PointData Scalars=...> with <DataArray type Name NumberOfComponents
// format offset>, and <AppendedData encoding="raw|base64">_...</AppendedData>. Written for cmc33.
//
// Data: ascii (decimal text), binary (base64 inline) and appended (raw or base64), each either
// uncompressed (a header word with the byte count, then the bytes) or compressed by
// vtkZLibDataCompressor (header: block count, block size, size of the last block, then each
// block's compressed size; then the zlib blocks). Header words are UInt32 or UInt64 (header_type)
// in byte_order. Base64 parts encoded separately (header, then data) are decoded as one stream,
// group by group, which gives their concatenation.
//
// Frame: world = Origin + Direction * (Spacing (.) (i, j, k)) for the indices of WholeExtent;
// Direction is row-major, so its column a is the world direction of axis a, as in cmc33.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cmc33/io.hpp"
#include "byte_source.hpp"
#include "sample_conversion.hpp"
#include "volume_formats.hpp"

namespace cmc33::io::detail {
namespace {

/// One XML start tag: its name, attributes and where it ends in the text.
struct Tag {
    std::string name;
    std::vector<std::pair<std::string, std::string>> attributes;
    std::size_t begin = 0, end = 0; ///< '<' and just past '>'
    bool self_closing = false;

    std::optional<std::string> get(std::string_view key) const
    {
        for (const auto& [k, v] : attributes) {
            if (k == key) return v;
        }
        return std::nullopt;
    }
};

/// The next start tag named `name` at or after `from` (before `limit`), or nullopt.
std::optional<Tag> find_tag(std::string_view text, std::string_view name, std::size_t from, std::size_t limit,
                            const std::string& label)
{
    const std::string open = "<" + std::string(name);
    std::size_t at = from;
    while (true) {
        at = text.find(open, at);
        if (at == std::string_view::npos || at >= limit) return std::nullopt;
        const std::size_t after = at + open.size();
        if (after < text.size() && (text[after] == ' ' || text[after] == '>' || text[after] == '/' || text[after] == '\n' ||
                                    text[after] == '\t' || text[after] == '\r')) {
            break;
        }
        at = after;
    }
    Tag tag;
    tag.name = std::string(name);
    tag.begin = at;
    std::size_t i = at + open.size();
    while (true) {
        while (i < text.size() && std::string_view(" \t\r\n").find(text[i]) != std::string_view::npos) ++i;
        if (i >= text.size()) throw Error(Status::truncated_file, str_cat(label, ": the <", name, "> tag is not closed"));
        if (text[i] == '>') {
            tag.end = i + 1;
            return tag;
        }
        if (text[i] == '/' && i + 1 < text.size() && text[i + 1] == '>') {
            tag.self_closing = true;
            tag.end = i + 2;
            return tag;
        }
        const std::size_t eq = text.find('=', i);
        if (eq == std::string_view::npos || eq + 1 >= text.size() || (text[eq + 1] != '"' && text[eq + 1] != '\'')) {
            throw Error(Status::bad_format, str_cat(label, ": a malformed attribute in the <", name, "> tag at byte ", i));
        }
        const std::string key(trim(text.substr(i, eq - i)));
        const std::size_t close = text.find(text[eq + 1], eq + 2);
        if (close == std::string_view::npos) {
            throw Error(Status::truncated_file, str_cat(label, ": the attribute ", quote_bytes(key), " of <", name, "> is not closed"));
        }
        tag.attributes.emplace_back(key, std::string(text.substr(eq + 2, close - eq - 2)));
        i = close + 1;
    }
}

std::vector<double> numbers(const Tag& tag, std::string_view key, std::size_t count, const std::string& label)
{
    const std::optional<std::string> value = tag.get(key);
    if (!value) throw Error(Status::bad_format, str_cat(label, ": <", tag.name, "> has no ", key));
    const std::vector<std::string_view> words = split_words(*value);
    if (words.size() != count) {
        throw Error(Status::bad_format, str_cat(label, ": ", key, "=", quote_bytes(*value), " has ", words.size(), " values, expected ", count));
    }
    std::vector<double> out(count);
    for (std::size_t i = 0; i < count; ++i) {
        if (!parse_real(words[i], out[i]) || !std::isfinite(out[i])) {
            throw Error(Status::bad_format, str_cat(label, ": ", key, " value ", quote_bytes(words[i]), " is not a finite number"));
        }
    }
    return out;
}

/// Base64 (RFC 4648) decoded group by group; blanks are skipped. Decodes until `want` bytes are
/// out (or the text ends); `used` receives the characters consumed.
std::string decode_base64(std::string_view text, std::size_t want, std::size_t& used, const std::string& label)
{
    static const auto kTable = [] {
        std::array<int, 256> t{};
        t.fill(-1);
        const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        for (int i = 0; i < 64; ++i) t[static_cast<unsigned char>(alphabet[i])] = i;
        return t;
    }();
    std::string out;
    out.reserve(std::min<std::size_t>(want, text.size()));
    std::size_t i = 0;
    while (out.size() < want) {
        std::array<int, 4> group{};
        int n = 0, pad = 0;
        while (n < 4 && i < text.size()) {
            const auto c = static_cast<unsigned char>(text[i++]);
            if (c == ' ' || c == '\n' || c == '\r' || c == '\t') continue;
            if (c == '=') {
                group[static_cast<std::size_t>(n++)] = 0, ++pad;
                continue;
            }
            if (kTable[c] < 0 || pad > 0) {
                throw Error(Status::bad_format, str_cat(label, ": ", quote_bytes(std::string_view(text).substr(i - 1, 1)),
                                                        " in base64 data is not a base64 character"));
            }
            group[static_cast<std::size_t>(n++)] = kTable[c];
        }
        if (n == 0) break;
        if (n < 4) throw Error(Status::truncated_file, str_cat(label, ": the base64 data ends inside a group of 4 characters"));
        const std::uint32_t v = static_cast<std::uint32_t>(group[0]) << 18 | static_cast<std::uint32_t>(group[1]) << 12 |
                                static_cast<std::uint32_t>(group[2]) << 6 | static_cast<std::uint32_t>(group[3]);
        out += static_cast<char>(v >> 16);
        if (pad < 2) out += static_cast<char>((v >> 8) & 0xff);
        if (pad < 1) out += static_cast<char>(v & 0xff);
    }
    used = i;
    return out;
}

struct ArrayType {
    std::string_view name;
    ScalarType read_as;
    StoredKind kind;
};

constexpr ArrayType kTypes[] = {
    {"Int8", ScalarType::i8, StoredKind::as_is},     {"UInt8", ScalarType::u8, StoredKind::as_is},
    {"Int16", ScalarType::i16, StoredKind::as_is},   {"UInt16", ScalarType::u16, StoredKind::as_is},
    {"Int32", ScalarType::i32, StoredKind::as_is},   {"UInt32", ScalarType::u32, StoredKind::as_is},
    {"Int64", ScalarType::f64, StoredKind::int64},   {"UInt64", ScalarType::f64, StoredKind::uint64},
    {"Float32", ScalarType::f32, StoredKind::as_is}, {"Float64", ScalarType::f64, StoredKind::as_is},
    {"Char", ScalarType::i8, StoredKind::as_is},
};

/// Reads one header word (4 or 8 bytes) at `at` of `bytes`.
std::uint64_t word(std::string_view bytes, std::size_t at, std::size_t width, Endian endian, const std::string& label)
{
    if (at + width > bytes.size()) {
        throw Error(Status::truncated_file, str_cat(label, ": the data array's header is cut short"));
    }
    std::array<unsigned char, 8> raw{};
    std::memcpy(raw.data(), bytes.data() + at, width);
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < width; ++i) {
        const std::size_t k = endian == Endian::little ? width - 1 - i : i;
        v = v << 8 | raw[k];
    }
    return v;
}

} // namespace

Volume read_vti(const ByteInput& file, const ReadOptions& options)
{
    const std::string& label = file.label();
    if (file.size() == 0) throw Error(Status::truncated_file, label + ": the file is empty (0 bytes), expected VTK XML");
    if (options.spacing || options.origin) {
        throw Error(Status::invalid_argument,
                    label + ": a .vti file gives its own frame; --spacing and --origin are for formats without one (.npy)");
    }
    const std::string text = file.read_string(0, file.size());
    const std::size_t n = text.size();
    const auto vtk = find_tag(text, "VTKFile", 0, n, label);
    if (!vtk) throw Error(Status::bad_format, label + ": no <VTKFile> tag: not a VTK XML file");
    if (vtk->get("type").value_or("") != "ImageData") {
        throw Error(Status::unsupported_format, str_cat(label, ": VTKFile type ", quote_bytes(vtk->get("type").value_or("")),
                                                        "; cmc33 reads ImageData (.vti)"));
    }
    const std::string order = vtk->get("byte_order").value_or("LittleEndian");
    if (order != "LittleEndian" && order != "BigEndian") {
        throw Error(Status::bad_format, str_cat(label, ": byte_order ", quote_bytes(order), ", expected LittleEndian or BigEndian"));
    }
    const Endian endian = order == "BigEndian" ? Endian::big : Endian::little;
    const std::string header_type = vtk->get("header_type").value_or("UInt32");
    if (header_type != "UInt32" && header_type != "UInt64") {
        throw Error(Status::bad_format, str_cat(label, ": header_type ", quote_bytes(header_type), ", expected UInt32 or UInt64"));
    }
    const std::size_t hw = header_type == "UInt64" ? 8 : 4;
    const std::string compressor = vtk->get("compressor").value_or("");
    if (!compressor.empty() && compressor != "vtkZLibDataCompressor") {
        throw Error(Status::unsupported_format, str_cat(label, ": compressor ", quote_bytes(compressor),
                                                        " is not read; cmc33 reads uncompressed and vtkZLibDataCompressor data"));
    }

    const auto image = find_tag(text, "ImageData", vtk->end, n, label);
    if (!image) throw Error(Status::bad_format, label + ": no <ImageData> tag");
    const std::vector<double> whole = numbers(*image, "WholeExtent", 6, label);
    Index3 dims{}, lo{};
    for (std::size_t a = 0; a < 3; ++a) {
        if (whole[2 * a] != std::floor(whole[2 * a]) || whole[2 * a + 1] != std::floor(whole[2 * a + 1]) ||
            std::fabs(whole[2 * a]) > 1e15 || std::fabs(whole[2 * a + 1]) > 1e15) {
            throw Error(Status::bad_format, str_cat(label, ": WholeExtent holds a value that is not a whole number"));
        }
        lo[a] = static_cast<std::int64_t>(whole[2 * a]);
        dims[a] = static_cast<std::int64_t>(whole[2 * a + 1]) - lo[a] + 1;
    }
    const std::vector<double> origin = image->get("Origin") ? numbers(*image, "Origin", 3, label) : std::vector<double>{0, 0, 0};
    const std::vector<double> spacing = image->get("Spacing") ? numbers(*image, "Spacing", 3, label) : std::vector<double>{1, 1, 1};
    const std::vector<double> direction =
        image->get("Direction") ? numbers(*image, "Direction", 9, label) : std::vector<double>{1, 0, 0, 0, 1, 0, 0, 0, 1};
    Grid grid;
    grid.dims = dims;
    std::array<Vec3, 3> axes{};
    Vec3 scale{};
    for (std::size_t a = 0; a < 3; ++a) {
        if (!(spacing[a] > 0)) {
            throw Error(Status::bad_format, str_cat(label, ": Spacing value ", format_real(spacing[a]), " is not positive; spacings must be > 0"));
        }
        for (std::size_t r = 0; r < 3; ++r) axes[a][r] = direction[3 * r + a];
        scale[a] = spacing[a];
    }
    set_frame(grid, axes, scale, label, "Direction");
    // the first sample of WholeExtent may lie at a non-zero index
    for (std::size_t r = 0; r < 3; ++r) {
        grid.origin[r] = origin[r];
        for (std::size_t a = 0; a < 3; ++a) grid.origin[r] += direction[3 * r + a] * spacing[a] * static_cast<double>(lo[a]);
    }
    grid.frame_source = image->get("Direction") ? "Origin, Spacing, Direction" : "Origin, Spacing (no Direction: axis-aligned)";

    // one piece covering the whole extent
    const auto piece = find_tag(text, "Piece", image->end, n, label);
    if (!piece) throw Error(Status::bad_format, label + ": no <Piece> in <ImageData>");
    if (find_tag(text, "Piece", piece->end, n, label)) {
        throw Error(Status::unsupported_format, label + ": several <Piece> elements; cmc33 reads a .vti of one piece (merge the pieces first)");
    }
    if (piece->get("Extent") && numbers(*piece, "Extent", 6, label) != whole) {
        throw Error(Status::unsupported_format, label + ": the piece's Extent differs from WholeExtent; cmc33 reads one piece covering it");
    }
    const std::size_t piece_end = std::min(n, text.find("</Piece>", piece->end));
    const auto point_data = find_tag(text, "PointData", piece->end, piece_end, label);
    std::vector<Tag> arrays;
    if (point_data && !point_data->self_closing) {
        const std::size_t pd_end = std::min(piece_end, text.find("</PointData>", point_data->end));
        for (std::size_t at = point_data->end; auto a = find_tag(text, "DataArray", at, pd_end, label);) {
            arrays.push_back(*a);
            at = a->end;
        }
    }
    if (arrays.empty()) {
        const bool cells = find_tag(text, "DataArray", piece->end, piece_end, label).has_value();
        throw Error(Status::unsupported_format, label + (cells ? ": no point data, only cell data; cmc33 meshes samples at the points"
                                                               : ": no point-data array"));
    }
    const std::string wanted = !options.array.empty() ? options.array : point_data->get("Scalars").value_or("");
    const Tag* chosen = nullptr;
    std::string names;
    for (const Tag& a : arrays) {
        names += str_cat(names.empty() ? "" : ", ", quote_bytes(a.get("Name").value_or("")));
        if (!wanted.empty() && a.get("Name") == wanted) chosen = &a;
    }
    if (!chosen) {
        if (!options.array.empty() || arrays.size() > 1) {
            throw Error(Status::invalid_argument,
                        str_cat(label, !options.array.empty() ? str_cat(": no point-data array named ", quote_bytes(options.array))
                                                              : std::string(": several point-data arrays and none marked Scalars"),
                                "; the arrays: ", names, " (choose one with --array NAME)"));
        }
        chosen = &arrays.front();
    }
    const std::string array_name = chosen->get("Name").value_or("");
    if (const auto components = chosen->get("NumberOfComponents"); components && *components != "1") {
        throw Error(Status::unsupported_format, str_cat(label, ": point-data array ", quote_bytes(array_name), " has ", quote_bytes(*components),
                                                        " components per point; cmc33 meshes one scalar per point"));
    }
    const std::string type_name_text = chosen->get("type").value_or("");
    const ArrayType* type = nullptr;
    for (const ArrayType& t : kTypes) {
        if (t.name == type_name_text) type = &t;
    }
    if (!type) {
        throw Error(Status::unsupported_format, str_cat(label, ": array ", quote_bytes(array_name), " has type ",
                                                        quote_bytes(type_name_text), "; cmc33 reads Int8 to Int64, UInt8 to UInt64, Float32, Float64"));
    }
    grid.type = type->read_as;
    const std::uint64_t bytes = payload_bytes(grid.dims, grid.type, label);
    const std::string format = chosen->get("format").value_or("ascii");
    const std::string what = str_cat("array ", quote_bytes(array_name), ": ");

    Volume volume;
    const auto make = [&](std::string samples) {
        auto buffer = std::make_unique<std::byte[]>(static_cast<std::size_t>(bytes));
        std::memcpy(buffer.get(), samples.data(), static_cast<std::size_t>(bytes));
        to_native(buffer.get(), static_cast<std::size_t>(bytes / type_size(grid.type)), type_size(grid.type), endian);
        Volume v(grid.type, grid.dims, grid.spacing, grid.origin, std::move(buffer));
        v.set_direction(grid.direction);
        v.set_frame_source(grid.frame_source);
        return v;
    };
    if (format == "ascii") {
        if (chosen->self_closing) throw Error(Status::bad_format, label + ": " + what + "ascii data without content");
        const std::size_t close = text.find("</DataArray>", chosen->end);
        if (close == std::string::npos) throw Error(Status::truncated_file, label + ": " + what + "no </DataArray>");
        Grid g = grid;
        if (type->kind != StoredKind::as_is) g.type = ScalarType::f64; // text integers read as double
        const MemoryInput part(std::string_view(text).substr(chosen->end, close - chosen->end), label);
        Storage storage;
        storage.encoding = Encoding::ascii;
        volume = read_samples(part, g, storage, label);
        volume.set_frame_source(grid.frame_source);
        return volume;
    }
    // the array's encoded bytes: inline base64, or appended (raw or base64) from its offset
    std::string_view source;
    bool base64 = true;
    if (format == "binary") {
        const std::size_t close = text.find("</DataArray>", chosen->end);
        if (close == std::string::npos) throw Error(Status::truncated_file, label + ": " + what + "no </DataArray>");
        source = std::string_view(text).substr(chosen->end, close - chosen->end);
    } else if (format == "appended") {
        const auto appended = find_tag(text, "AppendedData", piece_end, n, label);
        if (!appended) throw Error(Status::bad_format, label + ": " + what + "format appended, but no <AppendedData>");
        const std::string encoding = appended->get("encoding").value_or("raw");
        if (encoding != "raw" && encoding != "base64") {
            throw Error(Status::bad_format, str_cat(label, ": AppendedData encoding ", quote_bytes(encoding), ", expected raw or base64"));
        }
        base64 = encoding == "base64";
        const std::size_t underscore = text.find('_', appended->end);
        if (underscore == std::string::npos) throw Error(Status::truncated_file, label + ": AppendedData without its '_' mark");
        std::int64_t offset = 0;
        if (!parse_integer(chosen->get("offset").value_or(""), offset) || offset < 0 ||
            static_cast<std::uint64_t>(offset) > n - underscore - 1) {
            throw Error(Status::bad_format, str_cat(label, ": ", what, "offset ", quote_bytes(chosen->get("offset").value_or("")),
                                                    " is not within the appended data"));
        }
        source = std::string_view(text).substr(underscore + 1 + static_cast<std::size_t>(offset));
    } else {
        throw Error(Status::bad_format, str_cat(label, ": ", what, "format ", quote_bytes(format), ", expected ascii, binary or appended"));
    }
    // decoded bytes on demand: raw appended data is itself; base64 is decoded as far as needed
    std::size_t used = 0;
    const auto decoded = [&](std::size_t count) -> std::string {
        if (!base64) {
            if (count > source.size()) throw Error(Status::truncated_file, str_cat(label, ": ", what, "the data is cut short"));
            return std::string(source.substr(0, count));
        }
        if (count > source.size()) throw Error(Status::truncated_file, str_cat(label, ": ", what, "the data is cut short"));
        std::string out = decode_base64(source, count, used, label);
        if (out.size() < count) throw Error(Status::truncated_file, str_cat(label, ": ", what, "the data is cut short"));
        return out;
    };
    if (compressor.empty()) {
        const std::string head = decoded(hw);
        const std::uint64_t count = word(head, 0, hw, endian, label);
        if (count != bytes) {
            throw Error(count < bytes ? Status::truncated_file : Status::bad_format,
                        str_cat(label, ": ", what, "holds ", count, " bytes, but WholeExtent declares ", dims_text(grid.dims), ' ',
                                type->name, " (", bytes, " bytes)"));
        }
        const std::string all = decoded(hw + static_cast<std::size_t>(bytes));
        volume = make(all.substr(hw));
    } else {
        const std::string head = decoded(3 * hw);
        const std::uint64_t blocks = word(head, 0, hw, endian, label);
        const std::uint64_t block_size = word(head, hw, hw, endian, label);
        const std::uint64_t last = word(head, 2 * hw, hw, endian, label);
        const std::uint64_t expected = blocks == 0 ? 0 : (blocks - 1) * block_size + (last == 0 ? block_size : last);
        if (blocks == 0 || block_size == 0 || blocks > bytes || expected != bytes) {
            throw Error(Status::bad_format, str_cat(label, ": ", what, "compressed blocks (", blocks, " of ", block_size,
                                                    " bytes, the last ", last, ") do not hold the ", bytes, " bytes WholeExtent declares"));
        }
        const std::string sizes = decoded((3 + static_cast<std::size_t>(blocks)) * hw);
        std::uint64_t compressed = 0;
        std::vector<std::uint64_t> each(static_cast<std::size_t>(blocks));
        for (std::size_t b = 0; b < each.size(); ++b) {
            each[b] = word(sizes, (3 + b) * hw, hw, endian, label);
            compressed += each[b];
            if (compressed > source.size()) throw Error(Status::truncated_file, str_cat(label, ": ", what, "the compressed blocks are cut short"));
        }
        const std::string all = decoded((3 + each.size()) * hw + static_cast<std::size_t>(compressed));
        std::string samples;
        samples.reserve(static_cast<std::size_t>(bytes));
        std::size_t at = (3 + each.size()) * hw;
        for (std::size_t b = 0; b < each.size(); ++b) {
            const std::uint64_t size = b + 1 == each.size() && last != 0 ? last : block_size;
            check_inflate_bound(each[b], size, label, str_cat(what, "block ", b + 1, " declares ", size, " bytes"));
            const std::unique_ptr<std::byte[]> block =
                inflate_exact(std::string_view(all).substr(at, static_cast<std::size_t>(each[b])), 0, static_cast<std::size_t>(size), label);
            samples.append(reinterpret_cast<const char*>(block.get()), static_cast<std::size_t>(size));
            at += static_cast<std::size_t>(each[b]);
        }
        volume = make(std::move(samples));
    }
    return widen_samples(std::move(volume), type->kind);
}

} // namespace cmc33::io::detail
