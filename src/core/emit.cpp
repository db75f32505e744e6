// Pass 3 of the range extractor (range_extractor.hpp), emit: each crossed grid edge is owned by
// its lower sample and gets one vertex; every cell writes its tiling's triangles and interior
// vertices at its row's offsets, finding edge vertices by edge ownership (no hash map, no locks).
// Cells with a face or interior test replay the decision count stored for them (in the order
// count met them). Small fixed tilings take a short path: their ids come from a table of offsets
// into the id rows, copied a fixed width at a time.

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "range_extractor.hpp"
#include "sample_types.hpp"
#include "vertices.hpp"

namespace cmc33::detail {

template <class T>
void RangeExtractor<T>::emit(const RangeCounts& c, const RangeOffsets& off, const MeshSpans& out, Ticker* ticker) const
{
    const std::int64_t k0 = c.t_.k0, k1 = c.t_.k1;
    const std::int64_t seam = c.t_.seam_first.empty() ? 0 : c.t_.seam_first.back();
    const std::int64_t next = off.first_vertex + c.t_.vertices;
    if (off.first_vertex < 0 || off.first_triangle < 0 ||
        next + seam > static_cast<std::int64_t>(kNoVertex)) {
        throw Error(Status::too_large, "the mesh would have vertex ids up to " + std::to_string(next + seam) +
                                           ", more than 32-bit indices can address");
    }
    if (!(c.t_.iso == iso_) || c.t_.method != method_) {
        // emit uses count's classification and decisions: they must be of this isovalue and method
        throw Error(Status::invalid_argument, "emit: the counts are of iso " + std::to_string(c.t_.iso) + ", method " +
                                                  std::string(method_name(c.t_.method)) + "; expected iso " +
                                                  std::to_string(iso_) + ", method " +
                                                  std::string(method_name(method_)) + ", as given to emit");
    }
    if ((c.t_.vertices > 0 && out.positions == nullptr) || (c.t_.triangles > 0 && out.triangles == nullptr)) {
        throw Error(Status::invalid_argument, "emit: MeshSpans needs positions and triangles");
    }
    std::optional<VertexCellRanges<T>> ranges;
    if (out.vertex_cell_ranges) ranges.emplace(g_, k0, x_valid_, out.vertex_cell_ranges);
    const Emit e{c, off, out, gradient_scale(c.t_.largest_sample), ranges ? &*ranges : nullptr};
    Scratch s(nx_, ny_);
    std::size_t decision = 0; // the next of count's decisions
    bool finished = false;    // not stopped by the ticker
    switch (outputs_of(out)) {
    case Outputs::plain: finished = emit_planes<Outputs::plain>(e, s, ticker, decision); break;
    case Outputs::all: finished = emit_planes<Outputs::all>(e, s, ticker, decision); break;
    }
    if (!finished) return;
    if (decision != c.t_.decisions.size()) {
        throw Error(Status::internal, "emit met " + std::to_string(decision) + " cells with a face or interior test in planes " +
                                          std::to_string(k0) + " to " + std::to_string(k1) + ", count " +
                                          std::to_string(c.t_.decisions.size()) +
                                          ": the samples, isovalue or method differ between the passes, or a bug in cmc33");
    }
}

template <class T>
typename RangeExtractor<T>::RowSpan RangeExtractor<T>::span_of(const RangeCounts& c, std::int64_t j, std::int64_t k) const
{
    const std::size_t r = static_cast<std::size_t>(j + (k - c.t_.k0) * ny_);
    const RangeTable::Row& row = c.t_.rows[r];
    const RangeTable::Row& first = c.t_.rows[static_cast<std::size_t>((k - c.t_.k0) * ny_)];
    const bool last_row = j + 1 == ny_;
    const bool last_plane = k + 1 == c.t_.k1;
    RowSpan s{};
    s.xy0 = row.xy_first;
    s.xy1 = last_row ? first.z_first : c.t_.rows[r + 1].xy_first;
    s.z0 = row.z_first;
    s.v1 = !last_row ? c.t_.rows[r + 1].z_first : last_plane ? c.t_.vertices : c.t_.rows[r + 1].xy_first;
    s.t0 = row.triangle_first;
    s.t1 = !last_row ? c.t_.rows[r + 1].triangle_first : last_plane ? c.t_.triangles : c.t_.rows[r + 1].triangle_first;
    s.lo = row.lo, s.hi = row.hi;
    return s;
}

template <class T>
template <Outputs kOut>
bool RangeExtractor<T>::emit_planes(const Emit& e, Scratch& s, Ticker* ticker, std::size_t& decision) const
{
    const RangeCounts& c = e.c;
    for (std::int64_t k = c.t_.k0; k < c.t_.k1; ++k) {
        const RangeTable::Row* plane = &c.t_.rows[static_cast<std::size_t>((k - c.t_.k0) * ny_)];
        for (std::int64_t j = 0; j < ny_; ++j) {
            // an empty trim range: no crossed edge or cell, so nothing to emit (most rows of a
            // CT volume; cheaper than span_of)
            if (plane[j].hi <= plane[j].lo) continue;
            const RowSpan r = span_of(c, j, k);
            if (r.v1 == r.xy0 && r.t1 == r.t0) continue;
            std::int64_t interior = 0;
            const std::uint32_t* ids = row_ids(j, k, s, e, interior);
            const Word* f[4];
            detail::RowSigns unused[4];
            flags_around(j, k, s, f, unused);
            if constexpr (kOut == Outputs::all) {
                // the cells' ranges before the vertices, which take them from the cells around
                if (e.ranges && r.t1 != r.t0) e.ranges->cell_row(j, k, f, r.lo, r.hi);
            }
            if (r.xy0 != r.xy1 || r.z0 != r.v1) emit_row_vertices<kOut>(j, k, r, f, ids, e);
            std::int64_t vertex_end = interior, triangle_end = e.off.first_triangle + r.t0;
            if (r.t1 != r.t0) emit_row_cells<kOut>(j, k, r, f, s, e, vertex_end, triangle_end, decision);
            if (vertex_end != e.off.first_vertex + r.v1 || triangle_end != e.off.first_triangle + r.t1) {
                throw_mismatch("vertices or triangles", j, k);
            }
        }
        if (ticker && !ticker->tick()) return false;
    }
    return true;
}

template <class T>
CMC33_ALWAYS_INLINE const std::uint32_t* RangeExtractor<T>::row_ids(std::int64_t j, std::int64_t k, Scratch& s, const Emit& e, std::int64_t& interior) const
{
    bool fresh = false;
    std::int64_t* end = nullptr;
    std::uint32_t* ids = s.ids.get(j, k, fresh, end);
    if (!fresh) {
        interior = *end;
        return ids;
    }
    if (k == e.c.t_.k1) {
        // the next range's first plane: its x/y edge ids follow this range's last vertex
        *end = interior = -1; // not this range's row: no vertex of it is written
        const std::int64_t seam0 = e.c.t_.seam_first[static_cast<std::size_t>(j)];
        if (seam0 == e.c.t_.seam_first[static_cast<std::size_t>(j) + 1]) return ids; // nothing crosses: never read
        const Word* f = flags(j, k, s);
        const Word* fy = j + 1 < ny_ ? flags(j + 1, k, s) : f;
        auto xy = static_cast<std::uint32_t>(e.off.first_vertex + e.c.t_.vertices + seam0);
        for (std::int64_t w = 0; w < words_; ++w) {
            const EdgeWords edges(f, fy, f, w, x_valid_[static_cast<std::size_t>(w)]);
            for (Word bits = edges.x | edges.y; bits != 0; bits &= bits - 1) {
                const int b = std::countr_zero(bits);
                const std::int64_t i = 64 * w + b;
                if ((edges.x >> b) & 1u) ids[3 * i] = xy++;
                if ((edges.y >> b) & 1u) ids[3 * i + 1] = xy++;
            }
        }
        if (xy != e.off.first_vertex + e.c.t_.vertices + e.c.t_.seam_first[static_cast<std::size_t>(j) + 1]) {
            throw_mismatch("x/y edge vertices of the next range's first plane", j, k);
        }
        return ids;
    }
    const RowSpan r = span_of(e.c, j, k);
    if (r.xy0 == r.xy1 && r.z0 == r.v1) {
        // no vertex: no crossed edge, so no cell reads these slots (and no flags are needed)
        *end = interior = e.off.first_vertex + r.z0;
        return ids;
    }
    const Word* f = flags(j, k, s);
    const Word* fy = j + 1 < ny_ ? flags(j + 1, k, s) : f;
    const Word* fz = k + 1 < nz_ ? flags(j, k + 1, s) : f;
    auto xy = static_cast<std::uint32_t>(e.off.first_vertex + r.xy0);
    auto z = static_cast<std::uint32_t>(e.off.first_vertex + r.z0);
    // outside the trim range [lo, hi) no edge crosses
    for (std::int64_t w = r.lo / 64; w < (r.hi + 63) / 64; ++w) {
        const EdgeWords edges(f, fy, fz, w, x_valid_[static_cast<std::size_t>(w)]);
        for (Word bits = edges.any(); bits != 0; bits &= bits - 1) {
            const int b = std::countr_zero(bits);
            std::uint32_t* slot = &ids[3 * (64 * w + b)];
            // branch-free (selects, not jumps): crossings are unpredictable on rough surfaces
            const auto cx = static_cast<std::uint32_t>((edges.x >> b) & 1u);
            const auto cy = static_cast<std::uint32_t>((edges.y >> b) & 1u);
            const auto cz = static_cast<std::uint32_t>((edges.z >> b) & 1u);
            slot[0] = xy;
            xy += cx;
            slot[1] = xy;
            xy += cy;
            slot[2] = z;
            z += cz;
        }
    }
    if (xy != e.off.first_vertex + r.xy1) throw_mismatch("x/y edge vertices", j, k);
    if (z > e.off.first_vertex + r.v1) throw_mismatch("z edge vertices", j, k);
    *end = interior = z;
    return ids;
}

template <class T>
void RangeExtractor<T>::build_short_tilings()
{
    short_count_.fill(-1);
    const std::int64_t length = 3 * nx_; // IdRows::row_length()
    // the largest offset: the last of the four id rows (3 = kEdgeRow's largest), the largest slot
    // (std::max_element: the WebAssembly build's libc++ 13 has no std::ranges::max_element)
    const std::int64_t largest = 3 * length + *std::max_element(kEdgeSlot.begin(), kEdgeSlot.end());
    if (largest > std::numeric_limits<std::uint16_t>::max()) return;
    // a grid of a few cells (analyze_cell's one) would spend more on the table than it saves
    if ((nx_ - 1) * (ny_ - 1) * (nz_ - 1) < 64) return;
    short_offsets_.assign(4 * 256 * 3 * kShortTiling, 0);
    for (unsigned code = 0; code < 256; ++code) {
        const detail::Tiling* tl = fixed_tiling_[code];
        if (tl == nullptr || tl->interior_count != 0 || tl->triangle_count > kShortTiling) continue;
        short_count_[code] = static_cast<std::int8_t>(tl->triangle_count);
        const std::uint8_t* codes = &detail::kTriangleCodes[static_cast<std::size_t>(tl->first_triangle) * 3];
        for (unsigned parity = 0; parity < 4; ++parity)
            for (int q = 0; q < 3 * tl->triangle_count; ++q) {
                // past the tiling the entries stay 0: slot 0's first id, always inside the rows
                const std::size_t edge = codes[q];
                short_offsets_[(parity * 256 + code) * 3 * kShortTiling + static_cast<std::size_t>(q)] =
                    static_cast<std::uint16_t>((parity ^ kEdgeRow[edge]) * length + kEdgeSlot[edge]);
            }
    }
}

template <class T>
const std::vector<std::uint8_t>& RangeExtractor<T>::padded_codes()
{
    static const std::vector<std::uint8_t> table = [] {
        std::size_t n = 0;
        for (const detail::Variant* set : {detail::kVariants, detail::kLegacyVariants})
            for (unsigned v = 0; v < detail::kVariantOffset[256]; ++v)
                for (const detail::Tiling& t : set[v].tilings) {
                    n = std::max<std::size_t>(n, (static_cast<std::size_t>(t.first_triangle) + t.triangle_count) * 3);
                }
        std::vector<std::uint8_t> codes(detail::kTriangleCodes, detail::kTriangleCodes + n);
        codes.resize(n + 3 * kShortTiling, 0);
        return codes;
    }();
    return table;
}

template <class T>
const detail::Tiling* RangeExtractor<T>::replay(unsigned code, std::uint8_t decision) const
{
    const unsigned joined = decision >> 2u, tiling = decision & 3u;
    const unsigned variants = detail::kVariantOffset[code + 1] - detail::kVariantOffset[code];
    if (joined >= variants || tiling > 2) return nullptr;
    return &variants_[detail::kVariantOffset[code] + joined].tilings[tiling];
}

template <class T>
template <Outputs kOut>
void RangeExtractor<T>::emit_row_vertices(std::int64_t j, std::int64_t k, const RowSpan& r, const Word* const (&rows)[4],
                       const std::uint32_t* ids, const Emit& e) const
{
    const Word *f = rows[0], *fy = rows[1], *fz = rows[2];
    if constexpr (kOut == Outputs::all) {
        if (e.ranges) e.ranges->sample_row(j, k);
    }
    for (std::int64_t w = r.lo / 64; w < (r.hi + 63) / 64; ++w) {
        // an axis at a time: on rough surfaces which of a sample's edges cross is unpredictable
        const EdgeWords edges(f, fy, fz, w, x_valid_[static_cast<std::size_t>(w)]);
        emit_axis_vertices<0, kOut>(edges.x, w, j, k, ids, e);
        emit_axis_vertices<1, kOut>(edges.y, w, j, k, ids, e);
        emit_axis_vertices<2, kOut>(edges.z, w, j, k, ids, e);
    }
}

template <class T>
template <int axis, Outputs kOut>
CMC33_ALWAYS_INLINE void RangeExtractor<T>::emit_axis_vertices(Word crossed, std::int64_t w, std::int64_t j, std::int64_t k,
                                            const std::uint32_t* ids, const Emit& e) const
{
    for (Word bits = crossed; bits != 0; bits &= bits - 1) {
        const std::int64_t i = 64 * w + std::countr_zero(bits);
        emit_edge_vertex<axis, kOut>(i, j, k, ids[3 * i + axis], e);
    }
}

template <class T>
template <int axis, Outputs kOut>
CMC33_ALWAYS_INLINE void RangeExtractor<T>::emit_edge_vertex(std::int64_t i, std::int64_t j, std::int64_t k, std::uint32_t id,
                                          const Emit& e) const
{
    const MeshSpans& out = e.out;
    const std::int64_t end[3] = {i + (axis == 0), j + (axis == 1), k + (axis == 2)};
    const T a = at(i, j, k), b = at(end[0], end[1], end[2]);
    const double t = crossing(a, b);
    const double u[3] = {axis == 0 ? t : 0.0, axis == 1 ? t : 0.0, axis == 2 ? t : 0.0};
    const auto v = static_cast<std::size_t>(std::int64_t{id} - out.first_vertex);
    const bool zyx = kOut == Outputs::all && out.zyx;
    write_position(i, j, k, u, &out.positions[v * 3], zyx);
    if (out.normals && !write_normal(&out.normals[v * 3], edge_gradient(i, j, k, axis, t, e.gradient_scale), zyx)) {
        // central differences cancel (alternating samples): the interpolant's own gradient,
        // never 0 on a crossed edge
        write_normal(&out.normals[v * 3], edge_cell_gradient(i, j, k, axis, t, e.gradient_scale), zyx);
    }
    if constexpr (kOut == Outputs::all) {
        if (e.ranges) e.ranges->template edge_vertex<axis>(v, i, j, k);
        if (out.vertex_edges) out.vertex_edges[v] = 3 * whole_cell(i, j, k) + axis;
        if (out.vertex_parameters) out.vertex_parameters[v] = static_cast<float>(t);
        if (out.vertex_values) {
            const double va = static_cast<double>(a), vb = static_cast<double>(b);
            out.vertex_values[v] = static_cast<float>(va + t * (vb - va));
        }
    }
}

template <class T>
template <Outputs kOut>
void RangeExtractor<T>::emit_row_cells(std::int64_t j, std::int64_t k, const RowSpan& r, const Word* const (&rows)[4], Scratch& s,
                    const Emit& e, std::int64_t& vertex, std::int64_t& tri, std::size_t& decision) const
{
    // the edge ids of the four sample rows around the cell row: (j,k), (j+1,k), (j,k+1), (j+1,k+1)
    std::int64_t unused = 0;
    const std::uint32_t* ids[4] = {row_ids(j, k, s, e, unused), row_ids(j + 1, k, s, e, unused),
                                   row_ids(j, k + 1, s, e, unused), row_ids(j + 1, k + 1, s, e, unused)};
    // cube edge q of the cell at i has its vertex id at edge_ids[q][3 * i]
    // (codes 12.. are interior vertices, never looked up here; their entries point into the
    // rows too, so that the fixed-width copy of a short tiling below may read the codes past
    // its end: it writes them into ids that the next cells overwrite)
    const std::uint32_t* edge_ids[12 + detail::kMaxInteriorVertices];
    for (std::size_t q = 0; q < 12; ++q) edge_ids[q] = ids[kEdgeRow[q]] + kEdgeSlot[q];
    for (std::size_t q = 12; q < std::size(edge_ids); ++q) edge_ids[q] = ids[0];
    const Word *f00 = rows[0], *f10 = rows[1], *f01 = rows[2], *f11 = rows[3];
    const MeshSpans& out = e.out;
    const std::int64_t copy_end = e.copy_end();
    const std::uint8_t* const padded_table = padded_codes().data();
    const bool flip = kOut == Outputs::all ? mirrored_ != out.reverse_winding : mirrored_;
    // the short tilings' offsets for this row's parity: from `id_base` (IdRows' slot 0)
    // (none on grids too wide for them: short_count_ is then -1 for every code)
    const std::uint16_t* const short_offsets =
        short_offsets_.empty() ? nullptr
                               : short_offsets_.data() + static_cast<std::size_t>((j & 1) | (k & 1) << 1) * 256 * 3 * kShortTiling;
    const std::uint32_t* const id_base = s.ids.base();
    tri = e.off.first_triangle + r.t0;
    // The case codes come from the same flags as the edge ids of row_ids, so a tiling's edges
    // are crossed edges, whose slots row_ids wrote.
    for (std::int64_t w = r.lo / 64; w < (r.hi + 63) / 64; ++w) {
      const CellCodes cell_codes(f00, f10, f01, f11, w);
      for (Word bits = crossed_cells(f00, f10, f01, f11, w, x_valid_[static_cast<std::size_t>(w)]); bits != 0;
           bits &= bits - 1) {
        const int bit = std::countr_zero(bits);
        const std::int64_t i = 64 * w + bit;
        const unsigned code = cell_codes(bit);
        const auto t0 = static_cast<std::size_t>(tri - out.first_triangle);
        std::uint32_t* o = &out.triangles[t0 * 3];
        int count = short_count_[code]; // triangles written
        if (count >= 0 && tri + kShortTiling <= copy_end) {
            // most cells: a fixed short tiling, 3 * kShortTiling ids, the ones past the
            // tiling overwritten by the next cells (no loop whose length the branch
            // predictor has to guess); copy_end bounds the triangles
            const std::uint16_t* offset = short_offsets + static_cast<std::size_t>(code) * 3 * kShortTiling;
            const std::uint32_t* at = id_base + 3 * i;
            for (int q = 0; q < 3 * kShortTiling; ++q) o[q] = at[offset[q]];
        } else {
            count = emit_cell(i, j, k, code, edge_ids, padded_table, r, e, tri, o, vertex, decision);
        }
        if (flip) {
            for (int q = 0; q < 3 * count; q += 3) std::swap(o[q + 1], o[q + 2]);
        }
        if constexpr (kOut == Outputs::all) {
            if (out.triangle_cells) {
                const std::int64_t cell = whole_cell(i, j, k);
                for (int q = 0; q < count; ++q) out.triangle_cells[t0 + static_cast<std::size_t>(q)] = cell;
            }
        }
        tri += count;
      }
    }
}

template <class T>
int RangeExtractor<T>::emit_cell(std::int64_t i, std::int64_t j, std::int64_t k, unsigned code, const std::uint32_t* const* edge_ids,
              const std::uint8_t* padded_table, const RowSpan& r, const Emit& e,
              std::int64_t tri, std::uint32_t* o, std::int64_t& vertex, std::size_t& decision) const
{
    const std::vector<std::uint8_t>& decisions = e.c.t_.decisions;
    const detail::Tiling* tl = fixed_tiling_[code];
    if (tl == nullptr) {
        tl = decision < decisions.size() ? replay(code, decisions[decision]) : nullptr;
        ++decision;
    }
    if (tl == nullptr || vertex + tl->interior_count > e.off.first_vertex + r.v1 ||
        tri + tl->triangle_count > e.off.first_triangle + r.t1) {
        throw_mismatch("cells", j, k); // before writing past the row's part of the output
    }
    const std::uint8_t* codes = &detail::kTriangleCodes[static_cast<std::size_t>(tl->first_triangle) * 3];
    const int n = 3 * tl->triangle_count;
    if (tl->interior_count == 0) {
        if (tl->triangle_count <= kShortTiling && tri + kShortTiling <= e.copy_end()) {
            // as for the fixed short tilings in emit_row_cells
            const std::uint8_t* padded = &padded_table[static_cast<std::size_t>(tl->first_triangle) * 3];
            for (int q = 0; q < 3 * kShortTiling; ++q) o[q] = edge_ids[padded[q]][3 * i];
        } else {
            for (int q = 0; q < n; ++q) o[q] = edge_ids[codes[q]][3 * i];
        }
    } else {
        const std::int64_t first_interior = vertex;
        write_interior_vertices(i, j, k, *tl, vertex, e);
        vertex += tl->interior_count;
        for (int q = 0; q < n; ++q) {
            const int v = codes[q];
            o[q] = v < 12 ? edge_ids[v][3 * i] : static_cast<std::uint32_t>(first_interior + (v - 12));
        }
    }
    return tl->triangle_count;
}

#define CMC33_INSTANTIATE(T) \
    template void RangeExtractor<T>::emit(const RangeCounts&, const RangeOffsets&, const MeshSpans&, Ticker*) const; \
    template void RangeExtractor<T>::build_short_tilings(); \
    template double RangeExtractor<T>::min_crossing(const Index3&, const Vec3&, const Mat3&);
CMC33_FOR_EACH_SAMPLE_TYPE(CMC33_INSTANTIATE)
#undef CMC33_INSTANTIATE

} // namespace cmc33::detail
