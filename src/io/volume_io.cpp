// Volume I/O: the choice of format by extension, and what the formats share: size checks, reading
// samples (raw, compressed) into a volume, writing samples. Header values and ASCII samples:
// volume_header.cpp.

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "cmc33/io.hpp"
#include "atomic_file.hpp"
#include "byte_source.hpp"
#include "volume_formats.hpp"
#include "dicom.hpp"
#include "tiff.hpp"

namespace cmc33::io {
namespace detail {

// ---- samples --------------------------------------------------------------------------------

namespace {

Volume allocate(const Grid& grid, const std::string& label)
{
    try {
        Volume volume(grid.type, grid.dims, grid.spacing, grid.origin);
        volume.set_direction(grid.direction);
        volume.set_space(grid.space);
        volume.set_frame_source(grid.frame_source);
        return volume;
    } catch (const Error& e) {
        throw Error(e.status(), label + ": " + e.what());
    }
}

std::string declared(const Grid& grid, std::uint64_t bytes)
{
    return str_cat("header declares ", dims_text(grid.dims), ' ', type_name(grid.type), " (", bytes,
                   " bytes)");
}

} // namespace

namespace {

/// The bytes of a file of `size` bytes after the samples' offset.
/// @throws Error{truncated_file} when the offset lies beyond the end
std::uint64_t bytes_after_offset(std::uint64_t size, const Storage& storage, const std::string& label)
{
    if (storage.offset > size) {
        throw Error(Status::truncated_file,
                    str_cat(label, ": the samples should start at byte ", storage.offset,
                            " but the file has only ", size, " bytes (file cut short?)"));
    }
    return size - storage.offset;
}

} // namespace

std::uint64_t check_raw_samples(const ByteInput& file, const Grid& grid, const Storage& storage,
                                const std::string& label)
{
    const std::uint64_t bytes = payload_bytes(grid.dims, grid.type, label);
    const std::uint64_t size = file.size();
    const std::uint64_t available = bytes_after_offset(size, storage, label);
    if (available < bytes) {
        throw Error(Status::truncated_file,
                    str_cat(label, ": ", declared(grid, bytes), " but only ", available,
                            " bytes follow byte ", storage.offset,
                            " (file cut short, or wrong sizes?)"));
    }
    if (available > bytes && !storage.at_end && storage.check_trailing) {
        throw Error(Status::bad_format,
                    str_cat(label, ": ", declared(grid, bytes), " but ", available,
                            " bytes follow byte ", storage.offset, ": ", available - bytes,
                            " more after the samples (wrong sizes, or data appended?)"));
    }
    return storage.at_end ? size - bytes : storage.offset;
}

std::uint64_t check_compressed_samples(const ByteInput& file, const Grid& grid, const Storage& storage,
                                       const std::string& label)
{
    const std::uint64_t bytes = payload_bytes(grid.dims, grid.type, label);
    const std::uint64_t size = file.size();
    const std::uint64_t available = bytes_after_offset(size, storage, label);
    std::uint64_t stream = available;
    if (storage.stored_size) {
        if (*storage.stored_size > available) {
            throw Error(Status::truncated_file,
                        str_cat(label, ": the header declares ", *storage.stored_size,
                                " compressed bytes but only ", available, " follow byte ",
                                storage.offset,
                                " (file cut short, or wrong compressed size?)"));
        }
        stream = *storage.stored_size;
    }
    // Nothing of the declared size is allocated unless the stream could hold it, and then
    // only as much as the stream really yields.
    const std::uint64_t inflated = storage.skip_inflated + bytes;
    check_inflate_bound(stream, inflated,
                        label, storage.skip_inflated == 0
                                   ? declared(grid, bytes)
                                   : str_cat(declared(grid, bytes), " after ",
                                             storage.skip_inflated, " skipped bytes (",
                                             inflated, " in all)"));
    return stream;
}

void check_after_stream(const ByteInput& file, const Storage& storage, std::uint64_t stream, const std::string& label)
{
    const std::uint64_t available = file.size() - storage.offset;
    if (stream < available && storage.check_trailing) {
        throw Error(Status::bad_format,
                    str_cat(label, ": the header declares ", stream,
                            " compressed bytes but ", available, " follow byte ",
                            storage.offset, ": ", available - stream,
                            " more after the stream (wrong compressed size?)"));
    }
}

Volume read_samples(const ByteInput& file, const Grid& grid, const Storage& storage,
                    const std::string& label, std::uint64_t* end)
{
    const std::uint64_t bytes = payload_bytes(grid.dims, grid.type, label);
    const std::uint64_t size = file.size();
    const std::uint64_t available = bytes_after_offset(size, storage, label);
    const std::size_t width = type_size(grid.type);

    switch (storage.encoding) {
    case Encoding::raw: {
        const std::uint64_t offset = check_raw_samples(file, grid, storage, label);
        Volume volume = allocate(grid, label);
        file.read(offset, volume.bytes(), volume.byte_size());
        to_native(volume.bytes(), static_cast<std::size_t>(volume.sample_count()), width,
                  storage.endian);
        if (end) *end = offset + bytes;
        return volume;
    }
    case Encoding::compressed: {
        const std::uint64_t stream = check_compressed_samples(file, grid, storage, label);
        const std::string compressed = file.read_string(storage.offset, stream);
        std::unique_ptr<std::byte[]> samples = inflate_exact(
            compressed, storage.skip_inflated, static_cast<std::size_t>(bytes), label);
        check_after_stream(file, storage, stream, label);
        to_native(samples.get(), static_cast<std::size_t>(bytes / width), width, storage.endian);
        if (end) *end = storage.offset + stream;
        try {
            Volume volume(grid.type, grid.dims, grid.spacing, grid.origin, std::move(samples));
            volume.set_direction(grid.direction);
            volume.set_space(grid.space);
            volume.set_frame_source(grid.frame_source);
            return volume;
        } catch (const Error& e) {
            throw Error(e.status(), label + ": " + e.what());
        }
    }
    case Encoding::ascii: {
        // Each value takes at least two bytes (a digit and a blank), the last one at least one:
        // check before allocating.
        const auto count = static_cast<std::uint64_t>(grid.dims[0]) *
                           static_cast<std::uint64_t>(grid.dims[1]) *
                           static_cast<std::uint64_t>(grid.dims[2]);
        if (count > available / 2 + 1) {
            throw Error(Status::truncated_file,
                        str_cat(label, ": the header declares ", dims_text(grid.dims), " = ", count,
                                " ASCII values but only ", available,
                                " bytes of data follow; each value takes at "
                                "least 2 (file cut short, or wrong sizes?)"));
        }
        const std::string text = file.read_string(storage.offset, available);
        Volume volume = allocate(grid, label);
        const std::size_t stop = parse_ascii_samples(text, volume, label);
        if (storage.check_trailing) {
            const std::size_t extra = text.find_first_not_of(" \t\n\r\v\f", stop);
            if (extra != std::string::npos) {
                throw Error(Status::bad_format,
                            str_cat(label, ": the header declares ", count,
                                    " values but more follow: ",
                                    quote_bytes(split_words(std::string_view(text).substr(
                                                    extra, 64)).front()),
                                    " at byte ", storage.offset + extra,
                                    " (wrong sizes, or data appended?)"));
            }
        }
        if (end) *end = storage.offset + stop;
        return volume;
    }
    }
    throw Error(Status::internal, label + ": unknown sample encoding");
}

void write_samples(std::ostream& out, const Volume& volume, Endian endian)
{
    const std::size_t width = type_size(volume.type());
    const auto* data = reinterpret_cast<const char*>(volume.bytes());
    const std::size_t total = volume.byte_size();
    if (width == 1 || endian == native_endian()) {
        out.write(data, static_cast<std::streamsize>(total));
        return;
    }
    constexpr std::size_t kBlock = std::size_t{1} << 20; // a multiple of every sample size
    std::vector<std::byte> block(std::min(total, kBlock));
    for (std::size_t done = 0; done < total;) {
        const std::size_t n = std::min(kBlock, total - done);
        std::memcpy(block.data(), data + done, n);
        swap_bytes(block.data(), n / width, width);
        out.write(reinterpret_cast<const char*>(block.data()), static_cast<std::streamsize>(n));
        done += n;
    }
}

} // namespace detail

// ---- public API -----------------------------------------------------------------------------

ScalarType parse_type(const std::string& name)
{
    struct Name {
        std::string_view text;
        ScalarType type;
    };
    static constexpr std::array<Name, 16> kNames{{
        {"int8", ScalarType::i8},
        {"uint8", ScalarType::u8},
        {"int16", ScalarType::i16},
        {"uint16", ScalarType::u16},
        {"int32", ScalarType::i32},
        {"uint32", ScalarType::u32},
        {"float", ScalarType::f32},
        {"double", ScalarType::f64},
        {"char", ScalarType::i8},
        {"uchar", ScalarType::u8},
        {"short", ScalarType::i16},
        {"ushort", ScalarType::u16},
        {"int", ScalarType::i32},
        {"uint", ScalarType::u32},
        {"float32", ScalarType::f32},
        {"float64", ScalarType::f64},
    }};
    const std::string key = detail::lower_ascii(detail::trim(name));
    for (const Name& n : kNames) {
        if (n.text == key) return n.type;
    }
    throw Error(Status::invalid_argument,
                "unknown sample type " + detail::quote_bytes(name) +
                    "; expected one of int8, uint8, int16, uint16, int32, uint32, float, double "
                    "(or char, uchar, short, ushort, int, uint, float32, float64)");
}

namespace {

/// x.hdr beside x.img, or x.hdr.gz beside x.img.gz, when it is a NIfTI pair's header naming that
/// file (a NIfTI pair named by its data file).
std::optional<std::filesystem::path> nifti_pair_header(const std::filesystem::path& path)
{
    const std::string name = path.filename().string();
    const std::string lower = detail::lower_ascii(name);
    std::vector<std::string> headers;
    if (lower.ends_with(".img")) {
        const std::string stem = name.substr(0, name.size() - 4);
        headers = {stem + ".hdr", stem + ".HDR"};
    } else if (lower.ends_with(".img.gz")) {
        const std::string stem = name.substr(0, name.size() - 7);
        headers = {stem + ".hdr.gz", stem + ".HDR.gz", stem + ".HDR.GZ"};
    } else {
        return std::nullopt;
    }
    for (const std::string& candidate : headers) {
        const std::filesystem::path header = path.parent_path() / candidate;
        std::error_code ec;
        if (!std::filesystem::is_regular_file(header, ec)) continue;
        try {
            const detail::InputFile file(header, header.string());
            const std::optional<std::string> data = detail::nifti_data_file_name(file);
            if (data && detail::lower_ascii(*data) == lower) return header;
        } catch (const Error&) {
        }
    }
    return std::nullopt;
}

/// The format the content of `path` shows (NIfTI, .npy, .vti), or nullopt (also when unreadable).
std::optional<VolumeFormat> sniffed_format(const std::filesystem::path& path)
{
    try {
        std::error_code ec;
        if (!std::filesystem::is_regular_file(path, ec)) return std::nullopt;
        const detail::InputFile file(path, path.string());
        return detail::sniff_volume_format(file);
    } catch (const Error&) {
        return std::nullopt;
    }
}

/// NIfTI, .npy and .vti, read by content; `open_data` serves a NIfTI pair's .img.
Volume read_sniffed(VolumeFormat format, const detail::ByteInput& file, const detail::OpenDataFile& open_data,
                    const ReadOptions& options)
{
    switch (format) {
    case VolumeFormat::nifti: return detail::read_nifti(file, open_data, options);
    case VolumeFormat::npy: return detail::read_npy(file, options);
    case VolumeFormat::vti: return detail::read_vti(file, options);
    default: break;
    }
    throw Error(Status::internal, file.label() + ": not a format read by content");
}

} // namespace

bool has_volume_header(const std::filesystem::path& path)
{
    const std::string ext = detail::lower_extension(path);
    if (ext == ".nrrd" || ext == ".nhdr" || ext == ".mhd" || ext == ".mha" || ext == ".vtk" || ext == ".nii" ||
        ext == ".hdr" || ext == ".npy" || ext == ".vti" || detail::lower_ascii(path.filename().string()).ends_with(".nii.gz")) {
        return true;
    }
    return nifti_pair_header(path) || sniffed_format(path) || detail::image_input(path) != detail::ImageInput::none;
}

std::vector<std::filesystem::path> volume_files(const std::filesystem::path& path)
{
    // a DICOM or TIFF folder: the files in it that are read
    if (auto files = detail::image_input_files(path)) return std::move(*files);
    std::vector<std::filesystem::path> files{path};
    const std::string ext = detail::lower_extension(path);
    // a NIfTI pair: the header and its data file <stem>.img, whichever of them was named
    if (const auto header = nifti_pair_header(path)) {
        files.push_back(*header);
        return files;
    }
    if (sniffed_format(path) == VolumeFormat::nifti) {
        // the data file the reader opens (x.img, or x.img.gz beside a compressed x.hdr.gz)
        try {
            const detail::InputFile file(path, path.string());
            if (const auto data = detail::nifti_data_file_name(file)) files.push_back(detail::resolve_data_file(path, *data));
        } catch (const Error&) {
        }
        return files;
    }
    if (ext == ".hdr") {
        // not (yet) a NIfTI header: the data file it would name
        std::filesystem::path image = path;
        image.replace_extension(".img");
        files.push_back(image);
        return files;
    }
    const bool nrrd = ext == ".nrrd" || ext == ".nhdr";
    if (!nrrd && ext != ".mhd" && ext != ".mha") return files; // VTK and raw files hold their samples
    std::string head;
    try {
        const detail::InputFile file(path, path.string());
        head = file.read_string(0, detail::kMaxHeaderBytes);
    } catch (const Error&) {
        return files; // read_volume() fails on this file before it opens any other
    }
    const std::vector<std::string> names =
        nrrd ? detail::nrrd_data_file_names(head) : detail::metaimage_data_file_names(head);
    for (const std::string& name : names) files.push_back(detail::resolve_data_file(path, name));
    return files;
}

Volume read_volume(const std::filesystem::path& path, const std::optional<RawOptions>& raw, const ReadOptions& options)
{
    // DICOM and TIFF: folders, and files told by their marks (dicom.cpp)
    if (auto image = detail::read_image_input(path, options)) return std::move(*image);
    // a NIfTI pair named by its .img: read through its header
    if (const auto header = nifti_pair_header(path)) return read_volume(*header, raw, options);
    const std::string label = path.string();
    const std::string ext = detail::lower_extension(path);
    const detail::InputFile file(path, label);
    // Data files are named relative to the header's folder.
    const detail::OpenDataFile open_data = [&](std::string_view name) {
        const std::filesystem::path data = detail::resolve_data_file(path, name);
        return std::make_unique<detail::InputFile>(data, label + ": data file " + data.string());
    };
    // by content first (magic bytes), then by extension
    if (const auto format = detail::sniff_volume_format(file)) return read_sniffed(*format, file, open_data, options);
    if (ext == ".nii" || ext == ".hdr" || detail::lower_ascii(path.filename().string()).ends_with(".nii.gz")) return detail::read_nifti(file, open_data, options);
    if (ext == ".npy") return detail::read_npy(file, options);
    if (ext == ".vti") return detail::read_vti(file, options);
    if (ext == ".nrrd" || ext == ".nhdr") return detail::read_nrrd(file, open_data, ext == ".nhdr");
    if (ext == ".mhd" || ext == ".mha") return detail::read_metaimage(file, open_data);
    if (ext == ".vtk") return detail::read_vtk(file);
    return detail::read_raw(file, raw);
}

Volume read_volume_from_memory(std::string_view bytes, VolumeFormat format,
                               const std::string& label, const std::optional<RawOptions>& raw,
                               const MemoryFiles& data_files, const ReadOptions& options)
{
    const detail::MemoryInput input(bytes, label);
    const detail::OpenDataFile open_data =
        [&](std::string_view name) -> std::unique_ptr<detail::ByteInput> {
        const std::string data_label = label + ": data file " + std::string(name);
        const std::optional<std::string_view> data =
            data_files ? data_files(name) : std::optional<std::string_view>();
        if (!data) {
            throw Error(Status::io_error,
                        data_label + ": no such file among the data files given in memory");
        }
        return std::make_unique<detail::MemoryInput>(*data, data_label);
    };
    switch (format) {
    case VolumeFormat::nrrd: return detail::read_nrrd(input, open_data, false);
    case VolumeFormat::metaimage: return detail::read_metaimage(input, open_data);
    case VolumeFormat::vtk: return detail::read_vtk(input);
    case VolumeFormat::raw: break;
    case VolumeFormat::dicom: return detail::read_dicom_memory(bytes, label, options);
    case VolumeFormat::tiff: return detail::read_tiff_memory(bytes, label, options);
    case VolumeFormat::nifti:
    case VolumeFormat::npy:
    case VolumeFormat::vti: return read_sniffed(format, input, open_data, options);
    }
    return detail::read_raw(input, raw);
}

void write_volume(const Volume& volume, const std::filesystem::path& path)
{
    const std::string label = path.string();
    if (volume.bytes() == nullptr || volume.sample_count() <= 0) {
        throw Error(Status::invalid_argument,
                    label + ": cannot write an empty volume (it holds no samples)");
    }
    for (std::size_t axis = 0; axis < 3; ++axis) {
        if (!std::isfinite(volume.spacing()[axis]) || !std::isfinite(volume.origin()[axis])) {
            throw Error(Status::non_finite,
                        detail::str_cat(label,
                                        ": cannot write a volume whose spacing or origin "
                                        "is not finite (axis ",
                                        axis, ")"));
        }
        if (!(volume.spacing()[axis] > 0)) {
            throw Error(Status::invalid_argument,
                        detail::str_cat(label, ": cannot write spacing ", volume.spacing()[axis],
                                        " on axis ", axis, "; spacings must be > 0"));
        }
    }
    const std::string ext = detail::lower_extension(path);
    if (ext == ".nrrd" || ext == ".nhdr") {
        detail::write_nrrd(volume, path, ext == ".nhdr");
    } else if (ext == ".mhd" || ext == ".mha") {
        detail::write_metaimage(volume, path, ext == ".mha");
    } else if (ext == ".vtk") {
        detail::write_vtk(volume, path);
    } else if (ext == ".raw") {
        detail::write_raw(volume, path);
    } else {
        throw Error(Status::unsupported_format,
                    label + ": cannot write volume format " +
                        (ext.empty() ? "(no extension)" : "\"" + ext + "\"") +
                        "; accepted extensions: .nrrd .nhdr .mhd .mha .vtk .raw");
    }
}

} // namespace cmc33::io
