// smooth(): Taubin's lambda|mu smoothing (Taubin 1995, "A signal processing approach to fair
// surface design") with every vertex move checked exactly and locally.

#include <algorithm>
#include <cmath>
#include <string>

#include "cmc33/error.hpp"
#include "cmc33/mesh_ops.hpp"
#include "work_mesh.hpp"

namespace cmc33 {

namespace {

using mesh_ops::Pos;
using mesh_ops::Refusal;
using mesh_ops::Tri;
using mesh_ops::WorkMesh;

/// One pass of p += factor * (mean of neighbours - p), the umbrella operator. The targets of all
/// vertices are computed first (a Jacobi step, so the result does not depend on vertex order),
/// then the vertices move one by one in index order, each move checked against the mesh as it is.
void pass(WorkMesh& m, double factor, int halvings, SmoothStats& stats, const std::vector<std::vector<std::uint32_t>>& nbrs)
{
    const std::size_t nv = m.pos.size();
    std::vector<std::array<double, 3>> delta(nv, {0, 0, 0});
    for (std::size_t v = 0; v < nv; ++v) {
        if (m.locked[v] || m.boundary[v] || nbrs[v].empty()) continue;
        std::array<double, 3> mean{0, 0, 0};
        for (const std::uint32_t w : nbrs[v])
            for (int k = 0; k < 3; ++k) mean[static_cast<std::size_t>(k)] += static_cast<double>(m.pos[w][static_cast<std::size_t>(k)]);
        for (int k = 0; k < 3; ++k) {
            const std::size_t kk = static_cast<std::size_t>(k);
            delta[v][kk] = factor * (mean[kk] / static_cast<double>(nbrs[v].size()) - static_cast<double>(m.pos[v][kk]));
        }
    }
    std::vector<Tri> new_tris;
    for (std::uint32_t v = 0; v < nv; ++v) {
        if (delta[v][0] == 0 && delta[v][1] == 0 && delta[v][2] == 0) continue;
        new_tris.assign(m.vtris[v].size(), Tri{});
        for (std::size_t i = 0; i < m.vtris[v].size(); ++i) new_tris[i] = m.tri[m.vtris[v][i]];
        double scale = 1;
        bool done = false;
        for (int h = 0; h <= halvings && !done; ++h, scale *= 0.5) {
            Pos p;
            for (int k = 0; k < 3; ++k) {
                const std::size_t kk = static_cast<std::size_t>(k);
                p[kk] = static_cast<float>(static_cast<double>(m.pos[v][kk]) + scale * delta[v][kk]);
            }
            if (p == m.pos[v]) break;
            if (m.check(m.vtris[v], new_tris, v, p, {}) != Refusal::none) continue;
            for (const std::uint32_t t : m.vtris[v]) m.grid.remove(t);
            m.pos[v] = p;
            for (const std::uint32_t t : m.vtris[v]) m.grid.insert(t, m.corners(t));
            ++stats.moves;
            if (h > 0) ++stats.shortened;
            done = true;
        }
        if (!done) ++stats.undone;
    }
}

} // namespace

Mesh smooth(const Mesh& mesh, const SmoothOptions& options, SmoothStats* stats_out)
{
    if (options.iterations < 0) throw Error(Status::invalid_argument, "smooth: iterations must be >= 0");
    if (options.halvings < 0 || options.halvings > 30) throw Error(Status::invalid_argument, "smooth: halvings must be 0 to 30");
    if (!std::isfinite(options.lambda) || !std::isfinite(options.mu)) {
        throw Error(Status::invalid_argument, "smooth: lambda and mu must be finite");
    }
    WorkMesh m(mesh);
    std::vector<std::vector<std::uint32_t>> nbrs(m.pos.size());
    for (std::uint32_t v = 0; v < m.pos.size(); ++v) {
        for (const std::uint32_t t : m.vtris[v])
            for (const std::uint32_t w : m.tri[t])
                if (w != v) nbrs[v].push_back(w);
        std::sort(nbrs[v].begin(), nbrs[v].end());
        nbrs[v].erase(std::unique(nbrs[v].begin(), nbrs[v].end()), nbrs[v].end());
    }
    SmoothStats stats;
    for (int i = 0; i < options.iterations; ++i) {
        pass(m, options.lambda, options.halvings, stats, nbrs);
        pass(m, options.mu, options.halvings, stats, nbrs);
        if (options.progress && !options.progress(static_cast<double>(i + 1) / options.iterations)) {
            throw Error(Status::cancelled, "smooth: cancelled");
        }
    }
    if (stats_out) *stats_out = stats;
    return m.to_mesh(mesh.has_normals());
}

} // namespace cmc33
