#pragma once
// Internal: DICOM volumes through GDCM (src/io/dicom.cpp). A folder of slice files, a DICOMDIR or
// one multi-frame file; the files are grouped by SeriesInstanceUID, the slices sorted along their
// normal, and the frame taken from ImagePositionPatient / ImageOrientationPatient (LPS).
// Builds without GDCM (CMC33_WITH_GDCM=0: WebAssembly, or GDCM not found) refuse DICOM by name.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cmc33/io.hpp"
#include "cmc33/volume.hpp"

namespace cmc33::io::detail {

/// True when the build reads DICOM.
bool dicom_supported() noexcept;

/// True for a file with the "DICM" mark at byte 128 (bytes: the file's first 132 or more).
bool has_dicom_mark(std::string_view head) noexcept;

/// True when `path` is a DICOM input: a folder holding a DICOM file, or a file with the mark.
/// Never throws.
bool looks_like_dicom(const std::filesystem::path& path);

/// Reads the series `options.series` (or the only series) of a folder, a DICOMDIR or a file.
/// @throws Error with a one-line message naming the input (and the slice file) and the problem.
Volume read_dicom(const std::filesystem::path& path, const ReadOptions& options);

/// One DICOM file held in memory (a multi-frame image): the fuzz target's path.
Volume read_dicom_memory(std::string_view bytes, const std::string& label, const ReadOptions& options);

/// The series an input holds, from the headers only.
std::vector<DicomSeries> list_dicom_series(const std::filesystem::path& path);

/// The files reading `path` opens (the DICOM files of a folder, those a DICOMDIR names, the file
/// itself). Never throws.
std::vector<std::filesystem::path> dicom_input_files(const std::filesystem::path& path);

/// The inputs told by their content before any extension: a folder (a DICOM series or TIFF
/// slices), a file with the DICM mark or named DICOMDIR, a file with the TIFF mark. Reads them;
/// nullopt for any other file. @throws Error for a folder of neither, and the readers' errors.
std::optional<Volume> read_image_input(const std::filesystem::path& path, const ReadOptions& options);

/// What an input is, told by its content (a folder: by the files it holds).
enum class ImageInput { none, dicom, tiff, empty_folder };
ImageInput image_input(const std::filesystem::path& path);

/// What volume_files() lists for such an input (nullopt for any other). Never throws.
std::optional<std::vector<std::filesystem::path>> image_input_files(const std::filesystem::path& path);

} // namespace cmc33::io::detail
