#pragma once
// What the commands share: usage errors, the raw-volume options, number formatting, JSON helpers.

#include <cstdint>
#include <filesystem>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/io.hpp"
#include "cmc33/mesh.hpp"
#include "cmc33/topology.hpp"
#include "cmc33/verify.hpp"
#include "cmc33/volume.hpp"

namespace cmc33::cli {

/// JSON objects keep their keys in insertion order, so output reads in a fixed, logical order.
using Json = nlohmann::ordered_json;

/// A usage mistake found after CLI11 parsed the line (exit 2, like CLI11's own parse errors).
class UsageError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// --dims, --type, --spacing, --endian, --header-bytes: what a headerless raw file cannot say.
struct RawVolumeOptions {
    std::vector<std::int64_t> dims;
    std::string type;
    std::vector<double> spacing;
    std::string endian = "little";
    std::uint64_t header_bytes = 0;
    std::vector<CLI::Option*> given; ///< the options, to tell whether any was on the line
    // What files with a header leave open (io::ReadOptions), and the world space to write in.
    std::optional<std::int64_t> frame; ///< --frame N: a 4-D file's frame
    std::string array;                 ///< --array NAME: a .vti's point-data array
    std::vector<double> origin;        ///< --origin X Y Z: a .npy's first sample (with --spacing)
    std::string space;                 ///< --space ras|lps: the world space of positions (empty: the file's)
    std::string series;                ///< --series UID: the DICOM series to read

    bool any_given() const;
};

/// Adds the raw-volume options to `command`, in their own help group.
void add_raw_volume_options(CLI::App& command, RawVolumeOptions& raw);

/// Reads a volume. Files with a known header take no raw options (UsageError if some are given);
/// other files need --dims and --type (UsageError if missing). @throws Error from the readers.
Volume load_volume(const std::string& path, const RawVolumeOptions& raw);

/// What load_volume() reads `path` with: nullopt for a file with a header, the raw options
/// otherwise (UsageError and Error as load_volume()).
std::optional<io::RawOptions> raw_volume_options(const std::string& path, const RawVolumeOptions& raw);
/// --frame, --array, and --spacing/--origin for a .npy, as the readers take them.
io::ReadOptions read_options(const std::string& path, const RawVolumeOptions& raw);
/// --space applied to a frame read from a header (a layout of describe_volume()); nothing without --space.
void apply_space(Vec3& origin, Mat3& direction, std::string& space, const RawVolumeOptions& raw, const std::string& path);

/// A CLI11 validator accepting the names cmc33::parse_method accepts.
CLI::Validator method_validator();

/// The whole text is one decimal number ("-3.5", "1e-3", "+2", "nan", "inf"; not "", "12abc",
/// "0x10"): CLI11 alone reads "" as 0 and hex as a number. NaN and infinity pass: the library
/// refuses them where they matter, naming the input.
CLI::Validator number_check();
/// The whole text is a whole number in [min, max] (message "expected a whole number from 0 to
/// 1024, got '100000'"; ">= min" when max is the largest int64).
CLI::Validator whole_number(std::int64_t min, std::int64_t max);
/// The whole text is one decimal number that `accept` takes (message "expected <expected>, got
/// '<text>'"); `name` is what --help shows.
CLI::Validator real_number(const std::string& expected, bool (*accept)(double), const std::string& name);
/// A whole number >= 0 that fits 64 bits unsigned (--seed, --header-bytes).
CLI::Validator unsigned_number();
/// The value is not empty (an unset shell variable in `-o "$OUT"`).
CLI::Validator non_empty(const std::string& what);

/// --threads above this is refused before any work (the OS refuses such counts late, midway).
inline constexpr std::int64_t kMaxThreads = 1024;
/// --threads N: 0 (all cores) to kMaxThreads.
CLI::Validator thread_count();
/// --memory-limit SIZE: bytes, or a whole number with k, M, G or T (slabs::parse_size's message).
CLI::Validator memory_size();

/// Installs the cleanup of temporaries on SIGINT, SIGTERM and SIGHUP (cli/signals.cpp). Call
/// first in main(), before any thread starts.
void install_signal_cleanup();

/// UsageError if `output` names the same file as one of `inputs` or one of the data files their
/// headers name (io::volume_files), also through a link or another spelling: a command must never
/// overwrite what it reads.
void check_not_an_input(const std::string& output, const std::vector<std::string>& inputs);
/// Error{io_error} naming the folder unless `dir` is an existing folder in which a file can be
/// created (tried: root passes a permission test on a read-only file system).
void check_writable_folder(const std::filesystem::path& dir, const std::string& output);

/// Shortest decimal text that reads back as the same double: "80", "0.1", "1e-07", "nan".
std::string num(double value);
/// Same, for a float: 0.3f prints "0.3" (not the double expansion of the float).
std::string num(float value);
/// The double nearest to the shortest decimal text of `value`: 0.3f -> 0.3, for JSON output.
double pretty(float value);
/// printf("%.*g"): `digits` significant digits.
std::string sig(double value, int digits);

/// The note printed on stderr when an extraction gives no triangles (a valid result, exit 0, but
/// usually an isovalue on the wrong scale): names the input and the isovalue, and where `range`
/// (the samples' smallest and largest) is known, says whether the isovalue lies outside it.
std::string empty_mesh_note(const std::string& input, double iso, const std::optional<std::pair<double, double>>& range);
/// "256x256x256".
std::string dims_text(const Index3& dims);
/// "(1, 0.5, 2)".
std::string vec_text(const Vec3& v);

/// A JSON number, or null for NaN and infinities (JSON has no such numbers).
Json json_number(double value);
/// {"file", "dims", "type", "spacing", "origin"}.
Json volume_json(const std::string& path, const Volume& volume);
/// The same from a header's values (a volume read slab by slab has no Volume).
Json volume_json(const std::string& path, const Index3& dims, ScalarType type, const Vec3& spacing, const Vec3& origin,
                 const Mat3& direction, const std::string& space);
/// {"euler", "betti", "components", "closed_components", "boundary_edges", "boundary_loops",
///  "nonmanifold_edges", "nonmanifold_vertices", "degenerate_triangles", "closed", "oriented"}.
Json topology_json(const MeshTopology& topology);
/// The mesh in space (mesh_geometry): embedded, coincident vertices, zero-area triangles,
/// intersecting pairs (with examples) and the topology of the position-welded mesh.
Json geometry_json(const MeshGeometry& geometry);

/// Writes one JSON object to stdout, indented, with a final newline.
void print_json(const Json& json);

/// If `output` is not empty: throws, before any work is done, what write_mesh would throw for
/// it (unknown extension: the library's Error; a missing or non-writable directory, a directory,
/// a device, a read-only file: Error{io_error}), and a UsageError for --ascii with anything but
/// .ply, for --normals (`normals`) with .off or .stl, and for an output that is one of `inputs`
/// or of their data files. A symbolic link is checked where it leads (it is written through).
void check_mesh_output(const std::string& output, bool ascii, bool normals = false,
                       const std::vector<std::string>& inputs = {});

/// "1234" for rates of 100 and more, else 3 significant digits.
std::string rate_text(double per_second);

/// The progress of verify and dataset on stderr: redrawn in place on a terminal,
/// about once a second; when stderr is not a terminal, lines only if `forced`; always a final line.
/// Empty (no callback, nothing printed) when `quiet`.
ProgressCallback progress_line(bool forced, bool quiet, const std::string& what);
/// Ends a half-drawn progress line, so that an error message that follows starts its own line.
void end_progress_line();

/// Progress of one long step of extract ("extracting the mesh: 43%, 1.2 s") on stderr: on a
/// terminal, redrawn in place from one second into the step, at most 4 times a second, and
/// erased when the step ends (so the summary line starts clean); when stderr is not a terminal,
/// lines about once a second and a final 100% line only if `forced`. Empty (no callback) when
/// `quiet` or when there is nothing to show.
Progress fraction_line(bool forced, bool quiet, const std::string& what);

/// Throws `error` again with "path: " in front of its message, unless the message names the path.
[[noreturn]] void rethrow_naming(const Error& error, const std::string& path);

/// Runs `step()`. An Error is thrown again naming `path` (rethrow_naming), and std::bad_alloc
/// becomes Error{too_large} "path: out of memory while DOING": one line that says which file and
/// which step ran out of memory, rather than a bare "out of memory".
template <class Step> decltype(auto) named_step(const std::string& path, const std::string& doing, Step&& step)
{
    try {
        return step();
    } catch (const Error& e) {
        rethrow_naming(e, path);
    } catch (const std::bad_alloc&) {
        throw Error(Status::too_large, path + ": out of memory while " + doing);
    }
}

} // namespace cmc33::cli
