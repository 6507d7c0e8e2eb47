"""Meshes of other Python mesh libraries (trimesh, meshio, pyvista, open3d) as (vertices, faces) for
exactgeo.Mesh.

None of these libraries is imported: their objects are read through the attributes they document, so they
stay optional and exactgeo imports as fast without them. Polygons are fan-triangulated as the file readers do, by
the same code as exactgeo.Mesh(vertices, polygons).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from . import _inputs

_ACCEPTED = (
    "a trimesh.Trimesh, a meshio.Mesh, a pyvista.PolyData or UnstructuredGrid, an open3d.geometry.TriangleMesh, "
    "an exactgeo.Mesh or a (vertices, faces) pair"
)


def type_name(obj: object) -> str:
    """'trimesh.base.Trimesh' rather than 'Trimesh': the message says which library the object came from."""
    kind = type(obj)
    module = kind.__module__
    return kind.__qualname__ if module == "builtins" else f"{module}.{kind.__qualname__}"


def kind_of(obj: object) -> str | None:
    """Which library's mesh `obj` looks like, by the attributes it has: "pyvista", "meshio", "open3d",
    "trimesh", or None."""
    if hasattr(obj, "points") and hasattr(obj, "extract_surface"):
        return "pyvista"
    if hasattr(obj, "points") and hasattr(obj, "cells"):
        return "meshio"
    # trimesh.Trimesh has .triangles too (corner coordinates): it is told by .faces, which open3d lacks.
    if hasattr(obj, "vertices") and hasattr(obj, "faces") or hasattr(obj, "geometry") and hasattr(obj, "dump"):
        return "trimesh"
    if hasattr(obj, "vertices") and hasattr(obj, "triangles"):
        return "open3d"
    return None


def _require(obj: object, attributes: tuple[str, ...], expected: str) -> None:
    missing = [name for name in attributes if not hasattr(obj, name)]
    if missing:
        raise TypeError(
            f"mesh must be {expected}, not {type_name(obj)} (it has no attribute {', '.join(map(repr, missing))})"
        )


def from_trimesh(obj: Any) -> tuple[Any, Any]:
    if hasattr(obj, "geometry") and not hasattr(obj, "faces"):
        raise TypeError(
            f"mesh must be a trimesh.Trimesh, not a scene ({type_name(obj)}) of {len(obj.geometry)} meshes: "
            "trimesh.load(path, force='mesh') or scene.to_geometry() gives one mesh"
        )
    _require(obj, ("vertices", "faces"), "a trimesh.Trimesh (with .vertices and .faces)")
    return obj.vertices, obj.faces


def from_open3d(obj: Any) -> tuple[Any, Any]:
    _require(obj, ("vertices", "triangles"), "an open3d.geometry.TriangleMesh (with .vertices and .triangles)")
    # open3d's Vector3dVector and Vector3iVector convert to numpy arrays without a copy.
    return np.asarray(obj.vertices), np.asarray(obj.triangles)


def from_meshio(obj: Any) -> tuple[np.ndarray, np.ndarray]:
    """The points and every triangle, quad and polygon cell block, fanned block by block; other blocks (lines,
    vertices, volume and higher-order cells) are left out. 2-D points get z = 0 in exactgeo.Mesh."""
    _require(obj, ("points", "cells"), "a meshio.Mesh (with .points and .cells)")
    points = np.asarray(obj.points)
    blocks = [(block.type, block.data) for block in obj.cells]
    triangles = []
    for number, (kind, data) in enumerate(blocks):
        if _is_plain_polygon(kind):
            try:
                triangles.append(_inputs.triangles_array(data, len(points)))
            except ValueError as error:
                raise ValueError(f"meshio cell block {number} ({kind}): {error}") from None
    if not triangles:
        found = ", ".join(f"{len(data)} {kind}" for kind, data in blocks) or "no cells"
        raise ValueError(
            f"the meshio mesh has no triangle, quad or polygon cells to build a surface from (it has {found})"
        )
    return points, np.concatenate(triangles)


def _is_plain_polygon(kind: str) -> bool:
    """"triangle", "quad", "polygon", "polygon5"; not the higher-order "triangle6" or "quad8"."""
    return kind in ("triangle", "quad", "polygon") or (kind.startswith("polygon") and kind[7:].isdigit())


def from_pyvista(obj: Any) -> tuple[np.ndarray, Any]:
    """PolyData's polygons (the packed faces array); an UnstructuredGrid or any other dataset goes through
    its extract_surface() first. Lines, vertices and triangle strips are left out."""
    _require(obj, ("points",), "a pyvista.PolyData or UnstructuredGrid (with .points)")
    if not hasattr(obj, "faces") and hasattr(obj, "extract_surface"):
        obj = obj.extract_surface()
    _require(obj, ("faces",), "a pyvista.PolyData (with .faces) or a dataset with .extract_surface()")
    packed = np.asarray(obj.faces).reshape(-1)
    if packed.size == 0:
        raise ValueError(
            "the pyvista mesh has no polygons (triangle strips are left out: mesh.triangulate() turns them "
            "into triangles)"
        )
    return np.asarray(obj.points), unpack_vtk_faces(packed)


def unpack_vtk_faces(packed: np.ndarray) -> np.ndarray | list[np.ndarray]:
    """VTK's packed cell array (n, i0, ..., i(n-1), n, ...) as an (m, n) array if every face has the same
    size n, else as a list of index arrays."""
    size = int(packed[0])
    if size > 0 and packed.size % (size + 1) == 0:
        table = packed.reshape(-1, size + 1)
        if (table[:, 0] == size).all():
            return table[:, 1:]
    faces: list[np.ndarray] = []
    start = 0
    while start < packed.size:
        size = int(packed[start])
        end = start + 1 + size
        if size < 0 or end > packed.size:
            raise ValueError(f"the pyvista faces array is cut short: face {len(faces)} claims {size} vertices")
        faces.append(packed[start + 1 : end])
        start = end
    return faces


def vertices_and_faces(obj: Any) -> tuple[Any, Any]:
    """Any of the accepted meshes, told apart by their attributes, as (vertices, faces)."""
    kind = kind_of(obj)
    if kind is not None:
        return CONVERTERS[kind](obj)
    if isinstance(obj, (tuple, list)) and len(obj) == 2:
        return obj[0], obj[1]
    raise TypeError(f"mesh must be {_ACCEPTED}, not {type_name(obj)}")


CONVERTERS = {"trimesh": from_trimesh, "meshio": from_meshio, "pyvista": from_pyvista, "open3d": from_open3d}
