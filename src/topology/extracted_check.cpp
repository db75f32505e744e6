// check_extracted_mesh() (contract in topology.hpp): the topology slab by slab of sample planes
// (SeamTopology, the out-of-core extraction's summaries, merged in order) and the geometry layer
// by layer (grid_geometry()), both in parallel; the general functions when the mesh does not fit.

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <limits>
#include <mutex>
#include <optional>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/topology.hpp"
#include "grid_check.hpp"
#include "parallel.hpp"
#include "seam_topology.hpp"

namespace cmc33 {
namespace {

/// The layout is that of extract(): nz + 1 entries each, from 0 to the mesh's counts, never
/// decreasing, no triangles in plane nz - 1 (it has no cells).
bool layout_fits(const Mesh& mesh, const ExtractedGrid& grid)
{
    const auto& fv = grid.plane_first_vertex;
    const auto& ft = grid.plane_first_triangle;
    const std::int64_t nz = grid.dims[2];
    if (grid.dims[0] < 2 || grid.dims[1] < 2 || nz < 2) return false;
    const auto entries = static_cast<std::size_t>(nz) + 1;
    if (fv.size() != entries || ft.size() != entries) return false;
    if (fv.front() != 0 || ft.front() != 0) return false;
    if (fv.back() != static_cast<std::int64_t>(mesh.vertex_count()) ||
        ft.back() != static_cast<std::int64_t>(mesh.triangle_count()))
        return false;
    if (!std::is_sorted(fv.begin(), fv.end()) || !std::is_sorted(ft.begin(), ft.end())) return false;
    if (ft[static_cast<std::size_t>(nz) - 1] != ft.back()) return false;
    return mesh.triangles.size() % 3 == 0 && mesh.vertex_count() < std::numeric_limits<std::uint32_t>::max();
}

/// Whether the triangles of planes [a, b) use only the vertices SeamTopology's slab [a, b) may
/// see: own ones, and for the last layer the next plane's.
bool slab_ids_fit(const Mesh& mesh, const ExtractedGrid& grid, std::int64_t a, std::int64_t b)
{
    const auto& fv = grid.plane_first_vertex;
    const auto& ft = grid.plane_first_triangle;
    const std::int64_t nz = grid.dims[2];
    const auto at = [](std::span<const std::int64_t> s, std::int64_t i) { return s[static_cast<std::size_t>(i)]; };
    const std::int64_t lo = at(fv, a);
    const auto fits = [&](std::int64_t t0, std::int64_t t1, std::int64_t hi) {
        for (std::int64_t i = 3 * t0; i < 3 * t1; ++i) {
            const std::int64_t v = mesh.triangles[static_cast<std::size_t>(i)];
            if (v < lo || v >= hi) return false;
        }
        return true;
    };
    return fits(at(ft, a), at(ft, b - 1), at(fv, b)) && fits(at(ft, b - 1), at(ft, b), at(fv, std::min(b + 1, nz)));
}

std::span<const std::uint32_t> triangles_of(const Mesh& mesh, std::int64_t t0, std::int64_t t1)
{
    return {mesh.triangles.data() + 3 * t0, static_cast<std::size_t>(3 * (t1 - t0))};
}

/// mesh_topology() slab by slab, or nothing when a slab's triangles use ids it cannot see.
std::optional<MeshTopology> structured_topology(const Mesh& mesh, const ExtractedGrid& grid, int threads,
                                                const std::function<bool()>& tick)
{
    const std::int64_t nz = grid.dims[2];
    // slabs of a few planes: the working memory of each is that of its triangles
    const std::int64_t slabs = std::clamp<std::int64_t>(nz / 4, 1, 64 * std::int64_t{threads});
    const auto first_plane = [&](std::int64_t s) { return nz * s / slabs; };
    const auto& fv = grid.plane_first_vertex;
    const auto& ft = grid.plane_first_triangle;
    // summaries are merged in order as soon as their predecessors are: few wait at any time
    std::vector<std::optional<detail::SeamTopology>> parts(static_cast<std::size_t>(slabs));
    detail::SeamTopology whole;
    std::size_t merged = 0;
    std::mutex merging;
    std::atomic<bool> fits{true};
    detail::for_each_block(
        slabs, threads,
        [&](std::int64_t s, const std::atomic<bool>&) {
            const std::int64_t a = first_plane(s), b = first_plane(s + 1);
            if (!fits || !slab_ids_fit(mesh, grid, a, b)) {
                fits = false;
                return;
            }
            detail::SlabTriangles slab;
            slab.first_vertex = fv[static_cast<std::size_t>(a)];
            slab.vertex_count = fv[static_cast<std::size_t>(b)] - slab.first_vertex;
            slab.triangles = triangles_of(mesh, ft[static_cast<std::size_t>(a)], ft[static_cast<std::size_t>(b)]);
            if (a > 0) slab.below = triangles_of(mesh, ft[static_cast<std::size_t>(a) - 1], ft[static_cast<std::size_t>(a)]);
            detail::SeamTopology summary = detail::SeamTopology::of_slab(slab);
            const std::lock_guard<std::mutex> lock(merging);
            parts[static_cast<std::size_t>(s)] = std::move(summary);
            for (; merged < parts.size() && parts[merged]; ++merged) {
                whole = merged == 0 ? std::move(*parts[0]) : detail::SeamTopology::merge(whole, *parts[merged]);
                parts[merged].reset();
            }
        },
        tick);
    if (!fits) return std::nullopt;
    if (merged != parts.size()) throw Error(Status::internal, "check_extracted_mesh: a slab's topology was not merged");
    return whole.finish();
}

} // namespace

MeshCheck check_extracted_mesh(const Mesh& mesh, const ExtractedGrid& grid, const MeshCheckOptions& options)
{
    const int threads = thread_count(options.threads);
    // the topology is a small part of the work: a fifth of the fraction reported
    const auto report = [&](double fraction) { return !options.progress || options.progress(fraction); };
    MeshCheck check;
    std::optional<MeshTopology> topology;
    std::optional<detail::GridGeometry> geometry;
    if (layout_fits(mesh, grid)) {
        topology = structured_topology(mesh, grid, threads, [&] { return report(0.0); });
        if (topology) {
            if (!report(0.2)) throw Error(Status::cancelled, "the mesh check was cancelled");
            detail::LayeredTriangles layers;
            layers.dims = grid.dims;
            layers.origin = grid.origin;
            layers.frame = frame_matrix(grid.spacing, grid.direction);
            layers.positions = {mesh.positions.data(), mesh.positions.size()};
            layers.triangles = {mesh.triangles.data(), mesh.triangles.size()};
            layers.layer_first = grid.plane_first_triangle.first(static_cast<std::size_t>(grid.dims[2]));
            const std::int64_t cell_layers = grid.dims[2] - 1;
            detail::GridCheckOptions o;
            o.threads = threads;
            o.examples = options.examples;
            o.progress = [&](std::int64_t done) {
                return report(0.2 + 0.8 * static_cast<double>(done) / static_cast<double>(cell_layers));
            };
            geometry = detail::grid_geometry(layers, cell_layers, o);
            if (!geometry->decided()) geometry.reset();
        }
    }
    if (topology && geometry) {
        check.structured = true;
        check.topology = *topology;
        MeshGeometry& g = check.geometry;
        g.positions = topology->vertices; // no two used vertices at one position
        g.zero_area_triangles = geometry->zero_area_triangles;
        g.intersecting_pairs = geometry->intersecting_pairs;
        g.intersection_examples = std::move(geometry->examples);
        g.welded = *topology; // welding merges nothing
        return check;
    }
    check.topology = topology ? *topology : mesh_topology(mesh);
    if (!report(0.2)) throw Error(Status::cancelled, "the mesh check was cancelled");
    check.geometry = mesh_geometry(mesh, MeshGeometryOptions{options.threads, options.examples});
    if (!report(1.0)) throw Error(Status::cancelled, "the mesh check was cancelled");
    return check;
}

} // namespace cmc33
