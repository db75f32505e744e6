#pragma once
/// @file error.hpp
/// The one exception type of the library. Every failure the caller can cause (bad files, bad
/// arguments, sizes that overflow, non-finite samples) is reported as an `Error` whose message is
/// one line: what failed, the value found, what was expected. The library never prints or exits.

#include <stdexcept>
#include <string>
#include "cmc33/base_export.hpp"

namespace cmc33 {

enum class Status {
    invalid_argument,   ///< an option or argument out of its range (caller's fault)
    io_error,           ///< the operating system refused: missing file, directory, permission
    truncated_file,     ///< fewer bytes than the header declares
    bad_format,         ///< a header or payload that does not follow its format
    unsupported_format, ///< a valid but unsupported variant (encoding, type, extension)
    non_finite,         ///< NaN or infinity in samples or parameters
    too_large,          ///< sizes that overflow or exceed what can be allocated
    cancelled,          ///< the caller's progress callback asked to stop
    internal,           ///< a broken invariant: a bug in cmc33
};

class CMC33_BASE_EXPORT Error : public std::runtime_error {
public:
    Error(Status status, const std::string& message) : std::runtime_error(message), status_(status) {}
    Status status() const noexcept { return status_; }

private:
    Status status_;
};

} // namespace cmc33
