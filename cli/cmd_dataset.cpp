// cmc33 dataset: writes the public verification dataset (random fields as NRRD files and the
// invariants their isosurfaces must have), for judging any extractor.

#include <cstdint>
#include <iostream>
#include <limits>
#include <memory>
#include <string>

#include "cmc33/verify.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "dataset.hpp"
#include "plural.hpp"

namespace cmc33::cli {

namespace {

struct DatasetArgs {
    std::string output;
    DatasetOptions options;
    bool progress = false;
    bool quiet = false;
};

void run_dataset(const DatasetArgs& args)
{
    const int min_size = args.options.closed > 0 ? 3 : 2;
    if (args.options.size < min_size || args.options.size > 1024) {
        throw UsageError("--size " + std::to_string(args.options.size) +
                         " is out of range; expected " + std::to_string(min_size) + " to 1024");
    }
    if (args.options.cells + args.options.grids + args.options.closed + args.options.ties == 0) {
        throw UsageError("nothing to write: --cells, --grids, --closed and --ties are all 0");
    }
    DatasetOptions options = args.options;
    options.progress = progress_line(args.progress, args.quiet, "fields");
    DatasetSummary s;
    try {
        s = write_dataset(args.output, options);
    } catch (...) {
        end_progress_line();
        throw;
    }
    std::cout << "wrote " << counted(s.written[0], "cell") << ", " << counted(s.written[1], "grid") << ", "
              << counted(s.written[2], "closed grid") << " and " << counted(s.written[3], "tie grid") << " to " << args.output
              << "/ (manifest.tsv, README.txt) in " << sig(s.seconds, 3) << " s\n";
    const std::int64_t left_out = s.undetermined[0] + s.undetermined[1] + s.undetermined[2] + s.undetermined[3];
    if (left_out != 0) {
        std::cout << "left out " << counted(left_out, "field") << " whose topology is undetermined ("
                  << counted(s.undetermined[0], "cell") << ", " << counted(s.undetermined[1], "grid") << ", "
                  << s.undetermined[2] << " closed, " << counted(s.undetermined[3], "tie")
                  << "): their numbers are missing\n";
    }
    std::cout << "check an extractor with: cmc33 verify --dataset " << args.output
              << " --cmd 'TOOL {in} {iso} {out}'\n";
}

} // namespace

void add_dataset(CLI::App& app)
{
    auto args = std::make_shared<DatasetArgs>();
    CLI::App* cmd = app.add_subcommand(
        "dataset", "Write the verification dataset: random fields and their expected topology");
    cmd->add_option("OUT", args->output,
                    "Folder to write: new, empty, or a previous dataset (then replaced)")
        ->required()
        ->check(non_empty("a folder name"));
    cmd->add_option("--cells", args->options.cells,
                    "Random single cells, 2x2x2 samples (default 10000)")
        ->type_name("N")
        ->check(whole_number(0, std::numeric_limits<std::int64_t>::max()));
    cmd->add_option("--grids", args->options.grids,
                    "Random grids, samples uniform in [-1, 1] (default 10000)")
        ->type_name("N")
        ->check(whole_number(0, std::numeric_limits<std::int64_t>::max()));
    cmd->add_option("--closed", args->options.closed,
                    "Random grids whose surfaces are all closed (default 1000)")
        ->type_name("N")
        ->check(whole_number(0, std::numeric_limits<std::int64_t>::max()));
    cmd->add_option("--ties", args->options.ties,
                    "Random grids of integers -2..2 or -3..3 at iso 0, ties everywhere (default 0)")
        ->type_name("N")
        ->check(whole_number(0, std::numeric_limits<std::int64_t>::max()));
    cmd->add_option("--size", args->options.size, "Samples per axis of the grids (default 5)")
        ->type_name("N")
        ->check(whole_number(2, 1024));
    cmd->add_option("--seed", args->options.seed, "Seed of the random fields (default 1)")
        ->type_name("S")
        ->check(unsigned_number());
    cmd->add_option("--threads", args->options.threads,
                    "Worker threads, 0 = all cores (default 0, at most 1024)")
        ->type_name("N")
        ->check(thread_count());
    auto* progress = cmd->add_flag("--progress", args->progress,
                                   "Progress lines on stderr even when it is not a terminal");
    cmd->add_flag("--quiet", args->quiet, "No progress lines (shown on a terminal by default)")->excludes(progress);
    cmd->footer(
        "Writes OUT/cells/cell-000001.nrrd ..., OUT/grids/..., OUT/closed/..., OUT/ties/... (float NRRD), and\n"
        "OUT/manifest.tsv: one line per file with the isovalue and the Euler characteristic, "
        "Betti\n"
        "numbers and boundary loops its isosurface must have (a sample equal to the isovalue "
        "counts\n"
        "as above it). OUT/README.txt explains the columns. Fields whose topology cannot be "
        "settled\n"
        "are left out. The fields are those `cmc33 verify` draws with the same seed.\n"
        "OUT must be new, empty, or hold a previous dataset and nothing else (it is then replaced).\n"
        "The files are written into OUT/.cmc33-dataset-tmpPID/ and moved into place at the end:\n"
        "a failure or a signal leaves nothing behind.\n"
        "\n"
        "Examples:\n"
        "  cmc33 dataset mc-data\n"
        "  cmc33 verify --dataset mc-data --cmd 'mytool {in} {iso} {out}'");
    cmd->callback([args] { run_dataset(*args); });
}

} // namespace cmc33::cli
