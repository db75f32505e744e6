#pragma once
// The pass that reads every sample: a row of samples becomes a bitmask of above-flags (bit i of
// word i / 64: sample i is above, the sign rule v >= iso of docs/conventions.md), 64 samples per word.
// Everything after it (which rows and cells cross, case codes, counts) works on these words with
// bit operations, so that a row far from the surface costs a few word operations.
//
// Contiguous rows (x stride 1) of every sample type are compared a vector at a time, in the
// samples' own type: AVX2 when the CPU has it (chosen at run time, once, by
// __builtin_cpu_supports on x86-64 with GCC or Clang), else a portable loop. Both give the same
// bits; tests/core/test_classify.cpp checks that against a one-sample-at-a-time reference. The
// same pass finds non-finite float samples (the check of every sample that extract() needs) and
// the largest |sample| (the gradient's scale), so the volume is read once for all three.

#include <cstdint>
#include <type_traits>

namespace cmc33::detail {

/// The sign rule v >= iso for samples of type T, as one comparison in T's own type.
/// Integers: v >= ceil(iso) (or every sample above, or none, when ceil(iso) is outside T).
/// float: v >= the smallest float not below iso, which is the same test as double(v) >= iso.
/// double: v >= iso.
template <class T> struct Threshold {
    enum class Mode : std::uint8_t { compare, all, none };
    Mode mode = Mode::compare;
    T value{};
    explicit Threshold(double iso);
};

/// What one classified row saw besides its flags (float and double samples only).
struct RowScan {
    bool non_finite = false; ///< some sample is NaN or infinite
    double largest = 0;      ///< the largest |sample| (of the finite ones)
};

/// What a classified row's flags say as a whole.
enum class RowSigns : std::uint8_t { below, above, mixed };

/// bits[0 .. (n + 63) / 64) = the above-flags of row[0], row[stride], ..., row[(n - 1) * stride];
/// the bits past n are 0. Updates `scan` for floating-point T. Returns whether every sample is
/// below, every one above, or the row has both (summed up as the words are made: read back
/// from memory right after the stores, a wide load cannot take them from the store buffer).
template <class T>
RowSigns classify_row(const T* row, std::int64_t n, std::int64_t stride, const Threshold<T>& threshold,
                      std::uint64_t* bits, RowScan& scan);

/// classify_row one sample at a time, whatever the CPU: the reference the tests hold the vector
/// code to.
template <class T>
RowSigns classify_row_portable(const T* row, std::int64_t n, std::int64_t stride, const Threshold<T>& threshold,
                               std::uint64_t* bits, RowScan& scan);

/// Which implementation classify_row uses on this CPU: "avx2" or "portable".
const char* classify_implementation();

} // namespace cmc33::detail
