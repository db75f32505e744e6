// RangeCounts::share_sample_bound: ranges counted apart (MPI ranks, out-of-core slabs) give
// extract()'s normals byte for byte when each is given the largest sample bound of all ranges, as
// extract() gives its own ranges. The field below makes the difference visible: samples near the
// double range in the last planes scale every gradient down, and the subnormal differences of the
// first planes lose bits in that scaling, so a range that scales by its own bound alone writes
// other normals.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "cmc33/extract.hpp"
#include "cmc33/passes.hpp"

namespace {

using namespace cmc33;

struct Split {
    std::vector<float> normals;
    std::vector<float> positions;
    std::vector<std::uint32_t> triangles;
};

Split run(const GridView<double>& g, const ExtractOptions& o, bool share)
{
    std::vector<RangeCounts> counts{count(g, 0.0, o, 0, 4), count(g, 0.0, o, 4, g.nz())};
    if (share) {
        double bound = 0;
        for (const RangeCounts& c : counts) bound = std::max(bound, c.sample_bound());
        for (RangeCounts& c : counts) c.share_sample_bound(bound);
    }
    const std::vector<RangeOffsets> off = scan(counts);
    const auto nv = static_cast<std::size_t>(counts[0].vertex_count() + counts[1].vertex_count());
    const auto nt = static_cast<std::size_t>(counts[0].triangle_count() + counts[1].triangle_count());
    Split s{std::vector<float>(3 * nv), std::vector<float>(3 * nv), std::vector<std::uint32_t>(3 * nt)};
    for (std::size_t r = 0; r < 2; ++r) {
        MeshSpans out;
        const auto v = static_cast<std::size_t>(off[r].first_vertex), t = static_cast<std::size_t>(off[r].first_triangle);
        out.positions = s.positions.data() + 3 * v;
        out.normals = s.normals.data() + 3 * v;
        out.triangles = s.triangles.data() + 3 * t;
        out.first_vertex = off[r].first_vertex;
        out.first_triangle = off[r].first_triangle;
        emit(g, 0.0, o, counts[r], off[r], out);
    }
    return s;
}

TEST(PassesBound, SharedSampleBoundGivesExtractsNormalsNearTheDoubleRange)
{
    const Index3 d{6, 5, 12};
    std::vector<double> samples(static_cast<std::size_t>(d[0] * d[1] * d[2]));
    for (std::int64_t k = 0; k < d[2]; ++k)
        for (std::int64_t j = 0; j < d[1]; ++j)
            for (std::int64_t i = 0; i < d[0]; ++i) {
                const double v = k >= 9 ? ((i + j + k) % 2 ? 1.5e308 : -1.5e308)
                                        : static_cast<double>((i * 7 + j * 3 + k * 5) % 11 - 5) * 1e-310 + 1e-311 * static_cast<double>(i);
                samples[static_cast<std::size_t>(i + d[0] * (j + d[1] * k))] = v;
            }
    const auto g = GridView<double>::dense(samples.data(), d);
    ExtractOptions o;
    o.normals = true;
    o.threads = 1;
    const Mesh m = extract(g, 0.0, o);
    ASSERT_GT(m.vertex_count(), 100u);
    const Split shared = run(g, o, true);
    EXPECT_TRUE(std::equal(m.normals.begin(), m.normals.end(), shared.normals.begin(), shared.normals.end()));
    EXPECT_TRUE(std::equal(m.positions.begin(), m.positions.end(), shared.positions.begin(), shared.positions.end()));
    EXPECT_TRUE(std::equal(m.triangles.begin(), m.triangles.end(), shared.triangles.begin(), shared.triangles.end()));
    // the reason for the call: each range's own bound scales the first range's gradients differently
    const Split own = run(g, o, false);
    EXPECT_FALSE(std::equal(m.normals.begin(), m.normals.end(), own.normals.begin(), own.normals.end()));
}

TEST(PassesBound, TheBoundIsNeverLowered)
{
    std::vector<float> samples(27, 1.0f);
    samples[13] = -3.0f;
    const auto g = GridView<float>::dense(samples.data(), {3, 3, 3});
    RangeCounts c = count(g, 0.0, ExtractOptions{}, 0, 3);
    EXPECT_EQ(c.sample_bound(), 3.0);
    c.share_sample_bound(1.0);
    EXPECT_EQ(c.sample_bound(), 3.0);
    c.share_sample_bound(8.0);
    EXPECT_EQ(c.sample_bound(), 8.0);
}

} // namespace
