// Label maps (labels.hpp, docs/labels.md): one pass over the cells; two-label cells take cmc33's
// triangulation of the lower label's indicator at 0.5 from a table of its 256 corner patterns,
// cells with three or more labels are cut by cones from their centre over their faces' curves.

#include "cmc33/labels.hpp"

#include <algorithm>
#include <charconv>
#include <limits>
#include <mutex>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "cmc33/cell.hpp"
#include "cmc33/error.hpp"

namespace cmc33 {

namespace {

// A vertex of a cell's triangle: doubled coordinates in the cell (0..2 each: corners, edge
// midpoints, face and cell centres), or an interior point of cmc33's triangulation.
struct TableVertex {
    std::array<int, 3> doubled{0, 0, 0};
    bool interior = false;
    int slot = 0;                        ///< interior points: which of the cell's (below kInteriorSlots)
    std::array<double, 3> unit{0, 0, 0}; ///< position in the unit cube (interior points)
};

// cmc33's tunnels (7.4.1, 13.5.1 and the like) place up to 12 points inside a cell
constexpr std::uint64_t kInteriorSlots = 16;

struct Pattern {
    std::vector<std::array<TableVertex, 3>> triangles;
};

// cmc33's triangles of the cell whose corners in `config` hold the lower label (value 1 at iso
// 0.5: every crossing is an edge midpoint, every tied face saddle joins the lower label).
std::array<Pattern, 256> make_patterns()
{
    std::array<Pattern, 256> patterns;
    for (unsigned config = 1; config < 255; ++config) {
        std::array<double, 8> values{};
        for (unsigned c = 0; c < 8; ++c) values[c] = (config >> c & 1U) != 0 ? 1.0 : 0.0;
        const CellReport report = analyze_cell(values, 0.5, Method::cmc33);
        const Mesh& m = report.mesh;
        std::vector<std::array<double, 3>> interior;
        for (std::size_t t = 0; t < m.triangle_count(); ++t) {
            std::array<TableVertex, 3> tri{};
            for (std::size_t v = 0; v < 3; ++v) {
                const std::size_t index = m.triangles[3 * t + v];
                TableVertex& out = tri[v];
                for (std::size_t a = 0; a < 3; ++a) {
                    const double p = static_cast<double>(m.positions[3 * index + a]);
                    out.unit[a] = p;
                    const double twice = 2 * p;
                    out.doubled[a] = static_cast<int>(twice);
                    if (twice != static_cast<double>(out.doubled[a])) out.interior = true;
                }
                if (out.interior) {
                    const auto it = std::find(interior.begin(), interior.end(), out.unit);
                    out.slot = static_cast<int>(it - interior.begin());
                    if (it == interior.end()) interior.push_back(out.unit);
                    if (interior.size() > kInteriorSlots) {
                        throw Error(Status::internal, "label maps: a cell pattern with more than 16 interior points");
                    }
                }
            }
            patterns[config].triangles.push_back(tri);
        }
    }
    return patterns;
}

const std::array<Pattern, 256>& patterns()
{
    static const std::array<Pattern, 256> table = make_patterns();
    return table;
}

struct Triangle {
    std::array<std::uint32_t, 3> v;
    std::int64_t front, behind;
};

class Builder {
public:
    Builder(const Index3& dims, const Vec3& spacing, const Vec3& origin, const Mat3& direction,
            const std::vector<std::int64_t>& selected)
        : dims_(dims), m_(frame_matrix(spacing, direction)), origin_(origin), selected_(selected)
    {
        for (std::size_t a = 0; a < 3; ++a) span_[a] = static_cast<std::uint64_t>(2 * dims[a] - 1);
        interior_base_ = span_[0] * span_[1] * span_[2];
    }

    bool wanted(std::int64_t a, std::int64_t b) const
    {
        return std::binary_search(selected_.begin(), selected_.end(), a) ||
               std::binary_search(selected_.begin(), selected_.end(), b);
    }

    // The vertex at doubled grid coordinates (X, Y, Z), made on first use.
    std::uint32_t grid_vertex(std::int64_t x, std::int64_t y, std::int64_t z)
    {
        const std::uint64_t key = static_cast<std::uint64_t>(x) +
                                  span_[0] * (static_cast<std::uint64_t>(y) + span_[1] * static_cast<std::uint64_t>(z));
        return vertex(key, {0.5 * static_cast<double>(x), 0.5 * static_cast<double>(y), 0.5 * static_cast<double>(z)});
    }

    // Interior point `slot` of cmc33's triangulation of cell (i, j, k).
    std::uint32_t interior_vertex(std::int64_t i, std::int64_t j, std::int64_t k, int slot,
                                  const std::array<double, 3>& unit)
    {
        const auto n = [&](std::size_t a) { return static_cast<std::uint64_t>(dims_[a] - 1); };
        const std::uint64_t cell = static_cast<std::uint64_t>(i) +
                                   n(0) * (static_cast<std::uint64_t>(j) + n(1) * static_cast<std::uint64_t>(k));
        const std::uint64_t key = interior_base_ + kInteriorSlots * cell + static_cast<std::uint64_t>(slot);
        return vertex(key, {static_cast<double>(i) + unit[0], static_cast<double>(j) + unit[1],
                            static_cast<double>(k) + unit[2]});
    }

    void add(const std::array<std::uint32_t, 3>& v, std::int64_t front, std::int64_t behind)
    {
        triangles_.push_back(Triangle{v, front, behind});
    }

    LabelSurfaces finish(LabelSurfaces out)
    {
        const bool flip = determinant(m_) < 0; // a mirroring frame reverses every winding
        out.interfaces.positions = std::move(positions_);
        out.interfaces.triangles.reserve(3 * triangles_.size());
        out.front.reserve(triangles_.size());
        out.behind.reserve(triangles_.size());
        for (const Triangle& t : triangles_) {
            out.interfaces.triangles.push_back(t.v[0]);
            out.interfaces.triangles.push_back(flip ? t.v[2] : t.v[1]);
            out.interfaces.triangles.push_back(flip ? t.v[1] : t.v[2]);
            out.front.push_back(t.front);
            out.behind.push_back(t.behind);
        }
        return out;
    }

private:
    std::uint32_t vertex(std::uint64_t key, const std::array<double, 3>& index)
    {
        const auto [it, added] = map_.try_emplace(key, static_cast<std::uint32_t>(positions_.size() / 3));
        if (added) {
            if (positions_.size() / 3 >= std::numeric_limits<std::uint32_t>::max()) {
                throw Error(Status::too_large, "the label surfaces have more than 4294967295 vertices");
            }
            for (std::size_t r = 0; r < 3; ++r) {
                positions_.push_back(
                    static_cast<float>(origin_[r] + m_[r][0] * index[0] + m_[r][1] * index[1] + m_[r][2] * index[2]));
            }
        }
        return it->second;
    }

    Index3 dims_;
    Mat3 m_;
    Vec3 origin_;
    const std::vector<std::int64_t>& selected_;
    std::array<std::uint64_t, 3> span_{};
    std::uint64_t interior_base_ = 0;
    std::unordered_map<std::uint64_t, std::uint32_t> map_;
    Buffer<float> positions_;
    std::vector<Triangle> triangles_;
};

using Doubled = std::array<int, 3>;

Doubled corner_doubled(unsigned c)
{
    return {2 * static_cast<int>(c & 1U), static_cast<int>(c & 2U), static_cast<int>(c >> 1 & 2U)};
}

Doubled midpoint(unsigned u, unsigned w)
{
    const Doubled a = corner_doubled(u), b = corner_doubled(w);
    return {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2};
}

// A cell with three or more labels: a triangle from the centre to every segment of every face's
// curve. A segment starts at the midpoint of a face edge (u, w) whose labels differ and ends at
// `to`; u's label lies on u's side of it.
template <class Emit> void many_label_cell(const std::array<std::int64_t, 8>& label, Emit&& emit)
{
    const Doubled centre{1, 1, 1};
    const auto segment = [&](unsigned u, unsigned w, const Doubled& to) {
        const Doubled m = midpoint(u, w), cu = corner_doubled(u);
        const Doubled p{m[0] - 1, m[1] - 1, m[2] - 1}, q{to[0] - 1, to[1] - 1, to[2] - 1};
        const Doubled n{p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0]};
        const int side = n[0] * (cu[0] - 1) + n[1] * (cu[1] - 1) + n[2] * (cu[2] - 1);
        // the triangle's plane meets the face along the segment's line, which misses the corner u
        if (side > 0)
            emit(centre, m, to, label[u], label[w]);
        else
            emit(centre, m, to, label[w], label[u]);
    };
    for (unsigned axis = 0; axis < 3; ++axis) {
        const unsigned b = (axis + 1) % 3, c = (axis + 2) % 3;
        for (unsigned s = 0; s < 2; ++s) {
            // the face's corners in cyclic order
            const std::array<unsigned, 4> q{s << axis, s << axis | 1U << b, s << axis | 1U << b | 1U << c,
                                            s << axis | 1U << c};
            std::array<std::int64_t, 4> l{label[q[0]], label[q[1]], label[q[2]], label[q[3]]};
            std::array<std::int64_t, 4> sorted = l;
            std::sort(sorted.begin(), sorted.end());
            const auto distinct = std::unique(sorted.begin(), sorted.end()) - sorted.begin();
            if (distinct == 1) continue;
            // a label on both ends of a diagonal is joined across the face (the lower one when both
            // diagonals are alike, cmc33's tie rule): the other corners are cut off
            const bool diagonal0 = l[0] == l[2], diagonal1 = l[1] == l[3];
            if (diagonal0 || diagonal1) {
                const std::int64_t joined = diagonal0 && diagonal1 ? sorted[0] : (diagonal0 ? l[0] : l[1]);
                for (unsigned i = 0; i < 4; ++i) {
                    if (l[i] != joined) segment(q[i], q[(i + 1) % 4], midpoint(q[(i + 3) % 4], q[i]));
                }
                continue;
            }
            if (distinct == 2) {
                std::array<unsigned, 2> crossed{};
                unsigned found = 0;
                for (unsigned i = 0; i < 4; ++i) {
                    if (l[i] != l[(i + 1) % 4]) crossed[found++] = i;
                }
                segment(q[crossed[0]], q[(crossed[0] + 1) % 4], midpoint(q[crossed[1]], q[(crossed[1] + 1) % 4]));
                continue;
            }
            Doubled face_centre{1, 1, 1};
            face_centre[axis] = 2 * static_cast<int>(s);
            for (unsigned i = 0; i < 4; ++i) {
                if (l[i] != l[(i + 1) % 4]) segment(q[i], q[(i + 1) % 4], face_centre);
            }
        }
    }
}

template <class T> LabelSurfaces run(const GridView<T>& g, const LabelOptions& options)
{
    LabelSurfaces out;
    // every label present, for the selection
    {
        std::unordered_set<std::int64_t> seen;
        bool any = false;
        T last{};
        for (std::int64_t k = 0; k < g.nz(); ++k)
            for (std::int64_t j = 0; j < g.ny(); ++j)
                for (std::int64_t i = 0; i < g.nx(); ++i) {
                    const T v = g(i, j, k);
                    if (any && v == last) continue;
                    any = true;
                    last = v;
                    seen.insert(static_cast<std::int64_t>(v));
                }
        out.present.assign(seen.begin(), seen.end());
        std::sort(out.present.begin(), out.present.end());
    }
    for (const std::int64_t v : out.present) {
        const bool chosen = options.labels.empty() ? v != options.background
                                                   : std::any_of(options.labels.begin(), options.labels.end(),
                                                                 [&](const auto& r) { return r[0] <= v && v <= r[1]; });
        if (chosen) out.selected.push_back(v);
    }
    Builder builder(g.dims, g.spacing, g.origin, g.direction, out.selected);
    if (g.nx() < 2 || g.ny() < 2 || g.nz() < 2 || out.selected.empty()) return builder.finish(std::move(out));
    const auto& table = patterns();
    std::array<std::int64_t, 8> label{};
    for (std::int64_t k = 0; k + 1 < g.nz(); ++k)
        for (std::int64_t j = 0; j + 1 < g.ny(); ++j)
            for (std::int64_t i = 0; i + 1 < g.nx(); ++i) {
                bool uniform = true;
                for (unsigned c = 0; c < 8; ++c) {
                    label[c] = static_cast<std::int64_t>(g(i + (c & 1U), j + (c >> 1 & 1U), k + (c >> 2 & 1U)));
                    uniform = uniform && label[c] == label[0];
                }
                if (uniform) continue;
                std::int64_t low = label[0], high = label[0];
                for (const std::int64_t l : label) {
                    low = std::min(low, l);
                    high = std::max(high, l);
                }
                bool two = true;
                for (const std::int64_t l : label) two = two && (l == low || l == high);
                const auto at = [&](const Doubled& d) {
                    return builder.grid_vertex(2 * i + d[0], 2 * j + d[1], 2 * k + d[2]);
                };
                if (two) {
                    ++out.cells_two_labels;
                    if (!builder.wanted(low, high)) continue;
                    unsigned config = 0;
                    for (unsigned c = 0; c < 8; ++c) config |= (label[c] == low ? 1U : 0U) << c;
                    for (const auto& tri : table[config].triangles) {
                        std::array<std::uint32_t, 3> v{};
                        for (std::size_t n = 0; n < 3; ++n) {
                            v[n] = tri[n].interior ? builder.interior_vertex(i, j, k, tri[n].slot, tri[n].unit)
                                                   : at(tri[n].doubled);
                        }
                        // cmc33's normals point from above (the lower label) to below
                        builder.add(v, high, low);
                    }
                    continue;
                }
                ++out.cells_many_labels;
                many_label_cell(label, [&](const Doubled& a, const Doubled& b, const Doubled& c, std::int64_t front,
                                           std::int64_t behind) {
                    if (builder.wanted(front, behind)) builder.add({at(a), at(b), at(c)}, front, behind);
                });
            }
    return builder.finish(std::move(out));
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

LabelSurfaces label_surfaces(const Volume& labels, const LabelOptions& options)
{
    if (labels.type() == ScalarType::f32 || labels.type() == ScalarType::f64) {
        throw Error(Status::unsupported_format,
                    "label maps need integer samples (int8 to uint32), got " + std::string(type_name(labels.type())));
    }
    return labels.visit([&](const auto& view) -> LabelSurfaces {
        using T = std::remove_cvref_t<decltype(*view.data)>;
        if constexpr (std::is_floating_point_v<T>) {
            return {};
        } else {
            return run(view, options);
        }
    });
}

Mesh label_surface(const LabelSurfaces& surfaces, std::int64_t label)
{
    const Mesh& all = surfaces.interfaces;
    Mesh out;
    // an unselected label's interfaces with other unselected labels were not made
    if (!std::binary_search(surfaces.selected.begin(), surfaces.selected.end(), label)) return out;
    std::vector<std::uint32_t> remap(all.vertex_count(), std::numeric_limits<std::uint32_t>::max());
    const auto use = [&](std::uint32_t v) {
        if (remap[v] == std::numeric_limits<std::uint32_t>::max()) {
            remap[v] = static_cast<std::uint32_t>(out.positions.size() / 3);
            for (std::size_t a = 0; a < 3; ++a) out.positions.push_back(all.positions[3 * v + a]);
        }
        out.triangles.push_back(remap[v]);
    };
    for (std::size_t t = 0; t < all.triangle_count(); ++t) {
        const bool in_front = surfaces.front[t] == label;
        if (!in_front && surfaces.behind[t] != label) continue;
        // normals point into `front`; the label's surface points out of it
        use(all.triangles[3 * t]);
        use(all.triangles[3 * t + (in_front ? 2 : 1)]);
        use(all.triangles[3 * t + (in_front ? 1 : 2)]);
    }
    return out;
}

} // namespace cmc33
