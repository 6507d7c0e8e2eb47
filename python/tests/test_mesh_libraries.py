"""Meshes of trimesh, meshio, pyvista and open3d. trimesh and meshio are real (requirements-test.txt);
pyvista (vtk is a 140 MB wheel) and open3d are not installed here, so their meshes are stand-ins with the
same attributes: pyvista's packed faces array and extract_surface(), open3d's vertices and triangles."""

from __future__ import annotations

import subprocess
import sys
import warnings
from types import SimpleNamespace

import numpy as np
import pytest
from conftest import shared_mesh

import exactgeo

# A unit square as a quad and a triangle beside it: polygons of two sizes.
SQUARE = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0]], dtype=np.float64)
TRIANGLES = np.array([[0, 1, 2], [0, 2, 3], [1, 4, 2]], dtype=np.uint32)  # the quad fanned, then the triangle


def assert_same_mesh(mesh: exactgeo.Mesh, vertices: np.ndarray, faces: np.ndarray) -> None:
    np.testing.assert_array_equal(mesh.vertices, vertices)
    np.testing.assert_array_equal(mesh.faces, faces)


def test_importing_exactgeo_imports_none_of_the_mesh_libraries():
    libraries = "('trimesh', 'meshio', 'pyvista', 'open3d', 'matplotlib')"
    code = f"import sys, exactgeo; print([m for m in {libraries} if m in sys.modules])"
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert run.stdout.strip() == "[]"


def test_trimesh():
    trimesh = pytest.importorskip("trimesh")
    vertices, faces = exactgeo.make_icosphere(2)
    mesh = exactgeo.Mesh.from_trimesh(trimesh.Trimesh(vertices, faces, process=False))
    assert_same_mesh(mesh, vertices, faces)
    assert exactgeo.Mesh.from_any(trimesh.Trimesh(vertices, faces, process=False)).face_count == len(faces)
    with pytest.raises(TypeError, match=r"scene .* force='mesh'"):
        exactgeo.Mesh.from_trimesh(trimesh.Scene([trimesh.Trimesh(vertices, faces)]))
    with pytest.raises(TypeError, match=r"scene .* force=.mesh."):
        exactgeo.Mesh.from_any(trimesh.Scene([trimesh.Trimesh(vertices, faces)]))


def test_trimesh_seams_are_pointed_out_and_welded():
    trimesh = pytest.importorskip("trimesh")
    loaded = trimesh.load(shared_mesh("spot"))  # split at its texture seams, as trimesh loads textured OBJs
    with pytest.warns(UserWarning, match=r"vertices are unreachable.*weld_duplicate_positions=True"):
        assert np.isinf(exactgeo.distance(exactgeo.Mesh.from_trimesh(loaded), 0)).any()
    welded = exactgeo.Mesh.from_trimesh(loaded, weld_duplicate_positions=True)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert np.isfinite(exactgeo.distance(welded, 0)).all()
    assert welded.report.welded_vertices > 0


def test_meshio_cell_blocks():
    meshio = pytest.importorskip("meshio")
    cells = [("line", np.array([[0, 1]])), ("quad", np.array([[0, 1, 2, 3]])), ("vertex", np.array([[4]])),
             ("triangle", np.array([[1, 4, 2]]))]
    mesh = exactgeo.Mesh.from_meshio(meshio.Mesh(SQUARE, cells))
    assert_same_mesh(mesh, SQUARE, TRIANGLES)
    assert exactgeo.Mesh.from_any(meshio.Mesh(SQUARE, cells)).face_count == 3
    # 2-D points lie in z = 0.
    flat = exactgeo.Mesh.from_meshio(meshio.Mesh(SQUARE[:, :2], cells))
    assert_same_mesh(flat, SQUARE, TRIANGLES)
    with pytest.raises(ValueError, match=r"no triangle, quad or polygon cells .*\(it has 1 line, 1 vertex\)"):
        exactgeo.Mesh.from_meshio(meshio.Mesh(SQUARE, [("line", np.array([[0, 1]])), ("vertex", np.array([[4]]))]))
    with pytest.raises(ValueError, match=r"^face 2 names vertex 9, but the mesh has 5"):
        cells = [("quad", np.array([[0, 1, 2, 3]])), ("triangle", np.array([[1, 9, 2]]))]
        exactgeo.Mesh.from_meshio(meshio.Mesh(SQUARE, cells))
    with pytest.raises(ValueError, match=r"meshio cell block 1 \(quad\): face 0 names vertex 7, but the mesh has 5"):
        cells = [("triangle", np.array([[1, 4, 2]])), ("quad", np.array([[0, 1, 7, 3]]))]
        exactgeo.Mesh.from_meshio(meshio.Mesh(SQUARE, cells))


def test_meshio_reads_a_file_and_welds(tmp_path):
    meshio = pytest.importorskip("meshio")
    # Two triangles that share an edge by position only.
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]])
    meshio.write(tmp_path / "seam.obj", meshio.Mesh(vertices, [("triangle", np.array([[0, 1, 2], [3, 4, 5]]))]))
    read = meshio.read(tmp_path / "seam.obj")
    welded = exactgeo.Mesh.from_meshio(read, weld_duplicate_positions=True)
    assert welded.report.welded_vertices == 2
    assert exactgeo.distance(welded, 0)[4] == pytest.approx(np.sqrt(2))


class PolyData:
    """pyvista.PolyData's attributes: points and VTK's packed faces (n, i0, ..., n, ...)."""

    def __init__(self, points: np.ndarray, faces: np.ndarray) -> None:
        self.points, self.faces = points.astype(np.float32), np.asarray(faces, dtype=np.int64)

    def extract_surface(self) -> PolyData:
        return self


class UnstructuredGrid:
    """pyvista.UnstructuredGrid's attributes: points, cells, celltypes and extract_surface(), no faces."""

    def __init__(self, surface: PolyData) -> None:
        self.points, self.cells, self.celltypes = surface.points, np.array([4, 0, 1, 2, 3]), np.array([10])
        self._surface = surface

    def extract_surface(self) -> PolyData:
        return self._surface


def test_pyvista_stand_ins():
    mixed = PolyData(SQUARE, [4, 0, 1, 2, 3, 3, 1, 4, 2])
    assert_same_mesh(exactgeo.Mesh.from_pyvista(mixed), SQUARE, TRIANGLES)
    vertices, faces = exactgeo.make_icosphere(1)
    packed = np.column_stack([np.full(len(faces), 3), faces]).reshape(-1)
    assert_same_mesh(exactgeo.Mesh.from_pyvista(PolyData(vertices, packed)), vertices.astype(np.float32), faces)
    grid = UnstructuredGrid(mixed)
    assert_same_mesh(exactgeo.Mesh.from_pyvista(grid), SQUARE, TRIANGLES)
    assert exactgeo.Mesh.from_any(grid).face_count == 3  # meshio also has points and cells: told apart
    with pytest.raises(ValueError, match="no polygons .*triangulate"):
        exactgeo.Mesh.from_pyvista(PolyData(SQUARE, []))
    with pytest.raises(ValueError, match="cut short: face 1 claims 3 vertices"):
        exactgeo.Mesh.from_pyvista(PolyData(SQUARE, [4, 0, 1, 2, 3, 3, 1, 4]))


def test_open3d_stand_in_and_weld():
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]])
    triangle_mesh = SimpleNamespace(vertices=vertices, triangles=np.array([[0, 1, 2], [3, 4, 5]], dtype=np.int32))
    assert exactgeo.Mesh.from_open3d(triangle_mesh).vertex_count == 6
    welded = exactgeo.Mesh.from_any(triangle_mesh, weld_duplicate_positions=True)
    assert welded.report.welded_vertices == 2


def test_from_any_takes_pairs_and_meshes_and_names_what_it_got():
    vertices, faces = exactgeo.make_grid(2, 2, 1.0, 1.0)
    mesh = exactgeo.Mesh.from_any((vertices, faces))
    assert exactgeo.Mesh.from_any(mesh) is mesh
    assert exactgeo.Mesh.from_any(mesh, weld_duplicate_positions=True)._weld
    with pytest.raises(TypeError, match=r"mesh must be a trimesh.Trimesh, a meshio.Mesh, .* pair, not dict"):
        exactgeo.Mesh.from_any({"vertices": vertices})
    with pytest.raises(TypeError, match=r"mesh must be .*pyvista.* not numpy.ndarray"):
        exactgeo.Mesh.from_any(vertices)
    with pytest.raises(TypeError, match=r"mesh must be a trimesh.Trimesh .*not numpy.ndarray .*'faces'"):
        exactgeo.Mesh.from_trimesh(vertices)
    with pytest.raises(TypeError, match=r"mesh must be an open3d.geometry.TriangleMesh"):
        exactgeo.Mesh.from_open3d(SimpleNamespace(vertices=vertices))
