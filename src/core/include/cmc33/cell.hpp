#pragma once
/// @file cell.hpp
/// A person's window into one cell: every decision the extractor takes for it, with its numbers.

#include <array>
#include <string>

#include "cmc33/extract.hpp"
#include "cmc33/mesh.hpp"
#include "cmc33/core_export.hpp"

namespace cmc33 {

struct FaceReport {
    bool ambiguous = false;  ///< the above corners of the face are diagonal
    double saddle = 0;       ///< field value at the face's bilinear saddle (ambiguous faces)
    bool joined = false;     ///< the above corners are joined across the face (saddle >= iso)
    bool used = false;       ///< false where the method ignores the face test (mc)
};

struct InteriorReport {
    bool tested = false;       ///< an interior test ran
    std::string test;          ///< "tunnel" (4.1 6.1 7.4 10.1 12.1) or "13.5"
    int axis = 0;              ///< sweep axis (0 x, 1 y, 2 z)
    int corner_a = 0;          ///< A0: the tested corner on the first face of the sweep
    int corner_c = 0;          ///< C1 = A0 ^ 7, the diagonally opposite corner
    double a = 0, b = 0, c = 0; ///< F(t) = A_t C_t - B_t D_t = a t^2 + b t + c (values minus iso)
    double t1 = 0, t2 = 0;     ///< real roots of F (NaN when none)
    double t_max = 0;          ///< -b / 2a (NaN when a == 0)
    double f_t_max = 0;        ///< F(t_max)
    int lewiner_axis = 0, lewiner_corner = 0, lewiner_edge = 0;
    double t_alt = 0;          ///< Lewiner et al.'s height: where the field crosses lewiner_edge
    double f_t_alt = 0;        ///< F(t_alt) on Lewiner's sweep
    std::array<double, 2> saddle1{0, 0}, saddle2{0, 0}; ///< x_c(t1), x_c(t2) in the slice (13.5)
    bool skipped = false;      ///< mc33-lewiner's missing branch of cases 10 and 12
    bool tunnel = false;       ///< the decision
    int tunnel_corner = -1;    ///< 13.5.2: the corner of the isolated diagonal the tunnel faces
};

struct CellReport {
    unsigned config = 0;  ///< bit c: corner c above iso; corner c = x | y << 1 | z << 2
    int base_case = 0;    ///< 0..14
    int subcase = 0;      ///< index for subcase_name()
    std::array<FaceReport, 6> faces{}; ///< face f = 2 * axis + side
    InteriorReport interior;
    Mesh mesh;            ///< the cell's triangles in the unit cube [0,1]^3
};

/// Classifies and triangulates one cell exactly as extract() does.
/// @param values  corner values, corner c at (c & 1, c >> 1 & 1, c >> 2 & 1)
/// @throws Error{non_finite} for a NaN or infinite value or iso
CMC33_CORE_EXPORT CellReport analyze_cell(const std::array<double, 8>& values, double iso, Method method = Method::cmc33);

} // namespace cmc33
