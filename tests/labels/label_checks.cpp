// The checks of label_checks.hpp, made from the mesh alone and from the samples alone: nothing here
// uses the label extractor's tables.

#include "label_checks.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <vector>

#include "cmc33/extract.hpp"
#include "cmc33/topology.hpp"

namespace cmc33::label_checks {

namespace {

using Point = std::array<float, 3>;
using Tri = std::array<Point, 3>;

Point point(const Mesh& m, std::uint32_t v)
{
    return {m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]};
}

// A triangle rotated so that its smallest corner comes first (its orientation kept).
Tri smallest_first(Tri tri)
{
    std::rotate(tri.begin(), std::min_element(tri.begin(), tri.end()), tri.end());
    return tri;
}

// The oriented triangle, rotated so that its smallest corner comes first.
Tri oriented(const Mesh& m, std::size_t t)
{
    return smallest_first(
        {point(m, m.triangles[3 * t]), point(m, m.triangles[3 * t + 1]), point(m, m.triangles[3 * t + 2])});
}

// The triangles as a set, their corners rounded to 1e-5: cmc33's interior points of a cell come
// from analyze_cell() in floats of the unit cube, one float step from extract()'s.
std::multiset<Tri> triangle_set(const Mesh& m, bool reverse)
{
    std::multiset<Tri> out;
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
        Tri tri = oriented(m, t);
        for (Point& p : tri)
            for (float& x : p) x = static_cast<float>(std::round(static_cast<double>(x) * 1e5));
        if (reverse) {
            std::swap(tri[1], tri[2]);
        }
        out.insert(tri);
    }
    return out;
}

// Whether a float field has a sample within 1e-5 of 0.5, or a face whose diagonals are on opposite
// sides of 0.5 with its bilinear saddle's numerator (f00 f11 - f10 f01, of f - 0.5) within 1e-6 of 0.
bool near_tie(const Volume& field)
{
    const float* v = field.samples<float>();
    const Index3 n = field.dims();
    for (std::int64_t i = 0; i < field.sample_count(); ++i)
        if (std::fabs(v[i] - 0.5F) < 1e-5F) return true;
    const std::array<std::int64_t, 3> stride{1, n[0], n[0] * n[1]};
    for (std::size_t axis = 0; axis < 3; ++axis) {
        const std::size_t u = (axis + 1) % 3, w = (axis + 2) % 3;
        for (std::int64_t s = 0; s < field.sample_count(); ++s) {
            const std::array<std::int64_t, 3> p{s % n[0], s / n[0] % n[1], s / stride[2]};
            if (p[u] + 1 >= n[u] || p[w] + 1 >= n[w]) continue;
            const auto at = [&](std::int64_t du, std::int64_t dw) {
                return static_cast<double>(v[s + du * stride[u] + dw * stride[w]]) - 0.5;
            };
            const double f00 = at(0, 0), f10 = at(1, 0), f11 = at(1, 1), f01 = at(0, 1);
            const bool ambiguous = (f00 >= 0) == (f11 >= 0) && (f10 >= 0) == (f01 >= 0) && (f00 >= 0) != (f10 >= 0);
            if (ambiguous && std::fabs(f00 * f11 - f10 * f01) < 1e-6) return true;
        }
    }
    return false;
}

// The label a face joins across a diagonal (corners in cyclic order): the label on both ends of a
// diagonal, the lower one where both diagonals hold one; none without such a diagonal.
std::optional<std::int64_t> joined_label(const std::array<std::int64_t, 4>& l)
{
    const bool d0 = l[0] == l[2], d1 = l[1] == l[3];
    if (!d0 && !d1) return std::nullopt;
    return d0 && d1 ? std::min(l[0], l[1]) : (d0 ? l[0] : l[1]);
}

// An open face's contribution to the Euler characteristic of label x's region (euler_from_labels()).
std::int64_t face(const std::array<std::int64_t, 4>& l, std::int64_t x)
{
    const int mine = static_cast<int>(std::count(l.begin(), l.end(), x));
    if (mine == 4) return 1;
    if (mine != 2) return 0;
    return joined_label(l) == x ? -1 : 0;
}

using Corners = std::array<std::int64_t, 8>; ///< a cell's labels, corner m at (m & 1, m >> 1 & 1, m >> 2 & 1)

// Chi of label x's part of a cell's surface, and its pieces there (corners joined by edges and by
// joined diagonals).
std::int64_t on_cell_surface(const Corners& c, std::int64_t x, int& pieces)
{
    std::array<unsigned, 8> root{0, 1, 2, 3, 4, 5, 6, 7};
    const auto find = [&](unsigned u) {
        while (root[u] != u) u = root[u];
        return u;
    };
    std::int64_t chi = 0;
    for (unsigned m = 0; m < 8; ++m) chi += c[m] == x ? 1 : 0;
    for (unsigned m = 0; m < 8; ++m)
        for (unsigned a = 0; a < 3; ++a)
            if ((m >> a & 1U) == 0 && c[m] == x && c[m | 1U << a] == x) {
                --chi;
                root[find(m)] = find(m | 1U << a);
            }
    for (unsigned a = 0; a < 3; ++a)
        for (unsigned side = 0; side < 2; ++side) {
            const unsigned b = (a + 1) % 3, d = (a + 2) % 3, o = side << a;
            const std::array<unsigned, 4> q{o, o | 1U << b, o | 1U << b | 1U << d, o | 1U << d};
            const std::array<std::int64_t, 4> l{c[q[0]], c[q[1]], c[q[2]], c[q[3]]};
            const std::int64_t f = face(l, x);
            chi += f;
            if (f == -1) root[find(l[0] == x ? q[0] : q[1])] = find(l[0] == x ? q[2] : q[3]);
        }
    pieces = 0;
    for (unsigned m = 0; m < 8; ++m) pieces += c[m] == x && find(m) == m ? 1 : 0;
    return chi;
}

// The label that takes a cell's core (three or more labels): the lowest whose part of the cell's
// surface is not one disk; none where every part is one (the cell is cones from its centre).
std::optional<std::int64_t> core_label(const Corners& c)
{
    Corners labels = c;
    std::sort(labels.begin(), labels.end());
    for (auto x = labels.begin(); x != std::unique(labels.begin(), labels.end()); ++x) {
        int pieces = 0;
        const std::int64_t chi = on_cell_surface(c, *x, pieces);
        if (pieces != 1 || chi != 1) return *x;
    }
    return std::nullopt;
}

// Each label's surface's Euler characteristic computed from the labels alone, by the rules of
// docs/labels.md ("The partition") and not through the extractor: chi is additive over the open
// vertices, edges, faces and cells of the grid, so chi(R) of a label's region R is the sum of
// chi_c(R within each), and its surface S (R's boundary less the box) has chi(S) = 2 chi(R) - chi(B)
// with B = R on the box's faces. Per open piece:
//   - a sample of the label: 1; an edge with the label at both ends: -1 (an edge of two labels
//     holds a half-open part of each: 0);
//   - a face: 1 where all four corners hold the label; -1 where the label is joined across a
//     diagonal that holds its only two corners (the rest of the face cut off in two pieces); else 0
//     (each piece meets the face's boundary in one arc);
//   - a cell: all one label, -1 (a cube less its boundary sphere); two labels, (chi(S_c) - chi(R on
//     the cell's surface)) / 2 for each, with chi(S_c) from field_topology() of the cell's indicator
//     at 0.5; three or more, 0 for every label but the core's, which takes 1 - chi(its part of the
//     cell's surface) (cones and frustums have the chi of their base; the core with its frustums
//     is a ball).
std::map<std::int64_t, std::int64_t> euler_from_labels(const Volume& volume)
{
    const std::int32_t* v = volume.samples<std::int32_t>();
    const Index3 n = volume.dims();
    const auto at = [&](std::int64_t i, std::int64_t j, std::int64_t k) { return v[i + n[0] * (j + n[1] * k)]; };
    std::map<std::int64_t, std::int64_t> region, box;
    const std::array<std::int64_t, 3> dims{n[0], n[1], n[2]};
    const auto on_box = [&](const std::array<std::int64_t, 3>& lo, const std::array<std::int64_t, 3>& hi) {
        for (std::size_t a = 0; a < 3; ++a)
            if (lo[a] == hi[a] && (lo[a] == 0 || lo[a] == dims[a] - 1)) return true;
        return false;
    };
    const auto add = [&](std::int64_t label, std::int64_t c, bool boxed) {
        region[label] += c;
        if (boxed) box[label] += c;
    };
    std::map<unsigned, std::int64_t> cell_surface; // chi(S_c) by corner pattern
    for (std::int64_t k = 0; k < n[2]; ++k)
        for (std::int64_t j = 0; j < n[1]; ++j)
            for (std::int64_t i = 0; i < n[0]; ++i) {
                const std::array<std::int64_t, 3> p{i, j, k};
                add(at(i, j, k), 1, on_box(p, p));
                for (std::size_t a = 0; a < 3; ++a) {
                    std::array<std::int64_t, 3> q = p;
                    if (++q[a] >= dims[a]) continue;
                    if (at(i, j, k) == at(q[0], q[1], q[2])) add(at(i, j, k), -1, on_box(p, q));
                    // the face spanned by axes a and b = a + 1 at p
                    const std::size_t b = (a + 1) % 3;
                    std::array<std::int64_t, 3> r = p, t = q;
                    if (++r[b] >= dims[b]) continue;
                    ++t[b];
                    const std::array<std::int64_t, 4> l{at(p[0], p[1], p[2]), at(q[0], q[1], q[2]),
                                                        at(t[0], t[1], t[2]), at(r[0], r[1], r[2])};
                    std::array<std::int64_t, 4> seen = l;
                    std::sort(seen.begin(), seen.end());
                    for (auto x = seen.begin(); x != std::unique(seen.begin(), seen.end()); ++x) {
                        if (const std::int64_t c = face(l, *x); c != 0) add(*x, c, on_box(p, t));
                    }
                }
                if (i + 1 >= n[0] || j + 1 >= n[1] || k + 1 >= n[2]) continue;
                std::array<std::int64_t, 8> c{};
                for (unsigned m = 0; m < 8; ++m) c[m] = at(i + (m & 1U), j + (m >> 1 & 1U), k + (m >> 2 & 1U));
                std::array<std::int64_t, 8> labels = c;
                std::sort(labels.begin(), labels.end());
                const auto end = std::unique(labels.begin(), labels.end());
                const auto count = end - labels.begin();
                if (count == 1) {
                    add(c[0], -1, false);
                    continue;
                }
                if (count == 2) {
                    unsigned pattern = 0;
                    for (unsigned m = 0; m < 8; ++m) pattern |= (c[m] == labels[0] ? 1U : 0U) << m;
                    auto it = cell_surface.find(pattern);
                    if (it == cell_surface.end()) {
                        Volume one(ScalarType::f32, {2, 2, 2});
                        for (unsigned m = 0; m < 8; ++m)
                            one.samples<float>()[m] = (pattern >> m & 1U) != 0 ? 1.0F : 0.0F;
                        it = cell_surface.emplace(pattern, field_topology(one, 0.5).euler).first;
                    }
                    for (auto x = labels.begin(); x != end; ++x) {
                        int pieces = 0;
                        const std::int64_t chi = on_cell_surface(c, *x, pieces);
                        add(*x, (it->second - chi) / 2, false);
                    }
                    continue;
                }
                if (const auto core = core_label(c)) {
                    int pieces = 0;
                    add(*core, 1 - on_cell_surface(c, *core, pieces), false);
                }
            }
    std::map<std::int64_t, std::int64_t> out;
    for (const auto& [label, chi] : region) out[label] = 2 * chi - box[label];
    return out;
}

// What the inside of a cell of two labels joins beyond its surface (betti_from_labels()).
enum class Interior { none, joins_low, joins_high, undetermined };

// The cell's level set f_low = 0.5 has c(R) + c(cell - R) - 1 components (the cell is a ball too);
// the surface's joins give each label's classes of corners (its pieces, on_cell_surface()). Fewer components than those
// give mean the inside joins classes: determined where one label has one class and the other's are all joined (one
// fewer component per join).
Interior interior_join(const Corners& c, std::int64_t low)
{
    const std::int64_t high = *std::max_element(c.begin(), c.end());
    int low_classes = 0, high_classes = 0;
    (void)on_cell_surface(c, low, low_classes);
    (void)on_cell_surface(c, high, high_classes);
    Volume one(ScalarType::f32, {2, 2, 2});
    for (unsigned m = 0; m < 8; ++m) one.samples<float>()[m] = c[m] == low ? 1.0F : 0.0F;
    const FieldTopology f = field_topology(one, 0.5);
    if (!f.determined) return Interior::undetermined;
    const std::int64_t joins = low_classes + high_classes - 1 - f.b0;
    if (joins == 0) return Interior::none;
    if (joins > 0 && low_classes == 1 && high_classes == joins + 1) return Interior::joins_high;
    if (joins > 0 && high_classes == 1 && low_classes == joins + 1) return Interior::joins_low;
    return Interior::undetermined;
}

// Label x's surface's Betti numbers b0 and b2 and its boundary loops from the labels alone. The
// box B is a ball, and the surface S (the boundary of x's region R, less the box's faces) is
// properly embedded in it, so each component of S separates B: the components of R and of B - R
// are the nodes of a tree whose edges are S's components (Alexander duality), b0(S) = c(R) +
// c(B - R) - 1, and a component of S is closed exactly when one of its sides does not reach the
// box, so b2(S) is the number of components of R and of B - R that hold no sample on the box
// (every component holds a sample: a multilinear function has no interior extremum, and the
// construction's pieces each hold a corner). The loops are the same tree on the box's surface.
// Samples are joined, by the rules of docs/labels.md ("The partition"):
//   - along an edge whose ends are both x, or both not x;
//   - across a face's diagonal of x's where the face joins x, and across one of two other labels
//     unless the face joins x on the other diagonal;
//   - inside a cell of three or more labels with a core: the core label's corners (the core joins
//     its frustums), or for any other x every corner that is not x (the core is not x's and
//     touches every frustum);
//   - inside a cell of two labels: what field_topology() of the cell says its inside joins beyond
//     its surface (interior_join(); the tunnels of case 7); `determined` is false where that is
//     not clear.
struct SurfaceBetti {
    std::int64_t b0 = 0, b2 = 0;
    std::int64_t loops = 0; ///< boundary loops
    bool determined = true;
};

SurfaceBetti betti_from_labels(const Volume& volume, std::int64_t x, std::map<unsigned, Interior>& cell_joins)
{
    const std::int32_t* v = volume.samples<std::int32_t>();
    const Index3 n = volume.dims();
    const std::array<std::int64_t, 3> stride{1, n[0], n[0] * n[1]};
    std::vector<std::int64_t> root(static_cast<std::size_t>(volume.sample_count()));
    for (std::size_t i = 0; i < root.size(); ++i) root[i] = static_cast<std::int64_t>(i);
    const auto find = [&](std::int64_t u) {
        while (root[static_cast<std::size_t>(u)] != u) {
            root[static_cast<std::size_t>(u)] = root[static_cast<std::size_t>(root[static_cast<std::size_t>(u)])];
            u = root[static_cast<std::size_t>(u)];
        }
        return u;
    };
    const auto unite = [&](std::int64_t a, std::int64_t b) { root[static_cast<std::size_t>(find(a))] = find(b); };
    const auto mine = [&](std::int64_t s) { return v[s] == x; };
    // the surface's joins among four corners of a face (sample indices in cyclic order)
    const auto join_face = [&](const std::array<std::int64_t, 4>& q) {
        const std::array<std::int64_t, 4> l{v[q[0]], v[q[1]], v[q[2]], v[q[3]]};
        const std::optional<std::int64_t> joined = joined_label(l);
        for (std::size_t d = 0; d < 2; ++d) {
            const std::int64_t a = l[d], b = l[d + 2], other_a = l[1 - d], other_b = l[3 - d];
            if (a == x && b == x && joined == x) unite(q[d], q[d + 2]);
            const bool x_joined_across = other_a == x && other_b == x && joined == x;
            if (a != x && b != x && !x_joined_across) unite(q[d], q[d + 2]);
        }
    };
    for (std::int64_t s = 0; s < volume.sample_count(); ++s) {
        const std::array<std::int64_t, 3> p{s % n[0], s / n[0] % n[1], s / stride[2]};
        for (std::size_t a = 0; a < 3; ++a) {
            if (p[a] + 1 >= n[a]) continue;
            if (mine(s) == mine(s + stride[a])) unite(s, s + stride[a]);
            const std::size_t b = (a + 1) % 3;
            if (p[b] + 1 >= n[b]) continue;
            join_face({s, s + stride[a], s + stride[a] + stride[b], s + stride[b]});
        }
        if (p[0] + 1 >= n[0] || p[1] + 1 >= n[1] || p[2] + 1 >= n[2]) continue;
        Corners c{};
        std::array<std::int64_t, 8> at{};
        for (unsigned m = 0; m < 8; ++m) {
            at[m] = s + (m & 1U) * stride[0] + (m >> 1 & 1U) * stride[1] + (m >> 2 & 1U) * stride[2];
            c[m] = v[at[m]];
        }
        Corners sorted = c;
        std::sort(sorted.begin(), sorted.end());
        const auto count = std::unique(sorted.begin(), sorted.end()) - sorted.begin();
        if (count == 2) {
            const std::int64_t low = sorted[0];
            unsigned pattern = 0;
            for (unsigned m = 0; m < 8; ++m) pattern |= (c[m] == low ? 1U : 0U) << m;
            auto it = cell_joins.find(pattern);
            if (it == cell_joins.end()) it = cell_joins.emplace(pattern, interior_join(c, low)).first;
            if (it->second == Interior::undetermined) return {0, 0, false};
            if (it->second == Interior::none) continue;
            // the interior joins every corner of one label
            const bool lows = it->second == Interior::joins_low;
            for (unsigned m = 0; m < 8; ++m)
                for (unsigned w = m + 1; w < 8; ++w)
                    if ((c[m] == low) == lows && (c[w] == low) == lows) unite(at[m], at[w]);
            continue;
        }
        if (count < 3) continue;
        if (const auto core = core_label(c)) {
            for (unsigned m = 0; m < 8; ++m)
                for (unsigned w = m + 1; w < 8; ++w)
                    if ((*core == x ? c[m] == x && c[w] == x : c[m] != x && c[w] != x)) unite(at[m], at[w]);
        }
    }
    SurfaceBetti out;
    const auto on_side = [&](const std::array<std::int64_t, 3>& p, std::size_t a) {
        return p[a] == 0 || p[a] == n[a] - 1;
    };
    const auto on_box = [&](std::int64_t s) {
        const std::array<std::int64_t, 3> p{s % n[0], s / n[0] % n[1], s / stride[2]};
        return on_side(p, 0) || on_side(p, 1) || on_side(p, 2);
    };
    std::set<std::int64_t> parts, boxed;
    for (std::int64_t s = 0; s < volume.sample_count(); ++s) {
        parts.insert(find(s));
        if (on_box(s)) boxed.insert(find(s));
    }
    out.b0 = static_cast<std::int64_t>(parts.size()) - 1;
    out.b2 = static_cast<std::int64_t>(parts.size() - boxed.size());
    // the boundary loops: the same tree one dimension down, on the box's surface (a sphere), whose
    // parts are R and the rest there, joined along the edges and faces that lie in the box's faces
    for (std::size_t i = 0; i < root.size(); ++i) root[i] = static_cast<std::int64_t>(i);
    for (std::int64_t s = 0; s < volume.sample_count(); ++s) {
        const std::array<std::int64_t, 3> p{s % n[0], s / n[0] % n[1], s / stride[2]};
        for (std::size_t a = 0; a < 3; ++a) {
            if (p[a] + 1 >= n[a]) continue;
            const std::size_t b = (a + 1) % 3, c = (a + 2) % 3;
            if ((on_side(p, b) || on_side(p, c)) && mine(s) == mine(s + stride[a])) unite(s, s + stride[a]);
            if (p[b] + 1 < n[b] && on_side(p, c))
                join_face({s, s + stride[a], s + stride[a] + stride[b], s + stride[b]});
        }
    }
    std::set<std::int64_t> box_parts;
    for (std::int64_t s = 0; s < volume.sample_count(); ++s)
        if (on_box(s)) box_parts.insert(find(s));
    out.loops = static_cast<std::int64_t>(box_parts.size()) - 1;
    return out;
}

// Whether a surface has the Euler characteristic, Betti numbers and boundary loops of the level set
// field_topology() found.
bool same_topology(const FieldTopology& f, const MeshTopology& t)
{
    return f.determined && f.euler == t.euler && f.b0 == t.components && f.b1 == t.b1 && f.b2 == t.closed_components &&
           f.boundary_loops == t.boundary_loops;
}

// Whether every vertex of `a` lies within `tolerance` (in each coordinate) of a vertex of `b`.
bool near_vertices(const Mesh& a, const Mesh& b, float tolerance)
{
    std::vector<std::uint32_t> by_x(b.vertex_count());
    for (std::uint32_t v = 0; v < by_x.size(); ++v) by_x[v] = v;
    std::sort(by_x.begin(), by_x.end(),
              [&](std::uint32_t u, std::uint32_t w) { return b.positions[3 * u] < b.positions[3 * w]; });
    for (std::uint32_t v = 0; v < a.vertex_count(); ++v) {
        const Point p = point(a, v);
        auto it = std::lower_bound(by_x.begin(), by_x.end(), p[0] - tolerance,
                                   [&](std::uint32_t w, float x) { return b.positions[3 * w] < x; });
        bool found = false;
        for (; !found && it != by_x.end() && b.positions[3 * *it] <= p[0] + tolerance; ++it) {
            const Point q = point(b, *it);
            found = std::max({std::fabs(p[0] - q[0]), std::fabs(p[1] - q[1]), std::fabs(p[2] - q[2])}) <= tolerance;
        }
        if (!found) return false;
    }
    return true;
}

// A segment lies in the box's boundary when both ends share a coordinate at its lowest or highest
// (world positions of an axis-aligned frame with positive spacing, as the tests make).
bool on_box(const Point& a, const Point& b, const Volume& v)
{
    for (std::size_t c = 0; c < 3; ++c) {
        const float lo = static_cast<float>(v.origin()[c]);
        const float hi = static_cast<float>(v.origin()[c] + v.spacing()[c] * static_cast<double>(v.dims()[c] - 1));
        if ((a[c] == lo && b[c] == lo) || (a[c] == hi && b[c] == hi)) return true;
    }
    return false;
}

void fail(Counts& counts, std::int64_t& which, const std::string& what)
{
    ++which;
    if (counts.first_failure.empty()) counts.first_failure = what;
}

} // namespace

Volume random_labels(std::int64_t n, int labels, std::uint64_t seed, bool smooth)
{
    Volume v(ScalarType::i32, {n, n, n});
    std::int32_t* s = v.samples<std::int32_t>();
    std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ULL + static_cast<std::uint64_t>(labels));
    if (!smooth) {
        std::uniform_int_distribution<int> pick(1, labels);
        for (std::int64_t i = 0; i < n * n * n; ++i) s[i] = pick(rng);
        return v;
    }
    // the label of the nearest of a few random seeds per label (a Voronoi-like partition) with noise
    std::uniform_real_distribution<double> u(0, static_cast<double>(n - 1));
    std::vector<std::array<double, 4>> seeds;
    for (int l = 1; l <= labels; ++l)
        for (int k = 0; k < 3; ++k) seeds.push_back({u(rng), u(rng), u(rng), static_cast<double>(l)});
    std::uniform_real_distribution<double> noise(0, 1.5);
    for (std::int64_t z = 0; z < n; ++z)
        for (std::int64_t y = 0; y < n; ++y)
            for (std::int64_t x = 0; x < n; ++x) {
                double best = 1e300;
                int label = 1;
                for (const auto& p : seeds) {
                    const double d = std::hypot(static_cast<double>(x) - p[0], static_cast<double>(y) - p[1],
                                                static_cast<double>(z) - p[2]) +
                                     noise(rng);
                    if (d < best) {
                        best = d;
                        label = static_cast<int>(p[3]);
                    }
                }
                s[x + n * (y + n * z)] = label;
            }
    return v;
}

Volume filtered_indicator(const Volume& labels, std::int64_t label, double sigma)
{
    const Index3 n = labels.dims();
    Volume out(ScalarType::f32, n, labels.spacing(), labels.origin());
    const std::int32_t* in = labels.samples<std::int32_t>();
    const std::int64_t count = labels.sample_count();
    std::vector<double> f(static_cast<std::size_t>(count)), g(f.size());
    for (std::int64_t i = 0; i < count; ++i) f[static_cast<std::size_t>(i)] = in[i] == label ? 1.0 : 0.0;
    const auto r = static_cast<std::int64_t>(std::ceil(3 * sigma));
    const std::array<std::int64_t, 3> stride{1, n[0], n[0] * n[1]};
    for (std::size_t a = 0; a < 3; ++a) {
        for (std::int64_t s = 0; s < count; ++s) {
            const std::int64_t x = s / stride[a] % n[a];
            double sum = 0, weights = 0;
            for (std::int64_t d = -r; d <= r; ++d) {
                if (x + d < 0 || x + d >= n[a]) continue;
                const double w = std::exp(-0.5 * static_cast<double>(d * d) / (sigma * sigma));
                sum += w * f[static_cast<std::size_t>(s + d * stride[a])];
                weights += w;
            }
            g[static_cast<std::size_t>(s)] = sum / weights;
        }
        std::swap(f, g);
    }
    float* o = out.samples<float>();
    for (std::int64_t i = 0; i < count; ++i) o[i] = static_cast<float>(f[static_cast<std::size_t>(i)]);
    return out;
}

void check_field(const Volume& volume, Counts& counts, const std::string& name, double sigma)
{
    ++counts.fields;
    LabelOptions options;
    options.smooth = sigma;
    options.labels = {{std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::max()}};
    const LabelSurfaces s = label_surfaces(volume, options);
    const Mesh& all = s.interfaces;

    // every interface triangle once: no two with the same corners
    {
        std::set<std::array<std::uint32_t, 3>> seen;
        for (std::size_t t = 0; t < all.triangle_count(); ++t) {
            std::array<std::uint32_t, 3> k{all.triangles[3 * t], all.triangles[3 * t + 1], all.triangles[3 * t + 2]};
            std::sort(k.begin(), k.end());
            if (!seen.insert(k).second || s.front[t] == s.behind[t]) {
                fail(counts, counts.duplicate_triangles, name + ": triangle " + std::to_string(t) + " repeated");
                break;
            }
        }
    }
    // the union welded by position is watertight: at an edge off the box, every label is on a side
    // of an even number of its triangles (so no label's region leaks through the edge)
    {
        std::map<std::pair<Point, Point>, std::map<std::int64_t, int>> edges;
        for (std::size_t t = 0; t < all.triangle_count(); ++t) {
            const Tri tri = oriented(all, t);
            for (std::size_t e = 0; e < 3; ++e) {
                Point a = tri[e], b = tri[(e + 1) % 3];
                if (b < a) std::swap(a, b);
                auto& sides = edges[{a, b}];
                ++sides[s.front[t]];
                ++sides[s.behind[t]];
            }
        }
        for (const auto& [edge, sides] : edges) {
            if (on_box(edge.first, edge.second, volume)) continue;
            // every label's sides pair up (a label meeting itself along the edge has 4: counted as
            // not manifold, not as open)
            const bool ok = std::all_of(sides.begin(), sides.end(), [](const auto& p) { return p.second % 2 == 0; });
            if (!ok) {
                fail(counts, counts.union_not_watertight, name + ": the union is open or branched at an interior edge");
                break;
            }
        }
        if (!mesh_geometry(all).embedded())
            fail(counts, counts.union_not_embedded, name + ": the union is not embedded");
    }
    // each interface triangle by position, with the label it faces (front) and the one behind: a
    // label's surface whose triangles are all among them, facing out of the label, is embedded
    // because the union is (a subset of an embedded set of triangles is embedded)
    std::set<std::pair<Tri, std::int64_t>> faces_out;
    for (std::size_t t = 0; t < all.triangle_count(); ++t) {
        const Tri tri = oriented(all, t);
        faces_out.insert({tri, s.behind[t]}); // the behind label's surface faces the front one
        faces_out.insert({smallest_first({tri[0], tri[2], tri[1]}), s.front[t]});
    }
    // each label's surface
    std::map<std::int64_t, MeshTopology> topology;
    for (const std::int64_t label : s.selected) {
        ++counts.label_surfaces;
        const Mesh m = label_surface(s, label);
        const MeshTopology& t = topology[label] = mesh_topology(m);
        const std::string what = name + ", label " + std::to_string(label);
        counts.nonmanifold_edges += t.nonmanifold_edges;
        counts.nonmanifold_vertices += t.nonmanifold_vertices;
        if (t.nonmanifold_edges != 0 || t.nonmanifold_vertices != 0) {
            fail(counts, counts.not_manifold,
                 what + ": " + std::to_string(t.nonmanifold_edges) + " non-manifold edges, " +
                     std::to_string(t.nonmanifold_vertices) + " non-manifold vertices");
        }
        if (!t.oriented) fail(counts, counts.not_oriented, what + ": not oriented");
        // boundary edges only on the box
        std::map<std::pair<Point, Point>, int> uses;
        for (std::size_t f = 0; f < m.triangle_count(); ++f) {
            const Tri tri = oriented(m, f);
            for (std::size_t e = 0; e < 3; ++e) {
                Point a = tri[e], b = tri[(e + 1) % 3];
                if (b < a) std::swap(a, b);
                ++uses[{a, b}];
            }
        }
        for (const auto& [edge, n] : uses) {
            if (n == 1 && !on_box(edge.first, edge.second, volume)) {
                fail(counts, counts.not_closed, what + ": a boundary edge off the box");
                break;
            }
        }
        // and no two of its vertices at one position (its topology above is by index)
        std::set<Point> at;
        for (std::size_t v = 0; v < m.vertex_count(); ++v) at.insert(point(m, static_cast<std::uint32_t>(v)));
        if (at.size() != m.vertex_count()) fail(counts, counts.not_embedded, what + ": two vertices at one position");
        for (std::size_t f = 0; f < m.triangle_count(); ++f) {
            if (faces_out.count({oriented(m, f), label}) == 0) {
                fail(counts, counts.not_embedded,
                     what + ": triangle " + std::to_string(f) +
                         " is not an interface triangle facing out of the label");
                break;
            }
        }
    }
    // each label's Euler characteristic and (up to kBettiLabels labels) Betti numbers and boundary
    // loops from the labels alone (not with smoothing, whose faces and cells follow the filtered values)
    if (sigma == 0 && volume.type() == ScalarType::i32) {
        const std::map<std::int64_t, std::int64_t> euler = euler_from_labels(volume);
        std::map<unsigned, Interior> cell_joins;
        for (const std::int64_t label : s.selected) {
            const auto it = euler.find(label);
            const MeshTopology& got = topology.at(label);
            const std::string what = name + ", label " + std::to_string(label);
            if (it == euler.end() || it->second != got.euler) {
                fail(counts, counts.euler_mismatch,
                     what + ": Euler characteristic " + std::to_string(got.euler) + ", the labels give " +
                         (it == euler.end() ? std::string("none") : std::to_string(it->second)));
                continue;
            }
            if (s.present.size() > kBettiLabels) continue;
            ++counts.betti_compared;
            const SurfaceBetti want = betti_from_labels(volume, label, cell_joins);
            const std::int64_t b1 = want.b0 + want.b2 - it->second;
            if (!want.determined || want.b0 != got.components || want.b2 != got.closed_components || b1 != got.b1 ||
                want.loops != got.boundary_loops) {
                fail(counts, counts.betti_mismatch,
                     what + ": Betti numbers and boundary loops " + std::to_string(got.components) + " " +
                         std::to_string(got.b1) + " " + std::to_string(got.closed_components) + ", " +
                         std::to_string(got.boundary_loops) + "; the labels give " +
                         (want.determined
                              ? std::to_string(want.b0) + " " + std::to_string(b1) + " " + std::to_string(want.b2) +
                                    ", " + std::to_string(want.loops)
                              : std::string("none (a two-label cell's inside joins what the rules do not tell)")));
            }
        }
    }
    // two labels: each surface is the extraction of the lower label's indicator at 0.5 (the
    // higher's reversed), and has the field's topology
    // (a label the filter removed still has its share of the filtered indicators: compared only
    // where the input itself has two labels)
    bool two_in_input = s.present.size() == 2;
    if (two_in_input && sigma > 0) {
        const std::int32_t* samples = volume.samples<std::int32_t>();
        two_in_input = std::all_of(samples, samples + volume.sample_count(),
                                   [&](std::int32_t v) { return v == s.present[0] || v == s.present[1]; });
    }
    if (sigma > 0 && two_in_input) {
        // the filtered indicators of two labels sum to 1: the interface is the level set 0.5 of
        // the lower one's, up to rounding (the library places crossings of f_low - f_high, extract()
        // of f_low - 0.5); a field with a sample or a face's saddle within rounding of 0.5 can be
        // decided either way there and is not compared
        const std::int64_t low = s.present[0];
        const Volume f = filtered_indicator(volume, low, sigma);
        if (!near_tie(f)) {
            ++counts.two_label_compared;
            const Mesh expected = extract(f, 0.5);
            const Mesh m_low = label_surface(s, low);
            // the same triangle count and vertices, each within 0.01 of the other's: rounding moves
            // a crossing more than 1e-4 where both ends of its edge are within 1e-5 of the tie, and
            // decides a face or interior saddle within rounding of it either way (the topology,
            // below, is compared exactly)
            if (m_low.triangle_count() != expected.triangle_count() || !near_vertices(m_low, expected, 0.01F) ||
                !near_vertices(expected, m_low, 0.01F)) {
                fail(counts, counts.two_label_mismatch, name + ": not the extraction of the filtered indicator");
            }
            if (!same_topology(field_topology(f, 0.5), mesh_topology(m_low))) {
                fail(counts, counts.topology_mismatch, name + ": not the filtered field's topology");
            }
        }
    } else if (sigma == 0 && s.present.size() == 2) {
        ++counts.two_label_compared;
        const std::int64_t low = s.present[0];
        Volume indicator(ScalarType::f32, volume.dims());
        const std::int32_t* in = volume.samples<std::int32_t>();
        float* out = indicator.samples<float>();
        for (std::int64_t i = 0; i < volume.sample_count(); ++i) out[i] = in[i] == low ? 1.0F : 0.0F;
        const Mesh expected = extract(indicator, 0.5);
        const auto want = triangle_set(expected, false);
        const Mesh m_low = label_surface(s, low), m_high = label_surface(s, s.present[1]);
        if (triangle_set(m_low, false) != want || triangle_set(m_high, true) != want) {

            fail(counts, counts.two_label_mismatch, name + ": not the extraction of the lower label's indicator");
        }
        if (!same_topology(field_topology(indicator, 0.5), mesh_topology(m_low))) {
            fail(counts, counts.topology_mismatch, name + ": not the field's topology");
        }
    }
}

} // namespace cmc33::label_checks
