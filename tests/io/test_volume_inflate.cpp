// The portable inflater (src/io/inflate_portable.cpp, the readers' inflate where there is no zlib:
// the WebAssembly build) against zlib itself: the same bytes out of every kind of stream zlib
// writes, the same end and consumed count, and the same verdict on corrupt streams. Then the
// whole-buffer inflate with libdeflate against the streaming one.

#include <gtest/gtest.h>
#include <zlib.h>

#include <random>
#include <string>
#include <vector>

#include "cmc33/error.hpp"
#include "byte_source.hpp"
#include "inflate_portable.hpp"

namespace {

using cmc33::io::detail::inflate_exact;
using cmc33::io::detail::PortableInflater;

/// `data` deflated by zlib: windowBits 15 (zlib) or 31 (gzip), the given level and strategy.
std::string deflate_with_zlib(const std::string& data, int window_bits, int level, int strategy = Z_DEFAULT_STRATEGY)
{
    z_stream z{};
    EXPECT_EQ(deflateInit2(&z, level, Z_DEFLATED, window_bits, 8, strategy), Z_OK);
    std::string out(deflateBound(&z, static_cast<uLong>(data.size())) + 64, '\0');
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
    z.avail_in = static_cast<uInt>(data.size());
    z.next_out = reinterpret_cast<Bytef*>(out.data());
    z.avail_out = static_cast<uInt>(out.size());
    EXPECT_EQ(deflate(&z, Z_FINISH), Z_STREAM_END);
    out.resize(z.total_out);
    deflateEnd(&z);
    return out;
}

struct Outcome {
    bool complete = false; ///< the stream ended with a valid trailer
    std::string bytes;
    std::size_t consumed = 0;
};

/// zlib's inflate with automatic header detection, as byte_source.cpp runs it (one stream).
Outcome inflate_with_zlib(const std::string& in)
{
    Outcome o;
    z_stream z{};
    EXPECT_EQ(inflateInit2(&z, 15 + 32), Z_OK);
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data()));
    z.avail_in = static_cast<uInt>(in.size());
    char chunk[4096];
    for (;;) {
        z.next_out = reinterpret_cast<Bytef*>(chunk);
        z.avail_out = sizeof chunk;
        const int status = inflate(&z, Z_NO_FLUSH);
        o.bytes.append(chunk, sizeof chunk - z.avail_out);
        if (status == Z_STREAM_END) {
            o.complete = true;
            break;
        }
        if (status != Z_OK) break; // corrupt, or the input ended
    }
    o.consumed = in.size() - z.avail_in;
    inflateEnd(&z);
    return o;
}

/// The portable inflater, asked for `chunks` bytes at a time.
Outcome inflate_portable(const std::string& in, std::size_t chunk)
{
    Outcome o;
    const std::string label = "test.nrrd";
    try {
        PortableInflater inflater(in, label);
        std::vector<unsigned char> buffer(chunk);
        for (;;) {
            const std::size_t made = inflater.produce(buffer.data(), chunk);
            o.bytes.append(reinterpret_cast<const char*>(buffer.data()), made);
            if (made < chunk) break;
        }
        o.complete = inflater.ended();
        o.consumed = inflater.consumed();
    } catch (const cmc33::Error& e) {
        EXPECT_EQ(e.status(), cmc33::Status::bad_format) << e.what();
        EXPECT_EQ(std::string(e.what()).rfind(label + ": corrupt compressed data near byte ", 0), 0u) << e.what();
        o.complete = false;
    }
    return o;
}

/// `packed` (a zlib stream) with FDICT set and the header check fixed (CMF * 256 + FLG divisible by 31).
std::string with_preset_dictionary_flag(std::string packed)
{
    const unsigned cmf = static_cast<unsigned char>(packed[0]);
    unsigned flg = (static_cast<unsigned char>(packed[1]) | 0x20u) & ~31u;
    flg += 31 - (cmf * 256 + flg) % 31;
    packed[1] = static_cast<char>(flg);
    return packed;
}

/// Inputs with literals, short and long matches, runs, and incompressible stretches.
std::vector<std::string> samples()
{
    std::mt19937 rng(7);
    std::vector<std::string> out{"", "x", std::string(100000, '\0')};
    std::string noise(70000, '\0');
    for (char& c : noise) c = static_cast<char>(rng());
    out.push_back(noise);
    std::string volume; // a smooth uint16 field, as CT data compresses
    for (int k = 0; k < 40; ++k)
        for (int j = 0; j < 60; ++j)
            for (int i = 0; i < 60; ++i) {
                const int v = (i * i + j * 3 + k * k * 2) % 4096 + static_cast<int>(rng() % 3);
                volume.push_back(static_cast<char>(v & 255));
                volume.push_back(static_cast<char>(v >> 8));
            }
    out.push_back(volume);
    std::string text;
    while (text.size() < 300000) text += "sizes: 256 256 " + std::to_string(rng() % 1000) + "\nencoding: gzip\n";
    out.push_back(text);
    return out;
}

TEST(PortableInflate, SameBytesAsZlibForEveryKindOfStream)
{
    int streams = 0;
    for (const std::string& data : samples()) {
        for (const int window_bits : {15, 31})
            for (const int level : {0, 1, 6, 9})
                for (const int strategy : {Z_DEFAULT_STRATEGY, Z_FILTERED, Z_HUFFMAN_ONLY, Z_RLE, Z_FIXED}) {
                    const std::string packed = deflate_with_zlib(data, window_bits, level, strategy);
                    for (const std::size_t chunk : {std::size_t{1} << 20, std::size_t{1000}}) {
                        const Outcome got = inflate_portable(packed, chunk);
                        SCOPED_TRACE("size " + std::to_string(data.size()) + ", window bits " + std::to_string(window_bits) +
                                     ", level " + std::to_string(level) + ", strategy " + std::to_string(strategy));
                        ASSERT_TRUE(got.complete);
                        ASSERT_EQ(got.bytes, data);
                        EXPECT_EQ(got.consumed, packed.size());
                    }
                    ++streams;
                }
    }
    EXPECT_EQ(streams, 6 * 2 * 4 * 5);
}

TEST(PortableInflate, GzipMembersFollowOneAnother)
{
    const std::string a = "first member\n", b(50000, 'b');
    const std::string packed = deflate_with_zlib(a, 31, 6, Z_DEFAULT_STRATEGY) + deflate_with_zlib(b, 31, 9, Z_DEFAULT_STRATEGY);
    const Outcome got = inflate_portable(packed + std::string(5, '\0'), 777);
    EXPECT_TRUE(got.complete);
    EXPECT_EQ(got.bytes, a + b);
    EXPECT_EQ(got.consumed, packed.size()); // the zero padding is left to the caller
}

TEST(PortableInflate, EveryTruncationEndsEarlyWithoutError)
{
    const std::string data = samples()[4].substr(0, 8000);
    for (const int window_bits : {15, 31}) {
        const std::string packed = deflate_with_zlib(data, window_bits, 6, Z_DEFAULT_STRATEGY);
        for (std::size_t n = 0; n < packed.size(); ++n) {
            const Outcome got = inflate_portable(packed.substr(0, n), 4096);
            ASSERT_FALSE(got.complete) << "cut at " << n;
            ASSERT_EQ(data.compare(0, got.bytes.size(), got.bytes), 0) << "cut at " << n;
            ASSERT_LE(got.bytes.size(), inflate_with_zlib(packed.substr(0, n)).bytes.size() + 258 + 32768) << n;
        }
    }
}

TEST(PortableInflate, CorruptStreamsGetZlibsVerdict)
{
    std::mt19937 rng(11);
    const std::string data = samples()[4].substr(0, 30000) + samples()[5].substr(0, 30000);
    int rejected = 0, trials = 0;
    for (const int window_bits : {15, 31})
        for (const int strategy : {Z_DEFAULT_STRATEGY, Z_FIXED}) {
            const std::string packed = deflate_with_zlib(data, window_bits, 6, strategy);
            for (int t = 0; t < 1500; ++t, ++trials) {
                std::string bad = packed;
                const std::size_t at = rng() % bad.size();
                bad[at] = static_cast<char>(bad[at] ^ static_cast<char>(1 + rng() % 255));
                const Outcome want = inflate_with_zlib(bad), got = inflate_portable(bad, 1 << 16);
                ASSERT_EQ(got.complete, want.complete) << "byte " << at << " of " << bad.size();
                if (want.complete) {
                    ASSERT_EQ(got.bytes, want.bytes);
                    ASSERT_EQ(got.consumed, want.consumed);
                }
                rejected += !want.complete;
            }
        }
    EXPECT_GT(rejected, trials * 9 / 10);
}

TEST(PortableInflate, PresetDictionaryIsUnsupported)
{
    const std::string packed = with_preset_dictionary_flag(deflate_with_zlib("abc", 15, 6, Z_DEFAULT_STRATEGY));
    const std::string label = "dict.nrrd";
    PortableInflater inflater(packed, label);
    unsigned char out[16];
    try {
        (void)inflater.produce(out, sizeof out);
        ADD_FAILURE() << "no error";
    } catch (const cmc33::Error& e) {
        EXPECT_EQ(e.status(), cmc33::Status::unsupported_format);
        EXPECT_EQ(std::string(e.what()), "dict.nrrd: the compressed stream needs a preset dictionary");
    }
}

// ---- inflate_exact()'s whole-buffer path with libdeflate (src/io/inflate_libdeflate.cpp): it gives
// zlib's bytes for every stream zlib accepts, and gives up (null) on every stream inflate_exact()
// refuses, so that zlib's path, unchanged, says what is wrong; and inflate_exact() itself keeps its
// bytes and its one-line errors, whichever path ran.

/// A smooth uint16 field with a little noise, as CT samples compress.
std::string volume_bytes(std::size_t samples, unsigned seed)
{
    std::mt19937 rng(seed);
    std::string out;
    out.reserve(2 * samples);
    for (std::size_t i = 0; i < samples; ++i) {
        const auto v = static_cast<unsigned>((i % 97) * (i % 89) / 3 + rng() % 5) & 0xfffu;
        out.push_back(static_cast<char>(v & 255));
        out.push_back(static_cast<char>(v >> 8));
    }
    return out;
}

std::string as_string(const std::unique_ptr<std::byte[]>& bytes, std::size_t n)
{
    return {reinterpret_cast<const char*>(bytes.get()), n};
}

struct Verdict {
    bool ok = false;
    std::string bytes;
    cmc33::Status status = cmc33::Status::internal; ///< meaningful when !ok
    std::string message;
};

Verdict run_inflate_exact(const std::string& in, std::uint64_t skip, std::size_t size)
{
    Verdict v;
    try {
        v.bytes = as_string(inflate_exact(in, skip, size, "v.nrrd"), size);
        v.ok = true;
    } catch (const cmc33::Error& e) {
        v.status = e.status();
        v.message = e.what();
    }
    return v;
}

/// The streaming path alone (what inflate_exact() did before the whole-buffer path): InflateStream
/// over the bytes in memory, read to the declared size, then finished.
Verdict run_streaming(const std::string& in, std::uint64_t skip, std::size_t size)
{
    Verdict v;
    try {
        const std::string label = "v.nrrd";
        const cmc33::io::detail::MemoryInput input(in, label);
        cmc33::io::detail::InflateStream stream(input, 0, in.size(), label);
        stream.skip(skip, skip + size);
        std::string out(size, '\0');
        stream.read_exactly(reinterpret_cast<unsigned char*>(out.data()), size, skip + size);
        stream.finish(skip + size);
        v.bytes = out;
        v.ok = true;
    } catch (const cmc33::Error& e) {
        v.status = e.status();
        v.message = e.what();
    }
    return v;
}

void expect_same(const Verdict& got, const Verdict& want)
{
    ASSERT_EQ(got.ok, want.ok) << (got.ok ? want.message : got.message);
    EXPECT_EQ(got.bytes, want.bytes);
    EXPECT_EQ(got.status, want.status);
    EXPECT_EQ(got.message, want.message);
}

TEST(InflateWhole, SameBytesAsZlibForEveryKindOfStream)
{
    const std::string data = volume_bytes(300000, 3);
    for (const int window_bits : {15, 31})
        for (const int level : {0, 1, 6, 9})
            for (const int strategy : {Z_DEFAULT_STRATEGY, Z_FILTERED, Z_HUFFMAN_ONLY, Z_RLE, Z_FIXED}) {
                SCOPED_TRACE("window bits " + std::to_string(window_bits) + ", level " + std::to_string(level) +
                             ", strategy " + std::to_string(strategy));
                const std::string packed = deflate_with_zlib(data, window_bits, level, strategy);
#if defined(CMC33_WITH_LIBDEFLATE) && CMC33_WITH_LIBDEFLATE
                const auto whole = cmc33::io::detail::inflate_whole(packed, 0, data.size());
                ASSERT_TRUE(whole);
                ASSERT_EQ(as_string(whole, data.size()), data);
#endif
                const Verdict got = run_inflate_exact(packed, 0, data.size());
                ASSERT_TRUE(got.ok) << got.message;
                ASSERT_EQ(got.bytes, data);
            }
}

TEST(InflateWhole, GzipMembersSkipAndZeroPadding)
{
    const std::string a = volume_bytes(5000, 1), b = volume_bytes(70000, 2), c;
    const std::string packed = deflate_with_zlib(a, 31, 6) + deflate_with_zlib(c, 31, 6) + deflate_with_zlib(b, 31, 1);
    for (const std::string& in : {packed, packed + std::string(7, '\0')})
        for (const std::size_t skip : {std::size_t{0}, std::size_t{1}, a.size(), a.size() + 3}) {
            SCOPED_TRACE("skip " + std::to_string(skip) + ", padding " + std::to_string(in.size() - packed.size()));
            const std::size_t size = a.size() + b.size() - skip;
#if defined(CMC33_WITH_LIBDEFLATE) && CMC33_WITH_LIBDEFLATE
            // the last member's ISIZE is not the whole size: the stream does not vouch for the
            // allocation, and the streaming inflater reads it
            EXPECT_FALSE(cmc33::io::detail::inflate_whole(in, skip, size));
#endif
            expect_same(run_inflate_exact(in, skip, size), run_streaming(in, skip, size));
        }
    // a zlib stream followed by a gzip member, as InflateStream reads them
    const std::string mixed = deflate_with_zlib(a, 15, 6) + deflate_with_zlib(b, 31, 6);
    expect_same(run_inflate_exact(mixed, 0, a.size() + b.size()), run_streaming(mixed, 0, a.size() + b.size()));
}

/// Every stream inflate_exact() refuses: the whole-buffer path gives up, and the error is the
/// streaming path's, word for word.
TEST(InflateWhole, RefusedStreamsKeepTheirErrors)
{
    const std::string data = volume_bytes(40000, 5);
    std::vector<std::pair<std::string, std::string>> cases; // (what, stream)
    for (const int window_bits : {15, 31}) {
        const std::string packed = deflate_with_zlib(data, window_bits, 6);
        const std::string kind = window_bits == 15 ? "zlib" : "gzip";
        for (const std::size_t cut : {std::size_t{0}, std::size_t{1}, std::size_t{5}, packed.size() / 2,
                                      packed.size() - 4, packed.size() - 1})
            cases.emplace_back(kind + " cut at " + std::to_string(cut), packed.substr(0, cut));
        cases.emplace_back(kind + " with junk after it", packed + "junk");
        cases.emplace_back(kind + " with a zero and junk after it", packed + std::string(1, '\0') + "x");
        cases.emplace_back(kind + " followed by a cut gzip member",
                           packed + deflate_with_zlib(data, 31, 6).substr(0, 30));
        std::mt19937 rng(window_bits);
        for (int t = 0; t < 300; ++t) {
            std::string bad = packed;
            const std::size_t at = rng() % bad.size();
            bad[at] = static_cast<char>(bad[at] ^ static_cast<char>(1 + rng() % 255));
            cases.emplace_back(kind + " with byte " + std::to_string(at) + " changed", bad);
        }
    }
    // a gzip header CRC (FHCRC) that does not match: zlib checks it, libdeflate would not
    std::string hcrc = deflate_with_zlib(data, 31, 6);
    hcrc[3] = static_cast<char>(hcrc[3] | 0x02);
    hcrc.insert(10, "\x12\x34", 2);
    cases.emplace_back("gzip with a wrong header CRC", hcrc);
    // a zlib stream that needs a preset dictionary
    cases.emplace_back("zlib with a preset dictionary", with_preset_dictionary_flag(deflate_with_zlib(data, 15, 6)));

    int refused = 0;
    for (const auto& [what, stream] : cases) {
        SCOPED_TRACE(what);
        for (const std::size_t size : {data.size(), data.size() - 1, data.size() + 1}) {
            const Verdict want = run_streaming(stream, 0, size);
#if defined(CMC33_WITH_LIBDEFLATE) && CMC33_WITH_LIBDEFLATE
            if (!want.ok) {
                ASSERT_FALSE(cmc33::io::detail::inflate_whole(stream, 0, size)) << want.message;
            }
#endif
            expect_same(run_inflate_exact(stream, 0, size), want);
            refused += !want.ok;
        }
    }
    EXPECT_GT(refused, static_cast<int>(cases.size()) * 2);
}

TEST(InflateWhole, DeclaredSizeOtherThanTheStreamsIsRefusedAsBefore)
{
    const std::string data = volume_bytes(10000, 9);
    const std::string packed = deflate_with_zlib(data, 31, 9);
    const Verdict more = run_inflate_exact(packed, 0, data.size() + 10);
    EXPECT_EQ(more.status, cmc33::Status::truncated_file);
    EXPECT_EQ(more.message, "v.nrrd: the compressed stream holds only 20000 bytes but the header declares 20010");
    const Verdict fewer = run_inflate_exact(packed, 0, data.size() - 10);
    EXPECT_EQ(fewer.status, cmc33::Status::bad_format);
    EXPECT_EQ(fewer.message, "v.nrrd: the compressed stream holds more than the 19990 bytes the header declares");
}

} // namespace
