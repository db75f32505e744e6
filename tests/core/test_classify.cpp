// classify_row (src/core/classify.hpp): the bitmask of above-flags of a sample row must be the sign
// rule double(v) >= iso sample by sample, for every type, for the vector path this CPU takes and
// for the portable one, at every row length around the 64-sample words and vector widths, and at
// isovalues on, between and beyond the samples. The same pass reports non-finite samples and the
// largest |sample|.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "classify.hpp"

namespace {

using cmc33::detail::classify_row;
using cmc33::detail::classify_row_portable;
using cmc33::detail::RowScan;
using cmc33::detail::RowSigns;
using cmc33::detail::Threshold;

template <class T> std::vector<T> random_row(std::size_t n, std::mt19937_64& rng)
{
    std::vector<T> row(n);
    if constexpr (std::is_integral_v<T>) {
        // the type's extremes and a narrow band around a few values, so that ties are common
        std::uniform_int_distribution<int> pick(0, 5);
        std::uniform_int_distribution<long long> any(static_cast<long long>(std::numeric_limits<T>::lowest()),
                                                     static_cast<long long>(std::numeric_limits<T>::max()));
        for (T& v : row) {
            const int p = pick(rng);
            v = p == 0 ? std::numeric_limits<T>::lowest()
              : p == 1 ? std::numeric_limits<T>::max()
              : p == 2 ? static_cast<T>(any(rng))
                       : static_cast<T>(static_cast<long long>(std::numeric_limits<T>::lowest() / 2) + (p - 3));
        }
    } else {
        std::uniform_real_distribution<double> u(-2, 2);
        std::uniform_int_distribution<int> pick(0, 3);
        for (T& v : row) v = pick(rng) == 0 ? static_cast<T>(0.5) : static_cast<T>(u(rng));
    }
    return row;
}

template <class T> std::vector<double> isovalues()
{
    std::vector<double> isos = {0.0, 0.5, -0.5, 1.0, 1e-30, -1e-30};
    if constexpr (std::is_integral_v<T>) {
        const double lo = static_cast<double>(std::numeric_limits<T>::lowest());
        const double hi = static_cast<double>(std::numeric_limits<T>::max());
        for (double v : {lo, hi, lo - 0.5, hi + 0.5, lo + 0.5, hi - 0.5, lo / 2, lo / 2 + 1, lo / 2 + 0.5, lo / 2 + 2.5})
            isos.push_back(v);
    } else {
        // 0.5 as a float, and the doubles just beside it: the float threshold must round up
        isos.push_back(std::nextafter(0.5, 1.0));
        isos.push_back(std::nextafter(0.5, 0.0));
        isos.push_back(1e300);
        isos.push_back(-1e300);
    }
    return isos;
}

template <class T> void check_type()
{
    std::mt19937_64 rng(7);
    for (std::size_t n : {1u, 2u, 3u, 4u, 5u, 7u, 8u, 9u, 15u, 16u, 17u, 31u, 32u, 33u, 41u, 63u, 64u, 65u, 72u,
                          95u, 96u, 97u, 127u, 128u, 129u, 200u, 256u, 300u}) {
        const std::vector<T> data = random_row<T>(2 * n, rng);
        // stride 1: the row alone in an allocation of exactly n samples (ASan sees a read past it)
        const std::vector<T> alone(data.begin(), data.begin() + static_cast<std::ptrdiff_t>(n));
        for (double iso : isovalues<T>()) {
            const Threshold<T> th(iso);
            for (std::int64_t stride : {1, 2}) {
                const std::size_t words = (n + 63) / 64;
                std::vector<std::uint64_t> fast(words + 1, 0xdeadbeef), slow(words + 1, 0xdeadbeef);
                RowScan fast_scan, slow_scan;
                const T* row = stride == 1 ? alone.data() : data.data();
                const RowSigns fast_signs =
                    classify_row(row, static_cast<std::int64_t>(n), stride, th, fast.data(), fast_scan);
                const RowSigns slow_signs = classify_row_portable(data.data(), static_cast<std::int64_t>(n), stride, th,
                                                                  slow.data(), slow_scan);
                double largest = 0;
                std::size_t above = 0;
                for (std::size_t i = 0; i < 64 * words; ++i) {
                    const bool expected = i < n && static_cast<double>(data[i * static_cast<std::size_t>(stride)]) >= iso;
                    above += expected ? 1 : 0;
                    ASSERT_EQ(((fast[i / 64] >> (i % 64)) & 1u) != 0, expected)
                        << "sample " << i << " of " << n << ", stride " << stride << ", iso " << iso;
                    ASSERT_EQ(((slow[i / 64] >> (i % 64)) & 1u) != 0, expected) << "portable, sample " << i;
                    if (i < n) largest = std::max(largest, std::fabs(static_cast<double>(data[i * static_cast<std::size_t>(stride)])));
                }
                EXPECT_EQ(fast[words], 0xdeadbeefu) << "wrote past the row's words";
                const RowSigns signs = above == n ? RowSigns::above : above == 0 ? RowSigns::below : RowSigns::mixed;
                EXPECT_EQ(fast_signs, signs) << above << " of " << n << " above, stride " << stride << ", iso " << iso;
                EXPECT_EQ(slow_signs, signs) << "portable: " << above << " of " << n << " above";
                EXPECT_FALSE(fast_scan.non_finite);
                if constexpr (std::is_floating_point_v<T>) {
                    EXPECT_EQ(fast_scan.largest, largest);
                    EXPECT_EQ(slow_scan.largest, largest);
                }
            }
        }
    }
}

TEST(Classify, EveryTypeMatchesTheSignRule)
{
    check_type<std::int8_t>();
    check_type<std::uint8_t>();
    check_type<std::int16_t>();
    check_type<std::uint16_t>();
    check_type<std::int32_t>();
    check_type<std::uint32_t>();
    check_type<float>();
    check_type<double>();
    RecordProperty("implementation", cmc33::detail::classify_implementation());
}

template <class T> void check_non_finite()
{
    for (std::size_t n : {3u, 5u, 9u, 41u, 64u, 100u}) {
        for (std::size_t at : {std::size_t{0}, n / 2, n - 1}) {
            for (T bad : {std::numeric_limits<T>::quiet_NaN(), std::numeric_limits<T>::infinity(),
                          -std::numeric_limits<T>::infinity()}) {
                std::vector<T> row(n, T(1));
                row[at] = bad;
                row[(at + 1) % n] = T(-3);
                std::vector<std::uint64_t> bits((n + 63) / 64);
                RowScan scan, slow;
                classify_row(row.data(), static_cast<std::int64_t>(n), 1, Threshold<T>(0.0), bits.data(), scan);
                classify_row_portable(row.data(), static_cast<std::int64_t>(n), 1, Threshold<T>(0.0), bits.data(), slow);
                EXPECT_TRUE(scan.non_finite) << n << " samples, " << bad << " at " << at;
                EXPECT_TRUE(slow.non_finite);
                EXPECT_EQ(scan.largest, 3.0) << "the largest finite |sample|";
                EXPECT_EQ(slow.largest, 3.0);
            }
        }
    }
}

TEST(Classify, FindsNonFiniteSamples)
{
    check_non_finite<float>();
    check_non_finite<double>();
}

} // namespace
