"""Reproduce the shape of the VTP paper's variant comparison and ablations (Qin et al. 2016, Section 6.2).

Runs every algorithm variant (VTP, OPVTP, FTP, OPFTP) and every rule ablation on the shared meshes and the
nefertiti subdivisions, from vertex 0, and writes bench/results/NAME.{json,md} and NAME-*.png:

- Table 3 shape: time, window propagations and peak window memory per variant, and their ratios to VTP;
- Figure 12 shape: time and propagations with and without Rule 1 and Rules 2+3, and the savings;
- the share of prime propagations (inside the newly added triangles) among all window propagations;
- Figure 8 shape: propagation time split into window propagation, pruning and queue management, from
  separate runs with the engine's phase timers on (the timers cost a little, so the timed runs go without);
- an exactness cross-check: every variant's distances against default VTP's.

Every run is its own process started through launch.py (peak RSS, time and memory caps), by the same runner
as run.py's (solvers/runner.py); reports/variants.py writes the report. See bench/README.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
from pathlib import Path

from meshes import kSubdivided, select_meshes
from reports.files import write_json_and_markdown
from reports.machine import report_header
from reports.variants import (
    comparison,
    kPaperClaims,
    kPaperTable3,
    measured,
    paper_table3_summary,
    write_markdown,
    write_plots,
)
from solvers.commands import all_configurations, kReference, missing_cli_options, variant_solver
from solvers.runner import (
    RunSettings,
    SolverHistory,
    bench_variants,
    default_memory_limit_gb,
    exactness_exit_status,
    launcher_floor_bytes,
)

kBenchDir = Path(__file__).resolve().parent
kRepoRoot = kBenchDir.parent

# The full run takes every shared mesh plus nefertiti at 400K and 1.6M faces (kSubdivided; the paper's
# Figure 12 uses 345K and 1.4M faces). The quick run keeps small meshes that finish in seconds.
kQuickMeshes = ["woody", "cow", "spot", "homer", "fandisk"]


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true",
                        help=f"meshes {', '.join(kQuickMeshes)}; 1 run each; a minute or two")
    parser.add_argument("--name", help="results file stem (default: paper, or paper-quick)")
    parser.add_argument("--meshes", nargs="+", help="mesh names (default: every shared mesh and "
                        f"{', '.join(kSubdivided)}; quick: {', '.join(kQuickMeshes)})")
    parser.add_argument("--configurations", nargs="+", metavar="NAME",
                        help="configurations to run, e.g. vtp ftp-no-rule1 (default: all; "
                        f"{kReference} is always run, as the reference)")
    parser.add_argument("--repeat", type=int, help="timed runs per configuration; median reported (default 3; quick 1)")
    parser.add_argument("--max-repeat-seconds", type=float, default=60.0,
                        help="a run longer than this is not repeated (default 60)")
    parser.add_argument("--timeout", type=float, default=600.0, help="seconds per run (default 600)")
    parser.add_argument("--memory-limit-gb", type=float, help="address-space limit per run (default: run.py's)")
    parser.add_argument("--mesh-dir", type=Path, default=kRepoRoot.parent / "shared" / "meshes")
    parser.add_argument("--build-dir", type=Path, default=kRepoRoot / "build")
    parser.add_argument("--exactgeo", type=Path, help="exactgeo CLI (default: BUILD_DIR/cli/exactgeo)")
    parser.add_argument("--work-dir", type=Path, default=kBenchDir / "work")
    parser.add_argument("--results-dir", type=Path, default=kBenchDir / "results")
    args = parser.parse_args(argv)
    args.name = args.name or ("paper-quick" if args.quick else "paper")
    args.repeat = args.repeat or (1 if args.quick else 3)
    for key in ("build_dir", "mesh_dir", "work_dir", "results_dir"):
        setattr(args, key, getattr(args, key).resolve())
    args.exactgeo = (args.exactgeo or args.build_dir / "cli" / "exactgeo").resolve()
    if args.quick and not args.meshes:
        args.meshes = kQuickMeshes
    known = {c.name: c for c in all_configurations()}
    chosen = args.configurations or list(known)
    unknown = set(chosen) - set(known)
    if unknown:
        parser.error(f"unknown configuration(s) {', '.join(sorted(unknown))}; known: {', '.join(known)}")
    args.configurations = [known[name] for name in dict.fromkeys([kReference, *chosen])]
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    if missing := missing_cli_options(args.exactgeo):
        sys.exit(f"paper.py: {args.exactgeo} lacks {', '.join(missing)}: rebuild it (cmake --build build)")
    try:
        meshes = select_meshes(args.mesh_dir, args.work_dir, args.meshes, kSubdivided)
    except ValueError as error:
        sys.exit(f"paper.py: {error}")

    solvers = [variant_solver(c, args.exactgeo) for c in args.configurations]
    timer_solvers = [variant_solver(c, args.exactgeo, timers=True) for c in args.configurations
                     if c.rule1 and c.rule23]
    settings = RunSettings(repeat=args.repeat, timeout=args.timeout, max_repeat_seconds=args.max_repeat_seconds,
                           memory_limit_gb=args.memory_limit_gb or default_memory_limit_gb())
    runs_root = args.work_dir / "runs" / args.name
    args.results_dir.mkdir(parents=True, exist_ok=True)
    report = {**report_header(args, "paper.py", argv, launcher_floor_bytes(args.work_dir)),
              "configurations": [dataclasses.asdict(c) for c in args.configurations],
              "meshes": [], "records": [], "timer_records": []}
    histories = {solver.name: SolverHistory() for solver in solvers + timer_solvers}
    for mesh in meshes:
        timed, timed_once = bench_variants(mesh, solvers, timer_solvers, settings, runs_root, histories)
        report["meshes"].append({"name": mesh.name, "vertices": mesh.vertex_count, "faces": mesh.face_count,
                                 "path": os.path.relpath(mesh.obj_path, kRepoRoot)})
        report["records"] += timed
        report["timer_records"] += timed_once
    report["load_average_at_end"] = os.getloadavg()
    report["comparison"] = comparison(measured(report["records"]), report["meshes"])
    report["paper"] = {"claims": kPaperClaims, "table3": kPaperTable3, **paper_table3_summary()}
    report["plots"] = [str(p) for p in write_plots(args.results_dir, report)]
    json_path, markdown_path = write_json_and_markdown(args.results_dir, report, write_markdown)
    print(f"\nwrote {json_path}, {markdown_path}, " + ", ".join(report["plots"]))
    return exactness_exit_status(report["records"] + report["timer_records"])


if __name__ == "__main__":
    sys.exit(main())
