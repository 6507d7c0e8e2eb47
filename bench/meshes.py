"""Benchmark meshes: a minimal OBJ reader and writer, 1-to-4 midpoint subdivision, and a cache of the arrays.

Every solver must see the same triangles with the same vertex numbering, so the reader follows the rules of
exactgeo's own OBJ reader: vertices in file order, 1-based or negative (relative) indices, only the position
part of `v/vt/vn` references, polygons fan-triangulated from their first corner.
"""

from __future__ import annotations

import dataclasses
import functools
import sys
from pathlib import Path

import numpy as np


@dataclasses.dataclass(frozen=True)
class BenchMesh:
    name: str
    obj_path: Path  # what the C++ binaries read
    vertices_path: Path  # float64 (V, 3), what the Python peers read
    triangles_path: Path  # int32 (F, 3), zero-based
    vertex_count: int
    face_count: int


# 1-to-4 midpoint subdivisions of the workhorse mesh, 400K and 1.6M faces: (base mesh, levels).
kSubdivided = {"nefertiti-sub1": ("nefertiti", 1), "nefertiti-sub2": ("nefertiti", 2)}
# Made only where a script is asked for them by name (--meshes): 6.4M faces take minutes to write as an OBJ
# of ~400 MB, and most peers days to solve, so no script's default set includes them.
kSubdividedOptIn = {"nefertiti-sub3": ("nefertiti", 3)}


def read_obj(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Positions (V, 3) float64 and fan-triangulated faces (F, 3) int32 of an OBJ file."""
    positions: list[list[float]] = []
    triangles: list[tuple[int, int, int]] = []
    with open(path, "rb") as file:
        for line_number, line in enumerate(file, start=1):
            fields = line.split()
            if not fields:
                continue
            if fields[0] == b"v":
                if len(fields) < 4:
                    raise ValueError(f"{path}:{line_number}: vertex needs 3 coordinates")
                positions.append([float(fields[1]), float(fields[2]), float(fields[3])])
            elif fields[0] == b"f":
                corners = [_vertex_index(token, len(positions), path, line_number) for token in fields[1:]]
                if len(corners) < 3:
                    raise ValueError(f"{path}:{line_number}: face needs at least 3 vertices")
                for i in range(1, len(corners) - 1):
                    triangles.append((corners[0], corners[i], corners[i + 1]))
    vertex_array = np.array(positions, dtype=np.float64).reshape(-1, 3)
    triangle_array = np.array(triangles, dtype=np.int64).reshape(-1, 3)
    if triangle_array.size and triangle_array.max() >= len(vertex_array):
        bad = int(triangle_array.max()) + 1
        raise ValueError(f"{path}: face index {bad} out of range (file has {len(vertex_array)} vertices)")
    return vertex_array, triangle_array.astype(np.int32)


def _vertex_index(token: bytes, vertices_so_far: int, path: Path, line_number: int) -> int:
    index = int(token.split(b"/", 1)[0])
    if index > 0:
        return index - 1
    if index < 0 and vertices_so_far + index >= 0:
        return vertices_so_far + index
    raise ValueError(f"{path}:{line_number}: face index {index} out of range")


def write_obj(path: Path, positions: np.ndarray, triangles: np.ndarray) -> None:
    """%.17g round-trips every double, so the binaries parse exactly the coordinates the peers get."""
    temporary = path.with_suffix(".tmp")
    with open(temporary, "w") as file:
        file.write(f"# {len(positions)} vertices, {len(triangles)} triangles\n")
        np.savetxt(file, positions, fmt="v %.17g %.17g %.17g")
        np.savetxt(file, triangles.astype(np.int64) + 1, fmt="f %d %d %d")
    temporary.replace(path)


def subdivide_midpoint(positions: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """1-to-4 subdivision: one new vertex per undirected edge at its midpoint, rounded once.

    Original vertices keep their indices (so vertex 0 stays vertex 0); edge vertices follow, ordered by
    edge. Face f becomes faces 4f..4f+3 (three corner triangles, then the middle one), winding kept.
    """
    vertex_count = len(positions)
    tails = triangles.astype(np.int64)
    heads = np.roll(tails, -1, axis=1)  # column k is the edge from corner k to corner k+1
    edge_keys = np.minimum(tails, heads) * vertex_count + np.maximum(tails, heads)
    unique_keys, edge_of_face_edge = np.unique(edge_keys.ravel(), return_inverse=True)
    midpoints = 0.5 * (positions[unique_keys // vertex_count] + positions[unique_keys % vertex_count])
    mid = edge_of_face_edge.reshape(-1, 3) + vertex_count  # mid[:, k] sits on the edge corner k -> k+1
    corner = tails
    children = np.stack(
        [
            np.stack([corner[:, 0], mid[:, 0], mid[:, 2]], axis=1),
            np.stack([corner[:, 1], mid[:, 1], mid[:, 0]], axis=1),
            np.stack([corner[:, 2], mid[:, 2], mid[:, 1]], axis=1),
            mid,
        ],
        axis=1,
    )
    new_positions = np.concatenate([positions, midpoints])
    if len(new_positions) > np.iinfo(np.int32).max:
        raise ValueError(f"subdivision gives {len(new_positions)} vertices, more than int32 indices hold")
    return new_positions, children.reshape(-1, 3).astype(np.int32)


def _is_fresh(outputs: list[Path], inputs: list[Path]) -> bool:
    if not all(path.exists() for path in outputs):
        return False
    newest_input = max(path.stat().st_mtime for path in inputs)
    return min(path.stat().st_mtime for path in outputs) >= newest_input


def prepare_meshes(mesh_dir: Path, work_dir: Path, subdivided: dict[str, tuple[str, int]]) -> list[BenchMesh]:
    """Arrays for every OBJ in mesh_dir plus the subdivided meshes, cached under work_dir/meshes.

    subdivided maps a new mesh name to (base mesh name, subdivision levels). Cached files are rebuilt
    when older than their source mesh or than this file.
    """
    cache = work_dir / "meshes"
    cache.mkdir(parents=True, exist_ok=True)
    this_file = Path(__file__)
    meshes: dict[str, BenchMesh] = {}
    for obj_path in sorted(mesh_dir.glob("*.obj")):
        meshes[obj_path.stem] = _cached_arrays(obj_path.stem, obj_path, cache, [obj_path, this_file], None)
    for name, (base_name, levels) in subdivided.items():
        if base_name not in meshes:
            raise ValueError(f"{mesh_dir}: no {base_name}.obj to subdivide into {name}")
        base = meshes[base_name]
        inputs = [base.obj_path, this_file]

        def subdivide(base=base, levels=levels):
            positions, triangles = np.load(base.vertices_path), np.load(base.triangles_path)
            for _ in range(levels):
                positions, triangles = subdivide_midpoint(positions, triangles)
            return positions, triangles

        meshes[name] = _cached_arrays(name, cache / f"{name}.obj", cache, inputs, subdivide)
    return sorted(meshes.values(), key=lambda mesh: (mesh.face_count, mesh.name))


def select_meshes(mesh_dir: Path, work_dir: Path, names: list[str] | None,
                  subdivided: dict[str, tuple[str, int]]) -> list[BenchMesh]:
    """prepare_meshes limited to `names` (None: every one but the opt-in subdivisions); ValueError for a name
    that is none of them. A name in kSubdividedOptIn is made as well as those in `subdivided`."""
    known = subdivided if not names else {**subdivided, **kSubdividedOptIn}
    meshes = prepare_meshes(mesh_dir, work_dir,
                            {name: spec for name, spec in known.items() if not names or name in names})
    if not names:
        return meshes
    unknown = set(names) - {mesh.name for mesh in meshes}
    if unknown:
        raise ValueError(f"no mesh named {', '.join(sorted(unknown))} in {mesh_dir}")
    return [mesh for mesh in meshes if mesh.name in names]


def select_meshes_or_exit(script: str, mesh_dir: Path, work_dir: Path, names: list[str] | None,
                          subdivided: dict[str, tuple[str, int]]) -> list[BenchMesh]:
    """select_meshes for an entry script: saying where the meshes are made, and exiting with a message naming
    `script` if the mesh directory is missing or a name is unknown."""
    if not mesh_dir.is_dir():
        sys.exit(f"{script}: mesh directory {mesh_dir} not found (--mesh-dir)")
    print(f"preparing meshes in {work_dir / 'meshes'}", flush=True)
    try:
        return select_meshes(mesh_dir, work_dir, names, subdivided)
    except ValueError as error:
        sys.exit(f"{script}: {error}")


def _cached_arrays(name, obj_path, cache, inputs, generate) -> BenchMesh:
    vertices_path = cache / f"{name}.vertices.npy"
    triangles_path = cache / f"{name}.triangles.npy"
    outputs = [vertices_path, triangles_path] + ([obj_path] if generate else [])
    if not _is_fresh(outputs, inputs):
        positions, triangles = generate() if generate else read_obj(obj_path)
        if generate:
            write_obj(obj_path, positions, triangles)
        np.save(vertices_path, positions)
        np.save(triangles_path, triangles)
    positions = np.load(vertices_path, mmap_mode="r")
    triangles = np.load(triangles_path, mmap_mode="r")
    return BenchMesh(name, obj_path, vertices_path, triangles_path, len(positions), len(triangles))


# ------------------------------------------------------------------------------- anisotropic triangulations


def anisotropy(positions: np.ndarray, triangles: np.ndarray) -> float:
    """g(M) of Qin et al. 2016, Section 6.1 (after Xu et al. 2015): the mean over faces of P*H / (2*sqrt(3)*S),
    with P the half-perimeter, H the longest edge and S the area. 1 for equilateral faces, growing with
    elongation; infinite if any face has zero area."""
    corners = positions[triangles]
    edges = corners[:, [1, 2, 0]] - corners
    lengths = np.linalg.norm(edges, axis=2)
    areas = 0.5 * np.linalg.norm(np.cross(edges[:, 0], edges[:, 1]), axis=1)
    with np.errstate(divide="ignore"):
        quality = 0.5 * lengths.sum(axis=1) * lengths.max(axis=1) / (2 * np.sqrt(3) * areas)
    return float(quality.mean())


def surface_area(positions: np.ndarray, triangles: np.ndarray) -> float:
    corners = positions[triangles]
    return float(0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]),
                                      axis=1).sum())


def ridged_height(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """A smooth height field over the unit square: ridges across y whose height varies slowly along x, and a
    bump stretched along x. It curves mostly across y, so triangles stretched along x (as anisotropic
    remeshing aligns them with the direction of least curvature) keep the shape at every stretch, while
    geodesics still bend over the ridges and pass saddles."""
    ridges = 0.1 * np.sin(3 * np.pi * y) * (0.7 + 0.3 * np.cos(np.pi * x))
    bump = 0.15 * np.exp(-((x - 0.4) ** 2 / (2 * 0.25**2) + (y - 0.55) ** 2 / (2 * 0.08**2)))
    return ridges + bump


def anisotropic_height_field(face_count: int, stretch: float) -> tuple[np.ndarray, np.ndarray]:
    """ridged_height over the unit square on a grid of about face_count / 2 cells, each `stretch` times
    longer along x than along y and cut into two right triangles by its diagonal. Every row samples the same
    x positions, so the surface has no folds between rows however thin the triangles get. Square cells
    (stretch 1) give g(M) near 1.39; g grows about as stretch / sqrt(3). Vertex j * (columns + 1) + i sits at
    (i / columns, j / rows), so vertex 0 is the corner (0, 0)."""
    columns = max(1, round(np.sqrt(face_count / (2 * stretch))))
    rows = max(1, round(face_count / (2 * columns)))
    x, y = np.meshgrid(np.linspace(0.0, 1.0, columns + 1), np.linspace(0.0, 1.0, rows + 1))
    positions = np.stack([x.ravel(), y.ravel(), ridged_height(x.ravel(), y.ravel())], axis=1)
    corner = (np.arange(rows)[:, None] * (columns + 1) + np.arange(columns)[None, :]).ravel()
    right, up = corner + 1, corner + columns + 1
    lower = np.stack([corner, right, up], axis=1)  # counter-clockwise seen from +z
    upper = np.stack([right, up + 1, up], axis=1)
    return positions, np.concatenate([lower, upper]).astype(np.int32)


def prepare_anisotropic_meshes(work_dir: Path, face_count: int, stretches: list[float]) -> list[BenchMesh]:
    """One anisotropic_height_field per stretch, cached under work_dir/meshes like the other meshes."""
    cache = work_dir / "meshes"
    cache.mkdir(parents=True, exist_ok=True)
    meshes = []
    for stretch in stretches:
        name = f"ridged-{face_count}-x{stretch:g}"
        generate = functools.partial(anisotropic_height_field, face_count, stretch)
        meshes.append(_cached_arrays(name, cache / f"{name}.obj", cache, [Path(__file__)], generate))
    return meshes
