// A label map's names and colours: colour tables (3D Slicer, FreeSurfer, ITK-SNAP lines) and a
// 3D Slicer segmentation's NRRD header, read as those tools write them; anything else refused in
// one line that names the table and the line.

#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/io.hpp"

namespace {

using namespace cmc33;

std::string message_of(const std::string& text, bool table)
{
    try {
        if (table) {
            io::parse_colour_table(text, "t.txt");
        } else {
            io::parse_segment_names(text, "s.seg.nrrd");
        }
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(LabelNames, SlicerAndFreeSurferTables)
{
    const std::vector<io::LabelName> t = io::parse_colour_table("# Color table file\r\n"
                                                                "# 3 values\r\n"
                                                                "\r\n"
                                                                "0 Background 0 0 0 0\r\n"
                                                                "  17\tLeft-Hippocampus  220 216 20 0\r\n"
                                                                "2 \"Left kidney\" 255 0 51\r\n"
                                                                "-4 below_zero\n"
                                                                "300 x 1 2 3 255",
                                                                "t.txt");
    ASSERT_EQ(t.size(), 5u);
    EXPECT_EQ(t[0].value, 0);
    EXPECT_EQ(t[0].name, "Background");
    EXPECT_EQ(t[1].value, 17);
    EXPECT_EQ(t[1].name, "Left-Hippocampus");
    ASSERT_TRUE(t[1].colour);
    EXPECT_FLOAT_EQ((*t[1].colour)[0], 220.0f / 255);
    EXPECT_FLOAT_EQ((*t[1].colour)[2], 20.0f / 255);
    EXPECT_EQ(t[2].name, "Left kidney");
    EXPECT_FLOAT_EQ((*t[2].colour)[1], 0.0f);
    EXPECT_FLOAT_EQ((*t[2].colour)[2], 0.2f);
    EXPECT_EQ(t[3].value, -4);
    EXPECT_FALSE(t[3].colour); // a name alone
    EXPECT_EQ(t[4].value, 300);
}

TEST(LabelNames, ItkSnapDescriptions)
{
    const std::vector<io::LabelName> t =
        io::parse_colour_table("################################################\n"
                               "# ITK-SnAP Label Description File\n"
                               "# Columns = IDX -R- -G- -B- -A-- VIS MSH LABEL\n"
                               "    0     0    0    0        0  0  0    \"Clear Label\"\n"
                               "    5   255  128    0      0.5  1  1    \"grey matter\"\n",
                               "snap.txt");
    ASSERT_EQ(t.size(), 2u);
    EXPECT_EQ(t[1].value, 5);
    EXPECT_EQ(t[1].name, "grey matter");
    ASSERT_TRUE(t[1].colour);
    EXPECT_FLOAT_EQ((*t[1].colour)[0], 1.0f);
    EXPECT_FLOAT_EQ((*t[1].colour)[1], 128.0f / 255);
}

TEST(LabelNames, TablesThatAreNotOneAreRefusedInOneLine)
{
    const struct {
        const char* text;
        const char* says;
    } cases[] = {
        {"1 Liver 300 0 0\n", "line 1 \"1 Liver 300 0 0\" has a colour channel that is not an integer from 0 to 255"},
        {"# c\n1 Liver 0 0\n", "line 2 \"1 Liver 0 0\" has 4 words"},
        {"liver 1\n", "does not start with an integer label value"},
        {"1 \"Liver 1 2 3\n", "has a quote that is not closed"},
        {"1 Liver\n2 Spleen\n1 Other\n", "label 1 is named twice (lines 1 and 3)"},
        {"1 \"\"\n", "has an empty name"},
        {"1 Liver 1 2 3 256\n", "has an alpha that is not an integer"},
        {"1 2 3 4 7 1 1 \"x\"\n", "has an opacity that is not a number from 0 to 1"},
        {"# only comments\n\n", "no label in the colour table"},
        {"99999999999999999999 x\n", "does not start with an integer label value"},
    };
    for (const auto& c : cases) {
        const std::string m = message_of(c.text, true);
        EXPECT_EQ(m.rfind("t.txt: ", 0), 0u) << m;
        EXPECT_NE(m.find(c.says), std::string::npos) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
}

TEST(LabelNames, SlicerSegmentationHeader)
{
    const std::string header = "NRRD0004\n"
                               "type: unsigned char\n"
                               "dimension: 3\n"
                               "Segment1_Name:=Tumour\n"
                               "Segment1_LabelValue:=7\n"
                               "Segment1_Color:=0.5 1 0\n"
                               "Segment0_Color:=0.694118 0.478431 0.396078\n"
                               "Segment0_LabelValue:=1\n"
                               "Segment0_Layer:=0\n"
                               "Segment0_Name:=Left kidney\\nupper pole\n"
                               "Segment2_Name:=overlaps another\n"
                               "Segment2_LabelValue:=1\n"
                               "Segment2_Layer:=1\n"
                               "Segment3_Name:=no value\n"
                               "Segmentation_ContainedRepresentationNames:=Binary labelmap|\n"
                               "\n"
                               "Segment9_Name:=in the samples, not the header\n"
                               "Segment9_LabelValue:=9\n";
    const std::vector<io::LabelName> n = io::parse_segment_names(header, "s.seg.nrrd");
    ASSERT_EQ(n.size(), 2u); // the segment of layer 1, the one without a value and the samples' bytes name nothing
    EXPECT_EQ(n[0].value, 1);
    EXPECT_EQ(n[0].name, "Left kidney\nupper pole");
    ASSERT_TRUE(n[0].colour);
    EXPECT_FLOAT_EQ((*n[0].colour)[0], 0.694118f);
    EXPECT_EQ(n[1].value, 7);
    EXPECT_EQ(n[1].name, "Tumour");
    EXPECT_FLOAT_EQ((*n[1].colour)[1], 1.0f);
    EXPECT_TRUE(io::parse_segment_names("P5\n2 2\n", "x.pgm").empty());
    EXPECT_TRUE(io::parse_segment_names("NRRD0004\ntype: float\n\n", "plain.nrrd").empty());
}

TEST(LabelNames, SegmentFieldsThatAreNotSlicersAreRefusedInOneLine)
{
    const struct {
        const char* text;
        const char* says;
    } cases[] = {
        {"NRRD0004\nSegment0_LabelValue:=one\n", "line 2 \"Segment0_LabelValue:=one\" is not an integer label value"},
        {"NRRD0004\nSegment0_Color:=0.5 0.5\n", "is not a colour of three numbers from 0 to 1"},
        {"NRRD0004\nSegment0_Color:=0.5 0.5 1.5\n", "is not a colour of three numbers from 0 to 1"},
        {"NRRD0004\nSegment0_Layer:=-1\n", "is not a layer number from 0"},
        {"NRRD0004\nSegment0_LabelValue:=2\nSegment4_LabelValue:=2\n",
         "segments 0 and 4 both have label value 2 in layer 0"},
    };
    for (const auto& c : cases) {
        const std::string m = message_of(c.text, false);
        EXPECT_EQ(m.rfind("s.seg.nrrd: ", 0), 0u) << m;
        EXPECT_NE(m.find(c.says), std::string::npos) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
}

} // namespace
