#pragma once
// Internal: TIFF volumes through libtiff (src/io/tiff.cpp): a multi-page file (each page a z
// slice; ImageJ hyperstacks and OME-TIFF say how pages map to slices, channels and frames) or a
// folder of single-page files numbered in their names. Builds without libtiff (CMC33_WITH_TIFF=0:
// WebAssembly, or libtiff not found) refuse TIFF by name.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "cmc33/io.hpp"
#include "cmc33/volume.hpp"

namespace cmc33::io::detail {

/// True when the build reads TIFF.
bool tiff_supported() noexcept;

/// True for bytes that start as TIFF or BigTIFF does ("II*\0", "MM\0*", "II+\0", "MM\0+").
bool has_tiff_mark(std::string_view head) noexcept;

/// True when `path` is a TIFF input: a file with the mark, or a folder holding .tif/.tiff files
/// (and no DICOM file). Never throws.
bool looks_like_tiff(const std::filesystem::path& path);

/// Reads a TIFF file or a folder of numbered single-page TIFF files.
/// @throws Error with a one-line message naming the file (or the folder and the slice file).
Volume read_tiff(const std::filesystem::path& path, const ReadOptions& options);

/// One TIFF file held in memory (the fuzz target's path).
Volume read_tiff_memory(std::string_view bytes, const std::string& label, const ReadOptions& options);

/// The files reading `path` opens: the file, or the folder's slice files. Never throws.
std::vector<std::filesystem::path> tiff_input_files(const std::filesystem::path& path);

} // namespace cmc33::io::detail
