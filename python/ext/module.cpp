// cmc33._cmc33: the library's public API for Python. Argument checking, conversions that need a
// copy, defaults and the user-facing docstrings of the functions are in the pure-Python layer
// (python/src/cmc33); this file reads arrays in place, releases the GIL around library work and
// hands the library's memory to numpy without copying it (an array's base object keeps it alive).

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "binding.hpp"
#include "drop_in.hpp"
#include "portability.hpp"

#include "cmc33/cell.hpp"
#include "cmc33/cmc33.hpp"
#include "cmc33/verify.hpp"

namespace cmc33::python {
namespace {

using ssize = py::ssize_t;

// ------------------------------------------------------------------------------------------------
// Errors: cmc33::Error becomes the Python class cmc33._errors assigns to its Status.

std::string_view status_name(Status s) noexcept
{
    switch (s) {
    case Status::invalid_argument: return "invalid_argument";
    case Status::io_error: return "io_error";
    case Status::truncated_file: return "truncated_file";
    case Status::bad_format: return "bad_format";
    case Status::unsupported_format: return "unsupported_format";
    case Status::non_finite: return "non_finite";
    case Status::too_large: return "too_large";
    case Status::cancelled: return "cancelled";
    case Status::internal: break;
    }
    return "internal";
}

void translate_errors(std::exception_ptr p)
{
    try {
        if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
        const py::object classes = py::module_::import("cmc33._errors").attr("STATUS_ERRORS");
        const py::object cls = classes[py::str(std::string(status_name(e.status())))];
        PyErr_SetObject(cls.ptr(), py::str(e.what()).ptr());
    }
}

// ------------------------------------------------------------------------------------------------
// Meshes

py::array rows_of(const py::object& owner, const py::dtype& dtype, const void* data, std::size_t rows, ssize columns)
{
    const ssize size = dtype.itemsize();
    return py::array(dtype, std::vector<ssize>{static_cast<ssize>(rows), columns},
                     std::vector<ssize>{columns * size, size}, data, owner);
}

PyMesh mesh_from_arrays(const py::array_t<float, py::array::c_style | py::array::forcecast>& vertices,
                        const py::array& triangle_array,
                        const std::optional<py::array_t<float, py::array::c_style | py::array::forcecast>>& normals)
{
    const char kind = triangle_array.dtype().kind();
    if (kind != 'i' && kind != 'u') {
        throw Error(Status::invalid_argument, "triangles have type " +
                                                  py::str(static_cast<py::object>(triangle_array.dtype())).cast<std::string>() +
                                                  "; expected integers");
    }
    const auto triangles = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(triangle_array);
    if (vertices.ndim() != 2 || vertices.shape(1) != 3) {
        throw Error(Status::invalid_argument, "vertices have shape " + py::str(vertices.attr("shape")).cast<std::string>() +
                                                  "; expected (V, 3)");
    }
    if (triangles.ndim() != 2 || triangles.shape(1) != 3) {
        throw Error(Status::invalid_argument, "triangles have shape " +
                                                  py::str(triangles.attr("shape")).cast<std::string>() + "; expected (F, 3)");
    }
    const auto nv = static_cast<std::size_t>(vertices.shape(0));
    const auto nt = static_cast<std::size_t>(triangles.shape(0));
    if (nv >= std::numeric_limits<std::uint32_t>::max()) {
        throw Error(Status::too_large, std::to_string(nv) + " vertices; a mesh holds at most 2^32 - 2");
    }
    PyMesh m;
    m.mesh.positions.resize(nv * 3);
    if (nv > 0) std::memcpy(m.mesh.positions.data(), vertices.data(), nv * 3 * sizeof(float));
    m.mesh.triangles.resize(nt * 3);
    const std::int64_t* t = triangles.data();
    for (std::size_t i = 0; i < nt * 3; ++i) {
        if (t[i] < 0 || t[i] >= static_cast<std::int64_t>(nv)) {
            throw Error(Status::invalid_argument, "triangle " + std::to_string(i / 3) + " uses vertex " +
                                                      std::to_string(t[i]) + "; expected 0 <= index < " +
                                                      std::to_string(nv) + " (the vertex count)");
        }
        m.mesh.triangles[i] = static_cast<std::uint32_t>(t[i]);
    }
    if (normals) {
        if (normals->ndim() != 2 || normals->shape(1) != 3 || static_cast<std::size_t>(normals->shape(0)) != nv) {
            throw Error(Status::invalid_argument, "normals have shape " +
                                                      py::str(normals->attr("shape")).cast<std::string>() +
                                                      "; expected (" + std::to_string(nv) + ", 3), one per vertex");
        }
        m.mesh.normals.resize(nv * 3);
        if (nv > 0) std::memcpy(m.mesh.normals.data(), normals->data(), nv * 3 * sizeof(float));
        m.normals = true;
    }
    return m;
}

py::object subcase_counts(const ExtractStats& stats)
{
    py::dict d;
    for (int s = 0; s < kSubcaseCount; ++s) {
        d[py::str(std::string(subcase_name(s)))] = stats.cells_per_subcase[static_cast<std::size_t>(s)];
    }
    return d;
}

// ------------------------------------------------------------------------------------------------
// Volumes

py::dtype dtype_of(ScalarType type)
{
    return dispatch_scalar_type(type, [](auto tag) { return py::dtype::of<decltype(tag)>(); });
}

/// The samples of a volume as an array of shape (nz, ny, nx), in place.
py::array volume_samples(const py::object& self)
{
    const Volume& v = self.cast<const Volume&>();
    const py::dtype dtype = dtype_of(v.type());
    const ssize size = dtype.itemsize();
    const Index3& d = v.dims();
    return py::array(dtype, std::vector<ssize>{d[2], d[1], d[0]}, std::vector<ssize>{d[0] * d[1] * size, d[0] * size, size},
                     v.bytes(), self);
}

/// A Volume holding a copy of a C-contiguous array (the Python layer makes it one).
Volume volume_from_array(const py::array& array, const Vec3& spacing, const Vec3& origin, const Mat3& direction)
{
    const Samples s = samples_of(array, "samples");
    if (!(array.flags() & py::array::c_style)) {
        throw Error(Status::invalid_argument, "samples are not C-contiguous; expected a C-ordered array");
    }
    Volume v(s.type, s.dims, spacing, origin);
    v.set_direction(direction);
    if (v.byte_size() > 0) std::memcpy(v.bytes(), s.data, v.byte_size());
    return v;
}

/// "RAS", "LPS", ... for a space named by letters or by words ("left-posterior-superior"); "" for
/// none or a space that is not anatomical (one letter per world axis: R/L, A/P, S/I).
std::string space_code(const std::string& name)
{
    std::string words = name, code;
    for (char& c : words) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (words.size() == 3) {
        for (char c : words) code += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    } else {
        std::size_t at = 0;
        while (at <= words.size() && !words.empty()) {
            const std::size_t dash = std::min(words.find('-', at), words.size());
            const std::string word = words.substr(at, dash - at);
            static const std::array<std::pair<const char*, char>, 6> kWords{{{"right", 'R'}, {"left", 'L'}, {"anterior", 'A'},
                                                                              {"posterior", 'P'}, {"superior", 'S'}, {"inferior", 'I'}}};
            const auto* hit = std::find_if(kWords.begin(), kWords.end(), [&](const auto& w) { return word == w.first; });
            if (hit == kWords.end()) return "";
            code += hit->second;
            at = dash + 1;
        }
    }
    if (code.size() != 3 || (code[0] != 'R' && code[0] != 'L') || (code[1] != 'A' && code[1] != 'P') ||
        (code[2] != 'S' && code[2] != 'I')) {
        return "";
    }
    return code;
}

/// The 4x4 index-to-world matrix of a volume: columns direction * spacing, then the origin.
py::array affine_of(const Volume& v)
{
    py::array_t<double> a(std::vector<ssize>{4, 4});
    auto r = a.mutable_unchecked<2>();
    for (std::size_t i = 0; i < 4; ++i) {
        for (std::size_t j = 0; j < 4; ++j) {
            double value = i == j ? 1.0 : 0.0;
            if (i < 3 && j < 3) value = v.direction()[i][j] * v.spacing()[j];
            if (i < 3 && j == 3) value = v.origin()[i];
            r(static_cast<ssize>(i), static_cast<ssize>(j)) = value;
        }
    }
    return a;
}

py::array matrix_of(const Mat3& m)
{
    py::array_t<double> a(std::vector<ssize>{3, 3});
    auto r = a.mutable_unchecked<2>();
    for (ssize i = 0; i < 3; ++i)
        for (ssize j = 0; j < 3; ++j) r(i, j) = m[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
    return a;
}

// ------------------------------------------------------------------------------------------------
// Extraction

PyMesh extract_py(const py::array& volume, double iso, const Vec3& spacing, const Vec3& origin, const Mat3& direction,
                  const std::string& method, bool normals, int threads, const py::object& progress)
{
    const Samples s = samples_of(volume);
    const Frame frame{spacing, origin, direction};
    ExtractOptions options;
    options.method = parse_method(method);
    options.normals = normals;
    options.threads = threads;
    const bool background = !progress.is_none() || s.count() >= kBackgroundSamples;
    ExtractStats stats;
    Mesh mesh = run_interruptible<Mesh>(background, progress, [&](Control& control) {
        ExtractOptions o = options;
        if (background) o.progress = [&control](double fraction) { return control.keep_going(fraction); };
        return visit(s, frame, [&](const auto& grid) { return extract(grid, iso, o, &stats); });
    });
    return PyMesh{std::move(mesh), stats, normals};
}

/// marching_cubes' four arrays. `spacing` is in the array's axis order and so are the vertices
/// (extract_drop_in swaps x and z once a range is written).
py::tuple marching_cubes_py(const py::array& volume, double level, const Vec3& spacing, const std::string& method,
                            bool descent, const py::object& mask_cells, int threads, const py::object& progress)
{
    const Samples s = samples_of(volume);
    Frame frame;
    frame.spacing = {spacing[2], spacing[1], spacing[0]};
    DropInOptions options;
    options.method = parse_method(method);
    options.descent = descent;
    options.threads = threads;
    CellMask mask;
    std::optional<Samples> mask_samples;
    if (!mask_cells.is_none()) {
        mask_samples = samples_of(mask_cells.cast<py::array>(), "mask");
        if (mask_cells.cast<py::array>().dtype().kind() != 'b') {
            throw Error(Status::invalid_argument, "the cell mask is not boolean");
        }
        mask = {static_cast<const std::uint8_t*>(mask_samples->data), mask_samples->dims, mask_samples->strides};
        options.mask = &mask;
    }
    const bool background = !progress.is_none() || s.count() >= kBackgroundSamples;
    auto owned = std::make_unique<DropInMesh>(run_interruptible<DropInMesh>(
        background, progress, [&](Control& control) { return extract_drop_in(s, frame, level, options, control); }));
    const DropInMesh& m = *owned;
    const py::capsule owner(owned.get(), [](void* p) { delete static_cast<DropInMesh*>(p); });
    owned.release();
    const auto nv = static_cast<std::size_t>(m.vertex_count);
    const auto nt = static_cast<std::size_t>(m.triangle_count);
    // scikit-image's faces are int32: the same bytes while ids stay below 2^31
    const py::dtype index = m.vertex_count <= std::numeric_limits<std::int32_t>::max() ? py::dtype::of<std::int32_t>()
                                                                                        : py::dtype::of<std::uint32_t>();
    py::array values(py::dtype::of<float>(), std::vector<ssize>{static_cast<ssize>(nv)}, std::vector<ssize>{4},
                     m.values.data(), owner);
    return py::make_tuple(rows_of(owner, py::dtype::of<float>(), m.positions.data(), nv, 3),
                          rows_of(owner, index, m.triangles.data(), nt, 3),
                          rows_of(owner, py::dtype::of<float>(), m.normals.data(), nv, 3), values);
}

// ------------------------------------------------------------------------------------------------
// Reports as text

template <class... Fields> std::string fields_text(const char* name, const Fields&... fields)
{
    std::string s = std::string(name) + "(";
    bool first = true;
    const auto add = [&](const auto& field) {
        if (!first) s += ", ";
        first = false;
        s += field.first;
        s += "=";
        s += py::repr(py::cast(field.second)).template cast<std::string>();
    };
    (add(fields), ...);
    return s + ")";
}

std::string topology_text(const MeshTopology& t)
{
    using P = std::pair<const char*, std::int64_t>;
    return fields_text("MeshTopology", P{"vertices", t.vertices}, P{"edges", t.edges}, P{"faces", t.faces},
                       P{"euler", t.euler}, P{"components", t.components}, P{"closed_components", t.closed_components},
                       P{"b1", t.b1}, P{"boundary_edges", t.boundary_edges}, P{"boundary_loops", t.boundary_loops},
                       P{"nonmanifold_edges", t.nonmanifold_edges}, P{"nonmanifold_vertices", t.nonmanifold_vertices},
                       P{"degenerate_triangles", t.degenerate_triangles}, std::pair{"closed", t.closed},
                       std::pair{"oriented", t.oriented});
}

py::dict per_kind(const std::array<std::int64_t, kFieldKindCount>& values)
{
    py::dict d;
    for (int k = 0; k < kFieldKindCount; ++k) {
        d[py::str(std::string(field_kind_name(static_cast<FieldKind>(k))))] = values[static_cast<std::size_t>(k)];
    }
    return d;
}

py::dict per_subcase(const std::array<std::int64_t, kSubcaseCount>& values)
{
    py::dict d;
    for (int s = 0; s < kSubcaseCount; ++s) {
        if (values[static_cast<std::size_t>(s)] != 0) {
            d[py::str(std::string(subcase_name(s)))] = values[static_cast<std::size_t>(s)];
        }
    }
    return d;
}

FieldKind parse_kind(const std::string& name)
{
    for (int k = 0; k < kFieldKindCount; ++k) {
        if (field_kind_name(static_cast<FieldKind>(k)) == name) return static_cast<FieldKind>(k);
    }
    throw Error(Status::invalid_argument, "field kind \"" + name + "\"; expected cell, grid, closed or ties");
}

// ------------------------------------------------------------------------------------------------

void bind_meshes(py::module_& m)
{
    py::class_<PyMesh>(m, "Mesh", R"(An indexed triangle mesh held in the library's memory.

``vertices`` (V, 3) float32, ``triangles`` (F, 3) uint32 and ``normals`` ((V, 3) float32, or None)
are numpy arrays over that memory: no copy is made, and each array keeps the mesh alive. Triangles
wind counter-clockwise seen from the side their normal points to; normals point from the side
above the isovalue to the side below it.

``Mesh(vertices, triangles, normals=None)`` copies arrays of your own into a new mesh (for
write_mesh, mesh_topology and mesh_geometry).)")
        .def(py::init(&mesh_from_arrays), py::arg("vertices"), py::arg("triangles"), py::arg("normals") = py::none())
        .def_property_readonly(
            "vertices",
            [](const py::object& self) {
                const PyMesh& p = self.cast<const PyMesh&>();
                return rows_of(self, py::dtype::of<float>(), p.mesh.positions.data(), p.mesh.vertex_count(), 3);
            },
            "(V, 3) float32: vertex positions in world coordinates (x, y, z), in place")
        .def_property_readonly(
            "triangles",
            [](const py::object& self) {
                const PyMesh& p = self.cast<const PyMesh&>();
                return rows_of(self, py::dtype::of<std::uint32_t>(), p.mesh.triangles.data(), p.mesh.triangle_count(), 3);
            },
            "(F, 3) uint32: vertex indices of each triangle, in place")
        .def_property_readonly(
            "normals",
            [](const py::object& self) -> py::object {
                const PyMesh& p = self.cast<const PyMesh&>();
                if (!p.normals) return py::none();
                return rows_of(self, py::dtype::of<float>(), p.mesh.normals.data(), p.mesh.vertex_count(), 3);
            },
            "(V, 3) float32 unit normals, in place; None unless extract(..., normals=True) made them")
        .def_property_readonly("vertex_count", [](const PyMesh& p) { return p.mesh.vertex_count(); }, "V")
        .def_property_readonly("triangle_count", [](const PyMesh& p) { return p.mesh.triangle_count(); }, "F")
        .def_property_readonly(
            "cells_per_subcase",
            [](const PyMesh& p) -> py::object { return p.stats ? subcase_counts(*p.stats) : py::none(); },
            "dict subcase name -> number of cells the surface crosses (meshes made by extract; else None)")
        .def("__repr__", [](const PyMesh& p) {
            return "Mesh(" + std::to_string(p.mesh.vertex_count()) + " vertices, " + std::to_string(p.mesh.triangle_count()) +
                   " triangles" + (p.normals ? ", normals" : "") + ")";
        });
}

void bind_volumes(py::module_& m)
{
    py::class_<Volume>(m, "Volume", R"(Samples and their frame, as read_volume() returns them.

``samples`` is a numpy array of shape (nz, ny, nx) over the library's memory (no copy; it keeps
the volume alive): x, the fastest axis of the file, is the array's last axis. The frame is in the
library's axis order x, y, z: world position of samples[k, j, i] = origin + direction @
(spacing * (i, j, k)). ``Volume(samples, spacing, origin, direction)`` copies an array of yours.)")
        .def(py::init(&volume_from_array), py::arg("samples"), py::arg("spacing"), py::arg("origin"), py::arg("direction"))
        .def_property_readonly("samples", &volume_samples, "(nz, ny, nx) array of the samples, in place")
        .def_property_readonly("dtype", [](const Volume& v) { return dtype_of(v.type()); })
        .def_property_readonly("shape", [](const Volume& v) {
            return py::make_tuple(v.dims()[2], v.dims()[1], v.dims()[0]);
        }, "(nz, ny, nx), the shape of samples")
        .def_property_readonly("spacing", [](const Volume& v) { return py::make_tuple(v.spacing()[0], v.spacing()[1], v.spacing()[2]); },
                               "(sx, sy, sz): distance between samples along x, y, z")
        .def_property_readonly("origin", [](const Volume& v) { return py::make_tuple(v.origin()[0], v.origin()[1], v.origin()[2]); },
                               "(ox, oy, oz): world position of samples[0, 0, 0]")
        .def_property_readonly("direction", [](const Volume& v) { return matrix_of(v.direction()); },
                               "3x3 array: column a is the world direction of +axis a (x, y, z)")
        .def_property_readonly("space", [](const Volume& v) { return v.space(); },
                               "the named space the file gave (\"left-posterior-superior\", \"RAI\", ...), or \"\"")
        .def_property_readonly("space_code", [](const Volume& v) -> py::object {
            const std::string code = space_code(v.space());
            return code.empty() ? py::object(py::none()) : py::object(py::str(code));
        }, "the world space as three letters (\"RAS\", \"LPS\", ...: where +x, +y, +z point), or None when the file names no anatomical space")
        .def_property_readonly("frame_source", [](const Volume& v) { return v.frame_source(); },
                               "where the reader took the frame from (\"sform (code 2: aligned)\", \"qform\", \"pixdim ...\", ...), or \"\"")
        .def_property_readonly("affine", &affine_of,
                               "4x4 array: world position of samples[k, j, i] = affine @ (i, j, k, 1) (columns i = x, j = y, k = z)")
        .def("__repr__", [](const Volume& v) {
            const Index3& d = v.dims();
            return "Volume(" + std::to_string(d[0]) + "x" + std::to_string(d[1]) + "x" + std::to_string(d[2]) + " " +
                   std::string(type_name(v.type())) + ")";
        });
}

void bind_topology(py::module_& m)
{
    py::class_<MeshTopology>(m, "MeshTopology", "Combinatorial invariants of a triangle mesh (mesh_topology()).")
        .def_readonly("vertices", &MeshTopology::vertices, "V: vertices used by at least one triangle")
        .def_readonly("edges", &MeshTopology::edges, "E: distinct undirected edges")
        .def_readonly("faces", &MeshTopology::faces, "F: triangles")
        .def_readonly("euler", &MeshTopology::euler, "V - E + F")
        .def_readonly("components", &MeshTopology::components, "b0: connected components")
        .def_readonly("closed_components", &MeshTopology::closed_components, "b2: components without boundary")
        .def_readonly("b1", &MeshTopology::b1, "b0 + b2 - euler")
        .def_readonly("boundary_edges", &MeshTopology::boundary_edges, "edges with one triangle")
        .def_readonly("boundary_loops", &MeshTopology::boundary_loops, "cycles of boundary edges")
        .def_readonly("nonmanifold_edges", &MeshTopology::nonmanifold_edges, "edges with more than two triangles")
        .def_readonly("nonmanifold_vertices", &MeshTopology::nonmanifold_vertices,
                      "vertices whose triangles form more than one fan")
        .def_readonly("degenerate_triangles", &MeshTopology::degenerate_triangles, "triangles repeating a vertex index")
        .def_readonly("closed", &MeshTopology::closed, "no boundary edge (and at least one triangle)")
        .def_readonly("oriented", &MeshTopology::oriented, "every inner edge used once in each direction")
        .def("__repr__", &topology_text);

    py::class_<MeshGeometry>(m, "MeshGeometry", R"(The mesh as it sits in space (mesh_geometry()), by exact predicates.

Embedded: no two used vertices at one position, no zero-area triangle, and no two triangles meeting
except along a shared edge or at a shared corner; then welding by position changes nothing.)")
        .def_readonly("positions", &MeshGeometry::positions, "distinct positions among used vertices")
        .def_readonly("coincident_vertices", &MeshGeometry::coincident_vertices,
                      "used vertices whose position another used vertex has too")
        .def_readonly("zero_area_triangles", &MeshGeometry::zero_area_triangles, "triangles with collinear corners")
        .def_readonly("intersecting_pairs", &MeshGeometry::intersecting_pairs, "pairs of triangles meeting improperly")
        .def_property_readonly("intersection_examples", [](const MeshGeometry& g) {
            py::list l;
            for (const auto& pair : g.intersection_examples) l.append(py::make_tuple(pair[0], pair[1]));
            return l;
        }, "a few intersecting pairs (triangle indices, smaller first)")
        .def_readonly("welded", &MeshGeometry::welded, "MeshTopology of the mesh welded by exact position")
        .def_property_readonly("embedded", &MeshGeometry::embedded, "no coincident vertex, zero-area triangle or intersection")
        .def("__repr__", [](const MeshGeometry& g) {
            using P = std::pair<const char*, std::int64_t>;
            return fields_text("MeshGeometry", std::pair{"embedded", g.embedded()}, P{"positions", g.positions},
                               P{"coincident_vertices", g.coincident_vertices},
                               P{"zero_area_triangles", g.zero_area_triangles},
                               P{"intersecting_pairs", g.intersecting_pairs});
        });

    py::class_<FieldTopology>(m, "FieldTopology", R"(Invariants of the level set of the trilinear interpolant (field_topology()).

Computed from the samples alone, exactly. ``determined`` is False only when the exact arithmetic
lost range or a cross-check disagreed; ``why`` then says which cell.)")
        .def_readonly("determined", &FieldTopology::determined)
        .def_readonly("why", &FieldTopology::why)
        .def_readonly("euler", &FieldTopology::euler)
        .def_readonly("b0", &FieldTopology::b0, "components")
        .def_readonly("b1", &FieldTopology::b1, "tunnels (and boundary loops' share)")
        .def_readonly("b2", &FieldTopology::b2, "closed components")
        .def_readonly("boundary_loops", &FieldTopology::boundary_loops, "closed curves where the surface meets the box")
        .def("__repr__", [](const FieldTopology& t) {
            using P = std::pair<const char*, std::int64_t>;
            return fields_text("FieldTopology", std::pair{"determined", t.determined}, P{"euler", t.euler}, P{"b0", t.b0},
                               P{"b1", t.b1}, P{"b2", t.b2}, P{"boundary_loops", t.boundary_loops});
        });

    py::class_<FaceReport>(m, "FaceReport", "The face test of one face of a cell (analyze_cell()).")
        .def_readonly("ambiguous", &FaceReport::ambiguous, "the above corners of the face are diagonal")
        .def_readonly("saddle", &FaceReport::saddle, "field value at the face's bilinear saddle")
        .def_readonly("joined", &FaceReport::joined, "the above corners are joined across the face")
        .def_readonly("used", &FaceReport::used, "False where the method ignores the face test (mc)")
        .def("__repr__", [](const FaceReport& f) {
            return fields_text("FaceReport", std::pair{"ambiguous", f.ambiguous}, std::pair{"saddle", f.saddle},
                               std::pair{"joined", f.joined}, std::pair{"used", f.used});
        });

    py::class_<InteriorReport>(m, "InteriorReport", "The interior test of a cell (analyze_cell()); see cmc33/cell.hpp.")
        .def_readonly("tested", &InteriorReport::tested)
        .def_readonly("test", &InteriorReport::test, "\"tunnel\" or \"13.5\"")
        .def_readonly("axis", &InteriorReport::axis)
        .def_readonly("corner_a", &InteriorReport::corner_a)
        .def_readonly("corner_c", &InteriorReport::corner_c)
        .def_readonly("a", &InteriorReport::a)
        .def_readonly("b", &InteriorReport::b)
        .def_readonly("c", &InteriorReport::c)
        .def_readonly("t1", &InteriorReport::t1)
        .def_readonly("t2", &InteriorReport::t2)
        .def_readonly("t_max", &InteriorReport::t_max)
        .def_readonly("f_t_max", &InteriorReport::f_t_max)
        .def_readonly("t_alt", &InteriorReport::t_alt)
        .def_readonly("f_t_alt", &InteriorReport::f_t_alt)
        .def_readonly("skipped", &InteriorReport::skipped, "mc33-lewiner's missing branch of cases 10 and 12")
        .def_readonly("tunnel", &InteriorReport::tunnel, "the decision")
        .def_readonly("tunnel_corner", &InteriorReport::tunnel_corner)
        .def("__repr__", [](const InteriorReport& r) {
            return fields_text("InteriorReport", std::pair{"tested", r.tested}, std::pair{"test", r.test},
                               std::pair{"tunnel", r.tunnel}, std::pair{"t_max", r.t_max}, std::pair{"f_t_max", r.f_t_max});
        });

    py::class_<CellReport>(m, "CellReport", "Every decision the extractor takes for one cell (analyze_cell()).")
        .def_readonly("config", &CellReport::config, "bit c set: corner c above iso; corner c = x | y << 1 | z << 2")
        .def_readonly("base_case", &CellReport::base_case, "0..14")
        .def_readonly("subcase", &CellReport::subcase, "index into subcase_names()")
        .def_property_readonly("subcase_name", [](const CellReport& r) { return std::string(subcase_name(r.subcase)); },
                               "\"4.1.2\", \"13.5.1\", ...")
        .def_property_readonly("faces", [](const CellReport& r) {
            return std::vector<FaceReport>(r.faces.begin(), r.faces.end());
        }, "six FaceReports, face f = 2 * axis + side")
        .def_readonly("interior", &CellReport::interior)
        .def_property_readonly("mesh", [](const CellReport& r) { return PyMesh{r.mesh, std::nullopt, r.mesh.has_normals()}; },
                               "the cell's triangles in the unit cube (a copy)")
        .def("__repr__", [](const CellReport& r) {
            return "CellReport(case " + std::to_string(r.base_case) + ", subcase " + std::string(subcase_name(r.subcase)) +
                   ", " + std::to_string(r.mesh.triangle_count()) + " triangles)";
        });
}

void bind_verify(py::module_& m)
{
    py::class_<MethodReport>(m, "MethodReport", "Results of one method in verify() (see cmc33/verify.hpp).")
        .def_readonly("name", &MethodReport::name)
        .def_readonly("checked", &MethodReport::checked, "fields compared (determined ones)")
        .def_readonly("matched", &MethodReport::matched, "invariants equal, manifold and embedded")
        .def_readonly("mismatched", &MethodReport::mismatched)
        .def_readonly("undetermined", &MethodReport::undetermined)
        .def_readonly("nonmanifold", &MethodReport::nonmanifold)
        .def_readonly("unoriented", &MethodReport::unoriented)
        .def_readonly("not_embedded", &MethodReport::not_embedded)
        .def_readonly("errors", &MethodReport::errors)
        .def_property_readonly("checked_by_kind", [](const MethodReport& r) { return per_kind(r.checked_by_kind); })
        .def_property_readonly("mismatched_by_kind", [](const MethodReport& r) { return per_kind(r.mismatched_by_kind); })
        .def_property_readonly("fields_per_subcase", [](const MethodReport& r) { return per_subcase(r.fields_per_subcase); })
        .def_property_readonly("mismatches_per_subcase",
                               [](const MethodReport& r) { return per_subcase(r.mismatches_per_subcase); })
        .def_readonly("failures_written", &MethodReport::failures_written)
        .def_readonly("first_error", &MethodReport::first_error)
        .def("__repr__", [](const MethodReport& r) {
            using P = std::pair<const char*, std::int64_t>;
            return fields_text("MethodReport", std::pair{"name", r.name}, P{"checked", r.checked}, P{"matched", r.matched},
                               P{"mismatched", r.mismatched}, P{"undetermined", r.undetermined});
        });

    py::class_<VerifyReport>(m, "VerifyReport", "The result of verify(): one MethodReport per method.")
        .def_readonly("methods", &VerifyReport::methods)
        .def_property_readonly("fields", [](const VerifyReport& r) { return per_kind(r.fields); }, "fields run, per kind")
        .def_readonly("seed", &VerifyReport::seed)
        .def_readonly("size", &VerifyReport::size)
        .def_readonly("threads", &VerifyReport::threads)
        .def_readonly("seconds", &VerifyReport::seconds)
        .def_property_readonly("failures_dir", [](const VerifyReport& r) { return r.failures_dir.string(); })
        .def_readonly("failures_written", &VerifyReport::failures_written)
        .def_property_readonly("passed", &VerifyReport::passed, "no mismatch for any method")
        .def("__repr__", [](const VerifyReport& r) {
            std::string s = std::string("VerifyReport(") + (r.passed() ? "passed" : "FAILED");
            for (const MethodReport& mr : r.methods) {
                s += ", " + mr.name + " " + std::to_string(mr.matched) + "/" + std::to_string(mr.checked);
            }
            return s + ")";
        });
}

VerifyReport verify_py(const std::vector<std::string>& methods, std::int64_t cells, std::int64_t grids, std::int64_t closed,
                       std::int64_t ties, int size, std::uint64_t seed, int threads, const std::string& failures_dir,
                       int max_failures, const py::object& progress)
{
    VerifyOptions o;
    o.methods.clear();
    for (const std::string& name : methods) o.methods.push_back(parse_method(name));
    o.cells = cells;
    o.grids = grids;
    o.closed = closed;
    o.ties = ties;
    o.size = size;
    o.seed = seed;
    o.threads = threads;
    o.failures_dir = failures_dir;
    o.max_failures = max_failures;
    std::exception_ptr callback_error;
    if (!progress.is_none()) {
        // verify() calls it on this thread; it cannot be stopped, so an exception waits for the end
        o.progress = [&](const VerifyProgress& p) {
            py::gil_scoped_acquire gil;
            if (callback_error) return;
            try {
                progress(p.done, p.total, p.mismatched, p.seconds);
            } catch (...) {
                callback_error = std::current_exception();
            }
        };
    }
    VerifyReport report;
    {
        py::gil_scoped_release nogil;
        report = verify(o);
    }
    if (callback_error) std::rethrow_exception(callback_error);
    return report;
}

} // namespace

void bind_blocks(py::module_& m); // blocks.cpp: cmc33.dask's per-block extraction
void bind_labels(py::module_& m); // labels.cpp: label maps

} // namespace cmc33::python

PYBIND11_MODULE(_cmc33, m)
{
    using namespace cmc33;
    using namespace cmc33::python;
    m.doc() = "The compiled part of the cmc33 package; use the functions of `cmc33` itself.";
    py::module_::import("numpy");
    py::register_exception_translator(&translate_errors);
    // a new huge page costs more than it saves where the VM's balloon takes free memory back
    set_huge_page_advice(!detail::balloon_reports_free_memory());

    bind_meshes(m);
    bind_volumes(m);
    bind_topology(m);
    bind_verify(m);
    bind_blocks(m);
    bind_labels(m);

    m.attr("version") = std::string(CMC33_VERSION_STRING);
    m.def("method_names", [] {
        return std::vector<std::string>{std::string(method_name(Method::cmc33)), std::string(method_name(Method::mc33_lewiner)),
                                        std::string(method_name(Method::mc))};
    });
    m.def("subcase_names", [] {
        std::vector<std::string> names;
        for (int s = 0; s < kSubcaseCount; ++s) names.emplace_back(subcase_name(s));
        return names;
    });

    m.def("value_range", [](const py::array& volume, int threads) { return value_range(samples_of(volume), threads); },
          py::arg("volume"), py::arg("threads"));
    m.def("extract", &extract_py, py::arg("volume"), py::arg("iso"), py::arg("spacing"), py::arg("origin"),
          py::arg("direction"), py::arg("method"), py::arg("normals"), py::arg("threads"), py::arg("progress"));
    m.def("marching_cubes", &marching_cubes_py, py::arg("volume"), py::arg("level"), py::arg("spacing"), py::arg("method"),
          py::arg("descent"), py::arg("mask_cells"), py::arg("threads"), py::arg("progress"));

    m.def("read_volume", [](const std::filesystem::path& path, const std::optional<Index3>& dims, const std::string& type,
                            const std::optional<Vec3>& spacing, const std::string& endian, std::uint64_t header_bytes,
                            const std::optional<std::int64_t>& frame, const std::string& array, const std::string& series,
                            const std::optional<Vec3>& origin) {
        std::optional<io::RawOptions> raw;
        io::ReadOptions options;
        if (dims) {
            raw = io::RawOptions{*dims, io::parse_type(type), spacing.value_or(Vec3{1, 1, 1}),
                                 endian == "big" ? io::Endian::big : io::Endian::little, header_bytes};
        } else {
            options.spacing = spacing; // the frame of formats that have none (.npy, TIFF)
            options.origin = origin;
        }
        options.frame = frame;
        options.array = array;
        options.series = series;
        py::gil_scoped_release nogil;
        return io::read_volume(path, raw, options);
    }, py::arg("path"), py::arg("dims"), py::arg("type"), py::arg("spacing"), py::arg("endian"), py::arg("header_bytes"),
       py::arg("frame"), py::arg("array"), py::arg("series"), py::arg("origin"));
    m.def("convert_space", [](Volume& volume, const std::string& space) { io::convert_space(volume, space); },
          py::arg("volume"), py::arg("space"));
    m.def("write_volume", [](const Volume& v, const std::filesystem::path& path) {
        py::gil_scoped_release nogil;
        io::write_volume(v, path);
    }, py::arg("volume"), py::arg("path"));
    m.def("read_mesh", [](const std::filesystem::path& path) {
        Mesh mesh;
        {
            py::gil_scoped_release nogil;
            mesh = io::read_mesh(path);
        }
        const bool normals = mesh.has_normals();
        return PyMesh{std::move(mesh), std::nullopt, normals};
    }, py::arg("path"));
    m.def("write_mesh", [](const PyMesh& mesh, const std::filesystem::path& path, bool ascii) {
        py::gil_scoped_release nogil;
        io::write_mesh(mesh.mesh, path, io::MeshWriteOptions{ascii});
    }, py::arg("mesh"), py::arg("path"), py::arg("ascii"));

    m.def("mesh_topology", [](const PyMesh& mesh) {
        py::gil_scoped_release nogil;
        return mesh_topology(mesh.mesh);
    }, py::arg("mesh"));
    m.def("mesh_geometry", [](const PyMesh& mesh, int threads, std::size_t examples) {
        py::gil_scoped_release nogil;
        return mesh_geometry(mesh.mesh, MeshGeometryOptions{threads, examples});
    }, py::arg("mesh"), py::arg("threads"), py::arg("examples"));
    m.def("field_topology", [](const py::array& volume, double iso, int max_refinement) {
        const Samples s = samples_of(volume);
        py::gil_scoped_release nogil;
        return visit(s, Frame{}, [&](const auto& grid) {
            return field_topology(grid, iso, FieldTopologyOptions{max_refinement});
        });
    }, py::arg("volume"), py::arg("iso"), py::arg("max_refinement"));
    m.def("analyze_cell", [](const std::array<double, 8>& values, double iso, const std::string& method) {
        return analyze_cell(values, iso, parse_method(method));
    }, py::arg("values"), py::arg("iso"), py::arg("method"));
    m.def("random_field", [](const std::string& kind, std::int64_t n, std::uint64_t seed, int size) {
        return random_field(parse_kind(kind), n, seed, size);
    }, py::arg("kind"), py::arg("n"), py::arg("seed"), py::arg("size"));
    m.def("verify", &verify_py, py::arg("methods"), py::arg("cells"), py::arg("grids"), py::arg("closed"),
          py::arg("ties"), py::arg("size"), py::arg("seed"), py::arg("threads"), py::arg("failures_dir"),
          py::arg("max_failures"), py::arg("progress"));
}
