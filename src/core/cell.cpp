#include "cmc33/cell.hpp"

#include <cmath>
#include <string>

#include "cmc33/error.hpp"
#include "cube.hpp"
#include "decide.hpp"
#include "placement.hpp"
#include "mc33_tables.hpp"

namespace cmc33 {

CellReport analyze_cell(const std::array<double, 8>& values, double iso, Method method)
{
    if (!std::isfinite(iso)) throw Error(Status::non_finite, "isovalue is not a finite number");
    double v[8];
    unsigned config = 0;
    for (int c = 0; c < 8; ++c) {
        if (!std::isfinite(values[static_cast<std::size_t>(c)])) {
            throw Error(Status::non_finite, "corner " + std::to_string(c) + " value is not a finite number");
        }
        v[c] = values[static_cast<std::size_t>(c)] - iso;
        config |= static_cast<unsigned>(v[c] >= 0) << c;
    }
    CellReport report;
    report.config = config;
    report.base_case = detail::kBaseCase[config];
    if (config == 0 || config == 255) return report;

    const detail::Decision d = detail::decide(values.data(), iso, config, method, &report);
    report.subcase = d.subcase;
    const detail::Tiling& tl = d.variant->tilings[d.tiling];
    // Crossing positions in the unit cube, placed as extract() places them (core/placement.hpp).
    double crossing[12][3];
    for (int e = 0; e < 12; ++e) {
        const int a = detail::kEdgeCorners[e][0], b = detail::kEdgeCorners[e][1];
        const double t = (v[a] >= 0) != (v[b] >= 0) ? detail::clamp_crossing(v[a] / (v[a] - v[b]), detail::kMinCrossing) : 0.5;
        for (int c = 0; c < 3; ++c) crossing[e][c] = ((a >> c) & 1) + (c == e / 4 ? t : 0.0);
    }
    int index[12];
    for (int e = 0; e < 12; ++e) {
        index[e] = -1;
        if ((v[detail::kEdgeCorners[e][0]] >= 0) == (v[detail::kEdgeCorners[e][1]] >= 0)) continue;
        index[e] = static_cast<int>(report.mesh.vertex_count());
        for (double x : crossing[e]) report.mesh.positions.push_back(static_cast<float>(x));
    }
    const int first_interior = static_cast<int>(report.mesh.vertex_count());
    for (int q = 0; q < tl.interior_count; ++q) {
        double p[3];
        detail::interior_position(detail::kInteriorMasks[tl.first_interior + q], crossing, p);
        for (double x : p) report.mesh.positions.push_back(static_cast<float>(x));
    }
    for (int q = 0; q < 3 * tl.triangle_count; ++q) {
        const int code = detail::kTriangleCodes[static_cast<std::size_t>(tl.first_triangle) * 3 + static_cast<std::size_t>(q)];
        report.mesh.triangles.push_back(static_cast<std::uint32_t>(code < 12 ? index[code] : first_interior + code - 12));
    }
    return report;
}

} // namespace cmc33
