// Tallies, failure records and failures.tsv: what verify() and the CLI's dataset check share.

#include <algorithm>
#include <array>
#include <charconv>
#include <fstream>
#include <set>
#include <string>
#include <system_error>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "cmc33/verify.hpp"
#include "verify_detail.hpp"

namespace cmc33 {
namespace verification::detail {
namespace {

void add(MethodReport& into, const MethodReport& from)
{
    into.checked += from.checked;
    into.matched += from.matched;
    into.mismatched += from.mismatched;
    into.topology_mismatched += from.topology_mismatched;
    into.undetermined += from.undetermined;
    into.nonmanifold += from.nonmanifold;
    into.unoriented += from.unoriented;
    into.not_embedded += from.not_embedded;
    into.errors += from.errors;
    for (std::size_t k = 0; k < into.checked_by_kind.size(); ++k) {
        into.checked_by_kind[k] += from.checked_by_kind[k];
        into.mismatched_by_kind[k] += from.mismatched_by_kind[k];
        into.topology_mismatched_by_kind[k] += from.topology_mismatched_by_kind[k];
    }
    for (std::size_t s = 0; s < into.fields_per_subcase.size(); ++s) {
        into.fields_per_subcase[s] += from.fields_per_subcase[s];
        into.mismatches_per_subcase[s] += from.mismatches_per_subcase[s];
        into.topology_mismatches_per_subcase[s] += from.topology_mismatches_per_subcase[s];
        into.cells_per_subcase[s] += from.cells_per_subcase[s];
        into.cell_topology_mismatches_per_subcase[s] += from.cell_topology_mismatches_per_subcase[s];
    }
}

void trim(std::vector<Failure>& failures, int max_failures)
{
    std::sort(failures.begin(), failures.end(),
              [](const Failure& a, const Failure& b) { return a.order < b.order; });
    if (failures.size() > static_cast<std::size_t>(max_failures))
        failures.resize(static_cast<std::size_t>(max_failures));
}

std::string tsv_field(std::string text)
{
    for (char& c : text) {
        if (c == '\t' || c == '\n' || c == '\r') c = ' ';
    }
    return text.empty() ? "-" : text;
}

/// `cmc33 cell v0 ... v7 --method M` for a 2x2x2 field (values exactly as stored).
std::string cell_command(const Volume& volume, double iso, std::string_view method)
{
    std::string line = "cmc33 cell";
    volume.visit([&](auto view) {
        for (int c = 0; c < 8; ++c)
            line += " " + number_text(static_cast<double>(view(c & 1, c >> 1 & 1, c >> 2 & 1)));
    });
    if (iso != 0) line += " --iso " + number_text(iso);
    line += " --method " + std::string(method);
    return line;
}

} // namespace

bool is_ambiguous_subcase(int subcase) noexcept
{
    return subcase_name(subcase).find('.') != std::string_view::npos;
}

bool record(Tally& tally, Outcome&& outcome, int max_failures)
{
    MethodReport& r = tally.report;
    const auto k = static_cast<std::size_t>(outcome.kind);
    const bool cell = outcome.kind == FieldKind::cell;
    ++r.checked;
    ++r.checked_by_kind[k];
    for (int s : outcome.subcases) {
        ++r.fields_per_subcase[static_cast<std::size_t>(s)];
        if (cell) ++r.cells_per_subcase[static_cast<std::size_t>(s)];
    }
    std::optional<MeshTopology> got;
    bool ok = false;
    if (!outcome.mesh) {
        ++r.errors;
    } else {
        got = mesh_topology(*outcome.mesh);
        if (!topology_matches(*got, *outcome.expected)) {
            ++r.topology_mismatched;
            ++r.topology_mismatched_by_kind[k];
            for (int s : outcome.subcases) {
                ++r.topology_mismatches_per_subcase[static_cast<std::size_t>(s)];
                if (cell) ++r.cell_topology_mismatches_per_subcase[static_cast<std::size_t>(s)];
            }
        }
        const bool manifold = is_manifold(*got);
        if (!manifold) ++r.nonmanifold;
        if (got->faces > 0 && !got->oriented) ++r.unoriented;
        // In space too: embedded, and still right once welded by position (what users' tools do).
        const MeshGeometry geometry = mesh_geometry(*outcome.mesh, MeshGeometryOptions{1, 1});
        if (!geometry.embedded()) {
            ++r.not_embedded;
            if (!outcome.note.empty()) outcome.note += "; ";
            outcome.note += "not embedded: " + std::to_string(geometry.coincident_vertices) + " coincident vertices, " +
                            std::to_string(geometry.zero_area_triangles) + " zero-area triangles, " +
                            std::to_string(geometry.intersecting_pairs) + " intersecting triangle pairs";
        }
        ok = manifold && topology_matches(*got, *outcome.expected) && geometry.embedded() &&
             is_manifold(geometry.welded) && topology_matches(geometry.welded, *outcome.expected);
    }
    if (ok) {
        ++r.matched;
        return true;
    }
    ++r.mismatched;
    ++r.mismatched_by_kind[k];
    for (int s : outcome.subcases) ++r.mismatches_per_subcase[static_cast<std::size_t>(s)];
    if (max_failures <= 0) return false;

    Failure f;
    f.order = outcome.order;
    f.name = std::move(outcome.name);
    f.kind = outcome.kind;
    f.volume = std::move(outcome.volume);
    f.iso = outcome.iso;
    f.expected = *outcome.expected;
    f.got = got;
    f.mesh = std::move(outcome.mesh);
    for (int s : outcome.subcases) {
        if (!f.subcases.empty()) f.subcases += ',';
        f.subcases += subcase_name(s);
    }
    f.note = std::move(outcome.note);
    tally.failures.push_back(std::move(f));
    if (tally.failures.size() > 2 * static_cast<std::size_t>(max_failures)) {
        trim(tally.failures, max_failures);
    }
    return false;
}

void check_methods(const std::vector<Method>& methods)
{
    if (methods.empty()) {
        throw Error(Status::invalid_argument, "verify: no method to verify; expected at least one");
    }
    for (std::size_t i = 0; i < methods.size(); ++i) {
        if (std::find(methods.begin(), methods.begin() + static_cast<std::ptrdiff_t>(i),
                      methods[i]) != methods.begin() + static_cast<std::ptrdiff_t>(i)) {
            throw Error(Status::invalid_argument, "verify: method " +
                                                      std::string(method_name(methods[i])) +
                                                      " is listed twice; expected each once");
        }
    }
}

std::vector<std::vector<Tally>> make_tallies(int threads, const std::vector<Method>& methods,
                                             bool external)
{
    std::vector<Tally> one(external ? 1 : methods.size());
    for (std::size_t m = 0; m < one.size(); ++m) {
        MethodReport& r = one[m].report;
        r.external = external;
        r.method = external ? Method::cmc33 : methods[m];
        r.name = external ? "command" : std::string(method_name(r.method));
    }
    return std::vector<std::vector<Tally>>(static_cast<std::size_t>(threads), one);
}

std::vector<Tally> merge(std::vector<std::vector<Tally>>& per_thread, int max_failures)
{
    std::vector<Tally> total = std::move(per_thread.front());
    for (std::size_t t = 1; t < per_thread.size(); ++t) {
        for (std::size_t m = 0; m < total.size(); ++m) {
            add(total[m].report, per_thread[t][m].report);
            for (Failure& f : per_thread[t][m].failures) total[m].failures.push_back(std::move(f));
        }
    }
    for (Tally& tally : total) trim(tally.failures, std::max(max_failures, 0));
    return total;
}

void finish(std::vector<Tally>& tallies, const std::filesystem::path& dir, const RerunCommand& rerun_external,
            VerifyReport& report)
{
    bool any = false;
    for (Tally& t : tallies) {
        any = any || !t.failures.empty();
        for (const Failure& f : t.failures) { // in run order (merge trims and sorts them)
            if (f.mesh) continue;
            t.report.first_error = f.name + ": " + f.note;
            break;
        }
    }
    if (any && !dir.empty()) {
        std::error_code ec;
        std::filesystem::create_directories(dir, ec);
        if (ec) {
            throw Error(Status::io_error,
                        dir.string() + ": cannot create the failures folder: " + ec.message());
        }
        const std::filesystem::path tsv_path = dir / "failures.tsv";
        std::ofstream tsv(tsv_path, std::ios::binary | std::ios::trunc);
        tsv << "file\tmethod\tkind\tsubcases\texpected_euler\texpected_b0\texpected_b1\texpected_"
               "b2\t"
               "expected_loops\tgot_euler\tgot_b0\tgot_b1\tgot_b2\tgot_loops\tnonmanifold_edges\t"
               "nonmanifold_vertices\tcommand\tcell_command\tnote\n";
        std::set<std::string> volumes_written;
        for (Tally& tally : tallies) {
            const std::string method = tally.report.name;
            for (const Failure& f : tally.failures) {
                const std::filesystem::path volume_path = dir / (f.name + ".nrrd");
                if (volumes_written.insert(f.name).second) io::write_volume(*f.volume, volume_path);
                const std::filesystem::path mesh_base = dir / (f.name + "-" + method);
                std::string command, cell_line = "-";
                if (tally.report.external) {
                    command = rerun_external ? rerun_external(volume_path, f.iso, mesh_base) : "";
                } else {
                    command = "cmc33 extract " + shell_quote(volume_path.string()) + " --iso " +
                              number_text(f.iso) + " --method " + method + " --json";
                    if (f.kind == FieldKind::cell)
                        cell_line = cell_command(*f.volume, f.iso, method);
                }
                if (f.mesh) io::write_mesh(*f.mesh, mesh_base.string() + ".ply");
                const FieldTopology& e = f.expected;
                tsv << volume_path.string() << '\t' << method << '\t' << field_kind_name(f.kind)
                    << '\t' << tsv_field(f.subcases) << '\t' << e.euler << '\t' << e.b0 << '\t'
                    << e.b1 << '\t' << e.b2 << '\t' << e.boundary_loops;
                if (f.got) {
                    const MeshTopology& g = *f.got;
                    tsv << '\t' << g.euler << '\t' << g.components << '\t' << g.b1 << '\t'
                        << g.closed_components << '\t' << g.boundary_loops << '\t'
                        << g.nonmanifold_edges << '\t' << g.nonmanifold_vertices;
                } else {
                    tsv << "\t-\t-\t-\t-\t-\t-\t-";
                }
                tsv << '\t' << tsv_field(command) << '\t' << cell_line << '\t' << tsv_field(f.note)
                    << '\n';
                ++tally.report.failures_written;
                ++report.failures_written;
            }
        }
        tsv.flush();
        if (!tsv)
            throw Error(Status::io_error, tsv_path.string() + ": cannot write the failures list");
        report.failures_dir = dir;
    }
    for (Tally& tally : tallies) report.methods.push_back(std::move(tally.report));
}

std::string shell_quote(const std::string& text)
{
    std::string quoted = "'";
    for (char c : text) {
        if (c == '\'') {
            quoted += "'\\''";
        } else {
            quoted += c;
        }
    }
    return quoted + "'";
}

std::string number_text(double value)
{
    std::array<char, 32> buffer{};
    const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
    return std::string(buffer.data(), result.ptr);
}

} // namespace verification::detail

bool topology_matches(const MeshTopology& mesh, const FieldTopology& field) noexcept
{
    return field.determined && mesh.euler == field.euler && mesh.components == field.b0 &&
           mesh.b1 == field.b1 && mesh.closed_components == field.b2 &&
           mesh.boundary_loops == field.boundary_loops;
}

bool is_manifold(const MeshTopology& mesh) noexcept
{
    return mesh.nonmanifold_edges == 0 && mesh.nonmanifold_vertices == 0;
}

double VerifyReport::rate(FieldKind kind) const noexcept
{
    const auto k = static_cast<std::size_t>(kind);
    return kind_seconds[k] > 0 ? static_cast<double>(fields[k]) / kind_seconds[k] : 0.0;
}

bool VerifyReport::passed() const noexcept
{
    for (const MethodReport& m : methods) {
        if (m.mismatched != 0 || m.nonmanifold != 0) return false;
    }
    return true;
}

} // namespace cmc33
