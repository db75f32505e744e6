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
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "cmc33/extract.hpp"
#include "cmc33/mesh.hpp"
#include "cmc33/volume.hpp"

namespace cmc33::detail {

/// extract()'s passes over `grid` as it is (no refinement), with the method's decisions and table
/// set (extract.cpp).
template <class T> Mesh extract_passes(const GridView<T>& grid, double iso, const ExtractOptions& options, ExtractStats* stats);

/// A grid face where two tunnels meet: the cells (i, j, k) and (i, j, k) + unit(axis) both have a
/// Chernyaev tube (under cmc33's decisions) lying in the face between them.
struct SharedFace {
    Index3 lower{0, 0, 0}; ///< the cell below the face along `axis`
    int axis = 0;          ///< the face is perpendicular to this axis
};

/// Every face of `grid` at `iso` where two tunnels meet, in (k, j, i, axis) order.
template <class T> std::vector<SharedFace> shared_tunnel_faces(const GridView<T>& grid, double iso);

struct RefinedGrid; // refine.cpp

/// Method cmc33_paper (extract.hpp): the grid refined where shared_tunnel_faces() finds faces (C13
/// Sec. 6.2), at most kMaxRefinementRounds times; extract() runs the passes on view() at iso() and
/// maps their mesh back to the original grid with map_back().
class Refinement {
public:
    /// The refinement of `grid`, or none where no tunnels share a face (the grid as it is).
    /// @throws Error{internal} if faces are still shared after kMaxRefinementRounds rounds
    template <class T> static std::optional<Refinement> of(const GridView<T>& grid, double iso);
    GridView<double> view() const;
    double iso() const;
    /// The planes added.
    std::int64_t planes() const noexcept { return planes_; }
    /// Takes a mesh of view() to `grid`'s index space and world frame, with normals from `grid`'s
    /// samples when `normals`.
    template <class T> void map_back(const GridView<T>& grid, bool normals, Mesh& mesh) const;

private:
    std::shared_ptr<const RefinedGrid> grid_;
    std::int64_t planes_ = 0;
};

inline constexpr int kMaxRefinementRounds = 32;

} // namespace cmc33::detail
