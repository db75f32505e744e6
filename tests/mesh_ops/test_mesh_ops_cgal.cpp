// simplify() and smooth() judged by CGAL (a test-only dependency): their results on meshes
// extracted from random fields and shared volumes, and on two close sheets, have no
// self-intersection by CGAL::Polygon_mesh_processing::does_self_intersect (exact predicates),
// on a CGAL::Surface_mesh built from the mesh as it is (vertices by index).

#include <gtest/gtest.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <cstdint>
#include <string>
#include <vector>

#include "cmc33/extract.hpp"
#include "cmc33/io.hpp"
#include "cmc33/mesh_ops.hpp"
#include "cmc33/topology.hpp"
#include "cmc33/verify.hpp"
#include "test_support.hpp"

namespace {

using namespace cmc33;
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<K::Point_3>;

/// CGAL's answer; false (with a failure) if the mesh cannot be a Surface_mesh.
bool cgal_self_intersects(const Mesh& m, const std::string& what)
{
    SurfaceMesh s;
    std::vector<SurfaceMesh::Vertex_index> v;
    for (std::size_t i = 0; i < m.vertex_count(); ++i) {
        v.push_back(s.add_vertex(K::Point_3(static_cast<double>(m.positions[3 * i]), static_cast<double>(m.positions[3 * i + 1]),
                                            static_cast<double>(m.positions[3 * i + 2]))));
    }
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
        const auto f = s.add_face(v[m.triangles[3 * t]], v[m.triangles[3 * t + 1]], v[m.triangles[3 * t + 2]]);
        EXPECT_NE(f, SurfaceMesh::null_face()) << what << ": triangle " << t << " is not a valid Surface_mesh face";
    }
    return CGAL::Polygon_mesh_processing::does_self_intersect(s);
}

void check(const Mesh& mesh, const std::string& what)
{
    ASSERT_FALSE(cgal_self_intersects(mesh, what)) << what << ": the input";
    for (const double ratio : {0.1, 0.02}) {
        SimplifyOptions o;
        o.ratio = ratio;
        const Mesh s = simplify(mesh, o);
        EXPECT_FALSE(cgal_self_intersects(s, what)) << what << " at " << ratio;
        SmoothOptions so;
        so.iterations = 20;
        const Mesh sm = smooth(s, so);
        EXPECT_FALSE(cgal_self_intersects(sm, what)) << what << " at " << ratio << ", smoothed";
    }
}

TEST(MeshOpsCgal, RandomFields)
{
    for (const FieldKind kind : {FieldKind::grid, FieldKind::closed, FieldKind::ties}) {
        for (std::int64_t n = 1; n <= 2; ++n) {
            const Mesh m = extract(random_field(kind, n, 41, 10), 0.0);
            if (m.triangle_count() > 0) check(m, std::string(field_kind_name(kind)) + " " + std::to_string(n));
        }
    }
}

TEST(MeshOpsCgal, SharedVolumes)
{
    for (const auto& [file, iso] : {std::pair{"Bucky_32x32x32_uint8.nrrd", 100.5}, std::pair{"nucleon_41x41x41_uint8.nrrd", 60.5}}) {
        const auto path = test::shared_volume(file);
        if (!path) GTEST_SKIP() << file << " not found";
        check(extract(io::read_volume(*path), iso), file);
    }
}

} // namespace
