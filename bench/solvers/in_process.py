"""The Python packages timed inside one process, as a numpy user calls them (python_level.py).

Each peer answers from the same (V float64, F int32) arrays; a conversion a package needs happens inside its
timed call, as it would for its users. Times are medians over batches of calls (each at least kBatchSeconds)
taken round the peers, so a drift in machine load hits all alike.
"""

from __future__ import annotations

import os
import statistics
import time
from collections.abc import Callable

import numpy as np

import exactgeo

kBatchSeconds = 0.02
kMatrixSources = 16
# Local matrices: every vertex a source, out to these radii in mean edge lengths.
kLocalRadiiEdges = (3.0, 6.0)
# libigl's exact_geodesic also traces the path back from every vertex: at 100K faces one call takes over a
# minute, so it runs on the meshes up to this size only.
kLibiglMaxFaces = 25_000
# Kirsanov's code marks unreachable vertices with 1e100.
kKirsanovInfinity = 1e99


class Peer:
    """One package's way of answering: `build` returns its prepared structure (None if it has none), `query`
    the distances from one source given that structure (or the arrays)."""

    def __init__(self, name: str, package: str, build: Callable | None, query: Callable, exact: bool) -> None:
        self.name, self.package, self.build, self.query, self.exact = name, package, build, query, exact

    def one_call(self, vertices: np.ndarray, faces: np.ndarray, source: int) -> np.ndarray:
        prepared = self.build(vertices, faces) if self.build else None
        return self.query(prepared, vertices, faces, source)


def make_peers() -> list[Peer]:
    import gdist
    import igl
    import potpourri3d
    import pygeodesic.geodesic

    return [
        # One thread, as every peer runs (the package's default shares a run among the cores from 20,000 faces).
        Peer("exactgeo", "exactgeo", exactgeo.Mesh, lambda mesh, v, f, s: exactgeo.distance(mesh, s, threads=1), True),
        Peer(
            "pygeodesic",
            "pygeodesic",
            pygeodesic.geodesic.PyGeodesicAlgorithmExact,
            lambda algorithm, v, f, s: algorithm.geodesicDistances(np.array([s]), None)[0],
            True,
        ),
        Peer(
            "gdist",
            "tvb-gdist",
            None,
            lambda _, v, f, s: gdist.compute_gdist(v, f, source_indices=np.array([s], dtype=np.int32)),
            True,
        ),
        Peer(
            "libigl",
            "libigl",
            None,
            lambda _, v, f, s: igl.exact_geodesic(v, f, np.array([s]), VT=np.arange(len(v))),
            True,
        ),
        Peer(
            "heat",
            "potpourri3d",
            potpourri3d.MeshHeatMethodDistanceSolver,
            lambda solver, v, f, s: solver.compute_distance(s),
            False,
        ),
    ]


def per_call_seconds(call: Callable[[], object]) -> Callable[[], float]:
    """A timer for `call`: each use runs a batch of at least kBatchSeconds and returns the time per call."""
    start = time.perf_counter()
    call()  # warm-up, and the size of a batch
    number = max(1, int(kBatchSeconds / max(time.perf_counter() - start, 1e-9)))

    def batch() -> float:
        start = time.perf_counter()
        for _ in range(number):
            call()
        return (time.perf_counter() - start) / number

    return batch


def median_times(calls: dict[str, Callable[[], object]], repeat: int) -> dict[str, float]:
    """Median time per call of each, batches taken round the calls."""
    timers = {name: per_call_seconds(call) for name, call in calls.items()}
    samples: dict[str, list[float]] = {name: [] for name in calls}
    for _ in range(repeat):
        for name, timer in timers.items():
            samples[name].append(timer())
    return {name: statistics.median(values) for name, values in samples.items()}


def difference(ours: np.ndarray, theirs: np.ndarray) -> dict:
    """Largest |theirs - ours| over the vertices finite in both, relative to our largest distance, and the
    count of vertices one calls unreachable and the other does not."""
    theirs = np.asarray(theirs, dtype=np.float64)
    theirs = np.where(np.abs(theirs) < kKirsanovInfinity, theirs, np.inf)
    both = np.isfinite(ours) & np.isfinite(theirs)
    largest = ours[np.isfinite(ours)].max()
    return {
        "max_relative_difference": float(np.abs(ours[both] - theirs[both]).max() / largest),
        "max_absolute_difference": float(np.abs(ours[both] - theirs[both]).max()),
        "reachability_disagreements": int(np.count_nonzero(np.isfinite(ours) != np.isfinite(theirs))),
    }


def bench_mesh(name: str, vertices: np.ndarray, faces: np.ndarray, peers: list[Peer], repeat: int) -> dict:
    """One call and prepared-query times of every peer from the first used vertex, and each one's difference
    to exactgeo's distances."""
    source = int(np.unique(faces)[0])
    runnable = [p for p in peers if p.name != "libigl" or len(faces) <= kLibiglMaxFaces]
    prepared = {p.name: p.build(vertices, faces) if p.build else None for p in runnable}
    one_call = median_times({p.name: (lambda p=p: p.one_call(vertices, faces, source)) for p in runnable}, repeat)
    prepared_call = median_times(
        {p.name: (lambda p=p: p.query(prepared[p.name], vertices, faces, source)) for p in runnable if p.build}, repeat
    )
    ours = exactgeo.distance(prepared["exactgeo"], source)
    record = {"mesh": name, "vertices": len(vertices), "faces": len(faces), "source": source, "solvers": {}}
    for p in runnable:
        record["solvers"][p.name] = {
            "one_call_seconds": one_call[p.name],
            "prepared_seconds": prepared_call.get(p.name, one_call[p.name]),
            "rebuilds_every_call": p.build is None,
            **difference(ours, p.query(prepared[p.name], vertices, faces, source)),
        }
    skipped = [p.name for p in peers if p not in runnable]
    if skipped:
        record["skipped"] = {
            n: f"over {kLibiglMaxFaces:,} faces (one call traces every vertex's path)" for n in skipped
        }
    return record


def bench_matrix(name: str, vertices: np.ndarray, faces: np.ndarray, peers: list[Peer], repeat: int) -> dict:
    """kMatrixSources seeded sources to every vertex: exactgeo's distance_matrix (every core, one thread)
    against one prepared query per source for the others."""
    rng = np.random.default_rng(1)
    sources = rng.choice(np.unique(faces), size=kMatrixSources, replace=False)
    mesh = exactgeo.Mesh(vertices, faces)
    calls: dict[str, Callable[[], object]] = {
        "exactgeo": lambda: exactgeo.distance_matrix(mesh, sources),
        "exactgeo, 1 thread": lambda: exactgeo.distance_matrix(mesh, sources, threads=1),
    }
    for p in peers:
        if p.name == "exactgeo" or (p.name == "libigl" and len(faces) > kLibiglMaxFaces):
            continue
        prepared = p.build(vertices, faces) if p.build else None
        calls[p.name] = lambda p=p, prepared=prepared: [p.query(prepared, vertices, faces, int(s)) for s in sources]
    times = median_times(calls, repeat)
    return {
        "mesh": name,
        "vertices": len(vertices),
        "faces": len(faces),
        "sources": [int(s) for s in sources],
        "threads": os.cpu_count(),
        "seconds": times,
    }


def mean_edge_length(vertices: np.ndarray, faces: np.ndarray) -> float:
    """The mean length of the faces' sides (an edge shared by two faces counted twice)."""
    sides = vertices[np.roll(faces, -1, axis=1)] - vertices[faces]
    return float(np.linalg.norm(sides, axis=2).mean())


def local_difference(ours, theirs) -> dict:
    """How gdist's local matrix differs from ours: the largest difference over the entries both hold, and the
    entries only one holds (the 0 at each source, which gdist leaves out, not counted)."""
    ours, theirs = ours.tocsr(), theirs.tocsr()
    ours_pattern, theirs_pattern = ours.copy(), theirs.copy()
    ours_pattern.data[:] = 1
    theirs_pattern.data[:] = 1
    both = ours_pattern.multiply(theirs_pattern)
    gap = (ours.multiply(both) - theirs.multiply(both)).data
    return {
        "common_entries": int(both.nnz),
        "only_ours": int(ours_pattern.nnz - ours_pattern.diagonal().sum() - both.nnz),
        "only_theirs": int(theirs_pattern.nnz - both.nnz),
        "max_difference": float(np.abs(gap).max()) if len(gap) else 0.0,
    }


def bench_local_matrix(name: str, vertices: np.ndarray, faces: np.ndarray, repeat: int) -> dict:
    """Every vertex a source out to each radius of kLocalRadiiEdges: exactgeo.distance_matrix from the arrays
    (the mesh built in the call, as gdist builds its own) on one thread and on every core, against
    gdist.local_gdist_matrix; entries and agreement beside the times."""
    import gdist

    edge = mean_edge_length(vertices, faces)
    sources = np.arange(len(vertices), dtype=np.uint32)
    record: dict = {"mesh": name, "vertices": len(vertices), "faces": len(faces), "mean_edge": edge,
                    "threads": os.cpu_count(), "radii": []}
    for edges in kLocalRadiiEdges:
        radius = edges * edge

        def ours(threads: int | None, radius: float = radius) -> object:
            return exactgeo.distance_matrix(exactgeo.Mesh(vertices, faces), sources, max_distance=radius,
                                            threads=threads)

        def theirs(radius: float = radius) -> object:
            return gdist.local_gdist_matrix(vertices, faces, max_distance=radius)

        times = median_times({"exactgeo, 1 thread": lambda: ours(1), "exactgeo": lambda: ours(None),
                              "gdist": theirs}, repeat)
        matrix = ours(1)
        record["radii"].append({
            "edges": edges,
            "radius": radius,
            "entries": int(matrix.nnz),
            "seconds": times,
            **local_difference(matrix, theirs(radius)),
        })
    return record
