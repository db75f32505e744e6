// The verification dataset's folder (the paper's Sec. 4.1 offers the same: "Marching Cubes cases
// grids and randomly generated 5x5x5 grids" with their invariants): the fields of verify() as
// NRRD files, a README, and manifest.tsv with their expected invariants; written by
// write_dataset (into a hidden folder, moved into place at the end) and read by read_manifest.

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include <unistd.h>

#include "cmc33/cell.hpp"
#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "cmc33/topology.hpp"
#include "cmc33/verify.hpp"
#include "atomic_file.hpp"
#include "dataset.hpp"
#include "dataset_detail.hpp"
#include "parallel.hpp"
#include "verify_detail.hpp"

namespace cmc33::cli {

namespace dataset_detail {

std::string clip(std::string text, std::size_t max_chars)
{
    if (text.size() > max_chars) text = text.substr(0, max_chars) + "...";
    return text;
}

std::array<double, 8> corner_values(const Volume& volume)
{
    std::array<double, 8> v{};
    volume.visit([&](auto view) {
        for (int c = 0; c < 8; ++c)
            v[static_cast<std::size_t>(c)] =
                static_cast<double>(view(c & 1, c >> 1 & 1, c >> 2 & 1));
    });
    return v;
}

} // namespace dataset_detail

namespace {

using dataset_detail::clip;
using dataset_detail::corner_values;

constexpr std::string_view kManifestHeader =
    "file\tiso\teuler\tb0\tb1\tb2\tboundary_loops\tsubcase";
constexpr std::array<std::string_view, kFieldKindCount> kFolders = {"cells", "grids", "closed", "ties"};
/// write_dataset writes into DIR/.cmc33-dataset-tmpPID/ and moves the result into DIR.
constexpr std::string_view kTempPrefix = ".cmc33-dataset-tmp";

// README.txt of a dataset; @NAME@ fields are filled in by readme_text().
constexpr std::string_view kReadme = R"(cmc33 verification dataset
==========================

Random scalar fields and the topology of the level set of their trilinear interpolant, to test
whether an isosurface extractor is topologically correct (Etiene et al. 2012; Custodio et al.
2013, Sec. 4). Written by `cmc33 dataset` with seed @SEED@.

  cells/   @CELLS@ fields of 2x2x2 samples (one cell), drawn to cover all 256 sign configurations
           and all 33 subcases of Marching Cubes 33
  grids/   @GRIDS@ fields of @SIZE@ samples uniform in [-1, 1]
  closed/  @CLOSED@ fields of @SIZE@ samples whose boundary samples are in [-1, -0.1], so every
           surface is closed; the others uniform in [-1, 1]
  ties/    @TIES@ fields of @SIZE@ integer samples in -2..2 or -3..3: samples, face saddles and
           interior saddles equal to the isovalue (the sign rule below decides them)

Every file is an NRRD volume (attached header, raw float32 in the byte order its header gives),
x fastest, spacing 1. Fields whose topology the verifier could not decide are left out, so the
numbering may have gaps: @LEFT_OUT@ were left out.

manifest.tsv
------------
A header line, then one tab-separated line per file:
  file            path relative to this folder
  iso             the isovalue (0 for every field here)
  euler           Euler characteristic of the surface S = {f = iso} inside the grid's box
  b0 b1 b2        Betti numbers of S: components; b1 = b0 + b2 - euler (a component of genus g
                  adds 2g if it is closed, 2g + k - 1 if it has k boundary curves); closed
                  components
  boundary_loops  closed curves in which S meets the box's faces
  subcase         for cells, the Marching Cubes 33 subcase cmc33 assigns (Chernyaev's numbering,
                  e.g. 13.5.2); '-' for grids

f is the trilinear interpolant of the samples in every cell. The sign rule: a sample (or a face or
interior saddle) equal to the isovalue counts as above it, i.e. S is the level set at
iso - epsilon for an infinitesimal epsilon.

How to use it
-------------
Extract a mesh from every file at its isovalue, compute the mesh's Euler characteristic
(V - E + F), its components, closed components and boundary loops, b1 = b0 + b2 - euler, and
compare with the manifest. A topologically correct extractor matches every line with a manifold
mesh (every edge in two triangles, or one on the box's faces; every vertex one fan). With cmc33:

  cmc33 verify --dataset DIR --method cmc33       # cmc33 itself
  cmc33 verify --dataset DIR --cmd 'mytool {in} {iso} {out}'

The command runs for every file, with {in} the volume, {iso} the isovalue and {out} the mesh to
write (.ply; write {out}.obj or {out}.off to choose another format). Do not quote the
placeholders: cmc33 quotes the paths.
`cmc33 verify @ARGS@` checks the same fields without files.
)";

std::string readme_text(const DatasetOptions& options, const DatasetSummary& summary)
{
    const std::string size = std::to_string(options.size);
    const std::string cube = size + "x" + size + "x" + size;
    const std::pair<std::string_view, std::string> fields[] = {
        {"@SEED@", std::to_string(options.seed)},
        {"@CELLS@", std::to_string(summary.written[0])},
        {"@GRIDS@", std::to_string(summary.written[1])},
        {"@CLOSED@", std::to_string(summary.written[2])},
        {"@TIES@", std::to_string(summary.written[3])},
        {"@SIZE@", cube},
        {"@LEFT_OUT@", std::to_string(summary.undetermined[0]) + " cells, " +
                           std::to_string(summary.undetermined[1]) + " grids, " +
                           std::to_string(summary.undetermined[2]) + " closed grids and " +
                           std::to_string(summary.undetermined[3]) + " tie grids"},
        {"@ARGS@", "--seed " + std::to_string(options.seed) + " --cells " +
                       std::to_string(options.cells) + " --grids " + std::to_string(options.grids) +
                       " --closed " + std::to_string(options.closed) + " --ties " + std::to_string(options.ties) +
                       " --size " + size},
    };
    std::string text(kReadme);
    for (const auto& [key, value] : fields) {
        for (std::size_t at; (at = text.find(key)) != std::string::npos;)
            text.replace(at, key.size(), value);
    }
    return text;
}

void write_text(const std::filesystem::path& path, const std::string& text)
{
    const std::filesystem::path tmp = path.string() + ".tmp";
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        out << text;
        out.flush();
        if (!out) throw Error(Status::io_error, tmp.string() + ": cannot write");
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec)
        throw Error(Status::io_error,
                    path.string() + ": cannot rename " + tmp.string() + " to it: " + ec.message());
}

/// Splits a manifest line at tabs.
std::vector<std::string_view> split_tabs(std::string_view line)
{
    std::vector<std::string_view> fields;
    std::size_t start = 0;
    for (;;) {
        const std::size_t tab = line.find('\t', start);
        fields.push_back(line.substr(start, tab == std::string_view::npos ? std::string_view::npos
                                                                          : tab - start));
        if (tab == std::string_view::npos) break;
        start = tab + 1;
    }
    return fields;
}

int subcase_index(std::string_view name)
{
    for (int s = 0; s < kSubcaseCount; ++s) {
        if (subcase_name(s) == name) return s;
    }
    return -1;
}

/// Writes field n of `kind` into the dataset and returns its manifest line, or "" if its
/// topology is undetermined (then nothing is written).
std::string write_field(const std::filesystem::path& dir, FieldKind kind, std::int64_t n,
                        std::uint64_t seed, int size)
{
    const Volume volume = random_field(kind, n, seed, size);
    const FieldTopology t = field_topology(volume, 0.0);
    if (!t.determined) return {};
    const std::string file =
        std::string(kFolders[static_cast<std::size_t>(kind)]) + "/" + field_name(kind, n) + ".nrrd";
    io::write_volume(volume, dir / file);
    const std::string subcase =
        kind == FieldKind::cell
            ? std::string(subcase_name(analyze_cell(corner_values(volume), 0.0).subcase))
            : "-";
    return file + "\t0\t" + std::to_string(t.euler) + "\t" + std::to_string(t.b0) + "\t" +
           std::to_string(t.b1) + "\t" + std::to_string(t.b2) + "\t" +
           std::to_string(t.boundary_loops) + "\t" + subcase + "\n";
}

/// Why a dataset may not be written into `dir`, or "" if it may: `dir` does not exist, is an
/// empty folder, or holds a previous dataset and nothing else (manifest.tsv, README.txt, and in
/// cells/ grids/ closed/ only the files its manifest lists), which is then replaced.
std::string unfit_reason(const std::filesystem::path& dir)
{
    namespace fs = std::filesystem;
    std::error_code ec;
    if (!fs::exists(dir, ec)) return {};
    if (!fs::is_directory(dir, ec)) return "exists and is not a folder";
    if (fs::is_empty(dir, ec)) return {};
    if (!fs::exists(dir / "manifest.tsv", ec)) {
        return "folder is not empty and holds no dataset (no manifest.tsv)";
    }
    std::vector<std::string> listed;
    try {
        for (const ManifestEntry& e : read_manifest(dir)) listed.push_back(e.file);
    } catch (const Error& e) {
        return std::string("folder is not empty and its manifest.tsv is not a dataset's (") + e.what() + ")";
    }
    std::sort(listed.begin(), listed.end());
    for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec)) {
        const std::string rel = it->path().lexically_relative(dir).generic_string();
        const bool top = it.depth() == 0;
        const bool folder = it->is_directory(ec) && !it->is_symlink(ec);
        bool ours = false;
        if (top && folder && rel.rfind(kTempPrefix, 0) == 0) {
            it.disable_recursion_pending(); // left by a killed run: removed at the end
            continue;
        }
        if (top) {
            ours = folder ? rel == "cells" || rel == "grids" || rel == "closed" || rel == "ties"
                          : (rel == "manifest.tsv" || rel == "README.txt") && it->is_regular_file(ec);
        } else {
            ours = !folder && it->is_regular_file(ec) && !it->is_symlink(ec) &&
                   std::binary_search(listed.begin(), listed.end(), rel);
        }
        if (!ours) {
            return "folder holds " + rel + ", which is not part of the dataset its manifest.tsv lists";
        }
    }
    if (ec) return "folder cannot be listed: " + ec.message();
    return {};
}

} // namespace

DatasetSummary write_dataset(const std::filesystem::path& dir, const DatasetOptions& options)
{
    namespace fs = std::filesystem;
    if (options.cells < 0 || options.grids < 0 || options.closed < 0 || options.ties < 0) {
        throw Error(Status::invalid_argument, "dataset: field counts must be >= 0; got cells " +
                                                  std::to_string(options.cells) + ", grids " +
                                                  std::to_string(options.grids) + ", closed " +
                                                  std::to_string(options.closed) + ", ties " +
                                                  std::to_string(options.ties));
    }
    const int min_size = options.closed > 0 ? 3 : 2;
    if (options.size < min_size || options.size > 1024) {
        throw Error(Status::invalid_argument, "dataset: grid size " + std::to_string(options.size) +
                                                  " is out of range; expected " +
                                                  std::to_string(min_size) + " to 1024");
    }
    if (dir.empty()) {
        throw Error(Status::invalid_argument,
                    "dataset: the folder name is empty; expected a new, empty or dataset folder");
    }
    const std::string unfit = unfit_reason(dir);
    if (!unfit.empty()) {
        throw Error(Status::invalid_argument,
                    dir.string() + ": " + unfit + "; expected a new, empty or dataset folder");
    }

    // Everything is written into a hidden folder inside `dir` and moved into place at the end:
    // a failure or a signal removes that folder (and `dir`, if it was made here), and a previous
    // dataset is replaced only by a complete one.
    std::error_code ec;
    std::optional<io::detail::Temporary> made;
    if (!fs::exists(dir, ec)) {
        made.emplace(dir, [&] {
            fs::create_directories(dir, ec);
            if (ec) throw Error(Status::io_error, dir.string() + ": cannot create the folder: " + ec.message());
        });
    }
    const fs::path temp_dir = dir / (std::string(kTempPrefix) + std::to_string(::getpid()));
    io::detail::Temporary temp(temp_dir, [&] {
        fs::remove_all(temp_dir, ec); // left by a killed run with the same pid
        fs::create_directory(temp_dir, ec);
        if (ec) throw Error(Status::io_error, temp_dir.string() + ": cannot create the folder: " + ec.message());
    });
    const std::array<std::int64_t, kFieldKindCount> counts{options.cells, options.grids, options.closed,
                                                           options.ties};
    for (std::size_t k = 0; k < counts.size(); ++k) {
        if (counts[k] == 0) continue;
        const auto folder = temp_dir / kFolders[k];
        fs::create_directories(folder, ec);
        if (ec) {
            throw Error(Status::io_error,
                        folder.string() + ": cannot create the folder: " + ec.message());
        }
    }
    const std::int64_t total = options.cells + options.grids + options.closed + options.ties;
    const int threads = cmc33::detail::threads_for(options.threads, total);
    verification::detail::Ticker tick(options.progress, total, nullptr);

    DatasetSummary summary;
    std::string manifest = std::string(kManifestHeader) + "\n";
    for (std::size_t k = 0; k < counts.size(); ++k) {
        const auto kind = static_cast<FieldKind>(k);
        std::vector<std::string> lines(static_cast<std::size_t>(counts[k])); // empty: left out
        verification::detail::run_parallel(
            counts[k], threads, 16, tick, [&](int, std::int64_t begin, std::int64_t end) {
                for (std::int64_t i = begin; i < end; ++i) {
                    lines[static_cast<std::size_t>(i)] =
                        write_field(temp_dir, kind, i + 1, options.seed, options.size);
                }
            });
        for (const std::string& line : lines) {
            if (line.empty()) {
                ++summary.undetermined[k];
            } else {
                ++summary.written[k];
                manifest += line;
            }
        }
        tick.pass_done(counts[k]);
    }
    write_text(temp_dir / "manifest.tsv", manifest);
    write_text(temp_dir / "README.txt", readme_text(options, summary));
    temp.commit([&] {
        // The old manifest goes first and the new one comes last: a folder caught in between
        // is never taken for a complete dataset.
        for (const char* name : {"manifest.tsv", "README.txt", "cells", "grids", "closed", "ties"}) {
            fs::remove_all(dir / name, ec);
            if (ec) throw Error(Status::io_error, (dir / name).string() + ": cannot remove: " + ec.message());
        }
        for (const char* name : {"cells", "grids", "closed", "ties", "README.txt", "manifest.tsv"}) {
            if (!fs::exists(temp_dir / name)) continue;
            fs::rename(temp_dir / name, dir / name, ec);
            if (ec) throw Error(Status::io_error, (dir / name).string() + ": cannot move it into place: " + ec.message());
        }
        fs::remove(temp_dir, ec);
        for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
            if (e.path().filename().string().rfind(kTempPrefix, 0) == 0) fs::remove_all(e.path(), ec);
        }
    });
    if (made) made->commit([] {});
    summary.seconds = tick.seconds();
    tick(0);
    return summary;
}

std::vector<ManifestEntry> read_manifest(const std::filesystem::path& dir)
{
    const std::filesystem::path path = dir / "manifest.tsv";
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(Status::io_error, path.string() + ": cannot open the dataset's manifest");
    std::vector<ManifestEntry> entries;
    std::string line;
    int number = 0;
    auto fail = [&](const std::string& what) {
        throw Error(Status::bad_format, path.string() + ":" + std::to_string(number) + ": " + what);
    };
    while (std::getline(in, line)) {
        ++number;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (number == 1) {
            if (line != kManifestHeader) {
                fail("expected the header line \"file iso euler b0 b1 b2 boundary_loops subcase\" "
                     "(tab-separated) but found \"" +
                     clip(line) + "\"");
            }
            continue;
        }
        if (line.empty() || line[0] == '#') continue;
        const std::vector<std::string_view> f = split_tabs(line);
        if (f.size() != 8) {
            fail("expected 8 tab-separated columns (file iso euler b0 b1 b2 boundary_loops "
                 "subcase) but found " +
                 std::to_string(f.size()));
        }
        ManifestEntry e;
        e.line = number;
        e.file = std::string(f[0]);
        const std::filesystem::path file(e.file);
        if (e.file.empty() || file.is_absolute() ||
            std::any_of(file.begin(), file.end(),
                        [](const std::filesystem::path& p) { return p == ".."; })) {
            fail(
                "file \"" + clip(e.file) +
                "\" is not a path inside the dataset folder; expected e.g. cells/cell-000001.nrrd");
        }
        const std::string iso_text(f[1]);
        const auto iso_end = iso_text.data() + iso_text.size();
        const auto parsed = std::from_chars(iso_text.data(), iso_end, e.iso);
        if (parsed.ec != std::errc() || parsed.ptr != iso_end || !std::isfinite(e.iso)) {
            fail("iso \"" + clip(iso_text) + "\" is not a finite number");
        }
        static constexpr std::array<std::string_view, 5> kNames = {"euler", "b0", "b1", "b2",
                                                                   "boundary_loops"};
        std::array<std::int64_t, 5> v{};
        for (std::size_t c = 0; c < 5; ++c) {
            const std::string_view t = f[c + 2];
            const auto r = std::from_chars(t.data(), t.data() + t.size(), v[c]);
            if (r.ec != std::errc() || r.ptr != t.data() + t.size() || (c > 0 && v[c] < 0)) {
                fail(std::string(kNames[c]) + " \"" + clip(std::string(t)) + "\" is not " +
                     (c == 0 ? "an integer" : "an integer >= 0"));
            }
        }
        e.expected.determined = true;
        e.expected.euler = v[0];
        e.expected.b0 = v[1];
        e.expected.b1 = v[2];
        e.expected.b2 = v[3];
        e.expected.boundary_loops = v[4];
        if (e.expected.b0 - e.expected.b1 + e.expected.b2 != e.expected.euler) {
            fail("b0 - b1 + b2 = " + std::to_string(e.expected.b0 - e.expected.b1 + e.expected.b2) +
                 " differs from euler " + std::to_string(e.expected.euler) +
                 "; expected them equal");
        }
        e.subcase = std::string(f[7]);
        if (e.subcase != "-" && subcase_index(e.subcase) < 0) {
            fail("subcase \"" + clip(e.subcase) +
                 "\" is not a Marching Cubes 33 subcase name (e.g. 13.5.2) or '-'");
        }
        entries.push_back(std::move(e));
    }
    if (number == 0)
        throw Error(Status::bad_format,
                    path.string() + ": is empty; expected a header line and one line per file");
    return entries;
}

} // namespace cmc33::cli
