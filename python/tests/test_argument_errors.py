"""Every public function, method and constructor, given an argument of the wrong type (a str where a number
belongs, a float where an integer does, None, a bool) or out of the range its type allows: a TypeError or
ValueError in a short message naming the argument and what it takes, never nanobind's list of signatures or an
error from deep inside (an AttributeError, a KeyError, numpy's conversion messages), and nothing written."""

from __future__ import annotations

import inspect
from typing import Any, Callable

import numpy as np
import pytest

import exactgeo
from exactgeo import distributed

MESH = exactgeo.Mesh(*exactgeo.make_grid(2, 2, 1.0, 1.0))
SOLVER = exactgeo.GeodesicSolver(MESH)
SOLVER.solve(0)
VALUES = np.arange(9.0)

# What each kind of argument is given instead of what it takes; None only where it is not the default.
INTEGER = ["3", 1.5, True, 2**70]
COUNT = [*INTEGER, -1]
REAL = ["1", None, True, 1j, [1.0]]
OPTIONAL_REAL = ["1", True, 1j]
FLAG = ["no", None, 1]
TEXT = [1, None, b"viridis"]
FILE_NAME = [None, 1.5, ["a.ply"]]
INDICES = ["0", 1.5, True, -1, 2**40, [[0]]]
INDEX = [*INDICES[:-1], None, [0]]
ARRAY = ["x", None, [1.0]]
MESH_ARGUMENT = ["mesh", None, (np.zeros((3, 3)), [[0, 1, 2]])]
PROGRESS = ["yes", 1]

# An index out of range is named as the library names it: by the element and its position.
ELEMENT = {"sources": "source vertex", "first": "source vertex", "targets": "target 0: vertex", "from_vertex": "edge (",
           "to_vertex": "edge (", "a": "a 0: vertex", "b": "b 0: vertex"}


def needs(module: str, call: Callable[..., Any]) -> Callable[..., Any]:
    """`call`, skipped where the optional `module` is absent."""

    def checked(**arguments: Any) -> Any:
        pytest.importorskip(module)
        return call(**arguments)

    return checked


# Each entry: a name, the call, valid keyword arguments, and the wrong values to try for each argument.
CALLS: list[tuple[str, Callable[..., Any], dict[str, Any], dict[str, list[Any]]]] = [
    ("make_grid", exactgeo.make_grid, dict(nx=2, ny=2, width=1.0, height=1.0),
     dict(nx=[*INTEGER, None], ny=INTEGER, width=REAL, height=REAL)),
    ("make_icosphere", exactgeo.make_icosphere, dict(subdivisions=0), dict(subdivisions=[*INTEGER, None])),
    ("make_bumpy_torus", exactgeo.make_bumpy_torus, dict(major_segments=3, minor_segments=3),
     dict(major_segments=INTEGER, minor_segments=INTEGER)),
    ("subdivide_midpoint", exactgeo.subdivide_midpoint, dict(vertices=MESH.vertices, faces=MESH.faces),
     dict(vertices=ARRAY, faces=[*INDICES, None])),
    ("Mesh", exactgeo.Mesh, dict(vertices=MESH.vertices, faces=MESH.faces),
     dict(vertices=ARRAY, faces=[*INDICES, None], weld_duplicate_positions=FLAG, threads=[*COUNT, None],
          progress=PROGRESS)),
    ("Mesh.load", exactgeo.Mesh.load, dict(path="missing.obj"),
     dict(path=FILE_NAME, weld_duplicate_positions=FLAG, threads=COUNT, progress=PROGRESS)),
    ("Mesh.from_any", exactgeo.Mesh.from_any, dict(mesh=MESH),
     dict(mesh=["mesh", None], weld_duplicate_positions=FLAG)),
    *[(f"Mesh.{name}", getattr(exactgeo.Mesh, name), {}, dict(mesh=["mesh", None]))
      for name in ("from_trimesh", "from_meshio", "from_pyvista", "from_open3d")],
    ("SurfacePoint", exactgeo.SurfacePoint, dict(face=0), dict(face=INDEX, barycentric=ARRAY)),
    ("SurfacePoints", exactgeo.SurfacePoints, dict(faces=[0], barycentric=[[1.0, 0, 0]]),
     dict(faces=[*INDICES, None], barycentric=ARRAY)),
    ("SurfacePoints.of", exactgeo.SurfacePoints.of, {}, dict(points=["x", None, [0]])),
    ("vertex_point", exactgeo.vertex_point, dict(mesh=MESH, vertex=0), dict(mesh=MESH_ARGUMENT, vertex=INDEX)),
    ("edge_point", exactgeo.edge_point, dict(mesh=MESH, from_vertex=0, to_vertex=1, t=0.5),
     dict(mesh=MESH_ARGUMENT, from_vertex=INDEX, to_vertex=INDEX, t=REAL)),
    ("locate", exactgeo.locate, dict(mesh=MESH, xyz=[0.0, 0.0, 0.0]),
     dict(mesh=MESH_ARGUMENT, xyz=ARRAY, threads=COUNT)),
    ("point_position", exactgeo.point_position, dict(mesh=MESH, points=exactgeo.SurfacePoint(0)),
     dict(mesh=MESH_ARGUMENT, points=["x", None, 0])),
    ("GeodesicSolver", exactgeo.GeodesicSolver, {}, dict(mesh=MESH_ARGUMENT)),
    ("GeodesicSolver.solve", SOLVER.solve, dict(sources=0),
     dict(sources=[*INDICES, None], targets=INDICES, max_distance=OPTIONAL_REAL, targets_beyond=[None, 1, "all"],
          progress=PROGRESS, algorithm=TEXT, rule1=FLAG, rule23=FLAG, collect_timings=FLAG, threads=[*COUNT, None])),
    ("GeodesicSolver.path_to_vertex", SOLVER.path_to_vertex, {}, dict(vertex=INDEX)),
    ("GeodesicSolver.path_to_target", SOLVER.path_to_target, {}, dict(target=[*COUNT, None])),
    ("distance", exactgeo.distance, dict(mesh=MESH, sources=0),
     dict(mesh=MESH_ARGUMENT, sources=INDICES, targets=INDICES, max_distance=OPTIONAL_REAL, targets_beyond=[None, 1],
          return_nearest=FLAG, progress=PROGRESS, threads=COUNT, rule1=FLAG)),
    ("path", exactgeo.path, dict(mesh=MESH, sources=0, target=8),
     dict(mesh=MESH_ARGUMENT, sources=INDICES, target=[*INDICES, None], max_distance=OPTIONAL_REAL, threads=COUNT)),
    ("distance_matrix", exactgeo.distance_matrix, dict(mesh=MESH, sources=[0]),
     dict(mesh=MESH_ARGUMENT, sources=[*INDICES, None], targets=INDICES, max_distance=OPTIONAL_REAL,
          targets_beyond=[None, 1], threads=COUNT, progress=PROGRESS, algorithm=TEXT)),
    ("pair_distances", exactgeo.pair_distances, dict(mesh=MESH, a=[0, 1], b=[8, 4]),
     dict(mesh=MESH_ARGUMENT, a=[*INDICES, None, [0]], b=[*INDICES, None], return_paths=FLAG, threads=COUNT,
          max_distance=OPTIONAL_REAL, algorithm=TEXT, rule1=FLAG)),
    ("farthest_point_sampling", exactgeo.farthest_point_sampling, dict(mesh=MESH, count=2),
     dict(mesh=MESH_ARGUMENT, count=[*COUNT, None], first=[*INDICES, None], max_distance=OPTIONAL_REAL,
          progress=PROGRESS, threads=COUNT)),
    ("isolines", exactgeo.isolines, dict(mesh=MESH, values=VALUES, levels=1.0),
     dict(mesh=MESH_ARGUMENT, values=ARRAY, levels=["x", None, [[1.0]]])),
    ("save_ply", exactgeo.save_ply, dict(path="unwritten.ply", mesh=MESH, values=VALUES),
     dict(path=FILE_NAME, mesh=MESH_ARGUMENT, values=ARRAY, cmap=[1, None, "no such map"], vmin=OPTIONAL_REAL,
          vmax=OPTIONAL_REAL, value_name=TEXT)),
    ("save_vtk", exactgeo.save_vtk, dict(path="unwritten.vtk", mesh=MESH, values=VALUES),
     dict(path=FILE_NAME, mesh=MESH_ARGUMENT, values=ARRAY, value_name=TEXT)),
    ("plot", needs("matplotlib", exactgeo.plot), dict(mesh=MESH, values=VALUES),
     dict(mesh=MESH_ARGUMENT, values=["x", None], path=["x", [1.0]], isolines=["x", -1, [[1.0]]],
          file=[1.5, ["a.png"]], cmap=[1, "no such map"], view=["x", None, (1.0,)], up=[None, ["z"], "w"],
          vmin=OPTIONAL_REAL, vmax=OPTIONAL_REAL, title=[1], figsize=["x", None, (1.0,)], dpi=[*COUNT, None])),
    ("distributed.distance_matrix_to_zarr", needs("zarr", distributed.distance_matrix_to_zarr),
     dict(mesh=MESH, sources=[0], store="unwritten.zarr"),
     dict(mesh=MESH_ARGUMENT, sources=[*INDICES, None], store=FILE_NAME, targets=INDICES, max_distance=OPTIONAL_REAL,
          dtype=[None, 1, "int8"], block_rows=[*COUNT, 0], client=[1, "local"], resume=FLAG, progress=PROGRESS,
          threads=[*COUNT, None], retries=[*COUNT, None], verify=FLAG)),
    ("distributed.store_status", distributed.store_status, dict(store="unwritten.zarr"),
     dict(store=FILE_NAME, verify=FLAG)),
    ("distributed.read_sparse", needs("scipy", distributed.read_sparse), {}, dict(store=FILE_NAME)),
    ("distributed.mesh_hash", distributed.mesh_hash, {}, dict(mesh=MESH_ARGUMENT)),
    ("distributed.local_cluster", needs("distributed", distributed.local_cluster), {}, dict(workers=[*COUNT, 0])),
]


@pytest.mark.parametrize(
    ("call", "valid", "argument", "value"),
    [pytest.param(call, valid, argument, value, id=f"{name}-{argument}={value!r}")
     for name, call, valid, wrong in CALLS for argument, values in wrong.items() for value in values],
)
def test_a_wrong_argument_gets_a_short_error_naming_it(tmp_path, monkeypatch, call, valid, argument, value):
    monkeypatch.chdir(tmp_path)  # the file and store names above point here
    with pytest.raises((TypeError, ValueError)) as raised:
        call(**{**valid, argument: value})
    message = str(raised.value)
    assert len(message) < 300, message
    assert "incompatible function arguments" not in message and "Invoked with" not in message, message
    assert argument in message or ELEMENT.get(argument, argument) in message, message
    assert not list(tmp_path.iterdir()), f"written before the error: {list(tmp_path.iterdir())}"


@pytest.mark.parametrize("result", [exactgeo.GeodesicStats, exactgeo.MeshReport])
def test_the_librarys_reports_take_no_arguments_and_say_so(result):
    assert result() == result()  # every field zero
    wanted = rf"^exactgeo.{result.__name__}\(\) takes no arguments: the library fills it in$"
    with pytest.raises(TypeError, match=wanted):
        result(1)


def test_every_public_callable_is_in_the_table():
    """A function, class or method added to the package joins CALLS, or this fails."""
    built_by_the_library = {"GeodesicPath", "GeodesicResult", "GeodesicStats", "MeshReport", "Sampling", "MatrixRun",
                            "StoreStatus"}
    public = {name for name in exactgeo.__all__ if callable(getattr(exactgeo, name)) and name != "AlgorithmOptions"}
    public |= {f"distributed.{name}" for name in distributed.__all__}
    for cls in (exactgeo.Mesh, exactgeo.GeodesicSolver, exactgeo.SurfacePoints):
        public |= {f"{cls.__name__}.{name}" for name, member in vars(cls).items()
                   if not name.startswith("_") and (inspect.isfunction(member) or isinstance(member, classmethod))}
    public -= built_by_the_library | {f"distributed.{name}" for name in built_by_the_library}
    assert public == {name for name, *_ in CALLS}
