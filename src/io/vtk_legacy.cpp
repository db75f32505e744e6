// VTK legacy files, STRUCTURED_POINTS only:
//   # vtk DataFile Version X.Y / title / ASCII|BINARY / DATASET STRUCTURED_POINTS /
//   DIMENSIONS nx ny nz / SPACING (or ASPECT_RATIO) / ORIGIN / POINT_DATA n /
//   SCALARS name type [1] / [LOOKUP_TABLE name] / samples
// BINARY samples are big-endian, as VTK writes them. The first point attribute must be SCALARS;
// what follows the scalars (other attributes) is not read.

#include <string>
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

constexpr TypeName kTypes[] = {
    {"char", ScalarType::i8},
    {"signed_char", ScalarType::i8},
    {"unsigned_char", ScalarType::u8},
    {"short", ScalarType::i16},
    {"unsigned_short", ScalarType::u16},
    {"int", ScalarType::i32},
    {"unsigned_int", ScalarType::u32},
    {"float", ScalarType::f32},
    {"double", ScalarType::f64},
    {"vtktypeint8", ScalarType::i8},
    {"vtktypeuint8", ScalarType::u8},
    {"vtktypeint16", ScalarType::i16},
    {"vtktypeuint16", ScalarType::u16},
    {"vtktypeint32", ScalarType::i32},
    {"vtktypeuint32", ScalarType::u32},
    {"vtktypefloat32", ScalarType::f32},
    {"vtktypefloat64", ScalarType::f64},
};

// Valid VTK types that cmc33 does not hold.
constexpr std::string_view kUnsupportedTypes[] = {
    "bit",       "long",         "unsigned_long", "long_long", "unsigned_long_long",
    "vtkidtype", "vtktypeint64", "vtktypeuint64", "__int64",   "unsigned___int64",
    "string",    "utf8_string",  "variant",
};

constexpr std::string_view kDatasets[] = {
    "STRUCTURED_GRID", "RECTILINEAR_GRID", "UNSTRUCTURED_GRID", "POLYDATA", "FIELD",
};

constexpr std::string_view kAttributes[] = {
    "VECTORS",
    "NORMALS",
    "TENSORS",
    "TEXTURE_COORDINATES",
    "COLOR_SCALARS",
    "LOOKUP_TABLE",
    "FIELD",
    "GLOBAL_IDS",
    "PEDIGREE_IDS",
    "EDGE_FLAGS",
    "TANGENTS",
    "RATIONAL_WEIGHTS",
    "HIGHERORDER_DEGREES",
};

bool one_of(std::string_view word, const auto& list)
{
    for (std::string_view w : list) {
        if (equals_ignore_case(w, word)) return true;
    }
    return false;
}

ScalarType parse_vtk_type(std::string_view word, std::size_t line, const std::string& label)
{
    const std::string name = lower_ascii(word);
    for (const TypeName& t : kTypes) {
        if (t.name == name) return t.type;
    }
    for (std::string_view t : kUnsupportedTypes) {
        if (t == name) {
            throw Error(Status::unsupported_format,
                        str_cat(label, ": SCALARS type ", quote_bytes(word), " (line ", line,
                                ") is not supported; cmc33 reads char, unsigned_char, short, "
                                "unsigned_short, int, unsigned_int, float and double"));
        }
    }
    throw Error(Status::bad_format,
                str_cat(label, ": unknown SCALARS type ", quote_bytes(word), " (line ", line,
                        "); expected unsigned_char, short, float, ..."));
}

std::string vtk_type_name(ScalarType type)
{
    switch (type) {
    case ScalarType::i8: return "signed_char"; // "char" may be unsigned on some machines
    case ScalarType::u8: return "unsigned_char";
    case ScalarType::i16: return "short";
    case ScalarType::u16: return "unsigned_short";
    case ScalarType::i32: return "int";
    case ScalarType::u32: return "unsigned_int";
    case ScalarType::f32: return "float";
    case ScalarType::f64: break;
    }
    return "double";
}

/// Header lines, numbered, each required to end with a newline (samples follow the header).
class HeaderLines {
public:
    HeaderLines(std::string_view bytes, const std::string& label) : source_(bytes), label_(label) {}

    /// The next line (blank ones too). Throws if the file ends first or inside the line.
    std::string_view line(std::string_view expected)
    {
        std::string_view text;
        bool terminated = false;
        if (!source_.next_line(text, terminated) || !terminated) {
            throw Error(Status::truncated_file,
                        str_cat(label_, ": the file ends ", text.empty() ? "before" : "inside",
                                " header line ", number_ + 1, " (", expected,
                                "); file cut short?"));
        }
        ++number_;
        return text;
    }
    /// The words of the next non-blank line.
    std::vector<std::string_view> words(std::string_view expected)
    {
        while (true) {
            std::vector<std::string_view> w = split_words(line(expected));
            if (!w.empty()) return w;
        }
    }
    std::size_t number() const noexcept { return number_; }
    ByteSource& source() noexcept { return source_; }

private:
    ByteSource source_;
    const std::string& label_;
    std::size_t number_ = 0;
};

/// After the samples: blanks, then the end of the file or another section (an attribute, FIELD,
/// CELL_DATA, METADATA), which is not read. Anything else means more samples than declared.
void check_after_samples(const ByteInput& file, std::uint64_t end, std::int64_t samples,
                         const std::string& label)
{
    std::uint64_t pos = end;
    std::string chunk;
    std::size_t word = std::string::npos;
    while (word == std::string::npos) {
        chunk = file.read_string(pos, 1 << 12);
        if (chunk.empty()) return;
        word = chunk.find_first_not_of(" \t\r\n\v\f");
        if (word == std::string::npos) pos += chunk.size();
    }
    pos += word;
    // A keyword longer than the chunk's rest is read again from its start.
    chunk = file.read_string(pos, 64);
    const std::string_view next = split_words(chunk).front();
    if (equals_ignore_case(next, "SCALARS") || equals_ignore_case(next, "POINT_DATA") ||
        equals_ignore_case(next, "CELL_DATA") || equals_ignore_case(next, "METADATA") ||
        one_of(next, kAttributes)) {
        return;
    }
    throw Error(Status::bad_format,
                str_cat(label, ": after the ", samples, " samples POINT_DATA declares, ",
                        quote_bytes(chunk, 16), " follows at byte ", pos,
                        "; expected the end of the file or another attribute (SCALARS, VECTORS, "
                        "FIELD, CELL_DATA, ...): more samples than declared?"));
}

} // namespace

Volume read_vtk(const ByteInput& file, const ReadSamples& read)
{
    const std::string& label = file.label();
    const std::string head = read_header_bytes(file, "VTK legacy");
    HeaderLines lines(head, label);

    constexpr std::string_view kMagic = "# vtk DataFile Version";
    const std::string_view first =
        std::string_view(head).substr(0, std::min(head.find('\n'), head.size()));
    if (!equals_ignore_case(first.substr(0, kMagic.size()), kMagic)) {
        throw Error(Status::bad_format,
                    str_cat(label, ": not a VTK legacy file: it starts with ", quote_bytes(first),
                            " instead of \"# vtk DataFile Version\""));
    }
    lines.line("# vtk DataFile Version");
    lines.line("the title");
    const std::string_view format = trim(lines.line("ASCII or BINARY"));
    const bool binary = equals_ignore_case(format, "BINARY");
    if (!binary && !equals_ignore_case(format, "ASCII")) {
        throw Error(Status::bad_format, str_cat(label, ": line 3 ", quote_bytes(format),
                                                " is neither ASCII nor BINARY"));
    }

    // The dataset's geometry, up to POINT_DATA.
    std::vector<std::string_view> w = lines.words("DATASET STRUCTURED_POINTS");
    if (!equals_ignore_case(w[0], "DATASET") || w.size() != 2) {
        throw Error(Status::bad_format, str_cat(label, ": line ", lines.number(),
                                                " should be \"DATASET "
                                                "STRUCTURED_POINTS\", found ",
                                                quote_bytes(w[0])));
    }
    if (!equals_ignore_case(w[1], "STRUCTURED_POINTS")) {
        throw Error(one_of(w[1], kDatasets) ? Status::unsupported_format : Status::bad_format,
                    str_cat(label, ": DATASET ", quote_bytes(w[1]), " (line ", lines.number(),
                            ") is not supported; cmc33 reads STRUCTURED_POINTS"));
    }
    Grid grid;
    bool have_dims = false;
    std::int64_t points = 0;
    while (true) {
        w = lines.words("DIMENSIONS, SPACING, ORIGIN or POINT_DATA");
        const std::vector<std::string_view> values(w.begin() + 1, w.end());
        const std::string what = str_cat(w[0], " (line ", lines.number(), ")");
        if (equals_ignore_case(w[0], "DIMENSIONS")) {
            grid.dims = parse_dims(values, label, what);
            have_dims = true;
        } else if (equals_ignore_case(w[0], "SPACING") ||
                   equals_ignore_case(w[0], "ASPECT_RATIO")) {
            // a negative spacing flips its axis (vtkImageData allows it); 0 is degenerate
            const Vec3 step = parse_vec3(values, label, what, false);
            set_frame(grid, {{{step[0], 0, 0}, {0, step[1], 0}, {0, 0, step[2]}}}, {1, 1, 1}, label,
                      what);
        } else if (equals_ignore_case(w[0], "ORIGIN")) {
            grid.origin = parse_vec3(values, label, what, false);
        } else if (equals_ignore_case(w[0], "POINT_DATA")) {
            if (values.size() != 1 || !parse_integer(values[0], points) || points <= 0) {
                throw Error(Status::bad_format,
                            str_cat(label, ": ", what, " should give one positive count"));
            }
            break;
        } else if (equals_ignore_case(w[0], "FIELD")) {
            throw Error(Status::unsupported_format,
                        str_cat(label, ": ", what, ": field data in the dataset is not supported; "
                                                   "cmc33 reads POINT_DATA scalars"));
        } else if (equals_ignore_case(w[0], "CELL_DATA")) {
            throw Error(Status::unsupported_format,
                        str_cat(label, ": ", what, " is not supported; cmc33 reads POINT_DATA "
                                                   "scalars"));
        } else {
            throw Error(Status::bad_format,
                        str_cat(label, ": unexpected ", quote_bytes(w[0]), " on line ",
                                lines.number(),
                                "; expected DIMENSIONS, SPACING, ORIGIN or POINT_DATA"));
        }
    }
    if (!have_dims) {
        throw Error(Status::bad_format, str_cat(label, ": POINT_DATA (line ", lines.number(),
                                                ") comes before DIMENSIONS"));
    }
    const std::size_t point_data_line = lines.number();

    // The first point attribute: SCALARS name type [components].
    w = lines.words("SCALARS name type");
    if (!equals_ignore_case(w[0], "SCALARS")) {
        throw Error(one_of(w[0], kAttributes) ? Status::unsupported_format : Status::bad_format,
                    str_cat(label, ": the first POINT_DATA attribute is ", quote_bytes(w[0]),
                            " (line ", lines.number(), "); cmc33 reads SCALARS"));
    }
    if (w.size() < 3 || w.size() > 4) {
        throw Error(Status::bad_format, str_cat(label, ": line ", lines.number(),
                                                " should be \"SCALARS name type [components]\""));
    }
    grid.type = parse_vtk_type(w[2], lines.number(), label);
    if (w.size() == 4) {
        std::int64_t components = 0;
        if (!parse_integer(w[3], components) || components != 1) {
            throw Error(Status::unsupported_format,
                        str_cat(label, ": SCALARS with ", quote_bytes(w[3]), " components (line ",
                                lines.number(), ") is not supported; cmc33 reads one component"));
        }
    }
    // The sizes must be sane before they are multiplied.
    payload_bytes(grid.dims, grid.type, label);
    const std::int64_t expected = grid.dims[0] * grid.dims[1] * grid.dims[2];
    if (points != expected) {
        throw Error(Status::bad_format, str_cat(label, ": POINT_DATA ", points, " (line ",
                                                point_data_line, ") does not match DIMENSIONS ",
                                                dims_text(grid.dims), " = ", expected, " points"));
    }
    // An optional LOOKUP_TABLE line; binary samples start right after the line before them.
    ByteSource& source = lines.source();
    std::string_view rest = source.rest();
    const std::size_t word = binary ? 0 : std::min(rest.find_first_not_of(" \t\r\n"), rest.size());
    // VTK matches its keywords in any case: "lookup_table default" is a lookup table, not samples
    if (equals_ignore_case(rest.substr(word, 12), "LOOKUP_TABLE")) {
        std::string_view skipped;
        source.take(word, skipped);
        lines.line("LOOKUP_TABLE name");
    }

    Storage storage;
    storage.encoding = binary ? Encoding::raw : Encoding::ascii;
    storage.endian = Endian::big;
    storage.offset = source.position();
    storage.check_trailing = false; // other attributes may follow: checked here
    std::uint64_t end = 0;
    Volume volume = read(file, grid, storage, label, &end);
    check_after_samples(file, end, expected, label);
    return volume;
}

void write_vtk(const Volume& volume, const std::filesystem::path& path)
{
    const Index3& n = volume.dims();
    if (!is_diagonal(volume.direction())) {
        throw Error(Status::unsupported_format,
                    str_cat(path.string(),
                            ": VTK STRUCTURED_POINTS cannot hold the volume's rotated frame (only "
                            "ORIGIN and SPACING); write .nrrd or .mhd to keep it"));
    }
    Vec3 s = volume.spacing(); // signed: a flipped axis has a negative spacing
    for (std::size_t a = 0; a < 3; ++a) s[a] *= volume.direction()[a][a];
    const Vec3& o = volume.origin();
    std::string header = "# vtk DataFile Version 3.0\n"
                         "cmc33 volume\n"
                         "BINARY\n"
                         "DATASET STRUCTURED_POINTS\n";
    header += str_cat("DIMENSIONS ", n[0], ' ', n[1], ' ', n[2], '\n');
    header +=
        "SPACING " + format_real(s[0]) + " " + format_real(s[1]) + " " + format_real(s[2]) + "\n";
    header +=
        "ORIGIN " + format_real(o[0]) + " " + format_real(o[1]) + " " + format_real(o[2]) + "\n";
    header += str_cat("POINT_DATA ", volume.sample_count(), '\n');
    header += "SCALARS scalars " + vtk_type_name(volume.type()) + " 1\n";
    header += "LOOKUP_TABLE default\n";
    write_atomically(path, [&](std::ostream& out) {
        out << header;
        write_samples(out, volume, Endian::big);
    });
}

} // namespace cmc33::io::detail
