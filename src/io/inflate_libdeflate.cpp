// Whole-buffer inflate with libdeflate (contract in byte_source.hpp, inflate_whole): the declared
// size is known, so a compressed volume read whole is inflated in one call per gzip member,
// without zlib's window copies. Anything it does not accept goes back to InflateStream, whose
// messages say what is wrong; so both paths refuse the same files with the same words.

#include "byte_source.hpp"

#if defined(CMC33_WITH_LIBDEFLATE) && CMC33_WITH_LIBDEFLATE

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <new>

#include <libdeflate.h>

#include "portability.hpp"

namespace cmc33::io::detail {

namespace {

struct DecompressorDeleter {
    void operator()(libdeflate_decompressor* d) const noexcept { libdeflate_free_decompressor(d); }
};

bool is_gzip(const unsigned char* p, std::size_t n) noexcept { return n >= 2 && p[0] == 0x1f && p[1] == 0x8b; }

} // namespace

std::unique_ptr<std::byte[]> inflate_whole(std::string_view in, std::uint64_t skip, std::size_t out_size)
{
    // skip bytes are inflated and dropped: beyond the samples' size they would double the memory
    if (skip > out_size || out_size > std::numeric_limits<std::size_t>::max() - skip) return nullptr;
    const std::size_t total = static_cast<std::size_t>(skip) + out_size;
    // Allocate the declared size only when the stream vouches for it: a gzip stream's last four
    // bytes are its size mod 2^32 (ISIZE, RFC 1952), and deflate expands at most 1032:1. Otherwise
    // InflateStream reads what the stream holds and says what is wrong, at the cost of those bytes.
    const auto* head = reinterpret_cast<const unsigned char*>(in.data());
    if (total / 1032 > in.size()) return nullptr;
    if (is_gzip(head, in.size())) {
        if (in.size() < 18) return nullptr;
        const unsigned char* t = head + in.size() - 4;
        const std::uint32_t isize = std::uint32_t{t[0]} | std::uint32_t{t[1]} << 8 | std::uint32_t{t[2]} << 16 | std::uint32_t{t[3]} << 24;
        if (isize != static_cast<std::uint32_t>(total)) return nullptr;
    }
    const std::unique_ptr<libdeflate_decompressor, DecompressorDeleter> decompressor(libdeflate_alloc_decompressor());
    if (!decompressor) return nullptr;
    // Pages are touched only as bytes are decoded, so a header that declares more than the stream
    // holds costs address space, not memory.
    std::unique_ptr<std::byte[]> out(new (std::nothrow) std::byte[std::max<std::size_t>(total, 1)]);
    if (!out) return nullptr;
    cmc33::detail::advise_huge_pages_within(out.get(), total);

    const auto* data = reinterpret_cast<const unsigned char*>(in.data());
    std::size_t pos = 0, produced = 0;
    // The first stream is zlib or gzip; gzip members may follow (as InflateStream reads them).
    for (bool first = true; first || is_gzip(data + pos, in.size() - pos); first = false) {
        const unsigned char* src = data + pos;
        const std::size_t avail = in.size() - pos;
        std::size_t used = 0, made = 0;
        libdeflate_result result;
        if (is_gzip(src, avail)) {
            // libdeflate skips a gzip header's CRC (FHCRC) unchecked; zlib checks it
            if (avail < 4 || (src[3] & 0x02) != 0) return nullptr;
            result = libdeflate_gzip_decompress_ex(decompressor.get(), src, avail, out.get() + produced,
                                                   total - produced, &used, &made);
        } else {
            result = libdeflate_zlib_decompress_ex(decompressor.get(), src, avail, out.get() + produced,
                                                   total - produced, &used, &made);
        }
        if (result != LIBDEFLATE_SUCCESS || used == 0) return nullptr;
        pos += used;
        produced += made;
    }
    if (produced != total) return nullptr;
    // only zero padding may follow the stream
    for (std::size_t i = pos; i < in.size(); ++i) {
        if (data[i] != 0) return nullptr;
    }
    if (skip > 0) std::memmove(out.get(), out.get() + skip, out_size);
    return out;
}

} // namespace cmc33::io::detail

#endif
