// write_mesh / read_mesh: round trips through every format, what the writers produce, dispatch by
// extension, and the file-level errors (missing, directory, empty, unsupported extension).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "cmc33/topology.hpp"
#include "test_support.hpp"

namespace {

using cmc33::Error;
using cmc33::Mesh;
using cmc33::Status;
namespace fs = std::filesystem;

// A cube whose coordinates exercise exact float round trips (non-terminating decimals, extremes,
// a subnormal), no two vertices at the same position, with unit normals.
Mesh test_cube(bool normals)
{
    const float x0 = 0.1f, x1 = 1.0f / 3.0f;
    const float y0 = -2.5e-7f, y1 = 3.4028235e38f;
    const float z0 = 1e-45f, z1 = -1234567.875f;
    Mesh mesh;
    for (int v = 0; v < 8; ++v) {
        mesh.positions.push_back(v & 1 ? x1 : x0);
        mesh.positions.push_back(v & 2 ? y1 : y0);
        mesh.positions.push_back(v & 4 ? z1 : z0);
        if (normals) {
            const float s = 1.0f / std::sqrt(3.0f);
            mesh.normals.push_back(v & 1 ? s : -s);
            mesh.normals.push_back(v & 2 ? s : -s);
            mesh.normals.push_back(v & 4 ? s : -s);
        }
    }
    mesh.triangles = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
                      2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
    return mesh;
}

bool same_bits(float a, float b)
{
    return std::memcmp(&a, &b, sizeof a) == 0;
}

void expect_same_topology(const Mesh& a, const Mesh& b)
{
    const cmc33::MeshTopology ta = cmc33::mesh_topology(a), tb = cmc33::mesh_topology(b);
    EXPECT_EQ(ta.vertices, tb.vertices);
    EXPECT_EQ(ta.edges, tb.edges);
    EXPECT_EQ(ta.faces, tb.faces);
    EXPECT_EQ(ta.euler, tb.euler);
    EXPECT_EQ(ta.components, tb.components);
    EXPECT_EQ(ta.closed_components, tb.closed_components);
    EXPECT_EQ(ta.boundary_edges, tb.boundary_edges);
    EXPECT_EQ(ta.nonmanifold_vertices, tb.nonmanifold_vertices);
    EXPECT_EQ(ta.closed, tb.closed);
    EXPECT_EQ(ta.oriented, tb.oriented);
}

struct Format {
    const char* file;
    bool ascii;
    bool keeps_normals;
    bool keeps_indices; // STL re-numbers vertices by first appearance
};

const Format kFormats[] = {
    {"m.ply", false, true, true},   {"m_ascii.ply", true, true, true}, {"m.obj", false, true, true},
    {"m.stl", false, false, false}, {"m.off", false, false, true},
};

TEST(MeshIo, RoundTripEveryFormat)
{
    const fs::path dir = cmc33::test::temp_dir();
    for (bool with_normals : {false, true}) {
        const Mesh original = test_cube(with_normals);
        for (const Format& format : kFormats) {
            SCOPED_TRACE(std::string(format.file) +
                         (with_normals ? " with normals" : " without normals"));
            const fs::path path = dir / format.file;
            cmc33::io::write_mesh(original, path, {format.ascii});
            const Mesh back = cmc33::io::read_mesh(path);
            ASSERT_EQ(back.vertex_count(), original.vertex_count());
            ASSERT_EQ(back.triangle_count(), original.triangle_count());
            if (format.keeps_indices) {
                EXPECT_EQ(back.triangles, original.triangles);
                for (std::size_t i = 0; i < original.positions.size(); ++i) {
                    EXPECT_TRUE(same_bits(back.positions[i], original.positions[i]))
                        << "coordinate " << i << ": " << back.positions[i] << " vs "
                        << original.positions[i];
                }
            } else {
                // Same triangles corner by corner, whatever the vertex numbering.
                for (std::size_t c = 0; c < original.triangles.size(); ++c) {
                    for (int k = 0; k < 3; ++k) {
                        EXPECT_TRUE(same_bits(back.positions[3 * back.triangles[c] + k],
                                              original.positions[3 * original.triangles[c] + k]));
                    }
                }
            }
            if (with_normals && format.keeps_normals) {
                ASSERT_EQ(back.normals.size(), original.normals.size());
                for (std::size_t i = 0; i < original.normals.size(); ++i) {
                    EXPECT_TRUE(same_bits(back.normals[i], original.normals[i]));
                }
            } else {
                EXPECT_FALSE(back.has_normals());
            }
            expect_same_topology(original, back);
        }
    }
}

TEST(MeshIo, StlNumbersVerticesByFirstAppearance)
{
    const fs::path path = cmc33::test::temp_dir() / "cube.stl";
    const Mesh original = test_cube(false);
    cmc33::io::write_mesh(original, path);
    const Mesh back = cmc33::io::read_mesh(path);
    // Original order of first appearance: 0 2 3 1 4 5 7 6.
    const std::vector<std::uint32_t> first_triangles{0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};
    EXPECT_EQ(std::vector<std::uint32_t>(back.triangles.begin(), back.triangles.begin() + 12),
              first_triangles);
}

TEST(MeshIo, EmptyMeshRoundTrips)
{
    const fs::path dir = cmc33::test::temp_dir();
    for (const Format& format : kFormats) {
        SCOPED_TRACE(format.file);
        cmc33::io::write_mesh(Mesh{}, dir / format.file, {format.ascii});
        const Mesh back = cmc33::io::read_mesh(dir / format.file);
        EXPECT_EQ(back.vertex_count(), 0u);
        EXPECT_EQ(back.triangle_count(), 0u);
    }
}

TEST(MeshIo, PlyBinaryLayout)
{
    const fs::path path = cmc33::test::temp_dir() / "cube.ply";
    const Mesh mesh = test_cube(true);
    cmc33::io::write_mesh(mesh, path);
    const std::string bytes = cmc33::test::read_file(path);
    const std::string header =
        "ply\nformat binary_little_endian 1.0\ncomment generated by cmc33\n"
        "element vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        "element face 12\nproperty list uchar uint vertex_indices\nend_header\n";
    ASSERT_EQ(bytes.substr(0, header.size()), header);
    EXPECT_EQ(bytes.size(), header.size() + 8 * 24 + 12 * 13);
    // First face record: count 3 then indices 0 2 3, little-endian.
    const std::string face = bytes.substr(header.size() + 8 * 24, 13);
    EXPECT_EQ(face, std::string("\x03\x00\x00\x00\x00\x02\x00\x00\x00\x03\x00\x00\x00", 13));
    float x = 0;
    std::memcpy(&x, bytes.data() + header.size(), 4); // this test assumes a little-endian machine
    EXPECT_EQ(x, 0.1f);
}

TEST(MeshIo, PlyAsciiLayout)
{
    const fs::path path = cmc33::test::temp_dir() / "tri.ply";
    Mesh mesh;
    mesh.positions = {0, 0, 0, 1, 0, 0, 0, 0.5f, 0};
    mesh.triangles = {0, 1, 2};
    cmc33::io::write_mesh(mesh, path, {.ascii = true});
    EXPECT_EQ(
        cmc33::test::read_file(path),
        "ply\nformat ascii 1.0\ncomment generated by cmc33\nelement vertex 3\nproperty float x\n"
        "property float y\nproperty float z\nelement face 1\nproperty list uchar uint "
        "vertex_indices\n"
        "end_header\n0 0 0\n1 0 0\n0 0.5 0\n3 0 1 2\n");
}

TEST(MeshIo, ObjAndOffLayout)
{
    const fs::path dir = cmc33::test::temp_dir();
    Mesh mesh;
    mesh.positions = {0, 0, 0, 1, 0, 0, 0, 0.5f, 0};
    mesh.triangles = {0, 1, 2};
    cmc33::io::write_mesh(mesh, dir / "a.obj");
    EXPECT_EQ(cmc33::test::read_file(dir / "a.obj"),
              "# generated by cmc33\nv 0 0 0\nv 1 0 0\nv 0 0.5 0\nf 1 2 3\n");
    mesh.normals = {0, 0, 1, 0, 0, 1, 0, 0, 1};
    cmc33::io::write_mesh(mesh, dir / "b.obj");
    EXPECT_EQ(cmc33::test::read_file(dir / "b.obj"),
              "# generated by cmc33\nv 0 0 0\nv 1 0 0\nv 0 0.5 0\n"
              "vn 0 0 1\nvn 0 0 1\nvn 0 0 1\nf 1//1 2//2 3//3\n");
    cmc33::io::write_mesh(mesh, dir / "c.off");
    EXPECT_EQ(cmc33::test::read_file(dir / "c.off"),
              "OFF\n3 1 0\n0 0 0\n1 0 0\n0 0.5 0\n3 0 1 2\n");
}

TEST(MeshIo, StlBinaryLayout)
{
    const fs::path path = cmc33::test::temp_dir() / "tri.stl";
    Mesh mesh;
    mesh.positions = {0, 0, 0, 2, 0, 0, 0, 3, 0};
    mesh.triangles = {0, 1, 2, 0, 0, 1}; // the second triangle is degenerate
    cmc33::io::write_mesh(mesh, path);
    const std::string bytes = cmc33::test::read_file(path);
    ASSERT_EQ(bytes.size(), 84u + 2 * 50u);
    EXPECT_NE(bytes.substr(0, 5), "solid");
    std::uint32_t count = 0;
    std::memcpy(&count, bytes.data() + 80, 4);
    EXPECT_EQ(count, 2u);
    float normal[3];
    std::memcpy(normal, bytes.data() + 84, 12);
    EXPECT_EQ(normal[0], 0.0f);
    EXPECT_EQ(normal[1], 0.0f);
    EXPECT_EQ(normal[2], 1.0f); // counter-clockwise seen from +z
    std::memcpy(normal, bytes.data() + 84 + 50, 12);
    EXPECT_EQ(normal[2], 0.0f); // degenerate: zero normal
    EXPECT_EQ(bytes.substr(84 + 48, 2), std::string("\0\0", 2));
}

TEST(MeshIo, ExtensionIsCaseInsensitive)
{
    const fs::path path = cmc33::test::temp_dir() / "UPPER.PLY";
    cmc33::io::write_mesh(test_cube(false), path);
    EXPECT_EQ(cmc33::io::read_mesh(path).triangle_count(), 12u);
}

void expect_error(const std::function<void()>& f, Status status, const std::string& fragment)
{
    try {
        f();
        ADD_FAILURE() << "no exception; expected one containing " << fragment;
    } catch (const Error& e) {
        EXPECT_EQ(static_cast<int>(e.status()), static_cast<int>(status)) << e.what();
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "one line: " << e.what();
    }
}

TEST(MeshIo, UnsupportedExtension)
{
    const fs::path dir = cmc33::test::temp_dir();
    expect_error([&] { cmc33::io::write_mesh(test_cube(false), dir / "m.xyz"); },
                 Status::unsupported_format, "\".xyz\"; expected .ply, .obj, .stl, .off, .glb, .gltf, .vtp or .gii");
    EXPECT_FALSE(fs::exists(dir / "m.xyz"));
    cmc33::test::write_file(dir / "m.gltf", "{}");
    expect_error([&] { cmc33::io::read_mesh(dir / "m.gltf"); }, Status::unsupported_format,
                 "m.gltf: cmc33 writes \".gltf\" meshes but does not read them; expected .ply, .obj, .stl or .off");
    expect_error([&] { cmc33::io::read_mesh(dir / "noext"); }, Status::unsupported_format,
                 "(none)");
}

TEST(MeshIo, MissingFileAndDirectory)
{
    const fs::path dir = cmc33::test::temp_dir();
    expect_error([&] { cmc33::io::read_mesh(dir / "missing.ply"); }, Status::io_error,
                 "missing.ply: cannot open");
    fs::create_directory(dir / "folder.obj");
    expect_error([&] { cmc33::io::read_mesh(dir / "folder.obj"); }, Status::io_error,
                 "is a directory");
    expect_error([&] { cmc33::io::write_mesh(test_cube(false), dir / "folder.obj"); },
                 Status::io_error, "is a directory");
    expect_error([&] { cmc33::io::write_mesh(test_cube(false), dir / "no" / "such.ply"); },
                 Status::io_error, "does not exist");
}

TEST(MeshIo, EmptyFile)
{
    const fs::path dir = cmc33::test::temp_dir();
    for (const char* name : {"e.ply", "e.obj", "e.stl", "e.off"}) {
        cmc33::test::write_file(dir / name, "");
        expect_error([&] { cmc33::io::read_mesh(dir / name); }, Status::truncated_file,
                     "the file is empty");
    }
}

TEST(MeshIo, WriteRejectsInvalidMeshAndLeavesNoFile)
{
    const fs::path dir = cmc33::test::temp_dir();
    Mesh bad = test_cube(false);
    bad.triangles[7] = 8;
    expect_error([&] { cmc33::io::write_mesh(bad, dir / "bad.ply"); }, Status::invalid_argument,
                 "triangle 2 uses vertex 8 but the mesh has 8 vertices");
    EXPECT_FALSE(fs::exists(dir / "bad.ply"));

    Mesh ragged = test_cube(false);
    ragged.positions.pop_back();
    expect_error([&] { cmc33::io::write_mesh(ragged, dir / "bad.obj"); }, Status::invalid_argument,
                 "positions hold 23 floats");
    Mesh bad_normals = test_cube(true);
    bad_normals.normals.resize(3);
    expect_error([&] { cmc33::io::write_mesh(bad_normals, dir / "bad.off"); },
                 Status::invalid_argument, "normals hold 3 floats");
    EXPECT_TRUE(fs::is_empty(dir));
}

TEST(MeshIo, OverwritesAnExistingFile)
{
    const fs::path path = cmc33::test::temp_dir() / "m.off";
    cmc33::test::write_file(path,
                            "old content that is longer than the new file will be ..........");
    Mesh mesh;
    mesh.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    mesh.triangles = {0, 1, 2};
    cmc33::io::write_mesh(mesh, path);
    EXPECT_EQ(cmc33::test::read_file(path), "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
}

TEST(MeshIo, BeforeCommitRunsOnceTheBytesAreWrittenAndItsErrorLeavesEveryFileAsItWas)
{
    const fs::path dir = cmc33::test::temp_dir();
    const Mesh mesh = test_cube(true);
    // every kind of writer: the common one, .glb, and .gltf with its .bin
    for (const char* name : {"m.ply", "m.stl", "m.vtp", "m.gii", "m.glb", "m.gltf"}) {
        SCOPED_TRACE(name);
        const fs::path path = dir / name;
        fs::path bin = path;
        bin.replace_extension(".bin");
        const bool gltf = path.extension() == ".gltf";
        cmc33::test::write_file(path, "old");
        if (gltf) cmc33::test::write_file(bin, "old bin");
        cmc33::io::MeshWriteOptions refused;
        int calls = 0;
        refused.before_commit = [&] {
            ++calls;
            // the bytes are written by now, beside the target and not over it
            EXPECT_EQ(cmc33::test::read_file(path), "old");
            throw Error(Status::cancelled, "the check was cancelled");
        };
        expect_error([&] { cmc33::io::write_mesh(mesh, path, refused); }, Status::cancelled, "the check was cancelled");
        EXPECT_EQ(calls, 1);
        EXPECT_EQ(cmc33::test::read_file(path), "old");
        if (gltf) {
            EXPECT_EQ(cmc33::test::read_file(bin), "old bin");
        }

        cmc33::io::MeshWriteOptions allowed;
        allowed.before_commit = [&] { ++calls; };
        cmc33::io::write_mesh(mesh, path, allowed);
        EXPECT_EQ(calls, 2);
        EXPECT_NE(cmc33::test::read_file(path), "old");
        if (gltf) {
            EXPECT_NE(cmc33::test::read_file(bin), "old bin");
        }
    }
    // no temporary is left behind
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    EXPECT_EQ(names, (std::vector<std::string>{"m.bin", "m.gii", "m.glb", "m.gltf", "m.ply", "m.stl", "m.vtp"}));
}

} // namespace
