// The mesh readers on hand-made files: every variant each format allows, and bad input.

#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "atomic_file.hpp"
#include "mesh_formats.hpp"
#include "test_support.hpp"

namespace {

using cmc33::Error;
using cmc33::Mesh;
using cmc33::Status;
namespace detail = cmc33::io::detail;

using Indices = cmc33::Buffer<std::uint32_t>;
using Floats = cmc33::Buffer<float>;

// Reads `bytes` from a heap buffer of exactly that size (ASan then sees any over-read).
Mesh read_bytes(const std::string& bytes, const std::string& name)
{
    const std::vector<char> exact(bytes.begin(), bytes.end());
    const std::string ext = detail::lower_extension(name);
    const cmc33::io::MeshFormat format = ext == ".ply"   ? cmc33::io::MeshFormat::ply
                                         : ext == ".obj" ? cmc33::io::MeshFormat::obj
                                         : ext == ".stl" ? cmc33::io::MeshFormat::stl
                                                         : cmc33::io::MeshFormat::off;
    return cmc33::io::read_mesh_from_memory(std::string_view(exact.data(), exact.size()), format,
                                            name);
}

void expect_error(const std::string& bytes, const std::string& name, Status status,
                  const std::string& fragment)
{
    try {
        read_bytes(bytes, name);
        ADD_FAILURE() << "no exception; expected one containing: " << fragment;
    } catch (const Error& e) {
        EXPECT_EQ(static_cast<int>(e.status()), static_cast<int>(status)) << e.what();
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(name), std::string::npos)
            << "names the file: " << e.what();
        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "one line: " << e.what();
    }
}

// ---- binary builders ------------------------------------------------------------------------

template <class T> void put(std::string& out, T value, bool big_endian)
{
    unsigned char b[sizeof(T)];
    std::memcpy(b, &value, sizeof(T));
    if (big_endian == (std::endian::native == std::endian::little)) {
        for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
    }
    out.append(reinterpret_cast<const char*>(b), sizeof(T));
}

// ---- PLY ------------------------------------------------------------------------------------

TEST(PlyReader, AsciiWithExtraPropertiesElementsAndQuads)
{
    const std::string ply = "ply\r\n"
                            "format ascii 1.0\r\n"
                            "comment made by hand\r\n"
                            "obj_info anything\r\n"
                            "element vertex 5\r\n"
                            "property uchar red\r\n"
                            "property float32 x\r\n"
                            "property list uchar int neighbours\r\n"
                            "property double y\r\n"
                            "property int z\r\n"
                            "element edge 2\r\n"
                            "property int vertex1\r\n"
                            "property int vertex2\r\n"
                            "element face 2\r\n"
                            "property list uint8 uint32 vertex_index\r\n"
                            "property float quality\r\n"
                            "element material 1\r\n"
                            "property list uchar float params\r\n"
                            "end_header\r\n"
                            "255 0.5 2 7 8 1.25 -3\r\n"
                            "0 1 0 2 3\r\n"
                            "1 +1 1 9 0 4\r\n"
                            "2 -0 3 1 2 3 1e3 5\r\n"
                            "3 2.5 0 1e-45 6\r\n"
                            "0 1\r\n"
                            "1 2\r\n"
                            "4 0 1 2 3 0.5\r\n"
                            "3 4 3 2 0.25\r\n"
                            "2 1.5 2.5\r\n";
    const Mesh mesh = read_bytes(ply, "a.ply");
    EXPECT_EQ(mesh.positions,
              (Floats{0.5f, 1.25f, -3, 1, 2, 3, 1, 0, 4, -0.0f, 1000, 5, 2.5f, 1e-45f, 6}));
    EXPECT_EQ(mesh.triangles, (Indices{0, 1, 2, 0, 2, 3, 4, 3, 2}));
    EXPECT_FALSE(mesh.has_normals());
}

TEST(PlyReader, BinaryBigEndianDoublesAndIntIndices)
{
    std::string ply =
        "ply\nformat binary_big_endian 1.0\n"
        "element vertex 3\nproperty double x\nproperty double y\nproperty double z\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        "element face 1\nproperty uchar flags\nproperty list ushort int vertex_indices\n"
        "property list uchar float texcoord\n"
        "element material 2\nproperty list int short ids\nproperty float shininess\n"
        "end_header\n";
    const double p[3][3] = {{0.1, 0.2, 0.3}, {1e10, -2, 3}, {4, 5, 6}};
    for (const auto& v : p) {
        for (double c : v) put(ply, c, true);
        put(ply, 0.0f, true);
        put(ply, 0.0f, true);
        put(ply, 1.0f, true);
    }
    ply += '\x07';                    // flags
    put<std::uint16_t>(ply, 3, true); // count
    for (std::int32_t i : {2, 0, 1}) put(ply, i, true);
    ply += '\x02';
    put(ply, 0.5f, true);
    put(ply, 0.75f, true);
    for (int m = 0; m < 2; ++m) {
        put<std::int32_t>(ply, 2, true);
        put<std::int16_t>(ply, 1, true);
        put<std::int16_t>(ply, 2, true);
        put(ply, 8.0f, true);
    }
    const Mesh mesh = read_bytes(ply, "be.ply");
    EXPECT_EQ(mesh.positions, (Floats{0.1f, 0.2f, 0.3f, 1e10f, -2, 3, 4, 5, 6}));
    EXPECT_EQ(mesh.normals, (Floats{0, 0, 1, 0, 0, 1, 0, 0, 1}));
    EXPECT_EQ(mesh.triangles, (Indices{2, 0, 1}));

    // Trailing material bytes cut off: the skipped element is still checked.
    expect_error(ply.substr(0, ply.size() - 1), "be.ply", Status::truncated_file,
                 "\"material\" record 1");
}

TEST(PlyReader, BinaryLittleEndianIntegerCoordinatesAndNormalsOutOfOrder)
{
    std::string ply =
        "ply\nformat binary_little_endian 1.0\n"
        "element vertex 4\nproperty char x\nproperty float nz\nproperty ushort y\n"
        "property float nx\nproperty int16 z\nproperty float ny\nproperty uint8 alpha\n"
        "element face 1\nproperty list uint16 uint16 vertex_indices\n"
        "end_header\n";
    const int coords[4][3] = {{-1, 2, -3}, {127, 65535, 32767}, {-128, 0, -32768}, {0, 1, 2}};
    for (const auto& c : coords) {
        put<std::int8_t>(ply, static_cast<std::int8_t>(c[0]), false);
        put(ply, 0.25f, false);
        put<std::uint16_t>(ply, static_cast<std::uint16_t>(c[1]), false);
        put(ply, 0.5f, false);
        put<std::int16_t>(ply, static_cast<std::int16_t>(c[2]), false);
        put(ply, -0.75f, false);
        ply += '\xff';
    }
    put<std::uint16_t>(ply, 4, false);
    for (std::uint16_t i : {0, 1, 2, 3}) put(ply, i, false);
    const Mesh mesh = read_bytes(ply, "le.ply");
    EXPECT_EQ(mesh.positions, (Floats{-1, 2, -3, 127, 65535, 32767, -128, 0, -32768, 0, 1, 2}));
    ASSERT_EQ(mesh.normals.size(), 12u);
    EXPECT_EQ((Floats(mesh.normals.begin(), mesh.normals.begin() + 3)),
              (Floats{0.5f, -0.75f, 0.25f}));
    EXPECT_EQ(mesh.triangles, (Indices{0, 1, 2, 0, 2, 3}));
}

TEST(PlyReader, PartialNormalsAreIgnored)
{
    const std::string ply =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nproperty float nx\nelement face 1\n"
        "property list uchar int vertex_indices\nend_header\n"
        "0 0 0 1\n1 0 0 1\n0 1 0 1\n3 0 1 2\n";
    const Mesh mesh = read_bytes(ply, "n.ply");
    EXPECT_FALSE(mesh.has_normals());
    EXPECT_EQ(mesh.triangles, (Indices{0, 1, 2}));
}

TEST(PlyReader, VerticesOnlyAndNaN)
{
    std::string ply = "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\n"
                      "property float y\nproperty float z\nend_header\n";
    for (float f : {std::numeric_limits<float>::quiet_NaN(), 1.0f, 2.0f, 3.0f, 4.0f,
                    std::numeric_limits<float>::infinity()}) {
        put(ply, f, false);
    }
    const Mesh mesh = read_bytes(ply, "p.ply");
    ASSERT_EQ(mesh.vertex_count(), 2u);
    EXPECT_TRUE(std::isnan(mesh.positions[0]));
    EXPECT_TRUE(std::isinf(mesh.positions[5]));
    EXPECT_EQ(mesh.triangle_count(), 0u);

    const Mesh text =
        read_bytes("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                   "property float z\nend_header\nnan -inf 1\n",
                   "t.ply");
    EXPECT_TRUE(std::isnan(text.positions[0]));
    EXPECT_EQ(text.positions[1], -std::numeric_limits<float>::infinity());
}

TEST(PlyReader, DoublesBeyondFloatRangeBecomeInfinite)
{
    const Mesh mesh =
        read_bytes("ply\nformat ascii 1.0\nelement vertex 1\nproperty double x\nproperty double y\n"
                   "property double z\nend_header\n1e300 -1e300 3.4028235e38\n",
                   "d.ply");
    EXPECT_EQ(mesh.positions[0], std::numeric_limits<float>::infinity());
    EXPECT_EQ(mesh.positions[1], -std::numeric_limits<float>::infinity());
    EXPECT_EQ(mesh.positions[2], std::numeric_limits<float>::max());
}

const std::string kAsciiHeader =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face 2\nproperty list uchar int vertex_indices\n"
    "end_header\n";

TEST(PlyReader, Errors)
{
    expect_error("plx\nformat ascii 1.0\n", "m.ply", Status::bad_format,
                 "does not start with \"ply\" (found \"plx\")");
    expect_error("\x89PNG\r\n", "m.ply", Status::bad_format, "not a PLY file");
    expect_error("ply\nformat binary_middle_endian 1.0\nend_header\n", "m.ply",
                 Status::unsupported_format, "\"binary_middle_endian\"");
    expect_error("ply\nformat ascii 2.0\nend_header\n", "m.ply", Status::unsupported_format,
                 "version \"2.0\"");
    expect_error("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n", "m.ply",
                 Status::truncated_file, "without an end_header line");
    expect_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n",
                 "m.ply", Status::bad_format,
                 "header line 4 \"property float128 x\": unknown type name");
    expect_error("ply\nformat ascii 1.0\nelement vertex -1\nend_header\n", "m.ply",
                 Status::bad_format, "count >= 0");
    expect_error("ply\nformat ascii 1.0\nproperty float x\nend_header\n", "m.ply",
                 Status::bad_format, "a property before any element");
    expect_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float "
                 "y\nend_header\n1 2\n",
                 "m.ply", Status::bad_format, "no scalar property \"z\"");
    expect_error("ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int "
                 "vertex_indices\nend_header\n",
                 "m.ply", Status::bad_format, "no \"vertex\" element");
    expect_error("ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float "
                 "y\nproperty float z\n"
                 "element face 0\nproperty list uchar float vertex_indices\nend_header\n",
                 "m.ply", Status::bad_format, "floating-point item type");
    expect_error("ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float "
                 "y\nproperty float z\n"
                 "element face 0\nproperty int material\nend_header\n",
                 "m.ply", Status::bad_format, "no list property \"vertex_indices\"");
    expect_error("ply\nelement vertex 0\nend_header\n", "m.ply", Status::bad_format,
                 "no format line");
    expect_error("ply\nformat ascii 1.0\nelemental\nend_header\n", "m.ply", Status::bad_format,
                 "unknown header keyword");

    // Data errors, ASCII.
    expect_error(kAsciiHeader + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 7\n", "m.ply",
                 Status::bad_format, "face 1 uses vertex index 7 but the file has 3 vertices");
    expect_error(kAsciiHeader + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 -1 2\n", "m.ply",
                 Status::bad_format, "face 1 uses vertex index -1");
    expect_error(kAsciiHeader + "0 0 0\n1 abc 0\n0 1 0\n3 0 1 2\n3 0 2 1\n", "m.ply",
                 Status::bad_format,
                 "line 11: \"abc\" is not a number (property \"y\" of \"vertex\" record 1)");
    expect_error(kAsciiHeader + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n3 0 2 1\n", "m.ply",
                 Status::bad_format, "face 0 has 2 vertex indices; expected at least 3");
    expect_error(kAsciiHeader + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2   \n", "m.ply",
                 Status::truncated_file, "the data ends inside \"face\" record 1 of 2");
    expect_error(kAsciiHeader + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 1.5\n", "m.ply",
                 Status::bad_format, "\"1.5\" is not an integer index");
}

TEST(PlyReader, CountsLargerThanTheDataAreRejectedBeforeAllocating)
{
    const std::string header =
        "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\n"
        "property float x\nproperty float y\nproperty float z\nend_header\n";
    expect_error(header + std::string(100, '\0'), "big.ply", Status::truncated_file,
                 "declares 1000000000000 \"vertex\" records (at least 12 bytes each) but only 100 "
                 "bytes remain");
    expect_error(
        "ply\nformat ascii 1.0\nelement vertex 4294967295\nproperty float x\nproperty float y\n"
        "property float z\nend_header\n1 2 3\n",
        "big.ply", Status::truncated_file, "declares 4294967295 \"vertex\" records");
    // A face list longer than the file.
    std::string ply = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
                      "property float y\nproperty float z\nelement face 1\n"
                      "property list uint uint vertex_indices\nend_header\n" +
                      std::string(36, '\0');
    put<std::uint32_t>(ply, 4000000000u, false);
    ply += std::string(12, '\0');
    expect_error(ply, "list.ply", Status::truncated_file,
                 "the data ends inside \"face\" record 0 of 1");
    // An element without properties takes no bytes, whatever its count.
    const Mesh mesh =
        read_bytes("ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\n"
                   "property float y\nproperty float z\nelement nothing 9223372036854775807\n"
                   "end_header\n",
                   "empty.ply");
    EXPECT_EQ(mesh.vertex_count(), 0u);
}

// ---- OBJ ------------------------------------------------------------------------------------

TEST(ObjReader, FaceFormsNegativeIndicesPolygonsAndIgnoredStatements)
{
    const std::string obj = "# a comment\r\n"
                            "mtllib things.mtl\r\n"
                            "o object\n"
                            "g group\n"
                            "v 0 0 0\n"
                            "v 1 0 0 1.0\n"         // optional w
                            "v 1 1 0 0.5 0.5 0.5\n" // vertex colour
                            "v 0 1 0   # trailing comment\n"
                            "\n"
                            "vt 0 0\nvt 1 0\nvt 1 1\n"
                            "vn 0 0 1\n"
                            "s off\n"
                            "usemtl red\n"
                            "f 1 2 3\n"
                            "f 1/1 3/3 4/1\n"
                            "f 1//1 2//1 3//1\n"
                            "f -4/-3/-1 -3/-2/-1 -2/-1/-1 -1/1/1\n" // a quad, relative indices
                            "l 1 2\n"
                            "p 1\n";
    const Mesh mesh = read_bytes(obj, "a.obj");
    EXPECT_EQ(mesh.positions, (Floats{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}));
    EXPECT_EQ(mesh.triangles, (Indices{0, 1, 2, 0, 2, 3, 0, 1, 2, 0, 1, 2, 0, 2, 3}));
    EXPECT_FALSE(mesh.has_normals()); // some corners have no normal
}

TEST(ObjReader, NormalsArePerVertexWhenConsistent)
{
    const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\n"
                            "vn 0 0 -1\nvn 0 1 0\nvn 1 0 0\n"
                            "f 1//3 2//2 3//1\n";
    Mesh mesh = read_bytes(obj, "n.obj");
    // Vertex 3 (unused) takes the normal of the same rank: there is none, so no normals at all.
    EXPECT_FALSE(mesh.has_normals());

    mesh = read_bytes(obj + "vn 9 9 9\n", "n.obj");
    EXPECT_EQ(mesh.normals, (Floats{1, 0, 0, 0, 1, 0, 0, 0, -1, 9, 9, 9}));

    mesh = read_bytes(obj + "vn 9 9 9\nf 1//1 2//2 4//4\n",
                      "n.obj"); // vertex 1 paired with two normals
    EXPECT_FALSE(mesh.has_normals());
}

TEST(ObjReader, Errors)
{
    const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    expect_error(v + "f 1 2 4\n", "m.obj", Status::bad_format,
                 "line 4: vertex index 4 but only 3 vertices are defined before this face");
    expect_error(v + "f 1 2 0\n", "m.obj", Status::bad_format,
                 "line 4: vertex index 0; OBJ indices start at 1");
    expect_error(v + "f -1 -2 -4\n", "m.obj", Status::bad_format,
                 "line 4: relative vertex index -4");
    expect_error(v + "f 1 2\n", "m.obj", Status::bad_format, "a face with 2 vertices");
    expect_error(v + "f 1 x 3\n", "m.obj", Status::bad_format, "\"x\" is not a vertex index");
    expect_error("v 0 zero 0\n", "m.obj", Status::bad_format, "line 1: \"zero\" is not a number");
    expect_error("\n\nv 0 0\n", "m.obj", Status::bad_format,
                 "line 3: \"v\" has 2 numbers; expected 3");
    expect_error(v + "vn 0 0 1\nf 1//1 2//2 3//1\n", "m.obj", Status::bad_format, "normal index 2");

    const Mesh nan = read_bytes("v nan 0 0\n", "nan.obj");
    EXPECT_TRUE(std::isnan(nan.positions[0]));
}

// ---- STL ------------------------------------------------------------------------------------

TEST(StlReader, AsciiWeldsExactlyEqualVerticesInOrderOfAppearance)
{
    const std::string stl = "solid square\n"
                            "  facet normal 0 0 1\n"
                            "    outer loop\n"
                            "      vertex 0 0 0\n"
                            "      vertex 1 0 0\n"
                            "      vertex 1 1 0\n"
                            "    endloop\n"
                            "  endfacet\n"
                            "  FACET NORMAL 0 0 1\n"
                            "    OUTER LOOP\n"
                            "      VERTEX 1 1 -0\n" // -0.0 welds with 0.0
                            "      VERTEX 0 1 0\n"
                            "      VERTEX -0 0 0\n"
                            "    ENDLOOP\n"
                            "  ENDFACET\n"
                            "endsolid square\n"
                            "solid second\n"
                            "facet normal 0 0 0 outer loop vertex 1 0 0 vertex 1 0 1e-45 vertex 1 "
                            "1 0 endloop endfacet\n"
                            "endsolid\n";
    const Mesh mesh = read_bytes(stl, "a.stl");
    EXPECT_EQ(mesh.positions, (Floats{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 1, 0, 1e-45f}));
    EXPECT_EQ(mesh.triangles, (Indices{0, 1, 2, 2, 3, 0, 1, 4, 2}));
    EXPECT_FALSE(mesh.has_normals());
}

std::string binary_stl(const std::string& header80, const std::vector<std::array<float, 9>>& facets)
{
    std::string stl = header80;
    stl.resize(80, ' ');
    put<std::uint32_t>(stl, static_cast<std::uint32_t>(facets.size()), false);
    for (const auto& f : facets) {
        for (int k = 0; k < 3; ++k) put(stl, 0.0f, false);
        for (float c : f) put(stl, c, false);
        put<std::uint16_t>(stl, 0, false);
    }
    return stl;
}

TEST(StlReader, BinaryThatStartsWithSolid)
{
    const std::string stl =
        binary_stl("solid but binary", {{0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 0, 1, 0, 0, 1, 1, 0}});
    const Mesh mesh = read_bytes(stl, "b.stl");
    EXPECT_EQ(mesh.vertex_count(), 4u);
    EXPECT_EQ(mesh.triangles, (Indices{0, 1, 2, 2, 1, 3}));

    // Longer than the declared facets (and not ASCII): a count mismatch (docs/formats.md).
    expect_error(binary_stl("x", {{0, 0, 0, 1, 0, 0, 0, 1, 0}}) + std::string(7, '\0'), "p.stl",
                 Status::bad_format, "declares 1 triangles (134 bytes) but the file has 141 bytes");
    // NaN coordinates are kept (and weld by bits).
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const Mesh with_nan = read_bytes(binary_stl("x", {{nan, 0, 0, 1, 0, 0, nan, 0, 0}}), "n.stl");
    EXPECT_EQ(with_nan.vertex_count(), 2u);
    EXPECT_TRUE(std::isnan(with_nan.positions[0]));
}

TEST(StlReader, Errors)
{
    const std::string stl =
        binary_stl("binary", {{0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 0, 1, 0, 0, 1, 1, 0}});
    expect_error(stl.substr(0, stl.size() - 1), "t.stl", Status::truncated_file,
                 "binary STL declares 2 triangles (184 bytes) but the file has 183 bytes");
    expect_error("hello", "t.stl", Status::truncated_file, "5 bytes and no \"solid\" keyword");
    std::string huge = binary_stl("binary", {});
    huge[80] = '\xff';
    huge[81] = '\xff';
    huge[82] = '\xff';
    huge[83] = '\xff';
    expect_error(huge, "t.stl", Status::truncated_file, "declares 4294967295 triangles");
    expect_error("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 "
                 "0\nendloop\n",
                 "a.stl", Status::truncated_file, "the file ends where \"endfacet\" was expected");
    expect_error("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 zero 0\n",
                 "a.stl", Status::bad_format, "line 5: \"zero\" is not a number (in a vertex)");
    expect_error(
        "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\n"
        "endsolid\n",
        "a.stl", Status::bad_format, "a facet with 2 vertices");
    expect_error("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 "
                 "0\nendloop\n"
                 "endfacet\n",
                 "a.stl", Status::truncated_file, "ends before \"endsolid\"");
    expect_error("solid x\nfacet normal 0 0 1\nloop\n", "a.stl", Status::bad_format,
                 "line 3: expected \"outer\", found \"loop\"");
}

// ---- OFF ------------------------------------------------------------------------------------

TEST(OffReader, CommentsColoursPolygonsAndCountsOnTheKeywordLine)
{
    const std::string off = "# leading comment\n"
                            "OFF 5 3 0\n"
                            "\n"
                            "0 0 0\n"
                            "1 0 0 # comment\n"
                            "1 1 0\n"
                            "0 1 0\n"
                            "0.5 0.5 1e-45\n"
                            "4 0 1 2 3 255 0 0\n" // quad with a colour
                            "3 0 1 4\n"
                            "  3 1 2 4\n";
    const Mesh mesh = read_bytes(off, "a.off");
    EXPECT_EQ(mesh.positions, (Floats{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5f, 0.5f, 1e-45f}));
    EXPECT_EQ(mesh.triangles, (Indices{0, 1, 2, 0, 2, 3, 0, 1, 4, 1, 2, 4}));
}

TEST(OffReader, NoffAndCoff)
{
    const Mesh n =
        read_bytes("NOFF\n3 1 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 1 0\n3 0 1 2\n", "n.off");
    EXPECT_EQ(n.normals, (Floats{0, 0, 1, 0, 0, 1, 0, 1, 0}));
    const Mesh c =
        read_bytes("COFF\n3 1 0\n0 0 0 1 0 0 1\n1 0 0 0 1 0 1\n0 1 0 0 0 1 1\n3 0 1 2\n", "c.off");
    EXPECT_EQ(c.positions, (Floats{0, 0, 0, 1, 0, 0, 0, 1, 0}));
    EXPECT_FALSE(c.has_normals());
    const Mesh nan = read_bytes("OFF\n1 0 0\nnan 0 0\n", "nan.off");
    EXPECT_TRUE(std::isnan(nan.positions[0]));
}

TEST(OffReader, Errors)
{
    expect_error("OFX\n3 1 0\n", "m.off", Status::bad_format,
                 "does not start with \"OFF\" (found \"OFX\")");
    expect_error("# only a comment\n", "m.off", Status::bad_format, "no \"OFF\" keyword");
    expect_error("4OFF\n1 0 0\n0 0 0 0\n", "m.off", Status::unsupported_format, "only 3D OFF");
    expect_error("OFF BINARY\n", "m.off", Status::unsupported_format, "binary OFF");
    expect_error("OFF\n", "m.off", Status::truncated_file, "before the counts line");
    expect_error("OFF\n3 x 0\n", "m.off", Status::bad_format, "line 2: expected the counts");
    expect_error("OFF\n1000000 1 0\n0 0 0\n", "m.off", Status::truncated_file,
                 "the counts declare 1000000 vertices and 1 face (");
    expect_error("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "m.off", Status::bad_format,
                 "line 6: face 0 uses vertex index 3 but the file has 3 vertices");
    expect_error("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n", "m.off", Status::bad_format,
                 "vertex index -1");
    expect_error("OFF\n3 1 0\n0 0 0\n1 a 0\n0 1 0\n3 0 1 2\n", "m.off", Status::bad_format,
                 "line 4: \"a\" is not a number (vertex 1)");
    expect_error("OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n# padding\n", "m.off", Status::bad_format,
                 "vertex 1 has 2 numbers; expected 3");
    expect_error("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n# padding\n", "m.off", Status::bad_format,
                 "face 0 has 2 vertices");
    expect_error("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n", "m.off", Status::bad_format,
                 "face 0 lists 3 of its 4 vertex indices");
    expect_error("OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n           \n", "m.off",
                 Status::truncated_file, "the file ends after 1 of 2 faces");
}

// ---- truncation and corruption --------------------------------------------------------------

Mesh small_mesh(bool normals)
{
    Mesh mesh;
    mesh.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    if (normals) mesh.normals = {0, 0, -1, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    mesh.triangles = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    return mesh;
}

std::string written(const Mesh& mesh, const std::string& file, bool ascii = false)
{
    const auto path = cmc33::test::temp_dir() / file;
    cmc33::io::write_mesh(mesh, path, {ascii});
    return cmc33::test::read_file(path);
}

TEST(MeshTruncation, EveryCutOfBinaryPlyAndStlThrows)
{
    for (const auto& [file, normals] :
         {std::pair{"t.ply", true}, {"t.ply", false}, {"t.stl", false}}) {
        const std::string whole = written(small_mesh(normals), file);
        ASSERT_NO_THROW(read_bytes(whole, file));
        for (std::size_t n = 0; n < whole.size(); ++n) {
            EXPECT_THROW(read_bytes(whole.substr(0, n), file), Error)
                << file << " cut at " << n << " of " << whole.size();
        }
    }
}

TEST(MeshTruncation, EveryCutFileThroughReadMesh)
{
    const auto dir = cmc33::test::temp_dir();
    for (const char* file : {"t.ply", "t.stl"}) {
        cmc33::io::write_mesh(small_mesh(false), dir / file);
        const std::string whole = cmc33::test::read_file(dir / file);
        const auto cut = dir / (std::string("cut_") + file);
        for (std::size_t n = 0; n < whole.size(); ++n) {
            cmc33::test::write_file(cut, whole.substr(0, n));
            EXPECT_THROW(cmc33::io::read_mesh(cut), Error) << file << " cut at " << n;
        }
    }
}

// PLY and OFF declare their counts and end every record with a line end: every cut is refused,
// a cut inside the last number too (docs/formats.md).
TEST(MeshTruncation, EveryCutOfAsciiPlyAndOffThrows)
{
    for (const char* file : {"t.ply", "t.off"}) {
        const std::string whole = written(small_mesh(false), file, true);
        ASSERT_EQ(whole.back(), '\n');
        ASSERT_NO_THROW(read_bytes(whole, file));
        for (std::size_t n = 0; n < whole.size(); ++n) {
            EXPECT_THROW(read_bytes(whole.substr(0, n), file), Error)
                << file << " cut at " << n << " of " << whole.size();
        }
    }
}

// #9 item 7: the last index "12" cut to "1" used to read as a different mesh.
TEST(MeshTruncation, CutInsideTheLastNumberIsRefused)
{
    const std::string ply = "ply\nformat ascii 1.0\nelement vertex 13\nproperty float x\n"
                            "property float y\nproperty float z\nelement face 1\n"
                            "property list uchar int vertex_indices\nend_header\n" +
                            [] {
                                std::string v;
                                for (int i = 0; i < 13; ++i) v += std::to_string(i) + " 0 " + std::to_string(i % 2) + "\n";
                                return v;
                            }() +
                            "3 10 11 12\n";
    EXPECT_EQ(read_bytes(ply, "m.ply").triangles, (Indices{10, 11, 12}));
    expect_error(ply.substr(0, ply.size() - 2), "m.ply", Status::truncated_file,
                 "line 23: the file ends inside the number \"1\"");
    expect_error(ply.substr(0, ply.size() - 1), "m.ply", Status::truncated_file,
                 "ends inside the number \"12\"");
    // A blank after the last value, or a line end, ends it.
    EXPECT_NO_THROW(read_bytes(ply.substr(0, ply.size() - 1) + " ", "m.ply"));

    const std::string off = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    expect_error(off.substr(0, off.size() - 1), "m.off", Status::truncated_file,
                 "line 6: the file ends inside the number \"2\"");
    EXPECT_NO_THROW(read_bytes(off + "# no line end after this comment 7", "m.off"));

    // OBJ declares no counts: the last line must end unless it ends in a word or a comment.
    const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n";
    EXPECT_EQ(read_bytes(obj, "m.obj").triangle_count(), 2u);
    expect_error(obj.substr(0, obj.size() - 1), "m.obj", Status::truncated_file,
                 "line 6: the file ends inside the number \"3\"");
    expect_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3/", "m.obj",
                 Status::truncated_file, "ends inside the number \"3/\"");
    expect_error("v 0 0 0\nv 1 0 0\nv 0 1 2.5e", "m.obj", Status::truncated_file,
                 "\"2.5e\"");
    EXPECT_EQ(read_bytes(obj + "usemtl stone", "m.obj").triangle_count(), 2u);
    EXPECT_EQ(read_bytes(obj + "# end 2", "m.obj").triangle_count(), 2u);
}

// More records, values or bytes than a header declares is an error, like fewer.
TEST(MeshTruncation, MoreDataThanDeclaredIsRefused)
{
    const std::string ascii = written(small_mesh(false), "t.ply", true);
    expect_error(ascii + "3 0 1 2\n", "t.ply", Status::bad_format,
                 "\"3\" follows the last record the header declares");
    EXPECT_NO_THROW(read_bytes(ascii + "\n\n  \n", "t.ply"));
    const std::string binary = written(small_mesh(false), "t.ply", false);
    expect_error(binary + "\n", "t.ply", Status::bad_format,
                 "1 byte follows the last record the header declares");
    const std::string off = written(small_mesh(false), "t.off");
    expect_error(off + "3 0 1 2\n", "t.off", Status::bad_format,
                 "follows the last of the");
    EXPECT_NO_THROW(read_bytes(off + "# a comment\n\n", "t.off"));
}

// OBJ (no counts) cut anywhere may still be valid (whole lines gone); it must either read or
// throw cmc33::Error, never anything else and never read out of bounds.
TEST(MeshTruncation, EveryCutOfTextFormatsReadsOrThrowsError)
{
    const std::vector<std::pair<std::string, bool>> files{
        {"t.ply", true}, {"t.obj", false}, {"t.off", false}};
    for (const auto& [file, ascii] : files) {
        const std::string whole = written(small_mesh(true), file, ascii);
        for (std::size_t n = 0; n < whole.size(); ++n) {
            try {
                const Mesh mesh = read_bytes(whole.substr(0, n), file);
                for (std::uint32_t i : mesh.triangles) EXPECT_LT(i, mesh.vertex_count());
            } catch (const Error&) {
            }
        }
    }
    const std::string stl =
        "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
        "endloop\nendfacet\nendsolid t\n";
    for (std::size_t n = 0; n < stl.size(); ++n) {
        try {
            read_bytes(stl.substr(0, n), "t.stl");
        } catch (const Error&) {
        }
    }
}

// Random byte corruption (fixed seed): every reader returns a valid mesh or throws cmc33::Error.
TEST(MeshTruncation, CorruptedBytesReadOrThrowError)
{
    std::uint64_t state = 0x9E3779B97F4A7C15ull;
    auto next = [&] {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        return state;
    };
    const std::vector<std::tuple<std::string, bool, bool>> files{{"c.ply", false, true},
                                                                 {"c.ply", true, true},
                                                                 {"c.obj", false, true},
                                                                 {"c.stl", false, false},
                                                                 {"c.off", false, false}};
    for (const auto& [file, ascii, normals] : files) {
        const std::string whole = written(small_mesh(normals), file, ascii);
        for (int trial = 0; trial < 1500; ++trial) {
            std::string bytes = whole;
            const int flips = 1 + static_cast<int>(next() % 4);
            for (int k = 0; k < flips; ++k) {
                bytes[next() % bytes.size()] = static_cast<char>(next() & 0xff);
            }
            try {
                const Mesh mesh = read_bytes(bytes, file);
                for (std::uint32_t i : mesh.triangles) {
                    ASSERT_LT(i, mesh.vertex_count()) << file << " trial " << trial;
                }
                ASSERT_TRUE(mesh.normals.empty() || mesh.normals.size() == mesh.positions.size());
            } catch (const Error&) {
            }
        }
    }
}

} // namespace
