// cmc33 topo: the combinatorial topology of a mesh file.

#include <iostream>
#include <memory>
#include <new>
#include <string>

#include "cmc33/io.hpp"
#include "cmc33/topology.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "plural.hpp"

namespace cmc33::cli {

namespace {

struct TopoArgs {
    std::string input;
    bool json = false;
    bool geometry = true;
};

const char* yes_no(bool b) { return b ? "yes" : "no"; }

void run_topo(const TopoArgs& args)
{
    const Mesh mesh = named_step(args.input, "reading the mesh", [&] { return io::read_mesh(args.input); });
    const MeshTopology t = named_step(args.input, "computing the mesh's topology", [&] { return mesh_topology(mesh); });
    MeshGeometry g;
    if (args.geometry) {
        try {
            g = mesh_geometry(mesh);
        } catch (const Error& e) {
            // the library's "mesh_geometry: " is a function name; the user needs the way around it
            std::string why = e.what();
            if (const std::string prefix = "mesh_geometry: "; why.starts_with(prefix)) why.erase(0, prefix.size());
            throw Error(e.status(), args.input + ": cannot check the mesh in space: " + why +
                                        "; --no-geometry gives its topology without that check");
        } catch (const std::bad_alloc&) {
            throw Error(Status::too_large, args.input + ": out of memory while checking the mesh in space; "
                                                        "--no-geometry gives its topology without that check");
        }
    }
    if (args.json) {
        Json out{{"file", args.input},
                 {"vertices", t.vertices},
                 {"edges", t.edges},
                 {"faces", t.faces},
                 {"file_vertices", mesh.vertex_count()}};
        out.update(topology_json(t));
        out["geometry"] = args.geometry ? geometry_json(g) : Json(nullptr);
        print_json(out);
        return;
    }
    std::cout << args.input << ": " << counted(t.vertices, "vertex", "vertices") << ", " << counted(t.edges, "edge")
              << ", " << counted(t.faces, "face");
    if (static_cast<std::int64_t>(mesh.vertex_count()) != t.vertices) {
        const std::int64_t unused = static_cast<std::int64_t>(mesh.vertex_count()) - t.vertices;
        std::cout << " (the file has " << counted(mesh.vertex_count(), "vertex", "vertices") << "; " << unused
                  << (unused == 1 ? " is" : " are") << " used by no triangle)";
    }
    std::cout << '\n'
              << "euler " << t.euler << ", betti " << t.components << " " << t.b1 << " " << t.closed_components
              << " (b0 b1 b2)\n"
              << "components " << t.components << ", closed components " << t.closed_components << '\n'
              << "boundary edges " << t.boundary_edges << ", boundary loops " << t.boundary_loops << '\n'
              << "non-manifold edges " << t.nonmanifold_edges << ", non-manifold vertices "
              << t.nonmanifold_vertices << '\n'
              << "degenerate triangles " << t.degenerate_triangles << '\n'
              << "closed " << yes_no(t.closed) << ", oriented " << yes_no(t.oriented) << '\n';
    if (args.geometry) {
        std::cout << "in space: " << (g.embedded() ? "embedded" : "NOT embedded") << "; "
                  << counted(g.positions, "distinct position") << ", coincident vertices " << g.coincident_vertices
                  << ", zero-area triangles " << g.zero_area_triangles << ", intersecting triangle pairs "
                  << g.intersecting_pairs << '\n';
        for (const auto& pair : g.intersection_examples) {
            std::cout << "  triangles " << pair[0] << " and " << pair[1] << " meet improperly\n";
        }
        const MeshTopology& w = g.welded;
        std::cout << "welded by position: " << counted(w.vertices, "vertex", "vertices") << ", euler " << w.euler << ", betti "
                  << w.components << " " << w.b1 << " " << w.closed_components << ", boundary loops "
                  << w.boundary_loops << ", non-manifold edges " << w.nonmanifold_edges
                  << ", non-manifold vertices " << w.nonmanifold_vertices << '\n';
    }
    if (t.nonmanifold_edges != 0 || t.nonmanifold_vertices != 0) {
        std::cout << "note: the mesh is not a manifold, so b1 = b0 + b2 - euler is not its first Betti number\n";
    }
}

} // namespace

void add_topo(CLI::App& app)
{
    auto args = std::make_shared<TopoArgs>();
    CLI::App* cmd = app.add_subcommand("topo", "Topology of a mesh file: Euler characteristic, Betti numbers, manifoldness");
    cmd->add_option("MESH", args->input, "Mesh: .ply .obj .stl .off")->required();
    cmd->add_flag("--json", args->json, "Print one JSON object");
    cmd->add_flag("!--no-geometry", args->geometry,
                  "Skip the checks in space (coincident vertices, zero-area and intersecting triangles)");
    cmd->footer(
        "Reads MESH and prints its combinatorial invariants: vertices used by triangles (V), edges\n"
        "(E), triangles (F), the Euler characteristic V - E + F, the Betti numbers b0 (components),\n"
        "b1 and b2 (closed components), boundary edges and loops, non-manifold edges (more than two\n"
        "triangles) and vertices (more than one fan), degenerate triangles, and whether the mesh is\n"
        "closed and consistently oriented; then, in space: coincident vertices, zero-area triangles\n"
        "and pairs of triangles that meet other than at a shared edge or corner (exact predicates),\n"
        "and the same invariants after welding vertices by position. A sphere-like closed surface has euler 2 and betti 1 0 1;\n"
        "a torus euler 0 and betti 1 2 1. STL files have no shared vertices: coincident ones are\n"
        "welded when read.\n"
        "\n"
        "Example:\n"
        "  cmc33 topo vessels.ply --json");
    cmd->callback([args] { run_topo(*args); });
}

} // namespace cmc33::cli
