"""The whole `exactgeo distance` command, from the mesh file to the distances written, split into its steps, beside
what users run instead, end to end from the same OBJ file; writes bench/results/NAME.{json,md}.

Per mesh and thread count (1, 2 and every core by default), one process per run through launch.py:
  exactgeo distance MESH --source 0 --out d.npy --stats s.json --threads T
its wall time and peak RSS, split into start, read, build, solve and write by its --stats (solvers/end_to_end.py
says how); with --baseline-build, an earlier build on the same thread counts in the same run, for before/after
ratios per step. Beside it, each peer as its own process (peer_worker.py --obj), reading the OBJ with
potpourri3d.read_mesh, building its solver, solving once from the same vertex and writing its distances:
potpourri3d's heat method (the factorisation is its build), pygeodesic and gdist (one call builds and solves).
A peer that is not installed is skipped with a note. See bench/README.md.
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
from pathlib import Path

from meshes import kSubdivided, kSubdividedOptIn, select_meshes_or_exit
from reports.end_to_end import write_markdown
from reports.files import finish_report, until_interrupted, write_json
from reports.machine import build_info, report_header
from solvers.commands import missing_cli_options
from solvers.end_to_end import add_steps, configuration, kPeerReader, kPeers, whole_runs
from solvers.runner import (
    RunSettings,
    SolverHistory,
    add_build_and_folder_options,
    bench_mesh,
    default_memory_limit_gb,
    default_threads,
    launcher_floor_bytes,
)

kBenchDir = Path(__file__).resolve().parent
kRepoRoot = kBenchDir.parent

kDefaultMeshes = ["stanford-bunny", "nefertiti", "nefertiti-sub1", "nefertiti-sub2"]
kSolvers = ["exactgeo", *kPeers]


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--name", default="end-to-end", help="results file stem (default: end-to-end)")
    parser.add_argument("--meshes", nargs="+", default=kDefaultMeshes,
                        help=f"mesh names (default: {' '.join(kDefaultMeshes)}; "
                        f"{', '.join(kSubdividedOptIn)} only when named)")
    parser.add_argument("--threads", nargs="+", type=int, metavar="T",
                        help=f"exactgeo's thread counts (default: 1, 2 and every core: {default_threads()})")
    parser.add_argument("--solvers", nargs="+", default=kSolvers, help=f"of {' '.join(kSolvers)} (default: all)")
    parser.add_argument("--repeat", type=int, default=3, help="runs per configuration; medians reported (default 3)")
    parser.add_argument("--max-repeat-seconds", type=float, default=60.0,
                        help="a run longer than this is not repeated (default 60)")
    parser.add_argument("--timeout", type=float, default=600.0, help="seconds per run (default 600)")
    parser.add_argument("--memory-limit-gb", type=float,
                        help="address-space limit per run (default: 3/4 of the machine's memory)")
    add_build_and_folder_options(parser, exactgeo_option=True)
    args = parser.parse_args(argv)
    args.threads = sorted(set(args.threads or default_threads()))
    if args.threads[0] < 1:
        parser.error("--threads: every count must be 1 or more")
    if args.repeat < 1:
        parser.error("--repeat must be 1 or more")
    if unknown := set(args.solvers) - set(kSolvers):
        parser.error(f"unknown solver(s) {', '.join(sorted(unknown))}; choose from {', '.join(kSolvers)}")
    # Runs start in their own directories: every path must survive a change of working directory.
    for key in ("build_dir", "mesh_dir", "work_dir", "results_dir"):
        setattr(args, key, getattr(args, key).resolve())
    args.exactgeo = (args.exactgeo or args.build_dir / "cli" / "exactgeo").resolve()
    args.baseline_exactgeo = None
    if args.baseline_build:
        args.baseline_build = args.baseline_build.resolve()
        args.baseline_exactgeo = args.baseline_build / "cli" / "exactgeo"
    if args.memory_limit_gb is None:
        args.memory_limit_gb = default_memory_limit_gb()
    return args


def main(argv: list[str] | None = None) -> None:
    args = parse_args(argv)
    baseline_threads = True
    if args.baseline_exactgeo:
        if not os.access(args.baseline_exactgeo, os.X_OK):
            sys.exit(f"end_to_end.py: no baseline command at {args.baseline_exactgeo} (--baseline-build)")
        # An early build has no --threads: its engine runs on one thread, so it is compared on one thread.
        baseline_threads = not missing_cli_options(args.baseline_exactgeo, ["--threads"])
    runs = whole_runs(args.solvers, args.threads, args.exactgeo, args.baseline_exactgeo, baseline_threads)
    meshes = select_meshes_or_exit("end_to_end.py", args.mesh_dir, args.work_dir, args.meshes, kSubdivided)
    # Errors are against the current build on the fewest threads (the baseline's where only it ran).
    kinds = {run.name: configuration(run)["kind"] for run in runs}
    references = [name for name, kind in kinds.items() if kind == "exactgeo"]
    references += [name for name, kind in kinds.items() if kind == "baseline"]
    settings = RunSettings(repeat=args.repeat, timeout=args.timeout, max_repeat_seconds=args.max_repeat_seconds,
                           memory_limit_gb=args.memory_limit_gb, sources=1, reference_solvers=tuple(references))

    runs_root = args.work_dir / "runs" / args.name
    shutil.rmtree(runs_root, ignore_errors=True)
    args.results_dir.mkdir(parents=True, exist_ok=True)
    report = {
        **report_header(args, "end_to_end.py", argv, launcher_floor_bytes(args.work_dir)),
        "baseline": args.baseline_name or (str(args.baseline_build) if args.baseline_build else None),
        "baseline_build": build_info(args.baseline_build) if args.baseline_build else None,
        "peer_reader": kPeerReader,
        "configurations": [configuration(run) for run in runs],
        "meshes": [],
        "records": [],
    }
    histories = {run.name: SolverHistory() for run in runs}
    with until_interrupted(report):
        for mesh in meshes:
            sources, records = bench_mesh(mesh, runs, histories, settings, runs_root)
            add_steps(records)
            report["meshes"].append({"name": mesh.name, "path": os.path.relpath(mesh.obj_path, kRepoRoot),
                                     "vertices": mesh.vertex_count, "faces": mesh.face_count, "source": sources[0]})
            report["records"].extend(records)
            write_json(args.results_dir, report)  # what was measured survives a crash on a later mesh
    json_path, markdown_path = finish_report(args.results_dir, report, write_markdown)
    print(f"\n{markdown_path.read_text()}\nwrote {json_path}, {markdown_path}")


if __name__ == "__main__":
    main()
