"""One source on every thread count: exactgeo's propagation from one thread to every core, where the threads'
time goes, a build of an earlier commit (the baseline) on the same counts in the same run, and the exact solve
beside the heat method's approximate one. Writes bench/results/NAME.{json,md}.

usage: python3 bench/threads.py [--threads 1 2 4 8 16] [--build-dir build] [--baseline-build DIR]
                                [--meshes stanford-bunny ...] [--runs 5]

It needs the built command, the meshes and numpy (potpourri3d for the heat figures), not the exactgeo package.
Per mesh, one process per run through launch.py, the configurations taking turns in each of --runs rounds so
that a drift in the machine's load hits all alike:
- exactgeo distance MESH --source 0 --quiet --threads T --stats s.json --out d.npy, for every T (1 is always
  run: it is the reference of the speedups and of the distances), and the baseline after each;
- then one run on every T above 1 with --timers: where the threads' time went and the band timeline;
- heat: potpourri3d's MeshHeatMethodDistanceSolver built once (its factorisation, timed apart), then
  compute_distance timed --runs times, with its error against the exact distances.
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib.util
import os
import shutil
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from meshes import BenchMesh, kSubdivided, kSubdividedOptIn, select_meshes_or_exit
from peer_worker import heat_on_used_vertices
from reports.files import finish_report, until_interrupted, write_json
from reports.machine import build_info, report_header
from reports.threads import write_markdown
from solvers.commands import missing_cli_options
from solvers.runner import (
    RunSettings,
    SolverHistory,
    add_build_and_folder_options,
    bench_mesh,
    default_threads,
    launcher_floor_bytes,
)
from solvers.threads import threads_runs

kBenchDir = Path(__file__).resolve().parent
kRepoRoot = kBenchDir.parent
kDefaultMeshes = ["stanford-bunny", "nefertiti", "nefertiti-sub1", "nefertiti-sub2"]


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--name", default="threads", help="results file stem (default: threads)")
    parser.add_argument("--threads", nargs="+", type=int, metavar="T",
                        help=f"thread counts, 1 always among them (default: 1, 2 and every core: {default_threads()})")
    parser.add_argument("--meshes", nargs="+", default=kDefaultMeshes,
                        help=f"mesh names (default: {' '.join(kDefaultMeshes)}; "
                        f"{', '.join(kSubdividedOptIn)} only when named)")
    parser.add_argument("--runs", type=int, default=5, help="rounds of untimed runs; medians reported (default 5)")
    parser.add_argument("--max-repeat-seconds", type=float, default=60.0,
                        help="a run longer than this is not repeated (default 60)")
    parser.add_argument("--timeout", type=float, default=600.0, help="seconds per run (default 600)")
    add_build_and_folder_options(parser)
    args = parser.parse_args(argv)
    args.threads = sorted({1, *(args.threads or default_threads())})
    if args.threads[0] < 1:
        parser.error("--threads: every count must be 1 or more")
    if args.runs < 1:
        parser.error("--runs must be 1 or more")
    # Runs start in their own directories: every path must survive a change of working directory.
    for key in ("build_dir", "mesh_dir", "work_dir", "results_dir"):
        setattr(args, key, getattr(args, key).resolve())
    args.exactgeo = args.build_dir / "cli" / "exactgeo"
    args.baseline_exactgeo = None
    if args.baseline_build:
        args.baseline_build = args.baseline_build.resolve()
        args.baseline_exactgeo = args.baseline_build / "cli" / "exactgeo"
    return args


def heat_method(mesh: BenchMesh, source: int, exact: np.ndarray, runs: int) -> dict | None:
    """potpourri3d's heat method on the mesh, factorised once, then `runs` prefactored solves; None without
    potpourri3d."""
    try:
        import potpourri3d
    except ImportError:
        return None
    vertices, faces = np.load(mesh.vertices_path), np.load(mesh.triangles_path)
    used, new_index, used_positions, used_triangles = heat_on_used_vertices(vertices, faces)
    start = time.perf_counter()
    solver = potpourri3d.MeshHeatMethodDistanceSolver(used_positions, used_triangles)
    factor_seconds = time.perf_counter() - start
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        on_used = solver.compute_distance(int(new_index[source]))
        times.append(time.perf_counter() - start)
    approximate = np.full(len(vertices), np.inf)
    approximate[used] = on_used
    finite = np.isfinite(exact)
    error = np.abs(approximate[finite] - exact[finite]) / exact[finite].max()
    return {"factor_seconds": factor_seconds, "solve_seconds": statistics.median(times),
            "max_relative_error": float(error.max()), "mean_relative_error": float(error.mean())}


def main(argv: list[str] | None = None) -> None:
    args = parse_args(argv)
    if not os.access(args.exactgeo, os.X_OK):
        sys.exit(f"threads.py: no command at {args.exactgeo} (--build-dir)")
    baseline_threads = True
    if args.baseline_exactgeo:
        if not os.access(args.baseline_exactgeo, os.X_OK):
            sys.exit(f"threads.py: no baseline command at {args.baseline_exactgeo} (--baseline-build)")
        # An early build has no --threads: its engine runs on one thread, so it is compared on one thread.
        baseline_threads = not missing_cli_options(args.baseline_exactgeo, ["--threads"])
    if importlib.util.find_spec("potpourri3d") is None:
        print("potpourri3d is not installed: no heat-method figures (pip install -r bench/requirements.txt)",
              file=sys.stderr, flush=True)
    runs = threads_runs(args.threads, args.exactgeo, args.baseline_exactgeo, baseline_threads)
    timed_runs = threads_runs(args.threads, args.exactgeo, timers=True)
    meshes = select_meshes_or_exit("threads.py", args.mesh_dir, args.work_dir, args.meshes, kSubdivided)
    settings = RunSettings(repeat=args.runs, timeout=args.timeout, max_repeat_seconds=args.max_repeat_seconds,
                           sources=1, reference_solvers=("exactgeo-t1",))

    runs_root = args.work_dir / "runs" / args.name
    shutil.rmtree(runs_root, ignore_errors=True)
    args.results_dir.mkdir(parents=True, exist_ok=True)
    report = {
        **report_header(args, "threads.py", argv, launcher_floor_bytes(args.work_dir)),
        "threads": args.threads,
        "baseline": args.baseline_name or (str(args.baseline_build) if args.baseline_build else None),
        "baseline_build": build_info(args.baseline_build) if args.baseline_build else None,
        "meshes": [],
        "records": [],
        "timer_records": [],
    }
    histories = {run.name: SolverHistory() for run in runs + timed_runs}
    with until_interrupted(report):
        for mesh in meshes:
            sources, records = bench_mesh(mesh, runs, histories, settings, runs_root)
            timer_records = bench_mesh(mesh, timed_runs, histories, dataclasses.replace(settings, repeat=1),
                                       runs_root)[1]
            one = runs[0]  # exactgeo on one thread: the reference
            one_ran = next(record for record in records if record["solver"] == one.name)["status"] == "ok"
            heat = heat_method(mesh, sources[0], one.read_distances(one.distances_file(
                runs_root / mesh.name / one.name, sources[0])), args.runs) if one_ran else None
            report["meshes"].append({"name": mesh.name, "path": os.path.relpath(mesh.obj_path, kRepoRoot),
                                     "vertices": mesh.vertex_count, "faces": mesh.face_count, "source": sources[0],
                                     "heat": heat})
            report["records"].extend(records)
            report["timer_records"].extend(timer_records)
            write_json(args.results_dir, report)  # what was measured survives a crash on a later mesh
    json_path, markdown_path = finish_report(args.results_dir, report, write_markdown)
    print(f"\n{markdown_path.read_text()}\nwrote {json_path}, {markdown_path}")


if __name__ == "__main__":
    main()
