// Replays the committed fuzz corpus (fuzz/corpus/<target>/) through the fuzz targets' own
// harnesses: every input must be read or refused with a cmc33::Error whose message is one line
// starting with the label; the harness aborts on anything else (fuzz/fuzz_common.hpp).

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include "test_support.hpp"

#define CMC33_FUZZ_HARNESS(target) \
    extern "C" int cmc33_fuzz_##target(const std::uint8_t* data, std::size_t size);
CMC33_FUZZ_HARNESS(nrrd)
CMC33_FUZZ_HARNESS(nhdr)
CMC33_FUZZ_HARNESS(mha)
CMC33_FUZZ_HARNESS(mhd)
CMC33_FUZZ_HARNESS(vtk)
CMC33_FUZZ_HARNESS(raw)
CMC33_FUZZ_HARNESS(ply)
CMC33_FUZZ_HARNESS(obj)
CMC33_FUZZ_HARNESS(stl)
CMC33_FUZZ_HARNESS(off)
CMC33_FUZZ_HARNESS(dicom)
CMC33_FUZZ_HARNESS(tiff)
CMC33_FUZZ_HARNESS(nifti)
CMC33_FUZZ_HARNESS(npy)
CMC33_FUZZ_HARNESS(vti)
CMC33_FUZZ_HARNESS(labelnames)
#undef CMC33_FUZZ_HARNESS

namespace {

using Harness = int (*)(const std::uint8_t*, std::size_t);

void replay(const std::string& target, Harness harness)
{
    const std::filesystem::path folder = std::filesystem::path(CMC33_FUZZ_CORPUS) / target;
    ASSERT_TRUE(std::filesystem::is_directory(folder)) << folder;
    std::size_t inputs = 0;
    for (const auto& entry : std::filesystem::directory_iterator(folder)) {
        SCOPED_TRACE(entry.path().string());
        const std::string bytes = cmc33::test::read_file(entry.path());
        EXPECT_EQ(harness(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()), 0);
        ++inputs;
    }
    EXPECT_GE(inputs, 3u) << "a seed corpus holds at least three files";
}

TEST(FuzzCorpus, Nrrd) { replay("nrrd", cmc33_fuzz_nrrd); }
TEST(FuzzCorpus, Nhdr) { replay("nhdr", cmc33_fuzz_nhdr); }
TEST(FuzzCorpus, Mha) { replay("mha", cmc33_fuzz_mha); }
TEST(FuzzCorpus, Mhd) { replay("mhd", cmc33_fuzz_mhd); }
TEST(FuzzCorpus, Vtk) { replay("vtk", cmc33_fuzz_vtk); }
TEST(FuzzCorpus, Raw) { replay("raw", cmc33_fuzz_raw); }
TEST(FuzzCorpus, Ply) { replay("ply", cmc33_fuzz_ply); }
TEST(FuzzCorpus, Obj) { replay("obj", cmc33_fuzz_obj); }
TEST(FuzzCorpus, Stl) { replay("stl", cmc33_fuzz_stl); }
TEST(FuzzCorpus, Off) { replay("off", cmc33_fuzz_off); }
TEST(FuzzCorpus, Dicom) { replay("dicom", cmc33_fuzz_dicom); }
TEST(FuzzCorpus, Tiff) { replay("tiff", cmc33_fuzz_tiff); }
TEST(FuzzCorpus, Nifti) { replay("nifti", cmc33_fuzz_nifti); }
TEST(FuzzCorpus, Npy) { replay("npy", cmc33_fuzz_npy); }
TEST(FuzzCorpus, Vti) { replay("vti", cmc33_fuzz_vti); }
TEST(FuzzCorpus, LabelNames) { replay("labelnames", cmc33_fuzz_labelnames); }

} // namespace
