// mesh_topology() from slabs (contract in seam_topology.hpp). The per-vertex analysis is
// mesh_topology()'s (keys w << 32 | slot << 1 | forward per vertex, sorted into runs by edge),
// restricted to the vertices a slab owns; components and boundary loops are union-finds whose
// sets reaching a seam stay open until the neighbouring summaries are merged.

#include "seam_topology.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>
#include <string>

#include "cmc33/error.hpp"
#include "union_find.hpp"

namespace cmc33::detail {
namespace {

bool is_degenerate(std::uint32_t a, std::uint32_t b, std::uint32_t c) { return a == b || b == c || a == c; }

/// Sorts a vertex's ring keys, which are distinct (each holds its slot).
void sort_keys(std::vector<std::uint64_t>& keys)
{
    constexpr std::size_t kSmall = 16;
    const std::size_t n = keys.size();
    if (n > kSmall) {
        std::sort(keys.begin(), keys.end());
        return;
    }
    // each key's place is the number of smaller keys: no branch to mispredict
    std::uint64_t in[kSmall];
    std::copy(keys.begin(), keys.end(), in);
    for (std::size_t i = 0; i < n; ++i) {
        std::size_t rank = 0;
        for (std::size_t j = 0; j < n; ++j) rank += in[j] < in[i] ? 1 : 0;
        keys[rank] = in[i];
    }
}

/// Union-find over the ring slots of one vertex: a fixed array for the usual few (no allocation,
/// no ranks: its trees stay shallow), the general one beyond.
class SlotSets {
public:
    void reset(std::uint32_t n)
    {
        small_ = n <= kSmall;
        if (!small_) {
            big_.reset(n);
            return;
        }
        for (std::uint32_t i = 0; i < n; ++i) parent_[i] = static_cast<std::uint8_t>(i);
    }
    /// Merges the sets of a and b; false if they were one already.
    bool unite(std::uint32_t a, std::uint32_t b)
    {
        if (!small_) return big_.unite(a, b);
        a = find(a);
        b = find(b);
        if (a == b) return false;
        parent_[a] = static_cast<std::uint8_t>(b);
        return true;
    }

private:
    std::uint32_t find(std::uint32_t x)
    {
        while (parent_[x] != x) {
            parent_[x] = parent_[parent_[x]];
            x = parent_[x];
        }
        return x;
    }
    static constexpr std::uint32_t kSmall = 64;
    std::array<std::uint8_t, kSmall> parent_{};
    bool small_ = true;
    UnionFind big_;
};

/// The usual vertex, found without sorting its ring: every edge at it is used twice, once in each
/// direction (each slot's next vertex is exactly one slot's previous one, and those slots are all
/// different). Then its fans are the cycles of that matching; returns false (nothing decided)
/// for any other ring or more than 16 slots. `ring` holds (next, previous) per slot.
bool closed_ring(const std::uint32_t* ring, std::uint32_t count, std::uint32_t v, std::int64_t& edges, std::uint32_t& fans)
{
    constexpr std::uint32_t kMax = 16;
    if (count > kMax) return false;
    std::uint8_t match[kMax];
    std::uint32_t taken = 0;
    std::int64_t larger = 0;
    for (std::uint32_t s = 0; s < count; ++s) {
        const std::uint32_t w = ring[2 * s];
        std::uint32_t found = 0, at = 0;
        for (std::uint32_t t = 0; t < count; ++t) {
            const bool same = ring[2 * t + 1] == w;
            found += same ? 1 : 0;
            at = same ? t : at;
        }
        if (found != 1 || (taken >> at & 1u) != 0) return false;
        taken |= 1u << at;
        match[s] = static_cast<std::uint8_t>(at);
        larger += w > v ? 1 : 0;
    }
    std::uint32_t seen = 0, cycles = 0;
    for (std::uint32_t s = 0; s < count; ++s) {
        if ((seen >> s & 1u) != 0) continue;
        ++cycles;
        for (std::uint32_t t = s; (seen >> t & 1u) == 0; t = match[t]) seen |= 1u << t;
    }
    edges += larger;
    fans = cycles;
    return true;
}

/// Node numbers for union-find roots, given in order of first appearance.
class NodeMap {
public:
    explicit NodeMap(std::size_t n) : node_(n, -1) {}
    std::int32_t node(std::uint32_t root)
    {
        std::int32_t& n = node_[root];
        if (n < 0) {
            n = static_cast<std::int32_t>(roots_.size());
            roots_.push_back(root);
        }
        return n;
    }
    bool has(std::uint32_t root) const { return node_[root] >= 0; }
    const std::vector<std::uint32_t>& roots() const { return roots_; }

private:
    std::vector<std::int32_t> node_;
    std::vector<std::uint32_t> roots_;
};

[[noreturn]] void seam_mismatch(std::uint32_t id)
{
    throw Error(Status::internal, "the topology of neighbouring slabs does not fit at seam vertex " + std::to_string(id) +
                                      " (a boundary edge there has no component on either side); the slabs "
                                      "were not neighbours, or a bug in cmc33");
}

} // namespace

SeamTopology SeamTopology::of_slab(const SlabTriangles& slab)
{
    if (slab.triangles.size() % 3 != 0 || slab.below.size() % 3 != 0) {
        throw Error(Status::invalid_argument, "slab topology: a triangle array holds " +
                                                  std::to_string(slab.triangles.size()) + " or " +
                                                  std::to_string(slab.below.size()) + " ids; expected multiples of 3");
    }
    const std::int64_t v0 = slab.first_vertex, v1 = v0 + slab.vertex_count;
    if (v0 < 0 || slab.vertex_count < 0 || v1 > std::int64_t{std::numeric_limits<std::uint32_t>::max()} + 1) {
        throw Error(Status::invalid_argument, "slab topology: vertices [" + std::to_string(v0) + ", " + std::to_string(v1) +
                                                  ") are not 32-bit ids");
    }
    const auto own = [v0, v1](std::uint32_t id) { return id >= v0 && id < v1; };
    const auto n = static_cast<std::size_t>(slab.vertex_count);
    const std::span<const std::uint32_t> tri = slab.triangles, below = slab.below;
    const std::size_t tri_count = tri.size() / 3, below_count = below.size() / 3;
    SeamTopology r;
    r.empty_ = false;

    // The next slab's vertices this slab's triangles use: its upper side.
    std::vector<std::uint32_t> upper;
    std::uint32_t upper_hi = 0; // the largest of them
    for (std::size_t t = 0; t < tri_count; ++t) {
        const std::uint32_t* c = &tri[3 * t];
        for (int q = 0; q < 3; ++q) {
            if (c[q] < v0) {
                throw Error(Status::invalid_argument, "slab topology: triangle " + std::to_string(t) + " uses vertex " +
                                                          std::to_string(c[q]) + ", below the slab's first vertex " +
                                                          std::to_string(v0));
            }
        }
        if (is_degenerate(c[0], c[1], c[2])) continue;
        for (int q = 0; q < 3; ++q)
            if (c[q] >= v1) {
                upper.push_back(c[q]);
                upper_hi = std::max(upper_hi, c[q]);
            }
    }
    // Local numbers: own vertices first, then the upper side's in id order. The upper ids are
    // the first ones of the next slab, close together: numbered through a table over their
    // range, unless that range is far wider than their count.
    constexpr auto kUnused = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::uint32_t> upper_local; // per id v1 + i: its local number, or kUnused
    const std::int64_t upper_span = upper.empty() ? 0 : std::int64_t{upper_hi} - v1 + 1;
    if (!upper.empty() && upper_span <= 4 * static_cast<std::int64_t>(upper.size()) + 1024) {
        upper_local.assign(static_cast<std::size_t>(upper_span), kUnused);
        for (const std::uint32_t id : upper) upper_local[static_cast<std::size_t>(id - v1)] = 0;
        upper.clear();
        for (std::size_t i = 0; i < upper_local.size(); ++i) {
            if (upper_local[i] == kUnused) continue;
            upper_local[i] = static_cast<std::uint32_t>(n + upper.size());
            upper.push_back(static_cast<std::uint32_t>(v1 + static_cast<std::int64_t>(i)));
        }
    } else {
        std::sort(upper.begin(), upper.end());
        upper.erase(std::unique(upper.begin(), upper.end()), upper.end());
    }
    const std::size_t total = n + upper.size();
    const auto local = [&](std::uint32_t id) -> std::uint32_t {
        if (id < v1) return static_cast<std::uint32_t>(id - v0);
        const auto at = static_cast<std::size_t>(id - v1);
        if (at < upper_local.size() && upper_local[at] != kUnused) return upper_local[at];
        return static_cast<std::uint32_t>(n + static_cast<std::size_t>(std::lower_bound(upper.begin(), upper.end(), id) - upper.begin()));
    };

    // Components of the own triangles.
    UnionFind components(total);
    std::vector<std::uint8_t> used(total, 0);
    for (std::size_t t = 0; t < tri_count; ++t) {
        const std::uint32_t a = tri[3 * t], b = tri[3 * t + 1], c = tri[3 * t + 2];
        if (is_degenerate(a, b, c)) {
            ++r.degenerate_;
            continue;
        }
        ++r.faces_;
        const std::uint32_t la = local(a), lb = local(b), lc = local(c);
        used[la] = used[lb] = used[lc] = 1;
        components.unite(la, lb);
        components.unite(la, lc);
    }

    // Rings of the own vertices: (next, previous) of every triangle at them, own and ghost.
    std::vector<std::uint32_t> start(n + 1, 0);
    const auto count_corners = [&](std::span<const std::uint32_t> t3) {
        for (std::size_t t = 0; t < t3.size() / 3; ++t) {
            const std::uint32_t* c = &t3[3 * t];
            if (is_degenerate(c[0], c[1], c[2])) continue;
            for (int q = 0; q < 3; ++q)
                if (own(c[q])) ++start[c[q] - v0 + 1];
        }
    };
    count_corners(tri);
    count_corners(below);
    for (std::size_t v = 0; v < n; ++v) start[v + 1] += start[v];
    std::vector<std::uint32_t> rings(2 * static_cast<std::size_t>(start[n]));
    {
        std::vector<std::uint32_t> cursor(start.begin(), start.end() - 1);
        const auto fill = [&](std::span<const std::uint32_t> t3) {
            for (std::size_t t = 0; t < t3.size() / 3; ++t) {
                const std::uint32_t* c = &t3[3 * t];
                if (is_degenerate(c[0], c[1], c[2])) continue;
                for (int q = 0; q < 3; ++q) {
                    if (!own(c[q])) continue;
                    std::uint32_t* at = &rings[2 * static_cast<std::size_t>(cursor[c[q] - v0]++)];
                    at[0] = c[(q + 1) % 3];
                    at[1] = c[(q + 2) % 3];
                }
            }
        };
        fill(tri);
        fill(below);
    }

    // Per own vertex: its edges to larger ids (counted here), its fans, its boundary edges.
    UnionFind loops(total);
    std::vector<std::uint8_t> on_loop(total, 0), component_boundary(total, 0);
    std::vector<std::uint32_t> pending; // own vertices with a boundary edge but no own triangle
    std::vector<std::uint64_t> keys;
    SlotSets fan;
    for (std::size_t x = 0; x < n; ++x) {
        const std::uint32_t begin = start[x], count = start[x + 1] - begin;
        if (count == 0) continue;
        ++r.vertices_;
        const auto v = static_cast<std::uint32_t>(v0 + static_cast<std::int64_t>(x));
        // each edge used twice, consistently oriented: its edges to larger ids and its fans
        if (std::uint32_t fans = 0; closed_ring(&rings[2 * static_cast<std::size_t>(begin)], count, v, r.edges_, fans)) {
            if (fans > 1) ++r.nonmanifold_vertices_;
            continue;
        }
        keys.resize(2 * static_cast<std::size_t>(count));
        for (std::uint32_t slot = 0; slot < count; ++slot) {
            const std::uint32_t* ring = &rings[2 * static_cast<std::size_t>(begin + slot)];
            const std::uint64_t tag = std::uint64_t{slot} << 1;
            keys[2 * slot] = std::uint64_t{ring[0]} << 32 | tag | 1u;
            keys[2 * slot + 1] = std::uint64_t{ring[1]} << 32 | tag;
        }
        sort_keys(keys);
        fan.reset(count);
        std::uint32_t fans = count;
        for (std::size_t i = 0; i < keys.size();) {
            const auto w = static_cast<std::uint32_t>(keys[i] >> 32);
            const auto first_slot = static_cast<std::uint32_t>(keys[i] & 0xffffffffu) >> 1;
            std::uint32_t forward = keys[i] & 1u;
            std::size_t j = i + 1;
            for (; j < keys.size() && static_cast<std::uint32_t>(keys[j] >> 32) == w; ++j) {
                forward += keys[j] & 1u;
                if (fan.unite(first_slot, static_cast<std::uint32_t>(keys[j] & 0xffffffffu) >> 1)) --fans;
            }
            const std::size_t uses = j - i;
            i = j;
            if (w < v) continue; // counted at w's owner
            ++r.edges_;
            if (uses == 1) {
                ++r.boundary_edges_;
                // w > v is own or the next slab's: a triangle that uses it is this slab's own
                const std::uint32_t lv = local(v), lw = local(w);
                on_loop[lv] = on_loop[lw] = 1;
                loops.unite(lv, lw);
                if (used[lv]) {
                    component_boundary[components.find(lv)] = 1;
                } else {
                    pending.push_back(v);
                }
            } else if (uses == 2) {
                if (forward != 1) r.oriented_ = false;
            } else {
                ++r.nonmanifold_edges_;
            }
        }
        if (fans > 1) ++r.nonmanifold_vertices_;
    }

    // The outer sides: own vertices the ghost layer uses (lower), the next slab's (upper).
    std::vector<std::uint32_t> lower;
    if (below_count > 0) {
        // marked per own vertex, then listed in id order (no sort)
        std::vector<std::uint8_t> in_lower(n, 0);
        for (std::size_t t = 0; t < below_count; ++t) {
            const std::uint32_t* c = &below[3 * t];
            if (is_degenerate(c[0], c[1], c[2])) continue;
            for (int q = 0; q < 3; ++q)
                if (own(c[q])) in_lower[c[q] - v0] = 1;
        }
        for (std::size_t x = 0; x < n; ++x)
            if (in_lower[x]) lower.push_back(static_cast<std::uint32_t>(v0 + static_cast<std::int64_t>(x)));
    }
    std::sort(pending.begin(), pending.end());
    NodeMap component_nodes(total), loop_nodes(total);
    const auto side = [&](const std::vector<std::uint32_t>& ids, Side& s) {
        s.ids = ids;
        for (const std::uint32_t id : ids) {
            const std::uint32_t l = local(id);
            s.component.push_back(used[l] ? component_nodes.node(components.find(l)) : -1);
            s.loop.push_back(on_loop[l] ? loop_nodes.node(loops.find(l)) : -1);
            s.flag.push_back(std::binary_search(pending.begin(), pending.end(), id) ? 1 : 0);
        }
    };
    side(lower, r.lower_);
    side(upper, r.upper_);
    for (const std::uint32_t v : pending) {
        if (!std::binary_search(lower.begin(), lower.end(), v)) seam_mismatch(v);
    }
    for (const std::uint32_t root : component_nodes.roots()) r.node_boundary_.push_back(component_boundary[root]);
    r.loop_nodes_ = static_cast<std::int32_t>(loop_nodes.roots().size());
    for (std::size_t l = 0; l < total; ++l) {
        const auto x = static_cast<std::uint32_t>(l);
        if (used[l] && components.is_root(x) && !component_nodes.has(x)) {
            ++r.components_;
            if (!component_boundary[l]) ++r.closed_;
        }
        if (on_loop[l] && loops.is_root(x) && !loop_nodes.has(x)) ++r.loops_;
    }
    return r;
}

SeamTopology SeamTopology::merge(const SeamTopology& a, const SeamTopology& b)
{
    if (a.empty_) return b;
    if (b.empty_) return a;
    SeamTopology r;
    r.empty_ = false;
    r.vertices_ = a.vertices_ + b.vertices_;
    r.edges_ = a.edges_ + b.edges_;
    r.faces_ = a.faces_ + b.faces_;
    r.boundary_edges_ = a.boundary_edges_ + b.boundary_edges_;
    r.nonmanifold_edges_ = a.nonmanifold_edges_ + b.nonmanifold_edges_;
    r.nonmanifold_vertices_ = a.nonmanifold_vertices_ + b.nonmanifold_vertices_;
    r.degenerate_ = a.degenerate_ + b.degenerate_;
    r.oriented_ = a.oriented_ && b.oriented_;
    r.components_ = a.components_ + b.components_;
    r.closed_ = a.closed_ + b.closed_;
    r.loops_ = a.loops_ + b.loops_;

    const auto na = static_cast<std::uint32_t>(a.node_boundary_.size());
    const std::size_t nodes = a.node_boundary_.size() + b.node_boundary_.size();
    const auto la = static_cast<std::uint32_t>(a.loop_nodes_);
    const std::size_t loop_count = static_cast<std::size_t>(a.loop_nodes_) + static_cast<std::size_t>(b.loop_nodes_);
    UnionFind components(nodes), loops(loop_count);
    std::vector<std::uint8_t> boundary(a.node_boundary_);
    boundary.insert(boundary.end(), b.node_boundary_.begin(), b.node_boundary_.end());
    // The seam between them: a's upper side and b's lower side, joined by vertex id.
    const Side &up = a.upper_, &down = b.lower_;
    std::vector<std::uint32_t> flagged;
    std::size_t i = 0, j = 0;
    while (j < down.ids.size()) {
        if (i < up.ids.size() && up.ids[i] < down.ids[j]) {
            ++i;
            continue;
        }
        const bool both = i < up.ids.size() && up.ids[i] == down.ids[j];
        if (!both) {
            if (down.flag[j]) seam_mismatch(down.ids[j]);
            ++j;
            continue;
        }
        const std::int32_t ca = up.component[i], cb = down.component[j];
        if (ca >= 0 && cb >= 0) components.unite(static_cast<std::uint32_t>(ca), na + static_cast<std::uint32_t>(cb));
        if (down.flag[j]) {
            if (ca < 0) seam_mismatch(down.ids[j]);
            flagged.push_back(static_cast<std::uint32_t>(ca));
        }
        if (up.loop[i] >= 0 && down.loop[j] >= 0) {
            loops.unite(static_cast<std::uint32_t>(up.loop[i]), la + static_cast<std::uint32_t>(down.loop[j]));
        }
        ++i, ++j;
    }
    std::vector<std::uint8_t> root_boundary(nodes, 0);
    for (std::size_t x = 0; x < nodes; ++x) root_boundary[components.find(static_cast<std::uint32_t>(x))] |= boundary[x];
    for (const std::uint32_t x : flagged) root_boundary[components.find(x)] = 1;

    // The new outer sides: a's lower one and b's upper one, with the merged nodes.
    NodeMap component_nodes(nodes), loop_nodes(loop_count);
    const auto relabel = [&](const Side& s, std::uint32_t component_base, std::uint32_t loop_base, Side& out) {
        out.ids = s.ids;
        out.flag = s.flag;
        for (std::size_t k = 0; k < s.ids.size(); ++k) {
            const std::int32_t c = s.component[k], l = s.loop[k];
            out.component.push_back(c < 0 ? -1 : component_nodes.node(components.find(component_base + static_cast<std::uint32_t>(c))));
            out.loop.push_back(l < 0 ? -1 : loop_nodes.node(loops.find(loop_base + static_cast<std::uint32_t>(l))));
        }
    };
    relabel(a.lower_, 0, 0, r.lower_);
    relabel(b.upper_, na, la, r.upper_);
    for (const std::uint32_t root : component_nodes.roots()) r.node_boundary_.push_back(root_boundary[root]);
    r.loop_nodes_ = static_cast<std::int32_t>(loop_nodes.roots().size());
    // nodes on neither outer side are complete now
    for (std::size_t x = 0; x < nodes; ++x) {
        const auto id = static_cast<std::uint32_t>(x);
        if (components.is_root(id) && !component_nodes.has(id)) {
            ++r.components_;
            if (!root_boundary[x]) ++r.closed_;
        }
    }
    for (std::size_t x = 0; x < loop_count; ++x) {
        const auto id = static_cast<std::uint32_t>(x);
        if (loops.is_root(id) && !loop_nodes.has(id)) ++r.loops_;
    }
    return r;
}

MeshTopology SeamTopology::finish() const
{
    MeshTopology t;
    t.degenerate_triangles = degenerate_;
    t.faces = faces_;
    if (faces_ == 0) { // as mesh_topology(): no vertex used, not closed, trivially oriented
        t.oriented = true;
        return t;
    }
    t.vertices = vertices_;
    t.edges = edges_;
    t.boundary_edges = boundary_edges_;
    t.nonmanifold_edges = nonmanifold_edges_;
    t.nonmanifold_vertices = nonmanifold_vertices_;
    t.components = components_ + static_cast<std::int64_t>(node_boundary_.size());
    t.closed_components = closed_ + std::count(node_boundary_.begin(), node_boundary_.end(), std::uint8_t{0});
    t.boundary_loops = loops_ + loop_nodes_;
    t.euler = t.vertices - t.edges + t.faces;
    t.b1 = t.components + t.closed_components - t.euler;
    t.closed = t.boundary_edges == 0;
    t.oriented = oriented_;
    return t;
}

namespace {

class Writer {
public:
    template <class T> void value(T v)
    {
        const auto* p = reinterpret_cast<const std::byte*>(&v);
        bytes.insert(bytes.end(), p, p + sizeof v);
    }
    template <class T> void array(const std::vector<T>& v)
    {
        value(static_cast<std::uint64_t>(v.size()));
        if (v.empty()) return;
        const auto* p = reinterpret_cast<const std::byte*>(v.data());
        bytes.insert(bytes.end(), p, p + v.size() * sizeof(T));
    }
    std::vector<std::byte> bytes;
};

class Reader {
public:
    explicit Reader(std::span<const std::byte> b) : b_(b) {}
    template <class T> T value()
    {
        T v{};
        need(sizeof v);
        std::memcpy(&v, b_.data() + at_, sizeof v);
        at_ += sizeof v;
        return v;
    }
    template <class T> std::vector<T> array()
    {
        const auto n = value<std::uint64_t>();
        if (n > (b_.size() - at_) / sizeof(T)) fail();
        std::vector<T> v(static_cast<std::size_t>(n));
        if (!v.empty()) std::memcpy(v.data(), b_.data() + at_, v.size() * sizeof(T));
        at_ += v.size() * sizeof(T);
        return v;
    }
    bool done() const { return at_ == b_.size(); }
    [[noreturn]] static void fail() { throw Error(Status::internal, "a slab topology summary arrived damaged"); }

private:
    void need(std::size_t n) const
    {
        if (n > b_.size() - at_) fail();
    }
    std::span<const std::byte> b_;
    std::size_t at_ = 0;
};

} // namespace

std::vector<std::byte> SeamTopology::serialize() const
{
    Writer w;
    for (const std::int64_t v : {vertices_, edges_, faces_, boundary_edges_, nonmanifold_edges_, nonmanifold_vertices_,
                                 degenerate_, std::int64_t{oriented_}, std::int64_t{empty_}, components_, closed_, loops_,
                                 std::int64_t{loop_nodes_}}) {
        w.value(v);
    }
    w.array(node_boundary_);
    for (const Side* s : {&lower_, &upper_}) {
        w.array(s->ids);
        w.array(s->component);
        w.array(s->loop);
        w.array(s->flag);
    }
    return std::move(w.bytes);
}

SeamTopology SeamTopology::deserialize(std::span<const std::byte> bytes)
{
    Reader in(bytes);
    SeamTopology r;
    for (std::int64_t* v : {&r.vertices_, &r.edges_, &r.faces_, &r.boundary_edges_, &r.nonmanifold_edges_,
                            &r.nonmanifold_vertices_, &r.degenerate_}) {
        *v = in.value<std::int64_t>();
    }
    r.oriented_ = in.value<std::int64_t>() != 0;
    r.empty_ = in.value<std::int64_t>() != 0;
    r.components_ = in.value<std::int64_t>();
    r.closed_ = in.value<std::int64_t>();
    r.loops_ = in.value<std::int64_t>();
    r.loop_nodes_ = static_cast<std::int32_t>(in.value<std::int64_t>());
    r.node_boundary_ = in.array<std::uint8_t>();
    for (Side* s : {&r.lower_, &r.upper_}) {
        s->ids = in.array<std::uint32_t>();
        s->component = in.array<std::int32_t>();
        s->loop = in.array<std::int32_t>();
        s->flag = in.array<std::uint8_t>();
        const std::size_t n = s->ids.size();
        if (s->component.size() != n || s->loop.size() != n || s->flag.size() != n) Reader::fail();
        for (std::size_t k = 0; k < n; ++k) {
            if (s->component[k] >= static_cast<std::int32_t>(r.node_boundary_.size()) || s->loop[k] >= r.loop_nodes_) {
                Reader::fail();
            }
        }
    }
    if (!in.done()) Reader::fail();
    return r;
}

} // namespace cmc33::detail
