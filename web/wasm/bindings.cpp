// The JavaScript API of cmc33's WebAssembly module (web/README.md has its contract). Everything it
// computes is the library's: extract(), analyze_cell(), mesh_topology(), field_topology() and the
// readers; this file only converts. Typed arrays come in by one copy into the module's memory and
// go out as views of it (typed_memory_view, no copy): a view is valid until the object that owns the
// memory is deleted, or until the module's memory grows (web/src/cmc33.js copies them out at once).

#include <emscripten/bind.h>
#include <emscripten/emscripten.h>
#include <emscripten/val.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cmc33/cell.hpp"
#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/io.hpp"
#include "cmc33/topology.hpp"
#include "decide.hpp"
#include "union_find.hpp"

// A library error becomes a JavaScript Error with the library's one-line message.
EM_JS(void, cmc33_throw_js, (const char* message), { throw new Error(UTF8ToString(message)); });

namespace {

using emscripten::val;

/// Runs f; a C++ exception leaves as a JavaScript Error carrying its message.
template <class F> auto guard(F&& f) -> decltype(f())
{
    try {
        return f();
    } catch (const std::exception& e) {
        cmc33_throw_js(e.what());
    }
    std::abort(); // not reached: the JavaScript throw unwinds past this frame
}

template <class T> val view(const T* data, std::size_t n) { return val(emscripten::typed_memory_view(n, data)); }

/// A JS typed array or array of numbers as doubles (one copy).
std::vector<double> doubles(const val& array) { return emscripten::convertJSArrayToNumberVector<double>(array); }

/// Every method of the library, in the order of its enum: Method(k) for k = 0, 1, ... as long as
/// method_name() and parse_method() agree on it (past the last, method_name() falls back to a name
/// that parses to another value). The page never lists methods itself.
std::vector<cmc33::Method> all_methods()
{
    std::vector<cmc33::Method> out;
    for (int k = 0; k < 64; ++k) {
        const auto m = static_cast<cmc33::Method>(k);
        try {
            if (cmc33::parse_method(cmc33::method_name(m)) != m) break;
        } catch (const cmc33::Error&) {
            break;
        }
        out.push_back(m);
    }
    return out;
}

val methods()
{
    val out = val::array();
    for (const cmc33::Method m : all_methods()) out.call<void>("push", std::string(cmc33::method_name(m)));
    return out;
}

val subcase_names()
{
    val out = val::array();
    for (int s = 0; s < cmc33::kSubcaseCount; ++s) out.call<void>("push", std::string(cmc33::subcase_name(s)));
    return out;
}

/// An owned copy of a small array, for results that outlive no object (a cell's mesh).
template <class T> val copy_of(const T* data, std::size_t n) { return view(data, n).template call<val>("slice"); }

val topology_object(const cmc33::MeshTopology& t)
{
    val o = val::object();
    o.set("vertices", static_cast<double>(t.vertices));
    o.set("edges", static_cast<double>(t.edges));
    o.set("faces", static_cast<double>(t.faces));
    o.set("euler", static_cast<double>(t.euler));
    o.set("b0", static_cast<double>(t.components));
    o.set("b1", static_cast<double>(t.b1));
    o.set("b2", static_cast<double>(t.closed_components));
    o.set("boundaryEdges", static_cast<double>(t.boundary_edges));
    o.set("boundaryLoops", static_cast<double>(t.boundary_loops));
    o.set("nonManifoldEdges", static_cast<double>(t.nonmanifold_edges));
    o.set("nonManifoldVertices", static_cast<double>(t.nonmanifold_vertices));
    o.set("degenerateTriangles", static_cast<double>(t.degenerate_triangles));
    o.set("closed", t.closed);
    o.set("oriented", t.oriented);
    return o;
}

val field_object(const cmc33::FieldTopology& f)
{
    val o = val::object();
    o.set("determined", f.determined);
    o.set("why", f.why);
    o.set("euler", static_cast<double>(f.euler));
    o.set("b0", static_cast<double>(f.b0));
    o.set("b1", static_cast<double>(f.b1));
    o.set("b2", static_cast<double>(f.b2));
    o.set("boundaryLoops", static_cast<double>(f.boundary_loops));
    return o;
}

/// A mesh held in the module's memory.
class WebMesh {
public:
    explicit WebMesh(cmc33::Mesh mesh) : mesh_(std::move(mesh)) {}
    double vertex_count() const { return static_cast<double>(mesh_.vertex_count()); }
    double triangle_count() const { return static_cast<double>(mesh_.triangle_count()); }
    val positions() const { return view(mesh_.positions.data(), mesh_.positions.size()); }
    val normals() const { return view(mesh_.normals.data(), mesh_.normals.size()); }
    val triangles() const { return view(mesh_.triangles.data(), mesh_.triangles.size()); }
    val topology() const
    {
        return guard([&] { return topology_object(cmc33::mesh_topology(mesh_)); });
    }

    /// Vertex pairs (a < b) of the edges that more than two triangles share, flat.
    val non_manifold_edges()
    {
        std::vector<std::uint64_t> edges;
        edges.reserve(mesh_.triangles.size());
        const auto& t = mesh_.triangles;
        for (std::size_t i = 0; i < t.size(); i += 3)
            for (int e = 0; e < 3; ++e) {
                const std::uint32_t a = t[i + static_cast<std::size_t>(e)], b = t[i + static_cast<std::size_t>((e + 1) % 3)];
                edges.push_back(std::uint64_t{std::min(a, b)} << 32 | std::max(a, b));
            }
        std::sort(edges.begin(), edges.end());
        scratch_.clear();
        for (std::size_t i = 0; i < edges.size();) {
            std::size_t j = i;
            while (j < edges.size() && edges[j] == edges[i]) ++j;
            if (j - i > 2) {
                scratch_.push_back(static_cast<std::uint32_t>(edges[i] >> 32));
                scratch_.push_back(static_cast<std::uint32_t>(edges[i] & 0xffffffffu));
            }
            i = j;
        }
        return view(scratch_.data(), scratch_.size());
    }

    /// Component of every vertex (through shared triangles), numbered by size, largest first.
    val components()
    {
        cmc33::detail::UnionFind sets(mesh_.vertex_count());
        const auto& t = mesh_.triangles;
        for (std::size_t i = 0; i < t.size(); i += 3) sets.unite(t[i], t[i + 1]), sets.unite(t[i], t[i + 2]);
        std::map<std::uint32_t, std::uint32_t> size_of_root;
        for (std::uint32_t v = 0; v < mesh_.vertex_count(); ++v) ++size_of_root[sets.find(v)];
        std::vector<std::pair<std::uint32_t, std::uint32_t>> by_size; // (size, root)
        for (const auto& [root, size] : size_of_root) by_size.emplace_back(size, root);
        std::stable_sort(by_size.begin(), by_size.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
        std::map<std::uint32_t, std::uint32_t> rank;
        for (std::uint32_t r = 0; r < by_size.size(); ++r) rank[by_size[r].second] = r;
        scratch_.resize(mesh_.vertex_count());
        for (std::uint32_t v = 0; v < mesh_.vertex_count(); ++v) scratch_[v] = rank[sets.find(v)];
        return view(scratch_.data(), scratch_.size());
    }

private:
    cmc33::Mesh mesh_;
    std::vector<std::uint32_t> scratch_; // the memory of the last non_manifold_edges() or components()
};

cmc33::ExtractOptions one_thread(const std::string& method)
{
    cmc33::ExtractOptions options;
    options.method = cmc33::parse_method(method);
    options.threads = 1; // no threads in this build: the library's worker pool is never touched
    return options;
}

/// A volume held in the module's memory.
class WebVolume {
public:
    explicit WebVolume(cmc33::Volume volume) : volume_(std::move(volume)) {}

    /// Reads a volume file from its bytes; the format is told by the content where it has a mark
    /// (NIfTI, .npy, TIFF, DICOM), else by `name`'s extension (.nrrd, .nhdr, .mha, .mhd, .vtk, .nii,
    /// .nii.gz, .hdr, .npy, .vti). `files` (an object: name -> Uint8Array) holds a detached header's
    /// data files (NRRD, MetaImage, a NIfTI .hdr's .img).
    static std::unique_ptr<WebVolume> read(const std::string& bytes, const std::string& name, const val& files)
    {
    return guard([&] {
        std::string lower;
        for (const char c : name) lower += static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
        const auto ends = [&](std::string_view suffix) { return lower.ends_with(suffix); };
        const auto has = [&](std::size_t at, std::string_view mark) { return bytes.size() >= at + mark.size() && std::string_view(bytes).substr(at, mark.size()) == mark; };
        using cmc33::io::VolumeFormat;
        VolumeFormat format = VolumeFormat::nrrd;
        if (has(0, "\x93NUMPY") || ends(".npy")) {
            format = VolumeFormat::npy;
        } else if (has(0, "II*") || has(0, std::string_view("MM\0*", 4)) || has(0, "II+") || has(0, std::string_view("MM\0+", 4)) || ends(".tif") || ends(".tiff")) {
            format = VolumeFormat::tiff;
        } else if (has(128, "DICM") || ends(".dcm")) {
            format = VolumeFormat::dicom;
        } else if (has(344, std::string_view("n+1\0", 4)) || has(344, std::string_view("ni1\0", 4)) || has(4, std::string_view("n+2\0", 4)) ||
                   has(4, std::string_view("ni2\0", 4)) || ends(".nii") || ends(".nii.gz") || ends(".hdr") || ends(".hdr.gz")) {
            format = VolumeFormat::nifti;
        } else if (ends(".vti")) {
            format = VolumeFormat::vti;
        } else if (ends(".mha") || ends(".mhd")) {
            format = VolumeFormat::metaimage;
        } else if (ends(".vtk")) {
            format = VolumeFormat::vtk;
        } else if (!ends(".nrrd") && !ends(".nhdr")) {
            throw cmc33::Error(cmc33::Status::unsupported_format,
                               name + ": unknown volume extension; expected .nrrd, .nhdr, .mha, .mhd, .vtk, .nii, .nii.gz, "
                                      ".hdr (+ .img), .npy or .vti");
        }
        std::map<std::string, std::string, std::less<>> data;
        if (!files.isUndefined() && !files.isNull()) {
            const val keys = val::global("Object").call<val>("keys", files);
            for (int i = 0, n = keys["length"].as<int>(); i < n; ++i) {
                const auto key = keys[i].as<std::string>();
                data[key] = files[key].as<std::string>();
            }
        }
        const cmc33::io::MemoryFiles serve = [&](std::string_view file) -> std::optional<std::string_view> {
            const auto slash = file.find_last_of('/');
            const std::string_view base = slash == std::string_view::npos ? file : file.substr(slash + 1);
            const auto it = data.find(base);
            if (it == data.end()) return std::nullopt;
            return std::string_view(it->second);
        };
        try {
            return std::make_unique<WebVolume>(cmc33::io::read_volume_from_memory(bytes, format, name, std::nullopt, serve));
        } catch (const cmc33::Error& e) {
            // this build compiles neither libtiff nor GDCM: say so in the page's words, not the CLI's
            const bool image = format == VolumeFormat::tiff || format == VolumeFormat::dicom;
            if (!image || e.status() != cmc33::Status::unsupported_format || std::string_view(e.what()).find("this build") == std::string_view::npos) throw;
            const std::string what = format == VolumeFormat::tiff ? "TIFF" : "DICOM";
            throw cmc33::Error(cmc33::Status::unsupported_format,
                               name + ": a " + what + " file, which this page cannot read: its WebAssembly build has no " + what +
                                   " reader (" + (format == VolumeFormat::tiff ? "libtiff" : "GDCM") +
                                   " is not compiled into it); read it with the command-line tool (cmc33 extract), or convert it to "
                                   "NIfTI or NRRD and drop that");
        }
    });
}

    /// A dense volume of doubles, x fastest (the page's own fields, such as Fig. 8's).
    static std::unique_ptr<WebVolume> from_values(const val& values, int nx, int ny, int nz)
    {
    return guard([&] {
        const std::vector<double> v = doubles(values);
        cmc33::Volume volume(cmc33::ScalarType::f64, {nx, ny, nz});
        if (v.size() != static_cast<std::size_t>(volume.sample_count())) {
            throw cmc33::Error(cmc33::Status::invalid_argument, "from_values: " + std::to_string(v.size()) + " values for " +
                                                                    std::to_string(volume.sample_count()) + " samples");
        }
        std::copy(v.begin(), v.end(), volume.samples<double>());
        return std::make_unique<WebVolume>(std::move(volume));
    });
}

    val dims() const
    {
        val o = val::array();
        for (const auto d : volume_.dims()) o.call<void>("push", static_cast<double>(d));
        return o;
    }
    val spacing() const
    {
        val o = val::array();
        for (const auto s : volume_.spacing()) o.call<void>("push", s);
        return o;
    }
    std::string type() const { return std::string(cmc33::type_name(volume_.type())); }
    val origin() const
    {
        val o = val::array();
        for (const auto x : volume_.origin()) o.call<void>("push", x);
        return o;
    }
    /// Row by row: column a is the world direction of +axis a.
    val direction() const
    {
        val o = val::array();
        for (const auto& row : volume_.direction()) {
            val r = val::array();
            for (const auto x : row) r.call<void>("push", x);
            o.call<void>("push", r);
        }
        return o;
    }
    /// The world space the file names ("right-anterior-superior", ...), or "".
    std::string space() const { return volume_.space(); }
    /// Where the reader took the frame from ("sform (code 2: aligned)", ...), or "".
    std::string frame_source() const { return volume_.frame_source(); }

    /// {min, max, counts: Float64Array(bins)} over [min, max] of the finite samples.
    val histogram(int bins) const
    {
        return volume_.visit([&](auto grid) {
            double lo = std::numeric_limits<double>::infinity(), hi = -lo;
            const std::int64_t n = volume_.sample_count();
            for (std::int64_t i = 0; i < n; ++i) {
                const auto x = static_cast<double>(grid.data[i]);
                if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x);
            }
            std::vector<double> counts(static_cast<std::size_t>(std::max(bins, 1)), 0.0);
            const double width = hi > lo ? (hi - lo) / static_cast<double>(counts.size()) : 1.0;
            for (std::int64_t i = 0; i < n; ++i) {
                const auto x = static_cast<double>(grid.data[i]);
                if (!std::isfinite(x)) continue;
                const auto b = std::min(counts.size() - 1, static_cast<std::size_t>((x - lo) / width));
                counts[b] += 1;
            }
            val o = val::object();
            o.set("min", lo);
            o.set("max", hi);
            o.set("counts", copy_of(counts.data(), counts.size()));
            return o;
        });
    }

    std::unique_ptr<WebMesh> extract(double iso, const std::string& method) const
    {
        return guard([&] { return std::make_unique<WebMesh>(cmc33::extract(volume_, iso, one_thread(method))); });
    }
    /// The expected invariants of the level set of the trilinear field (the independent verifier).
    val field_topology(double iso) const
    {
        return guard([&] { return field_object(cmc33::field_topology(volume_, iso)); });
    }
    /// The cells the surface crosses, per subcase (index: subcaseNames()).
    val subcase_counts(double iso, const std::string& method) const
    {
    return guard([&] {
        cmc33::ExtractStats stats;
        (void)cmc33::extract(volume_, iso, one_thread(method), &stats);
        val o = val::array();
        for (const auto c : stats.cells_per_subcase) o.call<void>("push", static_cast<double>(c));
        return o;
    });
}

private:
    cmc33::Volume volume_;
};

std::array<double, 8> corners(const val& values)
{
    const std::vector<double> v = doubles(values);
    if (v.size() != 8) {
        throw cmc33::Error(cmc33::Status::invalid_argument, "a cell has 8 corner values, not " + std::to_string(v.size()));
    }
    std::array<double, 8> c{};
    std::copy(v.begin(), v.end(), c.begin());
    return c;
}

/// analyze_cell() as an object: config, baseCase, subcase (its name), faces, interior, and the
/// cell's mesh in the unit cube (positions, triangles: owned copies).
val analyze(const val& values, double iso, const std::string& method)
{
    return guard([&] {
    const cmc33::CellReport r = cmc33::analyze_cell(corners(values), iso, cmc33::parse_method(method));
    val o = val::object();
    o.set("config", r.config);
    o.set("baseCase", r.base_case);
    o.set("subcase", std::string(cmc33::subcase_name(r.subcase)));
    val faces = val::array();
    for (const cmc33::FaceReport& f : r.faces) {
        val face = val::object();
        face.set("ambiguous", f.ambiguous);
        face.set("saddle", f.saddle);
        face.set("joined", f.joined);
        face.set("used", f.used);
        faces.call<void>("push", face);
    }
    o.set("faces", faces);
    const cmc33::InteriorReport& i = r.interior;
    val in = val::object();
    in.set("tested", i.tested);
    in.set("test", i.test);
    in.set("axis", i.axis);
    in.set("cornerA", i.corner_a);
    in.set("cornerC", i.corner_c);
    in.set("a", i.a), in.set("b", i.b), in.set("c", i.c);
    in.set("t1", i.t1), in.set("t2", i.t2);
    in.set("tMax", i.t_max), in.set("fTMax", i.f_t_max);
    in.set("lewinerAxis", i.lewiner_axis), in.set("lewinerCorner", i.lewiner_corner), in.set("lewinerEdge", i.lewiner_edge);
    in.set("tAlt", i.t_alt), in.set("fTAlt", i.f_t_alt);
    val s1 = val::array(), s2 = val::array();
    s1.call<void>("push", i.saddle1[0]), s1.call<void>("push", i.saddle1[1]);
    s2.call<void>("push", i.saddle2[0]), s2.call<void>("push", i.saddle2[1]);
    in.set("saddle1", s1), in.set("saddle2", s2);
    in.set("skipped", i.skipped);
    in.set("tunnel", i.tunnel);
    in.set("tunnelCorner", i.tunnel_corner);
    o.set("interior", in);
    o.set("positions", copy_of(r.mesh.positions.data(), r.mesh.positions.size()));
    o.set("triangles", copy_of(r.mesh.triangles.data(), r.mesh.triangles.size()));
    o.set("topology", topology_object(cmc33::mesh_topology(r.mesh)));
    return o;
});
}

/// The interior test's sweep sampled at n + 1 heights t in [0, 1] (Figs. 4 and 6 of the paper):
/// F(t) = A_t C_t - B_t D_t, the slice saddle x_c(t) = ((A_t - D_t), (A_t - B_t)) / den(t) in the
/// slice's own (u, v), its value f(x_c(t)) = F(t) / den(t), and den(t) = A_t + C_t - B_t - D_t, whose
/// root is the asymptote t_a of Fig. 6; on the sweep that `axis` and the
/// tested corner `corner` give (those of analyze(): interior.axis and cornerA, or lewinerAxis and
/// lewinerCorner). The sweep is the kernel's (SweepT of decide.hpp).
val sweep(const val& values, double iso, int axis, int corner, int n)
{
    return guard([&] {
    const std::array<double, 8> c = corners(values);
    if (axis < 0 || axis > 2 || corner < 0 || corner > 7 || n < 1 || n > 100000) {
        throw cmc33::Error(cmc33::Status::invalid_argument, "sweep: axis 0..2, corner 0..7 and 1..100000 steps");
    }
    double v[8];
    for (int q = 0; q < 8; ++q) v[q] = c[static_cast<std::size_t>(q)] - iso;
    const cmc33::detail::Sweep s(v, axis, corner);
    std::vector<double> t(static_cast<std::size_t>(n) + 1), f(t.size()), u(t.size()), w(t.size()), saddle(t.size()),
        dens(t.size());
    for (std::size_t k = 0; k < t.size(); ++k) {
        const double h = static_cast<double>(k) / n;
        const double den = s.den(h);
        const double a_t = cmc33::detail::Sweep::at(s.A0, s.A1, h), b_t = cmc33::detail::Sweep::at(s.B0, s.B1, h),
                     d_t = cmc33::detail::Sweep::at(s.D0, s.D1, h);
        t[k] = h;
        f[k] = s.F(h);
        u[k] = (a_t - d_t) / den;
        w[k] = (a_t - b_t) / den;
        saddle[k] = f[k] / den;
        dens[k] = den;
    }
    val o = val::object();
    o.set("t", copy_of(t.data(), t.size()));
    o.set("F", copy_of(f.data(), f.size()));
    o.set("u", copy_of(u.data(), u.size()));
    o.set("v", copy_of(w.data(), w.size()));
    o.set("saddle", copy_of(saddle.data(), saddle.size()));
    o.set("den", copy_of(dens.data(), dens.size()));
    return o;
});
}

/// The level set of the cell's trilinear interpolant, densely sampled: the interpolant on an
/// (n + 1)^3 grid, extracted by cmc33 (each sub-cell's surface is within 1/n of the true one and has
/// its topology wherever the sub-cells resolve it). Positions in the unit cube.
std::unique_ptr<WebMesh> trilinear_surface(const val& values, double iso, int n)
{
    return guard([&] {
    const std::array<double, 8> c = corners(values);
    if (n < 1 || n > 256) throw cmc33::Error(cmc33::Status::invalid_argument, "trilinear_surface: 1..256 steps");
    const std::int64_t m = n + 1;
    std::vector<double> field(static_cast<std::size_t>(m * m * m));
    for (std::int64_t k = 0; k < m; ++k)
        for (std::int64_t j = 0; j < m; ++j)
            for (std::int64_t i = 0; i < m; ++i) {
                const double x = static_cast<double>(i) / n, y = static_cast<double>(j) / n, z = static_cast<double>(k) / n;
                double value = 0;
                for (int q = 0; q < 8; ++q) {
                    value += c[static_cast<std::size_t>(q)] * ((q & 1) ? x : 1 - x) * ((q & 2) ? y : 1 - y) * ((q & 4) ? z : 1 - z);
                }
                field[static_cast<std::size_t>((k * m + j) * m + i)] = value;
            }
    const double step = 1.0 / n;
    const auto grid = cmc33::GridView<double>::dense(field.data(), {m, m, m}, {step, step, step});
    return std::make_unique<WebMesh>(cmc33::extract(grid, iso, one_thread("cmc33")));
});
}

std::string version() { return CMC33_WEB_VERSION; }

} // namespace

EMSCRIPTEN_BINDINGS(cmc33)
{
    using namespace emscripten;
    function("version", &version);
    function("methods", &methods);
    function("subcaseNames", &subcase_names);
    function("analyzeCell", &analyze);
    function("sweep", &sweep);
    function("trilinearSurface", &trilinear_surface);
    class_<WebMesh>("Mesh")
        .function("vertexCount", &WebMesh::vertex_count)
        .function("triangleCount", &WebMesh::triangle_count)
        .function("positions", &WebMesh::positions)
        .function("normals", &WebMesh::normals)
        .function("triangles", &WebMesh::triangles)
        .function("topology", &WebMesh::topology)
        .function("nonManifoldEdges", &WebMesh::non_manifold_edges)
        .function("components", &WebMesh::components);
    class_<WebVolume>("Volume")
        .class_function("read", &WebVolume::read)
        .class_function("fromValues", &WebVolume::from_values)
        .function("dims", &WebVolume::dims)
        .function("spacing", &WebVolume::spacing)
        .function("type", &WebVolume::type)
        .function("origin", &WebVolume::origin)
        .function("direction", &WebVolume::direction)
        .function("space", &WebVolume::space)
        .function("frameSource", &WebVolume::frame_source)
        .function("histogram", &WebVolume::histogram)
        .function("extract", &WebVolume::extract)
        .function("fieldTopology", &WebVolume::field_topology)
        .function("subcaseCounts", &WebVolume::subcase_counts);
}
