#pragma once
// Internal: a triangle mesh being edited in place (collapses, vertex moves), with the incident
// triangles of each vertex, a uniform grid of triangle boxes, and the exact local checks every
// edit must pass: no triangle of zero area, none turned by more than 90 degrees, none meeting
// another improperly (the triangle-pair test of src/topology/exact_geometry.hpp).

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "cmc33/mesh.hpp"

namespace cmc33::mesh_ops {

using Pos = std::array<float, 3>;
using Tri = std::array<std::uint32_t, 3>;
using V3 = std::array<double, 3>;

inline V3 sub(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/// Squared distance from p to the closed triangle abc (Hausdorff samples, simplify's distance bound).
double point_triangle_sq(const V3& p, const V3& a, const V3& b, const V3& c);

/// Triangles by the grid cells their boxes overlap. Positions outside the grid's box clamp to its
/// border cells, so a moved vertex never falls out of it.
class TriangleGrid {
public:
    void build(const std::vector<Pos>& pos, const std::vector<Tri>& tri, const std::vector<std::uint8_t>& alive);
    void insert(std::uint32_t t, const std::array<Pos, 3>& corners);
    void remove(std::uint32_t t);
    /// Calls f(t) once per triangle whose cells overlap the box [lo, hi].
    template <class F> void query(const Pos& lo, const Pos& hi, F&& f);

private:
    std::array<int, 3> cell_of(const Pos& p) const;
    std::array<double, 3> origin_{};
    double inv_cell_ = 1;
    std::array<int, 3> dims_{1, 1, 1};
    std::vector<std::vector<std::uint32_t>> cells_;
    std::vector<std::array<int, 6>> range_; ///< per triangle: low and high cell, for remove()
    std::vector<std::uint32_t> mark_;
    std::uint32_t stamp_ = 0;
};

template <class F> void TriangleGrid::query(const Pos& lo, const Pos& hi, F&& f)
{
    const auto a = cell_of(lo);
    const auto b = cell_of(hi);
    if (++stamp_ == 0) {
        std::fill(mark_.begin(), mark_.end(), 0U);
        stamp_ = 1;
    }
    for (int z = a[2]; z <= b[2]; ++z)
        for (int y = a[1]; y <= b[1]; ++y)
            for (int x = a[0]; x <= b[0]; ++x) {
                const auto& cell = cells_[(static_cast<std::size_t>(z) * static_cast<std::size_t>(dims_[1]) +
                                           static_cast<std::size_t>(y)) * static_cast<std::size_t>(dims_[0]) +
                                          static_cast<std::size_t>(x)];
                for (const std::uint32_t t : cell) {
                    if (mark_[t] == stamp_) continue;
                    mark_[t] = stamp_;
                    f(t);
                }
            }
}

/// Why an edit was refused.
enum class Refusal { none, topology, flip, intersection };

struct WorkMesh {
    std::vector<Pos> pos;
    std::vector<Tri> tri;
    std::vector<std::uint8_t> alive;      ///< per triangle
    std::vector<std::uint8_t> locked;     ///< per vertex: on a non-manifold edge or vertex, or a degenerate triangle
    std::vector<std::uint8_t> boundary;   ///< per vertex: on a boundary edge
    std::vector<std::vector<std::uint32_t>> vtris; ///< per vertex: its live triangles
    std::int64_t alive_count = 0;
    std::int64_t grid_built_at = 0;
    TriangleGrid grid;

    /// Copies the mesh, finds locked and boundary vertices, builds the grid.
    /// @throws Error{invalid_argument} for bad indices or non-finite positions.
    explicit WorkMesh(const Mesh& mesh);

    std::array<Pos, 3> corners(std::uint32_t t) const { return {pos[tri[t][0]], pos[tri[t][1]], pos[tri[t][2]]}; }
    /// Rebuilds the grid when the live triangles have halved since it was built (its cells follow
    /// the mean edge length).
    void maybe_rebuild_grid();

    /// Checks triangles `changed` (indices into tri) given their new corner indices `corners` and
    /// positions (vertex `moved` at `p`), against every live triangle near them except `ignore`
    /// (triangles about to vanish). Returns the first reason to refuse, or none.
    Refusal check(std::span<const std::uint32_t> changed, std::span<const Tri> new_tris, std::uint32_t moved,
                  const Pos& p, std::span<const std::uint32_t> ignore);

    /// The mesh of the live triangles and the vertices they use (both in their original order);
    /// normals recomputed (area-weighted) when `normals`.
    Mesh to_mesh(bool normals) const;

private:
    std::vector<std::uint32_t> scratch_;
    std::vector<Pos> cand_lo_, cand_hi_;
};

/// Area-weighted vertex normals (unit length; a vertex without area gets (0, 0, 1)).
void compute_normals(Mesh& mesh);

} // namespace cmc33::mesh_ops
