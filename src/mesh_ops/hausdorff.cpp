// hausdorff_distance() and compare_meshes(): the report of a simplification or smoothing.

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>

#include "cmc33/error.hpp"
#include "cmc33/mesh_ops.hpp"
#include "parallel.hpp"
#include "work_mesh.hpp"

namespace cmc33 {

namespace {

using mesh_ops::V3;

using mesh_ops::dot;
using mesh_ops::point_triangle_sq;
using mesh_ops::sub;

V3 vertex(const Mesh& m, std::uint32_t v)
{
    return {static_cast<double>(m.positions[3 * v]), static_cast<double>(m.positions[3 * v + 1]),
            static_cast<double>(m.positions[3 * v + 2])};
}

/// Nearest-triangle queries on one mesh: triangles by the cells of a uniform grid their boxes
/// overlap; a query visits shells of cells around the point until the shell is farther than the
/// best distance found.
class NearestTriangle {
public:
    explicit NearestTriangle(const Mesh& m) : m_(m)
    {
        const std::size_t nt = m.triangle_count();
        lo_ = {std::numeric_limits<double>::max(), std::numeric_limits<double>::max(), std::numeric_limits<double>::max()};
        V3 hi{-lo_[0], -lo_[1], -lo_[2]};
        double edge = 0;
        for (std::size_t t = 0; t < nt; ++t) {
            for (int i = 0; i < 3; ++i) {
                const V3 p = vertex(m, m.triangles[3 * t + static_cast<std::size_t>(i)]);
                const V3 q = vertex(m, m.triangles[3 * t + static_cast<std::size_t>((i + 1) % 3)]);
                for (int k = 0; k < 3; ++k) {
                    lo_[static_cast<std::size_t>(k)] = std::min(lo_[static_cast<std::size_t>(k)], p[static_cast<std::size_t>(k)]);
                    hi[static_cast<std::size_t>(k)] = std::max(hi[static_cast<std::size_t>(k)], p[static_cast<std::size_t>(k)]);
                }
                const V3 d = sub(p, q);
                edge += std::sqrt(dot(d, d));
            }
        }
        double cell = nt ? 2 * edge / static_cast<double>(3 * nt) : 1;
        if (!(cell > 0)) cell = 1;
        const double maxc = static_cast<double>(std::max<std::size_t>(nt, 64));
        V3 ext = sub(hi, lo_);
        while ((ext[0] / cell + 1) * (ext[1] / cell + 1) * (ext[2] / cell + 1) > maxc) cell *= 1.25;
        cell_ = cell;
        for (int k = 0; k < 3; ++k) dims_[static_cast<std::size_t>(k)] = std::max(1, static_cast<int>(ext[static_cast<std::size_t>(k)] / cell) + 1);
        // counting sort of (cell, triangle) pairs
        std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
        for (std::size_t t = 0; t < nt; ++t) {
            V3 a = vertex(m, m.triangles[3 * t]), b = vertex(m, m.triangles[3 * t + 1]), c = vertex(m, m.triangles[3 * t + 2]);
            std::array<int, 3> l{}, h{};
            for (int k = 0; k < 3; ++k) {
                const std::size_t kk = static_cast<std::size_t>(k);
                l[kk] = clampc(std::min({a[kk], b[kk], c[kk]}), k);
                h[kk] = clampc(std::max({a[kk], b[kk], c[kk]}), k);
            }
            for (int z = l[2]; z <= h[2]; ++z)
                for (int y = l[1]; y <= h[1]; ++y)
                    for (int x = l[0]; x <= h[0]; ++x) pairs.emplace_back(index(x, y, z), static_cast<std::uint32_t>(t));
        }
        start_.assign(static_cast<std::size_t>(dims_[0]) * static_cast<std::size_t>(dims_[1]) * static_cast<std::size_t>(dims_[2]) + 1, 0);
        for (const auto& pr : pairs) ++start_[pr.first + 1];
        for (std::size_t i = 1; i < start_.size(); ++i) start_[i] += start_[i - 1];
        items_.resize(pairs.size());
        std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
        for (const auto& pr : pairs) items_[fill[pr.first]++] = pr.second;
    }

    /// Distance from p to the nearest triangle.
    double distance(const V3& p) const
    {
        if (m_.triangle_count() == 0) return std::numeric_limits<double>::infinity();
        std::array<int, 3> c{};
        for (int k = 0; k < 3; ++k) c[static_cast<std::size_t>(k)] = clampc(p[static_cast<std::size_t>(k)], k);
        // distance from p to the outside of the box of cells within ring r of c (for the stop rule)
        double best = std::numeric_limits<double>::infinity();
        const int max_r = std::max({dims_[0], dims_[1], dims_[2]});
        for (int r = 0; r <= max_r; ++r) {
            for (int z = c[2] - r; z <= c[2] + r; ++z) {
                if (z < 0 || z >= dims_[2]) continue;
                for (int y = c[1] - r; y <= c[1] + r; ++y) {
                    if (y < 0 || y >= dims_[1]) continue;
                    for (int x = c[0] - r; x <= c[0] + r; ++x) {
                        if (x < 0 || x >= dims_[0]) continue;
                        if (std::max({std::abs(x - c[0]), std::abs(y - c[1]), std::abs(z - c[2])}) != r) continue;
                        const std::uint32_t cell = index(x, y, z);
                        for (std::uint32_t i = start_[cell]; i < start_[cell + 1]; ++i) {
                            const std::uint32_t t = items_[i];
                            const double d = point_triangle_sq(p, vertex(m_, m_.triangles[3 * t]), vertex(m_, m_.triangles[3 * t + 1]),
                                                               vertex(m_, m_.triangles[3 * t + 2]));
                            best = std::min(best, d);
                        }
                    }
                }
            }
            // every point outside the cells of ring <= r is at least this far from p
            double reach = std::numeric_limits<double>::infinity();
            for (int k = 0; k < 3; ++k) {
                const std::size_t kk = static_cast<std::size_t>(k);
                const double lo = lo_[kk] + (c[kk] - r) * cell_;
                const double hi = lo_[kk] + (c[kk] + r + 1) * cell_;
                if (c[kk] - r > 0) reach = std::min(reach, p[kk] - lo);
                if (c[kk] + r + 1 < dims_[k]) reach = std::min(reach, hi - p[kk]);
            }
            if (best <= reach * reach) break;
        }
        return std::sqrt(best);
    }

private:
    int clampc(double x, int k) const
    {
        const double f = (x - lo_[static_cast<std::size_t>(k)]) / cell_;
        return f <= 0 ? 0 : (f >= dims_[static_cast<std::size_t>(k)] - 1 ? dims_[static_cast<std::size_t>(k)] - 1 : static_cast<int>(f));
    }
    std::uint32_t index(int x, int y, int z) const
    {
        return static_cast<std::uint32_t>((static_cast<std::size_t>(z) * static_cast<std::size_t>(dims_[1]) + static_cast<std::size_t>(y)) *
                                              static_cast<std::size_t>(dims_[0]) +
                                          static_cast<std::size_t>(x));
    }
    const Mesh& m_;
    V3 lo_{};
    double cell_ = 1;
    std::array<int, 3> dims_{1, 1, 1};
    std::vector<std::uint32_t> start_, items_;
};

/// The samples of `from` (see HausdorffResult) against `to`: max and mean distance.
void one_side(const Mesh& from, const Mesh& to, double spacing, int threads, double& max_d, double& mean_d, std::int64_t& count)
{
    const NearestTriangle near(to);
    const std::size_t nt = from.triangle_count();
    std::vector<std::uint8_t> used(from.vertex_count(), 0);
    for (const std::uint32_t v : from.triangles) used[v] = 1;
    const int n_threads = thread_count(threads);
    struct Part {
        double max = 0, sum = 0;
        std::int64_t count = 0;
    };
    // chunks of vertices then of triangles; each chunk's sums are added in chunk order
    const std::int64_t nv = static_cast<std::int64_t>(from.vertex_count());
    const std::int64_t total = nv + static_cast<std::int64_t>(nt);
    const std::int64_t chunks = std::min<std::int64_t>(std::max<std::int64_t>(total, 1), 256);
    std::vector<Part> parts(static_cast<std::size_t>(chunks));
    detail::parallel_chunks(chunks, n_threads, [&](int, std::int64_t cb, std::int64_t ce) {
        for (std::int64_t ch = cb; ch < ce; ++ch) {
            Part& part = parts[static_cast<std::size_t>(ch)];
            const std::int64_t b = total * ch / chunks, e = total * (ch + 1) / chunks;
            auto add = [&](const V3& p) {
                const double d = near.distance(p);
                part.max = std::max(part.max, d);
                part.sum += d;
                ++part.count;
            };
            for (std::int64_t i = b; i < e; ++i) {
                if (i < nv) {
                    if (used[static_cast<std::size_t>(i)]) add(vertex(from, static_cast<std::uint32_t>(i)));
                    continue;
                }
                const std::size_t t = static_cast<std::size_t>(i - nv);
                const V3 a = vertex(from, from.triangles[3 * t]), bb = vertex(from, from.triangles[3 * t + 1]),
                         c = vertex(from, from.triangles[3 * t + 2]);
                const V3 e1 = sub(bb, a), e2 = sub(c, bb), e3 = sub(a, c);
                const double longest = std::sqrt(std::max({dot(e1, e1), dot(e2, e2), dot(e3, e3)}));
                const int n = std::min(256, std::max(1, static_cast<int>(std::ceil(longest / spacing))));
                add({(a[0] + bb[0] + c[0]) / 3, (a[1] + bb[1] + c[1]) / 3, (a[2] + bb[2] + c[2]) / 3});
                if (n == 1) continue;
                // the barycentric grid (i/n, j/n, k/n), i + j + k = n, corners left out (vertices)
                for (int u = 0; u <= n; ++u)
                    for (int v = 0; v <= n - u; ++v) {
                        const int w = n - u - v;
                        if (u == n || v == n || w == n) continue;
                        const double fu = u / static_cast<double>(n), fv = v / static_cast<double>(n), fw = w / static_cast<double>(n);
                        add({fu * a[0] + fv * bb[0] + fw * c[0], fu * a[1] + fv * bb[1] + fw * c[1], fu * a[2] + fv * bb[2] + fw * c[2]});
                    }
            }
        }
    });
    max_d = 0;
    double sum = 0;
    count = 0;
    for (const Part& p : parts) {
        max_d = std::max(max_d, p.max);
        sum += p.sum;
        count += p.count;
    }
    mean_d = count ? sum / static_cast<double>(count) : 0;
}

} // namespace

HausdorffResult hausdorff_distance(const Mesh& a, const Mesh& b, double spacing, int threads)
{
    if (!(spacing > 0)) {
        double sum = 0;
        std::int64_t n = 0;
        for (std::size_t t = 0; t < a.triangle_count(); ++t) {
            for (int i = 0; i < 3; ++i) {
                const V3 d = sub(vertex(a, a.triangles[3 * t + static_cast<std::size_t>(i)]),
                                 vertex(a, a.triangles[3 * t + static_cast<std::size_t>((i + 1) % 3)]));
                sum += std::sqrt(dot(d, d));
                ++n;
            }
        }
        spacing = n && sum > 0 ? sum / static_cast<double>(n) : 1;
    }
    HausdorffResult r;
    one_side(a, b, spacing, threads, r.a_to_b, r.mean_a_to_b, r.samples_a);
    one_side(b, a, spacing, threads, r.b_to_a, r.mean_b_to_a, r.samples_b);
    return r;
}

bool MeshOpsReport::topology_same() const noexcept
{
    const MeshTopology& a = topology_before;
    const MeshTopology& b = topology_after;
    return a.euler == b.euler && a.components == b.components && a.closed_components == b.closed_components &&
           a.b1 == b.b1 && a.boundary_loops == b.boundary_loops && a.nonmanifold_edges == b.nonmanifold_edges &&
           a.nonmanifold_vertices == b.nonmanifold_vertices && a.closed == b.closed && a.oriented == b.oriented;
}

MeshOpsReport compare_meshes(const Mesh& before, const Mesh& after, int threads)
{
    MeshOpsReport r;
    r.topology_before = mesh_topology(before);
    r.topology_after = mesh_topology(after);
    MeshGeometryOptions g;
    g.threads = threads;
    r.geometry_before = mesh_geometry(before, g);
    r.geometry_after = mesh_geometry(after, g);
    r.hausdorff = hausdorff_distance(before, after, 0, threads);
    return r;
}

} // namespace cmc33
