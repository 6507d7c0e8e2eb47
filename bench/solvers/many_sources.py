"""exactgeo's many-source commands timed against their one-source equivalents (many_sources.py).

All from this process, one command after the other: the wall time of `exactgeo matrix --threads T` (mesh
loading included, the same in every run) on one thread and on every core, and the propagation_seconds of one
multi-source `exactgeo distance` against one run per source. The matrix rows are checked bit for bit across
thread counts, and their minimum against the multi-source distances.
"""

from __future__ import annotations

import json
import os
import subprocess
import time
from pathlib import Path

import numpy as np

from meshes import BenchMesh


def wall_seconds(command: list[str]) -> float:
    start = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def propagation_seconds(exactgeo: Path, mesh: Path, sources: list[int], stats: Path) -> float:
    """One `exactgeo distance` from all of `sources`, on one thread whatever the machine; its distances go beside
    `stats` as .npy."""
    command = [str(exactgeo), "distance", str(mesh), "--threads", "1", "--stats", str(stats), "--out",
               str(stats.with_suffix(".npy"))]
    for source in sources:
        command += ["--source", str(source)]
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    return json.loads(stats.read_text())["propagation_seconds"]


def measure_many_sources(exactgeo: Path, mesh: BenchMesh, sources: list[int], run_dir: Path) -> dict:
    """The many-sources report's measurements, keyed as in its JSON (thread counts as text)."""
    run_dir.mkdir(parents=True, exist_ok=True)
    source_list = ",".join(str(s) for s in sources)
    cores = os.cpu_count() or 1
    matrix_seconds, matrices = {}, {}
    for threads in sorted({1, cores}):
        out = run_dir / f"matrix-{threads}.npy"
        matrix_seconds[str(threads)] = wall_seconds([str(exactgeo), "matrix", str(mesh.obj_path), "--sources",
                                                     source_list, "--threads", str(threads), "--quiet", "--out",
                                                     str(out)])
        matrices[threads] = np.load(out)
    rows_agree = all(np.array_equal(matrices[1], m, equal_nan=True) for m in matrices.values())

    single = [propagation_seconds(exactgeo, mesh.obj_path, [s], run_dir / f"single-{s}.json") for s in sources]
    multi = propagation_seconds(exactgeo, mesh.obj_path, sources, run_dir / "multi.json")
    nearest = np.load(run_dir / "multi.npy")
    minimum = matrices[1].min(axis=0)
    finite = np.isfinite(minimum)
    min_error = float(np.max(np.abs(nearest[finite] - minimum[finite])) / np.max(minimum[finite]))
    return {
        "mesh": mesh.name, "faces": mesh.face_count, "sources": sources,
        "matrix_wall_seconds": matrix_seconds,
        "matrix_speedup": matrix_seconds["1"] / matrix_seconds[str(cores)],
        "matrix_rows_identical_across_threads": rows_agree,
        "single_source_propagation_seconds": single,
        "multi_source_propagation_seconds": multi,
        "multi_vs_singles": sum(single) / multi,
        "multi_source_vs_min_of_rows_relative_error": min_error,
    }
