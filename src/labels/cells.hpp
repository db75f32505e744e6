#pragma once
// The triangles of one cell of a label map (docs/labels.md, "The partition"): cmc33's
// triangulations of the 256 two-label corner patterns, and the face curves, pieces, cones and
// cores of cells with three or more labels. Points are in doubled (0..2) or quadrupled (0..4)
// coordinates within the cell, so that neighbouring cells name shared points alike.

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

namespace cmc33::label_cells {

// A vertex of a cell's triangle: doubled coordinates in the cell (0..2 each: corners, edge
// midpoints, face and cell centres), or an interior point of cmc33's triangulation.
struct TableVertex {
    std::array<int, 3> doubled{0, 0, 0};
    bool interior = false;
    int slot = 0;                        ///< interior points: which of the cell's (below kInteriorSlots)
    std::array<double, 3> unit{0, 0, 0}; ///< position in the unit cube (interior points)
};

// cmc33's tunnels (7.4.1, 13.5.1 and the like) place up to 12 points inside a cell
constexpr std::uint64_t kInteriorSlots = 16;

struct Pattern {
    std::vector<std::array<TableVertex, 3>> triangles;
};

/// cmc33's triangles of every corner pattern (bit c: corner c holds the lower label).
const std::array<Pattern, 256>& patterns();

using Doubled = std::array<int, 3>;

inline Doubled corner_doubled(unsigned c)
{
    return {2 * static_cast<int>(c & 1U), static_cast<int>(c & 2U), static_cast<int>(c >> 1 & 2U)};
}

inline Doubled midpoint(unsigned u, unsigned w)
{
    const Doubled a = corner_doubled(u), b = corner_doubled(w);
    return {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2};
}

// A point of a cell in quadrupled coordinates (0..4 each): corners 0 and 4, edge midpoints and face
// and cell centres 2. The core's points (below) are the odd ones.
using Quad = std::array<int, 3>;

inline Quad quad_of(const Doubled& d)
{
    return {2 * d[0], 2 * d[1], 2 * d[2]};
}

// The point halfway from the cell's centre to p: a corner of the core.
inline Quad toward_centre(const Quad& p)
{
    return {1 + p[0] / 2, 1 + p[1] / 2, 1 + p[2] / 2};
}

// Which of the 27 points of the cell's surface and centre p (even coordinates) is.
inline int lattice_slot(const Quad& p)
{
    return p[0] / 2 + 3 * (p[1] / 2) + 9 * (p[2] / 2);
}

// A segment of a face's curve, from the midpoint of the face edge (u, w) to `to`: label `near` on
// u's side, `far` on the other.
struct Segment {
    Quad from, to;
    Quad u; ///< the corner on near's side
    std::int64_t near = 0, far = 0;
};

// A connected piece of a face cut by its curve: a convex polygon in the face's cyclic order.
struct Piece {
    std::array<Quad, 6> points{};
    int size = 0;
    std::int64_t label = 0;
    void add(const Quad& p) { points[static_cast<std::size_t>(size++)] = p; }
    /// Where the piece's fan starts: its first corner of the square (every piece holds one; its
    /// angle there is a right angle, so no triangle of the fan is flat).
    int apex() const
    {
        const auto on_corner = [](const Quad& q) { return q[0] % 4 == 0 && q[1] % 4 == 0 && q[2] % 4 == 0; };
        int i = 0;
        while (!on_corner(points[static_cast<std::size_t>(i)])) ++i;
        return i;
    }
};

// The curves and pieces of a cell's six faces, each face's made from its four labels only, so
// that neighbouring cells agree on them (docs/labels.md, "Cells with three or more labels").
struct FaceCut {
    std::array<Segment, 24> segments{};
    std::array<Piece, 24> pieces{};
    int n_segments = 0, n_pieces = 0;
    std::array<int, 8> corner_root{}; ///< corners joined along uncut edges and joined diagonals
};

/// Which of a face's two labels low < high, one on each diagonal, is joined across it, given the
/// face's corners in cyclic order: the lower one without a rule (cmc33's tie), and with smoothed
/// labels the one cmc33 joins on their values.
using DiagonalRule =
    std::function<std::int64_t(const std::array<unsigned, 4>& corners, std::int64_t low, std::int64_t high)>;

/// The face curves and pieces of the cell with these corner labels (x fastest, then y, then z).
FaceCut cut_faces(const std::array<std::int64_t, 8>& label, const DiagonalRule* rule = nullptr);

/// The label whose part of the cell's surface is not one disk (more than one piece, or one piece
/// with more than one boundary loop), the lowest such; none when every label's part is a disk.
std::optional<std::int64_t> core_label(const std::array<std::int64_t, 8>& label, const FaceCut& cut);

// A cell with three or more labels. Where every label's part of the cell's surface is one disk, a
// triangle from the centre to every segment of every face's curve: each label's part of the cell
// is the cone from the centre over its part of the surface. Where a label's part is not one disk,
// such cones would meet at the centre (a pinch); instead the cell's core, the cube halfway to the
// centre, belongs to that label (`core_label`), and every piece of the surface to the frustum
// between it and the core: a quad per segment (two triangles) between neighbouring frustums, and
// the core's faces under the other labels' pieces (fans from a corner).
// Returns whether the cell took a core.
template <class Emit>
bool many_label_cell(const std::array<std::int64_t, 8>& label, Emit&& emit, const DiagonalRule* rule = nullptr)
{
    const FaceCut cut = cut_faces(label, rule);
    // front is the side the winding's normal points to; `probe` is a point on near's side
    const auto oriented = [&](const Quad& a, const Quad& b, const Quad& c, const Quad& probe, std::int64_t near,
                              std::int64_t far) {
        const Quad p{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, q{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        const Quad n{p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0]};
        const int side = n[0] * (probe[0] - a[0]) + n[1] * (probe[1] - a[1]) + n[2] * (probe[2] - a[2]);
        if (side > 0)
            emit(a, b, c, near, far);
        else
            emit(a, b, c, far, near);
    };
    const std::optional<std::int64_t> core = core_label(label, cut);
    const Quad centre{2, 2, 2};
    for (int i = 0; i < cut.n_segments; ++i) {
        const Segment& s = cut.segments[static_cast<std::size_t>(i)];
        // the triangle's plane passes through the centre and meets the face along the segment's
        // line, which misses the corner u
        if (!core) {
            oriented(centre, s.from, s.to, s.u, s.near, s.far);
            continue;
        }
        const Quad from = toward_centre(s.from), to = toward_centre(s.to);
        oriented(s.from, s.to, to, s.u, s.near, s.far);
        oriented(s.from, to, from, s.u, s.near, s.far);
    }
    if (!core) return false;
    for (int i = 0; i < cut.n_pieces; ++i) {
        const Piece& p = cut.pieces[static_cast<std::size_t>(i)];
        if (p.label == *core) continue;
        // the piece's corner of the square lies off the core's face, on the piece's side
        const int apex = p.apex();
        const auto at = [&](int k) { return p.points[static_cast<std::size_t>((apex + k) % p.size)]; };
        for (int k = 1; k + 1 < p.size; ++k) {
            oriented(toward_centre(at(0)), toward_centre(at(k)), toward_centre(at(k + 1)), at(0), p.label, *core);
        }
    }
    return true;
}

} // namespace cmc33::label_cells
