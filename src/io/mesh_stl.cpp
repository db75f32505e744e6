// STL: binary (80-byte header, uint32 count, 50 bytes per facet: normal, 3 vertices, uint16
// attribute; little-endian) and ASCII (solid / facet normal / outer loop / vertex / endloop /
// endfacet / endsolid). STL stores every triangle's corners by value: reading welds exactly equal
// positions (bitwise, with -0.0 == 0.0) into shared vertices, numbered in order of first
// appearance. Facet normals are not kept (they are per face; the Mesh has per-vertex normals).

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "mesh_formats.hpp"

namespace cmc33::io::detail {
namespace {

constexpr std::size_t kHeaderBytes = 80;
constexpr std::size_t kFacetBytes = 50;

// Open-addressing hash set of vertex ids keyed by their position's bits; the positions live in
// the mesh, so the table holds only 32-bit ids. Linear probing, at most half full.
class Welder {
public:
    explicit Welder(Mesh& mesh, const std::string& name) : mesh_(mesh), name_(name)
    {
        rehash(1024);
    }

    std::uint32_t add(const float xyz[3])
    {
        const std::array<std::uint32_t, 3> key{bits(xyz[0]), bits(xyz[1]), bits(xyz[2])};
        std::size_t slot = hash(key) & mask_;
        for (;;) {
            const std::uint32_t id = slots_[slot];
            if (id == kEmpty) break;
            const float* p = &mesh_.positions[3 * static_cast<std::size_t>(id)];
            if (bits(p[0]) == key[0] && bits(p[1]) == key[1] && bits(p[2]) == key[2]) return id;
            slot = (slot + 1) & mask_;
        }
        const std::size_t count = mesh_.vertex_count();
        if (count >= kEmpty) {
            throw Error(Status::too_large,
                        concat(name_, ": more than 4294967294 distinct vertices"));
        }
        const auto id = static_cast<std::uint32_t>(count);
        mesh_.positions.insert(mesh_.positions.end(), xyz, xyz + 3);
        slots_[slot] = id;
        if (2 * (count + 1) > slots_.size()) rehash(2 * slots_.size());
        return id;
    }

private:
    static constexpr std::uint32_t kEmpty = std::numeric_limits<std::uint32_t>::max();

    // -0.0 and +0.0 compare equal, so they must hash and compare as the same key.
    static std::uint32_t bits(float f)
    {
        const auto b = std::bit_cast<std::uint32_t>(f);
        return b == 0x80000000u ? 0u : b;
    }

    static std::size_t hash(const std::array<std::uint32_t, 3>& key)
    {
        std::uint64_t h = key[0];
        h = h * 0x9E3779B97F4A7C15ull ^ key[1];
        h = h * 0x9E3779B97F4A7C15ull ^ key[2];
        h *= 0xD6E8FEB86659FD93ull;
        return static_cast<std::size_t>(h ^ (h >> 32));
    }

    void rehash(std::size_t capacity)
    {
        slots_.assign(capacity, kEmpty);
        mask_ = capacity - 1;
        const float* p = mesh_.positions.data();
        for (std::size_t id = 0; id < mesh_.vertex_count(); ++id) {
            const std::array<std::uint32_t, 3> key{bits(p[3 * id]), bits(p[3 * id + 1]),
                                                   bits(p[3 * id + 2])};
            std::size_t slot = hash(key) & mask_;
            while (slots_[slot] != kEmpty) slot = (slot + 1) & mask_;
            slots_[slot] = static_cast<std::uint32_t>(id);
        }
    }

    Mesh& mesh_;
    const std::string& name_;
    std::vector<std::uint32_t> slots_;
    std::size_t mask_ = 0;
};

std::uint32_t load_u32_le(const char* p)
{
    const auto* u = reinterpret_cast<const unsigned char*>(p);
    return std::uint32_t{u[0]} | std::uint32_t{u[1]} << 8 | std::uint32_t{u[2]} << 16 |
           std::uint32_t{u[3]} << 24;
}

// Keywords are lower case in the format, upper case in some exporters' files.
bool equals_ignoring_case(std::string_view a, std::string_view b)
{
    auto lower = [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; };
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
        if (lower(a[i]) != lower(b[i])) return false;
    }
    return true;
}

bool starts_with_solid(std::string_view bytes)
{
    std::size_t i = 0;
    auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
    while (i < bytes.size() && blank(bytes[i])) ++i;
    return bytes.size() - i >= 5 && equals_ignoring_case(bytes.substr(i, 5), "solid");
}

Mesh read_binary(std::string_view bytes, std::uint32_t count, const std::string& name)
{
    Mesh mesh;
    // The file size was checked against count: these allocations are bounded by the file.
    mesh.triangles.reserve(3 * static_cast<std::size_t>(count));
    Welder welder(mesh, name);
    const char* facet = bytes.data() + kHeaderBytes + 4;
    for (std::uint32_t f = 0; f < count; ++f, facet += kFacetBytes) {
        for (int corner = 0; corner < 3; ++corner) {
            float xyz[3];
            for (int k = 0; k < 3; ++k) {
                xyz[k] = std::bit_cast<float>(load_u32_le(facet + 12 * (corner + 1) + 4 * k));
            }
            mesh.triangles.push_back(welder.add(xyz));
        }
    }
    return mesh;
}

Mesh read_ascii(std::string_view bytes, const std::string& name)
{
    Mesh mesh;
    Welder welder(mesh, name);
    TextCursor in(bytes);
    std::string_view token;
    std::vector<std::uint32_t> polygon;
    auto fail = [&](Status status, const std::string& what) {
        throw Error(status, concat(name, ": line ", in.line(), ": ", what));
    };
    auto expect = [&](std::string_view word) {
        if (!in.next_token(token)) {
            fail(Status::truncated_file,
                 concat("the file ends where ", quote_text(word), " was expected"));
        }
        if (!equals_ignoring_case(token, word)) {
            fail(Status::bad_format,
                 concat("expected ", quote_text(word), ", found ", quote_text(token)));
        }
    };
    auto numbers = [&](float* xyz, std::string_view what) {
        for (int k = 0; k < 3; ++k) {
            if (!in.next_token(token)) {
                fail(Status::truncated_file, concat("the file ends inside a ", what));
            }
            if (!parse_float(token, xyz[k])) {
                fail(Status::bad_format,
                     concat(quote_text(token), " is not a number (in a ", what, ")"));
            }
        }
    };

    expect("solid");
    in.skip_line(); // the solid's name
    for (;;) {
        if (!in.next_token(token)) {
            fail(Status::truncated_file, "the file ends before \"endsolid\"");
        }
        if (equals_ignoring_case(token, "endsolid")) {
            in.skip_line();
            if (!in.next_token(token)) break; // a file may hold several solids
            if (!equals_ignoring_case(token, "solid")) {
                fail(Status::bad_format,
                     concat("expected \"solid\" or the end after \"endsolid\", found ",
                            quote_text(token)));
            }
            in.skip_line();
            continue;
        }
        if (!equals_ignoring_case(token, "facet")) {
            fail(Status::bad_format,
                 concat("expected \"facet\" or \"endsolid\", found ", quote_text(token)));
        }
        float normal[3];
        expect("normal");
        numbers(normal, "facet normal");
        expect("outer");
        expect("loop");
        polygon.clear();
        for (;;) {
            if (!in.next_token(token)) fail(Status::truncated_file, "the file ends inside a facet");
            if (equals_ignoring_case(token, "endloop")) break;
            if (!equals_ignoring_case(token, "vertex")) {
                fail(Status::bad_format,
                     concat("expected \"vertex\" or \"endloop\", found ", quote_text(token)));
            }
            float xyz[3];
            numbers(xyz, "vertex");
            polygon.push_back(welder.add(xyz));
        }
        if (polygon.size() < 3) {
            fail(Status::bad_format,
                 concat("a facet with ", polygon.size(), " vertices; expected 3"));
        }
        expect("endfacet");
        for (std::size_t i = 1; i + 1 < polygon.size(); ++i) {
            mesh.triangles.insert(mesh.triangles.end(), {polygon[0], polygon[i], polygon[i + 1]});
        }
    }
    return mesh;
}

} // namespace

Mesh read_stl(std::string_view bytes, const std::string& name)
{
    // A binary file may start with "solid" too: it is binary when its size is exactly what its
    // triangle count says. Otherwise "solid" means ASCII; anything else must be binary.
    std::uint64_t expected = 0;
    std::uint32_t count = 0;
    if (bytes.size() >= kHeaderBytes + 4) {
        count = load_u32_le(bytes.data() + kHeaderBytes);
        expected = kHeaderBytes + 4 + std::uint64_t{count} * kFacetBytes;
        if (expected == bytes.size()) return read_binary(bytes, count, name);
    }
    if (starts_with_solid(bytes)) return read_ascii(bytes, name);
    if (bytes.size() < kHeaderBytes + 4) {
        throw Error(Status::truncated_file,
                    concat(name, ": ", bytes.size(),
                           " bytes and no \"solid\" keyword: too short for a binary STL "
                           "(84-byte header and count at least)"));
    }
    if (expected > bytes.size()) {
        throw Error(Status::truncated_file,
                    concat(name, ": binary STL declares ", count, " triangles (", expected,
                           " bytes) but the file has ", bytes.size(), " bytes"));
    }
    // Longer than declared (and not ASCII): a count mismatch, like any other (docs/formats.md).
    throw Error(Status::bad_format,
                concat(name, ": binary STL declares ", count, " triangles (", expected,
                       " bytes) but the file has ", bytes.size(), " bytes: ",
                       bytes.size() - expected,
                       " more after the last triangle (wrong count, or data appended?)"));
}

void write_stl(const Mesh& mesh, std::ostream& out)
{
    OutputBuffer o(out); // write_mesh checked that the triangle count fits the 32-bit field
    // Must not start with "solid", or readers could take it for ASCII.
    std::string header = "binary STL generated by cmc33";
    header.resize(kHeaderBytes, ' ');
    o.text(header);
    o.u32_le(static_cast<std::uint32_t>(mesh.triangle_count()));
    const float* p = mesh.positions.data();
    const std::uint32_t* t = mesh.triangles.data();
    constexpr std::size_t kRecord = 50; // normal, three corners (12 floats), attribute count (uint16)
    o.records(mesh.triangle_count(), kRecord, [&](char* dst, std::size_t first, std::size_t count) {
        for (std::size_t f = first; f < first + count; ++f, dst += kRecord) {
            const float* a = p + 3 * static_cast<std::size_t>(t[3 * f]);
            const float* b = p + 3 * static_cast<std::size_t>(t[3 * f + 1]);
            const float* c = p + 3 * static_cast<std::size_t>(t[3 * f + 2]);
            // Facet normal: (b - a) x (c - a), unit length; zero for a degenerate triangle.
            double u[3], v[3];
            for (int k = 0; k < 3; ++k) {
                u[k] = static_cast<double>(b[k]) - static_cast<double>(a[k]);
                v[k] = static_cast<double>(c[k]) - static_cast<double>(a[k]);
            }
            double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
            const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            for (int k = 0; k < 3; ++k) {
                const double x = length > 0 && std::isfinite(length) ? n[k] / length : 0.0;
                store_f32_le(dst + 4 * k, static_cast<float>(x));
            }
            store_f32s_le(dst + 12, a, 3);
            store_f32s_le(dst + 24, b, 3);
            store_f32s_le(dst + 36, c, 3);
            store_le(dst + 48, std::uint16_t{0});
        }
    });
    o.flush();
}

} // namespace cmc33::io::detail
