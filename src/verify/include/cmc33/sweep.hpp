#pragma once
/// @file sweep.hpp
/// The topology of a volume's isosurfaces over a range of isovalues, per method: what Custodio et
/// al. 2013 plot in Figs. 13 and 14 (connected components, non-manifold edges), with the
/// topology the trilinear field's level set has (field_topology) beside the cmc33 rows.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cmc33/extract.hpp"
#include "cmc33/topology.hpp"
#include "cmc33/verify.hpp"
#include "cmc33/volume.hpp"
#include "cmc33/verify_export.hpp"

namespace cmc33 {

/// from, from + step, ... up to `to` (inclusive, within a millionth of a step), each value the
/// double nearest its 15-digit decimal, so that 10:11:0.1 gives 10.3 and not 10.299999999999999:
/// the isovalue `cmc33 extract --iso 10.3` uses.
/// @throws Error{invalid_argument} unless from <= to, step > 0, all finite, and at most 10^6 values
CMC33_VERIFY_EXPORT std::vector<double> sweep_isovalues(double from, double to, double step);

struct SweepOptions {
    std::vector<double> isovalues;
    std::vector<Method> methods{Method::cmc33, Method::chernyaev, Method::mc33_lewiner, Method::mc};
    bool expected = true; ///< field_topology at every isovalue, for the cmc33 rows
    int threads = 0;      ///< isovalues run in parallel, each extraction on one thread; 0: all cores
    /// Called on the calling thread about every 0.2 s and at the end: isovalues done of total.
    ProgressCallback progress;
};

/// One (isovalue, method): the mesh's invariants as mesh_topology() counts them (by index).
struct SweepRow {
    double iso = 0;
    Method method = Method::cmc33;
    std::int64_t vertices = 0;
    std::int64_t triangles = 0;
    std::int64_t euler = 0;
    std::int64_t b0 = 0, b1 = 0, b2 = 0; ///< components, b0 + b2 - euler, closed components
    std::int64_t boundary_loops = 0;
    std::int64_t nonmanifold_edges = 0;
    /// cmc33 rows (with SweepOptions::expected): the level set's topology; none when the field's
    /// topology is undetermined or for other methods
    std::optional<FieldTopology> expected;
};

struct SweepReport {
    std::vector<SweepRow> rows; ///< by isovalue, then in the order of SweepOptions::methods
    int threads = 0;
    double seconds = 0;
};

/// Extracts the volume at every isovalue with every method and counts the meshes' topology.
/// The rows do not depend on the thread count. Each extraction equals extract() with that method
/// and one thread, so a row equals what `cmc33 extract --json` reports for it.
/// @throws Error{invalid_argument} for no isovalue, a non-finite one, no method or one twice;
///         the errors of extract()
CMC33_VERIFY_EXPORT SweepReport sweep(const Volume& volume, const SweepOptions& options);

} // namespace cmc33
