// Pass 1 of the range extractor (range_extractor.hpp), count: per cell row the case code of each
// crossed cell from the rows' above-flags (rows whose samples are all on one side are skipped),
// the face and interior tests of the cells that have them (each decision kept as one byte for
// emit to replay), and the number of vertices (crossed edges owned by the row's samples, interior
// vertices) and triangles; a scan inside the range then gives every row its first ids.

#include <algorithm>
#include <bit>
#include <cstdint>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "range_extractor.hpp"
#include "sample_types.hpp"

namespace cmc33::detail {

template <class T>
bool RangeExtractor<T>::same_rows(const RangeCounts& c, const GridView<T>& g)
{
    const std::int64_t planes = std::min(c.t_.k1, g.nz() - 1) - c.t_.k0 + 1;
    return c.t_.nx == g.nx() && c.t_.ny == g.ny() && c.t_.rows.size() == static_cast<std::size_t>((c.t_.k1 - c.t_.k0) * g.ny()) &&
           (c.t_.k1 == g.nz() || c.t_.seam_first.size() == static_cast<std::size_t>(g.ny()) + 1) &&
           planes > 0;
}

template <class T>
RangeCounts RangeExtractor<T>::count(std::int64_t k0, std::int64_t k1, double largest_sample, Ticker* ticker) const
{
    RangeCounts c;
    c.t_.k0 = k0, c.t_.k1 = k1, c.t_.nx = nx_, c.t_.ny = ny_, c.t_.largest_sample = largest_sample;
    c.t_.iso = iso_, c.t_.method = method_;
    c.t_.rows.assign(static_cast<std::size_t>((k1 - k0) * ny_), {});
    Scratch s(nx_, ny_);
    // Each sample row is classified once, straight into its slice of s.masks: the rows of plane
    // k + 1 as cell row j reaches them (j + 1; row 0 before), those of the range's first plane
    // before it. Cell row (j, k) reads rows j, j + 1 of planes k, k + 1; a row past the grid
    // is (j, k) again, as in flags_around (no cell reads it then).
    const std::int64_t st = s.masks.stride();
    const auto classify_into = [&](std::int64_t j, std::int64_t k) {
        s.masks.plane_signs(k)[j] = classify(j, k, s.masks.plane_words(k) + j * st, s);
    };
    for (std::int64_t j = 0; j < ny_; ++j) classify_into(j, k0);
    for (std::int64_t k = k0; k < k1; ++k) {
        const bool top = k + 1 < nz_;
        if (top) classify_into(0, k + 1);
        const Word* const lower = s.masks.plane_words(k);
        const Word* const upper = top ? s.masks.plane_words(k + 1) : lower;
        const detail::RowSigns* const lower_signs = s.masks.plane_signs(k);
        const detail::RowSigns* const upper_signs = top ? s.masks.plane_signs(k + 1) : lower_signs;
        for (std::int64_t j = 0; j < ny_; ++j) {
            const bool next = j + 1 < ny_;
            if (top && next) classify_into(j + 1, k + 1);
            const std::int64_t j1 = next ? j + 1 : j;
            const bool corner = next && top; // (j + 1, k + 1) exists
            const Word* const rows[4] = {lower + j * st, lower + j1 * st, upper + j * st,
                                         corner ? upper + j1 * st : lower + j * st};
            const detail::RowSigns signs[4] = {lower_signs[j], lower_signs[j1], upper_signs[j],
                                               corner ? upper_signs[j1] : lower_signs[j]};
            count_row(j, k, s, c, rows, signs);
        }
        if (ticker && !ticker->tick()) return c;
    }
    if (k1 < nz_) {
        // plane k1 is the next range's: its rows' x/y edge vertices come first there
        c.t_.seam_first.assign(static_cast<std::size_t>(ny_) + 1, 0);
        const Word* const seam = s.masks.plane_words(k1); // classified with plane k1 - 1
        for (std::int64_t j = 0; j < ny_; ++j) {
            const Word* f = seam + j * st;
            const Word* fy = j + 1 < ny_ ? f + st : f;
            std::uint32_t xy = 0;
            for (std::int64_t w = 0; w < words_; ++w) {
                const EdgeWords e(f, fy, f, w, x_valid_[static_cast<std::size_t>(w)]);
                xy += static_cast<std::uint32_t>(popcount(e.x) + popcount(e.y));
            }
            c.t_.seam_first[static_cast<std::size_t>(j) + 1] = c.t_.seam_first[static_cast<std::size_t>(j)] + xy;
        }
    }
    // every sample of planes k0..k1 has been classified, which also looked for non-finite ones
    if (s.scan.non_finite) scan_samples(g_, k0, std::min(k1, nz_ - 1)); // throws, naming the first
    // (for integer types, the type's bound: scan_samples reads nothing then)
    c.t_.largest_sample = std::max(largest_sample, std::is_floating_point_v<T> ? s.scan.largest : scan_samples(g_, k0, k0));
    // the rows hold their counts; turn them into first ids (the numbering of passes.hpp)
    std::int64_t v = 0, t = 0;
    const auto first_id = [&v, k0, k1](std::uint32_t& count) {
        if (v >= static_cast<std::int64_t>(kNoVertex)) {
            throw Error(Status::too_large, "sample planes " + std::to_string(k0) + " to " + std::to_string(k1) +
                                               " would have more vertices than 32-bit indices can address");
        }
        v += std::exchange(count, static_cast<std::uint32_t>(v));
    };
    for (std::int64_t k = k0; k < k1; ++k) {
        RangeTable::Row* plane = &c.t_.rows[static_cast<std::size_t>((k - k0) * ny_)];
        for (std::int64_t j = 0; j < ny_; ++j) first_id(plane[j].xy_first);
        for (std::int64_t j = 0; j < ny_; ++j) first_id(plane[j].z_first);
        for (std::int64_t j = 0; j < ny_; ++j) t += std::exchange(plane[j].triangle_first, t);
    }
    c.t_.vertices = v, c.t_.triangles = t;
    return c;
}

template <class T>
const detail::Tiling& RangeExtractor<T>::decide_cell(std::int64_t i, std::int64_t j, std::int64_t k, unsigned code, int& subcase,
                                  std::uint8_t& decision) const
{
    double raw[8];
    for (int c = 0; c < 8; ++c) {
        raw[c] = static_cast<double>(at(i + kCornerOffset[c][0], j + kCornerOffset[c][1], k + kCornerOffset[c][2]));
    }
    const detail::Decision d = detail::decide(raw, iso_, code, method_, variants_);
    subcase = d.subcase;
    decision = static_cast<std::uint8_t>(d.joined << 2 | static_cast<unsigned>(d.tiling));
    return d.variant->tilings[d.tiling];
}

template <class T>
CMC33_ALWAYS_INLINE void RangeExtractor<T>::count_row(std::int64_t j, std::int64_t k, Scratch& s, RangeCounts& c,
                                   const Word* const (&rows)[4], const detail::RowSigns (&signs)[4]) const
{
    // Trim: when the sample rows this row's edges and cells reach are all above or all below,
    // nothing crosses (most rows of a CT volume).
    const Word *f = rows[0], *fy = rows[1], *fz = rows[2], *fyz = rows[3];
    const bool cells = j + 1 < ny_ && k + 1 < nz_;
    if constexpr (std::is_floating_point_v<T>) {
        if (s.scan.non_finite) {
            // before any cell of these rows is decided (a NaN has no sign): name the first one
            scan_samples(g_, c.t_.k0, std::min(c.t_.k1, nz_ - 1));
        }
    }
    const detail::RowSigns first = signs[0]; // all four rows all above or all below: the counts stay 0
    if (first != detail::RowSigns::mixed && signs[1] == first && signs[2] == first && signs[3] == first) return;
    RangeTable::Row& row = c.t_.rows[static_cast<std::size_t>(j + (k - c.t_.k0) * ny_)];
    std::uint32_t xy = 0, z = 0;
    std::int64_t interior = 0, triangles = 0;
    std::int64_t lo = nx_, hi = 0;
    for (std::int64_t w = 0; w < words_; ++w) {
        const Word x_valid = x_valid_[static_cast<std::size_t>(w)];
        const EdgeWords edges(f, fy, fz, w, x_valid);
        const Word crossed = cells ? crossed_cells(f, fy, fz, fyz, w, x_valid) : 0;
        const Word used = edges.any() | crossed; // samples whose edges or cells cross
        if (used == 0) continue;
        lo = std::min<std::int64_t>(lo, 64 * w + std::countr_zero(used));
        hi = 64 * w + 64 - std::countl_zero(used);
        xy += static_cast<std::uint32_t>(popcount(edges.x) + popcount(edges.y));
        z += static_cast<std::uint32_t>(popcount(edges.z));
        const CellCodes codes(f, fy, fz, fyz, w);
        for (Word bits = crossed; bits != 0; bits &= bits - 1) {
            const int b = std::countr_zero(bits);
            const unsigned code = codes(b);
            int subcase = fixed_subcase_[code];
            const detail::Tiling* tl = fixed_tiling_[code];
            if (tl == nullptr) {
                std::uint8_t decision = 0;
                tl = &decide_cell(64 * w + b, j, k, code, subcase, decision);
                c.t_.decisions.push_back(decision);
            }
            interior += tl->interior_count;
            triangles += tl->triangle_count;
            ++c.t_.stats.cells_per_subcase[static_cast<std::size_t>(subcase)];
        }
    }
    if (hi > lo) row.lo = static_cast<std::int32_t>(lo), row.hi = static_cast<std::int32_t>(hi);
    row.xy_first = xy;
    row.z_first = static_cast<std::uint32_t>(z + interior); // < 16 nx < 2^32 (check_grid)
    row.triangle_first = triangles;
}

#define CMC33_INSTANTIATE(T) \
    template RangeCounts RangeExtractor<T>::count(std::int64_t, std::int64_t, double, Ticker*) const; \
    template bool RangeExtractor<T>::same_rows(const RangeCounts&, const GridView<T>&);
CMC33_FOR_EACH_SAMPLE_TYPE(CMC33_INSTANTIATE)
#undef CMC33_INSTANTIATE

} // namespace cmc33::detail
