// glTF 2.0 (Khronos, "glTF 2.0 Specification"): binary .glb and .gltf with its buffer in a .bin
// beside it. One buffer holds every part's positions (FLOAT VEC3), normals (FLOAT VEC3, when the
// mesh has them) and triangle indices (UNSIGNED_INT SCALAR), each in its own bufferView.
//
// glTF's own frame is y-up and its unit the metre (spec 3.4 "Coordinate System and Units"). cmc33
// writes the positions as they are, in the volume's world space and length unit, and says so in
// the root's `extras` (docs/formats.md): moving a medical volume's frame into a viewer's is a
// choice this writer does not make silently.

#include <algorithm>
#include <array>
#include <charconv>
#include <cstdint>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

#include "cmc33/version.hpp"
#include "mesh_formats.hpp"

namespace cmc33::io::detail {
namespace {

// Spec 3.6.2.2 accessor componentType and 3.6.1 bufferView target values.
constexpr int kFloat = 5126;
constexpr int kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962;
constexpr int kElementArrayBuffer = 34963;
// Spec 4.4.3.x (GLB): header magic "glTF", version 2, chunk types "JSON" and "BIN\0".
constexpr std::uint32_t kGlbMagic = 0x46546C67u;
constexpr std::uint32_t kGlbVersion = 2;
constexpr std::uint32_t kChunkJson = 0x4E4F534Au;
constexpr std::uint32_t kChunkBin = 0x004E4942u;

struct View {
    std::uint64_t offset = 0;
    std::uint64_t length = 0;
    int target = 0;
};

/// Where each part's arrays lie in the one buffer. Every array is a whole number of 4-byte
/// values, so every offset is a multiple of 4, as accessors of 4-byte components require
/// (spec 3.6.2.4 "Data Alignment").
struct Layout {
    struct Part {
        int positions = -1, normals = -1, indices = -1; ///< bufferView (== accessor) indices, -1: none
    };
    std::vector<Part> parts;
    std::vector<View> views;
    std::uint64_t bytes = 0;
};

Layout layout(const std::vector<GltfPart>& parts)
{
    Layout l;
    auto add = [&](std::uint64_t length, int target) {
        l.views.push_back({l.bytes, length, target});
        l.bytes += length;
        return static_cast<int>(l.views.size() - 1);
    };
    for (const GltfPart& part : parts) {
        Layout::Part p;
        const Mesh& m = *part.mesh;
        if (m.vertex_count() > 0) { // an accessor's count is at least 1 (spec, accessor.count)
            p.positions = add(12 * std::uint64_t{m.vertex_count()}, kArrayBuffer);
            if (m.has_normals()) p.normals = add(12 * std::uint64_t{m.vertex_count()}, kArrayBuffer);
            if (m.triangle_count() > 0) p.indices = add(12 * std::uint64_t{m.triangle_count()}, kElementArrayBuffer);
        }
        l.parts.push_back(p);
    }
    return l;
}

/// A URI reference to a file beside the .gltf (RFC 3986: unreserved characters as they are,
/// every other byte percent-encoded; spec 3.9.2 "URIs").
std::string uri_of(const std::string& file_name)
{
    static constexpr char kHex[] = "0123456789ABCDEF";
    std::string out;
    for (char c : file_name) {
        const auto u = static_cast<unsigned char>(c);
        if ((u >= 'A' && u <= 'Z') || (u >= 'a' && u <= 'z') || (u >= '0' && u <= '9') || c == '-' || c == '.' ||
            c == '_' || c == '~') {
            out += c;
        } else {
            out += '%';
            out += kHex[u >> 4];
            out += kHex[u & 15];
        }
    }
    return out;
}

class Json {
public:
    Json& raw(std::string_view s)
    {
        text_ += s;
        return *this;
    }
    Json& num(std::uint64_t v)
    {
        text_ += std::to_string(v);
        return *this;
    }
    Json& real(double v)
    {
        char buffer[40];
        text_.append(buffer, std::to_chars(buffer, buffer + sizeof buffer, v).ptr);
        return *this;
    }
    Json& real(float v)
    {
        char buffer[32];
        text_.append(buffer, std::to_chars(buffer, buffer + sizeof buffer, v).ptr);
        return *this;
    }
    std::string& text() { return text_; }

private:
    std::string text_;
};

/// The glTF JSON of `parts`; `bin_uri` empty for a GLB (its buffer is the BIN chunk).
std::string gltf_json(const std::vector<GltfPart>& parts, const Layout& l, const MeshWriteOptions& options,
                      const std::string& bin_uri)
{
    Json j;
    j.raw("{\"asset\":{\"version\":\"2.0\",\"generator\":\"cmc33 " CMC33_VERSION_STRING "\"}");
    // The frame, said where every glTF reader keeps it (spec 3.2 "extras": application-specific data).
    j.raw(",\"extras\":{\"cmc33\":{\"space\":").raw(options.space.empty() ? "null" : json_string(options.space));
    j.raw(",\"units\":\"the source volume's spacing unit (usually mm)\"");
    j.raw(",\"frame\":\"positions are the source volume's world coordinates as they are: not moved into glTF's y-up "
          "metres\"}}");

    std::vector<std::size_t> meshes; // parts that have a mesh
    for (std::size_t i = 0; i < parts.size(); ++i) {
        if (l.parts[i].positions >= 0) meshes.push_back(i);
    }
    j.raw(",\"scene\":0,\"scenes\":[{");
    if (!meshes.empty()) {
        j.raw("\"nodes\":[");
        for (std::size_t k = 0; k < meshes.size(); ++k) j.raw(k ? "," : "").num(k);
        j.raw("]");
    }
    j.raw("}]");
    if (meshes.empty()) {
        j.raw("}");
        return std::move(j.text());
    }

    j.raw(",\"nodes\":[");
    for (std::size_t k = 0; k < meshes.size(); ++k) {
        const GltfPart& part = parts[meshes[k]];
        j.raw(k ? "," : "").raw("{\"mesh\":").num(k);
        if (!part.name.empty()) j.raw(",\"name\":").raw(json_string(part.name));
        if (options.offset) { // double-precision world position of the mesh's local origin
            j.raw(",\"translation\":[");
            for (std::size_t c = 0; c < 3; ++c) j.raw(c ? "," : "").real((*options.offset)[c]);
            j.raw("]");
        }
        j.raw("}");
    }
    j.raw("]");

    std::size_t materials = 0;
    j.raw(",\"meshes\":[");
    for (std::size_t k = 0; k < meshes.size(); ++k) {
        const GltfPart& part = parts[meshes[k]];
        const Layout::Part& p = l.parts[meshes[k]];
        j.raw(k ? "," : "").raw("{\"primitives\":[{\"attributes\":{\"POSITION\":").num(static_cast<std::uint64_t>(p.positions));
        if (p.normals >= 0) j.raw(",\"NORMAL\":").num(static_cast<std::uint64_t>(p.normals));
        j.raw("}");
        // Without indices the vertices alone are drawn as points (mode 0), never as triangles.
        if (p.indices >= 0) {
            j.raw(",\"indices\":").num(static_cast<std::uint64_t>(p.indices)).raw(",\"mode\":4");
        } else {
            j.raw(",\"mode\":0");
        }
        if (part.colour) j.raw(",\"material\":").num(materials++);
        j.raw("}]");
        if (!part.name.empty()) j.raw(",\"name\":").raw(json_string(part.name));
        j.raw("}");
    }
    j.raw("]");

    if (materials > 0) {
        j.raw(",\"materials\":[");
        bool first = true;
        for (std::size_t i : meshes) {
            if (!parts[i].colour) continue;
            const auto& c = *parts[i].colour;
            j.raw(first ? "" : ",").raw("{\"pbrMetallicRoughness\":{\"baseColorFactor\":[");
            for (std::size_t k = 0; k < 4; ++k) j.raw(k ? "," : "").real(c[k]);
            j.raw("]}");
            if (c[3] < 1.0f) j.raw(",\"alphaMode\":\"BLEND\""); // else alpha is ignored (OPAQUE)
            if (!parts[i].name.empty()) j.raw(",\"name\":").raw(json_string(parts[i].name));
            j.raw("}");
            first = false;
        }
        j.raw("]");
    }

    // One accessor per bufferView, in the same order.
    j.raw(",\"accessors\":[");
    bool first = true;
    for (std::size_t i : meshes) {
        const Mesh& m = *parts[i].mesh;
        const Layout::Part& p = l.parts[i];
        // POSITION accessors must give min and max (spec 3.7.2.1 "Meshes: Overview").
        std::array<float, 3> lo{std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity(),
                                std::numeric_limits<float>::infinity()};
        std::array<float, 3> hi{-lo[0], -lo[1], -lo[2]};
        const float* xyz = m.positions.data();
        for (std::size_t v = 0; v < m.vertex_count(); ++v) {
            for (std::size_t c = 0; c < 3; ++c) {
                lo[c] = std::min(lo[c], xyz[3 * v + c]);
                hi[c] = std::max(hi[c], xyz[3 * v + c]);
            }
        }
        j.raw(first ? "" : ",").raw("{\"bufferView\":").num(static_cast<std::uint64_t>(p.positions));
        j.raw(",\"componentType\":").num(kFloat).raw(",\"count\":").num(m.vertex_count()).raw(",\"type\":\"VEC3\"");
        j.raw(",\"min\":[").real(lo[0]).raw(",").real(lo[1]).raw(",").real(lo[2]).raw("]");
        j.raw(",\"max\":[").real(hi[0]).raw(",").real(hi[1]).raw(",").real(hi[2]).raw("]}");
        first = false;
        if (p.normals >= 0) {
            j.raw(",{\"bufferView\":").num(static_cast<std::uint64_t>(p.normals));
            j.raw(",\"componentType\":").num(kFloat).raw(",\"count\":").num(m.vertex_count()).raw(",\"type\":\"VEC3\"}");
        }
        if (p.indices >= 0) {
            j.raw(",{\"bufferView\":").num(static_cast<std::uint64_t>(p.indices));
            j.raw(",\"componentType\":").num(kUnsignedInt).raw(",\"count\":").num(m.triangles.size());
            j.raw(",\"type\":\"SCALAR\"}");
        }
    }
    j.raw("]");

    j.raw(",\"bufferViews\":[");
    for (std::size_t v = 0; v < l.views.size(); ++v) {
        j.raw(v ? "," : "").raw("{\"buffer\":0,\"byteOffset\":").num(l.views[v].offset);
        j.raw(",\"byteLength\":").num(l.views[v].length).raw(",\"target\":").num(static_cast<std::uint64_t>(l.views[v].target)).raw("}");
    }
    j.raw("]");
    j.raw(",\"buffers\":[{\"byteLength\":").num(l.bytes);
    if (!bin_uri.empty()) j.raw(",\"uri\":\"").raw(uri_of(bin_uri)).raw("\"");
    j.raw("}]}");
    return std::move(j.text());
}

void write_buffer(const std::vector<GltfPart>& parts, const Layout& l, OutputBuffer& o)
{
    for (std::size_t i = 0; i < parts.size(); ++i) {
        const Mesh& m = *parts[i].mesh;
        const Layout::Part& p = l.parts[i];
        if (p.positions < 0) continue;
        auto floats = [&](const float* values) {
            o.records(m.vertex_count(), 12, [&](char* dst, std::size_t first, std::size_t n) {
                store_f32s_le(dst, values + 3 * first, 3 * n);
            });
        };
        floats(m.positions.data());
        if (p.normals >= 0) floats(m.normals.data());
        if (p.indices >= 0) {
            o.records(m.triangle_count(), 12, [&](char* dst, std::size_t first, std::size_t n) {
                store_u32s_le(dst, m.triangles.data() + 3 * first, 3 * n);
            });
        }
    }
}

} // namespace

void write_glb(const std::vector<GltfPart>& parts, std::ostream& out, const MeshWriteOptions& options,
               const std::string& name)
{
    const Layout l = layout(parts);
    std::string json = gltf_json(parts, l, options, "");
    // Chunks start and end on 4-byte boundaries: the JSON chunk is padded with spaces (0x20), the
    // BIN chunk with zeros (spec 4.4.3.3 "Structured JSON Content", 4.4.3.4 "Binary buffer").
    json.resize((json.size() + 3) / 4 * 4, ' ');
    const std::uint64_t bin = (l.bytes + 3) / 4 * 4; // l.bytes is already a multiple of 4
    const std::uint64_t total = 12 + 8 + json.size() + (l.bytes > 0 ? 8 + bin : 0);
    if (total > std::numeric_limits<std::uint32_t>::max()) {
        throw Error(Status::too_large, concat(name, ": a GLB file holds at most 4294967295 bytes (its header's length "
                                                    "is 32 bits), this mesh needs ",
                                              total, "; write .gltf (its buffer goes to a .bin beside it)"));
    }
    OutputBuffer o(out);
    o.u32_le(kGlbMagic);
    o.u32_le(kGlbVersion);
    o.u32_le(static_cast<std::uint32_t>(total));
    o.u32_le(static_cast<std::uint32_t>(json.size()));
    o.u32_le(kChunkJson);
    o.text(json);
    if (l.bytes > 0) { // no BIN chunk without a buffer (spec 4.4.3.4: it is optional)
        o.u32_le(static_cast<std::uint32_t>(bin));
        o.u32_le(kChunkBin);
        write_buffer(parts, l, o);
        for (std::uint64_t k = l.bytes; k < bin; ++k) o.u8(0);
    }
    o.flush();
}

void write_gltf_json(const std::vector<GltfPart>& parts, std::ostream& out, const MeshWriteOptions& options,
                     const std::string& bin_uri)
{
    const Layout l = layout(parts);
    // Without vertices there is no buffer at all (buffer.byteLength is at least 1).
    std::string json = gltf_json(parts, l, options, bin_uri);
    json += '\n';
    out.write(json.data(), static_cast<std::streamsize>(json.size()));
}

void write_gltf_bin(const std::vector<GltfPart>& parts, std::ostream& out)
{
    const Layout l = layout(parts);
    OutputBuffer o(out);
    write_buffer(parts, l, o);
    o.flush();
}

} // namespace cmc33::io::detail
