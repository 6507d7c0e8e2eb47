"""Exact geodesic distances and shortest paths: the reusable solver and the one-off functions over it."""

from __future__ import annotations

import dataclasses
import threading
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, Callable, Literal, TypedDict, overload

import numpy as np

from . import _core, _inputs
from ._mesh import Mesh, checked_mesh
from ._progress import Progress, run_with_progress
from ._surface_point import Sites, SurfacePoint, SurfacePoints, holds_points, source_sites, target_points
from ._warnings import warn

if TYPE_CHECKING:
    from typing_extensions import Unpack

ALGORITHMS: tuple[str, ...] = tuple(_core.algorithm_names())
"""Names accepted by the `algorithm` option."""


class RunOptions(TypedDict, total=False):
    """The AlgorithmOptions but `threads`: the keyword arguments of distance_matrix and pair_distances, whose
    own `threads` argument is the number of threads their sources (pairs) are spread over."""

    algorithm: str  # one of ALGORITHMS (paper Section 5); "vtp", the default, is the paper's final algorithm
    rule1: bool  # paper Section 4.1: prune with the window list's separating point
    rule23: bool  # paper Sections 4.2-4.3: pairwise checks between neighbouring windows
    collect_timings: bool  # split propagation_seconds in `stats` into its phases (slows the run down by up to 60%)


class AlgorithmOptions(RunOptions, total=False):
    """Keyword arguments that choose how the engine runs (C++: exactgeo::GeodesicOptions). Every one has the
    library's default; distances are exact whatever they are."""

    # threads sharing one run (0: one per core). Default: one per 10,000 faces, up to one per core (1 below
    # 20,000 faces). Every count above 1 gives one thread's distances to within 1e-14 of the largest, the last
    # bits changing from run to run (include/exactgeo/geodesic.hpp, for_each_option_field).
    # The face-sorted algorithms (ftp, opftp) run on one thread; stats.threads says how many a run shared.
    # farthest_point_sampling's runs share them likewise, until one reaches fewer than 10,000 vertices (the
    # later ones run on one thread); distance_matrix's own `threads` argument spreads its sources over threads
    # instead (RunOptions).
    threads: int


_OPTION_NAMES = frozenset(AlgorithmOptions.__annotations__)
# Each option's checked conversion, by its type above; the library checks the values (an algorithm's name,
# at most 1024 threads).
_OPTION_CONVERSIONS: dict[str, Callable[[Any, str], object]] = {
    "algorithm": _inputs.text,
    "rule1": _inputs.flag,
    "rule23": _inputs.flag,
    "collect_timings": _inputs.flag,
    "threads": _inputs.count,
}

TargetsBeyond = Literal["inf", "exact"]


def exact_targets(targets_beyond: str, has_targets: bool, max_distance: float | None) -> bool:
    """Whether a run with targets goes on past `max_distance` until every target is final
    (targets_beyond="exact"), the cut-off then applying to the vertex distances alone."""
    if targets_beyond not in ("inf", "exact"):
        raise ValueError(f"targets_beyond must be 'inf' or 'exact', not {targets_beyond!r}")
    return targets_beyond == "exact" and has_targets and max_distance is not None


def geodesic_options(
    max_distance: float | None, options: Mapping[str, object], keep_windows: bool = False
) -> _core.GeodesicOptions:
    unknown = sorted(options.keys() - _OPTION_NAMES)
    if unknown:
        raise TypeError(f"unexpected keyword argument {unknown[0]!r} (options: {', '.join(sorted(_OPTION_NAMES))})")
    checked = {name: _OPTION_CONVERSIONS[name](value, name) for name, value in options.items()}
    return _core.GeodesicOptions(
        max_distance=_inputs.cutoff(max_distance), keep_windows=_inputs.flag(keep_windows, "keep_windows"), **checked
    )


def _number(value: float) -> str:
    """A length or distance as a repr shows it: six significant digits, inf as inf."""
    return f"{value:.6g}"


def _point(point: np.ndarray) -> str:
    return "(" + ", ".join(_number(c) for c in point) + ")"


def _largest_finite(values: np.ndarray) -> str:
    finite = values[np.isfinite(values)]
    return _number(float(finite.max())) if finite.size else "none"


# The results' reprs give counts, lengths and ends, never the arrays: a result printed in a notebook or a log
# stays one line whatever the mesh's size.
@dataclasses.dataclass(frozen=True, repr=False)
class GeodesicResult:
    """What a run computed (C++: exactgeo::GeodesicResult)."""

    distances: np.ndarray  # (vertex_count,) float64: to the nearest source, inf if unreachable or cut off
    nearest_source: np.ndarray  # (vertex_count,) int64: index into the sources, -1 where distances is inf
    target_distances: np.ndarray  # (targets,) float64, likewise per target
    target_nearest_source: np.ndarray  # (targets,) int64
    stats: _core.GeodesicStats  # the engine's counters and its time, as attributes; .to_dict() for a dict

    def __repr__(self) -> str:
        unreachable = int(np.count_nonzero(np.isinf(self.distances)))
        return (
            f"exactgeo.GeodesicResult(vertices={len(self.distances)}, largest_distance="
            f"{_largest_finite(self.distances)}, inf={unreachable}, targets={len(self.target_distances)})"
        )


@dataclasses.dataclass(frozen=True, repr=False)
class GeodesicPath:
    """A shortest path from the nearest source to a point, straight inside each face (C++: exactgeo::GeodesicPath).

    Each point is a convex combination of up to three input vertices: points[i] equals
    sum_k weights[i, k] * mesh.vertices[vertices[i, k]] over the k with vertices[i, k] >= 0.
    Empty arrays, length inf and source -1 if the point is unreachable.
    """

    points: np.ndarray  # (k, 3) float64, from the source to the point
    kind: np.ndarray  # (k,) str: "vertex", "edge" or "face", where each point lies
    vertices: np.ndarray  # (k, 3) int64: the vertex; the edge's two ends; the face's three corners; -1 unused
    weights: np.ndarray  # (k, 3) float64: 1; (1 - t, t) along the edge; the barycentric coordinates
    face: np.ndarray  # (k,) int64: the input face of "face" points, -1 for the others
    length: float
    source: int  # index into the sources

    def __repr__(self) -> str:
        if len(self.points) == 0:
            return "exactgeo.GeodesicPath(points=0, length=inf, source=-1)"
        return (
            f"exactgeo.GeodesicPath(points={len(self.points)}, length={_number(self.length)}, source={self.source}, "
            f"start={_point(self.points[0])}, end={_point(self.points[-1])})"
        )

    @classmethod
    def _of(cls, arrays: tuple[Any, ...]) -> GeodesicPath:
        points, kind, vertices, weights, face, length, source = arrays
        return cls(points, np.asarray(kind, dtype=str), vertices, weights, face, length, source)


_NO_TARGETS = SurfacePoints(np.empty(0, dtype=np.uint32), np.empty((0, 3)))


class GeodesicSolver:
    """A reusable solver on one mesh (C++: exactgeo::GeodesicSolver): keeps the engine's buffers between
    runs, and answers path queries about its last run.

    The GIL is released while it runs, so solvers in several threads run in parallel. Use one solver per
    thread: one solver used from several threads runs one call at a time, and a path query after another
    thread's solve() raises RuntimeError rather than answer about that other run.
    """

    def __init__(self, mesh: Mesh) -> None:
        self._mesh = checked_mesh(mesh)
        self._core = _core.GeodesicSolver(mesh._core)
        self._last_run = threading.local()  # per thread: the number of its last run, for path queries

    @property
    def mesh(self) -> Mesh:
        return self._mesh

    def __reduce__(self) -> tuple[object, tuple[object, ...]]:
        # A solver pickles as its mesh: the copy is ready to run, with no run to trace paths in yet.
        return (GeodesicSolver, (self._mesh,))

    def solve(
        self,
        sources: Sites,
        targets: Sites | None = None,
        *,
        max_distance: float | None = None,
        targets_beyond: TargetsBeyond = "inf",
        keep_windows: bool = False,
        progress: Progress = None,
        **options: Unpack[AlgorithmOptions],
    ) -> GeodesicResult:
        """Distances from the nearest of `sources` to every vertex, and to `targets` if given.

        Sources and targets are vertex indices (an int, a list or an array of any integer dtype), a
        SurfacePoint, a list of them, or SurfacePoints; sources are either all vertices or all points, targets
        may mix the two. A vertex, or a point at a corner of a face, is that input vertex: where the mesh split
        it into several surface copies (non-manifold), a source there is a source at each copy, and a target
        has the smallest distance over them, as `distances` has it. With targets,
        the run stops as soon as they are final: vertex distances are then exact up to the farthest target
        and inf beyond. `max_distance`: nothing farther is computed (inf), targets included: the run stops
        at the cut-off. `targets_beyond="exact"` answers every target exactly instead, as gdist and
        pygeodesic do: the run goes on until every target is final, and the cut-off applies to the vertex
        distances alone (inf beyond it). `keep_windows=True` keeps what the run learnt about every face (see
        stats.kept_window_bytes), so that distance_at and path_to_point answer any point afterwards.
        `progress`: True for a tqdm bar, or a function called with (thousandths of the mesh passed, 1000).
        Ctrl-C stops a run on a large mesh within milliseconds.
        """
        exact = exact_targets(targets_beyond, targets is not None, max_distance)
        config = geodesic_options(
            None if exact else max_distance,
            {"threads": _core.recommended_threads(self._mesh._core), **options},
            keep_windows,
        )
        ends = _NO_TARGETS if targets is None else target_points(targets, self._mesh)
        starts = source_sites(sources, self._mesh)

        def run(reporter: object) -> tuple[Any, ...]:
            if isinstance(starts, SurfacePoints):
                return self._core.solve_from_points(
                    starts.faces, starts.barycentric, ends.faces, ends.barycentric, config, reporter
                )
            return self._core.solve_from_vertices(starts, ends.faces, ends.barycentric, config, reporter)

        *arrays, self._last_run.number = run_with_progress(progress, "distances", 1000, run)
        if exact:
            beyond = arrays[0] > max_distance
            arrays[0] = np.where(beyond, np.inf, arrays[0])
            arrays[1] = np.where(beyond, -1, arrays[1])
        result = GeodesicResult(*arrays)
        if targets is None and max_distance is None:
            _warn_if_seams_cut_the_surface(self._mesh, result.distances)
        return result

    def _run_number(self) -> int:
        """This thread's last run; 0 before its first, which only a solver that never ran accepts."""
        return getattr(self._last_run, "number", 0)

    def path_to_vertex(self, vertex: int) -> GeodesicPath:
        """The shortest path of the last run to input vertex `vertex`."""
        checked = _inputs.vertex_index(vertex, self._mesh.vertex_count, "vertex", "vertex")
        return GeodesicPath._of(self._core.path_to_vertex(checked, self._run_number()))

    def path_to_target(self, target: int) -> GeodesicPath:
        """The shortest path of the last run to its target number `target`."""
        return GeodesicPath._of(self._core.path_to_target(_inputs.count(target, "target"), self._run_number()))

    def distance_at(self, points: Sites) -> np.ndarray:
        """Distances from the last run's nearest source to `points`, as exact as if they had been its targets:
        float64, one per point, inf where unreachable or beyond the run's cut-off (max_distance, or the farthest
        target). The run must have kept its windows (`solve(..., keep_windows=True)`); any number of calls
        follow it. Points as `targets` takes them: vertex indices, a SurfacePoint, a list of them, SurfacePoints.
        """
        checked = target_points(points, self._mesh, "points", "point")
        return self._core.distance_at(checked.faces, checked.barycentric, self._run_number())

    def path_to_point(self, point: int | np.integer | SurfacePoint) -> GeodesicPath:
        """The shortest path of the last run (with `keep_windows=True`) from its nearest source to `point`, a
        SurfacePoint or a vertex index."""
        if isinstance(point, bool) or not isinstance(point, (SurfacePoint, int, np.integer)):
            raise TypeError(f"point must be a SurfacePoint or a vertex index, not {type(point).__name__}")
        checked = target_points(point, self._mesh, "point", "point")
        return GeodesicPath._of(self._core.path_to_point(checked.faces, checked.barycentric, self._run_number()))


def _warn_if_seams_cut_the_surface(mesh: Mesh, distances: np.ndarray) -> None:
    """Vertices used by faces yet unreachable, on a mesh with vertices at duplicate positions: most likely a
    mesh library split it at texture or normal seams, and welding joins it again."""
    report = mesh.report
    if mesh._weld or report.duplicate_positions == 0:
        return
    unreachable = int(np.count_nonzero(np.isinf(distances))) - report.unreferenced_vertices
    if unreachable > 0:
        warn(
            f"{unreachable} of {mesh.vertex_count} vertices are unreachable, and {report.duplicate_positions} "
            "vertices repeat another's position (seams, as mesh libraries split meshes): "
            "exactgeo.Mesh(..., weld_duplicate_positions=True) joins them"
        )


@overload
def distance(
    mesh: Mesh,
    sources: Sites,
    *,
    targets: Sites | None = None,
    max_distance: float | None = None,
    targets_beyond: TargetsBeyond = "inf",
    return_nearest: Literal[False] = False,
    progress: Progress = None,
    **options: Unpack[AlgorithmOptions],
) -> np.ndarray: ...
@overload
def distance(
    mesh: Mesh,
    sources: Sites,
    *,
    targets: Sites | None = None,
    max_distance: float | None = None,
    targets_beyond: TargetsBeyond = "inf",
    return_nearest: Literal[True],
    progress: Progress = None,
    **options: Unpack[AlgorithmOptions],
) -> tuple[np.ndarray, np.ndarray]: ...
def distance(
    mesh: Mesh,
    sources: Sites,
    *,
    targets: Sites | None = None,
    max_distance: float | None = None,
    targets_beyond: TargetsBeyond = "inf",
    return_nearest: bool = False,
    progress: Progress = None,
    **options: Unpack[AlgorithmOptions],
) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Exact geodesic distance from the nearest of `sources`: float64, inf where unreachable or cut off.

    Without `targets`, one distance per input vertex. With `targets` (vertex indices or surface points),
    one distance per target, in their order; the run stops as soon as they are final, so a few nearby
    targets cost a fraction of a full run. `return_nearest=True` also returns, per vertex or target, the
    index of the nearest source (int64, -1 where the distance is inf). `max_distance`: inf beyond it,
    targets too; with `targets_beyond="exact"` every target gets its exact distance whatever the cut-off
    (what gdist and pygeodesic return). See GeodesicSolver.solve for the forms sources and targets take,
    and for `progress`.
    """
    with_nearest = _inputs.flag(return_nearest, "return_nearest")
    result = GeodesicSolver(mesh).solve(
        sources, targets, max_distance=max_distance, targets_beyond=targets_beyond, progress=progress, **options
    )
    if targets is None:
        values, nearest = result.distances, result.nearest_source
    else:
        values, nearest = result.target_distances, result.target_nearest_source
    return (values, nearest) if with_nearest else values


@overload
def path(
    mesh: Mesh,
    sources: Sites,
    target: int | np.integer | SurfacePoint,
    *,
    max_distance: float | None = None,
    **options: Unpack[AlgorithmOptions],
) -> GeodesicPath: ...
@overload
def path(
    mesh: Mesh,
    sources: Sites,
    target: Sequence[int] | np.ndarray | Sequence[SurfacePoint] | SurfacePoints,
    *,
    max_distance: float | None = None,
    **options: Unpack[AlgorithmOptions],
) -> list[GeodesicPath]: ...
def path(
    mesh: Mesh,
    sources: Sites,
    target: Sites,
    *,
    max_distance: float | None = None,
    **options: Unpack[AlgorithmOptions],
) -> GeodesicPath | list[GeodesicPath]:
    """The shortest path from the nearest of `sources` to `target`, a vertex index or a SurfacePoint; for
    several targets (a list or array of vertices, a list of SurfacePoints, SurfacePoints), a list of paths
    in their order, all from one run.

    Its length equals the geodesic distance (to about 1e-12 relative); it bends only at saddle and boundary
    vertices. The run stops once the targets are final.
    """
    solver = GeodesicSolver(mesh)
    if holds_points(target):
        solver.solve(sources, target, max_distance=max_distance, **options)
        if isinstance(target, SurfacePoint):
            return solver.path_to_target(0)
        return [solver.path_to_target(i) for i in range(len(target))]
    vertices = _inputs.vertex_array(target, mesh.vertex_count, "target", lambda i: f"target {i}: vertex")
    solver.solve(sources, vertices, max_distance=max_distance, **options)
    paths = [solver.path_to_vertex(int(v)) for v in vertices]
    return paths[0] if isinstance(target, (int, np.integer)) else paths
