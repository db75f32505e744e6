#pragma once
// Internal: the DICOM reader's first pass through GDCM (dicom_headers.cpp), shared with its second
// (dicom.cpp): what a file's header says, read up to its Pixel Data, and the input files.

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <gdcmDataSet.h>
#include <gdcmReader.h>
#include <gdcmTransferSyntax.h>

#include "cmc33/volume.hpp"
#include "dicom_scan.hpp"

namespace cmc33::io::detail {

/// A file named DICOMDIR (any case), the index of a DICOM medium (dicom.cpp).
bool is_dicomdir_name(const std::filesystem::path& path);
/// The files of a folder taken as DICOM: the "DICM" mark, or a DICOM extension (dicom.cpp).
std::vector<std::filesystem::path> folder_dicom_files(const std::filesystem::path& folder);

namespace dicom_gdcm {

namespace fs = std::filesystem;

inline const gdcm::Tag kDirectoryRecords(0x0004, 0x1220);
inline const gdcm::Tag kReferencedFileId(0x0004, 0x1500);

/// Where a frame lies and how its values map to the modality's units.
struct Geometry {
    std::optional<Vec3> position;                 // ImagePositionPatient
    std::optional<std::array<double, 6>> orientation; // ImageOrientationPatient: row then column cosine
    std::optional<std::array<double, 2>> pixel_spacing; // PixelSpacing: between rows, between columns
    double slope = 1, intercept = 0;
};

/// What a file's header says.
struct Header {
    std::size_t source = 0; // index in the input's file list
    std::string label;
    std::string transfer_uid;
    gdcm::TransferSyntax ts;
    std::string series, description, modality, photometric;
    std::string instance;
    unsigned rows = 0, columns = 0, bits_allocated = 0, bits_stored = 0, high_bit = 0, representation = 0,
             samples_per_pixel = 1;
    bool has_pixels = false, float_pixels = false;
    std::int64_t frames = 1;
    std::vector<Geometry> geometry; // one per frame
    std::optional<std::uint64_t> native_offset; // native transfer syntaxes: the first sample's byte
    DicomLayout layout; // from scan_dicom
};

/// One input file: a path, or bytes in memory.
struct Source {
    fs::path path;
    std::string_view bytes;
    bool in_memory = false;
    std::string label;
};

/// GDCM's own warnings and errors go to stderr unless turned off: ours say it in one line.
void quiet_gdcm();
/// A text value, trimmed.
std::string text_value(const gdcm::DataSet& ds, const gdcm::Tag& tag);
/// "(x, y, z)" for messages.
std::string vec_text(const Vec3& v);
/// Points `reader` at the source (a file, or a stream over its bytes kept in `stream`).
void open(gdcm::Reader& reader, const Source& source, std::unique_ptr<std::istringstream>& stream);
/// The VR the data dictionary gives a tag (for scan_dicom under implicit VR).
std::string dictionary_vr(std::uint16_t group, std::uint16_t element, std::string_view vr);
/// What file `index` of the input says, up to its Pixel Data.
/// @throws Error{bad_format, unsupported_format} naming the file and the tag
Header read_header(const Source& source, std::size_t index);

/// The headers of every source.
std::vector<Header> read_headers(const std::vector<Source>& sources);
/// The files of a DICOMDIR, as it lists them.
std::vector<fs::path> dicomdir_files(const fs::path& dicomdir);
/// The sources of an input: a folder's DICOM files, a DICOMDIR's files, or the file itself.
std::vector<Source> input_sources(const fs::path& path);
/// The headers of the input's sources (which it fills in).
std::vector<Header> headers_of(const fs::path& path, std::vector<Source>& sources);

} // namespace dicom_gdcm
} // namespace cmc33::io::detail
