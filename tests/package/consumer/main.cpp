// Extracts a sphere through cmc33's public API and prints what a user checks first.
#include <cmc33/cmc33.hpp>
#include <cmc33/version.hpp>

#include <cstdio>
#include <vector>

#include "sphere.hpp"

int main()
{
    const int n = 24;
    const std::vector<float> samples = sphere_samples(n);
    const auto view = cmc33::GridView<float>::dense(samples.data(), {n, n, n});
    const cmc33::Mesh mesh = cmc33::extract(view, 8.0);
    const cmc33::MeshTopology t = cmc33::mesh_topology(mesh);
    std::printf("cmc33 %s: %zu triangles, euler %lld, components %lld\n", CMC33_VERSION_STRING, mesh.triangle_count(),
                static_cast<long long>(t.euler), static_cast<long long>(t.components));
    return t.euler == 2 && t.components == 1 ? 0 : 1;
}
