// cmc33.dask's per-block extraction: one block of a chunked array (its cells plus the halo they
// need) through count, scan and emit (cmc33/passes.hpp), placed in the whole array
// (MeshSpans::index_offset and whole_dims), so that the library writes each vertex's position as
// the whole-array extraction writes it, bit for bit. The block keeps the triangles of the cells it
// owns and gives each vertex its global key, so that the driver merges blocks by key alone.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "binding.hpp"

#include "cmc33/cmc33.hpp"
#include "cmc33/passes.hpp"

namespace cmc33::python {
namespace {

using I64 = std::int64_t;

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
    grid.spacing = a.spacing;
    grid.origin = a.origin;
    grid.direction = kIdentity3;
    ExtractOptions options;
    options.method = a.method;
    options.threads = 1;
    RangeCounts counts = count(grid, a.iso, options, 0, grid.nz());
    BlockResult r;
    r.sample_bound = counts.sample_bound();
    if (a.bound > 0) counts.share_sample_bound(a.bound);
    const auto nv = static_cast<std::size_t>(counts.vertex_count());
    const auto nt = static_cast<std::size_t>(counts.triangle_count());
    // the block's arrays are its worker's largest: sized once, and compacted in place below
    r.positions.resize(nv * 3);
    r.triangles.resize(nt * 3);
    r.keys.resize(nv); // the vertices' grid edges first (MeshSpans::vertex_edges), keys after
    std::vector<I64> cells(nt);
    if (a.normals) r.normals.resize(nv * 3);
    MeshSpans spans;
    spans.positions = r.positions.data();
    spans.triangles = r.triangles.data();
    spans.normals = a.normals ? r.normals.data() : nullptr;
    spans.vertex_edges = r.keys.data();
    spans.triangle_cells = cells.data();
    spans.index_offset = a.lower;
    spans.whole_dims = a.dims;
    emit(grid, a.iso, options, counts, RangeOffsets{}, spans);

    // the owned cells' triangles, in order (cells are the whole array's: i + NX * (j + NY * k))
    const I64 NX = a.dims[0], NY = a.dims[1];
    I64 first[3], end[3];
    for (std::size_t d = 0; d < 3; ++d) first[d] = a.lower[d] + a.own_lo[d], end[d] = a.lower[d] + a.own_hi[d];
    constexpr std::uint32_t kUnused = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::uint32_t> index(nv, kUnused);
    std::size_t kept_triangles = 0;
    I64 last_cell = -1;
    bool last_owned = false;
    for (std::size_t f = 0; f < nt; ++f) {
        const I64 c = cells[f];
        if (c != last_cell) { // a cell's triangles are consecutive
            const I64 g[3] = {c % NX, (c / NX) % NY, c / (NX * NY)};
            last_owned = true;
            for (std::size_t d = 0; d < 3; ++d) last_owned &= g[d] >= first[d] && g[d] < end[d];
            last_cell = c;
        }
        if (!last_owned) continue;
        for (std::size_t e = 0; e < 3; ++e) {
            const std::uint32_t v = r.triangles[f * 3 + e];
            index[v] = 0; // used; numbered below in vertex order
            r.triangles[kept_triangles * 3 + e] = v;
        }
        ++kept_triangles;
    }
    r.triangles.resize(kept_triangles * 3);
    cells = {};

    const auto used = static_cast<std::size_t>(std::count_if(index.begin(), index.end(), [](std::uint32_t id) { return id != kUnused; }));
    r.flags.reserve(used);
    I64 previous_cell = std::numeric_limits<I64>::min();
    I64 q = 0; // rank of an interior vertex in its cell
    std::uint32_t kept = 0;
    for (std::size_t v = 0; v < nv; ++v) {
        const I64 edge = r.keys[v];
        I64 key = 0;
        std::uint8_t flag = kOwned;
        if (edge < 0) {
            const I64 c = -1 - edge; // an interior vertex: only its cell's block has it
            q = c == previous_cell ? q + 1 : 0;
            previous_cell = c;
            key = -1 - (c * 32 + q);
        } else {
            previous_cell = std::numeric_limits<I64>::min();
            const I64 s = edge / 3;
            const I64 g[3] = {s % NX, (s / NX) % NY, s / (NX * NY)};
            for (std::size_t d = 0; d < 3; ++d) {
                const I64 cell = std::min(g[d], a.dims[d] - 2);
                if (cell < first[d] || cell >= end[d]) flag = 0;
                if (g[d] == first[d] && first[d] > 0) flag |= kExported;
            }
            if (!(flag & kOwned)) flag = 0;
            key = edge;
        }
        if (index[v] == kUnused) continue;
        // kept <= v: each array moves down in place
        r.keys[kept] = key;
        r.flags.push_back(flag);
        for (std::size_t d = 0; d < 3; ++d) r.positions[kept * 3 + d] = r.positions[v * 3 + d];
        if (a.normals) {
            for (std::size_t d = 0; d < 3; ++d) r.normals[kept * 3 + d] = r.normals[v * 3 + d];
        }
        index[v] = kept++;
    }
    r.keys.resize(kept);
    r.positions.resize(std::size_t{kept} * 3);
    if (a.normals) r.normals.resize(std::size_t{kept} * 3);
    for (std::uint32_t& t : r.triangles) t = index[t];
    return r;
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
