#pragma once
/// @file mesh.hpp
/// An indexed triangle mesh: a vertex is shared by every triangle that uses it.

#include <cstdint>
#include <vector>

namespace cmc33 {

struct Mesh {
    std::vector<float> positions;        ///< 3 per vertex, world coordinates
    std::vector<float> normals;          ///< empty, or 3 per vertex (unit length)
    std::vector<std::uint32_t> triangles; ///< 3 vertex indices per triangle, counter-clockwise
                                         ///< seen from the side the normal points to

    std::size_t vertex_count() const noexcept { return positions.size() / 3; }
    std::size_t triangle_count() const noexcept { return triangles.size() / 3; }
    bool has_normals() const noexcept { return !normals.empty(); }
};

} // namespace cmc33
