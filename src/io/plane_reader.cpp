// Reading a volume's samples a range of planes at a time (contract in plane_reader.hpp).

#include "plane_reader.hpp"

#include <cstring>
#include <utility>

#include "cmc33/error.hpp"
#include "atomic_file.hpp"
#include "dicom.hpp"

namespace cmc33::io::detail {

VolumeLayout describe_volume(const std::filesystem::path& given, const std::optional<RawOptions>& raw,
                             const ReadOptions& options)
{
    // DICOM and TIFF are read whole (slices from files in any order, decoders without plane
    // offsets); the planes are then copied out of the volume, as for ASCII samples
    if (image_input(given) == ImageInput::dicom || image_input(given) == ImageInput::tiff) {
        auto whole = std::make_shared<const Volume>(read_volume(given, raw, options));
        VolumeLayout layout;
        layout.grid = Grid{whole->type(), whole->dims(), whole->spacing(), whole->origin(), whole->direction(),
                           whole->space(), whole->frame_source()};
        layout.storage.encoding = Encoding::ascii;
        layout.data_path = given;
        layout.label = given.string();
        layout.whole = std::move(whole);
        return layout;
    }
    // a NIfTI pair named by its .img is read through its header, as read_volume() does
    const std::vector<std::filesystem::path> files = volume_files(given);
    const std::string given_name = lower_ascii(given.filename().string());
    const bool pair_by_image = (given_name.ends_with(".img") || given_name.ends_with(".img.gz")) && files.size() == 2;
    const std::filesystem::path path = pair_by_image ? files[1] : given;
    const std::string label = path.string();
    const std::string ext = lower_extension(path);
    const InputFile file(path, label);
    VolumeLayout layout;
    std::filesystem::path data_path = path;
    // as read_volume(): data files are named relative to the header's folder
    const OpenDataFile open_data = [&](std::string_view name) {
        data_path = resolve_data_file(path, name);
        return std::make_unique<InputFile>(data_path, label + ": data file " + data_path.string());
    };
    // in place of read_samples: the same checks, and where the samples are instead of them
    const ReadSamples record = [&](const ByteInput& input, const Grid& grid, const Storage& storage,
                                   const std::string& data_label, std::uint64_t* end) {
        layout.grid = grid;
        layout.storage = storage;
        layout.label = data_label;
        layout.data_path = &input == &file ? path : data_path;
        switch (storage.encoding) {
        case Encoding::raw: {
            const std::uint64_t offset = check_raw_samples(input, grid, storage, data_label);
            layout.storage.offset = offset;
            layout.storage.at_end = false;
            if (end) *end = offset + payload_bytes(grid.dims, grid.type, data_label);
            break;
        }
        case Encoding::compressed:
            layout.stream_size = check_compressed_samples(input, grid, storage, data_label);
            if (end) *end = storage.offset + layout.stream_size;
            break;
        case Encoding::ascii:
            layout.whole = std::make_shared<const Volume>(read_samples(input, grid, storage, data_label, end));
            break;
        }
        return Volume{};
    };
    const std::optional<VolumeFormat> sniffed = sniff_volume_format(file);
    if (sniffed == VolumeFormat::nifti) {
        read_nifti(file, open_data, options, record, true);
    } else if (sniffed == VolumeFormat::npy) {
        read_npy(file, options, record, true);
    } else if (sniffed == VolumeFormat::vti) {
        throw Error(Status::unsupported_format,
                    label + ": a .vti file is read whole (its samples are base64 text or compressed blocks, without plane "
                            "offsets); read it without --memory-limit");
    } else if (ext == ".nrrd" || ext == ".nhdr") {
        read_nrrd(file, open_data, ext == ".nhdr", record);
    } else if (ext == ".mhd" || ext == ".mha") {
        read_metaimage(file, open_data, record);
    } else if (ext == ".vtk") {
        read_vtk(file, record);
    } else {
        read_raw(file, raw, record);
    }
    return layout;
}

PlaneReader::PlaneReader(VolumeLayout layout) : layout_(std::move(layout))
{
    if (!layout_.whole) file_ = std::make_unique<InputFile>(layout_.data_path, layout_.label);
}

PlaneReader::~PlaneReader() = default;

void PlaneReader::read(std::int64_t k0, std::int64_t k1, std::byte* out)
{
    const Grid& g = layout_.grid;
    if (!(0 <= k0 && k0 < k1 && k1 <= g.dims[2])) {
        throw Error(Status::invalid_argument, layout_.label + ": planes [" + std::to_string(k0) + ", " +
                                                  std::to_string(k1) + ") are not within the volume's " +
                                                  std::to_string(g.dims[2]));
    }
    const std::uint64_t plane = layout_.plane_bytes();
    const std::uint64_t bytes = static_cast<std::uint64_t>(k1 - k0) * plane;
    const std::size_t width = type_size(g.type);
    const std::size_t samples = static_cast<std::size_t>(bytes / width);
    switch (layout_.storage.encoding) {
    case Encoding::ascii:
        std::memcpy(out, layout_.whole->bytes() + static_cast<std::uint64_t>(k0) * plane, static_cast<std::size_t>(bytes));
        return; // parsed into the machine's order already
    case Encoding::raw:
        file_->read(layout_.storage.offset + static_cast<std::uint64_t>(k0) * plane, out, static_cast<std::size_t>(bytes));
        break;
    case Encoding::compressed: {
        const std::uint64_t wanted = layout_.storage.skip_inflated + static_cast<std::uint64_t>(g.dims[2]) * plane;
        if (!stream_ || k0 < next_plane_) {
            stream_ = std::make_unique<InflateStream>(*file_, layout_.storage.offset, layout_.stream_size, layout_.label);
            stream_->skip(layout_.storage.skip_inflated, wanted);
            next_plane_ = 0;
        }
        stream_->skip(static_cast<std::uint64_t>(k0 - next_plane_) * plane, wanted);
        stream_->read_exactly(reinterpret_cast<unsigned char*>(out), static_cast<std::size_t>(bytes), wanted);
        next_plane_ = k1;
        if (k1 == g.dims[2]) {
            // read_volume()'s checks at the end of the stream, in its order
            stream_->finish(wanted);
            check_after_stream(*file_, layout_.storage, layout_.stream_size, layout_.label);
            stream_.reset();
        }
        break;
    }
    }
    to_native(out, samples, width, layout_.storage.endian);
}

} // namespace cmc33::io::detail
