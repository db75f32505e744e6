#pragma once
// Inflate (RFC 1951) of zlib (RFC 1950) and gzip (RFC 1952) streams without zlib, for builds that
// have none (CMC33_WITH_ZLIB=OFF: the WebAssembly build, where Debian ships no zlib for wasm).
// Written for cmc33 from the RFCs. It has the contract of byte_source.cpp's zlib Inflater, which it
// replaces there: the same bytes out, the same end and consumed count, corrupt data and a preset
// dictionary reported as zlib's inflate reports them (tests/io/test_inflate_portable.cpp checks it
// against zlib). Huffman codes are read through a 9-bit table, longer ones bit by bit.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace cmc33::io::detail {

class PortableInflater {
public:
    /// Inflates the stream(s) in `in`: zlib or gzip, recognised by their first bytes; gzip members
    /// may follow one another. `label` names the file in errors (kept by reference).
    PortableInflater(std::string_view in, const std::string& label);

    /// Writes up to `count` bytes to `out`; fewer only when the input ended (then `ended()` says
    /// whether the stream was complete). Returns how many were written.
    /// @throws Error{bad_format} for corrupt data or a wrong checksum, Error{unsupported_format} for
    /// a stream that needs a preset dictionary.
    std::size_t produce(unsigned char* out, std::size_t count);

    /// The last stream ended with a valid trailer.
    bool ended() const noexcept { return ended_; }
    /// Bytes of `in` read so far (after the end: up to the end of the trailer).
    std::size_t consumed() const noexcept { return pos_ - bits_ / 8; }

    /// Huffman code of one alphabet: canonical, as RFC 1951 3.2.2 builds it.
    struct Code {
        std::array<std::uint16_t, 16> count{};   ///< codes of each length
        std::array<std::uint16_t, 288> symbol{}; ///< symbols ordered by code
        std::array<std::uint16_t, 512> fast{};   ///< 9 bits reversed -> symbol << 4 | length (0: longer)
    };

private:
    void start_member();
    void block();
    void finish_member();
    void stored();
    void codes(const Code& lengths, const Code& distances);
    void dynamic_codes(Code& lengths, Code& distances);

    bool fill(int n);       ///< at least n bits in the buffer, or false at the end of the input
    std::uint32_t bits(int n); ///< the next n bits (throws the internal Truncated at the end)
    int decode(const Code& code);
    void emit(unsigned char byte);
    [[noreturn]] void corrupt(const char* what) const;

    std::string_view in_;
    const std::string& label_;
    std::size_t pos_ = 0;      ///< next byte of in_ to load into the bit buffer
    std::uint64_t buffer_ = 0; ///< bits not yet read, the next one lowest
    int bits_ = 0;

    std::vector<unsigned char> out_; ///< the last 32 KiB handed out (the window) and the bytes not yet handed out
    std::size_t next_ = 0;           ///< first byte of out_ not yet handed out
    std::uint64_t member_bytes_ = 0; ///< bytes inflated in this member (distances reach no further back)
    std::uint32_t crc_ = 0, adler_ = 1;
    bool gzip_ = false, in_member_ = false, last_block_ = false, ended_ = false, truncated_ = false;
};

} // namespace cmc33::io::detail
