#pragma once
// The consumers' field: distance from the centre of an n^3 grid (a sphere at any isovalue).
#include <cmath>
#include <cstddef>
#include <vector>

inline std::vector<float> sphere_samples(int n)
{
    std::vector<float> samples(static_cast<std::size_t>(n) * n * n);
    const double c = (n - 1) / 2.0;
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const double x = i - c, y = j - c, z = k - c;
                samples[static_cast<std::size_t>(i + n * (j + n * k))] = static_cast<float>(std::sqrt(x * x + y * y + z * z));
            }
    return samples;
}
