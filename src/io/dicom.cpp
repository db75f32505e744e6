// DICOM volumes through GDCM (contract in dicom.hpp; what is read and refused: docs/formats.md).
//
// Two passes. The first reads each file's header up to its Pixel Data (GDCM stops there) and
// keeps what grouping, sorting and the frame need. The second reads the samples of the chosen
// series only: native transfer syntaxes straight from the file at the offset the first pass
// found (no second parse), the others through GDCM's decoders (JPEG, JPEG-LS, JPEG 2000, RLE,
// deflate).

#include "dicom.hpp"
#include "dicom_scan.hpp"
#include "tiff.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iomanip>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "cmc33/error.hpp"
#include "atomic_file.hpp"
#include "byte_source.hpp"
#include "portability.hpp"
#include "volume_formats.hpp"

#if CMC33_WITH_GDCM
#include "dicom_gdcm.hpp"
#include <gdcmDataSet.h>
#include <gdcmDictEntry.h>
#include <gdcmDicts.h>
#include <gdcmGlobal.h>
#include <gdcmFile.h>
#include <gdcmImage.h>
#include <gdcmImageReader.h>
#include <gdcmReader.h>
#include <gdcmSequenceOfItems.h>
#include <gdcmTrace.h>
#include <gdcmTransferSyntax.h>
#endif

namespace cmc33::io::detail {

namespace fs = std::filesystem;

bool has_dicom_mark(std::string_view head) noexcept
{
    return head.size() >= 132 && head.substr(128, 4) == "DICM";
}

bool is_dicomdir_name(const fs::path& path)
{
    return equals_ignore_case(path.filename().string(), "DICOMDIR");
}

namespace {

/// The first 132 bytes of a regular file ("" when it cannot be read).
std::string file_head(const fs::path& path)
{
    try {
        const InputFile file(path, path.string());
        return file.read_string(0, 132);
    } catch (const Error&) {
        return {};
    }
}

bool dicom_extension(const fs::path& path)
{
    const std::string ext = lower_extension(path);
    return ext == ".dcm" || ext == ".dicom" || ext == ".ima";
}


/// The regular files under `folder` (recursively, hidden entries skipped), sorted by name so that
/// messages come in a fixed order. DICOMDIR files are left out: they index, they hold no image.
std::vector<fs::path> folder_files(const fs::path& folder)
{
    std::vector<fs::path> files;
    std::error_code ec;
    fs::recursive_directory_iterator it(folder, fs::directory_options::skip_permission_denied, ec), end;
    if (ec) throw Error(Status::io_error, str_cat(folder.string(), ": cannot list the folder: ", ec.message()));
    for (; it != end; it.increment(ec)) {
        if (ec) throw Error(Status::io_error, str_cat(folder.string(), ": cannot list the folder: ", ec.message()));
        const std::string name = it->path().filename().string();
        if (!name.empty() && name[0] == '.') {
            if (it->is_directory(ec)) it.disable_recursion_pending();
            continue;
        }
        if (it->is_regular_file(ec) && !is_dicomdir_name(it->path())) files.push_back(it->path());
    }
    std::sort(files.begin(), files.end());
    return files;
}


} // namespace

/// The files of a folder taken as DICOM: the "DICM" mark, or a DICOM extension (files written
/// without the preamble).
std::vector<fs::path> folder_dicom_files(const fs::path& folder)
{
    std::vector<fs::path> out;
    for (const fs::path& file : folder_files(folder)) {
        if (dicom_extension(file) || has_dicom_mark(file_head(file))) out.push_back(file);
    }
    return out;
}

bool looks_like_dicom(const fs::path& path)
{
    std::error_code ec;
    if (fs::is_directory(path, ec)) {
        try {
            for (const fs::path& file : folder_files(path)) {
                if (dicom_extension(file) || is_dicomdir_name(file) || has_dicom_mark(file_head(file))) return true;
            }
        } catch (const Error&) {
        }
        return false;
    }
    return has_dicom_mark(file_head(path));
}

ImageInput image_input(const fs::path& path)
{
    std::error_code ec;
    if (fs::is_directory(path, ec)) {
        if (looks_like_dicom(path)) return ImageInput::dicom;
        if (looks_like_tiff(path)) return ImageInput::tiff;
        return ImageInput::empty_folder;
    }
    if (is_dicomdir_name(path) && fs::is_regular_file(path, ec)) return ImageInput::dicom;
    const std::string head = file_head(path);
    if (has_dicom_mark(head)) return ImageInput::dicom;
    if (has_tiff_mark(head)) return ImageInput::tiff;
    return ImageInput::none;
}

std::optional<Volume> read_image_input(const fs::path& path, const ReadOptions& options)
{
    switch (image_input(path)) {
    case ImageInput::dicom: return read_dicom(path, options);
    case ImageInput::tiff: return read_tiff(path, options);
    case ImageInput::empty_folder:
        throw Error(Status::unsupported_format,
                    path.string() + ": a folder without DICOM files (the \"DICM\" mark, *.dcm) or TIFF slices (*.tif, *.tiff); "
                                    "expected a DICOM series, a DICOMDIR, a folder of TIFF slices, or a volume file");
    case ImageInput::none: break;
    }
    return std::nullopt;
}

std::optional<std::vector<fs::path>> image_input_files(const fs::path& path)
{
    try {
        switch (image_input(path)) {
        case ImageInput::dicom: return dicom_input_files(path);
        case ImageInput::tiff: return tiff_input_files(path);
        case ImageInput::empty_folder: return std::vector<fs::path>{path};
        case ImageInput::none: break;
        }
    } catch (const std::exception&) {
        return std::vector<fs::path>{path};
    }
    return std::nullopt;
}

#if !CMC33_WITH_GDCM

bool dicom_supported() noexcept { return false; }

namespace {
[[noreturn]] void no_dicom(const std::string& label)
{
    throw Error(Status::unsupported_format,
                label + ": DICOM input, but this build of cmc33 has no DICOM reader (built without GDCM); "
                        "convert the series to NRRD or NIfTI, or use a build with GDCM");
}
} // namespace

Volume read_dicom(const fs::path& path, const ReadOptions&) { no_dicom(path.string()); }
Volume read_dicom_memory(std::string_view, const std::string& label, const ReadOptions&) { no_dicom(label); }
std::vector<DicomSeries> list_dicom_series(const fs::path& path) { no_dicom(path.string()); }
std::vector<fs::path> dicom_input_files(const fs::path& path) { return {path}; }

#else

bool dicom_supported() noexcept { return true; }

namespace {

using namespace dicom_gdcm; // the first pass: Header, Source, read_header()

// ---- slices ---------------------------------------------------------------------------------

/// One z slice: a frame of a file.
struct Slice {
    const Header* header = nullptr;
    std::int64_t frame = 0;
    const Geometry* geometry = nullptr;
    double key = 0; // position along the slice normal

    std::string name() const
    {
        if (header->frames > 1) return str_cat(header->label, ": frame ", frame + 1);
        return header->label;
    }
};

/// A code or UID from the file as it is when it is one short printable word (RGB, CT, 1.2.840...),
/// else quoted with its odd bytes escaped: a message stays one line whatever the file holds.
std::string shown(const std::string& value)
{
    const bool plain = value.size() <= 64 && std::all_of(value.begin(), value.end(), [](unsigned char c) { return c > 0x20 && c < 0x7f; });
    return plain ? value : quote_bytes(value, 64);
}

std::string series_summary(const std::vector<const Header*>& files)
{
    const Header& h = *files.front();
    std::int64_t slices = 0;
    for (const Header* f : files) slices += f->frames;
    std::string s = h.series.empty() ? std::string("(no SeriesInstanceUID)") : shown(h.series);
    s += " (";
    if (!h.modality.empty()) s += shown(h.modality) + " ";
    if (!h.description.empty()) s += quote_bytes(h.description, 64) + " ";
    s += str_cat(h.columns, "x", h.rows, "x", slices, ")");
    return s;
}

/// The files of one series, in the input's order.
using SeriesMap = std::map<std::string, std::vector<const Header*>>;

SeriesMap group_series(const std::vector<Header>& headers)
{
    SeriesMap map;
    for (const Header& h : headers) {
        if (h.has_pixels || h.float_pixels) map[h.series].push_back(&h);
    }
    return map;
}

const std::vector<const Header*>& choose_series(const SeriesMap& map, const std::string& label, const ReadOptions& options)
{
    if (map.empty()) {
        throw Error(Status::bad_format, label + ": no DICOM image (no file with Pixel Data); expected the slice files of a series");
    }
    std::string list;
    for (const auto& [uid, files] : map) {
        if (!list.empty()) list += ", ";
        list += series_summary(files);
    }
    if (!options.series.empty()) {
        const auto it = map.find(options.series);
        if (it == map.end()) {
            throw Error(Status::invalid_argument,
                        str_cat(label, ": no series ", quote_bytes(options.series, 80), "; the input holds ", map.size(),
                                map.size() == 1 ? " series: " : " series: ", list));
        }
        return it->second;
    }
    if (map.size() > 1) {
        throw Error(Status::bad_format, str_cat(label, ": ", map.size(), " DICOM series; choose one with --series UID: ", list));
    }
    return map.begin()->second;
}

double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 cross(const Vec3& a, const Vec3& b)
{
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

/// Cosines are written with a few digits (often 6): directions within this are the same.
constexpr double kCosineTolerance = 1e-4;

/// The checks on the series' files: one sample layout, one orientation, positions for all.
void check_uniform(const std::vector<const Header*>& files, const std::string& label)
{
    const Header& a = *files.front();
    for (const Header* f : files) {
        if (f->float_pixels) {
            throw Error(Status::unsupported_format,
                        f->label + ": Float Pixel Data (parametric maps) is not read; expected integer Pixel Data");
        }
        if (f->samples_per_pixel != 1) {
            throw Error(Status::unsupported_format,
                        str_cat(f->label, ": ", f->samples_per_pixel, " samples per pixel (",
                                f->photometric.empty() ? "color" : shown(f->photometric),
                                "); expected one sample per pixel (MONOCHROME1 or MONOCHROME2), a scalar volume"));
        }
        // PALETTE COLOR indices are no scalar, and GDCM's decoders assert on an unknown value (none: read as MONOCHROME2)
        if (!f->photometric.empty() && f->photometric != "MONOCHROME1" && f->photometric != "MONOCHROME2") {
            throw Error(Status::unsupported_format,
                        str_cat(f->label, ": PhotometricInterpretation ", quote_bytes(f->photometric),
                                "; expected MONOCHROME1 or MONOCHROME2 (one sample per pixel, a scalar volume)"));
        }
        if (f->rows != a.rows || f->columns != a.columns) {
            throw Error(Status::bad_format, str_cat(label, ": mixed slice sizes in one series: ", a.label, " has ", a.columns, "x",
                                                    a.rows, " (columns x rows), ", f->label, " has ", f->columns, "x", f->rows));
        }
        if (f->bits_allocated != a.bits_allocated || f->representation != a.representation || f->bits_stored != a.bits_stored) {
            throw Error(Status::bad_format,
                        str_cat(label, ": mixed pixel types in one series: ", a.label, " has ", a.bits_allocated, " bits allocated, ",
                                a.bits_stored, " stored, ", a.representation ? "signed" : "unsigned", "; ", f->label, " has ",
                                f->bits_allocated, ", ", f->bits_stored, ", ", f->representation ? "signed" : "unsigned"));
        }
    }
    if (a.rows < 2 || a.columns < 2) {
        throw Error(Status::bad_format, str_cat(a.label, ": ", a.columns, "x", a.rows,
                                                " pixels (columns x rows); an isosurface needs at least 2 on each axis"));
    }
    if (a.bits_allocated != 8 && a.bits_allocated != 16 && a.bits_allocated != 32) {
        throw Error(Status::unsupported_format, str_cat(a.label, ": BitsAllocated ", a.bits_allocated, "; expected 8, 16 or 32"));
    }
    if (a.bits_stored < 1 || a.bits_stored > a.bits_allocated || a.high_bit >= a.bits_allocated ||
        a.high_bit + 1 < a.bits_stored) {
        throw Error(Status::bad_format, str_cat(a.label, ": BitsStored ", a.bits_stored, " with HighBit ", a.high_bit,
                                                " does not fit BitsAllocated ", a.bits_allocated));
    }
    if (a.representation > 1) {
        throw Error(Status::bad_format,
                    str_cat(a.label, ": PixelRepresentation ", a.representation, "; expected 0 (unsigned) or 1 (signed)"));
    }
}

/// The slices of the series sorted along their normal, with the checks on their positions.
/// Returns the slices and sets `grid`'s frame.
std::vector<Slice> sort_slices(const std::vector<const Header*>& files, const std::string& label, Grid& grid)
{
    std::vector<Slice> slices;
    for (const Header* f : files) {
        for (std::int64_t k = 0; k < f->frames; ++k) {
            const Geometry& g = f->geometry[static_cast<std::size_t>(k)];
            Slice s{f, k, &g, 0};
            if (!g.position || !g.orientation) {
                throw Error(Status::bad_format,
                            str_cat(s.name(), ": no ", !g.position ? "ImagePositionPatient" : "ImageOrientationPatient",
                                    " (or not 3 and 6 numbers); the slices cannot be placed in space without it"));
            }
            slices.push_back(s);
        }
    }
    if (slices.size() < 2) {
        throw Error(Status::bad_format,
                    str_cat(label, ": the series has 1 slice (", slices.front().name(),
                            "); an isosurface needs at least 2: give the folder of the series' slice files"));
    }
    const std::array<double, 6>& o = *slices.front().geometry->orientation;
    const Vec3 row{o[0], o[1], o[2]}, col{o[3], o[4], o[5]};
    for (const Slice& s : slices) {
        const std::array<double, 6>& p = *s.geometry->orientation;
        for (std::size_t i = 0; i < 6; ++i) {
            if (std::fabs(p[i] - o[i]) > kCosineTolerance) {
                throw Error(Status::bad_format,
                            str_cat(label, ": mixed orientations in one series: ", slices.front().name(), " has ImageOrientationPatient ",
                                    format_real(o[0]), "\\", format_real(o[1]), "\\", format_real(o[2]), "\\", format_real(o[3]), "\\",
                                    format_real(o[4]), "\\", format_real(o[5]), ", ", s.name(), " has ", format_real(p[0]), "\\",
                                    format_real(p[1]), "\\", format_real(p[2]), "\\", format_real(p[3]), "\\", format_real(p[4]), "\\",
                                    format_real(p[5])));
            }
        }
    }
    const double nr = std::sqrt(dot(row, row)), nc = std::sqrt(dot(col, col));
    Vec3 normal = cross(row, col);
    const double nn = std::sqrt(dot(normal, normal));
    if (!(std::fabs(nr - 1) < 0.01 && std::fabs(nc - 1) < 0.01 && nn > 0.99)) {
        throw Error(Status::bad_format,
                    str_cat(slices.front().name(), ": ImageOrientationPatient's row ", vec_text(row), " and column ", vec_text(col),
                            " cosines are not two orthogonal unit vectors"));
    }
    for (double& v : normal) v /= nn;
    for (Slice& s : slices) s.key = dot(normal, *s.geometry->position);
    std::stable_sort(slices.begin(), slices.end(), [](const Slice& a, const Slice& b) { return a.key < b.key; });

    // The step between slices: the median of the steps (robust to a gap), then each checked.
    const std::size_t n = slices.size();
    std::vector<double> steps(n - 1);
    for (std::size_t k = 0; k + 1 < n; ++k) steps[k] = slices[k + 1].key - slices[k].key;
    std::vector<double> sorted = steps;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
    const double step = sorted[sorted.size() / 2];
    // Positions are written in mm with a few decimals; a slice this close to another one is the
    // same position, and one off the regular grid by more than 1% of a step is irregular.
    const double tolerance = std::max(1e-4, 0.01 * std::fabs(step));
    for (std::size_t k = 0; k + 1 < n; ++k) {
        if (std::fabs(steps[k]) <= tolerance) {
            throw Error(Status::bad_format,
                        str_cat(label, ": duplicate slice position ", vec_text(*slices[k].geometry->position), ": ", slices[k].name(),
                                " and ", slices[k + 1].name(), " (one position per slice expected; two acquisitions in one series?)"));
        }
    }
    for (std::size_t k = 0; k + 1 < n; ++k) {
        const double ratio = steps[k] / step;
        if (std::fabs(steps[k] - step) <= tolerance) continue;
        const double whole = std::round(ratio);
        if (whole >= 2 && std::fabs(steps[k] - whole * step) <= tolerance) {
            throw Error(Status::bad_format,
                        str_cat(label, ": missing slice", whole > 2 ? "s" : "", ": ", static_cast<long long>(whole) - 1,
                                " between ", slices[k].name(), " at ", format_real(slices[k].key), " mm and ", slices[k + 1].name(),
                                " at ", format_real(slices[k + 1].key), " mm along the slice normal (the step elsewhere is ",
                                format_real(step), " mm)"));
        }
        throw Error(Status::bad_format,
                    str_cat(label, ": non-uniform slice spacing: ", format_real(steps[k]), " mm between ", slices[k].name(), " at ",
                            format_real(slices[k].key), " mm and ", slices[k + 1].name(), " at ", format_real(slices[k + 1].key),
                            " mm along the slice normal, ", format_real(step), " mm elsewhere; expected evenly spaced slices"));
    }
    // The slice axis: from the first to the last position (a gantry tilt makes it oblique to the
    // normal: a sheared frame); every slice must lie on it.
    const Vec3 p0 = *slices.front().geometry->position, p1 = *slices.back().geometry->position;
    const double last = static_cast<double>(n - 1);
    const Vec3 axis{(p1[0] - p0[0]) / last, (p1[1] - p0[1]) / last, (p1[2] - p0[2]) / last};
    for (std::size_t k = 1; k + 1 < n; ++k) {
        const Vec3& p = *slices[k].geometry->position;
        const double t = static_cast<double>(k);
        const Vec3 d{p[0] - p0[0] - t * axis[0], p[1] - p0[1] - t * axis[1], p[2] - p0[2] - t * axis[2]};
        if (std::sqrt(dot(d, d)) > tolerance) {
            throw Error(Status::bad_format,
                        str_cat(label, ": ", slices[k].name(), " at ", vec_text(p), " is ", format_real(std::sqrt(dot(d, d))),
                                " mm off the line from the first slice ", vec_text(p0), " to the last ", vec_text(p1),
                                "; expected the slices on one straight line"));
        }
    }
    std::array<double, 2> ps{1, 1};
    if (const auto& s = slices.front().geometry->pixel_spacing) ps = *s;
    for (const Slice& s : slices) {
        const auto& q = s.geometry->pixel_spacing;
        if (q && (std::fabs((*q)[0] - ps[0]) > 1e-6 * ps[0] || std::fabs((*q)[1] - ps[1]) > 1e-6 * ps[1])) {
            throw Error(Status::bad_format,
                        str_cat(label, ": mixed PixelSpacing in one series: ", slices.front().name(), " has ", format_real(ps[0]), "\\",
                                format_real(ps[1]), ", ", s.name(), " has ", format_real((*q)[0]), "\\", format_real((*q)[1])));
        }
    }
    if (!(ps[0] > 0 && ps[1] > 0)) {
        throw Error(Status::bad_format, str_cat(slices.front().name(), ": PixelSpacing ", format_real(ps[0]), "\\", format_real(ps[1]),
                                                " is not positive; expected the distances between rows and between columns"));
    }
    // PS3.3 C.7.6.2.1.1: the first cosine is the direction of a row (increasing column index i,
    // our x), the second that of a column (increasing row index j, our y); PixelSpacing is the
    // row spacing (between rows, along y) then the column spacing (between columns, along x).
    set_frame(grid, {row, col, axis}, {ps[1], ps[0], 1}, label, "ImageOrientationPatient and ImagePositionPatient");
    // the cosines are unit vectors written with a few digits: the spacing is PixelSpacing's own
    grid.spacing[0] = ps[1];
    grid.spacing[1] = ps[0];
    grid.origin = p0;
    grid.space = "left-posterior-superior";
    grid.frame_source = slices.front().header->frames > 1 ? "PlanePositionSequence/PlaneOrientationSequence (functional groups)"
                                                          : "ImagePositionPatient/ImageOrientationPatient";
    grid.dims = {static_cast<std::int64_t>(slices.front().header->columns), static_cast<std::int64_t>(slices.front().header->rows),
                 static_cast<std::int64_t>(n)};
    return slices;
}

// ---- samples --------------------------------------------------------------------------------

ScalarType stored_type(const Header& h)
{
    const bool s = h.representation == 1;
    switch (h.bits_allocated) {
    case 8: return s ? ScalarType::i8 : ScalarType::u8;
    case 16: return s ? ScalarType::i16 : ScalarType::u16;
    default: return s ? ScalarType::i32 : ScalarType::u32;
    }
}

/// Keeps the BitsStored bits below HighBit (PS3.5 8.1.1), sign-extended when signed: the bits
/// above may hold overlays or garbage.
template <class T> void clean_bits(T* data, std::size_t count, const Header& h)
{
    using U = std::make_unsigned_t<T>;
    const unsigned width = 8 * sizeof(T);
    if (h.bits_stored == width) return;
    const unsigned shift = h.high_bit + 1 - h.bits_stored;
    const U mask = static_cast<U>((U{1} << h.bits_stored) - 1);
    const U sign = static_cast<U>(U{1} << (h.bits_stored - 1));
    for (std::size_t i = 0; i < count; ++i) {
        U v = static_cast<U>((static_cast<U>(data[i]) >> shift) & mask);
        if (std::is_signed_v<T> && (v & sign)) v = static_cast<U>(v | static_cast<U>(~mask));
        data[i] = static_cast<T>(v);
    }
}

/// Reads every slice's stored samples into `out` (slice k at k * slice_bytes).
void read_stored(const std::vector<Slice>& slices, const std::vector<Source>& sources, std::byte* out,
                 std::size_t slice_bytes, ScalarType type)
{
    // files read through GDCM's decoders, decoded once for all their frames
    std::map<const Header*, std::vector<char>> decoded;
    std::unique_ptr<InputFile> open_file;
    const Header* open_header = nullptr;
    for (std::size_t k = 0; k < slices.size(); ++k) {
        const Slice& s = slices[k];
        const Header& h = *s.header;
        const Source& src = sources[h.source];
        std::byte* dst = out + k * slice_bytes;
        const std::uint64_t frame_offset = static_cast<std::uint64_t>(s.frame) * slice_bytes;
        if (h.native_offset) {
            const std::uint64_t at = *h.native_offset + frame_offset;
            if (src.in_memory) {
                if (at > src.bytes.size() || src.bytes.size() - at < slice_bytes) {
                    throw Error(Status::truncated_file, str_cat(s.name(), ": the Pixel Data ends before the frame's ", slice_bytes,
                                                                " bytes (file cut short?)"));
                }
                std::memcpy(dst, src.bytes.data() + at, slice_bytes);
            } else {
                if (open_header != &h) {
                    open_file = std::make_unique<InputFile>(src.path, src.label);
                    open_header = &h;
                }
                if (at > open_file->size() || open_file->size() - at < slice_bytes) {
                    throw Error(Status::truncated_file,
                                str_cat(s.name(), ": the Pixel Data holds fewer than the ", h.frames * static_cast<std::int64_t>(slice_bytes),
                                        " bytes of ", h.frames, " frame", h.frames == 1 ? "" : "s", " of ", h.columns, "x", h.rows, " ",
                                        type_name(type), " samples (file cut short?)"));
                }
                open_file->read(at, dst, slice_bytes);
            }
            to_native(dst, slice_bytes / type_size(type), type_size(type),
                      h.ts == gdcm::TransferSyntax::ExplicitVRBigEndian ? Endian::big : Endian::little);
            continue;
        }
        auto it = decoded.find(&h);
        if (it == decoded.end()) {
            if (!h.ts.IsValid()) {
                throw Error(Status::unsupported_format,
                            str_cat(h.label, ": transfer syntax ", quote_bytes(h.transfer_uid, 80),
                                    " is not one GDCM decodes; expected a native or a JPEG, JPEG-LS, JPEG 2000 or RLE syntax"));
            }
            gdcm::ImageReader reader;
            std::unique_ptr<std::istringstream> stream;
            open(reader, src, stream);
            bool ok = false;
            try {
                ok = reader.Read();
            } catch (...) { // GDCM also throws plain strings
                ok = false;
            }
            if (!ok) throw Error(Status::bad_format, h.label + ": GDCM cannot read the image (corrupt or unsupported Pixel Data)");
            const gdcm::Image& image = reader.GetImage();
            const std::uint64_t want = static_cast<std::uint64_t>(h.frames) * slice_bytes;
            const unsigned long have = image.GetBufferLength();
            if (have != want) {
                throw Error(Status::bad_format, str_cat(h.label, ": the decoded Pixel Data holds ", have, " bytes, expected ", want,
                                                        " (", h.frames, " frame", h.frames == 1 ? "" : "s", " of ", h.columns, "x", h.rows,
                                                        " ", type_name(type), " samples)"));
            }
            std::vector<char> buffer(static_cast<std::size_t>(want));
            bool decoded_ok = false;
            try {
                decoded_ok = image.GetBuffer(buffer.data());
            } catch (...) { // GDCM also throws plain strings
                decoded_ok = false;
            }
            if (!decoded_ok) {
                throw Error(Status::unsupported_format,
                            str_cat(h.label, ": GDCM cannot decode the Pixel Data of transfer syntax ", h.ts.GetString() ? h.ts.GetString() : "?",
                                    " (", quote_bytes(h.transfer_uid, 80), ")"));
            }
            it = decoded.emplace(&h, std::move(buffer)).first;
        }
        std::memcpy(dst, it->second.data() + frame_offset, slice_bytes);
        if (k + 1 == slices.size() || slices[k + 1].header != &h) {
            // keep a decoded file only while later slices may still come from it
            bool later = false;
            for (std::size_t j = k + 1; j < slices.size() && !later; ++j) later = slices[j].header == &h;
            if (!later) decoded.erase(it);
        }
    }
}

/// Samples after Rescale Slope/Intercept (PS3.3 C.11.1.1.2), in the narrowest type that holds them
/// exactly: the stored type without rescale; int16 or int32 when slopes and intercepts are whole
/// and the values fit; float otherwise. `samples` holds the stored samples, slice after slice;
/// it is converted in place when the type keeps its width (the usual CT: uint16 or int16 stored,
/// int16 Hounsfield units), else into a new buffer.
template <class T>
Volume rescale(std::unique_ptr<std::byte[]> samples, const Grid& grid, const std::vector<Slice>& slices)
{
    const auto make = [&](ScalarType type, std::unique_ptr<std::byte[]> bytes) {
        Volume v(type, grid.dims, grid.spacing, grid.origin, std::move(bytes));
        v.set_direction(grid.direction);
        v.set_space(grid.space);
        v.set_frame_source(grid.frame_source);
        return v;
    };
    bool identity = true, whole = true;
    for (const Slice& s : slices) {
        const double m = s.geometry->slope, c = s.geometry->intercept;
        identity = identity && m == 1 && c == 0;
        whole = whole && m == std::round(m) && c == std::round(c) && std::fabs(m) < 1e6 && std::fabs(c) < 1e9;
    }
    if (identity) return make(grid.type, std::move(samples));
    const std::int64_t plane = grid.dims[0] * grid.dims[1];
    const T* in = reinterpret_cast<const T*>(samples.get());
    double lo = std::numeric_limits<double>::max(), hi = std::numeric_limits<double>::lowest();
    for (std::size_t k = 0; k < slices.size(); ++k) {
        const T* p = in + static_cast<std::int64_t>(k) * plane;
        T mn = p[0], mx = p[0];
        for (std::int64_t i = 0; i < plane; ++i) { // values, not iterators: this vectorizes
            mn = std::min(mn, p[i]);
            mx = std::max(mx, p[i]);
        }
        const double a = slices[k].geometry->slope * static_cast<double>(mn) + slices[k].geometry->intercept;
        const double b = slices[k].geometry->slope * static_cast<double>(mx) + slices[k].geometry->intercept;
        lo = std::min({lo, a, b});
        hi = std::max({hi, a, b});
    }
    if (!(lo >= -static_cast<double>(std::numeric_limits<float>::max()) && hi <= static_cast<double>(std::numeric_limits<float>::max()))) {
        throw Error(Status::non_finite, str_cat(slices.front().name(), ": RescaleSlope and RescaleIntercept take the samples to ",
                                                format_real(lo), " .. ", format_real(hi),
                                                ", outside the float range; expected rescaled values a float holds"));
    }
    ScalarType target = ScalarType::f32;
    if (whole && lo >= -32768 && hi <= 32767) target = ScalarType::i16;
    else if (whole && lo >= -2147483648.0 && hi <= 2147483647.0) target = ScalarType::i32;
    const std::size_t count = static_cast<std::size_t>(plane) * slices.size();
    const bool in_place = type_size(target) == sizeof(T);
    std::unique_ptr<std::byte[]> out =
        in_place ? std::move(samples) : std::make_unique_for_overwrite<std::byte[]>(count * type_size(target));
    if (!in_place) cmc33::detail::advise_huge_pages_within(out.get(), count * type_size(target));
    dispatch_scalar_type(target, [&](auto out_tag) {
        using O = decltype(out_tag);
        O* o = reinterpret_cast<O*>(out.get());
        const T* src = in_place ? reinterpret_cast<const T*>(out.get()) : in;
        // In place the source and the target share memory: a block is copied out first, so that
        // the loops below see distinct arrays and vectorize.
        constexpr std::size_t kBlock = 1024;
        T block[kBlock];
        for (std::size_t k = 0; k < slices.size(); ++k) {
            const double m = slices[k].geometry->slope, c = slices[k].geometry->intercept;
            const bool narrow = sizeof(T) <= 2 && std::fabs(m) <= 16384 && std::fabs(c) <= 536870912;
            // used only for an integer target, whose slopes and intercepts are whole and small
            // (`whole` above); a float target may have any, whose conversion would be undefined
            const bool small = std::fabs(m) < 1e15 && std::fabs(c) < 1e15;
            const auto mi = small ? static_cast<std::int64_t>(m) : 0, ci = small ? static_cast<std::int64_t>(c) : 0;
            for (std::size_t at = k * static_cast<std::size_t>(plane), stop = at + static_cast<std::size_t>(plane); at < stop;) {
                const std::size_t n = std::min(kBlock, stop - at);
                std::memcpy(block, src + at, n * sizeof(T));
                O* __restrict dst = o + at;
                if constexpr (std::is_floating_point_v<O>) {
                    for (std::size_t i = 0; i < n; ++i) dst[i] = static_cast<O>(m * static_cast<double>(block[i]) + c);
                } else if (narrow) {
                    // 16-bit samples times |m| <= 2^14, plus |c| <= 2^29, stay within 32 bits
                    const auto m32 = static_cast<std::int32_t>(mi), c32 = static_cast<std::int32_t>(ci);
                    for (std::size_t i = 0; i < n; ++i) dst[i] = static_cast<O>(m32 * static_cast<std::int32_t>(block[i]) + c32);
                } else {
                    for (std::size_t i = 0; i < n; ++i) dst[i] = static_cast<O>(mi * static_cast<std::int64_t>(block[i]) + ci);
                }
                at += n;
            }
        }
        return 0;
    });
    return make(target, std::move(out));
}

/// The volume of one series.
Volume build_volume(const std::vector<const Header*>& files, const std::vector<Source>& sources, const std::string& label)
{
    check_uniform(files, label);
    Grid grid;
    const std::vector<Slice> slices = sort_slices(files, label, grid);
    const Header& first = *files.front();
    grid.type = stored_type(first);
    const std::uint64_t bytes = payload_bytes(grid.dims, grid.type, label);
    const std::size_t slice_bytes = static_cast<std::size_t>(bytes / static_cast<std::uint64_t>(grid.dims[2]));
    // a file cut short is found before allocating the volume
    for (const Header* f : files) {
        if (!f->native_offset) continue;
        const Source& src = sources[f->source];
        std::uint64_t size = 0;
        if (src.in_memory) {
            size = src.bytes.size();
        } else {
            std::error_code ec;
            size = fs::file_size(src.path, ec);
            if (ec) throw Error(Status::io_error, str_cat(f->label, ": cannot open: ", ec.message()));
        }
        const std::uint64_t need = static_cast<std::uint64_t>(f->frames) * slice_bytes;
        if (*f->native_offset > size || size - *f->native_offset < need) {
            throw Error(Status::truncated_file,
                        str_cat(f->label, ": the Pixel Data should hold ", need, " bytes (", f->frames, " frame", f->frames == 1 ? "" : "s",
                                " of ", f->columns, "x", f->rows, " ", type_name(grid.type), " samples) but the file has ",
                                size > *f->native_offset ? size - *f->native_offset : 0, " after byte ", *f->native_offset,
                                " (file cut short?)"));
        }
    }
    // not zeroed: every byte is read into
    std::unique_ptr<std::byte[]> samples = std::make_unique_for_overwrite<std::byte[]>(static_cast<std::size_t>(bytes));
    cmc33::detail::advise_huge_pages_within(samples.get(), static_cast<std::size_t>(bytes)); // 2 MiB faults, not 4 KiB
    read_stored(slices, sources, samples.get(), slice_bytes, grid.type);
    const auto count = static_cast<std::size_t>(bytes / type_size(grid.type));
    return dispatch_scalar_type(grid.type, [&](auto tag) -> Volume {
        using T = decltype(tag);
        if constexpr (std::is_floating_point_v<T>) {
            throw Error(Status::internal, label + ": floating-point stored samples");
        } else {
            clean_bits(reinterpret_cast<T*>(samples.get()), count, first);
            return rescale<T>(std::move(samples), grid, slices);
        }
    });
}

} // namespace

Volume read_dicom(const fs::path& path, const ReadOptions& options)
{
    std::vector<Source> sources;
    const std::vector<Header> headers = headers_of(path, sources);
    const SeriesMap map = group_series(headers);
    return build_volume(choose_series(map, path.string(), options), sources, path.string());
}

Volume read_dicom_memory(std::string_view bytes, const std::string& label, const ReadOptions& options)
{
    std::vector<Source> sources{Source{{}, bytes, true, label}};
    std::vector<Header> headers;
    headers.push_back(read_header(sources.front(), 0));
    if (headers.front().modality == "DICOMDIR") {
        throw Error(Status::unsupported_format, label + ": a DICOMDIR; in memory, expected one DICOM image file");
    }
    const SeriesMap map = group_series(headers);
    return build_volume(choose_series(map, label, options), sources, label);
}

std::vector<DicomSeries> list_dicom_series(const fs::path& path)
{
    std::vector<Source> sources;
    const std::vector<Header> headers = headers_of(path, sources);
    std::vector<DicomSeries> out;
    for (const auto& [uid, files] : group_series(headers)) {
        DicomSeries s;
        s.uid = uid;
        s.description = files.front()->description;
        s.modality = files.front()->modality;
        s.files = files.size();
        std::int64_t slices = 0;
        for (const Header* f : files) slices += f->frames;
        s.dims = {files.front()->columns, files.front()->rows, slices};
        try {
            Grid grid;
            check_uniform(files, path.string());
            sort_slices(files, path.string(), grid);
            s.spacing = grid.spacing;
        } catch (const Error& e) {
            s.problem = e.what();
        }
        out.push_back(std::move(s));
    }
    return out;
}

std::vector<fs::path> dicom_input_files(const fs::path& path)
{
    try {
        std::vector<fs::path> files;
        std::error_code ec;
        if (fs::is_directory(path, ec)) {
            for (const Source& s : input_sources(path)) files.push_back(s.path);
            return files;
        }
        files.push_back(path);
        bool dicomdir = is_dicomdir_name(path);
        if (!dicomdir && has_dicom_mark(file_head(path))) {
            // a DICOMDIR under another name lists its files too
            dicomdir = read_header(Source{path, {}, false, path.string()}, 0).modality == "DICOMDIR";
        }
        if (dicomdir) {
            for (const fs::path& f : dicomdir_files(path)) files.push_back(f);
        }
        return files;
    } catch (const std::exception&) {
        return {path};
    }
}

#endif // CMC33_WITH_GDCM

} // namespace cmc33::io::detail

namespace cmc33::io {

bool is_dicom_input(const std::filesystem::path& path)
{
    try {
        return detail::image_input(path) == detail::ImageInput::dicom;
    } catch (const std::exception&) {
        return false;
    }
}

bool is_tiff_input(const std::filesystem::path& path)
{
    try {
        return detail::image_input(path) == detail::ImageInput::tiff;
    } catch (const std::exception&) {
        return false;
    }
}

std::vector<DicomSeries> dicom_series(const std::filesystem::path& path)
{
    return detail::list_dicom_series(path);
}

} // namespace cmc33::io
