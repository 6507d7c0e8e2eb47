"""One source on one and two threads: exactgeo's sequential and parallel propagation against a build of an
earlier commit (the baseline) in the same run, and the exact solve beside the heat method's approximate one.
Writes bench/results/threads.{json,md}.

usage: python3 bench/threads.py [--build-dir build] [--baseline-build DIR] [--meshes stanford-bunny ...]
                                [--runs 5]

Every figure is the median over --runs runs, taken round the configurations (baseline, 1 thread, 2 threads)
so that a drift in the machine's load hits all alike:
- propagation: `exactgeo distance MESH --source 0` run as its own process, its propagation_seconds (mesh
  reading and building excluded), and its peak RSS;
- heat: potpourri3d's MeshHeatMethodDistanceSolver built once (its factorisation, timed apart), then
  compute_distance(0) timed, with its error against the exact distances.
The baseline is any earlier build of the command (it runs without --threads); without one, its columns stay
empty.
"""

from __future__ import annotations

import argparse
import datetime
import importlib.util
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from meshes import kSubdivided, select_meshes
from peer_worker import heat_on_used_vertices
from reports.machine import machine_info
from reports.threads import write_markdown

kBenchDir = Path(__file__).resolve().parent
kDefaultMeshes = ["stanford-bunny", "nefertiti", "nefertiti-sub1", "nefertiti-sub2"]


def run_once(command: list[str], stats_path: Path) -> dict:
    """One run of the command: its stats file and its peak RSS (the operating system's own accounting)."""
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(process.pid, 0)
    process.returncode = os.waitstatus_to_exitcode(status)
    if process.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} failed: {process.stderr.read().decode()}")
    stats = json.loads(stats_path.read_text())
    return {"propagation_seconds": stats["propagation_seconds"], "peak_rss_bytes": usage.ru_maxrss * 1024,
            "stats": stats}


def measure_configurations(configurations: dict[str, tuple[str, list[str]]], mesh_path: Path, work: Path,
                           runs: int) -> dict:
    """Median propagation time and peak RSS of each configuration, runs taken in turn; the last run's stats and
    distances of each."""
    samples: dict[str, list[dict]] = {name: [] for name in configurations}
    for _ in range(runs):
        for name, (executable, options) in configurations.items():
            stats_path, distances_path = work / f"{name}.json", work / f"{name}.npy"
            samples[name].append(run_once([executable, "distance", str(mesh_path), "--source", "0", "--quiet", "--stats",
                                           str(stats_path), "--out", str(distances_path), *options], stats_path))
    results = {}
    for name, runs_of in samples.items():
        last = runs_of[-1]["stats"]
        results[name] = {
            "propagation_seconds": statistics.median(r["propagation_seconds"] for r in runs_of),
            "propagation_seconds_min": min(r["propagation_seconds"] for r in runs_of),
            "peak_rss_bytes": statistics.median(r["peak_rss_bytes"] for r in runs_of),
            "window_propagations": last["window_propagations"],
            "vertex_pops": last["vertex_pops"],
            "parallel_bands": last.get("parallel_bands", 0),
            "parallel_critical_path": last.get("parallel_critical_path", 0),
            "list_crossings": last.get("list_crossings", 0),
        }
    return results


def phase_split(exactgeo: Path, mesh_path: Path, work: Path, runs: int) -> dict:
    """The phases of a run on 2 threads (--timers), each the median over `runs` runs: what the threads share
    and what stays on one. Keyed by the thread count, as the report reads it."""
    keys = ("propagation_seconds", "window_propagation_seconds", "pruning_seconds", "queue_seconds", "parallel_seconds")
    stats_path = work / "timers-2.json"
    samples = []
    for _ in range(runs):
        run_once([str(exactgeo), "distance", str(mesh_path), "--source", "0", "--quiet", "--timers", "--threads", "2",
                  "--stats", str(stats_path)], stats_path)
        samples.append(json.loads(stats_path.read_text()))
    return {"2": {key: statistics.median(s[key] for s in samples) for key in keys}}


def heat_method(vertices: np.ndarray, faces: np.ndarray, exact: np.ndarray, runs: int) -> dict | None:
    try:
        import potpourri3d
    except ImportError:
        return None
    used, new_index, used_positions, used_triangles = heat_on_used_vertices(vertices, faces)
    start = time.perf_counter()
    solver = potpourri3d.MeshHeatMethodDistanceSolver(used_positions, used_triangles)
    factor_seconds = time.perf_counter() - start
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        on_used = solver.compute_distance(int(new_index[0]))
        times.append(time.perf_counter() - start)
    approximate = np.full(len(vertices), np.inf)
    approximate[used] = on_used
    finite = np.isfinite(exact)
    largest = exact[finite].max()
    error = np.abs(approximate[finite] - exact[finite]) / largest
    return {"factor_seconds": factor_seconds, "solve_seconds": statistics.median(times),
            "max_relative_error": float(error.max()), "mean_relative_error": float(error.mean())}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build-dir", type=Path, default=kBenchDir.parent / "build")
    parser.add_argument("--baseline-build", type=Path, help="build folder of the commit to compare with")
    parser.add_argument("--baseline-name", default="", help="what the baseline is (its commit), for the report")
    parser.add_argument("--meshes", nargs="+", default=kDefaultMeshes)
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--mesh-dir", type=Path, default=kBenchDir.parent.parent / "shared" / "meshes")
    parser.add_argument("--work-dir", type=Path, default=kBenchDir / "work")
    parser.add_argument("--results-dir", type=Path, default=kBenchDir / "results")
    args = parser.parse_args()
    if importlib.util.find_spec("potpourri3d") is None:
        print("potpourri3d is not installed: no heat-method figures (pip install -r bench/requirements.txt)",
              file=sys.stderr, flush=True)
    exactgeo = (args.build_dir / "cli" / "exactgeo").resolve()
    configurations = {"1-thread": (str(exactgeo), ["--threads", "1"]), "2-threads": (str(exactgeo), ["--threads", "2"])}
    if args.baseline_build:  # an older command, without --threads
        configurations = {"baseline": (str((args.baseline_build / "cli" / "exactgeo").resolve()), []), **configurations}
    meshes = select_meshes(args.mesh_dir.resolve(), args.work_dir.resolve(), args.meshes, kSubdivided)
    report = {
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "command": "python3 bench/threads.py --runs " + str(args.runs),
        "baseline": args.baseline_name or (str(args.baseline_build) if args.baseline_build else None),
        "machine": machine_info(),
        "load_average_at_start": os.getloadavg(),
        "meshes": [],
    }
    for mesh in meshes:
        work = args.work_dir.resolve() / "runs" / "threads" / mesh.name
        work.mkdir(parents=True, exist_ok=True)
        results = measure_configurations(configurations, mesh.obj_path, work, args.runs)
        sequential = np.load(work / "1-thread.npy")
        parallel = np.load(work / "2-threads.npy")
        finite = np.isfinite(sequential)
        record = {
            "name": mesh.name, "faces": mesh.face_count, "vertices": mesh.vertex_count,
            "results": results,
            "phases": phase_split(exactgeo, mesh.obj_path, work, args.runs),
            "parallel_vs_sequential_relative_error": float(
                np.abs(parallel[finite] - sequential[finite]).max() / sequential[finite].max()),
            "same_reachability": bool((np.isfinite(parallel) == finite).all()),
            "heat": heat_method(np.load(mesh.vertices_path), np.load(mesh.triangles_path), sequential, args.runs),
        }
        if "baseline" in results:
            baseline = np.load(work / "baseline.npy")
            record["sequential_vs_baseline_relative_error"] = float(
                np.abs(baseline[finite] - sequential[finite]).max() / sequential[finite].max())
        report["meshes"].append(record)
        print(f"{mesh.name}: " + ", ".join(f"{name} {r['propagation_seconds']:.4f} s" for name, r in results.items()),
              flush=True)
    report["load_average_at_end"] = os.getloadavg()
    args.results_dir.mkdir(parents=True, exist_ok=True)
    (args.results_dir / "threads.json").write_text(json.dumps(report, indent=1))
    print(write_markdown(args.results_dir / "threads.md", report))


if __name__ == "__main__":
    main()
