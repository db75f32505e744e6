// The cell constructions of cells.hpp.

#include "cells.hpp"

#include <algorithm>

#include "cmc33/cell.hpp"
#include "cmc33/error.hpp"

namespace cmc33::label_cells {

namespace {

// cmc33's triangles of the cell whose corners in `config` hold the lower label (value 1 at iso
// 0.5: every crossing is an edge midpoint, every tied face saddle joins the lower label).
std::array<Pattern, 256> make_patterns()
{
    std::array<Pattern, 256> patterns;
    for (unsigned config = 1; config < 255; ++config) {
        std::array<double, 8> values{};
        for (unsigned c = 0; c < 8; ++c) values[c] = (config >> c & 1U) != 0 ? 1.0 : 0.0;
        const CellReport report = analyze_cell(values, 0.5, Method::cmc33);
        const Mesh& m = report.mesh;
        std::vector<std::array<double, 3>> interior;
        for (std::size_t t = 0; t < m.triangle_count(); ++t) {
            std::array<TableVertex, 3> tri{};
            for (std::size_t v = 0; v < 3; ++v) {
                const std::size_t index = m.triangles[3 * t + v];
                TableVertex& out = tri[v];
                for (std::size_t a = 0; a < 3; ++a) {
                    const double p = static_cast<double>(m.positions[3 * index + a]);
                    out.unit[a] = p;
                    const double twice = 2 * p;
                    out.doubled[a] = static_cast<int>(twice);
                    if (twice != static_cast<double>(out.doubled[a])) out.interior = true;
                }
                if (out.interior) {
                    const auto it = std::find(interior.begin(), interior.end(), out.unit);
                    out.slot = static_cast<int>(it - interior.begin());
                    if (it == interior.end()) interior.push_back(out.unit);
                    if (interior.size() > kInteriorSlots) {
                        throw Error(Status::internal, "label maps: a cell pattern with more than 16 interior points");
                    }
                }
            }
            patterns[config].triangles.push_back(tri);
        }
    }
    return patterns;
}

} // namespace

const std::array<Pattern, 256>& patterns()
{
    static const std::array<Pattern, 256> table = make_patterns();
    return table;
}

namespace {

// The root of x in a union-find forest (parent[x] == x at a root).
template <std::size_t N> int root_of(const std::array<int, N>& parent, int x)
{
    while (parent[static_cast<std::size_t>(x)] != x) x = parent[static_cast<std::size_t>(x)];
    return x;
}

} // namespace

FaceCut cut_faces(const std::array<std::int64_t, 8>& label, const DiagonalRule* rule)
{
    FaceCut cut;
    std::array<int, 8> parent{0, 1, 2, 3, 4, 5, 6, 7};
    const auto join = [&](unsigned a, unsigned b) {
        parent[static_cast<std::size_t>(root_of(parent, static_cast<int>(a)))] = root_of(parent, static_cast<int>(b));
    };
    const auto corner = [](unsigned c) { return quad_of(corner_doubled(c)); };
    const auto mid = [](unsigned u, unsigned w) { return quad_of(midpoint(u, w)); };
    for (unsigned axis = 0; axis < 3; ++axis) {
        const unsigned b = (axis + 1) % 3, c = (axis + 2) % 3;
        for (unsigned s = 0; s < 2; ++s) {
            // the face's corners in cyclic order
            const std::array<unsigned, 4> q{s << axis, s << axis | 1U << b, s << axis | 1U << b | 1U << c,
                                            s << axis | 1U << c};
            const std::array<std::int64_t, 4> l{label[q[0]], label[q[1]], label[q[2]], label[q[3]]};
            const auto next = [](unsigned i) { return (i + 1) % 4; };
            const auto prev = [](unsigned i) { return (i + 3) % 4; };
            for (unsigned i = 0; i < 4; ++i) {
                if (l[i] == l[next(i)]) join(q[i], q[next(i)]);
            }
            const auto segment = [&](unsigned i, const Quad& to) {
                cut.segments[static_cast<std::size_t>(cut.n_segments++)] =
                    Segment{mid(q[i], q[next(i)]), to, corner(q[i]), l[i], l[next(i)]};
            };
            const auto piece = [&]() -> Piece& {
                Piece& p = cut.pieces[static_cast<std::size_t>(cut.n_pieces++)];
                p = Piece{};
                return p;
            };
            std::array<std::int64_t, 4> sorted = l;
            std::sort(sorted.begin(), sorted.end());
            const auto distinct = std::unique(sorted.begin(), sorted.end()) - sorted.begin();
            if (distinct == 1) {
                Piece& p = piece();
                for (unsigned i = 0; i < 4; ++i) p.add(corner(q[i]));
                p.label = l[0];
                continue;
            }
            // a label on both ends of a diagonal is joined across the face (the lower one when both
            // diagonals are alike, cmc33's tie rule): the other corners are cut off
            const bool diagonal0 = l[0] == l[2], diagonal1 = l[1] == l[3];
            if (diagonal0 || diagonal1) {
                const std::int64_t joined = diagonal0 && diagonal1
                                                ? (rule != nullptr ? (*rule)(q, sorted[0], sorted[1]) : sorted[0])
                                                : (diagonal0 ? l[0] : l[1]);
                Piece& whole = piece();
                whole.label = joined;
                for (unsigned i = 0; i < 4; ++i) {
                    if (l[i] == joined) {
                        whole.add(corner(q[i]));
                        continue;
                    }
                    whole.add(mid(q[prev(i)], q[i]));
                    whole.add(mid(q[i], q[next(i)]));
                }
                for (unsigned i = 0; i < 4; ++i) {
                    if (l[i] == joined) continue;
                    segment(i, mid(q[prev(i)], q[i]));
                    Piece& p = piece();
                    p.add(corner(q[i]));
                    p.add(mid(q[i], q[next(i)]));
                    p.add(mid(q[prev(i)], q[i]));
                    p.label = l[i];
                }
                join(q[diagonal0 && l[0] == joined ? 0 : 1], q[diagonal0 && l[0] == joined ? 2 : 3]);
                continue;
            }
            // the face's edges whose labels differ, in cyclic order
            std::array<unsigned, 4> crossed{};
            unsigned n = 0;
            for (unsigned i = 0; i < 4; ++i) {
                if (l[i] != l[next(i)]) crossed[n++] = i;
            }
            Quad face_centre{2, 2, 2};
            face_centre[axis] = 4 * static_cast<int>(s);
            if (distinct == 2) { // the one segment between the two crossed edges' midpoints
                segment(crossed[0], mid(q[crossed[1]], q[next(crossed[1])]));
            } else { // a star from the face's centre
                for (unsigned e = 0; e < n; ++e) segment(crossed[e], face_centre);
            }
            // a piece per run of corners between crossed edges
            for (unsigned e = 0; e < n; ++e) {
                const unsigned from = crossed[e], to = crossed[(e + 1) % n];
                Piece& p = piece();
                p.add(mid(q[from], q[next(from)]));
                for (unsigned i = next(from);; i = next(i)) {
                    p.add(corner(q[i]));
                    if (i == to) break;
                }
                p.add(mid(q[to], q[next(to)]));
                if (distinct > 2) p.add(face_centre);
                p.label = l[next(from)];
            }
        }
    }
    for (unsigned c = 0; c < 8; ++c) cut.corner_root[c] = root_of(parent, static_cast<int>(c));
    return cut;
}

std::optional<std::int64_t> core_label(const std::array<std::int64_t, 8>& label, const FaceCut& cut)
{
    std::array<std::int64_t, 8> sorted = label;
    std::sort(sorted.begin(), sorted.end());
    const auto end = std::unique(sorted.begin(), sorted.end());
    for (auto l = sorted.begin(); l != end; ++l) {
        // its pieces: the distinct roots of its corners
        int roots = 0;
        std::array<bool, 8> seen{};
        for (unsigned c = 0; c < 8; ++c) {
            if (label[c] != *l) continue;
            const auto r = static_cast<std::size_t>(cut.corner_root[c]);
            if (!seen[r]) ++roots;
            seen[r] = true;
        }
        // the label's boundary: the segments with the label on a side, each point of the curves on
        // it at most once per loop (a point's sectors hold distinct labels), so loops are components
        std::array<int, 27> parent{};
        std::array<bool, 27> used{};
        for (int i = 0; i < 27; ++i) parent[static_cast<std::size_t>(i)] = i;
        const auto find = [&](int x) { return root_of(parent, x); };
        for (int i = 0; i < cut.n_segments; ++i) {
            const Segment& s = cut.segments[static_cast<std::size_t>(i)];
            if (s.near != *l && s.far != *l) continue;
            const int a = lattice_slot(s.from), b = lattice_slot(s.to);
            used[static_cast<std::size_t>(a)] = used[static_cast<std::size_t>(b)] = true;
            parent[static_cast<std::size_t>(find(a))] = find(b);
        }
        int loops = 0;
        for (int i = 0; i < 27; ++i) loops += used[static_cast<std::size_t>(i)] && find(i) == i ? 1 : 0;
        if (roots != 1 || loops != 1) return *l;
    }
    return std::nullopt;
}

} // namespace cmc33::label_cells
