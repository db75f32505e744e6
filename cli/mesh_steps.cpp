// The steps after a mesh is made (mesh_steps.hpp).

#include "mesh_steps.hpp"

#include <algorithm>
#include <chrono>
#include <limits>

#include <CLI/CLI.hpp>

#include "cmc33/error.hpp"

namespace cmc33::cli {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// A step with a progress line that is ended before an error message.
template <class F> auto with_progress(const StepsContext& c, const std::string& what, F&& step)
{
    const Progress progress = fraction_line(c.progress, c.quiet, what);
    return named_step(c.file, what, [&] {
        try {
            return step(progress);
        } catch (...) {
            end_progress_line();
            throw;
        }
    });
}

Json hausdorff_json(const HausdorffResult& h)
{
    return Json{{"distance", h.distance()},       {"input_to_output", h.a_to_b}, {"output_to_input", h.b_to_a},
                {"mean_input_to_output", h.mean_a_to_b}, {"mean_output_to_input", h.mean_b_to_a},
                {"samples_input", h.samples_a},   {"samples_output", h.samples_b},
                {"method", "every vertex, each triangle's centroid and a barycentric grid on triangles longer than the "
                           "input's mean edge; exact point-to-triangle distance to the nearest triangle (uniform grid)"}};
}

} // namespace

void add_mesh_step_options(CLI::App* cmd, MeshSteps& s)
{
    auto* ratio = cmd->add_option("--ratio", s.ratio, "Keep this fraction of the triangles (of those --largest and --min-size keep; 0 < R <= 1)")
                      ->type_name("R")
                      ->check(CLI::Range(1e-9, 1.0));
    cmd->add_option("--triangles", s.triangles, "Stop at N triangles or fewer")
        ->type_name("N")
        ->check(whole_number(1, std::numeric_limits<std::int64_t>::max()))
        ->excludes(ratio);
    cmd->add_option("--max-error", s.max_error,
                    "Stop before a collapse whose quadric error exceeds E (world units: the root of the sum of "
                    "squared distances of the new vertex to the input planes merged into it)")
        ->type_name("E")
        ->check(CLI::Range(0.0, std::numeric_limits<double>::max()));
    cmd->add_option("--max-distance", s.max_distance,
                    "Keep every input vertex within D of the simplified surface (guaranteed, world units; "
                    "--smooth does not keep it), and refuse a collapse that puts the new vertex, a new "
                    "triangle's centroid or an edge midpoint at the new vertex farther than D from the input "
                    "triangles nearby (sampled: points between them may be farther)")
        ->type_name("D")
        ->check(CLI::Range(0.0, std::numeric_limits<double>::max()));
    cmd->add_option("--smooth", s.smooth, "Taubin lambda|mu smoothing, N iterations, after simplifying")
        ->type_name("N")
        ->check(whole_number(0, 100000));
    cmd->add_flag("--largest", s.largest, "Keep only the largest component (by triangles)");
    cmd->add_option("--min-size", s.min_size, "Drop components with fewer than N triangles")
        ->type_name("N")
        ->check(whole_number(0, std::numeric_limits<std::int64_t>::max()));
}

void check_mesh_steps(const MeshSteps& s)
{
    if (s.ratio && s.triangles) throw UsageError("--ratio and --triangles do not combine: give one target");
    if (s.max_distance && !s.simplifies()) {
        throw UsageError("--max-distance bounds a simplification: give --ratio R, --triangles N or --max-error E with it");
    }
}

MeshStepsResult run_mesh_steps(const Mesh& input, const MeshSteps& steps, const StepsContext& c,
                               const MeshTopology* known_topology, const MeshGeometry* known_geometry)
{
    MeshStepsResult r;
    const auto start = std::chrono::steady_clock::now();
    // the mesh the steps start from: the input itself, or what the component filter kept (no copy)
    Mesh filtered;
    if (steps.filters()) {
        filtered = named_step(c.file, "finding components", [&] {
            return filter_components(input, ComponentFilter{steps.largest, steps.min_size}, &r.dropped);
        });
    }
    const Mesh& start_mesh = steps.filters() ? filtered : input;
    // what a check of the input said holds for the mesh the steps start from if no component went
    const bool known = r.dropped == 0 && known_topology && known_geometry;
    MeshGeometryOptions geometry_options;
    geometry_options.threads = c.threads;
    r.before = known ? *known_topology : named_step(c.file, "computing the mesh's topology", [&] { return mesh_topology(start_mesh); });
    r.geometry_before = known ? *known_geometry : named_step(c.file, "checking the mesh in space", [&] {
        return mesh_geometry(start_mesh, geometry_options);
    });
    if (steps.simplifies()) {
        SimplifyOptions o;
        if (steps.ratio) o.ratio = *steps.ratio;
        if (steps.triangles) o.target_triangles = std::max<std::int64_t>(1, *steps.triangles);
        if (steps.max_error) o.max_error = *steps.max_error;
        if (steps.max_distance) o.max_distance = *steps.max_distance;
        const auto t0 = std::chrono::steady_clock::now();
        r.mesh = with_progress(c, "simplifying", [&](const Progress& p) {
            o.progress = p;
            return simplify(start_mesh, o, &r.simplify);
        });
        r.simplify_seconds = seconds_since(t0);
    }
    if (steps.smooth > 0) {
        SmoothOptions o;
        o.iterations = steps.smooth;
        const auto t0 = std::chrono::steady_clock::now();
        r.mesh = with_progress(c, "smoothing", [&](const Progress& p) {
            o.progress = p;
            return smooth(steps.simplifies() ? r.mesh : start_mesh, o, &r.smooth);
        });
        r.smooth_seconds = seconds_since(t0);
    }
    if (!steps.simplifies() && steps.smooth == 0) r.mesh = start_mesh; // components dropped only
    r.seconds = seconds_since(start);
    r.after = named_step(c.file, "computing the result's topology", [&] { return mesh_topology(r.mesh); });
    r.geometry_after = named_step(c.file, "checking the result in space", [&] { return mesh_geometry(r.mesh, geometry_options); });
    r.hausdorff = named_step(c.file, "measuring the Hausdorff distance",
                             [&] { return hausdorff_distance(start_mesh, r.mesh, 0, c.threads); });
    MeshOpsReport report;
    report.topology_before = r.before;
    report.topology_after = r.after;
    const bool same = report.topology_same();
    // the guarantees are checked before anything is written: a result that breaks them is a bug
    if (!same || (r.geometry_before.embedded() && !r.geometry_after.embedded())) {
        throw Error(Status::internal, c.file + ": the result " +
                                          (same ? "is not embedded (" + std::to_string(r.geometry_after.intersecting_pairs) +
                                                      " intersecting pairs)"
                                                : "changed the topology") +
                                          "; nothing written (please report this mesh)");
    }
    return r;
}

Json mesh_steps_json(const MeshStepsResult& r, const MeshSteps& steps)
{
    MeshOpsReport report;
    report.topology_before = r.before;
    report.topology_after = r.after;
    return Json{{"components_dropped", r.dropped},
                {"triangles_out", static_cast<std::int64_t>(r.mesh.triangle_count())},
                {"vertices_out", static_cast<std::int64_t>(r.mesh.vertex_count())},
                {"seconds", r.seconds},
                {"simplify_seconds", r.simplify_seconds},
                {"smooth_seconds", r.smooth_seconds},
                {"collapses", r.simplify.collapses},
                {"refused", {{"topology", r.simplify.refused_topology}, {"flip", r.simplify.refused_flip},
                             {"intersection", r.simplify.refused_intersection}, {"distance", r.simplify.refused_distance}}},
                {"max_quadric_error", r.simplify.max_quadric_error},
                {"smooth", {{"iterations", steps.smooth}, {"moves", r.smooth.moves}, {"shortened", r.smooth.shortened},
                            {"undone", r.smooth.undone}}},
                {"topology_same", report.topology_same()},
                {"topology_before", topology_json(r.before)},
                {"topology_after", topology_json(r.after)},
                {"geometry_before", geometry_json(r.geometry_before)},
                {"geometry_after", geometry_json(r.geometry_after)},
                {"hausdorff", hausdorff_json(r.hausdorff)}};
}

std::string mesh_steps_text(const MeshStepsResult& r)
{
    const MeshTopology& t = r.after;
    return "topology kept (euler " + std::to_string(t.euler) + ", betti " + std::to_string(t.components) + " " +
           std::to_string(t.b1) + " " + std::to_string(t.closed_components) + ", boundary loops " +
           std::to_string(t.boundary_loops) + ", non-manifold edges " + std::to_string(t.nonmanifold_edges) + "), " +
           (r.geometry_after.embedded() ? "embedded" : "NOT embedded") + "; Hausdorff " + sig(r.hausdorff.distance(), 4) +
           " (mean " + sig(r.hausdorff.mean_a_to_b, 3) + ")";
}

} // namespace cmc33::cli
