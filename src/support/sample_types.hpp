#pragma once
// The eight sample types of volume.hpp, for the explicit instantiations of the templates that run
// on samples: CMC33_FOR_EACH_SAMPLE_TYPE(M) expands to M(T); for each of them, in the order of
// cmc33::ScalarType (volume.hpp).

#include <cstdint>

#define CMC33_FOR_EACH_SAMPLE_TYPE(M)                                                                 \
    M(std::int8_t)                                                                                    \
    M(std::uint8_t)                                                                                   \
    M(std::int16_t)                                                                                   \
    M(std::uint16_t)                                                                                  \
    M(std::int32_t)                                                                                   \
    M(std::uint32_t)                                                                                  \
    M(float)                                                                                          \
    M(double)
