"""The cmc33 ParaView plugin: a filter "CMC33 Isosurface" on image data (Filters > Alphabetical),
with the isovalues, the input point array, the method, normals, topology, embedding and threads as
properties; the topology and embedding verdicts are in the output's field data (Information panel,
or the Spreadsheet view's Field Data). It is :class:`cmc33.vtk.ExtractFilter` with ParaView's
property decorators, nothing more.

Load this file as a plugin: in the GUI, Tools > Manage Plugins > Load New; in pvpython or pvbatch,
``cmc33.vtk.load_paraview_plugin()`` (or ``LoadPlugin(path, ns=globals())``); or name its folder
in PV_PLUGIN_PATH. ParaView's Python must import cmc33 (same Python version as the extension was
built for). ParaView 5.11 on Python 3.11 (Debian 12) first needs
``inspect.getargspec = inspect.getfullargspec`` (its paraview/detail/pythonalgorithm.py imports
the name Python 3.11 removed): docs/paraview.md says where to put it.
"""

import os
import sys

try:
    import cmc33.vtk as _cmc33_vtk
except ImportError:
    # loaded by path from an installed package that ParaView's sys.path does not list
    sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.realpath(__file__))))
    import cmc33.vtk as _cmc33_vtk

from paraview.util.vtkAlgorithm import smdomain, smhint, smproperty, smproxy

paraview_plugin_name = "cmc33"
paraview_plugin_version = _cmc33_vtk.__version__

_METHODS = "".join(f'<Entry value="{i}" text="{name}"/>' for i, name in enumerate(_cmc33_vtk.METHODS))


@smproxy.filter(name="CMC33Isosurface", label="CMC33 Isosurface")
@smhint.xml('<ShowInMenu category="Alphabetical"/>')
@smproperty.input(name="Input", port_index=0)
@smdomain.datatype(dataTypes=["vtkImageData"], composite_data_supported=False)
@smdomain.xml('<InputArrayDomain name="input_array" attribute_type="point" number_of_components="1"/>')
class CMC33Isosurface(_cmc33_vtk.ExtractFilter):
    """Topologically correct, manifold and embedded isosurfaces (Marching Cubes 33 as corrected by
    Custodio et al. 2013) of a point array of image data."""

    @smproperty.xml("""
        <StringVectorProperty name="SelectInputScalars" label="Contour By" command="SetInputArrayToProcess"
                              number_of_elements="5" element_types="0 0 0 0 2" animateable="0">
          <ArrayListDomain name="array_list" attribute_type="Scalars" input_domain_name="input_array">
            <RequiredProperties><Property name="Input" function="Input"/></RequiredProperties>
          </ArrayListDomain>
          <Documentation>The point array to extract the isosurfaces of (one component).</Documentation>
        </StringVectorProperty>""")
    def SetInputArrayToProcess(self, *args):
        return _cmc33_vtk.ExtractFilter.SetInputArrayToProcess(self, *args)

    @smproperty.doublevector(name="Isovalues", label="Isosurfaces", command="SetIsovalueAt", number_of_elements=0,
                             repeat_command=1, number_of_elements_per_command=1, use_index=1,
                             set_number_command="SetNumberOfIsovalues")
    @smdomain.xml("""
        <ArrayRangeDomain name="scalar_range" default_mode="mid">
          <RequiredProperties>
            <Property name="Input" function="Input"/>
            <Property name="SelectInputScalars" function="ArraySelection"/>
          </RequiredProperties>
        </ArrayRangeDomain>""")
    def SetIsovalueAt(self, index, value):
        """The isovalues: one mesh each (a sample equal to the isovalue counts as above it)."""
        _cmc33_vtk.ExtractFilter.SetIsovalueAt(self, index, value)

    def SetNumberOfIsovalues(self, n):
        _cmc33_vtk.ExtractFilter.SetNumberOfIsovalues(self, n)

    @smproperty.intvector(name="Method", default_values=0)
    @smdomain.xml(f'<EnumerationDomain name="enum">{_METHODS}</EnumerationDomain>')
    def SetMethod(self, method):
        """cmc33 (topologically correct) or, for comparison, mc33-lewiner or mc."""
        _cmc33_vtk.ExtractFilter.SetMethod(self, int(method))

    @smproperty.intvector(name="ComputeNormals", label="Compute Normals", default_values=1)
    @smdomain.xml('<BooleanDomain name="bool"/>')
    def SetComputeNormals(self, on):
        """Unit per-vertex normals from the field's gradient ("Normals")."""
        _cmc33_vtk.ExtractFilter.SetComputeNormals(self, on)

    @smproperty.intvector(name="ComputeTopology", label="Compute Topology", default_values=1)
    @smdomain.xml('<BooleanDomain name="bool"/>')
    def SetComputeTopology(self, on):
        """The meshes' Euler characteristic, Betti numbers and manifoldness in the field data."""
        _cmc33_vtk.ExtractFilter.SetComputeTopology(self, on)

    @smproperty.intvector(name="CheckEmbedding", label="Check Embedding", default_values=1)
    @smdomain.xml('<BooleanDomain name="bool"/>')
    def SetCheckEmbedding(self, on):
        """With topology: check with exact predicates that no two triangles meet improperly
        (cmc33_embedded in the field data)."""
        _cmc33_vtk.ExtractFilter.SetCheckEmbedding(self, on)

    @smproperty.intvector(name="Threads", default_values=0, panel_visibility="advanced")
    @smdomain.intrange(min=0, max=1024)
    def SetThreads(self, threads):
        """Worker threads, 0 for every core (the mesh is the same for every count)."""
        _cmc33_vtk.ExtractFilter.SetThreads(self, threads)
