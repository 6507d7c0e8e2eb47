"""Queries at any surface point after one run (GeodesicOptions::keep_windows): what keeping the windows costs
and how fast the points are answered. Writes bench/results/NAME.{json,md}.

usage: python3 bench/queries.py [--meshes spot homer stanford-bunny nefertiti] [--points 1000000] [--runs 3]

It needs the built command (peak memory) and the exactgeo package (times). Per mesh, from vertex 0 on one
thread, the configurations taking turns in each of --runs rounds so that a drift in the machine's load hits
all alike:
- peak RSS: `exactgeo distance MESH --source 0 --threads 1 --out d.npy`, one process per run through
  launch.py, and the same with `--query-points` (1,000 random points) and `--query-out`: what keeping the
  windows adds to a whole process;
- in one process: GeodesicSolver.solve from vertex 0 without and with keep_windows (the run's time, the kept
  windows and their bytes from its stats), then distance_at on --points random points inside faces, one
  call: points answered per second of CPU time (the call runs on one core), from the numpy arrays to the
  distances.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import exactgeo
from reports.files import finish_report
from reports.machine import report_header
from reports.queries import write_markdown
from solvers.runner import launcher_floor_bytes

kBenchDir = Path(__file__).resolve().parent
kRepoRoot = kBenchDir.parent
kDefaultMeshes = ["spot", "homer", "stanford-bunny", "nefertiti"]
kFilePoints = 1000  # points the command reads and answers in the memory runs


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--name", default="queries", help="results file stem (default: queries)")
    parser.add_argument("--meshes", nargs="+", default=kDefaultMeshes, help="shared mesh names")
    parser.add_argument("--points", type=int, default=1_000_000, help="points per distance_at call (default 1e6)")
    parser.add_argument("--runs", type=int, default=3, help="rounds; medians reported (default 3)")
    parser.add_argument("--build-dir", type=Path, default=kRepoRoot / "build")
    parser.add_argument("--mesh-dir", type=Path, default=kRepoRoot.parent / "shared" / "meshes")
    parser.add_argument("--results-dir", type=Path, default=kBenchDir / "results")
    parser.add_argument("--work-dir", type=Path, default=kBenchDir / "work" / "queries")
    return parser.parse_args(argv)


def random_points(mesh: exactgeo.Mesh, count: int, seed: int) -> exactgeo.SurfacePoints:
    """Uniform in a random face each: faces uniformly, barycentric coordinates uniformly on the triangle."""
    rng = np.random.default_rng(seed)
    return exactgeo.SurfacePoints(rng.integers(0, mesh.face_count, count), rng.dirichlet((1, 1, 1), count))


def peak_rss(args: argparse.Namespace, command: list[str], label: str) -> int:
    report = args.work_dir / f"{label}.launch.json"
    subprocess.run([sys.executable, "-I", "-S", str(kBenchDir / "launch.py"), str(report), "600", "0", "--",
                    *command], check=True, stdout=subprocess.DEVNULL)
    outcome = json.loads(report.read_text())
    if outcome["exit_code"] != 0:
        raise RuntimeError(f"{' '.join(command)} failed: {outcome}")
    return outcome["peak_rss_bytes"]


def bench_mesh(args: argparse.Namespace, name: str) -> dict:
    path = args.mesh_dir / f"{name}.obj"
    mesh = exactgeo.Mesh.load(path)
    points = random_points(mesh, args.points, seed=35)
    points_file = args.work_dir / f"{name}-points.txt"
    file_points = random_points(mesh, kFilePoints, seed=36)
    points_file.write_text("".join(f"{face}:{','.join(repr(float(c)) for c in weights)}\n"
                                   for face, weights in zip(file_points.faces, file_points.barycentric)))
    cli = args.build_dir / "cli" / "exactgeo"
    ordinary = [str(cli), "distance", str(path), "--source", "0", "--threads", "1", "--quiet",
                "--out", str(args.work_dir / "d.npy")]
    keeping = [*ordinary, "--query-points", str(points_file), "--query-out", str(args.work_dir / "q.npy")]
    solver = exactgeo.GeodesicSolver(mesh)
    measured: dict[str, list[float]] = {key: [] for key in ("rss", "rss_keep", "solve", "solve_keep", "query")}
    for _ in range(args.runs):
        measured["rss"].append(peak_rss(args, ordinary, "ordinary"))
        measured["rss_keep"].append(peak_rss(args, keeping, "keeping"))
        measured["solve"].append(solver.solve(0, threads=1).stats.propagation_seconds)
        stats = solver.solve(0, threads=1, keep_windows=True).stats
        measured["solve_keep"].append(stats.propagation_seconds)
        start = time.process_time()  # one core's time: the calling thread answers the points
        distances = solver.distance_at(points)
        measured["query"].append(time.process_time() - start)
    median = {key: statistics.median(values) for key, values in measured.items()}
    record = {
        "mesh": name,
        "faces": mesh.face_count,
        "kept_windows": stats.kept_windows,
        "kept_window_bytes": stats.kept_window_bytes,
        "peak_rss_bytes": median["rss"],
        "peak_rss_keep_bytes": median["rss_keep"],
        "solve_seconds": median["solve"],
        "solve_keep_seconds": median["solve_keep"],
        "points": args.points,
        "query_seconds": median["query"],
        "unreached_points": int(np.count_nonzero(np.isinf(distances))),
    }
    print(f"{name}: {stats.kept_window_bytes / mesh.face_count:.0f} bytes per face, peak RSS x"
          f"{median['rss_keep'] / median['rss']:.2f}, {args.points / median['query'] / 1e6:.2f}M points/s",
          flush=True)
    return record


def main(argv: list[str] | None = None) -> None:
    args = parse_args(argv)
    args.work_dir.mkdir(parents=True, exist_ok=True)
    report = report_header(args, "queries.py", argv, launcher_floor_bytes(args.work_dir))
    report["meshes"] = [bench_mesh(args, name) for name in args.meshes]
    args.results_dir.mkdir(parents=True, exist_ok=True)
    json_path, markdown_path = finish_report(args.results_dir, report, write_markdown)
    print(f"wrote {json_path} and {markdown_path}")


if __name__ == "__main__":
    main()
