// cmc33 extract far from the origin (scanner or map coordinates): where 32-bit floats cannot keep
// the mesh embedded it is made at the origin and written as origin + position in double precision
// (--positions auto, the default); STL (floats only), --positions float and --memory-limit refuse
// such volumes before any work, leaving no file.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "cli_run.hpp"
#include "test_support.hpp"

namespace {

namespace fs = std::filesystem;
using cmc33::test::cli::quote;
using cmc33::test::cli::run;

/// A 12^3 uint8 NRRD of two touching balls, at `origin` with cells of `spacing`.
fs::path write_balls(const fs::path& dir, const std::string& origin, double spacing)
{
    std::string samples;
    for (int k = 0; k < 12; ++k)
        for (int j = 0; j < 12; ++j)
            for (int i = 0; i < 12; ++i) {
                const double a = std::hypot(i - 4.3, j - 5.1, k - 5.6), b = std::hypot(i - 7.9, j - 6.2, k - 5.2);
                samples += static_cast<char>(static_cast<unsigned char>(std::min(255.0, 40 * std::min(a, b))));
            }
    std::ostringstream h;
    h << "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 12 12 12\nspace: left-posterior-superior\n"
      << "space directions: (" << spacing << ",0,0) (0," << spacing << ",0) (0,0," << spacing << ")\n"
      << "space origin: (" << origin << ")\nencoding: raw\n\n";
    const fs::path path = dir / "balls.nrrd";
    cmc33::test::write_file(path, h.str() + samples);
    return path;
}

struct Ply {
    std::string header;
    std::vector<double> positions; ///< 3 per vertex
};

/// The positions of a binary PLY that cmc33 wrote (float or double x y z first, then the faces).
Ply read_positions(const fs::path& path)
{
    const std::string bytes = cmc33::test::read_file(path);
    const std::size_t end = bytes.find("end_header\n");
    Ply ply{bytes.substr(0, end + 11), {}};
    const std::size_t n = std::stoul(ply.header.substr(ply.header.find("element vertex ") + 15));
    const bool wide = ply.header.find("property double x") != std::string::npos;
    const bool normals = ply.header.find("property float nx") != std::string::npos;
    const std::size_t stride = (wide ? 24 : 12) + (normals ? 12 : 0);
    for (std::size_t v = 0; v < n; ++v) {
        const char* p = bytes.data() + end + 11 + v * stride;
        for (int c = 0; c < 3; ++c) {
            if (wide) {
                double x;
                std::memcpy(&x, p + 8 * c, 8);
                ply.positions.push_back(x);
            } else {
                float x;
                std::memcpy(&x, p + 4 * c, 4);
                ply.positions.push_back(static_cast<double>(x));
            }
        }
    }
    return ply;
}

class FarFromTheOrigin : public ::testing::Test {
protected:
    void SetUp() override { dir_ = cmc33::test::temp_dir(); }
    fs::path dir_;
};

TEST_F(FarFromTheOrigin, DoublePositionsKeepTheMeshEmbeddedWhereTheVolumeLies)
{
    // 4e6 with unit cells: floats resolve a quarter of a cell there
    const fs::path far = write_balls(dir_, "500000,4000000,0", 1);
    const fs::path out = dir_ / "far.ply";
    const auto e = run("extract " + quote(far.string()) + " --iso 100 --json -o " + quote(out.string()));
    ASSERT_EQ(e.code, 0) << e.err;
    const nlohmann::json j = cmc33::test::cli::parse(e);
    EXPECT_EQ(j["positions"], "double");
    EXPECT_TRUE(j["geometry"]["embedded"].get<bool>()) << e.out;
    const Ply ply = read_positions(out);
    EXPECT_NE(ply.header.find("property double x\nproperty double y\nproperty double z\n"), std::string::npos);
    // every vertex at its own position, inside the volume's box in world space
    std::set<std::tuple<double, double, double>> distinct;
    for (std::size_t v = 0; v < ply.positions.size() / 3; ++v) {
        const double x = ply.positions[3 * v], y = ply.positions[3 * v + 1], z = ply.positions[3 * v + 2];
        EXPECT_TRUE(x >= 500000 && x <= 500011 && y >= 4000000 && y <= 4000011 && z >= 0 && z <= 11) << x << " " << y << " " << z;
        distinct.insert({x, y, z});
    }
    EXPECT_EQ(distinct.size(), ply.positions.size() / 3);

    // the same mesh as at the origin, moved by the origin exactly
    const fs::path near = dir_ / "near.nrrd";
    fs::rename(write_balls(dir_, "0,0,0", 1), near);
    const fs::path near_out = dir_ / "near.ply";
    ASSERT_EQ(run("extract " + quote(near.string()) + " --iso 100 -o " + quote(near_out.string())).code, 0);
    const Ply at_zero = read_positions(near_out);
    ASSERT_EQ(at_zero.positions.size(), ply.positions.size());
    const double origin[3] = {500000, 4000000, 0};
    for (std::size_t i = 0; i < ply.positions.size(); ++i) ASSERT_EQ(ply.positions[i], origin[i % 3] + at_zero.positions[i]);
}

TEST_F(FarFromTheOrigin, TextFormatsWriteEnoughDigits)
{
    const fs::path far = write_balls(dir_, "1000000,1000000,1000000", 0.01);
    for (const char* ext : {".obj", ".off"}) {
        const fs::path out = dir_ / (std::string("far") + ext);
        const auto r = run("extract " + quote(far.string()) + " --iso 100 -o " + quote(out.string()));
        ASSERT_EQ(r.code, 0) << r.err;
        EXPECT_NE(r.out.find(", embedded"), std::string::npos) << r.out;
        // the vertices read back as distinct doubles
        std::istringstream in(cmc33::test::read_file(out));
        std::string line;
        std::set<std::tuple<double, double, double>> distinct;
        std::size_t count = 0;
        bool header = std::string(ext) == ".off";
        std::size_t vertices = 0;
        while (std::getline(in, line)) {
            std::istringstream l(line);
            if (std::string(ext) == ".obj") {
                std::string key;
                l >> key;
                if (key != "v") continue;
            } else if (header) {
                if (line == "OFF") continue;
                l >> vertices;
                header = false;
                continue;
            } else if (count == vertices) {
                break;
            }
            double x, y, z;
            l >> x >> y >> z;
            ASSERT_TRUE(l) << line;
            distinct.insert({x, y, z});
            ++count;
        }
        EXPECT_GT(count, 100u);
        EXPECT_EQ(distinct.size(), count) << ext;
    }
}

TEST_F(FarFromTheOrigin, FloatsOnlyOutputsAreRefusedBeforeAnyWork)
{
    const fs::path far = write_balls(dir_, "500000,4000000,0", 1);
    const fs::path stl = dir_ / "far.stl", ply = dir_ / "far.ply";
    const auto s = run("extract " + quote(far.string()) + " --iso 100 -o " + quote(stl.string()));
    EXPECT_EQ(s.code, 1);
    EXPECT_NE(s.err.find("STL stores 32-bit floats"), std::string::npos) << s.err;
    EXPECT_NE(s.err.find(far.string()), std::string::npos) << s.err;
    EXPECT_FALSE(fs::exists(stl));
    const auto f = run("extract " + quote(far.string()) + " --iso 100 --positions float -o " + quote(ply.string()));
    EXPECT_EQ(f.code, 1);
    EXPECT_NE(f.err.find("too few to keep the mesh embedded"), std::string::npos) << f.err;
    const auto m = run("extract " + quote(far.string()) + " --iso 100 --memory-limit 64M -o " + quote(ply.string()));
    EXPECT_EQ(m.code, 1);
    EXPECT_NE(m.err.find("--memory-limit writes 32-bit floats"), std::string::npos) << m.err;
    EXPECT_FALSE(fs::exists(ply));
    // asked for: a usage conflict
    const auto d = run("extract " + quote(far.string()) + " --iso 100 --positions double -o " + quote(stl.string()));
    EXPECT_EQ(d.code, 2) << d.err;
    EXPECT_FALSE(fs::exists(stl));
}

TEST_F(FarFromTheOrigin, NearTheOriginFloatsStayUnlessDoubleIsAsked)
{
    const fs::path near = write_balls(dir_, "-120.5,-80,-1000", 0.5);
    const fs::path a = dir_ / "a.ply", b = dir_ / "b.ply";
    const auto r = run("extract " + quote(near.string()) + " --iso 100 --json -o " + quote(a.string()));
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(cmc33::test::cli::parse(r)["positions"], "float");
    EXPECT_NE(cmc33::test::read_file(a).find("property float x"), std::string::npos);
    ASSERT_EQ(run("extract " + quote(near.string()) + " --iso 100 --positions double -o " + quote(b.string())).code, 0);
    const Ply fa = read_positions(a), fb = read_positions(b);
    EXPECT_NE(fb.header.find("property double x"), std::string::npos);
    ASSERT_EQ(fa.positions.size(), fb.positions.size());
    // the same vertices, but crossings next to a sample: floats far from 0 need those kept more
    // units in the last place from it (placement.hpp's delta grows with the largest coordinate)
    for (std::size_t i = 0; i < fa.positions.size(); ++i) EXPECT_NEAR(fa.positions[i], fb.positions[i], 0.5 / 64);
}

} // namespace
