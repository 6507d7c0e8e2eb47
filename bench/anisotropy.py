"""Robustness to triangulation (the shape of Figures 10 and 11 of Qin et al. 2016, Section 6.1).

One smooth shape (meshes.ridged_height over the unit square) at a fixed face count, triangulated with
increasingly stretched triangles; each mesh's anisotropy is measured with the paper's g(M). Our variants and
the benchmark's peers (CGAL, pygeodesic, gdist, the heat method) run from vertex 0 on every mesh, each run its
own process through run.py's runner and launch.py (peak RSS, caps). Writes bench/results/NAME.{json,md} and
NAME.png: time and window propagations against g, and VTP's phase times against g (one run with --timers).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

import numpy as np

import paper
import run
from meshes import anisotropy, prepare_anisotropic_meshes

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


def parse_args(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true",
                        help=f"{kQuickFaces:,} faces, stretches {kQuickStretches}, 1 run each")
    parser.add_argument("--name", help="results file stem (default: anisotropy, or anisotropy-quick)")
    parser.add_argument("--faces", type=int, help=f"faces per mesh (default {kFaces:,})")
    parser.add_argument("--stretches", type=float, nargs="+", help=f"triangle stretches (default {kStretches})")
    parser.add_argument("--variants", nargs="+", default=paper.kAlgorithms, choices=paper.kAlgorithms,
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
    args.variants = [name for name in paper.kAlgorithms if name in dict.fromkeys([paper.kReference, *args.variants])]
    return args


def peer_solvers(args) -> list[run.Solver]:
    run_args = paper.runner_args(args, args.repeat, args.peers)
    run_args.cgal_driver = args.cgal_driver
    return run.make_solvers(run_args)


def surface_area(positions: np.ndarray, triangles: np.ndarray) -> float:
    corners = positions[triangles]
    return float(0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]),
                                      axis=1).sum())


def table_by_solver(records: list[dict]) -> dict[tuple[str, str], dict]:
    return {(r["mesh"], r["solver"]): r for r in records}


def growth(records_by_key: dict, meshes: list[dict], solver: str, key) -> float | None:
    """A quantity on the most anisotropic mesh ÷ on the least, for one solver (None unless both ran)."""
    first, last = (records_by_key.get((meshes[i]["name"], solver)) for i in (0, -1))
    if not (first and last and first["status"] == "ok" and last["status"] == "ok"):
        return None
    return paper.ratio(key(last), key(first))


def propagations(record: dict) -> int | None:
    return record["solver_stats"].get("window_propagations")


def write_markdown(path: Path, report: dict) -> None:
    meshes, solvers = report["meshes"], report["solvers"]
    records = table_by_solver(report["records"])
    timers = table_by_solver(report["timer_records"])
    ours = [name for name in solvers if name in paper.kAlgorithms]
    lines = [
        "# Robustness to anisotropic triangulation",
        "",
        f"{report['date']} · {report['machine']['cpu_model']}, {report['machine']['logical_cores']} logical cores · "
        f"exactgeo {report['software']['exactgeo_revision'] or '(no commit)'} · `{report['command']}` · "
        f"{run.runs_text(report['settings']['repeat'])} per solver, source vertex 0",
        "",
        "The shape of Figures 10 and 11 of Qin et al. 2016: one smooth shape (ridges and a bump on the unit "
        f"square, `bench/meshes.py`) with about {report['settings']['faces']:,} faces, on grids whose cells are "
        "`stretch` times longer along x than along y, each cut into two right triangles; the surface area "
        "column shows the shape stays the same. Anisotropy g(M) is the mean over faces of P·H / (2√3·S) (P half-perimeter, "
        "H longest edge, S area), 1 for equilateral triangles. Times are each solver's propagation time "
        "(bench/README.md says what that covers for each), median over the runs.",
        "",
        "## Propagation time against anisotropy",
        "",
        "| stretch | faces | area | g(M) | " + " | ".join(solvers) + " |",
        "|---:|---:|---:|---:|" + "---:|" * len(solvers),
    ]
    for mesh in meshes:
        cells = []
        for solver in solvers:
            record = records.get((mesh["name"], solver))
            if record is None:
                cells.append("—")
            elif record["status"] != "ok":
                cells.append(record["status"])
            else:
                cells.append(run.format_seconds(record["propagation_seconds"]))
        lines.append(f"| {mesh['stretch']:g} | {mesh['faces']:,} | {mesh['area']:.5f} | {mesh['g']:.2f} | "
                     + " | ".join(cells) + " |")
    growth_cells = [paper.times(growth(records, meshes, s, lambda r: r["propagation_seconds"])) for s in solvers]
    lines += [f"| **growth** | | | {meshes[0]['g']:.2f} → {meshes[-1]['g']:.2f} | " + " | ".join(growth_cells) + " |",
              "", "growth: time on the most anisotropic mesh ÷ time on the least.", ""]

    lines += ["## Window propagations and peak windows (our variants)", "",
              "| stretch | g(M) | " + " | ".join(f"{name}: propagations · peak windows" for name in ours) + " |",
              "|---:|---:|" + "---:|" * len(ours)]
    for mesh in meshes:
        cells = []
        for name in ours:
            record = records.get((mesh["name"], name))
            ok = record and record["status"] == "ok"
            cells.append(f"{run.format_count(propagations(record))} · "
                         f"{run.format_count(record['solver_stats'].get('peak_windows'))}" if ok else "—")
        lines.append(f"| {mesh['stretch']:g} | {mesh['g']:.2f} | " + " | ".join(cells) + " |")
    growth_cells = [paper.times(growth(records, meshes, name, propagations)) for name in ours]
    lines += ["| **growth** | | " + " | ".join(growth_cells) + " |", ""]

    lines += ["## Phases of VTP against anisotropy (Figure 11 shape)", "",
              "One run per mesh with the phase timers on; bench/results/paper.md says what each phase covers.", "",
              "| stretch | g(M) | propagation time | " + " | ".join(label for _, label in paper.kPhases) + " |",
              "|---:|---:|---:|" + "---:|" * len(paper.kPhases)]
    for mesh in meshes:
        record = timers.get((mesh["name"], f"{paper.kReference}+timers"))
        if not record or record["status"] != "ok":
            continue
        stats = record["solver_stats"]
        lines.append(f"| {mesh['stretch']:g} | {mesh['g']:.2f} | {run.format_seconds(record['propagation_seconds'])} | "
                     + " | ".join(run.format_seconds(stats.get(key)) for key, _ in paper.kPhases) + " |")
    lines.append("")

    lines += paper.exactness_lines(report["records"] + report["timer_records"],
                                   solvers + [f"{name}+timers" for name in ours])
    lines += ["Our variants are judged; for the peers the column is information (the heat method is approximate). "
              "Errors against CGAL, where it ran, are in the JSON (`error`).", ""]
    failed = [r for r in report["records"] if r["status"] != "ok"]
    if failed:
        lines += ["## Runs that did not finish", ""]
        lines += [f"- {r['mesh']} {r['solver']}: {r['status']}: {r['reason']}" for r in failed] + [""]
    lines += [f"Plot: `{Path(report['plot']).name}`.", ""]
    lines += paper.machine_lines(report)
    path.write_text("\n".join(lines))


def write_plot(results_dir: Path, report: dict) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    meshes, solvers = report["meshes"], report["solvers"]
    records = table_by_solver(report["records"])
    timers = table_by_solver(report["timer_records"])
    g = [mesh["g"] for mesh in meshes]
    figure, ((time_axes, relative_axes), (count_axes, phase_axes)) = plt.subplots(2, 2, figsize=(12, 9))

    def series(solver, key):
        points = [(mesh["g"], key(records[(mesh["name"], solver)])) for mesh in meshes
                  if (mesh["name"], solver) in records and records[(mesh["name"], solver)]["status"] == "ok"]
        return [x for x, _ in points], [y for _, y in points]

    for solver in solvers:
        style = {"marker": "o", "linestyle": "-" if solver in paper.kAlgorithms else "--", "label": solver}
        x, y = series(solver, lambda r: r["propagation_seconds"])
        time_axes.plot(x, y, **style)
        if y:
            relative_axes.plot(x, [value / y[0] for value in y], **style)
        if solver in paper.kAlgorithms:
            x, y = series(solver, propagations)
            count_axes.plot(x, y, **style)
    time_axes.set(yscale="log", ylabel="propagation time (s)", title="time against anisotropy (Figure 10)")
    relative_axes.set(yscale="log", ylabel="time ÷ time on the most isotropic mesh",
                      title="growth of time with anisotropy")
    count_axes.set(ylabel="window propagations", title="window propagations (our variants)")
    for key, label in paper.kPhases:
        points = [(mesh["g"], timers[(mesh["name"], f"{paper.kReference}+timers")]["solver_stats"].get(key))
                  for mesh in meshes if (mesh["name"], f"{paper.kReference}+timers") in timers
                  and timers[(mesh["name"], f"{paper.kReference}+timers")]["status"] == "ok"]
        phase_axes.plot([x for x, _ in points], [y for _, y in points], marker="o", label=label)
    phase_axes.set(ylabel="seconds (run with timers on)", title="VTP's phases against anisotropy (Figure 11)")
    for axes in (time_axes, relative_axes, count_axes, phase_axes):
        axes.set_xscale("log")
        axes.set_xlabel("anisotropy g(M)")
        axes.set_xticks(g, [f"{value:.2g}" for value in g], rotation=45)
        axes.minorticks_off()
        axes.grid(True, alpha=0.3)
        axes.legend(fontsize="small")
    figure.suptitle(f"ridged square, ~{report['settings']['faces']:,} faces, stretched triangles, source vertex 0")
    return run.save_figure(figure, results_dir / f"{report['name']}.png")


def main(argv=None) -> int:
    args = parse_args(argv)
    if missing := paper.missing_cli_options(args.exactgeo):
        sys.exit(f"anisotropy.py: {args.exactgeo} lacks {', '.join(missing)}: rebuild it (cmake --build build)")
    configurations = [paper.Configuration(name) for name in args.variants]
    solvers = [paper.variant_solver(c, args.exactgeo) for c in configurations] + peer_solvers(args)
    timer_solvers = [paper.variant_solver(c, args.exactgeo, timers=True) for c in configurations]
    runs_root = args.work_dir / "runs" / args.name
    args.results_dir.mkdir(parents=True, exist_ok=True)
    report = {**paper.report_header(args, args.name), "solvers": [s.name for s in solvers],
              "meshes": [], "records": [], "timer_records": []}
    histories = {solver.name: run.SolverHistory() for solver in solvers + timer_solvers}
    for stretch, mesh in zip(args.stretches, prepare_anisotropic_meshes(args.work_dir, args.faces, args.stretches)):
        positions, triangles = np.load(mesh.vertices_path), np.load(mesh.triangles_path)
        g = anisotropy(positions, triangles)
        print(f"\n{mesh.name}: stretch {stretch:g}, g(M) = {g:.3f}", flush=True)
        timed, timed_once = paper.bench_variants(mesh, solvers, timer_solvers, args, runs_root, histories)
        report["meshes"].append({"name": mesh.name, "stretch": stretch, "g": g, "vertices": mesh.vertex_count,
                                 "faces": mesh.face_count, "area": surface_area(positions, triangles)})
        report["records"] += timed
        report["timer_records"] += timed_once
    report["load_average_at_end"] = os.getloadavg()
    report["plot"] = str(write_plot(args.results_dir, report))
    json_path = args.results_dir / f"{args.name}.json"
    json_path.write_text(json.dumps(report, indent=1))
    markdown_path = args.results_dir / f"{args.name}.md"
    write_markdown(markdown_path, report)
    print(f"\nwrote {json_path}, {markdown_path}, {report['plot']}")
    failures = paper.exactness_failures(report["records"] + report["timer_records"])
    for failure in failures:
        print(f"EXACTNESS MISMATCH: {failure}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
