#pragma once
/// @file verify.hpp
/// The topology stress test (Etiene et al. 2012; Custodio et al. 2013, Sec. 4): random fields,
/// the topology their trilinear level set must have (field_topology), the topology of the mesh a
/// method extracts (mesh_topology), and the comparison. docs/verification.md explains what is
/// compared and why. The verification dataset (the same fields as NRRD files with their expected
/// invariants, and the check of any extractor against it) is the CLI's (`cmc33 dataset`,
/// `cmc33 verify --dataset`), built on the report and bookkeeping here.

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "cmc33/extract.hpp"
#include "cmc33/topology.hpp"
#include "cmc33/volume.hpp"
#include "cmc33/verify_export.hpp"

namespace cmc33 {

/// The three families of random fields.
///  - cell:   2x2x2 samples from a mix of distributions that covers all 256 sign configurations
///            and all 33 subcases (docs/verification.md lists them);
///  - grid:   size^3 samples uniform in [-1, 1] (the paper's 5x5x5 grids);
///  - closed: size^3 samples, those with an index 0 or size - 1 in [-1, -0.1] (below iso 0, so
///            every surface is closed), the others uniform in [-1, 1];
///  - ties:   size^3 integer samples, odd items uniform in {-2, ..., 2}, even items in
///            {-3, ..., 3} (integer data 0..4 at iso 2 and 0..6 at iso 3, shifted): samples equal
///            to the isovalue everywhere, and face and interior saddles at it too.
/// The isovalue is 0 for all of them.
enum class FieldKind { cell, grid, closed, ties };
inline constexpr int kFieldKindCount = 4;

CMC33_VERIFY_EXPORT std::string_view field_kind_name(FieldKind kind) noexcept; ///< "cell", "grid", "closed", "ties"

/// Item n (n >= 1) of kind `kind` in a run with seed `seed`: float samples, spacing 1, origin 0.
/// Each item has its own generator, seeded from (seed, kind, n) (SplitMix64), so a field does not
/// depend on the thread count, the order of work or the other items of the run.
/// @param size  samples per axis of grid and closed fields (ignored for cells)
/// @throws Error{invalid_argument} if n < 1 or size < 2 (size < 3 for closed: no interior sample)
CMC33_VERIFY_EXPORT Volume random_field(FieldKind kind, std::int64_t n, std::uint64_t seed, int size = 5);

/// Name of the distribution cell n is drawn from ("uniform", "cubed", "pattern", ...).
CMC33_VERIFY_EXPORT std::string_view cell_distribution_name(std::int64_t n) noexcept;

/// "cell-000042": the file stem of item n (six digits at least).
CMC33_VERIFY_EXPORT std::string field_name(FieldKind kind, std::int64_t n);

/// True iff the mesh has the field's euler, b0, b1, b2 and boundary loops. False if the field is
/// undetermined. Manifoldness is not part of it: see is_manifold().
CMC33_VERIFY_EXPORT bool topology_matches(const MeshTopology& mesh, const FieldTopology& field) noexcept;
/// No non-manifold edge and no non-manifold vertex.
CMC33_VERIFY_EXPORT bool is_manifold(const MeshTopology& mesh) noexcept;

/// Where a long run is, for a progress line. Called on the thread that called verify(),
/// about every 0.2 s, and once more at the end with done == total.
struct VerifyProgress {
    std::int64_t done = 0;       ///< fields finished
    std::int64_t total = 0;      ///< fields in the run
    std::int64_t mismatched = 0; ///< (field, method) pairs that did not match so far
    double seconds = 0;          ///< since the run started
};
using ProgressCallback = std::function<void(const VerifyProgress&)>;

struct VerifyOptions {
    std::vector<Method> methods{Method::cmc33, Method::mc33_lewiner, Method::mc};
    std::int64_t cells = 0;  ///< cell fields, items 1..cells
    std::int64_t grids = 0;  ///< grid fields
    std::int64_t closed = 0; ///< closed fields
    std::int64_t ties = 0;   ///< tie fields
    int size = 5; ///< samples per axis of grid and closed fields, >= 2 (>= 3 with closed)
    std::uint64_t seed = 1;
    int threads = 0; ///< 0: all cores. Each extract() runs single-threaded.
    /// Where failing fields go (created only if there is one); empty: nowhere. See verify().
    std::filesystem::path failures_dir;
    int max_failures = 20; ///< per method: the first ones in (kind, n) order
    ProgressCallback progress;
};

/// Results of one method (or of the external command `cmc33 verify --dataset --cmd` judges).
struct MethodReport {
    std::string name; ///< method_name(method), or "command"
    Method method = Method::cmc33;
    bool external = false;         ///< an external command (`cmc33 verify --cmd`)
    std::int64_t checked = 0;      ///< fields compared (determined ones)
    std::int64_t matched = 0;      ///< invariants equal, manifold and embedded (also once welded)
    std::int64_t mismatched = 0;   ///< checked - matched (includes non-manifold and errors)
    /// meshes whose invariants (euler, b0, b1, b2, boundary loops, by index) differ from the
    /// field's: the topology claims of Custodio et al. 2013, apart from manifoldness and geometry
    std::int64_t topology_mismatched = 0;
    std::int64_t undetermined = 0; ///< fields field_topology could not settle: not compared
    std::int64_t nonmanifold = 0;  ///< meshes with a non-manifold edge or vertex
    std::int64_t unoriented = 0;   ///< meshes not consistently oriented (reported, not a mismatch)
    /// meshes not embedded in space (coincident vertices, zero-area or intersecting triangles:
    /// mesh_geometry); each is a mismatch, as is a mesh whose topology changes once welded
    std::int64_t not_embedded = 0;
    std::int64_t errors = 0;       ///< extract threw, or the command failed (also mismatched)
    std::array<std::int64_t, kFieldKindCount> checked_by_kind{};
    std::array<std::int64_t, kFieldKindCount> mismatched_by_kind{};
    std::array<std::int64_t, kFieldKindCount> topology_mismatched_by_kind{};
    /// Per subcase: fields that contain it, and of those the mismatching ones. A cell counts for
    /// the subcase the method assigns it (analyze_cell); a grid counts for every subcase with a
    /// face or interior test (3.x 4.x 6.x 7.x 10.x 12.x 13.x) that occurs among its cells.
    std::array<std::int64_t, kSubcaseCount> fields_per_subcase{};
    std::array<std::int64_t, kSubcaseCount> mismatches_per_subcase{};
    std::array<std::int64_t, kSubcaseCount> topology_mismatches_per_subcase{}; ///< of those, topology_mismatched
    /// The same for single cells alone, where a mismatch points at one decision: cells per
    /// subcase (as the method classifies them) and those whose topology mismatched.
    std::array<std::int64_t, kSubcaseCount> cells_per_subcase{};
    std::array<std::int64_t, kSubcaseCount> cell_topology_mismatches_per_subcase{};
    std::int64_t failures_written = 0; ///< failing fields saved for this method
    /// "cell-000001: why": the first field (in run order) that gave no mesh, among the
    /// max_failures kept; "" if none. Set whether or not failures are written.
    std::string first_error;
};

struct CMC33_VERIFY_EXPORT VerifyReport {
    std::vector<MethodReport> methods;
    std::array<std::int64_t, kFieldKindCount> fields{}; ///< fields run, per kind
    std::array<double, kFieldKindCount> kind_seconds{}; ///< wall time per kind
    std::uint64_t seed = 0;
    int size = 0;
    int threads = 0;                    ///< threads used
    double seconds = 0;                 ///< wall time of the whole run
    std::filesystem::path failures_dir; ///< empty if nothing was written
    std::int64_t failures_written = 0;  ///< lines of failures.tsv

    /// Fields per second of one kind (0 if none ran).
    double rate(FieldKind kind) const noexcept;
    /// No mismatch (hence no non-manifold mesh) for any method.
    bool passed() const noexcept;
};

/// Runs the stress test. For every field: field_topology once, then for every method extract
/// (threads = 1), mesh_topology and the comparison. Fields run in parallel; totals are the same
/// for every thread count.
///
/// Failing fields (up to max_failures per method, the first in (kind, n) order) are written to
/// failures_dir: `<kind>-<n>.nrrd` (float samples), `<kind>-<n>-<method>.ply` (the mesh) and one
/// line each in `failures.tsv` (expected and obtained invariants, and the commands that reproduce
/// the failure).
/// @throws Error{invalid_argument} for a negative count, size < 2 (< 3 with closed fields), no
///         method, or a repeated method; Error from the writers.
CMC33_VERIFY_EXPORT VerifyReport verify(const VerifyOptions& options);

} // namespace cmc33
