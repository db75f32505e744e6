# Types of the compiled module cmc33._cmc33 (python/ext/module.cpp). The public functions are the
# typed wrappers of cmc33/_api.py and cmc33/_skimage.py; the classes below are public as cmc33.X.
from typing import Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

Vec3 = Tuple[float, float, float]
Mat3 = Tuple[Vec3, Vec3, Vec3]

version: str

class Mesh:
    """An indexed triangle mesh held in the library's memory; its arrays are views of it."""
    def __init__(self, vertices: npt.ArrayLike, triangles: npt.ArrayLike,
                 normals: Optional[npt.ArrayLike] = ...) -> None: ...
    @property
    def vertices(self) -> npt.NDArray[np.float32]: ...
    @property
    def triangles(self) -> npt.NDArray[np.uint32]: ...
    @property
    def normals(self) -> Optional[npt.NDArray[np.float32]]: ...
    @property
    def vertex_count(self) -> int: ...
    @property
    def triangle_count(self) -> int: ...
    @property
    def cells_per_subcase(self) -> Optional[Dict[str, int]]: ...

class Volume:
    """Samples (nz, ny, nx) in the library's memory and their frame in x, y, z order."""
    def __init__(self, samples: npt.NDArray[np.generic], spacing: Vec3, origin: Vec3, direction: Mat3) -> None: ...
    @property
    def samples(self) -> npt.NDArray[np.generic]: ...
    @property
    def dtype(self) -> np.dtype: ...
    @property
    def shape(self) -> Tuple[int, int, int]: ...
    @property
    def spacing(self) -> Vec3: ...
    @property
    def origin(self) -> Vec3: ...
    @property
    def direction(self) -> npt.NDArray[np.float64]: ...
    @property
    def space(self) -> str: ...
    @property
    def space_code(self) -> Optional[str]: ...
    @property
    def frame_source(self) -> str: ...
    @property
    def affine(self) -> npt.NDArray[np.float64]: ...

class MeshTopology:
    vertices: int
    edges: int
    faces: int
    euler: int
    components: int
    closed_components: int
    b1: int
    boundary_edges: int
    boundary_loops: int
    nonmanifold_edges: int
    nonmanifold_vertices: int
    degenerate_triangles: int
    closed: bool
    oriented: bool

class MeshGeometry:
    positions: int
    coincident_vertices: int
    zero_area_triangles: int
    intersecting_pairs: int
    intersection_examples: List[Tuple[int, int]]
    welded: MeshTopology
    embedded: bool

class FieldTopology:
    determined: bool
    why: str
    euler: int
    b0: int
    b1: int
    b2: int
    boundary_loops: int

class FaceReport:
    ambiguous: bool
    saddle: float
    joined: bool
    used: bool

class InteriorReport:
    tested: bool
    test: str
    axis: int
    corner_a: int
    corner_c: int
    a: float
    b: float
    c: float
    t1: float
    t2: float
    t_max: float
    f_t_max: float
    t_alt: float
    f_t_alt: float
    skipped: bool
    tunnel: bool
    tunnel_corner: int

class CellReport:
    config: int
    base_case: int
    subcase: int
    subcase_name: str
    faces: List[FaceReport]
    interior: InteriorReport
    mesh: Mesh

class MethodReport:
    name: str
    checked: int
    matched: int
    mismatched: int
    undetermined: int
    nonmanifold: int
    unoriented: int
    not_embedded: int
    errors: int
    checked_by_kind: Dict[str, int]
    mismatched_by_kind: Dict[str, int]
    fields_per_subcase: Dict[str, int]
    mismatches_per_subcase: Dict[str, int]
    failures_written: int
    first_error: str

class VerifyReport:
    methods: List[MethodReport]
    fields: Dict[str, int]
    seed: int
    size: int
    threads: int
    seconds: float
    failures_dir: str
    failures_written: int
    passed: bool

def method_names() -> List[str]: ...
def subcase_names() -> List[str]: ...
def value_range(volume: npt.NDArray[np.generic], threads: int) -> Tuple[float, float]: ...
def extract(volume: npt.NDArray[np.generic], iso: float, spacing: Vec3, origin: Vec3, direction: Mat3, method: str,
            normals: bool, threads: int, progress: Optional[Callable[[float], Optional[bool]]]) -> Mesh: ...
def marching_cubes(volume: npt.NDArray[np.generic], level: float, spacing: Vec3, method: str, descent: bool,
                   mask_cells: Optional[npt.NDArray[np.bool_]], threads: int,
                   progress: Optional[Callable[[float], Optional[bool]]]
                   ) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.int32], npt.NDArray[np.float32],
                              npt.NDArray[np.float32]]: ...
def read_volume(path: str, dims: Optional[Tuple[int, int, int]], type: str, spacing: Optional[Vec3], endian: str,
                header_bytes: int, frame: Optional[int], array: str, series: str, origin: Optional[Vec3]) -> Volume: ...
def convert_space(volume: Volume, space: str) -> None: ...
def write_volume(volume: Volume, path: str) -> None: ...
def read_mesh(path: str) -> Mesh: ...
def write_mesh(mesh: Mesh, path: str, ascii: bool) -> None: ...
def mesh_topology(mesh: Mesh) -> MeshTopology: ...
def mesh_geometry(mesh: Mesh, threads: int, examples: int) -> MeshGeometry: ...
def field_topology(volume: npt.NDArray[np.generic], iso: float, max_refinement: int) -> FieldTopology: ...
def analyze_cell(values: Sequence[float], iso: float, method: str) -> CellReport: ...
def label_surfaces(labels: npt.NDArray[np.integer], spacing: Vec3, origin: Vec3, direction: Mat3, background: int,
                   selection: List[Tuple[int, int]], normals: bool, threads: int, per_label: bool,
                   smooth: float = ...) -> Tuple[Mesh, npt.NDArray[np.int64], npt.NDArray[np.int64], Optional[Dict[int, Mesh]],
                              List[int], List[int], int, int]: ...
def parse_label_ranges(text: str) -> List[Tuple[int, int]]: ...
def random_field(kind: str, n: int, seed: int, size: int) -> Volume: ...
def verify(methods: List[str], cells: int, grids: int, closed: int, ties: int, size: int, seed: int, threads: int,
           failures_dir: str, max_failures: int,
           progress: Optional[Callable[[int, int, int, float], None]]) -> VerifyReport: ...
