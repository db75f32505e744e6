// cmc33.dask's per-block extraction: one block of a chunked array (its cells plus the halo they
// need) through count, scan and emit (cmc33/passes.hpp), keeping the triangles of the cells the
// block owns and giving each vertex a global key and the position the whole-array extraction
// writes, bit for bit, so that the driver merges blocks by key alone.
//
// Why positions are recomputed: the library writes float(origin + spacing * (index + u)) with
// index + u summed in double for the global index, where u is the vertex's place in its cell (an
// edge's crossing parameter, or an interior vertex's unit coordinates). A block's own extraction
// sums the local index instead, which rounds differently. So an edge vertex's crossing is computed
// again as the extractor computes it (vertices.hpp, crossing(); the same clamp delta as the whole
// grid, min_crossing()), and an interior vertex's unit coordinates are read back from
// extractions of its single cell at origins that subtract what is already known: each gives the
// next 24 bits of the double, three give all of it.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "binding.hpp"

#include "cmc33/cmc33.hpp"
#include "cmc33/passes.hpp"

namespace cmc33::python {
namespace {

using I64 = std::int64_t;
constexpr double kMinCrossing = 0x1p-10; // the extractor's default clamp (src/core/placement.hpp)

/// The extractor's clamp delta for a grid with identity direction (vertices.hpp, min_crossing).
double grid_delta(const Index3& dims, const Vec3& spacing, const Vec3& origin)
{
    double largest = 0, shortest = std::numeric_limits<double>::infinity();
    for (std::size_t a = 0; a < 3; ++a) {
        const double far = origin[a] + spacing[a] * static_cast<double>(dims[a] - 1);
        largest = std::max({largest, std::fabs(origin[a]), std::fabs(far)});
        shortest = std::min(shortest, std::fabs(spacing[a]));
    }
    if (!(largest > 0) || !(shortest > 0) || !std::isfinite(largest)) return kMinCrossing;
    const double ulp = std::ldexp(1.0, std::ilogb(largest) - 23);
    return std::clamp(16 * ulp / shortest, kMinCrossing, 0.125);
}

/// The largest |world coordinate| of the grid's box (what grid_delta reads).
double box_largest(const Index3& dims, const Vec3& spacing, const Vec3& origin)
{
    double largest = 0;
    for (std::size_t a = 0; a < 3; ++a) {
        largest = std::max({largest, std::fabs(origin[a]), std::fabs(origin[a] + spacing[a] * static_cast<double>(dims[a] - 1))});
    }
    return largest;
}

/// An edge's crossing parameter as the extractor computes it (vertices.hpp, crossing()).
template <class T> double crossing(T a, T b, double iso, double delta)
{
    const double va = static_cast<double>(a), vb = static_cast<double>(b);
    const double d = vb - va;
    const double t = std::isinf(d) ? (0.5 * iso - 0.5 * va) / (0.5 * vb - 0.5 * va) : (iso - va) / d;
    return std::clamp(t, delta, 1.0 - delta);
}

struct Passes {
    std::vector<float> positions, normals;
    std::vector<std::uint32_t> triangles;
    std::vector<I64> vertex_edges, triangle_cells;
    double sample_bound = 0;
};

/// count, scan and emit over the whole grid (one range), with the grid edge of every vertex and
/// the cell of every triangle. `bound` > 0 is shared as the sample bound (normals' scaling).
template <class T> Passes run_passes(const GridView<T>& grid, double iso, Method method, bool normals, double bound)
{
    ExtractOptions options;
    options.method = method;
    options.threads = 1;
    std::vector<RangeCounts> counts;
    counts.push_back(count(grid, iso, options, 0, grid.nz()));
    Passes p;
    p.sample_bound = counts[0].sample_bound();
    if (bound > 0) counts[0].share_sample_bound(bound);
    const auto offsets = scan(counts);
    const auto nv = static_cast<std::size_t>(counts[0].vertex_count());
    const auto nt = static_cast<std::size_t>(counts[0].triangle_count());
    p.positions.resize(nv * 3);
    p.triangles.resize(nt * 3);
    p.vertex_edges.resize(nv);
    p.triangle_cells.resize(nt);
    if (normals) p.normals.resize(nv * 3);
    MeshSpans spans;
    spans.positions = p.positions.data();
    spans.triangles = p.triangles.data();
    spans.normals = normals ? p.normals.data() : nullptr;
    spans.vertex_edges = p.vertex_edges.data();
    spans.triangle_cells = p.triangle_cells.data();
    emit(grid, iso, options, counts[0], offsets[0], spans);
    return p;
}

/// The unit-cell coordinates, in double, of the interior vertices of the cell with these corner
/// values (corner c at (c & 1, c >> 1 & 1, c >> 2 & 1)), in the order the extractor numbers them.
/// Each extraction of the single cell at spacing 1 writes float(origin + u) exactly rounded; with
/// the origin at minus the sum so far it writes the next bits of u (the subtraction is exact: the
/// two are within a float step, Sterbenz), and three extractions cover the double's 53 bits.
template <class T> std::vector<std::array<double, 3>> interior_units(const std::array<T, 8>& values, double iso, Method method)
{
    std::vector<std::array<double, 3>> sums;
    for (int round = 0; round < 3; ++round) {
        Vec3 origin{0, 0, 0};
        GridView<T> cell = GridView<T>::dense(values.data(), Index3{2, 2, 2});
        if (round > 0) {
            std::vector<std::array<double, 3>> known = sums;
            // one vertex at a time when there are several: each needs its own origin
            std::vector<std::array<double, 3>> next;
            for (std::size_t q = 0; q < known.size(); ++q) {
                for (std::size_t c = 0; c < 3; ++c) origin[c] = -known[q][c];
                cell.origin = origin;
                const Passes p = run_passes(cell, iso, method, false, 0);
                std::size_t seen = 0;
                for (std::size_t v = 0; v < p.vertex_edges.size(); ++v) {
                    if (p.vertex_edges[v] >= 0) continue;
                    if (seen++ != q) continue;
                    std::array<double, 3> s = known[q];
                    for (std::size_t c = 0; c < 3; ++c) s[c] += static_cast<double>(p.positions[v * 3 + c]);
                    next.push_back(s);
                }
            }
            if (next.size() != known.size()) throw Error(Status::internal, "a cell's interior vertices changed between extractions");
            sums = std::move(next);
            continue;
        }
        const Passes p = run_passes(cell, iso, method, false, 0);
        for (std::size_t v = 0; v < p.vertex_edges.size(); ++v) {
            if (p.vertex_edges[v] >= 0) continue;
            sums.push_back({static_cast<double>(p.positions[v * 3]), static_cast<double>(p.positions[v * 3 + 1]),
                            static_cast<double>(p.positions[v * 3 + 2])});
        }
    }
    return sums;
}

/// The single-cell extractions clamp crossings at kMinCrossing: refuse a cell where the whole
/// grid's wider clamp `delta` would move one of its crossings.
template <class T> void refuse_wider_clamp(const std::array<T, 8>& values, double iso, double delta, double largest)
{
    for (int c0 = 0; c0 < 8; ++c0) {
        for (int axis = 0; axis < 3; ++axis) {
            if ((c0 >> axis) & 1) continue; // each of the 12 edges once, from its lower corner
            const T va = values[static_cast<std::size_t>(c0)], vb = values[static_cast<std::size_t>(c0 | 1 << axis)];
            if ((static_cast<double>(va) >= iso) == (static_cast<double>(vb) >= iso)) continue;
            const double t = crossing(va, vb, iso, kMinCrossing);
            if (t < delta || t > 1 - delta) {
                throw Error(Status::invalid_argument,
                            "the grid's box reaches " + std::to_string(largest) + " world units, where the extractor keeps crossings " +
                                std::to_string(delta) + " of an edge from the samples, and a cell with an interior vertex has one " +
                                "closer, which cmc33.dask cannot place as the whole-array extraction does; extract with the " +
                                "origin at 0 and add it afterwards, or extract in memory");
            }
        }
    }
}

struct BlockArgs {
    double iso = 0;
    Method method = Method::cmc33;
    Index3 lower{0, 0, 0};  ///< global index of the block's sample (0, 0, 0)
    Index3 own_lo{0, 0, 0}, own_hi{0, 0, 0}; ///< the cells the block owns, local [lo, hi)
    Index3 dims{0, 0, 0};   ///< the whole array's samples
    Vec3 spacing{1, 1, 1}, origin{0, 0, 0};
    bool normals = false;
    double bound = 0;
};

/// Vertex flags: kOwned on the copy the merge keeps (the block owning the cell at the edge's lower
/// sample, clamped into the cells: every crossed edge's cells use its vertex, so that block has
/// it); kExported on owned vertices of a block's lower faces, which the blocks below use too.
constexpr std::uint8_t kOwned = 1, kExported = 2;

struct BlockResult {
    std::vector<I64> keys;
    std::vector<std::uint8_t> flags;
    std::vector<float> positions, normals;
    std::vector<std::uint32_t> triangles;
    double sample_bound = 0;
};

template <class T> BlockResult extract_block(GridView<T> grid, const BlockArgs& a)
{
    const double delta = grid_delta(a.dims, a.spacing, a.origin);
    // The block's own frame only steers its normals' clamp delta (its positions are recomputed):
    // a corner at the whole grid's largest coordinate gives the block the same delta.
    const double largest = box_largest(a.dims, a.spacing, a.origin);
    grid.spacing = a.spacing;
    for (std::size_t c = 0; c < 3; ++c) grid.origin[c] = -0.5 * a.spacing[c] * static_cast<double>(grid.dims[c] - 1);
    grid.origin[0] = a.spacing[0] > 0 ? -largest : largest;
    grid.direction = kIdentity3;

    const Passes p = run_passes(grid, a.iso, a.method, a.normals, a.bound);
    const I64 nx = grid.nx(), ny = grid.ny();
    const auto nv = p.vertex_edges.size();
    const auto nt = p.triangle_cells.size();
    constexpr std::uint32_t kUnused = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::uint32_t> index(nv, kUnused);
    BlockResult r;
    r.sample_bound = p.sample_bound;
    const auto owned = [&](std::size_t f) {
        const I64 c = p.triangle_cells[f];
        const I64 ci = c % nx, cj = (c / nx) % ny, ck = c / (nx * ny);
        return ci >= a.own_lo[0] && ci < a.own_hi[0] && cj >= a.own_lo[1] && cj < a.own_hi[1] && ck >= a.own_lo[2] &&
               ck < a.own_hi[2];
    };
    // exact sizes first: the block's arrays are its worker's largest, and growing them doubles
    std::size_t kept_triangles = 0;
    for (std::size_t f = 0; f < nt; ++f) kept_triangles += owned(f) ? 1 : 0;
    r.triangles.reserve(kept_triangles * 3);
    for (std::size_t f = 0; f < nt; ++f) {
        if (!owned(f)) continue;
        for (std::size_t e = 0; e < 3; ++e) {
            std::uint32_t& id = index[p.triangles[f * 3 + e]];
            if (id == kUnused) id = 0; // marked used; numbered below in vertex order
            r.triangles.push_back(p.triangles[f * 3 + e]);
        }
    }
    const auto used = static_cast<std::size_t>(std::count_if(index.begin(), index.end(), [](std::uint32_t id) { return id != kUnused; }));
    r.keys.reserve(used);
    r.flags.reserve(used);
    r.positions.reserve(used * 3);
    if (a.normals) r.normals.reserve(used * 3);
    const I64 NX = a.dims[0], NY = a.dims[1];
    I64 previous_cell = std::numeric_limits<I64>::min();
    I64 units_cell = std::numeric_limits<I64>::min();
    std::size_t q = 0;                        // rank of an interior vertex in its cell
    std::vector<std::array<double, 3>> units; // units_cell's interior vertices' unit coordinates
    std::uint32_t kept = 0;
    for (std::size_t v = 0; v < nv; ++v) {
        const I64 edge = p.vertex_edges[v];
        if (edge < 0) {
            const I64 c = -1 - edge;
            q = c == previous_cell ? q + 1 : 0;
            previous_cell = c;
            if (index[v] == kUnused) continue;
            const I64 i = c % nx, j = (c / nx) % ny, k = c / (nx * ny);
            if (c != units_cell) {
                std::array<T, 8> values{};
                for (int corner = 0; corner < 8; ++corner) {
                    values[static_cast<std::size_t>(corner)] = grid(i + (corner & 1), j + (corner >> 1 & 1), k + (corner >> 2 & 1));
                }
                if (delta != kMinCrossing) refuse_wider_clamp(values, a.iso, delta, largest);
                units = interior_units(values, a.iso, a.method);
                units_cell = c;
            }
            if (q >= units.size()) throw Error(Status::internal, "a cell has more interior vertices in its block than alone");
            const I64 g[3] = {i + a.lower[0], j + a.lower[1], k + a.lower[2]};
            r.keys.push_back(-1 - ((g[0] + NX * (g[1] + NY * g[2])) * 32 + static_cast<I64>(q)));
            r.flags.push_back(kOwned); // only the cell's block has it
            for (std::size_t d = 0; d < 3; ++d) {
                const double x = static_cast<double>(g[d]) + units[q][d];
                r.positions.push_back(static_cast<float>(a.origin[d] + a.spacing[d] * x));
            }
        } else {
            previous_cell = std::numeric_limits<I64>::min();
            if (index[v] == kUnused) continue;
            const I64 axis = edge % 3, s = edge / 3;
            const I64 i = s % nx, j = (s / nx) % ny, k = s / (nx * ny);
            const T va = grid(i, j, k), vb = grid(i + (axis == 0), j + (axis == 1), k + (axis == 2));
            const double t = crossing(va, vb, a.iso, delta);
            const I64 g[3] = {i + a.lower[0], j + a.lower[1], k + a.lower[2]};
            r.keys.push_back(3 * (g[0] + NX * (g[1] + NY * g[2])) + axis);
            std::uint8_t flag = kOwned;
            for (std::size_t d = 0; d < 3; ++d) {
                const I64 first = a.lower[d] + a.own_lo[d], end = a.lower[d] + a.own_hi[d];
                const I64 cell = std::min(g[d], a.dims[d] - 2);
                if (cell < first || cell >= end) flag = 0;
                if (g[d] == first && first > 0) flag |= kExported;
            }
            r.flags.push_back(flag & kOwned ? flag : std::uint8_t{0});
            for (std::size_t d = 0; d < 3; ++d) {
                const double x = static_cast<double>(g[d]) + (static_cast<I64>(d) == axis ? t : 0.0);
                r.positions.push_back(static_cast<float>(a.origin[d] + a.spacing[d] * x));
            }
        }
        index[v] = kept++;
        if (a.normals) r.normals.insert(r.normals.end(), &p.normals[v * 3], &p.normals[v * 3 + 3]);
    }
    for (std::uint32_t& t : r.triangles) t = index[t];
    return r;
}

template <class V> py::array_t<typename V::value_type> to_numpy(V&& values, I64 columns)
{
    using E = typename V::value_type;
    auto* owned = new V(std::move(values));
    py::capsule free_when_done(owned, [](void* o) { delete static_cast<V*>(o); });
    const auto rows = columns > 0 ? static_cast<py::ssize_t>(owned->size()) / columns : static_cast<py::ssize_t>(owned->size());
    if (columns > 0) {
        return py::array_t<E>({rows, static_cast<py::ssize_t>(columns)}, owned->data(), free_when_done);
    }
    return py::array_t<E>({rows}, owned->data(), free_when_done);
}

} // namespace

void bind_blocks(py::module_& m)
{
    m.def("extract_block", [](const py::array& samples, double iso, const std::string& method, const Index3& lower,
                              const Index3& own_lo, const Index3& own_hi, const Index3& dims, const Vec3& spacing,
                              const Vec3& origin, bool normals, double bound) {
        const Samples s = samples_of(samples, "block");
        BlockArgs a{iso, parse_method(method), lower, own_lo, own_hi, dims, spacing, origin, normals, bound};
        BlockResult r;
        {
            py::gil_scoped_release nogil;
            r = visit(s, Frame{}, [&](const auto& grid) { return extract_block(grid, a); });
        }
        const double bound_out = r.sample_bound;
        py::object n = py::none();
        if (normals) n = to_numpy(std::move(r.normals), 3);
        return py::make_tuple(to_numpy(std::move(r.keys), 0), to_numpy(std::move(r.positions), 3), n,
                              to_numpy(std::move(r.triangles), 3), bound_out, to_numpy(std::move(r.flags), 0));
    }, py::arg("samples"), py::arg("iso"), py::arg("method"), py::arg("lower"), py::arg("own_lo"), py::arg("own_hi"),
       py::arg("dims"), py::arg("spacing"), py::arg("origin"), py::arg("normals"), py::arg("bound"));
}

} // namespace cmc33::python
