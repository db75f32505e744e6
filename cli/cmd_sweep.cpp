// cmc33 sweep: the topology of a volume's isosurfaces over a range of isovalues, per method
// (Custodio et al. 2013, Figs. 13 and 14), with the trilinear field's own beside cmc33's.

#include <algorithm>
#include <charconv>
#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/sweep.hpp"
#include "commands.hpp"
#include "common.hpp"

namespace cmc33::cli {

namespace {

struct SweepArgs {
    std::string input;
    std::string iso;
    std::string methods; ///< "a,b,c"; empty: the default four
    bool json = false;
    bool csv = false;
    bool no_expected = false;
    int threads = 0;
    bool progress = false;
    bool quiet = false;
    RawVolumeOptions raw;
};

/// FROM:TO:STEP, three numbers (number_check's rules for each).
std::vector<double> parse_range(const std::string& text)
{
    const auto bad = [&](const std::string& why) {
        return UsageError("--iso " + text + ": " + why + "; expected FROM:TO:STEP, e.g. 10:250:1");
    };
    std::vector<double> parts;
    std::size_t start = 0;
    for (int i = 0; i < 3; ++i) {
        const std::size_t colon = i < 2 ? text.find(':', start) : text.size();
        if (colon == std::string::npos) throw bad("too few numbers");
        const std::string piece = text.substr(start, colon - start);
        double value = 0;
        const auto [end, ec] = std::from_chars(piece.data(), piece.data() + piece.size(), value);
        if (piece.empty() || ec != std::errc() || end != piece.data() + piece.size()) {
            throw bad("'" + piece + "' is not a number");
        }
        parts.push_back(value);
        start = colon + 1;
    }
    if (text.find(':', text.rfind(':') + 1) != std::string::npos) throw bad("too many numbers");
    try {
        return sweep_isovalues(parts[0], parts[1], parts[2]);
    } catch (const Error& e) { // "isovalues F:T:S: why"
        const std::string what = e.what();
        throw UsageError("--iso " + text + what.substr(what.find(": ")));
    }
}

/// "a,b,c" as its names. (--methods is one string, not a CLI11 list: its split trips g++ 12's
/// -Wnull-dereference at -O1, the ThreadSanitizer build.)
std::vector<std::string> split_commas(const std::string& text)
{
    std::vector<std::string> parts;
    std::size_t start = 0;
    for (std::size_t comma = text.find(','); comma != std::string::npos; comma = text.find(',', start)) {
        parts.push_back(text.substr(start, comma - start));
        start = comma + 1;
    }
    parts.push_back(text.substr(start));
    return parts;
}

std::vector<Method> parse_methods(const std::string& list)
{
    std::vector<Method> methods;
    if (list.empty()) return SweepOptions{}.methods;
    for (const std::string& name : split_commas(list)) {
        const Method m = parse_method(name);
        if (std::find(methods.begin(), methods.end(), m) != methods.end()) {
            throw UsageError("--methods " + name + " is given twice");
        }
        methods.push_back(m);
    }
    if (methods.empty()) methods = SweepOptions{}.methods;
    return methods;
}

Json expected_json(const SweepRow& row)
{
    if (!row.expected) return Json(nullptr);
    return {{"euler", row.expected->euler}, {"b0", row.expected->b0}, {"b1", row.expected->b1}, {"b2", row.expected->b2}};
}

void print_sweep_json(const SweepArgs& args, const Volume& volume, const std::vector<Method>& methods, const SweepReport& r)
{
    const Index3 d = volume.dims();
    Json names = Json::array();
    for (Method m : methods) names.push_back(std::string(method_name(m)));
    Json rows = Json::array();
    for (const SweepRow& row : r.rows) {
        rows.push_back({{"iso", row.iso},
                        {"method", std::string(method_name(row.method))},
                        {"vertices", row.vertices},
                        {"triangles", row.triangles},
                        {"euler", row.euler},
                        {"b0", row.b0},
                        {"b1", row.b1},
                        {"b2", row.b2},
                        {"boundary_loops", row.boundary_loops},
                        {"non_manifold_edges", row.nonmanifold_edges},
                        {"expected", expected_json(row)}});
    }
    print_json({{"volume", args.input},
                {"dims", {d[0], d[1], d[2]}},
                {"type", std::string(type_name(volume.type()))},
                {"cells", (d[0] - 1) * (d[1] - 1) * (d[2] - 1)},
                {"methods", names},
                {"rows", rows}});
}

void print_sweep_csv(const SweepReport& r)
{
    std::cout << "iso,method,vertices,triangles,euler,b0,b1,b2,boundary_loops,non_manifold_edges,"
                 "expected_euler,expected_b0,expected_b1,expected_b2\n";
    for (const SweepRow& row : r.rows) {
        std::cout << num(row.iso) << ',' << method_name(row.method) << ',' << row.vertices << ',' << row.triangles << ','
                  << row.euler << ',' << row.b0 << ',' << row.b1 << ',' << row.b2 << ',' << row.boundary_loops << ','
                  << row.nonmanifold_edges;
        if (row.expected) {
            std::cout << ',' << row.expected->euler << ',' << row.expected->b0 << ',' << row.expected->b1 << ','
                      << row.expected->b2;
        } else {
            std::cout << ",,,,";
        }
        std::cout << '\n';
    }
}

void print_sweep_text(const SweepReport& r)
{
    const auto pad = [](std::string text, std::size_t width) {
        return text.size() >= width ? text : std::string(width - text.size(), ' ') + text;
    };
    std::cout << pad("iso", 10) << "  " << std::string("method") + std::string(8, ' ') << pad("triangles", 11)
              << pad("euler", 9) << pad("b0", 8) << pad("b1", 8) << pad("b2", 8) << pad("loops", 7)
              << pad("non-manifold", 14) << "  expected euler b0 b1 b2\n";
    for (const SweepRow& row : r.rows) {
        std::string name(method_name(row.method));
        name.resize(std::max<std::size_t>(name.size(), 14), ' ');
        std::cout << pad(num(row.iso), 10) << "  " << name << pad(std::to_string(row.triangles), 11)
                  << pad(std::to_string(row.euler), 9) << pad(std::to_string(row.b0), 8) << pad(std::to_string(row.b1), 8)
                  << pad(std::to_string(row.b2), 8) << pad(std::to_string(row.boundary_loops), 7)
                  << pad(std::to_string(row.nonmanifold_edges), 14);
        if (row.expected) {
            const FieldTopology& e = *row.expected;
            const bool same = e.euler == row.euler && e.b0 == row.b0 && e.b1 == row.b1 && e.b2 == row.b2;
            std::cout << "  " << e.euler << ' ' << e.b0 << ' ' << e.b1 << ' ' << e.b2 << (same ? " (equal)" : " (DIFFERENT)");
        }
        std::cout << '\n';
    }
}

void run_sweep(const SweepArgs& args)
{
    if (args.json && args.csv) throw UsageError("--json and --csv: give one of them");
    SweepOptions options;
    options.isovalues = parse_range(args.iso);
    options.methods = parse_methods(args.methods);
    options.expected = !args.no_expected;
    options.threads = args.threads;
    const Volume volume = load_volume(args.input, args.raw);
    options.progress = progress_line(args.progress, args.quiet, "isovalues");
    SweepReport report;
    try {
        report = named_step(args.input, "sweeping the isovalues", [&] { return sweep(volume, options); });
    } catch (...) {
        end_progress_line();
        throw;
    }
    if (args.json) {
        print_sweep_json(args, volume, options.methods, report);
    } else if (args.csv) {
        print_sweep_csv(report);
    } else {
        print_sweep_text(report);
    }
}

} // namespace

void add_sweep(CLI::App& app)
{
    auto args = std::make_shared<SweepArgs>();
    CLI::App* cmd = app.add_subcommand(
        "sweep", "Topology of the isosurfaces over a range of isovalues, per method (the paper's Figs. 13-14)");
    cmd->add_option("INPUT", args->input, "Volume: .nrrd .nhdr .mhd .mha .vtk, or headerless raw with --dims/--type")
        ->required()
        ->check(non_empty("a volume file name"));
    cmd->add_option("-i,--iso", args->iso, "Isovalues FROM:TO:STEP, TO included (e.g. 10:250:1)")
        ->type_name("FROM:TO:STEP")
        ->required()
        ->check(non_empty("FROM:TO:STEP"));
    cmd->add_option("--methods,--method", args->methods,
                    "Methods, comma-separated (default cmc33,chernyaev,mc33-lewiner,mc);\n"
                    "also cmc33-paper")
        ->type_name("NAME")
        ->check(CLI::Validator(
            [](std::string& list) -> std::string {
                for (const std::string& name : split_commas(list)) {
                    try {
                        (void)parse_method(name);
                    } catch (const Error& e) {
                        return e.what();
                    }
                }
                return {};
            },
            "NAME[,NAME...]", "methods"));
    auto* json = cmd->add_flag("--json", args->json, "One JSON object: volume, dims, type, cells, methods, rows");
    cmd->add_flag("--csv", args->csv, "Comma-separated rows with a header line")->excludes(json);
    cmd->add_flag("--no-expected", args->no_expected,
                  "Skip the trilinear field's topology beside cmc33 (about a third of the time)");
    cmd->add_option("--threads", args->threads, "Isovalues run at once, 0 = all cores (default 0, at most 1024)")
        ->type_name("N")
        ->check(thread_count());
    auto* progress = cmd->add_flag("--progress", args->progress, "Progress lines on stderr even when it is not a terminal");
    cmd->add_flag("--quiet", args->quiet, "No progress line (shown on a terminal by default)")->excludes(progress);
    add_raw_volume_options(*cmd, args->raw);
    cmd->footer(
        "Extracts the isosurface at every isovalue FROM, FROM + STEP, ... TO with every method and\n"
        "prints, per isovalue and method, the mesh's triangles, Euler characteristic, Betti numbers\n"
        "b0 (components) b1 b2 (closed components), boundary loops and non-manifold edges; for\n"
        "cmc33 also the topology of the trilinear interpolant's level set, computed from the\n"
        "samples alone (field_topology), which a correct mesh equals. Isovalues run in parallel.\n"
        "The counts are those `cmc33 extract --json` reports for the same isovalue and method.\n"
        "\n"
        "Examples:\n"
        "  cmc33 sweep aneurism.nrrd --iso 10:250:1 --json > aneurism.json\n"
        "  cmc33 sweep bonsai.nrrd --iso 20:60:0.5 --methods cmc33,mc33-lewiner --csv\n"
        "  cmc33 sweep Cranium.nrrd -i 100:590:10 --methods chernyaev,mc33-lewiner,cmc33-paper");
    cmd->callback([args] { run_sweep(*args); });
}

} // namespace cmc33::cli
