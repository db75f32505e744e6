#pragma once
// The checks of a label map's surfaces (tests/labels), shared by the fast test and the 20,000-field
// sweep: each returns what failed, empty when all held.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "cmc33/labels.hpp"
#include "cmc33/volume.hpp"

namespace cmc33::label_checks {

/// Fields with more labels than this get no Betti count from the labels (a pass over the grid per label).
inline constexpr std::size_t kBettiLabels = 16;

struct Counts {
    std::int64_t fields = 0;
    std::int64_t label_surfaces = 0;
    std::int64_t not_closed = 0;                                  ///< a boundary edge off the volume's box
    std::int64_t not_manifold = 0;                                ///< a non-manifold edge or vertex
    std::int64_t nonmanifold_edges = 0, nonmanifold_vertices = 0; ///< their sums over all surfaces
    std::int64_t not_oriented = 0;
    /// a label's surface not embedded: a triangle that is not an interface triangle facing out of
    /// the label (the union's mesh_geometry covers the rest), or two vertices at one position
    std::int64_t not_embedded = 0;
    std::int64_t union_not_watertight = 0;
    std::int64_t union_not_embedded = 0;
    std::int64_t duplicate_triangles = 0;
    std::int64_t two_label_mismatch = 0; ///< two-label field: not the extraction of the indicator
    std::int64_t topology_mismatch = 0;  ///< two-label field: not field_topology's numbers
    std::int64_t two_label_compared = 0; ///< two-label fields compared with the extraction
    std::int64_t euler_mismatch = 0;     ///< a label's Euler characteristic not the one its labels give
    std::int64_t betti_mismatch = 0;     ///< a label's Betti numbers or boundary loops not the labels' ones
    std::int64_t betti_compared = 0;     ///< label surfaces whose Betti numbers were compared
    std::string first_failure;
};

/// A random label field: `labels` values 1..labels at the samples of an n^3 grid (i.i.d. when
/// `smooth` is false, else by thresholds of a smooth random function), from `seed`.
Volume random_labels(std::int64_t n, int labels, std::uint64_t seed, bool smooth);

/// Every check on `volume` (all its labels selected), added to `counts`; with sigma > 0 on its
/// smoothed labels (LabelOptions::smooth), where a two-label field's surfaces are compared with the
/// extraction of the lower label's indicator filtered here (gaussian_filter()).
void check_field(const Volume& volume, Counts& counts, const std::string& name, double sigma = 0);

/// A label's indicator (1 at its samples, 0 elsewhere) filtered by the Gaussian of docs/labels.md
/// ("Smooth labels"): taps exp(-d^2 / (2 sigma^2)) for |d| <= ceil(3 sigma), renormalised to the
/// samples inside the grid, along x, y and z in turn; written here apart from the library's.
Volume filtered_indicator(const Volume& labels, std::int64_t label, double sigma);

} // namespace cmc33::label_checks
