// Links cmc33::core alone (no io, topology or verify, no zlib): extracts a sphere with the public
// passes into arrays this program owns, as a numpy or VTK wrapper would.
#include <cmc33/passes.hpp>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "sphere.hpp"

int main()
{
    const int n = 24;
    const std::vector<float> samples = sphere_samples(n);
    const auto view = cmc33::GridView<float>::dense(samples.data(), {n, n, n});
    const cmc33::ExtractOptions options;
    std::vector<cmc33::RangeCounts> counts = {cmc33::count(view, 8.0, options, 0, 10),
                                              cmc33::count(view, 8.0, options, 10, n)};
    const std::vector<cmc33::RangeOffsets> offsets = cmc33::scan(counts);
    const std::size_t vertices = static_cast<std::size_t>(counts[0].vertex_count() + counts[1].vertex_count());
    const std::size_t triangles = static_cast<std::size_t>(counts[0].triangle_count() + counts[1].triangle_count());
    std::vector<float> positions(3 * vertices);
    std::vector<std::uint32_t> indices(3 * triangles);
    cmc33::MeshSpans out;
    out.positions = positions.data();
    out.triangles = indices.data();
    for (std::size_t r = 0; r < counts.size(); ++r) cmc33::emit(view, 8.0, options, counts[r], offsets[r], out);
    const cmc33::Mesh mesh = cmc33::extract(view, 8.0);
    const bool same = mesh.triangle_count() == triangles &&
                      std::equal(indices.begin(), indices.end(), mesh.triangles.begin()) &&
                      std::equal(positions.begin(), positions.end(), mesh.positions.begin());
    std::printf("cmc33::core alone (%s): %zu triangles, %s extract()\n", CMC33_CONSUMED, triangles,
                same ? "the same as" : "NOT the same as");
    return same ? 0 : 1;
}
