"""Robustness to triangulation (the shape of Figures 10 and 11 of Qin et al. 2016, Section 6.1).

One smooth shape (meshes.ridged_height over the unit square) at a fixed face count, triangulated with
increasingly stretched triangles; each mesh's anisotropy is measured with the paper's g(M). Our variants and
the benchmark's peers (CGAL, pygeodesic, gdist, the heat method) run from vertex 0 on every mesh, each run its
own process through solvers/runner.py and launch.py (peak RSS, caps). Writes bench/results/NAME.{json,md} and
NAME.png: time and window propagations against g, and VTP's phase times against g (one run with --timers).
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np

from meshes import anisotropy, prepare_anisotropic_meshes, surface_area
from reports.anisotropy import write_markdown, write_plot
from reports.files import write_json_and_markdown
from reports.machine import report_header
from solvers.commands import Configuration, kAlgorithms, kReference, make_solvers, missing_cli_options, variant_solver
from solvers.runner import (
    RunSettings,
    SolverHistory,
    bench_variants,
    default_memory_limit_gb,
    exactness_exit_status,
    launcher_floor_bytes,
)

kBenchDir = Path(__file__).resolve().parent

kPeers = ["cgal", "pygeodesic", "gdist", "heat"]
# Aspect ratio of the grid cells, each cut into two right triangles: 1 gives g(M) ~ 1.39, and g grows about
# as stretch / sqrt(3). The paper uses eight meshes per model.
kStretches = [1, 2, 3, 4, 8, 16, 32, 64]
# The ridges make saddle vertices everywhere: at 60K faces the MMP peers already need 15 s and CGAL 40 s per
# run on the most isotropic mesh, about ten times that on the most stretched one.
kFaces = 20_000
kQuickStretches = [1, 8, 64]
kQuickFaces = 6_000


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true",
                        help=f"{kQuickFaces:,} faces, stretches {kQuickStretches}, 1 run each")
    parser.add_argument("--name", help="results file stem (default: anisotropy, or anisotropy-quick)")
    parser.add_argument("--faces", type=int, help=f"faces per mesh (default {kFaces:,})")
    parser.add_argument("--stretches", type=float, nargs="+", help=f"triangle stretches (default {kStretches})")
    parser.add_argument("--variants", nargs="+", default=kAlgorithms, choices=kAlgorithms,
                        help="our variants, all rules on (default: all)")
    parser.add_argument("--peers", nargs="+", default=kPeers, help=f"run.py's solvers (default: {' '.join(kPeers)})")
    parser.add_argument("--repeat", type=int, help="timed runs per solver; median reported (default 3; quick 1)")
    parser.add_argument("--max-repeat-seconds", type=float, default=10.0,
                        help="a run longer than this is not repeated (default 10: the peers take 5-150 s here, "
                        "where one run is precise enough)")
    parser.add_argument("--timeout", type=float, default=300.0, help="seconds per run (default 300)")
    parser.add_argument("--memory-limit-gb", type=float, help="address-space limit per run (default: run.py's)")
    parser.add_argument("--build-dir", type=Path, default=kBenchDir.parent / "build")
    parser.add_argument("--exactgeo", type=Path, help="exactgeo CLI (default: BUILD_DIR/cli/exactgeo)")
    parser.add_argument("--cgal-driver", type=Path, help="CGAL driver (default: BUILD_DIR/bench/exactgeo_cgal_driver)")
    parser.add_argument("--work-dir", type=Path, default=kBenchDir / "work")
    parser.add_argument("--results-dir", type=Path, default=kBenchDir / "results")
    args = parser.parse_args(argv)
    args.name = args.name or ("anisotropy-quick" if args.quick else "anisotropy")
    args.faces = args.faces or (kQuickFaces if args.quick else kFaces)
    args.stretches = args.stretches or (kQuickStretches if args.quick else kStretches)
    args.repeat = args.repeat or (1 if args.quick else 3)
    for key in ("build_dir", "work_dir", "results_dir"):
        setattr(args, key, getattr(args, key).resolve())
    args.exactgeo = (args.exactgeo or args.build_dir / "cli" / "exactgeo").resolve()
    args.cgal_driver = (args.cgal_driver or args.build_dir / "bench" / "exactgeo_cgal_driver").resolve()
    args.variants = [name for name in kAlgorithms if name in dict.fromkeys([kReference, *args.variants])]
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    if missing := missing_cli_options(args.exactgeo):
        sys.exit(f"anisotropy.py: {args.exactgeo} lacks {', '.join(missing)}: rebuild it (cmake --build build)")
    configurations = [Configuration(name) for name in args.variants]
    try:
        peers = make_solvers(args.peers, args.exactgeo, args.cgal_driver)
    except ValueError as error:
        sys.exit(f"anisotropy.py: {error}")
    solvers = [variant_solver(c, args.exactgeo) for c in configurations] + peers
    timer_solvers = [variant_solver(c, args.exactgeo, timers=True) for c in configurations]
    settings = RunSettings(repeat=args.repeat, timeout=args.timeout, max_repeat_seconds=args.max_repeat_seconds,
                           memory_limit_gb=args.memory_limit_gb or default_memory_limit_gb())
    runs_root = args.work_dir / "runs" / args.name
    args.results_dir.mkdir(parents=True, exist_ok=True)
    report = {**report_header(args, "anisotropy.py", argv, launcher_floor_bytes(args.work_dir)),
              "solvers": [s.name for s in solvers], "meshes": [], "records": [], "timer_records": []}
    histories = {solver.name: SolverHistory() for solver in solvers + timer_solvers}
    for stretch, mesh in zip(args.stretches, prepare_anisotropic_meshes(args.work_dir, args.faces, args.stretches)):
        positions, triangles = np.load(mesh.vertices_path), np.load(mesh.triangles_path)
        g = anisotropy(positions, triangles)
        print(f"\n{mesh.name}: stretch {stretch:g}, g(M) = {g:.3f}", flush=True)
        timed, timed_once = bench_variants(mesh, solvers, timer_solvers, settings, runs_root, histories)
        report["meshes"].append({"name": mesh.name, "stretch": stretch, "g": g, "vertices": mesh.vertex_count,
                                 "faces": mesh.face_count, "area": surface_area(positions, triangles)})
        report["records"] += timed
        report["timer_records"] += timed_once
    report["load_average_at_end"] = os.getloadavg()
    report["plot"] = str(write_plot(args.results_dir, report))
    json_path, markdown_path = write_json_and_markdown(args.results_dir, report, write_markdown)
    print(f"\nwrote {json_path}, {markdown_path}, {report['plot']}")
    return exactness_exit_status(report["records"] + report["timer_records"])


if __name__ == "__main__":
    sys.exit(main())
