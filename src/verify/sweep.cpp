// sweep(): isosurface topology over isovalues and methods (contract in cmc33/sweep.hpp).
//
// The volume is read once by the caller and shared; every isovalue is a task of its own, its
// methods' extractions single-threaded one after the other (each mesh freed before the next), so
// two cores run two isovalues at once: a 256^3 volume at an isovalue costs tens of milliseconds
// per method, far too little to split. Rows land at fixed places, so the report is the same for
// every thread count.

#include "cmc33/sweep.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "cmc33/error.hpp"
#include "parallel.hpp"
#include "verify_detail.hpp"

namespace cmc33 {

std::vector<double> sweep_isovalues(double from, double to, double step)
{
    const auto text = [](double v) { return verification::detail::number_text(v); };
    if (!std::isfinite(from) || !std::isfinite(to) || !std::isfinite(step) || !(step > 0) || !(from <= to)) {
        throw Error(Status::invalid_argument, "isovalues " + text(from) + ":" + text(to) + ":" + text(step) +
                                                  ": expected FROM <= TO and STEP > 0, all finite");
    }
    const double steps = std::floor((to - from) / step + 1e-6);
    if (!(steps < 1e6)) {
        throw Error(Status::invalid_argument, "isovalues " + text(from) + ":" + text(to) + ":" + text(step) + ": " +
                                                  text(steps + 1) + " values; expected at most 1000000");
    }
    std::vector<double> out;
    for (std::int64_t i = 0; i <= static_cast<std::int64_t>(steps); ++i) {
        char buffer[40];
        std::snprintf(buffer, sizeof buffer, "%.15g", from + static_cast<double>(i) * step);
        out.push_back(std::strtod(buffer, nullptr));
    }
    return out;
}

SweepReport sweep(const Volume& volume, const SweepOptions& options)
{
    if (options.isovalues.empty()) throw Error(Status::invalid_argument, "sweep: no isovalue; expected at least one");
    for (double iso : options.isovalues) {
        if (!std::isfinite(iso)) {
            throw Error(Status::non_finite, "sweep: isovalue " + verification::detail::number_text(iso) +
                                                " is not a finite number");
        }
    }
    verification::detail::check_methods(options.methods);
    const auto n = static_cast<std::int64_t>(options.isovalues.size());
    const std::size_t per_iso = options.methods.size();
    SweepReport report;
    report.threads = detail::threads_for(options.threads, n);
    report.rows.resize(static_cast<std::size_t>(n) * per_iso);
    std::atomic<std::int64_t> none{0};
    verification::detail::Ticker tick(options.progress, n, &none);
    verification::detail::run_parallel(n, report.threads, 1, tick, [&](int, std::int64_t begin, std::int64_t end) {
        for (std::int64_t i = begin; i < end; ++i) {
            const double iso = options.isovalues[static_cast<std::size_t>(i)];
            for (std::size_t m = 0; m < per_iso; ++m) {
                ExtractOptions extract_options;
                extract_options.method = options.methods[m];
                extract_options.threads = 1;
                SweepRow& row = report.rows[static_cast<std::size_t>(i) * per_iso + m];
                row.iso = iso;
                row.method = options.methods[m];
                {
                    const Mesh mesh = extract(volume, iso, extract_options);
                    const MeshTopology t = mesh_topology(mesh);
                    row.vertices = static_cast<std::int64_t>(mesh.vertex_count());
                    row.triangles = static_cast<std::int64_t>(mesh.triangle_count());
                    row.euler = t.euler;
                    row.b0 = t.components;
                    row.b1 = t.b1;
                    row.b2 = t.closed_components;
                    row.boundary_loops = t.boundary_loops;
                    row.nonmanifold_edges = t.nonmanifold_edges;
                }
                if (options.expected && row.method == Method::cmc33) {
                    FieldTopology f = field_topology(volume, iso);
                    if (f.determined) row.expected = std::move(f);
                }
            }
        }
    });
    report.seconds = tick.seconds();
    tick(n);
    return report;
}

} // namespace cmc33
