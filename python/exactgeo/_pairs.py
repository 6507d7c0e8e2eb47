"""Exact geodesic distances between given pairs of points, each from a search aimed at the pair's second point."""

from __future__ import annotations

from typing import TYPE_CHECKING, Literal, overload

import numpy as np

from . import _core, _inputs
from ._geodesic import GeodesicPath, RunOptions, geodesic_options
from ._many_sources import _workers
from ._mesh import Mesh, checked_mesh
from ._surface_point import Sites, target_points

if TYPE_CHECKING:
    from typing_extensions import Unpack


@overload
def pair_distances(
    mesh: Mesh,
    a: Sites,
    b: Sites,
    return_paths: Literal[False] = False,
    threads: int | None = None,
    *,
    max_distance: float | None = None,
    **options: Unpack[RunOptions],
) -> np.ndarray: ...
@overload
def pair_distances(
    mesh: Mesh,
    a: Sites,
    b: Sites,
    return_paths: Literal[True],
    threads: int | None = None,
    *,
    max_distance: float | None = None,
    **options: Unpack[RunOptions],
) -> tuple[np.ndarray, list[GeodesicPath]]: ...
def pair_distances(
    mesh: Mesh,
    a: Sites,
    b: Sites,
    return_paths: bool = False,
    threads: int | None = None,
    *,
    max_distance: float | None = None,
    **options: Unpack[RunOptions],
) -> np.ndarray | tuple[np.ndarray, list[GeodesicPath]]:
    """Exact geodesic distance from a[i] to b[i] for every i: float64, inf where b[i] lies on another piece of
    the mesh or beyond `max_distance`.

    `a` and `b` hold as many points each: vertex indices or surface points (a SurfacePoint, a list of them,
    SurfacePoints; a list may mix in vertex indices). Each pair is a search of its own that heads for b[i] and
    stops as soon as nothing left can reach it shorter, so a pair costs a fraction of a full run from a[i]
    (docs/pairs.md). `return_paths=True` also returns each pair's shortest path (a GeodesicPath from a[i] to
    b[i], source 0; empty where the distance is inf). One pair per thread, `threads` of them (0 or None, the
    default: one per core), with the GIL released; the answers are identical whatever the thread count.
    Ctrl-C stops the work within milliseconds.
    """
    mesh = checked_mesh(mesh)
    with_paths = _inputs.flag(return_paths, "return_paths")
    first = target_points(a, mesh, "a", "a")
    second = target_points(b, mesh, "b", "b")
    if len(first) != len(second):
        raise ValueError(f"a and b must have the same length (a has {len(first)} points, b {len(second)})")
    config = geodesic_options(max_distance, options)
    distances, paths = _core.pair_distances(
        mesh._core, first.faces, first.barycentric, second.faces, second.barycentric, config, _workers(threads),
        with_paths,
    )
    if with_paths:
        return distances, [GeodesicPath._of(path) for path in paths]
    return distances
