// The portable inflater (src/io/inflate_portable.cpp, the readers' inflate where there is no zlib:
// the WebAssembly build) against zlib itself: the same bytes out of every kind of stream zlib
// writes, the same end and consumed count, and the same verdict on corrupt streams.

#include <gtest/gtest.h>
#include <zlib.h>

#include <random>
#include <string>
#include <vector>

#include "cmc33/error.hpp"
#include "inflate_portable.hpp"

namespace {

using cmc33::io::detail::PortableInflater;

/// `data` deflated by zlib: windowBits 15 (zlib) or 31 (gzip), the given level and strategy.
std::string deflate_with_zlib(const std::string& data, int window_bits, int level, int strategy)
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
    std::string packed = deflate_with_zlib("abc", 15, 6, Z_DEFAULT_STRATEGY);
    // set FDICT and fix the header check (CMF * 256 + FLG divisible by 31)
    const unsigned cmf = static_cast<unsigned char>(packed[0]);
    unsigned flg = (static_cast<unsigned char>(packed[1]) | 0x20u) & ~31u;
    flg += 31 - (cmf * 256 + flg) % 31;
    packed[1] = static_cast<char>(flg);
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

} // namespace
