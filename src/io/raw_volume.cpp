// Headerless raw volumes: the samples and nothing else (after `header_bytes` skipped bytes). The
// file cannot describe itself, so RawOptions must, and the file's size is the only check on them:
// it must match exactly, or the options are almost certainly wrong.

#include <cmath>
#include <limits>
#include <string>

#include "cmc33/io.hpp"
#include "atomic_file.hpp"
#include "byte_source.hpp"
#include "volume_formats.hpp"

namespace cmc33::io::detail {

Volume read_raw(const ByteInput& file, const std::optional<RawOptions>& raw, const ReadSamples& read)
{
    const std::string& label = file.label();
    if (!raw) {
        throw Error(Status::invalid_argument,
                    label + ": headerless raw volume needs --dims X Y Z and --type T");
    }
    const RawOptions& options = *raw;
    for (std::int64_t d : options.dims) {
        if (d < 1) {
            throw Error(Status::invalid_argument,
                        str_cat(label, ": --dims ", dims_text(options.dims),
                                ": each size must be a positive integer"));
        }
        if (d < 2) {
            throw Error(Status::invalid_argument,
                        str_cat(label, ": --dims ", dims_text(options.dims),
                                ": an isosurface needs at least 2 samples on each axis"));
        }
    }
    for (double s : options.spacing) {
        if (!std::isfinite(s) || !(s > 0)) {
            throw Error(Status::invalid_argument,
                        str_cat(label, ": spacing ", s, " is not a positive finite number"));
        }
    }
    Grid grid;
    grid.type = options.type;
    grid.dims = options.dims;
    grid.spacing = options.spacing;
    const std::uint64_t bytes = payload_bytes(grid.dims, grid.type, label);
    const std::string described = str_cat("--dims ", options.dims[0], ' ', options.dims[1], ' ',
                                          options.dims[2], " --type ", type_name(grid.type));
    if (options.header_bytes > std::numeric_limits<std::uint64_t>::max() - bytes) {
        throw Error(Status::too_large,
                    str_cat(label, ": ", options.header_bytes, " header bytes plus ", bytes,
                            " bytes of samples overflow 64 bits"));
    }
    const std::uint64_t total = options.header_bytes + bytes;
    const std::string parts =
        options.header_bytes == 0
            ? str_cat(total, " bytes")
            : str_cat(total, " bytes (", options.header_bytes, " header + ", bytes, " samples)");
    if (file.size() < total) {
        throw Error(Status::truncated_file,
                    str_cat(label, ": the file holds ", file.size(), " bytes but ", described,
                            " need ", parts, "; file cut short, or wrong --dims/--type?"));
    }
    if (file.size() > total) {
        throw Error(Status::invalid_argument,
                    str_cat(label, ": the file holds ", file.size(), " bytes but ", described,
                            " describe ", parts, "; --dims/--type probably do not match the file"));
    }
    Storage storage;
    storage.encoding = Encoding::raw;
    storage.endian = options.endian;
    storage.offset = options.header_bytes;
    return read(file, grid, storage, label, nullptr);
}

std::filesystem::path data_file_beside(const std::filesystem::path& header)
{
    std::filesystem::path data = header;
    data.replace_extension(".raw");
    return data;
}

void write_raw(const Volume& volume, const std::filesystem::path& path)
{
    write_atomically(path, [&](std::ostream& out) { write_samples(out, volume, native_endian()); });
}

} // namespace cmc33::io::detail
