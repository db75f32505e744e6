// Wavefront OBJ, geometry subset: `v`, `vn` and `f` (forms a, a/b, a//c, a/b/c; 1-based or
// negative = relative to the last one defined; a face may only use vertices defined before it,
// as the format intends). Polygons are fanned; every other statement (vt, o, g, s, usemtl,
// mtllib, l, p, ...) and `#` comments are ignored.
//
// OBJ indexes normals separately from positions; the Mesh has one normal per vertex. Normals are
// kept when every face corner names a normal and each vertex is always paired with the same one
// (what write_obj produces: f a//a); otherwise they are dropped rather than guessed.

#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "mesh_formats.hpp"
#include "plural.hpp"

namespace cmc33::io::detail {
namespace {

constexpr std::uint32_t kNoNormal = std::numeric_limits<std::uint32_t>::max();

struct ObjReader {
    ObjReader(std::string_view bytes, const std::string& file_name)
        : name(file_name), in(bytes, '#')
    {
    }

    const std::string& name;
    TextCursor in;
    Mesh mesh;
    Buffer<float> file_normals;           // the vn list
    std::vector<std::uint32_t> normal_of; // per vertex: vn index, or kNoNormal
    bool normals_consistent = true;
    std::vector<std::uint32_t> polygon;

    [[noreturn]] void fail(Status status, const std::string& what) const
    {
        throw Error(status, concat(name, ": line ", in.line(), ": ", what));
    }

    void read_vector(Buffer<float>& out, std::string_view keyword)
    {
        std::string_view token;
        for (int k = 0; k < 3; ++k) {
            if (!in.next_token_in_line(token)) {
                fail(Status::bad_format,
                     concat("\"", keyword, "\" has ", counted(k, "number"), "; expected 3"));
            }
            float value = 0;
            if (!parse_float(token, value)) {
                fail(Status::bad_format,
                     concat(quote_text(token), " is not a number (in \"", keyword, "\")"));
            }
            out.push_back(value);
        }
    }

    // Resolves a 1-based or negative index against `count` items defined so far.
    std::int64_t resolve(std::string_view text, std::size_t count, const char* what)
    {
        const char* plural = std::string_view(what) == "vertex" ? "vertices" : "normals";
        const std::string_view are = count == 1 ? " is" : " are";
        std::int64_t index = 0;
        if (!parse_int(text, index)) {
            fail(Status::bad_format, concat(quote_text(text), " is not a ", what, " index"));
        }
        if (index == 0) fail(Status::bad_format, concat(what, " index 0; OBJ indices start at 1"));
        if (index < 0) {
            if (static_cast<std::uint64_t>(-(index + 1)) >= count) {
                fail(Status::bad_format, concat("relative ", what, " index ", index, " but only ",
                                                counted(count, what, plural), are, " defined so far"));
            }
            return static_cast<std::int64_t>(count) + index;
        }
        return index - 1;
    }

    void read_face()
    {
        polygon.clear();
        std::string_view token;
        while (in.next_token_in_line(token)) {
            const std::size_t slash = token.find('/');
            const std::string_view vertex_text = token.substr(0, slash);
            const std::int64_t vertex = resolve(vertex_text, mesh.vertex_count(), "vertex");
            if (static_cast<std::uint64_t>(vertex) >= mesh.vertex_count()) {
                fail(Status::bad_format,
                     concat("vertex index ", vertex + 1, " but only ",
                            counted(mesh.vertex_count(), "vertex", "vertices"),
                            mesh.vertex_count() == 1 ? " is" : " are", " defined before this face"));
            }
            std::uint32_t normal = kNoNormal;
            if (slash != std::string_view::npos) {
                const std::size_t second = token.find('/', slash + 1);
                if (second != std::string_view::npos && second + 1 < token.size()) {
                    const std::int64_t n =
                        resolve(token.substr(second + 1), file_normals.size() / 3, "normal");
                    if (n >= static_cast<std::int64_t>(file_normals.size() / 3)) {
                        fail(Status::bad_format,
                             concat("normal index ", n + 1, " but only ", counted(file_normals.size() / 3, "normal"),
                                    file_normals.size() / 3 == 1 ? " is" : " are", " defined"));
                    }
                    normal = static_cast<std::uint32_t>(n);
                }
            }
            note_normal(static_cast<std::uint32_t>(vertex), normal);
            polygon.push_back(static_cast<std::uint32_t>(vertex));
        }
        if (polygon.size() < 3) {
            fail(Status::bad_format,
                 concat("a face with ", counted(polygon.size(), "vertex", "vertices"), "; expected at least 3"));
        }
        for (std::size_t i = 1; i + 1 < polygon.size(); ++i) {
            mesh.triangles.push_back(polygon[0]);
            mesh.triangles.push_back(polygon[i]);
            mesh.triangles.push_back(polygon[i + 1]);
        }
    }

    void note_normal(std::uint32_t vertex, std::uint32_t normal)
    {
        if (!normals_consistent) return;
        if (normal == kNoNormal) {
            normals_consistent = false;
            return;
        }
        if (normal_of.size() <= vertex) {
            normal_of.resize(static_cast<std::size_t>(vertex) + 1, kNoNormal);
        }
        if (normal_of[vertex] == kNoNormal) {
            normal_of[vertex] = normal;
        } else if (normal_of[vertex] != normal) {
            normals_consistent = false;
        }
    }

    void attach_normals()
    {
        if (!normals_consistent || file_normals.empty()) return;
        const std::size_t n = mesh.vertex_count();
        const std::size_t file_count = file_normals.size() / 3;
        Buffer<float> normals(3 * n); // every element is written below, or it is dropped
        for (std::size_t v = 0; v < n; ++v) {
            // A vertex no face uses keeps the normal of the same rank, if there is one.
            std::size_t source = v < normal_of.size() ? normal_of[v] : kNoNormal;
            if (source == kNoNormal) source = v;
            if (source >= file_count) return; // unknown normal: keep none
            for (int k = 0; k < 3; ++k) normals[3 * v + k] = file_normals[3 * source + k];
        }
        mesh.normals = std::move(normals);
    }

    Mesh read()
    {
        std::string_view keyword;
        while (in.next_token(keyword)) {
            if (keyword == "v") {
                read_vector(mesh.positions, keyword);
            } else if (keyword == "vn") {
                read_vector(file_normals, keyword);
            } else if (keyword == "f") {
                read_face();
            }
            in.skip_line(); // the rest: a w or colours after v, or an ignored statement
        }
        if (mesh.vertex_count() > std::numeric_limits<std::uint32_t>::max()) {
            throw Error(Status::too_large,
                        concat(name, ": ", mesh.vertex_count(),
                               " vertices; at most 4294967295 (32-bit indices)"));
        }
        attach_normals();
        return std::move(mesh);
    }
};

} // namespace

Mesh read_obj(std::string_view bytes, const std::string& name)
{
    check_text_end(bytes, '#', name);
    ObjReader reader(bytes, name);
    return reader.read();
}

void write_obj(const Mesh& mesh, std::ostream& out, const double* offset)
{
    OutputBuffer o(out);
    o.text("# generated by cmc33\n");
    const float* p = mesh.positions.data();
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        o.text("v ");
        write_position(o, &p[3 * v], offset);
        o.character('\n');
    }
    const bool normals = mesh.has_normals();
    const float* n = mesh.normals.data();
    for (std::size_t v = 0; normals && v < mesh.vertex_count(); ++v) {
        o.text("vn ");
        o.real(n[3 * v]);
        o.character(' ');
        o.real(n[3 * v + 1]);
        o.character(' ');
        o.real(n[3 * v + 2]);
        o.character('\n');
    }
    const std::uint32_t* t = mesh.triangles.data();
    for (std::size_t f = 0; f < mesh.triangle_count(); ++f) {
        o.character('f');
        for (int k = 0; k < 3; ++k) {
            const std::uint64_t index = std::uint64_t{t[3 * f + k]} + 1;
            o.character(' ');
            o.integer(index);
            if (normals) {
                o.text("//");
                o.integer(index);
            }
        }
        o.character('\n');
    }
    o.flush();
}

} // namespace cmc33::io::detail
