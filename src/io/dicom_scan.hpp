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
#include <string>

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
};

/// Walks every data element of a DICOM Part 10 file (contract above).
/// @throws Error (bad_format, truncated_file or unsupported_format) with a one-line message
/// starting with the input's label.
DicomLayout scan_dicom(const ByteInput& input);

} // namespace cmc33::io::detail
