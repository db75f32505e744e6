// NRRD (teem.sourceforge.net/nrrd/format.html): "NRRD000N", then "field: value" lines, comments
// ("#") and "key:=value" pairs; an attached header ends at the first empty line and the samples
// follow it; a detached header (.nhdr) names its data file with "data file:".
//
// Read: 3D, the 8 types, encodings raw / gzip / ascii, endian, spacings or axis-aligned space
// directions, space origin, line skip, byte skip (for gzip it counts inflated bytes, as in teem).
// Written: NRRD0004 with "space directions" and "space origin"; teem does not allow "spacings"
// together with a space origin, so the spacing goes into the diagonal of the directions.

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

struct TypeName {
    std::string_view name;
    ScalarType type;
};

// Every spelling of the NRRD spec for the types cmc33 holds (compared after collapsing blanks).
constexpr TypeName kTypes[] = {
    {"signed char", ScalarType::i8},
    {"int8", ScalarType::i8},
    {"int8_t", ScalarType::i8},
    {"uchar", ScalarType::u8},
    {"unsigned char", ScalarType::u8},
    {"uint8", ScalarType::u8},
    {"uint8_t", ScalarType::u8},
    {"short", ScalarType::i16},
    {"short int", ScalarType::i16},
    {"signed short", ScalarType::i16},
    {"signed short int", ScalarType::i16},
    {"int16", ScalarType::i16},
    {"int16_t", ScalarType::i16},
    {"ushort", ScalarType::u16},
    {"unsigned short", ScalarType::u16},
    {"unsigned short int", ScalarType::u16},
    {"uint16", ScalarType::u16},
    {"uint16_t", ScalarType::u16},
    {"int", ScalarType::i32},
    {"signed int", ScalarType::i32},
    {"int32", ScalarType::i32},
    {"int32_t", ScalarType::i32},
    {"uint", ScalarType::u32},
    {"unsigned int", ScalarType::u32},
    {"uint32", ScalarType::u32},
    {"uint32_t", ScalarType::u32},
    {"float", ScalarType::f32},
    {"double", ScalarType::f64},
};

// Valid NRRD types that cmc33 does not hold.
constexpr std::string_view kUnsupportedTypes[] = {
    "longlong", "long long", "long long int", "signed long long",   "signed long long int",
    "int64",    "int64_t",   "ulonglong",     "unsigned long long", "unsigned long long int",
    "uint64",   "uint64_t",  "block",
};

// Fields of the spec that say nothing cmc33 uses ("space", "centers", "axis mins" and
// "axis maxs" are read: kReadFields is looked up first).
constexpr std::string_view kIgnoredFields[] = {
    "content",     "space",     "space dimension", "space units", "measurement frame",
    "centers",     "centerings", "labels",         "units",
    "thicknesses", "axis mins", "axismins",        "axis maxs",   "axismaxs",
    "min",         "max",       "old min",         "oldmin",      "old max",
    "oldmax",      "number",    "sample units",    "sampleunits", "block size",
    "blocksize",
};

// Fields read here, with their older one-word spellings.
constexpr std::pair<std::string_view, std::string_view> kReadFields[] = {
    {"type", "type"},
    {"dimension", "dimension"},
    {"sizes", "sizes"},
    {"encoding", "encoding"},
    {"endian", "endian"},
    {"spacings", "spacings"},
    {"space directions", "space directions"},
    {"space origin", "space origin"},
    {"space", "space"},
    {"centers", "centers"},
    {"centerings", "centers"},
    {"axis mins", "axis mins"},
    {"axismins", "axis mins"},
    {"axis maxs", "axis maxs"},
    {"axismaxs", "axis maxs"},
    {"byte skip", "byte skip"},
    {"byteskip", "byte skip"},
    {"line skip", "line skip"},
    {"lineskip", "line skip"},
    {"data file", "data file"},
    {"datafile", "data file"},
    {"kinds", "kinds"},
};

// The kinds of an axis along which samples are places (teem's domain kinds; "???" and "none" say
// nothing). Every other kind (RGB-color, 3-vector, list, complex, ...) makes an axis of values
// per sample: meshing across it would mix channels as if they were neighbours in space.
constexpr std::string_view kDomainKinds[] = {"domain", "space", "time", "???", "none"};

struct Field {
    std::string value;
    std::size_t line = 0;
};

using Fields = std::map<std::string, Field, std::less<>>;

const Field* find(const Fields& fields, std::string_view name)
{
    const auto it = fields.find(name);
    return it == fields.end() ? nullptr : &it->second;
}

const Field& require(const Fields& fields, std::string_view name, const std::string& label)
{
    const Field* field = find(fields, name);
    if (field == nullptr) {
        throw Error(Status::bad_format,
                    str_cat(label, ": the NRRD header has no \"", name, "\" field (required)"));
    }
    return *field;
}

ScalarType parse_nrrd_type(const Field& field, const std::string& label)
{
    const std::string name = lower_ascii(normalize_blanks(field.value));
    for (const TypeName& t : kTypes) {
        if (t.name == name) return t.type;
    }
    for (std::string_view t : kUnsupportedTypes) {
        if (t == name) {
            throw Error(Status::unsupported_format,
                        str_cat(label, ": type ", quote_bytes(field.value), " (line ", field.line,
                                ") is not supported; cmc33 reads int8, uint8, int16, uint16, "
                                "int32, uint32, float and double"));
        }
    }
    throw Error(Status::bad_format,
                str_cat(label, ": unknown type ", quote_bytes(field.value), " (line ", field.line,
                        "); expected a NRRD type such as uchar, short, ushort, int, float, "
                        "double"));
}

Encoding parse_encoding(const Field& field, const std::string& label)
{
    const std::string name = lower_ascii(trim(field.value));
    if (name == "raw") return Encoding::raw;
    if (name == "gzip" || name == "gz") return Encoding::compressed;
    if (name == "ascii" || name == "text" || name == "txt") return Encoding::ascii;
    if (name == "bzip2" || name == "bz2" || name == "hex" || name == "zrl") {
        throw Error(Status::unsupported_format,
                    str_cat(label, ": encoding ", quote_bytes(field.value), " (line ", field.line,
                            ") is not supported; cmc33 reads raw, gzip and ascii"));
    }
    throw Error(Status::bad_format,
                str_cat(label, ": unknown encoding ", quote_bytes(field.value), " (line ",
                        field.line, "); expected raw, gzip or ascii"));
}

/// The vectors "(a,b,c) (d,e,f) ..." of a space field; an empty optional for "none".
std::vector<std::optional<std::vector<double>>>
parse_vectors(const Field& field, std::string_view name, const std::string& label)
{
    std::vector<std::optional<std::vector<double>>> vectors;
    std::string_view rest = trim(field.value);
    while (!rest.empty()) {
        if (rest.substr(0, 4) == "none") {
            vectors.emplace_back();
            rest = trim(rest.substr(4));
            continue;
        }
        const std::size_t close = rest.find(')');
        if (rest.front() != '(' || close == std::string_view::npos) {
            throw Error(Status::bad_format, str_cat(label, ": field \"", name, "\" (line ",
                                                    field.line, ") ", quote_bytes(field.value),
                                                    " is not a list of vectors like (1,0,0)"));
        }
        std::vector<double> components;
        std::string_view inside = rest.substr(1, close - 1);
        while (true) {
            const std::size_t comma = inside.find(',');
            const std::string_view token = trim(inside.substr(0, comma));
            double value = 0;
            if (!parse_real(token, value)) {
                throw Error(Status::bad_format,
                            str_cat(label, ": field \"", name, "\" (line ", field.line,
                                    "): component ", quote_bytes(token), ' ',
                                    real_problem(token)));
            }
            if (!std::isfinite(value)) {
                throw Error(Status::non_finite,
                            str_cat(label, ": field \"", name, "\" (line ", field.line,
                                    "): component ", quote_bytes(token), " is not finite"));
            }
            components.push_back(value);
            if (comma == std::string_view::npos) break;
            inside.remove_prefix(comma + 1);
        }
        vectors.emplace_back(std::move(components));
        rest = trim(rest.substr(close + 1));
    }
    return vectors;
}

/// The three axis vectors (world steps, any signs, permutations, oblique).
std::array<Vec3, 3> parse_space_directions(const Field& field, const std::string& label)
{
    const auto vectors = parse_vectors(field, "space directions", label);
    if (vectors.size() != 3) {
        throw Error(Status::bad_format,
                    str_cat(label, ": field \"space directions\" (line ", field.line, ") has ",
                            vectors.size(), " vectors, expected 3 (one per axis)"));
    }
    std::array<Vec3, 3> axes{};
    for (std::size_t axis = 0; axis < 3; ++axis) {
        if (!vectors[axis]) {
            throw Error(Status::unsupported_format,
                        str_cat(label, ": space direction ", axis + 1, " is \"none\" (line ",
                                field.line, "); cmc33 needs three spatial axes"));
        }
        const std::vector<double>& v = *vectors[axis];
        if (v.size() != 3) {
            throw Error(Status::unsupported_format,
                        str_cat(label, ": space direction ", axis + 1, " has ", v.size(),
                                " components (line ", field.line,
                                "); cmc33 reads volumes in a 3D space"));
        }
        axes[axis] = {v[0], v[1], v[2]};
    }
    return axes;
}

/// "axis mins" (where each axis starts) as the position of the first sample: with "centers:
/// cell" a sample sits in the middle of its cell, half a step (signed) after the axis's start.
Vec3 parse_axis_mins(const Field& mins, const Field* centers, const Vec3& step,
                     const std::string& label)
{
    Vec3 first = parse_vec3(split_words(mins.value), label,
                            str_cat("field \"axis mins\" (line ", mins.line, ")"), false);
    if (centers) {
        const std::vector<std::string_view> words = split_words(centers->value);
        if (words.size() != 3) {
            throw Error(Status::bad_format,
                        str_cat(label, ": field \"centers\" (line ", centers->line, ") ",
                                quote_bytes(centers->value),
                                " does not give 3 centerings (cell, node or \"???\" each)"));
        }
        for (std::size_t a = 0; a < 3; ++a)
            if (lower_ascii(words[a]) == "cell") first[a] += 0.5 * step[a];
    }
    return first;
}

/// The spacing "axis mins" and "axis maxs" imply: the extent over n - 1 steps for node
/// centering (the default), n steps for cell centering. Negative when max < min.
Vec3 spacing_from_axis_range(const Field& mins, const Field& maxs, const Field* centers,
                             const Index3& dims, const std::string& label)
{
    const Vec3 lo = parse_vec3(split_words(mins.value), label,
                               str_cat("field \"axis mins\" (line ", mins.line, ")"), false);
    const Vec3 hi = parse_vec3(split_words(maxs.value), label,
                               str_cat("field \"axis maxs\" (line ", maxs.line, ")"), false);
    const std::vector<std::string_view> words =
        centers ? split_words(centers->value) : std::vector<std::string_view>{};
    Vec3 step{};
    for (std::size_t a = 0; a < 3; ++a) {
        const bool cell = words.size() == 3 && lower_ascii(words[a]) == "cell";
        step[a] = (hi[a] - lo[a]) / static_cast<double>(cell ? dims[a] : dims[a] - 1);
    }
    return step;
}

Vec3 parse_space_origin(const Field& field, const std::string& label)
{
    const auto vectors = parse_vectors(field, "space origin", label);
    if (vectors.size() != 1 || !vectors[0] || vectors[0]->size() != 3) {
        throw Error(Status::bad_format,
                    str_cat(label, ": field \"space origin\" (line ", field.line, ") ",
                            quote_bytes(field.value), " is not one 3D vector like (x,y,z)"));
    }
    const std::vector<double>& v = *vectors[0];
    return {v[0], v[1], v[2]};
}

std::int64_t parse_skip(const Field& field, std::string_view name, std::int64_t lowest,
                        const std::string& label)
{
    std::int64_t n = 0;
    if (!parse_integer(trim(field.value), n) || n < lowest) {
        throw Error(Status::bad_format,
                    str_cat(label, ": field \"", name, "\" (line ", field.line, ") ",
                            quote_bytes(field.value), " is not an integer >= ", lowest));
    }
    return n;
}

/// "kinds": Error{unsupported_format} for an axis that is not a domain axis (channels), naming it;
/// Error{bad_format} when the kinds are not one per axis.
void check_kinds(const Field& kinds, std::int64_t dimension, const Field* sizes, const std::string& label)
{
    const std::vector<std::string_view> words = split_words(kinds.value);
    const std::vector<std::string_view> size_words =
        sizes ? split_words(sizes->value) : std::vector<std::string_view>{};
    for (std::size_t axis = 0; axis < words.size(); ++axis) {
        bool domain = false;
        for (std::string_view k : kDomainKinds) domain = domain || equals_ignore_case(k, words[axis]);
        if (domain) continue;
        std::int64_t count = 0;
        const std::string size = axis < size_words.size() && parse_integer(size_words[axis], count)
                                     ? str_cat(" (size ", count, ")")
                                     : std::string();
        throw Error(Status::unsupported_format,
                    str_cat(label, ": kinds ", quote_bytes(kinds.value, 80), " (line ", kinds.line, "): axis ",
                            axis, size, " is ", quote_bytes(words[axis]),
                            ", values per sample, not a spatial axis; cmc33 meshes one scalar per sample "
                            "over 3 spatial axes (kinds domain or space): extract one channel first "
                            "(unu slice -a ",
                            axis, " -p 0)"));
    }
    if (words.size() != static_cast<std::size_t>(dimension) && dimension == 3) {
        throw Error(Status::bad_format,
                    str_cat(label, ": field \"kinds\" (line ", kinds.line, ") ", quote_bytes(kinds.value),
                            " has ", words.size(), " kinds, expected 3 (one per axis)"));
    }
}

/// The offset after `lines` more line ends, counted from `offset`.
std::uint64_t skip_lines(const ByteInput& file, std::uint64_t offset, std::int64_t lines,
                         const std::string& label)
{
    std::int64_t seen = 0;
    std::uint64_t pos = offset;
    while (seen < lines) {
        const std::string chunk = file.read_string(pos, 1 << 16);
        if (chunk.empty()) {
            throw Error(Status::truncated_file,
                        str_cat(label, ": \"line skip: ", lines, "\" but only ", seen,
                                " lines follow byte ", offset, " (file cut short?)"));
        }
        std::size_t at = 0;
        while (seen < lines) {
            const std::size_t end = chunk.find('\n', at);
            if (end == std::string::npos) {
                at = chunk.size();
                break;
            }
            ++seen;
            at = end + 1;
        }
        pos += at;
    }
    return pos;
}

/// The 3D spaces NRRD names ("space: ..."); other names (MetaImage's "RAI") are not written.
bool is_nrrd_space(std::string_view name)
{
    constexpr std::string_view kSpaces[] = {
        "right-anterior-superior", "ras", "left-anterior-superior", "las",
        "left-posterior-superior", "lps", "scanner-xyz", "3d-right-handed", "3d-left-handed",
    };
    const std::string lower = lower_ascii(name);
    for (std::string_view s : kSpaces)
        if (s == lower) return true;
    return false;
}

std::string nrrd_type_name(ScalarType type)
{
    return std::string(type_name(type)); // int8 ... double are all NRRD spellings
}

} // namespace

Volume read_nrrd(const ByteInput& file, const OpenDataFile& open_data, bool detached_header, const ReadSamples& read)
{
    const std::string& label = file.label();
    const std::string head = read_header_bytes(file, "NRRD");
    ByteSource source(head);

    std::string_view line;
    bool terminated = false;
    source.next_line(line, terminated);
    const bool magic =
        line.size() == 8 && line.substr(0, 7) == "NRRD000" && line[7] >= '1' && line[7] <= '9';
    if (!magic) {
        if (line.substr(0, 4) == "NRRD" && line.size() == 8) {
            throw Error(Status::unsupported_format,
                        str_cat(label, ": NRRD version ", quote_bytes(line),
                                " is not supported; expected NRRD0001 to NRRD0009"));
        }
        throw Error(Status::bad_format,
                    str_cat(label, ": not a NRRD file: it starts with ", quote_bytes(line),
                            " instead of the magic NRRD000N"));
    }
    if (!terminated) {
        throw Error(Status::truncated_file,
                    str_cat(label, ": the file ends after the NRRD magic (file cut short?)"));
    }

    Fields fields;
    std::size_t line_number = 1;
    bool blank_line = false;
    while (source.next_line(line, terminated)) {
        ++line_number;
        if (trim(line).empty()) {
            blank_line = true;
            break;
        }
        if (trim(line).front() == '#') continue;
        const std::size_t colon = line.find(':');
        if (colon == std::string_view::npos) {
            throw Error(Status::bad_format,
                        str_cat(label, ": header line ", line_number, ' ', quote_bytes(line),
                                " is not a field \"name: value\""));
        }
        if (colon + 1 < line.size() && line[colon + 1] == '=') continue; // key:=value
        const std::string raw_name = normalize_blanks(line.substr(0, colon));
        std::string name;
        for (const auto& [spelling, canonical] : kReadFields) {
            if (spelling == raw_name) name = canonical;
        }
        if (name.empty()) {
            bool ignored = false;
            for (std::string_view f : kIgnoredFields) ignored = ignored || f == raw_name;
            if (ignored) continue;
            throw Error(Status::bad_format, str_cat(label, ": unknown field ",
                                                    quote_bytes(raw_name), " on line ", line_number,
                                                    " (NRRD field names are lower case, like "
                                                    "\"sizes\" or \"space origin\")"));
        }
        const std::string_view value = trim(line.substr(colon + 1));
        if (name == "data file" && !split_words(value).empty() && split_words(value)[0] == "LIST") {
            // The file names follow on the next lines, which are not fields: stop here.
            throw Error(Status::unsupported_format,
                        str_cat(label, ": \"data file: LIST\" (line ", line_number,
                                ", several data files) is not supported; cmc33 reads "
                                "one data file"));
        }
        if (const Field* earlier = find(fields, name)) {
            throw Error(Status::bad_format,
                        str_cat(label, ": field \"", name, "\" is given twice (lines ",
                                earlier->line, " and ", line_number, ")"));
        }
        fields[name] = Field{std::string(value), line_number};
    }
    const Field* data_file = find(fields, "data file");
    if (!blank_line) {
        if (head.size() < file.size()) {
            throw Error(Status::bad_format,
                        str_cat(label, ": no empty line ends the NRRD header within its first ",
                                kMaxHeaderBytes, " bytes"));
        }
        if (data_file == nullptr && detached_header) {
            throw Error(Status::bad_format,
                        str_cat(label, ": the detached header (.nhdr) has no \"data file\" field"));
        }
        if (data_file == nullptr) {
            throw Error(Status::truncated_file,
                        str_cat(label, ": the NRRD header is not followed by an empty line "
                                       "and the samples (file cut short?)"));
        }
    }

    // Shape and type.
    const Field& dimension = require(fields, "dimension", label);
    std::int64_t dim = 0;
    if (!parse_integer(trim(dimension.value), dim)) {
        throw Error(Status::bad_format, str_cat(label, ": dimension ", quote_bytes(dimension.value),
                                                " (line ", dimension.line, ") is not an integer"));
    }
    if (const Field* kinds = find(fields, "kinds")) check_kinds(*kinds, dim, find(fields, "sizes"), label);
    if (dim != 3) {
        throw Error(Status::unsupported_format,
                    str_cat(label, ": dimension ", dim, " (line ", dimension.line,
                            ") is not supported; cmc33 reads 3D volumes (dimension: 3)"));
    }
    Grid grid;
    grid.type = parse_nrrd_type(require(fields, "type", label), label);
    const Field& sizes = require(fields, "sizes", label);
    grid.dims = parse_dims(split_words(sizes.value), label, "field \"sizes\"");
    payload_bytes(grid.dims, grid.type, label); // size errors name the header, not the data file

    Storage storage;
    storage.encoding = parse_encoding(require(fields, "encoding", label), label);
    storage.endian = native_endian();
    if (const Field* endian = find(fields, "endian")) {
        const std::string e = lower_ascii(trim(endian->value));
        if (e != "little" && e != "big") {
            throw Error(Status::bad_format,
                        str_cat(label, ": endian ", quote_bytes(endian->value), " (line ",
                                endian->line, ") is neither \"little\" nor \"big\""));
        }
        storage.endian = e == "big" ? Endian::big : Endian::little;
    } else if (type_size(grid.type) > 1 && storage.encoding != Encoding::ascii) {
        throw Error(Status::bad_format,
                    str_cat(label, ": the NRRD header has no \"endian\" field, required for ",
                            type_name(grid.type), " samples with a binary encoding"));
    }

    // Place in space.
    const Field* spacings = find(fields, "spacings");
    const Field* directions = find(fields, "space directions");
    if (spacings && directions) {
        throw Error(Status::bad_format,
                    str_cat(label, ": both \"spacings\" (line ", spacings->line,
                            ") and \"space directions\" (line ", directions->line,
                            ") are given; NRRD allows only one"));
    }
    const Field* mins = find(fields, "axis mins");
    const Field* maxs = find(fields, "axis maxs");
    const Field* centers = find(fields, "centers");
    if (mins && directions) {
        throw Error(Status::bad_format,
                    str_cat(label, ": both \"axis mins\" (line ", mins->line,
                            ") and \"space directions\" (line ", directions->line,
                            ") are given; NRRD places a spatial frame by \"space origin\""));
    }
    if (spacings) {
        grid.spacing = parse_vec3(split_words(spacings->value), label, "field \"spacings\"", true);
    } else if (mins && maxs) {
        const Vec3 step = spacing_from_axis_range(*mins, *maxs, centers, grid.dims, label);
        set_frame(grid, {{{step[0], 0, 0}, {0, step[1], 0}, {0, 0, step[2]}}}, {1, 1, 1}, label,
                  str_cat("fields \"axis mins\" and \"axis maxs\" (lines ", mins->line, " and ",
                          maxs->line, ")"));
    }
    if (directions) {
        set_frame(grid, parse_space_directions(*directions, label), {1, 1, 1}, label,
                  str_cat("field \"space directions\" (line ", directions->line, ")"));
    }
    if (const Field* space = find(fields, "space")) grid.space = normalize_blanks(space->value);
    if (const Field* origin = find(fields, "space origin")) {
        grid.origin = parse_space_origin(*origin, label);
    } else if (mins) {
        Vec3 step{}; // the frame is diagonal here: no space directions
        for (std::size_t a = 0; a < 3; ++a) step[a] = grid.direction[a][a] * grid.spacing[a];
        grid.origin = parse_axis_mins(*mins, centers, step, label);
    }

    // Where the samples are.
    std::unique_ptr<ByteInput> detached;
    if (data_file) {
        const std::string name(trim(data_file->value));
        if (is_file_pattern(name)) {
            throw Error(Status::unsupported_format,
                        str_cat(label, ": data file ", quote_bytes(name), " (line ",
                                data_file->line,
                                ") is a multi-file pattern, which is not supported; cmc33 "
                                "reads one data file"));
        }
        if (name.empty()) {
            throw Error(Status::bad_format, str_cat(label, ": field \"data file\" (line ",
                                                    data_file->line, ") names no file"));
        }
        detached = open_data(name);
    } else if (detached_header) {
        throw Error(Status::bad_format,
                    str_cat(label, ": the detached header (.nhdr) has no \"data file\" field"));
    }
    const ByteInput& data = detached ? *detached : file;
    const std::string& data_label = data.label();
    storage.offset = detached ? 0 : source.position();
    if (const Field* lines = find(fields, "line skip")) {
        storage.offset =
            skip_lines(data, storage.offset, parse_skip(*lines, "line skip", 0, label), data_label);
    }
    if (const Field* bytes = find(fields, "byte skip")) {
        const std::int64_t skip = parse_skip(*bytes, "byte skip", -1, label);
        if (skip == -1) {
            if (storage.encoding != Encoding::raw) {
                throw Error(Status::bad_format,
                            str_cat(label, ": \"byte skip: -1\" (line ", bytes->line,
                                    ") is only allowed with raw encoding"));
            }
            storage.at_end = true;
        } else if (storage.encoding == Encoding::compressed) {
            storage.skip_inflated = static_cast<std::uint64_t>(skip);
        } else {
            storage.offset += static_cast<std::uint64_t>(skip);
        }
    }
    return read(data, grid, storage, data_label, nullptr);
}

std::vector<std::string> nrrd_data_file_names(std::string_view head)
{
    std::vector<std::string> names;
    ByteSource source(head);
    std::string_view line;
    bool terminated = false;
    source.next_line(line, terminated); // the magic
    while (source.next_line(line, terminated)) {
        if (trim(line).empty()) break; // the end of the header
        const std::size_t colon = line.find(':');
        if (colon == std::string_view::npos || (colon + 1 < line.size() && line[colon + 1] == '=')) continue;
        const std::string name = normalize_blanks(line.substr(0, colon));
        if (name != "data file" && name != "datafile") continue;
        const std::string_view value = trim(line.substr(colon + 1));
        const std::vector<std::string_view> words = split_words(value);
        if (!words.empty() && words[0] == "LIST") {
            // Every later line names one file, to the end of the header file.
            while (source.next_line(line, terminated)) {
                if (!trim(line).empty()) names.emplace_back(trim(line));
            }
            break;
        }
        if (is_file_pattern(value)) {
            const std::vector<std::string> expanded = expand_file_pattern(value, kMaxPatternFiles);
            names.insert(names.end(), expanded.begin(), expanded.end());
        } else if (!value.empty()) {
            names.emplace_back(value);
        }
    }
    return names;
}

void write_nrrd(const Volume& volume, const std::filesystem::path& path, bool detached)
{
    const Index3& n = volume.dims();
    const Mat3 m = frame_matrix(volume.spacing(), volume.direction());
    const Vec3& o = volume.origin();
    std::string header = "NRRD0004\n"
                         "# Complete NRRD file format specification at:\n"
                         "# http://teem.sourceforge.net/nrrd/format.html\n";
    header += "type: " + nrrd_type_name(volume.type()) + "\n";
    header += "dimension: 3\n";
    if (!is_nrrd_space(volume.space())) {
        header += "space dimension: 3\n";
    } else {
        header += "space: " + volume.space() + "\n";
    }
    header += str_cat("sizes: ", n[0], ' ', n[1], ' ', n[2], '\n');
    header += "space directions:";
    for (std::size_t a = 0; a < 3; ++a) {
        header += " (" + format_real(m[0][a]) + "," + format_real(m[1][a]) + "," +
                  format_real(m[2][a]) + ")";
    }
    header += "\n";
    header += "kinds: domain domain domain\n";
    if (type_size(volume.type()) > 1) header += "endian: little\n";
    header += "encoding: raw\n";
    header += "space origin: (" + format_real(o[0]) + "," + format_real(o[1]) + "," +
              format_real(o[2]) + ")\n";
    if (detached) {
        const std::filesystem::path data = data_file_beside(path);
        write_atomically(data,
                         [&](std::ostream& out) { write_samples(out, volume, Endian::little); });
        header += "data file: " + data.filename().string() + "\n";
        write_atomically(path, [&](std::ostream& out) { out << header; });
        return;
    }
    header += "\n";
    write_atomically(path, [&](std::ostream& out) {
        out << header;
        write_samples(out, volume, Endian::little);
    });
}

} // namespace cmc33::io::detail
