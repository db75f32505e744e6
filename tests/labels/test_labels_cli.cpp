// `cmc33 labels` run as a program: the folder and interface outputs against the library, the same
// bytes twice, and bad input refused with one line and nothing written.

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <sys/wait.h>
#include <utility>

#include <nlohmann/json.hpp>

#include "cmc33/io.hpp"
#include "cmc33/labels.hpp"
#include "cmc33/topology.hpp"
#include "label_checks.hpp"
#include "test_support.hpp"

namespace {

using namespace cmc33;
namespace fs = std::filesystem;

// Exit status of `cmc33 ARGS`, stderr into `err`.
int run(const std::string& args, const fs::path& err)
{
    const std::string command = std::string(CMC33_EXE) + " " + args + " >/dev/null 2>" + err.string();
    const int status = std::system(command.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(LabelsCli, FolderAndInterfaces)
{
    const fs::path dir = test::temp_dir();
    const Volume seg = label_checks::random_labels(8, 4, 5, true);
    io::write_volume(seg, dir / "seg.nrrd");
    const LabelSurfaces s = label_surfaces(seg);
    ASSERT_EQ(
        run("labels " + (dir / "seg.nrrd").string() + " -o " + (dir / "out").string() + " --background 2", dir / "err"),
        0)
        << test::read_file(dir / "err");
    for (const std::int64_t l : {1, 3, 4}) {
        const Mesh m = io::read_mesh(dir / "out" / ("label_" + std::to_string(l) + ".ply"));
        const Mesh want = label_surface(s, l);
        EXPECT_EQ(m.triangle_count(), want.triangle_count());
        EXPECT_EQ(mesh_topology(m).euler, mesh_topology(want).euler);
    }
    EXPECT_FALSE(fs::exists(dir / "out" / "label_2.ply"));
    ASSERT_EQ(run("labels " + (dir / "seg.nrrd").string() + " -o " + (dir / "i.ply").string(), dir / "err"), 0);
    ASSERT_EQ(run("labels " + (dir / "seg.nrrd").string() + " -o " + (dir / "j.ply").string(), dir / "err"), 0);
    const std::string a = test::read_file(dir / "i.ply");
    EXPECT_EQ(a, test::read_file(dir / "j.ply"));
    EXPECT_NE(a.find("property int front"), std::string::npos);
    EXPECT_EQ(io::read_mesh(dir / "i.ply").triangle_count(), s.interfaces.triangle_count());
}

// --normals: each label's file and the interfaces' PLY carry the library's normals, byte for byte
// in the PLY (binary floats); formats without normals are refused before any work.
TEST(LabelsCli, Normals)
{
    const fs::path dir = test::temp_dir();
    const Volume seg = label_checks::random_labels(8, 3, 6, true);
    io::write_volume(seg, dir / "seg.nrrd");
    LabelOptions o;
    o.normals = true;
    const LabelSurfaces s = label_surfaces(seg, o);
    ASSERT_EQ(
        run("labels " + (dir / "seg.nrrd").string() + " -o " + (dir / "out").string() + " --normals", dir / "err"), 0)
        << test::read_file(dir / "err");
    for (const std::int64_t l : s.selected) {
        const Mesh m = io::read_mesh(dir / "out" / ("label_" + std::to_string(l) + ".ply"));
        const Mesh want = label_surface(s, l);
        ASSERT_TRUE(m.has_normals()) << l;
        EXPECT_TRUE(m.normals == want.normals) << l;
    }
    ASSERT_EQ(
        run("labels " + (dir / "seg.nrrd").string() + " -o " + (dir / "i.ply").string() + " --normals", dir / "err"), 0)
        << test::read_file(dir / "err");
    const Mesh i = io::read_mesh(dir / "i.ply");
    EXPECT_TRUE(i.normals == s.interfaces.normals);
    // the other writers that store normals (OBJ read back; VTP and glTF by their normals' tags)
    for (const auto& [format, tag] : {std::pair{"obj", ""}, std::pair{"vtp", "Normals=\"Normals\""},
                                      std::pair{"glb", "\"NORMAL\""}, std::pair{"gii", "NIFTI_INTENT_VECTOR"}}) {
        const fs::path out = dir / (std::string("f_") + format);
        ASSERT_EQ(run("labels " + (dir / "seg.nrrd").string() + " -o " + out.string() + " --normals --format " + format,
                      dir / "err"),
                  0)
            << format << ": " << test::read_file(dir / "err");
        const fs::path file = out / (std::string("label_1.") + format);
        if (std::string(format) == "obj") {
            const Mesh m = io::read_mesh(file), want = label_surface(s, 1);
            ASSERT_EQ(m.normals.size(), want.normals.size());
            for (std::size_t k = 0; k < m.normals.size(); ++k) ASSERT_NEAR(m.normals[k], want.normals[k], 1e-6) << k;
        } else {
            EXPECT_NE(test::read_file(file).find(tag), std::string::npos) << format;
        }
    }
    ASSERT_EQ(
        run("labels " + (dir / "seg.nrrd").string() + " -o " + (dir / "s.glb").string() + " --normals", dir / "err"), 0)
        << test::read_file(dir / "err");
    EXPECT_NE(test::read_file(dir / "s.glb").find("\"NORMAL\""), std::string::npos);
    EXPECT_EQ(run("labels " + (dir / "seg.nrrd").string() + " -o " + (dir / "stl").string() + " --normals --format stl",
                  dir / "err"),
              2);
    const std::string err = test::read_file(dir / "err");
    EXPECT_NE(err.find("cannot store normals"), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(dir / "stl"));
}

TEST(LabelsCli, InterfaceLabelsPastInt32AreUint)
{
    // two halves, labels 0 and 3e9 (uint32 samples): the PLY's face properties hold both exactly
    const fs::path dir = test::temp_dir();
    Volume seg(ScalarType::u32, {6, 5, 4});
    std::uint32_t* v = reinterpret_cast<std::uint32_t*>(seg.bytes());
    for (std::size_t i = 0; i < 6 * 5 * 4; ++i) v[i] = i % 6 < 3 ? 0u : 3000000000u;
    io::write_volume(seg, dir / "seg.nrrd");
    ASSERT_EQ(run("labels " + (dir / "seg.nrrd").string() + " -o " + (dir / "i.ply").string(), dir / "err"), 0)
        << test::read_file(dir / "err");
    const LabelSurfaces s = label_surfaces(seg);
    ASSERT_GT(s.interfaces.triangle_count(), 0u);
    const std::string ply = test::read_file(dir / "i.ply");
    const std::size_t data = ply.find("end_header\n") + 11;
    const std::string header = ply.substr(0, data);
    EXPECT_NE(header.find("property uint " + std::string(s.front[0] == 0 ? "behind" : "front")), std::string::npos)
        << header;
    const std::size_t faces = data + 12 * s.interfaces.vertex_count();
    ASSERT_EQ(ply.size(), faces + 21 * s.interfaces.triangle_count());
    for (std::size_t t = 0; t < s.interfaces.triangle_count(); ++t) {
        std::uint32_t front = 0, behind = 0;
        std::memcpy(&front, ply.data() + faces + 21 * t + 13, 4); // little-endian hosts, as the writer
        std::memcpy(&behind, ply.data() + faces + 21 * t + 17, 4);
        ASSERT_EQ(front, s.front[t]) << t;
        ASSERT_EQ(behind, s.behind[t]) << t;
    }
}

// --smooth SIGMA: the library's smoothed surfaces, the JSON says so, and a bad SIGMA is refused as
// a usage error (exit 2) before any work, nothing written.
TEST(LabelsCli, Smooth)
{
    const fs::path dir = test::temp_dir();
    const Volume seg = label_checks::random_labels(9, 3, 8, true);
    io::write_volume(seg, dir / "seg.nrrd");
    LabelOptions o;
    o.smooth = 1.25;
    const LabelSurfaces s = label_surfaces(seg, o);
    ASSERT_EQ(std::system((std::string(CMC33_EXE) + " labels " + (dir / "seg.nrrd").string() + " -o " +
                           (dir / "out").string() + " --smooth 1.25 --json >" + (dir / "j").string())
                              .c_str()),
              0);
    const nlohmann::json j = nlohmann::json::parse(test::read_file(dir / "j"));
    EXPECT_EQ(j["smooth"], 1.25);
    EXPECT_EQ(j["interface_triangles"], static_cast<std::int64_t>(s.interfaces.triangle_count()));
    ASSERT_FALSE(s.selected.empty());
    for (const std::int64_t l : s.selected) {
        const Mesh m = io::read_mesh(dir / "out" / ("label_" + std::to_string(l) + ".ply"));
        const Mesh want = label_surface(s, l);
        EXPECT_TRUE(m.positions == want.positions) << l;
        EXPECT_TRUE(m.triangles == want.triangles) << l;
    }
    EXPECT_NE(label_surfaces(seg).interfaces.positions, s.interfaces.positions);
    for (const char* bad : {"-1", "abc", "nan", "inf", "2000"}) {
        EXPECT_EQ(run("labels " + (dir / "seg.nrrd").string() + " -o " + (dir / "bad").string() + " --smooth " + bad,
                      dir / "err"),
                  2)
            << bad;
        const std::string err = test::read_file(dir / "err");
        EXPECT_EQ(err.rfind("cmc33: --smooth: ", 0), 0U) << err;
        EXPECT_FALSE(fs::exists(dir / "bad")) << bad;
    }
}

TEST(LabelsCli, BadInput)
{
    const fs::path dir = test::temp_dir();
    io::write_volume(Volume(ScalarType::f32, {4, 4, 4}), dir / "f.nrrd");
    EXPECT_NE(run("labels " + (dir / "f.nrrd").string() + " -o " + (dir / "out").string(), dir / "err"), 0);
    const std::string err = test::read_file(dir / "err");
    EXPECT_NE(err.find("integer samples"), std::string::npos) << err;
    EXPECT_EQ(err.find('\n'), err.size() - 1) << err;
    EXPECT_FALSE(fs::exists(dir / "out"));
    io::write_volume(Volume(ScalarType::u8, {4, 4, 4}), dir / "u.nrrd");
    EXPECT_EQ(
        run("labels " + (dir / "u.nrrd").string() + " -o " + (dir / "o2").string() + " --labels 5-1", dir / "err"), 2);
    EXPECT_NE(run("labels " + (dir / "u.nrrd").string() + " -o " + (dir / "none" / "o3").string(), dir / "err"), 0);
    // a glTF scene where its folder does not exist: refused before any work, nothing written
    EXPECT_NE(run("labels " + (dir / "u.nrrd").string() + " -o " + (dir / "none" / "o.glb").string(), dir / "err"), 0);
    EXPECT_FALSE(fs::exists(dir / "none"));
    // and where it does: written (its contents are checked by the glTF validator, tests/io)
    Volume two(ScalarType::u8, {4, 4, 4});
    for (std::size_t i = 0; i < 32; ++i) two.bytes()[i] = std::byte{1};
    io::write_volume(two, dir / "two.nrrd");
    EXPECT_EQ(run("labels " + (dir / "two.nrrd").string() + " -o " + (dir / "o.glb").string(), dir / "err"), 0)
        << test::read_file(dir / "err");
    EXPECT_TRUE(fs::exists(dir / "o.glb"));
}

// Names and colours: a 3D Slicer .seg.nrrd's segments name the files, the scene's meshes and the
// JSON's labels; --label-names's table wins where both name a label; a bad table is refused in
// one line before any work, nothing written.
TEST(LabelsCli, NamesAndColoursFromTheSegmentationAndATable)
{
    const fs::path dir = test::temp_dir();
    const Volume seg = label_checks::random_labels(8, 3, 11, true);
    io::write_volume(seg, dir / "plain.nrrd");
    std::string nrrd = test::read_file(dir / "plain.nrrd");
    const std::size_t blank = nrrd.find("\n\n");
    ASSERT_NE(blank, std::string::npos);
    nrrd.insert(blank + 1, "Segment0_Color:=1 0.5 0\nSegment0_LabelValue:=1\nSegment0_Layer:=0\n"
                           "Segment0_Name:=Left kidney\nSegment1_LabelValue:=3\nSegment1_Name:=Tumour/mass\n");
    test::write_file(dir / "s.seg.nrrd", nrrd);
    test::write_file(dir / "lut.txt", "# value name R G B A\n3 Lesion 0 0 255 0\n");
    const std::string input = (dir / "s.seg.nrrd").string();

    // a folder given with a trailing separator is made, as without
    ASSERT_EQ(run("labels " + input + " -o " + (dir / "out").string() + "/", dir / "err"), 0)
        << test::read_file(dir / "err");
    EXPECT_TRUE(fs::exists(dir / "out" / "label_1_Left_kidney.ply"));
    EXPECT_TRUE(fs::exists(dir / "out" / "label_2.ply"));
    EXPECT_TRUE(fs::exists(dir / "out" / "label_3_Tumour_mass.ply"));

    ASSERT_EQ(std::system((std::string(CMC33_EXE) + " labels " + input + " -o " + (dir / "s.glb").string() +
                           " --label-names " + (dir / "lut.txt").string() + " --json >" + (dir / "j").string())
                              .c_str()),
              0);
    const nlohmann::json j = nlohmann::json::parse(test::read_file(dir / "j"));
    ASSERT_EQ(j["labels"].size(), 3u);
    EXPECT_EQ(j["labels"][0]["name"], "Left kidney");
    EXPECT_EQ(j["labels"][0]["color"], nlohmann::json({1.0, 0.5, 0.0}));
    EXPECT_TRUE(j["labels"][1]["name"].is_null());
    EXPECT_TRUE(j["labels"][1]["color"].is_null());
    EXPECT_EQ(j["labels"][2]["name"], "Lesion"); // the table's, over the file's
    EXPECT_EQ(j["labels"][2]["color"], nlohmann::json({0.0, 0.0, 1.0}));
    const std::string glb = test::read_file(dir / "s.glb");
    EXPECT_NE(glb.find("\"name\":\"Left kidney\""), std::string::npos);
    EXPECT_NE(glb.find("\"name\":\"label_2\""), std::string::npos);
    // sRGB 0.5 is linear 0.21404114 in glTF's baseColorFactor
    EXPECT_NE(glb.find("\"baseColorFactor\":[1,0.21404114,0,1]"), std::string::npos) << glb.substr(0, 2000);

    test::write_file(dir / "bad.txt", "1 Liver\n2 Spleen 0 0\n");
    EXPECT_EQ(run("labels " + input + " -o " + (dir / "o2").string() + " --label-names " + (dir / "bad.txt").string(),
                  dir / "err"),
              1);
    const std::string err = test::read_file(dir / "err");
    EXPECT_NE(err.find("bad.txt: line 2 \"2 Spleen 0 0\" has 4 words"), std::string::npos) << err;
    EXPECT_EQ(err.find('\n'), err.size() - 1) << err;
    EXPECT_FALSE(fs::exists(dir / "o2"));
}

} // namespace
