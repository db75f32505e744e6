// OFF (Geomview Object File Format), ASCII: a keyword line [ST][C][N]OFF, a counts line
// "V F E" (it may follow the keyword on the same line), V vertex lines "x y z [nx ny nz] [...]",
// F face lines "n i0 ... i(n-1) [colour]". `#` starts a comment. Each vertex and face is read
// from its own line, so trailing colours or texture coordinates are ignored whatever their
// count. Polygons are fanned. Binary OFF and the 4D / nD variants are not supported.

#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "mesh_formats.hpp"
#include "plural.hpp"

namespace cmc33::io::detail {

Mesh read_off(std::string_view bytes, const std::string& name)
{
    check_text_end(bytes, '#', name);
    TextCursor in(bytes, '#');
    std::string_view token;
    auto fail = [&](Status status, const std::string& what) {
        throw Error(status, concat(name, ": line ", in.line(), ": ", what));
    };

    // Keyword: [ST][C][N][4][n]OFF.
    if (!in.next_token(token)) {
        fail(Status::bad_format, "no \"OFF\" keyword; the file holds only comments");
    }
    std::string_view prefix = token;
    const bool has_off = prefix.size() >= 3 && prefix.substr(prefix.size() - 3) == "OFF";
    if (has_off) prefix.remove_suffix(3);
    bool normals = false, higher_dimension = false;
    if (prefix.starts_with("ST")) prefix.remove_prefix(2);
    if (prefix.starts_with("C")) prefix.remove_prefix(1);
    if (prefix.starts_with("N")) {
        normals = true;
        prefix.remove_prefix(1);
    }
    if (prefix.starts_with("4")) {
        higher_dimension = true;
        prefix.remove_prefix(1);
    }
    if (prefix.starts_with("n")) {
        higher_dimension = true;
        prefix.remove_prefix(1);
    }
    if (!has_off || !prefix.empty()) {
        fail(Status::bad_format, concat("does not start with \"OFF\" (found ",
                                        quote_text(token, 16), "); not an OFF file"));
    }
    if (higher_dimension) {
        fail(Status::unsupported_format, concat(quote_text(token), ": only 3D OFF is supported"));
    }

    // Counts, on the keyword's line or the next non-comment line.
    std::string_view first;
    if (in.next_token_in_line(first)) {
        if (first == "BINARY") {
            fail(Status::unsupported_format, "binary OFF is not supported; expected ASCII");
        }
    } else if (!in.next_token(first)) {
        fail(Status::truncated_file, "the file ends before the counts line \"V F E\"");
    }
    std::int64_t vertex_count = 0, face_count = 0;
    std::string_view second;
    if (!parse_int(first, vertex_count) || vertex_count < 0 || !in.next_token_in_line(second) ||
        !parse_int(second, face_count) || face_count < 0) {
        fail(Status::bad_format, concat("expected the counts \"V F E\" (integers >= 0), found ",
                                        quote_text(first), " ", quote_text(second)));
    }
    in.skip_line();

    // Every vertex line holds at least "0 0 0\n", every face line its count "0\n": a face of 0 or 2
    // vertices is then reported on its own line, not as a file too short for the counts.
    const std::uint64_t remaining = in.remaining() + 1;
    const std::uint64_t vertex_min = normals ? 12 : 6;
    const auto v = static_cast<std::uint64_t>(vertex_count),
               f = static_cast<std::uint64_t>(face_count);
    if (v > remaining / vertex_min || f > remaining / 2 || v * vertex_min + f * 2 > remaining) {
        fail(Status::truncated_file,
             concat("the counts declare ", counted(v, "vertex", "vertices"), " and ", counted(f, "face"),
                    " (at least ", counted(v * vertex_min + f * 2, "byte"), ") but only ",
                    counted(in.remaining(), "byte"), " follow"));
    }
    if (v > std::numeric_limits<std::uint32_t>::max()) {
        fail(Status::too_large, concat(v, " vertices; at most 4294967295 (32-bit indices)"));
    }

    Mesh mesh;
    mesh.positions.resize(3 * v);
    if (normals) mesh.normals.resize(3 * v);
    mesh.triangles.reserve(3 * std::min(f, remaining / 8)); // room for at most that many "3 i j k\n"
    for (std::uint64_t i = 0; i < v; ++i) {
        if (!in.next_token(token)) {
            fail(Status::truncated_file, concat("the file ends after ", i, " of ", counted(v, "vertex", "vertices")));
        }
        for (int k = 0; k < (normals ? 6 : 3); ++k) {
            if (k > 0 && !in.next_token_in_line(token)) {
                fail(Status::bad_format,
                     concat("vertex ", i, " has ", counted(k, "number"), "; expected ", normals ? 6 : 3));
            }
            float value = 0;
            if (!parse_float(token, value)) {
                fail(Status::bad_format,
                     concat(quote_text(token), " is not a number (vertex ", i, ")"));
            }
            (k < 3 ? mesh.positions[3 * i + k] : mesh.normals[3 * i + k - 3]) = value;
        }
        in.skip_line();
    }
    std::vector<std::uint32_t> polygon;
    for (std::uint64_t i = 0; i < f; ++i) {
        if (!in.next_token(token)) {
            fail(Status::truncated_file, concat("the file ends after ", i, " of ", counted(f, "face")));
        }
        std::int64_t n = 0;
        if (!parse_int(token, n)) {
            fail(Status::bad_format,
                 concat(quote_text(token), " is not a vertex count (face ", i, ")"));
        }
        if (n < 3) {
            fail(Status::bad_format,
                 concat("face ", i, " has ", counted(n, "vertex", "vertices"), "; expected at least 3"));
        }
        polygon.clear();
        for (std::int64_t k = 0; k < n; ++k) {
            std::int64_t index = 0;
            if (!in.next_token_in_line(token)) {
                fail(Status::bad_format,
                     concat("face ", i, " lists ", k, " of its ", n, " vertex indices"));
            }
            if (!parse_int(token, index)) {
                fail(Status::bad_format,
                     concat(quote_text(token), " is not a vertex index (face ", i, ")"));
            }
            if (index < 0 || static_cast<std::uint64_t>(index) >= v) {
                fail(Status::bad_format, concat("face ", i, " uses vertex index ", index,
                                                " but the file has ", counted(v, "vertex", "vertices")));
            }
            polygon.push_back(static_cast<std::uint32_t>(index));
        }
        for (std::size_t k = 1; k + 1 < polygon.size(); ++k) {
            mesh.triangles.insert(mesh.triangles.end(), {polygon[0], polygon[k], polygon[k + 1]});
        }
        in.skip_line(); // a colour may follow
    }
    if (in.next_token(token)) {
        fail(Status::bad_format,
             concat(quote_text(token), " follows the last of the ", counted(f, "face"),
                    " the counts declare; more data than declared (wrong counts?)"));
    }
    return mesh;
}

void write_off(const Mesh& mesh, std::ostream& out, const double* offset)
{
    OutputBuffer o(out);
    o.text("OFF\n");
    o.integer(mesh.vertex_count());
    o.character(' ');
    o.integer(mesh.triangle_count());
    o.text(" 0\n");
    const float* p = mesh.positions.data();
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        write_position(o, &p[3 * v], offset);
        o.character('\n');
    }
    const std::uint32_t* t = mesh.triangles.data();
    for (std::size_t f = 0; f < mesh.triangle_count(); ++f) {
        o.text("3 ");
        o.integer(t[3 * f]);
        o.character(' ');
        o.integer(t[3 * f + 1]);
        o.character(' ');
        o.integer(t[3 * f + 2]);
        o.character('\n');
    }
    o.flush();
}

} // namespace cmc33::io::detail
