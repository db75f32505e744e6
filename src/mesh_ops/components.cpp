// filter_components(): components by edge connectivity, the largest or those above a size.

#include <algorithm>
#include <numeric>
#include <string>
#include <utility>

#include "cmc33/error.hpp"
#include "cmc33/mesh_ops.hpp"

namespace cmc33 {

Mesh filter_components(const Mesh& mesh, const ComponentFilter& filter, std::int64_t* dropped_components)
{
    const std::size_t nt = mesh.triangle_count();
    const std::size_t nv = mesh.vertex_count();
    for (const std::uint32_t v : mesh.triangles) {
        if (v >= nv) throw Error(Status::invalid_argument, "mesh: a triangle uses vertex " + std::to_string(v) + ", expected below " + std::to_string(nv));
    }
    if (nt == 0) {
        if (dropped_components) *dropped_components = 0;
        return Mesh{};
    }
    std::vector<std::uint32_t> parent(nt);
    std::iota(parent.begin(), parent.end(), 0U);
    auto find = [&](std::uint32_t x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
    };
    // triangles sharing an undirected edge are joined
    std::vector<std::pair<std::uint64_t, std::uint32_t>> edges;
    edges.reserve(3 * nt);
    for (std::size_t t = 0; t < nt; ++t) {
        for (int i = 0; i < 3; ++i) {
            std::uint64_t a = mesh.triangles[3 * t + static_cast<std::size_t>(i)];
            std::uint64_t b = mesh.triangles[3 * t + static_cast<std::size_t>((i + 1) % 3)];
            if (a > b) std::swap(a, b);
            edges.emplace_back((a << 32) | b, static_cast<std::uint32_t>(t));
        }
    }
    std::sort(edges.begin(), edges.end());
    for (std::size_t i = 1; i < edges.size(); ++i) {
        if (edges[i].first == edges[i - 1].first) parent[find(edges[i].second)] = find(edges[i - 1].second);
    }
    std::vector<std::int64_t> size(nt, 0);
    for (std::uint32_t t = 0; t < nt; ++t) ++size[find(t)];
    std::vector<std::uint8_t> keep(nt, 0);
    std::uint32_t largest = 0;
    std::int64_t components = 0;
    for (std::uint32_t t = 0; t < nt; ++t) {
        if (find(t) != t) continue;
        ++components;
        if (size[t] > size[largest] || find(largest) != largest) largest = t;
    }
    std::int64_t kept = 0;
    for (std::uint32_t t = 0; t < nt; ++t) {
        if (find(t) != t) continue;
        const bool k = (!filter.largest || t == largest) && size[t] >= filter.min_triangles;
        keep[t] = k ? 1 : 0;
        kept += k ? 1 : 0;
    }
    if (dropped_components) *dropped_components = components - kept;
    Mesh out;
    std::vector<std::uint32_t> remap(nv, 0xffffffffU);
    for (std::uint32_t t = 0; t < nt; ++t) {
        if (!keep[find(t)]) continue;
        for (int i = 0; i < 3; ++i) remap[mesh.triangles[3 * t + static_cast<std::size_t>(i)]] = 0;
    }
    std::uint32_t next = 0;
    for (std::size_t v = 0; v < nv; ++v) {
        if (remap[v] != 0) continue;
        remap[v] = next++;
        out.positions.insert(out.positions.end(), mesh.positions.begin() + static_cast<std::ptrdiff_t>(3 * v),
                             mesh.positions.begin() + static_cast<std::ptrdiff_t>(3 * v + 3));
        if (mesh.has_normals()) {
            out.normals.insert(out.normals.end(), mesh.normals.begin() + static_cast<std::ptrdiff_t>(3 * v),
                               mesh.normals.begin() + static_cast<std::ptrdiff_t>(3 * v + 3));
        }
    }
    for (std::uint32_t t = 0; t < nt; ++t) {
        if (!keep[find(t)]) continue;
        for (int i = 0; i < 3; ++i) out.triangles.push_back(remap[mesh.triangles[3 * t + static_cast<std::size_t>(i)]]);
    }
    return out;
}

} // namespace cmc33
