#include "common.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "atomic_file.hpp"
#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "slabs.hpp"
#include "volume_formats.hpp"

namespace cmc33::cli {

namespace fs = std::filesystem;

namespace {

/// A progress line is drawn on the terminal without its newline yet.
bool line_open = false;

/// "N" must be a whole number >= 1 (CLI11's PositiveNumber prints DBL_MAX in its message).
const CLI::Validator kPositiveInteger(
    [](std::string& text) -> std::string {
        std::int64_t n = 0;
        const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), n);
        if (ec != std::errc() || end != text.data() + text.size() || n < 1) {
            return "expected a whole number >= 1, got '" + text + "'";
        }
        return {};
    },
    "N >= 1", "positive integer");

const CLI::Validator kPositiveReal =
    real_number("a finite number > 0", [](double v) { return std::isfinite(v) && v > 0; }, "> 0");

} // namespace

bool RawVolumeOptions::any_given() const
{
    return std::any_of(given.begin(), given.end(), [](const CLI::Option* o) { return o->count() > 0; });
}

void add_raw_volume_options(CLI::App& command, RawVolumeOptions& raw)
{
    const std::string group = "Headerless raw volumes (any extension but .nrrd .nhdr .mhd .mha .vtk)";
    raw.given.push_back(command.add_option("--dims", raw.dims, "Samples along x, y, z")
                            ->expected(3)
                            ->type_name("X Y Z")
                            ->check(kPositiveInteger)
                            ->group(group));
    raw.given.push_back(
        command.add_option("--type", raw.type, "Sample type: int8 uint8 int16 uint16 int32 uint32 float double")
            ->type_name("T")
            ->check(CLI::Validator(
                [](std::string& name) -> std::string {
                    try {
                        (void)io::parse_type(name);
                        return {};
                    } catch (const Error& e) {
                        return e.what();
                    }
                },
                "TYPE", "type"))
            ->group(group));
    raw.given.push_back(command.add_option("--spacing", raw.spacing, "Distance between samples along x, y, z (default 1 1 1)")
                            ->expected(3)
                            ->type_name("SX SY SZ")
                            ->check(kPositiveReal)
                            ->group(group));
    raw.given.push_back(command.add_option("--endian", raw.endian, "Byte order of the samples (default little)")
                            ->type_name("ORDER")
                            ->check(CLI::IsMember({"little", "big"}))
                            ->group(group));
    raw.given.push_back(command.add_option("--header-bytes", raw.header_bytes, "Bytes to skip at the start of the file (default 0)")
                            ->type_name("N")
                            ->check(unsigned_number())
                            ->group(group));
    const std::string files = "Volumes in files with a header";
    command.add_option("--frame", raw.frame, "4-D files (NIfTI, .npy stacks): the frame to read, from 0 (nibabel's [..., N])")
        ->type_name("N")
        ->check(whole_number(0, std::numeric_limits<std::int64_t>::max()))
        ->group(files);
    command.add_option("--array", raw.array, ".vti: the point-data array to read (default: the active scalars)")
        ->type_name("NAME")
        ->check(non_empty("--array"))
        ->group(files);
    command.add_option("--origin", raw.origin, ".npy (with --spacing): the position of sample [0, 0, 0] (default 0 0 0)")
        ->expected(3)
        ->type_name("X Y Z")
        ->check(number_check())
        ->group(files);
    command.add_option("--space", raw.space,
                       "World space of the positions: ras or lps (default: the file's own, e.g. NIfTI ras, NRRD and DICOM lps)")
        ->type_name("SPACE")
        ->check(CLI::IsMember({"ras", "lps"}))
        ->group(files);
    command.add_option("--series", raw.series, "DICOM: the SeriesInstanceUID to read when the input holds several (info lists them)")
        ->type_name("UID")
        ->check(non_empty("--series"))
        ->group(files);
}

namespace {

/// A .npy file, by its name or its magic: the format whose frame --spacing/--origin give.
bool is_npy(const std::string& path)
{
    if (fs::path(path).extension() == ".npy") return true;
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return false;
    char magic[6] = {};
    const bool npy = std::fread(magic, 1, 6, f) == 6 && std::memcmp(magic, "\x93NUMPY", 6) == 0;
    std::fclose(f);
    return npy;
}

/// The format of `path` among those that read --frame, --array or --series, as read_volume()
/// chooses it (content first, then the name); "" for the others (NRRD, MetaImage, VTK, raw).
std::string choice_format(const std::string& path)
{
    if (io::is_dicom_input(path)) return "DICOM";
    if (io::is_tiff_input(path)) return "TIFF";
    if (is_npy(path)) return ".npy";
    std::error_code ec;
    if (fs::is_regular_file(path, ec)) {
        try {
            const io::detail::InputFile file(path, path);
            if (const auto format = io::detail::sniff_volume_format(file)) {
                if (*format == io::VolumeFormat::nifti) return "NIfTI";
                if (*format == io::VolumeFormat::vti) return ".vti";
            }
        } catch (const Error&) {
            // unreadable: read_volume() says why
        }
    }
    const std::string name = io::detail::lower_ascii(fs::path(path).filename().string());
    if (name.ends_with(".vti")) return ".vti";
    if (name.ends_with(".nii") || name.ends_with(".nii.gz") || name.ends_with(".hdr") || name.ends_with(".hdr.gz")) return "NIfTI";
    // a NIfTI pair named by its data file (x.img or x.img.gz beside its header)
    if ((name.ends_with(".img") || name.ends_with(".img.gz")) && io::volume_files(path).size() == 2) return "NIfTI";
    return "";
}

/// --frame, --array and --series for an input whose format has no use for them: a usage error,
/// not an option silently ignored.
void check_volume_choices(const std::string& path, const RawVolumeOptions& raw)
{
    if (!raw.frame && raw.array.empty() && raw.series.empty()) return;
    const std::string format = choice_format(path);
    if (raw.frame && format != "NIfTI" && format != ".npy" && format != "TIFF") {
        throw UsageError("--frame is for files holding several frames (4-D NIfTI, 4-D .npy, TIFF hyperstacks); " + path +
                         (format.empty() ? " holds one volume" : " is " + format + ", read as one volume"));
    }
    if (!raw.array.empty() && format != ".vti") {
        throw UsageError("--array is for .vti files, which can hold several point-data arrays; " + path + " is " +
                         (format.empty() ? std::string("not a .vti file") : format));
    }
    if (!raw.series.empty() && format != "DICOM") {
        throw UsageError("--series is for DICOM inputs, which can hold several series; " + path + " is " +
                         (format.empty() ? std::string("not DICOM") : format));
    }
}

} // namespace

io::ReadOptions read_options(const std::string& path, const RawVolumeOptions& raw)
{
    check_volume_choices(path, raw);
    io::ReadOptions options;
    options.frame = raw.frame;
    options.array = raw.array;
    options.series = raw.series;
    if (is_npy(path) || io::is_tiff_input(path)) { // formats without a frame, or TIFF's to replace
        if (!raw.spacing.empty()) options.spacing = Vec3{raw.spacing[0], raw.spacing[1], raw.spacing[2]};
        if (!raw.origin.empty()) options.origin = Vec3{raw.origin[0], raw.origin[1], raw.origin[2]};
    } else if (!raw.origin.empty()) {
        throw UsageError("--origin is for .npy files, which have no frame; " + path + " gives its own");
    }
    return options;
}

void apply_space(Vec3& origin, Mat3& direction, std::string& space, const RawVolumeOptions& raw, const std::string& path)
{
    if (raw.space.empty()) return;
    io::detail::convert_space(origin, direction, space, raw.space, path);
}

Volume load_volume(const std::string& path, const RawVolumeOptions& raw)
{
    const std::optional<io::RawOptions> options = raw_volume_options(path, raw);
    Volume volume = named_step(path, "reading the volume", [&] { return io::read_volume(path, options, read_options(path, raw)); });
    if (!raw.space.empty()) {
        Vec3 origin = volume.origin();
        Mat3 direction = volume.direction();
        std::string space = volume.space();
        apply_space(origin, direction, space, raw, path);
        volume.set_origin(origin);
        volume.set_direction(direction);
        volume.set_space(space);
    }
    return volume;
}

std::optional<io::RawOptions> raw_volume_options(const std::string& path, const RawVolumeOptions& raw)
{
    if (io::has_volume_header(path)) {
        // --spacing is also the frame of a .npy (read_options)
        const bool only_spacing = raw.given.size() > 2 && raw.given[2]->count() > 0 &&
                                  std::count_if(raw.given.begin(), raw.given.end(), [](const CLI::Option* o) { return o->count() > 0; }) == 1;
        if (only_spacing && (is_npy(path) || io::is_tiff_input(path))) return std::nullopt;
        if (raw.any_given()) {
            throw UsageError("--dims/--type are for headerless raw files; " + path +
                             " has a header that gives its dimensions and type");
        }
        return std::nullopt;
    }
    const bool has_dims = !raw.dims.empty(), has_type = !raw.type.empty();
    if (!has_dims || !has_type) {
        std::error_code ec;
        if (!fs::exists(path, ec)) throw Error(Status::io_error, path + ": cannot open: no such file");
        if (fs::is_directory(path, ec)) {
            throw Error(Status::io_error, path + ": is a directory, expected a volume file");
        }
        if (has_dims || has_type) {
            throw UsageError(std::string(has_dims ? "--dims needs --type" : "--type needs --dims") +
                             " to read the headerless file " + path);
        }
        throw UsageError(path + ": no volume header known by its extension (.nrrd .nhdr .mhd .mha "
                                ".vtk); for a headerless raw file give --dims X Y Z and --type T");
    }
    io::RawOptions options;
    options.dims = {raw.dims[0], raw.dims[1], raw.dims[2]};
    options.type = io::parse_type(raw.type);
    if (!raw.spacing.empty()) options.spacing = {raw.spacing[0], raw.spacing[1], raw.spacing[2]};
    options.endian = raw.endian == "big" ? io::Endian::big : io::Endian::little;
    options.header_bytes = raw.header_bytes;
    return options;
}

CLI::Validator method_validator()
{
    return CLI::Validator(
        [](std::string& name) -> std::string {
            try {
                (void)parse_method(name);
                return {};
            } catch (const Error& e) {
                return e.what();
            }
        },
        "cmc33|cmc33-paper|chernyaev|mc33-lewiner|mc", "method");
}

CLI::Validator number_check()
{
    return CLI::Validator(
        [](std::string& text) -> std::string {
            // from_chars takes no '+' and no hex: "0x10" stops at 'x' and is refused.
            const std::size_t skip = text.size() > 1 && text[0] == '+' && text[1] != '-' ? 1 : 0;
            double v = 0;
            const char* end = text.data() + text.size();
            const auto [at, ec] = std::from_chars(text.data() + skip, end, v);
            if (text.empty()) return "expected a number, got an empty value";
            if (ec == std::errc::result_out_of_range && at == end) return "'" + text + "' is out of the range of a double";
            if (ec != std::errc() || at != end) return "expected a number, got '" + text + "'";
            return {};
        },
        "NUMBER", "number");
}

CLI::Validator whole_number(std::int64_t min, std::int64_t max)
{
    const std::string range = max == std::numeric_limits<std::int64_t>::max()
                                  ? ">= " + std::to_string(min)
                                  : "from " + std::to_string(min) + " to " + std::to_string(max);
    return CLI::Validator(
        [min, max, range](std::string& text) -> std::string {
            std::int64_t n = 0;
            const char* end = text.data() + text.size();
            const auto [at, ec] = std::from_chars(text.data(), end, n);
            if (text.empty()) return "expected a whole number " + range + ", got an empty value";
            if (ec != std::errc() || at != end || n < min || n > max) {
                return "expected a whole number " + range + ", got '" + text + "'";
            }
            return {};
        },
        "N " + range, "whole number");
}

CLI::Validator real_number(const std::string& expected, bool (*accept)(double), const std::string& name)
{
    return CLI::Validator(
        [expected, accept](std::string& text) -> std::string {
            char* end = nullptr;
            const double v = std::strtod(text.c_str(), &end);
            if (text.empty() || *end != '\0' || !accept(v)) return "expected " + expected + ", got '" + text + "'";
            return {};
        },
        name, name);
}

CLI::Validator unsigned_number()
{
    return CLI::Validator(
        [](std::string& text) -> std::string {
            std::uint64_t n = 0;
            const char* end = text.data() + text.size();
            const auto [at, ec] = std::from_chars(text.data(), end, n);
            if (text.empty()) return "expected a whole number >= 0, got an empty value";
            if (ec == std::errc::result_out_of_range) return "'" + text + "' does not fit in 64 bits";
            if (ec != std::errc() || at != end) return "expected a whole number >= 0, got '" + text + "'";
            return {};
        },
        "N >= 0", "unsigned whole number");
}

CLI::Validator non_empty(const std::string& what)
{
    return CLI::Validator(
        [what](std::string& text) -> std::string {
            if (text.empty()) return "expected " + what + ", got an empty value";
            return {};
        },
        "", "non-empty");
}

CLI::Validator thread_count() { return whole_number(0, kMaxThreads); }

CLI::Validator memory_size()
{
    return CLI::Validator(
        [](std::string& text) -> std::string {
            try {
                (void)slabs::parse_size(text);
                return {};
            } catch (const Error& e) {
                return e.what();
            }
        },
        "SIZE", "size");
}

namespace {

template <class T> std::string shortest(T value)
{
    if (std::isnan(value)) return "nan";
    if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
    char text[64];
    const auto result = std::to_chars(text, text + sizeof text, value);
    return std::string(text, result.ptr);
}

} // namespace

std::string num(double value) { return shortest(value); }
std::string num(float value) { return shortest(value); }

double pretty(float value)
{
    if (!std::isfinite(value)) return static_cast<double>(value);
    const std::string text = shortest(value);
    return std::strtod(text.c_str(), nullptr);
}

std::string empty_mesh_note(const std::string& input, double iso, const std::optional<std::pair<double, double>>& range)
{
    std::string line = "cmc33: note: " + input + ": the mesh is empty: ";
    if (range && (iso < range->first || iso > range->second)) {
        return line + "the isovalue " + num(iso) + " is outside the samples' range [" + num(range->first) + ", " +
               num(range->second) + "]";
    }
    line += "no cell has samples on both sides of the isovalue " + num(iso);
    if (range) line += " (samples from " + num(range->first) + " to " + num(range->second) + ")";
    return line + "; a sample equal to the isovalue counts as above it";
}

std::string sig(double value, int digits)
{
    char text[64];
    std::snprintf(text, sizeof text, "%.*g", digits, value);
    return text;
}

std::string dims_text(const Index3& dims)
{
    return std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" + std::to_string(dims[2]);
}

std::string vec_text(const Vec3& v)
{
    return "(" + num(v[0]) + ", " + num(v[1]) + ", " + num(v[2]) + ")";
}

Json json_number(double value)
{
    if (!std::isfinite(value)) return nullptr;
    return value;
}

Json volume_json(const std::string& path, const Volume& volume)
{
    return volume_json(path, volume.dims(), volume.type(), volume.spacing(), volume.origin(), volume.direction(),
                       volume.space());
}

Json volume_json(const std::string& path, const Index3& d, ScalarType type, const Vec3& s, const Vec3& o, const Mat3& m,
                 const std::string& space)
{
    Json direction = Json::array(); // row by row: column a is the world direction of axis a
    for (const Vec3& row : m) direction.push_back({json_number(row[0]), json_number(row[1]), json_number(row[2])});
    return Json{{"file", path},
                {"dims", {d[0], d[1], d[2]}},
                {"type", std::string(type_name(type))},
                {"spacing", {json_number(s[0]), json_number(s[1]), json_number(s[2])}},
                {"origin", {json_number(o[0]), json_number(o[1]), json_number(o[2])}},
                {"direction", direction},
                {"mirrored", determinant(m) < 0},
                {"space", space.empty() ? Json(nullptr) : Json(space)}};
}

Json topology_json(const MeshTopology& t)
{
    return Json{{"euler", t.euler},
                {"betti", {t.components, t.b1, t.closed_components}},
                {"components", t.components},
                {"closed_components", t.closed_components},
                {"boundary_edges", t.boundary_edges},
                {"boundary_loops", t.boundary_loops},
                {"nonmanifold_edges", t.nonmanifold_edges},
                {"nonmanifold_vertices", t.nonmanifold_vertices},
                {"degenerate_triangles", t.degenerate_triangles},
                {"closed", t.closed},
                {"oriented", t.oriented}};
}

Json geometry_json(const MeshGeometry& g)
{
    Json examples = Json::array();
    for (const auto& pair : g.intersection_examples) examples.push_back({pair[0], pair[1]});
    return Json{{"embedded", g.embedded()},
                {"positions", g.positions},
                {"coincident_vertices", g.coincident_vertices},
                {"zero_area_triangles", g.zero_area_triangles},
                {"intersecting_pairs", g.intersecting_pairs},
                {"intersection_examples", examples},
                {"welded", topology_json(g.welded)}};
}

namespace {

bool is_flat(const Json& json)
{
    return std::none_of(json.begin(), json.end(), [](const Json& e) { return e.is_structured(); });
}

/// Like dump(2), but an array of numbers, strings or booleans stays on one line: "dims": [8, 8, 8].
void write_json(std::ostream& out, const Json& json, int indent)
{
    const std::string pad(static_cast<std::size_t>(indent + 2), ' '), end_pad(static_cast<std::size_t>(indent), ' ');
    if (json.is_array() && (json.empty() || is_flat(json))) {
        out << '[';
        for (std::size_t i = 0; i < json.size(); ++i) out << (i ? ", " : "") << json[i].dump();
        out << ']';
    } else if (json.is_array()) {
        out << "[\n";
        for (std::size_t i = 0; i < json.size(); ++i) {
            out << pad;
            write_json(out, json[i], indent + 2);
            out << (i + 1 < json.size() ? ",\n" : "\n");
        }
        out << end_pad << ']';
    } else if (json.is_object() && !json.empty()) {
        out << "{\n";
        std::size_t i = 0;
        for (auto it = json.begin(); it != json.end(); ++it, ++i) {
            out << pad << Json(it.key()).dump() << ": ";
            write_json(out, it.value(), indent + 2);
            out << (i + 1 < json.size() ? ",\n" : "\n");
        }
        out << end_pad << '}';
    } else {
        out << json.dump();
    }
}

} // namespace

void print_json(const Json& json)
{
    write_json(std::cout, json, 0);
    std::cout << '\n';
}

void check_not_an_input(const std::string& output, const std::vector<std::string>& inputs)
{
    for (const std::string& input : inputs) {
        // The header first, then every data file it names.
        const std::vector<fs::path> files = io::volume_files(input);
        for (std::size_t i = 0; i < files.size(); ++i) {
            std::error_code ec;
            if (!fs::equivalent(files[i], output, ec) || ec) continue;
            const std::string advice = "; write the output to another file, a command never replaces what it reads";
            if (i == 0) {
                throw UsageError(output + " is the input " +
                                 (input == output ? "file" : input + " under another name") + advice);
            }
            const std::string data = files[i].string();
            throw UsageError(output + " is " + (data == output ? "" : data + " under another name, ") +
                             "a data file of the input " + input + advice);
        }
    }
}

void check_writable_folder(const fs::path& dir, const std::string& output)
{
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) {
        throw Error(Status::io_error, output + ": cannot write: the directory " + dir.string() + " does not exist");
    }
    // Try it: access(W_OK) says yes to root on a read-only file system.
    const fs::path probe = dir / (".cmc33-probe-" + std::to_string(::getpid()));
    const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd < 0) {
        if (errno == EEXIST) return; // a file of ours, left by a process with the same pid: the folder is writable
        throw Error(Status::io_error, output + ": cannot write: the directory " + dir.string() +
                                          " is not writable (" + std::strerror(errno) + ")");
    }
    ::close(fd);
    ::unlink(probe.c_str());
}

void check_mesh_output(const std::string& output, bool ascii, bool normals, const std::vector<std::string>& inputs)
{
    if (output.empty()) {
        if (ascii) throw UsageError("--ascii needs -o OUT.ply");
        return;
    }
    const fs::path path(output);
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext != ".ply" && ext != ".obj" && ext != ".stl" && ext != ".off" && ext != ".glb" && ext != ".gltf" &&
        ext != ".vtp" && ext != ".gii") {
        // write_mesh checks the extension before it creates anything: let it say what it accepts.
        io::write_mesh(Mesh{}, path);
        throw Error(Status::unsupported_format,
                    output + ": unsupported mesh extension; expected .ply, .obj, .stl, .off, .glb, .gltf, .vtp or .gii");
    }
    if (ascii && ext != ".ply") throw UsageError("--ascii is for .ply output only, not " + output);
    if (normals && (ext == ".off" || ext == ".stl")) {
        throw UsageError(output + ": OFF/STL cannot store normals; use .ply or .obj, or drop --normals");
    }
    check_not_an_input(output, inputs);
    // A .gltf writes its buffer to STEM.bin beside it: that file must not be an input either.
    if (ext == ".gltf") {
        try {
            check_not_an_input(fs::path(path).replace_extension(".bin").string(), inputs);
        } catch (const UsageError& e) {
            throw UsageError(output + " writes its buffer beside it: " + e.what());
        }
    }
    // A directory, a device, a read-only file: refused now, as the writer would refuse them.
    const fs::path target = io::detail::output_target(path).target;
    const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    std::error_code ec;
    if (target != path && !fs::is_directory(dir, ec)) {
        throw Error(Status::io_error, output + ": cannot write: it is a symbolic link to " + target.string() +
                                          ", whose directory " + dir.string() + " does not exist");
    }
    check_writable_folder(dir, output);
}

void rethrow_naming(const Error& error, const std::string& path)
{
    const std::string message = error.what();
    if (message.find(path) != std::string::npos) throw error;
    throw Error(error.status(), path + ": " + message);
}

std::string rate_text(double per_second)
{
    return per_second >= 100 ? std::to_string(static_cast<std::int64_t>(per_second + 0.5))
                             : sig(per_second, 3);
}

/// The progress line on stderr: rewritten in place about once a second when stderr is a
/// terminal (or printed as lines when `forced` and it is not), and always a final line.
ProgressCallback progress_line(bool forced, bool quiet, const std::string& what)
{
    line_open = false;
    if (quiet) return {};
    const bool tty = ::isatty(STDERR_FILENO) == 1;
    struct State {
        double last = -1;
        bool finished = false;
    };
    auto state = std::make_shared<State>();
    return [tty, forced, what, state](const VerifyProgress& p) {
        if (state->finished) return;
        const bool final = p.done == p.total;
        if (!final && (!(tty || forced) || p.seconds - state->last < 1.0)) return;
        state->last = p.seconds;
        state->finished = final;
        const double rate = p.seconds > 0 ? static_cast<double>(p.done) / p.seconds : 0.0;
        std::string line = std::to_string(p.done) + "/" + std::to_string(p.total) + " " + what +
                           ", " + rate_text(rate) + "/s, " + sig(p.seconds, 3) + " s";
        if (p.mismatched != 0) line += ", " + std::to_string(p.mismatched) + " mismatched";
        std::cout.flush();
        if (tty) {
            std::cerr << '\r' << line << "\x1b[K" << (final ? "\n" : "") << std::flush;
            line_open = !final;
        } else {
            std::cerr << line << '\n' << std::flush;
        }
    };
}

Progress fraction_line(bool forced, bool quiet, const std::string& what)
{
    const bool tty = ::isatty(STDERR_FILENO) == 1;
    if (quiet || !(tty || forced)) return {};
    struct State {
        std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
        double last = -1;
    };
    auto state = std::make_shared<State>();
    // Called by extract() from one worker thread at a time; line_open is read by the main thread
    // only after extract() has joined them.
    return [tty, what, state](double fraction) {
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - state->start).count();
        const bool final = fraction >= 1.0;
        if (tty && final) {
            if (line_open) std::cerr << "\r\x1b[K" << std::flush;
            line_open = false;
            return true;
        }
        const double gap = tty ? 0.25 : 1.0;
        if (!final && ((tty && seconds < 1.0) || seconds - state->last < gap)) return true;
        state->last = seconds;
        const std::string line = what + ": " + std::to_string(static_cast<int>(100 * fraction)) + "%, " +
                                 sig(seconds, 2) + " s";
        if (tty) {
            std::cerr << '\r' << line << "\x1b[K" << std::flush;
            line_open = true;
        } else {
            std::cerr << line << '\n' << std::flush;
        }
        return true;
    };
}

/// Ends a half-drawn progress line, so that an error message that follows starts its own line.
void end_progress_line()
{
    if (line_open) std::cerr << '\n';
    line_open = false;
}

} // namespace cmc33::cli
