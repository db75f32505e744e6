#pragma once
// Method cmc33-paper: the grid refinement of Custodio et al. 2013 (C13), Sec. 6.2 and Fig. 11.
//
// With Chernyaev's tubes (kLegacyVariants) a tunnel that crosses an ambiguous face lies in that
// face; when the cell on the other side has such a tunnel through the same face, the two meet
// there and the mesh has non-manifold edges (C13 Sec. 5.2, Fig. 8). C13's cure: split the slab of
// cells holding that face by a plane through the face's saddle point, perpendicular to the face.
// The trilinear interpolant is linear along each axis inside a cell, so samples on the new plane
// interpolated along that axis give every sub-cell the interpolant of its cell: the level set is
// unchanged. The face is cut through its saddle: both halves have two corners at the saddle's
// value, so neither is ambiguous, and the two tunnels no longer share a face. Repeat until no
// two tunnels share one (C13: "in practice k = O(1)" splits), then extract from the refined grid.

#include <cstdint>
#include <vector>

#include "cmc33/extract.hpp"
#include "cmc33/mesh.hpp"
#include "cmc33/volume.hpp"

namespace cmc33::detail {

/// extract() without the dispatch to extract_refined(): the passes over `grid` as it is, with the
/// method's decisions and table set (extract.cpp).
template <class T> Mesh extract_passes(const GridView<T>& grid, double iso, const ExtractOptions& options, ExtractStats* stats);

/// A grid face where two tunnels meet: the cells (i, j, k) and (i, j, k) + unit(axis) both have a
/// Chernyaev tube (under cmc33's decisions) lying in the face between them.
struct SharedFace {
    Index3 lower{0, 0, 0}; ///< the cell below the face along `axis`
    int axis = 0;          ///< the face is perpendicular to this axis
};

/// Every face of `grid` at `iso` where two tunnels meet, in (k, j, i, axis) order.
template <class T> std::vector<SharedFace> shared_tunnel_faces(const GridView<T>& grid, double iso);

/// Method cmc33_paper (extract.hpp): refines the grid where shared_tunnel_faces() finds faces, at
/// most kMaxRefinementRounds times, and extracts from the refined grid; without such faces it is
/// extract_passes() on `grid` itself. `stats`, if given, also gets the planes added.
/// @throws Error{internal} if faces are still shared after kMaxRefinementRounds rounds
template <class T> Mesh extract_refined(const GridView<T>& grid, double iso, const ExtractOptions& options, ExtractStats* stats);

inline constexpr int kMaxRefinementRounds = 32;

} // namespace cmc33::detail
