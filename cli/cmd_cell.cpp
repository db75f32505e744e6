// cmc33 cell: every decision the extractor takes for one cell, with its numbers.

#include <array>
#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cmc33/cell.hpp"
#include "cmc33/io.hpp"
#include "cmc33/topology.hpp"
#include "commands.hpp"
#include "common.hpp"

namespace cmc33::cli {

namespace {

struct CellArgs {
    std::vector<double> values;
    double iso = 0;
    std::string method = "cmc33";
    bool json = false;
    std::string output;
};

constexpr const char* kAxis[3] = {"x", "y", "z"};

std::string corner_text(int c)
{
    return std::to_string(c) + " (" + std::to_string(c & 1) + "," + std::to_string(c >> 1 & 1) + "," +
           std::to_string(c >> 2 & 1) + ")";
}

std::string face_text(int f)
{
    return std::to_string(f) + " (" + kAxis[f / 2] + "=" + std::to_string(f % 2) + ")";
}

std::string binary(unsigned config)
{
    std::string s;
    for (int bit = 7; bit >= 0; --bit) s += (config >> bit & 1u) ? '1' : '0';
    return s;
}

/// "none" for NaN (no root, a == 0): the report's way of saying a number does not exist.
std::string maybe(double value) { return std::isnan(value) ? "none" : sig(value, 7); }

/// Computed numbers in the text: 7 significant digits (the JSON output has them all).
std::string g7(double value) { return sig(value, 7); }

std::string count(std::size_t n, const char* one, const char* many) { return std::to_string(n) + " " + (n == 1 ? one : many); }

Json interior_json(const InteriorReport& r)
{
    return Json{{"tested", r.tested},
                {"test", r.tested ? Json(r.test) : Json(nullptr)},
                {"axis", r.axis},
                {"corner_a", r.corner_a},
                {"corner_c", r.corner_c},
                {"a", json_number(r.a)},
                {"b", json_number(r.b)},
                {"c", json_number(r.c)},
                {"t1", json_number(r.t1)},
                {"t2", json_number(r.t2)},
                {"t_max", json_number(r.t_max)},
                {"f_t_max", json_number(r.f_t_max)},
                {"lewiner_axis", r.lewiner_axis},
                {"lewiner_corner", r.lewiner_corner},
                {"lewiner_edge", r.lewiner_edge},
                {"t_alt", json_number(r.t_alt)},
                {"f_t_alt", json_number(r.f_t_alt)},
                {"saddle1", {json_number(r.saddle1[0]), json_number(r.saddle1[1])}},
                {"saddle2", {json_number(r.saddle2[0]), json_number(r.saddle2[1])}},
                {"skipped", r.skipped},
                {"tunnel", r.tunnel},
                {"tunnel_corner", r.tunnel_corner}};
}

Json cell_json(const CellArgs& args, Method method, const CellReport& r, const MeshTopology& t)
{
    Json values = Json::array();
    for (double v : args.values) values.push_back(v);
    Json faces = Json::array();
    for (const FaceReport& f : r.faces) {
        faces.push_back({{"ambiguous", f.ambiguous},
                         {"saddle", f.ambiguous && f.used ? json_number(f.saddle) : Json(nullptr)},
                         {"joined", f.joined},
                         {"used", f.used}});
    }
    Json vertices = Json::array();
    for (std::size_t i = 0; i < r.mesh.vertex_count(); ++i) {
        vertices.push_back({pretty(r.mesh.positions[3 * i]), pretty(r.mesh.positions[3 * i + 1]),
                            pretty(r.mesh.positions[3 * i + 2])});
    }
    Json triangles = Json::array();
    for (std::size_t i = 0; i < r.mesh.triangle_count(); ++i) {
        triangles.push_back({r.mesh.triangles[3 * i], r.mesh.triangles[3 * i + 1], r.mesh.triangles[3 * i + 2]});
    }
    Json above = Json::array();
    for (int c = 0; c < 8; ++c) {
        if (r.config >> c & 1u) above.push_back(c);
    }
    return Json{{"values", values},
                {"iso", args.iso},
                {"method", std::string(method_name(method))},
                {"config", r.config},
                {"config_binary", binary(r.config)},
                {"above", above},
                {"base_case", r.base_case},
                {"subcase", std::string(subcase_name(r.subcase))},
                {"subcase_index", r.subcase},
                {"faces", faces},
                {"interior", interior_json(r.interior)},
                {"mesh", {{"vertices", vertices}, {"triangles", triangles}}},
                {"topology",
                 {{"euler", t.euler},
                  {"betti", {t.components, t.b1, t.closed_components}},
                  {"boundary_loops", t.boundary_loops},
                  {"components", t.components}}},
                {"output", args.output.empty() ? Json(nullptr) : Json(args.output)}};
}

void print_interior(const InteriorReport& r, Method method)
{
    if (!r.tested) {
        std::cout << "interior test: none\n";
        return;
    }
    std::cout << "interior test: " << r.test << ", sweeping along " << kAxis[r.axis] << " from corner A0 = "
              << corner_text(r.corner_a) << " to C1 = " << corner_text(r.corner_c) << '\n'
              << "  F(t) = A_t C_t - B_t D_t = a t^2 + b t + c (values minus iso): a = " << g7(r.a)
              << ", b = " << g7(r.b) << ", c = " << g7(r.c) << '\n'
              << "  roots: t1 = " << maybe(r.t1) << ", t2 = " << maybe(r.t2) << '\n'
              << "  t_max = -b/2a = " << maybe(r.t_max) << ", F(t_max) = " << maybe(r.f_t_max) << '\n'
              << "  Lewiner et al.: sweep along " << kAxis[r.lewiner_axis] << " from corner "
              << corner_text(r.lewiner_corner) << ", edge " << r.lewiner_edge << ": t_alt = " << maybe(r.t_alt)
              << ", F(t_alt) = " << maybe(r.f_t_alt) << '\n';
    if (r.test == "13.5" && (method == Method::cmc33 || method == Method::cmc33_paper)) { // Algorithm 1's numbers
        std::cout << "  slice saddles: x_c(t1) = (" << maybe(r.saddle1[0]) << ", " << maybe(r.saddle1[1])
                  << "), x_c(t2) = (" << maybe(r.saddle2[0]) << ", " << maybe(r.saddle2[1]) << ")\n";
    }
    if (r.skipped) {
        std::cout << "  skipped: mc33-lewiner never tests this branch (cases 10 and 12 with both faces joined)\n";
    }
    std::cout << "  decision: " << (r.tunnel ? "tunnel" : "no tunnel");
    if (r.tunnel && r.tunnel_corner >= 0) std::cout << ", facing corner " << corner_text(r.tunnel_corner);
    std::cout << '\n';
}

void print_cell(const CellArgs& args, Method method, const CellReport& r, const MeshTopology& t)
{
    std::cout << "method " << method_name(method) << ", iso " << num(args.iso) << '\n';
    std::cout << "corners (x,y,z) value:\n";
    for (int c = 0; c < 8; ++c) {
        std::cout << "  " << corner_text(c) << " " << num(args.values[static_cast<std::size_t>(c)])
                  << ((r.config >> c & 1u) ? "  above" : "  below") << '\n';
    }
    std::cout << "config " << r.config << " = " << binary(r.config) << " (bit c: corner c above iso), above:";
    bool any = false;
    for (int c = 0; c < 8; ++c) {
        if (r.config >> c & 1u) std::cout << " " << c, any = true;
    }
    std::cout << (any ? "" : " none") << '\n';
    std::cout << "base case " << r.base_case << ", subcase " << subcase_name(r.subcase) << '\n';
    std::cout << "faces (saddle: value minus iso at the bilinear saddle):\n";
    for (int f = 0; f < 6; ++f) {
        const FaceReport& face = r.faces[static_cast<std::size_t>(f)];
        std::cout << "  face " << face_text(f) << ": ";
        if (!face.ambiguous) {
            std::cout << "not ambiguous\n";
        } else if (!face.used) {
            std::cout << "ambiguous, not used (method " << method_name(method) << ")\n";
        } else {
            std::cout << "ambiguous, saddle "
                      << (std::isfinite(face.saddle) ? g7(face.saddle) : "beyond the double range") << ", "
                      << (face.joined ? "joined" : "separated") << '\n';
        }
    }
    print_interior(r.interior, method);
    std::cout << "mesh: " << count(r.mesh.vertex_count(), "vertex", "vertices") << ", "
              << count(r.mesh.triangle_count(), "triangle", "triangles") << " (unit cube coordinates)\n";
    for (std::size_t i = 0; i < r.mesh.vertex_count(); ++i) {
        std::cout << "  v" << i << " (" << num(r.mesh.positions[3 * i]) << ", " << num(r.mesh.positions[3 * i + 1])
                  << ", " << num(r.mesh.positions[3 * i + 2]) << ")\n";
    }
    for (std::size_t i = 0; i < r.mesh.triangle_count(); ++i) {
        std::cout << "  t" << i << " " << r.mesh.triangles[3 * i] << " " << r.mesh.triangles[3 * i + 1] << " "
                  << r.mesh.triangles[3 * i + 2] << '\n';
    }
    std::cout << "topology: euler " << t.euler << ", components " << t.components << ", boundary loops "
              << t.boundary_loops << ", betti " << t.components << " " << t.b1 << " " << t.closed_components
              << '\n';
    if (!args.output.empty()) std::cout << "written to " << args.output << '\n';
}

void run_cell(const CellArgs& args)
{
    if (args.values.size() != 8) {
        throw UsageError("cell takes 8 corner values, got " + std::to_string(args.values.size()));
    }
    const Method method = parse_method(args.method);
    check_mesh_output(args.output, false);
    std::array<double, 8> values{};
    for (std::size_t c = 0; c < 8; ++c) values[c] = args.values[c];
    const CellReport report = analyze_cell(values, args.iso, method);
    const MeshTopology topology = mesh_topology(report.mesh);
    if (!args.output.empty()) io::write_mesh(report.mesh, args.output);
    if (args.json) {
        print_json(cell_json(args, method, report, topology));
    } else {
        print_cell(args, method, report, topology);
    }
}

} // namespace

void add_cell(CLI::App& app)
{
    auto args = std::make_shared<CellArgs>();
    CLI::App* cmd = app.add_subcommand("cell", "Explain how one cell is classified and triangulated");
    cmd->add_option("VALUES", args->values, "The 8 corner values, corner c = x | y<<1 | z<<2")
        ->expected(8)
        ->required()
        ->type_name("V")
        ->check(number_check());
    cmd->add_option("-i,--iso", args->iso, "Isovalue (default 0)")->check(number_check());
    cmd->add_option("--method", args->method, "cmc33 (default), cmc33-paper, chernyaev, mc33-lewiner or mc")
        ->type_name("NAME")
        ->check(method_validator());
    cmd->add_flag("--json", args->json, "Print one JSON object");
    cmd->add_option("-o,--output", args->output, "Write the cell's mesh: .ply .obj .stl .off .glb .gltf .vtp .gii")
        ->type_name("OUT")
        ->check(non_empty("a mesh file name"));
    cmd->footer(
        "Takes the values at the 8 corners of one cell, in the order (0,0,0) (1,0,0) (0,1,0)\n"
        "(1,1,0) (0,0,1) (1,0,1) (0,1,1) (1,1,1), i.e. corner c = x | y<<1 | z<<2, and prints every\n"
        "decision the extractor takes for it: the sign configuration (a value equal to iso counts\n"
        "as above), the base case and subcase of MC33, the asymptotic decider on each ambiguous\n"
        "face, the numbers of the interior test (Chernyaev's quadratic F(t), its roots and maximum,\n"
        "Lewiner's t_alt, the 13.5 saddles) and the decision, then the cell's triangles in the unit\n"
        "cube and their topology. Negative values are values, not options.\n"
        "\n"
        "Examples:\n"
        "  cmc33 cell 1 -1 -1 -1 -1 -1 -1 -1\n"
        "  cmc33 cell -0.5 0.2 0.3 -0.4 0.6 -0.1 -0.7 0.8 --method mc33-lewiner --json");
    cmd->callback([args] { run_cell(*args); });
}

} // namespace cmc33::cli
