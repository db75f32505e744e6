// sweep(): isovalues from a range, rows that equal single extractions, any thread count.

#include <gtest/gtest.h>

#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/sweep.hpp"
#include "cmc33/verify.hpp"

namespace cmc33 {
namespace {

TEST(Sweep, IsovaluesAreTheDecimalSteps)
{
    EXPECT_EQ(sweep_isovalues(10, 12, 1), (std::vector<double>{10, 11, 12}));
    EXPECT_EQ(sweep_isovalues(10, 10.3, 0.1), (std::vector<double>{10, 10.1, 10.2, 10.3}));
    EXPECT_EQ(sweep_isovalues(-1, -1, 5), (std::vector<double>{-1}));
    EXPECT_EQ(sweep_isovalues(0, 1, 0.4), (std::vector<double>{0, 0.4, 0.8}));
    EXPECT_THROW(sweep_isovalues(2, 1, 1), Error);
    EXPECT_THROW(sweep_isovalues(0, 1, 0), Error);
    EXPECT_THROW(sweep_isovalues(0, 1e9, 1e-3), Error);
}

TEST(Sweep, RowsAreSingleExtractionsWhateverTheThreads)
{
    const Volume v = random_field(FieldKind::grid, 26, 1, 5); // two tunnels share a face at 0
    SweepOptions o;
    o.isovalues = sweep_isovalues(-0.2, 0.2, 0.1);
    o.methods = {Method::cmc33, Method::cmc33_paper, Method::chernyaev, Method::mc33_lewiner, Method::mc};
    o.threads = 1;
    const SweepReport one = sweep(v, o);
    ASSERT_EQ(one.rows.size(), 25u);
    int nonmanifold = 0;
    for (const SweepRow& row : one.rows) {
        ExtractOptions e;
        e.method = row.method;
        e.threads = 1;
        const Mesh mesh = extract(v, row.iso, e);
        const MeshTopology t = mesh_topology(mesh);
        EXPECT_EQ(row.triangles, static_cast<std::int64_t>(mesh.triangle_count()));
        EXPECT_EQ(row.vertices, static_cast<std::int64_t>(mesh.vertex_count()));
        EXPECT_EQ(row.euler, t.euler);
        EXPECT_EQ(row.b0, t.components);
        EXPECT_EQ(row.b1, t.b1);
        EXPECT_EQ(row.b2, t.closed_components);
        EXPECT_EQ(row.boundary_loops, t.boundary_loops);
        EXPECT_EQ(row.nonmanifold_edges, t.nonmanifold_edges);
        nonmanifold += row.nonmanifold_edges > 0;
        EXPECT_EQ(row.expected.has_value(), row.method == Method::cmc33);
        if (row.expected) {
            EXPECT_EQ(row.expected->euler, t.euler);
            EXPECT_EQ(row.expected->b0, t.components);
        }
    }
    EXPECT_GT(nonmanifold, 0);
    o.threads = 3;
    const SweepReport three = sweep(v, o);
    ASSERT_EQ(three.rows.size(), one.rows.size());
    for (std::size_t i = 0; i < one.rows.size(); ++i) {
        EXPECT_EQ(three.rows[i].iso, one.rows[i].iso);
        EXPECT_EQ(three.rows[i].method, one.rows[i].method);
        EXPECT_EQ(three.rows[i].triangles, one.rows[i].triangles);
        EXPECT_EQ(three.rows[i].euler, one.rows[i].euler);
    }
    o.methods = {Method::mc, Method::mc};
    EXPECT_THROW(sweep(v, o), Error);
    o.methods = {Method::mc};
    o.isovalues = {};
    EXPECT_THROW(sweep(v, o), Error);
}

} // namespace
} // namespace cmc33
