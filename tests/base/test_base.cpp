// The base part (src/base): the sample buffers and their block cache (buffer.cpp), the volume
// that owns samples and its frame (volume.hpp), and errors. The extractor's use of the buffers is
// in tests/core/test_extract.cpp (ReusedMeshBlocksHoldNoTraceOfTheirLastMesh).

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <string>

#include "cmc33/error.hpp"
#include "cmc33/mesh.hpp"
#include "cmc33/volume.hpp"
#include "portability.hpp"
#include "test_support.hpp"

namespace {

using cmc33::Error;
using cmc33::Index3;
using cmc33::Mat3;
using cmc33::ScalarType;
using cmc33::Status;
using cmc33::Volume;

/// The status of the Error that f throws, or nothing if it throws none.
template <class F> std::string status_of(F&& f)
{
    try {
        f();
    } catch (const Error& e) {
        return std::to_string(static_cast<int>(e.status())) + ": " + e.what();
    }
    return "no error";
}

} // namespace

TEST(Volume, HoldsZeroedSamplesOfItsTypeAndSize)
{
    const Volume v(ScalarType::i16, {3, 4, 5}, {0.5, 1, 2}, {-1, 0, 7});
    EXPECT_EQ(v.type(), ScalarType::i16);
    EXPECT_EQ(v.dims(), (Index3{3, 4, 5}));
    EXPECT_EQ(v.sample_count(), 60);
    EXPECT_EQ(v.byte_size(), 120u);
    const std::int16_t* s = v.samples<std::int16_t>();
    for (std::int64_t i = 0; i < v.sample_count(); ++i) EXPECT_EQ(s[i], 0) << i;
    EXPECT_THROW((void)v.samples<std::uint16_t>(), Error); // the stored type only
    const auto view = v.view<std::int16_t>();
    EXPECT_EQ(view.strides, (Index3{1, 3, 12})); // x fastest
    EXPECT_EQ(view.spacing, v.spacing());
    EXPECT_EQ(view.origin, v.origin());
}

TEST(Volume, SizesThatAreNotPositiveOrOverflowAreRefused)
{
    EXPECT_NE(status_of([] { Volume(ScalarType::u8, {0, 4, 4}); }).find("not positive"), std::string::npos);
    EXPECT_NE(status_of([] { Volume(ScalarType::u8, {4, -1, 4}); }).find("not positive"), std::string::npos);
    const std::int64_t big = std::int64_t{1} << 40;
    EXPECT_NE(status_of([&] { Volume(ScalarType::f64, {big, big, 4}); }).find("overflows"), std::string::npos);
    EXPECT_NE(status_of([] { Volume(ScalarType::u8, {2, 2, 2}, {1, 1, 1}, {0, 0, 0}, nullptr); }).find("null buffer"),
              std::string::npos);
}

TEST(Volume, GivenSamplesAreKept)
{
    auto bytes = std::make_unique<std::byte[]>(8);
    bytes[5] = std::byte{42};
    const std::byte* at = bytes.get();
    const Volume v(ScalarType::u8, {2, 2, 2}, {1, 1, 1}, {0, 0, 0}, std::move(bytes));
    EXPECT_EQ(v.bytes(), at);
    EXPECT_EQ(v.view<std::uint8_t>()(1, 0, 1), 42); // x + 2 * (y + 2 * z)
}

TEST(Frame, MatrixInverseTransposeAndDiagonal)
{
    // an oblique frame: a rotation about z by 30 degrees, spacings 0.5, 2 and 3
    const double c = std::sqrt(3.0) / 2, s = 0.5;
    const Mat3 direction{{{c, -s, 0}, {s, c, 0}, {0, 0, 1}}};
    const Mat3 m = cmc33::frame_matrix({0.5, 2, 3}, direction);
    EXPECT_DOUBLE_EQ(m[0][0], 0.5 * c);
    EXPECT_DOUBLE_EQ(m[0][1], -2 * s);
    EXPECT_DOUBLE_EQ(m[2][2], 3);
    EXPECT_NEAR(cmc33::determinant(m), 0.5 * 2 * 3, 1e-12);
    // (M^-1)^T M^T is the identity
    const Mat3 it = cmc33::inverse_transpose(m);
    for (std::size_t r = 0; r < 3; ++r)
        for (std::size_t col = 0; col < 3; ++col) {
            double sum = 0;
            for (std::size_t k = 0; k < 3; ++k) sum += it[r][k] * m[col][k];
            EXPECT_NEAR(sum, r == col ? 1.0 : 0.0, 1e-12) << r << "," << col;
        }
    EXPECT_FALSE(cmc33::is_diagonal(m));
    EXPECT_TRUE(cmc33::is_diagonal(cmc33::frame_matrix({1, -2, 3}, cmc33::kIdentity3)));
}

TEST(Buffer, BlocksPastSixteenMiBAreKeptForTheNextOfTheirSizeClass)
{
    // src/base/buffer.cpp: a block of more than 16 MiB is kept when freed and given to the next
    // request of its size class (the next eighth of its power of two); a request of another
    // class releases the kept blocks and gets a new one
    using cmc33::detail::allocate_buffer;
    using cmc33::detail::deallocate_buffer;
    constexpr std::size_t kMiB = std::size_t{1} << 20;
    void* first = allocate_buffer(40 * kMiB);
    static_cast<char*>(first)[40 * kMiB - 1] = 1;
    deallocate_buffer(first, 40 * kMiB);
    void* again = allocate_buffer(37 * kMiB); // the same class (36 to 40 MiB)
    EXPECT_EQ(again, first);
    void* other = allocate_buffer(41 * kMiB); // the next class, while `again` is in use
    EXPECT_NE(other, again);
    static_cast<char*>(other)[41 * kMiB - 1] = 2;
    deallocate_buffer(again, 37 * kMiB);
    deallocate_buffer(other, 41 * kMiB);
    void* both[2] = {allocate_buffer(38 * kMiB), allocate_buffer(43 * kMiB)};
    EXPECT_EQ(both[0], first);
    EXPECT_EQ(both[1], other);
    deallocate_buffer(both[0], 38 * kMiB);
    deallocate_buffer(both[1], 43 * kMiB);
    void* large = allocate_buffer(100 * kMiB); // no class kept: both released, a new block
    EXPECT_NE(large, nullptr);
    static_cast<char*>(large)[100 * kMiB - 1] = 3;
    deallocate_buffer(large, 100 * kMiB);
    EXPECT_EQ(allocate_buffer(100 * kMiB), large);
    deallocate_buffer(large, 100 * kMiB);
}

TEST(Buffer, ABalloonThatReportsFreeMemoryIsFoundInSysfs)
{
    // portability.hpp: a virtio device of id 0x0005 (the balloon) whose features (one '0' or '1'
    // per bit) have bit 5 (free page reporting) set; in a fake sysfs tree
    namespace fs = std::filesystem;
    using cmc33::detail::balloon_reports_free_memory_in;
    const fs::path root = cmc33::test::temp_dir() / "devices";
    EXPECT_FALSE(balloon_reports_free_memory_in(root.string() + "/")); // no such directory
    const auto device = [&](const char* name, const char* id, const char* features) {
        fs::create_directories(root / name);
        std::ofstream(root / name / "device") << id << "\n";
        std::ofstream(root / name / "features") << features << "\n";
    };
    device("virtio0", "0x0002", "0110010100000000000000000000000010000000"); // a block device
    EXPECT_FALSE(balloon_reports_free_memory_in(root.string() + "/"));
    device("virtio1", "0x0005", "0110000100000000000000000000000010000000"); // a balloon, no reporting
    EXPECT_FALSE(balloon_reports_free_memory_in(root.string() + "/"));
    device("virtio1", "0x0005", "01100");
    EXPECT_FALSE(balloon_reports_free_memory_in(root.string() + "/"));
    device("virtio1", "0x0005", "0110010100000000000000000000000010000000"); // reporting
    EXPECT_TRUE(balloon_reports_free_memory_in(root.string() + "/"));
}

TEST(Buffer, BlocksTakeHugePagesAsAdvised)
{
    // src/base/buffer.cpp: blocks of 1 MiB and more are advised for huge pages unless
    // set_huge_page_advice(false) (the CLI's choice where the balloon hands free memory back to
    // the host). Seen in /proc/self/smaps (THPeligible) when the kernel's THP mode is "madvise",
    // where the advice decides.
    std::string mode;
    std::getline(std::ifstream("/sys/kernel/mm/transparent_hugepage/enabled"), mode);
    if (mode.find("[madvise]") == std::string::npos) GTEST_SKIP() << "THP mode is not madvise: " << mode;
    const auto eligible = [](const void* p) {
        std::ifstream smaps("/proc/self/smaps");
        const auto at = reinterpret_cast<std::uintptr_t>(p);
        bool inside = false;
        for (std::string line; std::getline(smaps, line);) {
            unsigned long lo = 0, hi = 0;
            if (std::sscanf(line.c_str(), "%lx-%lx ", &lo, &hi) == 2) { // a mapping's header line
                inside = lo <= at && at < hi;
            } else if (inside && line.rfind("THPeligible:", 0) == 0) {
                return line.find('1') != std::string::npos;
            }
        }
        ADD_FAILURE() << "no THPeligible line for " << p;
        return false;
    };
    constexpr std::size_t kMiB = std::size_t{1} << 20;
    EXPECT_TRUE(cmc33::huge_page_advice()); // the library's default
    for (const bool advised : {false, true}) {
        cmc33::set_huge_page_advice(advised);
        cmc33::detail::release_kept_buffers(); // new blocks, not ones kept under the other advice
        for (const std::size_t bytes : {3 * kMiB, 28 * kMiB, 36 * kMiB}) { // up to 16 MiB, past it, past 32 MiB
            void* block = cmc33::detail::allocate_buffer(bytes);
            EXPECT_EQ(eligible(block), advised) << bytes << " bytes";
            cmc33::detail::deallocate_buffer(block, bytes);
        }
    }
}

