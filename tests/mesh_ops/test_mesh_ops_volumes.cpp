// simplify() and smooth() on larger shared volumes at README isovalues (label slow): simplified
// to 10 % and 2 % and smoothed 20 iterations, the topology is the extracted mesh's, the result
// is a manifold and embedded.

#include <gtest/gtest.h>

#include <string>

#include "cmc33/extract.hpp"
#include "cmc33/io.hpp"
#include "cmc33/mesh_ops.hpp"
#include "cmc33/topology.hpp"
#include "test_support.hpp"

namespace {

using namespace cmc33;

struct Case {
    const char* file;
    double iso;
};

class MeshOpsVolume : public ::testing::TestWithParam<Case> {};

TEST_P(MeshOpsVolume, KeepsTopologyAndEmbedding)
{
    const auto path = test::shared_volume(GetParam().file);
    if (!path) GTEST_SKIP() << GetParam().file << " not found";
    const Mesh mesh = extract(io::read_volume(*path), GetParam().iso);
    const MeshTopology before = mesh_topology(mesh);
    for (const double ratio : {0.1, 0.02}) {
        SimplifyOptions o;
        o.ratio = ratio;
        const Mesh s = simplify(mesh, o);
        SmoothOptions so;
        so.iterations = 20;
        const Mesh sm = smooth(s, so);
        for (const Mesh* m : {&s, &sm}) {
            MeshOpsReport r;
            r.topology_before = before;
            r.topology_after = mesh_topology(*m);
            EXPECT_TRUE(r.topology_same()) << GetParam().file << " at " << ratio;
            EXPECT_EQ(r.topology_after.nonmanifold_edges + r.topology_after.nonmanifold_vertices, 0);
            EXPECT_TRUE(mesh_geometry(*m).embedded()) << GetParam().file << " at " << ratio;
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Shared, MeshOpsVolume,
                         ::testing::Values(Case{"aneurism_256x256x256_uint8.nrrd", 80.5}, Case{"tooth_103x94x161_uint8.nrrd", 120.5},
                                           Case{"engine_256x256x128_uint8.nrrd", 80.5},
                                           Case{"CThead_256x256x113_uint16.nrrd", 650.5}),
                         [](const auto& p) { return std::string(p.param.file).substr(0, std::string(p.param.file).find('_')); });

} // namespace
