#pragma once
// MeshSpans::vertex_cell_ranges (scikit-image's `values` of marching_cubes), a per-vertex
// attribute that emit (emit.cpp) computes through a hook rather than code of its own: per
// vertex, the largest range of samples (largest minus smallest of a cell's 8) among the cells
// whose triangles use it. emit calls the hook once per cell row before its vertices
// (cell_row), once per sample row before that row's edge vertices (sample_row), and per vertex
// (edge_vertex, interior_vertex). Each crossed cell's range is computed once, into rows of two
// cell planes, and shared by the vertices around it: no scatter over triangles afterwards.

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <vector>

#include "bit_rows.hpp"
#include "cmc33/mesh.hpp"
#include "cmc33/volume.hpp"
#include "portability.hpp"

namespace cmc33::detail {

template <class T> class VertexCellRanges {
public:
    /// The attribute of a range of emit whose first sample plane is k0, written to out[v] for
    /// the range's vertex v (0 = its first). `x_valid`: the grid's valid bits per word of a row
    /// (valid_words()), kept by the caller for as long as this lives.
    VertexCellRanges(const GridView<T>& g, std::int64_t k0, const std::vector<Word>& x_valid, float* out)
        : g_(g), nx_(g.nx()), ny_(g.ny()), nz_(g.nz()), sx_(g.strides[0]), k0_(k0), x_valid_(x_valid), out_(out),
          len_(static_cast<std::size_t>(nx_) + 1)
    {
        // a row of nx + 1 floats per cell row of two planes, cell i at i + 1; entry 0 (cell -1)
        // and entry nx (cell nx - 1) are 0 and never written, and one last row of zeros stands
        // for the cells outside the grid or below the range. The other entries are not
        // initialized: only crossed cells are read, all of them written first (a crossed edge's
        // cells are all crossed); a plane's row holds the plane two before until then.
        ranges_.resize((2 * static_cast<std::size_t>(ny_) + 1) * len_);
#ifndef NDEBUG
        // debug builds (the sanitizers' in CI) poison the rest: a cell read before it is written
        // would win every max, and the tests compare the values with their own
        std::fill(ranges_.begin(), ranges_.end(), std::numeric_limits<float>::infinity());
#endif
        for (std::size_t r = 0; r < 2 * static_cast<std::size_t>(ny_); ++r) ranges_[r * len_] = ranges_[r * len_ + len_ - 1] = 0;
        std::fill(ranges_.end() - static_cast<std::ptrdiff_t>(len_), ranges_.end(), 0.0f);
    }

    /// The ranges of the crossed cells of cell row (j, k) (f: the flags of sample rows (j, k),
    /// (j + 1, k), (j, k + 1), (j + 1, k + 1); [lo, hi) the row's trim range). Where x is the
    /// array's contiguous axis, 8 cells at a time from the first crossed cell not yet done, in a
    /// loop the compiler vectorizes (a group may reach into the next word's cells, which that
    /// word computes again); else, and for the row's last cells, cell by cell. Unaligned groups
    /// of 8 measured best (docs/performance.md, "Python").
    void cell_row(std::int64_t j, std::int64_t k, const Word* const (&f)[4], std::int64_t lo, std::int64_t hi)
    {
        // the narrowest type whose difference, rounded to float, is cell_range()'s: float for
        // float (rounding through double first is innocuous: 53 >= 2 * 24 + 2 bits), int for 8-
        // and 16-bit samples; these vectorize, Exact's int64 would not
        using Difference = std::conditional_t<std::is_same_v<T, float>, float,
                                              std::conditional_t<(sizeof(T) <= 2), int, Exact>>;
        float* ranges = row(j, k) + 1;
        const T* a = g_.data + g_.offset(0, j, k);
        const T* b = a + g_.strides[1];
        const T* c = a + g_.strides[2];
        const T* d = b + g_.strides[2];
        for (std::int64_t w = lo / 64; w < (hi + 63) / 64; ++w) {
            Word bits = crossed_cells(f[0], f[1], f[2], f[3], w, x_valid_[static_cast<std::size_t>(w)]);
            if (sx_ == 1) {
                while (bits != 0) {
                    const int first = std::countr_zero(bits);
                    const std::int64_t i = 64 * w + first;
                    if (i + 8 >= nx_) break; // the last cells read past the row: one by one
                    // cell_range()'s tree spelled out on the four rows: through a shared helper
                    // the loop stops vectorizing
                    for (std::int64_t q = i; q < i + 8; ++q) {
                        const T low = std::min(std::min(std::min(a[q], a[q + 1]), std::min(b[q], b[q + 1])),
                                               std::min(std::min(c[q], c[q + 1]), std::min(d[q], d[q + 1])));
                        const T high = std::max(std::max(std::max(a[q], a[q + 1]), std::max(b[q], b[q + 1])),
                                                std::max(std::max(c[q], c[q + 1]), std::max(d[q], d[q + 1])));
                        ranges[q] = static_cast<float>(static_cast<Difference>(high) - static_cast<Difference>(low));
                    }
                    bits &= ~(Word{0xff} << first);
                }
            }
            for (; bits != 0; bits &= bits - 1) {
                const std::int64_t i = 64 * w + std::countr_zero(bits);
                ranges[i] = static_cast<float>(cell_range(a + i * sx_));
            }
        }
    }

    /// Before the edge vertices of sample row (j, k): the cell rows around it, (j - 1 .. j,
    /// k - 1 .. k). On the range's first plane (not the grid's) the cells below are the previous
    /// range's, so its x and y edge vertices take edge_range() instead.
    void sample_row(std::int64_t j, std::int64_t k)
    {
        const auto cell_row = [&](std::int64_t cj, std::int64_t ck) -> const float* {
            const bool exists = cj >= 0 && cj + 1 < ny_ && ck >= k0_ && ck + 1 < nz_;
            return exists ? row(cj, ck) : zero();
        };
        below_[0] = cell_row(j - 1, k - 1), below_[1] = cell_row(j, k - 1);
        here_[0] = cell_row(j - 1, k), here_[1] = cell_row(j, k);
        first_plane_ = k == k0_ && k > 0;
    }

    /// Vertex v, on the edge from sample (i, j, k) along `axis` of the row sample_row() named:
    /// the largest range of the cells around the edge, (i, j - 1 .. j, k - 1 .. k) for x,
    /// (i - 1 .. i, j, k - 1 .. k) for y, (i - 1 .. i, j - 1 .. j, k) for z.
    template <int axis>
    CMC33_ALWAYS_INLINE void edge_vertex(std::size_t v, std::int64_t i, std::int64_t j, std::int64_t k) const
    {
        if (axis != 2 && first_plane_) {
            out_[v] = edge_range(i, j, k, axis);
            return;
        }
        const auto c = static_cast<std::size_t>(i); // cell i - 1 at c, cell i at c + 1
        if constexpr (axis == 0) {
            out_[v] = std::max(std::max(below_[0][c + 1], below_[1][c + 1]), std::max(here_[0][c + 1], here_[1][c + 1]));
        } else if constexpr (axis == 1) {
            out_[v] = std::max(std::max(below_[1][c], below_[1][c + 1]), std::max(here_[1][c], here_[1][c + 1]));
        } else {
            out_[v] = std::max(std::max(here_[0][c], here_[0][c + 1]), std::max(here_[1][c], here_[1][c + 1]));
        }
    }

    /// Vertex v, inside cell (i, j, k): that cell's range.
    void interior_vertex(std::size_t v, std::int64_t i, std::int64_t j, std::int64_t k) const
    {
        out_[v] = static_cast<float>(cell_range(g_.data + g_.offset(i, j, k)));
    }

private:
    /// Samples widened so that differences of two are exact: int64 for integer types, double else.
    using Exact = std::conditional_t<std::is_integral_v<T>, std::int64_t, double>;

    float* row(std::int64_t j, std::int64_t k) noexcept
    {
        return &ranges_[(static_cast<std::size_t>(k & 1) * static_cast<std::size_t>(ny_) + static_cast<std::size_t>(j)) * len_];
    }
    const float* zero() const noexcept { return &ranges_[2 * static_cast<std::size_t>(ny_) * len_]; }

    /// Largest minus smallest of the 8 samples of the cell whose lowest corner sample is at p:
    /// pairs, then a tree, no branch.
    CMC33_ALWAYS_INLINE Exact cell_range(const T* p) const
    {
        const std::int64_t sy = g_.strides[1], sz = g_.strides[2];
        const T a0 = p[0], a1 = p[sx_], a2 = p[sy], a3 = p[sx_ + sy];
        const T a4 = p[sz], a5 = p[sx_ + sz], a6 = p[sy + sz], a7 = p[sx_ + sy + sz];
        const T lo = std::min(std::min(std::min(a0, a1), std::min(a2, a3)), std::min(std::min(a4, a5), std::min(a6, a7)));
        const T hi = std::max(std::max(std::max(a0, a1), std::max(a2, a3)), std::max(std::max(a4, a5), std::max(a6, a7)));
        return static_cast<Exact>(hi) - static_cast<Exact>(lo);
    }

    /// The largest cell_range() of the (up to four) cells around the edge from sample (i, j, k)
    /// along `axis`, from the samples (the cells of the range's first plane below it are not in
    /// the rows).
    float edge_range(std::int64_t i, std::int64_t j, std::int64_t k, int axis) const
    {
        const std::int64_t idx[3] = {i, j, k}, n[3] = {nx_, ny_, nz_};
        const auto b = static_cast<std::size_t>((axis + 1) % 3), c = static_cast<std::size_t>((axis + 2) % 3);
        Exact largest = 0;
        if (idx[b] >= 1 && idx[b] + 1 < n[b] && idx[c] >= 1 && idx[c] + 1 < n[c]) {
            // all four cells: the smallest and largest of the edge's 3 x 3 lines of two samples
            // along `axis`, then each cell's 2 x 2 of those (selects, no branches)
            const T* p = g_.data + g_.offset(i, j, k);
            const std::int64_t sa = g_.strides[static_cast<std::size_t>(axis)], sb = g_.strides[b], sc = g_.strides[c];
            T lo[3][3], hi[3][3];
            for (std::int64_t u = 0; u < 3; ++u)
                for (std::int64_t w = 0; w < 3; ++w) {
                    const T* q = p + (u - 1) * sb + (w - 1) * sc;
                    const T x = q[0], y = q[sa];
                    lo[u][w] = x < y ? x : y;
                    hi[u][w] = x < y ? y : x;
                }
            for (int u = 0; u < 2; ++u)
                for (int w = 0; w < 2; ++w) {
                    const T l = std::min(std::min(lo[u][w], lo[u + 1][w]), std::min(lo[u][w + 1], lo[u + 1][w + 1]));
                    const T h = std::max(std::max(hi[u][w], hi[u + 1][w]), std::max(hi[u][w + 1], hi[u + 1][w + 1]));
                    const Exact range = static_cast<Exact>(h) - static_cast<Exact>(l);
                    largest = range > largest ? range : largest;
                }
            return static_cast<float>(largest);
        }
        for (std::int64_t u = -1; u <= 0; ++u)
            for (std::int64_t w = -1; w <= 0; ++w) {
                std::int64_t cell[3] = {i, j, k};
                cell[b] += u;
                cell[c] += w;
                if (cell[b] < 0 || cell[b] + 1 >= n[b] || cell[c] < 0 || cell[c] + 1 >= n[c]) continue;
                largest = std::max(largest, cell_range(g_.data + g_.offset(cell[0], cell[1], cell[2])));
            }
        return static_cast<float>(largest);
    }

    const GridView<T>& g_;
    std::int64_t nx_, ny_, nz_, sx_, k0_;
    const std::vector<Word>& x_valid_;
    float* out_;
    std::size_t len_;
    Buffer<float> ranges_; // not zeroed: see the constructor
    const float* below_[2] = {nullptr, nullptr};
    const float* here_[2] = {nullptr, nullptr};
    bool first_plane_ = false;
};

} // namespace cmc33::detail
