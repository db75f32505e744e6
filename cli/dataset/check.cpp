// verify_dataset: every file of a dataset's manifest extracted (in-process with each method, or by
// the external command) and judged against its expected invariants by the library's verification
// bookkeeping (src/verify/verify_detail.hpp), into the report `cmc33 verify` prints.

#include <array>
#include <atomic>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cmc33/cell.hpp"
#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/io.hpp"
#include "cmc33/verify.hpp"
#include "dataset.hpp"
#include "dataset_detail.hpp"
#include "parallel.hpp"
#include "verify_detail.hpp"

namespace cmc33::cli {
namespace {

using dataset_detail::CommandResult;
using dataset_detail::corner_values;
using dataset_detail::run_command;
using dataset_detail::TempFolder;
using verification::detail::Outcome;
using verification::detail::Tally;

bool is_cell(const Volume& volume)
{
    return volume.dims() == Index3{2, 2, 2};
}

/// The subcases a field counts for under `method` (see MethodReport).
std::vector<int> subcases_of(const Volume& volume, double iso, Method method,
                             const ExtractStats* stats)
{
    std::vector<int> out;
    if (is_cell(volume)) {
        out.push_back(analyze_cell(corner_values(volume), iso, method).subcase);
        return out;
    }
    ExtractStats own;
    if (stats == nullptr) {
        ExtractOptions o;
        o.method = method;
        o.threads = 1;
        extract(volume, iso, o, &own);
        stats = &own;
    }
    for (int s = 0; s < kSubcaseCount; ++s) {
        if (stats->cells_per_subcase[static_cast<std::size_t>(s)] > 0 &&
            verification::detail::is_ambiguous_subcase(s)) {
            out.push_back(s);
        }
    }
    return out;
}

/// Kind of a manifest entry: cell-* files and lines with a subcase are cells, closed-* files
/// closed grids, anything else a grid.
FieldKind kind_of(const ManifestEntry& entry)
{
    const std::string stem = std::filesystem::path(entry.file).filename().string();
    if (stem.rfind("closed", 0) == 0) return FieldKind::closed;
    if (stem.rfind("ties", 0) == 0) return FieldKind::ties;
    if (entry.subcase != "-" || stem.rfind("cell", 0) == 0) return FieldKind::cell;
    return FieldKind::grid;
}

struct EntryCheck {
    const std::filesystem::path& dir;
    const ManifestEntry& entry;
    FieldKind kind;
    std::int64_t order; ///< line index: failures are kept in manifest order
};

/// Checks one manifest entry with every method (or the command); `scratch` is this thread's
/// prefix for the command's output and log files.
void check_entry(const EntryCheck& check, const DatasetVerifyOptions& options,
                 const std::filesystem::path& scratch, std::vector<Tally>& mine,
                 std::atomic<std::int64_t>& mismatched)
{
    const ManifestEntry& entry = check.entry;
    const std::filesystem::path path = check.dir / entry.file;
    const auto volume = std::make_shared<const Volume>(io::read_volume(path));
    for (Tally& tally : mine) {
        Outcome outcome;
        outcome.kind = check.kind;
        outcome.order = check.order;
        outcome.name = std::filesystem::path(entry.file).stem().string();
        outcome.volume = volume;
        outcome.iso = entry.iso;
        outcome.expected = &entry.expected;
        if (tally.report.external) {
            const ExternalCommand command = expand_command(options.command, path, entry.iso,
                                                           scratch.string() + "-" + outcome.name);
            CommandResult result =
                run_command(command, scratch.string() + "-log.txt", options.timeout_seconds);
            outcome.mesh = std::move(result.mesh);
            outcome.note = std::move(result.note);
            outcome.subcases = subcases_of(*volume, entry.iso, Method::cmc33, nullptr);
        } else {
            ExtractOptions o;
            o.method = tally.report.method;
            o.threads = 1;
            ExtractStats stats;
            try {
                outcome.mesh = extract(*volume, entry.iso, o, &stats);
            } catch (const Error& e) {
                outcome.note = std::string("extract failed: ") + e.what();
            }
            outcome.subcases = subcases_of(*volume, entry.iso, o.method, &stats);
        }
        if (!verification::detail::record(tally, std::move(outcome), options.max_failures)) {
            mismatched.fetch_add(1, std::memory_order_relaxed);
        }
    }
}

} // namespace

VerifyReport verify_dataset(const std::filesystem::path& dir, const DatasetVerifyOptions& options)
{
    const std::vector<ManifestEntry> entries = read_manifest(dir);
    if (entries.empty()) {
        throw Error(Status::bad_format, (dir / "manifest.tsv").string() +
                                            ": lists no file; expected one line per file");
    }
    const bool external = !options.command.empty();
    if (external) {
        (void)expand_command(options.command, "in", 0.0, "out"); // throws without {in} or {out}
    } else {
        verification::detail::check_methods(options.methods);
    }
    const auto total = static_cast<std::int64_t>(entries.size());
    const int threads = cmc33::detail::threads_for(options.threads, total);
    std::vector<std::vector<Tally>> tallies =
        verification::detail::make_tallies(threads, options.methods, external);
    std::atomic<std::int64_t> mismatched{0};
    verification::detail::Ticker tick(options.progress, total, &mismatched);
    std::optional<TempFolder> temp;
    if (external) temp.emplace();

    // Each kind runs as one pass (in manifest order), so that its rate can be reported.
    std::array<std::vector<std::size_t>, kFieldKindCount> by_kind;
    for (std::size_t i = 0; i < entries.size(); ++i) {
        by_kind[static_cast<std::size_t>(kind_of(entries[i]))].push_back(i);
    }
    VerifyReport report;
    report.threads = threads;
    for (int k = 0; k < kFieldKindCount; ++k) {
        const std::vector<std::size_t>& items = by_kind[static_cast<std::size_t>(k)];
        const double kind_start = tick.seconds();
        const auto count = static_cast<std::int64_t>(items.size());
        verification::detail::run_parallel(
            count, threads, external ? 2 : 16, tick,
            [&](int t, std::int64_t begin, std::int64_t end) {
                for (std::int64_t i = begin; i < end; ++i) {
                    const std::size_t item = items[static_cast<std::size_t>(i)];
                    const EntryCheck check{dir, entries[item], static_cast<FieldKind>(k),
                                           static_cast<std::int64_t>(item)};
                    const std::filesystem::path scratch =
                        external ? temp->path / ("t" + std::to_string(t)) : std::filesystem::path();
                    check_entry(check, options, scratch, tallies[static_cast<std::size_t>(t)],
                                mismatched);
                }
            });
        report.fields[static_cast<std::size_t>(k)] = count;
        report.kind_seconds[static_cast<std::size_t>(k)] = tick.seconds() - kind_start;
        tick.pass_done(count);
    }
    std::vector<Tally> merged = verification::detail::merge(tallies, options.max_failures);
    report.seconds = tick.seconds();
    verification::detail::RerunCommand rerun;
    if (external) {
        rerun = [&options](const std::filesystem::path& in, double iso, const std::filesystem::path& out_base) {
            return expand_command(options.command, in, iso, out_base).shell;
        };
    }
    verification::detail::finish(merged, options.failures_dir, rerun, report);
    tick(0);
    return report;
}

} // namespace cmc33::cli
