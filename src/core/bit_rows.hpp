#pragma once
// The bit-row machinery of the passes (extract.cpp): a sample row's above-flags as 64-bit words,
// and from the flags of the four sample rows around a cell row its crossed edges, crossed cells
// and case codes, a word (64 samples) at a time. Vertex ids of crossed edges are kept per sample
// row (IdRows), found by edge ownership: each grid edge belongs to its lower sample.

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "classify.hpp"
#include "cube.hpp"
#include "portability.hpp"

namespace cmc33::detail {

constexpr std::int64_t kCornerOffset[8][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                                              {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};

/// For each cell edge: which of the four sample rows around a cell row owns it (bit 0: j + 1, bit
/// 1: k + 1, the index into the ids of those rows), and its slot there relative to 3 * i (3 * x
/// offset + axis).
constexpr std::array<std::uint8_t, 12> kEdgeRow = [] {
    std::array<std::uint8_t, 12> r{};
    for (int q = 0; q < 12; ++q) {
        const int c = kEdgeCorners[q][0];
        r[static_cast<std::size_t>(q)] = static_cast<std::uint8_t>(kCornerOffset[c][1] + 2 * kCornerOffset[c][2]);
    }
    return r;
}();
constexpr std::array<std::uint8_t, 12> kEdgeSlot = [] {
    std::array<std::uint8_t, 12> s{};
    for (int q = 0; q < 12; ++q) {
        s[static_cast<std::size_t>(q)] = static_cast<std::uint8_t>(3 * kCornerOffset[kEdgeCorners[q][0]][0] + q / 4);
    }
    return s;
}();

/// A row's above-flags as 64-bit words (classify.hpp), with one zero word after the last so that
/// "the flag of sample i + 1" can read one word past any sample's.
using Word = std::uint64_t;

/// The set bits of a word. std::popcount is a call into libgcc for generic x86-64 (no POPCNT
/// instruction without -mpopcnt); this is the same count in a dozen inline operations.
CMC33_ALWAYS_INLINE int popcount(Word x)
{
    x = x - ((x >> 1) & 0x5555555555555555u);
    x = (x & 0x3333333333333333u) + ((x >> 2) & 0x3333333333333333u);
    x = (x + (x >> 4)) & 0x0f0f0f0f0f0f0f0fu;
    return static_cast<int>((x * 0x0101010101010101u) >> 56);
}

/// Word w of the row shifted down by one sample: bit b is the flag of sample 64 w + b + 1.
CMC33_ALWAYS_INLINE Word next_sample(const Word* m, std::int64_t w) { return m[w] >> 1 | m[w + 1] << 63; }

/// The above-flags of sample rows, for three consecutive slices at once (slice k lives in buffer
/// k mod 3): a pass over cell rows (j, k) reads slices k..k+2 at most. Each row is classified once
/// per thread, with its signs (detail::RowSigns): on demand through get() (emit), or in order by
/// count() itself (plane_words()), which saves get()'s bookkeeping.
class SliceMasks {
public:
    SliceMasks(std::int64_t nx, std::int64_t ny)
        : words_((nx + 63) / 64), stride_(words_ + 1), ny_(ny), bits_(static_cast<std::size_t>(3 * ny * stride_), 0),
          slice_of_(static_cast<std::size_t>(3 * ny), -1),
          signs_(static_cast<std::size_t>(3 * ny), detail::RowSigns::below)
    {
    }
    /// The words of row (j, k); `fresh` when they must be computed (then also set `signs`).
    CMC33_ALWAYS_INLINE Word* get(std::int64_t j, std::int64_t k, bool& fresh, detail::RowSigns*& signs)
    {
        const auto row = static_cast<std::size_t>((k % 3) * ny_ + j);
        fresh = slice_of_[row] != k;
        slice_of_[row] = k;
        signs = &signs_[row];
        return &bits_[row * static_cast<std::size_t>(stride_)];
    }
    /// Slice k's words (row j's at j * stride()) and signs, without get()'s bookkeeping: for
    /// count(), which classifies the rows of its planes itself, each once and in order (a
    /// SliceMasks is used one way or the other).
    Word* plane_words(std::int64_t k) { return &bits_[static_cast<std::size_t>((k % 3) * ny_ * stride_)]; }
    detail::RowSigns* plane_signs(std::int64_t k) { return &signs_[static_cast<std::size_t>((k % 3) * ny_)]; }
    std::int64_t stride() const { return stride_; }

private:
    std::int64_t words_, stride_, ny_;
    std::vector<Word> bits_;
    std::vector<std::int64_t> slice_of_;
    std::vector<detail::RowSigns> signs_;
};

/// Vertex ids of the edges owned by four sample rows, one slot per parity of (j, k): a cell row
/// (j, k) reads rows j..j+1 of slices k..k+1, which never share a slot, and the next cell row
/// along j finds two of them already filled. Each slot also keeps where its row's interior
/// vertices start. Only the slots of crossed edges are written (and read).
class IdRows {
public:
    explicit IdRows(std::int64_t nx) : ids_(4 * 3 * static_cast<std::size_t>(nx)), len_(3 * static_cast<std::size_t>(nx)) {}
    /// Slot s's ids start at base() + s * row_length(); row (j, k) has slot (j & 1) | (k & 1) << 1.
    const std::uint32_t* base() const noexcept { return ids_.data(); }
    std::size_t row_length() const noexcept { return len_; }
    /// Row (j, k); `fresh` when its slot held another row and must be filled.
    std::uint32_t* get(std::int64_t j, std::int64_t k, bool& fresh, std::int64_t*& interior_start)
    {
        const auto slot = static_cast<std::size_t>((j & 1) | (k & 1) << 1);
        fresh = key_[slot][0] != j || key_[slot][1] != k;
        key_[slot] = {j, k};
        interior_start = &interior_start_[slot];
        return &ids_[slot * len_];
    }

private:
    std::vector<std::uint32_t> ids_;
    std::size_t len_;
    std::array<std::int64_t, 2> key_[4] = {{-1, -1}, {-1, -1}, {-1, -1}, {-1, -1}};
    std::int64_t interior_start_[4] = {};
};

/// The edges owned by the samples of one word of a sample row that cross: x (from the row's flags
/// f), y (against the row at j + 1, fy) and z (against the row at k + 1, fz). At the grid's last
/// row or slice pass f itself for fy or fz: those edges do not exist and never cross. `x_valid`
/// clears the x edge of the row's last sample, which does not exist either.
struct EdgeWords {
    Word x, y, z;
    CMC33_ALWAYS_INLINE EdgeWords(const Word* f, const Word* fy, const Word* fz, std::int64_t w, Word x_valid)
        : x((f[w] ^ next_sample(f, w)) & x_valid), y(f[w] ^ fy[w]), z(f[w] ^ fz[w])
    {
    }
    Word any() const { return x | y | z; }
};

/// The crossed cells of one word of a cell row, from the flags of its four sample rows a (j, k),
/// b (j + 1, k), c (j, k + 1), d (j + 1, k + 1): a cell is crossed unless its 8 corners agree.
CMC33_ALWAYS_INLINE Word crossed_cells(const Word* a, const Word* b, const Word* c, const Word* d, std::int64_t w,
                                       Word cell_valid)
{
    const Word any = a[w] | b[w] | c[w] | d[w], all = a[w] & b[w] & c[w] & d[w];
    const Word any_next = (any >> 1) | (a[w + 1] | b[w + 1] | c[w + 1] | d[w + 1]) << 63;
    const Word all_next = (all >> 1) | (a[w + 1] & b[w + 1] & c[w + 1] & d[w + 1]) << 63;
    return (any | any_next) & ~(all & all_next) & cell_valid;
}

/// The case codes (bit c: corner c above, corner order of cube.hpp) of the cells of word w of a
/// cell row, from the flags of its four sample rows a (j, k), b (j + 1, k), c (j, k + 1),
/// d (j + 1, k + 1). The words are read once, into registers (stores of counts in between could
/// alias them).
struct CellCodes {
    Word lo[4], hi[4];
    CMC33_ALWAYS_INLINE CellCodes(const Word* a, const Word* b, const Word* c, const Word* d, std::int64_t w)
        : lo{a[w], b[w], c[w], d[w]}, hi{a[w + 1], b[w + 1], c[w + 1], d[w + 1]}
    {
    }
    /// The code of the cell at bit s.
    CMC33_ALWAYS_INLINE unsigned operator()(int s) const
    {
        if (s < 63) { // both corners of a row in its word
            return static_cast<unsigned>((lo[0] >> s & 3u) | (lo[1] >> s & 3u) << 2 | (lo[2] >> s & 3u) << 4 |
                                         (lo[3] >> s & 3u) << 6);
        }
        return static_cast<unsigned>((lo[0] >> 63) | (hi[0] & 1u) << 1 | (lo[1] >> 63) << 2 | (hi[1] & 1u) << 3 |
                                     (lo[2] >> 63) << 4 | (hi[2] & 1u) << 5 | (lo[3] >> 63) << 6 | (hi[3] & 1u) << 7);
    }
};

/// Words of valid bits: sample bits (below nx) or cell and x edge bits (below nx - 1).
inline std::vector<Word> valid_words(std::int64_t words, std::int64_t bits)
{
    std::vector<Word> v(static_cast<std::size_t>(words), 0);
    for (std::int64_t w = 0; w < words; ++w) {
        const std::int64_t n = std::clamp<std::int64_t>(bits - 64 * w, 0, 64);
        v[static_cast<std::size_t>(w)] = n == 64 ? ~Word{0} : (Word{1} << n) - 1;
    }
    return v;
}

constexpr std::uint32_t kNoVertex = std::numeric_limits<std::uint32_t>::max();

} // namespace cmc33::detail
