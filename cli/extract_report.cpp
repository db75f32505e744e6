// What `cmc33 extract` prints (extract_report.hpp): shared by the in-memory run, the run slab by
// slab (--memory-limit) and cmc33-mpi.

#include "extract_report.hpp"

#include <iostream>
#include <string>

#include "plural.hpp"

namespace cmc33::cli {

void print_extract_report(const ExtractArgs& args, const ExtractReport& r)
{
    if (args.json) {
        // Subcase "0" (no crossing) is left out: extract counts the cells the surface crosses.
        Json subcases = Json::object();
        for (int s = 1; s < kSubcaseCount; ++s) {
            subcases[std::string(subcase_name(s))] = r.stats.cells_per_subcase[static_cast<std::size_t>(s)];
        }
        Json geometry = nullptr;
        if (!args.no_topology) {
            geometry = geometry_json(r.geometry);
            if (!r.welded_known) geometry["welded"] = nullptr; // not computed slab by slab: vertices coincide
        }
        Json out{{"input", r.volume},
                 {"iso", args.iso},
                 {"method", std::string(method_name(r.method))},
                 {"normals", args.normals},
                 {"vertices", r.vertices},
                 {"triangles", r.triangles},
                 {"seconds", r.seconds},
                 {"runs_seconds", r.runs_seconds},
                 {"threads", r.threads},
                 {"output", args.output.empty() ? Json(nullptr) : Json(args.output)},
                 {"topology", !args.no_topology ? topology_json(r.topology) : Json(nullptr)},
                 {"geometry", geometry},
                 // cmc33-paper: planes the Sec. 6.2 refinement added (0: none needed); null for the others
                 {"refinement_planes", r.method == Method::cmc33_paper ? Json(r.stats.refinement_planes) : Json(nullptr)}};
        for (auto it = r.extra.begin(); it != r.extra.end(); ++it) out[it.key()] = it.value();
        out["subcases"] = subcases; // last, as in docs/cli.md's table: the long one
        print_json(out);
        return;
    }
    const MeshTopology& topology = r.topology;
    const MeshGeometry& geometry = r.geometry;
    std::string line = args.input + ": " + dims_text(r.dims) + " " + std::string(type_name(r.type)) +
                       ", iso " + num(args.iso) + ", " + std::string(method_name(r.method)) + ": " +
                       counted(r.vertices, "vertex", "vertices") + ", " + counted(r.triangles, "triangle") + " in " +
                       sig(r.seconds, 3) + " s";
    if (args.repeat > 1) line += " (median of " + std::to_string(args.repeat) + ")";
    if (!args.no_topology) {
        line += "; euler " + std::to_string(topology.euler) + ", components " +
                std::to_string(topology.components) + ", boundary edges " +
                std::to_string(topology.boundary_edges) + ", non-manifold edges " +
                std::to_string(topology.nonmanifold_edges);
    }
    if (!args.no_topology && topology.nonmanifold_vertices != 0) {
        line += ", non-manifold vertices " + std::to_string(topology.nonmanifold_vertices);
    }
    if (!args.no_topology) {
        line += geometry.embedded() ? ", embedded"
                                    : ", NOT embedded (" +
                                          counted(geometry.coincident_vertices, "coincident vertex", "coincident vertices") +
                                          ", " + counted(geometry.zero_area_triangles, "zero-area triangle") + ", " +
                                          counted(geometry.intersecting_pairs, "intersecting triangle pair") + ")";
    }
    if (!r.steps_text.empty()) line += "; then " + r.steps_text;
    if (!args.output.empty()) line += " (" + args.output + ")";
    std::cout << line << '\n';
}

} // namespace cmc33::cli
