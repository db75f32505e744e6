// Label maps (labels.hpp, docs/labels.md): one pass over the cells; two-label cells take cmc33's
// triangulation of the lower label's indicator at 0.5 from a table of its 256 corner patterns,
// cells with three or more labels are cut by cones from their centre over their faces' curves, or
// around a core where such cones would pinch a label.

#include "cmc33/labels.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <unordered_set>
#include <utility>
#include <vector>

#include "cells.hpp"
#include "cmc33/cell.hpp"
#include "cmc33/error.hpp"
#include "parallel.hpp"
#include "sample_types.hpp"
#include "smooth.hpp"

namespace cmc33 {

namespace {

using namespace label_cells;

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

// World coordinates of grid indices: origin + M * index. Without rotation M is diagonal and the
// zero products are skipped (they add nothing).
class Placer {
public:
    Placer(const Vec3& spacing, const Vec3& origin, const Mat3& direction)
        : m_(frame_matrix(spacing, direction)), origin_(origin), diagonal_(is_diagonal(m_))
    {
    }
    void put(Buffer<float>& out, double x, double y, double z) const
    {
        if (diagonal_) {
            out.push_back(static_cast<float>(origin_[0] + m_[0][0] * x));
            out.push_back(static_cast<float>(origin_[1] + m_[1][1] * y));
            out.push_back(static_cast<float>(origin_[2] + m_[2][2] * z));
            return;
        }
        for (std::size_t r = 0; r < 3; ++r) {
            out.push_back(static_cast<float>(origin_[r] + m_[r][0] * x + m_[r][1] * y + m_[r][2] * z));
        }
    }
    bool mirrors() const { return determinant(m_) < 0; }

private:
    Mat3 m_;
    Vec3 origin_;
    bool diagonal_ = false;
};

// Whether a label gets a surface (the selection's rule, applied to any value).
struct Chooser {
    const LabelOptions& options;
    bool operator()(std::int64_t v) const
    {
        if (options.labels.empty()) return v != options.background;
        return std::any_of(options.labels.begin(), options.labels.end(),
                           [&](const auto& r) { return r[0] <= v && v <= r[1]; });
    }
    bool wanted(std::int64_t a, std::int64_t b) const { return (*this)(a) || (*this)(b); }
};

// One z-range of cell layers [k0, k1): its vertices numbered from 0 in order of first use, and the
// ids of its vertices on its first and last planes (z = k0 and z = k1), to weld the ranges.
struct Part {
    Buffer<float> positions;
    Buffer<std::uint32_t> triangles;
    std::vector<std::int64_t> front, behind;
    std::vector<std::array<std::uint32_t, 2>> bottom, top; ///< (index in the plane, vertex id)
    std::unordered_set<std::int64_t> present;
    std::int64_t cells_two_labels = 0, cells_many_labels = 0, cells_with_core = 0;
};

// Every label of a grid too thin to have cells.
template <class T> std::vector<std::int64_t> scan_present(const GridView<T>& g)
{
    std::unordered_set<std::int64_t> seen;
    for (std::int64_t k = 0; k < g.nz(); ++k)
        for (std::int64_t j = 0; j < g.ny(); ++j)
            for (std::int64_t i = 0; i < g.nx(); ++i) seen.insert(static_cast<std::int64_t>(g(i, j, k)));
    std::vector<std::int64_t> out(seen.begin(), seen.end());
    std::sort(out.begin(), out.end());
    return out;
}

// The cell pass over layers [k0, k1). Vertices at doubled grid coordinates are found through three
// planes of ids (doubled z = 2k, 2k + 1, 2k + 2), reset through the lists of the entries they set;
// cmc33's interior points belong to one cell and are numbered within it.
template <class T> class Worker {
public:
    /// With `smooth`, g is its label map and the crossings and tied faces follow its values.
    Worker(const GridView<T>& g, const Placer& place, const Chooser& chosen, Part& out,
           const label_smooth::Smoothed<T>* smooth = nullptr)
        : g_(g), place_(place), chosen_(chosen), smooth_(smooth), flip_(place.mirrors()), out_(out),
          span0_(static_cast<std::size_t>(2 * g.nx() - 1))
    {
        const std::size_t plane = span0_ * static_cast<std::size_t>(2 * g.ny() - 1);
        for (auto& p : planes_) p.assign(plane, kNone);
    }

    void layers(std::int64_t k0, std::int64_t k1)
    {
        const auto& table = patterns();
        const std::int64_t sx = g_.strides[0];
        std::array<std::int64_t, 8> label{};
        std::int64_t last = 0;
        bool any = false;
        const auto note = [&](std::int64_t v) {
            if (any && v == last) return;
            any = true;
            last = v;
            out_.present.insert(v);
        };
        for (std::int64_t k = k0; k < k1; ++k) {
            for (std::int64_t j = 0; j + 1 < g_.ny(); ++j) {
                const std::array<const T*, 4> row{g_.data + g_.offset(0, j, k), g_.data + g_.offset(0, j + 1, k),
                                                  g_.data + g_.offset(0, j, k + 1),
                                                  g_.data + g_.offset(0, j + 1, k + 1)};
                for (std::int64_t i = 0; i + 1 < g_.nx(); ++i) {
                    std::array<T, 8> s;
                    bool uniform = true;
                    for (unsigned c = 0; c < 8; ++c) {
                        s[c] = row[c >> 1][(i + (c & 1U)) * sx];
                        uniform = uniform && s[c] == s[0];
                    }
                    if (uniform) {
                        note(static_cast<std::int64_t>(s[0]));
                        continue;
                    }
                    for (unsigned c = 0; c < 8; ++c) {
                        label[c] = static_cast<std::int64_t>(s[c]);
                        note(label[c]);
                    }
                    cell(table, label, i, j, k);
                }
            }
            if (k == k0) out_.bottom = ids(0);
            reserve_ahead(k + 1 - k0, k1 - k0);
            // the plane z = k + 1 becomes the next layer's first
            reset(0);
            reset(1);
            std::swap(planes_[0], planes_[2]);
            std::swap(touched_[0], touched_[2]);
        }
        out_.top = ids(0);
    }

private:
    void cell(const std::array<Pattern, 256>& table, const std::array<std::int64_t, 8>& label, std::int64_t i,
              std::int64_t j, std::int64_t k)
    {
        std::int64_t low = label[0], high = label[0];
        for (const std::int64_t l : label) {
            low = std::min(low, l);
            high = std::max(high, l);
        }
        bool two = true;
        for (const std::int64_t l : label) two = two && (l == low || l == high);
        const auto at = [&](const Doubled& d) {
            return grid_vertex(2 * i + d[0], 2 * j + d[1], 2 * k + d[2], static_cast<std::size_t>(d[2]));
        };
        if (two) {
            ++out_.cells_two_labels;
            if (!chosen_.wanted(low, high)) return;
            if (smooth_ != nullptr) return smooth_two_labels(low, high, i, j, k);
            unsigned config = 0;
            for (unsigned c = 0; c < 8; ++c) config |= (label[c] == low ? 1U : 0U) << c;
            std::array<std::uint32_t, kInteriorSlots> interior;
            interior.fill(kNone);
            for (const auto& tri : table[config].triangles) {
                std::array<std::uint32_t, 3> v{};
                for (std::size_t n = 0; n < 3; ++n) {
                    const TableVertex& t = tri[n];
                    if (!t.interior) {
                        v[n] = at(t.doubled);
                        continue;
                    }
                    std::uint32_t& id = interior[static_cast<std::size_t>(t.slot)];
                    if (id == kNone) {
                        id = new_vertex(static_cast<double>(i) + t.unit[0], static_cast<double>(j) + t.unit[1],
                                        static_cast<double>(k) + t.unit[2]);
                    }
                    v[n] = id;
                }
                // cmc33's normals point from above (the lower label) to below
                add(v, high, low);
            }
            return;
        }
        ++out_.cells_many_labels;
        std::array<std::uint32_t, 27> core;
        core.fill(kNone);
        const auto vertex = [&](const Quad& q) {
            if (q[0] % 2 == 0 && q[1] % 2 == 0 && q[2] % 2 == 0) return at({q[0] / 2, q[1] / 2, q[2] / 2});
            // a corner of the cell's core: the cell's own
            std::uint32_t& id = core[static_cast<std::size_t>((q[0] - 1) + 3 * (q[1] - 1) + 9 * (q[2] - 1))];
            if (id == kNone) {
                // halfway from the centre to the point of the cell's surface it is the image of
                const Doubled from{q[0] - 1, q[1] - 1, q[2] - 1};
                std::array<double, 3> p{0.25 * q[0], 0.25 * q[1], 0.25 * q[2]};
                if (smooth_ != nullptr && odd_count(from) == 1) {
                    const std::size_t axis = odd_axis(from);
                    p[axis] = 0.25 + 0.5 * edge_t(2 * i + from[0], 2 * j + from[1], 2 * k + from[2], axis);
                }
                id = new_vertex(static_cast<double>(i) + p[0], static_cast<double>(j) + p[1],
                                static_cast<double>(k) + p[2]);
            }
            return id;
        };
        // with smoothing, a face of two labels on its diagonals joins the pair cmc33 joins on the
        // values (the two-label cell beside it decides so)
        DiagonalRule rule; // empty without smoothing: nothing allocated per cell
        if (smooth_ != nullptr)
            rule = [&](const std::array<unsigned, 4>& q, std::int64_t lo, std::int64_t hi) {
                std::array<double, 4> v{};
                for (std::size_t c = 0; c < 4; ++c) {
                    v[c] = smooth_->difference(lo, hi, i + (q[c] & 1U), j + (q[c] >> 1 & 1U), k + (q[c] >> 2 & 1U));
                }
                // the bilinear saddle's sign against 0: products of floats are exact in double, and a
                // difference of doubles is 0 only when they are equal
                const bool lo_on_diagonal0 = v[0] >= 0;
                const double joined_lo = lo_on_diagonal0 ? v[0] * v[2] - v[1] * v[3] : v[1] * v[3] - v[0] * v[2];
                return joined_lo >= 0 ? lo : hi;
            };
        const bool took_core = many_label_cell(
            label,
            [&](const Quad& a, const Quad& b, const Quad& c, std::int64_t front, std::int64_t behind) {
                if (chosen_.wanted(front, behind)) add({vertex(a), vertex(b), vertex(c)}, front, behind);
            },
            smooth_ != nullptr ? &rule : nullptr);
        if (took_core) ++out_.cells_with_core;
    }

    // Room for the range at the rate of its layers so far (a quarter more), once that passes the
    // capacity: fewer regrowths, each of which copies the arrays and touches fresh pages.
    void reserve_ahead(std::int64_t done, std::int64_t all)
    {
        const auto ahead = [&](auto& v) {
            const std::size_t need = v.size() / static_cast<std::size_t>(done) * static_cast<std::size_t>(all);
            if (need > v.capacity()) v.reserve(need + need / 4);
        };
        ahead(out_.positions);
        ahead(out_.triangles);
        ahead(out_.front);
        ahead(out_.behind);
    }

    std::uint32_t grid_vertex(std::int64_t x, std::int64_t y, std::int64_t z, std::size_t plane)
    {
        const std::size_t at = static_cast<std::size_t>(x) + span0_ * static_cast<std::size_t>(y);
        std::uint32_t& id = planes_[plane][at];
        if (id == kNone) {
            std::array<double, 3> p{0.5 * static_cast<double>(x), 0.5 * static_cast<double>(y),
                                    0.5 * static_cast<double>(z)};
            const Doubled d{static_cast<int>(x & 1), static_cast<int>(y & 1), static_cast<int>(z & 1)};
            if (smooth_ != nullptr && odd_count(d) == 1) {
                const std::size_t axis = odd_axis(d);
                p[axis] = std::floor(p[axis]) + edge_t(x, y, z, axis);
            }
            id = new_vertex(p[0], p[1], p[2]);
            touched_[plane].push_back(static_cast<std::uint32_t>(at));
        }
        return id;
    }

    static int odd_count(const Doubled& d) { return (d[0] & 1) + (d[1] & 1) + (d[2] & 1); }
    // The axis of the one odd coordinate of an edge's midpoint.
    static std::size_t odd_axis(const Doubled& d) { return (d[0] & 1) != 0 ? 0 : ((d[1] & 1) != 0 ? 1 : 2); }

    // Where f_low - f_high of the edge's two labels is 0 on the edge at doubled coordinates
    // (x, y, z) along `axis`, from its lower end: linear along the edge as cmc33 places a crossing,
    // and at least 2^-10 of the edge from either end as cmc33 keeps it (docs/conventions.md).
    double edge_t(std::int64_t x, std::int64_t y, std::int64_t z, std::size_t axis) const
    {
        std::array<std::int64_t, 3> p{x / 2, y / 2, z / 2}, q = p;
        ++q[axis];
        const auto a = static_cast<std::int64_t>(g_(p[0], p[1], p[2])),
                   b = static_cast<std::int64_t>(g_(q[0], q[1], q[2]));
        const std::int64_t lo = std::min(a, b), hi = std::max(a, b);
        const double vp = smooth_->difference(lo, hi, p[0], p[1], p[2]),
                     vq = smooth_->difference(lo, hi, q[0], q[1], q[2]);
        constexpr double delta = 1.0 / 1024;
        return std::clamp(vp / (vp - vq), delta, 1 - delta);
    }

    // A cell of two labels with smoothing: cmc33's triangulation of f_low - f_high at 0 (corners of
    // the lower label above), its crossings on the cell's edges shared with the neighbours.
    void smooth_two_labels(std::int64_t low, std::int64_t high, std::int64_t i, std::int64_t j, std::int64_t k)
    {
        std::array<double, 8> values{};
        for (unsigned c = 0; c < 8; ++c) {
            values[c] = smooth_->difference(low, high, i + (c & 1U), j + (c >> 1 & 1U), k + (c >> 2 & 1U));
        }
        const Mesh m = analyze_cell(values, 0.0, Method::cmc33).mesh;
        std::vector<std::uint32_t> id(m.vertex_count(), kNone);
        const auto vertex = [&](std::uint32_t n) {
            if (id[n] != kNone) return id[n];
            const float* p = &m.positions[3 * static_cast<std::size_t>(n)];
            Doubled d{};
            int on_edge = 0;
            for (std::size_t a = 0; a < 3; ++a) {
                const bool end = p[a] == 0.0F || p[a] == 1.0F;
                on_edge += end ? 1 : 0;
                d[a] = end ? 2 * static_cast<int>(p[a]) : 1;
            }
            // a crossing has its two other coordinates on the cell's faces; cmc33's fan centres
            // and tubes lie inside the open cell
            id[n] = on_edge >= 2 ? grid_vertex(2 * i + d[0], 2 * j + d[1], 2 * k + d[2], static_cast<std::size_t>(d[2]))
                                 : new_vertex(static_cast<double>(i) + static_cast<double>(p[0]),
                                              static_cast<double>(j) + static_cast<double>(p[1]),
                                              static_cast<double>(k) + static_cast<double>(p[2]));
            return id[n];
        };
        for (std::size_t t = 0; t < m.triangle_count(); ++t) {
            add({vertex(m.triangles[3 * t]), vertex(m.triangles[3 * t + 1]), vertex(m.triangles[3 * t + 2])}, high,
                low);
        }
    }

    std::uint32_t new_vertex(double x, double y, double z)
    {
        const std::size_t n = out_.positions.size() / 3;
        if (n >= kNone) throw Error(Status::too_large, "the label surfaces have more than 4294967295 vertices");
        place_.put(out_.positions, x, y, z);
        return static_cast<std::uint32_t>(n);
    }

    void add(std::array<std::uint32_t, 3> v, std::int64_t front, std::int64_t behind)
    {
        // every triangle faces its higher label: the interface of two labels is one sheet wound
        // one way, so that its vertex normals can point to every triangle's front
        if (front < behind) {
            std::swap(v[1], v[2]);
            std::swap(front, behind);
        }
        // a mirroring frame reverses every winding
        out_.triangles.push_back(v[0]);
        out_.triangles.push_back(flip_ ? v[2] : v[1]);
        out_.triangles.push_back(flip_ ? v[1] : v[2]);
        out_.front.push_back(front);
        out_.behind.push_back(behind);
    }

    std::vector<std::array<std::uint32_t, 2>> ids(std::size_t plane) const
    {
        std::vector<std::array<std::uint32_t, 2>> out;
        out.reserve(touched_[plane].size());
        for (const std::uint32_t at : touched_[plane]) out.push_back({at, planes_[plane][at]});
        return out;
    }

    void reset(std::size_t plane)
    {
        for (const std::uint32_t at : touched_[plane]) planes_[plane][at] = kNone;
        touched_[plane].clear();
    }

    const GridView<T>& g_;
    const Placer& place_;
    const Chooser& chosen_;
    const label_smooth::Smoothed<T>* smooth_;
    bool flip_;
    Part& out_;
    std::size_t span0_;
    std::array<std::vector<std::uint32_t>, 3> planes_;
    std::array<std::vector<std::uint32_t>, 3> touched_;
};

// The parts joined in order: a part's vertices on its first plane that the part below made take
// that part's ids, every other vertex the next id. That is the numbering one range would give.
void weld(std::vector<Part>& parts, std::size_t plane, LabelSurfaces& out)
{
    Mesh& mesh = out.interfaces;
    if (parts.size() == 1) {
        mesh.positions = std::move(parts[0].positions);
        mesh.triangles = std::move(parts[0].triangles);
        out.front = std::move(parts[0].front);
        out.behind = std::move(parts[0].behind);
        return;
    }
    std::size_t vertices = 0, triangles = 0;
    for (const Part& p : parts) {
        vertices += p.positions.size();
        triangles += p.triangles.size();
    }
    mesh.positions.reserve(vertices);
    mesh.triangles.reserve(triangles);
    out.front.reserve(triangles / 3);
    out.behind.reserve(triangles / 3);
    std::vector<std::uint32_t> boundary(plane, kNone), remap;
    std::uint64_t next = 0;
    for (std::size_t r = 0; r < parts.size(); ++r) {
        Part& p = parts[r];
        remap.assign(p.positions.size() / 3, kNone);
        if (r > 0) {
            for (const auto& [at, id] : p.bottom) remap[id] = boundary[at];
            for (const auto& [at, id] : parts[r - 1].top) boundary[at] = kNone;
        }
        for (std::size_t v = 0; v < remap.size(); ++v) {
            if (remap[v] != kNone) continue;
            if (next >= kNone) throw Error(Status::too_large, "the label surfaces have more than 4294967295 vertices");
            remap[v] = static_cast<std::uint32_t>(next++);
            mesh.positions.insert(mesh.positions.end(), p.positions.begin() + static_cast<std::ptrdiff_t>(3 * v),
                                  p.positions.begin() + static_cast<std::ptrdiff_t>(3 * v + 3));
        }
        for (const auto& [at, id] : p.top) boundary[at] = remap[id];
        for (const std::uint32_t v : p.triangles) mesh.triangles.push_back(remap[v]);
        out.front.insert(out.front.end(), p.front.begin(), p.front.end());
        out.behind.insert(out.behind.end(), p.behind.begin(), p.behind.end());
        Buffer<float>().swap(p.positions); // each part freed once copied
        Buffer<std::uint32_t>().swap(p.triangles);
    }
}

using Normal = std::array<double, 3>;

// The normal of interface triangle t as wound, twice its area long, from the float positions.
Normal face_normal(const Mesh& m, std::size_t t)
{
    const float* p = m.positions.data();
    const std::uint32_t* v = &m.triangles[3 * t];
    Normal a{}, b{};
    for (std::size_t k = 0; k < 3; ++k) {
        a[k] = static_cast<double>(p[3 * v[1] + k]) - static_cast<double>(p[3 * v[0] + k]);
        b[k] = static_cast<double>(p[3 * v[2] + k]) - static_cast<double>(p[3 * v[0] + k]);
    }
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

double length(const Normal& n)
{
    return std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

// Unit normals into `out` (3 floats per vertex) of the vertices v with wanted(v): the sum of the
// normals `face(i)` (twice the area long) of the triangles `corners(i)`, i < `triangles`, at each,
// summed in triangle order so that the bytes depend on nothing else. Where the sum vanishes against
// the areas (triangles that cancel) the vertex takes its largest triangle's normal (the first of
// equals), and where it has only zero-area triangles (0, 0, up(v)): finite and unit everywhere.
// Faces negated in the same order give exactly the negated normals (rounding is symmetric).
template <class Corners, class Face, class Up, class Wanted>
void vertex_normals(Buffer<float>& out, std::size_t vertices, std::size_t triangles, Corners&& corners, Face&& face,
                    Up&& up, Wanted&& wanted)
{
    // floats, summed into the output: a quarter of the memory traffic of doubles, and a few
    // triangles' sum keeps float precision
    Buffer<float> area(vertices);
    for (std::size_t v = 0; v < vertices; ++v) {
        if (!wanted(v)) continue;
        out[3 * v] = out[3 * v + 1] = out[3 * v + 2] = area[v] = 0;
    }
    for (std::size_t i = 0; i < triangles; ++i) {
        const std::array<std::uint32_t, 3> c = corners(i);
        if (!wanted(c[0]) && !wanted(c[1]) && !wanted(c[2])) continue;
        const Normal n = face(i);
        const std::array<float, 3> f{static_cast<float>(n[0]), static_cast<float>(n[1]), static_cast<float>(n[2])};
        const float l = static_cast<float>(length(n));
        for (const std::uint32_t v : c) {
            if (!wanted(v)) continue;
            float* o = &out[3 * v];
            o[0] += f[0];
            o[1] += f[1];
            o[2] += f[2];
            area[v] += l;
        }
    }
    std::vector<std::uint32_t> degenerate;
    for (std::size_t v = 0; v < vertices; ++v) {
        if (!wanted(v)) continue;
        float* o = &out[3 * v];
        const double l = length({static_cast<double>(o[0]), static_cast<double>(o[1]), static_cast<double>(o[2])});
        // relative to the areas, so that rounding left by cancelling triangles is no direction
        if (!(l > 1e-4 * static_cast<double>(area[v])) || !(l > 0) || !std::isfinite(l)) {
            degenerate.push_back(static_cast<std::uint32_t>(v));
            continue;
        }
        for (std::size_t k = 0; k < 3; ++k) o[k] = static_cast<float>(static_cast<double>(o[k]) / l);
    }
    if (degenerate.empty()) return;
    std::vector<std::uint32_t> slot(vertices, kNone);
    for (std::size_t d = 0; d < degenerate.size(); ++d) slot[degenerate[d]] = static_cast<std::uint32_t>(d);
    std::vector<Normal> best(degenerate.size(), Normal{0, 0, 0});
    std::vector<double> best_length(degenerate.size(), 0);
    for (std::size_t i = 0; i < triangles; ++i) {
        const std::array<std::uint32_t, 3> c = corners(i);
        if (slot[c[0]] == kNone && slot[c[1]] == kNone && slot[c[2]] == kNone) continue;
        const Normal n = face(i);
        const double l = length(n);
        if (!std::isfinite(l)) continue;
        for (const std::uint32_t v : c) {
            if (slot[v] == kNone || !(l > best_length[slot[v]])) continue;
            best[slot[v]] = n;
            best_length[slot[v]] = l;
        }
    }
    for (std::size_t d = 0; d < degenerate.size(); ++d) {
        const std::size_t v = degenerate[d];
        const double l = best_length[d];
        for (std::size_t k = 0; k < 3; ++k) {
            out[3 * v + k] = l > 0 ? static_cast<float>(best[d][k] / l) : (k == 2 ? static_cast<float>(up(v)) : 0.0F);
        }
    }
}

// The interfaces' normals, and which vertices have triangles of more than one pair of labels.
void interface_normals(LabelSurfaces& s)
{
    Mesh& m = s.interfaces;
    const std::size_t nv = m.vertex_count(), nt = m.triangle_count();
    Buffer<std::uint32_t> first(nv);
    std::fill(first.begin(), first.end(), kNone);
    s.junctions.assign(nv, 0);
    for (std::size_t t = 0; t < nt; ++t) {
        for (std::size_t c = 0; c < 3; ++c) {
            const std::uint32_t v = m.triangles[3 * t + c];
            if (first[v] == kNone) {
                first[v] = static_cast<std::uint32_t>(t);
            } else if (s.front[first[v]] != s.front[t] || s.behind[first[v]] != s.behind[t]) {
                s.junctions[v] = 1;
            }
        }
    }
    m.normals.resize(3 * nv);
    vertex_normals(
        m.normals, nv, nt,
        [&](std::size_t t) {
            return std::array<std::uint32_t, 3>{m.triangles[3 * t], m.triangles[3 * t + 1], m.triangles[3 * t + 2]};
        },
        [&](std::size_t t) { return face_normal(m, t); }, [](std::size_t) { return 1.0; },
        [](std::size_t) { return true; });
}

// Counts, offsets, fill: the triangles of each selected label in ascending order.
void index_by_label(LabelSurfaces& s)
{
    const std::size_t n = s.selected.size(), none = n;
    const auto slot = [&](std::int64_t label) {
        const auto it = std::lower_bound(s.selected.begin(), s.selected.end(), label);
        return it != s.selected.end() && *it == label ? static_cast<std::size_t>(it - s.selected.begin()) : none;
    };
    s.by_label_start.assign(n + 1, 0);
    for (std::size_t t = 0; t < s.front.size(); ++t) {
        for (const std::int64_t label : {s.front[t], s.behind[t]}) {
            const std::size_t i = slot(label);
            if (i != none) ++s.by_label_start[i + 1];
        }
    }
    for (std::size_t i = 0; i < n; ++i) s.by_label_start[i + 1] += s.by_label_start[i];
    s.by_label.resize(s.by_label_start[n]);
    std::vector<std::size_t> next(s.by_label_start.begin(), s.by_label_start.end() - 1);
    for (std::size_t t = 0; t < s.front.size(); ++t) {
        for (const std::int64_t label : {s.front[t], s.behind[t]}) {
            const std::size_t i = slot(label);
            if (i != none) s.by_label[next[i]++] = static_cast<std::uint32_t>(t);
        }
    }
}

template <class T> LabelSurfaces run(const GridView<T>& input, const LabelOptions& options)
{
    LabelSurfaces out;
    std::optional<label_smooth::Smoothed<T>> smooth;
    if (options.smooth != 0) smooth.emplace(input, options.smooth, options.threads);
    const GridView<T>& g = smooth ? smooth->view() : input;
    const Chooser chosen{options};
    const Placer place(g.spacing, g.origin, g.direction);
    if (g.nx() < 2 || g.ny() < 2 || g.nz() < 2) {
        out.present = scan_present(g);
    } else {
        // z-ranges of cell layers, one per thread; the output does not depend on how many
        const std::int64_t layers = g.nz() - 1;
        const int threads = detail::threads_for(options.threads, layers);
        std::vector<Part> parts(static_cast<std::size_t>(threads));
        detail::parallel_chunks(layers, threads, [&](int t, std::int64_t k0, std::int64_t k1) {
            Worker<T> worker(g, place, chosen, parts[static_cast<std::size_t>(t)], smooth ? &*smooth : nullptr);
            worker.layers(k0, k1);
        });
        std::unordered_set<std::int64_t> present;
        for (Part& p : parts) {
            present.insert(p.present.begin(), p.present.end());
            out.cells_two_labels += p.cells_two_labels;
            out.cells_many_labels += p.cells_many_labels;
            out.cells_with_core += p.cells_with_core;
        }
        out.present.assign(present.begin(), present.end());
        std::sort(out.present.begin(), out.present.end());
        weld(parts, static_cast<std::size_t>((2 * g.nx() - 1) * (2 * g.ny() - 1)), out);
    }
    for (const std::int64_t v : out.present) {
        if (chosen(v)) out.selected.push_back(v);
    }
    if (out.selected.empty()) {
        // nothing selected: no cell was triangulated, none counted
        out.cells_two_labels = out.cells_many_labels = out.cells_with_core = 0;
    }
    // with many labels, finding each one's triangles by a scan of all would cost labels x triangles
    if (out.selected.size() > 8 && out.front.size() < kNone) index_by_label(out);
    if (options.normals && out.front.size() < kNone) interface_normals(out);
    return out;
}

std::int64_t parse_value(std::string_view text, std::string_view whole)
{
    std::int64_t v = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (text.empty() || ec != std::errc{} || end != text.data() + text.size()) {
        throw Error(Status::invalid_argument, "labels '" + std::string(whole) +
                                                  "': expected 'all' or values and ranges such "
                                                  "as 1,3,7 or 2-9, got '" +
                                                  std::string(text) + "'");
    }
    return v;
}

} // namespace

LabelRanges parse_label_ranges(std::string_view text)
{
    LabelRanges ranges;
    if (text == "all") return ranges;
    std::size_t start = 0;
    while (start <= text.size()) {
        const std::size_t comma = std::min(text.find(',', start), text.size());
        const std::string_view item = text.substr(start, comma - start);
        // a range's dash follows a digit: "-5--1" is -5 to -1
        std::size_t dash = std::string_view::npos;
        for (std::size_t p = 1; p < item.size(); ++p) {
            if (item[p] == '-' && item[p - 1] >= '0' && item[p - 1] <= '9') {
                dash = p;
                break;
            }
        }
        if (dash == std::string_view::npos) {
            const std::int64_t v = parse_value(item, text);
            ranges.push_back({v, v});
        } else {
            const std::int64_t a = parse_value(item.substr(0, dash), text),
                               b = parse_value(item.substr(dash + 1), text);
            if (a > b) {
                throw Error(Status::invalid_argument, "labels '" + std::string(text) + "': the range '" +
                                                          std::string(item) + "' ends before it starts");
            }
            ranges.push_back({a, b});
        }
        start = comma + 1;
    }
    return ranges;
}

template <class T> LabelSurfaces label_surfaces(const GridView<T>& labels, const LabelOptions& options)
{
    if constexpr (std::is_floating_point_v<T>) {
        throw Error(Status::unsupported_format, "label maps need integer samples (int8 to uint32), got " +
                                                    std::string(type_name(scalar_type_of<T>())));
    } else {
        return run(labels, options);
    }
}

LabelSurfaces label_surfaces(const Volume& labels, const LabelOptions& options)
{
    return labels.visit([&](const auto& view) { return label_surfaces(view, options); });
}

#define CMC33_INSTANTIATE(T) template LabelSurfaces label_surfaces<T>(const GridView<T>&, const LabelOptions&);
CMC33_FOR_EACH_SAMPLE_TYPE(CMC33_INSTANTIATE)
#undef CMC33_INSTANTIATE

Mesh label_surface(const LabelSurfaces& surfaces, std::int64_t label)
{
    const Mesh& all = surfaces.interfaces;
    Mesh out;
    // an unselected label's interfaces with other unselected labels were not made
    if (!std::binary_search(surfaces.selected.begin(), surfaces.selected.end(), label)) return out;
    std::vector<std::size_t> mine;
    if (!surfaces.by_label_start.empty()) {
        const auto i = static_cast<std::size_t>(
            std::lower_bound(surfaces.selected.begin(), surfaces.selected.end(), label) - surfaces.selected.begin());
        mine.assign(surfaces.by_label.begin() + static_cast<std::ptrdiff_t>(surfaces.by_label_start[i]),
                    surfaces.by_label.begin() + static_cast<std::ptrdiff_t>(surfaces.by_label_start[i + 1]));
    } else {
        for (std::size_t t = 0; t < all.triangle_count(); ++t) {
            if (surfaces.front[t] == label || surfaces.behind[t] == label) mine.push_back(t);
        }
    }
    // sized for the most and written by index (a push_back per float was a tenth of the command's
    // time), cut to what was used at the end; pages never written are never touched
    out.triangles.resize(3 * mine.size());
    const std::size_t most = std::min(all.vertex_count(), 3 * mine.size());
    out.positions.resize(3 * most);
    // vertices numbered in order of first use, through an array over all vertices, or for a label
    // with few of them (one of many) through the sorted list of those it uses
    std::vector<std::uint32_t> used, remap;
    const bool few = 16 * most < all.vertex_count();
    if (few) {
        used.reserve(3 * mine.size());
        for (const std::size_t t : mine) used.insert(used.end(), &all.triangles[3 * t], &all.triangles[3 * t] + 3);
        std::sort(used.begin(), used.end());
        used.erase(std::unique(used.begin(), used.end()), used.end());
        remap.assign(used.size(), kNone);
    } else {
        remap.assign(all.vertex_count(), kNone);
    }
    // normals: at a vertex of one pair of labels the interfaces' (the lower label's: the same sum),
    // negated where the label is in front; at a junction the label's own sum, from the interface
    // triangles' normals negated where it is in front (exactly the other side's negation), with
    // the first triangle's side as the last resort's direction
    const bool normals = all.has_normals();
    const bool flagged = surfaces.junctions.size() == all.vertex_count();
    Buffer<signed char> own; // per vertex: 0 the interfaces' normal, else the last resort's side
    if (normals) {
        out.normals.resize(3 * most);
        own.resize(most);
    }
    std::size_t vertices = 0, corner = 0;
    float* const position = out.positions.data();
    float* const normal = out.normals.data();
    std::uint32_t* const triangle = out.triangles.data();
    bool any_junction = false;
    const auto use = [&](std::uint32_t v, bool in_front) {
        std::uint32_t& id =
            few ? remap[static_cast<std::size_t>(std::lower_bound(used.begin(), used.end(), v) - used.begin())]
                : remap[v];
        if (id == kNone) {
            id = static_cast<std::uint32_t>(vertices);
            for (std::size_t a = 0; a < 3; ++a) position[3 * vertices + a] = all.positions[3 * v + a];
            if (normals) {
                const bool junction = !flagged || surfaces.junctions[v] != 0;
                const float sign = in_front ? -1.0F : 1.0F;
                for (std::size_t a = 0; a < 3; ++a)
                    normal[3 * vertices + a] = junction ? 0.0F : sign * all.normals[3 * v + a];
                own[vertices] = junction ? static_cast<signed char>(in_front ? -1 : 1) : 0;
                any_junction = any_junction || junction;
            }
            ++vertices;
        }
        triangle[corner++] = id;
    };
    for (const std::size_t t : mine) {
        // normals point into `front`; the label's surface points out of it
        const bool in_front = surfaces.front[t] == label;
        use(all.triangles[3 * t], in_front);
        use(all.triangles[3 * t + (in_front ? 2 : 1)], in_front);
        use(all.triangles[3 * t + (in_front ? 1 : 2)], in_front);
    }
    out.positions.resize(3 * vertices);
    if (normals) out.normals.resize(3 * vertices);
    if (any_junction) {
        vertex_normals(
            out.normals, out.vertex_count(), mine.size(),
            [&](std::size_t i) {
                return std::array<std::uint32_t, 3>{out.triangles[3 * i], out.triangles[3 * i + 1],
                                                    out.triangles[3 * i + 2]};
            },
            [&](std::size_t i) {
                Normal n = face_normal(all, mine[i]);
                if (surfaces.front[mine[i]] == label) n = {-n[0], -n[1], -n[2]};
                return n;
            },
            [&](std::size_t v) { return static_cast<double>(own[v]); }, [&](std::size_t v) { return own[v] != 0; });
    }
    return out;
}

} // namespace cmc33
