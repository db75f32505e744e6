// cmc33 extract --memory-limit SIZE: the volume streamed through a bounded buffer and the mesh
// written as it is made (src/slabs/slabs.hpp), byte for byte what extract writes without it.

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <memory>
#include <span>
#include <string>

#include "atomic_file.hpp"
#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/threads.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "extract_report.hpp"
#include "plane_reader.hpp"
#include "slabs.hpp"

namespace cmc33::cli {

namespace {

/// The records of the mesh into a temporary beside the output, renamed when all are there.
class FileSink final : public slabs::ByteSink {
public:
    explicit FileSink(const std::string& path) : file_(path) {}
    void write_at(std::uint64_t offset, std::span<const std::byte> bytes) override
    {
        file_.write_at(offset, bytes.data(), bytes.size());
    }
    void commit() { file_.commit(); }

private:
    io::detail::PositionalFile file_;
};

/// Runs step(); an Error that does not name `output` is made to name `input`.
template <class Step> decltype(auto) input_step(const std::string& input, const std::string& output, const std::string& doing,
                                                Step&& step)
{
    try {
        return step();
    } catch (const Error& e) {
        end_progress_line();
        if (!output.empty() && std::string(e.what()).find(output) != std::string::npos) throw;
        rethrow_naming(e, input);
    } catch (const std::bad_alloc&) {
        end_progress_line();
        throw Error(Status::too_large, input + ": out of memory while " + doing + " (lower --memory-limit?)");
    }
}

std::int64_t peak_rss_bytes()
{
    rusage usage{};
    ::getrusage(RUSAGE_SELF, &usage);
    return static_cast<std::int64_t>(usage.ru_maxrss) * 1024; // Linux: kilobytes
}

} // namespace


void run_extract_slabs(const ExtractArgs& args)
{
    if (args.repeat > 1) throw UsageError("--repeat does not combine with --memory-limit (each run would read the volume again)");
    if (args.ascii) {
        throw UsageError("--ascii does not combine with --memory-limit, which writes binary .ply (records of fixed "
                         "size, each placed at its offset as it is made)");
    }
    if (!args.output.empty() && io::detail::lower_extension(args.output) != ".ply") {
        throw UsageError("--memory-limit writes binary .ply only (records of fixed size, each placed at its offset as "
                         "it is made), not " + args.output);
    }
    slabs::SlabOptions options;
    options.extract.method = parse_method(args.method);
    options.extract.normals = args.normals;
    options.extract.threads = args.threads;
    options.memory_limit = slabs::parse_size(args.memory_limit);
    options.analyse = !args.no_topology;
    // A bad -o must fail before minutes of work, not after.
    check_mesh_output(args.output, false, args.normals, {args.input});
    const std::optional<io::RawOptions> raw = raw_volume_options(args.input, args.raw);
    io::detail::VolumeLayout layout = named_step(args.input, "reading the volume's header", [&] {
        return io::detail::describe_volume(args.input, raw, read_options(args.input, args.raw));
    });
    apply_space(layout.grid.origin, layout.grid.direction, layout.grid.space, args.raw, args.input);
    const io::detail::Grid& grid = layout.grid;
    // The slabs' records are 32-bit float positions at fixed offsets; a volume far from the origin
    // needs the in-memory run, which writes doubles (--positions).
    if (args.positions == "double") {
        throw UsageError("--positions double does not combine with --memory-limit (its records hold 32-bit floats)");
    }
    if (const double steps = float_steps_per_cell(grid.dims, grid.spacing, grid.origin, grid.direction);
        args.positions == "auto" && steps < kMinFloatStepsPerCell) {
        throw Error(Status::too_large,
                    args.input + ": the volume lies so far from the origin that 32-bit floats resolve only " +
                        sig(steps, 3) + " steps across a cell (at least " + num(kMinFloatStepsPerCell) +
                        " keep the mesh embedded); --memory-limit writes 32-bit floats: run without it "
                        "(double-precision positions), or move the volume's origin nearer 0");
    }

    const auto start = std::chrono::steady_clock::now();
    const Progress progress = fraction_line(args.progress, args.quiet, "extracting the mesh slab by slab");
    options.progress = [&progress](double fraction) {
        if (progress) progress(fraction);
    };
    io::detail::PlaneReader reader(layout);
    slabs::RangeRun run = input_step(args.input, "", "planning the slabs", [&] {
        return slabs::RangeRun(reader, args.iso, options, 0, grid.dims[2]);
    });
    const slabs::RangeTotals totals = input_step(args.input, "", "counting the mesh", [&] {
        const slabs::RangeTotals t = run.count();
        if (t.non_finite > 0) throw Error(Status::non_finite, slabs::non_finite_message(t.non_finite, t.first_non_finite));
        if (t.vertices >= static_cast<std::int64_t>(std::numeric_limits<std::uint32_t>::max())) {
            throw Error(Status::too_large, "the mesh would have " + std::to_string(t.vertices) +
                                               " vertices, more than 32-bit indices can address");
        }
        return t;
    });
    if (totals.triangles == 0) std::cerr << empty_mesh_note(args.input, args.iso, std::nullopt) << '\n';
    const slabs::PlyLayout ply(static_cast<std::uint64_t>(totals.vertices), static_cast<std::uint64_t>(totals.triangles),
                               args.normals);
    std::unique_ptr<FileSink> file;
    if (!args.output.empty()) {
        file = std::make_unique<FileSink>(args.output);
        const std::string header = ply.header();
        file->write_at(0, std::as_bytes(std::span<const char>(header)));
    }
    const slabs::RangeResult result = input_step(args.input, args.output, "extracting the mesh", [&] {
        return run.emit(0, 0, totals.sample_bound, ply, file.get());
    });
    if (file) named_step(args.output, "writing the mesh", [&] { file->commit(); });
    if (progress) progress(1.0);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    ExtractReport report;
    report.volume = volume_json(args.input, grid.dims, grid.type, grid.spacing, grid.origin, grid.direction, grid.space);
    report.dims = grid.dims;
    report.type = grid.type;
    report.method = options.extract.method;
    report.vertices = totals.vertices;
    report.triangles = totals.triangles;
    report.seconds = seconds;
    report.runs_seconds = {seconds};
    report.threads = cmc33::thread_count(args.threads);
    report.stats = totals.stats;
    if (!args.no_topology) {
        report.topology = result.topology.finish();
        report.geometry = slabs::finish_geometry(result.geometry, report.topology, report.welded_known);
    }
    report.extra["memory_limit"] = options.memory_limit;
    report.extra["slabs"] = totals.slabs;
    report.extra["phases_seconds"] = {{"read_wait", totals.wait_seconds + result.wait_seconds},
                                      {"count", totals.count_seconds},
                                      {"emit", result.emit_seconds},
                                      {"write", result.write_seconds},
                                      {"analyse", result.analyse_seconds}};
    report.extra["peak_rss_bytes"] = peak_rss_bytes();
    print_extract_report(args, report);
}

} // namespace cmc33::cli
