#pragma once
// Where the vertices of a cell go, in the cell's own unit coordinates: one definition for
// extract() and analyze_cell(). The rules keep the mesh embedded (docs/conventions.md, "Geometry"):
//
// - Edge vertices lie strictly inside their edge: the crossing parameter is clamped to
//   [delta, 1 - delta]. At a tie (a sample equal to the isovalue, which counts as above) the
//   crossing would be the sample itself and the triangles around it would collapse; the clamp
//   moves it delta along the edge, as if the isovalue were lowered by a tiny amount, which is
//   exactly the topology the sign rule gives.
// - A disc's fan centre is the mean of its loop's crossings, moved a tenth of the way toward the
//   cell's centre: strictly inside the cell, and the fan (a cone over the loop) is embedded.
// - A tube's vertices are points of the cell's surface (crossings or corners) moved halfway toward
//   the centre: the tube is walls over its two loops plus a radial copy of the surface between
//   them (tools/gen_tables/gen_tables.py, tube()), embedded for any crossings.

#include <algorithm>
#include <bit>
#include <cstdint>

#include "cube.hpp"

namespace cmc33::detail {

/// kInteriorMasks entries with this bit are tube vertices: bits 0..4 hold the point moved toward
/// the centre (0..11: the crossing on that edge; 12 + c: corner c). Without it, an edge mask.
inline constexpr unsigned kRadialBit = 0x8000;
inline constexpr unsigned kCornerPoint = 12;
inline constexpr double kTubeScale = 0.5;    ///< tube vertices: centre + 0.5 (point - centre)
inline constexpr double kFanScale = 0.9;     ///< fan centres: centre + 0.9 (mean - centre)
inline constexpr double kMinCrossing = 0x1p-10; ///< default delta: crossings in [delta, 1 - delta]

/// The crossing parameter of an edge from a (above) to b, or from a (below) to b, clamped.
inline double clamp_crossing(double t, double delta) { return std::clamp(t, delta, 1.0 - delta); }

/// True if an interior code needs the crossing of edge e.
inline bool interior_uses_edge(unsigned code, int e)
{
    if (code & kRadialBit) return (code & 31u) == static_cast<unsigned>(e);
    return (code >> e) & 1u;
}

/// Position of interior vertex `code` in unit cell coordinates, given the positions of the
/// crossings (only those of the edges the code uses are read).
inline void interior_position(unsigned code, const double (&crossing)[12][3], double out[3])
{
    if (code & kRadialBit) {
        const unsigned point = code & 31u;
        double p[3];
        for (int c = 0; c < 3; ++c) {
            p[c] = point < kCornerPoint ? crossing[point][c] : static_cast<double>(((point - kCornerPoint) >> c) & 1u);
        }
        for (int c = 0; c < 3; ++c) out[c] = 0.5 + kTubeScale * (p[c] - 0.5);
        return;
    }
    double sum[3] = {0, 0, 0};
    int n = 0;
    for (unsigned edges = code & 0xfffu; edges != 0; edges &= edges - 1) { // in edge order, as before
        const int e = std::countr_zero(edges);
        for (int c = 0; c < 3; ++c) sum[c] += crossing[e][c];
        ++n;
    }
    for (int c = 0; c < 3; ++c) out[c] = 0.5 + kFanScale * (sum[c] / n - 0.5);
}

/// Weights of the 8 corners for trilinear interpolation at unit coordinates p (for normals).
inline void trilinear_weights(const double p[3], double w[8])
{
    for (int c = 0; c < 8; ++c) {
        double x = 1;
        for (int a = 0; a < 3; ++a) x *= ((c >> a) & 1) ? p[a] : 1 - p[a];
        w[c] = x;
    }
}

} // namespace cmc33::detail
