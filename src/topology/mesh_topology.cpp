// Combinatorial invariants of an indexed triangle mesh (contract in src/topology/include/cmc33/topology.hpp).
//
// Everything comes from one structure: for every vertex v, the (next, previous) vertex pair of each
// non-degenerate triangle at v, bucketed by v with a counting sort (CSR). Per vertex, the 2k
// keys (w << 32 | triangle slot << 1 | direction), sorted, group v's triangles by edge {v, w}:
//   - edges: a run with w > v is one undirected edge counted once, at its smaller end. The counting
//     sort on v is the most significant digit, so this is a sort of all keys (min << 32 | max)
//     without a map or a hash; the run length is the edge's triangle count, the direction bits
//     say whether its two triangles traverse it in opposite directions;
//   - fans: triangles in one run share an edge at v; a union-find over v's k triangles merges
//     them, and more than one resulting group makes v non-manifold.
// Components and boundary loops use union-find over the vertices.
// Cost: O(F) time and memory (24 bytes per triangle plus 13 per vertex) plus the per-vertex sorts
// (insertion sort on typical degrees). Measured: 20M triangles in about 1.5 s (g++ -O2), about 4 s
// when vertex ids are randomly permuted (every access then misses the cache).

#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/topology.hpp"
#include "union_find.hpp"

namespace cmc33 {
namespace {

// Buckets are tiny (about 3 edges per vertex on a typical mesh): insertion sort beats std::sort
// there; large fans (a cone apex) fall back to std::sort.
void sort_keys(std::uint64_t* first, std::uint64_t* last)
{
    if (last - first > 24) {
        std::sort(first, last);
        return;
    }
    for (std::uint64_t* i = first + 1; i < last; ++i) {
        const std::uint64_t key = *i;
        std::uint64_t* j = i;
        while (j > first && *(j - 1) > key) {
            *j = *(j - 1);
            --j;
        }
        *j = key;
    }
}

std::uint32_t slot_of(std::uint64_t key)
{
    return static_cast<std::uint32_t>(key & 0xffffffffu) >> 1;
}

bool is_degenerate(std::uint32_t a, std::uint32_t b, std::uint32_t c)
{
    return a == b || b == c || a == c;
}

} // namespace

MeshTopology mesh_topology(const Mesh& mesh)
{
    const auto& tri = mesh.triangles;
    if (tri.size() % 3 != 0) {
        throw Error(Status::invalid_argument, "mesh_topology: the triangle array holds " +
                                                  std::to_string(tri.size()) +
                                                  " indices; expected a multiple of 3");
    }
    // Corner ids and CSR offsets are 32-bit.
    if (tri.size() >= std::numeric_limits<std::uint32_t>::max()) {
        throw Error(Status::too_large, "mesh_topology: " + std::to_string(tri.size() / 3) +
                                           " triangles; at most 1431655764 are supported");
    }
    const std::size_t n = mesh.vertex_count();
    const std::size_t triangle_count = tri.size() / 3;
    MeshTopology result;

    // Pass 1: validate, drop degenerate triangles, count corners per vertex.
    std::vector<std::uint32_t> offsets(n + 1, 0);
    std::int64_t faces = 0;
    for (std::size_t t = 0; t < triangle_count; ++t) {
        const std::uint32_t a = tri[3 * t], b = tri[3 * t + 1], c = tri[3 * t + 2];
        const std::uint32_t largest = std::max({a, b, c});
        if (largest >= n) {
            throw Error(Status::invalid_argument, "mesh_topology: triangle " + std::to_string(t) +
                                                      " uses vertex " + std::to_string(largest) +
                                                      " but the mesh has " + std::to_string(n) +
                                                      " vertices");
        }
        if (is_degenerate(a, b, c)) {
            ++result.degenerate_triangles;
            continue;
        }
        ++offsets[a + 1];
        ++offsets[b + 1];
        ++offsets[c + 1];
        ++faces;
    }
    result.faces = faces;
    if (faces == 0) { // no vertex used: all counts 0; not closed, but trivially oriented (no edge)
        result.oriented = true;
        return result;
    }

    for (std::size_t v = 0; v < n; ++v) {
        if (offsets[v + 1] != 0) ++result.vertices;
        offsets[v + 1] += offsets[v];
    }

    // Pass 2: fill the CSR with, for each corner at v, the triangle's next and previous vertex
    // (storing them rather than a corner id keeps pass 4 sequential: the random access happens
    // once, here). Each offsets[v] serves as v's write cursor and ends at v's end, which is
    // v + 1's start; shifting the array by one restores the starts.
    std::vector<std::uint32_t> rings(static_cast<std::size_t>(6 * faces));
    {
        std::uint32_t* cursor = offsets.data();
        std::uint32_t* out = rings.data();
        for (std::size_t t = 0; t < triangle_count; ++t) {
            const std::uint32_t a = tri[3 * t], b = tri[3 * t + 1], c = tri[3 * t + 2];
            if (is_degenerate(a, b, c)) continue;
            std::uint32_t* at = out + 2 * static_cast<std::size_t>(cursor[a]++);
            at[0] = b;
            at[1] = c;
            at = out + 2 * static_cast<std::size_t>(cursor[b]++);
            at[0] = c;
            at[1] = a;
            at = out + 2 * static_cast<std::size_t>(cursor[c]++);
            at[0] = a;
            at[1] = b;
        }
        for (std::size_t v = n; v > 0; --v) offsets[v] = offsets[v - 1];
        offsets[0] = 0;
    }

    // Pass 3: components of triangles through shared vertices.
    detail::UnionFind components(n);
    for (std::size_t t = 0; t < triangle_count; ++t) {
        const std::uint32_t a = tri[3 * t], b = tri[3 * t + 1], c = tri[3 * t + 2];
        if (is_degenerate(a, b, c)) continue;
        components.unite(a, b);
        components.unite(a, c);
    }

    // Pass 4: per vertex, its edges to larger ids and its link.
    enum : std::uint8_t { kOnBoundary = 1, kComponentHasBoundary = 2 };
    std::vector<std::uint8_t> flags;  // allocated at the first boundary edge
    detail::UnionFind boundary_graph; // idem
    std::int64_t boundary_vertices = 0;
    std::int64_t boundary_unions = 0;
    bool oriented = true;

    // Per vertex v, one key per (incident triangle, other vertex w): w << 32 | slot << 1 | forward,
    // where slot numbers v's triangles and forward says the triangle runs v -> w. Sorted, a run
    // of equal w is the set of v's triangles on edge {v, w}: it gives the edge's use count and
    // directions (counted at the smaller end only) and links those triangles into one fan.
    std::vector<std::uint64_t> keys;
    detail::UnionFind fan;

    for (std::size_t vi = 0; vi < n; ++vi) {
        const std::uint32_t v = static_cast<std::uint32_t>(vi);
        const std::uint32_t begin = offsets[v], count = offsets[v + 1] - begin;
        if (count == 0) continue;

        keys.resize(2 * static_cast<std::size_t>(count));
        std::uint64_t* key = keys.data();
        const std::uint32_t* ring = rings.data() + 2 * static_cast<std::size_t>(begin);
        for (std::uint32_t slot = 0; slot < count; ++slot) {
            const std::uint64_t tag = std::uint64_t{slot} << 1;
            key[2 * slot] = std::uint64_t{ring[2 * slot]} << 32 | tag | 1u;
            key[2 * slot + 1] = std::uint64_t{ring[2 * slot + 1]} << 32 | tag;
        }
        sort_keys(key, key + keys.size());

        fan.reset(count);
        std::uint32_t fans = count;
        for (std::size_t r = 0; r < keys.size();) {
            const std::uint32_t w = static_cast<std::uint32_t>(key[r] >> 32);
            const std::uint32_t first_slot = slot_of(key[r]);
            std::uint32_t forward = key[r] & 1u;
            std::size_t s = r + 1;
            for (; s < keys.size() && static_cast<std::uint32_t>(key[s] >> 32) == w; ++s) {
                forward += key[s] & 1u;
                if (fan.unite(first_slot, slot_of(key[s]))) --fans;
            }
            const std::size_t uses = s - r;
            r = s;
            if (w < v) continue; // edge {w, v} was counted at w
            ++result.edges;
            if (uses == 1) {
                ++result.boundary_edges;
                if (flags.empty()) {
                    flags.assign(n, 0);
                    boundary_graph.reset(n);
                }
                for (std::uint32_t x : {v, w}) {
                    if (!(flags[x] & kOnBoundary)) {
                        flags[x] |= kOnBoundary;
                        ++boundary_vertices;
                    }
                }
                if (boundary_graph.unite(v, w)) ++boundary_unions;
                flags[components.find(v)] |= kComponentHasBoundary;
            } else if (uses == 2) {
                if (forward != 1) oriented = false; // both triangles run the edge the same way
            } else {
                ++result.nonmanifold_edges;
            }
        }
        if (fans > 1) ++result.nonmanifold_vertices;
    }

    // Pass 5: count components, closed components and boundary loops.
    for (std::size_t vi = 0; vi < n; ++vi) {
        const std::uint32_t v = static_cast<std::uint32_t>(vi);
        if (offsets[v] == offsets[v + 1] || !components.is_root(v)) continue;
        ++result.components;
        if (flags.empty() || !(flags[v] & kComponentHasBoundary)) ++result.closed_components;
    }
    result.boundary_loops = boundary_vertices - boundary_unions;
    result.euler = result.vertices - result.edges + result.faces;
    result.b1 = result.components + result.closed_components - result.euler;
    result.closed = result.boundary_edges == 0;
    result.oriented = oriented;
    return result;
}

} // namespace cmc33
