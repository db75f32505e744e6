#pragma once
// The range extractor: the passes of passes.hpp (count, emit) over a range of sample planes
// [k0, k1) of one grid and isovalue. Declared here, defined along the algorithm:
//   count.cpp       pass 1: per cell row the case codes, the cells' decisions, the counts;
//   emit.cpp        pass 3: the vertices of crossed edges and the cells' triangles at the ids the
//                   scan fixed, with the short-tiling path for small fixed tilings;
//   vertices.hpp    vertex placement (crossings, interior vertices) and normals (gradients);
//   cell_ranges.hpp the one per-vertex attribute computed from the cells (scikit-image's
//                   values, MeshSpans::vertex_cell_ranges), a hook emit calls;
//   bit_rows.hpp    the above-flags as words and what is read from them.
// What does not depend on the range (the frame, the grid's place in a larger one, the sign rule,
// which configurations need the samples) is set up once in the constructor and shared by the
// ranges, which may run at the same time: every pass is const.

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "bit_rows.hpp"
#include "cell_ranges.hpp"
#include "classify.hpp"
#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/passes.hpp"
#include "decide.hpp"
#include "grid_checks.hpp"
#include "mc33_tables.hpp"
#include "portability.hpp"
#include "schedule.hpp"

namespace cmc33::detail {

/// Which of MeshSpans' outputs an instantiation of emit's row functions writes. plain:
/// positions, triangles and normals, the usual output, without the extras' tests (they cost
/// 2-4 % where not taken); all: every extra and layout, each tested at run time, and the
/// per-vertex attribute hook (Emit::ranges) where it is set.
enum class Outputs { plain, all };

/// A block's place in its larger grid (MeshSpans::index_offset, whole_dims); both zero: the whole.
struct BlockPlacement {
    Index3 offset{0, 0, 0};
    Index3 whole_dims{0, 0, 0};
};

template <class T> class RangeExtractor {
public:
    /// `block` fixes emit's positions, numbers and crossing margin once (count reads none of it).
    RangeExtractor(const GridView<T>& g, double iso, const ExtractOptions& opt, const BlockPlacement& block = {})
        : g_(g), iso_(iso), threshold_(iso), method_(opt.method), nx_(g.nx()), ny_(g.ny()), nz_(g.nz()), sx_(g.strides[0]),
          words_((nx_ + 63) / 64), x_valid_(valid_words(words_, nx_ - 1)),
          m_(frame_matrix(g.spacing, g.direction)), diagonal_(is_diagonal(m_)), mirrored_(determinant(m_) < 0),
          offset_(block.offset), whole_(block.whole_dims == Index3{0, 0, 0} ? g.dims : block.whole_dims),
          delta_(min_crossing(whole_, g.origin, m_)), variants_(detail::tables_of(opt.method))
    {
        for (std::size_t a = 0; a < 3; ++a) {
            step_[a] = diagonal_ ? m_[a][a] : 1.0;
            half_inverse_step_[a] = 0.5 / step_[a];
        }
        if (!diagonal_) normal_map_ = inverse_transpose(m_);
        for (unsigned code = 0; code < 256; ++code) {
            const detail::Variant& first = variants_[detail::kVariantOffset[code]];
            const bool tested = opt.method != Method::mc &&
                                (detail::kAmbiguousFaces[code] != 0 || first.test != detail::kTestNone);
            fixed_tiling_[code] = tested ? nullptr : &first.tilings[0];
            fixed_subcase_[code] = first.subcase;
        }
        build_short_tilings();
    }

    /// Whether `c` was counted on a grid with these rows.
    static bool same_rows(const RangeCounts& c, const GridView<T>& g);

    /// Pass 1 on planes [k0, k1); `largest_sample` bounds |sample| on planes k0 - 1 .. k1 + 1.
    /// Stops early (returning partial counts) when the ticker says so.
    RangeCounts count(std::int64_t k0, std::int64_t k1, double largest_sample, Ticker* ticker) const;

    /// Pass 3 (see passes.hpp).
    void emit(const RangeCounts& c, const RangeOffsets& off, const MeshSpans& out, Ticker* ticker) const;

private:
    /// emit() found other numbers than count() in row (j, k): the samples, the isovalue or the
    /// method changed between the passes, or a bug in cmc33. Thrown before writing outside the
    /// row's part of the output.
    [[noreturn]] static void throw_mismatch(const char* what, std::int64_t j, std::int64_t k)
    {
        throw Error(Status::internal, std::string("emit found other ") + what + " in sample row (" + std::to_string(j) +
                                          ", " + std::to_string(k) +
                                          ") than count did: the samples, isovalue or method differ between "
                                          "the passes, or a bug in cmc33");
    }

    static Outputs outputs_of(const MeshSpans& out)
    {
        const bool extras = out.vertex_edges || out.vertex_parameters || out.vertex_values || out.triangle_cells ||
                            out.vertex_cell_ranges;
        return extras || out.zyx || out.reverse_winding ? Outputs::all : Outputs::plain;
    }

    /// One range's emit: its counts, offsets and output.
    struct Emit {
        const RangeCounts& c;
        const RangeOffsets& off;
        const MeshSpans& out;
        double gradient_scale;
        /// MeshSpans::vertex_cell_ranges' hook (cell_ranges.hpp); null without that output.
        VertexCellRanges<T>* ranges;
        /// One past the range's last triangle id: a short tiling's fixed-size copy may write past
        /// its row's triangles into those of the range's next rows, which this thread writes
        /// later, but not past the range's (another thread's, or the end of the caller's output).
        std::int64_t copy_end() const { return off.first_triangle + c.t_.triangles; }
    };

    /// One thread's working memory: above-flags of three slices (3 nx ny / 8 bytes), vertex ids
    /// of four sample rows (emit), and what classifying the rows saw. emit classifies the rows it
    /// needs again rather than keeping count's: on a dense surface reading them back costs more
    /// than the vector compare, and on a sparse one it saves little.
    struct Scratch {
        Scratch(std::int64_t nx, std::int64_t ny) : masks(nx, ny), ids(nx) {}
        SliceMasks masks;
        IdRows ids;
        detail::RowScan scan;
    };

    /// The range-relative ids of row (j, k) of a range: x/y edge vertices [xy0, xy1), z edge and
    /// interior vertices [z0, v1), triangles [t0, t1); its trim range [lo, hi).
    struct RowSpan {
        std::int64_t xy0, xy1, z0, v1, t0, t1;
        std::int64_t lo, hi;
    };
    RowSpan span_of(const RangeCounts& c, std::int64_t j, std::int64_t k) const;

    /// emit()'s planes, row by row, with the outputs `kOut` says (one instantiation per kind of
    /// output, chosen once per range). Returns false when the ticker stopped it.
    template <Outputs kOut>
    bool emit_planes(const Emit& e, Scratch& s, Ticker* ticker, std::size_t& decision) const;

    T at(std::int64_t i, std::int64_t j, std::int64_t k) const { return g_.data[g_.offset(i, j, k)]; }

    /// Classifies row (j, k) into f; returns its signs.
    CMC33_ALWAYS_INLINE detail::RowSigns classify(std::int64_t j, std::int64_t k, Word* f, Scratch& s) const
    {
        return detail::classify_row(g_.data + g_.offset(0, j, k), nx_, sx_, threshold_, f, s.scan);
    }

    /// Above-flags of the samples of row (j, k), and the row's signs (emit, which reads rows out
    /// of order: each is classified when first asked for).
    CMC33_ALWAYS_INLINE const Word* flags(std::int64_t j, std::int64_t k, Scratch& s, detail::RowSigns& signs) const
    {
        bool fresh = false;
        detail::RowSigns* known = nullptr;
        Word* f = s.masks.get(j, k, fresh, known);
        if (fresh) *known = classify(j, k, f, s);
        signs = *known;
        return f;
    }
    const Word* flags(std::int64_t j, std::int64_t k, Scratch& s) const
    {
        detail::RowSigns unused{};
        return flags(j, k, s, unused);
    }

    /// The flags and signs of the sample rows around cell row (j, k): (j, k), (j + 1, k),
    /// (j, k + 1), (j + 1, k + 1); a row past the grid gets (j, k)'s (no cell reads it then).
    CMC33_ALWAYS_INLINE void flags_around(std::int64_t j, std::int64_t k, Scratch& s, const Word* (&f)[4],
                                          detail::RowSigns (&signs)[4]) const
    {
        f[0] = flags(j, k, s, signs[0]);
        f[1] = f[2] = f[3] = f[0];
        signs[1] = signs[2] = signs[3] = signs[0];
        if (j + 1 < ny_) f[1] = flags(j + 1, k, s, signs[1]);
        if (k + 1 < nz_) f[2] = flags(j, k + 1, s, signs[2]);
        if (j + 1 < ny_ && k + 1 < nz_) f[3] = flags(j + 1, k + 1, s, signs[3]);
    }

    /// Vertex ids of the edges owned by the samples of row (j, k): ids[3 * i + axis], kNoVertex
    /// where the edge does not cross or does not exist (or, in the next range's plane k1, for the z
    /// edges, which no cell of this range uses). `interior`: the id after the row's last z edge
    /// vertex, where the interior vertices of its cells begin.
    CMC33_ALWAYS_INLINE const std::uint32_t* row_ids(std::int64_t j, std::int64_t k, Scratch& s, const Emit& e, std::int64_t& interior) const;

    /// Count's decision for crossed cell (i, j, k) with case code `code`, which has no fixed tiling: its
    /// tiling, its subcase, and as one byte for emit to replay, (face tests' bits << 2) | tiling
    /// (at most 6 ambiguous faces and 3 tilings).
    const detail::Tiling& decide_cell(std::int64_t i, std::int64_t j, std::int64_t k, unsigned code, int& subcase,
                                      std::uint8_t& decision) const;

    /// Tilings of at most this many triangles are written a fixed 3 * kShortTiling ids at a time.
    static constexpr int kShortTiling = 4;

    /// short_count_ and short_offsets_: for the case codes whose fixed tiling has no interior
    /// vertex and at most kShortTiling triangles, where each id of their triangles sits in the
    /// four id rows of IdRows, so that emit_row_cells goes from a cell's code to its ids in two
    /// loads. The offsets are 16 bits, a table of 24 KiB that stays in the L1 cache better than
    /// 32-bit ones; grids wider than 7281 samples, where they would not fit, and grids of fewer
    /// than 64 cells have none (every cell takes emit_cell()).
    void build_short_tilings();

    /// kTriangleCodes followed by 3 * kShortTiling zeros, so that a short tiling's fixed-size copy
    /// stays inside the table (both table sets index it).
    static const std::vector<std::uint8_t>& padded_codes();

    /// The tiling a decision byte of decide_cell() names for case code `code`; null when the byte
    /// cannot be one of that code's (the samples changed between count and emit).
    const detail::Tiling* replay(unsigned code, std::uint8_t decision) const;

    /// Counts row (j, k) into its Row of `c`: x/y edge vertices in xy_first, z edge and interior
    /// vertices in z_first, triangles in triangle_first (count() turns them into first ids).
    /// `rows` and `signs`: those of the sample rows around the cell row, as flags_around(j, k) gives them.
    CMC33_ALWAYS_INLINE void count_row(std::int64_t j, std::int64_t k, Scratch& s, RangeCounts& c,
                                       const Word* const (&rows)[4], const detail::RowSigns (&signs)[4]) const;

    /// The crossing parameter of the edge from sample value a to b, in [delta_, 1 - delta_]
    /// (src/core/placement.hpp: never on a sample, so ties do not collapse triangles).
    CMC33_ALWAYS_INLINE double crossing(T a, T b) const;

    /// delta of placement.hpp for a grid of `dims` samples at `origin` with index-to-world map m:
    /// 2^-10 of an edge, or more where the output floats cannot tell a point delta along an edge
    /// from the sample (16 units in the last place of the largest coordinate, at most 1/8 of an
    /// edge).
    static double min_crossing(const Index3& dims, const Vec3& origin, const Mat3& m);

    /// The world position of unit point u of cell (i, j, k) at the larger grid's index, as floats
    /// (x, y, z), or (z, y, x) with `zyx` (MeshSpans).
    CMC33_ALWAYS_INLINE void write_position(std::int64_t i, std::int64_t j, std::int64_t k, const double (&u)[3],
                                            float* out, bool zyx) const;

    /// The larger grid's number of cell (i, j, k) (MeshSpans::vertex_edges, triangle_cells).
    std::int64_t whole_cell(std::int64_t i, std::int64_t j, std::int64_t k) const
    {
        return (i + offset_[0]) + whole_[0] * ((j + offset_[1]) + whole_[1] * (k + offset_[2]));
    }

    /// out = p, or p reversed (z, y, x) with `zyx`.
    CMC33_ALWAYS_INLINE static void store(const float p[3], float* out, bool zyx)
    {
        const std::size_t first = zyx ? 2 : 0;
        out[first] = p[0];
        out[1] = p[1];
        out[2 - first] = p[2];
    }

    /// A power of two that keeps every scaled gradient, and its interpolation between two samples,
    /// finite: 1 unless the samples or the map to world gradients are near the double range.
    /// (Scaling by a power of two is exact, so ranges with different bounds give the same normals.)
    double gradient_scale(double largest_sample) const;

    /// The gradient at sample (i, j, k) by central differences (one-sided at the border), in world
    /// coordinates for a diagonal frame, in index coordinates otherwise (write_normal maps it),
    /// times `scale`.
    std::array<double, 3> gradient(std::int64_t i, std::int64_t j, std::int64_t k, double scale) const;

    /// The gradient at parameter t of the edge from sample (i, j, k) along `axis`: its ends'
    /// gradients (gradient()) mixed linearly. Where both ends have all six neighbours (nearly
    /// every vertex) the same numbers come from one bounds check and, for integer samples, exact
    /// differences in their own arithmetic.
    CMC33_ALWAYS_INLINE std::array<double, 3> edge_gradient(std::int64_t i, std::int64_t j, std::int64_t k, int axis,
                                                            double t, double scale) const;

    /// scale * hi - scale * lo, as gradient() computes it: for integers at scale 1 (always, but
    /// for frames near the double range) the exact difference.
    static double difference(T hi, T lo, double scale);

    /// The vertices of the crossed edges owned by row (j, k) (its span `r`, its rows of flags as
    /// emit_planes found them), at the ids row_ids gave them; the outputs of MeshSpans that `kOut`
    /// says.
    template <Outputs kOut>
    void emit_row_vertices(std::int64_t j, std::int64_t k, const RowSpan& r, const Word* const (&rows)[4],
                           const std::uint32_t* ids, const Emit& e) const;

    /// The vertices of the crossed edges along `axis` of samples 64 w + b of row (j, k), b a bit of
    /// `crossed`.
    template <int axis, Outputs kOut>
    CMC33_ALWAYS_INLINE void emit_axis_vertices(Word crossed, std::int64_t w, std::int64_t j, std::int64_t k,
                                                const std::uint32_t* ids, const Emit& e) const;

    /// The vertex `id` on the edge from sample (i, j, k) along `axis`.
    template <int axis, Outputs kOut>
    CMC33_ALWAYS_INLINE void emit_edge_vertex(std::int64_t i, std::int64_t j, std::int64_t k, std::uint32_t id,
                                              const Emit& e) const;

    /// Normals point from above to below: along minus the world gradient. `zyx` as in write_position.
    /// False (and (0, 0, 0) written) where g is 0: the caller then falls back to another gradient.
    CMC33_ALWAYS_INLINE bool write_normal(float* out, std::array<double, 3> g, bool zyx) const;

    /// The gradient of the trilinear interpolant at parameter t of the edge from sample (i, j, k)
    /// along `axis`, in the cell on the edge's upper side of each other axis (the lower side at the
    /// grid's last sample), scaled as gradient(). Its `axis` component is b - a: never 0 on a
    /// crossed edge, so a normal always has a direction.
    std::array<double, 3> edge_cell_gradient(std::int64_t i, std::int64_t j, std::int64_t k, int axis, double t,
                                             double scale) const;

    /// The cells of cell row (j, k) (its span `r`, its four rows of flags as emit_planes found
    /// them): interior vertices from id `vertex` on and triangles from id `tri` on; both are left
    /// one past the last written. Cells with a test take the next of count's decisions, from
    /// `decision` on. The outputs of MeshSpans that `kOut` says.
    template <Outputs kOut>
    void emit_row_cells(std::int64_t j, std::int64_t k, const RowSpan& r, const Word* const (&rows)[4], Scratch& s,
                        const Emit& e, std::int64_t& vertex, std::int64_t& tri, std::size_t& decision) const;

    /// The triangles of cell (i, j, k) (case code `code`) from `o` on (triangle id `tri`), and its
    /// interior vertices from id `vertex` on (then moved past them), unless its tiling is a short
    /// fixed one (the caller's); tested cells replay count's next decision. Returns the number of
    /// triangles.
    int emit_cell(std::int64_t i, std::int64_t j, std::int64_t k, unsigned code, const std::uint32_t* const* edge_ids,
                  const std::uint8_t* padded_table, const RowSpan& r, const Emit& e,
                  std::int64_t tri, std::uint32_t* o, std::int64_t& vertex, std::size_t& decision) const;

    /// The gradient of the cell's trilinear interpolant (corner samples `value`) at unit point p,
    /// scaled as gradient().
    std::array<double, 3> cell_gradient(const T (&value)[8], const double (&p)[3], double scale) const;

    /// Minus the area-weighted normal of the tiling's triangles around its interior vertex q (unit
    /// point pq), as a gradient for write_normal(): where the interpolant itself is flat there (a
    /// critical point), the surface still has a side. Triangles wind with their normals toward the
    /// below side (mc33_tables.hpp), in index space; M^-T takes them to world space as it does
    /// gradients.
    std::array<double, 3> fan_gradient(const T (&value)[8], const detail::Tiling& tl, int q, const double (&pq)[3]) const;

    /// The interior vertices of cell (i, j, k)'s tiling, ids from `first` on, placed by
    /// placement.hpp from the cell's crossings; normals interpolate the corners' gradients.
    void write_interior_vertices(std::int64_t i, std::int64_t j, std::int64_t k, const detail::Tiling& tl,
                                 std::int64_t first, const Emit& e) const;

    const GridView<T>& g_;
    double iso_;
    detail::Threshold<T> threshold_;
    Method method_;
    std::int64_t nx_, ny_, nz_, sx_;
    std::int64_t words_;               ///< words of a row's flags
    std::vector<Word> x_valid_;        ///< bits of the x edges and cells 0..nx-2
    Mat3 m_;                  ///< index to world: M = D * diag(spacing)
    bool diagonal_, mirrored_; ///< M diagonal; det M < 0 (triangles are reversed)
    double step_[3] = {};      ///< the diagonal of M when diagonal_, else 1 (see gradient())
    double half_inverse_step_[3] = {}; ///< 1 / (2 step_), central differences' factor
    Mat3 normal_map_{};        ///< M^-T, for a non-diagonal M
    Index3 offset_; ///< BlockPlacement::offset: the larger grid's index of sample (0, 0, 0)
    Index3 whole_;  ///< the larger grid's dims (the grid's own without a block placement)
    double delta_;  ///< crossings lie in [delta_, 1 - delta_] of their edge (the larger grid's box)
    /// The method's table set (detail::tables_of): chosen once here, so the passes' loops read one
    /// pointer and nothing in them depends on the method
    const detail::Variant* variants_;
    /// Per case code: its one tiling, or null when the method decides the cell (face or interior
    /// tests); and its subcase then.
    std::array<const detail::Tiling*, 256> fixed_tiling_{};
    std::array<std::uint8_t, 256> fixed_subcase_{};
    /// build_short_tilings(): per case code its short tiling's triangle count, or -1; per parity
    /// of the cell row and code, 3 * kShortTiling offsets into IdRows
    std::array<std::int8_t, 256> short_count_{};
    std::vector<std::uint16_t> short_offsets_;
};

} // namespace cmc33::detail
