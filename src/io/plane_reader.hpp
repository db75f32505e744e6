#pragma once
// Internal: a volume's samples read a range of z planes at a time, never whole, for the callers
// that hold only a slab of a volume: the out-of-core extraction of `cmc33 extract --memory-limit`
// and the ranks of cmc33-mpi (src/slabs).
//
// describe_volume() runs the reader of the file's format (the same header parsing and checks as
// read_volume()) up to the point where it would read the samples, and records where they are
// instead. PlaneReader then reads planes by their offsets: raw samples (raw files, NRRD raw,
// MetaImage raw, VTK binary) with pread at any plane, in any order; compressed samples (NRRD gzip,
// MetaImage zlib) by inflating the stream forward a block at a time, so that a plane costs the
// inflation of every byte before it once per pass (reading backwards restarts the stream);
// ASCII samples (NRRD text, VTK ASCII) have no offsets: describe_volume() reads them whole with
// read_volume()'s own code, and PlaneReader copies planes out of that volume.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "cmc33/io.hpp"
#include "cmc33/volume.hpp"
#include "cmc33/io_export.hpp"
#include "byte_source.hpp"
#include "volume_formats.hpp"

namespace cmc33::io::detail {

/// Where a volume file keeps its samples.
struct VolumeLayout {
    Grid grid;                       ///< type, dims and frame, as read_volume() would set them
    Storage storage;                 ///< encoding and byte order; raw: offset of the first sample
    std::filesystem::path data_path; ///< the file that holds the samples (the header's own, or its data file)
    std::string label;               ///< how messages name that file ("head.nhdr: data file head.raw")
    std::uint64_t stream_size = 0;   ///< compressed: the stream's bytes from storage.offset
    std::shared_ptr<const Volume> whole; ///< ASCII samples: the volume, read whole

    std::uint64_t plane_bytes() const noexcept
    {
        return static_cast<std::uint64_t>(grid.dims[0]) * static_cast<std::uint64_t>(grid.dims[1]) *
               type_size(grid.type);
    }
};

/// The layout of the samples of `path`, with every check read_volume() makes before it reads
/// them (the same messages). `raw` as for read_volume().
/// @throws Error as read_volume()
CMC33_IO_EXPORT VolumeLayout describe_volume(const std::filesystem::path& path,
                                             const std::optional<RawOptions>& raw = std::nullopt,
                                             const ReadOptions& options = {});

/// Reads planes of the volume `layout` describes. Not thread-safe (one reader per thread).
class CMC33_IO_EXPORT PlaneReader {
public:
    explicit PlaneReader(VolumeLayout layout);
    ~PlaneReader();
    PlaneReader(const PlaneReader&) = delete;
    PlaneReader& operator=(const PlaneReader&) = delete;

    const VolumeLayout& layout() const noexcept { return layout_; }
    /// Reads planes [k0, k1) (0 <= k0 < k1 <= nz) into `out`, (k1 - k0) * plane_bytes() bytes, in
    /// the machine's byte order. Compressed samples: reading the last plane also checks the
    /// stream's end, as read_volume() does (nothing more declared, only zero padding after it).
    /// @throws Error{truncated_file, bad_format, io_error} as read_volume() for the same bytes
    void read(std::int64_t k0, std::int64_t k1, std::byte* out);
    /// Whether reading a plane before the last one read is cheap (false: a compressed stream
    /// starts over).
    bool random_access() const noexcept { return layout_.storage.encoding != Encoding::compressed; }

private:
    VolumeLayout layout_;
    std::unique_ptr<InputFile> file_;
    std::unique_ptr<InflateStream> stream_;
    std::int64_t next_plane_ = 0; ///< compressed: the plane the stream is at
};

} // namespace cmc33::io::detail
