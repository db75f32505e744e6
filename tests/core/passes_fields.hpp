#pragma once
// Volumes the tests of the passes share (test_passes*.cpp; CMC33_SOURCE_DIR from CMake).

#include <cstdint>
#include <filesystem>
#include <random>

#include "cmc33/io.hpp"
#include "cmc33/volume.hpp"
#include "test_support.hpp"

namespace cmc33::test {

/// data/Bucky_32x32x32_uint8.nrrd
inline Volume bucky()
{
    return io::read_volume(std::filesystem::path(CMC33_SOURCE_DIR) / "data" / "Bucky_32x32x32_uint8.nrrd");
}

/// Samples uniform in [-1, 1], the same for the same seed.
inline Volume noise(Index3 dims, std::uint64_t seed)
{
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    return make_volume(dims, [&](auto, auto, auto) { return u(rng); });
}

} // namespace cmc33::test
