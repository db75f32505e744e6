// The editable mesh of simplify() and smooth(): incident triangles, grid, exact local checks.

#include "work_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "cmc33/error.hpp"
#include "exact_geometry.hpp"

namespace cmc33::mesh_ops {

namespace {

using detail::Point3;

Point3 to_point(const Pos& p) { return {static_cast<double>(p[0]), static_cast<double>(p[1]), static_cast<double>(p[2])}; }

std::array<double, 3> normal_of(const Pos& a, const Pos& b, const Pos& c)
{
    const double ux = static_cast<double>(b[0]) - static_cast<double>(a[0]);
    const double uy = static_cast<double>(b[1]) - static_cast<double>(a[1]);
    const double uz = static_cast<double>(b[2]) - static_cast<double>(a[2]);
    const double vx = static_cast<double>(c[0]) - static_cast<double>(a[0]);
    const double vy = static_cast<double>(c[1]) - static_cast<double>(a[1]);
    const double vz = static_cast<double>(c[2]) - static_cast<double>(a[2]);
    return {uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx};
}

void box_of(const std::array<Pos, 3>& c, Pos& lo, Pos& hi)
{
    for (int k = 0; k < 3; ++k) {
        lo[k] = std::min({c[0][k], c[1][k], c[2][k]});
        hi[k] = std::max({c[0][k], c[1][k], c[2][k]});
    }
}

bool boxes_overlap(const Pos& alo, const Pos& ahi, const Pos& blo, const Pos& bhi)
{
    for (int k = 0; k < 3; ++k) {
        if (ahi[k] < blo[k] || bhi[k] < alo[k]) return false;
    }
    return true;
}

/// Small union-find over the link of one vertex (a handful of entries).
int find_root(std::vector<int>& parent, int i)
{
    while (parent[static_cast<std::size_t>(i)] != i) i = parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    return i;
}

} // namespace

std::array<int, 3> TriangleGrid::cell_of(const Pos& p) const
{
    std::array<int, 3> c{};
    for (int k = 0; k < 3; ++k) {
        const double f = (static_cast<double>(p[k]) - origin_[k]) * inv_cell_;
        c[k] = f <= 0 ? 0 : (f >= dims_[k] - 1 ? dims_[k] - 1 : static_cast<int>(f));
    }
    return c;
}

void TriangleGrid::build(const std::vector<Pos>& pos, const std::vector<Tri>& tri, const std::vector<std::uint8_t>& alive)
{
    Pos lo{std::numeric_limits<float>::max(), std::numeric_limits<float>::max(), std::numeric_limits<float>::max()};
    Pos hi{-lo[0], -lo[1], -lo[2]};
    double edge_sum = 0;
    std::int64_t live = 0;
    for (std::size_t t = 0; t < tri.size(); ++t) {
        if (!alive[t]) continue;
        ++live;
        for (int i = 0; i < 3; ++i) {
            const Pos& a = pos[tri[t][static_cast<std::size_t>(i)]];
            const Pos& b = pos[tri[t][static_cast<std::size_t>((i + 1) % 3)]];
            for (int k = 0; k < 3; ++k) {
                lo[k] = std::min(lo[k], a[k]);
                hi[k] = std::max(hi[k], a[k]);
            }
            const double dx = static_cast<double>(a[0]) - static_cast<double>(b[0]);
            const double dy = static_cast<double>(a[1]) - static_cast<double>(b[1]);
            const double dz = static_cast<double>(a[2]) - static_cast<double>(b[2]);
            edge_sum += std::sqrt(dx * dx + dy * dy + dz * dz);
        }
    }
    cells_.clear();
    range_.assign(tri.size(), {0, 0, 0, -1, -1, -1});
    mark_.assign(tri.size(), 0);
    stamp_ = 0;
    if (live == 0) {
        dims_ = {1, 1, 1};
        cells_.resize(1);
        return;
    }
    // cells about twice the mean edge: a fan of triangles spans few cells, a cell holds few; at most
    // about four cells per live triangle (and never below 1 per axis)
    double cell = 2 * edge_sum / static_cast<double>(3 * live);
    double extent[3];
    for (int k = 0; k < 3; ++k) extent[k] = static_cast<double>(hi[k]) - static_cast<double>(lo[k]);
    if (!(cell > 0)) cell = std::max({extent[0], extent[1], extent[2], 1.0});
    const double max_cells = static_cast<double>(std::max<std::int64_t>(4 * live, 64));
    while ((extent[0] / cell + 1) * (extent[1] / cell + 1) * (extent[2] / cell + 1) > max_cells) cell *= 1.25;
    for (int k = 0; k < 3; ++k) {
        origin_[k] = static_cast<double>(lo[k]);
        dims_[k] = std::max(1, static_cast<int>(extent[k] / cell) + 1);
    }
    inv_cell_ = 1 / cell;
    cells_.resize(static_cast<std::size_t>(dims_[0]) * static_cast<std::size_t>(dims_[1]) * static_cast<std::size_t>(dims_[2]));
    for (std::size_t t = 0; t < tri.size(); ++t) {
        if (alive[t]) insert(static_cast<std::uint32_t>(t), {pos[tri[t][0]], pos[tri[t][1]], pos[tri[t][2]]});
    }
}

void TriangleGrid::insert(std::uint32_t t, const std::array<Pos, 3>& corners)
{
    Pos lo, hi;
    box_of(corners, lo, hi);
    const auto a = cell_of(lo);
    const auto b = cell_of(hi);
    range_[t] = {a[0], a[1], a[2], b[0], b[1], b[2]};
    for (int z = a[2]; z <= b[2]; ++z)
        for (int y = a[1]; y <= b[1]; ++y)
            for (int x = a[0]; x <= b[0]; ++x) {
                cells_[(static_cast<std::size_t>(z) * static_cast<std::size_t>(dims_[1]) + static_cast<std::size_t>(y)) *
                           static_cast<std::size_t>(dims_[0]) +
                       static_cast<std::size_t>(x)]
                    .push_back(t);
            }
}

void TriangleGrid::remove(std::uint32_t t)
{
    const auto r = range_[t];
    for (int z = r[2]; z <= r[5]; ++z)
        for (int y = r[1]; y <= r[4]; ++y)
            for (int x = r[0]; x <= r[3]; ++x) {
                auto& cell = cells_[(static_cast<std::size_t>(z) * static_cast<std::size_t>(dims_[1]) +
                                     static_cast<std::size_t>(y)) * static_cast<std::size_t>(dims_[0]) +
                                    static_cast<std::size_t>(x)];
                const auto it = std::find(cell.begin(), cell.end(), t);
                if (it != cell.end()) {
                    *it = cell.back();
                    cell.pop_back();
                }
            }
    range_[t] = {0, 0, 0, -1, -1, -1};
}

WorkMesh::WorkMesh(const Mesh& mesh)
{
    const std::size_t nv = mesh.vertex_count();
    const std::size_t nt = mesh.triangle_count();
    if (mesh.positions.size() % 3 != 0 || mesh.triangles.size() % 3 != 0) {
        throw Error(Status::invalid_argument, "mesh: the position or index array is not a multiple of 3");
    }
    if (nt >= 0xffffffffULL || nv >= 0xffffffffULL) throw Error(Status::too_large, "mesh: too many triangles or vertices");
    pos.assign(nv, Pos{0, 0, 0});
    for (std::size_t v = 0; v < nv; ++v) {
        for (int k = 0; k < 3; ++k) {
            const float x = mesh.positions[3 * v + static_cast<std::size_t>(k)];
            if (!std::isfinite(x)) {
                throw Error(Status::invalid_argument, "mesh: vertex " + std::to_string(v) + " has a non-finite coordinate");
            }
            pos[v][static_cast<std::size_t>(k)] = x;
        }
    }
    tri.assign(nt, Tri{0, 0, 0});
    alive.assign(nt, 1);
    locked.assign(nv, 0);
    boundary.assign(nv, 0);
    vtris.assign(nv, {});
    for (std::size_t t = 0; t < nt; ++t) {
        for (int i = 0; i < 3; ++i) {
            const std::uint32_t v = mesh.triangles[3 * t + static_cast<std::size_t>(i)];
            if (v >= nv) {
                throw Error(Status::invalid_argument, "mesh: triangle " + std::to_string(t) + " uses vertex " +
                                                          std::to_string(v) + ", expected below " + std::to_string(nv));
            }
            tri[t][static_cast<std::size_t>(i)] = v;
        }
        const Tri& c = tri[t];
        const bool degenerate = c[0] == c[1] || c[1] == c[2] || c[0] == c[2] ||
                                detail::collinear(to_point(pos[c[0]]), to_point(pos[c[1]]), to_point(pos[c[2]]));
        for (const std::uint32_t v : c) {
            if (degenerate) locked[v] = 1;
            if (vtris[v].empty() || vtris[v].back() != t) vtris[v].push_back(static_cast<std::uint32_t>(t));
        }
    }
    alive_count = static_cast<std::int64_t>(nt);
    // Per vertex: its edges' triangle counts, and whether its link is one cycle or one path.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> link;
    std::vector<std::uint32_t> ids;
    std::vector<int> parent, degree;
    for (std::uint32_t v = 0; v < nv; ++v) {
        if (vtris[v].empty()) continue;
        link.clear();
        ids.clear();
        for (const std::uint32_t t : vtris[v]) {
            const Tri& c = tri[t];
            std::uint32_t o[2];
            int n = 0;
            for (const std::uint32_t w : c) {
                if (w != v && n < 2) o[n++] = w;
            }
            if (n < 2) {
                locked[v] = 1;
                continue;
            }
            link.emplace_back(o[0], o[1]);
            ids.push_back(o[0]);
            ids.push_back(o[1]);
        }
        std::sort(ids.begin(), ids.end());
        // each neighbour w: how many triangles hold edge vw (= its degree in the link)
        std::vector<std::uint32_t> uniq = ids;
        uniq.erase(std::unique(uniq.begin(), uniq.end()), uniq.end());
        degree.assign(uniq.size(), 0);
        parent.resize(uniq.size());
        for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
        auto index = [&](std::uint32_t w) {
            return static_cast<int>(std::lower_bound(uniq.begin(), uniq.end(), w) - uniq.begin());
        };
        for (const auto& [a, b] : link) {
            const int ia = index(a);
            const int ib = index(b);
            ++degree[static_cast<std::size_t>(ia)];
            ++degree[static_cast<std::size_t>(ib)];
            parent[static_cast<std::size_t>(find_root(parent, ia))] = find_root(parent, ib);
        }
        int roots = 0, ends = 0;
        for (std::size_t i = 0; i < uniq.size(); ++i) {
            if (find_root(parent, static_cast<int>(i)) == static_cast<int>(i)) ++roots;
            if (degree[i] > 2) {
                locked[v] = 1;
                locked[uniq[i]] = 1;
            }
            if (degree[i] == 1) {
                ++ends;
                boundary[v] = 1;
            }
        }
        if (roots != 1 || (ends != 0 && ends != 2)) locked[v] = 1;
    }
    grid.build(pos, tri, alive);
    grid_built_at = alive_count;
}

void WorkMesh::maybe_rebuild_grid()
{
    if (alive_count * 2 < grid_built_at) {
        grid.build(pos, tri, alive);
        grid_built_at = alive_count;
    }
}

Refusal WorkMesh::check(std::span<const std::uint32_t> changed, std::span<const Tri> new_tris, std::uint32_t moved,
                        const Pos& p, std::span<const std::uint32_t> ignore)
{
    auto position = [&](std::uint32_t v) -> const Pos& { return v == moved ? p : pos[v]; };
    // 1. no zero area, no turn by more than 90 degrees
    for (std::size_t i = 0; i < changed.size(); ++i) {
        const Tri& c = new_tris[i];
        const Pos& a = position(c[0]);
        const Pos& b = position(c[1]);
        const Pos& d = position(c[2]);
        if (detail::collinear(to_point(a), to_point(b), to_point(d))) return Refusal::flip;
        const auto n_new = normal_of(a, b, d);
        const Tri& o = tri[changed[i]];
        const auto n_old = normal_of(pos[o[0]], pos[o[1]], pos[o[2]]);
        if (n_new[0] * n_old[0] + n_new[1] * n_old[1] + n_new[2] * n_old[2] <= 0) return Refusal::flip;
    }
    // 2. each changed triangle against every live triangle whose box meets its box: one grid
    // query for the box of all changed triangles, then box tests per pair, then the exact test
    const std::size_t nc = changed.size();
    std::array<Pos, 3> tc{};
    Pos all_lo{}, all_hi{};
    cand_lo_.resize(nc);
    cand_hi_.resize(nc);
    for (std::size_t i = 0; i < nc; ++i) {
        const Tri& c = new_tris[i];
        tc = {position(c[0]), position(c[1]), position(c[2])};
        box_of(tc, cand_lo_[i], cand_hi_[i]);
        for (int k = 0; k < 3; ++k) {
            all_lo[k] = i == 0 ? cand_lo_[i][k] : std::min(all_lo[k], cand_lo_[i][k]);
            all_hi[k] = i == 0 ? cand_hi_[i][k] : std::max(all_hi[k], cand_hi_[i][k]);
        }
    }
    // the others: live, not changed, not vanishing
    scratch_.clear();
    grid.query(all_lo, all_hi, [&](std::uint32_t s) {
        if (!alive[s]) return;
        if (std::find(ignore.begin(), ignore.end(), s) != ignore.end()) return;
        if (std::find(changed.begin(), changed.end(), s) != changed.end()) return;
        scratch_.push_back(s);
    });
    auto meet = [&](const Tri& c, const Tri& d) {
        std::array<std::uint32_t, 3> ta{}, tb{};
        int shared = 0;
        for (const std::uint32_t v : c) {
            if (v == d[0] || v == d[1] || v == d[2]) {
                ta[static_cast<std::size_t>(shared)] = v;
                tb[static_cast<std::size_t>(shared)] = v;
                ++shared;
            }
        }
        if (shared == 3) return true;
        int na = shared, nb = shared;
        for (const std::uint32_t v : c) {
            if (na < 3 && v != d[0] && v != d[1] && v != d[2]) ta[static_cast<std::size_t>(na++)] = v;
        }
        for (const std::uint32_t v : d) {
            if (nb < 3 && v != c[0] && v != c[1] && v != c[2]) tb[static_cast<std::size_t>(nb++)] = v;
        }
        const std::array<Point3, 3> pa{to_point(position(ta[0])), to_point(position(ta[1])), to_point(position(ta[2]))};
        const std::array<Point3, 3> pb{to_point(position(tb[0])), to_point(position(tb[1])), to_point(position(tb[2]))};
        return detail::triangles_meet_improperly(pa, pb, shared);
    };
    for (const std::uint32_t s : scratch_) {
        const Tri& d = tri[s];
        const std::array<Pos, 3> sc{pos[d[0]], pos[d[1]], pos[d[2]]};
        Pos slo, shi;
        box_of(sc, slo, shi);
        if (!boxes_overlap(all_lo, all_hi, slo, shi)) continue;
        bool degenerate_checked = false;
        for (std::size_t i = 0; i < nc; ++i) {
            if (!boxes_overlap(cand_lo_[i], cand_hi_[i], slo, shi)) continue;
            if (!degenerate_checked) {
                degenerate_checked = true;
                // a degenerate input triangle nearby (its corners are locked): no exact test applies, refuse
                if (locked[d[0]] && locked[d[1]] && locked[d[2]] &&
                    detail::collinear(to_point(sc[0]), to_point(sc[1]), to_point(sc[2]))) {
                    return Refusal::intersection;
                }
            }
            if (meet(new_tris[i], d)) return Refusal::intersection;
        }
    }
    // the changed triangles among themselves
    for (std::size_t i = 0; i < nc; ++i)
        for (std::size_t j = i + 1; j < nc; ++j) {
            if (!boxes_overlap(cand_lo_[i], cand_hi_[i], cand_lo_[j], cand_hi_[j])) continue;
            if (meet(new_tris[i], new_tris[j])) return Refusal::intersection;
        }
    return Refusal::none;
}

Mesh WorkMesh::to_mesh(bool normals) const
{
    Mesh out;
    std::vector<std::uint32_t> remap(pos.size(), 0xffffffffU);
    for (std::size_t t = 0; t < tri.size(); ++t) {
        if (!alive[t]) continue;
        for (const std::uint32_t v : tri[t]) remap[v] = 0;
    }
    std::uint32_t next = 0;
    for (std::size_t v = 0; v < pos.size(); ++v) {
        if (remap[v] == 0xffffffffU) continue;
        remap[v] = next++;
        out.positions.insert(out.positions.end(), pos[v].begin(), pos[v].end());
    }
    out.triangles.reserve(static_cast<std::size_t>(alive_count) * 3);
    for (std::size_t t = 0; t < tri.size(); ++t) {
        if (!alive[t]) continue;
        for (const std::uint32_t v : tri[t]) out.triangles.push_back(remap[v]);
    }
    if (normals) compute_normals(out);
    return out;
}

void compute_normals(Mesh& mesh)
{
    const std::size_t nv = mesh.vertex_count();
    std::vector<double> acc(3 * nv, 0.0);
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        const std::uint32_t* c = &mesh.triangles[3 * t];
        const Pos a{mesh.positions[3 * c[0]], mesh.positions[3 * c[0] + 1], mesh.positions[3 * c[0] + 2]};
        const Pos b{mesh.positions[3 * c[1]], mesh.positions[3 * c[1] + 1], mesh.positions[3 * c[1] + 2]};
        const Pos d{mesh.positions[3 * c[2]], mesh.positions[3 * c[2] + 1], mesh.positions[3 * c[2] + 2]};
        const auto n = normal_of(a, b, d); // twice the area, so the sum is area-weighted
        for (int i = 0; i < 3; ++i)
            for (int k = 0; k < 3; ++k) acc[3 * c[i] + static_cast<std::size_t>(k)] += n[static_cast<std::size_t>(k)];
    }
    mesh.normals.resize(3 * nv);
    for (std::size_t v = 0; v < nv; ++v) {
        const double l = std::sqrt(acc[3 * v] * acc[3 * v] + acc[3 * v + 1] * acc[3 * v + 1] + acc[3 * v + 2] * acc[3 * v + 2]);
        for (int k = 0; k < 3; ++k) {
            const std::size_t i = 3 * v + static_cast<std::size_t>(k);
            mesh.normals[i] = l > 0 ? static_cast<float>(acc[i] / l) : (k == 2 ? 1.0F : 0.0F);
        }
    }
}

// Squared distance from p to the closed triangle abc, by the region of the triangle's plane p
/// projects to (a corner, an edge or the inside), from the barycentric signs.
double point_triangle_sq(const V3& p, const V3& a, const V3& b, const V3& c)
{
    const V3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
    const double d1 = dot(ab, ap), d2 = dot(ac, ap);
    auto sq = [&](const V3& q) { const V3 d = sub(p, q); return dot(d, d); };
    if (d1 <= 0 && d2 <= 0) return sq(a);
    const V3 bp = sub(p, b);
    const double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return sq(b);
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        const double v = d1 / (d1 - d3);
        return sq({a[0] + v * ab[0], a[1] + v * ab[1], a[2] + v * ab[2]});
    }
    const V3 cp = sub(p, c);
    const double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return sq(c);
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        const double w = d2 / (d2 - d6);
        return sq({a[0] + w * ac[0], a[1] + w * ac[1], a[2] + w * ac[2]});
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return sq({b[0] + w * (c[0] - b[0]), b[1] + w * (c[1] - b[1]), b[2] + w * (c[2] - b[2])});
    }
    const double denom = 1 / (va + vb + vc);
    const double v = vb * denom, w = vc * denom;
    return sq({a[0] + ab[0] * v + ac[0] * w, a[1] + ab[1] * v + ac[1] * w, a[2] + ab[2] * v + ac[2] * w});
}

} // namespace cmc33::mesh_ops
