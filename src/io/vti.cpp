// VTK XML ImageData (.vti): placeholder until the reader is written.

#include "volume_formats.hpp"

namespace cmc33::io::detail {

Volume read_vti(const ByteInput& file, const ReadOptions&)
{
    throw Error(Status::unsupported_format, file.label() + ": VTK XML ImageData is not read yet");
}

} // namespace cmc33::io::detail
