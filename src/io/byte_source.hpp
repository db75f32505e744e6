#pragma once
// Internal: bounded access to untrusted bytes for the volume readers.
//
// - `InputFile`: a regular file read by (offset, count); every range is checked against the size
// the
//   file had when it was opened, so no read can run past its end.
// - `ByteSource`: a cursor over bytes held in memory (a header); every read checks what remains.
// - Byte order: samples are converted in place to the machine's order.
// - Inflate: a zlib or gzip stream is inflated straight into the caller's buffer of exactly the
//   declared size, after a check that the stream can hold that many bytes at all.
//
// Every error message starts with the `label` given by the caller (the file as the user named it).

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "cmc33/io.hpp"

namespace cmc33::io::detail {

/// A regular file opened for reading. Its size is taken once, when it is opened.
class InputFile {
public:
    /// Opens `path`; `label` starts every message. @throws Error{io_error} if the file is missing,
    /// unreadable, a directory or not a regular file (a FIFO would block).
    InputFile(const std::filesystem::path& path, std::string label);
    ~InputFile();
    InputFile(const InputFile&) = delete;
    InputFile& operator=(const InputFile&) = delete;

    const std::string& label() const noexcept { return label_; }
    std::uint64_t size() const noexcept { return size_; }

    /// Reads exactly `count` bytes at `offset` into `out`.
    /// @throws Error{truncated_file} if the range passes the end, Error{io_error} on a read error.
    void read(std::uint64_t offset, void* out, std::size_t count) const;
    /// Reads min(max_count, size - offset) bytes at `offset` (nothing if offset >= size).
    std::string read_string(std::uint64_t offset, std::uint64_t max_count) const;

private:
    int fd_ = -1;
    std::string label_;
    std::uint64_t size_ = 0;
};

/// A cursor over bytes in memory. Reads never pass the end: they report what is missing instead.
class ByteSource {
public:
    explicit ByteSource(std::string_view bytes) noexcept : bytes_(bytes) {}

    std::size_t position() const noexcept { return pos_; }
    std::size_t remaining() const noexcept { return bytes_.size() - pos_; }
    bool at_end() const noexcept { return pos_ == bytes_.size(); }
    /// The bytes not yet consumed (not consumed by this call).
    std::string_view rest() const noexcept { return bytes_.substr(pos_); }

    /// The next `count` bytes, consumed. False (nothing consumed) if fewer remain.
    bool take(std::size_t count, std::string_view& out) noexcept;
    /// The next line, consumed, without its "\n" and without a "\r" before it. `terminated` says
    /// whether a "\n" ended it (false: the bytes ended first). False when nothing remains.
    bool next_line(std::string_view& line, bool& terminated) noexcept;
    /// True if the rest starts with `prefix` (nothing consumed).
    bool starts_with(std::string_view prefix) const noexcept
    {
        return rest().substr(0, prefix.size()) == prefix;
    }

private:
    std::string_view bytes_;
    std::size_t pos_ = 0;
};

// ---- byte order -----------------------------------------------------------------------------

Endian native_endian() noexcept;

/// Reverses the bytes of each of `count` samples of `width` bytes (1, 2, 4 or 8) in place.
void swap_bytes(std::byte* data, std::size_t count, std::size_t width) noexcept;

/// Converts `count` samples of `width` bytes stored in `stored` order to the machine's order.
inline void to_native(std::byte* data, std::size_t count, std::size_t width, Endian stored) noexcept
{
    if (width > 1 && stored != native_endian()) swap_bytes(data, count, width);
}

// ---- zlib / gzip ----------------------------------------------------------------------------

/// Deflate expands at most about 1032:1. Throws Error{truncated_file} if `declared` bytes cannot
/// come out of `compressed` bytes (declared > 1032 * compressed + 1024): call it before
/// allocating anything of the declared size. `what` describes the declared size in the message.
void check_inflate_bound(std::uint64_t compressed, std::uint64_t declared, const std::string& label,
                         const std::string& what);

/// Inflates the zlib or gzip stream in `in` (the kind is detected from its first bytes; gzip
/// members may follow one another), discards its first `skip` bytes, and fills exactly
/// `out_size` bytes at `out`. After the stream's end, only zero bytes may follow.
/// @throws Error{bad_format} for corrupt data, a stream that holds more bytes, or non-zero
/// trailing bytes; Error{truncated_file} for a stream that ends early or holds fewer bytes.
void inflate_exact(std::string_view in, std::uint64_t skip, std::byte* out, std::size_t out_size,
                   const std::string& label);

} // namespace cmc33::io::detail
