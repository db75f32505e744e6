// Custodio et al. 2013 (C13), Sec. 5.2 and 6.2: Chernyaev's tubes lie in the ambiguous face they
// cross, so two tunnels through one face meet there and the mesh has non-manifold edges (Fig. 8);
// C13's C-MC33 (method cmc33-paper) splits the slab holding such a face at the face's saddle
// (Fig. 11) until no two tunnels share a face. Checked against the independent field topology.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/passes.hpp"
#include "cmc33/topology.hpp"
#include "cmc33/verify.hpp"
#include "refine.hpp"

namespace {

using cmc33::ExtractOptions;
using cmc33::Method;
using cmc33::Volume;

/// The paper's 5x5x5 grids: samples uniform in [-1, 1] (verify's grid n of seed 1).
Volume grid(std::int64_t n) { return cmc33::random_field(cmc33::FieldKind::grid, n, 1, 5); }

bool same_topology(const cmc33::MeshTopology& t, const cmc33::FieldTopology& f)
{
    return f.determined && t.euler == f.euler && t.components == f.b0 && t.b1 == f.b1 && t.closed_components == f.b2 &&
           t.boundary_loops == f.boundary_loops;
}

cmc33::Mesh extract(const Volume& v, Method m, cmc33::ExtractStats* stats = nullptr, bool normals = false)
{
    ExtractOptions o;
    o.method = m;
    o.threads = 1;
    o.normals = normals;
    return cmc33::extract(v, 0.0, o, stats);
}

// Grid 26 of seed 1 (found by `cmc33 verify --method chernyaev --grids 600`): two neighbouring
// cells have tunnels through the face they share, as in C13's Fig. 8.
TEST(Paper, TwoTunnelsThroughOneFaceMakeChernyaevsMeshNonManifoldAndCmc33PaperSplitsTheSlab)
{
    const Volume v = grid(26);
    const auto view = v.view<float>();
    const std::vector<cmc33::detail::SharedFace> faces = cmc33::detail::shared_tunnel_faces(view, 0.0);
    ASSERT_EQ(faces.size(), 1u);
    const cmc33::FieldTopology field = cmc33::field_topology(v, 0.0);
    ASSERT_TRUE(field.determined) << field.why;

    // the legacy methods: non-manifold edges, all of them in the shared face
    for (const Method m : {Method::chernyaev, Method::mc33_lewiner}) {
        const cmc33::Mesh mesh = extract(v, m);
        const cmc33::MeshTopology t = cmc33::mesh_topology(mesh);
        if (m == Method::mc33_lewiner && t.nonmanifold_edges == 0) continue; // t_alt may miss a tunnel
        EXPECT_GT(t.nonmanifold_edges, 0) << cmc33::method_name(m);
        EXPECT_FALSE(same_topology(t, field)) << cmc33::method_name(m);
    }
    const cmc33::Mesh legacy = extract(v, Method::chernyaev);
    const auto& f = faces[0];
    std::vector<std::vector<std::uint32_t>> around(legacy.vertex_count());
    for (std::size_t q = 0; q < legacy.triangle_count(); ++q)
        for (int s = 0; s < 3; ++s) around[legacy.triangles[3 * q + s]].push_back(static_cast<std::uint32_t>(q));
    int in_face = 0;
    for (std::size_t q = 0; q < legacy.triangle_count(); ++q) {
        bool all = true;
        for (int s = 0; s < 3; ++s) {
            const float x = legacy.positions[3 * legacy.triangles[3 * q + s] + static_cast<std::size_t>(f.axis)];
            all = all && x == static_cast<float>(f.lower[static_cast<std::size_t>(f.axis)] + 1);
        }
        in_face += all;
    }
    EXPECT_EQ(in_face, 4) << "each cell puts its tube's quadrilateral (two triangles) in the shared face";

    // cmc33-paper: one split, the field's topology, a manifold, embedded
    cmc33::ExtractStats stats;
    const cmc33::Mesh paper = extract(v, Method::cmc33_paper, &stats);
    EXPECT_GE(stats.refinement_planes, 1);
    EXPECT_TRUE(stats.plane_first_vertex.empty()); // the refined grid's layout is not the caller's
    EXPECT_TRUE(stats.plane_first_triangle.empty());
    const cmc33::MeshTopology t = cmc33::mesh_topology(paper);
    EXPECT_EQ(t.nonmanifold_edges, 0);
    EXPECT_EQ(t.nonmanifold_vertices, 0);
    EXPECT_TRUE(t.oriented);
    EXPECT_TRUE(same_topology(t, field));
    EXPECT_TRUE(cmc33::mesh_geometry(paper).embedded());
    // cmc33, without subdivision
    EXPECT_TRUE(same_topology(cmc33::mesh_topology(extract(v, Method::cmc33)), field));
    // the added plane goes through the face's saddle: some vertices lie strictly inside a cell
    // along the split axis, on the face's plane
    bool on_plane = false;
    for (std::size_t q = 0; q < paper.vertex_count(); ++q) {
        const float* p = &paper.positions[3 * q];
        int off = 0;
        for (int a = 0; a < 3; ++a) off += p[a] != std::round(p[a]);
        on_plane = on_plane || (off == 2 && p[f.axis] == static_cast<float>(f.lower[static_cast<std::size_t>(f.axis)] + 1));
    }
    EXPECT_TRUE(on_plane);
}

// Without a shared face there is nothing to split: the mesh is the passes' with the legacy tubes,
// byte for byte (and that is what cmc33-paper's decisions are: cmc33's).
TEST(Paper, WithoutASharedFaceCmc33PaperIsTheLegacyTablesWithCmc33sDecisions)
{
    int checked = 0;
    for (std::int64_t n = 1; n <= 60; ++n) {
        const Volume v = grid(n);
        if (!cmc33::detail::shared_tunnel_faces(v.view<float>(), 0.0).empty()) continue;
        ExtractOptions o;
        o.method = Method::cmc33_paper;
        o.threads = 1;
        cmc33::ExtractStats stats;
        const cmc33::Mesh a = cmc33::extract(v, 0.0, o, &stats);
        const cmc33::Mesh b = cmc33::detail::extract_passes(v.view<float>(), 0.0, o, nullptr);
        EXPECT_EQ(a.positions, b.positions);
        EXPECT_EQ(a.triangles, b.triangles);
        EXPECT_EQ(stats.refinement_planes, 0);
        // the same cells and decisions as cmc33: the same subcases
        cmc33::ExtractStats ours;
        o.method = Method::cmc33;
        (void)cmc33::extract(v, 0.0, o, &ours);
        EXPECT_EQ(stats.cells_per_subcase, ours.cells_per_subcase);
        ++checked;
    }
    EXPECT_GT(checked, 50);
}

// On the paper's random grids: the legacy tubes under cmc33's decisions (cmc33-paper without its
// refinement) are non-manifold exactly where tunnels share a face, and right everywhere else;
// cmc33-paper always has the field's topology, without a non-manifold edge. chernyaev (the same
// decisions but for 13.5) is non-manifold on about as many grids.
TEST(Paper, OnRandomGridsCmc33PaperIsRightWhereTheLegacyMeshesAreNot)
{
    int shared = 0, chernyaev_nonmanifold = 0;
    for (std::int64_t n = 1; n <= 1500; ++n) {
        const Volume v = grid(n);
        const cmc33::FieldTopology field = cmc33::field_topology(v, 0.0);
        if (!field.determined) continue;
        const bool has_shared = !cmc33::detail::shared_tunnel_faces(v.view<float>(), 0.0).empty();
        shared += has_shared;
        cmc33::ExtractStats stats;
        const cmc33::MeshTopology p = cmc33::mesh_topology(extract(v, Method::cmc33_paper, &stats));
        ASSERT_TRUE(same_topology(p, field)) << "grid " << n;
        ASSERT_EQ(p.nonmanifold_edges + p.nonmanifold_vertices, 0) << "grid " << n;
        EXPECT_EQ(stats.refinement_planes > 0, has_shared) << "grid " << n;
        ExtractOptions o;
        o.method = Method::cmc33_paper;
        o.threads = 1;
        const cmc33::MeshTopology unrefined = cmc33::mesh_topology(cmc33::detail::extract_passes(v.view<float>(), 0.0, o, nullptr));
        EXPECT_EQ(unrefined.nonmanifold_edges > 0, has_shared) << "grid " << n;
        if (!has_shared) {
            EXPECT_TRUE(same_topology(unrefined, field)) << "grid " << n;
        }
        chernyaev_nonmanifold += cmc33::mesh_topology(extract(v, Method::chernyaev)).nonmanifold_edges > 0;
    }
    EXPECT_GE(shared, 5);
    EXPECT_GE(chernyaev_nonmanifold, shared / 2);
    EXPECT_LE(chernyaev_nonmanifold, 2 * shared);
}

// The refined grid keeps the frame: a mirrored, scaled and shifted copy of grid 26 gives the same
// mesh mapped by the frame, with reversed winding, and unit normals pointing from above to below.
TEST(Paper, TheRefinedMeshIsInTheVolumesFrameWithNormals)
{
    const Volume plain = grid(26);
    Volume framed = grid(26);
    framed.set_spacing({0.5, 2.0, 1.5});
    framed.set_origin({10, -3, 7});
    cmc33::Mat3 flip = cmc33::kIdentity3;
    flip[1][1] = -1; // mirrors y
    framed.set_direction(flip);
    const cmc33::Mesh a = extract(plain, Method::cmc33_paper);
    const cmc33::Mesh b = extract(framed, Method::cmc33_paper, nullptr, true);
    ASSERT_EQ(a.positions.size(), b.positions.size());
    for (std::size_t i = 0; i < a.positions.size(); i += 3) {
        EXPECT_NEAR(b.positions[i], 10 + 0.5 * static_cast<double>(a.positions[i]), 1e-5);
        EXPECT_NEAR(b.positions[i + 1], -3 - 2.0 * static_cast<double>(a.positions[i + 1]), 1e-5);
        EXPECT_NEAR(b.positions[i + 2], 7 + 1.5 * static_cast<double>(a.positions[i + 2]), 1e-5);
    }
    for (std::size_t t = 0; t < a.triangle_count(); ++t) {
        EXPECT_EQ(a.triangles[3 * t], b.triangles[3 * t]);
        EXPECT_EQ(a.triangles[3 * t + 1], b.triangles[3 * t + 2]);
    }
    EXPECT_TRUE(cmc33::mesh_topology(b).oriented);
    // normals: minus the world gradient, M^-T times the index one, normalised
    const cmc33::Mesh an = extract(plain, Method::cmc33_paper, nullptr, true);
    ASSERT_EQ(b.normals.size(), b.positions.size());
    for (std::size_t q = 0; q < b.vertex_count(); ++q) {
        const double g[3] = {static_cast<double>(an.normals[3 * q]) / 0.5, -static_cast<double>(an.normals[3 * q + 1]) / 2.0,
                             static_cast<double>(an.normals[3 * q + 2]) / 1.5};
        const double len = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(b.normals[3 * q + static_cast<std::size_t>(k)], g[k] / len, 1e-5);
    }
    // and at a vertex on an edge the refinement left alone, extract()'s normal: match vertices of
    // the unrefined legacy mesh by position
    ExtractOptions o;
    o.method = Method::cmc33_paper;
    o.threads = 1;
    o.normals = true;
    const cmc33::Mesh direct = cmc33::detail::extract_passes(plain.view<float>(), 0.0, o, nullptr);
    int matched = 0;
    for (std::size_t q = 0; q < an.vertex_count(); ++q)
        for (std::size_t r = 0; r < direct.vertex_count(); ++r) {
            if (an.positions[3 * q] != direct.positions[3 * r] || an.positions[3 * q + 1] != direct.positions[3 * r + 1] ||
                an.positions[3 * q + 2] != direct.positions[3 * r + 2]) {
                continue;
            }
            ++matched;
            for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(an.normals[3 * q + k], direct.normals[3 * r + k], 1e-5);
        }
    EXPECT_GT(matched, static_cast<int>(an.vertex_count()) / 2);
}

// Integer data: the saddle of a shared face is a fraction of integers, and the samples of the new
// plane are too. cmc33-paper scales the grid by the denominator, so the plane goes exactly through
// the saddle and the ties on it (samples, face saddles equal to iso) are decided by the sign rule,
// not by rounding. Ties grid 4228 of seed 1 (found by `cmc33 verify --method cmc33-paper --ties
// 5000` when the new samples were rounded): one split, and the field's topology.
TEST(Paper, TiesOnTheAddedPlaneAreDecidedExactly)
{
    const Volume v = cmc33::random_field(cmc33::FieldKind::ties, 4228, 1, 5);
    ASSERT_FALSE(cmc33::detail::shared_tunnel_faces(v.view<float>(), 0.0).empty());
    cmc33::ExtractStats stats;
    const cmc33::MeshTopology t = cmc33::mesh_topology(extract(v, Method::cmc33_paper, &stats));
    EXPECT_EQ(stats.refinement_planes, 1);
    EXPECT_TRUE(same_topology(t, cmc33::field_topology(v, 0.0)));
    EXPECT_EQ(t.nonmanifold_edges, 0);
    // and the same volume as uint8 at iso 3 (the ties grids are integers -3..3 shifted)
    Volume u(cmc33::ScalarType::u8, v.dims());
    for (std::int64_t i = 0; i < v.sample_count(); ++i) u.samples<std::uint8_t>()[i] = static_cast<std::uint8_t>(v.samples<float>()[i] + 3);
    ExtractOptions o;
    o.method = Method::cmc33_paper;
    const cmc33::MeshTopology w = cmc33::mesh_topology(cmc33::extract(u, 3.0, o));
    EXPECT_TRUE(same_topology(w, cmc33::field_topology(u, 3.0)));
}

TEST(Paper, ThePassesRefuseCmc33Paper)
{
    const Volume v = grid(26);
    ExtractOptions o;
    o.method = Method::cmc33_paper;
    EXPECT_THROW((void)cmc33::count(v.view<float>(), 0.0, o, 0, 5), cmc33::Error);
}

} // namespace
