// cmc33 simplify: fewer triangles, smoother, small pieces dropped, with the topology and the
// embedding kept and shown (before and after), and the Hausdorff distance to the input.

#include <iostream>
#include <memory>
#include <string>

#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "cmc33/mesh_ops.hpp"
#include "cmc33/topology.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "mesh_steps.hpp"
#include "plural.hpp"

namespace cmc33::cli {

namespace {

struct SimplifyArgs {
    std::string input, output;
    MeshSteps steps;
    bool json = false;
    int threads = 0;
    bool progress = false;
    bool quiet = false;
    bool ascii = false;
};

void run_simplify(const SimplifyArgs& args)
{
    check_mesh_steps(args.steps);
    if (!args.steps.any()) {
        throw UsageError("nothing to do: give --ratio R, --triangles N or --max-error E (and/or --smooth N, --largest, "
                         "--min-size N)");
    }
    // a bad -o fails before any work (normals, if the input has them, are written where the format can hold them)
    check_mesh_output(args.output, args.ascii, false, {args.input});
    const Mesh input = named_step(args.input, "reading the mesh", [&] { return io::read_mesh(args.input); });
    const MeshStepsResult r = run_mesh_steps(input, args.steps, StepsContext{args.input, args.progress, args.quiet, args.threads});
    if (!args.output.empty()) {
        named_step(args.output, "writing the mesh", [&] { io::write_mesh(r.mesh, args.output, io::MeshWriteOptions{args.ascii}); });
    }
    if (args.json) {
        Json j{{"file", args.input},
               {"output", args.output.empty() ? Json(nullptr) : Json(args.output)},
               {"triangles_in", static_cast<std::int64_t>(input.triangle_count())}};
        j.update(mesh_steps_json(r, args.steps));
        print_json(j);
        return;
    }
    std::cout << args.input << ": " << counted(static_cast<std::int64_t>(input.triangle_count()), "triangle") << " -> "
              << counted(static_cast<std::int64_t>(r.mesh.triangle_count()), "triangle");
    if (r.dropped > 0) std::cout << " (" << counted(r.dropped, "component") << " dropped)";
    std::cout << " in " << sig(r.seconds, 3) << " s; " << mesh_steps_text(r) << "\n";
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
    add_mesh_step_options(cmd, args->steps);
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
