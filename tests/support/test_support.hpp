#pragma once
// Helpers shared by the test executables: temporary folders, the shared volumes, small fields.

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "cmc33/volume.hpp"

namespace cmc33::test {

/// A fresh, empty folder for the running test (removed at the start of the next run).
std::filesystem::path temp_dir();

/// A shared volume and an isovalue from its README (an integer; tests also run iso + 0.5).
struct VolumeCase {
    const char* file;
    double iso;
};
/// Every test volume (CONTRIBUTING.md, "Test volumes") with one README isovalue each.
const std::vector<VolumeCase>& shared_volume_cases();
void PrintTo(const VolumeCase& c, std::ostream* os);

/// Path of a test volume in $CMC33_SHARED/data/volumes (CMake's CMC33_SHARED_DIR, ../shared by
/// default; CONTRIBUTING.md, "Test volumes"), or nullopt when it is absent.
std::optional<std::filesystem::path> shared_volume(const std::string& file_name);

/// Folder of the repository's small test files (tests/data).
std::filesystem::path test_data_dir();

/// Runs `python script FOLDER` (an independent writer: pydicom, tifffile, ...) into a fresh folder
/// FOLDER = the temp directory / (`name` + this process's id); the folder, or empty if it failed.
std::filesystem::path run_writer(const std::string& python, const std::string& script, const std::string& name);

/// Writes bytes to a file (for building bad inputs).
void write_file(const std::filesystem::path& path, const std::string& bytes);
std::string read_file(const std::filesystem::path& path);

/// The little-endian uint32 at byte `at` of `bytes` (for checking written files).
std::uint32_t u32_le(const std::string& bytes, std::size_t at);

/// `data` compressed as one gzip stream, or as one zlib stream (for building compressed inputs).
std::string gzip_bytes(const std::string& data);
std::string zlib_bytes(const std::string& data);

/// A little-endian NIfTI-1 header (nifti1.h's nifti_1_header), for building inputs. Besides what
/// is given here: sizeof_hdr 348, pixdim[0..3] 1, qform unset, everything else 0.
struct Nifti1Header {
    std::vector<std::int16_t> dims; ///< the sizes (dim[1], dim[2], ...); dim[0] is their count, later dims 1
    std::int16_t datatype = 16;     ///< a NIFTI_TYPE_* code (16: float32); bitpix follows from it
    /// "n+1": a single file, 352 bytes (the header and 4 zero extension bytes), vox_offset 352;
    /// "ni1": the .hdr of a pair, 348 bytes, vox_offset 0
    std::string magic = "n+1";
    std::optional<std::array<std::array<float, 4>, 3>> srow{}; ///< sform_code 2 (aligned anatomy) with these rows
};
std::string nifti1_header(const Nifti1Header& header);

/// A double volume of the given dims filled by f(i, j, k).
Volume make_volume(Index3 dims, const std::function<double(std::int64_t, std::int64_t, std::int64_t)>& f,
                   Vec3 spacing = {1, 1, 1}, Vec3 origin = {0, 0, 0});

} // namespace cmc33::test
