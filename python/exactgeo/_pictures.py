"""Pictures of a per-vertex field without plotting code: a coloured binary PLY for any mesh viewer
(save_ply), the values themselves for VTK-based tools (save_vtk), and a shaded matplotlib figure with a
colour bar, isolines and a path (plot)."""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any, Callable, Union

import numpy as np

from . import _core, _inputs
from ._isolines import _per_vertex, isolines as _isolines
from ._mesh import Mesh, checked_mesh

Colormap = Union[str, Callable[[np.ndarray], np.ndarray]]

# Inf and NaN, as in the command line's .ply (exactgeo::kNoValueColour).
GREY = np.array(_core.no_value_colour, dtype=np.uint8)


def ramp_rgb(t: np.ndarray) -> np.ndarray:
    """The built-in ramp when matplotlib is absent, the command line's (exactgeo::ramp_colour): five colours of
    viridis at 0, 1/4, 1/2, 3/4 and 1, interpolated linearly in RGB in between. At t in [0, 1] (clamped), as (n, 3)
    floats in [0, 1]."""
    rgb: np.ndarray = _core.ramp_colour(np.ascontiguousarray(t, dtype=np.float64)) / 255.0
    return rgb


def colormap(cmap: Colormap) -> Callable[[np.ndarray], np.ndarray]:
    """A function from t in [0, 1] to (n, 3) RGB floats: matplotlib's colormap of that name if matplotlib
    is installed, else the built-in ramp for "viridis"; a callable (a matplotlib Colormap) as it is."""
    if callable(cmap):
        return lambda t: np.asarray(cmap(t), dtype=np.float64)[:, :3]
    _inputs.text(cmap, "cmap")
    try:
        import matplotlib
    except ImportError:
        if cmap == "viridis":
            return ramp_rgb
        raise ValueError(
            f"cmap {cmap!r} needs matplotlib (pip install matplotlib); without it only 'viridis' (a built-in "
            "ramp) is available"
        ) from None
    if cmap not in matplotlib.colormaps:
        raise ValueError(f"cmap {cmap!r} is not a matplotlib colormap (matplotlib.colormaps lists them)")
    table = matplotlib.colormaps[cmap]
    return lambda t: np.asarray(table(np.clip(t, 0.0, 1.0)), dtype=np.float64)[:, :3]


def _limits(values: np.ndarray, vmin: float | None, vmax: float | None) -> tuple[float, float]:
    """The colour range: the smallest and largest finite values unless given."""
    finite = values[np.isfinite(values)]
    low = float(finite.min()) if vmin is None and finite.size else float(vmin or 0.0)
    high = float(finite.max()) if vmax is None and finite.size else float(vmax if vmax is not None else 1.0)
    return low, high


def vertex_colours(values: np.ndarray, cmap: Colormap, vmin: float | None, vmax: float | None) -> np.ndarray:
    """(n, 3) uint8: `cmap` from vmin to vmax (clamped beyond), grey for inf and NaN."""
    low, high = _limits(values, vmin, vmax)
    finite = np.isfinite(values)
    colours = np.empty((len(values), 3), dtype=np.uint8)
    colours[~finite] = GREY
    t = (values[finite] - low) / (high - low) if high > low else np.zeros(int(finite.sum()))
    colours[finite] = np.clip(np.round(colormap(cmap)(t) * 255), 0, 255).astype(np.uint8)
    return colours


def save_ply(
    path: str | os.PathLike[str],
    mesh: Mesh,
    values: Any,
    cmap: Colormap = "viridis",
    vmin: float | None = None,
    vmax: float | None = None,
    value_name: str = "distance",
) -> None:
    """Writes `mesh` as a binary little-endian PLY with a colour per vertex from `values` (one per vertex,
    e.g. exactgeo.distance's result), for MeshLab, Blender, ParaView or any viewer.

    Colours: `cmap` (a matplotlib colormap name or Colormap if matplotlib is installed; without it, "viridis"
    is a built-in ramp: five colours of viridis interpolated linearly, the command line's) from `vmin`
    (default: the smallest finite value) to `vmax` (default: the largest), clamped beyond; inf and NaN
    vertices are grey (128, 128, 128). The value itself is kept as a double property named `value_name`.

    The layout: element vertex with float x, y, z, double `value_name`, uchar red, green, blue; element face
    with list uchar int vertex_indices (the mesh's triangles). Raises ValueError if `values` does not have
    one number per vertex, naming both lengths.
    """
    file_name = _inputs.path(path)
    surface = checked_mesh(mesh)
    field = _per_vertex(values, surface)
    name = _inputs.text(value_name, "value_name")
    colours = vertex_colours(field, cmap, _inputs.optional_real(vmin, "vmin"), _inputs.optional_real(vmax, "vmax"))
    data = _core.ply_file_bytes(surface._core, field, name, np.ascontiguousarray(colours))  # the command's writer
    with open(file_name, "wb") as file:
        file.write(data)


def save_vtk(
    path: str | os.PathLike[str], mesh: Mesh, values: Any, value_name: str = "distance"
) -> None:
    """Writes `mesh` as a legacy VTK file (binary), with `values` (one per vertex) as point data named
    `value_name`, for ParaView, VisIt, pyvista and meshio: VTK's PLY reader keeps only a PLY's colours, not a
    value property, so save_ply's values never reach those tools.

    The layout, the command line's `distance --out d.vtk` byte for byte: "# vtk DataFile Version 3.0",
    "written by exactgeo", BINARY, DATASET POLYDATA; POINTS n double (the mesh's vertices exactly); POLYGONS m
    4m (3 and the corners of each triangle, int32); POINT_DATA n with SCALARS `value_name` double 1 and
    LOOKUP_TABLE default (the values exactly, inf and NaN included). Numbers are big-endian, as the format
    has them; a newline follows each block of them. Raises ValueError if `values` does not have one number per
    vertex, naming both lengths.
    """
    file_name = _inputs.path(path)
    surface = checked_mesh(mesh)
    field = _per_vertex(values, surface)
    data = _core.vtk_file_bytes(surface._core, field, _inputs.text(value_name, "value_name"))  # the command's writer
    with open(file_name, "wb") as file:
        file.write(data)


def plot(
    mesh: Mesh,
    values: Any,
    path: Any = None,
    *,
    isolines: int | Sequence[float] | None = None,
    file: str | os.PathLike[str] | None = None,
    cmap: Colormap = "viridis",
    view: tuple[float, float] = (30.0, -60.0),
    up: str = "z",
    vmin: float | None = None,
    vmax: float | None = None,
    title: str | None = None,
    figsize: tuple[float, float] = (6.0, 5.0),
    dpi: int = 100,
) -> Any:
    """A shaded picture of `values` (one per vertex) on `mesh`, with a colour bar; returns the
    matplotlib Figure, saved to `file` too if given (the format from its extension).

    Each face is coloured by the mean of its three values (grey if one is inf or NaN), darkened by Lambert
    shading for a light near the camera. `isolines`: a number n of evenly spaced levels strictly between the
    colour range's ends, or the levels themselves (exactgeo.isolines draws them, in black). `path`: a
    GeodesicPath (its .points) or a (k, 3) array, drawn in red. `view` is (elevation, azimuth) in degrees, about
    the axis `up` ("x", "y" or "z"; many OBJ files, the Stanford bunny among them, have "y" up).
    Isolines and the path are sorted with the faces by depth, so the surface hides what lies behind it, up
    to the painter's ordering of matplotlib's 3-D axes.

    Works without a display: it uses matplotlib.figure.Figure and the Agg canvas, never pyplot. Raises
    ImportError naming `pip install matplotlib` without it.
    """
    try:
        from matplotlib.cm import ScalarMappable
        from matplotlib.colors import Normalize
        from matplotlib.figure import Figure
        from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    except ImportError:
        raise ImportError("exactgeo.plot needs matplotlib (its plot extra): pip install matplotlib") from None
    surface = checked_mesh(mesh)
    field = _per_vertex(values, surface)
    low, high = _limits(field, _inputs.optional_real(vmin, "vmin"), _inputs.optional_real(vmax, "vmax"))
    if _inputs.text(up, "up") not in _UP:
        raise ValueError(f"up must be 'x', 'y' or 'z', not {up!r}")
    elevation_degrees, azimuth_degrees = _inputs.reals(view, "view", size=2)
    size_inches = tuple(_inputs.reals(figsize, "figsize", size=2))
    dots = _inputs.count(dpi, "dpi", minimum=1)
    if title is not None:
        _inputs.text(title, "title")
    if file is not None and not hasattr(file, "write"):  # a file object, or a name
        file = os.fsdecode(_inputs.path(file, "file"))
    path_points = None if path is None else _inputs.real_array(getattr(path, "points", path), "path", columns=3)
    axes_order = _UP[up]
    positions, faces = surface.vertices[:, axes_order], surface.faces.astype(np.int64)
    triangles = positions[faces]  # (m, 3, 3)

    elevation, azimuth = np.radians(elevation_degrees), np.radians(azimuth_degrees)
    eye = np.array([np.cos(elevation) * np.cos(azimuth), np.cos(elevation) * np.sin(azimuth), np.sin(elevation)])
    light = eye + np.array([-np.sin(azimuth), np.cos(azimuth), 0.0]) * -0.4 + np.array([0, 0, 0.5])
    light /= np.linalg.norm(light)
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    lengths = np.linalg.norm(normals, axis=1)
    normals /= np.where(lengths > 0, lengths, 1.0)[:, None]
    shade = 0.35 + 0.65 * np.abs(normals @ light)

    face_values = field[faces].mean(axis=1)
    finite = np.isfinite(face_values)
    rgb = np.full((len(faces), 3), 0.5)
    if finite.any():
        t = (face_values[finite] - low) / (high - low) if high > low else np.zeros(int(finite.sum()))
        rgb[finite] = colormap(cmap)(t)
    rgba = np.column_stack([rgb * shade[:, None], np.ones(len(faces))])

    # Lines are thin triangles (p, q, q) in the faces' collection, so matplotlib sorts them by depth with
    # the faces; moved towards the camera by an edge length, they come after the face they lie on.
    edge = float(np.median(np.linalg.norm(triangles[:, 1] - triangles[:, 0], axis=1))) if len(faces) else 0.0
    pieces, colours = [triangles], [rgba]
    levels = _levels(isolines, low, high)
    for curves in _isolines(surface, field, levels) if len(levels) else []:
        for line in curves:
            pieces.append(_as_thin_triangles(line[:, axes_order] + edge * eye))
            colours.append(np.tile([0.0, 0.0, 0.0, 1.0], (len(line) - 1, 1)))
    if path_points is not None and len(path_points) >= 2:
        pieces.append(_as_thin_triangles(path_points[:, axes_order] + edge * eye))
        colours.append(np.tile([0.85, 0.1, 0.1, 1.0], (len(path_points) - 1, 1)))
    items, item_colours = np.concatenate(pieces), np.concatenate(colours)
    edge_colours = item_colours.copy()

    figure = Figure(figsize=size_inches, dpi=dots)
    # Orthographic, as the shading above assumes: one viewing direction for every face.
    axes = figure.add_subplot(projection="3d", proj_type="ortho")
    collection = Poly3DCollection(items, facecolors=item_colours, edgecolors=edge_colours, linewidths=0.7)
    axes.add_collection3d(collection)
    # Equal scales on the three axes, the box fitted to the mesh (at least 1/50 of its size in each).
    lower, upper = positions.min(axis=0), positions.max(axis=0)
    size = np.maximum(upper - lower, (upper - lower).max() / 50 or 1.0)
    middle = (lower + upper) / 2
    axes.set_xlim(middle[0] - size[0] / 2, middle[0] + size[0] / 2)
    axes.set_ylim(middle[1] - size[1] / 2, middle[1] + size[1] / 2)
    axes.set_zlim(middle[2] - size[2] / 2, middle[2] + size[2] / 2)
    axes.view_init(elev=elevation_degrees, azim=azimuth_degrees)
    axes.set_axis_off()
    mappable = ScalarMappable(norm=Normalize(low, high), cmap=_mpl_cmap(cmap))
    figure.colorbar(mappable, ax=axes, shrink=0.7, pad=0.02)
    axes.set_box_aspect(tuple(size), zoom=_zoom_to_fit(axes, positions, middle, size))
    if title:
        axes.set_title(title)
    if file is not None:
        figure.savefig(file, dpi=dots, bbox_inches="tight")
    return figure


# How much of the axes' area, across and up, the mesh's picture may fill at most.
_FILL = 0.95


def _zoom_to_fit(axes: Any, points: np.ndarray, middle: np.ndarray, size: np.ndarray) -> float:
    """The zoom at which the projection of every point lies inside the axes, _FILL of the way to its edges.

    matplotlib scales the 3-D box to a fixed diagonal whatever its shape, so one zoom for every mesh would
    either crop an elongated mesh (a beetle, a bone) or leave a round one small. Under the orthographic
    projection the picture scales linearly with the zoom about the projection of the box's middle: the
    points projected once at zoom 1 give the zoom that fits.
    """
    from mpl_toolkits.mplot3d import proj3d

    axes.set_box_aspect(tuple(size), zoom=1.0)
    axes.apply_aspect()  # the square area the axes draw in, as at drawing time
    projection = axes.get_proj()
    x, y, _ = proj3d.proj_transform(*points.T, projection)
    centre_x, centre_y, _ = proj3d.proj_transform(*middle, projection)
    picture = axes.transData.transform(np.column_stack([x, y]))
    centre = axes.transData.transform([[centre_x, centre_y]])[0]
    area = axes.bbox
    reach = max(
        (picture[:, 0].max() - centre[0]) / (area.x1 - centre[0]),
        (centre[0] - picture[:, 0].min()) / (centre[0] - area.x0),
        (picture[:, 1].max() - centre[1]) / (area.y1 - centre[1]),
        (centre[1] - picture[:, 1].min()) / (centre[1] - area.y0),
    )
    return _FILL / reach if reach > 0 else 1.0


# Which input axes the plot's x, y and z show, for each axis that points up: cyclic, so nothing is mirrored.
_UP = {"z": [0, 1, 2], "y": [2, 0, 1], "x": [1, 2, 0]}


def _levels(isolines: int | Sequence[float] | None, low: float, high: float) -> np.ndarray:
    if isolines is None:
        return np.empty(0)
    if isinstance(isolines, (int, np.integer)) and not isinstance(isolines, bool):
        if isolines < 0:
            raise ValueError(f"isolines must be a number of levels (at least 0) or the levels, not {isolines}")
        return np.linspace(low, high, int(isolines) + 2)[1:-1]
    return _inputs.reals(isolines, "isolines")


def _as_thin_triangles(line: np.ndarray) -> np.ndarray:
    """Each segment (p, q) of a polyline as the triangle (p, q, q)."""
    return np.stack([line[:-1], line[1:], line[1:]], axis=1)


def _mpl_cmap(cmap: Colormap) -> Any:
    """What ScalarMappable takes for the colour bar: a name, a Colormap, or a ListedColormap of a callable."""
    if isinstance(cmap, str):
        return cmap
    from matplotlib.colors import Colormap as MplColormap, ListedColormap

    if isinstance(cmap, MplColormap):
        return cmap
    return ListedColormap(colormap(cmap)(np.linspace(0, 1, 256)))
