// Frames in volume files (volume.hpp): NRRD space directions with any signs, permutations and
// oblique axes, space origin, space, axis mins (with centers and axis maxs); MetaImage
// TransformMatrix, Offset and AnatomicalOrientation; VTK's signed SPACING; and the writers'
// round trip of all of it.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "test_support.hpp"

namespace cmc33::io {
namespace {

using test::temp_dir;
using test::write_file;

const std::string kNrrd = "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n";
const std::string kSamples = "12345678";
const std::string kMeta = "ObjectType = Image\nNDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\n";
const std::string kMetaSamples = "ElementDataFile = LOCAL\n12345678";

Volume read_text(const std::string& name, const std::string& content)
{
    const auto dir = temp_dir();
    write_file(dir / name, content);
    return read_volume(dir / name);
}

void expect_error_with(const std::string& name, const std::string& content, const std::string& words)
{
    const auto dir = temp_dir();
    write_file(dir / name, content);
    try {
        read_volume(dir / name);
        ADD_FAILURE() << name << ": no error";
    } catch (const Error& e) {
        const std::string what = e.what();
        EXPECT_EQ(what.rfind((dir / name).string(), 0), 0u) << what; // names the file first
        EXPECT_NE(what.find(words), std::string::npos) << what;
        EXPECT_EQ(what.find('\n'), std::string::npos) << what; // one line
    }
}

TEST(VolumeFrames, NrrdNegativeDirectionKeepsItsSign)
{
    // the example of issue #9: read as spacing (1, 1, 3) and a flipped x axis, not a mirror image
    const Volume v = read_text("lps.nrrd", kNrrd + "space: left-posterior-superior\n"
                                                   "space directions: (-1,0,0) (0,1,0) (0,0,3)\n"
                                                   "space origin: (10,20,30)\n\n" + kSamples);
    EXPECT_EQ(v.spacing(), (Vec3{1, 1, 3}));
    EXPECT_EQ(v.direction(), (Mat3{{{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}));
    EXPECT_EQ(v.origin(), (Vec3{10, 20, 30}));
    EXPECT_EQ(v.space(), "left-posterior-superior");
    EXPECT_LT(determinant(v.direction()), 0);
}

TEST(VolumeFrames, NrrdPermutedAndObliqueDirections)
{
    const Volume p = read_text("perm.nrrd", kNrrd + "space directions: (0,2,0) (0.5,0,0) (0,0,-1)\n\n" + kSamples);
    EXPECT_EQ(p.spacing(), (Vec3{2, 0.5, 1}));
    EXPECT_EQ(p.direction(), (Mat3{{{0, 1, 0}, {1, 0, 0}, {0, 0, -1}}}));

    const double c = std::cos(std::numbers::pi / 6), s = std::sin(std::numbers::pi / 6);
    const Volume o = read_text("rot.nrrd", kNrrd + "space directions: (" + std::to_string(2 * c) + "," +
                                               std::to_string(2 * s) + ",0) (" + std::to_string(-s) + "," +
                                               std::to_string(c) + ",0) (0,0,1)\n\n" + kSamples);
    EXPECT_NEAR(o.spacing()[0], 2, 1e-6);
    EXPECT_NEAR(o.spacing()[1], 1, 1e-6);
    EXPECT_NEAR(o.direction()[0][0], c, 1e-6);
    EXPECT_NEAR(o.direction()[1][0], s, 1e-6);
    EXPECT_NEAR(o.direction()[0][1], -s, 1e-6);
    EXPECT_NEAR(o.direction()[1][1], c, 1e-6);
}

TEST(VolumeFrames, NrrdAxisMinsPlaceTheFirstSample)
{
    // node centering: the first sample is at the axis min; cell: half a spacing inside
    const Volume a = read_text("mins.nrrd", kNrrd + "spacings: 2 1 4\naxis mins: 10 20 30\n"
                                                    "centers: cell node ???\n\n" + kSamples);
    EXPECT_EQ(a.origin(), (Vec3{11, 20, 30}));
    EXPECT_EQ(a.spacing(), (Vec3{2, 1, 4}));
    // mins and maxs without spacings: the spacing follows, a max below the min flips the axis
    const Volume b = read_text("range.nrrd", kNrrd + "axis mins: 0 5 0\naxis maxs: 3 2 8\n"
                                                     "centers: node node cell\n\n" + kSamples);
    EXPECT_EQ(b.spacing(), (Vec3{3, 3, 4}));
    EXPECT_EQ(b.direction(), (Mat3{{{1, 0, 0}, {0, -1, 0}, {0, 0, 1}}}));
    EXPECT_EQ(b.origin(), (Vec3{0, 5, 2}));
    // the space origin wins when both are given
    const Volume c = read_text("both.nrrd", kNrrd + "spacings: 1 1 1\naxis mins: 7 7 7\n"
                                                    "space origin: (1,2,3)\n\n" + kSamples);
    EXPECT_EQ(c.origin(), (Vec3{1, 2, 3}));
}

TEST(VolumeFrames, NrrdFrameErrors)
{
    expect_error_with("flat.nrrd", kNrrd + "space directions: (1,0,0) (2,0,0) (0,0,1)\n\n" + kSamples, "one plane");
    expect_error_with("zero.nrrd", kNrrd + "space directions: (1,0,0) (0,0,0) (0,0,1)\n\n" + kSamples,
                      "axis 2 (0,0,0) has no length");
    expect_error_with("none.nrrd", kNrrd + "space directions: (1,0,0) none (0,0,1)\n\n" + kSamples, "\"none\"");
    expect_error_with("mixed.nrrd",
                      kNrrd + "space directions: (1,0,0) (0,1,0) (0,0,1)\naxis mins: 0 0 0\n\n" + kSamples,
                      "both \"axis mins\"");
    expect_error_with("centers.nrrd", kNrrd + "spacings: 1 1 1\naxis mins: 0 0 0\ncenters: cell\n\n" + kSamples,
                      "3 centerings");
    expect_error_with("same.nrrd", kNrrd + "axis mins: 1 1 1\naxis maxs: 1 2 3\n\n" + kSamples, "no length");
}

TEST(VolumeFrames, MetaImageTransformMatrixIsTheAxesOneAfterTheOther)
{
    // ITK's convention: the first three numbers are the world direction of +x (i)
    const Volume v = read_text("lps.mha", kMeta + "TransformMatrix = -1 0 0 0 1 0 0 0 1\n"
                                                  "Offset = 10 20 30\nCenterOfRotation = 5 5 5\n"
                                                  "AnatomicalOrientation = RAI\nElementSpacing = 1 1 3\n" +
                                              kMetaSamples);
    EXPECT_EQ(v.spacing(), (Vec3{1, 1, 3}));
    EXPECT_EQ(v.direction(), (Mat3{{{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}));
    EXPECT_EQ(v.origin(), (Vec3{10, 20, 30})); // CenterOfRotation does not move the samples
    EXPECT_EQ(v.space(), "RAI");
    const Volume p = read_text("perm.mha", kMeta + "Rotation = 0 1 0 0 0 1 1 0 0\nPosition = 1 2 3\n" + kMetaSamples);
    EXPECT_EQ(p.direction(), (Mat3{{{0, 0, 1}, {1, 0, 0}, {0, 1, 0}}}));
    EXPECT_EQ(p.origin(), (Vec3{1, 2, 3}));
    // the same frame as the NRRD file of the issue
    const Volume n = read_text("lps.nrrd", kNrrd + "space directions: (-1,0,0) (0,1,0) (0,0,3)\n\n" + kSamples);
    EXPECT_EQ(v.direction(), n.direction());
    EXPECT_EQ(v.spacing(), n.spacing());
    expect_error_with("flat.mha", kMeta + "TransformMatrix = 1 0 0 1 0 0 0 0 1\n" + kMetaSamples, "one plane");
    expect_error_with("inf.mha", kMeta + "TransformMatrix = 1 0 0 0 1 0 0 0 inf\n" + kMetaSamples, "not finite");
}

TEST(VolumeFrames, VtkNegativeSpacingFlipsItsAxis)
{
    const Volume v = read_text("flip.vtk", "# vtk DataFile Version 3.0\nx\nASCII\nDATASET STRUCTURED_POINTS\n"
                                           "DIMENSIONS 2 2 2\nSPACING 1 -2 3\nORIGIN 0 0 0\nPOINT_DATA 8\n"
                                           "SCALARS s unsigned_char 1\nLOOKUP_TABLE default\n1 2 3 4 5 6 7 8\n");
    EXPECT_EQ(v.spacing(), (Vec3{1, 2, 3}));
    EXPECT_EQ(v.direction(), (Mat3{{{1, 0, 0}, {0, -1, 0}, {0, 0, 1}}}));
}

TEST(VolumeFrames, WritersKeepTheFrame)
{
    const auto dir = temp_dir();
    const double c = std::cos(0.4), s = std::sin(0.4);
    Volume oblique(ScalarType::i16, {3, 2, 2}, {0.5, 1.25, 3}, {-4, 5.5, 1e-3});
    oblique.set_direction(Mat3{{{c, 0, -s}, {0, -1, 0}, {s, 0, c}}}); // a rotation times a flip
    oblique.set_space("left-posterior-superior");
    for (const char* name : {"o.nrrd", "o.nhdr", "o.mhd", "o.mha"}) {
        SCOPED_TRACE(name);
        write_volume(oblique, dir / name);
        const Volume back = read_volume(dir / name);
        for (std::size_t a = 0; a < 3; ++a) {
            EXPECT_NEAR(back.spacing()[a], oblique.spacing()[a], 1e-15);
            EXPECT_EQ(back.origin()[a], oblique.origin()[a]);
            for (std::size_t r = 0; r < 3; ++r) EXPECT_NEAR(back.direction()[r][a], oblique.direction()[r][a], 1e-15);
        }
    }
    EXPECT_EQ(read_volume(dir / "o.nrrd").space(), "left-posterior-superior");
    // a flipped axis-aligned frame survives exactly, VTK included (as a negative SPACING)
    Volume flipped(ScalarType::u8, {2, 2, 2}, {1, 2, 3}, {4, 5, 6});
    flipped.set_direction(Mat3{{{-1, 0, 0}, {0, 1, 0}, {0, 0, -1}}});
    flipped.set_space("RAI");
    for (const char* name : {"f.nrrd", "f.mhd", "f.vtk"}) {
        SCOPED_TRACE(name);
        write_volume(flipped, dir / name);
        const Volume back = read_volume(dir / name);
        EXPECT_EQ(back.spacing(), flipped.spacing());
        EXPECT_EQ(back.direction(), flipped.direction());
        EXPECT_EQ(back.origin(), flipped.origin());
    }
    EXPECT_EQ(read_volume(dir / "f.mhd").space(), "RAI");
    // VTK cannot hold a rotation: refused, naming the file and the formats that can
    try {
        write_volume(oblique, dir / "o.vtk");
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("o.vtk"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(".nrrd or .mhd"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(std::filesystem::exists(dir / "o.vtk"));
}

} // namespace
} // namespace cmc33::io
