#pragma once
// The verification dataset of `cmc33 dataset` and `cmc33 verify --dataset`: the random fields of
// cmc33::verify() as NRRD files with the invariants their isosurfaces must have, and the check of
// an extractor against them, in-process or as an external shell command. Part of the CLI, not of
// the installed library: it writes folders, forks and runs /bin/sh. The report and per-field
// bookkeeping it fills are the library's (cmc33/verify.hpp, src/verify/verify_detail.hpp).

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "cmc33/extract.hpp"
#include "cmc33/topology.hpp"
#include "cmc33/verify.hpp"

namespace cmc33::cli {

struct DatasetOptions {
    std::int64_t cells = 10000;
    std::int64_t grids = 10000;
    std::int64_t closed = 1000;
    std::int64_t ties = 0;
    std::uint64_t seed = 1;
    int size = 5;
    int threads = 0;
    ProgressCallback progress;
};

struct DatasetSummary {
    std::array<std::int64_t, kFieldKindCount> written{};      ///< files written, per kind
    std::array<std::int64_t, kFieldKindCount> undetermined{}; ///< fields left out, per kind
    double seconds = 0;
};

/// Writes `dir/cells/cell-000001.nrrd`, `dir/grids/grid-000001.nrrd`, `dir/closed/...` (float
/// NRRD; the same fields verify() draws with the same seed), `dir/manifest.tsv` and
/// `dir/README.txt`. Fields whose topology is undetermined are left out (their numbers are
/// skipped). `dir` is created if it does not exist; else it must be empty or hold a previous
/// dataset and nothing else (manifest.tsv, README.txt and the files the manifest lists), which is
/// replaced. The files are written into the hidden folder `dir/.cmc33-dataset-tmpPID/` and moved
/// into place at the end: on an error nothing is left (and `dir` is removed if it was created).
/// @throws Error{invalid_argument} if dir is empty (""), not a folder or holds other files, for a
///         negative count or a bad size; Error{io_error} from the writers.
DatasetSummary write_dataset(const std::filesystem::path& dir, const DatasetOptions& options);

/// One line of manifest.tsv.
struct ManifestEntry {
    std::string file; ///< relative to the dataset folder, '/' separated
    double iso = 0;
    FieldTopology expected; ///< determined = true
    std::string subcase;    ///< cmc33's subcase name for cells, "-" for other fields
    int line = 0;           ///< line number in manifest.tsv
};

/// Reads `dir/manifest.tsv`. @throws Error{io_error} if it cannot be read, Error{bad_format}
/// naming the file and the line for a line that does not parse.
std::vector<ManifestEntry> read_manifest(const std::filesystem::path& dir);

struct DatasetVerifyOptions {
    std::vector<Method> methods{Method::cmc33}; ///< in-process extractors, if command is empty
    /// An external extractor instead: a shell command with the placeholders {in} (the volume),
    /// {iso} and {out} (the mesh to write). {out} is a fresh temporary path ending in .ply, unless
    /// the template writes an extension right after it ("{out}.obj", ".off", ".ply", ".stl"), in
    /// which case {out} is the path without extension. Paths are single-quoted for the shell.
    std::string command;
    /// The command is killed (its whole process group) after this many seconds on one file; the
    /// file then counts as an error. <= 0: no limit.
    double timeout_seconds = 60;
    int threads = 0;
    std::filesystem::path failures_dir; ///< as in VerifyOptions
    int max_failures = 20;
    ProgressCallback progress;
};

/// Checks every manifest entry: extracts it (in-process, or by running the command with
/// /bin/sh -c in a process group of its own and reading its mesh with io::read_mesh) and compares with the manifest's
/// invariants. A command that exits non-zero or writes no readable mesh counts as a mismatch
/// (MethodReport::errors; the reason is in failures.tsv). Subcases are counted as in verify()
/// (a 2x2x2 field is a cell), under the method, or under cmc33 for a command. Kinds: a file named
/// cell-* or with a subcase is a cell, closed-* a closed grid, anything else a grid.
/// @throws Error from read_manifest and read_volume (a missing or broken dataset file).
VerifyReport verify_dataset(const std::filesystem::path& dir, const DatasetVerifyOptions& options);

/// A command line for one field, and the mesh file it writes.
struct ExternalCommand {
    std::string shell;            ///< for /bin/sh -c
    std::filesystem::path output; ///< the mesh file the command is expected to write
};

/// The template with {in}, {iso} and {out} replaced, every occurrence, paths single-quoted.
/// {out} is `out_base` + ".ply", or `out_base` alone where the template writes ".ply", ".obj",
/// ".off" or ".stl" right after it. @throws Error{invalid_argument} if {in} or {out} is missing.
ExternalCommand expand_command(std::string_view command_template, const std::filesystem::path& in, double iso,
                               const std::filesystem::path& out_base);

} // namespace cmc33::cli
