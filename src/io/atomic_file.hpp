#pragma once
// Writing output files so that a failure never leaves a half-written file behind: the content
// goes to a temporary file in the target's folder, which is renamed over the target only after
// everything was written and flushed.

#include <filesystem>
#include <functional>
#include <ostream>

namespace cmc33::io::detail {

/// Calls write(stream) on a temporary file beside `path`, then renames it to `path`.
/// If write throws, or the stream fails, the temporary file is removed and Error{io_error}
/// (or write's own exception) propagates; `path` is left as it was.
void write_atomically(const std::filesystem::path& path, const std::function<void(std::ostream&)>& write);

/// Lower-case extension with the dot (".ply"); "" if none.
std::string lower_extension(const std::filesystem::path& path);

} // namespace cmc33::io::detail
