// Inflate without zlib (contract in inflate_portable.hpp). RFC 1950 (zlib), 1951 (deflate),
// 1952 (gzip); messages follow zlib's, so that both builds report a corrupt file alike.

#include "inflate_portable.hpp"

#include <algorithm>
#include <cstring>

#include "cmc33/error.hpp"

namespace cmc33::io::detail {

namespace {

struct Truncated {}; // the input ended inside a stream: produce() stops, ended() stays false

constexpr std::size_t kWindow = std::size_t{1} << 15;

/// Base value and extra bits of the length symbols 257..285 (RFC 1951 3.2.5), computed from the
/// rule the RFC's table follows; the distances' rule is short enough to apply where used.
struct LengthBases {
    std::array<std::uint16_t, 29> base{};
    std::array<std::uint8_t, 29> extra{};
    LengthBases()
    {
        int b = 3;
        for (std::size_t i = 0; i < 28; ++i) {
            const int e = i < 8 ? 0 : static_cast<int>(i - 4) / 4;
            base[i] = static_cast<std::uint16_t>(b), extra[i] = static_cast<std::uint8_t>(e);
            b += 1 << e;
        }
        base[28] = 258, extra[28] = 0; // 285: 258 with no extra bits, not 227 + 32
    }
};
const LengthBases kLength;

constexpr int distance_extra(int symbol) { return symbol < 4 ? 0 : (symbol - 2) / 2; }
constexpr std::size_t distance_base(int symbol)
{
    std::size_t d = 1;
    for (int i = 0; i < symbol; ++i) d += std::size_t{1} << distance_extra(i);
    return d;
}
constexpr std::array<std::uint16_t, 30> kDistanceBase = [] {
    std::array<std::uint16_t, 30> t{};
    for (int i = 0; i < 30; ++i) t[static_cast<std::size_t>(i)] = static_cast<std::uint16_t>(distance_base(i));
    return t;
}();
static_assert(kDistanceBase[29] == 24577, "RFC 1951: distance code 29 starts at 24577");

std::array<std::uint32_t, 256> make_crc_table()
{
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t n = 0; n < 256; ++n) {
        std::uint32_t c = n;
        for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xedb88320u ^ (c >> 1) : c >> 1;
        t[n] = c;
    }
    return t;
}
const std::array<std::uint32_t, 256> kCrcTable = make_crc_table();

std::uint32_t crc32_update(std::uint32_t crc, const unsigned char* p, std::size_t n)
{
    std::uint32_t c = ~crc;
    for (std::size_t i = 0; i < n; ++i) c = kCrcTable[(c ^ p[i]) & 0xffu] ^ (c >> 8);
    return ~c;
}

std::uint32_t adler32_update(std::uint32_t adler, const unsigned char* p, std::size_t n)
{
    std::uint32_t a = adler & 0xffffu, b = adler >> 16;
    while (n > 0) {
        const std::size_t run = std::min<std::size_t>(n, 5552); // no overflow of b before the modulo
        for (std::size_t i = 0; i < run; ++i) a += p[i], b += a;
        a %= 65521u, b %= 65521u;
        p += run, n -= run;
    }
    return b << 16 | a;
}

/// Builds `code` from the code lengths of n symbols; nullptr, or zlib's word for what is wrong.
/// Over-subscribed sets are wrong; incomplete ones too, except a single code of one bit and the
/// empty set (whose codes then decode as invalid), as zlib allows for literals and distances.
const char* build(PortableInflater::Code& code, const std::uint8_t* lengths, int n, bool code_lengths)
{
    code = {};
    for (int s = 0; s < n; ++s) ++code.count[lengths[s]];
    code.count[0] = 0;
    int left = 1, longest = 0;
    for (int len = 1; len < 16; ++len) {
        left = 2 * left - code.count[static_cast<std::size_t>(len)];
        if (left < 0) return "over-subscribed";
        if (code.count[static_cast<std::size_t>(len)] != 0) longest = len;
    }
    if (left > 0 && longest != 0 && (code_lengths || longest != 1)) return "incomplete";
    std::array<std::uint16_t, 16> offset{}, next{};
    for (std::size_t len = 1; len < 15; ++len) offset[len + 1] = static_cast<std::uint16_t>(offset[len] + code.count[len]);
    int c = 0;
    for (std::size_t len = 1; len < 16; ++len) {
        c = (c + code.count[len - 1]) << 1;
        next[len] = static_cast<std::uint16_t>(c);
    }
    for (int s = 0; s < n; ++s) {
        const std::size_t len = lengths[s];
        if (len == 0) continue;
        code.symbol[offset[len]++] = static_cast<std::uint16_t>(s);
        const unsigned canonical = next[len]++;
        if (len > 9) continue;
        unsigned reversed = 0;
        for (std::size_t b = 0; b < len; ++b) reversed |= ((canonical >> b) & 1u) << (len - 1 - b);
        for (unsigned k = reversed; k < 512; k += 1u << len) code.fast[k] = static_cast<std::uint16_t>(s << 4 | static_cast<int>(len));
    }
    return nullptr;
}

} // namespace

PortableInflater::PortableInflater(std::string_view in, const std::string& label) : in_(in), label_(label) {}

void PortableInflater::corrupt(const char* what) const
{
    throw Error(Status::bad_format, label_ + ": corrupt compressed data near byte " + std::to_string(consumed()) +
                                        " of the " + std::to_string(in_.size()) + "-byte stream (inflate: " + what + ")");
}

bool PortableInflater::fill(int n)
{
    while (bits_ < n) {
        if (pos_ == in_.size()) return false;
        buffer_ |= static_cast<std::uint64_t>(static_cast<unsigned char>(in_[pos_++])) << bits_;
        bits_ += 8;
    }
    return true;
}

std::uint32_t PortableInflater::bits(int n)
{
    if (n == 0) return 0;
    if (!fill(n)) throw Truncated{};
    const auto v = static_cast<std::uint32_t>(buffer_ & ((std::uint64_t{1} << n) - 1));
    buffer_ >>= n;
    bits_ -= n;
    return v;
}

int PortableInflater::decode(const Code& code)
{
    if (fill(9)) {
        const unsigned e = code.fast[buffer_ & 511u];
        if (e != 0) {
            const int len = static_cast<int>(e & 15u);
            buffer_ >>= len;
            bits_ -= len;
            return static_cast<int>(e >> 4);
        }
    }
    int value = 0, first = 0, index = 0; // canonical decoding, one bit at a time (RFC 1951 3.2.2)
    for (std::size_t len = 1; len < 16; ++len) {
        value |= static_cast<int>(bits(1));
        const int count = code.count[len];
        if (value - first < count) return code.symbol[static_cast<std::size_t>(index + value - first)];
        index += count, first += count;
        first <<= 1, value <<= 1;
    }
    return -1;
}

void PortableInflater::emit(unsigned char byte) { out_.push_back(byte); }

void PortableInflater::start_member()
{
    if (!fill(16)) throw Truncated{};
    const auto b0 = static_cast<unsigned>(buffer_ & 0xffu), b1 = static_cast<unsigned>(buffer_ >> 8 & 0xffu);
    gzip_ = b0 == 0x1f && b1 == 0x8b;
    member_bytes_ = 0, crc_ = 0, adler_ = 1, last_block_ = false;
    if (gzip_) {
        unsigned char header[10];
        for (unsigned char& h : header) h = static_cast<unsigned char>(bits(8));
        std::uint32_t header_crc = crc32_update(0, header, 10);
        const auto read_byte = [&] {
            const auto b = static_cast<unsigned char>(bits(8));
            header_crc = crc32_update(header_crc, &b, 1);
            return b;
        };
        if (header[2] != 8) corrupt("unknown compression method");
        const unsigned flags = header[3];
        if (flags & 0xe0u) corrupt("unknown header flags set");
        if (flags & 4u) { // FEXTRA
            unsigned xlen = read_byte();
            xlen |= static_cast<unsigned>(read_byte()) << 8;
            for (unsigned i = 0; i < xlen; ++i) read_byte();
        }
        for (const unsigned zero_terminated : {8u, 16u}) { // FNAME, FCOMMENT
            if (flags & zero_terminated) {
                while (read_byte() != 0) continue;
            }
        }
        if (flags & 2u) { // FHCRC: the low 16 bits of the header's CRC-32
            const std::uint32_t want = header_crc & 0xffffu;
            if (bits(16) != want) corrupt("header crc mismatch");
        }
    } else {
        const unsigned cmf = static_cast<unsigned>(bits(8)), flg = static_cast<unsigned>(bits(8));
        if ((cmf << 8 | flg) % 31 != 0) corrupt("incorrect header check");
        if ((cmf & 15u) != 8) corrupt("unknown compression method");
        if ((cmf >> 4) > 7) corrupt("invalid window size");
        if (flg & 0x20u) {
            throw Error(Status::unsupported_format, label_ + ": the compressed stream needs a preset dictionary");
        }
    }
    in_member_ = true;
}

void PortableInflater::finish_member()
{
    const int skip = bits_ % 8; // the trailer starts at a byte boundary
    buffer_ >>= skip;
    bits_ -= skip;
    if (gzip_) {
        const auto little_endian_32 = [this] {
            const std::uint32_t low = bits(16); // two statements: the order of the reads is fixed
            return low | bits(16) << 16;
        };
        const std::uint32_t crc = little_endian_32();
        if (crc != crc_) corrupt("incorrect data check");
        const std::uint32_t size = little_endian_32();
        if (size != static_cast<std::uint32_t>(member_bytes_)) corrupt("incorrect length check");
    } else {
        std::uint32_t adler = 0;
        for (int i = 0; i < 4; ++i) adler = adler << 8 | bits(8);
        if (adler != adler_) corrupt("incorrect data check");
    }
    in_member_ = false;
    ended_ = true;
}

void PortableInflater::block()
{
    const std::size_t start = out_.size();
    last_block_ = bits(1) != 0;
    const std::uint32_t type = bits(2);
    if (type == 0) {
        stored();
    } else if (type == 1) {
        static const std::pair<Code, Code> fixed = [] {
            std::uint8_t lengths[288];
            std::fill(lengths, lengths + 144, 8);
            std::fill(lengths + 144, lengths + 256, 9);
            std::fill(lengths + 256, lengths + 280, 7);
            std::fill(lengths + 280, lengths + 288, 8);
            std::uint8_t distances[32];
            std::fill(distances, distances + 32, 5);
            std::pair<Code, Code> c;
            build(c.first, lengths, 288, false);
            build(c.second, distances, 32, false);
            return c;
        }();
        codes(fixed.first, fixed.second);
    } else if (type == 2) {
        Code lengths, distances;
        dynamic_codes(lengths, distances);
        codes(lengths, distances);
    } else {
        corrupt("invalid block type");
    }
    const std::size_t n = out_.size() - start;
    if (gzip_) {
        crc_ = crc32_update(crc_, out_.data() + start, n);
    } else {
        adler_ = adler32_update(adler_, out_.data() + start, n);
    }
}

void PortableInflater::stored()
{
    const int skip = bits_ % 8;
    buffer_ >>= skip;
    bits_ -= skip;
    const std::uint32_t length = bits(16), complement = bits(16);
    if (length != (~complement & 0xffffu)) corrupt("invalid stored block lengths");
    for (std::uint32_t i = 0; i < length; ++i) emit(static_cast<unsigned char>(bits(8)));
    member_bytes_ += length;
}

void PortableInflater::dynamic_codes(Code& lengths, Code& distances)
{
    const int nlen = static_cast<int>(bits(5)) + 257, ndist = static_cast<int>(bits(5)) + 1;
    const int ncode = static_cast<int>(bits(4)) + 4;
    if (nlen > 286 || ndist > 30) corrupt("too many length or distance symbols");
    static constexpr int kOrder[19] = {16, 17, 18, 0, 8, 7, 9, 6, 10, 5, 11, 4, 12, 3, 13, 2, 14, 1, 15};
    std::uint8_t l[320] = {};
    for (int i = 0; i < ncode; ++i) l[kOrder[i]] = static_cast<std::uint8_t>(bits(3));
    Code code_lengths;
    if (build(code_lengths, l, 19, true) != nullptr) corrupt("invalid code lengths set");
    std::fill(l, l + 19, 0);
    for (int i = 0; i < nlen + ndist;) {
        const int sym = decode(code_lengths);
        if (sym < 0) corrupt("invalid code lengths set");
        if (sym < 16) {
            l[i++] = static_cast<std::uint8_t>(sym);
            continue;
        }
        int repeat = 0;
        std::uint8_t value = 0;
        if (sym == 16) {
            if (i == 0) corrupt("invalid bit length repeat");
            value = l[i - 1];
            repeat = 3 + static_cast<int>(bits(2));
        } else if (sym == 17) {
            repeat = 3 + static_cast<int>(bits(3));
        } else {
            repeat = 11 + static_cast<int>(bits(7));
        }
        if (i + repeat > nlen + ndist) corrupt("invalid bit length repeat");
        while (repeat-- > 0) l[i++] = value;
    }
    if (l[256] == 0) corrupt("invalid code -- missing end-of-block");
    if (build(lengths, l, nlen, false) != nullptr) corrupt("invalid literal/lengths set");
    if (build(distances, l + nlen, ndist, false) != nullptr) corrupt("invalid distances set");
}

void PortableInflater::codes(const Code& lengths, const Code& distances)
{
    for (;;) {
        const int sym = decode(lengths);
        if (sym < 0 || sym > 285) corrupt("invalid literal/length code");
        if (sym < 256) {
            emit(static_cast<unsigned char>(sym));
            ++member_bytes_;
            continue;
        }
        if (sym == 256) return;
        const auto li = static_cast<std::size_t>(sym - 257);
        const std::size_t length = kLength.base[li] + bits(kLength.extra[li]);
        const int ds = decode(distances);
        if (ds < 0 || ds > 29) corrupt("invalid distance code");
        const std::size_t distance = kDistanceBase[static_cast<std::size_t>(ds)] + bits(distance_extra(ds));
        if (distance > member_bytes_) corrupt("invalid distance too far back");
        std::size_t from = out_.size() - distance;
        for (std::size_t k = 0; k < length; ++k) emit(out_[from++]);
        member_bytes_ += length;
    }
}

std::size_t PortableInflater::produce(unsigned char* out, std::size_t count)
{
    std::size_t done = 0;
    while (done < count) {
        if (next_ < out_.size()) {
            const std::size_t n = std::min(count - done, out_.size() - next_);
            std::memcpy(out + done, out_.data() + next_, n);
            next_ += n, done += n;
            if (next_ > 2 * kWindow) { // keep the last 32 KiB handed out: distances reach that far
                out_.erase(out_.begin(), out_.begin() + static_cast<std::ptrdiff_t>(next_ - kWindow));
                next_ = kWindow;
            }
            continue;
        }
        if (truncated_) break;
        if (ended_) {
            // A gzip file may hold several members one after the other: continue into the next.
            const std::string_view rest = in_.substr(consumed());
            if (rest.size() < 2 || static_cast<unsigned char>(rest[0]) != 0x1f ||
                static_cast<unsigned char>(rest[1]) != 0x8b) {
                break;
            }
            ended_ = false;
        }
        try {
            if (!in_member_) {
                start_member();
            } else if (last_block_) {
                finish_member();
            } else {
                block();
            }
        } catch (const Truncated&) {
            truncated_ = true;
        }
    }
    return done;
}

} // namespace cmc33::io::detail
