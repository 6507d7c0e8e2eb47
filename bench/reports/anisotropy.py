"""anisotropy.py's report: time, window propagations and VTP's phases against the triangles' anisotropy g(M)
(the shape of Figures 10 and 11 of Qin et al. 2016), as NAME.md and NAME.png."""

from __future__ import annotations

from pathlib import Path

from reports.figures import pyplot, save_figure
from reports.machine import machine_section, run_line
from reports.tables import format_count, format_seconds, format_times, markdown_table, ratio
from reports.variants import exactness_lines, kPhases
from solvers.commands import kAlgorithms, kReference

kTimersSolver = f"{kReference}+timers"  # the run of VTP with its phase timers on


def table_by_solver(records: list[dict]) -> dict[tuple[str, str], dict]:
    return {(r["mesh"], r["solver"]): r for r in records}


def growth(records_by_key: dict, meshes: list[dict], solver: str, key) -> float | None:
    """A quantity on the most anisotropic mesh ÷ on the least, for one solver (None unless both ran)."""
    first, last = (records_by_key.get((meshes[i]["name"], solver)) for i in (0, -1))
    if not (first and last and first["status"] == "ok" and last["status"] == "ok"):
        return None
    return ratio(key(last), key(first))


def propagations(record: dict) -> int | None:
    return record["solver_stats"].get("window_propagations")


def propagation_seconds(record: dict) -> float | None:
    return record["propagation_seconds"]


def write_markdown(path: Path, report: dict) -> None:
    meshes, solvers = report["meshes"], report["solvers"]
    records = table_by_solver(report["records"])
    timers = table_by_solver(report["timer_records"])
    ours = [name for name in solvers if name in kAlgorithms]
    lines = [
        "# Robustness to anisotropic triangulation",
        "",
        run_line(report, "solver"),
        "",
        "The shape of Figures 10 and 11 of Qin et al. 2016: one smooth shape (ridges and a bump on the unit "
        f"square, `bench/meshes.py`) with about {report['settings']['faces']:,} faces, on grids whose cells are "
        "`stretch` times longer along x than along y, each cut into two right triangles; the surface area "
        "column shows the shape stays the same. Anisotropy g(M) is the mean over faces of P·H / (2√3·S) "
        "(P half-perimeter, H longest edge, S area), 1 for equilateral triangles. Times are each solver's "
        "propagation time (bench/README.md says what that covers for each), median over the runs.",
        "",
        "## Propagation time against anisotropy",
        "",
    ]
    rows = []
    for mesh in meshes:
        cells = []
        for solver in solvers:
            record = records.get((mesh["name"], solver))
            if record is None:
                cells.append(None)
            elif record["status"] != "ok":
                cells.append(record["status"])
            else:
                cells.append(format_seconds(record["propagation_seconds"]))
        rows.append([f"{mesh['stretch']:g}", mesh["faces"], f"{mesh['area']:.5f}", f"{mesh['g']:.2f}", *cells])
    rows.append(["**growth**", "", "", f"{meshes[0]['g']:.2f} → {meshes[-1]['g']:.2f}",
                 *(format_times(growth(records, meshes, s, propagation_seconds)) for s in solvers)])
    lines += markdown_table(["stretch", "faces", "area", "g(M)", *solvers], rows, "rrrr" + "r" * len(solvers))
    lines += ["", "growth: time on the most anisotropic mesh ÷ time on the least.", ""]

    lines += ["## Window propagations and peak windows (our variants)", ""]
    rows = []
    for mesh in meshes:
        cells = []
        for name in ours:
            record = records.get((mesh["name"], name))
            ok = record and record["status"] == "ok"
            cells.append(f"{format_count(propagations(record))} · "
                         f"{format_count(record['solver_stats'].get('peak_windows'))}" if ok else None)
        rows.append([f"{mesh['stretch']:g}", f"{mesh['g']:.2f}", *cells])
    rows.append(["**growth**", "", *(format_times(growth(records, meshes, name, propagations)) for name in ours)])
    lines += markdown_table(["stretch", "g(M)", *(f"{name}: propagations · peak windows" for name in ours)], rows,
                            "rr" + "r" * len(ours))
    lines.append("")

    lines += ["## Phases of VTP against anisotropy (Figure 11 shape)", "",
              "One run per mesh with the phase timers on; bench/results/paper.md says what each phase covers.", ""]
    rows = []
    for mesh in meshes:
        record = timers.get((mesh["name"], kTimersSolver))
        if not record or record["status"] != "ok":
            continue
        stats = record["solver_stats"]
        rows.append([f"{mesh['stretch']:g}", f"{mesh['g']:.2f}", format_seconds(record["propagation_seconds"]),
                     *(format_seconds(stats.get(key)) for key, _ in kPhases)])
    lines += markdown_table(["stretch", "g(M)", "propagation time", *(label for _, label in kPhases)], rows,
                            "rrr" + "r" * len(kPhases))
    lines.append("")

    lines += exactness_lines(report["records"] + report["timer_records"],
                             solvers + [f"{name}+timers" for name in ours])
    lines += ["Our variants are judged; for the peers the column is information (the heat method is approximate). "
              "Errors against CGAL, where it ran, are in the JSON (`error`).", ""]
    failed = [r for r in report["records"] if r["status"] != "ok"]
    if failed:
        lines += ["## Runs that did not finish", ""]
        lines += [f"- {r['mesh']} {r['solver']}: {r['status']}: {r['reason']}" for r in failed] + [""]
    lines += [f"Plot: `{Path(report['plot']).name}`.", ""]
    lines += machine_section(report)
    path.write_text("\n".join(lines))


def write_plot(results_dir: Path, report: dict) -> Path:
    """NAME.png: time, its growth and window propagations against g, and VTP's phase times against g."""
    plt = pyplot()
    meshes, solvers = report["meshes"], report["solvers"]
    records = table_by_solver(report["records"])
    timers = table_by_solver(report["timer_records"])
    g = [mesh["g"] for mesh in meshes]
    figure, ((time_axes, relative_axes), (count_axes, phase_axes)) = plt.subplots(2, 2, figsize=(12, 9))

    def series(records_by_key, solver, key):
        points = [(mesh["g"], key(records_by_key[(mesh["name"], solver)])) for mesh in meshes
                  if (mesh["name"], solver) in records_by_key
                  and records_by_key[(mesh["name"], solver)]["status"] == "ok"]
        return [x for x, _ in points], [y for _, y in points]

    for solver in solvers:
        style = {"marker": "o", "linestyle": "-" if solver in kAlgorithms else "--", "label": solver}
        x, y = series(records, solver, propagation_seconds)
        time_axes.plot(x, y, **style)
        if y:
            relative_axes.plot(x, [value / y[0] for value in y], **style)
        if solver in kAlgorithms:
            count_axes.plot(*series(records, solver, propagations), **style)
    time_axes.set(yscale="log", ylabel="propagation time (s)", title="time against anisotropy (Figure 10)")
    relative_axes.set(yscale="log", ylabel="time ÷ time on the most isotropic mesh",
                      title="growth of time with anisotropy")
    count_axes.set(ylabel="window propagations", title="window propagations (our variants)")
    for key, label in kPhases:
        phase_axes.plot(*series(timers, kTimersSolver, lambda record, key=key: record["solver_stats"].get(key)),
                        marker="o", label=label)
    phase_axes.set(ylabel="seconds (run with timers on)", title="VTP's phases against anisotropy (Figure 11)")
    for axes in (time_axes, relative_axes, count_axes, phase_axes):
        axes.set_xscale("log")
        axes.set_xlabel("anisotropy g(M)")
        axes.set_xticks(g, [f"{value:.2g}" for value in g], rotation=45)
        axes.minorticks_off()
        axes.grid(True, alpha=0.3)
        axes.legend(fontsize="small")
    figure.suptitle(f"ridged square, ~{report['settings']['faces']:,} faces, stretched triangles, source vertex 0")
    return save_figure(figure, results_dir / f"{report['name']}.png")
