// Extracts a sphere through cmc33's public API and prints what a user checks first.
#include <cmc33/cmc33.hpp>
#include <cmc33/version.hpp>

#include <cmath>
#include <cstdio>
#include <vector>

int main()
{
    const int n = 24;
    std::vector<float> samples(static_cast<std::size_t>(n * n * n));
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const double x = i - 11.5, y = j - 11.5, z = k - 11.5;
                samples[static_cast<std::size_t>(i + n * (j + n * k))] = static_cast<float>(std::sqrt(x * x + y * y + z * z));
            }
    const auto view = cmc33::GridView<float>::dense(samples.data(), {n, n, n});
    const cmc33::Mesh mesh = cmc33::extract(view, 8.0);
    const cmc33::MeshTopology t = cmc33::mesh_topology(mesh);
    std::printf("cmc33 %s: %zu triangles, euler %lld, components %lld\n", CMC33_VERSION_STRING, mesh.triangle_count(),
                static_cast<long long>(t.euler), static_cast<long long>(t.components));
    return t.euler == 2 && t.components == 1 ? 0 : 1;
}
