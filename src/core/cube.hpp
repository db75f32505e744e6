#pragma once
// The one definition of corner, edge and face numbering (tools/gen_tables/cube.py mirrors it).
//
//          6 ---------- 7          bit c of a case code  <=>  corner c is above iso
//         /|           /|          (value >= iso: the sign rule, docs/conventions.md)
//        4 ---------- 5 |          z
//        | |          | |          |  y
//        | 2 ---------|-3          | /
//        |/           |/           |/
//        0 ---------- 1            +---- x        corner c = x | y << 1 | z << 2
//
// Faces: f = 2 * axis + side (0: x=0, 1: x=1, 2: y=0, 3: y=1, 4: z=0, 5: z=1).

#include <array>

namespace cmc33::detail {

inline constexpr int kEdgeCorners[12][2] = {
    {0, 1}, {2, 3}, {4, 5}, {6, 7}, // edges 0-3  run along x
    {0, 2}, {1, 3}, {4, 6}, {5, 7}, // edges 4-7  run along y
    {0, 4}, {1, 5}, {2, 6}, {3, 7}, // edges 8-11 run along z
};

constexpr bool edges_follow_axes()
{
    for (int e = 0; e < 12; ++e) {
        const int a = kEdgeCorners[e][0], b = kEdgeCorners[e][1];
        if ((a ^ b) != (1 << (e / 4)) || (a & (1 << (e / 4))) != 0) return false;
    }
    return true;
}
static_assert(edges_follow_axes(), "edge e joins a corner to its +axis(e/4) neighbour, lower corner first");

/// Corners of face f in cyclic order p00, p10, p11, p01, where u < v are the face's two axes.
/// Both cells sharing a face list its samples in the same order, so they compute the same
/// face decision bit for bit.
constexpr std::array<int, 4> face_cycle(int f)
{
    const int axis = f / 2, side = f % 2;
    const int u = axis == 0 ? 1 : 0;
    const int v = axis == 2 ? 1 : 2;
    const int base = side << axis;
    return {base, base | 1 << u, base | 1 << u | 1 << v, base | 1 << v};
}

/// The corner of the cube reached from corner c by moving along `axis`.
constexpr int flip(int c, int axis) { return c ^ (1 << axis); }

} // namespace cmc33::detail
