// cmc33._cmc33.label_surfaces: a label map (an integer numpy array, read in place) to its interface
// mesh, the two labels of each triangle and, if asked for, each selected label's closed surface.
// The Python layer (cmc33/_labels.py) checks the arguments and wraps the result.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "binding.hpp"

#include "cmc33/labels.hpp"

namespace cmc33::python {
namespace {

/// What the work without the GIL hands back: the library's result and the per-label surfaces.
struct Labelled {
    LabelSurfaces surfaces;
    std::vector<Mesh> per_label; // one per surfaces.selected, when asked for
};

py::tuple label_surfaces_py(const py::array& labels, const Vec3& spacing, const Vec3& origin, const Mat3& direction,
                            std::int64_t background, const LabelRanges& selection, bool normals, int threads,
                            bool per_label, double smooth)
{
    const Samples s = samples_of(labels, "labels");
    LabelOptions options;
    options.background = background;
    options.labels = selection;
    options.normals = normals;
    options.threads = threads;
    options.smooth = smooth;
    const Frame frame{spacing, origin, direction};
    Labelled out = run_interruptible<Labelled>(false, py::none(), [&](Control&) {
        Labelled l;
        l.surfaces = visit(s, frame, [&](const auto& grid) { return label_surfaces(grid, options); });
        if (per_label) {
            l.per_label.reserve(l.surfaces.selected.size());
            for (const std::int64_t label : l.surfaces.selected) l.per_label.push_back(label_surface(l.surfaces, label));
        }
        return l;
    });
    py::dict surfaces;
    for (std::size_t i = 0; i < out.per_label.size(); ++i) {
        surfaces[py::int_(out.surfaces.selected[i])] = py::cast(PyMesh{std::move(out.per_label[i]), std::nullopt, normals});
    }
    LabelSurfaces& r = out.surfaces;
    py::object front = to_numpy(std::move(r.front)), behind = to_numpy(std::move(r.behind));
    py::object interfaces = py::cast(PyMesh{std::move(r.interfaces), std::nullopt, normals});
    return py::make_tuple(interfaces, front, behind, per_label ? py::object(surfaces) : py::object(py::none()),
                          r.present, r.selected, r.cells_two_labels, r.cells_many_labels, r.cells_with_core);
}

} // namespace

void bind_labels(py::module_& m)
{
    m.def("label_surfaces", &label_surfaces_py, py::arg("labels"), py::arg("spacing"), py::arg("origin"),
          py::arg("direction"), py::arg("background"), py::arg("selection"), py::arg("normals"), py::arg("threads"),
          py::arg("per_label"), py::arg("smooth") = 0.0);
    m.def("parse_label_ranges", [](const std::string& text) { return parse_label_ranges(text); }, py::arg("text"));
}

} // namespace cmc33::python
