"""Benchmark exactgeo against the geodesic solvers users would pick instead; write JSON, Markdown and plots.

Every run of every solver is a separate process started through launch.py, which measures its peak RSS
and enforces the time and memory caps. See bench/README.md for what is measured and how to read it.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import shutil
import sys
from pathlib import Path

from meshes import kSubdivided, select_meshes_or_exit
from reports.files import finish_report, until_interrupted, write_json
from reports.machine import report_header
from reports.peers import write_markdown, write_plots
from solvers.commands import kSolverNames, make_solvers
from solvers.runner import (
    RunSettings,
    SolverHistory,
    bench_mesh,
    default_memory_limit_gb,
    kDefaultMaxFaces,
    launcher_floor_bytes,
)

kBenchDir = Path(__file__).resolve().parent
kRepoRoot = kBenchDir.parent

kQuickMeshes = ["beetle", "spot", "rocker-arm", "nefertiti"]


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true",
                        help=f"meshes {', '.join(kQuickMeshes)}; 1 source; 3 runs; 60 s timeout")
    parser.add_argument("--name", help="results file stem (default: quick or full)")
    parser.add_argument("--meshes", nargs="+", help="mesh names to run (default: all, or the quick set)")
    parser.add_argument("--solvers", nargs="+", default=kSolverNames,
                        help="solvers to run (default: all)")
    parser.add_argument("--sources", type=int,
                        help="sources per mesh: vertex 0 plus seeded random ones (default 3; quick 1)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the random sources (default 1)")
    parser.add_argument("--repeat", type=int, help="runs per solver from the first source; median reported "
                        "(default 5; quick 3)")
    parser.add_argument("--repeat-other", type=int, default=1,
                        help="runs per solver from the other sources (default 1)")
    parser.add_argument("--max-repeat-seconds", type=float, default=60.0,
                        help="a run longer than this is not repeated (default 60)")
    parser.add_argument("--timeout", type=float, help="seconds per run (default 600; quick 60)")
    parser.add_argument("--memory-limit-gb", type=float,
                        help="address-space limit per run (default: 3/4 of the machine's memory)")
    parser.add_argument("--max-faces", nargs="+", default=[], metavar="SOLVER=N",
                        help="skip SOLVER on meshes with more than N faces (0: no limit); defaults: "
                        + ", ".join(f"{name}={count}" for name, count in kDefaultMaxFaces.items()))
    parser.add_argument("--cgal-once-faces", type=int, default=150_000,
                        help="CGAL runs once (not --repeat times) on meshes above this many faces (default 150000)")
    parser.add_argument("--mesh-dir", type=Path, default=kRepoRoot.parent / "shared" / "meshes",
                        help="the shared OBJ meshes (default: ../shared/meshes beside the repository)")
    parser.add_argument("--build-dir", type=Path, default=kRepoRoot / "build",
                        help="CMake build holding the binaries (default: build/)")
    parser.add_argument("--exactgeo", type=Path, help="exactgeo CLI (default: BUILD_DIR/cli/exactgeo)")
    parser.add_argument("--cgal-driver", type=Path,
                        help="CGAL driver (default: BUILD_DIR/bench/exactgeo_cgal_driver)")
    parser.add_argument("--work-dir", type=Path, default=kBenchDir / "work",
                        help="generated meshes and per-run files (default: bench/work/)")
    parser.add_argument("--results-dir", type=Path, default=kBenchDir / "results",
                        help="where NAME.json, NAME.md and the plots go (default: bench/results/)")
    args = parser.parse_args(argv)

    quick = args.quick
    args.name = args.name or ("quick" if quick else "full")
    args.sources = args.sources or (1 if quick else 3)
    args.repeat = args.repeat or (3 if quick else 5)
    args.timeout = args.timeout or (60.0 if quick else 600.0)
    if args.memory_limit_gb is None:
        args.memory_limit_gb = default_memory_limit_gb()
    # Runs start in their own directories: every path must survive a change of working directory.
    for key in ("build_dir", "mesh_dir", "work_dir", "results_dir"):
        setattr(args, key, getattr(args, key).resolve())
    args.exactgeo = (args.exactgeo or args.build_dir / "cli" / "exactgeo").resolve()
    args.cgal_driver = (args.cgal_driver or args.build_dir / "bench" / "exactgeo_cgal_driver").resolve()
    max_faces = dict(kDefaultMaxFaces)
    for item in args.max_faces:
        name, _, count = item.partition("=")
        if not count.isdigit():
            parser.error(f"--max-faces {item}: expected SOLVER=N")
        max_faces[name] = int(count) or None
    args.max_faces = max_faces
    if quick and not args.meshes:
        args.meshes = kQuickMeshes
    return args


def main(argv: list[str] | None = None) -> None:
    args = parse_args(argv)
    try:
        solvers = make_solvers(args.solvers, args.exactgeo, args.cgal_driver)
    except ValueError as error:
        sys.exit(f"run.py: {error}")
    if importlib.util.find_spec("matplotlib") is None:
        sys.exit("run.py: matplotlib is needed for the plots (pip install -r bench/requirements.txt)")
    meshes = select_meshes_or_exit("run.py", args.mesh_dir, args.work_dir, args.meshes, kSubdivided)
    settings = RunSettings(repeat=args.repeat, timeout=args.timeout, max_repeat_seconds=args.max_repeat_seconds,
                           memory_limit_gb=args.memory_limit_gb, sources=args.sources, seed=args.seed,
                           repeat_other=args.repeat_other, cgal_once_faces=args.cgal_once_faces,
                           max_faces=args.max_faces)

    runs_root = args.work_dir / "runs" / args.name
    shutil.rmtree(runs_root, ignore_errors=True)
    args.results_dir.mkdir(parents=True, exist_ok=True)
    report = {
        **report_header(args, "run.py", argv, launcher_floor_bytes(args.work_dir)),
        "solvers": [{"name": s.name, "label": s.label, "exact": s.exact,
                     "build_in_propagation": s.build_in_propagation} for s in solvers],
        "meshes": [],
        "records": [],
    }
    histories = {solver.name: SolverHistory() for solver in solvers}
    with until_interrupted(report):
        for mesh in meshes:
            sources, records = bench_mesh(mesh, solvers, histories, settings, runs_root)
            report["meshes"].append({"name": mesh.name, "path": os.path.relpath(mesh.obj_path, kRepoRoot),
                                     "vertices": mesh.vertex_count, "faces": mesh.face_count, "sources": sources})
            report["records"].extend(records)
            write_json(args.results_dir, report)
    json_path, markdown_path = finish_report(args.results_dir, report, write_markdown)
    plots = write_plots(args.results_dir, report)
    print(f"\nwrote {json_path}, {markdown_path}, " + ", ".join(str(p) for p in plots))


if __name__ == "__main__":
    main()
