// MeshWriteOptions::triangle_arrays in PLY: face properties after vertex_indices, in binary and
// ASCII, each of the PLY type that holds its values (an int64 array that fits neither int nor uint
// refused before anything is written), checked byte by byte here and read back independently
// (tests/io/read_ply_faces.py: numpy from the header's layout, and meshio for ASCII; VTK's
// vtkPLYReader drops face properties). cmc33's own reader skips them: it gives the same mesh back.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sys/wait.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <limits>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "cmc33/mesh.hpp"
#include "test_support.hpp"

namespace {

using cmc33::Mesh;
namespace fs = std::filesystem;
using cmc33::test::u32_le;
namespace io = cmc33::io;
using nlohmann::json;

/// Three triangles of a tetrahedron.
Mesh tetra()
{
    Mesh m;
    m.positions = {0, 0, 0, 2, 0, 0, 0, 3, 0, 0, 0, 5};
    m.triangles = {0, 2, 1, 0, 1, 3, 0, 3, 2};
    return m;
}

// One array of each kind: float, int32, int64 past int32 (uint), int64 of two components (int).
const std::vector<float> kQuality{0.5f, -1.25f, 3.0e38f};
const std::vector<std::int32_t> kRegion{-3, 0, std::numeric_limits<std::int32_t>::max()};
const std::vector<std::int64_t> kLabel{0, 4294967295, 5};
const std::vector<std::int64_t> kPair{-1, 2, 3, -2147483648, 5, 6};

io::MeshWriteOptions arrays(bool ascii)
{
    io::MeshWriteOptions o;
    o.ascii = ascii;
    o.triangle_arrays = {{"quality", std::span<const float>(kQuality), 1},
                         {"region", std::span<const std::int32_t>(kRegion), 1},
                         {"label", std::span<const std::int64_t>(kLabel), 1},
                         {"pair", std::span<const std::int64_t>(kPair), 2}};
    return o;
}

const std::string kFaceHeader = "element face 3\nproperty list uchar uint vertex_indices\nproperty float quality\n"
                                "property int region\nproperty uint label\nproperty int pair_0\nproperty int pair_1\n"
                                "end_header\n";

/// The bytes of one value of the PLY scalar type `type`, or 0 for a name PLY does not have.
std::size_t ply_type_bytes(const std::string& type)
{
    if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
    if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
    if (type == "int" || type == "uint" || type == "float" || type == "int32" || type == "uint32" || type == "float32")
        return 4;
    if (type == "double" || type == "float64") return 8;
    return 0;
}

/// The face records of `m` written as the binary little-endian PLY file `bytes`, read by the layout
/// its header declares (the vertex records skipped by their properties' sizes, then per face a
/// `list uchar uint vertex_indices` and 4-byte scalar properties): per triangle, the words of its
/// properties after vertex_indices, in the header's order. A failure is added, and no records
/// returned, when the header is not of that shape, the faces do not have `words` properties each,
/// they are not m's triangles in order, or the records do not end exactly at the end of the file.
std::vector<std::vector<std::uint32_t>> face_records(const std::string& bytes, const Mesh& m, std::size_t words)
{
    const std::size_t end = bytes.find("end_header\n");
    if (end == std::string::npos) {
        ADD_FAILURE() << "no end_header";
        return {};
    }
    EXPECT_NE(bytes.find("\nformat binary_little_endian 1.0\n"), std::string::npos);
    std::istringstream header(bytes.substr(0, end));
    std::string line;
    std::string element;
    std::size_t vertices = 0;
    std::size_t vertex_bytes = 0;
    std::size_t faces = 0;
    std::size_t face_words = 0;
    while (std::getline(header, line)) {
        std::istringstream fields(line);
        std::string key;
        std::string type;
        fields >> key;
        if (key == "element") {
            std::size_t n = 0;
            fields >> element >> n;
            (element == "vertex" ? vertices : faces) = n;
        }
        if (key != "property") continue;
        fields >> type;
        if (element == "vertex") {
            EXPECT_NE(ply_type_bytes(type), 0u) << line;
            vertex_bytes += ply_type_bytes(type);
        } else if (type == "list") {
            EXPECT_EQ(line, "property list uchar uint vertex_indices");
        } else {
            EXPECT_EQ(ply_type_bytes(type), 4u) << line;
            ++face_words;
        }
    }
    EXPECT_EQ(face_words, words) << "face properties after vertex_indices";
    EXPECT_EQ(faces, m.triangles.size() / 3) << "faces";
    std::vector<std::vector<std::uint32_t>> records;
    cmc33::Buffer<std::uint32_t> indices;
    std::size_t at = end + 11 + vertices * vertex_bytes;
    for (std::size_t f = 0; f < faces && at < bytes.size(); ++f) {
        const std::size_t n = static_cast<unsigned char>(bytes[at]);
        if (at + 1 + 4 * (n + face_words) > bytes.size()) break;
        for (std::size_t k = 0; k < n; ++k) indices.push_back(u32_le(bytes, at + 1 + 4 * k));
        records.emplace_back();
        for (std::size_t k = 0; k < face_words; ++k) records.back().push_back(u32_le(bytes, at + 1 + 4 * (n + k)));
        at += 1 + 4 * (n + face_words);
    }
    EXPECT_EQ(records.size(), faces) << "the file ends inside the face records";
    EXPECT_EQ(at, bytes.size()) << "the face records do not end where the file ends";
    EXPECT_EQ(indices, m.triangles) << "the faces' vertex_indices";
    const bool whole =
        face_words == words && records.size() == m.triangles.size() / 3 && at == bytes.size() && indices == m.triangles;
    return whole ? records : std::vector<std::vector<std::uint32_t>>{};
}

TEST(MeshPlyFaces, BinaryRecordsHoldTheValues)
{
    const fs::path dir = cmc33::test::temp_dir();
    const Mesh m = tetra();
    io::write_mesh(m, dir / "b.ply", arrays(false));
    const std::string bytes = cmc33::test::read_file(dir / "b.ply");
    const std::size_t end = bytes.find("end_header\n");
    ASSERT_NE(end, std::string::npos);
    EXPECT_NE(bytes.substr(0, end + 11).find(kFaceHeader), std::string::npos) << bytes.substr(0, end + 11);
    const std::vector<std::vector<std::uint32_t>> faces = face_records(bytes, m, 5);
    ASSERT_EQ(faces.size(), 3u);
    for (std::size_t f = 0; f < 3; ++f) {
        SCOPED_TRACE(f);
        const std::vector<std::uint32_t>& w = faces[f];
        EXPECT_EQ(std::bit_cast<float>(w[0]), kQuality[f]);
        EXPECT_EQ(static_cast<std::int32_t>(w[1]), kRegion[f]);
        EXPECT_EQ(w[2], static_cast<std::uint64_t>(kLabel[f]));
        EXPECT_EQ(static_cast<std::int32_t>(w[3]), kPair[2 * f]);
        EXPECT_EQ(static_cast<std::int32_t>(w[4]), kPair[2 * f + 1]);
    }
    // cmc33's reader skips the properties by their declared types: the same mesh
    const Mesh back = io::read_mesh(dir / "b.ply");
    EXPECT_EQ(back.positions, m.positions);
    EXPECT_EQ(back.triangles, m.triangles);
}

TEST(MeshPlyFaces, AsciiLinesHoldTheValues)
{
    const fs::path dir = cmc33::test::temp_dir();
    const Mesh m = tetra();
    io::write_mesh(m, dir / "a.ply", arrays(true));
    const std::string text = cmc33::test::read_file(dir / "a.ply");
    const std::size_t data = text.find("end_header\n") + 11;
    EXPECT_NE(text.substr(0, data).find(kFaceHeader), std::string::npos);
    EXPECT_EQ(text.substr(data), "0 0 0\n2 0 0\n0 3 0\n0 0 5\n"
                                 "3 0 2 1 0.5 -3 0 -1 2\n"
                                 "3 0 1 3 -1.25 0 4294967295 3 -2147483648\n"
                                 "3 0 3 2 3e+38 2147483647 5 5 6\n");
    const Mesh back = io::read_mesh(dir / "a.ply");
    EXPECT_EQ(back.positions, m.positions);
    EXPECT_EQ(back.triangles, m.triangles);
}

TEST(MeshPlyFaces, Int64BoundsChooseTheType)
{
    const fs::path dir = cmc33::test::temp_dir();
    struct Case {
        std::vector<std::int64_t> values;
        const char* type;
    };
    const std::vector<Case> cases = {{{-2147483648, 2147483647, 0}, "int"},
                                     {{0, 2147483648, 4294967295}, "uint"},
                                     {{7, 7, 7}, "int"}};
    for (const Case& c : cases) {
        SCOPED_TRACE(c.type);
        io::MeshWriteOptions o;
        o.triangle_arrays = {{"v", std::span<const std::int64_t>(c.values), 1}};
        io::write_mesh(tetra(), dir / "t.ply", o);
        EXPECT_NE(cmc33::test::read_file(dir / "t.ply").find(std::string("property ") + c.type + " v\n"),
                  std::string::npos);
    }
}

void expect_refused(const io::MeshWriteOptions& o, const fs::path& path, const std::vector<std::string>& parts)
{
    try {
        io::write_mesh(tetra(), path, o);
        FAIL() << "no error";
    } catch (const cmc33::Error& e) {
        EXPECT_EQ(e.status(), cmc33::Status::invalid_argument);
        const std::string what = e.what();
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
        for (const std::string& part : parts) EXPECT_NE(what.find(part), std::string::npos) << part << " in " << what;
    }
    EXPECT_FALSE(fs::exists(path));
}

TEST(MeshPlyFaces, WhatPlyCannotHoldIsRefusedBeforeWriting)
{
    const fs::path dir = cmc33::test::temp_dir();
    const fs::path path = dir / "r.ply";
    // a negative label beside one past int32: neither int nor uint holds both
    const std::vector<std::int64_t> mixed{-1, 2147483648, 0};
    io::MeshWriteOptions o;
    o.triangle_arrays = {{"front", std::span<const std::int64_t>(mixed), 1}};
    expect_refused(o, path,
                   {path.string() + ": cannot write the triangle array \"front\" as PLY face properties",
                    "from -1 (triangle 0) to 2147483648 (triangle 1)", "PLY has no 64-bit integers"});
    // none negative, but one past uint32
    const std::vector<std::int64_t> huge{0, 4294967296, 1};
    o.triangle_arrays = {{"behind", std::span<const std::int64_t>(huge), 1}};
    expect_refused(o, path, {"\"behind\"", "from 0 (triangle 0) to 4294967296 (triangle 1)"});
    // names the header cannot hold or that repeat
    const std::vector<float> f(3, 1.0f);
    o.triangle_arrays = {{"two words", std::span<const float>(f), 1}};
    expect_refused(o, path, {"\"two words\"", "without blanks"});
    o.triangle_arrays = {{"vertex_indices", std::span<const float>(f), 1}};
    expect_refused(o, path, {"already has a property \"vertex_indices\""});
    const std::vector<float> f2(6, 1.0f);
    o.triangle_arrays = {{"a_1", std::span<const float>(f), 1}, {"a", std::span<const float>(f2), 2}};
    expect_refused(o, path, {"\"a\"", "already has a property \"a_1\""});
    // the size check of every format covers PLY
    const std::vector<std::int32_t> short_array{1, 2};
    o.triangle_arrays = {{"label", std::span<const std::int32_t>(short_array), 1}};
    expect_refused(o, path, {"\"label\": 2 values of 1 components", "(3 triangles)"});
}

TEST(MeshPlyFaces, VtpWritesInt64CellData)
{
    const fs::path dir = cmc33::test::temp_dir();
    const std::vector<std::int64_t> labels{-1, 4294967296, 3};
    io::MeshWriteOptions o;
    o.triangle_arrays = {{"label", std::span<const std::int64_t>(labels), 1}};
    io::write_mesh(tetra(), dir / "m.vtp", o);
    EXPECT_NE(cmc33::test::read_file(dir / "m.vtp").find("type=\"Int64\" Name=\"label\""), std::string::npos);
}

/// read_ply_faces.py's reading of `path`, or null when numpy is not installed.
json read_with_meshio(const fs::path& path)
{
    const fs::path out = path.string() + ".json";
    const std::string command = std::string(CMC33_SYSTEM_PYTHON) + " " + CMC33_READ_PLY_FACES + " \"" + path.string() +
                                "\" \"" + out.string() + "\"";
    const int status = std::system(command.c_str());
    if (WIFEXITED(status) && WEXITSTATUS(status) == 77) return nullptr;
    EXPECT_EQ(status, 0) << command;
    if (status != 0) return json::object();
    return json::parse(cmc33::test::read_file(out));
}

TEST(MeshPlyFaces, AnIndependentReaderFindsTheValues)
{
    const fs::path dir = cmc33::test::temp_dir();
    const Mesh m = tetra();
    for (const bool ascii : {false, true}) {
        SCOPED_TRACE(ascii ? "ascii" : "binary");
        const fs::path path = dir / (ascii ? "a.ply" : "b.ply");
        io::write_mesh(m, path, arrays(ascii));
        const json j = read_with_meshio(path);
        if (j.is_null()) GTEST_SKIP() << "numpy is not installed (python3-numpy)";
        ASSERT_TRUE(j.contains("cell_data")) << j.dump();
        ASSERT_EQ(j["points"].size(), 4u);
        for (std::size_t v = 0; v < 4; ++v)
            for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(j["points"][v][k].get<double>(), static_cast<double>(m.positions[3 * v + k]));
        ASSERT_EQ(j["triangles"].size(), 3u);
        for (std::size_t f = 0; f < 3; ++f)
            for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(j["triangles"][f][k].get<std::uint32_t>(), m.triangles[3 * f + k]);
        const json& d = j["cell_data"];
        ASSERT_EQ(d.size(), 5u) << d.dump();
        for (std::size_t f = 0; f < 3; ++f) {
            EXPECT_EQ(d["quality"][f].get<double>(), static_cast<double>(kQuality[f]));
            EXPECT_EQ(d["region"][f].get<std::int64_t>(), kRegion[f]);
            EXPECT_EQ(d["label"][f].get<std::int64_t>(), kLabel[f]);
            EXPECT_EQ(d["pair_0"][f].get<std::int64_t>(), kPair[2 * f]);
            EXPECT_EQ(d["pair_1"][f].get<std::int64_t>(), kPair[2 * f + 1]);
        }
        EXPECT_EQ(j["dtypes"]["quality"], "float32");
        EXPECT_EQ(j["dtypes"]["label"], "uint32");
        EXPECT_EQ(j["dtypes"]["region"], "int32");
        if (ascii && !j["meshio"].get<bool>()) std::cout << "note: meshio is not installed; numpy's reading only\n";
    }
}

/// Tetrahedron face records wider than 4,096 bytes: `components` floats and an int64 array of three
/// components (negative values: PLY int), each value a function of its triangle and component.
struct WideArrays {
    std::vector<float> reals;
    std::vector<std::int64_t> labels;
    explicit WideArrays(std::size_t components) : reals(3 * components), labels(9)
    {
        for (std::size_t i = 0; i < reals.size(); ++i) reals[i] = static_cast<float>(i) * 0.25f - 1000.0f;
        for (std::size_t i = 0; i < labels.size(); ++i) labels[i] = static_cast<std::int64_t>(i * i) - 40;
    }
    io::MeshWriteOptions options(bool ascii) const
    {
        io::MeshWriteOptions o;
        o.ascii = ascii;
        o.triangle_arrays = {{"w", std::span<const float>(reals), static_cast<int>(reals.size() / 3)},
                             {"l", std::span<const std::int64_t>(labels), 3}};
        return o;
    }
};

/// The binary file's face records hold exactly the arrays' values; cmc33's reader gives the mesh back.
void expect_wide_records(const fs::path& path, const Mesh& m, const WideArrays& w);

/// tetra() with `w`'s arrays written in binary to dir/name and its records checked; the mesh.
Mesh write_wide(const fs::path& dir, const char* name, const WideArrays& w)
{
    const Mesh m = tetra();
    io::write_mesh(m, dir / name, w.options(false));
    expect_wide_records(dir / name, m, w);
    return m;
}

void expect_wide_records(const fs::path& path, const Mesh& m, const WideArrays& w)
{
    const std::size_t c = w.reals.size() / 3;
    const std::string bytes = cmc33::test::read_file(path);
    EXPECT_NE(bytes.find("property float w_" + std::to_string(c - 1) + "\nproperty int l_0\n"), std::string::npos);
    const std::vector<std::vector<std::uint32_t>> faces = face_records(bytes, m, c + 3);
    ASSERT_EQ(faces.size(), 3u);
    for (std::size_t f = 0; f < 3; ++f) {
        SCOPED_TRACE(f);
        const std::vector<std::uint32_t>& words = faces[f];
        std::size_t wrong = 0;
        for (std::size_t k = 0; k < c; ++k) wrong += std::bit_cast<float>(words[k]) != w.reals[c * f + k];
        EXPECT_EQ(wrong, 0u);
        for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(static_cast<std::int32_t>(words[c + k]), w.labels[3 * f + k]);
    }
    const Mesh back = io::read_mesh(path);
    EXPECT_EQ(back.positions, m.positions);
    EXPECT_EQ(back.triangles, m.triangles);
}

TEST(MeshPlyFaces, FaceRecordsLargerThan4096Bytes)
{
    // 1,100 floats and 3 ints per triangle: 4,425-byte records
    const fs::path dir = cmc33::test::temp_dir();
    const WideArrays w(1100);
    const Mesh m = write_wide(dir, "w.ply", w);
    // read independently (numpy from the header's layout; meshio too for ASCII), both encodings
    for (const bool ascii : {false, true}) {
        SCOPED_TRACE(ascii ? "ascii" : "binary");
        const fs::path path = dir / (ascii ? "wa.ply" : "wb.ply");
        io::write_mesh(m, path, w.options(ascii));
        const json j = read_with_meshio(path);
        if (j.is_null()) GTEST_SKIP() << "numpy is not installed (python3-numpy)";
        const json& d = j["cell_data"];
        ASSERT_EQ(d.size(), 1103u);
        std::size_t wrong = 0;
        for (std::size_t f = 0; f < 3; ++f) {
            for (std::size_t k = 0; k < 1100; ++k)
                wrong += d["w_" + std::to_string(k)][f].get<double>() != static_cast<double>(w.reals[1100 * f + k]);
            for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(d["l_" + std::to_string(k)][f].get<std::int64_t>(), w.labels[3 * f + k]);
        }
        EXPECT_EQ(wrong, 0u);
        EXPECT_EQ(j["dtypes"]["w_0"], "float32");
        EXPECT_EQ(j["dtypes"]["l_0"], "int32");
    }
}

TEST(MeshPlyFaces, FaceRecordsLargerThanTheOutputBlock)
{
    // 70,000 floats per triangle: records of 280,025 bytes, more than OutputBuffer's 256 KiB block
    write_wide(cmc33::test::temp_dir(), "h.ply", WideArrays(70000));
}

} // namespace
