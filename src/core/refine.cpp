// Method cmc33-paper: C13's grid refinement (Sec. 6.2, Fig. 11); contract in refine.hpp.
//
// 1. Find the faces where two tunnels meet: every cell whose configuration can hold a tube is
//    decided as cmc33 decides it, its tiling taken from the legacy set; a tiling "lies in face f"
//    when one of its triangles has its three vertices on edges of f (only Chernyaev's tubes do,
//    where they cross an ambiguous face: tests/core/test_tables.cpp). Two cells across a face
//    that both lie in it are a shared face.
// 2. For each shared face, the saddle (u_c, v_c) of its bilinear interpolant (C13 Eq. 1) gives a
//    plane perpendicular to the face through the saddle: along the face's axis u at u_c, or along
//    v at v_c, whichever cuts the cell further from its sides. The slab of cells holding the face
//    is split there (C13 Fig. 11: the whole slice, not only the two cells).
// 3. Samples on a new plane are interpolated along its axis from the two planes around it: the
//    interpolant is linear along an axis within a cell, so every sub-cell gets its cell's
//    trilinear interpolant and the level set does not change. Each is rounded to double so that
//    its side of the isovalue (the sign rule: equal counts as above) is the exact value's: an
//    exact rational where the rounding could decide it.
// 4. Repeat on the refined grid; then extract from it and map every vertex back through the
//    planes' coordinates (piecewise linear per axis, affine in each cell) to the original index
//    space and its world frame. Normals come from the original samples' gradients (central
//    differences, one-sided at the border), trilinearly interpolated at the vertex: the same
//    normals extract() gives a vertex on an original edge.

#include "refine.hpp"

#if !defined(CMC33_WITH_GMP) || CMC33_WITH_GMP
#include <gmpxx.h>
#else
#include "cmc33/error.hpp"
#include "expansion.hpp"
#endif

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <numeric>
#include <string>
#include <type_traits>
#include <utility>

#include "cmc33/error.hpp"
#include "cube.hpp"
#include "decide.hpp"
#include "mc33_tables.hpp"
#include "sample_types.hpp"

namespace cmc33::detail {
namespace {

constexpr std::int64_t kCorner[8][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                                        {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};

/// Cube edges on face f (bit e).
unsigned face_edges(int f)
{
    const auto p = face_cycle(f);
    unsigned edges = 0;
    for (int e = 0; e < 12; ++e) {
        int on = 0;
        for (int c : p) on += (c == kEdgeCorners[e][0]) + (c == kEdgeCorners[e][1]);
        if (on == 2) edges |= 1u << e;
    }
    return edges;
}

/// Per legacy variant and tiling: the faces its triangles lie in (bit f); and per configuration,
/// whether any of its tilings lies in a face (the cells worth deciding).
struct FaceLying {
    std::vector<std::array<std::uint8_t, 3>> by_variant;
    std::array<bool, 256> config_may{};
};

const FaceLying& face_lying()
{
    static const FaceLying table = [] {
        FaceLying t;
        unsigned edges_of[6];
        for (int f = 0; f < 6; ++f) edges_of[f] = face_edges(f);
        t.by_variant.resize(kVariantOffset[256]);
        for (unsigned config = 0; config < 256; ++config) {
            for (unsigned v = kVariantOffset[config]; v < kVariantOffset[config + 1]; ++v) {
                for (int i = 0; i < 3; ++i) {
                    const Tiling& tl = kLegacyVariants[v].tilings[i];
                    std::uint8_t faces = 0;
                    for (int q = 0; q < tl.triangle_count; ++q) {
                        const std::uint8_t* tri = &kTriangleCodes[(static_cast<std::size_t>(tl.first_triangle) + q) * 3];
                        if (tri[0] >= 12 || tri[1] >= 12 || tri[2] >= 12) continue;
                        const unsigned mask = 1u << tri[0] | 1u << tri[1] | 1u << tri[2];
                        for (int f = 0; f < 6; ++f) {
                            if ((mask & edges_of[f]) == mask) faces = static_cast<std::uint8_t>(faces | 1u << f);
                        }
                    }
                    t.by_variant[v][static_cast<std::size_t>(i)] = faces;
                    t.config_may[config] = t.config_may[config] || faces != 0;
                }
            }
        }
        return t;
    }();
    return table;
}

/// The sign rule: a value equal to iso is above.
bool above(double value, double iso) { return value >= iso; }

/// a + s (b - a) rounded to a double on the same side of iso as the exact value (equal to iso
/// if the exact value is). a, b: samples on the two planes around the new one; 0 < s < 1.
double interpolate(double a, double b, double s, double iso)
{
    const double r = a + s * (b - a);
    // three roundings of at most 2^-53 of numbers below |a| + |b| each, and one more in r - iso
    const double bound = 0x1p-50 * (std::fabs(a) + std::fabs(b) + std::fabs(iso)) + std::numeric_limits<double>::denorm_min();
    if (std::fabs(r - iso) > bound) return r;
#if !defined(CMC33_WITH_GMP) || CMC33_WITH_GMP
    const mpq_class exact = mpq_class(a) + mpq_class(s) * (mpq_class(b) - mpq_class(a)) - mpq_class(iso);
    const int side = sgn(exact);
#else
    // without GMP (the WebAssembly build): the same sum in Shewchuk expansions, exact unless a
    // product underflows; then an error, never a guess
    const Expansion exact = Expansion(a) + Expansion(s) * (Expansion(b) - Expansion(a)) - Expansion(iso);
    if (exact.lost()) {
        throw Error(Status::internal, "cmc33-paper: a refined sample within rounding of the isovalue needs exact arithmetic "
                                      "beyond this build's range; a build with GMP decides it");
    }
    const int side = exact.sign();
#endif
    if (side == 0) return iso;
    if (side > 0 && !(r > iso)) return std::nextafter(iso, std::numeric_limits<double>::infinity());
    if (side < 0 && !(r < iso)) return std::nextafter(iso, -std::numeric_limits<double>::infinity());
    return r;
}

/// A plane to insert: perpendicular to an axis, between planes `slab` and `slab + 1`, a fraction
/// num / den of the way (exact, in an exact grid) or s (rounded).
struct Cut {
    std::int64_t slab = 0;
    std::int64_t num = 0, den = 1;
    double s = 0;
};

} // namespace

/// A grid of double samples with, per axis, the original index coordinate of each plane.
///
/// Exact mode: where the samples and iso are integers after scaling by a power of two (integer
/// data, integer-valued floats, dyadic isovalues: the data whose ties are common), the grid holds
/// those integers and every cut is a rational num / den of integers: scaling all samples and iso
/// by the cuts' common denominator (which changes no decision: they are signs of homogeneous
/// polynomials in value - iso) makes the new planes' samples integers too. The plane then goes
/// exactly through the face's saddle and no decision on the refined grid is left to rounding.
/// When the integers would pass 2^50 the grid falls back to rounded mode: new samples rounded to
/// the nearest double on their exact value's side of iso (interpolate()).
struct RefinedGrid {
    Index3 dims{0, 0, 0};
    std::vector<double> values;
    std::array<std::vector<double>, 3> coord;
    double iso = 0;
    bool exact = false;
    double largest = 0; ///< exact mode: the largest |sample|

    static constexpr double kExactLimit = 0x1p50;

    GridView<double> view() const { return GridView<double>::dense(values.data(), dims); }
    double at(std::int64_t i, std::int64_t j, std::int64_t k) const
    {
        return values[static_cast<std::size_t>(i + dims[0] * (j + dims[1] * k))];
    }

    template <class T> static RefinedGrid of(const GridView<T>& g, double iso)
    {
        RefinedGrid r;
        r.dims = g.dims;
        r.iso = iso;
        r.values.resize(static_cast<std::size_t>(g.dims[0] * g.dims[1] * g.dims[2]));
        std::size_t n = 0;
        for (std::int64_t k = 0; k < g.nz(); ++k)
            for (std::int64_t j = 0; j < g.ny(); ++j)
                for (std::int64_t i = 0; i < g.nx(); ++i) r.values[n++] = static_cast<double>(g(i, j, k));
        for (std::size_t a = 0; a < 3; ++a) {
            r.coord[a].resize(static_cast<std::size_t>(g.dims[a]));
            for (std::int64_t i = 0; i < g.dims[a]; ++i) r.coord[a][static_cast<std::size_t>(i)] = static_cast<double>(i);
        }
        double largest = std::fabs(iso);
        for (double v : r.values) largest = std::max(largest, std::fabs(v));
        for (double scale = 1; scale <= 0x1p30 && largest * scale <= kExactLimit; scale *= 2) {
            const auto integer = [scale](double v) { return v * scale == std::floor(v * scale); };
            if (!integer(iso) || !std::all_of(r.values.begin(), r.values.end(), integer)) continue;
            for (double& v : r.values) v *= scale; // powers of two: exact
            r.iso = iso * scale;
            r.exact = true;
            r.largest = largest * scale;
            break;
        }
        return r;
    }

    /// The cut through the saddle of shared face f, perpendicular to the face: along its axis u at
    /// u_c or along v at v_c (C13 Eq. 1), whichever lies further from the cell's sides. `along`
    /// gets the cut's axis.
    Cut saddle_cut(const SharedFace& f, int& along) const
    {
        const int u = f.axis == 0 ? 1 : 0, v = f.axis == 2 ? 1 : 2;
        const auto p = face_cycle(2 * f.axis + 1);
        double value[4];
        for (int q = 0; q < 4; ++q) {
            const int c = p[static_cast<std::size_t>(q)];
            value[q] = at(f.lower[0] + kCorner[c][0], f.lower[1] + kCorner[c][1], f.lower[2] + kCorner[c][2]);
        }
        // A..D = p00, p10, p11, p01: u_c = (A - D) / (A - B + C - D), v_c = (A - B) / (A - B + C - D)
        const double A = value[0], B = value[1], C = value[2], D = value[3];
        const auto inside = [](double s) { return std::clamp(s, std::nextafter(0.0, 1.0), std::nextafter(1.0, 0.0)); };
        const double den = A - B + C - D, su = inside((A - D) / den), sv = inside((A - B) / den);
        const bool along_u = std::min(su, 1 - su) >= std::min(sv, 1 - sv);
        along = along_u ? u : v;
        Cut cut;
        cut.slab = f.lower[static_cast<std::size_t>(along)];
        cut.s = along_u ? su : sv;
        if (exact) { // integers below 2^50: the differences are exact
            auto n = static_cast<std::int64_t>(along_u ? A - D : A - B), d = static_cast<std::int64_t>(den);
            if (d < 0) n = -n, d = -d;
            const std::int64_t g = std::gcd(n, d);
            cut.num = n / g, cut.den = d / g;
        }
        return cut;
    }

    /// Inserts the planes of `cuts` (at most one per slab) perpendicular to `axis`.
    void split(int axis, std::vector<Cut> cuts)
    {
        const auto a = static_cast<std::size_t>(axis);
        std::sort(cuts.begin(), cuts.end(), [](const Cut& x, const Cut& y) { return x.slab < y.slab; });
        std::int64_t common = 1; // the denominators' least common multiple, in exact mode
        for (const Cut& c : cuts) {
            if (!exact) break;
            const std::int64_t l = std::lcm(common, c.den);
            if (static_cast<double>(l) * std::max(largest, std::fabs(iso)) > kExactLimit) {
                exact = false; // from here on, rounded
                break;
            }
            common = l;
        }
        std::vector<std::pair<std::int64_t, const Cut*>> planes; // (old plane, cut or null)
        std::size_t next = 0;
        for (std::int64_t p = 0; p < dims[a]; ++p) {
            planes.emplace_back(p, nullptr);
            if (next < cuts.size() && cuts[next].slab == p) planes.emplace_back(p, &cuts[next++]);
        }
        Index3 nd = dims;
        nd[a] = static_cast<std::int64_t>(planes.size());
        std::vector<double> nv(static_cast<std::size_t>(nd[0] * nd[1] * nd[2]));
        std::vector<double> nc;
        for (const auto& [p, cut] : planes) {
            const double x0 = coord[a][static_cast<std::size_t>(p)];
            nc.push_back(cut == nullptr ? x0 : x0 + cut->s * (coord[a][static_cast<std::size_t>(p) + 1] - x0));
        }
        const double scale = exact ? static_cast<double>(common) : 1.0;
        for (std::int64_t k = 0; k < nd[2]; ++k)
            for (std::int64_t j = 0; j < nd[1]; ++j)
                for (std::int64_t i = 0; i < nd[0]; ++i) {
                    std::int64_t idx[3] = {i, j, k};
                    const auto& [p, cut] = planes[static_cast<std::size_t>(idx[a])];
                    idx[a] = p;
                    const double lo = at(idx[0], idx[1], idx[2]);
                    double value = lo * scale;
                    if (cut != nullptr) {
                        ++idx[a];
                        const double hi = at(idx[0], idx[1], idx[2]);
                        if (exact) { // lo Q + num (Q / den) (hi - lo): integers below 2^53
                            const auto l = static_cast<std::int64_t>(lo), h = static_cast<std::int64_t>(hi);
                            value = static_cast<double>(l * common + cut->num * (common / cut->den) * (h - l));
                        } else {
                            value = interpolate(lo, hi, cut->s, iso);
                        }
                    }
                    nv[static_cast<std::size_t>(i + nd[0] * (j + nd[1] * k))] = value;
                }
        iso *= scale;
        largest *= scale;
        dims = nd;
        values = std::move(nv);
        coord[a] = std::move(nc);
    }
};

namespace {

/// The original index coordinate of refined index coordinate x along one axis.
double unrefine(const std::vector<double>& coord, double x)
{
    const auto last = static_cast<double>(coord.size() - 1);
    const double c = std::clamp(std::floor(x), 0.0, last - 1);
    const auto p = static_cast<std::size_t>(c);
    return coord[p] + (x - c) * (coord[p + 1] - coord[p]);
}

/// Half the index-space gradient of the samples at sample (i, j, k): central differences inside,
/// one-sided at the border (as extract()), halved so that no difference of doubles overflows.
template <class T> std::array<double, 3> half_gradient(const GridView<T>& g, const Index3& at)
{
    std::array<double, 3> out{};
    for (std::size_t a = 0; a < 3; ++a) {
        Index3 lo = at, hi = at;
        if (at[a] > 0) --lo[a];
        if (at[a] + 1 < g.dims[a]) ++hi[a];
        const double vl = static_cast<double>(g(lo[0], lo[1], lo[2])), vh = static_cast<double>(g(hi[0], hi[1], hi[2]));
        const double span = static_cast<double>(hi[a] - lo[a]);
        out[a] = (0.5 * vh - 0.5 * vl) / span;
    }
    return out;
}

/// The unit normal at original index point x: minus the world gradient, trilinear in the cell's
/// corner gradients; 0 where the gradient vanishes.
template <class T> std::array<float, 3> normal_at(const GridView<T>& g, const Mat3& normal_map, const double x[3])
{
    Index3 cell{};
    double w[3];
    for (std::size_t a = 0; a < 3; ++a) {
        const double c = std::clamp(std::floor(x[a]), 0.0, static_cast<double>(g.dims[a] - 2));
        cell[a] = static_cast<std::int64_t>(c);
        w[a] = x[a] - c;
    }
    std::array<double, 3> grad{};
    for (int c = 0; c < 8; ++c) {
        double weight = 1;
        Index3 corner{};
        for (std::size_t a = 0; a < 3; ++a) {
            const bool up = kCorner[c][a] != 0;
            weight *= up ? w[a] : 1 - w[a];
            corner[a] = cell[a] + kCorner[c][a];
        }
        if (weight == 0) continue;
        const auto h = half_gradient(g, corner);
        for (std::size_t a = 0; a < 3; ++a) grad[a] += weight * h[a];
    }
    std::array<double, 3> world{};
    for (std::size_t r = 0; r < 3; ++r)
        world[r] = normal_map[r][0] * grad[0] + normal_map[r][1] * grad[1] + normal_map[r][2] * grad[2];
    double big = std::max({std::fabs(world[0]), std::fabs(world[1]), std::fabs(world[2])});
    if (!(big > 0) || !std::isfinite(big)) return {0.0f, 0.0f, 0.0f};
    for (double& c : world) c /= big;
    const double len = std::sqrt(world[0] * world[0] + world[1] * world[1] + world[2] * world[2]);
    return {static_cast<float>(-world[0] / len), static_cast<float>(-world[1] / len), static_cast<float>(-world[2] / len)};
}

} // namespace

template <class T> std::vector<SharedFace> shared_tunnel_faces(const GridView<T>& g, double iso)
{
    const FaceLying& lying = face_lying();
    // cells whose tiling lies in a face, in (k, j, i) order, with those faces
    std::vector<std::pair<std::int64_t, std::uint8_t>> cells;
    double raw[8];
    for (std::int64_t k = 0; k + 1 < g.nz(); ++k)
        for (std::int64_t j = 0; j + 1 < g.ny(); ++j)
            for (std::int64_t i = 0; i + 1 < g.nx(); ++i) {
                unsigned config = 0;
                for (int c = 0; c < 8; ++c) {
                    raw[c] = static_cast<double>(g(i + kCorner[c][0], j + kCorner[c][1], k + kCorner[c][2]));
                    config |= static_cast<unsigned>(above(raw[c], iso)) << c;
                }
                if (!lying.config_may[config]) continue;
                const Decision d = decide(raw, iso, config, Method::cmc33, kLegacyVariants);
                const auto v = static_cast<std::size_t>(d.variant - kLegacyVariants);
                const std::uint8_t faces = lying.by_variant[v][static_cast<std::size_t>(d.tiling)];
                if (faces != 0) cells.emplace_back(i + g.nx() * (j + g.ny() * k), faces);
            }
    std::vector<SharedFace> out;
    const std::int64_t step[3] = {1, g.nx(), g.nx() * g.ny()};
    for (const auto& [cell, faces] : cells) {
        for (int axis = 0; axis < 3; ++axis) {
            if (!((faces >> (2 * axis + 1)) & 1u)) continue; // the upper face along axis
            const std::int64_t next = cell + step[axis];
            const auto it = std::lower_bound(cells.begin(), cells.end(), std::pair<std::int64_t, std::uint8_t>{next, 0});
            if (it == cells.end() || it->first != next || !((it->second >> (2 * axis)) & 1u)) continue;
            SharedFace f;
            f.lower = {cell % g.nx(), (cell / g.nx()) % g.ny(), cell / (g.nx() * g.ny())};
            f.axis = axis;
            out.push_back(f);
        }
    }
    return out;
}

template <class T> std::optional<Refinement> Refinement::of(const GridView<T>& grid, double iso)
{
    std::vector<SharedFace> faces = shared_tunnel_faces(grid, iso);
    if (faces.empty()) return std::nullopt;
    auto r = std::make_shared<RefinedGrid>(RefinedGrid::of(grid, iso));
    std::int64_t planes = 0;
    for (int round = 0; !faces.empty(); ++round) {
        if (round == kMaxRefinementRounds) {
            throw Error(Status::internal, "cmc33-paper: tunnels still share " + std::to_string(faces.size()) +
                                              " faces after " + std::to_string(round) +
                                              " rounds of refinement (C13 Sec. 6.2); a bug in cmc33");
        }
        // one cut per slab and round: a second shared face in a slab already cut is met again
        // on the refined grid if its tunnels still share it
        std::array<std::vector<Cut>, 3> cuts;
        for (const SharedFace& f : faces) {
            int along = 0;
            const Cut cut = r->saddle_cut(f, along);
            auto& list = cuts[static_cast<std::size_t>(along)];
            if (std::none_of(list.begin(), list.end(), [&](const Cut& c) { return c.slab == cut.slab; })) list.push_back(cut);
        }
        for (int b = 0; b < 3; ++b) {
            if (cuts[static_cast<std::size_t>(b)].empty()) continue;
            planes += static_cast<std::int64_t>(cuts[static_cast<std::size_t>(b)].size());
            r->split(b, cuts[static_cast<std::size_t>(b)]);
        }
        faces = shared_tunnel_faces(r->view(), r->iso);
    }
    Refinement out;
    out.grid_ = std::move(r);
    out.planes_ = planes;
    return out;
}

GridView<double> Refinement::view() const { return grid_->view(); }
double Refinement::iso() const { return grid_->iso; }

template <class T> void Refinement::map_back(const GridView<T>& grid, bool normals, Mesh& mesh) const
{
    // back to the original grid's index space, then its world frame
    const Mat3 m = frame_matrix(grid.spacing, grid.direction);
    const Mat3 normal_map = inverse_transpose(m);
    if (normals) mesh.normals.resize(mesh.positions.size());
    for (std::size_t q = 0; q < mesh.vertex_count(); ++q) {
        double x[3];
        for (std::size_t a = 0; a < 3; ++a) x[a] = unrefine(grid_->coord[a], static_cast<double>(mesh.positions[3 * q + a]));
        for (std::size_t c = 0; c < 3; ++c) {
            mesh.positions[3 * q + c] = static_cast<float>(grid.origin[c] + (m[c][0] * x[0] + m[c][1] * x[1] + m[c][2] * x[2]));
        }
        if (normals) {
            const auto n = normal_at(grid, normal_map, x);
            for (std::size_t c = 0; c < 3; ++c) mesh.normals[3 * q + c] = n[c];
        }
    }
    if (determinant(m) < 0) { // a mirroring frame: the winding rule holds in world space
        for (std::size_t t = 0; t < mesh.triangle_count(); ++t) std::swap(mesh.triangles[3 * t + 1], mesh.triangles[3 * t + 2]);
    }
}

#define CMC33_INSTANTIATE(T)                                                                                     \
    template std::vector<SharedFace> shared_tunnel_faces<T>(const GridView<T>&, double);                         \
    template std::optional<Refinement> Refinement::of<T>(const GridView<T>&, double);                         \
    template void Refinement::map_back<T>(const GridView<T>&, bool, Mesh&) const;
CMC33_FOR_EACH_SAMPLE_TYPE(CMC33_INSTANTIATE)
#undef CMC33_INSTANTIATE

} // namespace cmc33::detail
