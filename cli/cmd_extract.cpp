// cmc33 extract: volume -> isosurface mesh, with timings, topology and subcase counts.

#include <algorithm>
#include <chrono>
#include <iostream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/io.hpp"
#include "cmc33/topology.hpp"
#include "commands.hpp"
#include "common.hpp"

namespace cmc33::cli {

namespace {

struct ExtractArgs {
    std::string input;
    double iso = 0;
    std::string output;
    std::string method = "cmc33";
    bool normals = false;
    int threads = 0;
    bool json = false;
    bool ascii = false;
    int repeat = 1;
    bool no_topology = false;
    bool progress = false;
    bool quiet = false;
    RawVolumeOptions raw;
};

double median(std::vector<double> values)
{
    std::sort(values.begin(), values.end());
    const std::size_t n = values.size();
    return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

void run_extract(const ExtractArgs& args)
{
    ExtractOptions options;
    options.method = parse_method(args.method);
    options.normals = args.normals;
    options.threads = args.threads;
    // A bad -o must fail before minutes of work, not after.
    check_mesh_output(args.output, args.ascii, args.normals, {args.input});

    const Volume volume = load_volume(args.input, args.raw);

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
    MeshTopology topology;
    MeshGeometry geometry;
    if (!args.no_topology) {
        topology = named_step(args.input, "computing the mesh's topology (about 24 bytes per triangle; "
                                          "--no-topology skips it)",
                              [&] { return mesh_topology(mesh); });
    }
    if (!args.no_topology) {
        geometry = named_step(args.input, "checking the mesh's geometry",
                              [&] { return mesh_geometry(mesh, MeshGeometryOptions{args.threads, 8}); });
    }
    if (!args.output.empty()) {
        named_step(args.output, "writing the mesh",
                   [&] { io::write_mesh(mesh, args.output, io::MeshWriteOptions{args.ascii}); });
    }

    const int threads = args.threads > 0 ? args.threads
                                         : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    if (args.json) {
        // Subcase "0" (no crossing) is left out: extract counts the cells the surface crosses.
        Json subcases = Json::object();
        for (int s = 1; s < kSubcaseCount; ++s) {
            subcases[std::string(subcase_name(s))] = stats.cells_per_subcase[static_cast<std::size_t>(s)];
        }
        Json out{{"input", volume_json(args.input, volume)},
                 {"iso", args.iso},
                 {"method", std::string(method_name(options.method))},
                 {"normals", args.normals},
                 {"vertices", mesh.vertex_count()},
                 {"triangles", mesh.triangle_count()},
                 {"seconds", seconds},
                 {"runs_seconds", runs},
                 {"threads", threads},
                 {"output", args.output.empty() ? Json(nullptr) : Json(args.output)},
                 {"topology", !args.no_topology ? topology_json(topology) : Json(nullptr)},
                 {"geometry", !args.no_topology ? geometry_json(geometry) : Json(nullptr)},
                 {"subcases", subcases},
                 // cmc33-paper: planes the Sec. 6.2 refinement added (0: none needed); null for the others
                 {"refinement_planes", options.method == Method::cmc33_paper ? Json(stats.refinement_planes) : Json(nullptr)}};
        print_json(out);
        return;
    }
    std::string line = args.input + ": " + dims_text(volume.dims()) + " " + std::string(type_name(volume.type())) +
                       ", iso " + num(args.iso) + ", " + std::string(method_name(options.method)) + ": " +
                       std::to_string(mesh.vertex_count()) + " vertices, " +
                       std::to_string(mesh.triangle_count()) + " triangles in " + sig(seconds, 3) + " s";
    if (args.repeat > 1) line += " (median of " + std::to_string(args.repeat) + ")";
    if (!args.no_topology) {
        line += "; euler " + std::to_string(topology.euler) + ", components " +
                std::to_string(topology.components) + ", boundary edges " +
                std::to_string(topology.boundary_edges) + ", non-manifold edges " +
                std::to_string(topology.nonmanifold_edges);
    }
    if (!args.no_topology && topology.nonmanifold_vertices != 0) {
        line += ", non-manifold vertices " + std::to_string(topology.nonmanifold_vertices);
    }
    if (!args.no_topology) {
        line += geometry.embedded() ? ", embedded"
                                    : ", NOT embedded (" + std::to_string(geometry.coincident_vertices) +
                                          " coincident vertices, " + std::to_string(geometry.zero_area_triangles) +
                                          " zero-area triangles, " + std::to_string(geometry.intersecting_pairs) +
                                          " intersecting triangle pairs)";
    }
    if (!args.output.empty()) line += " (" + args.output + ")";
    std::cout << line << '\n';
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
    cmd->add_option("-o,--output", args->output, "Write the mesh: .ply .obj .stl .off (by extension)")
        ->type_name("OUT")
        ->check(non_empty("a mesh file name"));
    cmd->add_option("--method", args->method, "cmc33 (default), cmc33-paper, chernyaev, mc33-lewiner or mc")
        ->type_name("NAME")
        ->check(method_validator());
    cmd->add_flag("--normals", args->normals, "Per-vertex normals from the field's gradient (.ply and .obj only)");
    cmd->add_option("--threads", args->threads, "Worker threads, 0 = all cores (default 0, at most 1024)")
        ->type_name("N")
        ->check(thread_count());
    cmd->add_flag("--json", args->json, "Print one JSON object instead of the summary line");
    cmd->add_flag("--ascii", args->ascii, "ASCII PLY instead of binary (only with -o OUT.ply)");
    cmd->add_option("--repeat", args->repeat, "Extract N times and report the median time (default 1)")
        ->type_name("N")
        ->check(whole_number(1, 1000000));
    cmd->add_flag("--no-topology", args->no_topology,
                  "Skip the mesh topology (saves time and about 24 bytes per triangle; JSON topology: null)");
    auto* progress = cmd->add_flag("--progress", args->progress,
                                   "Progress lines on stderr even when it is not a terminal");
    cmd->add_flag("--quiet", args->quiet, "No progress line (shown on a terminal when extraction takes over a second)")
        ->excludes(progress);
    add_raw_volume_options(*cmd, args->raw);
    cmd->footer(
        "Reads INPUT, extracts the triangle mesh of the isosurface at ISO with Marching Cubes 33\n"
        "(method cmc33: topologically correct, manifold and embedded; cmc33-paper, chernyaev,\n"
        "mc33-lewiner and mc reproduce Custodio et al. 2013's comparison: docs/paper.md),\n"
        "and prints one summary line: vertices, triangles, the time of the extraction alone (no\n"
        "reading or writing), and the mesh's topology (Euler characteristic, components, boundary\n"
        "and non-manifold edges). With -o the mesh is written in the format of OUT's extension.\n"
        "--json prints the same and more (per-subcase cell counts, Betti numbers) as one object.\n"
        "\n"
        "Examples:\n"
        "  cmc33 extract aneurism.nrrd --iso 80 -o vessels.ply\n"
        "  cmc33 extract scan.raw --dims 256 256 128 --type uint16 --endian big -i 600 --json\n"
        "  cmc33 extract bonsai.nrrd -i 40 --method mc --repeat 5 --threads 1");
    cmd->callback([args] { run_extract(*args); });
}

} // namespace cmc33::cli
