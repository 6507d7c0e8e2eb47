"""Points anywhere on the surface: a face and barycentric coordinates, one at a time or many as arrays, and
the closest of them to points in space (locate).

Barycentric coordinates off by rounding are taken as meant (each down to -1e-6, their sum within 1e-6 of 1:
clamped and rescaled; below 1e-12 snapped to 0); anything else is rejected by the library when the point is
used, with a message naming the source or target.
"""

from __future__ import annotations

import dataclasses
import operator
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, Union

import numpy as np

from . import _core, _inputs
from ._mesh import Mesh, checked_mesh

if TYPE_CHECKING:
    from typing_extensions import TypeGuard  # typing's own from Python 3.10


@dataclasses.dataclass(frozen=True)
class SurfacePoint:
    """The point sum_k barycentric[k] * (corner k of input face `face`) (C++: exactgeo::SurfacePoint)."""

    face: int
    barycentric: tuple[float, float, float] = (1.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        try:
            face = operator.index(self.face)
        except TypeError:
            face = None
        if face is None or isinstance(self.face, (bool, np.bool_)):
            raise TypeError(f"SurfacePoint: face must be an integer face index, not {self.face!r}")
        if not 0 <= face < _inputs.INDEX_LIMIT:
            raise ValueError(f"SurfacePoint: face {face} is not a face index")
        try:
            barycentric = tuple(float(c) for c in np.asarray(self.barycentric, dtype=np.float64).reshape(-1))
        except (TypeError, ValueError):
            raise TypeError(
                f"SurfacePoint: barycentric must be three real numbers, not {self.barycentric!r}"
            ) from None
        if len(barycentric) != 3:
            raise ValueError(f"SurfacePoint: {len(barycentric)} barycentric coordinates, not 3")
        # Frozen: the normalized values go in the way dataclasses allow.
        object.__setattr__(self, "face", face)
        object.__setattr__(self, "barycentric", barycentric)


class SurfacePoints:
    """Many surface points as two arrays: `faces` (n,) and `barycentric` (n, 3), any int and real dtypes.

    Use it instead of a list of SurfacePoint for thousands of sources or targets.
    """

    __slots__ = ("faces", "barycentric")

    def __init__(self, faces: object, barycentric: object) -> None:
        self.faces = _inputs.index_array(
            faces,
            "SurfacePoints faces",
            columns=None,
            element=lambda position: "SurfacePoints: face",
            out_of_range=" is not a face index",
        )
        self.barycentric = _inputs.real_array(barycentric, "barycentric coordinates", columns=3)
        if len(self.barycentric) != len(self.faces):
            raise ValueError(
                f"SurfacePoints: {len(self.faces)} faces but {len(self.barycentric)} rows of barycentric coordinates"
            )

    @classmethod
    def of(cls, points: Sequence[SurfacePoint]) -> SurfacePoints:
        """The same points as one SurfacePoints."""
        if not isinstance(points, Sequence) or not all(isinstance(p, SurfacePoint) for p in points):
            raise TypeError(f"points must be a sequence of SurfacePoint, not {_points_text(points)}")
        return cls(
            np.fromiter((p.face for p in points), dtype=np.uint32, count=len(points)),
            np.array([p.barycentric for p in points], dtype=np.float64).reshape(-1, 3),
        )

    def __len__(self) -> int:
        return len(self.faces)

    def __getitem__(self, index: int) -> SurfacePoint:
        return SurfacePoint(int(self.faces[index]), tuple(self.barycentric[index]))

    def __repr__(self) -> str:
        return f"exactgeo.SurfacePoints({len(self)} points)"


# Vertex indices: one, or a list or array of any integer dtype.
VertexIndices = Union[int, np.integer, Sequence[int], np.ndarray]
# Where a geodesic run starts or what it asks about: vertices, or points anywhere on the surface.
Sites = Union[VertexIndices, SurfacePoint, Sequence[SurfacePoint], SurfacePoints]


def source_sites(sources: Any, mesh: Mesh) -> np.ndarray | SurfacePoints:
    """Vertex indices as a uint32 array, or the points as SurfacePoints.

    Vertices and points do not mix: a vertex that the mesh split into several surface copies (non-manifold)
    is a source at every copy, a point only on its face.
    """
    if not holds_points(sources):
        return _inputs.vertex_array(sources, mesh.vertex_count, "sources", lambda i: "source vertex")
    if isinstance(sources, Sequence) and not all(isinstance(s, SurfacePoint) for s in sources):
        raise ValueError(
            "sources mix vertex indices and SurfacePoints: give SurfacePoints only "
            "(exactgeo.vertex_point turns a vertex into one)"
        )
    return _as_surface_points(sources)


def target_points(targets: Any, mesh: Mesh, what: str = "targets", item: str = "target") -> SurfacePoints:
    """Targets are points: a vertex target is the point at the vertex (which is the vertex, all its copies).

    `what` names the argument and `item` its elements in messages ("target 3: vertex 99 is out of range")."""
    if not holds_points(targets):
        vertices = _inputs.vertex_array(targets, mesh.vertex_count, what, lambda i: f"{item} {i}: vertex")
        return SurfacePoints(*_core.vertex_points(mesh._core, vertices, item))
    if isinstance(targets, Sequence):
        targets = [
            t if isinstance(t, SurfacePoint) else _vertex_target(mesh, i, t, item) for i, t in enumerate(targets)
        ]
    return _as_surface_points(targets)


def _points_text(points: Any) -> str:
    """What was given instead of points, for a message: a type, or the types a sequence holds."""
    if isinstance(points, Sequence) and not isinstance(points, str):
        return "a sequence holding " + ", ".join(sorted({type(p).__name__ for p in points}))
    return type(points).__name__


def holds_points(sites: Any) -> TypeGuard[SurfacePoint | Sequence[SurfacePoint] | SurfacePoints]:
    """Whether `sites` are surface points (a SurfacePoint, SurfacePoints, or a sequence with a SurfacePoint)."""
    return isinstance(sites, (SurfacePoint, SurfacePoints)) or (
        isinstance(sites, Sequence) and any(isinstance(s, SurfacePoint) for s in sites)
    )


def _as_surface_points(points: Any) -> SurfacePoints:
    if isinstance(points, SurfacePoints):
        return points
    return SurfacePoints.of([points] if isinstance(points, SurfacePoint) else points)


def _vertex_target(mesh: Mesh, index: int, vertex: int, item: str) -> SurfacePoint:
    try:
        return vertex_point(mesh, vertex)
    except ValueError as error:
        raise ValueError(f"{item} {index}: {error}") from None


def vertex_point(mesh: Mesh, vertex: int) -> SurfacePoint:
    """The point at input vertex `vertex`: as a source or target, the vertex itself (every surface copy of it)."""
    mesh = checked_mesh(mesh)
    vertices = np.array([_inputs.vertex_index(vertex, mesh.vertex_count, "vertex", "vertex")], dtype=np.uint32)
    faces, barycentric = _core.vertex_points(mesh._core, vertices, "")
    return SurfacePoint(int(faces[0]), tuple(barycentric[0]))


def edge_point(mesh: Mesh, from_vertex: int, to_vertex: int, t: float) -> SurfacePoint:
    """The point (1 - t) * from_vertex + t * to_vertex on their edge, t in [0, 1]."""
    mesh = checked_mesh(mesh)
    start, end = [
        _inputs.vertex_index(vertex, mesh.vertex_count, what, f"edge ({from_vertex}, {to_vertex}): vertex")
        for vertex, what in ((from_vertex, "from_vertex"), (to_vertex, "to_vertex"))
    ]
    face, (b0, b1, b2) = _core.edge_point(mesh._core, start, end, _inputs.real(t, "t"))
    return SurfacePoint(face, (b0, b1, b2))


def point_position(mesh: Mesh, points: SurfacePoint | SurfacePoints) -> np.ndarray:
    """Where points lie in space: (3,) for one SurfacePoint, (n, 3) for SurfacePoints."""
    mesh = checked_mesh(mesh)
    if not isinstance(points, (SurfacePoint, SurfacePoints)):
        raise TypeError(f"points must be a SurfacePoint or SurfacePoints, not {type(points).__name__}")
    many = _as_surface_points(points)
    positions = _core.point_positions(mesh._core, many.faces, many.barycentric)
    return positions if isinstance(points, SurfacePoints) else positions[0]


def locate(mesh: Mesh, xyz: object, *, threads: int | None = None) -> tuple[SurfacePoints, np.ndarray]:
    """The closest surface point of each point in space, and its distance to the surface.

    `xyz` is an (n, 3) array of any real dtype, or one point (3,) (then n = 1). Returns SurfacePoints (on kept
    input faces; where several faces hold the closest point, an edge or a corner, the lowest face index) and
    the distances as float64 (n,). The points serve as they are as sources and targets. The first call on a
    mesh builds a bounding-volume hierarchy of its faces (about 110 bytes per face), which the mesh keeps for
    later calls. `threads` share the points (0 or None, the default: one per core). The GIL is released while
    the points are located.
    """
    mesh = checked_mesh(mesh)
    array = np.asarray(xyz)
    if array.ndim == 1:
        if array.shape != (3,):
            raise ValueError(f"xyz must have shape (n, 3) or (3,), not {array.shape}")
        array = array.reshape(1, 3)
    points = _inputs.real_array(array, "xyz", columns=3)
    workers = 0 if threads is None else _inputs.count(threads, "threads")
    faces, barycentric, distances = _core.locate(mesh._core, points, workers)
    return SurfacePoints(faces, barycentric), distances
