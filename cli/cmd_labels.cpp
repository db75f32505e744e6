// cmc33 labels: the surfaces of every label of a segmentation, as a partition whose interfaces are
// shared (src/labels, docs/labels.md): a folder of one closed surface per label, or one PLY of
// interface triangles with the labels on their two sides.

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "cmc33/labels.hpp"
#include "cmc33/threads.hpp"
#include "cmc33/topology.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "parallel.hpp"
#include "plural.hpp"

namespace cmc33::cli {

namespace {

namespace fs = std::filesystem;

struct LabelsArgs {
    std::string input, output;
    std::string labels = "all";
    std::int64_t background = 0;
    std::string format = "ply";
    std::string label_names;
    bool json = false;
    bool normals = false;
    double smooth = 0;
    int threads = 0;
    RawVolumeOptions raw;
};

/// sRGB to linear, as glTF's baseColorFactor is linear.
float linear_from_srgb(double srgb)
{
    // IEC 61966-2-1
    return static_cast<float>(srgb <= 0.04045 ? srgb / 12.92 : std::pow((srgb + 0.055) / 1.055, 2.4));
}

/// The colour of the n-th label of a scene: hues a golden angle apart (so that neighbours in the
/// list differ), saturation 0.6, value 0.9, as linear RGBA.
std::array<float, 4> label_colour(std::size_t n)
{
    const double h = std::fmod(static_cast<double>(n) * 0.381966011250105, 1.0) * 6;
    const double v = 0.9, s = 0.6, c = v * s, x = c * (1 - std::fabs(std::fmod(h, 2.0) - 1)), m = v - c;
    const int sector = static_cast<int>(h) % 6;
    const double rgb[6][3] = {{c, x, 0}, {x, c, 0}, {0, c, x}, {0, x, c}, {x, 0, c}, {c, 0, x}};
    std::array<float, 4> out{0, 0, 0, 1};
    for (std::size_t k = 0; k < 3; ++k) out[k] = linear_from_srgb(rgb[sector][k] + m);
    return out;
}

/// The part of a name that goes into a file name: letters, digits, '-', '_' and '.', every other
/// run of characters one '_', at most 64 characters.
std::string file_name_part(const std::string& name)
{
    std::string out;
    for (const char c : name) {
        const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' ||
                          c == '_' || c == '.';
        if (keep) {
            out += c;
        } else if (!out.empty() && out.back() != '_') {
            out += '_';
        }
        if (out.size() == 64) break;
    }
    while (!out.empty() && (out.back() == '_' || out.back() == '.')) out.pop_back();
    while (!out.empty() && out.front() == '.') out.erase(out.begin());
    return out;
}

/// An sRGB colour as JSON, each channel to 6 decimals (a float's digits, not its binary tail).
Json rgb_json(const std::array<float, 3>& rgb)
{
    Json out = Json::array();
    for (const float c : rgb) out.push_back(std::round(static_cast<double>(c) * 1e6) / 1e6);
    return out;
}

/// The labels' names and colours: the volume's own (a 3D Slicer .seg.nrrd), then --label-names's,
/// which win where both name a value.
std::map<std::int64_t, io::LabelName> label_names(const LabelsArgs& args)
{
    std::map<std::int64_t, io::LabelName> names;
    if (!args.raw.any_given()) {
        for (io::LabelName& n : io::read_segment_names(args.input)) names[n.value] = std::move(n);
    }
    if (!args.label_names.empty()) {
        for (io::LabelName& n : io::read_colour_table(args.label_names)) names[n.value] = std::move(n);
    }
    return names;
}

void run_labels(const LabelsArgs& args)
{
    LabelOptions options;
    options.background = args.background;
    options.threads = args.threads;
    options.normals = args.normals;
    options.smooth = args.smooth;
    try {
        options.labels = parse_label_ranges(args.labels);
    } catch (const Error& e) {
        throw UsageError(std::string("--") + e.what());
    }
    const bool scene =
        (args.output.ends_with(".glb") || args.output.ends_with(".gltf")) && !fs::is_directory(args.output);
    const bool single = (scene || args.output.ends_with(".ply")) && !fs::is_directory(args.output);
    if (single) {
        check_mesh_output(args.output, false, args.normals, {args.input});
    } else {
        // a folder, made if missing (its parent must exist), of files label_<value>[_<name>].<format>
        fs::path folder(args.output);
        if (folder.filename().empty()) folder = folder.parent_path(); // "meshes/" is the folder meshes
        const bool exists = fs::is_directory(folder);
        if (!exists && fs::exists(folder)) throw UsageError("-o " + args.output + ": not a folder or a .ply file");
        const fs::path where = exists ? folder : (folder.parent_path().empty() ? fs::path(".") : folder.parent_path());
        check_mesh_output((where / ("label_0." + args.format)).string(), false, args.normals, {args.input});
    }
    const std::map<std::int64_t, io::LabelName> names = label_names(args);
    const Volume volume = load_volume(args.input, args.raw);
    const auto name_of = [&](std::int64_t value) {
        const auto it = names.find(value);
        return it == names.end() ? std::string() : it->second.name;
    };
    const auto colour_of = [&](std::int64_t value) -> std::optional<std::array<float, 3>> {
        const auto it = names.find(value);
        return it == names.end() ? std::nullopt : it->second.colour;
    };
    const LabelSurfaces s =
        named_step(args.input, "making the label surfaces", [&] { return label_surfaces(volume, options); });

    std::vector<Mesh> meshes; // the scene's, one per selected label
    if (scene) {
        meshes.resize(s.selected.size());
        detail::parallel_chunks(static_cast<std::int64_t>(meshes.size()),
                                detail::threads_for(args.threads, static_cast<std::int64_t>(meshes.size())),
                                [&](int, std::int64_t begin, std::int64_t end) {
                                    for (std::int64_t i = begin; i < end; ++i) {
                                        const auto at = static_cast<std::size_t>(i);
                                        meshes[at] = label_surface(s, s.selected[at]);
                                    }
                                });
        std::vector<io::ScenePart> parts;
        for (std::size_t i = 0; i < meshes.size(); ++i) {
            const std::int64_t value = s.selected[i];
            std::array<float, 4> colour = label_colour(i);
            if (const auto c = colour_of(value)) {
                for (std::size_t k = 0; k < 3; ++k) colour[k] = linear_from_srgb(static_cast<double>((*c)[k]));
            }
            const std::string name = name_of(value);
            parts.push_back({&meshes[i], name.empty() ? "label_" + std::to_string(value) : name, colour});
        }
        io::MeshWriteOptions wo;
        wo.space = volume.space();
        named_step(args.output, "writing the scene", [&] { io::write_scene(parts, args.output, wo); });
    } else if (single) {
        // the labels on the two sides as face properties: int, or uint for labels past int32's range
        io::MeshWriteOptions wo;
        wo.space = volume.space();
        wo.triangle_arrays = {{"front", std::span<const std::int64_t>(s.front), 1},
                              {"behind", std::span<const std::int64_t>(s.behind), 1}};
        named_step(args.output, "writing the interfaces", [&] { io::write_mesh(s.interfaces, args.output, wo); });
    } else {
        std::error_code ec;
        fs::create_directory(args.output, ec);
        if (ec) throw Error(Status::io_error, args.output + ": cannot make the folder (" + ec.message() + ")");
    }
    // Each label's file (a folder) and --json entry. A folder's labels are made, written and dropped
    // on all threads, a label to a thread at a time; the scene's meshes are reused; the interfaces'
    // .ply needs a label's surface only for --json.
    const std::size_t count = s.selected.size();
    std::vector<Json> entries(count);
    const auto one_label = [&](std::size_t i, const Mesh& m, int check_threads) {
        const std::int64_t value = s.selected[i];
        std::string file = scene ? args.output : std::string();
        if (!single) {
            // label_<value>.<format>, or label_<value>_<name>.<format> for a named label
            const std::string name = file_name_part(name_of(value));
            file = (fs::path(args.output) /
                    ("label_" + std::to_string(value) + (name.empty() ? "" : "_" + name) + "." + args.format))
                       .string();
            io::MeshWriteOptions wo;
            wo.space = volume.space();
            named_step(file, "writing a label's surface", [&] { io::write_mesh(m, file, wo); });
        }
        if (!args.json) return;
        const MeshTopology t = mesh_topology(m);
        MeshGeometryOptions geometry_options;
        geometry_options.threads = check_threads;
        const MeshGeometry g = mesh_geometry(m, geometry_options);
        const std::string name = name_of(value);
        const auto colour = colour_of(value);
        entries[i] = Json{{"value", value},
                          {"name", name.empty() ? Json(nullptr) : Json(name)},
                          {"color", colour ? rgb_json(*colour) : Json(nullptr)},
                          {"file", file.empty() ? Json(nullptr) : Json(file)},
                          {"vertices", static_cast<std::int64_t>(m.vertex_count())},
                          {"triangles", static_cast<std::int64_t>(m.triangle_count())},
                          {"topology", topology_json(t)},
                          {"embedded", g.embedded()},
                          {"geometry", geometry_json(g)}};
    };
    if (scene) {
        for (std::size_t i = 0; i < count && args.json; ++i) one_label(i, meshes[i], args.threads);
    } else if (single) {
        for (std::size_t i = 0; i < count && args.json; ++i) one_label(i, label_surface(s, s.selected[i]), args.threads);
    } else {
        const int workers = detail::threads_for(args.threads, static_cast<std::int64_t>(count));
        // the checks' threads shared among the labels made at once
        const int check_threads = std::max(1, cmc33::thread_count(args.threads) / workers);
        std::atomic<bool> failed{false};
        detail::parallel_chunks(static_cast<std::int64_t>(count), workers, [&](int, std::int64_t begin, std::int64_t end) {
            for (std::int64_t i = begin; i < end && !failed; ++i) {
                try {
                    one_label(static_cast<std::size_t>(i), label_surface(s, s.selected[static_cast<std::size_t>(i)]),
                              check_threads);
                } catch (...) {
                    failed = true;
                    throw;
                }
            }
        });
    }
    Json labels = Json::array();
    for (Json& e : entries)
        if (!e.is_null()) labels.push_back(std::move(e));
    if (args.json) {
        Json present = Json::array();
        for (const std::int64_t v : s.present) present.push_back(v);
        print_json(Json{{"volume", volume_json(args.input, volume)},
                        {"output", args.output},
                        {"background", args.background},
                        {"smooth", args.smooth},
                        {"present", present},
                        {"interface_triangles", static_cast<std::int64_t>(s.interfaces.triangle_count())},
                        {"cells_two_labels", s.cells_two_labels},
                        {"cells_many_labels", s.cells_many_labels},
                        {"cells_with_core", s.cells_with_core},
                        {"labels", labels}});
        return;
    }
    std::cout << args.input << ": " << counted(static_cast<std::int64_t>(s.present.size()), "label") << " present, "
              << counted(static_cast<std::int64_t>(s.selected.size()), "surface") << ", "
              << counted(static_cast<std::int64_t>(s.interfaces.triangle_count()), "interface triangle") << " -> "
              << args.output << "\n";
}

} // namespace

void add_labels(CLI::App& app)
{
    auto args = std::make_shared<LabelsArgs>();
    CLI::App* cmd = app.add_subcommand("labels", "Surfaces of every label of a label map, sharing their interfaces");
    cmd->add_option("VOLUME", args->input, "Label map: integer samples (.nrrd .nii .mha .vtk .npy .vti .tif, or raw)")
        ->required()
        ->check(non_empty("a volume file"));
    cmd->add_option("-o,--output", args->output,
                    "A folder (one file per label, label_<value>.<format> or label_<value>_<name>.<format>; made "
                    "if missing), a .ply of the interface triangles with face properties front and behind, or a "
                    ".glb/.gltf scene with a mesh per label, named by its name or label_<value>, in its colour")
        ->required()
        ->type_name("OUT")
        ->check(non_empty("an output folder, .ply, .glb or .gltf file"));
    cmd->add_option("--labels", args->labels, "Labels that get surfaces: all (default), a list 1,3,7, ranges 2-9")
        ->type_name("LIST");
    cmd->add_option("--background", args->background, "The label without a surface (default 0); it still takes part")
        ->type_name("VALUE")
        ->check(whole_number(std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::max()));
    cmd->add_option("--format", args->format,
                    "Format of a folder's files: ply (default), obj, stl, off, glb, gltf, vtp, gii")
        ->type_name("EXT")
        ->check(CLI::IsMember({"ply", "obj", "stl", "off", "glb", "gltf", "vtp", "gii"}));
    cmd->add_flag("--normals", args->normals,
                  "Per-vertex normals: each label's pointing out of it, the interfaces' to the front label "
                  "(area-weighted triangle normals; not in .off or .stl)");
    cmd->add_option("--smooth", args->smooth,
                    "Smooth labels: filter each label's indicator by a Gaussian of SIGMA voxels first (0, the "
                    "default: none); the surfaces stay one partition with the same guarantees")
        ->type_name("SIGMA")
        ->check(real_number("a number of voxels from 0 (none) to 1000", [](double v) { return v >= 0 && v <= 1000; },
                            "SIGMA"));
    cmd->add_option("--label-names", args->label_names,
                    "A colour table naming the labels: lines \"value name R G B [A]\" (3D Slicer .ctbl/.txt, "
                    "FreeSurfer LUT) or ITK-SNAP's label descriptions; a .seg.nrrd's own segment names are read "
                    "without it, and it wins where both name a label")
        ->type_name("FILE")
        ->check(non_empty("a colour table file"));
    cmd->add_flag("--json", args->json,
                  "Print one JSON object: every label's name, colour, file, size, topology and embedding");
    cmd->add_option("--threads", args->threads,
                    "Threads of the surfaces and the --json checks, 0 = all cores (the same files for any count)")
        ->type_name("N")
        ->check(thread_count());
    add_raw_volume_options(*cmd, args->raw);
    cmd->footer("Every point of the volume's box belongs to one label: the one whose indicator's trilinear\n"
                "interpolant is largest there, ties to the lower label. Where two labels meet in a cell their\n"
                "interface is cmc33's triangulation of the level set 0.5 of the lower label's indicator; cells\n"
                "with three or more labels are cut by cones from the cell's centre (docs/labels.md). Each\n"
                "label's surface is closed except on the volume's box, oriented outward and embedded, and\n"
                "neighbouring labels share their interface triangles exactly.\n"
                "\n"
                "--smooth SIGMA first filters every label's indicator by a Gaussian of SIGMA voxels (as\n"
                "3D Slicer's smoothing rounds its surfaces): each sample takes the label whose filtered\n"
                "indicator is largest, and the interfaces pass where two labels' filtered indicators are\n"
                "equal, cmc33's decisions on their difference in cells of two labels. A label thinner than\n"
                "the filter can vanish.\n"
                "\n"
                "Examples:\n"
                "  cmc33 labels seg.nrrd -o meshes/ --json\n"
                "  cmc33 labels seg.nrrd -o meshes/ --labels 1,3-5 --format stl\n"
                "  cmc33 labels seg.nrrd -o interfaces.ply\n"
                "  cmc33 labels seg.nrrd -o organs.glb --normals\n"
                "  cmc33 labels seg.nrrd -o smooth/ --smooth 1.5 --normals\n"
                "  cmc33 labels aseg.nii.gz -o regions/ --label-names FreeSurferColorLUT.txt");
    cmd->callback([args] { run_labels(*args); });
}

} // namespace cmc33::cli
