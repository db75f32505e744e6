#pragma once
// Internal: the structure of a DICOM file checked before GDCM parses it (src/io/dicom_scan.cpp).
//
// GDCM allocates a value's declared length before it reads it (a crafted 4 GiB length allocates
// and zeroes 4 GiB), re-parses a file it cannot read under other, guessed encodings, and stops
// on assert() for several malformed structures. So every element of a file is walked here first,
// in the transfer syntax the file meta group names, and anything GDCM might mishandle is refused
// in one line naming the file, the tag, the byte offset and what was expected:
// - PS3.10 7.1: the 128-byte preamble, "DICM", the file meta group (explicit VR little endian);
// - PS3.5 7.1: each element's tag, VR (explicit syntaxes) and value length; a defined length is
//   even and within its enclosing item or the file;
// - PS3.5 7.5: sequences and items, of defined or undefined length, with their delimiters; a
//   nesting depth limit;
// - PS3.5 A.4: encapsulated Pixel Data: the Basic Offset Table item, the fragments and the
//   sequence delimiter.

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "byte_source.hpp"

namespace cmc33::io::detail {

/// Sequences nested deeper than this are refused (real files nest a handful deep).
inline constexpr int kMaxDicomNesting = 32;

/// What the walk found.
struct DicomLayout {
    std::string transfer_syntax; // the UID of (0002,0010), without its padding
    bool encapsulated = false;   // a compressed (encapsulated) transfer syntax
    /// The bytes of the top-level Pixel Data: its value length (native), or the sum of its
    /// fragments' lengths (encapsulated). 0 when there is none.
    std::uint64_t pixel_bytes = 0;
    /// Encapsulated top-level Pixel Data: each fragment's value (offset, length), in order.
    std::vector<std::pair<std::uint64_t, std::uint32_t>> fragments;
};

/// Checks RLE Lossless Pixel Data (PS3.5 Annex G) before GDCM's decoder, which reads past its
/// input on a malformed header or segment: one fragment per frame, a 64-byte header with 1 to 15
/// segments (one per byte of a sample) at increasing offsets within the fragment, each segment
/// decoding (PackBits, G.3.1) to exactly `rows * columns` bytes without reading past its end.
/// @throws Error{bad_format} naming the input, the frame and the problem.
void check_rle(const ByteInput& input, const DicomLayout& layout, std::uint64_t frames, std::uint64_t rows,
               std::uint64_t columns, unsigned segments);

/// Judges an explicit VR for a tag: "" when acceptable, else the VR expected. dicom.cpp passes
/// one built on GDCM's data dictionary, whose attribute readers assert on an incompatible VR.
using DicomVrCheck = std::function<std::string(std::uint16_t group, std::uint16_t element, std::string_view vr)>;

/// Walks every data element of a DICOM Part 10 file (contract above); `vr_check`, if given, is
/// asked about every element of an explicit VR data set.
/// @throws Error (bad_format, truncated_file or unsupported_format) with a one-line message
/// starting with the input's label.
DicomLayout scan_dicom(const ByteInput& input, const DicomVrCheck& vr_check = {});

} // namespace cmc33::io::detail
