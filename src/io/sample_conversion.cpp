// Samples of types cmc33 does not hold, widened; rescaled samples (contract in sample_conversion.hpp).

#include "sample_conversion.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>

#include "cmc33/error.hpp"

namespace cmc33::io::detail {
namespace {

/// IEEE 754 binary16 to binary32: every half value is exactly a float.
float half_to_float(std::uint16_t h) noexcept
{
    const std::uint32_t sign = static_cast<std::uint32_t>(h & 0x8000u) << 16;
    const std::uint32_t exponent = (h >> 10) & 0x1fu;
    std::uint32_t mantissa = h & 0x3ffu;
    std::uint32_t bits = 0;
    if (exponent == 0x1f) {
        bits = sign | 0x7f800000u | (mantissa << 13); // infinity or NaN
    } else if (exponent != 0) {
        bits = sign | ((exponent + 112u) << 23) | (mantissa << 13); // rebias 15 -> 127
    } else if (mantissa == 0) {
        bits = sign; // signed zero
    } else {
        // subnormal half: normalise (value = mantissa * 2^-24)
        int shift = 0;
        while ((mantissa & 0x400u) == 0) {
            mantissa <<= 1;
            ++shift;
        }
        mantissa &= 0x3ffu;
        bits = sign | (static_cast<std::uint32_t>(113 - shift) << 23) | (mantissa << 13);
    }
    float f = 0;
    std::memcpy(&f, &bits, sizeof f);
    return f;
}

Volume like(const Volume& volume, ScalarType type)
{
    Volume out(type, volume.dims(), volume.spacing(), volume.origin());
    out.set_direction(volume.direction());
    out.set_space(volume.space());
    out.set_frame_source(volume.frame_source());
    return out;
}

} // namespace

Volume widen_samples(Volume volume, StoredKind kind)
{
    const auto n = static_cast<std::size_t>(volume.sample_count());
    switch (kind) {
    case StoredKind::as_is: return volume;
    case StoredKind::int64:
    case StoredKind::uint64: {
        // the same 8 bytes per sample, converted in place
        std::byte* bytes = volume.bytes();
        for (std::size_t i = 0; i < n; ++i) {
            double value = 0;
            if (kind == StoredKind::int64) {
                std::int64_t word = 0;
                std::memcpy(&word, bytes + 8 * i, 8);
                value = static_cast<double>(word);
            } else {
                std::uint64_t word = 0;
                std::memcpy(&word, bytes + 8 * i, 8);
                value = static_cast<double>(word);
            }
            std::memcpy(bytes + 8 * i, &value, 8);
        }
        return volume;
    }
    case StoredKind::float16: {
        Volume out = like(volume, ScalarType::f32);
        const std::uint16_t* in = volume.samples<std::uint16_t>();
        float* to = out.samples<float>();
        for (std::size_t i = 0; i < n; ++i) to[i] = half_to_float(in[i]);
        return out;
    }
    }
    return volume;
}

Volume rescale_samples(const Volume& volume, double slope, double inter, ScalarType type, const std::string& label)
{
    Volume out;
    try {
        out = like(volume, type);
    } catch (const Error& e) {
        throw Error(e.status(), label + ": " + e.what());
    }
    const auto n = static_cast<std::size_t>(volume.sample_count());
    volume.visit([&](const auto& grid) {
        if (type == ScalarType::f32) {
            float* to = out.samples<float>();
            for (std::size_t i = 0; i < n; ++i) to[i] = static_cast<float>(static_cast<double>(grid.data[i]) * slope + inter);
        } else {
            double* to = out.samples<double>();
            for (std::size_t i = 0; i < n; ++i) to[i] = static_cast<double>(grid.data[i]) * slope + inter;
        }
    });
    return out;
}

} // namespace cmc33::io::detail
