// Every shared volume at a README isovalue, as an integer (ties) and halfway between integers:
// cmc33's mesh is embedded by our check and by CGAL's (Polygon_mesh_processing::self_intersections
// on the mesh as a Surface_mesh, with exact predicates), and CGAL sees no degenerate face either.
// Label slow: about a minute for the 38 meshes in Release.

#include <gtest/gtest.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "cmc33/extract.hpp"
#include "cmc33/io.hpp"
#include "cmc33/topology.hpp"
#include "test_support.hpp"

namespace {

// Exact predicates are all self_intersections needs; inexact constructions keep it fast.
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<K::Point_3>;

using Case = cmc33::test::VolumeCase; // an integer iso; the test also runs iso + 0.5


class CgalVolume : public ::testing::TestWithParam<Case> {};

TEST_P(CgalVolume, EmbeddedForUsAndForCgal)
{
    const auto path = cmc33::test::shared_volume(GetParam().file);
    if (!path) GTEST_SKIP() << "../shared/data/volumes not present";
    const cmc33::Volume v = cmc33::io::read_volume(*path);
    for (double iso : {GetParam().iso, GetParam().iso + 0.5}) {
        SCOPED_TRACE("iso " + std::to_string(iso));
        const cmc33::Mesh mesh = cmc33::extract(v, iso);
        const cmc33::MeshGeometry g = cmc33::mesh_geometry(mesh);
        EXPECT_TRUE(g.embedded());

        // No coincident vertices (checked above), so the mesh's own vertices are the welded ones.
        SurfaceMesh sm;
        std::vector<SurfaceMesh::Vertex_index> vertex(mesh.vertex_count());
        for (std::size_t i = 0; i < mesh.vertex_count(); ++i) {
            vertex[i] = sm.add_vertex(K::Point_3(mesh.positions[3 * i], mesh.positions[3 * i + 1], mesh.positions[3 * i + 2]));
        }
        std::size_t refused = 0;
        for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
            const auto f = sm.add_face(vertex[mesh.triangles[3 * t]], vertex[mesh.triangles[3 * t + 1]],
                                       vertex[mesh.triangles[3 * t + 2]]);
            refused += f == SurfaceMesh::null_face();
        }
        ASSERT_EQ(refused, 0u) << "a manifold, oriented mesh is a valid Surface_mesh";
        std::vector<std::pair<SurfaceMesh::Face_index, SurfaceMesh::Face_index>> pairs;
        CGAL::Polygon_mesh_processing::self_intersections(sm, std::back_inserter(pairs));
        // CGAL reports a degenerate (collinear) face f as the pair (f, f), any other as two faces
        EXPECT_TRUE(pairs.empty()) << pairs.size() << " pairs, the first (" << pairs.front().first << ", "
                                   << pairs.front().second << ")";
    }
}

INSTANTIATE_TEST_SUITE_P(SharedVolumes, CgalVolume, ::testing::ValuesIn(cmc33::test::shared_volume_cases()), [](const auto& p) {
    std::string name = p.param.file;
    return name.substr(0, name.find('_'));
});

} // namespace
