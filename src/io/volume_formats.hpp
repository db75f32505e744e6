#pragma once
// Internal: the volume formats behind io::read_volume / io::write_volume (src/io/include/cmc33/io.hpp),
// and the helpers they share (defined in volume_io.cpp).
//
// A reader parses its header into a `Grid` (type, dims, spacing, origin) and a `Storage` (where
// the samples are and how they are coded), then read_samples() checks the declared size against
// the bytes the input holds *before* allocating the volume, reads or inflates the samples into it
// and converts them to the machine's byte order. Readers see a `ByteInput` (a file or a buffer)
// and open data files through an `OpenDataFile`, so files and memory share one code path.
//
// One policy for what the bytes say against the header (docs/formats.md): fewer or more samples,
// values or bytes than declared is an error; blanks after the last ASCII value, or none, are not.
//
// Messages start with `label`: the file as the user named it, then ": data file X" when the
// samples are in a second file, then ": " and what is wrong.

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <ostream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "cmc33/volume.hpp"
#include "byte_source.hpp"

namespace cmc33::io::detail {

/// Headers longer than this are refused (real ones are a few hundred bytes).
constexpr std::size_t kMaxHeaderBytes = std::size_t{1} << 20;

// ---- messages and text ----------------------------------------------------------------------

/// Concatenates anything `ostream <<` accepts.
template <class... Parts> std::string str_cat(const Parts&... parts)
{
    std::ostringstream s;
    (s << ... << parts);
    return s.str();
}

/// `text` in double quotes, non-printable bytes as \xNN, cut after `max_chars` characters.
std::string quote_bytes(std::string_view text, std::size_t max_chars = 40);
/// Without leading and trailing blanks (space, tab, CR, LF, VT, FF).
std::string_view trim(std::string_view text) noexcept;
/// Blank-separated words.
std::vector<std::string_view> split_words(std::string_view text);
/// Words joined by one space (collapses runs of blanks).
std::string normalize_blanks(std::string_view text);
CMC33_IO_EXPORT std::string lower_ascii(std::string_view text);
bool equals_ignore_case(std::string_view a, std::string_view b) noexcept;
/// Shortest decimal that reads back as exactly `value`.
std::string format_real(double value);
/// "64x64x93".
std::string dims_text(const Index3& dims);

/// The whole token is a decimal number (a leading '+' is accepted; "nan", "inf" too).
bool parse_real(std::string_view token, double& value);
/// Why parse_real refused `token`: "is out of the double range ..." or "is not a number".
std::string real_problem(std::string_view token);
/// The whole token is a decimal integer (a leading '+' is accepted).
bool parse_integer(std::string_view token, std::int64_t& value);

// ---- header values --------------------------------------------------------------------------

/// Three sample counts (`what` names the field in messages). Each must be an integer >= 2.
/// @throws Error{bad_format} (not 3 words, not integers, < 2) or Error{too_large}.
Index3 parse_dims(const std::vector<std::string_view>& words, const std::string& label,
                  std::string_view what);
/// Three finite numbers; with `positive`, each must be > 0 (spacings).
Vec3 parse_vec3(const std::vector<std::string_view>& words, const std::string& label,
                std::string_view what, bool positive);

/// Bytes of dims[0]*dims[1]*dims[2] samples of `type`. Each axis must hold >= 2 samples.
/// @throws Error{bad_format} for an axis < 2, Error{too_large} if the size overflows.
std::uint64_t payload_bytes(const Index3& dims, ScalarType type, const std::string& label);

/// The start of `file` (at most kMaxHeaderBytes), for parsing a header.
/// @throws Error{truncated_file} for an empty file (`format` names what was expected).
std::string read_header_bytes(const ByteInput& file, std::string_view format);

/// `name` from a header, relative to the header's folder unless absolute.
std::filesystem::path resolve_data_file(const std::filesystem::path& header, std::string_view name);
/// True for the multi-file form "<printf pattern> <min> <max> <step> [<axis>]" (NRRD, MetaImage).
bool is_file_pattern(std::string_view value);
/// The names a multi-file form stands for (at most `max_names`, the first ones), formatted as
/// printf would with an int. Empty unless the pattern has exactly one integer conversion (%d, %i,
/// %u with flags, width, precision; "%%" is a '%') and min, max fit an int.
std::vector<std::string> expand_file_pattern(std::string_view value, std::size_t max_names);
/// The most names volume_files() lists for one multi-file pattern.
constexpr std::size_t kMaxPatternFiles = std::size_t{1} << 16;

/// The data files a NRRD (or MetaImage) header names, as written: a single name, the lines after
/// "data file: LIST" (ElementDataFile = LIST), or a pattern's names. Read leniently from the start
/// of the header file, without the reader's checks, so that even a header the reader refuses
/// shows what it points to. Empty for an attached header (ElementDataFile = LOCAL).
std::vector<std::string> nrrd_data_file_names(std::string_view head);
std::vector<std::string> metaimage_data_file_names(std::string_view head);

// ---- samples --------------------------------------------------------------------------------

/// What a header says about the samples' type and place in space (the frame of volume.hpp).
struct Grid {
    ScalarType type = ScalarType::u8;
    Index3 dims{0, 0, 0};
    Vec3 spacing{1, 1, 1};
    Vec3 origin{0, 0, 0};
    Mat3 direction = kIdentity3;
    std::string space; ///< the named space, recorded for `info`
    std::string frame_source; ///< where the frame came from (Volume::frame_source), for `info`
};

/// Sets grid.direction and grid.spacing from three axis vectors: axes[a] is the world step of
/// axis a times 1 / scale[a] (scale = the spacings when the vectors are unit directions, 1 when
/// they are the steps). Column a of the direction is axes[a] / |axes[a]|, spacing[a] is
/// scale[a] * |axes[a]|. `what` names the field in messages.
/// @throws Error{bad_format} for a zero vector or a degenerate frame (axes in one plane).
void set_frame(Grid& grid, const std::array<Vec3, 3>& axes, const Vec3& scale, const std::string& label,
               std::string_view what);

enum class Encoding {
    raw,        ///< the bytes as they are
    compressed, ///< one zlib or gzip stream (detected from its first bytes)
    ascii,      ///< decimal numbers separated by blanks
};

/// Where the samples are in their file and how they are coded.
struct Storage {
    Encoding encoding = Encoding::raw;
    Endian endian = Endian::little;
    std::uint64_t offset = 0;                 ///< first byte of the stored samples
    bool at_end = false;                      ///< raw: the samples are the file's last bytes
    std::optional<std::uint64_t> stored_size; ///< compressed: the stream's bytes, if declared
    std::uint64_t skip_inflated = 0;          ///< compressed: output bytes to discard first
    /// What may follow the samples: nothing (blanks after ASCII values), or anything, for a
    /// reader that checks the rest itself (VTK: further attributes).
    bool check_trailing = true;
};

/// Reads the samples `grid` declares from `file` as `storage` says. Checks the sizes against the
/// file before allocating. `label` starts the messages. `end`, if given, receives the offset just
/// past the samples (raw: the last sample byte; ASCII: the last value; compressed: the stream).
/// @throws Error{truncated_file} for fewer bytes or values than declared, Error{bad_format} for
/// more (unless `storage.check_trailing` is false).
Volume read_samples(const ByteInput& file, const Grid& grid, const Storage& storage,
                    const std::string& label, std::uint64_t* end = nullptr);

/// The last step of every reader: read_samples, or what a caller that reads the samples itself
/// puts in its place (describe_volume() of plane_reader.hpp records the layout instead).
using ReadSamples = std::function<Volume(const ByteInput& file, const Grid& grid, const Storage& storage,
                                         const std::string& label, std::uint64_t* end)>;

/// The checks read_samples makes on raw samples before reading them: where they start (past a
/// `storage.at_end` file's other bytes), with Error{truncated_file} or Error{bad_format} when
/// the file holds fewer or more bytes than `grid` declares.
std::uint64_t check_raw_samples(const ByteInput& file, const Grid& grid, const Storage& storage,
                                const std::string& label);
/// The checks read_samples makes on compressed samples before inflating them; returns the
/// stream's size. Error{truncated_file} if the stream cannot hold the declared samples.
std::uint64_t check_compressed_samples(const ByteInput& file, const Grid& grid, const Storage& storage,
                                       const std::string& label);
/// The check read_samples makes after inflating: Error{bad_format} for bytes after a stream
/// whose size the header declared (unless `storage.check_trailing` is false).
void check_after_stream(const ByteInput& file, const Storage& storage, std::uint64_t stream, const std::string& label);

/// Fills `volume` from decimal text: blank-separated values, the last one followed by blanks or
/// by the end of the text. Returns the offset just past the last value.
/// @throws Error{truncated_file} (too few values), Error{bad_format} (not a number, out of range).
std::size_t parse_ascii_samples(std::string_view text, Volume& volume, const std::string& label);

/// Writes the samples in `endian` order (in blocks, swapping a copy when needed).
void write_samples(std::ostream& out, const Volume& volume, Endian endian);

// ---- formats --------------------------------------------------------------------------------

/// Opens the data file a detached header names (`name` as the header writes it). The input's
/// label says "<header>: data file <name>". @throws Error{io_error} if there is no such file.
using OpenDataFile = std::function<std::unique_ptr<ByteInput>(std::string_view name)>;

/// NRRD, attached or detached; `detached_header` (a .nhdr file) requires a "data file" field.
/// Each reader parses and checks its header, then hands the samples' layout to `read` (which
/// reads them, unless a caller put another step there).
Volume read_nrrd(const ByteInput& file, const OpenDataFile& open_data, bool detached_header,
                 const ReadSamples& read = read_samples);
/// MetaImage, .mha (ElementDataFile = LOCAL) or .mhd (a data file).
Volume read_metaimage(const ByteInput& file, const OpenDataFile& open_data, const ReadSamples& read = read_samples);
Volume read_vtk(const ByteInput& file, const ReadSamples& read = read_samples);
Volume read_raw(const ByteInput& file, const std::optional<RawOptions>& raw, const ReadSamples& read = read_samples);

/// NIfTI-1 or NIfTI-2 (nifti.cpp): `file` is a .nii (gzip-compressed or not) or a .hdr whose
/// samples are in the data file "<stem>.img" (opened through `open_data`). With `planes` the
/// caller reads the samples plane by plane through `read` (describe_volume()): what must be
/// converted after reading (scl_slope, 64-bit integers) is refused instead.
Volume read_nifti(const ByteInput& file, const OpenDataFile& open_data, const ReadOptions& options,
                  const ReadSamples& read = read_samples, bool planes = false);
/// The data file a NIfTI pair's header `file` names, "<stem>.img" or, for a compressed header
/// "<stem>.hdr.gz", "<stem>.img.gz" (relative to the header's folder); nullopt for a single-file
/// NIfTI or anything else. Never throws.
std::optional<std::string> nifti_data_file_name(const ByteInput& file);
/// NumPy .npy (npy.cpp); `planes` as for read_nifti.
Volume read_npy(const ByteInput& file, const ReadOptions& options, const ReadSamples& read = read_samples,
                bool planes = false);
/// VTK XML ImageData (vti.cpp); read whole (base64 and compressed blocks have no plane offsets).
Volume read_vti(const ByteInput& file, const ReadOptions& options);
/// The format of nifti.cpp, npy.cpp or vti.cpp that the first bytes of `file` show (a gzip stream
/// is inflated far enough to see a NIfTI header), or nullopt.
CMC33_IO_EXPORT std::optional<VolumeFormat> sniff_volume_format(const ByteInput& file);

/// Moves a frame into the anatomical space `target` ("ras", "lps" or a NRRD name): negates the
/// world axes whose direction differs (world_space.cpp). @throws Error{invalid_argument} naming
/// `label` for an unknown target, a frame without a space, or a space that is not anatomical.
CMC33_IO_EXPORT void convert_space(Vec3& origin, Mat3& direction, std::string& space, std::string_view target,
                                   const std::string& label);

/// The data file a detached header names: "<stem>.raw" in the header's folder.
std::filesystem::path data_file_beside(const std::filesystem::path& header);

void write_nrrd(const Volume& volume, const std::filesystem::path& path, bool detached);
void write_metaimage(const Volume& volume, const std::filesystem::path& path, bool local);
void write_vtk(const Volume& volume, const std::filesystem::path& path);
void write_raw(const Volume& volume, const std::filesystem::path& path);

} // namespace cmc33::io::detail
