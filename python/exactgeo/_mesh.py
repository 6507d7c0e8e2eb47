"""exactgeo.Mesh: a validated triangle mesh, built once, shared by every query on it."""

from __future__ import annotations

import atexit
import os
import threading
import uuid
import weakref
from typing import Any

import numpy as np

from . import _core, _inputs, _mesh_libraries
from ._progress import Progress, run_with_progress


class Mesh:
    """A triangle mesh ready for geodesic queries (C++: exactgeo::Mesh).

    `vertices` is (n, 3) coordinates, or (n, 2) for a flat mesh at z = 0, and `faces` is (m, 3) zero-based
    vertex indices, of any real and any integer dtype respectively (float indices must be whole numbers), C or
    Fortran order, or nested lists.
    Polygons ((m, k) arrays, or lists of index lists of any lengths) are fan-triangulated as Mesh.load does;
    face indices (in reports, SurfacePoints, paths) then count the triangles.
    Real-world meshes are accepted as they are: vertices used by no face (distance inf), faces repeating a
    vertex (dropped), degenerate faces, holes, several components, non-manifold edges and vertices (cut into
    a manifold surface), see `report`. Raises ValueError, with the library's message naming the element,
    for non-finite coordinates, indices out of range or a mesh without a usable face.

    `weld_duplicate_positions` merges vertices with identical coordinates (seams) before anything else.

    The mesh is built on `threads` threads (0, the default: one per core; the mesh is the same on any
    count), without the GIL. `progress`: True for a tqdm bar, or a function called with (done, total)
    thousandths of the build. Ctrl-C stops a large build within a tenth of a second.

    A Mesh pickles as its arrays and options (for multiprocessing and Dask): the copy is built and validated
    anew, and equals the original. A process that unpickles the same mesh again (Dask tasks that share it)
    gets the copy it built before, as long as one is alive or it was the last one unpickled.
    """

    __slots__ = ("_core", "_weld", "_identity", "__weakref__")

    def __init__(
        self,
        vertices: object,
        faces: object,
        *,
        weld_duplicate_positions: bool = False,
        threads: int = 0,
        progress: Progress = None,
    ) -> None:
        positions = _inputs.positions_array(vertices)
        triangles = _inputs.triangles_array(faces, len(positions))
        weld = _inputs.flag(weld_duplicate_positions, "weld_duplicate_positions")
        count = _inputs.count(threads, "threads")
        self._core = run_with_progress(
            progress, "mesh", 1000, lambda reporter: _core.Mesh(positions, triangles, weld, count, reporter)
        )
        self._weld = weld
        self._identity: str | None = None  # made when first pickled (a uuid costs a tenth of a tiny build)

    @classmethod
    def load(
        cls,
        path: str | bytes | os.PathLike[str] | os.PathLike[bytes],
        *,
        weld_duplicate_positions: bool = False,
        threads: int = 0,
        progress: Progress = None,
    ) -> Mesh:
        """Reads an .obj, .ply (ASCII or binary), .off or .stl file; polygons are fan-triangulated. The file
        is read and the mesh built on `threads` threads, with `progress` and Ctrl-C as in Mesh().

        `path` is a str, bytes or os.PathLike, as open() takes: a name that is not UTF-8 is read as it is.
        Raises OSError if the file cannot be read, ValueError naming the line or element if its content is
        malformed.
        """
        name = _inputs.path(path)
        weld = _inputs.flag(weld_duplicate_positions, "weld_duplicate_positions")
        count = _inputs.count(threads, "threads")
        mesh = cls.__new__(cls)
        mesh._core = run_with_progress(
            progress, "mesh", 1000, lambda reporter: _core.load_mesh(name, weld, count, reporter)
        )
        mesh._weld = weld
        mesh._identity = None
        return mesh

    @classmethod
    def from_trimesh(cls, mesh: Any, *, weld_duplicate_positions: bool = False) -> Mesh:
        """A trimesh.Trimesh's vertices and faces.

        trimesh splits vertices at texture and normal seams when it loads a file (spot.obj, any textured
        OBJ): distances then stop at the seams, which exactgeo.distance warns about;
        `weld_duplicate_positions=True` joins them again. A trimesh.Scene raises TypeError naming
        trimesh.load(path, force="mesh").
        """
        return cls._of(_mesh_libraries.from_trimesh(mesh), weld_duplicate_positions)

    @classmethod
    def from_meshio(cls, mesh: Any, *, weld_duplicate_positions: bool = False) -> Mesh:
        """A meshio.Mesh's points and its triangle, quad and polygon cell blocks (polygons fan-triangulated;
        face numbers count the triangles block after block). Lines, vertices, volume and higher-order cells
        are left out; ValueError naming the cell types found if no block is usable. 2-D points get z = 0.
        """
        return cls._of(_mesh_libraries.from_meshio(mesh), weld_duplicate_positions)

    @classmethod
    def from_pyvista(cls, mesh: Any, *, weld_duplicate_positions: bool = False) -> Mesh:
        """A pyvista.PolyData's points and polygons (its packed faces array, fan-triangulated); an
        UnstructuredGrid or another dataset is reduced to its outer surface with extract_surface() first.
        Lines, vertices and triangle strips are left out (mesh.triangulate() turns strips into triangles).
        """
        return cls._of(_mesh_libraries.from_pyvista(mesh), weld_duplicate_positions)

    @classmethod
    def from_open3d(cls, mesh: Any, *, weld_duplicate_positions: bool = False) -> Mesh:
        """An open3d.geometry.TriangleMesh's vertices and triangles."""
        return cls._of(_mesh_libraries.from_open3d(mesh), weld_duplicate_positions)

    @classmethod
    def from_any(cls, mesh: Any, *, weld_duplicate_positions: bool = False) -> Mesh:
        """A mesh of any of the libraries above, told apart by its attributes (none of them is imported), an
        exactgeo.Mesh (itself, or rebuilt if `weld_duplicate_positions` differs) or a (vertices, faces) pair.
        Anything else raises TypeError naming its type and what is accepted."""
        if isinstance(mesh, Mesh):
            if mesh._weld == _inputs.flag(weld_duplicate_positions, "weld_duplicate_positions"):
                return mesh
            return cls(mesh.vertices, mesh.faces, weld_duplicate_positions=weld_duplicate_positions)
        return cls._of(_mesh_libraries.vertices_and_faces(mesh), weld_duplicate_positions)

    @classmethod
    def _of(cls, arrays: tuple[Any, Any], weld_duplicate_positions: bool) -> Mesh:
        return cls(arrays[0], arrays[1], weld_duplicate_positions=weld_duplicate_positions)

    def __reduce__(self) -> tuple[object, tuple[object, ...]]:
        # The input arrays (a file's polygons already fanned into them) rebuild the same mesh; the identity
        # lets a process that already rebuilt it reuse that copy. (Two threads pickling a mesh for the first
        # time at once may give it two identities: a process receiving both then builds it twice.)
        if self._identity is None:
            self._identity = uuid.uuid4().hex
        return (_rebuilt_mesh, (np.array(self.vertices), np.array(self.faces), self._weld, self._identity))

    @property
    def vertex_count(self) -> int:
        """Input vertices, used by a face or not."""
        return self._core.vertex_count

    @property
    def face_count(self) -> int:
        """Input triangles, dropped ones included."""
        return self._core.face_count

    @property
    def vertices(self) -> np.ndarray:
        """(vertex_count, 3) float64, a read-only view of the mesh's own storage."""
        return self._core.positions

    @property
    def faces(self) -> np.ndarray:
        """(face_count, 3) uint32, a read-only view of the mesh's own storage."""
        return self._core.triangles

    @property
    def report(self) -> _core.MeshReport:
        """What validation found: counts of dropped and degenerate faces, boundary and non-manifold edges,
        split vertices, components, saddle vertices, as attributes (C++: exactgeo::MeshReport);
        .to_dict() gives them as a dict."""
        return self._core.report

    def __repr__(self) -> str:
        return f"exactgeo.Mesh(vertex_count={self.vertex_count}, face_count={self.face_count})"


# Meshes this process unpickled, by the identity of the original: every copy still alive, and the last one
# unpickled, so that tasks receiving the same mesh one after the other do not each build it again.
_unpickled: weakref.WeakValueDictionary[str, Mesh] = weakref.WeakValueDictionary()
_last_unpickled: list[Mesh] = []
_unpickled_lock = threading.Lock()
# Let go before the interpreter tears the compiled module down (which counts what is still held as a leak).
atexit.register(_last_unpickled.clear)


def _rebuilt_mesh(vertices: np.ndarray, faces: np.ndarray, weld: bool, identity: str | None = None) -> Mesh:
    with _unpickled_lock:
        mesh = _unpickled.get(identity) if identity else None
    if mesh is not None:
        return mesh
    mesh = Mesh(vertices, faces, weld_duplicate_positions=weld)
    if identity:
        mesh._identity = identity
        with _unpickled_lock:
            _unpickled[identity] = mesh
            _last_unpickled[:] = [mesh]
    return mesh


def checked_mesh(mesh: object, what: str = "mesh") -> Mesh:
    """`mesh` itself if it is an exactgeo.Mesh; a TypeError saying how to make one otherwise."""
    if isinstance(mesh, Mesh):
        return mesh
    raise TypeError(
        f"{what} must be an exactgeo.Mesh, not {type(mesh).__name__}: build one with exactgeo.Mesh(vertices, faces) "
        "or exactgeo.Mesh.load(path)"
    )
