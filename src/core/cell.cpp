// analyze_cell: the extractor's decisions for one cell, with the numbers behind them. The
// decisions are the kernel's (decide.hpp); the report is derived from its Decision, and the mesh
// is extract() of the cell as a 2x2x2 grid, so both are the extractor's by construction.

#include "cmc33/cell.hpp"

#include <array>
#include <cmath>
#include <string>

#include "cmc33/error.hpp"
#include "cmc33/volume.hpp"
#include "cube.hpp"
#include "decide.hpp"
#include "mc33_tables.hpp"

namespace cmc33 {

namespace {

using namespace detail; // the kernel's numbering, tables and number types

/// The face saddle's value minus iso, for reports (rounded; the decision does not use it).
/// Computed in long double from the samples: with values near +-1e308, A C and A + C pass the
/// double range (x86-64 and AArch64 long doubles reach 1e4932), while the saddle, which lies
/// between the face's values, fits a double again. Where long double is double, such values give
/// inf or NaN here (callers print them as out of range) and the decision stays exact.
double face_saddle(const double* raw, double iso, int f)
{
    const auto p = face_cycle(f);
    const long double i = static_cast<long double>(iso);
    const long double A = static_cast<long double>(raw[p[0]]) - i, B = static_cast<long double>(raw[p[1]]) - i,
                      C = static_cast<long double>(raw[p[2]]) - i, D = static_cast<long double>(raw[p[3]]) - i;
    return static_cast<double>((A * C - B * D) / (A + C - B - D));
}

/// The numbers `cmc33 cell` shows (plain values, without the eps of the decisions), computed in
/// long double from the samples so that values near +-1e308 give finite roots and saddles (and
/// inf, not NaN, for a, b, c and F where those pass the double range; see face_saddle).
void report_numbers(const double* raw, double iso, double t_lewiner, const Variant& var, InteriorReport& r)
{
    using L = long double;
    L vl[8];
    for (int q = 0; q < 8; ++q) vl[q] = static_cast<L>(raw[q]) - static_cast<L>(iso);
    const SweepT<L> s(vl, var.axis, var.corner), lewiner(vl, var.lewiner_axis, var.lewiner_corner);
    r.tested = true;
    r.test = var.test == kTestTunnel ? "tunnel" : "13.5";
    r.axis = var.axis, r.corner_a = var.corner, r.corner_c = var.corner ^ 7;
    r.lewiner_axis = var.lewiner_axis, r.lewiner_corner = var.lewiner_corner, r.lewiner_edge = var.lewiner_edge;
    const L a = s.a(), b = s.b(), c = s.c();
    r.a = static_cast<double>(a), r.b = static_cast<double>(b), r.c = static_cast<double>(c);
    const L t_max = a != 0 ? -b / (2 * a) : L(kNaN);
    r.t_max = static_cast<double>(t_max);
    r.f_t_max = a != 0 ? static_cast<double>(s.F(t_max)) : kNaN;
    r.t_alt = t_lewiner;
    r.f_t_alt = static_cast<double>(lewiner.F(static_cast<L>(t_lewiner)));
    r.t1 = r.t2 = kNaN;
    L t1 = static_cast<L>(kNaN), t2 = static_cast<L>(kNaN);
    const L disc = b * b - 4 * a * c;
    if (a != 0 && disc >= 0) {
        const L q = -0.5L * (b + std::copysign(std::sqrt(disc), b)); // stable roots
        t1 = q / a, t2 = q != 0 ? c / q : t1;
        if (t1 > t2) std::swap(t1, t2);
        r.t1 = static_cast<double>(t1), r.t2 = static_cast<double>(t2);
    }
    const auto saddle = [&](L t) -> std::array<double, 2> {
        if (std::isnan(t)) return {kNaN, kNaN};
        const L a_t = SweepT<L>::at(s.A0, s.A1, t), b_t = SweepT<L>::at(s.B0, s.B1, t),
                d_t = SweepT<L>::at(s.D0, s.D1, t);
        const L den = s.den(t);
        return {static_cast<double>((a_t - d_t) / den), static_cast<double>((a_t - b_t) / den)};
    };
    r.saddle1 = saddle(t1), r.saddle2 = saddle(t2);
}

/// The report of the kernel's decision `d` on the cell (faces, interior numbers, the outcome).
void describe(const double* raw, double iso, unsigned config, Method method, const detail::Decision& d,
              CellReport& report)
{
    const unsigned amb = detail::kAmbiguousFaces[config];
    int i = 0;
    for (int f = 0; f < 6; ++f) {
        if (!((amb >> f) & 1u)) continue;
        if (method == Method::mc) {
            report.faces[static_cast<std::size_t>(f)] = {true, 0, false, false};
        } else {
            report.faces[static_cast<std::size_t>(f)] = {true, face_saddle(raw, iso, f), ((d.joined >> i) & 1u) != 0, true};
        }
        ++i;
    }
    const Variant& var = *d.variant;
    if (var.test == detail::kTestNone || method == Method::mc) return;
    double v[8];
    for (int q = 0; q < 8; ++q) v[q] = raw[q] - iso;
    InteriorReport& r = report.interior;
    report_numbers(raw, iso, detail::t_alt(v, var.lewiner_edge), var, r);
    r.skipped = method == Method::mc33_lewiner && (var.lewiner & detail::kLewinerSkips) != 0;
    r.tunnel = d.tiling != 0;
    if (r.tunnel && var.test == detail::kTest13_5) {
        // tiling 1 faces the above corner of the isolated diagonal (kept in lewiner_corner)
        r.tunnel_corner = d.tiling == 1 ? var.lewiner_corner : var.lewiner_corner ^ 7;
    }
}

} // namespace

CellReport analyze_cell(const std::array<double, 8>& values, double iso, Method method)
{
    if (!std::isfinite(iso)) throw Error(Status::non_finite, "isovalue is not a finite number");
    unsigned config = 0;
    for (int c = 0; c < 8; ++c) {
        if (!std::isfinite(values[static_cast<std::size_t>(c)])) {
            throw Error(Status::non_finite, "corner " + std::to_string(c) + " value is not a finite number");
        }
        config |= static_cast<unsigned>(values[static_cast<std::size_t>(c)] - iso >= 0) << c;
    }
    CellReport report;
    report.config = config;
    report.base_case = detail::kBaseCase[config];
    if (config == 0 || config == 255) return report;

    const detail::Decision d = detail::decide(values.data(), iso, config, method, detail::tables_of(method));
    report.subcase = d.subcase;
    describe(values.data(), iso, config, method, d, report);
    // Corner c at (c & 1, c >> 1 & 1, c >> 2 & 1) is sample (x, y, z) of a dense 2x2x2 grid.
    const auto view = GridView<double>::dense(values.data(), {2, 2, 2});
    ExtractOptions options;
    options.method = method;
    options.threads = 1;
    report.mesh = extract(view, iso, options);
    return report;
}

} // namespace cmc33
