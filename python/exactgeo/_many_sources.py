"""Work over many sources: distance matrices across sources on every core, farthest-point sampling."""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING, overload

import numpy as np

from . import _core, _inputs
from ._geodesic import AlgorithmOptions, RunOptions, TargetsBeyond, exact_targets, geodesic_options
from ._mesh import Mesh, checked_mesh
from ._progress import Progress, run_with_progress
from ._surface_point import VertexIndices, holds_points
from ._warnings import warn

if TYPE_CHECKING:
    from scipy.sparse import csr_array
    from typing_extensions import Unpack


@overload
def distance_matrix(
    mesh: Mesh,
    sources: VertexIndices,
    *,
    targets: VertexIndices | None = None,
    max_distance: None = None,
    targets_beyond: TargetsBeyond = "inf",
    threads: int | None = None,
    progress: Progress = None,
    **options: Unpack[RunOptions],
) -> np.ndarray: ...
@overload
def distance_matrix(
    mesh: Mesh,
    sources: VertexIndices,
    *,
    targets: VertexIndices | None = None,
    max_distance: float,
    targets_beyond: TargetsBeyond = "inf",
    threads: int | None = None,
    progress: Progress = None,
    **options: Unpack[RunOptions],
) -> csr_array: ...
def distance_matrix(
    mesh: Mesh,
    sources: VertexIndices,
    *,
    targets: VertexIndices | None = None,
    max_distance: float | None = None,
    targets_beyond: TargetsBeyond = "inf",
    threads: int | None = None,
    progress: Progress = None,
    **options: Unpack[RunOptions],
) -> np.ndarray | csr_array:
    """Distances from each source vertex (rows) to every input vertex (columns), or to `targets`.

    Row i is `sources[i]`, in the order given: vertex indices only (TypeError for surface points, whose rows
    exactgeo.distance gives one at a time). With `targets` (vertex indices), column j is `targets[j]`: a
    (sources, targets) block holding exactly those columns of the full matrix, and each run stops as soon
    as the targets are final, so nearby targets cost a fraction of a full row. The caller has the row and
    column vertices already (the command line's .npz stores them as `sources` and `targets`).

    Without `max_distance`: a dense float64 ndarray, inf where unreachable. With it: a
    scipy.sparse.csr_array holding the distances up to `max_distance` (the 0 at each source included, as
    an explicit entry); entries not stored are beyond the cut-off or unreachable. Each run stops at the
    cut-off, so a small radius costs a fraction of the dense matrix. `targets_beyond="exact"` stores every
    reachable target's exact distance however far (runs go on until the targets are final), as gdist's
    distance_matrix_of_selected_points does.

    One source per thread, `threads` of them (0 or None, the default: one per core; never more than the
    sources), with the GIL released; rows are identical whatever the thread count. `progress`: True for a tqdm
    bar, or a function called with (rows done, rows). Ctrl-C stops the work within milliseconds.
    """
    mesh = checked_mesh(mesh)
    vertices, columns, has_targets = _rows_and_columns(mesh, sources, targets)
    exact = exact_targets(targets_beyond, has_targets, max_distance)
    config = geodesic_options(None if exact else max_distance, options)
    workers = _workers(threads)
    width = len(columns) if has_targets else mesh.vertex_count
    if max_distance is None:
        matrix = np.empty((len(vertices), width))
        _fill(matrix, mesh, vertices, columns, has_targets, config, workers, progress)
        return matrix
    try:
        import scipy.sparse
    except ImportError:
        raise ImportError("a distance matrix with max_distance is a scipy.sparse matrix: pip install scipy") from None
    values, indices, row_offsets = run_with_progress(
        progress,
        "rows",
        len(vertices),
        lambda r: _core.sparse_distance_matrix(mesh._core, vertices, columns, has_targets, config, workers, r),
    )
    return scipy.sparse.csr_array((values, indices, row_offsets), shape=(len(vertices), width))


def _rows_and_columns(
    mesh: Mesh, sources: VertexIndices, targets: VertexIndices | None
) -> tuple[np.ndarray, np.ndarray, bool]:
    """The source vertices, the target vertices (empty without targets) and whether targets were given."""
    # The library's matrices run from vertices only; for points, say which call takes them.
    if holds_points(sources):
        raise TypeError(
            "distance_matrix takes source vertex indices, not surface points: for a point source, one row is "
            "exactgeo.distance(mesh, point) (a GeodesicSolver reused across the points keeps its buffers)"
        )
    if targets is not None and holds_points(targets):
        raise TypeError(
            "distance_matrix takes target vertex indices, not surface points: "
            "exactgeo.distance(mesh, source, targets=points) gives one row's distances to points"
        )
    vertices = _inputs.vertex_array(sources, mesh.vertex_count, "sources", lambda i: "source vertex")
    columns = (
        np.empty(0, dtype=np.uint32)
        if targets is None
        else _inputs.vertex_array(targets, mesh.vertex_count, "targets", lambda i: f"target {i}: vertex")
    )
    return vertices, columns, targets is not None


def _workers(threads: int | None) -> int:
    return 0 if threads is None else _inputs.count(threads, "threads")


def _fill(out: np.ndarray, mesh: Mesh, vertices: np.ndarray, columns: np.ndarray, has_targets: bool,
          config: _core.GeodesicOptions, workers: int, progress: Progress) -> None:
    run_with_progress(
        progress,
        "rows",
        len(vertices),
        lambda r: _core.fill_distance_matrix(mesh._core, vertices, columns, has_targets, config, workers, out, r),
    )


def fill_distance_matrix(out: np.ndarray, mesh: Mesh, sources: VertexIndices, *, targets: VertexIndices | None = None,
                         threads: int | None = None) -> None:
    """distance_matrix(mesh, sources, targets=targets, threads=threads) written into `out`, a C-ordered float64 or
    float32 array of shape (sources, targets) (float32: each distance rounded to nearest, as astype rounds), a
    few rows at a time: no other copy of the matrix is made. exactgeo.distributed's blocks are computed this way,
    straight into the chunk they are written from."""
    mesh = checked_mesh(mesh)
    vertices, columns, has_targets = _rows_and_columns(mesh, sources, targets)
    _fill(out, mesh, vertices, columns, has_targets, geodesic_options(None, {}), _workers(threads), None)


@dataclasses.dataclass(frozen=True, repr=False)
class Sampling:
    """Result of farthest_point_sampling (C++: exactgeo::Sampling)."""

    samples: np.ndarray  # (k,) int64 vertex indices, in the order taken
    radii: np.ndarray  # (k,) float64: each sample's distance to the samples before it (inf for the first)
    distances: np.ndarray  # (vertex_count,) float64: to the nearest sample, inf where unreachable
    nearest_sample: np.ndarray  # (vertex_count,) int64: index into samples, -1 where unreachable

    def __repr__(self) -> str:
        # One line whatever the mesh's size, as the other results' reprs.
        last_radius = f", last_radius={self.radii[-1]:.6g}" if len(self.radii) else ""
        return f"exactgeo.Sampling(samples={len(self.samples)}, vertices={len(self.distances)}{last_radius})"


def farthest_point_sampling(
    mesh: Mesh,
    count: int,
    *,
    first: VertexIndices = 0,
    max_distance: float | None = None,
    progress: Progress = None,
    **options: Unpack[AlgorithmOptions],
) -> Sampling:
    """Geodesic farthest-point sampling: from `first`, each next sample is the vertex farthest from all
    samples so far (ties to the lowest index).

    `first` is one vertex or several, taken as the first samples in their order (each one's radius its
    distance to those before). Each run after the first stops at the current largest distance, so later
    samples cost less. `progress`: True for a tqdm bar, or a function called with (samples taken, count).
    Ctrl-C stops the work within milliseconds.

    Samples are distinct vertices (but for repeated `first` ones): a `count` above the vertex count (and above
    len(first)) raises ValueError before any work. Sampling stops early once every vertex within reach (of
    `first`'s piece of the mesh, and within `max_distance`) is a sample; the result then has fewer samples
    than `count`, and a UserWarning says how many, pointing at the caller's line.
    """
    mesh = checked_mesh(mesh)
    taken = _inputs.count(count, "count", maximum=2**64 - 1)
    start = _inputs.vertex_array(first, mesh.vertex_count, "first", lambda i: "source vertex")
    if taken > max(mesh.vertex_count, len(start)):
        raise ValueError(
            f"count {taken} exceeds the mesh's {mesh.vertex_count} vertices: farthest-point samples are "
            "distinct vertices"
        )
    config = geodesic_options(max_distance, options)
    arrays = run_with_progress(
        progress, "samples", taken, lambda r: _core.farthest_point_sampling(mesh._core, taken, start, config, r)
    )
    sampling = Sampling(*arrays)
    if len(sampling.samples) < taken:
        within = "" if max_distance is None else f" within max_distance={max_distance}"
        warn(
            f"farthest_point_sampling took {len(sampling.samples)} of the {taken} samples asked for: every vertex "
            f"reachable from `first`{within} is a sample"
        )
    return sampling
