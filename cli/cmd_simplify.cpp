// cmc33 simplify: fewer triangles, smoother, small pieces dropped, with the topology and the
// embedding kept and shown (before and after), and the Hausdorff distance to the input.

#include <algorithm>
#include <chrono>
#include <limits>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "cmc33/mesh_ops.hpp"
#include "cmc33/topology.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "plural.hpp"

namespace cmc33::cli {

namespace {

struct SimplifyArgs {
    std::string input, output;
    std::optional<double> ratio;
    std::optional<std::int64_t> triangles;
    std::optional<double> max_error;
    std::optional<double> max_distance;
    int smooth = 0;
    bool largest = false;
    std::int64_t min_size = 0;
    bool json = false;
    int threads = 0;
    bool progress = false;
    bool quiet = false;
    bool ascii = false;
};

double seconds_since(std::chrono::steady_clock::time_point start)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// A step with a progress line that is ended before an error message.
template <class F> auto with_progress(const SimplifyArgs& args, const std::string& what, F&& step)
{
    const Progress progress = fraction_line(args.progress, args.quiet, what);
    return named_step(args.input, what, [&] {
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

void run_simplify(const SimplifyArgs& args)
{
    if (args.ratio && args.triangles) throw UsageError("--ratio and --triangles do not combine: give one target");
    if (!args.ratio && !args.triangles && !args.max_error && args.smooth == 0 && !args.largest && args.min_size == 0) {
        throw UsageError("nothing to do: give --ratio R, --triangles N or --max-error E (and/or --smooth N, --largest, "
                         "--min-size N)");
    }
    // a bad -o fails before any work (normals, if the input has them, are written where the format can hold them)
    check_mesh_output(args.output, args.ascii, false, {args.input});
    const Mesh input = named_step(args.input, "reading the mesh", [&] { return io::read_mesh(args.input); });
    const auto start = std::chrono::steady_clock::now();

    Mesh mesh = input;
    std::int64_t dropped = 0;
    if (args.largest || args.min_size > 0) {
        mesh = named_step(args.input, "finding components",
                          [&] { return filter_components(input, ComponentFilter{args.largest, args.min_size}, &dropped); });
    }
    const MeshTopology before = named_step(args.input, "computing the mesh's topology", [&] { return mesh_topology(mesh); });
    MeshGeometryOptions geometry_options;
    geometry_options.threads = args.threads;
    const MeshGeometry geometry_before =
        named_step(args.input, "checking the mesh in space", [&] { return mesh_geometry(mesh, geometry_options); });

    SimplifyStats sstats;
    double simplify_seconds = 0;
    Mesh out = mesh;
    if (args.ratio || args.triangles || args.max_error) {
        SimplifyOptions o;
        if (args.ratio) o.ratio = *args.ratio;
        if (args.triangles) o.target_triangles = std::max<std::int64_t>(1, *args.triangles);
        if (args.max_error) o.max_error = *args.max_error;
        if (args.max_distance) o.max_distance = *args.max_distance;
        const auto t0 = std::chrono::steady_clock::now();
        out = with_progress(args, "simplifying", [&](const Progress& p) {
            o.progress = p;
            return simplify(mesh, o, &sstats);
        });
        simplify_seconds = seconds_since(t0);
    }
    SmoothStats mstats;
    double smooth_seconds = 0;
    if (args.smooth > 0) {
        SmoothOptions o;
        o.iterations = args.smooth;
        const auto t0 = std::chrono::steady_clock::now();
        out = with_progress(args, "smoothing", [&](const Progress& p) {
            o.progress = p;
            return smooth(out, o, &mstats);
        });
        smooth_seconds = seconds_since(t0);
    }
    const double seconds = seconds_since(start);
    const MeshTopology after = named_step(args.input, "computing the result's topology", [&] { return mesh_topology(out); });
    const MeshGeometry geometry_after =
        named_step(args.input, "checking the result in space", [&] { return mesh_geometry(out, geometry_options); });
    const HausdorffResult h = named_step(args.input, "measuring the Hausdorff distance",
                                         [&] { return hausdorff_distance(mesh, out, 0, args.threads); });
    MeshOpsReport report;
    report.topology_before = before;
    report.topology_after = after;
    const bool same = report.topology_same();
    // the guarantees are checked before anything is written: a result that breaks them is a bug
    if (!same || (geometry_before.embedded() && !geometry_after.embedded())) {
        throw Error(Status::internal, args.input + ": the result " +
                                                (same ? "is not embedded (" + std::to_string(geometry_after.intersecting_pairs) +
                                                            " intersecting pairs)"
                                                      : "changed the topology") +
                                                "; nothing written (please report this mesh)");
    }
    if (!args.output.empty()) {
        named_step(args.output, "writing the mesh", [&] { io::write_mesh(out, args.output, io::MeshWriteOptions{args.ascii}); });
    }
    if (args.json) {
        Json j{{"file", args.input},
               {"output", args.output.empty() ? Json(nullptr) : Json(args.output)},
               {"triangles_in", static_cast<std::int64_t>(input.triangle_count())},
               {"components_dropped", dropped},
               {"triangles_out", static_cast<std::int64_t>(out.triangle_count())},
               {"vertices_out", static_cast<std::int64_t>(out.vertex_count())},
               {"seconds", seconds},
               {"simplify_seconds", simplify_seconds},
               {"smooth_seconds", smooth_seconds},
               {"collapses", sstats.collapses},
               {"refused", {{"topology", sstats.refused_topology}, {"flip", sstats.refused_flip},
                            {"intersection", sstats.refused_intersection},
                            {"distance", sstats.refused_distance}}},
               {"max_quadric_error", sstats.max_quadric_error},
               {"smooth", {{"iterations", args.smooth}, {"moves", mstats.moves}, {"shortened", mstats.shortened},
                           {"undone", mstats.undone}}},
               {"topology_same", same}};
        Json tb = topology_json(before), ta = topology_json(after);
        j["topology_before"] = tb;
        j["topology_after"] = ta;
        j["geometry_before"] = geometry_json(geometry_before);
        j["geometry_after"] = geometry_json(geometry_after);
        j["hausdorff"] = hausdorff_json(h);
        print_json(j);
        return;
    }
    std::cout << args.input << ": " << counted(static_cast<std::int64_t>(input.triangle_count()), "triangle") << " -> "
              << counted(static_cast<std::int64_t>(out.triangle_count()), "triangle");
    if (dropped > 0) std::cout << " (" << counted(dropped, "component") << " dropped)";
    std::cout << " in " << sig(seconds, 3) << " s; topology " << (same ? "kept" : "CHANGED") << " (euler " << after.euler
              << ", betti " << after.components << " " << after.b1 << " " << after.closed_components << ", boundary loops "
              << after.boundary_loops << ", non-manifold edges " << after.nonmanifold_edges << "), "
              << (geometry_after.embedded() ? "embedded" : "NOT embedded") << "; Hausdorff " << sig(h.distance(), 4)
              << " (mean " << sig(h.mean_a_to_b, 3) << ")\n";
}

} // namespace

void add_simplify(CLI::App& app)
{
    auto args = std::make_shared<SimplifyArgs>();
    CLI::App* cmd = app.add_subcommand("simplify", "Simplify and smooth a mesh, keeping its topology and embedding");
    cmd->add_option("MESH", args->input, "Mesh: .ply .obj .stl .off")->required()->check(non_empty("a mesh file"));
    cmd->add_option("-o,--output", args->output, "Write the result: .ply .obj .stl .off (by extension)")
        ->type_name("OUT")
        ->check(non_empty("a mesh file name"));
    auto* ratio = cmd->add_option("--ratio", args->ratio, "Keep this fraction of the triangles (of those --largest and --min-size keep; 0 < R <= 1)")
                      ->type_name("R")
                      ->check(CLI::Range(1e-9, 1.0));
    cmd->add_option("--triangles", args->triangles, "Stop at N triangles or fewer")
        ->type_name("N")
        ->check(whole_number(1, std::numeric_limits<std::int64_t>::max()))
        ->excludes(ratio);
    cmd->add_option("--max-error", args->max_error,
                    "Stop before a collapse whose quadric error exceeds E (world units: the root of the sum of "
                    "squared distances of the new vertex to the input planes merged into it)")
        ->type_name("E")
        ->check(CLI::Range(0.0, std::numeric_limits<double>::max()));
    cmd->add_option("--max-distance", args->max_distance,
                    "Keep every input vertex within D of the simplified surface (guaranteed, world units; "
                    "--smooth does not keep it), and refuse a collapse that puts the new vertex, a new "
                    "triangle's centroid or an edge midpoint at the new vertex farther than D from the input "
                    "triangles nearby (sampled: points between them may be farther)")
        ->type_name("D")
        ->check(CLI::Range(0.0, std::numeric_limits<double>::max()));
    cmd->add_option("--smooth", args->smooth, "Taubin lambda|mu smoothing, N iterations, after simplifying")
        ->type_name("N")
        ->check(whole_number(0, 100000));
    cmd->add_flag("--largest", args->largest, "Keep only the largest component (by triangles)");
    cmd->add_option("--min-size", args->min_size, "Drop components with fewer than N triangles")
        ->type_name("N")
        ->check(whole_number(0, std::numeric_limits<std::int64_t>::max()));
    cmd->add_flag("--json", args->json, "Print one JSON object instead of the summary line");
    cmd->add_flag("--ascii", args->ascii, "ASCII PLY instead of binary (only with -o OUT.ply)");
    cmd->add_option("--threads", args->threads, "Worker threads of the checks, 0 = all cores (simplification: one)")
        ->type_name("N")
        ->check(thread_count());
    auto* progress = cmd->add_flag("--progress", args->progress, "Progress lines on stderr even when it is not a terminal");
    cmd->add_flag("--quiet", args->quiet, "No progress line")->excludes(progress);
    cmd->footer(
        "Reads MESH; drops components (--largest, --min-size; components by shared edges); simplifies\n"
        "it by edge collapses in order of quadric error (Garland and Heckbert 1997) to --ratio R of\n"
        "its triangles, to --triangles N, or until --max-error E; smooths it --smooth N times (Taubin\n"
        "1995). A collapse is refused when it would change the topology (link condition), make the\n"
        "mesh non-manifold, turn a triangle over or make two triangles meet improperly (exact\n"
        "predicates), so a target may not be reached; a smoothing move that would is halved, then\n"
        "undone. Prints the triangles before and after, the topology kept (checked: Euler\n"
        "characteristic, Betti numbers, boundary loops), the embedding (checked as `cmc33 topo`\n"
        "does) and the two-sided Hausdorff distance to the input, sampled (--json: the method).\n"
        "Nothing is written if a check fails.\n"
        "\n"
        "Examples:\n"
        "  cmc33 simplify vessels.ply -o small.ply --ratio 0.1\n"
        "  cmc33 simplify skull.ply -o print.stl --triangles 200000 --smooth 20 --largest --json");
    cmd->callback([args] { run_simplify(*args); });
}

} // namespace cmc33::cli
