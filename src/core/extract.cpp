// extract(): Marching Cubes 33 in passes (design.md, after VTK's Flying Edges):
//   1. classify + decide + count: per row of cells, the case code of each cell from the rows'
//      above-flags (rows whose samples are all on one side are skipped), the face and interior
//      tests of the cells that have them, and the number of vertices (crossed edges owned by the
//      row's samples, interior vertices) and triangles;
//   2. scan: prefix sums give every row its first vertex and first triangle;
//   3. emit vertices: each crossed grid edge is owned by its lower sample and gets one vertex;
//   4. emit triangles: every cell writes its tiling's triangles and interior vertices at its row's
//      offsets, finding edge vertices by edge ownership (no hash map, no locks). Tested cells are
//      decided again rather than stored: working memory is O(rows + threads * nx), not O(cells).
// Rows are processed in parallel by z-slab; all writes land at offsets fixed by pass 2, so the mesh
// is the same, byte for byte, for every thread count.
//
// World coordinates (volume.hpp): x = origin + M * (i, j, k) with M = D * diag(spacing). A diagonal
// M (the usual axis-aligned frame, flips included) takes the per-axis multiply of old; only an
// oblique or permuted frame pays for the full product. Normals map the index-space gradient by
// M^-T; a mirroring frame (det M < 0) reverses every triangle so that the winding rule of
// docs/conventions.md holds in world space.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "core/cube.hpp"
#include "core/decide.hpp"
#include "core/parallel.hpp"
#include "core/placement.hpp"
#include "tables/mc33_tables.hpp"

namespace cmc33 {
namespace {

using detail::kEdgeCorners;

/// The sign rule for samples of type T: v >= iso. Integer samples are compared in their own type
/// against ceil(iso) (exact, and cheap in the hot loop); floating-point samples in double.
template <class T> class Above {
public:
    explicit Above(double iso) : iso_(iso)
    {
        if constexpr (std::is_integral_v<T>) {
            const double t = std::ceil(iso);
            if (t <= static_cast<double>(std::numeric_limits<T>::lowest())) {
                mode_ = Mode::all;
            } else if (t > static_cast<double>(std::numeric_limits<T>::max())) {
                mode_ = Mode::none;
            } else {
                threshold_ = static_cast<T>(t);
            }
        }
    }
    /// flags[i] = 1 if row[i] is above, else 0.
    void row(const T* row, std::int64_t n, std::uint8_t* flags) const
    {
        if constexpr (std::is_integral_v<T>) {
            if (mode_ != Mode::compare) {
                std::memset(flags, mode_ == Mode::all ? 1 : 0, static_cast<std::size_t>(n));
                return;
            }
            const T t = threshold_;
            for (std::int64_t i = 0; i < n; ++i) flags[i] = static_cast<std::uint8_t>(row[i] >= t);
        } else {
            const double iso = iso_;
            for (std::int64_t i = 0; i < n; ++i) flags[i] = static_cast<std::uint8_t>(static_cast<double>(row[i]) >= iso);
        }
    }

private:
    enum class Mode { compare, all, none };
    double iso_;
    Mode mode_ = Mode::compare;
    T threshold_{};
};

constexpr std::int64_t kCornerOffset[8][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                                              {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};

/// A column code holds the above-flags of the four samples (i, j, k), (i, j+1, k), (i, j, k+1),
/// (i, j+1, k+1) in bits 0..3. Two neighbouring columns make a cell:
/// kCellCode[col(i) | col(i+1) << 4] is the cell's case code (bit c: corner c above).
constexpr std::array<std::uint8_t, 256> kCellCode = [] {
    std::array<std::uint8_t, 256> table{};
    for (unsigned pair = 0; pair < 256; ++pair) {
        unsigned code = 0;
        for (unsigned c = 0; c < 8; ++c) code |= ((pair >> (4 * (c & 1u) + (c >> 1))) & 1u) << c;
        table[pair] = static_cast<std::uint8_t>(code);
    }
    return table;
}();

/// Above-flags of sample rows, filled row by row on demand, for three consecutive slices at once
/// (slice k lives in buffer k mod 3): a pass over cell rows (j, k) reads slices k..k+2 at most.
/// Each row is computed once per thread; `count` holds its number of samples above.
class SliceFlags {
public:
    SliceFlags(std::int64_t nx, std::int64_t ny)
        : nx_(nx), ny_(ny), flags_(static_cast<std::size_t>(3 * nx * ny)),
          slice_of_(static_cast<std::size_t>(3 * ny), -1), count_(static_cast<std::size_t>(3 * ny), 0)
    {
    }
    /// The flags of row (j, k); `fresh` when they must be computed (then also set `count`).
    std::uint8_t* get(std::int64_t j, std::int64_t k, bool& fresh, std::int64_t*& count)
    {
        const auto row = static_cast<std::size_t>((k % 3) * ny_ + j);
        fresh = slice_of_[row] != k;
        slice_of_[row] = k;
        count = &count_[row];
        return &flags_[row * static_cast<std::size_t>(nx_)];
    }

private:
    std::int64_t nx_, ny_;
    std::vector<std::uint8_t> flags_;
    std::vector<std::int64_t> slice_of_;
    std::vector<std::int64_t> count_;
};

/// Vertex ids of the edges owned by four sample rows, one slot per parity of (j, k): a cell row
/// (j, k) reads rows j..j+1 of slices k..k+1, which never share a slot, and the next cell row
/// along j finds two of them already filled. Each slot also keeps where its row's interior
/// vertices start.
class IdRows {
public:
    explicit IdRows(std::int64_t nx) : ids_(4 * 3 * static_cast<std::size_t>(nx)), len_(3 * static_cast<std::size_t>(nx)) {}
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

/// Bits 0..2: which of the x, y, z edges owned by sample i of a row cross, from the above-flags of
/// the row (f), of the row at j + 1 (fy) and of the row at k + 1 (fz). At the grid's last row or
/// slice pass f itself for fy or fz: those edges do not exist and never cross.
inline unsigned crossed_edges(const std::uint8_t* f, const std::uint8_t* fy, const std::uint8_t* fz, std::int64_t i,
                              std::int64_t nx)
{
    return static_cast<unsigned>(i + 1 < nx && f[i] != f[i + 1]) | static_cast<unsigned>(f[i] != fy[i]) << 1 |
           static_cast<unsigned>(f[i] != fz[i]) << 2;
}

constexpr std::uint32_t kNoVertex = std::numeric_limits<std::uint32_t>::max();

/// The largest |world coordinate| over the 8 corners of the grid's box (every vertex lies in it).
template <class T> double largest_coordinate(const GridView<T>& g)
{
    const Mat3 m = frame_matrix(g.spacing, g.direction);
    double largest = 0;
    for (int corner = 0; corner < 8; ++corner) {
        double x[3];
        for (std::size_t a = 0; a < 3; ++a) x[a] = (corner >> a) & 1 ? static_cast<double>(g.dims[a] - 1) : 0.0;
        for (std::size_t r = 0; r < 3; ++r) {
            const double w = g.origin[r] + (m[r][0] * x[0] + m[r][1] * x[1] + m[r][2] * x[2]);
            largest = std::max(largest, std::fabs(w));
        }
    }
    return largest;
}

template <class T> class Extractor {
public:
    Extractor(const GridView<T>& g, double iso, const ExtractOptions& opt, double largest_sample)
        : g_(g), iso_(iso), above_(iso), opt_(opt), nx_(g.nx()), ny_(g.ny()), nz_(g.nz()),
          threads_(detail::resolve_threads(opt.threads)), m_(frame_matrix(g.spacing, g.direction)),
          diagonal_(is_diagonal(m_)), mirrored_(determinant(m_) < 0), delta_(min_crossing(g, m_))
    {
        for (std::size_t a = 0; a < 3; ++a) step_[a] = diagonal_ ? m_[a][a] : 1.0;
        if (!diagonal_) normal_map_ = inverse_transpose(m_);
        gradient_scale_ = gradient_scale(largest_sample);
        for (unsigned code = 0; code < 256; ++code) {
            const detail::Variant& first = detail::kVariants[detail::kVariantOffset[code]];
            needs_values_[code] = opt.method != Method::mc &&
                                  (detail::kAmbiguousFaces[code] != 0 || first.test != detail::kTestNone);
        }
    }

    Mesh run(ExtractStats* stats)
    {
        const std::int64_t rows = ny_ * nz_;
        row_vertices_.assign(static_cast<std::size_t>(rows) + 1, 0);
        row_triangles_.assign(static_cast<std::size_t>(rows) + 1, 0);
        range_.assign(static_cast<std::size_t>(rows), {0, 0});
        std::vector<ExtractStats> per_thread(static_cast<std::size_t>(threads_));

        // Pass 1: classify, decide, count.
        detail::parallel_chunks(nz_, threads_, [&](int t, std::int64_t k0, std::int64_t k1) {
            Scratch scratch(nx_, ny_);
            for (std::int64_t k = k0; k < k1; ++k)
                for (std::int64_t j = 0; j < ny_; ++j) count_row(j, k, scratch, per_thread[static_cast<std::size_t>(t)]);
        });
        if (stats) {
            *stats = {};
            for (const auto& s : per_thread)
                for (std::size_t i = 0; i < static_cast<std::size_t>(kSubcaseCount); ++i) {
                    stats->cells_per_subcase[i] += s.cells_per_subcase[i];
                }
        }

        // Pass 2: exclusive scan (row r's counts are stored at r + 1).
        for (std::int64_t r = 0; r < rows; ++r) {
            row_vertices_[static_cast<std::size_t>(r) + 1] += row_vertices_[static_cast<std::size_t>(r)];
            row_triangles_[static_cast<std::size_t>(r) + 1] += row_triangles_[static_cast<std::size_t>(r)];
        }
        const std::int64_t nv = row_vertices_.back(), nt = row_triangles_.back();
        if (nv >= static_cast<std::int64_t>(kNoVertex)) {
            throw Error(Status::too_large, "the mesh would have " + std::to_string(nv) +
                                               " vertices, more than 32-bit indices can address");
        }
        Mesh mesh;
        mesh.positions.resize(static_cast<std::size_t>(nv) * 3);
        if (opt_.normals) mesh.normals.resize(static_cast<std::size_t>(nv) * 3);
        mesh.triangles.resize(static_cast<std::size_t>(nt) * 3);

        // Passes 3 and 4: emit.
        detail::parallel_chunks(nz_, threads_, [&](int, std::int64_t k0, std::int64_t k1) {
            Scratch scratch(nx_, ny_);
            for (std::int64_t k = k0; k < k1; ++k)
                for (std::int64_t j = 0; j < ny_; ++j) {
                    const auto r = static_cast<std::size_t>(row_index(j, k));
                    std::int64_t interior_start = row_vertices_[r];
                    if (row_vertices_[r + 1] != row_vertices_[r]) {
                        emit_row_vertices(j, k, row_ids(j, k, scratch, interior_start), mesh);
                    }
                    if (j + 1 < ny_ && k + 1 < nz_ && row_triangles_[r + 1] != row_triangles_[r]) {
                        emit_row_cells(j, k, scratch, interior_start, mesh);
                    }
                }
        });
        return mesh;
    }

private:
    /// One thread's working memory: above-flags of three slices, vertex ids of four sample rows,
    /// and the column codes of the current cell row. O(nx * ny) bytes.
    struct Scratch {
        Scratch(std::int64_t nx, std::int64_t ny) : flags(nx, ny), ids(nx), columns(static_cast<std::size_t>(nx)) {}
        SliceFlags flags;
        IdRows ids;
        std::vector<std::uint8_t> columns;
    };

    T at(std::int64_t i, std::int64_t j, std::int64_t k) const { return g_.data[g_.offset(i, j, k)]; }
    std::int64_t row_index(std::int64_t j, std::int64_t k) const { return j + k * ny_; }

    /// Above-flags of the samples of row (j, k); `above` counts the samples above.
    const std::uint8_t* flags(std::int64_t j, std::int64_t k, Scratch& s, std::int64_t& above) const
    {
        bool fresh = false;
        std::int64_t* count = nullptr;
        std::uint8_t* f = s.flags.get(j, k, fresh, count);
        if (fresh) {
            above_.row(g_.data + g_.offset(0, j, k), nx_, f);
            std::uint32_t n = 0; // nx < 2^31 (validate); a narrow sum vectorises
            for (std::int64_t i = 0; i < nx_; ++i) n += f[i];
            *count = n;
        }
        above = *count;
        return f;
    }
    const std::uint8_t* flags(std::int64_t j, std::int64_t k, Scratch& s) const
    {
        std::int64_t unused = 0;
        return flags(j, k, s, unused);
    }

    /// Column codes of cell row (j, k) into s.columns (see kCellCode).
    void column_codes(std::int64_t j, std::int64_t k, Scratch& s) const
    {
        const std::uint8_t* __restrict f00 = flags(j, k, s);
        const std::uint8_t* __restrict f10 = flags(j + 1, k, s);
        const std::uint8_t* __restrict f01 = flags(j, k + 1, s);
        const std::uint8_t* __restrict f11 = flags(j + 1, k + 1, s);
        std::uint8_t* __restrict col = s.columns.data();
        const std::int64_t n = nx_; // a local bound: byte stores may alias members, which blocks vectorising
        for (std::int64_t i = 0; i < n; ++i) {
            col[i] = static_cast<std::uint8_t>(f00[i] | f10[i] << 1 | f01[i] << 2 | f11[i] << 3);
        }
    }

    /// Vertex ids of the edges owned by the samples of row (j, k): ids[3 * i + axis], kNoVertex
    /// where the edge does not cross or does not exist. `interior_start`: the id after the row's
    /// last edge vertex, where the interior vertices of its cells begin.
    const std::uint32_t* row_ids(std::int64_t j, std::int64_t k, Scratch& s, std::int64_t& interior_start) const
    {
        bool fresh = false;
        std::int64_t* end = nullptr;
        std::uint32_t* ids = s.ids.get(j, k, fresh, end);
        const std::size_t r = static_cast<std::size_t>(row_index(j, k));
        if (fresh && row_vertices_[r + 1] == row_vertices_[r]) {
            // no crossed edge (and no interior vertex): no cell will read these ids
            *end = row_vertices_[r];
        } else if (fresh) {
            const std::uint8_t* f = flags(j, k, s);
            const std::uint8_t* fy = j + 1 < ny_ ? flags(j + 1, k, s) : f;
            const std::uint8_t* fz = k + 1 < nz_ ? flags(j, k + 1, s) : f;
            auto id = static_cast<std::uint32_t>(row_vertices_[r]);
            // outside the range no edge crosses: those slots are never read for a vertex
            for (std::int64_t i = range_[r][0]; i < range_[r][1]; ++i) {
                const unsigned crossed = crossed_edges(f, fy, fz, i, nx_);
                for (std::int64_t axis = 0; axis < 3; ++axis) {
                    const bool c = (crossed >> axis) & 1u;
                    ids[3 * i + axis] = c ? id : kNoVertex;
                    id += c;
                }
            }
            *end = id;
        }
        interior_start = *end;
        return ids;
    }

    /// The tiling of crossed cell (i, j, k) with case code `code`, and its subcase. Cells with a
    /// face or interior test are decided here, in pass 1 and again in pass 4 (the same exact
    /// predicates on the same values, so the same answer): that costs less than storing a
    /// decision per cell, and leaves no per-cell working memory.
    const detail::Tiling& tiling_of(std::int64_t i, std::int64_t j, std::int64_t k, unsigned code, int& subcase) const
    {
        const detail::Variant& first = detail::kVariants[detail::kVariantOffset[code]];
        if (!needs_values_[code]) {
            subcase = first.subcase;
            return first.tilings[0];
        }
        double raw[8];
        for (int c = 0; c < 8; ++c) {
            raw[c] = static_cast<double>(at(i + kCornerOffset[c][0], j + kCornerOffset[c][1], k + kCornerOffset[c][2]));
        }
        const detail::Decision d = detail::decide(raw, iso_, code, opt_.method, nullptr, std::is_integral_v<T>);
        subcase = d.subcase;
        return d.variant->tilings[d.tiling];
    }

    void count_row(std::int64_t j, std::int64_t k, Scratch& s, ExtractStats& stats)
    {
        // Trim: when the sample rows this row's edges and cells reach are all above or all below,
        // nothing crosses (most rows of a CT volume).
        std::int64_t n0 = 0, n1 = 0, n2 = 0, n3 = 0;
        const std::uint8_t* f = flags(j, k, s, n0);
        n1 = n2 = n3 = n0;
        const std::uint8_t* fy = j + 1 < ny_ ? flags(j + 1, k, s, n1) : f;
        const std::uint8_t* fz = k + 1 < nz_ ? flags(j, k + 1, s, n2) : f;
        if (j + 1 < ny_ && k + 1 < nz_) flags(j + 1, k + 1, s, n3);
        if ((n0 == 0 || n0 == nx_) && n1 == n0 && n2 == n0 && n3 == n0) return; // counts stay 0
        const auto r = static_cast<std::size_t>(row_index(j, k));
        // crossed edges owned by the row: flags are 0 or 1, so != is ^ and the sum vectorises
        std::uint32_t crossed = 0;
        for (std::int64_t i = 0; i + 1 < nx_; ++i) crossed += static_cast<std::uint32_t>(f[i] ^ f[i + 1]);
        for (std::int64_t i = 0; i < nx_; ++i) crossed += static_cast<std::uint32_t>((f[i] ^ fy[i]) + (f[i] ^ fz[i]));
        std::int64_t vertices = crossed, triangles = 0;
        std::int64_t lo = nx_, hi = 0;
        if (crossed != 0) {
            lo = 0;
            while (crossed_edges(f, fy, fz, lo, nx_) == 0) ++lo;
            hi = nx_;
            while (crossed_edges(f, fy, fz, hi - 1, nx_) == 0) --hi;
        }
        if (j + 1 < ny_ && k + 1 < nz_) {
            column_codes(j, k, s);
            const std::uint8_t* col = s.columns.data();
            for (std::int64_t i = 0; i + 1 < nx_; ++i) {
                const unsigned code = kCellCode[static_cast<unsigned>(col[i] | col[i + 1] << 4)];
                if (code == 0 || code == 255) continue;
                int subcase = 0;
                const detail::Tiling& tl = tiling_of(i, j, k, code, subcase);
                vertices += tl.interior_count;
                triangles += tl.triangle_count;
                ++stats.cells_per_subcase[static_cast<std::size_t>(subcase)];
                lo = std::min(lo, i);
                hi = std::max(hi, i + 1);
            }
        }
        if (hi > lo) range_[r] = {static_cast<std::int32_t>(lo), static_cast<std::int32_t>(hi)};
        row_vertices_[r + 1] = vertices;
        row_triangles_[r + 1] = triangles;
    }

    /// The crossing parameter of the edge from sample value a to b, in [delta, 1 - delta]
    /// (src/core/placement.hpp: never on a sample, so ties do not collapse triangles).
    double crossing(T a, T b) const
    {
        const double va = static_cast<double>(a), vb = static_cast<double>(b);
        const double d = vb - va; // ends differ in sign: vb != va
        if (std::isinf(d)) {
            // |vb - va| passes DBL_MAX (samples near +-1e308): the same ratio on halved values,
            // which cannot overflow; iso lies between va and vb, so |iso - va| <= |vb - va|
            return detail::clamp_crossing((0.5 * iso_ - 0.5 * va) / (0.5 * vb - 0.5 * va), delta_);
        }
        return detail::clamp_crossing((iso_ - va) / d, delta_);
    }

    /// delta of placement.hpp for this grid: 2^-10 of an edge, or more where the output floats
    /// cannot tell a point delta along an edge from the sample (16 units in the last place of the
    /// largest coordinate, at most 1/8 of an edge).
    static double min_crossing(const GridView<T>& g, const Mat3& m)
    {
        const double largest = largest_coordinate(g);
        double shortest = std::numeric_limits<double>::infinity();
        for (std::size_t a = 0; a < 3; ++a) {
            const double length = is_diagonal(m) ? std::fabs(m[a][a]) : std::hypot(m[0][a], m[1][a], m[2][a]);
            shortest = std::min(shortest, length);
        }
        if (!(largest > 0) || !(shortest > 0) || !std::isfinite(largest)) return detail::kMinCrossing;
        const double ulp = std::ldexp(1.0, std::ilogb(largest) - 23);
        return std::clamp(16 * ulp / shortest, detail::kMinCrossing, 0.125);
    }

    /// The world position of index-space point x (the frame of volume.hpp), rounded to float.
    void write_position(const double x[3], float* out) const
    {
        if (diagonal_) {
            for (std::size_t c = 0; c < 3; ++c) out[c] = static_cast<float>(g_.origin[c] + step_[c] * x[c]);
            return;
        }
        for (std::size_t c = 0; c < 3; ++c)
            out[c] = static_cast<float>(g_.origin[c] + (m_[c][0] * x[0] + m_[c][1] * x[1] + m_[c][2] * x[2]));
    }

    static Mat3 inverse_transpose(const Mat3& m)
    {
        // the cofactor matrix over the determinant: (M^-1)^T = cof(M) / det M
        const double det = determinant(m);
        Mat3 r{};
        for (std::size_t i = 0; i < 3; ++i)
            for (std::size_t j = 0; j < 3; ++j) {
                const std::size_t i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
                r[i][j] = (m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1]) / det;
            }
        return r;
    }

    /// A power of two that keeps every scaled gradient, and its interpolation between two samples,
    /// finite: 1 unless the samples or the map to world gradients are near the double range.
    double gradient_scale(double largest_sample) const
    {
        double map = 0; // largest factor from an index difference to a world gradient component
        for (std::size_t r = 0; r < 3; ++r) {
            if (diagonal_) {
                map = std::max(map, 1 / std::fabs(step_[r]));
            } else {
                map = std::max(map, std::fabs(normal_map_[r][0]) + std::fabs(normal_map_[r][1]) +
                                        std::fabs(normal_map_[r][2]));
            }
        }
        if (!(largest_sample > 0) || !(map > 0) || !std::isfinite(map)) return 1;
        // |gradient component| <= 2 * largest * map, its interpolation 3 times that: 2^3
        const int exponent = std::ilogb(largest_sample) + std::ilogb(map) + 5;
        return exponent > 1000 ? std::ldexp(1.0, 1000 - exponent) : 1.0;
    }

    /// The gradient at sample (i, j, k) by central differences (one-sided at the border), in world
    /// coordinates for a diagonal frame, in index coordinates otherwise (write_normal maps it),
    /// times gradient_scale_.
    std::array<double, 3> gradient(std::int64_t i, std::int64_t j, std::int64_t k) const
    {
        std::array<double, 3> grad{};
        const std::int64_t idx[3] = {i, j, k};
        const std::int64_t n[3] = {nx_, ny_, nz_};
        for (int axis = 0; axis < 3; ++axis) {
            std::int64_t lo[3] = {i, j, k}, hi[3] = {i, j, k};
            if (idx[axis] > 0) --lo[axis];
            if (idx[axis] + 1 < n[axis]) ++hi[axis];
            const double d = static_cast<double>(hi[axis] - lo[axis]) * step_[static_cast<std::size_t>(axis)];
            const double s = gradient_scale_; // 1 unless differences of the samples could overflow
            grad[static_cast<std::size_t>(axis)] =
                (s * static_cast<double>(at(hi[0], hi[1], hi[2])) - s * static_cast<double>(at(lo[0], lo[1], lo[2]))) / d;
        }
        return grad;
    }

    void emit_row_vertices(std::int64_t j, std::int64_t k, const std::uint32_t* ids, Mesh& mesh) const
    {
        const auto r = static_cast<std::size_t>(row_index(j, k));
        for (std::int64_t slot = 3 * std::int64_t{range_[r][0]}; slot < 3 * std::int64_t{range_[r][1]}; ++slot) {
            const std::uint32_t id = ids[slot];
            if (id == kNoVertex) continue;
            const std::int64_t i = slot / 3;
            const int axis = static_cast<int>(slot % 3);
            const std::int64_t end[3] = {i + (axis == 0), j + (axis == 1), k + (axis == 2)};
            const double t = crossing(at(i, j, k), at(end[0], end[1], end[2]));
            const double p[3] = {static_cast<double>(i), static_cast<double>(j), static_cast<double>(k)};
            double x[3];
            for (int c = 0; c < 3; ++c) x[c] = p[c] + (c == axis ? t : 0.0);
            write_position(x, &mesh.positions[static_cast<std::size_t>(id) * 3]);
            if (opt_.normals) {
                const auto ga = gradient(i, j, k), gb = gradient(end[0], end[1], end[2]);
                write_normal(&mesh.normals[static_cast<std::size_t>(id) * 3],
                             {ga[0] + t * (gb[0] - ga[0]), ga[1] + t * (gb[1] - ga[1]), ga[2] + t * (gb[2] - ga[2])});
            }
        }
    }

    /// Normals point from above to below: along minus the world gradient.
    void write_normal(float* out, std::array<double, 3> g) const
    {
        if (!diagonal_) {
            const Mat3& n = normal_map_;
            g = {n[0][0] * g[0] + n[0][1] * g[1] + n[0][2] * g[2], n[1][0] * g[0] + n[1][1] * g[1] + n[1][2] * g[2],
                 n[2][0] * g[0] + n[2][1] * g[1] + n[2][2] * g[2]};
        }
        double len = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
        if (!(len > 0) || !std::isfinite(len)) {
            // the squares overflow (or underflow): divide by the largest component first
            const double big = std::max({std::fabs(g[0]), std::fabs(g[1]), std::fabs(g[2])});
            if (big > 0 && std::isfinite(big)) {
                for (double& c : g) c /= big;
                len = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
            }
        }
        for (int c = 0; c < 3; ++c) out[c] = len > 0 ? static_cast<float>(-g[static_cast<std::size_t>(c)] / len) : 0.0f;
    }

    void emit_row_cells(std::int64_t j, std::int64_t k, Scratch& s, std::int64_t vertex, Mesh& mesh) const
    {
        // the edge ids of the four sample rows around the cell row: (j,k), (j+1,k), (j,k+1), (j+1,k+1)
        std::int64_t unused = 0;
        const std::uint32_t* ids[4] = {row_ids(j, k, s, unused), row_ids(j + 1, k, s, unused),
                                       row_ids(j, k + 1, s, unused), row_ids(j + 1, k + 1, s, unused)};
        column_codes(j, k, s);
        const std::uint8_t* col = s.columns.data();
        const auto r = static_cast<std::size_t>(row_index(j, k));
        std::int64_t tri = row_triangles_[r];
        const std::int64_t last = std::min<std::int64_t>(range_[r][1], nx_ - 1);
        for (std::int64_t i = range_[r][0]; i < last; ++i) {
            const unsigned code = kCellCode[static_cast<unsigned>(col[i] | col[i + 1] << 4)];
            if (code == 0 || code == 255) continue;
            int subcase = 0;
            const detail::Tiling& tl = tiling_of(i, j, k, code, subcase);
            std::uint32_t edge_id[12];
            for (int e = 0; e < 12; ++e) {
                const int c = kEdgeCorners[e][0];
                const std::uint32_t* row = ids[kCornerOffset[c][1] + 2 * kCornerOffset[c][2]];
                edge_id[e] = row[3 * (i + kCornerOffset[c][0]) + e / 4];
            }
            const std::int64_t first_interior = vertex;
            if (tl.interior_count > 0) write_interior_vertices(i, j, k, tl, vertex, mesh);
            vertex += tl.interior_count;
            const std::uint8_t* codes = &detail::kTriangleCodes[static_cast<std::size_t>(tl.first_triangle) * 3];
            std::uint32_t* out = &mesh.triangles[static_cast<std::size_t>(tri) * 3];
            for (int q = 0; q < 3 * tl.triangle_count; ++q) {
                const int v = codes[q];
                out[q] = v < 12 ? edge_id[v] : static_cast<std::uint32_t>(first_interior + (v - 12));
            }
            if (mirrored_) {
                for (int q = 0; q < 3 * tl.triangle_count; q += 3) std::swap(out[q + 1], out[q + 2]);
            }
            tri += tl.triangle_count;
        }
    }

    /// The interior vertices of cell (i, j, k)'s tiling, ids from `first` on, placed by
    /// placement.hpp from the cell's crossings; normals interpolate the corners' gradients.
    void write_interior_vertices(std::int64_t i, std::int64_t j, std::int64_t k, const detail::Tiling& tl,
                                 std::int64_t first, Mesh& mesh) const
    {
        T value[8];
        for (int c = 0; c < 8; ++c) value[c] = at(i + kCornerOffset[c][0], j + kCornerOffset[c][1], k + kCornerOffset[c][2]);
        double crossing_at[12][3] = {};
        unsigned needed = 0;
        for (int q = 0; q < tl.interior_count; ++q) {
            const unsigned code = detail::kInteriorMasks[tl.first_interior + q];
            for (int e = 0; e < 12; ++e) needed |= static_cast<unsigned>(detail::interior_uses_edge(code, e)) << e;
        }
        for (int e = 0; e < 12; ++e) {
            if (!((needed >> e) & 1u)) continue;
            const int a = kEdgeCorners[e][0], b = kEdgeCorners[e][1];
            const double t = crossing(value[a], value[b]);
            for (int c = 0; c < 3; ++c) crossing_at[e][c] = static_cast<double>(kCornerOffset[a][c]) + (c == e / 4 ? t : 0.0);
        }
        std::array<double, 3> grad[8];
        if (opt_.normals) {
            for (int c = 0; c < 8; ++c) grad[c] = gradient(i + kCornerOffset[c][0], j + kCornerOffset[c][1], k + kCornerOffset[c][2]);
        }
        const double base[3] = {static_cast<double>(i), static_cast<double>(j), static_cast<double>(k)};
        for (int q = 0; q < tl.interior_count; ++q) {
            double p[3];
            detail::interior_position(detail::kInteriorMasks[tl.first_interior + q], crossing_at, p);
            const auto id = static_cast<std::size_t>(first + q);
            const double x[3] = {base[0] + p[0], base[1] + p[1], base[2] + p[2]};
            write_position(x, &mesh.positions[id * 3]);
            if (opt_.normals) {
                double w[8];
                detail::trilinear_weights(p, w);
                std::array<double, 3> n{};
                for (int c = 0; c < 8; ++c)
                    for (std::size_t a = 0; a < 3; ++a) n[a] += w[c] * grad[c][a];
                write_normal(&mesh.normals[id * 3], n);
            }
        }
    }

    const GridView<T>& g_;
    double iso_;
    Above<T> above_;
    ExtractOptions opt_;
    std::int64_t nx_, ny_, nz_;
    int threads_;
    Mat3 m_;                  ///< index to world: M = D * diag(spacing)
    bool diagonal_, mirrored_; ///< M diagonal; det M < 0 (triangles are reversed)
    double step_[3] = {};      ///< the diagonal of M when diagonal_, else 1 (see gradient())
    Mat3 normal_map_{};        ///< M^-T, for a non-diagonal M
    double gradient_scale_ = 1;
    double delta_; ///< crossings lie in [delta_, 1 - delta_] of their edge
    std::array<bool, 256> needs_values_{};
    std::vector<std::int64_t> row_vertices_, row_triangles_;
    /// Trim range from pass 1, per row r: [range_[r][0], range_[r][1]) holds every sample of row r
    /// that owns a crossed edge and every crossed cell of cell row r (nx < 2^31: validate()).
    std::vector<std::array<std::int32_t, 2>> range_;
};

/// Checks the grid and isovalue; returns the largest |sample| (a bound for integer types).
template <class T> double validate(const GridView<T>& g, double iso)
{
    if (!std::isfinite(iso)) {
        throw Error(Status::non_finite, "isovalue " + std::to_string(iso) + " is not a finite number");
    }
    for (int a = 0; a < 3; ++a) {
        if (g.dims[static_cast<std::size_t>(a)] < 2) {
            throw Error(Status::invalid_argument, "grid has " + std::to_string(g.dims[static_cast<std::size_t>(a)]) +
                                                      " samples along " + "xyz"[a] +
                                                      "; an isosurface needs at least 2 on each axis");
        }
    }
    if (g.strides[0] != 1) throw Error(Status::invalid_argument, "grid view must have unit x-stride");
    const Mat3 m = frame_matrix(g.spacing, g.direction);
    for (std::size_t r = 0; r < 3; ++r) {
        const bool finite = std::isfinite(g.origin[r]) && std::isfinite(m[r][0]) && std::isfinite(m[r][1]) &&
                            std::isfinite(m[r][2]);
        if (!finite) throw Error(Status::non_finite, "the grid's origin, spacing or direction is not finite");
    }
    if (!(std::fabs(determinant(m)) > 0)) {
        throw Error(Status::invalid_argument,
                    "the grid's frame is degenerate (det of direction * spacing is 0); expected three "
                    "independent axes");
    }
    const double largest = largest_coordinate(g);
    if (!std::isfinite(static_cast<float>(largest))) {
        char text[200];
        std::snprintf(text, sizeof text, "world coordinates up to %.4g do not fit the output's 32-bit floats "
                                         "(at most %.4g); scale the spacing or origin down", largest,
                      static_cast<double>(std::numeric_limits<float>::max()));
        throw Error(Status::too_large, text);
    }
    // a row's crossed-edge count (up to 3 nx) is summed in 32 bits, which keeps that loop vectorised
    constexpr std::int64_t kMaxRow = std::numeric_limits<std::uint32_t>::max() / 3;
    if (g.nx() > kMaxRow) {
        throw Error(Status::too_large, "grid has " + std::to_string(g.nx()) + " samples along x; the extractor handles at most " +
                                           std::to_string(kMaxRow) + " per row");
    }
    double largest_sample = 0;
    if constexpr (std::is_floating_point_v<T>) {
        std::int64_t count = 0;
        Index3 first{-1, -1, -1};
        for (std::int64_t k = 0; k < g.nz(); ++k)
            for (std::int64_t j = 0; j < g.ny(); ++j)
                for (std::int64_t i = 0; i < g.nx(); ++i) {
                    const double v = std::fabs(static_cast<double>(g(i, j, k)));
                    if (!std::isfinite(v) && count++ == 0) first = {i, j, k};
                    largest_sample = std::max(largest_sample, v);
                }
        if (count > 0) {
            throw Error(Status::non_finite, std::to_string(count) + " samples are NaN or infinite, the first at (" +
                                                std::to_string(first[0]) + ", " + std::to_string(first[1]) + ", " +
                                                std::to_string(first[2]) + "); cmc33 needs finite samples");
        }
    } else {
        largest_sample = std::max(std::fabs(static_cast<double>(std::numeric_limits<T>::lowest())),
                                  static_cast<double>(std::numeric_limits<T>::max()));
    }
    return largest_sample;
}

} // namespace

template <class T> Mesh extract(const GridView<T>& grid, double iso, const ExtractOptions& options, ExtractStats* stats)
{
    const double largest_sample = validate(grid, iso);
    return Extractor<T>(grid, iso, options, largest_sample).run(stats);
}

Mesh extract(const Volume& volume, double iso, const ExtractOptions& options, ExtractStats* stats)
{
    return volume.visit([&](auto view) { return extract(view, iso, options, stats); });
}

#define CMC33_INSTANTIATE(T) \
    template Mesh extract<T>(const GridView<T>&, double, const ExtractOptions&, ExtractStats*);
CMC33_INSTANTIATE(std::int8_t)
CMC33_INSTANTIATE(std::uint8_t)
CMC33_INSTANTIATE(std::int16_t)
CMC33_INSTANTIATE(std::uint16_t)
CMC33_INSTANTIATE(std::int32_t)
CMC33_INSTANTIATE(std::uint32_t)
CMC33_INSTANTIATE(float)
CMC33_INSTANTIATE(double)
#undef CMC33_INSTANTIATE

} // namespace cmc33
