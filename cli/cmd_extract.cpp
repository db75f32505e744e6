// cmc33 extract: volume -> isosurface mesh, with timings, topology and subcase counts.

#include <algorithm>
#include <chrono>
#include <future>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "atomic_file.hpp"
#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/threads.hpp"
#include "cmc33/io.hpp"
#include "cmc33/topology.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "extract_report.hpp"
#include "plural.hpp"

namespace cmc33::cli {

namespace {

double median(std::vector<double> values)
{
    std::sort(values.begin(), values.end());
    const std::size_t n = values.size();
    return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

/// Whether the mesh is extracted with the origin at 0 and written as origin + position in double
/// precision: --positions double, or auto where 32-bit floats cannot keep it embedded in world space.
bool double_positions(const ExtractArgs& args, const Volume& volume)
{
    const bool stl = !args.output.empty() && io::detail::lower_extension(args.output) == ".stl";
    if (args.positions == "double") {
        if (stl) throw UsageError("--positions double does not combine with STL output (32-bit floats only): " + args.output);
        return true;
    }
    const double steps = float_steps_per_cell(volume.dims(), volume.spacing(), volume.origin(), volume.direction());
    if (args.positions == "float" || steps >= kMinFloatStepsPerCell) return false;
    if (stl) {
        throw Error(Status::too_large,
                    args.input + ": the volume lies so far from the origin that 32-bit floats resolve only " + sig(steps, 3) +
                        " steps across a cell (at least " + num(kMinFloatStepsPerCell) +
                        " keep the mesh embedded), and STL stores 32-bit floats; write .ply, .obj or .off "
                        "(double-precision positions), or move the volume's origin nearer 0");
    }
    return true;
}

void run_extract(const ExtractArgs& args)
{
    ExtractOptions options;
    options.method = parse_method(args.method);
    options.normals = args.normals;
    options.threads = args.threads;
    // A bad -o must fail before minutes of work, not after.
    check_mesh_output(args.output, args.ascii, args.normals, {args.input});

    Volume volume = load_volume(args.input, args.raw);
    // Far from the origin the mesh is made at the origin and moved back in double precision when
    // written: floats near 0 keep it embedded, and adding the origin in double is exact.
    std::optional<Vec3> offset;
    if (double_positions(args, volume)) {
        offset = volume.origin();
        volume.set_origin({0, 0, 0});
    }

    Mesh mesh;
    ExtractStats stats;
    std::vector<double> runs;
    for (int r = 0; r < args.repeat; ++r) {
        mesh = Mesh{}; // free the previous run's mesh before the next one allocates
        stats = ExtractStats{};
        const auto start = std::chrono::steady_clock::now();
        options.progress = fraction_line(args.progress, args.quiet, "extracting the mesh");
        mesh = named_step(args.input, "extracting the mesh", [&] {
            try {
                return extract(volume, args.iso, options, &stats);
            } catch (...) {
                end_progress_line(); // the error message starts its own line
                throw;
            }
        });
        const auto stop = std::chrono::steady_clock::now();
        runs.push_back(std::chrono::duration<double>(stop - start).count());
    }
    const double seconds = median(runs);
    if (mesh.triangle_count() == 0) std::cerr << empty_mesh_note(args.input, args.iso, value_range(volume)) << '\n';
    MeshTopology topology;
    MeshGeometry geometry;
    bool structured = false;
    const io::MeshWriteOptions write_options{args.ascii, offset, volume.space()};
    const auto write = [&](const Mesh& m, const io::MeshWriteOptions& o) {
        named_step(args.output, "writing the mesh", [&] { io::write_mesh(m, args.output, o); });
    };
    // Without mesh steps the file does not depend on the check: it is written while the check
    // runs, and replaces OUT only once the check has finished. If the check fails, `checked` is
    // destroyed unset before `written` (declared first) waits for the writer, which then throws
    // and leaves OUT as it was.
    std::future<void> written;
    std::promise<void> checked;
    if (!args.output.empty() && !args.steps.any()) {
        io::MeshWriteOptions o = write_options;
        o.before_commit = [done = checked.get_future().share()] { done.get(); };
        written = std::async(std::launch::async, [&write, &mesh, o] { write(mesh, o); });
    }
    if (!args.no_topology) {
        // with the grid's structure (extract()'s layout of planes), slab by slab in parallel
        ExtractedGrid grid{volume.dims(), volume.spacing(), volume.origin(), volume.direction(),
                           stats.plane_first_vertex, stats.plane_first_triangle};
        MeshCheckOptions check_options;
        check_options.threads = args.threads;
        const Progress progress = fraction_line(args.progress, args.quiet, "checking the mesh");
        check_options.progress = progress;
        const MeshCheck check = named_step(args.input, "checking the mesh", [&] {
            try {
                return check_extracted_mesh(mesh, grid, check_options);
            } catch (...) {
                end_progress_line();
                throw;
            }
        });
        topology = check.topology;
        geometry = check.geometry;
        structured = check.structured;
    }
    if (written.valid()) {
        checked.set_value();
        written.get();
    }
    // the steps of `cmc33 simplify`, from what the check found; the mesh written is their result
    std::optional<MeshStepsResult> steps;
    if (args.steps.any()) {
        steps = run_mesh_steps(mesh, args.steps, StepsContext{args.input, args.progress, args.quiet, args.threads},
                               &topology, &geometry);
        if (!args.output.empty()) write(steps->mesh, write_options);
    }
    if (offset) volume.set_origin(*offset);

    ExtractReport report;
    report.volume = volume_json(args.input, volume);
    report.dims = volume.dims();
    report.type = volume.type();
    report.method = options.method;
    report.vertices = static_cast<std::int64_t>(mesh.vertex_count());
    report.triangles = static_cast<std::int64_t>(mesh.triangle_count());
    report.seconds = seconds;
    report.runs_seconds = runs;
    report.threads = cmc33::thread_count(args.threads);
    report.topology = topology;
    report.geometry = geometry;
    report.stats = stats;
    report.extra["positions"] = offset ? "double" : "float";
    // how the check ran: with the grid's structure, or the general checks (a mesh the grid's layout
    // does not describe: cmc33-paper's refined grid, or one with coincident vertices)
    report.extra["check"] = args.no_topology ? Json(nullptr) : Json(structured ? "structured" : "general");
    if (steps) {
        report.extra["simplify"] = mesh_steps_json(*steps, args.steps);
        report.steps_text = counted(static_cast<std::int64_t>(steps->mesh.triangle_count()), "triangle") +
                            (steps->dropped > 0 ? " (" + counted(steps->dropped, "component") + " dropped)" : std::string()) +
                            " in " + sig(steps->seconds, 3) + " s, " + mesh_steps_text(*steps);
    }
    print_extract_report(args, report);
}

} // namespace

void add_extract(CLI::App& app)
{
    auto args = std::make_shared<ExtractArgs>();
    CLI::App* cmd = app.add_subcommand("extract", "Extract the isosurface f = ISO of a volume as a triangle mesh");
    cmd->add_option("INPUT", args->input, "Volume: .nrrd .nhdr .mhd .mha .vtk, or headerless raw with --dims/--type")
        ->required()
        ->check(non_empty("a volume file"));
    cmd->add_option("-i,--iso", args->iso, "Isovalue (a sample equal to it counts as above)")
        ->required()
        ->check(number_check());
    cmd->add_option("-o,--output", args->output, "Write the mesh: .ply .obj .stl .off .glb .gltf .vtp .gii (by extension)")
        ->type_name("OUT")
        ->check(non_empty("a mesh file name"));
    cmd->add_option("--method", args->method, "cmc33 (default), cmc33-paper, chernyaev, mc33-lewiner or mc")
        ->type_name("NAME")
        ->check(method_validator());
    cmd->add_flag("--normals", args->normals, "Per-vertex normals from the field's gradient (not in .off or .stl)");
    cmd->add_option("--threads", args->threads, "Worker threads, 0 = all cores (default 0, at most 1024)")
        ->type_name("N")
        ->check(thread_count());
    cmd->add_flag("--json", args->json, "Print one JSON object instead of the summary line");
    cmd->add_flag("--ascii", args->ascii, "ASCII PLY instead of binary (only with -o OUT.ply)");
    cmd->add_option("--repeat", args->repeat, "Extract N times and report the median time (default 1)")
        ->type_name("N")
        ->check(whole_number(1, 1000000));
    cmd->add_flag("--no-topology", args->no_topology,
                  "Skip the check of the mesh's topology and embedding (JSON topology and geometry: null)");
    auto* progress = cmd->add_flag("--progress", args->progress,
                                   "Progress lines on stderr even when it is not a terminal");
    cmd->add_flag("--quiet", args->quiet, "No progress line (shown on a terminal when extraction takes over a second)")
        ->excludes(progress);
    cmd->add_option("--positions", args->positions,
                    "auto (default): 32-bit float positions, or double where floats cannot keep the mesh embedded "
                    "far from the origin; float: always (refused where they cannot); double: always (not .stl)")
        ->type_name("PRECISION")
        ->check(CLI::IsMember({"auto", "float", "double"}));
    cmd->add_option("--memory-limit", args->memory_limit,
                    "Read the volume and write the mesh slab by slab within SIZE bytes (256M, 2G): for "
                    "volumes and meshes larger than memory; binary .ply only, same bytes")
        ->type_name("SIZE")
        ->check(memory_size());
    add_mesh_step_options(cmd, args->steps);
    add_raw_volume_options(*cmd, args->raw);
    cmd->footer(
        "Reads INPUT, extracts the triangle mesh of the isosurface at ISO with Marching Cubes 33\n"
        "(method cmc33: topologically correct, manifold and embedded; cmc33-paper, chernyaev,\n"
        "mc33-lewiner and mc reproduce Custodio et al. 2013's comparison: docs/paper.md),\n"
        "and prints one summary line: vertices, triangles, the time of the extraction alone (no\n"
        "reading or writing), and the mesh's topology (Euler characteristic, components, boundary\n"
        "and non-manifold edges). With -o the mesh is written in the format of OUT's extension.\n"
        "--json prints the same and more (per-subcase cell counts, Betti numbers) as one object.\n"
        "--memory-limit streams: the volume is read twice, slab by slab (count, then emit), and the\n"
        "mesh written as it is made; the file is byte for byte the one written without it, and the\n"
        "time reported is then the whole run's (reading and writing included).\n"
        "--ratio, --triangles, --max-error, --smooth, --largest and --min-size then do what\n"
        "`cmc33 simplify` does to the checked mesh (the same refusals and checks; --json: under\n"
        "\"simplify\"), and the result is written; the counts at the top are the extraction's.\n"
        "\n"
        "Examples:\n"
        "  cmc33 extract aneurism.nrrd --iso 80 -o vessels.ply\n"
        "  cmc33 extract scan.raw --dims 256 256 128 --type uint16 --endian big -i 600 --json\n"
        "  cmc33 extract bonsai.nrrd -i 40 --method mc --repeat 5 --threads 1\n"
        "  cmc33 extract scan_4096.nrrd -i 900 -o bone.ply --memory-limit 4G\n"
        "  cmc33 extract skull.nrrd -i 500 -o print.stl --ratio 0.1 --smooth 20 --largest");
    cmd->callback([args] {
        check_mesh_steps(args->steps);
        if (args->steps.any() && args->no_topology) {
            throw UsageError("--no-topology skips the check the simplification starts from (its topology must be kept): "
                             "not with --ratio, --triangles, --max-error, --smooth, --largest or --min-size");
        }
        if (args->steps.any() && !args->memory_limit.empty()) {
            throw UsageError("--memory-limit writes the mesh slab by slab as it is made; --ratio, --triangles, --max-error, "
                             "--smooth, --largest and --min-size need it whole: run cmc33 simplify on the file it writes");
        }
        if (args->memory_limit.empty()) {
            run_extract(*args);
            return;
        }
        // a usage conflict (exit 2) before any reading, not the passes' "use extract()" (exit 1)
        if (parse_method(args->method) == Method::cmc33_paper) {
            throw UsageError("--method cmc33-paper does not combine with --memory-limit: its refinement (Custodio et "
                             "al. 2013, Sec. 6.2) inserts sample planes into the whole grid, which slabs cannot; run "
                             "without --memory-limit, or with another method");
        }
        run_extract_slabs(*args);
    });
}

} // namespace cmc33::cli
