#pragma once
// One cell of the field-topology verifier: the loops that S = {f = iso - eps} draws on the cell's
// faces, and which loops bound the same piece of S inside the cell. Derived from the trilinear
// interpolant alone; nothing here comes from src/core or src/tables (the extractor). The method
// and its proofs are in the comment block at the top of field_topology.cpp.
//
// Numbering (docs/conventions.md): corner c = x | y << 1 | z << 2; edges 0-3 run along x
// (0-1, 2-3, 4-5, 6-7), 4-7 along y (0-2, 1-3, 4-6, 5-7), 8-11 along z (0-4, 1-5, 2-6, 3-7);
// face f = 2 * axis + side. A case code has bit c set when corner c is above (value >= iso).

#include <cstdint>

#include "field_exact.hpp"

namespace cmc33::topology::detail {

inline constexpr int kEdgeCorners[12][2] = {
    {0, 1}, {2, 3}, {4, 5}, {6, 7}, // along x
    {0, 2}, {1, 3}, {4, 6}, {5, 7}, // along y
    {0, 4}, {1, 5}, {2, 6}, {3, 7}, // along z
};

constexpr bool edges_follow_axes()
{
    for (int e = 0; e < 12; ++e) {
        const int a = kEdgeCorners[e][0];
        const int b = kEdgeCorners[e][1];
        if ((a ^ b) != (1 << (e / 4)) || (a & (1 << (e / 4))) != 0) return false;
    }
    return true;
}
static_assert(edges_follow_axes(),
              "edge e joins a corner to its +axis(e/4) neighbour, lower corner first");

/// In-plane axes of a face or slice normal to `axis`, in increasing order.
constexpr int plane_axis_u(int axis)
{
    return axis == 0 ? 1 : 0;
}
constexpr int plane_axis_v(int axis)
{
    return axis == 2 ? 1 : 2;
}

/// Cell corner of face `f` at in-plane position (pu, pv).
constexpr int face_corner(int f, int pu, int pv)
{
    const int axis = f / 2;
    return ((f % 2) << axis) | (pu << plane_axis_u(axis)) | (pv << plane_axis_v(axis));
}

/// Cell edge joining corners a and b (adjacent), or -1.
constexpr int edge_of(int a, int b)
{
    for (int e = 0; e < 12; ++e) {
        if ((kEdgeCorners[e][0] == a && kEdgeCorners[e][1] == b) ||
            (kEdgeCorners[e][0] == b && kEdgeCorners[e][1] == a)) {
            return e;
        }
    }
    return -1;
}

/// Bit mask of the edges whose two corners lie on different sides.
constexpr unsigned crossed_edges(unsigned code)
{
    unsigned mask = 0;
    for (int e = 0; e < 12; ++e) {
        if (((code >> kEdgeCorners[e][0]) & 1u) != ((code >> kEdgeCorners[e][1]) & 1u)) {
            mask |= 1u << e;
        }
    }
    return mask;
}

/// Bit mask of the four edges of face f.
constexpr unsigned face_edge_mask(int f)
{
    return (1u << edge_of(face_corner(f, 0, 0), face_corner(f, 1, 0))) |
           (1u << edge_of(face_corner(f, 0, 1), face_corner(f, 1, 1))) |
           (1u << edge_of(face_corner(f, 0, 0), face_corner(f, 0, 1))) |
           (1u << edge_of(face_corner(f, 1, 0), face_corner(f, 1, 1)));
}

/// Bit mask of the faces whose above corners are diagonal (4 crossings: the face needs a decision).
constexpr unsigned ambiguous_faces(unsigned code)
{
    unsigned mask = 0;
    for (int f = 0; f < 6; ++f) {
        const unsigned p00 = (code >> face_corner(f, 0, 0)) & 1u;
        const unsigned p10 = (code >> face_corner(f, 1, 0)) & 1u;
        const unsigned p01 = (code >> face_corner(f, 0, 1)) & 1u;
        const unsigned p11 = (code >> face_corner(f, 1, 1)) & 1u;
        if (p00 == p11 && p10 == p01 && p00 != p10) mask |= 1u << f;
    }
    return mask;
}

/// The arcs of S on face f: pairs of cell edges (up to two). `joined` says whether the above
/// corners of an ambiguous face are joined (its saddle is above); it is ignored otherwise.
/// An ambiguous face cuts off its two below corners when the above ones are joined, else its two
/// above corners; each cut-off corner gives the arc between its two face edges.
int face_arcs(unsigned code, int f, bool joined, int arcs[2][2]);

/// Loops of S on the boundary of a cell, for one case code and one set of face decisions.
struct CellLoops {
    std::int8_t loops = 0;          ///< number of closed curves on the cell's boundary
    std::int8_t loop_of_edge[12]{}; ///< loop through the crossing on each edge, -1 if not crossed
    std::int8_t rep_edge[8]{};      ///< one crossed edge on each loop
};

/// `face_bits` bit f: the above corners of face f are joined (read only for ambiguous faces).
const CellLoops& cell_loops(unsigned code, unsigned face_bits);

/// Corner values of one cell and the isovalue. All decisions use the exact values v - iso.
struct CellInput {
    double v[8] = {};
    double iso = 0.0;
};

/// Case code: bit c set when v[c] >= iso.
unsigned cell_code(const CellInput& in);

/// Exact sign of the numerator M(t) = P00 P11 - P10 P01 of the saddle value of the slice of the
/// cell normal to `axis` at height t (P_uv = lerp along the axis of the corner values minus iso,
/// u, v the other axes in increasing order). t must be a dyadic rational in [0, 1] with at most
/// 26 fraction bits.
int slice_numerator_sign(const CellInput& in, int axis, double t, Numerics& numerics);

/// Face decision: are the above corners of face f joined? (f ambiguous for the cell's code.)
/// Exact; ties (saddle value equal to iso) count as above, so the corners are then joined.
bool face_joins_above(const CellInput& in, unsigned code, int f, Numerics& numerics);

/// Decision bits of all the ambiguous faces of a cell.
unsigned face_decisions(const CellInput& in, unsigned code, Numerics& numerics);

/// Exact sign of f - iso at the point (x, y, z) / 2^bits of the cell (bits <= 17).
int point_sign(const CellInput& in, std::int64_t x, std::int64_t y, std::int64_t z, int bits,
               Numerics& numerics);

/// Pieces of S inside one cell.
struct CellPieces {
    enum class Status { ok, inconsistent, lost_precision, disagreement };
    Status status = Status::ok;
    int loops = 0;                  ///< closed curves on the cell's boundary
    int pieces = 0;                 ///< connected components of S in the cell (discs and tubes)
    int euler = 0;                  ///< Euler characteristic of S in the cell
    std::int8_t piece_of_loop[8]{}; ///< piece of each loop
    bool cross_checked = false;     ///< the refinement settled the cell and agreed
    int refined_euler = 0;          ///< refinement's answer, when cross_checked or disagreement
    int refined_pieces = 0;
};

/// Interior analysis of one cell (any code, any number of loops): the exact sweep of
/// field_topology.cpp, then, if max_refinement >= 2, the independent cross-check by adaptive
/// refinement up to that subdivision factor (capped at 1024).
CellPieces cell_pieces(const CellInput& in, unsigned code, unsigned face_bits, int max_refinement,
                       Numerics& numerics);

/// The refinement alone (for tests): resolved == false when some sub-cell still had two or more
/// loops at the finest level allowed.
struct RefinedCell {
    bool resolved = false;
    int euler = 0;
    int pieces = 0;
    std::int8_t piece_of_edge[12]{}; ///< -1 for edges not crossed
};
RefinedCell refine_cell(const CellInput& in, int max_refinement, Numerics& numerics);

} // namespace cmc33::topology::detail
