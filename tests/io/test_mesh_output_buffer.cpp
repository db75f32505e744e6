// OutputBuffer, the text writers' buffer: integers of every width and sign as printf writes them,
// and records of any size (small ones filled in place across block boundaries, ones larger than
// the block filled alone and written through), byte for byte.

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "mesh_formats.hpp"

namespace {

using cmc33::io::detail::OutputBuffer;

std::string printf_text(const char* format, auto value)
{
    char text[64];
    std::snprintf(text, sizeof text, format, value);
    return text;
}

TEST(MeshOutputBuffer, IntegersAsPrintfWritesThem)
{
    const std::vector<long long> signed_values{0,
                                               1,
                                               -1,
                                               9,
                                               -10,
                                               std::numeric_limits<std::int32_t>::min(),
                                               std::numeric_limits<std::int32_t>::max(),
                                               std::numeric_limits<std::int64_t>::min(),
                                               std::numeric_limits<std::int64_t>::min() + 1,
                                               std::numeric_limits<std::int64_t>::max()};
    const std::vector<unsigned long long> unsigned_values{0, 1, 4294967295ull, 4294967296ull,
                                                          std::numeric_limits<std::uint64_t>::max()};
    std::ostringstream out;
    std::string expected;
    {
        OutputBuffer o(out);
        for (const long long v : signed_values) {
            o.integer(static_cast<std::int64_t>(v));
            o.character(' ');
            expected += printf_text("%lld", v) + " ";
        }
        for (const unsigned long long v : unsigned_values) {
            o.integer(static_cast<std::uint64_t>(v));
            o.character(' ');
            expected += printf_text("%llu", v) + " ";
        }
        // narrower types keep their sign: int32 -1 is "-1", uint32 max is "4294967295"
        o.integer(std::int32_t{-1});
        o.integer(std::uint32_t{4294967295u});
        o.integer(std::int16_t{-32768});
        o.integer(std::size_t{7});
        expected += "-14294967295-327687";
        o.flush();
    }
    EXPECT_EQ(out.str(), expected);
}

TEST(MeshOutputBuffer, IntegersAcrossBlocksLoseNothing)
{
    // more text than a block (256 KiB): every value's digits whole, in order
    std::ostringstream out;
    std::string expected;
    {
        OutputBuffer o(out);
        for (std::int64_t v = -100000; v < 100000; v += 3) {
            o.integer(v * 1000003);
            o.character('\n');
            expected += printf_text("%lld", static_cast<long long>(v * 1000003)) + "\n";
        }
        o.flush();
    }
    ASSERT_GT(expected.size(), std::size_t{1} << 19);
    EXPECT_EQ(out.str(), expected);
}

/// `count` records of `size` bytes through OutputBuffer::records, each byte a function of its
/// record and position; the bytes the stream got.
std::string write_records(std::size_t lead, std::size_t count, std::size_t size, std::vector<std::size_t>* batches = nullptr)
{
    std::ostringstream out;
    OutputBuffer o(out);
    for (std::size_t i = 0; i < lead; ++i) o.character('L');
    o.records(count, size, [&](char* dst, std::size_t first, std::size_t n) {
        if (batches) batches->push_back(n);
        for (std::size_t r = first; r < first + n; ++r)
            for (std::size_t k = 0; k < size; ++k) *dst++ = static_cast<char>((r * 31 + k * 7) & 0xff);
    });
    o.character('E');
    o.flush();
    return out.str();
}

std::string expected_records(std::size_t lead, std::size_t count, std::size_t size)
{
    std::string s(lead, 'L');
    for (std::size_t r = 0; r < count; ++r)
        for (std::size_t k = 0; k < size; ++k) s += static_cast<char>((r * 31 + k * 7) & 0xff);
    return s + "E";
}

TEST(MeshOutputBuffer, RecordsOfAnySize)
{
    struct Case {
        std::size_t lead, count, size;
    };
    // small records crossing block ends; records just under, at and over the block's 256 KiB;
    // far larger ones; and none
    const std::size_t block = std::size_t{1} << 18;
    const std::vector<Case> cases = {{0, 100000, 13},        {5, 100000, 33},       {1, 3, block - 1}, {0, 3, block},
                                     {7, 3, block + 1},      {3, 2, 3 * block + 5}, {0, 0, 4 * block}, {2, 5, 4097},
                                     {block - 1, 2, block + 9}};
    for (const Case& c : cases) {
        SCOPED_TRACE(testing::Message() << "lead " << c.lead << ", " << c.count << " records of " << c.size);
        const std::string bytes = write_records(c.lead, c.count, c.size);
        const std::string expected = expected_records(c.lead, c.count, c.size);
        ASSERT_EQ(bytes.size(), expected.size());
        EXPECT_TRUE(bytes == expected);
    }
    // a record larger than the block is filled alone
    std::vector<std::size_t> batches;
    write_records(0, 4, block + 1, &batches);
    EXPECT_EQ(batches, std::vector<std::size_t>(4, 1));
    // records of no bytes write nothing and never call fill
    batches.clear();
    EXPECT_EQ(write_records(1, 10, 0, &batches), "LE");
    EXPECT_TRUE(batches.empty());
}

} // namespace
