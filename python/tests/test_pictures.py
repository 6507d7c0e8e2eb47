"""exactgeo.save_ply (read back by its header and numpy, and by trimesh and meshio where installed),
exactgeo.save_vtk (by its layout, the command line's .vtk, and pyvista where installed), exactgeo.plot
(headless, framing meshes of any shape), and the docs' pictures script."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import REPOSITORY, run_cli, write_obj

import exactgeo
from exactgeo import _pictures

VIRIDIS_ENDS = ([68, 1, 84], [253, 231, 37])  # viridis at 0 and 1, in matplotlib's table and the built-in ramp
GREY = [128, 128, 128]


def read_ply(path: Path) -> tuple[list[str], np.ndarray, np.ndarray]:
    """The header's lines, the vertex records and the faces of a binary PLY as save_ply lays it out."""
    data = path.read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    vertex_count = int(next(line for line in header if line.startswith("element vertex")).split()[2])
    face_count = int(next(line for line in header if line.startswith("element face")).split()[2])
    name = next(line for line in header if line.startswith("property double")).split()[2]
    vertex_type = np.dtype(
        [("x", "<f4"), ("y", "<f4"), ("z", "<f4"), (name, "<f8"), ("red", "u1"), ("green", "u1"), ("blue", "u1")]
    )
    vertices = np.frombuffer(data, vertex_type, vertex_count, end)
    face_type = np.dtype([("count", "u1"), ("indices", "<i4", (3,))])
    faces = np.frombuffer(data, face_type, face_count, end + vertex_count * vertex_type.itemsize)
    assert end + vertex_count * vertex_type.itemsize + face_count * face_type.itemsize == len(data)
    return header, vertices, faces


@pytest.fixture
def grid_with_inf():
    vertices, faces = exactgeo.make_grid(4, 4, 1.0, 1.0)
    mesh = exactgeo.Mesh(vertices, faces)
    d = exactgeo.distance(mesh, 0)
    d[-1] = np.inf
    d[-2] = np.nan
    return mesh, d


def test_save_ply_layout_values_and_colours(tmp_path, grid_with_inf):
    mesh, d = grid_with_inf
    exactgeo.save_ply(tmp_path / "d.ply", mesh, d)
    header, vertices, faces = read_ply(tmp_path / "d.ply")
    assert header == [
        "ply",
        "format binary_little_endian 1.0",
        "comment written by exactgeo",
        f"element vertex {mesh.vertex_count}",
        "property float x",
        "property float y",
        "property float z",
        "property double distance",
        "property uchar red",
        "property uchar green",
        "property uchar blue",
        f"element face {mesh.face_count}",
        "property list uchar int vertex_indices",
        "end_header",
    ]
    np.testing.assert_array_equal(np.column_stack([vertices["x"], vertices["y"], vertices["z"]]), mesh.vertices)
    np.testing.assert_array_equal(vertices["distance"], d)  # the raw values, inf and NaN included
    assert (faces["count"] == 3).all()
    np.testing.assert_array_equal(faces["indices"], mesh.faces)
    rgb = np.column_stack([vertices["red"], vertices["green"], vertices["blue"]])
    finite = np.isfinite(d)
    assert rgb[np.argmin(np.where(finite, d, np.inf))].tolist() == VIRIDIS_ENDS[0]
    assert rgb[np.argmax(np.where(finite, d, -np.inf))].tolist() == VIRIDIS_ENDS[1]
    assert rgb[-1].tolist() == GREY and rgb[-2].tolist() == GREY


def test_save_ply_range_name_and_colour_map(tmp_path, grid_with_inf):
    mesh, d = grid_with_inf
    grey_ramp = lambda t: np.column_stack([t, t, t])  # noqa: E731
    exactgeo.save_ply(tmp_path / "v.ply", mesh, d, vmin=0.5, vmax=1.0, value_name="value", cmap=grey_ramp)
    header, vertices, _ = read_ply(tmp_path / "v.ply")
    assert "property double value" in header
    grey = vertices["red"]
    below, above = d < 0.5, d > 1.0
    assert (grey[below] == 0).all() and (grey[above & np.isfinite(d)] == 255).all()  # clamped beyond the range
    middle = (d >= 0.5) & (d <= 1.0)
    np.testing.assert_allclose(grey[middle], np.round((d[middle] - 0.5) / 0.5 * 255), atol=0)


def test_the_built_in_ramp_without_matplotlib(tmp_path, grid_with_inf, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    mesh, d = grid_with_inf
    exactgeo.save_ply(tmp_path / "d.ply", mesh, d)
    _, vertices, _ = read_ply(tmp_path / "d.ply")
    assert [vertices[0][k] for k in ("red", "green", "blue")] == VIRIDIS_ENDS[0]
    # Linear between its stops: halfway between the first two.
    np.testing.assert_allclose(_pictures.ramp_rgb(np.array([0.125]))[0] * 255, [63.5, 41.5, 111.5])
    with pytest.raises(ValueError, match="cmap 'magma' needs matplotlib"):
        exactgeo.save_ply(tmp_path / "m.ply", mesh, d, cmap="magma")



def test_plot_without_matplotlib_names_the_extra():
    # In a fresh interpreter: once other tests have imported matplotlib, blocking it here would not be enough.
    script = (
        "import sys; sys.modules['matplotlib'] = None\n"
        "import exactgeo\n"
        "mesh = exactgeo.Mesh(*exactgeo.make_grid(2, 2, 1.0, 1.0))\n"
        "try:\n"
        "    exactgeo.plot(mesh, exactgeo.distance(mesh, 0))\n"
        "except ImportError as e:\n"
        "    print(e)\n"
    )
    output = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout
    assert "pip install matplotlib" in output


def test_matplotlib_and_the_built_in_ramp_agree_closely():
    matplotlib = pytest.importorskip("matplotlib")
    t = np.linspace(0, 1, 101)
    difference = np.abs(matplotlib.colormaps["viridis"](t)[:, :3] - _pictures.ramp_rgb(t)).max()
    # Five stops, linear in between: at most 27/255 off matplotlib's 256-colour table (in green, near 3/8).
    assert difference < 0.11


def test_save_ply_reads_back_in_trimesh_and_meshio(tmp_path, grid_with_inf):
    mesh, d = grid_with_inf
    exactgeo.save_ply(tmp_path / "d.ply", mesh, d)
    trimesh = pytest.importorskip("trimesh")
    loaded = trimesh.load(tmp_path / "d.ply", process=False)
    np.testing.assert_allclose(loaded.vertices, mesh.vertices)
    np.testing.assert_array_equal(loaded.faces, mesh.faces)
    assert loaded.visual.vertex_colors[0, :3].tolist() == VIRIDIS_ENDS[0]
    meshio = pytest.importorskip("meshio")
    read = meshio.read(tmp_path / "d.ply")
    np.testing.assert_array_equal(read.point_data["distance"], d)
    np.testing.assert_array_equal(read.cells_dict["triangle"], mesh.faces)


def read_vtk(path: Path) -> tuple[list[bytes], np.ndarray, np.ndarray, np.ndarray]:
    """The text lines, the points, the polygons and the values of a legacy binary VTK file as save_vtk lays it
    out, each block of big-endian numbers checked to be followed by a newline and nothing left over."""
    data = path.read_bytes()
    lines, at = [], 0

    def line() -> bytes:
        nonlocal at
        end = data.index(b"\n", at)
        lines.append(data[at:end])
        at = end + 1
        return lines[-1]

    def block(dtype: str, count: int) -> np.ndarray:
        nonlocal at
        values = np.frombuffer(data, dtype, count, at)
        at += values.nbytes
        assert data[at : at + 1] == b"\n"
        at += 1
        return values

    for _ in range(5):
        line()
    points = block(">f8", 3 * int(lines[4].split()[1])).reshape(-1, 3)
    polygons = block(">i4", int(line().split()[2])).reshape(-1, 4)
    for _ in range(3):
        line()
    values = block(">f8", int(lines[6].split()[1]))
    assert at == len(data)
    return lines, points, polygons, values


def test_save_vtk_layout_holds_the_exact_values(tmp_path, grid_with_inf):
    mesh, d = grid_with_inf
    exactgeo.save_vtk(tmp_path / "d.vtk", mesh, d)
    lines, points, polygons, values = read_vtk(tmp_path / "d.vtk")
    assert lines == [
        b"# vtk DataFile Version 3.0",
        b"written by exactgeo",
        b"BINARY",
        b"DATASET POLYDATA",
        f"POINTS {mesh.vertex_count} double".encode(),
        f"POLYGONS {mesh.face_count} {4 * mesh.face_count}".encode(),
        f"POINT_DATA {mesh.vertex_count}".encode(),
        b"SCALARS distance double 1",
        b"LOOKUP_TABLE default",
    ]
    np.testing.assert_array_equal(points, mesh.vertices)
    np.testing.assert_array_equal(polygons[:, 0], 3)
    np.testing.assert_array_equal(polygons[:, 1:], mesh.faces)
    np.testing.assert_array_equal(values, d)  # inf and NaN as they are
    exactgeo.save_vtk(tmp_path / "v.vtk", mesh, d, value_name="value")
    assert read_vtk(tmp_path / "v.vtk")[0][7] == b"SCALARS value double 1"
    with pytest.raises(ValueError, match="plain name"):
        exactgeo.save_vtk(tmp_path / "x.vtk", mesh, d, value_name="geodesic distance")
    with pytest.raises(ValueError, match="got 24 values, but the mesh has 25 vertices"):
        exactgeo.save_vtk(tmp_path / "x.vtk", mesh, d[:-1])
    assert not (tmp_path / "x.vtk").exists()


def test_save_vtk_is_the_command_lines_vtk(cli, tmp_path):
    vertices, faces = exactgeo.make_grid(5, 3, 2.0, 1.0)
    vertices[:, 2] = np.sin(vertices[:, 0]) / 3  # coordinates that need all 17 digits
    path = write_obj(tmp_path / "m.obj", vertices, faces)
    run_cli("distance", path, "--source", "4", "--out", tmp_path / "cli.vtk")
    mesh = exactgeo.Mesh(vertices, faces)
    exactgeo.save_vtk(tmp_path / "python.vtk", mesh, exactgeo.distance(mesh, 4))
    assert (tmp_path / "python.vtk").read_bytes() == (tmp_path / "cli.vtk").read_bytes()


def test_the_built_in_ramp_colours_as_the_command_lines_ply(cli, tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    vertices, faces = exactgeo.make_grid(9, 7, 2.0, 1.0)
    vertices[:, 2] = np.sin(3 * vertices[:, 0]) * np.cos(2 * vertices[:, 1]) / 3
    # A triangle apart from the grid: its vertices are unreachable, grey in both.
    vertices = np.vstack([vertices, [[5.0, 5.0, 0.0], [6.0, 5.0, 0.0], [5.0, 6.0, 0.0]]])
    faces = np.vstack([faces, [[len(vertices) - 3, len(vertices) - 2, len(vertices) - 1]]])
    path = write_obj(tmp_path / "m.obj", vertices, faces)
    run_cli("distance", path, "--source", "4", "--out", tmp_path / "cli.ply")
    mesh = exactgeo.Mesh(vertices, faces)
    exactgeo.save_ply(tmp_path / "python.ply", mesh, exactgeo.distance(mesh, 4))
    rgb = [np.column_stack([v["red"], v["green"], v["blue"]]) for v in
           (read_ply(tmp_path / name)[1] for name in ("cli.ply", "python.ply"))]
    assert len(np.unique(rgb[0], axis=0)) > 20  # many colours of the ramp, not only its ends
    assert rgb[0][-3:].tolist() == [GREY] * 3
    np.testing.assert_array_equal(rgb[1], rgb[0])


def test_vtk_tools_read_the_values_from_the_vtk_file(tmp_path, grid_with_inf):
    pyvista = pytest.importorskip("pyvista")
    mesh, d = grid_with_inf
    exactgeo.save_vtk(tmp_path / "d.vtk", mesh, d)
    read = pyvista.read(tmp_path / "d.vtk")
    assert read.point_data["distance"].dtype == np.float64
    np.testing.assert_array_equal(read.point_data["distance"], d)
    np.testing.assert_array_equal(read.points, mesh.vertices)
    np.testing.assert_array_equal(read.faces.reshape(-1, 4)[:, 1:], mesh.faces)


def test_wrong_lengths_are_named(tmp_path, grid_with_inf):
    mesh, d = grid_with_inf
    with pytest.raises(ValueError, match="got 24 values, but the mesh has 25 vertices"):
        exactgeo.save_ply(tmp_path / "d.ply", mesh, d[:-1])
    if importlib.util.find_spec("matplotlib"):  # plot checks its values once it has matplotlib
        with pytest.raises(ValueError, match="got 24 values, but the mesh has 25 vertices"):
            exactgeo.plot(mesh, d[:-1])
    with pytest.raises(ValueError, match="plain name"):
        exactgeo.save_ply(tmp_path / "d.ply", mesh, d, value_name="geodesic distance")
    assert not (tmp_path / "d.ply").exists()


def test_plot_returns_a_figure_and_saves_it_headless(tmp_path):
    pytest.importorskip("matplotlib")
    code = (
        "import sys, exactgeo\n"
        "mesh = exactgeo.Mesh(*exactgeo.make_bumpy_torus(16, 8))\n"
        "d = exactgeo.distance(mesh, 0)\n"
        "figure = exactgeo.plot(mesh, d, exactgeo.path(mesh, 0, 60), isolines=5, file=sys.argv[1])\n"
        "assert type(figure).__name__ == 'Figure'\n"
        "assert 'matplotlib.pyplot' not in sys.modules\n"
    )
    # No display and no backend chosen: it must still work (and never needs pyplot).
    env = {"PATH": "/usr/bin:/bin", "MPLBACKEND": "", "HOME": str(tmp_path)}
    subprocess.run([sys.executable, "-c", code, str(tmp_path / "t.png")], check=True, env=env)
    assert (tmp_path / "t.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_plot_isolines_path_and_options():
    pytest.importorskip("matplotlib")
    vertices, faces = exactgeo.make_grid(6, 6, 1.0, 1.0)
    mesh = exactgeo.Mesh(vertices, faces)
    d = exactgeo.distance(mesh, 0)
    items = lambda figure: len(figure.axes[0].collections[0].get_facecolors())  # noqa: E731
    plain = exactgeo.plot(mesh, d)
    assert items(plain) == mesh.face_count and len(plain.axes) == 2  # the surface, and the colour bar
    lines = sum(len(c) - 1 for curves in exactgeo.isolines(mesh, d, [0.3, 0.6]) for c in curves)
    assert items(exactgeo.plot(mesh, d, isolines=[0.3, 0.6])) == mesh.face_count + lines
    points = exactgeo.path(mesh, 0, 48).points
    assert items(exactgeo.plot(mesh, d, points, up="y", view=(10, 20))) == mesh.face_count + len(points) - 1
    assert items(exactgeo.plot(mesh, d, exactgeo.path(mesh, 0, 48), isolines=3, cmap="magma")) > mesh.face_count
    with pytest.raises(ValueError, match="up must be"):
        exactgeo.plot(mesh, d, up="w")


@pytest.mark.parametrize("up", ["x", "y", "z"])
def test_plot_frames_a_long_thin_mesh_whole_in_every_view(up):
    pytest.importorskip("matplotlib")
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from mpl_toolkits.mplot3d import proj3d

    vertices, faces = exactgeo.make_grid(40, 2, 20.0, 1.0)  # 20 by 1
    vertices[:, 2] = 0.2 * np.sin(vertices[:, 0])
    mesh = exactgeo.Mesh(vertices, faces)
    d = exactgeo.distance(mesh, 0)
    for view in [(30, -60), (50, -70), (0, 0), (0, 90), (90, 0), (-20, 135)]:
        figure = exactgeo.plot(mesh, d, view=view, up=up)
        FigureCanvasAgg(figure).draw()  # the layout as drawn: the axes made square, the colour bar beside
        axes = figure.axes[0]
        x, y, _ = proj3d.proj_transform(*mesh.vertices[:, _pictures._UP[up]].T, axes.get_proj())
        picture = axes.transData.transform(np.column_stack([x, y]))
        area = axes.bbox
        inside = (picture[:, 0] >= area.x0) & (picture[:, 0] <= area.x1)
        inside &= (picture[:, 1] >= area.y0) & (picture[:, 1] <= area.y1)
        assert inside.all(), f"view {view}: vertices {np.flatnonzero(~inside)[:5]} drawn outside the axes"
        # Framed, not lost in the middle: the picture spans most of the axes across or up.
        span = max(np.ptp(picture[:, 0]) / area.width, np.ptp(picture[:, 1]) / area.height)
        assert span > 0.8, f"view {view}: the mesh spans {span:.2f} of the axes"


def test_the_docs_pictures_script_runs(tmp_path):
    pytest.importorskip("matplotlib")
    script = REPOSITORY / "docs" / "images" / "make_images.py"
    subprocess.run([sys.executable, str(script), str(tmp_path)], check=True)
    made = sorted(path.name for path in tmp_path.glob("*.png"))
    assert made == sorted(path.name for path in script.parent.glob("*.png"))
    assert all(path.stat().st_size < 200_000 for path in tmp_path.glob("*.png"))
