// The topology a level set of the trilinear interpolant must have, from the samples alone.
//
// Independence: this file and field_cell.* / field_exact.hpp include nothing from src/core or
// src/tables. Everything is derived from the trilinear interpolant f of the samples.
//
// ================================ The method, and why it is right ================================
// Cells are unit cubes in index space (spacing does not change topology). Values are read as
// a = v - iso. The sign rule (a value equal to iso counts as above) makes S the level set at
// iso - eps for every small enough eps > 0; at such a level S is a compact surface with boundary
// on the box, and every decision below is made exactly (field_exact.hpp: a floating-point filter,
// then exact expansion arithmetic), in the limit eps -> 0+. "Above" means a >= 0, "below" a < 0.
//
// (F1) Faces. On a grid face f is bilinear. S crosses every grid edge whose ends are on different
//   sides, once (f is linear on an edge). A face has 0, 2 or 4 crossings; with 4 (above corners
//   diagonal) the arcs follow the asymptotic decider: the above corners are joined iff the saddle
//   value (AC - BD)/(A + C - B - D) is above, i.e. iff AC - BD >= 0 for A, C the above diagonal
//   (the denominator is then > 0). In the limit eps -> 0+ a saddle exactly at iso is above.
//   Both cells of a face read the same four values and the predicate is exact, so they agree.
//   The arcs of a cell's six faces form its loops (field_cell: cell_loops).
//
// (F2) No closed pieces, no extrema. f is harmonic in a cell (f_xx = f_yy = f_zz = 0), bilinear
//   on faces, linear on edges. By the maximum principle every component of {f >= c} or {f < c}
//   in a box (cell, sub-box, face or slice) reaches the boundary, and going down one dimension at
//   a time, contains a corner. Every piece of S in a cell meets the cell's boundary.
//
// (F3) Interior connectivity by a sweep along z. Slice the cell by the planes z = t. On the slice
//   f is bilinear with corner values a_q(t) = A_q + t (B_q - A_q) on the four z-edges q.
//   By (F2) every component of a slice's above set contains a slice corner, i.e. a point of a
//   z-edge, and a z-edge's above part is one interval. So the components of U = {f >= iso} in the
//   cell are the classes of the z-edges under "joined in some slice", and joined-in-a-slice is
//   either along a slice side (the two z-edges share a vertical face: that is the face's own
//   connectivity, from (F1)) or across the slice's diagonal. For the diagonal pair (j, k) with
//   (m, n) the other pair, N(t) = a_j a_k - a_m a_n: on a slice where j, k are above and m, n
//   below, the saddle value is N / (a_j + a_k - a_m - a_n) with a positive denominator, so j and
//   k are joined there iff N(t) >= 0; where m or n is above too, j and k are joined through it
//   (and N >= 0 or the face relations already join them). Hence
//       W(j, k) = exists t in [0, 1]: a_j(t) >= 0, a_k(t) >= 0, N(t) >= 0.
//   N is a quadratic: its maximum over the interval [lo, hi] where a_j, a_k >= 0 is at an end or
//   at the vertex, inside iff N'(lo) > 0 > N'(hi) with N concave, where it is >= 0 iff the
//   discriminant is >= 0. Every end is 0, 1 or a crossing tau_q = A_q / (A_q - B_q); all these
//   signs are polynomials of degree <= 4 in the values (field_cell: Sweep), decided exactly.
//   The below set L = {f < iso} is the same with strict inequalities (W': a_j, a_k < 0, N > 0).
//   Limit: W and the face relations are closed conditions that only get easier as every a grows
//   by eps; W' and its face relations are open conditions; in both cases the classes at eps = 0
//   (with >= for above, > for below-joined) equal the classes for every small eps > 0 (where W
//   holds at eps = 0 with m, n below, N grows by eps (a_j + a_k - a_m - a_n) > 0; where m is
//   above, j, m, k are joined by the face relations; W' symmetric).
//   This is Chernyaev's plane test done on the interval where the slice really is ambiguous with
//   that diagonal, which is what makes it right where C13 Sec. 5.1 shows the original fails.
//
// (F4) Pieces. The cell minus S is U and L; each piece of S is a properly embedded connected
//   surface in a ball, so it separates it in two: the graph whose nodes are the components of U
//   and L and whose edges are the pieces is a tree. Hence #pieces = #U + #L - 1 (checked), and a
//   piece is named by the pair (component of U, component of L) it separates. A loop lies on one
//   piece; its above side is the component of an above end of any crossed edge on it, its below
//   side that of the below end.
//
// (F5) Every piece is a disc or a tube (genus 0, one or two loops), so chi(S in cell) =
//   sum over pieces of (2 - loops). Proof sketch: sweep a piece P by z. A slice of S is at most two
//   arcs (a bilinear level curve in a square: at most two hyperbola branches, each monotone, so
//   each meets the square in one arc; no closed curves by (F2)). chi(P) = (arcs of P at z = 0)
//   + (births of arcs at z-edges) - (saddles), where a saddle is a point of P at which the slice's
//   saddle lies on the level: N(t) = 0 for the shifted slice numerator, a quadratic not identically
//   zero at a regular level, so at most two. A saddle needs two arcs of P just below it, so P had
//   at least two starts before its first saddle: chi(P) >= 0. A connected orientable surface with
//   b >= 1 boundary loops and chi = 2 - 2g - b >= 0 has g = 0 and b <= 2. (This agrees with the
//   classification of trilinear level sets in a cell: Nielson 2003, Lopes and Brodlie 2003.)
//   The code checks that every piece has one or two loops.
//
// (F6) Cross-check by refinement, independent of (F3)-(F5)'s algebra. A trilinear function
//   restricted to a sub-box is the trilinear interpolant of its values at the sub-box corners, so a
//   refined grid has the same S. A (sub-)box whose boundary carries at most one loop holds at most
//   one piece, a disc (F2, F5). Other boxes are split 2 x 2 x 2 (adaptively, down to
//   1 / max_refinement, at most 1/1024) and glued: pieces are classes of the crossed sub-edges,
//   chi(box) = sum chi(children) - arcs on the children's faces + crossed sub-edges (each once).
//   Sub-face decisions use the slice through the sub-face: a sub-face with diagonal above
//   corners contains its slice's saddle (otherwise the bilinear function would be monotone in one
//   direction on it), whose value has the sign of the slice numerator on the main diagonal and the
//   opposite on the other. Point values at dyadic points are decided exactly. When the
//   refinement settles the cell, its pieces and chi must equal (F3)-(F5)'s, else the cell is
//   reported undetermined (that would be a bug). Near-ties (a body saddle at or very near iso,
//   a whole curve of critical points at iso, common with integer data) never settle: there the
//   exact analysis stands alone.
//
// (F7) Assembly, by additivity of the Euler characteristic with compact support over the open
//   cells, open faces and open edges of the grid (S meets no grid vertex): the part of S in an
//   open cell has chi_c = chi(S in cell) - chi(its loops) = chi(S in cell); an open arc has -1, a
//   point +1. So chi(S) = sum over cells of chi(S in cell) - arcs over all grid faces (each once)
//   + crossed grid edges. b0: classes of the crossed grid edges, uniting the crossings of each
//   loop (which contains its faces' arcs) and the loops of each piece. b2: classes with no
//   crossing on the box's boundary. boundary_loops: classes of the crossings on the box's
//   boundary linked by the arcs of the boundary faces (each such crossing has two such arcs, so
//   the classes are closed curves). b1 = b0 + b2 - chi, since S is a compact orientable surface.
//
// Cost: one pass over the samples to find the rows of cells that are all above or all below (skipped),
// then one over the other cells; a cell with one loop costs a table lookup. Working memory is two
// planes of edge ids plus 9 bytes per crossed grid edge; no allocation per cell except on the
// rare exact-arithmetic fallback (ties).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include "cmc33/topology.hpp"
#include "field_cell.hpp"

namespace cmc33 {
namespace topology::detail {
namespace {

// Union-find over crossed grid edges, numbered as they are met.
class EdgeSets {
public:
    std::uint32_t add()
    {
        if (parent_.size() >= std::numeric_limits<std::uint32_t>::max()) {
            throw Error(Status::too_large,
                        "field_topology: more than 2^32 - 1 crossed grid edges; expected fewer");
        }
        const auto id = static_cast<std::uint32_t>(parent_.size());
        parent_.push_back(id);
        return id;
    }
    std::uint32_t find(std::uint32_t x)
    {
        while (parent_[x] != x) {
            parent_[x] = parent_[parent_[x]];
            x = parent_[x];
        }
        return x;
    }
    void unite(std::uint32_t a, std::uint32_t b)
    {
        a = find(a);
        b = find(b);
        if (a < b) parent_[b] = a;
        if (b < a) parent_[a] = b;
    }
    std::size_t size() const noexcept { return parent_.size(); }

private:
    std::vector<std::uint32_t> parent_;
};

struct CodeInfo {
    unsigned crossed[256];
    unsigned ambiguous[256];
};
constexpr CodeInfo make_code_info()
{
    CodeInfo info{};
    for (unsigned code = 0; code < 256; ++code) {
        info.crossed[code] = crossed_edges(code);
        info.ambiguous[code] = ambiguous_faces(code);
    }
    return info;
}
constexpr CodeInfo kCodeInfo = make_code_info();

int popcount(unsigned x) noexcept
{
    int n = 0;
    for (; x != 0; x &= x - 1) ++n;
    return n;
}

class Assembler {
public:
    Assembler(const Index3& dims, int max_refinement)
        : nx_(dims[0]), ny_(dims[1]), nz_(dims[2]), max_refinement_(max_refinement),
          plane_(static_cast<std::size_t>(nx_ * ny_))
    {
        lower_.assign(2 * plane_, kNone);
        upper_.assign(2 * plane_, kNone);
        z_.assign(plane_, kNone);
    }

    void begin_slab(std::int64_t k)
    {
        if (k > 0) {
            lower_.swap(upper_);
            std::fill(upper_.begin(), upper_.end(), kNone);
            std::fill(z_.begin(), z_.end(), kNone);
        }
    }

    // Adds one cell that S crosses; false (with `why`) when it cannot be decided.
    bool add_cell(const CellInput& in, unsigned code, std::int64_t i, std::int64_t j,
                  std::int64_t k)
    {
        Numerics numerics;
        const unsigned crossed = kCodeInfo.crossed[code];
        const unsigned face_bits =
            kCodeInfo.ambiguous[code] != 0 ? face_decisions(in, code, numerics) : 0u;
        const CellLoops& loops = cell_loops(code, face_bits);

        std::uint32_t id[12] = {};
        for (int e = 0; e < 12; ++e) {
            if (((crossed >> e) & 1u) != 0) id[e] = edge_id(e, i, j, k);
        }
        for (int e = 0; e < 12; ++e) {
            if (((crossed >> e) & 1u) != 0) {
                sets_.unite(id[loops.rep_edge[loops.loop_of_edge[e]]], id[e]);
            }
        }

        if (loops.loops == 1) {
            euler_cells_ += 1; // (F5) one loop: one disc
        } else {
            const CellPieces pieces = cell_pieces(in, code, face_bits, max_refinement_, numerics);
            if (pieces.status != CellPieces::Status::ok) {
                why_ = cell_name(i, j, k) + reason(pieces);
                return false;
            }
            euler_cells_ += pieces.euler;
            for (int a = 0; a < loops.loops; ++a) {
                for (int b = 0; b < a; ++b) {
                    if (pieces.piece_of_loop[a] == pieces.piece_of_loop[b]) {
                        sets_.unite(id[loops.rep_edge[a]], id[loops.rep_edge[b]]);
                    }
                }
            }
        }
        if (numerics.lost) {
            why_ = cell_name(i, j, k) + reason_lost();
            return false;
        }

        // Faces owned by this cell: its three lower faces, and its upper faces on the box's far
        // sides; each grid face is counted once.
        const bool last[3] = {i + 2 == nx_, j + 2 == ny_, k + 2 == nz_};
        const bool first[3] = {i == 0, j == 0, k == 0};
        for (int f = 0; f < 6; ++f) {
            const int axis = f / 2;
            const bool upper = (f % 2) != 0;
            if (upper && !last[axis]) continue;
            arcs_ += popcount(crossed & face_edge_mask(f)) / 2;
            if (upper ? last[axis] : first[axis]) {
                int arcs[2][2];
                const int n = face_arcs(code, f, ((face_bits >> f) & 1u) != 0, arcs);
                for (int a = 0; a < n; ++a) boundary_sets_.unite(id[arcs[a][0]], id[arcs[a][1]]);
            }
        }
        return true;
    }

    const std::string& why() const noexcept { return why_; }

    FieldTopology finish()
    {
        FieldTopology out;
        out.determined = true;
        const std::size_t n = sets_.size();
        out.euler = euler_cells_ - arcs_ + static_cast<std::int64_t>(n);
        std::vector<std::uint8_t> root_touches(n, 0);
        for (std::size_t x = 0; x < n; ++x) {
            const auto id = static_cast<std::uint32_t>(x);
            if (on_boundary_[x] != 0) root_touches[sets_.find(id)] = 1;
        }
        for (std::size_t x = 0; x < n; ++x) {
            const auto id = static_cast<std::uint32_t>(x);
            if (sets_.find(id) != id) continue;
            ++out.b0;
            if (root_touches[x] == 0) ++out.b2;
        }
        for (std::size_t x = 0; x < n; ++x) {
            const auto id = static_cast<std::uint32_t>(x);
            if (on_boundary_[x] != 0 && boundary_sets_.find(id) == id) ++out.boundary_loops;
        }
        out.b1 = out.b0 + out.b2 - out.euler;
        return out;
    }

private:
    static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

    // Id of the crossed grid edge that is edge e of cell (i, j, k), numbered on first sight.
    std::uint32_t edge_id(int e, std::int64_t i, std::int64_t j, std::int64_t k)
    {
        const int axis = e / 4;
        const int c0 = kEdgeCorners[e][0];
        const std::int64_t x = i + (c0 & 1);
        const std::int64_t y = j + ((c0 >> 1) & 1);
        const std::int64_t z = k + (c0 >> 2);
        const auto in_plane = static_cast<std::size_t>(y * nx_ + x);
        std::uint32_t& slot =
            axis == 2 ? z_[in_plane] : ((z == k) ? lower_ : upper_)[axis * plane_ + in_plane];
        if (slot == kNone) {
            slot = sets_.add();
            boundary_sets_.add();
            const std::int64_t coord[3] = {x, y, z};
            const std::int64_t size[3] = {nx_, ny_, nz_};
            bool boundary = false;
            for (int b = 0; b < 3; ++b) {
                if (b != axis && (coord[b] == 0 || coord[b] == size[b] - 1)) boundary = true;
            }
            on_boundary_.push_back(boundary ? 1 : 0);
        }
        return slot;
    }

    static std::string cell_name(std::int64_t i, std::int64_t j, std::int64_t k)
    {
        return "field_topology: cell (" + std::to_string(i) + ", " + std::to_string(j) + ", " +
               std::to_string(k) + "): ";
    }
    static std::string reason_lost()
    {
        return "values out of range for the exact predicates (a product under- or overflowed); "
               "expected magnitudes within about 2^-200..2^200";
    }
    static std::string reason(const CellPieces& p)
    {
        switch (p.status) {
        case CellPieces::Status::lost_precision: return reason_lost();
        case CellPieces::Status::inconsistent:
            return "interior analysis found " + std::to_string(p.pieces) + " pieces on " +
                   std::to_string(p.loops) +
                   " loops, which is not a set of discs and tubes (a bug in the verifier)";
        case CellPieces::Status::disagreement:
            return "exact analysis (euler " + std::to_string(p.euler) + ", " +
                   std::to_string(p.pieces) + " pieces) and refinement (euler " +
                   std::to_string(p.refined_euler) + ", " + std::to_string(p.refined_pieces) +
                   " pieces) disagree (a bug in the verifier)";
        case CellPieces::Status::ok: break;
        }
        return "undetermined";
    }

    std::int64_t nx_, ny_, nz_;
    int max_refinement_;
    std::size_t plane_;
    std::vector<std::uint32_t> lower_, upper_, z_; // ids of x/y-edges at z = k, k + 1; z-edges
    EdgeSets sets_;
    EdgeSets boundary_sets_;
    std::vector<std::uint8_t> on_boundary_;
    std::int64_t euler_cells_ = 0;
    std::int64_t arcs_ = 0;
    std::string why_;
};

std::string format_dims(const Index3& d)
{
    return std::to_string(d[0]) + "x" + std::to_string(d[1]) + "x" + std::to_string(d[2]);
}

void check_arguments(bool null_data, const Index3& dims, double iso)
{
    if (dims[0] < 2 || dims[1] < 2 || dims[2] < 2) {
        throw Error(Status::invalid_argument, "field_topology: grid of " + format_dims(dims) +
                                                  " samples; expected at least 2 on each axis");
    }
    if (null_data) {
        throw Error(Status::invalid_argument,
                    "field_topology: grid has no data pointer; expected samples");
    }
    if (!std::isfinite(iso)) {
        throw Error(Status::non_finite,
                    "field_topology: iso is " + std::to_string(iso) + "; expected a finite value");
    }
}

template <class T> void check_finite(const GridView<T>& grid)
{
    if constexpr (std::is_floating_point_v<T>) {
        std::int64_t count = 0;
        Index3 first{-1, -1, -1};
        for (std::int64_t k = 0; k < grid.nz(); ++k) {
            for (std::int64_t j = 0; j < grid.ny(); ++j) {
                for (std::int64_t i = 0; i < grid.nx(); ++i) {
                    if (!std::isfinite(grid(i, j, k)) && count++ == 0) first = {i, j, k};
                }
            }
        }
        if (count > 0) {
            throw Error(Status::non_finite,
                        "field_topology: " + std::to_string(count) +
                            " samples are NaN or infinite, the first at (" +
                            std::to_string(first[0]) + ", " + std::to_string(first[1]) + ", " +
                            std::to_string(first[2]) + "); expected finite samples");
        }
    }
}

/// f[i] = 1 if sample i of the row at r (stride sx) is above iso (the sign rule: >=, as
/// cell_code), else 0. Integers compare with ceil(iso) in their own type: the same answers, and
/// a contiguous row is a loop the compiler vectorises.
template <class T> void above_flags(const T* r, std::int64_t n, std::int64_t sx, double iso, std::uint8_t* f)
{
    if constexpr (std::is_integral_v<T>) {
        if (iso > static_cast<double>(std::numeric_limits<T>::max()) || iso <= static_cast<double>(std::numeric_limits<T>::lowest())) {
            std::fill(f, f + n, static_cast<std::uint8_t>(iso <= static_cast<double>(std::numeric_limits<T>::lowest())));
            return;
        }
        const auto threshold = static_cast<T>(std::ceil(iso)); // within T's range: lowest < iso <= max
        if (sx == 1) {
            for (std::int64_t i = 0; i < n; ++i) f[i] = static_cast<std::uint8_t>(r[i] >= threshold);
        } else {
            for (std::int64_t i = 0; i < n; ++i) f[i] = static_cast<std::uint8_t>(r[i * sx] >= threshold);
        }
    } else {
        for (std::int64_t i = 0; i < n; ++i) f[i] = static_cast<std::uint8_t>(static_cast<double>(r[i * sx]) >= iso);
    }
}

} // namespace
} // namespace topology::detail

template <class T> FieldTopology field_topology(const GridView<T>& grid, double iso,
                                                const FieldTopologyOptions& options)
{
    using namespace topology::detail;
    check_arguments(grid.data == nullptr, grid.dims, iso);
    check_finite(grid);

    Assembler assembler(grid.dims, options.max_refinement);
    const std::int64_t sx = grid.strides[0]; // any stride: a view of a larger or reordered array
    // Each sample row's above-flags (the sign rule, as cell_code), and its side of iso: all above,
    // all below, or mixed. A row of cells whose four sample rows are all above or all below holds
    // no crossed cell (most rows of a CT volume); in the others a cell's code comes from the
    // flags, and only crossed cells read their values.
    enum : std::uint8_t { kRowBelow = 1, kRowAbove = 2 };
    const std::int64_t nx = grid.nx(), ny = grid.ny(), nz = grid.nz();
    std::vector<std::uint8_t> row_side(static_cast<std::size_t>(ny * nz));
    std::vector<std::uint8_t> flags(static_cast<std::size_t>(nx * ny * 2)); // two slices of rows
    const auto flags_of = [&](std::int64_t j, std::int64_t k) {
        return &flags[static_cast<std::size_t>(nx * (j + ny * (k % 2)))];
    };
    const auto classify_slice = [&](std::int64_t k) {
        for (std::int64_t j = 0; j < ny; ++j) {
            std::uint8_t* f = flags_of(j, k);
            above_flags(grid.data + grid.offset(0, j, k), nx, sx, iso, f);
            unsigned any = 0, all = 1;
            for (std::int64_t i = 0; i < nx; ++i) {
                any |= f[i];
                all &= f[i];
            }
            row_side[static_cast<std::size_t>(j + ny * k)] = static_cast<std::uint8_t>((all ? kRowAbove : 0) | (any ? 0 : kRowBelow));
        }
    };
    classify_slice(0);
    for (std::int64_t k = 0; k + 1 < nz; ++k) {
        classify_slice(k + 1);
        assembler.begin_slab(k);
        for (std::int64_t j = 0; j + 1 < ny; ++j) {
            const auto side = [&](std::int64_t jj, std::int64_t kk) { return row_side[static_cast<std::size_t>(jj + ny * kk)]; };
            if ((side(j, k) & side(j + 1, k) & side(j, k + 1) & side(j + 1, k + 1)) != 0) continue;
            const T* r0 = grid.data + grid.offset(0, j, k);         // (., j,     k    )
            const T* r1 = grid.data + grid.offset(0, j + 1, k);     // (., j + 1, k    )
            const T* r2 = grid.data + grid.offset(0, j, k + 1);     // (., j,     k + 1)
            const T* r3 = grid.data + grid.offset(0, j + 1, k + 1); // (., j + 1, k + 1)
            const std::uint8_t *f0 = flags_of(j, k), *f1 = flags_of(j + 1, k), *f2 = flags_of(j, k + 1),
                               *f3 = flags_of(j + 1, k + 1);
            for (std::int64_t i = 0; i + 1 < nx; ++i) {
                const unsigned quick = f0[i] | f0[i + 1] << 1 | f1[i] << 2 | f1[i + 1] << 3 | f2[i] << 4 |
                                       f2[i + 1] << 5 | f3[i] << 6 | f3[i + 1] << 7;
                if (quick == 0 || quick == 255) continue;
                CellInput in;
                in.iso = iso;
                in.v[0] = static_cast<double>(r0[i * sx]);
                in.v[1] = static_cast<double>(r0[(i + 1) * sx]);
                in.v[2] = static_cast<double>(r1[i * sx]);
                in.v[3] = static_cast<double>(r1[(i + 1) * sx]);
                in.v[4] = static_cast<double>(r2[i * sx]);
                in.v[5] = static_cast<double>(r2[(i + 1) * sx]);
                in.v[6] = static_cast<double>(r3[i * sx]);
                in.v[7] = static_cast<double>(r3[(i + 1) * sx]);
                const unsigned code = cell_code(in);
                if (!assembler.add_cell(in, code, i, j, k)) {
                    FieldTopology undetermined;
                    undetermined.why = assembler.why();
                    return undetermined;
                }
            }
        }
    }
    return assembler.finish();
}

FieldTopology field_topology(const Volume& volume, double iso, const FieldTopologyOptions& options)
{
    return volume.visit([&](auto view) { return field_topology(view, iso, options); });
}

template FieldTopology field_topology<std::int8_t>(const GridView<std::int8_t>&, double,
                                                   const FieldTopologyOptions&);
template FieldTopology field_topology<std::uint8_t>(const GridView<std::uint8_t>&, double,
                                                    const FieldTopologyOptions&);
template FieldTopology field_topology<std::int16_t>(const GridView<std::int16_t>&, double,
                                                    const FieldTopologyOptions&);
template FieldTopology field_topology<std::uint16_t>(const GridView<std::uint16_t>&, double,
                                                     const FieldTopologyOptions&);
template FieldTopology field_topology<std::int32_t>(const GridView<std::int32_t>&, double,
                                                    const FieldTopologyOptions&);
template FieldTopology field_topology<std::uint32_t>(const GridView<std::uint32_t>&, double,
                                                     const FieldTopologyOptions&);
template FieldTopology field_topology<float>(const GridView<float>&, double,
                                             const FieldTopologyOptions&);
template FieldTopology field_topology<double>(const GridView<double>&, double,
                                              const FieldTopologyOptions&);

} // namespace cmc33
