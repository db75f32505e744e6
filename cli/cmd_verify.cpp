// cmc33 verify: the topology stress test on random fields, or a check of a verification dataset
// (in-process, or of any extractor run as a command). docs/verification.md explains both.

#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/verify.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "dataset.hpp"
#include "plural.hpp"

namespace cmc33::cli {

namespace {

/// A run that found mismatches: main() prints the message and exits with status 1.
class VerificationFailed : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

struct VerifyArgs {
    std::int64_t cells = 0;
    std::int64_t grids = 0;
    std::int64_t closed = 0;
    std::int64_t ties = 0;
    int size = 5;
    std::uint64_t seed = 1;
    std::vector<std::string> methods;
    int threads = 0;
    bool json = false;
    bool progress = false;
    bool quiet = false;
    std::string failures;
    int max_failures = 20;
    std::string dataset;
    std::string command;
    double timeout = 60;
    CLI::Option* timeout_option = nullptr;
    std::vector<CLI::Option*> random_only; ///< options that make no sense with --dataset
};

constexpr std::array<std::string_view, kFieldKindCount> kKindSingular = {"cell", "grid", "closed", "tie"};
constexpr std::array<std::string_view, kFieldKindCount> kKindPlural = {"cells", "grids", "closed", "ties"};

/// --method NAME, repeated or comma-separated; "all" for the five. Default: cmc33 alone (the
/// legacy methods fail by design, so a default run that includes them could never pass).
std::vector<Method> parse_methods(const std::vector<std::string>& names)
{
    std::vector<Method> methods;
    for (const std::string& name : names) {
        if (name == "all") {
            if (names.size() != 1) throw UsageError("--method all lists every method; give no other with it");
            return {Method::cmc33, Method::cmc33_paper, Method::chernyaev, Method::mc33_lewiner, Method::mc};
        }
        const Method m = parse_method(name);
        if (std::find(methods.begin(), methods.end(), m) != methods.end()) {
            throw UsageError("--method " + name + " is given twice");
        }
        methods.push_back(m);
    }
    if (methods.empty()) methods = {Method::cmc33};
    return methods;
}

Json report_json(const VerifyReport& r, const VerifyArgs& args)
{
    Json fields = Json::object(), rates = Json::object();
    for (int k = 0; k < kFieldKindCount; ++k) {
        const std::string kind(field_kind_name(static_cast<FieldKind>(k)));
        fields[kind] = r.fields[static_cast<std::size_t>(k)];
        rates[kind] = r.rate(static_cast<FieldKind>(k));
    }
    Json out = Json::object();
    if (args.dataset.empty()) {
        out["seed"] = r.seed;
        out["size"] = r.size;
    } else {
        out["dataset"] = args.dataset;
        out["command"] = args.command.empty() ? Json(nullptr) : Json(args.command);
    }
    out["fields"] = fields;
    out["threads"] = r.threads;
    out["seconds"] = r.seconds;
    out["fields_per_second"] = rates;
    Json methods = Json::array();
    for (const MethodReport& m : r.methods) {
        Json by_kind = Json::object();
        for (int k = 0; k < kFieldKindCount; ++k) {
            by_kind[std::string(field_kind_name(static_cast<FieldKind>(k)))] = {
                {"checked", m.checked_by_kind[static_cast<std::size_t>(k)]},
                {"mismatched", m.mismatched_by_kind[static_cast<std::size_t>(k)]},
                {"topology_mismatched", m.topology_mismatched_by_kind[static_cast<std::size_t>(k)]}};
        }
        Json subcases = Json::object();
        for (int s = 0; s < kSubcaseCount; ++s) {
            const auto i = static_cast<std::size_t>(s);
            if (m.fields_per_subcase[i] == 0) continue;
            subcases[std::string(subcase_name(s))] = {
                {"fields", m.fields_per_subcase[i]},
                {"mismatched", m.mismatches_per_subcase[i]},
                {"topology_mismatched", m.topology_mismatches_per_subcase[i]},
                {"cells", m.cells_per_subcase[i]},
                {"cells_topology_mismatched", m.cell_topology_mismatches_per_subcase[i]}};
        }
        methods.push_back({{"method", m.name},
                           {"checked", m.checked},
                           {"matched", m.matched},
                           {"mismatched", m.mismatched},
                           {"topology_mismatched", m.topology_mismatched},
                           {"undetermined", m.undetermined},
                           {"nonmanifold", m.nonmanifold},
                           {"unoriented", m.unoriented},
                           {"not_embedded", m.not_embedded},
                           {"errors", m.errors},
                           {"first_error", m.first_error.empty() ? Json(nullptr) : Json(m.first_error)},
                           {"by_kind", by_kind},
                           {"subcases", subcases},
                           {"failures_written", m.failures_written}});
    }
    out["methods"] = methods;
    out["failures"] = r.failures_dir.empty()
                          ? Json(nullptr)
                          : Json{{"dir", r.failures_dir.string()},
                                 {"list", (r.failures_dir / "failures.tsv").string()},
                                 {"written", r.failures_written}};
    out["passed"] = r.passed();
    return out;
}

std::string pad(std::string text, std::size_t width, bool right = true)
{
    if (text.size() >= width) return text;
    const std::string fill(width - text.size(), ' ');
    return right ? fill + text : text + fill;
}

void print_report(const VerifyReport& r, const VerifyArgs& args)
{
    std::string head = args.dataset.empty() ? "random fields, seed " + std::to_string(r.seed) + ":"
                                            : "dataset " + args.dataset + ":";
    for (int k = 0; k < kFieldKindCount; ++k) {
        const auto i = static_cast<std::size_t>(k);
        if (r.fields[i] == 0) continue;
        head += " " + counted(r.fields[i], kKindSingular[i], kKindPlural[i]);
        if (k != 0 && args.dataset.empty()) head += " " + std::to_string(r.size) + "^3";
        head += " (" + rate_text(r.rate(static_cast<FieldKind>(k))) + "/s),";
    }
    std::cout << head << " " << counted(r.threads, "thread") << ", " << sig(r.seconds, 3) << " s\n";
    if (!args.command.empty()) std::cout << "command: " << args.command << '\n';
    std::cout << '\n';

    std::size_t name_width = 12;
    for (const MethodReport& m : r.methods) name_width = std::max(name_width, m.name.size());
    std::cout << pad("method", name_width, false) << "  " << pad("checked", 9) << pad("matched", 9)
              << pad("mismatched", 12) << pad("topology", 10) << pad("non-manifold", 14)
              << pad("not embedded", 14) << pad("undetermined", 14) << "  mismatched cells/grids/closed/ties\n";
    for (const MethodReport& m : r.methods) {
        std::cout << pad(m.name, name_width, false) << "  " << pad(std::to_string(m.checked), 9)
                  << pad(std::to_string(m.matched), 9) << pad(std::to_string(m.mismatched), 12)
                  << pad(std::to_string(m.topology_mismatched), 10)
                  << pad(std::to_string(m.nonmanifold), 14) << pad(std::to_string(m.not_embedded), 14)
                  << pad(std::to_string(m.undetermined), 14) << "  " << m.mismatched_by_kind[0]
                  << "/" << m.mismatched_by_kind[1] << "/" << m.mismatched_by_kind[2] << "/"
                  << m.mismatched_by_kind[3] << '\n';
    }
    std::cout << "(a mesh matches when its Euler characteristic, Betti numbers and boundary loops equal the\n"
                 " field's (else it counts under topology), it is manifold, and it is embedded in space)\n";
    for (const MethodReport& m : r.methods) {
        if (m.errors != 0)
            std::cout << m.name << ": " << counted(m.errors, "field") << " gave no mesh"
                      << (m.first_error.empty() ? "" : "; the first, " + m.first_error)
                      << (r.failures_dir.empty() ? "" : " (all in failures.tsv)") << '\n';
        if (m.unoriented != 0)
            std::cout << m.name << ": " << counted(m.unoriented, "mesh", "meshes") << " not consistently oriented\n";
    }

    // Per subcase, topology mismatches only: single cells (each is the one subcase the method
    // gives it, so a mismatch is that decision's), then the other fields (charged to every
    // face- or interior-tested subcase they hold: where to look, not a diagnosis).
    const std::size_t column = std::max<std::size_t>(name_width, 16) + 2;
    const auto table = [&](const char* title, auto&& fields, auto&& mismatches) {
        bool any = false;
        for (int s = 0; s < kSubcaseCount; ++s)
            for (const MethodReport& m : r.methods) any = any || fields(m, static_cast<std::size_t>(s)) != 0;
        if (!any) return;
        std::cout << '\n' << title << '\n' << pad("subcase", 8, false);
        for (const MethodReport& m : r.methods) std::cout << pad(m.name, column);
        std::cout << '\n';
        for (int s = 0; s < kSubcaseCount; ++s) {
            const auto i = static_cast<std::size_t>(s);
            if (std::none_of(r.methods.begin(), r.methods.end(), [&](const MethodReport& m) { return fields(m, i) != 0; }))
                continue;
            std::cout << pad(std::string(subcase_name(s)), 8, false);
            for (const MethodReport& m : r.methods) {
                const std::int64_t n = fields(m, i);
                std::cout << pad(n == 0 ? "-" : std::to_string(mismatches(m, i)) + " / " + std::to_string(n), column);
            }
            std::cout << '\n';
        }
    };
    table("topology mismatches / cells per subcase (single cells, by the subcase the method gives them)",
          [](const MethodReport& m, std::size_t i) { return m.cells_per_subcase[i]; },
          [](const MethodReport& m, std::size_t i) { return m.cell_topology_mismatches_per_subcase[i]; });
    table("topology mismatches / grids per subcase (a grid counts for every face- or interior-tested\n"
          "subcase among its cells)",
          [](const MethodReport& m, std::size_t i) { return m.fields_per_subcase[i] - m.cells_per_subcase[i]; },
          [](const MethodReport& m, std::size_t i) {
              return m.topology_mismatches_per_subcase[i] - m.cell_topology_mismatches_per_subcase[i];
          });
    if (r.failures_written != 0) {
        std::cout << "\n"
                  << counted(r.failures_written, "failure") << " written to " << r.failures_dir.string()
                  << "/ (listed in " << (r.failures_dir / "failures.tsv").string()
                  << " with the commands that reproduce them)\n";
    }
}

/// Where failures will go must be usable before the run, not after it: a folder, or a path whose
/// nearest existing ancestor is a writable folder; never the dataset checked.
void check_failures_folder(const VerifyArgs& args)
{
    if (args.failures.empty()) return;
    const std::filesystem::path dir(args.failures);
    std::error_code ec;
    if (std::filesystem::exists(dir, ec) && !std::filesystem::is_directory(dir, ec)) {
        throw Error(Status::io_error, args.failures + ": --failures exists and is not a folder");
    }
    if (!args.dataset.empty() && std::filesystem::equivalent(dir, args.dataset, ec) && !ec) {
        throw UsageError("--failures " + args.failures + " is the dataset folder; give another folder");
    }
    std::filesystem::path existing = std::filesystem::absolute(dir, ec);
    while (!existing.empty() && !std::filesystem::exists(existing, ec) && existing.has_parent_path() &&
           existing.parent_path() != existing) {
        existing = existing.parent_path();
    }
    check_writable_folder(existing, args.failures);
}

void check_usage(const VerifyArgs& args)
{
    if (args.timeout_option->count() > 0 && args.command.empty()) {
        throw UsageError("--timeout limits each run of --cmd; give --dataset DIR --cmd TEMPLATE with it");
    }
    if (!args.dataset.empty()) {
        for (const CLI::Option* o : args.random_only) {
            if (o->count() > 0) {
                throw UsageError(o->get_name() +
                                 " is for random fields; --dataset DIR checks the dataset's files");
            }
        }
        if (!args.command.empty()) {
            try {
                (void)expand_command(args.command, "in", 0.0, "out");
            } catch (const Error& e) {
                throw UsageError(std::string("--cmd: ") + e.what());
            }
        }
        if (!args.command.empty() && !args.methods.empty()) {
            throw UsageError(
                "--cmd runs an external extractor; --method chooses cmc33's own: give one of them");
        }
        return;
    }
    if (!args.command.empty())
        throw UsageError("--cmd needs --dataset DIR (the files to run it on)");
    if (args.cells + args.grids + args.closed + args.ties == 0) {
        throw UsageError("nothing to do: give --cells N, --grids N, --closed N and/or --ties N "
                         "(e.g. --cells 20000 --grids 5000), or --dataset DIR");
    }
    const int min_size = args.closed > 0 ? 3 : 2;
    if (args.size < min_size || args.size > 1024) {
        throw UsageError("--size " + std::to_string(args.size) + " is out of range; expected " +
                         std::to_string(min_size) + " to 1024" +
                         (args.closed > 0 ? " (closed grids need an interior sample)" : ""));
    }
}

void run_verify(const VerifyArgs& args)
{
    check_usage(args);
    check_failures_folder(args);
    const std::filesystem::path failures = args.failures; // empty: none written
    VerifyReport report;
    if (args.dataset.empty()) {
        VerifyOptions options;
        options.methods = parse_methods(args.methods);
        options.cells = args.cells;
        options.grids = args.grids;
        options.closed = args.closed;
        options.ties = args.ties;
        options.size = args.size;
        options.seed = args.seed;
        options.threads = args.threads;
        options.failures_dir = failures;
        options.max_failures = args.max_failures;
        options.progress = progress_line(args.progress, args.quiet, "fields");
        try {
            report = verify(options);
        } catch (...) {
            end_progress_line();
            throw;
        }
    } else {
        DatasetVerifyOptions options;
        if (args.command.empty()) options.methods = parse_methods(args.methods);
        options.command = args.command;
        options.timeout_seconds = args.timeout;
        options.threads = args.threads;
        options.failures_dir = failures;
        options.max_failures = args.max_failures;
        options.progress = progress_line(args.progress, args.quiet, "files");
        try {
            report = verify_dataset(args.dataset, options);
        } catch (...) {
            end_progress_line();
            throw;
        }
    }
    if (args.json) {
        print_json(report_json(report, args));
    } else {
        print_report(report, args);
    }
    if (!report.passed()) {
        std::string what;
        for (const MethodReport& m : report.methods) {
            if (m.mismatched == 0) continue;
            what += (what.empty() ? "" : ", ") + m.name + " " + std::to_string(m.mismatched) +
                    " mismatched";
            if (m.nonmanifold != 0) what += " (" + std::to_string(m.nonmanifold) + " non-manifold)";
        }
        if (!report.failures_dir.empty()) {
            what += "; failures in " + report.failures_dir.string() + "/";
        } else if (args.failures.empty()) {
            what += "; rerun with --failures DIR to save the failing fields";
        }
        throw VerificationFailed("verify: " + what);
    }
}

} // namespace

void add_verify(CLI::App& app)
{
    auto args = std::make_shared<VerifyArgs>();
    CLI::App* cmd = app.add_subcommand(
        "verify",
        "Topology stress test: mesh invariants against the field's, on random fields or a dataset");
    const std::string random_group = "Random fields";
    args->random_only.push_back(
        cmd->add_option("--cells", args->cells, "Random single cells (2x2x2 samples)")
            ->type_name("N")
            ->check(whole_number(0, std::numeric_limits<std::int64_t>::max()))
            ->group(random_group));
    args->random_only.push_back(
        cmd->add_option("--grids", args->grids, "Random grids, samples uniform in [-1, 1]")
            ->type_name("N")
            ->check(whole_number(0, std::numeric_limits<std::int64_t>::max()))
            ->group(random_group));
    args->random_only.push_back(
        cmd->add_option("--closed", args->closed, "Random grids whose surfaces are all closed")
            ->type_name("N")
            ->check(whole_number(0, std::numeric_limits<std::int64_t>::max()))
            ->group(random_group));
    args->random_only.push_back(
        cmd->add_option("--ties", args->ties,
                        "Random grids of integers -2..2 or -3..3 at iso 0: ties everywhere")
            ->type_name("N")
            ->check(whole_number(0, std::numeric_limits<std::int64_t>::max()))
            ->group(random_group));
    args->random_only.push_back(
        cmd->add_option("--size", args->size, "Samples per axis of the grids (default 5)")
            ->type_name("N")
            ->check(whole_number(2, 1024))
            ->group(random_group));
    args->random_only.push_back(
        cmd->add_option("--seed", args->seed, "Seed of the random fields (default 1)")
            ->type_name("S")
            ->check(unsigned_number())
            ->group(random_group));
    cmd->add_option("--dataset", args->dataset,
                    "Check the files of a dataset written by `cmc33 dataset`")
        ->type_name("DIR")
        ->check(non_empty("a dataset folder"))
        ->group("Dataset");
    cmd->add_option("--cmd", args->command,
                    "With --dataset: judge this extractor command instead, e.g.\n"
                    "'tool {in} {iso} {out}' ({out}: a .ply to write)")
        ->type_name("TEMPLATE")
        ->check(non_empty("a command template"))
        ->group("Dataset");
    args->timeout_option =
        cmd->add_option("--timeout", args->timeout,
                        "With --cmd: seconds one run may take; then its process group is\n"
                        "killed and the file counts as an error (default 60)")
            ->type_name("SECONDS")
            ->check(real_number("a number of seconds > 0", [](double v) { return std::isfinite(v) && v > 0; }, "> 0"))
            ->group("Dataset");
    cmd->add_option("--method,--methods", args->methods,
                    "Method to check: cmc33 (default), cmc33-paper, chernyaev, mc33-lewiner,\n"
                    "mc, or all; repeat or separate with commas for several")
        ->type_name("NAME")
        ->delimiter(',')
        ->check(CLI::Validator(
            [](std::string& name) -> std::string {
                if (name == "all") return {};
                try {
                    (void)parse_method(name);
                    return {};
                } catch (const Error& e) {
                    return std::string(e.what()) + " (or all)";
                }
            },
            "cmc33|cmc33-paper|chernyaev|mc33-lewiner|mc|all", "method"));
    cmd->add_option("--threads", args->threads, "Worker threads, 0 = all cores (default 0, at most 1024)")
        ->type_name("N")
        ->check(thread_count());
    cmd->add_option("--failures", args->failures,
                    "Save failing fields, meshes and failures.tsv in this folder\n"
                    "(created only if something fails; default: none saved)")
        ->type_name("DIR")
        ->check(non_empty("a folder name"));
    cmd->add_option("--max-failures", args->max_failures,
                    "Failing fields saved per method (default 20)")
        ->type_name("N")
        ->check(whole_number(0, std::numeric_limits<int>::max()));
    cmd->add_flag("--json", args->json, "Print one JSON object instead of the tables");
    auto* progress = cmd->add_flag("--progress", args->progress,
                                   "Progress lines on stderr even when it is not a terminal");
    cmd->add_flag("--quiet", args->quiet, "No progress lines (shown on a terminal by default)")->excludes(progress);
    cmd->footer(
        "For every field, the Euler characteristic, Betti numbers b0 b1 b2 and boundary loops of "
        "the\n"
        "level set f = 0 of its trilinear interpolant are computed from the samples alone and\n"
        "compared with those of the mesh each method extracts; a mesh matches if they are equal "
        "and\n"
        "it has no non-manifold edge or vertex and is embedded in space. The table counts apart\n"
        "the meshes whose invariants differ (topology), the non-manifold ones and those not\n"
        "embedded; per subcase it shows topology mismatches. Fields whose topology cannot be\n"
        "settled are counted as undetermined. With --failures DIR, failing fields are saved with\n"
        "the commands that reproduce them. The methods that reproduce Custodio et al. 2013\n"
        "(chernyaev, mc33-lewiner, and mc) fail by design: they run only when asked for\n"
        "(--method all, or e.g. --method chernyaev,mc33-lewiner).\n"
        "Exit status: 0 all matched, 1 a mismatch or non-manifold mesh, 2 bad usage.\n"
        "\n"
        "Examples:\n"
        "  cmc33 verify --cells 200000 --grids 20000 --closed 5000\n"
        "  cmc33 verify --method all --cells 20000 --grids 5000 --failures failed\n"
        "  cmc33 verify --method chernyaev,mc33-lewiner,cmc33-paper --cells 100000 --grids 20000\n"
        "  cmc33 verify --dataset mc-data --cmd 'mytool {in} {iso} {out}' --timeout 10");
    cmd->callback([args] { run_verify(*args); });
}

} // namespace cmc33::cli
