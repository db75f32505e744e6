#pragma once
// The synthetic volumes of the benchmarks. cmc33_bench builds them in memory and cmc33_make_field
// writes the same volumes to files for bench/run_bench.py, so both measure the same surfaces.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

#include "cmc33/volume.hpp"

namespace cmc33::bench {

/// Periods of each sine across the box, whatever the size: the surface is the same shape at every
/// size, with about n^2 triangles.
inline constexpr double kSinesPeriods = 8;
/// Added to every sine's argument so that no sample (the corner (0, 0, 0) in particular) is exactly
/// 0: every tool then sees the same signs whatever its rule for samples equal to the isovalue.
inline constexpr double kSinesPhase = 0.3;

/// n^3 float samples f(x, y, z) = sin(a x + p) + sin(a y + p) + sin(a z + p), a = 2 pi * 8 / n,
/// p = kSinesPhase: values in [-3, 3]; at iso 0 a large, smooth, periodic surface (close to the
/// Schwarz P minimal surface), about 16 M triangles at n = 512 (60 n^2).
inline Volume make_sines(std::int64_t n)
{
    Volume volume(ScalarType::f32, {n, n, n});
    const double a = 2 * std::numbers::pi * kSinesPeriods / static_cast<double>(n);
    std::vector<double> s(static_cast<std::size_t>(n));
    for (std::int64_t i = 0; i < n; ++i) s[static_cast<std::size_t>(i)] = std::sin(a * static_cast<double>(i) + kSinesPhase);
    float* out = volume.samples<float>();
    for (std::size_t z = 0; z < s.size(); ++z) {
        for (std::size_t y = 0; y < s.size(); ++y) {
            const double yz = s[y] + s[z];
            for (std::size_t x = 0; x < s.size(); ++x) *out++ = static_cast<float>(s[x] + yz);
        }
    }
    return volume;
}

/// n^3 float samples uniform in [-1, 1) from std::mt19937_64(seed) (whose sequence the C++
/// standard fixes, so a seed gives the same volume everywhere): at iso 0 nearly every cell is
/// crossed and every case of the table occurs, the worst case of an extractor.
inline Volume make_noise(std::int64_t n, std::uint64_t seed)
{
    Volume volume(ScalarType::f32, {n, n, n});
    std::mt19937_64 random(seed);
    float* out = volume.samples<float>();
    const std::int64_t count = volume.sample_count();
    for (std::int64_t i = 0; i < count; ++i) {
        // The top 53 bits as a double in [0, 1), exactly; then [-1, 1).
        const double u = static_cast<double>(random() >> 11) * 0x1p-53;
        out[i] = static_cast<float>(2 * u - 1);
    }
    return volume;
}

/// n^3 samples drawn from {60, 80, 100} by std::mt19937_64(seed), as uint8 or as float32: at iso
/// 80 every third sample is a tie and most cells are ambiguous, the case where exact decisions work
/// hardest; the two types hold the same numbers, so their times compare the decisions' paths.
inline Volume make_ties(std::int64_t n, std::uint64_t seed, bool as_float)
{
    Volume volume(as_float ? ScalarType::f32 : ScalarType::u8, {n, n, n});
    std::mt19937_64 random(seed);
    const std::int64_t count = volume.sample_count();
    for (std::int64_t i = 0; i < count; ++i) {
        const int value = 60 + 20 * static_cast<int>(random() % 3);
        if (as_float) {
            volume.samples<float>()[i] = static_cast<float>(value);
        } else {
            volume.samples<std::uint8_t>()[i] = static_cast<std::uint8_t>(value);
        }
    }
    return volume;
}

/// The distance to the grid's centre minus N / 3: at iso 0 one sphere, a smooth surface crossing
/// few cells of a large grid.
inline Volume make_sphere(std::int64_t n)
{
    Volume volume(ScalarType::f32, {n, n, n});
    const double c = static_cast<double>(n - 1) / 2, r = static_cast<double>(n) / 3;
    float* out = volume.samples<float>();
    for (std::int64_t z = 0; z < n; ++z)
        for (std::int64_t y = 0; y < n; ++y)
            for (std::int64_t x = 0; x < n; ++x) {
                const double dx = static_cast<double>(x) - c, dy = static_cast<double>(y) - c, dz = static_cast<double>(z) - c;
                *out++ = static_cast<float>(std::sqrt(dx * dx + dy * dy + dz * dz) - r);
            }
    return volume;
}

/// The sines volume quantised to uint8: round((f + 3) * 255 / 6), so iso 0 becomes 127.5 (a value
/// no sample has). The same surface, read through 8-bit samples as in most CT and MRI volumes.
inline constexpr double kSinesU8Iso = 127.5;
inline Volume to_uint8_sines(const Volume& sines)
{
    Volume volume(ScalarType::u8, sines.dims(), sines.spacing(), sines.origin());
    const float* in = sines.samples<float>();
    std::uint8_t* out = volume.samples<std::uint8_t>();
    const std::int64_t count = sines.sample_count();
    for (std::int64_t i = 0; i < count; ++i) {
        const double q = std::round((static_cast<double>(in[i]) + 3) * 255 / 6);
        out[i] = static_cast<std::uint8_t>(q < 0 ? 0 : q > 255 ? 255 : q);
    }
    return volume;
}

} // namespace cmc33::bench
