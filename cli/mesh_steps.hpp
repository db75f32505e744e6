#pragma once
// The steps after a mesh is made, shared by `cmc33 simplify` (on a mesh file) and `cmc33 extract`
// (on the mesh it extracts): small components dropped, simplification, smoothing, and the checks
// that show the guarantees kept (topology before and after, embedding, Hausdorff distance).

#include <cstdint>
#include <optional>
#include <string>

#include "cmc33/mesh.hpp"
#include "cmc33/mesh_ops.hpp"
#include "cmc33/topology.hpp"
#include "common.hpp"

namespace cmc33::cli {

/// What the options ask for (--ratio --triangles --max-error --max-distance --smooth --largest --min-size).
struct MeshSteps {
    std::optional<double> ratio;
    std::optional<std::int64_t> triangles;
    std::optional<double> max_error;
    std::optional<double> max_distance;
    int smooth = 0;
    bool largest = false;
    std::int64_t min_size = 0;

    bool simplifies() const { return ratio || triangles || max_error; }
    bool filters() const { return largest || min_size > 0; }
    bool any() const { return simplifies() || filters() || smooth > 0; }
};

/// Registers the options of MeshSteps on `cmd`.
void add_mesh_step_options(CLI::App* cmd, MeshSteps& steps);

/// Usage errors of a combination (--ratio with --triangles, --max-distance alone).
void check_mesh_steps(const MeshSteps& steps);

/// Where the steps report: the file named in errors, progress lines, threads of the checks.
struct StepsContext {
    std::string file;
    bool progress = false;
    bool quiet = false;
    int threads = 0;
};

struct MeshStepsResult {
    Mesh mesh;                  ///< the result
    std::int64_t dropped = 0;   ///< components dropped
    SimplifyStats simplify;
    SmoothStats smooth;
    double seconds = 0, simplify_seconds = 0, smooth_seconds = 0;
    MeshTopology before, after; ///< of the mesh the steps start from (components dropped) and of the result
    MeshGeometry geometry_before, geometry_after;
    HausdorffResult hausdorff;  ///< between the mesh they start from and the result
};

/// Runs the steps on `input`. `known_topology` and `known_geometry`, when given, are `input`'s
/// (a check already made); else they are computed. @throws Error{internal} when the result
/// changed the topology or is not embedded where the input was: nothing should be written.
MeshStepsResult run_mesh_steps(const Mesh& input, const MeshSteps& steps, const StepsContext& context,
                               const MeshTopology* known_topology = nullptr, const MeshGeometry* known_geometry = nullptr);

/// The JSON keys of a result (collapses, refusals, smoothing, topology and geometry before and
/// after, Hausdorff distance): `cmc33 simplify --json`'s, and `extract --json`'s "simplify".
Json mesh_steps_json(const MeshStepsResult& r, const MeshSteps& steps);

/// "topology kept (euler .., betti .., boundary loops .., non-manifold edges ..), embedded; Hausdorff .. (mean ..)"
std::string mesh_steps_text(const MeshStepsResult& r);

} // namespace cmc33::cli
