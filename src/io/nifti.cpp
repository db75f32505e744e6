// NIfTI-1 (nifti.nimh.nih.gov/nifti-1, the header nifti1.h documents: 348 bytes) and NIfTI-2
// (nifti2.h: 540 bytes, 64-bit dims and offsets, double fields): a single file .nii ("n+1",
// "n+2"), gzip-compressed or not, or a header .hdr ("ni1", "ni2") whose samples are in <stem>.img
// (a .hdr.gz header: in <stem>.img.gz, compressed as well).
// Written for cmc33 from those headers' documentation.
//
// Byte order: sizeof_hdr (348 or 540) read in either order says it. The frame, in the order
// nifti1.h gives ("METHOD 3" when sform_code > 0, else "METHOD 2" when qform_code > 0, else
// "METHOD 1"):
//   sform:  [x y z]^T = [srow_x; srow_y; srow_z] [i j k 1]^T
//   qform:  [x y z]^T = R [pixdim[1] i, pixdim[2] j, qfac pixdim[3] k]^T + [qoffset_x y z]^T,
//           R the rotation of the unit quaternion (a, b, c, d), a = sqrt(1 - b^2 - c^2 - d^2),
//           qfac = pixdim[0] (-1 or 1; 0 is taken as 1)
//   pixdim: [x y z]^T = [pixdim[1] i, pixdim[2] j, pixdim[3] k]^T, "no particular spatial
//           orientation" (ANALYZE 7.5 compatibility)
// sform and qform give RAS+ coordinates (x to the right, y anterior, z superior): nibabel's
// img.affine. scl_slope != 0 (and finite) gives value = stored * scl_slope + scl_inter, stored as
// float (8- and 16-bit integers, float) or double (wider types), numpy's promotion of the stored
// type with nibabel's float32 slope.

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "cmc33/io.hpp"
#include "byte_source.hpp"
#include "sample_conversion.hpp"
#include "volume_formats.hpp"

namespace cmc33::io::detail {
namespace {

constexpr std::size_t kHeader1 = 348, kHeader2 = 540;
constexpr std::uint32_t swapped(std::uint32_t v)
{
    return (v >> 24) | ((v >> 8) & 0xff00u) | ((v << 8) & 0xff0000u) | (v << 24);
}

/// Fixed-offset fields of a header in a known byte order.
class Fields {
public:
    Fields(std::string_view bytes, Endian endian) : bytes_(bytes), endian_(endian) {}
    template <class T> T get(std::size_t offset) const
    {
        std::array<unsigned char, sizeof(T)> raw{};
        std::memcpy(raw.data(), bytes_.data() + offset, sizeof(T));
        if (endian_ != native_endian()) {
            for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
        }
        T value{};
        std::memcpy(&value, raw.data(), sizeof(T));
        return value;
    }
    double real(std::size_t offset, bool wide) const
    {
        return wide ? get<double>(offset) : static_cast<double>(get<float>(offset));
    }

private:
    std::string_view bytes_;
    Endian endian_;
};

/// What cmc33 reads of a header, from either version.
struct Header {
    int version = 1;
    Endian endian = Endian::little;
    bool single_file = true; ///< "n+1"/"n+2": the samples follow the header in the same file
    std::array<std::int64_t, 8> dim{};
    int datatype = 0;
    std::array<double, 8> pixdim{};
    double vox_offset = 0;
    double scl_slope = 0, scl_inter = 0;
    int qform_code = 0, sform_code = 0;
    std::array<double, 3> quatern{}, qoffset{};
    std::array<std::array<double, 4>, 3> srow{};
    int intent_code = 0;
};

/// 1 or 2 and the byte order, from sizeof_hdr and the magic; 0 when `head` is no NIfTI header.
int version_of(std::string_view head, Endian* endian, bool* single_file)
{
    if (head.size() < 8) return 0;
    std::uint32_t size = 0;
    std::memcpy(&size, head.data(), 4);
    const bool native = size == kHeader1 || size == kHeader2;
    const bool other = swapped(size) == kHeader1 || swapped(size) == kHeader2;
    if (!native && !other) return 0;
    const std::uint32_t value = native ? size : swapped(size);
    const Endian order = native ? native_endian() : (native_endian() == Endian::little ? Endian::big : Endian::little);
    int version = 0;
    bool single = true;
    if (value == kHeader1 && head.size() >= kHeader1) {
        const std::string_view magic = head.substr(344, 4);
        if (magic == std::string_view("n+1\0", 4)) version = 1;
        if (magic == std::string_view("ni1\0", 4)) version = 1, single = false;
    } else if (value == kHeader2) {
        const std::string_view magic = head.substr(4, 8);
        if (magic == std::string_view("n+2\0\r\n\032\n", 8)) version = 2;
        if (magic == std::string_view("ni2\0\r\n\032\n", 8)) version = 2, single = false;
    }
    if (version != 0) {
        if (endian) *endian = order;
        if (single_file) *single_file = single;
    }
    return version;
}

Header parse_header(std::string_view head, const std::string& label)
{
    Header h;
    if (version_of(head, &h.endian, &h.single_file) == 0) {
        std::uint32_t size = 0;
        if (head.size() >= 4) std::memcpy(&size, head.data(), 4);
        if ((size == kHeader1 || swapped(size) == kHeader1) && head.size() >= kHeader1) {
            throw Error(Status::unsupported_format,
                        str_cat(label, ": an ANALYZE 7.5 header (sizeof_hdr 348 without the NIfTI magic \"n+1\" or "
                                       "\"ni1\" at byte 344, found ",
                                quote_bytes(head.substr(344, 4)),
                                "); cmc33 reads NIfTI-1 and NIfTI-2, whose orientation is defined (convert it to NIfTI)"));
        }
        if (head.size() < kHeader1) {
            throw Error(Status::truncated_file, str_cat(label, ": ", head.size(),
                                                        " bytes, shorter than a NIfTI-1 header (348 bytes)"));
        }
        throw Error(Status::bad_format,
                    str_cat(label, ": not a NIfTI file: sizeof_hdr ", quote_bytes(head.substr(0, 4)),
                            " is neither 348 (NIfTI-1) nor 540 (NIfTI-2) in either byte order, or the magic is missing"));
    }
    h.version = version_of(head, nullptr, nullptr);
    const std::size_t need = h.version == 1 ? kHeader1 : kHeader2;
    if (head.size() < need) {
        throw Error(Status::truncated_file, str_cat(label, ": the NIfTI-", h.version, " header takes ", need,
                                                    " bytes but the file holds only ", head.size()));
    }
    const Fields f(head, h.endian);
    if (h.version == 1) {
        for (std::size_t i = 0; i < 8; ++i) h.dim[i] = f.get<std::int16_t>(40 + 2 * i);
        h.intent_code = f.get<std::int16_t>(68);
        h.datatype = f.get<std::int16_t>(70);
        for (std::size_t i = 0; i < 8; ++i) h.pixdim[i] = f.real(76 + 4 * i, false);
        h.vox_offset = f.real(108, false);
        h.scl_slope = f.real(112, false);
        h.scl_inter = f.real(116, false);
        h.qform_code = f.get<std::int16_t>(252);
        h.sform_code = f.get<std::int16_t>(254);
        for (std::size_t i = 0; i < 3; ++i) h.quatern[i] = f.real(256 + 4 * i, false);
        for (std::size_t i = 0; i < 3; ++i) h.qoffset[i] = f.real(268 + 4 * i, false);
        for (std::size_t r = 0; r < 3; ++r)
            for (std::size_t c = 0; c < 4; ++c) h.srow[r][c] = f.real(280 + 16 * r + 4 * c, false);
    } else {
        h.datatype = f.get<std::int16_t>(12);
        for (std::size_t i = 0; i < 8; ++i) h.dim[i] = f.get<std::int64_t>(16 + 8 * i);
        for (std::size_t i = 0; i < 8; ++i) h.pixdim[i] = f.real(104 + 8 * i, true);
        h.vox_offset = static_cast<double>(f.get<std::int64_t>(168));
        h.scl_slope = f.real(176, true);
        h.scl_inter = f.real(184, true);
        h.qform_code = f.get<std::int32_t>(344);
        h.sform_code = f.get<std::int32_t>(348);
        for (std::size_t i = 0; i < 3; ++i) h.quatern[i] = f.real(352 + 8 * i, true);
        for (std::size_t i = 0; i < 3; ++i) h.qoffset[i] = f.real(376 + 8 * i, true);
        for (std::size_t r = 0; r < 3; ++r)
            for (std::size_t c = 0; c < 4; ++c) h.srow[r][c] = f.real(400 + 32 * r + 8 * c, true);
        h.intent_code = f.get<std::int32_t>(504);
    }
    return h;
}

struct DataType {
    int code;
    std::string_view name;
    ScalarType read_as; ///< the type of the same width the bytes are read as
    StoredKind kind;
    bool supported;
};

// nifti1.h's DT_* codes.
constexpr DataType kDataTypes[] = {
    {2, "uint8", ScalarType::u8, StoredKind::as_is, true},
    {4, "int16", ScalarType::i16, StoredKind::as_is, true},
    {8, "int32", ScalarType::i32, StoredKind::as_is, true},
    {16, "float32", ScalarType::f32, StoredKind::as_is, true},
    {64, "float64", ScalarType::f64, StoredKind::as_is, true},
    {256, "int8", ScalarType::i8, StoredKind::as_is, true},
    {512, "uint16", ScalarType::u16, StoredKind::as_is, true},
    {768, "uint32", ScalarType::u32, StoredKind::as_is, true},
    {1024, "int64", ScalarType::f64, StoredKind::int64, true},
    {1280, "uint64", ScalarType::f64, StoredKind::uint64, true},
    {1, "binary (1 bit per voxel)", ScalarType::u8, StoredKind::as_is, false},
    {32, "complex64", ScalarType::u8, StoredKind::as_is, false},
    {128, "RGB24", ScalarType::u8, StoredKind::as_is, false},
    {1536, "float128", ScalarType::u8, StoredKind::as_is, false},
    {1792, "complex128", ScalarType::u8, StoredKind::as_is, false},
    {2048, "complex256", ScalarType::u8, StoredKind::as_is, false},
    {2304, "RGBA32", ScalarType::u8, StoredKind::as_is, false},
};

std::string_view xform_name(int code)
{
    switch (code) {
    case 1: return "scanner anatomy";
    case 2: return "aligned anatomy";
    case 3: return "Talairach";
    case 4: return "MNI 152";
    case 5: return "template";
    default: return "";
    }
}

std::string xform_source(std::string_view which, int code)
{
    const std::string_view name = xform_name(code);
    return str_cat(which, " (code ", code, name.empty() ? "" : ": ", name, ")");
}

/// Sets the frame of `grid` from the header, in nifti1.h's order of methods.
void set_nifti_frame(Grid& grid, const Header& h, const std::string& label)
{
    const auto finite = [&](double v, std::string_view what) {
        if (!std::isfinite(v)) {
            throw Error(Status::non_finite, str_cat(label, ": ", what, " is ", v, "; the frame needs finite numbers"));
        }
    };
    std::array<Vec3, 3> axes{};
    if (h.sform_code > 0) {
        for (std::size_t r = 0; r < 3; ++r) {
            for (std::size_t c = 0; c < 4; ++c) finite(h.srow[r][c], str_cat("srow_", "xyz"[r], '[', c, ']'));
            for (std::size_t a = 0; a < 3; ++a) axes[a][r] = h.srow[r][a];
            grid.origin[r] = h.srow[r][3];
        }
        set_frame(grid, axes, {1, 1, 1}, label, "the sform (srow_x, srow_y, srow_z)");
        grid.space = "right-anterior-superior";
        grid.frame_source = xform_source("sform", h.sform_code);
        return;
    }
    if (h.qform_code > 0) {
        const double b = h.quatern[0], c = h.quatern[1], d = h.quatern[2];
        finite(b, "quatern_b"), finite(c, "quatern_c"), finite(d, "quatern_d");
        for (std::size_t i = 0; i < 3; ++i) finite(h.qoffset[i], str_cat("qoffset_", "xyz"[i]));
        const double bcd = b * b + c * c + d * d;
        // a^2 = 1 - (b^2 + c^2 + d^2) must not be negative beyond the rounding of the stored floats
        if (bcd > 1 + 1e-6) {
            throw Error(Status::bad_format,
                        str_cat(label, ": the qform quaternion (b, c, d) = (", format_real(b), ", ", format_real(c), ", ",
                                format_real(d), ") has b^2 + c^2 + d^2 = ", format_real(bcd),
                                " > 1; expected the vector part of a unit quaternion"));
        }
        const double a = bcd < 1 ? std::sqrt(1 - bcd) : 0.0;
        // the rotation of the quaternion (a, b, c, d), normalised as a unit quaternion
        const double s = 2 / (a * a + bcd);
        const Mat3 rot{{{1 - s * (c * c + d * d), s * (b * c - a * d), s * (b * d + a * c)},
                        {s * (b * c + a * d), 1 - s * (b * b + d * d), s * (c * d - a * b)},
                        {s * (b * d - a * c), s * (c * d + a * b), 1 - s * (b * b + c * c)}}};
        const double qfac = h.pixdim[0] < 0 ? -1.0 : 1.0;
        Vec3 scale{};
        for (std::size_t a_ = 0; a_ < 3; ++a_) {
            const double p = h.pixdim[a_ + 1];
            finite(p, str_cat("pixdim[", a_ + 1, ']'));
            if (!(p > 0)) {
                throw Error(Status::bad_format,
                            str_cat(label, ": pixdim[", a_ + 1, "] = ", format_real(p),
                                    "; the qform (code ", h.qform_code, ", no sform) needs voxel sizes pixdim[1..3] > 0"));
            }
            scale[a_] = p;
        }
        scale[2] *= qfac;
        for (std::size_t a_ = 0; a_ < 3; ++a_)
            for (std::size_t r = 0; r < 3; ++r) axes[a_][r] = rot[r][a_];
        set_frame(grid, axes, {1, 1, 1}, label, "the qform");
        // spacing > 0: a negative qfac flips the direction of axis k instead
        grid.spacing = {scale[0], scale[1], std::fabs(scale[2])};
        if (qfac < 0)
            for (std::size_t r = 0; r < 3; ++r) grid.direction[r][2] = -grid.direction[r][2];
        grid.origin = {h.qoffset[0], h.qoffset[1], h.qoffset[2]};
        grid.space = "right-anterior-superior";
        grid.frame_source = xform_source("qform", h.qform_code);
        return;
    }
    for (std::size_t a = 0; a < 3; ++a) {
        const double p = h.pixdim[a + 1];
        finite(p, str_cat("pixdim[", a + 1, ']'));
        if (p == 0) {
            throw Error(Status::bad_format,
                        str_cat(label, ": pixdim[", a + 1,
                                "] = 0 and neither sform_code nor qform_code is set: no spacing for axis ", a,
                                "; expected voxel sizes pixdim[1..3] != 0"));
        }
        axes[a][a] = p;
    }
    set_frame(grid, axes, {1, 1, 1}, label, "pixdim");
    grid.origin = {0, 0, 0};
    grid.space.clear(); // nifti1.h: no particular orientation
    grid.frame_source = "pixdim (sform_code and qform_code 0: no orientation)";
}

/// A gzip stream (RFC 1952's magic): a .nii.gz file.
bool is_compressed(const ByteInput& input)
{
    const std::string magic = input.read_string(0, 2);
    return magic == "\x1f\x8b";
}

/// The first bytes of `input` (inflated when it is compressed): enough for a NIfTI-2 header.
std::string head_of(const ByteInput& input, bool compressed)
{
    if (!compressed) return input.read_string(0, kHeader2);
    InflateStream stream(input, 0, input.size(), input.label());
    std::string head(kHeader2, '\0');
    std::size_t got = 0;
    while (got < head.size()) {
        const std::size_t n = stream.produce(reinterpret_cast<unsigned char*>(head.data()) + got, head.size() - got);
        if (n == 0) break;
        got += n;
    }
    head.resize(got);
    return head;
}

/// x.hdr -> x.img; a compressed x.hdr.gz -> x.img.gz, compressed too (as nibabel writes pairs).
std::string pair_data_name(const std::string& header_name, bool compressed)
{
    std::filesystem::path stem = std::filesystem::path(header_name).stem();
    if (compressed && lower_ascii(stem.extension().string()) == ".hdr") stem = stem.stem();
    return stem.string() + (compressed ? ".img.gz" : ".img");
}

} // namespace

std::optional<std::string> nifti_data_file_name(const ByteInput& file)
{
    try {
        const bool compressed = is_compressed(file);
        bool single = true;
        if (version_of(head_of(file, compressed), nullptr, &single) == 0 || single) return std::nullopt;
        return pair_data_name(file.label(), compressed);
    } catch (const Error&) {
        return std::nullopt; // not inflatable: no NIfTI header
    }
}

Volume read_nifti(const ByteInput& file, const OpenDataFile& open_data, const ReadOptions& options,
                  const ReadSamples& read, bool planes)
{
    const std::string& label = file.label();
    if (file.size() == 0) {
        throw Error(Status::truncated_file, label + ": the file is empty (0 bytes), expected a NIfTI header");
    }
    if (options.spacing || options.origin) {
        throw Error(Status::invalid_argument,
                    label + ": a NIfTI file gives its own frame; --spacing and --origin are for formats without one (.npy)");
    }
    const bool header_compressed = is_compressed(file);
    const std::string head = head_of(file, header_compressed);
    const Header h = parse_header(head, label);
    const std::string version = str_cat("NIfTI-", h.version);

    // dimensions: dim[0] says how many of dim[1..7] count
    const std::int64_t rank = h.dim[0];
    if (rank < 1 || rank > 7) {
        throw Error(Status::bad_format, str_cat(label, ": dim[0] = ", rank, ", expected the number of dimensions, 1 to 7"));
    }
    for (std::int64_t i = 1; i <= rank; ++i) {
        if (h.dim[static_cast<std::size_t>(i)] < 1) {
            throw Error(Status::bad_format, str_cat(label, ": dim[", i, "] = ", h.dim[static_cast<std::size_t>(i)],
                                                    ", expected a size >= 1 (dim[0] = ", rank, ")"));
        }
    }
    if (rank < 3) {
        throw Error(Status::unsupported_format, str_cat(label, ": dim[0] = ", rank, ": a ", rank,
                                                        "-D image; cmc33 meshes 3-D volumes"));
    }
    for (std::size_t i = 5; i <= static_cast<std::size_t>(rank); ++i) {
        if (h.dim[i] > 1) {
            throw Error(Status::unsupported_format,
                        str_cat(label, ": dim[", i, "] = ", h.dim[i], " (intent code ", h.intent_code,
                                "): values per voxel beyond time, such as vectors or tensors; cmc33 meshes one scalar "
                                "per voxel, 3-D or 3-D over time (dim[4])"));
        }
    }
    const std::int64_t frames = rank >= 4 ? h.dim[4] : 1;
    std::int64_t frame = 0;
    if (options.frame) {
        frame = *options.frame;
        if (frame < 0 || frame >= frames) {
            throw Error(Status::invalid_argument,
                        frames == 1 ? str_cat(label, ": frame ", frame, " asked for, but the file holds one 3-D volume (frame 0)")
                                    : str_cat(label, ": frame ", frame, " asked for, but the file holds ", frames,
                                              " frames (dim[4]): 0 to ", frames - 1));
        }
    } else if (frames > 1) {
        throw Error(Status::invalid_argument,
                    str_cat(label, ": holds ", frames, " frames of ", h.dim[1], 'x', h.dim[2], 'x', h.dim[3],
                            " (dim[4] = ", frames, "); choose one with --frame N, 0 to ", frames - 1,
                            " (as nibabel's img.dataobj[..., N])"));
    }

    const DataType* type = nullptr;
    for (const DataType& t : kDataTypes) {
        if (t.code == h.datatype) type = &t;
    }
    if (!type) {
        throw Error(Status::bad_format, str_cat(label, ": datatype ", h.datatype,
                                                " is not a NIfTI type code (2 uint8, 4 int16, 8 int32, 16 float32, 64 "
                                                "float64, 256 int8, 512 uint16, 768 uint32, 1024 int64, 1280 uint64)"));
    }
    if (!type->supported) {
        throw Error(Status::unsupported_format,
                    str_cat(label, ": datatype ", h.datatype, " (", type->name,
                            ") is not a real scalar; cmc33 reads uint8, int8, int16, uint16, int32, uint32, int64, "
                            "uint64, float32 and float64 samples"));
    }

    Grid grid;
    grid.type = type->read_as;
    grid.dims = {h.dim[1], h.dim[2], h.dim[3]};
    set_nifti_frame(grid, h, label);

    // where the samples are
    const double min_offset = h.single_file ? static_cast<double>(h.version == 1 ? kHeader1 + 4 : kHeader2 + 4) : 0.0;
    if (!std::isfinite(h.vox_offset) || h.vox_offset != std::floor(h.vox_offset) || h.vox_offset < min_offset ||
        h.vox_offset > 9.0e15) {
        throw Error(Status::bad_format,
                    str_cat(label, ": vox_offset ", format_real(h.vox_offset), " is not a whole number of bytes",
                            h.single_file ? str_cat(" >= ", min_offset, " (the header and its extension flag come first)") : ""));
    }
    const auto vox_offset = static_cast<std::uint64_t>(h.vox_offset);
    const std::uint64_t frame_bytes = payload_bytes(grid.dims, grid.type, label);
    if (static_cast<std::uint64_t>(frames) > (std::numeric_limits<std::uint64_t>::max() - vox_offset) / frame_bytes) {
        throw Error(Status::too_large, str_cat(label, ": ", frames, " frames of ", frame_bytes, " bytes overflow 64 bits"));
    }
    const std::uint64_t total = vox_offset + static_cast<std::uint64_t>(frames) * frame_bytes;
    const std::uint64_t start = vox_offset + static_cast<std::uint64_t>(frame) * frame_bytes;

    std::unique_ptr<ByteInput> data_file;
    if (!h.single_file) data_file = open_data(pair_data_name(label, header_compressed));
    const ByteInput& data = data_file ? *data_file : file;
    // a single file is compressed when its header is, and so is the .img.gz of a compressed pair
    const bool compressed = header_compressed;
    const std::string what = frames == 1 ? str_cat(dims_text(grid.dims), ' ', type->name)
                                         : str_cat(frames, " frames of ", dims_text(grid.dims), ' ', type->name);

    Storage storage;
    storage.endian = h.endian;
    Volume volume;
    if (!compressed) {
        // every frame must be there, and nothing after them (docs/formats.md)
        if (data.size() < total) {
            throw Error(Status::truncated_file,
                        str_cat(data.label(), ": the ", version, " header declares ", what, " (", total - vox_offset,
                                " bytes) from byte ", vox_offset, " but the file holds only ", data.size(),
                                " bytes (file cut short, or wrong dim?)"));
        }
        if (data.size() > total) {
            throw Error(Status::bad_format,
                        str_cat(data.label(), ": the ", version, " header declares ", what, " (", total - vox_offset,
                                " bytes) from byte ", vox_offset, " but the file holds ", data.size() - total,
                                " more bytes after them (wrong dim, or data appended?)"));
        }
        storage.encoding = Encoding::raw;
        storage.offset = start;
        storage.check_trailing = false; // checked above for all frames
        volume = read(data, grid, storage, data.label(), nullptr);
    } else if (frame + 1 == frames) {
        // the last (or only) frame ends the stream: read_samples' checks hold as they are
        storage.encoding = Encoding::compressed;
        storage.offset = 0;
        storage.skip_inflated = start;
        volume = read(data, grid, storage, data.label(), nullptr);
    } else {
        if (planes) {
            throw Error(Status::unsupported_format,
                        str_cat(data.label(), ": frame ", frame, " of ", frames,
                                " in a compressed NIfTI file cannot be read plane by plane (only the last frame can); "
                                "decompress it (gunzip) or read it without --memory-limit"));
        }
        check_inflate_bound(data.size(), total, data.label(), str_cat("the header declares ", what, " (", total, " bytes with the header)"));
        InflateStream stream(data, 0, data.size(), data.label());
        stream.skip(start, total);
        auto samples = std::make_unique<std::byte[]>(static_cast<std::size_t>(frame_bytes));
        stream.read_exactly(reinterpret_cast<unsigned char*>(samples.get()), static_cast<std::size_t>(frame_bytes), total);
        stream.skip(total - start - frame_bytes, total);
        stream.finish(total);
        to_native(samples.get(), static_cast<std::size_t>(frame_bytes / type_size(grid.type)), type_size(grid.type), h.endian);
        volume = Volume(grid.type, grid.dims, grid.spacing, grid.origin, std::move(samples));
        volume.set_direction(grid.direction);
        volume.set_space(grid.space);
        volume.set_frame_source(grid.frame_source);
    }

    // nifti1.h: scl_slope 0 means unscaled; nibabel also leaves slope 1, inter 0 unscaled
    const bool scaled = std::isfinite(h.scl_slope) && h.scl_slope != 0 &&
                        !(h.scl_slope == 1 && (h.scl_inter == 0 || !std::isfinite(h.scl_inter)));
    if (planes) {
        if (type->kind != StoredKind::as_is || scaled) {
            throw Error(Status::unsupported_format,
                        str_cat(label, ": ",
                                scaled ? str_cat("samples rescaled by scl_slope ", format_real(h.scl_slope), ", scl_inter ",
                                                 format_real(h.scl_inter))
                                       : str_cat(type->name, " samples"),
                                " are converted after reading, which --memory-limit cannot do plane by plane; read it "
                                "without --memory-limit"));
        }
        return volume;
    }
    volume = widen_samples(std::move(volume), type->kind);
    if (scaled) {
        const double inter = std::isfinite(h.scl_inter) ? h.scl_inter : 0.0;
        const ScalarType to = type_size(grid.type) <= 2 || grid.type == ScalarType::f32 ? ScalarType::f32 : ScalarType::f64;
        volume = rescale_samples(volume, h.scl_slope, inter, to, label);
    }
    return volume;
}

std::optional<VolumeFormat> sniff_volume_format(const ByteInput& file)
{
    const std::string start = file.read_string(0, 1024);
    if (start.rfind("\x93NUMPY", 0) == 0) return VolumeFormat::npy;
    // VTK XML: an optional XML declaration and comments, then <VTKFile type="ImageData"
    const std::size_t tag = start.find("<VTKFile");
    if (tag != std::string::npos && start.find("ImageData", tag) != std::string::npos &&
        start.find_first_not_of(" \t\r\n", 0) == start.find('<')) {
        return VolumeFormat::vti;
    }
    try {
        const std::string head = head_of(file, is_compressed(file));
        if (version_of(head, nullptr, nullptr) != 0) return VolumeFormat::nifti;
    } catch (const Error&) {
        // a stream that does not inflate is no NIfTI file
    }
    return std::nullopt;
}

} // namespace cmc33::io::detail
