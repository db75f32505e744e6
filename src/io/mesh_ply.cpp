// PLY (Turk 1994, "The PLY polygon file format"): ascii, binary_little_endian and
// binary_big_endian 1.0. Read: vertex x y z (any numeric type), optional nx ny nz, the face list
// vertex_indices (or vertex_index) fanned into triangles; every other property and element is
// skipped by its declared layout (so the face properties cmc33 writes are not read back). Write:
// float vertices (+ normals), uchar/uint triangle lists, then the triangle arrays as face properties.

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <unordered_set>
#include <variant>
#include <vector>

#include "mesh_formats.hpp"
#include "plural.hpp"

namespace cmc33::io::detail {
namespace {

enum class PlyType : std::uint8_t { i8, u8, i16, u16, i32, u32, f32, f64 };

struct PlyTypeName {
    std::string_view name;
    PlyType type;
};

// Both the original names and the sized ones later writers use.
constexpr std::array<PlyTypeName, 16> kTypeNames{{
    {"char", PlyType::i8},
    {"int8", PlyType::i8},
    {"uchar", PlyType::u8},
    {"uint8", PlyType::u8},
    {"short", PlyType::i16},
    {"int16", PlyType::i16},
    {"ushort", PlyType::u16},
    {"uint16", PlyType::u16},
    {"int", PlyType::i32},
    {"int32", PlyType::i32},
    {"uint", PlyType::u32},
    {"uint32", PlyType::u32},
    {"float", PlyType::f32},
    {"float32", PlyType::f32},
    {"double", PlyType::f64},
    {"float64", PlyType::f64},
}};

std::optional<PlyType> type_from_name(std::string_view name)
{
    for (const PlyTypeName& t : kTypeNames) {
        if (t.name == name) return t.type;
    }
    return std::nullopt;
}

std::size_t size_of(PlyType type)
{
    switch (type) {
    case PlyType::i8:
    case PlyType::u8: return 1;
    case PlyType::i16:
    case PlyType::u16: return 2;
    case PlyType::i32:
    case PlyType::u32:
    case PlyType::f32: return 4;
    case PlyType::f64: return 8;
    }
    return 8;
}

bool is_integer(PlyType type)
{
    return type != PlyType::f32 && type != PlyType::f64;
}

enum class Encoding { ascii, binary_little_endian, binary_big_endian };

struct Property {
    std::string name;
    bool list = false;
    PlyType type = PlyType::f32;      // the value type (list: the item type)
    PlyType count_type = PlyType::u8; // list only
};

// What a property means to us.
enum class Role : std::uint8_t { skip, x, y, z, nx, ny, nz, indices };

struct Element {
    std::string name;
    std::uint64_t count = 0;
    std::vector<Property> properties;
    std::vector<Role> roles; // filled after the header
};

struct Header {
    Encoding encoding = Encoding::ascii;
    std::vector<Element> elements;
    std::size_t data_offset = 0; // first byte after the end_header line
    std::size_t lines = 0;       // header lines, for ASCII line numbers
};

std::string_view trim_cr(std::string_view line)
{
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    return line;
}

Header parse_header(std::string_view bytes, const std::string& name)
{
    Header header;
    bool have_format = false;
    std::size_t pos = 0;
    for (;;) {
        const std::size_t newline = bytes.find('\n', pos);
        const std::size_t end = newline == std::string_view::npos ? bytes.size() : newline;
        const std::string_view line = trim_cr(bytes.substr(pos, end - pos));
        ++header.lines;
        if (header.lines == 1) {
            if (line != "ply") {
                throw Error(Status::bad_format,
                            concat(name, ": does not start with \"ply\" (found ",
                                   quote_text(line, 16), "); not a PLY file"));
            }
        } else {
            TextCursor words(line);
            std::string_view keyword;
            words.next_token(keyword);
            auto fail = [&](const std::string& what) {
                throw Error(Status::bad_format, concat(name, ": header line ", header.lines, " ",
                                                       quote_text(line, 60), ": ", what));
            };
            std::string_view a, b, c, d;
            if (keyword == "end_header") {
                if (!have_format) fail("no format line before end_header");
                header.data_offset = newline == std::string_view::npos ? bytes.size() : newline + 1;
                return header;
            } else if (keyword == "comment" || keyword == "obj_info" || keyword.empty()) {
                // free text
            } else if (keyword == "format") {
                if (!words.next_token(a) || !words.next_token(b)) {
                    fail("expected \"format <encoding> 1.0\"");
                }
                if (a == "ascii") {
                    header.encoding = Encoding::ascii;
                } else if (a == "binary_little_endian") {
                    header.encoding = Encoding::binary_little_endian;
                } else if (a == "binary_big_endian") {
                    header.encoding = Encoding::binary_big_endian;
                } else {
                    throw Error(
                        Status::unsupported_format,
                        concat(name, ": PLY format ", quote_text(a),
                               "; expected ascii, binary_little_endian or binary_big_endian"));
                }
                if (b != "1.0" && b != "1") {
                    throw Error(Status::unsupported_format,
                                concat(name, ": PLY version ", quote_text(b), "; expected 1.0"));
                }
                have_format = true;
            } else if (keyword == "element") {
                std::int64_t count = 0;
                if (!words.next_token(a) || !words.next_token(b) || !parse_int(b, count) ||
                    count < 0) {
                    fail("expected \"element <name> <count>\" with a count >= 0");
                }
                header.elements.push_back(
                    Element{std::string(a), static_cast<std::uint64_t>(count), {}, {}});
            } else if (keyword == "property") {
                if (header.elements.empty()) fail("a property before any element");
                Property property;
                if (!words.next_token(a)) fail("expected a property type");
                if (a == "list") {
                    if (!words.next_token(b) || !words.next_token(c) || !words.next_token(d)) {
                        fail("expected \"property list <count type> <item type> <name>\"");
                    }
                    const auto count_type = type_from_name(b);
                    const auto item_type = type_from_name(c);
                    if (!count_type || !item_type) fail("unknown type name");
                    if (!is_integer(*count_type)) fail("a list count must have an integer type");
                    property.list = true;
                    property.count_type = *count_type;
                    property.type = *item_type;
                    property.name = std::string(d);
                } else {
                    if (!words.next_token(b)) fail("expected \"property <type> <name>\"");
                    const auto type = type_from_name(a);
                    if (!type) fail("unknown type name");
                    property.type = *type;
                    property.name = std::string(b);
                }
                header.elements.back().properties.push_back(std::move(property));
            } else {
                fail("unknown header keyword");
            }
        }
        if (newline == std::string_view::npos) {
            throw Error(Status::truncated_file,
                        concat(name, ": the PLY header ends after ", header.lines,
                               " lines without an end_header line"));
        }
        pos = newline + 1;
    }
}

// Assigns roles; returns the vertex count (the number of records of element "vertex").
std::uint64_t assign_roles(Header& header, const std::string& name, bool& has_normals)
{
    const Element* vertex = nullptr;
    const Element* face = nullptr;
    for (Element& e : header.elements) {
        e.roles.assign(e.properties.size(), Role::skip);
        if (e.name == "vertex") {
            if (vertex != nullptr) {
                throw Error(Status::bad_format, name + ": two \"vertex\" elements");
            }
            vertex = &e;
            std::array<int, 6> found{-1, -1, -1, -1, -1, -1};
            static constexpr std::array<std::string_view, 6> kNames{"x",  "y",  "z",
                                                                    "nx", "ny", "nz"};
            for (std::size_t p = 0; p < e.properties.size(); ++p) {
                if (e.properties[p].list) continue;
                for (std::size_t k = 0; k < kNames.size(); ++k) {
                    if (e.properties[p].name == kNames[k]) found[k] = static_cast<int>(p);
                }
            }
            for (std::size_t k = 0; k < 3; ++k) {
                if (found[k] < 0) {
                    throw Error(Status::bad_format,
                                concat(name, ": the vertex element has no scalar property ",
                                       quote_text(kNames[k]), "; expected x, y and z"));
                }
            }
            has_normals = found[3] >= 0 && found[4] >= 0 && found[5] >= 0;
            const std::size_t roles = has_normals ? 6 : 3;
            for (std::size_t k = 0; k < roles; ++k) {
                e.roles[static_cast<std::size_t>(found[k])] =
                    static_cast<Role>(static_cast<int>(Role::x) + k);
            }
        } else if (e.name == "face") {
            if (face != nullptr) throw Error(Status::bad_format, name + ": two \"face\" elements");
            face = &e;
            int found = -1;
            for (std::size_t p = 0; p < e.properties.size(); ++p) {
                const Property& prop = e.properties[p];
                if (prop.list && (prop.name == "vertex_indices" || prop.name == "vertex_index")) {
                    if (!is_integer(prop.type)) {
                        throw Error(
                            Status::bad_format,
                            concat(name, ": face property ", quote_text(prop.name),
                                   " has a floating-point item type; expected an integer type"));
                    }
                    found = static_cast<int>(p);
                }
            }
            if (found < 0) {
                throw Error(Status::bad_format, name + ": the face element has no list property "
                                                       "\"vertex_indices\" (or \"vertex_index\")");
            }
            e.roles[static_cast<std::size_t>(found)] = Role::indices;
        }
    }
    if (vertex == nullptr) {
        throw Error(Status::bad_format, name + ": the header declares no \"vertex\" element");
    }
    return vertex->count;
}

// Bytes (binary) or tokens (ascii) one record of `e` takes with `face_items` items in its face
// index list and none in other lists. With 0, the least a record can take: a face of 0 or 2
// indices is then reported as such where it is read, not as a file too short for its counts.
std::uint64_t min_record_units(const Element& e, bool binary, std::uint64_t face_items = 0)
{
    std::uint64_t units = 0;
    for (std::size_t p = 0; p < e.properties.size(); ++p) {
        const Property& prop = e.properties[p];
        const std::uint64_t items = e.roles[p] == Role::indices ? face_items : 0;
        if (binary) {
            units += prop.list ? size_of(prop.count_type) + items * size_of(prop.type)
                               : size_of(prop.type);
        } else {
            units += prop.list ? 1 + items : 1;
        }
    }
    return units;
}

// Narrowing a double beyond float's range is undefined in C++; give what IEEE rounding gives.
float to_float(double value)
{
    constexpr double kRoundsToInfinity = 3.4028235677973366e38; // FLT_MAX + half an ulp
    if (value >= kRoundsToInfinity) return std::numeric_limits<float>::infinity();
    if (value <= -kRoundsToInfinity) return -std::numeric_limits<float>::infinity();
    return static_cast<float>(value);
}

struct Sink {
    Mesh& mesh;
    std::uint64_t vertex_count;
    std::vector<std::int64_t> polygon;
    std::uint64_t face_number = 0;
    const std::string& name;

    void vertex_value(std::uint64_t record, Role role, double value)
    {
        const std::size_t r = static_cast<std::size_t>(record);
        const float v = to_float(value);
        switch (role) {
        case Role::x: mesh.positions[3 * r] = v; break;
        case Role::y: mesh.positions[3 * r + 1] = v; break;
        case Role::z: mesh.positions[3 * r + 2] = v; break;
        case Role::nx: mesh.normals[3 * r] = v; break;
        case Role::ny: mesh.normals[3 * r + 1] = v; break;
        case Role::nz: mesh.normals[3 * r + 2] = v; break;
        default: break;
        }
    }

    // Checks the polygon in `polygon` and fans it into triangles; `line` is its line in ASCII, 0 in binary.
    void end_face(std::size_t line = 0)
    {
        const auto fail = [&](const std::string& what) {
            throw Error(Status::bad_format, concat(name, ": ", line > 0 ? concat("line ", line, ": ") : std::string(),
                                                   "face ", face_number, " ", what));
        };
        if (polygon.size() < 3) {
            fail(concat("has ", counted(polygon.size(), "vertex index", "vertex indices"), "; expected at least 3"));
        }
        for (std::int64_t index : polygon) {
            if (index < 0 || static_cast<std::uint64_t>(index) >= vertex_count) {
                fail(concat("uses vertex index ", index, " but the file has ",
                            counted(vertex_count, "vertex", "vertices")));
            }
        }
        for (std::size_t i = 1; i + 1 < polygon.size(); ++i) {
            mesh.triangles.push_back(static_cast<std::uint32_t>(polygon[0]));
            mesh.triangles.push_back(static_cast<std::uint32_t>(polygon[i]));
            mesh.triangles.push_back(static_cast<std::uint32_t>(polygon[i + 1]));
        }
        polygon.clear();
        ++face_number;
    }
};

void check_count(const Element& e, std::uint64_t min_units, std::uint64_t capacity_units,
                 std::uint64_t remaining_bytes, const char* unit, const std::string& name)
{
    if (min_units == 0 || e.count <= capacity_units / min_units) return;
    throw Error(Status::truncated_file,
                concat(name, ": the header declares ", e.count, " ", quote_text(e.name),
                       " records (at least ", min_units, " ", unit, " each) but only ",
                       remaining_bytes, " bytes remain"));
}

// Called once the element's count has been checked against the data; at most `faces` faces are
// reserved for (those the data holds room for as triangles), whatever the count declares.
void allocate(const Element& e, Mesh& mesh, const std::string& name, std::uint64_t faces)
{
    if (e.name == "vertex") {
        if (e.count > std::numeric_limits<std::uint32_t>::max()) {
            throw Error(
                Status::too_large,
                concat(name, ": ", e.count, " vertices; at most 4294967295 (32-bit indices)"));
        }
        mesh.positions.assign(3 * static_cast<std::size_t>(e.count), 0.0f);
        if (std::find(e.roles.begin(), e.roles.end(), Role::nx) != e.roles.end()) {
            mesh.normals.assign(3 * static_cast<std::size_t>(e.count), 0.0f);
        }
    } else if (e.name == "face") {
        mesh.triangles.reserve(3 * static_cast<std::size_t>(std::min(e.count, faces)));
    }
}

// ---- binary ---------------------------------------------------------------------------------

class BinaryInput {
public:
    BinaryInput(std::string_view bytes, std::size_t start, bool big_endian, const std::string& name)
        : bytes_(bytes), pos_(start),
          swap_(big_endian != (std::endian::native == std::endian::big)), name_(name)
    {
    }

    std::size_t remaining() const noexcept { return bytes_.size() - pos_; }

    // Makes sure `n` more bytes exist; `what` names the record for the message.
    void need(std::uint64_t n, const Element& e, std::uint64_t record)
    {
        if (n <= remaining()) return;
        throw Error(Status::truncated_file,
                    concat(name_, ": the data ends inside ", quote_text(e.name), " record ", record,
                           " of ", e.count, " (", n, " more bytes needed at byte ", pos_, ", ",
                           remaining(), " left); the file is shorter than its header declares"));
    }

    void skip(std::size_t n) { pos_ += n; }

    double real(PlyType type)
    {
        const char* p = bytes_.data() + pos_;
        pos_ += size_of(type);
        switch (type) {
        case PlyType::i8: return static_cast<std::int8_t>(*p);
        case PlyType::u8: return static_cast<std::uint8_t>(*p);
        case PlyType::i16: return load<std::int16_t>(p);
        case PlyType::u16: return load<std::uint16_t>(p);
        case PlyType::i32: return load<std::int32_t>(p);
        case PlyType::u32: return load<std::uint32_t>(p);
        case PlyType::f32: return static_cast<double>(std::bit_cast<float>(load<std::uint32_t>(p)));
        case PlyType::f64: return std::bit_cast<double>(load<std::uint64_t>(p));
        }
        return 0;
    }

    std::int64_t integer(PlyType type)
    {
        const char* p = bytes_.data() + pos_;
        pos_ += size_of(type);
        switch (type) {
        case PlyType::i8: return static_cast<std::int8_t>(*p);
        case PlyType::u8: return static_cast<std::uint8_t>(*p);
        case PlyType::i16: return load<std::int16_t>(p);
        case PlyType::u16: return load<std::uint16_t>(p);
        case PlyType::i32: return load<std::int32_t>(p);
        case PlyType::u32: return load<std::uint32_t>(p);
        default: return 0; // the header parser only lets integer types reach here
        }
    }

private:
    template <class T> T load(const char* p) const
    {
        using U = std::make_unsigned_t<T>;
        U u;
        std::memcpy(&u, p, sizeof u);
        if (swap_) {
            U swapped = 0;
            for (std::size_t i = 0; i < sizeof u; ++i) {
                swapped = static_cast<U>(swapped << 8 | ((u >> (8 * i)) & 0xff));
            }
            u = swapped;
        }
        return static_cast<T>(u);
    }

    std::string_view bytes_;
    std::size_t pos_;
    bool swap_;
    const std::string& name_;
};

void read_binary(const Header& header, std::string_view bytes, Sink& sink, const std::string& name)
{
    BinaryInput in(bytes, header.data_offset, header.encoding == Encoding::binary_big_endian, name);
    for (const Element& e : header.elements) {
        const std::uint64_t min_bytes = min_record_units(e, true);
        if (min_bytes == 0) continue; // no properties: records take no bytes
        check_count(e, min_bytes, in.remaining(), in.remaining(), "bytes", name);
        allocate(e, sink.mesh, name, in.remaining() / min_record_units(e, true, 3));
        for (std::uint64_t r = 0; r < e.count; ++r) {
            for (std::size_t p = 0; p < e.properties.size(); ++p) {
                const Property& prop = e.properties[p];
                const Role role = e.roles[p];
                if (!prop.list) {
                    in.need(size_of(prop.type), e, r);
                    if (role == Role::skip) {
                        in.skip(size_of(prop.type));
                    } else {
                        sink.vertex_value(r, role, in.real(prop.type));
                    }
                    continue;
                }
                in.need(size_of(prop.count_type), e, r);
                const std::int64_t items = in.integer(prop.count_type);
                if (items < 0) {
                    throw Error(Status::bad_format,
                                concat(name, ": ", quote_text(e.name), " record ", r,
                                       " has a list of ", items, " items"));
                }
                const std::uint64_t item_bytes =
                    static_cast<std::uint64_t>(items) * size_of(prop.type);
                in.need(item_bytes, e, r);
                if (role != Role::indices) {
                    in.skip(static_cast<std::size_t>(item_bytes));
                    continue;
                }
                for (std::int64_t i = 0; i < items; ++i) {
                    sink.polygon.push_back(in.integer(prop.type));
                }
                sink.end_face();
            }
        }
    }
    if (in.remaining() > 0) {
        throw Error(Status::bad_format,
                    concat(name, ": ", in.remaining(),
                           in.remaining() == 1 ? " byte follows" : " bytes follow",
                           " the last record the header declares (at byte ",
                           bytes.size() - in.remaining(), " of ", bytes.size(),
                           "); more data than declared (wrong counts?)"));
    }
}

// ---- ascii ----------------------------------------------------------------------------------

void read_ascii(const Header& header, std::string_view bytes, Sink& sink, const std::string& name)
{
    TextCursor in(bytes.substr(header.data_offset));
    std::string_view token;
    auto next = [&](const Element& e, std::uint64_t r, const Property& prop) {
        if (!in.next_token(token)) {
            throw Error(Status::truncated_file,
                        concat(name, ": the data ends inside ", quote_text(e.name), " record ", r,
                               " of ", e.count, " (property ", quote_text(prop.name),
                               "); the file is shorter than its header declares"));
        }
    };
    auto bad_number = [&](const Element& e, std::uint64_t r, const Property& prop,
                          const char* expected) {
        throw Error(Status::bad_format,
                    concat(name, ": line ", header.lines + in.line(), ": ", quote_text(token),
                           " is not ", expected, " (property ", quote_text(prop.name), " of ",
                           quote_text(e.name), " record ", r, ")"));
    };
    for (const Element& e : header.elements) {
        const std::uint64_t min_tokens = min_record_units(e, false);
        if (min_tokens == 0) continue;
        // Each token takes at least one character and one separator.
        check_count(e, min_tokens, (in.remaining() + 1) / 2, in.remaining(), "numbers", name);
        allocate(e, sink.mesh, name, (in.remaining() + 1) / 2 / min_record_units(e, false, 3));
        for (std::uint64_t r = 0; r < e.count; ++r) {
            for (std::size_t p = 0; p < e.properties.size(); ++p) {
                const Property& prop = e.properties[p];
                const Role role = e.roles[p];
                next(e, r, prop);
                if (!prop.list) {
                    if (role == Role::skip) continue;
                    double value = 0;
                    if (prop.type == PlyType::f32) {
                        float f = 0;
                        if (!parse_float(token, f)) bad_number(e, r, prop, "a number");
                        value = static_cast<double>(f);
                    } else if (!parse_double(token, value)) {
                        bad_number(e, r, prop, "a number");
                    }
                    sink.vertex_value(r, role, value);
                    continue;
                }
                std::int64_t items = 0;
                if (!parse_int(token, items) || items < 0) bad_number(e, r, prop, "a list length");
                for (std::int64_t i = 0; i < items; ++i) {
                    next(e, r, prop);
                    if (role != Role::indices) continue;
                    std::int64_t index = 0;
                    if (!parse_int(token, index)) bad_number(e, r, prop, "an integer index");
                    sink.polygon.push_back(index);
                }
                if (role == Role::indices) sink.end_face(header.lines + in.line());
            }
        }
    }
    if (in.next_token(token)) {
        throw Error(Status::bad_format,
                    concat(name, ": line ", header.lines + in.line(), ": ", quote_text(token),
                           " follows the last record the header declares; more data than "
                           "declared (wrong counts?)"));
    }
}

} // namespace

Mesh read_ply(std::string_view bytes, const std::string& name)
{
    Header header = parse_header(bytes, name);
    bool has_normals = false;
    const std::uint64_t vertex_count = assign_roles(header, name, has_normals);
    Mesh mesh;
    Sink sink{mesh, vertex_count, {}, 0, name};
    if (header.encoding == Encoding::ascii) {
        check_text_end(bytes, 0, name);
        read_ascii(header, bytes, sink, name);
    } else {
        read_binary(header, bytes, sink, name);
    }
    return mesh;
}

namespace {

/// The property names of one array: its name, or NAME_0, NAME_1, ... with several components.
std::vector<std::string> property_names(const MeshArray& a)
{
    if (a.components == 1) return {a.name};
    std::vector<std::string> names;
    for (int c = 0; c < a.components; ++c) names.push_back(a.name + "_" + std::to_string(c));
    return names;
}

/// The PLY integer type of int64 values: int when all fit int32, uint when none is negative and
/// all fit uint32, else nullptr.
const char* integer_type(std::span<const std::int64_t> values, std::size_t& low, std::size_t& high)
{
    low = high = 0;
    for (std::size_t i = 1; i < values.size(); ++i) {
        if (values[i] < values[low]) low = i;
        if (values[i] > values[high]) high = i;
    }
    if (values.empty()) return "int";
    if (values[low] >= std::numeric_limits<std::int32_t>::min() && values[high] <= std::numeric_limits<std::int32_t>::max())
        return "int";
    if (values[low] >= 0 && values[high] <= std::numeric_limits<std::uint32_t>::max()) return "uint";
    return nullptr;
}

} // namespace

std::vector<PlyFaceArray> ply_face_arrays(const std::vector<MeshArray>& arrays, const std::string& name)
{
    std::vector<PlyFaceArray> faces;
    // a set: an array of many components brings as many names
    std::unordered_set<std::string> taken{"vertex_indices", "vertex_index"};
    for (const MeshArray& a : arrays) {
        const auto fail = [&](const std::string& what) {
            throw Error(Status::invalid_argument,
                        concat(name, ": cannot write the triangle array ", quote_text(a.name), " as PLY face properties: ", what));
        };
        for (const std::string& property : property_names(a)) {
            const bool word = std::all_of(property.begin(), property.end(), [](char c) { return c > ' ' && c < 127; });
            if (!word) fail("a PLY property name is printable ASCII without blanks (the header splits its lines at blanks)");
            if (!taken.insert(property).second) {
                fail(concat("the face element already has a property ", quote_text(property), "; expected distinct names"));
            }
        }
        PlyFaceArray face{&a, "float"};
        if (std::holds_alternative<std::span<const std::int32_t>>(a.values)) face.type = "int";
        if (const auto* wide = std::get_if<std::span<const std::int64_t>>(&a.values)) {
            std::size_t low = 0, high = 0;
            face.type = integer_type(*wide, low, high);
            if (face.type == nullptr) {
                const auto at = [&](std::size_t i) {
                    return concat((*wide)[i], " (triangle ", i / static_cast<std::size_t>(a.components), ")");
                };
                fail(concat("its values run from ", at(low), " to ", at(high),
                            ", which fit neither PLY's int (-2147483648 to 2147483647) nor, without negative values, "
                            "its uint (0 to 4294967295); PLY has no 64-bit integers (.vtp stores Int64)"));
            }
        }
        faces.push_back(face);
    }
    return faces;
}

std::string ply_header(std::uint64_t vertices, std::uint64_t triangles, bool normals, bool ascii, bool double_positions,
                       const std::vector<PlyFaceArray>& faces)
{
    std::string h = ascii ? "ply\nformat ascii 1.0\n" : "ply\nformat binary_little_endian 1.0\n";
    h += "comment generated by cmc33\nelement vertex " + std::to_string(vertices);
    h += double_positions ? "\nproperty double x\nproperty double y\nproperty double z\n"
                          : "\nproperty float x\nproperty float y\nproperty float z\n";
    if (normals) h += "property float nx\nproperty float ny\nproperty float nz\n";
    h += "element face " + std::to_string(triangles);
    h += "\nproperty list uchar uint vertex_indices\n";
    for (const PlyFaceArray& f : faces) {
        for (const std::string& property : property_names(*f.array)) h += concat("property ", f.type, " ", property, "\n");
    }
    h += "end_header\n";
    return h;
}

void write_ply(const Mesh& mesh, std::ostream& out, bool ascii, const double* offset, const std::vector<PlyFaceArray>& faces)
{
    OutputBuffer o(out);
    const bool normals = mesh.has_normals();
    o.text(ply_header(mesh.vertex_count(), mesh.triangle_count(), normals, ascii, offset != nullptr, faces));

    const float* p = mesh.positions.data();
    const float* n = mesh.normals.data();
    const std::uint32_t* t = mesh.triangles.data();
    if (!ascii && !offset) {
        // Binary records as they lie in memory: x y z [nx ny nz] floats.
        if (!normals) {
            o.records(mesh.vertex_count(), kPlyVertexBytes, [&](char* dst, std::size_t first, std::size_t count) {
                store_f32s_le(dst, p + 3 * first, 3 * count);
            });
        } else {
            o.records(mesh.vertex_count(), kPlyNormalVertexBytes, [&](char* dst, std::size_t first, std::size_t count) {
                for (std::size_t v = first; v < first + count; ++v, dst += kPlyNormalVertexBytes) {
                    store_f32s_le(dst, p + 3 * v, 3);
                    store_f32s_le(dst + 12, n + 3 * v, 3);
                }
            });
        }
    } else {
        for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
            const std::size_t count = normals ? 6 : 3;
            for (std::size_t k = 0; k < count; ++k) {
                const float value = k < 3 ? p[3 * v + k] : n[3 * v + k - 3];
                if (offset && k < 3) {
                    const double world = offset[k] + static_cast<double>(value);
                    if (ascii) {
                        if (k > 0) o.character(' ');
                        o.real(world);
                    } else {
                        o.f64_le(world);
                    }
                    continue;
                }
                if (ascii) {
                    if (k > 0) o.character(' ');
                    o.real(value);
                } else {
                    o.f32_le(value);
                }
            }
            if (ascii) o.character('\n');
        }
    }

    if (ascii) {
        // A line interleaves every array's values, so the loop over triangles is the outer one;
        // each array's element type is looked up once here instead of per value.
        struct Column {
            const float* reals = nullptr;
            const std::int32_t* narrow = nullptr;
            const std::int64_t* wide = nullptr;
            std::size_t components = 0;
        };
        std::vector<Column> columns;
        for (const PlyFaceArray& a : faces) {
            Column c;
            c.components = static_cast<std::size_t>(a.array->components);
            std::visit(
                [&](const auto& span) {
                    using T = typename std::decay_t<decltype(span)>::element_type;
                    if constexpr (std::is_same_v<T, const float>) {
                        c.reals = span.data();
                    } else if constexpr (std::is_same_v<T, const std::int32_t>) {
                        c.narrow = span.data();
                    } else {
                        c.wide = span.data();
                    }
                },
                a.array->values);
            columns.push_back(c);
        }
        for (std::size_t f = 0; f < mesh.triangle_count(); ++f) {
            o.text("3 ");
            o.integer(t[3 * f]);
            o.character(' ');
            o.integer(t[3 * f + 1]);
            o.character(' ');
            o.integer(t[3 * f + 2]);
            for (const Column& c : columns) {
                for (std::size_t k = c.components * f; k < c.components * (f + 1); ++k) {
                    o.character(' ');
                    if (c.reals) {
                        o.real(c.reals[k]);
                    } else if (c.narrow) {
                        o.integer(c.narrow[k]);
                    } else {
                        o.integer(c.wide[k]);
                    }
                }
            }
            o.character('\n');
        }
        o.flush();
        return;
    }
    // Binary: uchar 3, 3 uints, then each array's values. int and uint values are the low 32 bits
    // of the int64 ones: ply_face_arrays() chose a type that holds every value. Each batch of
    // records gets its indices first, then one array at a time (its type looked up once).
    std::size_t face_bytes = kPlyFaceBytes;
    for (const PlyFaceArray& f : faces) face_bytes += 4 * static_cast<std::size_t>(f.array->components);
    o.records(mesh.triangle_count(), face_bytes, [&](char* dst, std::size_t first, std::size_t count) {
        for (std::size_t f = first; f < first + count; ++f) {
            char* record = dst + (f - first) * face_bytes;
            record[0] = 3;
            store_u32s_le(record + 1, t + 3 * f, 3);
        }
        std::size_t at = kPlyFaceBytes; // the array's first value within a record
        for (const PlyFaceArray& a : faces) {
            const std::size_t c = static_cast<std::size_t>(a.array->components);
            std::visit(
                [&](const auto& span) {
                    using T = typename std::decay_t<decltype(span)>::element_type;
                    for (std::size_t f = first; f < first + count; ++f) {
                        char* values = dst + (f - first) * face_bytes + at;
                        if constexpr (std::is_same_v<T, const float>) {
                            store_f32s_le(values, span.data() + c * f, c);
                        } else {
                            for (std::size_t k = 0; k < c; ++k) store_le(values + 4 * k, static_cast<std::uint32_t>(span[c * f + k]));
                        }
                    }
                },
                a.array->values);
            at += 4 * c;
        }
    });
    o.flush();
}

} // namespace cmc33::io::detail
