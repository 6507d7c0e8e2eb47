"""run.py's report: exactgeo against the peers, as NAME.md and the plots NAME-time.png, NAME-memory.png.

Reads only the report dict run.py writes as NAME.json, so a report can be rewritten from a committed JSON.
"""

from __future__ import annotations

import math
from pathlib import Path

from meshes import kSubdivided
from reports.figures import pyplot, save_figure
from reports.machine import compiler_text, cpu_text, load_text, revision_text, versions_text
from reports.tables import (
    format_bytes,
    format_ratio,
    format_relative_error,
    format_seconds,
    kGiB,
    kMissing,
    markdown_table,
    runs_text,
)

# One shape at growing resolution: each subdivision has 4x the faces of the mesh before it.
kResolutionFamily = ["nefertiti", *kSubdivided]


def format_error(error: dict | None) -> str:
    """A record's error against the reference solver, or why there is none."""
    if not error:
        return kMissing
    if error.get("is_reference"):
        return "reference"
    if "failure" in error:
        return error["failure"]
    return format_relative_error(error["max_relative_error"])


def heading(solver: dict) -> str:
    return solver["name"] + (" †" if solver["build_in_propagation"] else "")


def write_markdown(path: Path, report: dict) -> None:
    records, solvers, meshes = report["records"], report["solvers"], report["meshes"]
    machine, build, software, settings = report["machine"], report["build"], report["software"], report["settings"]
    floor = report["launcher_floor_bytes"]
    records_by_key = {(r["mesh"], r["solver"], r["source_rank"]): r for r in records}

    def record(mesh, solver, rank=0):
        return records_by_key.get((mesh, solver, rank))

    def ok(r):
        return r if r and r["status"] == "ok" else None

    lines = [
        f"# exactgeo benchmark `{report['name']}`",
        "",
        f"{report['date']} · {machine['cpu_model']}, {machine['logical_cores']} logical cores, "
        f"{machine['memory_bytes'] / kGiB:.0f} GiB · load average at start "
        f"{load_text(report['load_average_at_start'])} · exactgeo {revision_text(software)} · `{report['command']}`",
        "",
        "## Ratios to exactgeo",
        "",
        f"First source of each mesh (vertex 0), {runs_text(settings['repeat'])}. Each cell is "
        "**propagation time ÷ exactgeo's** · **peak RSS ÷ exactgeo's**, both from this run; above 1x, exactgeo "
        "is faster or smaller. exactgeo runs on one thread, as the peers do (`threads.md` has two).",
        "",
    ]
    others = [solver for solver in solvers if solver["name"] != "exactgeo"]
    rows = []
    for mesh in meshes:
        ours = ok(record(mesh["name"], "exactgeo"))
        cells = []
        for solver in others:
            theirs = record(mesh["name"], solver["name"])
            if theirs and theirs["status"] != "ok":
                cells.append(theirs["status"])
            elif theirs and ours:
                cells.append(f"{format_ratio(theirs['propagation_seconds'], ours['propagation_seconds'])} · "
                             f"{format_ratio(theirs['peak_rss_bytes'], ours['peak_rss_bytes'])}")
            else:
                cells.append(None)
        rows.append([mesh["name"], mesh["faces"], *cells])
    lines += markdown_table(["mesh", "faces", *(heading(solver) for solver in others)], rows,
                            "lr" + "r" * len(others))

    lines += ["", "## Per mesh and solver, first source", ""]
    rows = []
    for mesh in meshes:
        ours = ok(record(mesh["name"], "exactgeo"))
        for solver in solvers:
            r = record(mesh["name"], solver["name"])
            if r is None:
                continue
            row = [f"{mesh['name']} ({mesh['faces']:,})", heading(solver), len(r["runs"])]
            if r["status"] != "ok":
                rows.append(row + [None] * 9 + [f"{r['status']}: {r['reason']}"])
                continue
            stats, error = r["solver_stats"], r.get("error") or {}
            note = ""
            if "rss_at_start_bytes" in stats:
                note = f"{format_bytes(stats['rss_at_start_bytes'])} before the build (Python, numpy, mesh)"
            rows.append(row + [
                format_seconds(r["build_seconds"]), format_seconds(r["propagation_seconds"]),
                format_ratio(r["propagation_seconds"], ours and ours["propagation_seconds"]),
                format_bytes(r["peak_rss_bytes"], floor),
                format_ratio(r["peak_rss_bytes"], ours and ours["peak_rss_bytes"]),
                stats.get("window_propagations"), stats.get("peak_windows"), format_error(error),
                error.get("reachability_disagreements"), note])
    lines += markdown_table(["mesh", "solver", "runs", "build", "propagation", "÷ exactgeo", "peak RSS", "÷ exactgeo",
                             "window propagations", "peak windows", "max error", "reachability disagreements",
                             "notes"], rows, "llrrrrrrrrrrl")

    if settings["sources"] > 1:
        lines += all_sources_lines(report, record, ok)
    lines += scaling_lines(report)

    lines += ["", "## Solvers", ""]
    lines += [f"- **{solver['name']}**: {solver['label']}." for solver in solvers]
    lines += [
        "",
        "† builds the mesh and propagates in one call: its propagation time includes the mesh build.",
        "",
        "## Machine and software",
        "",
        f"- {cpu_text(machine)}",
        f"- {compiler_text(build)}",
        f"- Python {software['python']}; {versions_text(software)}; CGAL (libcgal-dev) {software['cgal'] or kMissing}",
        f"- caps per run: {settings['timeout']:g} s, {settings['memory_limit_gb']:g} GB of address space; "
        f"peak RSS cannot read below the launcher's {format_bytes(floor)} (values marked ≤ are at that floor)",
        "",
        "bench/README.md says what each column measures and how.",
        "",
    ]
    path.write_text("\n".join(lines))


def all_sources_lines(report: dict, record, ok) -> list[str]:
    """Per mesh and solver over every source: the propagation-time ratio's geometric mean and range, the worst
    error, the reachability disagreements summed. `record` and `ok` look records up as write_markdown does."""
    settings = report["settings"]
    lines = [
        "",
        "## All sources",
        "",
        f"Every source of each mesh ({runs_text(settings['repeat'])} from the first, "
        f"{runs_text(settings['repeat_other'])} from each other): geometric mean and range of the per-source "
        "propagation-time ratio to exactgeo, the worst max error, and the reachability disagreements summed over "
        "the sources.",
        "",
    ]
    rows = []
    for mesh in report["meshes"]:
        for solver in report["solvers"]:
            mine = [r for r in report["records"] if r["mesh"] == mesh["name"] and r["solver"] == solver["name"]
                    and r["status"] == "ok"]
            if not mine:
                continue
            ratios = []
            for r in mine:
                ours = ok(record(mesh["name"], "exactgeo", r["source_rank"]))
                if ours and ours["propagation_seconds"] and r["propagation_seconds"]:
                    ratios.append(r["propagation_seconds"] / ours["propagation_seconds"])
            ratio_text = None
            if ratios:
                mean = math.exp(sum(math.log(ratio) for ratio in ratios) / len(ratios))
                ratio_text = f"{mean:.3g}x ({min(ratios):.3g}–{max(ratios):.3g})"
            errors = [r.get("error") or {} for r in mine]
            relative = [e["max_relative_error"] for e in errors if e.get("max_relative_error") is not None]
            if errors and all(e.get("is_reference") for e in errors):
                worst = "reference"
            else:
                worst = format_relative_error(max(relative)) if relative else None
            disagreements = sum(e.get("reachability_disagreements", 0) for e in errors)
            rows.append([mesh["name"], heading(solver), len(mine), ratio_text, worst, disagreements])
    return lines + markdown_table(["mesh", "solver", "sources", "propagation ÷ exactgeo: mean (min–max)",
                                   "worst max error", "reachability disagreements"], rows, "llrrrr")


def log_log_slope(points: list[tuple[float, float]]) -> float | None:
    """Least-squares slope of log(y) against log(x): the exponent k of y ~ x^k."""
    points = [(math.log(x), math.log(y)) for x, y in points if x and y]
    if len(points) < 2:
        return None
    mean_x = sum(x for x, _ in points) / len(points)
    mean_y = sum(y for _, y in points) / len(points)
    spread = sum((x - mean_x) ** 2 for x, _ in points)
    return sum((x - mean_x) * (y - mean_y) for x, y in points) / spread if spread else None


def scaling_lines(report: dict) -> list[str]:
    """How each solver's propagation time and peak RSS grow with the face count, first source of each mesh."""
    faces = {mesh["name"]: mesh["faces"] for mesh in report["meshes"]}
    lines = [
        "",
        "## Scaling",
        "",
        "Exponent k of a least-squares fit `y ~ faces^k` over every mesh a solver finished (first source), and "
        "the meshes it spans. Peak RSS includes each process's fixed start-up (Python and numpy for the peers), "
        "which flattens the memory exponent on small meshes.",
        "",
    ]
    rows = []
    for solver in report["solvers"]:
        mine = [r for r in report["records"] if r["solver"] == solver["name"] and r["source_rank"] == 0
                and r["status"] == "ok" and r["mesh"] in faces]
        if not mine:
            continue
        sizes = sorted(faces[r["mesh"]] for r in mine)
        slopes = [log_log_slope([(faces[r["mesh"]], r[key]) for r in mine])
                  for key in ("propagation_seconds", "peak_rss_bytes")]
        rows.append([solver["name"], len(mine), f"{sizes[0]:,}–{sizes[-1]:,}",
                     *(None if slope is None else f"{slope:.2f}" for slope in slopes)])
    lines += markdown_table(["solver", "meshes", "faces", "time exponent", "memory exponent"], rows, "lrrrr")

    family = [name for name in kResolutionFamily if name in faces]
    if len(family) > 1:
        lines += [
            "",
            "One shape at growing resolution (each mesh has 4x the faces of the one before): propagation time "
            "and peak RSS.",
            "",
        ]
        rows = []
        for solver in report["solvers"]:
            cells = []
            for name in family:
                r = next((r for r in report["records"] if r["solver"] == solver["name"] and r["mesh"] == name
                          and r["source_rank"] == 0), None)
                ok = r is not None and r["status"] == "ok"
                cells.append(f"{format_seconds(r['propagation_seconds'])} · {format_bytes(r['peak_rss_bytes'])}"
                             if ok else (r["status"] if r else None))
            rows.append([solver["name"], *cells])
        lines += markdown_table(["solver", *(f"{name} ({faces[name]:,})" for name in family)], rows,
                                "l" + "r" * len(family))
    return lines


def write_plots(results_dir: Path, report: dict) -> list[Path]:
    """Log-log, one line per solver through its first-source medians; the approximate solver dashed."""
    plt = pyplot()
    from matplotlib.ticker import FuncFormatter, NullFormatter

    def face_count_text(value, _):
        for factor, suffix in [(1e6, "M"), (1e3, "K")]:
            if value >= factor:
                return f"{value / factor:g}{suffix}"
        return f"{value:g}"

    plots = []
    # (record key, what it is, unit the values are plotted in, tick label)
    quantities = [("propagation_seconds", "propagation time", 1, format_seconds),
                  ("peak_rss_bytes", "peak RSS", 1024**2, lambda megabytes: f"{megabytes:g} MB")]
    for key, quantity, unit, format_value in quantities:
        figure, axes = plt.subplots(figsize=(8, 5.5))
        for solver in report["solvers"]:
            points = sorted((r["faces"], r[key]) for r in report["records"]
                            if r["solver"] == solver["name"] and r["source_rank"] == 0 and r["status"] == "ok"
                            and r.get(key))
            if points:
                faces = [face_count for face_count, _ in points]
                values = [value / unit for _, value in points]
                axes.plot(faces, values, marker="o", linestyle="-" if solver["exact"] else "--",
                          label=solver["name"])
        axes.set_xscale("log")
        axes.set_yscale("log")
        axes.xaxis.set_major_formatter(FuncFormatter(face_count_text))
        axes.yaxis.set_major_formatter(FuncFormatter(lambda value, _, tick_text=format_value: tick_text(value)))
        for axis in (axes.xaxis, axes.yaxis):
            axis.set_minor_formatter(NullFormatter())
        axes.set_xlabel("faces")
        axes.set_ylabel(f"{quantity} (median of runs)")
        axes.set_title(f"{quantity} vs faces, first source of each mesh ({report['name']})")
        axes.grid(True, which="both", alpha=0.3)
        axes.legend()
        path = results_dir / f"{report['name']}-{'time' if key == 'propagation_seconds' else 'memory'}.png"
        plots.append(save_figure(figure, path, dpi=110))
    return plots
