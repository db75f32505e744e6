#pragma once
/// @file labels.hpp
/// Label maps: the surfaces of every label of a segmentation from one pass, as a partition of
/// space whose interfaces are shared (docs/labels.md).
///
/// Labels are integers at the samples. A label's region is where its indicator's trilinear
/// interpolant is largest, ties to the lower label. In a cell holding two labels a < b that is the
/// level set 0.5 of a's indicator, triangulated with cmc33's own decisions (a's corners above); a
/// cell holding three or more labels is cut by cones from its centre over its faces' curves, or
/// around a core where a cone would pinch a label's surface; every label's surface is a manifold.
/// Each interface triangle is emitted once with the label in front (the side its normal points
/// to) and the label behind; a label's closed surface is the triangles that have it on a side.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "cmc33/labels_export.hpp"
#include "cmc33/mesh.hpp"
#include "cmc33/volume.hpp"

namespace cmc33 {

/// Inclusive ranges of label values ({v, v} for one value).
using LabelRanges = std::vector<std::array<std::int64_t, 2>>;

/// "all" (empty ranges), or a comma-separated list of values and ranges "1,3,7", "2-9", "-5--1".
/// @throws Error{invalid_argument} naming the text and what was expected.
CMC33_LABELS_EXPORT LabelRanges parse_label_ranges(std::string_view text);

struct LabelOptions {
    /// The label that gets no surface (it still takes part in the partition).
    std::int64_t background = 0;
    /// The labels that get surfaces; empty: every label present except `background`.
    LabelRanges labels{};
    /// Threads of the cell pass (z-ranges); 0: all cores. The output is the same for every count.
    int threads = 0;
    /// Per-vertex unit normals on `interfaces` (and so on every label_surface()): at each vertex the
    /// area-weighted mean of its triangles' normals, as each mesh is wound (docs/labels.md).
    bool normals = false;
    /// Smooth labels: 0, or sigma in voxels of the Gaussian each label's indicator is filtered
    /// by first (truncated at 3 sigma). Each sample then takes the label whose filtered indicator
    /// is largest (ties to the lower), and the interfaces pass where the two labels' filtered
    /// indicators are equal on the edges, with cmc33's decisions on their difference in cells
    /// of two labels (docs/labels.md, "Smooth labels"). @throws Error{invalid_argument} unless
    /// finite and >= 0.
    double smooth = 0;
};

/// The interfaces of a label map, in world coordinates as extract() places vertices (the volume's
/// origin, spacing and direction).
struct LabelSurfaces {
    /// Every interface triangle that has a selected label on a side, once. Its normal (counter-
    /// clockwise winding) points into `front`, the higher of its two labels. Vertices are shared:
    /// welded by grid position. With LabelOptions::normals, per-vertex normals pointing to `front`
    /// (at a vertex where more than two labels meet: the mean of the triangles there).
    Mesh interfaces;
    std::vector<std::int64_t> front, behind; ///< one label per triangle of `interfaces`
    std::vector<std::int64_t> present;       ///< every label value in the volume, ascending
    std::vector<std::int64_t> selected;      ///< the labels that get surfaces, ascending
    std::int64_t cells_two_labels = 0;       ///< cells with exactly two labels (cmc33's triangulation)
    std::int64_t cells_many_labels = 0;      ///< cells with three or more (cones or a core)
    std::int64_t cells_with_core = 0;        ///< of those, the cells cut around a core (a label not one disk)
    /// label_surface()'s index when many labels are selected (empty otherwise): the triangles with
    /// selected[i] on a side are by_label[by_label_start[i] .. by_label_start[i + 1]), ascending.
    std::vector<std::uint32_t> by_label;
    std::vector<std::size_t> by_label_start;
    /// With normals, per vertex of `interfaces`: 1 where triangles of more than one pair of labels
    /// meet. label_surface() sums a label's own normals there and turns the interfaces' elsewhere.
    std::vector<std::uint8_t> junctions;
};

/// One pass over `labels` (an integer sample type).
/// @throws Error{unsupported_format} for float or double samples; Error{too_large} past 2^32 vertices.
CMC33_LABELS_EXPORT LabelSurfaces label_surfaces(const Volume& labels, const LabelOptions& options = {});

/// The same over samples read in place (a numpy array with any strides, a sub-block of a larger
/// grid): the frame is the view's.
template <class T>
CMC33_LABELS_EXPORT LabelSurfaces label_surfaces(const GridView<T>& labels, const LabelOptions& options = {});

/// The closed surface of `label` (closed except where it meets the volume's box): the interface
/// triangles with `label` on a side, wound so that normals point out of the label's region,
/// with only the vertices they use. Empty for a label that is not in `selected`. When `interfaces`
/// has normals, the surface has its own, pointing out of the label: at a vertex only two labels
/// share, the exact negation of the other label's.
CMC33_LABELS_EXPORT Mesh label_surface(const LabelSurfaces& surfaces, std::int64_t label);

} // namespace cmc33
