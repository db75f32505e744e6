// Every volume of ../shared/data/volumes at a README isovalue, once at an integer (exact ties on
// integer data) and once halfway between integers: the cmc33 mesh is manifold, consistently
// oriented, has boundary edges only where the surface meets the volume's outer faces, and has the
// Euler characteristic, Betti numbers and boundary loops of the trilinear interpolant's level set.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "cmc33/extract.hpp"
#include "cmc33/io.hpp"
#include "cmc33/topology.hpp"
#include "test_support.hpp"

namespace {

using Case = cmc33::test::VolumeCase; // an integer iso; the test also runs iso + 0.5


class RealVolume : public ::testing::TestWithParam<Case> {};

TEST_P(RealVolume, ManifoldOrientedBoundaryOnlyOnTheBox)
{
    const auto path = cmc33::test::shared_volume(GetParam().file);
    if (!path) GTEST_SKIP() << "../shared/data/volumes not present";
    const cmc33::Volume v = cmc33::io::read_volume(*path);
    for (double iso : {GetParam().iso, GetParam().iso + 0.5}) {
        SCOPED_TRACE("iso " + std::to_string(iso));
        const cmc33::Mesh mesh = cmc33::extract(v, iso);
        const cmc33::MeshTopology t = cmc33::mesh_topology(mesh);
        EXPECT_GT(t.faces, 0);
        EXPECT_EQ(t.nonmanifold_edges, 0);
        EXPECT_EQ(t.nonmanifold_vertices, 0);
        EXPECT_EQ(t.degenerate_triangles, 0);
        EXPECT_TRUE(t.oriented);
        // boundary edges: both ends on an outer face of the volume
        float lo[3], hi[3];
        for (int a = 0; a < 3; ++a) {
            lo[a] = static_cast<float>(v.origin()[a] + v.spacing()[a] * 0.0);
            hi[a] = static_cast<float>(v.origin()[a] + v.spacing()[a] * static_cast<double>(v.dims()[a] - 1));
        }
        const auto on_box = [&](std::uint32_t id) {
            const float* p = &mesh.positions[3 * static_cast<std::size_t>(id)];
            for (int a = 0; a < 3; ++a)
                if (p[a] == lo[a] || p[a] == hi[a]) return true;
            return false;
        };
        std::vector<std::uint64_t> edges;
        edges.reserve(mesh.triangles.size());
        for (std::size_t f = 0; f < mesh.triangle_count(); ++f)
            for (int s = 0; s < 3; ++s) {
                const std::uint64_t a = mesh.triangles[3 * f + static_cast<std::size_t>(s)];
                const std::uint64_t b = mesh.triangles[3 * f + static_cast<std::size_t>((s + 1) % 3)];
                edges.push_back(std::min(a, b) << 32 | std::max(a, b));
            }
        std::sort(edges.begin(), edges.end());
        std::int64_t boundary = 0, off_box = 0;
        for (std::size_t e = 0; e < edges.size();) {
            std::size_t n = 1;
            while (e + n < edges.size() && edges[e + n] == edges[e]) ++n;
            if (n == 1) {
                ++boundary;
                off_box += !(on_box(static_cast<std::uint32_t>(edges[e] >> 32)) && on_box(static_cast<std::uint32_t>(edges[e] & 0xffffffffu)));
            }
            e += n;
        }
        EXPECT_EQ(boundary, t.boundary_edges);
        EXPECT_EQ(off_box, 0);
        // and the mesh has the topology of the trilinear level set (src/topology, no shared code)
        const cmc33::FieldTopology field = cmc33::field_topology(v, iso);
        ASSERT_TRUE(field.determined) << field.why;
        EXPECT_EQ(t.euler, field.euler);
        EXPECT_EQ(t.components, field.b0);
        EXPECT_EQ(t.b1, field.b1);
        EXPECT_EQ(t.closed_components, field.b2);
        EXPECT_EQ(t.boundary_loops, field.boundary_loops);
        // in space: embedded (no coincident vertices, zero-area or intersecting triangles), so the
        // STL round trip (triangles without shared vertices, welded by position when read back)
        // gives the same manifold with the same invariants
        const cmc33::MeshGeometry g = cmc33::mesh_geometry(mesh);
        EXPECT_EQ(g.coincident_vertices, 0);
        EXPECT_EQ(g.zero_area_triangles, 0);
        EXPECT_EQ(g.intersecting_pairs, 0);
        const auto stl = cmc33::test::temp_dir() / (std::string(GetParam().file) + ".stl");
        cmc33::io::write_mesh(mesh, stl);
        const cmc33::MeshTopology w = cmc33::mesh_topology(cmc33::io::read_mesh(stl));
        std::filesystem::remove(stl);
        EXPECT_EQ(w.nonmanifold_edges, 0);
        EXPECT_EQ(w.nonmanifold_vertices, 0);
        EXPECT_EQ(w.degenerate_triangles, 0);
        EXPECT_EQ(w.euler, field.euler);
        EXPECT_EQ(w.components, field.b0);
        EXPECT_EQ(w.b1, field.b1);
        EXPECT_EQ(w.closed_components, field.b2);
        EXPECT_EQ(w.boundary_loops, field.boundary_loops);
    }
}

INSTANTIATE_TEST_SUITE_P(SharedVolumes, RealVolume, ::testing::ValuesIn(cmc33::test::shared_volume_cases()), [](const auto& p) {
    std::string name = p.param.file;
    name = name.substr(0, name.find('_'));
    return name;
});

// Real data, with normals and every method: the mesh is the same, byte for byte, whatever the
// thread count (the bundled Bucky volume always; engine and CThead when ../shared is present).
TEST(RealVolumeThreads, ByteIdenticalForOneTwoAndSevenThreads)
{
    std::vector<std::pair<cmc33::Volume, double>> volumes;
    volumes.emplace_back(cmc33::io::read_volume(std::string(CMC33_SOURCE_DIR) + "/data/Bucky_32x32x32_uint8.nrrd"), 100.0);
    for (const auto& [file, iso] : {std::pair{"engine_256x256x128_uint8.nrrd", 80.0},
                                    std::pair{"CThead_256x256x113_uint16.nrrd", 650.5}}) {
        if (const auto path = cmc33::test::shared_volume(file)) volumes.emplace_back(cmc33::io::read_volume(*path), iso);
    }
    for (const auto& [volume, iso] : volumes) {
        for (cmc33::Method m : {cmc33::Method::cmc33, cmc33::Method::mc33_lewiner, cmc33::Method::mc}) {
            cmc33::ExtractOptions opt{m, true, 1};
            const cmc33::Mesh one = cmc33::extract(volume, iso, opt);
            ASSERT_GT(one.triangle_count(), 0u);
            for (int threads : {2, 7}) {
                opt.threads = threads;
                const cmc33::Mesh many = cmc33::extract(volume, iso, opt);
                EXPECT_EQ(one.positions, many.positions) << threads << " threads";
                EXPECT_EQ(one.normals, many.normals) << threads << " threads";
                EXPECT_EQ(one.triangles, many.triangles) << threads << " threads";
            }
        }
    }
}

} // namespace
