#include "byte_source.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <cstring>
#include <limits>
#include <new>
#include <system_error>
#include <utility>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#if !defined(CMC33_WITH_ZLIB) || CMC33_WITH_ZLIB
#include <zlib.h>
#else
#include "inflate_portable.hpp"
#endif

#include "portability.hpp"

#include "cmc33/error.hpp"

namespace cmc33::io::detail {

namespace {

std::string errno_text(int error)
{
    return std::error_code(error, std::generic_category()).message();
}

} // namespace

// ---- ByteInput ------------------------------------------------------------------------------

void ByteInput::read(std::uint64_t offset, void* out, std::size_t count) const
{
    if (offset > size_ || count > size_ - offset) {
        throw Error(Status::truncated_file, label_ + ": " + std::to_string(count) +
                                                " bytes at byte " + std::to_string(offset) +
                                                " pass the end of the file (" +
                                                std::to_string(size_) + " bytes)");
    }
    if (count > 0) read_checked(offset, out, count);
}

std::string ByteInput::read_string(std::uint64_t offset, std::uint64_t max_count) const
{
    if (offset >= size_) return {};
    const std::uint64_t count = std::min(max_count, size_ - offset);
    if (count > std::numeric_limits<std::size_t>::max() / 2) {
        throw Error(Status::too_large,
                    label_ + ": " + std::to_string(count) + " bytes cannot be held in memory");
    }
    std::string bytes(static_cast<std::size_t>(count), '\0');
    read(offset, bytes.data(), bytes.size());
    return bytes;
}

// ---- InputFile ------------------------------------------------------------------------------

InputFile::InputFile(const std::filesystem::path& path, std::string label)
    : ByteInput(std::move(label))
{
    // O_NONBLOCK: opening a FIFO must not wait for a writer; it is rejected below as not regular.
    do {
        fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    } while (fd_ < 0 && errno == EINTR);
    if (fd_ < 0) {
        throw Error(Status::io_error, label_ + ": cannot open the file: " + errno_text(errno));
    }
    struct stat info {};
    if (::fstat(fd_, &info) != 0) {
        const int error = errno;
        ::close(fd_);
        throw Error(Status::io_error,
                    label_ + ": cannot read the file's size: " + errno_text(error));
    }
    if (S_ISDIR(info.st_mode)) {
        ::close(fd_);
        throw Error(Status::io_error, label_ + ": is a directory, expected a volume file");
    }
    if (!S_ISREG(info.st_mode)) {
        ::close(fd_);
        throw Error(Status::io_error, label_ + ": is not a regular file, expected a volume file");
    }
    size_ = static_cast<std::uint64_t>(info.st_size);
}

InputFile::~InputFile()
{
    if (fd_ >= 0) ::close(fd_);
}

void InputFile::read_checked(std::uint64_t offset, void* out, std::size_t count) const
{
    auto* dst = static_cast<unsigned char*>(out);
    std::size_t done = 0;
    while (done < count) {
        // pread moves at most about 2 GiB per call on Linux.
        const std::size_t chunk = std::min<std::size_t>(count - done, std::size_t{1} << 30);
        const ::ssize_t n = ::pread(fd_, dst + done, chunk, static_cast<::off_t>(offset + done));
        if (n < 0) {
            if (errno == EINTR) continue;
            throw Error(Status::io_error, label_ + ": read error at byte " +
                                              std::to_string(offset + done) + ": " +
                                              errno_text(errno));
        }
        if (n == 0) {
            throw Error(Status::truncated_file,
                        label_ + ": the file ended at byte " + std::to_string(offset + done) +
                            " although it had " + std::to_string(size_) +
                            " bytes when opened (was it changed while being read?)");
        }
        done += static_cast<std::size_t>(n);
    }
}

// ---- MemoryInput ----------------------------------------------------------------------------

MemoryInput::MemoryInput(std::string_view bytes, std::string label)
    : ByteInput(std::move(label)), bytes_(bytes)
{
    size_ = bytes_.size();
}

void MemoryInput::read_checked(std::uint64_t offset, void* out, std::size_t count) const
{
    std::memcpy(out, bytes_.data() + offset, count);
}

// ---- ByteSource -----------------------------------------------------------------------------

bool ByteSource::take(std::size_t count, std::string_view& out) noexcept
{
    if (count > remaining()) return false;
    out = bytes_.substr(pos_, count);
    pos_ += count;
    return true;
}

bool ByteSource::next_line(std::string_view& line, bool& terminated) noexcept
{
    if (at_end()) return false;
    const std::size_t end = bytes_.find('\n', pos_);
    terminated = end != std::string_view::npos;
    const std::size_t stop = terminated ? end : bytes_.size();
    line = bytes_.substr(pos_, stop - pos_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos_ = terminated ? end + 1 : stop;
    return true;
}

// ---- byte order -----------------------------------------------------------------------------

Endian native_endian() noexcept
{
    return std::endian::native == std::endian::big ? Endian::big : Endian::little;
}

namespace {

template <class U, U (*Swap)(U)> void swap_all(std::byte* data, std::size_t count) noexcept
{
    // memcpy keeps this free of alignment assumptions; compilers turn the loop into vector code.
    for (std::size_t i = 0; i < count; ++i) {
        U value;
        std::memcpy(&value, data + i * sizeof(U), sizeof(U));
        value = Swap(value);
        std::memcpy(data + i * sizeof(U), &value, sizeof(U));
    }
}

std::uint16_t swap16(std::uint16_t v)
{
    return __builtin_bswap16(v);
}
std::uint32_t swap32(std::uint32_t v)
{
    return __builtin_bswap32(v);
}
std::uint64_t swap64(std::uint64_t v)
{
    return __builtin_bswap64(v);
}

} // namespace

void swap_bytes(std::byte* data, std::size_t count, std::size_t width) noexcept
{
    switch (width) {
    case 2: swap_all<std::uint16_t, swap16>(data, count); break;
    case 4: swap_all<std::uint32_t, swap32>(data, count); break;
    case 8: swap_all<std::uint64_t, swap64>(data, count); break;
    default: break;
    }
}

// ---- zlib / gzip ----------------------------------------------------------------------------

void check_inflate_bound(std::uint64_t compressed, std::uint64_t declared, const std::string& label,
                         const std::string& what)
{
    // A deflate block codes at most 258 bytes per 2 bits, hence about 1032:1; 1024 covers headers.
    constexpr std::uint64_t kRatio = 1032;
    constexpr std::uint64_t kSlack = 1024;
    const bool possible =
        compressed > (std::numeric_limits<std::uint64_t>::max() - kSlack) / kRatio ||
        declared <= compressed * kRatio + kSlack;
    if (!possible) {
        throw Error(Status::truncated_file,
                    label + ": " + what + ", which cannot come out of the " +
                        std::to_string(compressed) +
                        " compressed bytes in the file (deflate expands at most 1032:1); "
                        "the header's sizes are wrong or the file was cut short");
    }
}

// ---- InflateStream --------------------------------------------------------------------------

std::size_t InflateStream::block_for(std::uint64_t size) noexcept
{
    // a short stream (a small .nii.gz, a header read alone) needs no 1 MiB block
    return static_cast<std::size_t>(std::clamp<std::uint64_t>(size, 1, kBlock));
}

#if !defined(CMC33_WITH_ZLIB) || CMC33_WITH_ZLIB
InflateStream::InflateStream(const ByteInput& input, std::uint64_t offset, std::uint64_t size, std::string label)
    : in_(input), offset_(offset), size_(size), label_(std::move(label)), block_size_(block_for(size)),
      block_(new unsigned char[block_size_]), z_(new z_stream_s{})
{
    // 15 + 32: a 32 KiB window, and a zlib or gzip header recognised automatically.
    const int status = inflateInit2(z_.get(), 15 + 32);
    if (status != Z_OK) {
        throw Error(status == Z_MEM_ERROR ? Status::too_large : Status::internal,
                    label_ + ": cannot start zlib inflate (" + std::to_string(status) + ")");
    }
}

InflateStream::~InflateStream() { inflateEnd(z_.get()); }

std::uint64_t InflateStream::consumed() const noexcept { return fed_ - z_->avail_in; }

std::size_t InflateStream::produce(unsigned char* out, std::size_t count)
{
    std::size_t done = 0;
    while (done < count) {
        if (ended_) {
            // A gzip file may hold several members one after the other: continue into the next.
            const std::uint64_t at = consumed();
            unsigned char magic[2] = {0, 0};
            if (size_ - at < 2) break;
            in_.read(offset_ + at, magic, 2);
            if (magic[0] != 0x1f || magic[1] != 0x8b) break;
            inflateReset(z_.get());
            ended_ = false;
        }
        if (z_->avail_in == 0) {
            if (fed_ == size_) break;
            const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(size_ - fed_, block_size_));
            in_.read(offset_ + fed_, block_.get(), n);
            z_->next_in = block_.get();
            z_->avail_in = static_cast<uInt>(n);
            fed_ += n;
        }
        const std::size_t room = std::min<std::size_t>(count - done, kMaxOut);
        z_->next_out = out + done;
        z_->avail_out = static_cast<uInt>(room);
        const int status = inflate(z_.get(), Z_NO_FLUSH);
        done += room - z_->avail_out;
        if (status == Z_STREAM_END) {
            ended_ = true;
        } else if (status == Z_BUF_ERROR) {
            // No progress possible: the input is used up (a full output is handled by the loop).
            if (z_->avail_in == 0 && fed_ < size_) continue;
            break;
        } else if (status == Z_DATA_ERROR) {
            throw Error(Status::bad_format,
                        label_ + ": corrupt compressed data near byte " + std::to_string(consumed()) + " of the " +
                            std::to_string(size_) + "-byte stream (zlib: " + (z_->msg ? z_->msg : "invalid data") + ")");
        } else if (status == Z_NEED_DICT) {
            throw Error(Status::unsupported_format, label_ + ": the compressed stream needs a preset dictionary");
        } else if (status == Z_MEM_ERROR) {
            throw Error(Status::too_large, label_ + ": zlib ran out of memory while inflating");
        } else if (status != Z_OK) {
            throw Error(Status::internal, label_ + ": zlib inflate returned " + std::to_string(status));
        }
    }
    produced_ += done;
    return done;
}

#else
InflateStream::InflateStream(const ByteInput& input, std::uint64_t offset, std::uint64_t size, std::string label)
    : in_(input), offset_(offset), size_(size), label_(std::move(label)), block_size_(block_for(size)),
      block_(new unsigned char[block_size_])
{
    // the portable inflater reads memory: the compressed stream is read whole (a build without
    // zlib, the WebAssembly one, holds its files in memory anyway)
    whole_.resize(static_cast<std::size_t>(size_));
    if (size_ > 0) in_.read(offset_, reinterpret_cast<unsigned char*>(whole_.data()), whole_.size());
    portable_ = std::make_unique<PortableInflater>(whole_, label_);
}

InflateStream::~InflateStream() = default;

std::uint64_t InflateStream::consumed() const noexcept { return portable_->consumed(); }

std::size_t InflateStream::produce(unsigned char* out, std::size_t count)
{
    const std::size_t done = portable_->produce(out, count); // gzip members one after another too
    ended_ = portable_->ended();
    produced_ += done;
    return done;
}

#endif

void InflateStream::read_exactly(unsigned char* out, std::size_t count, std::uint64_t wanted)
{
    if (produce(out, count) < count) fail_short(wanted);
}

void InflateStream::skip(std::uint64_t count, std::uint64_t wanted)
{
    std::array<unsigned char, 1 << 16> scratch{};
    while (count > 0) {
        const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(count, scratch.size()));
        read_exactly(scratch.data(), n, wanted);
        count -= n;
    }
}

void InflateStream::fail_short(std::uint64_t wanted) const
{
    if (ended_) {
        throw Error(Status::truncated_file, label_ + ": the compressed stream holds only " + std::to_string(produced_) +
                                                " bytes but the header declares " + std::to_string(wanted));
    }
    throw Error(Status::truncated_file, label_ + ": the compressed stream ends early, after " +
                                            std::to_string(produced_) + " of the " + std::to_string(wanted) +
                                            " declared bytes (file cut short?)");
}

void InflateStream::finish(std::uint64_t wanted)
{
    // Everything declared is there; the stream must now end (its trailer holds the checksum).
    if (!ended_) {
        unsigned char one = 0;
        if (produce(&one, 1) != 0) {
            throw Error(Status::bad_format, label_ + ": the compressed stream holds more than the " +
                                                std::to_string(wanted) + " bytes the header declares");
        }
        if (!ended_) {
            throw Error(Status::truncated_file,
                        label_ + ": the compressed stream ends before its end marker and checksum (file cut short?)");
        }
    }
    // Only zero padding may follow the stream.
    for (std::uint64_t at = consumed(); at < size_;) {
        const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(size_ - at, block_size_));
        in_.read(offset_ + at, block_.get(), n);
        const auto* first = std::find_if(block_.get(), block_.get() + n, [](unsigned char c) { return c != 0; });
        if (first != block_.get() + n) {
            const std::uint64_t junk = at + static_cast<std::uint64_t>(first - block_.get());
            throw Error(Status::bad_format,
                        label_ + ": " + std::to_string(size_ - junk) +
                            " bytes that are not zero padding follow the end of the compressed stream (at byte " +
                            std::to_string(junk) + " of " + std::to_string(size_) + ")");
        }
        at += n;
    }
#if !defined(CMC33_WITH_ZLIB) || CMC33_WITH_ZLIB
    // the block no longer feeds zlib: nothing reads it after this
    z_->avail_in = 0;
    fed_ = size_;
#endif
}

namespace {

/// A block of bytes that grows by doubling up to a limit, without zeroing (only the bytes
/// written are ever touched, so the memory used follows the bytes decoded).
class GrowingBuffer {
public:
    GrowingBuffer(std::size_t initial, std::size_t limit, const std::string& label)
        : limit_(limit), label_(label)
    {
        reserve(std::min(initial, limit));
    }

    unsigned char* data() noexcept { return reinterpret_cast<unsigned char*>(data_.get()); }
    std::size_t capacity() const noexcept { return capacity_; }
    bool full() const noexcept { return capacity_ == limit_; }
    /// Doubles the capacity (at most to the limit), keeping the first `used` bytes.
    void grow(std::size_t used)
    {
        const std::size_t next = capacity_ > limit_ / 2 ? limit_ : std::max<std::size_t>(2 * capacity_, 1);
        std::unique_ptr<std::byte[]> old = std::move(data_);
        reserve(next);
        std::memcpy(data_.get(), old.get(), used);
    }
    std::unique_ptr<std::byte[]> release() noexcept { return std::move(data_); }

private:
    void reserve(std::size_t count)
    {
        try {
            data_.reset(new std::byte[std::max<std::size_t>(count, 1)]);
        } catch (const std::bad_alloc&) {
            throw Error(Status::too_large,
                        label_ + ": cannot allocate " + std::to_string(count) +
                            " bytes for the inflated samples (the header declares " +
                            std::to_string(limit_) + ")");
        }
        cmc33::detail::advise_huge_pages_within(data_.get(), count);
        capacity_ = count;
    }

    std::unique_ptr<std::byte[]> data_;
    std::size_t capacity_ = 0;
    std::size_t limit_;
    const std::string& label_;
};

} // namespace

std::unique_ptr<std::byte[]> inflate_exact(std::string_view in, std::uint64_t skip,
                                           std::size_t out_size, const std::string& label)
{
#if defined(CMC33_WITH_LIBDEFLATE) && CMC33_WITH_LIBDEFLATE
    if (std::unique_ptr<std::byte[]> whole = inflate_whole(in, skip, out_size)) return whole;
#endif
    const MemoryInput input(in, label);
    InflateStream inflater(input, 0, in.size(), label);
    const std::uint64_t wanted = skip + out_size;
    inflater.skip(skip, wanted);
    // Real volumes compress a few times; start at 16 times the stream (at least 64 KiB, never
    // more than declared) and double while the stream keeps producing.
    constexpr std::size_t kRatioGuess = 16;
    constexpr std::size_t kMinimum = std::size_t{1} << 16;
    const std::size_t guess = in.size() > std::numeric_limits<std::size_t>::max() / kRatioGuess
                                  ? out_size
                                  : std::max(kMinimum, kRatioGuess * in.size());
    GrowingBuffer buffer(guess, out_size, label);
    std::size_t filled = 0;
    while (true) {
        const std::size_t room = buffer.capacity() - filled;
        inflater.read_exactly(buffer.data() + filled, room, wanted);
        filled += room;
        if (buffer.full()) break;
        buffer.grow(filled);
    }
    inflater.finish(wanted);
    return buffer.release();
}

} // namespace cmc33::io::detail
