"""exactgeo.isolines: level curves of a per-vertex field as polylines on the surface."""

from __future__ import annotations

from typing import Any

import numpy as np

from . import _inputs
from ._mesh import Mesh, checked_mesh


def isolines(mesh: Mesh, values: Any, levels: Any) -> list[list[np.ndarray]]:
    """The curves where the piecewise-linear interpolation of `values` over each triangle equals each level.

    `values` has one number per vertex (e.g. exactgeo.distance's result); `levels` is one level or a
    sequence of them. Returns one list per level, of polylines as (k, 3) float64 arrays of points on the
    surface. Segments are chained across shared edges into one polyline per connected curve; a closed curve
    repeats its first point at the end. A curve stops at the boundary, at a face it cannot cross and where
    more than two pieces meet (a saddle exactly at the level, a non-manifold edge).

    How the points are placed: on each edge whose ends lie on both sides of the level, at the point where
    the linear interpolation of the two end values equals the level, and joined by a straight segment
    inside each triangle. A vertex exactly at a level counts as above it: the curve then passes through the
    vertex itself, without a zero-length or doubled segment. Faces with an inf or NaN value at a corner
    (unreachable vertices, a cut-off) are left out, so curves end there.

    How accurate: the points are exact for the linear interpolation, not for the field. A geodesic distance
    is not linear along an edge: where it is convex along the edge (a flat mesh, a point source at distance
    r from the edge) a point's true distance lies below its level by at most |e|**2 / (8 r) for an edge of
    length |e| -- the interpolation error of a function whose second derivative is at most 1 / r -- and the
    distance to the true curve is the same amount, since the distance's gradient has length 1. So the error
    is O(h**2) times the curvature of the level curves, and zero where the distance is linear along the
    edges (a flat mesh with the source far away, edges pointing away from the source). Inside a triangle
    the segment is a chord of the true curve, off by the same order.
    """
    surface = checked_mesh(mesh)
    field = _per_vertex(values, surface)
    level_list = _inputs.reals(levels, "levels")
    faces = surface.faces.astype(np.int64)
    corner_values = field[faces]
    usable = np.isfinite(corner_values).all(axis=1)
    faces, corner_values = faces[usable], corner_values[usable]
    return [_level_curves(surface.vertices, faces, corner_values, float(level)) for level in level_list]


def _per_vertex(values: Any, mesh: Mesh) -> np.ndarray:
    """`values` as float64, one per vertex; ValueError naming both lengths otherwise."""
    array = np.asarray(values)
    if array.dtype.kind not in "fiub":
        raise ValueError(f"values must be numbers, not dtype {array.dtype}")
    if array.ndim != 1 or len(array) != mesh.vertex_count:
        size = f"{len(array)} values" if array.ndim == 1 else f"an array of shape {array.shape}"
        raise ValueError(
            f"values must have one number per vertex: got {size}, but the mesh has {mesh.vertex_count} vertices"
        )
    return array.astype(np.float64)


def _level_curves(
    positions: np.ndarray, faces: np.ndarray, corner_values: np.ndarray, level: float
) -> list[np.ndarray]:
    above = corner_values >= level
    crossing = above.any(axis=1) & ~above.all(axis=1)
    faces, corner_values, above = faces[crossing], corner_values[crossing], above[crossing]
    if len(faces) == 0:
        return []
    # Each crossed face has exactly two edges with one end on each side: corners (k, k + 1 mod 3).
    ends = np.array([[0, 1], [1, 2], [2, 0]])
    crossed = above[:, ends[:, 0]] != above[:, ends[:, 1]]  # (m, 3), two True per row
    face_of, edge_of = np.nonzero(crossed)
    first, second = faces[face_of, ends[edge_of, 0]], faces[face_of, ends[edge_of, 1]]
    first_above = above[face_of, ends[edge_of, 0]]
    low = np.where(first_above, second, first)
    high = np.where(first_above, first, second)
    first_value, second_value = corner_values[face_of, ends[edge_of, 0]], corner_values[face_of, ends[edge_of, 1]]
    low_value = np.where(first_above, second_value, first_value)
    high_value = np.where(first_above, first_value, second_value)
    # A point exactly at a vertex is named by the vertex, so that every edge meeting there gives the same
    # point; any other by its edge (both faces of the edge give the same key).
    at_vertex = high_value == level
    vertex_count = len(positions)
    key = np.where(
        at_vertex, high, vertex_count + np.minimum(low, high) * vertex_count + np.maximum(low, high)
    )
    t = (level - low_value) / (high_value - low_value)
    point = positions[low] + t[:, None] * (positions[high] - positions[low])
    point[at_vertex] = positions[high[at_vertex]]
    # Segments as pairs of keys (np.nonzero lists each face's two crossings one after the other); a
    # segment whose ends are the same vertex has no length, and a segment along an edge exactly at the level
    # with both neighbouring faces below comes from each of them: one is kept.
    pairs = np.sort(key.reshape(-1, 2), axis=1)
    pairs = pairs[pairs[:, 0] != pairs[:, 1]]
    pairs = np.unique(pairs, axis=0)
    if len(pairs) == 0:
        return []
    keys, first_of_key = np.unique(key, return_index=True)
    nodes = np.searchsorted(keys, pairs)
    return _chain(nodes, point[first_of_key])


def _chain(segments: np.ndarray, points: np.ndarray) -> list[np.ndarray]:
    """Polylines through `segments` ((s, 2) node numbers): from every node where a curve ends or branches
    (not two segments), then around the closed curves left."""
    node_count = len(points)
    ends = segments.reshape(-1)
    order = np.argsort(ends, kind="stable")
    incident: list[int] = (order // 2).tolist()  # segment numbers, grouped by node
    start_of = np.concatenate([[0], np.cumsum(np.bincount(ends, minlength=node_count))]).tolist()
    degree = np.diff(start_of)
    seg = segments.tolist()
    used = [False] * len(segments)

    def next_segment(node: int) -> int:
        for i in range(start_of[node], start_of[node + 1]):
            if not used[incident[i]]:
                return incident[i]
        return -1

    def walk(node: int) -> list[int]:
        path = [node]
        while True:
            segment = next_segment(node)
            if segment < 0:
                return path
            used[segment] = True
            a, b = seg[segment]
            node = b if a == node else a
            path.append(node)
            if degree[node] != 2:
                return path

    polylines = []
    for node in np.flatnonzero(degree != 2).tolist():
        while next_segment(node) >= 0:
            polylines.append(walk(node))
    for segment in range(len(segments)):
        if not used[segment]:
            polylines.append(walk(seg[segment][0]))  # a closed curve: the walk returns to its start
    return [points[path] for path in polylines]
