// cmc33-mpi: `cmc33 extract` over MPI ranks, run as `mpirun -n P cmc33-mpi extract IN -i ISO -o OUT.ply`.
// A separate executable, so that neither the cmc33 CLI nor the library depends on MPI.
//
// Rank r of P takes the sample planes [nz r / P, nz (r + 1) / P) (src/slabs: it reads only those
// and the two planes on either side, by offset; within --memory-limit, slab by slab). Then:
//   1. count: each rank counts its planes; MPI_Exscan of the vertex and triangle counts gives each
//      rank its first global ids (the ids of passes.hpp run plane by plane, so ranks in plane
//      order with consecutive first ids give exactly extract()'s numbering; a rank's last
//      triangles use the first vertices of the next rank, which owns the plane they share);
//      MPI_Allreduce gives the totals, the bound on |sample| that scales normals (so every rank's
//      normals are extract()'s), the subcase counts and the non-finite samples;
//   2. emit: the ranks write one binary PLY together: rank 0 the header, every rank its vertex
//      and face records at the offsets of its first ids, in rounds of MPI_File_write_at_all (the
//      same number on every rank, known after step 1), into a temporary that rank 0 renames;
//   3. topology: each rank's SeamTopology (its slabs' components, open at its two seams) is
//      merged up a binomial tree (log2 P rounds, messages the size of one seam); the geometric
//      counts are summed. Rank 0 prints what `cmc33 extract` prints, plus the ranks' figures.
// No rank holds more than its slab of samples and its slab's mesh.
//
// Errors: a failing step is agreed on by every rank (the lowest failing rank's message), so that
// no rank waits in a collective call the others left; rank 0 prints one line and exits 1 (2 for
// usage), which mpirun returns; the other ranks exit 0; the temporary file is removed.

#include <mpi.h>
#include <sys/resource.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <new>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "atomic_file.hpp"
#include "cmc33/error.hpp"
#include "cmc33/mesh.hpp"
#include "cmc33/threads.hpp"
#include "cmc33/version.hpp"
#include "common.hpp"
#include "extract_report.hpp"
#include "plane_reader.hpp"
#include "portability.hpp"
#include "slabs.hpp"

namespace cmc33::mpi {
namespace {

using cli::ExtractArgs;
using cli::Json;

constexpr int kExitFailure = 1;
constexpr int kExitUsage = 2;

struct World {
    int rank = 0, size = 1;
};

/// A failure every rank knows about: rank 0 prints it, every rank exits with `code`.
struct Failed {
    int code;
    std::string message;
};

/// Every rank says whether its step failed; if one did, every rank throws Failed with the
/// message of the lowest rank that failed.
void agree(const World& w, int code, std::string message)
{
    const int mine = code != 0 ? w.rank : w.size;
    int lowest = w.size;
    MPI_Allreduce(&mine, &lowest, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (lowest == w.size) return;
    MPI_Bcast(&code, 1, MPI_INT, lowest, MPI_COMM_WORLD);
    long long length = static_cast<long long>(message.size());
    MPI_Bcast(&length, 1, MPI_LONG_LONG, lowest, MPI_COMM_WORLD);
    message.resize(static_cast<std::size_t>(length));
    MPI_Bcast(message.data(), static_cast<int>(length), MPI_CHAR, lowest, MPI_COMM_WORLD);
    throw Failed{code, message};
}

/// Runs step() on every rank, then agree()s on the outcome.
template <class Step> void together(const World& w, Step&& step)
{
    int code = 0;
    std::string message;
    try {
        step();
    } catch (const Failed&) {
        throw;
    } catch (const cli::UsageError& e) {
        code = kExitUsage, message = e.what();
    } catch (const Error& e) {
        code = kExitFailure, message = e.what();
    } catch (const std::bad_alloc&) {
        code = kExitFailure, message = "out of memory on rank " + std::to_string(w.rank) + " (lower --memory-limit?)";
    } catch (const std::exception& e) {
        code = kExitFailure, message = e.what();
    }
    agree(w, code, std::move(message));
}

std::string mpi_error(int code)
{
    char text[MPI_MAX_ERROR_STRING];
    int length = 0;
    MPI_Error_string(code, text, &length);
    return std::string(text, static_cast<std::size_t>(length));
}

/// The PLY written by every rank: MPI-IO collective writes at offsets, in rounds.
class MpiFile final : public slabs::ByteSink {
public:
    MpiFile(const std::string& path, const std::string& output) : output_(output)
    {
        const int rc = MPI_File_open(MPI_COMM_WORLD, path.c_str(), MPI_MODE_CREATE | MPI_MODE_WRONLY, MPI_INFO_NULL, &file_);
        if (rc != MPI_SUCCESS) {
            file_ = MPI_FILE_NULL;
            throw Error(Status::io_error, output + ": cannot create the file (MPI-IO: " + mpi_error(rc) + ")");
        }
    }
    ~MpiFile() { close(); }
    MpiFile(const MpiFile&) = delete;
    MpiFile& operator=(const MpiFile&) = delete;

    /// One collective round: this rank's bytes at `offset` (none for a rank that has no more).
    void write_at(std::uint64_t offset, std::span<const std::byte> bytes) override
    {
        ++rounds_;
        MPI_Status status;
        const int rc = MPI_File_write_at_all(file_, static_cast<MPI_Offset>(offset), bytes.data(), static_cast<int>(bytes.size()),
                                             MPI_BYTE, &status);
        if (rc != MPI_SUCCESS && error_.empty()) error_ = output_ + ": writing failed at byte " + std::to_string(offset) + " (MPI-IO: " + mpi_error(rc) + ")";
        if (!error_.empty()) throw Error(Status::io_error, error_);
    }
    /// Empty rounds until `total`, so that every rank has made as many collective calls.
    void pad(std::int64_t total)
    {
        while (rounds_ < total) {
            ++rounds_;
            MPI_Status status;
            const int rc = MPI_File_write_at_all(file_, 0, nullptr, 0, MPI_BYTE, &status);
            if (rc != MPI_SUCCESS && error_.empty()) error_ = output_ + ": writing failed (MPI-IO: " + mpi_error(rc) + ")";
        }
    }
    /// Collective. @throws Error{io_error} if this rank's writes or the close failed
    void close()
    {
        if (file_ == MPI_FILE_NULL) return;
        const int rc = MPI_File_close(&file_);
        file_ = MPI_FILE_NULL;
        if (rc != MPI_SUCCESS && error_.empty()) error_ = output_ + ": closing failed (MPI-IO: " + mpi_error(rc) + ")";
    }
    const std::string& error() const { return error_; }

private:
    std::string output_;
    MPI_File file_ = MPI_FILE_NULL;
    std::int64_t rounds_ = 0;
    std::string error_;
};

std::int64_t peak_rss_bytes()
{
    rusage usage{};
    ::getrusage(RUSAGE_SELF, &usage);
    return static_cast<std::int64_t>(usage.ru_maxrss) * 1024;
}

/// Runs step(); an Error not naming `input` (or `output`) is made to name `input`.
template <class Step> decltype(auto) naming(const std::string& input, const std::string& output, Step&& step)
{
    try {
        return step();
    } catch (const Error& e) {
        cli::end_progress_line();
        if (!output.empty() && std::string(e.what()).find(output) != std::string::npos) throw;
        cli::rethrow_naming(e, input);
    }
}

/// The binomial tree of SeamTopology summaries: rank r receives from r + 2^d while r is a
/// multiple of 2^(d + 1), sends to r - 2^d in the round where it is not; rank 0 ends with all.
detail::SeamTopology reduce_topology(const World& w, detail::SeamTopology mine)
{
    for (int step = 1; step < w.size; step *= 2) {
        if (w.rank % (2 * step) == step) {
            const std::vector<std::byte> bytes = mine.serialize();
            const long long n = static_cast<long long>(bytes.size());
            MPI_Send(&n, 1, MPI_LONG_LONG, w.rank - step, 0, MPI_COMM_WORLD);
            MPI_Send(bytes.data(), static_cast<int>(n), MPI_BYTE, w.rank - step, 1, MPI_COMM_WORLD);
            return mine;
        }
        if (w.rank % (2 * step) == 0 && w.rank + step < w.size) {
            long long n = 0;
            MPI_Recv(&n, 1, MPI_LONG_LONG, w.rank + step, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            std::vector<std::byte> bytes(static_cast<std::size_t>(n));
            MPI_Recv(bytes.data(), static_cast<int>(n), MPI_BYTE, w.rank + step, 1, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            mine = detail::SeamTopology::merge(mine, detail::SeamTopology::deserialize(bytes));
        }
    }
    return mine;
}

/// The geometric counts summed on rank 0, with the smallest intersecting pairs of all ranks.
slabs::GeometryPart reduce_geometry(const World& w, const slabs::GeometryPart& mine)
{
    std::array<long long, 4> counts{mine.positions, mine.coincident_vertices, mine.zero_area_triangles, mine.intersecting_pairs};
    std::array<long long, 4> sums{};
    MPI_Reduce(counts.data(), sums.data(), 4, MPI_LONG_LONG, MPI_SUM, 0, MPI_COMM_WORLD);
    constexpr int kPairs = static_cast<int>(slabs::GeometryPart::kExamples);
    std::vector<long long> pairs(1 + 2 * kPairs, -1);
    pairs[0] = static_cast<long long>(mine.examples.size());
    for (std::size_t i = 0; i < mine.examples.size(); ++i) {
        pairs[1 + 2 * i] = mine.examples[i][0];
        pairs[2 + 2 * i] = mine.examples[i][1];
    }
    std::vector<long long> all(w.rank == 0 ? pairs.size() * static_cast<std::size_t>(w.size) : 0);
    MPI_Gather(pairs.data(), 1 + 2 * kPairs, MPI_LONG_LONG, all.data(), 1 + 2 * kPairs, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
    slabs::GeometryPart whole;
    if (w.rank != 0) return whole;
    whole.positions = sums[0], whole.coincident_vertices = sums[1], whole.zero_area_triangles = sums[2], whole.intersecting_pairs = sums[3];
    for (int r = 0; r < w.size; ++r) {
        const long long* p = &all[static_cast<std::size_t>(r) * pairs.size()];
        slabs::GeometryPart part;
        for (long long i = 0; i < p[0]; ++i) part.examples.push_back({p[1 + 2 * i], p[2 + 2 * i]});
        whole.add(part);
    }
    return whole;
}

/// Every rank's value, on rank 0.
std::vector<long long> gather_counts(const World& w, long long value)
{
    std::vector<long long> all(w.rank == 0 ? static_cast<std::size_t>(w.size) : 0);
    MPI_Gather(&value, 1, MPI_LONG_LONG, all.data(), 1, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
    return all;
}

std::vector<double> gather_seconds(const World& w, double value)
{
    std::vector<double> all(w.rank == 0 ? static_cast<std::size_t>(w.size) : 0);
    MPI_Gather(&value, 1, MPI_DOUBLE, all.data(), 1, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    return all;
}

double max_over_ranks(double value)
{
    double largest = 0;
    MPI_Reduce(&value, &largest, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
    return largest;
}

void run_extract(const World& w, const ExtractArgs& args)
{
    const double t0 = MPI_Wtime();
    slabs::SlabOptions options;
    std::optional<io::detail::VolumeLayout> layout;
    std::unique_ptr<io::detail::PlaneReader> reader;
    std::unique_ptr<slabs::RangeRun> run;
    Progress progress;
    together(w, [&] {
        if (!args.output.empty() && io::detail::lower_extension(args.output) != ".ply") {
            throw cli::UsageError("cmc33-mpi writes binary .ply only (each rank places its records at their offsets), not " +
                                  args.output);
        }
        options.extract.method = parse_method(args.method);
        if (options.extract.method == Method::cmc33_paper) { // a usage conflict (exit 2), not the passes' "use extract()"
            throw cli::UsageError("--method cmc33-paper does not run over ranks: its refinement (Custodio et al. 2013, "
                                  "Sec. 6.2) inserts sample planes into the whole grid, which slabs cannot; run `cmc33 "
                                  "extract` without --memory-limit, or another method");
        }
        options.extract.normals = args.normals;
        options.extract.threads = args.threads;
        options.memory_limit = args.memory_limit.empty() ? 0 : slabs::parse_size(args.memory_limit);
        options.analyse = !args.no_topology;
        if (w.rank == 0) cli::check_mesh_output(args.output, false, args.normals, {args.input});
        const std::optional<io::RawOptions> raw = cli::raw_volume_options(args.input, args.raw);
        layout = cli::named_step(args.input, "reading the volume's header",
                                 [&] { return io::detail::describe_volume(args.input, raw); });
        if (w.rank == 0) {
            progress = cli::fraction_line(args.progress, args.quiet,
                                          "rank 0 of " + std::to_string(w.size) + ": extracting the mesh slab by slab");
        }
        options.progress = [&progress](double fraction) {
            if (progress) progress(fraction);
        };
        const auto planes = slabs::rank_planes(layout->grid.dims[2], w.rank, w.size);
        reader = std::make_unique<io::detail::PlaneReader>(*layout);
        run = naming(args.input, "", [&] { return std::make_unique<slabs::RangeRun>(*reader, args.iso, options, planes[0], planes[1]); });
    });
    const io::detail::Grid& grid = layout->grid;

    // 1. count, and what the ranks must know of each other
    const double t1 = MPI_Wtime();
    slabs::RangeTotals mine;
    together(w, [&] { mine = naming(args.input, "", [&] { return run->count(); }); });
    const double t2 = MPI_Wtime();
    long long counts[2] = {mine.vertices, mine.triangles}, first[2] = {0, 0}, totals[2] = {0, 0};
    MPI_Exscan(counts, first, 2, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
    if (w.rank == 0) first[0] = first[1] = 0; // undefined on rank 0
    MPI_Allreduce(counts, totals, 2, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
    double bound = 0;
    MPI_Allreduce(&mine.sample_bound, &bound, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    std::array<long long, kSubcaseCount> subcases{}, cells{};
    for (std::size_t s = 0; s < subcases.size(); ++s) cells[s] = mine.stats.cells_per_subcase[s];
    MPI_Allreduce(cells.data(), subcases.data(), kSubcaseCount, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
    long long non_finite = 0, slab_count = 0;
    MPI_Allreduce(&mine.non_finite, &non_finite, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
    MPI_Allreduce(&mine.slabs, &slab_count, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
    const long long nx = grid.dims[0], ny = grid.dims[1];
    long long first_bad = mine.non_finite > 0 ? mine.first_non_finite[0] + nx * (mine.first_non_finite[1] + ny * mine.first_non_finite[2])
                                              : std::numeric_limits<long long>::max();
    long long lowest_bad = 0;
    MPI_Allreduce(&first_bad, &lowest_bad, 1, MPI_LONG_LONG, MPI_MIN, MPI_COMM_WORLD);
    if (non_finite > 0) {
        const Index3 at{lowest_bad % nx, lowest_bad / nx % ny, lowest_bad / (nx * ny)};
        throw Failed{kExitFailure, args.input + ": " + slabs::non_finite_message(non_finite, at)};
    }
    if (totals[0] >= static_cast<long long>(std::numeric_limits<std::uint32_t>::max())) {
        throw Failed{kExitFailure, args.input + ": the mesh would have " + std::to_string(totals[0]) +
                                       " vertices, more than 32-bit indices can address"};
    }
    const slabs::PlyLayout ply(static_cast<std::uint64_t>(totals[0]), static_cast<std::uint64_t>(totals[1]), args.normals);
    long long writes = slabs::write_count(mine.vertices, mine.triangles, ply.normals(), slabs::piece_bytes(options.memory_limit));
    long long rounds = 0;
    MPI_Allreduce(&writes, &rounds, 1, MPI_LONG_LONG, MPI_MAX, MPI_COMM_WORLD);
    ++rounds; // the header's

    // 2. emit into one file: a temporary beside the output (rank 0 names and renames it)
    std::optional<io::detail::Temporary> temporary; // destroyed last: removes the file unless renamed
    std::unique_ptr<MpiFile> file;
    if (!args.output.empty()) {
        std::string temp;
        together(w, [&] {
            if (w.rank == 0) {
                temp = io::detail::temporary_beside(args.output).string();
                temporary.emplace(temp, [] {}); // MPI-IO creates it; registered first, for a signal
            }
        });
        long long length = static_cast<long long>(temp.size());
        MPI_Bcast(&length, 1, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
        temp.resize(static_cast<std::size_t>(length));
        MPI_Bcast(temp.data(), static_cast<int>(length), MPI_CHAR, 0, MPI_COMM_WORLD);
        together(w, [&] { file = std::make_unique<MpiFile>(temp, args.output); });
    }
    const double t3 = MPI_Wtime();
    slabs::RangeResult result;
    together(w, [&] {
        try {
            if (file) {
                const std::string header = ply.header();
                file->write_at(0, w.rank == 0 ? std::as_bytes(std::span<const char>(header)) : std::span<const std::byte>());
            }
            result = naming(args.input, args.output, [&] { return run->emit(first[0], first[1], bound, ply, file.get()); });
        } catch (...) {
            if (file) file->pad(rounds); // the others are still writing: take part in every round
            throw;
        }
        if (file) file->pad(rounds);
    });
    if (file) {
        together(w, [&] {
            file->close();
            if (!file->error().empty()) throw Error(Status::io_error, file->error());
        });
        together(w, [&] {
            if (w.rank == 0) {
                temporary->commit([&] {
                    std::error_code ec;
                    std::filesystem::rename(temporary->path(), args.output, ec);
                    if (ec) throw Error(Status::io_error, args.output + ": cannot rename the temporary file: " + ec.message());
                });
            }
        });
    }
    if (progress) progress(1.0);
    const double t4 = MPI_Wtime();

    // 3. topology and geometry of the whole mesh
    cli::ExtractReport report;
    detail::SeamTopology topology;
    slabs::GeometryPart geometry;
    if (!args.no_topology) {
        topology = reduce_topology(w, result.topology);
        geometry = reduce_geometry(w, result.geometry);
    }
    const double t5 = MPI_Wtime();
    const std::vector<long long> rss = gather_counts(w, peak_rss_bytes());
    const std::vector<long long> read = gather_counts(w, mine.planes_read + result.planes_read);
    // where each rank's time went (seconds): reading not hidden by the work, counting, emitting,
    // writing, the slabs' topology and geometry, and the reduction over the ranks
    Json per_rank = Json::object();
    per_rank["read_wait"] = gather_seconds(w, mine.wait_seconds + result.wait_seconds);
    per_rank["count"] = gather_seconds(w, mine.count_seconds);
    per_rank["emit"] = gather_seconds(w, result.emit_seconds);
    per_rank["write"] = gather_seconds(w, result.write_seconds);
    per_rank["analyse"] = gather_seconds(w, result.analyse_seconds);
    per_rank["reduce"] = gather_seconds(w, t5 - t4);
    const double setup = max_over_ranks(t1 - t0), count = max_over_ranks(t2 - t1), emit = max_over_ranks(t4 - t3),
                 reduce = max_over_ranks(t5 - t4), total = max_over_ranks(t5 - t0);
    if (w.rank != 0) return;
    report.volume = cli::volume_json(args.input, grid.dims, grid.type, grid.spacing, grid.origin, grid.direction, grid.space);
    report.dims = grid.dims;
    report.type = grid.type;
    report.method = options.extract.method;
    report.vertices = totals[0];
    report.triangles = totals[1];
    report.seconds = total;
    report.runs_seconds = {total};
    report.threads = cmc33::thread_count(args.threads); // per rank
    for (std::size_t s = 0; s < subcases.size(); ++s) report.stats.cells_per_subcase[s] = subcases[s];
    if (!args.no_topology) {
        report.topology = topology.finish();
        report.geometry = slabs::finish_geometry(geometry, report.topology, report.welded_known);
    }
    Json read_bytes = Json::array();
    for (const long long planes : read) read_bytes.push_back(planes * static_cast<long long>(layout->plane_bytes()));
    report.extra["ranks"] = w.size;
    report.extra["memory_limit"] = options.memory_limit == 0 ? Json(nullptr) : Json(options.memory_limit);
    report.extra["slabs"] = slab_count;
    report.extra["phases_seconds"] = {{"setup", setup}, {"count", count}, {"emit_and_write", emit}, {"topology", reduce}};
    report.extra["rank_seconds"] = per_rank;
    report.extra["peak_rss_bytes"] = rss;
    report.extra["read_bytes"] = read_bytes;
    cli::print_extract_report(args, report);
}

/// CLI11 reads "-5" as a value but "-.5" as an option: spell such numbers "-0.5" (as cmc33 does).
std::vector<std::string> arguments(int argc, char** argv)
{
    std::vector<std::string> args;
    for (int i = argc - 1; i >= 1; --i) {
        std::string a = argv[i];
        if (a.size() >= 3 && a[0] == '-' && a[1] == '.' && a[2] >= '0' && a[2] <= '9') a.insert(1, "0");
        args.push_back(std::move(a));
    }
    return args;
}

void add_extract(CLI::App& app, ExtractArgs& args)
{
    CLI::App* cmd = app.add_subcommand("extract", "Extract the isosurface f = ISO of a volume over the MPI ranks, into one .ply");
    cmd->add_option("INPUT", args.input, "Volume: .nrrd .nhdr .mhd .mha .vtk, or headerless raw with --dims/--type")
        ->required()
        ->check(cli::non_empty("a volume file"));
    cmd->add_option("-i,--iso", args.iso, "Isovalue (a sample equal to it counts as above)")->required()->check(cli::number_check());
    cmd->add_option("-o,--output", args.output, "Write the mesh: binary .ply (every rank writes its part)")
        ->type_name("OUT.ply")
        ->check(cli::non_empty("a mesh file name"));
    cmd->add_option("--method", args.method, "cmc33 (default), mc33-lewiner or mc")->type_name("NAME")->check(cli::method_validator());
    cmd->add_flag("--normals", args.normals, "Per-vertex normals from the field's gradient");
    cmd->add_option("--threads", args.threads, "Worker threads per rank (default 1; 0 = all cores of the node)")
        ->type_name("N")
        ->check(cli::thread_count());
    cmd->add_flag("--json", args.json, "Print one JSON object (rank 0) instead of the summary line");
    cmd->add_flag("--no-topology", args.no_topology, "Skip the mesh's topology and geometry (JSON: null)");
    cmd->add_option("--memory-limit", args.memory_limit,
                    "Per rank: read the rank's planes and write its mesh slab by slab within SIZE bytes (256M, 2G)")
        ->type_name("SIZE")
        ->check(cli::memory_size());
    auto* progress = cmd->add_flag("--progress", args.progress, "Progress lines of rank 0 on stderr even when it is not a terminal");
    cmd->add_flag("--quiet", args.quiet, "No progress line")->excludes(progress);
    cli::add_raw_volume_options(*cmd, args.raw);
    cmd->footer(
        "Rank r of P reads only its share of the volume's z planes (by offset; gzip streams are\n"
        "inflated from their start, every rank up to its planes), extracts them, and all ranks write\n"
        "one binary PLY together at offsets from prefix sums of their counts: byte for byte the file\n"
        "`cmc33 extract` writes, for every P. Rank 0 prints what `cmc33 extract` prints (topology\n"
        "from a union-find merged across the ranks' seams), and with --json the ranks' figures.\n"
        "\n"
        "Examples:\n"
        "  mpirun -n 4 cmc33-mpi extract aneurism.nrrd --iso 80 -o vessels.ply\n"
        "  srun -n 256 cmc33-mpi extract scan_8192.nhdr -i 900 -o bone.ply --threads 4 --json\n"
        "  mpirun -n 2 cmc33-mpi extract big.raw --dims 2048 2048 1024 --type uint8 -i 128 --memory-limit 1G");
}

/// Rank 0 prints the failure and returns its code; the other ranks return 0, so that mpirun
/// reports rank 0's code and does not kill ranks that are still finishing.
int report_failure(const World& w, const Failed& f)
{
    if (w.rank != 0) return 0;
    std::cout.flush();
    std::string line = f.message;
    for (char& c : line) c = c == '\n' || c == '\r' ? ' ' : c;
    std::cerr << "cmc33-mpi: " << line << '\n';
    if (f.code == kExitUsage) std::cerr << "Run with --help for more information.\n";
    return f.code;
}

} // namespace
} // namespace cmc33::mpi

int main(int argc, char** argv)
{
    using namespace cmc33::mpi;
    cmc33::cli::install_signal_cleanup(); // before MPI starts its threads: they inherit the mask
    cmc33::set_huge_page_advice(!cmc33::detail::balloon_reports_free_memory()); // as cmc33's main
    int provided = 0;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided); // only the main thread calls MPI
    World w;
    MPI_Comm_rank(MPI_COMM_WORLD, &w.rank);
    MPI_Comm_size(MPI_COMM_WORLD, &w.size);
    int code = 0;
    {
        CLI::App app("cmc33-mpi " CMC33_VERSION_STRING ": cmc33 extract over MPI ranks, one binary PLY written together,\n"
                     "byte for byte the single-process file.",
                     "cmc33-mpi");
        app.set_version_flag("--version", "cmc33-mpi " CMC33_VERSION_STRING, "Print the version and exit");
        app.require_subcommand(1);
        app.get_formatter()->column_width(36);
        ExtractArgs args;
        args.threads = 1;
        add_extract(app, args);
        app.footer("Exit codes: 0 success, 1 bad input or failure, 2 bad usage.\n"
                   "Example:\n"
                   "  mpirun -n 4 cmc33-mpi extract head.nrrd --iso 80 -o head.ply");
        try {
            try {
                app.parse(arguments(argc, argv));
            } catch (const CLI::CallForHelp& e) {
                code = w.rank == 0 ? app.exit(e) : 0;
                throw Failed{-1, ""};
            } catch (const CLI::CallForAllHelp& e) {
                code = w.rank == 0 ? app.exit(e) : 0;
                throw Failed{-1, ""};
            } catch (const CLI::CallForVersion& e) {
                code = w.rank == 0 ? app.exit(e) : 0;
                throw Failed{-1, ""};
            } catch (const CLI::ParseError& e) {
                throw Failed{kExitUsage, e.what()};
            }
            run_extract(w, args);
            if (w.rank == 0) {
                std::cout.flush();
                if (!std::cout) throw Failed{kExitFailure, "cannot write to standard output"};
            }
        } catch (const Failed& f) {
            if (f.code >= 0) code = report_failure(w, f);
        }
    }
    MPI_Finalize();
    return code;
}
