// The glTF, VTK XML PolyData and GIfTI writers' byte layout: GLB chunks and their 4-byte alignment,
// the JSON parsed by nlohmann-json (accessors, min/max, buffer views), the .gltf's side file, the
// .vtp's compressed blocks inflated by zlib, GIfTI's pointset moved from LPS+ to RAS+. Independent
// readers (the Khronos validator, VTK, nibabel) check the same files in tests/io/mesh_writers.py.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <zlib.h>

#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "cmc33/mesh.hpp"
#include "mesh_formats.hpp"
#include "test_support.hpp"

namespace {

using cmc33::Mesh;
namespace fs = std::filesystem;
using cmc33::test::u32_le;
using nlohmann::json;

std::uint64_t u64(const std::string& s, std::size_t at)
{
    return u32_le(s, at) | (std::uint64_t{u32_le(s, at + 4)} << 32);
}
float f32(const std::string& s, std::size_t at) { return std::bit_cast<float>(u32_le(s, at)); }

/// A tetrahedron with outward normals at its corners (one triangle less: an open mesh is fine here).
Mesh tetra(bool normals)
{
    Mesh m;
    const float p[] = {0, 0, 0, 2, 0, 0, 0, 3, 0, 0, 0, 5};
    m.positions.assign(std::begin(p), std::end(p));
    const std::uint32_t t[] = {0, 2, 1, 0, 1, 3, 0, 3, 2};
    m.triangles.assign(std::begin(t), std::end(t));
    if (normals) {
        const float n[] = {-0.57735027f, -0.57735027f, -0.57735027f, 1, 0, 0, 0, 1, 0, 0, 0, 1};
        m.normals.assign(std::begin(n), std::end(n));
    }
    return m;
}

TEST(MeshWriteFormats, GlbChunksAlignedAndJsonComplete)
{
    const fs::path dir = cmc33::test::temp_dir();
    const Mesh m = tetra(true);
    cmc33::io::MeshWriteOptions options;
    options.space = "left-posterior-superior";
    cmc33::io::write_mesh(m, dir / "t.glb", options);
    const std::string bytes = cmc33::test::read_file(dir / "t.glb");
    ASSERT_GE(bytes.size(), 20u);
    EXPECT_EQ(u32_le(bytes, 0), 0x46546C67u); // "glTF"
    EXPECT_EQ(u32_le(bytes, 4), 2u);
    EXPECT_EQ(u32_le(bytes, 8), bytes.size());
    const std::uint32_t json_length = u32_le(bytes, 12);
    EXPECT_EQ(u32_le(bytes, 16), 0x4E4F534Au); // "JSON"
    EXPECT_EQ(json_length % 4, 0u);
    const std::string text = bytes.substr(20, json_length);
    const json j = json::parse(text); // trailing spaces are JSON whitespace
    const std::size_t bin_at = 20 + json_length;
    ASSERT_EQ(bin_at % 4, 0u);
    const std::uint32_t bin_length = u32_le(bytes, bin_at);
    EXPECT_EQ(u32_le(bytes, bin_at + 4), 0x004E4942u); // "BIN\0"
    EXPECT_EQ(bin_length % 4, 0u);
    EXPECT_EQ(bin_at + 8 + bin_length, bytes.size());

    EXPECT_EQ(j["asset"]["version"], "2.0");
    EXPECT_EQ(j["asset"]["generator"].get<std::string>().rfind("cmc33 ", 0), 0u);
    EXPECT_EQ(j["extras"]["cmc33"]["space"], "left-posterior-superior");
    ASSERT_EQ(j["buffers"].size(), 1u);
    EXPECT_FALSE(j["buffers"][0].contains("uri"));
    EXPECT_EQ(j["buffers"][0]["byteLength"], 4 * (12 + 12 + 9));
    const json& prim = j["meshes"][0]["primitives"][0];
    EXPECT_EQ(prim["mode"], 4);
    const json& pos = j["accessors"][prim["attributes"]["POSITION"].get<int>()];
    EXPECT_EQ(pos["count"], 4);
    EXPECT_EQ(pos["min"], json::array({0.0, 0.0, 0.0}));
    EXPECT_EQ(pos["max"], json::array({2.0, 3.0, 5.0}));
    const json& idx = j["accessors"][prim["indices"].get<int>()];
    EXPECT_EQ(idx["componentType"], 5125);
    EXPECT_EQ(idx["count"], 9);
    ASSERT_TRUE(prim["attributes"].contains("NORMAL"));
    // Every bufferView starts on a multiple of 4 and its bytes are the mesh's, little-endian.
    const std::size_t data = bin_at + 8;
    for (const json& view : j["bufferViews"]) EXPECT_EQ(view["byteOffset"].get<std::size_t>() % 4, 0u);
    const std::size_t p_at = data + j["bufferViews"][pos["bufferView"].get<int>()]["byteOffset"].get<std::size_t>();
    for (std::size_t i = 0; i < 12; ++i) EXPECT_EQ(f32(bytes, p_at + 4 * i), m.positions[i]);
    const std::size_t t_at = data + j["bufferViews"][idx["bufferView"].get<int>()]["byteOffset"].get<std::size_t>();
    for (std::size_t i = 0; i < 9; ++i) EXPECT_EQ(u32_le(bytes, t_at + 4 * i), m.triangles[i]);
}

TEST(MeshWriteFormats, GlbPartsHaveTheirNodesMeshesAndColours)
{
    // The per-label layout: one node, mesh and material per part, in the parts' order.
    const Mesh a = tetra(false);
    Mesh b = tetra(true);
    for (float& x : b.positions) x += 10;
    const std::vector<cmc33::io::detail::GltfPart> parts{{&a, "label 1", std::array<float, 4>{1, 0, 0, 1}},
                                                         {&b, "label \"2\"", std::array<float, 4>{0, 0.5f, 1, 0.25f}}};
    std::ostringstream out;
    cmc33::io::detail::write_glb(parts, out, {}, "parts.glb");
    const std::string bytes = out.str();
    ASSERT_EQ(u32_le(bytes, 8), bytes.size());
    const json j = json::parse(bytes.substr(20, u32_le(bytes, 12)));
    ASSERT_EQ(j["nodes"].size(), 2u);
    ASSERT_EQ(j["meshes"].size(), 2u);
    ASSERT_EQ(j["materials"].size(), 2u);
    EXPECT_EQ(j["scenes"][0]["nodes"], json::array({0, 1}));
    EXPECT_EQ(j["nodes"][1]["name"], "label \"2\"");
    EXPECT_EQ(j["meshes"][1]["primitives"][0]["material"], 1);
    EXPECT_EQ(j["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"], json::array({1.0, 0.0, 0.0, 1.0}));
    EXPECT_FALSE(j["materials"][0].contains("alphaMode"));
    EXPECT_EQ(j["materials"][1]["alphaMode"], "BLEND");
    EXPECT_EQ(j["accessors"][j["meshes"][1]["primitives"][0]["attributes"]["POSITION"].get<int>()]["min"],
              json::array({10.0, 10.0, 10.0}));
    EXPECT_FALSE(j["meshes"][0]["primitives"][0]["attributes"].contains("NORMAL"));
    EXPECT_TRUE(j["meshes"][1]["primitives"][0]["attributes"].contains("NORMAL"));
    EXPECT_EQ(j["buffers"][0]["byteLength"], 4 * (12 + 9) + 4 * (12 + 12 + 9));
}

TEST(MeshWriteFormats, GltfWithBinBesideIt)
{
    const fs::path dir = cmc33::test::temp_dir();
    cmc33::io::MeshWriteOptions options;
    options.offset = cmc33::Vec3{1e6, -2.5, 0.125};
    cmc33::io::write_mesh(tetra(false), dir / "a b.gltf", options);
    const json j = json::parse(cmc33::test::read_file(dir / "a b.gltf"));
    EXPECT_EQ(j["buffers"][0]["uri"], "a%20b.bin");
    EXPECT_EQ(cmc33::test::read_file(dir / "a b.bin").size(), j["buffers"][0]["byteLength"].get<std::size_t>());
    EXPECT_EQ(j["nodes"][0]["translation"], json::array({1e6, -2.5, 0.125}));
    EXPECT_TRUE(j["extras"]["cmc33"]["space"].is_null());
    EXPECT_FALSE(j["meshes"][0]["primitives"][0]["attributes"].contains("NORMAL"));
}

TEST(MeshWriteFormats, EmptyMeshGlbHasNoBuffer)
{
    const fs::path dir = cmc33::test::temp_dir();
    cmc33::io::write_mesh(Mesh{}, dir / "e.glb");
    const std::string bytes = cmc33::test::read_file(dir / "e.glb");
    EXPECT_EQ(u32_le(bytes, 8), bytes.size());
    EXPECT_EQ(20 + u32_le(bytes, 12), bytes.size()); // no BIN chunk
    const json j = json::parse(bytes.substr(20));
    EXPECT_FALSE(j.contains("buffers"));
    EXPECT_FALSE(j.contains("meshes"));
}

/// The bytes of the vtkZLibDataCompressor array at `at` (UInt64 header) inflated.
std::string inflate_array(const std::string& appended, std::size_t at)
{
    const std::uint64_t blocks = u64(appended, at);
    const std::uint64_t block = u64(appended, at + 8);
    const std::uint64_t last = u64(appended, at + 16);
    std::string out;
    std::size_t data = at + 24 + 8 * blocks;
    for (std::uint64_t b = 0; b < blocks; ++b) {
        const std::uint64_t compressed = u64(appended, at + 24 + 8 * b);
        std::string raw(b + 1 == blocks && last != 0 ? last : block, '\0');
        uLongf size = raw.size();
        EXPECT_EQ(uncompress(reinterpret_cast<Bytef*>(raw.data()), &size,
                             reinterpret_cast<const Bytef*>(appended.data() + data), compressed),
                  Z_OK);
        EXPECT_EQ(size, raw.size());
        out += raw;
        data += compressed;
    }
    return out;
}

std::size_t offset_of(const std::string& xml, const std::string& name)
{
    const std::size_t at = xml.find("Name=\"" + name + "\"");
    EXPECT_NE(at, std::string::npos) << name;
    const std::size_t o = xml.find("offset=\"", at) + 8;
    return std::stoull(xml.substr(o, xml.find('"', o) - o));
}

TEST(MeshWriteFormats, VtpBlocksInflate)
{
    const fs::path dir = cmc33::test::temp_dir();
    // enough vertices for several 256 KiB blocks
    Mesh m;
    for (std::size_t i = 0; i < 3 * 70000; ++i) m.positions.push_back(static_cast<float>(i) * 0.5f);
    for (std::size_t i = 0; i < 3 * 50000; ++i) m.triangles.push_back(static_cast<std::uint32_t>((i * 7) % 70000));
    std::vector<float> values(70000);
    for (std::size_t i = 0; i < values.size(); ++i) values[i] = static_cast<float>(i) / 3.0f;
    std::vector<std::int32_t> labels(50000, 7);
    cmc33::io::MeshWriteOptions options;
    options.vertex_arrays.push_back({"values", std::span<const float>(values), 1});
    options.triangle_arrays.push_back({"label", std::span<const std::int32_t>(labels), 1});
    cmc33::io::write_mesh(m, dir / "m.vtp", options);
    const std::string file = cmc33::test::read_file(dir / "m.vtp");
    const std::size_t underscore = file.find("<AppendedData encoding=\"raw\">\n_");
    ASSERT_NE(underscore, std::string::npos);
    const std::string xml = file.substr(0, underscore);
    const std::string appended = file.substr(underscore + 31);
    EXPECT_NE(xml.find("header_type=\"UInt64\""), std::string::npos);
    EXPECT_NE(xml.find("NumberOfPoints=\"70000\""), std::string::npos);
    EXPECT_NE(xml.find("NumberOfPolys=\"50000\""), std::string::npos);

    const std::string points = inflate_array(appended, offset_of(xml, "Points"));
    ASSERT_EQ(points.size(), 4 * m.positions.size());
    EXPECT_EQ(std::memcmp(points.data(), m.positions.data(), points.size()), 0);
    const std::string connectivity = inflate_array(appended, offset_of(xml, "connectivity"));
    ASSERT_EQ(connectivity.size(), 4 * m.triangles.size());
    EXPECT_EQ(std::memcmp(connectivity.data(), m.triangles.data(), connectivity.size()), 0);
    const std::string offsets = inflate_array(appended, offset_of(xml, "offsets"));
    ASSERT_EQ(offsets.size(), 4u * 50000);
    EXPECT_EQ(u32_le(offsets, 0), 3u);
    EXPECT_EQ(u32_le(offsets, offsets.size() - 4), 150000u);
    const std::string v = inflate_array(appended, offset_of(xml, "values"));
    ASSERT_EQ(v.size(), 4 * values.size());
    EXPECT_EQ(std::memcmp(v.data(), values.data(), v.size()), 0);
    EXPECT_EQ(inflate_array(appended, offset_of(xml, "label")).size(), 4u * 50000);
}

TEST(MeshWriteFormats, ArraysOfTheWrongSizeAreRefused)
{
    const fs::path dir = cmc33::test::temp_dir();
    std::vector<float> values(3);
    cmc33::io::MeshWriteOptions options;
    options.vertex_arrays.push_back({"values", std::span<const float>(values), 1});
    try {
        cmc33::io::write_mesh(tetra(false), dir / "m.vtp", options);
        FAIL() << "no error";
    } catch (const cmc33::Error& e) {
        EXPECT_EQ(e.status(), cmc33::Status::invalid_argument);
        EXPECT_NE(std::string(e.what()).find("\"values\": 3 values of 1 components; expected a name and 1 values per "
                                             "vertex (4 vertices)"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_FALSE(fs::exists(dir / "m.vtp"));
}

TEST(MeshWriteFormats, GiftiNamesItsSpace)
{
    const fs::path dir = cmc33::test::temp_dir();
    cmc33::io::MeshWriteOptions options;
    options.space = "left-posterior-superior";
    cmc33::io::write_mesh(tetra(true), dir / "lps.gii", options);
    const std::string lps = cmc33::test::read_file(dir / "lps.gii");
    EXPECT_NE(lps.find("<DataSpace>NIFTI_XFORM_SCANNER_ANAT</DataSpace>"), std::string::npos);
    EXPECT_NE(lps.find("RAS+: x and y negated from the source space"), std::string::npos);
    EXPECT_NE(lps.find("NumberOfDataArrays=\"3\""), std::string::npos);
    options.space = "left-anterior-superior"; // a mirror: winding reversed too
    cmc33::io::write_mesh(tetra(false), dir / "las.gii", options);
    EXPECT_NE(cmc33::test::read_file(dir / "las.gii").find("x negated from the source space, the winding of each triangle reversed"),
              std::string::npos);
    options.space = "scanner-xyz";
    cmc33::io::write_mesh(tetra(false), dir / "xyz.gii", options);
    EXPECT_NE(cmc33::test::read_file(dir / "xyz.gii").find("<DataSpace>NIFTI_XFORM_UNKNOWN</DataSpace>"),
              std::string::npos);
}

} // namespace
