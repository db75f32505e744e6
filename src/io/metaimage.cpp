// MetaImage (ITK / VTK): "Key = Value" lines; ElementDataFile is the last one. Its value LOCAL
// means the samples follow that line in the same file (.mha); otherwise it names the data file,
// relative to the header (.mhd). Keys are matched without regard to case; unknown keys (Comment,
// AnatomicalOrientation, CenterOfRotation, ...) say nothing cmc33 uses and are skipped.
//
// HeaderSize (bytes to skip, -1: the samples are the last bytes) applies to a separate data file.

#include <array>
#include <cctype>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cmc33/io.hpp"
#include "atomic_file.hpp"
#include "byte_source.hpp"
#include "volume_formats.hpp"

namespace cmc33::io::detail {
namespace {

struct Field {
    std::string key; // as written
    std::string value;
    std::size_t line = 0;
};

using Fields = std::map<std::string, Field, std::less<>>; // by lower-case key

const Field* find(const Fields& fields, std::string_view lower_key)
{
    const auto it = fields.find(lower_key);
    return it == fields.end() ? nullptr : &it->second;
}

const Field& require(const Fields& fields, std::string_view lower_key, std::string_view key,
                     const std::string& label)
{
    const Field* field = find(fields, lower_key);
    if (field == nullptr) {
        throw Error(Status::bad_format,
                    str_cat(label, ": the MetaImage header has no ", key, " (required)"));
    }
    return *field;
}

bool parse_bool(const Field& field, const std::string& label)
{
    const std::string v = lower_ascii(field.value);
    if (v == "true" || v == "t" || v == "1") return true;
    if (v == "false" || v == "f" || v == "0") return false;
    throw Error(Status::bad_format, str_cat(label, ": ", field.key, " = ", quote_bytes(field.value),
                                            " (line ", field.line, ") is neither True nor False"));
}

std::int64_t parse_int_field(const Field& field, const std::string& label)
{
    std::int64_t n = 0;
    if (!parse_integer(field.value, n)) {
        throw Error(Status::bad_format,
                    str_cat(label, ": ", field.key, " = ", quote_bytes(field.value), " (line ",
                            field.line, ") is not an integer"));
    }
    return n;
}

std::string field_name(const Field& field)
{
    return str_cat(field.key, " (line ", field.line, ")");
}

ScalarType parse_element_type(const Field& field, const std::string& label)
{
    struct Name {
        std::string_view name;
        ScalarType type;
    };
    static constexpr Name kTypes[] = {
        {"MET_CHAR", ScalarType::i8},   {"MET_UCHAR", ScalarType::u8},
        {"MET_SHORT", ScalarType::i16}, {"MET_USHORT", ScalarType::u16},
        {"MET_INT", ScalarType::i32},   {"MET_UINT", ScalarType::u32},
        {"MET_FLOAT", ScalarType::f32}, {"MET_DOUBLE", ScalarType::f64},
    };
    for (const Name& t : kTypes) {
        if (equals_ignore_case(t.name, field.value)) return t.type;
    }
    if (field.value.size() > 4 && equals_ignore_case(field.value.substr(0, 4), "MET_")) {
        throw Error(Status::unsupported_format,
                    str_cat(label, ": ElementType ", quote_bytes(field.value), " (line ",
                            field.line,
                            ") is not supported; cmc33 reads MET_CHAR, MET_UCHAR, MET_SHORT, "
                            "MET_USHORT, MET_INT, MET_UINT, MET_FLOAT and MET_DOUBLE"));
    }
    throw Error(Status::bad_format,
                str_cat(label, ": unknown ElementType ", quote_bytes(field.value), " (line ",
                        field.line, "); expected MET_UCHAR, MET_SHORT, MET_FLOAT, ..."));
}

/// TransformMatrix (or its synonyms Rotation, Orientation): 9 numbers, the world directions of
/// the x, y and z axes one after the other, as ITK writes and reads them (its direction matrix
/// column by column).
std::array<Vec3, 3> parse_transform_matrix(const Field& field, const std::string& label)
{
    const std::vector<std::string_view> words = split_words(field.value);
    if (words.size() != 9) {
        throw Error(Status::bad_format,
                    str_cat(label, ": ", field_name(field), " has ", words.size(),
                            " values, expected 9 (a 3x3 matrix)"));
    }
    std::array<Vec3, 3> axes{};
    for (std::size_t i = 0; i < 9; ++i) {
        double v = 0;
        if (!parse_real(words[i], v)) {
            throw Error(Status::bad_format, str_cat(label, ": ", field_name(field), " value ",
                                                    quote_bytes(words[i]), ' ',
                                                    real_problem(words[i])));
        }
        if (!std::isfinite(v)) {
            throw Error(Status::non_finite, str_cat(label, ": ", field_name(field), " value ",
                                                    quote_bytes(words[i]), " is not finite"));
        }
        axes[i / 3][i % 3] = v;
    }
    return axes;
}

std::string met_type_name(ScalarType type)
{
    switch (type) {
    case ScalarType::i8: return "MET_CHAR";
    case ScalarType::u8: return "MET_UCHAR";
    case ScalarType::i16: return "MET_SHORT";
    case ScalarType::u16: return "MET_USHORT";
    case ScalarType::i32: return "MET_INT";
    case ScalarType::u32: return "MET_UINT";
    case ScalarType::f32: return "MET_FLOAT";
    case ScalarType::f64: break;
    }
    return "MET_DOUBLE";
}

} // namespace

Volume read_metaimage(const ByteInput& file, const OpenDataFile& open_data, const ReadSamples& read)
{
    const std::string& label = file.label();
    const std::string head = read_header_bytes(file, "MetaImage");
    ByteSource source(head);

    Fields fields;
    std::string_view line;
    bool terminated = false;
    std::size_t line_number = 0;
    const Field* data_file = nullptr;
    while (source.next_line(line, terminated)) {
        ++line_number;
        if (trim(line).empty()) continue;
        const std::size_t equals = line.find('=');
        const std::string key(trim(line.substr(0, equals == std::string_view::npos ? 0 : equals)));
        bool word = !key.empty();
        for (char c : key) word = word && (std::isalnum(static_cast<unsigned char>(c)) || c == '_');
        if (equals == std::string_view::npos || !word) {
            if (fields.empty()) {
                throw Error(Status::bad_format,
                            str_cat(label, ": not a MetaImage header: line ", line_number, ' ',
                                    quote_bytes(line), " is not \"Key = Value\""));
            }
            throw Error(Status::bad_format,
                        str_cat(label, ": MetaImage header line ", line_number, ' ',
                                quote_bytes(line), " is not \"Key = Value\""));
        }
        const std::string lower = lower_ascii(key);
        if (const Field* earlier = find(fields, lower)) {
            throw Error(Status::bad_format, str_cat(label, ": ", key, " is given twice (lines ",
                                                    earlier->line, " and ", line_number, ")"));
        }
        const Field& field = fields[lower] =
            Field{key, std::string(trim(line.substr(equals + 1))), line_number};
        if (lower == "elementdatafile") {
            data_file = &field;
            break;
        }
    }
    if (data_file == nullptr) {
        if (head.size() < file.size()) {
            throw Error(Status::bad_format,
                        str_cat(label, ": no ElementDataFile line within the first ",
                                kMaxHeaderBytes, " bytes of the MetaImage header"));
        }
        throw Error(Status::bad_format,
                    str_cat(label, ": the MetaImage header has no ElementDataFile line (it "
                                   "must be the last one; file cut short?)"));
    }

    if (const Field* object = find(fields, "objecttype");
        object && !equals_ignore_case(object->value, "Image")) {
        throw Error(Status::unsupported_format,
                    str_cat(label, ": ObjectType ", quote_bytes(object->value), " (line ",
                            object->line, ") is not supported; cmc33 reads Image"));
    }
    const Field& ndims = require(fields, "ndims", "NDims", label);
    const std::int64_t n = parse_int_field(ndims, label);
    if (n != 3) {
        throw Error(Status::unsupported_format,
                    str_cat(label, ": NDims = ", n, " (line ", ndims.line,
                            ") is not supported; cmc33 reads 3D volumes (NDims = 3)"));
    }
    if (const Field* channels = find(fields, "elementnumberofchannels")) {
        const std::int64_t c = parse_int_field(*channels, label);
        if (c != 1) {
            throw Error(Status::unsupported_format,
                        str_cat(label, ": ElementNumberOfChannels = ", c, " (line ", channels->line,
                                ") is not supported; cmc33 reads one scalar per sample"));
        }
    }
    if (const Field* binary = find(fields, "binarydata"); binary && !parse_bool(*binary, label)) {
        throw Error(Status::unsupported_format,
                    str_cat(label, ": BinaryData = False (line ", binary->line,
                            ", samples as text) is not supported"));
    }
    const Field* matrix = nullptr;
    for (const char* key : {"transformmatrix", "rotation", "orientation"}) {
        if (matrix == nullptr) matrix = find(fields, key);
    }

    Grid grid;
    const Field& dims = require(fields, "dimsize", "DimSize", label);
    grid.dims = parse_dims(split_words(dims.value), label, field_name(dims));
    grid.type = parse_element_type(require(fields, "elementtype", "ElementType", label), label);
    payload_bytes(grid.dims, grid.type, label); // size errors name the header, not the data file
    const Field* spacing = find(fields, "elementspacing");
    if (spacing == nullptr) spacing = find(fields, "elementsize");
    if (spacing)
        grid.spacing = parse_vec3(split_words(spacing->value), label, field_name(*spacing), true);
    for (const char* key : {"offset", "origin", "position"}) {
        if (const Field* origin = find(fields, key)) {
            grid.origin = parse_vec3(split_words(origin->value), label, field_name(*origin), false);
            break;
        }
    }
    // CenterOfRotation does not move the samples (ITK ignores it for positions too).
    if (matrix) {
        set_frame(grid, parse_transform_matrix(*matrix, label), grid.spacing, label,
                  field_name(*matrix));
    }
    if (const Field* orientation = find(fields, "anatomicalorientation"))
        grid.space = normalize_blanks(orientation->value);

    Storage storage;
    storage.endian = Endian::little;
    const Field* msb = find(fields, "binarydatabyteordermsb");
    if (msb == nullptr) msb = find(fields, "elementbyteordermsb");
    if (msb && parse_bool(*msb, label)) storage.endian = Endian::big;
    const Field* compressed = find(fields, "compresseddata");
    if (compressed && parse_bool(*compressed, label)) {
        storage.encoding = Encoding::compressed;
        if (const Field* size = find(fields, "compresseddatasize")) {
            const std::int64_t bytes = parse_int_field(*size, label);
            if (bytes <= 0) {
                throw Error(Status::bad_format,
                            str_cat(label, ": CompressedDataSize = ", bytes, " (line ", size->line,
                                    ") is not a positive byte count"));
            }
            storage.stored_size = static_cast<std::uint64_t>(bytes);
        }
    }

    const std::string& name = data_file->value;
    if (equals_ignore_case(name, "LOCAL")) {
        storage.offset = source.position();
        return read(file, grid, storage, label, nullptr);
    }
    if (name == "LIST" || name.rfind("LIST ", 0) == 0) {
        throw Error(Status::unsupported_format,
                    str_cat(label, ": ElementDataFile = LIST (line ", data_file->line,
                            ", one file per slice) is not supported; cmc33 reads one "
                            "data file"));
    }
    if (is_file_pattern(name)) {
        throw Error(
            Status::unsupported_format,
            str_cat(
                label, ": ElementDataFile ", quote_bytes(name), " (line ", data_file->line,
                ") is a numbered file pattern, which is not supported; cmc33 reads one data file"));
    }
    if (name.empty()) {
        throw Error(Status::bad_format, str_cat(label, ": ElementDataFile (line ", data_file->line,
                                                ") names no file; expected LOCAL or a file name"));
    }
    const std::unique_ptr<ByteInput> data_input = open_data(name);
    const ByteInput& data = *data_input;
    if (const Field* header_size = find(fields, "headersize")) {
        const std::int64_t skip = parse_int_field(*header_size, label);
        if (skip < -1 || (skip == -1 && storage.encoding != Encoding::raw)) {
            throw Error(Status::bad_format,
                        str_cat(label, ": HeaderSize = ", skip, " (line ", header_size->line,
                                ") is not a byte count >= 0",
                                storage.encoding == Encoding::raw ? " or -1" : ""));
        }
        if (skip == -1) {
            storage.at_end = true;
        } else {
            storage.offset = static_cast<std::uint64_t>(skip);
        }
    }
    return read(data, grid, storage, data.label(), nullptr);
}

std::vector<std::string> metaimage_data_file_names(std::string_view head)
{
    std::vector<std::string> names;
    ByteSource source(head);
    std::string_view line;
    bool terminated = false;
    while (source.next_line(line, terminated)) {
        const std::size_t equals = line.find('=');
        if (equals == std::string_view::npos || !equals_ignore_case(trim(line.substr(0, equals)), "ElementDataFile"))
            continue;
        const std::string_view value = trim(line.substr(equals + 1));
        const std::vector<std::string_view> words = split_words(value);
        if (!words.empty() && equals_ignore_case(words[0], "LIST")) {
            // File names follow, one a line (MetaIO), or several a line split at blanks.
            while (source.next_line(line, terminated)) {
                const std::vector<std::string_view> files = split_words(line);
                if (files.size() > 1) names.emplace_back(trim(line));
                for (std::string_view file : files) names.emplace_back(file);
            }
        } else if (is_file_pattern(value)) {
            names = expand_file_pattern(value, kMaxPatternFiles);
        } else if (!value.empty() && !equals_ignore_case(value, "LOCAL")) {
            names.emplace_back(value);
        }
        break; // ElementDataFile is the header's last line
    }
    return names;
}

void write_metaimage(const Volume& volume, const std::filesystem::path& path, bool local)
{
    const Index3& n = volume.dims();
    const Vec3& s = volume.spacing();
    const Vec3& o = volume.origin();
    const Mat3& d = volume.direction();
    std::string header = "ObjectType = Image\n"
                         "NDims = 3\n"
                         "BinaryData = True\n"
                         "BinaryDataByteOrderMSB = False\n"
                         "CompressedData = False\n";
    header += "TransformMatrix =";
    for (std::size_t a = 0; a < 3; ++a) // axis by axis, as parse_transform_matrix reads it
        for (std::size_t r = 0; r < 3; ++r) header += " " + format_real(d[r][a]);
    header += "\n";
    header +=
        "Offset = " + format_real(o[0]) + " " + format_real(o[1]) + " " + format_real(o[2]) + "\n";
    header += "ElementSpacing = " + format_real(s[0]) + " " + format_real(s[1]) + " " +
              format_real(s[2]) + "\n";
    // only MetaImage's own three-letter codes ("RAI"), not a NRRD space name
    const std::string& space = volume.space();
    if (space.size() == 3 && space.find_first_not_of("RLAPSIrlapsi") == std::string::npos)
        header += "AnatomicalOrientation = " + space + "\n";
    header += str_cat("DimSize = ", n[0], ' ', n[1], ' ', n[2], '\n');
    header += "ElementType = " + met_type_name(volume.type()) + "\n";
    if (local) {
        header += "ElementDataFile = LOCAL\n";
        write_atomically(path, [&](std::ostream& out) {
            out << header;
            write_samples(out, volume, Endian::little);
        });
        return;
    }
    const std::filesystem::path data = data_file_beside(path);
    write_atomically(data, [&](std::ostream& out) { write_samples(out, volume, Endian::little); });
    header += "ElementDataFile = " + data.filename().string() + "\n";
    write_atomically(path, [&](std::ostream& out) { out << header; });
}

} // namespace cmc33::io::detail
