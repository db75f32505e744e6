#pragma once
// Internal: bounded access to untrusted bytes for the volume readers.
//
// - `ByteInput`: bytes read by (offset, count), every range checked against the size the input
//   had when it was opened, so no read can run past its end. Two kinds: `InputFile` (a regular
//   file) and `MemoryInput` (a buffer the caller holds); the readers see only `ByteInput`, so the
//   file API and the in-memory API run the same parsing code.
// - `ByteSource`: a cursor over bytes held in memory (a header); every read checks what remains.
// - Byte order: samples are converted in place to the machine's order.
// - Inflate: a zlib or gzip stream is inflated into a buffer that grows with the bytes actually
//   decoded, up to the declared size, after a check that the stream can hold that many at all.
//
// Every error message starts with the `label` given by the caller (the file as the user named it).

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <utility>

#include "cmc33/io.hpp"
#include "cmc33/io_export.hpp" // the CLI opens its inputs with InputFile across the library boundary

struct z_stream_s; // zlib's z_stream

namespace cmc33::io::detail {

class PortableInflater; // inflate_portable.hpp: InflateStream's engine in builds without zlib

/// Bytes that can be read by (offset, count). The size is fixed when the input is opened.
class CMC33_IO_EXPORT ByteInput {
public:
    virtual ~ByteInput() = default;
    ByteInput(const ByteInput&) = delete;
    ByteInput& operator=(const ByteInput&) = delete;

    const std::string& label() const noexcept { return label_; }
    std::uint64_t size() const noexcept { return size_; }

    /// Reads exactly `count` bytes at `offset` into `out`.
    /// @throws Error{truncated_file} if the range passes the end, Error{io_error} on a read error.
    void read(std::uint64_t offset, void* out, std::size_t count) const;
    /// Reads min(max_count, size - offset) bytes at `offset` (nothing if offset >= size).
    std::string read_string(std::uint64_t offset, std::uint64_t max_count) const;

protected:
    explicit ByteInput(std::string label) : label_(std::move(label)) {}
    /// Reads a range already checked to lie within [0, size).
    virtual void read_checked(std::uint64_t offset, void* out, std::size_t count) const = 0;

    std::string label_;
    std::uint64_t size_ = 0;
};

/// A regular file opened for reading.
class CMC33_IO_EXPORT InputFile final : public ByteInput {
public:
    /// Opens `path`; `label` starts every message. @throws Error{io_error} if the file is missing,
    /// unreadable, a directory or not a regular file (a FIFO would block).
    InputFile(const std::filesystem::path& path, std::string label);
    ~InputFile() override;

private:
    void read_checked(std::uint64_t offset, void* out, std::size_t count) const override;
    int fd_ = -1;
};

/// Bytes held by the caller, who keeps them alive while the input is used.
class MemoryInput final : public ByteInput {
public:
    MemoryInput(std::string_view bytes, std::string label);

private:
    void read_checked(std::uint64_t offset, void* out, std::size_t count) const override;
    std::string_view bytes_;
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
/// allocating anything of the declared size. `what` says what the header declares, with its size
/// in bytes, and starts the message after the label.
void check_inflate_bound(std::uint64_t compressed, std::uint64_t declared, const std::string& label,
                         const std::string& what);

/// A zlib or gzip stream (gzip members may follow one another) in bytes [offset, offset + size)
/// of `input`, read a block at a time and inflated on demand: its memory is one block and zlib's
/// window, whatever the stream's size. inflate_exact() is built on it; so is the reading of
/// compressed volumes plane by plane (plane_reader.hpp). Messages start with `label`.
class InflateStream {
public:
    InflateStream(const ByteInput& input, std::uint64_t offset, std::uint64_t size, std::string label);
    ~InflateStream();
    InflateStream(const InflateStream&) = delete;
    InflateStream& operator=(const InflateStream&) = delete;

    /// Writes up to `count` bytes to `out`; fewer only when the input ended (then `ended()` says
    /// whether the stream was complete). Returns how many were written.
    /// @throws Error{bad_format} for corrupt data
    std::size_t produce(unsigned char* out, std::size_t count);
    /// Exactly `count` bytes, or Error{truncated_file} saying the stream holds fewer than the
    /// `wanted` bytes the header declares.
    void read_exactly(unsigned char* out, std::size_t count, std::uint64_t wanted);
    /// Inflates and drops `count` bytes (as read_exactly).
    void skip(std::uint64_t count, std::uint64_t wanted);
    /// After all `wanted` declared bytes came out: the stream must end there, and only zero bytes
    /// may follow it. @throws Error{bad_format} for more data or junk, Error{truncated_file} for a
    /// stream without its end.
    void finish(std::uint64_t wanted);
    bool ended() const noexcept { return ended_; }
    std::uint64_t produced() const noexcept { return produced_; }

private:
    [[noreturn]] void fail_short(std::uint64_t wanted) const;
    std::uint64_t consumed() const noexcept;
    static std::size_t block_for(std::uint64_t size) noexcept;
    static constexpr std::size_t kBlock = std::size_t{1} << 20;
    static constexpr std::size_t kMaxOut = std::size_t{1} << 30; // zlib counts in 32-bit uInt
    const ByteInput& in_;
    std::uint64_t offset_, size_;
    std::string label_;
    std::size_t block_size_; ///< kBlock, or the whole stream when shorter
    std::unique_ptr<unsigned char[]> block_;
#if !defined(CMC33_WITH_ZLIB) || CMC33_WITH_ZLIB
    std::unique_ptr<z_stream_s> z_;
#else
    std::string whole_; ///< the compressed stream (the portable inflater reads memory)
    std::unique_ptr<PortableInflater> portable_;
#endif
    std::uint64_t fed_ = 0, produced_ = 0;
    bool ended_ = false;
};

/// Inflates the zlib or gzip stream in `in` (the kind is detected from its first bytes; gzip
/// members may follow one another), discards its first `skip` bytes, and returns the next
/// `out_size` bytes, which must be all the stream holds. After the stream's end, only zero bytes
/// may follow. The buffer grows with the bytes decoded (it starts near what the compressed size
/// suggests and doubles, up to `out_size`), so a header that lies about the size costs no more
/// memory than the stream really holds.
/// @throws Error{bad_format} for corrupt data, a stream that holds more bytes, or non-zero
/// trailing bytes; Error{truncated_file} for a stream that ends early or holds fewer bytes;
/// Error{too_large} if the memory for the bytes decoded so far cannot be had.
std::unique_ptr<std::byte[]> inflate_exact(std::string_view in, std::uint64_t skip,
                                           std::size_t out_size, const std::string& label);

#if defined(CMC33_WITH_LIBDEFLATE) && CMC33_WITH_LIBDEFLATE
/// inflate_exact()'s fast path (inflate_libdeflate.cpp): the stream in `in` inflated by libdeflate
/// in one call per member into one block of the declared size. Null for anything inflate_exact()
/// would refuse, and also for a gzip header with a header CRC, a `skip` larger than `out_size` or
/// memory that cannot be had: then inflate_exact() inflates through InflateStream, whose errors
/// say what is wrong.
std::unique_ptr<std::byte[]> inflate_whole(std::string_view in, std::uint64_t skip, std::size_t out_size);
#endif

} // namespace cmc33::io::detail
