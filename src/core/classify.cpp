// classify_row (classify.hpp): the above-flags of a sample row as bitmasks, AVX2 or portable.

#include "classify.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "sample_types.hpp"

#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__)
#define CMC33_CLASSIFY_AVX2 1
#include <immintrin.h>
#else
#define CMC33_CLASSIFY_AVX2 0
#endif

namespace cmc33::detail {

template <class T> Threshold<T>::Threshold(double iso)
{
    if constexpr (std::is_integral_v<T>) {
        const double t = std::ceil(iso);
        if (t <= static_cast<double>(std::numeric_limits<T>::lowest())) {
            mode = Mode::all;
        } else if (t > static_cast<double>(std::numeric_limits<T>::max())) {
            mode = Mode::none;
        } else {
            value = static_cast<T>(t);
        }
    } else if constexpr (std::is_same_v<T, float>) {
        // the smallest float f with double(f) >= iso: every float v has v >= f iff double(v) >= iso
        float f = static_cast<float>(iso); // nearest (or +-inf beyond the float range)
        if (static_cast<double>(f) < iso) f = std::nextafter(f, std::numeric_limits<float>::infinity());
        value = f;
    } else {
        value = static_cast<T>(iso);
    }
}

namespace {

/// RowSigns of a row from its words, summed as they are made (a value, kept in registers: the
/// stores to the words cannot alias it).
struct Signs {
    std::uint64_t any = 0, all = ~std::uint64_t{0};
    /// Word `m` whose samples are the bits of `valid`.
    void add(std::uint64_t m, std::uint64_t valid = ~std::uint64_t{0})
    {
        any |= m;
        all &= m | ~valid;
    }
    RowSigns signs() const
    {
        return all == ~std::uint64_t{0} ? RowSigns::above : any != 0 ? RowSigns::mixed : RowSigns::below;
    }
};

/// One sample at a time: the reference the vector code must equal, and the strided path.
template <class T>
Signs classify_portable(const T* row, std::int64_t n, std::int64_t stride, const Threshold<T>& th, std::uint64_t* bits,
                        RowScan& scan, Signs signs = {})
{
    const std::int64_t words = (n + 63) / 64;
    const T t = th.value;
    for (std::int64_t w = 0; w < words; ++w) {
        const std::int64_t i0 = 64 * w, i1 = std::min<std::int64_t>(n, i0 + 64);
        std::uint64_t m = 0;
        if constexpr (std::is_floating_point_v<T>) {
            double largest = scan.largest;
            bool bad = false;
            for (std::int64_t i = i0; i < i1; ++i) {
                const T v = row[i * stride];
                m |= static_cast<std::uint64_t>(v >= t) << (i - i0);
                const double a = std::fabs(static_cast<double>(v));
                bad |= !(a <= std::numeric_limits<double>::max());
                if (a > largest && !std::isinf(a)) largest = a;
            }
            scan.largest = largest;
            scan.non_finite |= bad;
        } else {
            for (std::int64_t i = i0; i < i1; ++i) m |= static_cast<std::uint64_t>(row[i * stride] >= t) << (i - i0);
        }
        bits[w] = m;
        signs.add(m, i1 - i0 == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << (i1 - i0)) - 1);
    }
    return signs;
}

#if CMC33_CLASSIFY_AVX2

/// Bit b of the result: sample b of the 32 (8-bit), 16 (16-bit) or 8 (32-bit) at p is below t.
/// Unsigned samples are compared as signed after flipping their top bit on both sides.
#define CMC33_AVX2 __attribute__((target("avx2")))

template <class T> CMC33_AVX2 inline __m256i bias()
{
    if constexpr (std::is_unsigned_v<T>) {
        if constexpr (sizeof(T) == 1) return _mm256_set1_epi8(static_cast<char>(0x80));
        if constexpr (sizeof(T) == 2) return _mm256_set1_epi16(static_cast<short>(0x8000));
        if constexpr (sizeof(T) == 4) return _mm256_set1_epi32(static_cast<int>(0x80000000u));
    }
    return _mm256_setzero_si256();
}

template <class T> CMC33_AVX2 inline __m256i broadcast(T t)
{
    if constexpr (sizeof(T) == 1) return _mm256_set1_epi8(static_cast<char>(t));
    if constexpr (sizeof(T) == 2) return _mm256_set1_epi16(static_cast<short>(t));
    return _mm256_set1_epi32(static_cast<int>(t));
}

template <class T> CMC33_AVX2 inline __m256i load_biased(const T* p, int q, __m256i b)
{
    return _mm256_xor_si256(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(p) + q), b);
}

/// Samples per 256-bit vector.
template <class T> constexpr std::int64_t kLanes = 32 / static_cast<std::int64_t>(sizeof(T));

/// Bit i: sample i of the kLanes<T> integer samples at p is below t (biased).
template <class T> CMC33_AVX2 inline std::uint32_t below_lanes_int(const T* p, __m256i t, __m256i b)
{
    const __m256i v = load_biased(p, 0, b);
    if constexpr (sizeof(T) == 1) {
        return static_cast<std::uint32_t>(_mm256_movemask_epi8(_mm256_cmpgt_epi8(t, v)));
    } else if constexpr (sizeof(T) == 2) {
        const __m256i below = _mm256_cmpgt_epi16(t, v);
        const __m128i packed = _mm_packs_epi16(_mm256_castsi256_si128(below), _mm256_extracti128_si256(below, 1));
        return static_cast<std::uint32_t>(_mm_movemask_epi8(packed));
    } else {
        return static_cast<std::uint32_t>(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(t, v))));
    }
}

/// 64 integer samples at p against t (biased): the above-bits.
template <class T> CMC33_AVX2 inline std::uint64_t above64_int(const T* p, __m256i t, __m256i b)
{
    std::uint64_t below = 0;
    if constexpr (sizeof(T) == 2) {
        // two vectors a movemask, not one each as below_lanes_int does
        for (int q = 0; q < 2; ++q) {
            const __m256i lo = _mm256_cmpgt_epi16(t, load_biased(p, 2 * q, b));
            const __m256i hi = _mm256_cmpgt_epi16(t, load_biased(p, 2 * q + 1, b));
            // packs interleaves 128-bit lanes (lo0 hi0 lo1 hi1); the permute restores the order
            const __m256i packed = _mm256_permute4x64_epi64(_mm256_packs_epi16(lo, hi), 0xD8);
            const auto m = static_cast<std::uint32_t>(_mm256_movemask_epi8(packed));
            below |= std::uint64_t{m} << (32 * q);
        }
    } else {
        for (int q = 0; q < 64 / kLanes<T>; ++q) {
            below |= std::uint64_t{below_lanes_int(p + kLanes<T> * q, t, b)} << (kLanes<T> * q);
        }
    }
    return ~below;
}

/// The above-bits of the kLanes<T> integer samples at p against t (biased).
template <class T> CMC33_AVX2 inline std::uint32_t above_lanes_int(const T* p, __m256i t, __m256i b)
{
    return ~below_lanes_int(p, t, b) & static_cast<std::uint32_t>(~std::uint64_t{0} >> (64 - kLanes<T>));
}

/// The word of above-bits of row[o, n) (0 < n - o < 64, n >= kLanes<T>) from lanes(p), the bits
/// of the kLanes<T> samples at p, a vector at a time and none read outside row[0, n): the last
/// vector ends at the row's end, overlapping the one before, and its bits are shifted into
/// place. (One sample at a time, a 41-sample row of nucleon 41^3 took 14 % of its extraction.)
template <class T, class Lanes>
CMC33_AVX2 inline std::uint64_t above_tail(const T* row, std::int64_t o, std::int64_t n, const Lanes& lanes)
{
    std::uint64_t m = 0;
    for (std::int64_t s = o; s < n; s += kLanes<T>) {
        const std::int64_t c = std::min(s, n - kLanes<T>);
        m |= (std::uint64_t{lanes(row + c)} >> (s - c)) << (s - o);
    }
    return m;
}

template <class T>
CMC33_AVX2 Signs classify_avx2_int(const T* row, std::int64_t n, const Threshold<T>& th, std::uint64_t* bits)
{
    const __m256i b = bias<T>();
    const __m256i t = _mm256_xor_si256(broadcast<T>(th.value), b);
    const std::int64_t full = n / 64;
    Signs signs;
    for (std::int64_t w = 0; w < full; ++w) {
        const std::uint64_t m = above64_int<T>(row + 64 * w, t, b);
        bits[w] = m;
        signs.add(m);
    }
    if (n % 64 == 0) return signs;
    if (n >= kLanes<T>) {
        const auto lane_bits = [t, b](const T* p) CMC33_AVX2 { return above_lanes_int<T>(p, t, b); };
        bits[full] = above_tail<T>(row, 64 * full, n, lane_bits);
        signs.add(bits[full], (std::uint64_t{1} << (n % 64)) - 1);
        return signs;
    }
    RowScan unused;
    return classify_portable(row + 64 * full, n - 64 * full, 1, th, bits + full, unused, signs);
}

/// The AVX2 operations on a vector of kLanes<T> floating-point samples that classify_avx2_real
/// needs: the _ps intrinsics for float, the _pd ones for double.
template <class T> struct RealLanes;
template <> struct RealLanes<float> {
    using V = __m256;
    CMC33_AVX2 static V load(const float* p) { return _mm256_loadu_ps(p); }
    CMC33_AVX2 static V splat(float x) { return _mm256_set1_ps(x); }
    CMC33_AVX2 static V abs_mask() { return _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff)); }
    CMC33_AVX2 static V bit_and(V a, V b) { return _mm256_and_ps(a, b); }
    CMC33_AVX2 static V and_not(V a, V b) { return _mm256_andnot_ps(a, b); }
    CMC33_AVX2 static V bit_or(V a, V b) { return _mm256_or_ps(a, b); }
    CMC33_AVX2 static V max(V a, V b) { return _mm256_max_ps(a, b); }
    CMC33_AVX2 static V ge(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_GE_OQ); }
    CMC33_AVX2 static V not_less(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_NLT_UQ); } // true for NaN
    CMC33_AVX2 static std::uint32_t signs(V v) { return static_cast<std::uint32_t>(_mm256_movemask_ps(v)); }
    CMC33_AVX2 static void store(float* out, V v) { _mm256_storeu_ps(out, v); }
};
template <> struct RealLanes<double> {
    using V = __m256d;
    CMC33_AVX2 static V load(const double* p) { return _mm256_loadu_pd(p); }
    CMC33_AVX2 static V splat(double x) { return _mm256_set1_pd(x); }
    CMC33_AVX2 static V abs_mask() { return _mm256_castsi256_pd(_mm256_set1_epi64x(0x7fffffffffffffff)); }
    CMC33_AVX2 static V bit_and(V a, V b) { return _mm256_and_pd(a, b); }
    CMC33_AVX2 static V and_not(V a, V b) { return _mm256_andnot_pd(a, b); }
    CMC33_AVX2 static V bit_or(V a, V b) { return _mm256_or_pd(a, b); }
    CMC33_AVX2 static V max(V a, V b) { return _mm256_max_pd(a, b); }
    CMC33_AVX2 static V ge(V a, V b) { return _mm256_cmp_pd(a, b, _CMP_GE_OQ); }
    CMC33_AVX2 static V not_less(V a, V b) { return _mm256_cmp_pd(a, b, _CMP_NLT_UQ); }
    CMC33_AVX2 static std::uint32_t signs(V v) { return static_cast<std::uint32_t>(_mm256_movemask_pd(v)); }
    CMC33_AVX2 static void store(double* out, V v) { _mm256_storeu_pd(out, v); }
};

/// classify_row of float or double samples: the flags, and the scan for non-finite samples and
/// the largest |sample|.
template <class T>
CMC33_AVX2 Signs classify_avx2_real(const T* row, std::int64_t n, const Threshold<T>& th, std::uint64_t* bits,
                                    RowScan& scan)
{
    using L = RealLanes<T>;
    using V = typename L::V;
    const V t = L::splat(th.value), abs_mask = L::abs_mask(), inf = L::splat(std::numeric_limits<T>::infinity());
    // the largest |sample| of the finite ones, in two accumulators (even and odd vectors) so that
    // the chain of max is half as long; a non-finite sample counts as 0 (and_not, which keeps the
    // chain free of a blend)
    V largest[2] = {L::splat(0), L::splat(0)};
    V bad = L::splat(0);
    // the above-bits of the vector at p; its samples join the scan in accumulator `q`
    const auto lane_bits = [&](const T* p, int q) CMC33_AVX2 {
        const V v = L::load(p);
        const V a = L::bit_and(v, abs_mask);
        const V not_finite = L::not_less(a, inf); // inf or NaN
        bad = L::bit_or(bad, not_finite);
        largest[q] = L::max(largest[q], L::and_not(not_finite, a));
        return L::signs(L::ge(v, t));
    };
    const std::int64_t full = n / 64;
    Signs signs;
    for (std::int64_t w = 0; w < full; ++w) {
        std::uint64_t m = 0;
        for (int q = 0; q < 64 / kLanes<T>; ++q) {
            m |= std::uint64_t{lane_bits(row + 64 * w + kLanes<T> * q, q & 1)} << (kLanes<T> * q);
        }
        bits[w] = m;
        signs.add(m);
    }
    const bool tail = n % 64 != 0 && n >= kLanes<T>;
    if (tail) {
        bits[full] = above_tail(row, 64 * full, n, [&](const T* p) CMC33_AVX2 { return lane_bits(p, 0); });
        signs.add(bits[full], (std::uint64_t{1} << (n % 64)) - 1);
    }
    alignas(32) T lanes[kLanes<T>];
    L::store(lanes, L::max(largest[0], largest[1]));
    for (T x : lanes) scan.largest = std::max(scan.largest, static_cast<double>(x));
    scan.non_finite |= L::signs(bad) != 0;
    if (n % 64 == 0 || tail) return signs;
    return classify_portable(row + 64 * full, n - 64 * full, 1, th, bits + full, scan, signs);
}

#undef CMC33_AVX2

bool has_avx2()
{
    static const bool yes = __builtin_cpu_supports("avx2") != 0;
    return yes;
}

#else

constexpr bool has_avx2() { return false; }

#endif

} // namespace

template <class T>
RowSigns classify_row(const T* row, std::int64_t n, std::int64_t stride, const Threshold<T>& th, std::uint64_t* bits,
                      RowScan& scan)
{
    using Mode = typename Threshold<T>::Mode;
    if (th.mode != Mode::compare) {
        // every integer sample is above (or none is): no sample needs reading
        const std::int64_t words = (n + 63) / 64;
        const std::uint64_t fill = th.mode == Mode::all ? ~std::uint64_t{0} : 0;
        for (std::int64_t w = 0; w < words; ++w) bits[w] = fill;
        if (n % 64 != 0) bits[words - 1] &= (std::uint64_t{1} << (n % 64)) - 1;
        return th.mode == Mode::all ? RowSigns::above : RowSigns::below;
    }
#if CMC33_CLASSIFY_AVX2
    if (stride == 1 && has_avx2()) {
        if constexpr (std::is_floating_point_v<T>) {
            return classify_avx2_real(row, n, th, bits, scan).signs();
        } else {
            return classify_avx2_int(row, n, th, bits).signs();
        }
    }
#endif
    return classify_portable(row, n, stride, th, bits, scan).signs();
}

template <class T>
RowSigns classify_row_portable(const T* row, std::int64_t n, std::int64_t stride, const Threshold<T>& th,
                               std::uint64_t* bits, RowScan& scan)
{
    if (th.mode != Threshold<T>::Mode::compare) return classify_row(row, n, stride, th, bits, scan);
    return classify_portable(row, n, stride, th, bits, scan).signs();
}

const char* classify_implementation() { return has_avx2() ? "avx2" : "portable"; }

#define CMC33_INSTANTIATE(T)                                                                                     \
    template struct Threshold<T>;                                                                                \
    template RowSigns classify_row<T>(const T*, std::int64_t, std::int64_t, const Threshold<T>&, std::uint64_t*, \
                                      RowScan&);                                                                 \
    template RowSigns classify_row_portable<T>(const T*, std::int64_t, std::int64_t, const Threshold<T>&,        \
                                               std::uint64_t*, RowScan&);
CMC33_FOR_EACH_SAMPLE_TYPE(CMC33_INSTANTIATE)
#undef CMC33_INSTANTIATE

} // namespace cmc33::detail
