// verify(): the stress test of Etiene et al. 2012 as Custodio et al. 2013 (Sec. 4) ran it on
// MC33. For each random field, the invariants its trilinear level set must have come from
// field_topology (the samples alone, no code shared with the extractor); each method's mesh is
// extracted and its invariants compared. A mismatch is a counterexample: the field and the mesh
// are saved so that it can be reproduced.
//
// Parallelism is across fields (each extract() runs on one thread): a 5x5x5 grid is far too small
// to split, and fields are independent. Workers pull batches of items from a shared counter; the
// tallies are sums, and the failures kept are the first in item order, so the report does not
// depend on the thread count.

#include <algorithm>
#include <array>
#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "cmc33/cell.hpp"
#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/topology.hpp"
#include "cmc33/verify.hpp"
#include "parallel.hpp"
#include "verify_detail.hpp"

namespace cmc33 {
namespace {

using verification::detail::Outcome;
using verification::detail::Tally;

std::array<double, 8> cell_values(const GridView<float>& view)
{
    std::array<double, 8> v{};
    for (int c = 0; c < 8; ++c)
        v[static_cast<std::size_t>(c)] = static_cast<double>(view(c & 1, c >> 1 & 1, c >> 2 & 1));
    return v;
}

void check_options(const VerifyOptions& options)
{
    auto bad = [](const std::string& what) {
        throw Error(Status::invalid_argument, "verify: " + what);
    };
    if (options.cells < 0 || options.grids < 0 || options.closed < 0 || options.ties < 0) {
        bad("field counts must be >= 0; got cells " + std::to_string(options.cells) + ", grids " +
            std::to_string(options.grids) + ", closed " + std::to_string(options.closed) + ", ties " +
            std::to_string(options.ties));
    }
    verification::detail::check_methods(options.methods);
    const int min_size = options.closed > 0 ? 3 : 2;
    if ((options.grids > 0 || options.closed > 0 || options.ties > 0) &&
        (options.size < min_size || options.size > 1024)) {
        bad("grid size " + std::to_string(options.size) + " is out of range; expected " +
            std::to_string(min_size) + " to 1024" +
            (options.closed > 0 ? " (closed grids need an interior sample)" : ""));
    }
    if (options.max_failures < 0)
        bad("max_failures must be >= 0; got " + std::to_string(options.max_failures));
}

/// Checks field n of `kind` with every method; `mine` holds this thread's tally per method.
void check_field(const VerifyOptions& options, FieldKind kind, std::int64_t n, std::int64_t order,
                 std::vector<Tally>& mine, std::atomic<std::int64_t>& mismatched)
{
    const auto volume =
        std::make_shared<const Volume>(random_field(kind, n, options.seed, options.size));
    const GridView<float> view = volume->view<float>();
    FieldTopology expected;
    try {
        expected = field_topology(view, 0.0);
    } catch (const Error& e) {
        throw Error(e.status(), field_name(kind, n) + " (seed " + std::to_string(options.seed) +
                                    "): field_topology failed: " + e.what());
    }
    for (std::size_t m = 0; m < options.methods.size(); ++m) {
        Tally& tally = mine[m];
        if (!expected.determined) {
            ++tally.report.undetermined;
            continue;
        }
        ExtractOptions extract_options;
        extract_options.method = options.methods[m];
        extract_options.threads = 1;
        ExtractStats stats;
        Outcome outcome;
        outcome.kind = kind;
        outcome.order = order;
        outcome.name = field_name(kind, n);
        outcome.volume = volume;
        outcome.expected = &expected;
        try {
            outcome.mesh = extract(view, 0.0, extract_options, &stats);
        } catch (const Error& e) {
            outcome.note = std::string("extract failed: ") + e.what();
        }
        if (kind == FieldKind::cell) {
            outcome.subcases.push_back(
                analyze_cell(cell_values(view), 0.0, extract_options.method).subcase);
        } else {
            for (int s = 0; s < kSubcaseCount; ++s) {
                if (stats.cells_per_subcase[static_cast<std::size_t>(s)] > 0 &&
                    verification::detail::is_ambiguous_subcase(s)) {
                    outcome.subcases.push_back(s);
                }
            }
        }
        if (!verification::detail::record(tally, std::move(outcome), options.max_failures)) {
            mismatched.fetch_add(1, std::memory_order_relaxed);
        }
    }
}

} // namespace

VerifyReport verify(const VerifyOptions& options)
{
    check_options(options);
    const std::array<std::int64_t, kFieldKindCount> counts{options.cells, options.grids, options.closed,
                                                           options.ties};
    const std::int64_t total = options.cells + options.grids + options.closed + options.ties;
    const int threads = detail::threads_for(options.threads, total);
    std::vector<std::vector<Tally>> tallies =
        verification::detail::make_tallies(threads, options.methods, false);
    std::atomic<std::int64_t> mismatched{0};
    verification::detail::Ticker tick(options.progress, total, &mismatched);

    VerifyReport report;
    report.seed = options.seed;
    report.size = options.size;
    report.threads = threads;
    for (int k = 0; k < kFieldKindCount; ++k) {
        const auto kind = static_cast<FieldKind>(k);
        const std::int64_t count = counts[static_cast<std::size_t>(k)];
        const double kind_start = tick.seconds();
        const std::int64_t batch = kind == FieldKind::cell ? 64 : 8;
        const std::int64_t first = tick.done_before(); // a field's place in the run orders failures
        verification::detail::run_parallel(
            count, threads, batch, tick, [&](int t, std::int64_t begin, std::int64_t end) {
                for (std::int64_t i = begin; i < end; ++i) {
                    check_field(options, kind, i + 1, first + i,
                                tallies[static_cast<std::size_t>(t)], mismatched);
                }
            });
        report.fields[static_cast<std::size_t>(k)] = count;
        report.kind_seconds[static_cast<std::size_t>(k)] = tick.seconds() - kind_start;
        tick.pass_done(count);
    }
    std::vector<Tally> merged = verification::detail::merge(tallies, options.max_failures);
    report.seconds = tick.seconds();
    verification::detail::finish(merged, options.failures_dir, {}, report);
    tick(0);
    return report;
}

} // namespace cmc33
