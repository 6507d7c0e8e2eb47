"""end_to_end.py's report: the whole `exactgeo distance` command split into its steps, against the peers' whole
scripts and an earlier build, as NAME.md.

Everything here reads the JSON alone: each record's median steps (`steps`), wall time and peak RSS, as
solvers/end_to_end.py and the runner left them.
"""

from __future__ import annotations

from pathlib import Path

from reports.machine import compiler_text, load_text, machine_section, run_line
from reports.tables import (
    format_bytes,
    format_percent,
    format_ratio,
    format_relative_error,
    format_seconds,
    kMissing,
    markdown_table,
)

kStepHeaders = {"start": "start + other", "read": "read", "build": "build", "solve": "solve", "write": "write"}

# What each peer's steps are, and what falls in its start (static text: the commands are peer_worker.py's).
kPeerSteps = {
    "heat": "build: `MeshHeatMethodDistanceSolver(V, F)` (intrinsic Delaunay mesh, Laplacian factorisations); "
            "solve: `compute_distance` (dropping the vertices no face uses, which geometry-central rejects, is in "
            "its start + other)",
    "pygeodesic": "build: `PyGeodesicAlgorithmExact(V, F)`; solve: `geodesicDistances` to every vertex",
    "gdist": "`compute_gdist` builds and solves in one call: its build is inside its solve",
}


def ok_records(report: dict) -> dict[tuple[str, str], dict]:
    """(mesh, configuration name) -> the record of every configuration that ran."""
    return {(r["mesh"], r["solver"]): r for r in report["records"] if r["status"] == "ok"}


def of_kind(report: dict, kind: str) -> list[dict]:
    return [c for c in report["configurations"] if c["kind"] == kind]


def baseline_of(report: dict, current: dict) -> dict | None:
    """The baseline configuration run beside `current`: on as many threads, or on one without --threads."""
    for baseline in of_kind(report, "baseline"):
        if baseline["threads"] == current["threads"] or (baseline["threads"] is None and current["threads"] == 1):
            return baseline
    return None


def run_text(configuration: dict) -> str:
    """A run in the tables: exactgeo's with its build and threads, a peer by its name (the runs section says
    what it is)."""
    return configuration["name"] if configuration["kind"] == "peer" else configuration["label"]


def threads_text(report: dict, configuration: dict) -> str:
    count = configuration["threads"]
    if count is None:
        return "(no --threads)"
    return f"{count} (every core)" if count == report["machine"]["logical_cores"] and count > 1 else str(count)


def step_cell(record: dict, configuration: dict, step: str) -> str:
    """A step's median, or where that time went when the process does not time the step apart."""
    value = record["steps"][step]
    if value is not None:
        return format_seconds(value)
    if step == "build" and configuration["build_in_propagation"]:
        return "in solve"
    if step == "write" and record.get("build_counts_read"):
        return "in start"
    return kMissing


def headline_lines(report: dict, records: dict) -> list[str]:
    peers, has_baseline = of_kind(report, "peer"), bool(of_kind(report, "baseline"))
    lines = ["## exactgeo against the peers, end to end", "",
             "exactgeo's whole command, wall time divided by each peer's whole script's (below 1: exactgeo's takes "
             "less time; 0.25 is a quarter of the peer's)"
             + (", and the baseline's divided by exactgeo's (above 1: the current build is faster)" if has_baseline
                else "") + ". Medians of each, from the same run.", ""]
    rows = []
    for mesh in report["meshes"]:
        for current in of_kind(report, "exactgeo"):
            record = records.get((mesh["name"], current["name"]))
            if record is None:
                continue
            wall = record["wall_seconds"]
            row = [mesh["name"], f"{mesh['faces']:,}", threads_text(report, current)]
            row += [format_ratio(wall, records[(mesh["name"], p["name"])]["wall_seconds"])
                    if (mesh["name"], p["name"]) in records else None for p in peers]
            if has_baseline:
                baseline = baseline_of(report, current)
                before = records.get((mesh["name"], baseline["name"])) if baseline else None
                row.append(format_ratio(before["wall_seconds"], wall) if before else None)
            rows.append(row)
    header = ["mesh", "faces", "threads", *(f"exactgeo ÷ {p['name']}" for p in peers)]
    header += ["baseline ÷ exactgeo"] if has_baseline else []
    return lines + markdown_table(header, rows, "lrl" + "r" * (len(header) - 3)) + [""]


def steps_lines(report: dict, records: dict) -> list[str]:
    lines = ["## Where the time goes", "",
             "Each step's median over the runs (taken on its own, so the steps need not add up to the median wall). "
             "read, build, solve and write are the process's own clocks: exactgeo's `--stats` (`read_seconds`, "
             "`build_seconds`, `propagation_seconds`, `write_seconds`), the peers' around their calls; start + other "
             "is the rest of the process's wall time: starting it and loading its code, what it does between the "
             "steps, its teardown. Outside the solve: 1 − solve ÷ wall.", ""]
    rows = []
    for mesh in report["meshes"]:
        for configuration in report["configurations"]:
            record = records.get((mesh["name"], configuration["name"]))
            if record is None:
                continue
            steps = record["steps"]
            rows.append([mesh["name"], run_text(configuration),
                         *(step_cell(record, configuration, step) for step in kStepHeaders),
                         format_seconds(record["wall_seconds"]),
                         format_percent(1 - steps["solve"] / record["wall_seconds"]),
                         format_bytes(record["peak_rss_bytes"], report["launcher_floor_bytes"])])
    lines += markdown_table(["mesh", "run", *kStepHeaders.values(), "wall", "outside the solve", "peak RSS"], rows,
                            "ll" + "r" * 8)
    older = [build for kind, build in (("exactgeo", "the current build"), ("baseline", "the baseline"))
             if any(records.get((mesh["name"], c["name"]), {}).get("build_counts_read")
                    for c in of_kind(report, kind) for mesh in report["meshes"])]
    if older:
        lines += ["", f"The stats of {' and of '.join(older)} have no `write_seconds`: there `build_seconds` counts "
                  "from the start, read included, so the build here is `build_seconds` − `read_seconds`, and the "
                  "write is in start + other."]
    return lines + [""]


def before_after_lines(report: dict, records: dict) -> list[str]:
    if not of_kind(report, "baseline"):
        return []
    lines = ["## Before and after, per step", "",
             f"The baseline ({report['baseline']}) divided by the current build, step by step (above 1: the current "
             "build is faster); peak RSS the other way round, now ÷ before (below 1: less memory now).", ""]
    rows = []
    for mesh in report["meshes"]:
        for current in of_kind(report, "exactgeo"):
            baseline = baseline_of(report, current)
            now = records.get((mesh["name"], current["name"]))
            before = records.get((mesh["name"], baseline["name"])) if baseline else None
            if now is None or before is None:
                continue
            rows.append([mesh["name"], threads_text(report, current),
                         *(format_ratio(before["steps"][step], now["steps"][step]) for step in kStepHeaders),
                         format_ratio(before["wall_seconds"], now["wall_seconds"]),
                         format_ratio(now["peak_rss_bytes"], before["peak_rss_bytes"])])
    return lines + markdown_table(["mesh", "threads", *kStepHeaders.values(), "wall", "peak RSS, now ÷ before"],
                                  rows, "ll" + "r" * 7) + [""]


def build_timings_lines(report: dict, records: dict) -> list[str]:
    """The build's own steps (`build_timings` in the stats), where the builds report them."""
    timed = [c for c in report["configurations"] if c["kind"] != "peer" and any(
        records.get((mesh["name"], c["name"]), {}).get("build_timings") for mesh in report["meshes"])]
    if not timed:
        return []
    lines = ["## The mesh build's steps", "",
             "`build_timings` from `--stats`, each step's median over the runs; the last row per mesh is the whole "
             "build, as in the table above.", ""]
    rows = []
    for mesh in report["meshes"]:
        timings = {c["name"]: (records.get((mesh["name"], c["name"])) or {}).get("build_timings") or {} for c in timed}
        for step in dict.fromkeys(step for steps in timings.values() for step in steps):
            rows.append([mesh["name"], step, *(format_seconds(timings[c["name"]].get(step)) for c in timed)])
        rows.append([mesh["name"], "build", *(format_seconds(records[(mesh["name"], c["name"])]["steps"]["build"])
                                              if (mesh["name"], c["name"]) in records else None for c in timed)])
    return lines + markdown_table(["mesh", "step", *(run_text(c) for c in timed)], rows, "ll" + "r" * len(timed)) + [""]


def distances_lines(report: dict) -> list[str]:
    names = {c["name"]: run_text(c) for c in report["configurations"]}
    rows = []
    for record in report["records"]:
        error = record.get("error")
        if record["status"] != "ok" or not error or error.get("is_reference"):
            continue
        run, reference = names[record["solver"]], names[error["reference"]]
        if "failure" in error:
            rows.append([record["mesh"], run, reference, error["failure"], None])
            continue
        rows.append([record["mesh"], run, reference, format_relative_error(error["max_relative_error"]),
                     error["reachability_disagreements"]])
    if not rows:
        return []
    return ["## Distances", "",
            "Each run's distances against the reference run's on the same mesh: the largest difference relative to "
            "the largest distance, and the vertices one calls unreachable and the other does not. The heat method "
            "is approximate.", ""] + markdown_table(
        ["mesh", "run", "reference", "max difference", "reachability disagreements"], rows, "lllrr") + [""]


def left_out_lines(report: dict) -> list[str]:
    names = {c["name"]: run_text(c) for c in report["configurations"]}
    rows = [[r["mesh"], names[r["solver"]], r["status"], r["reason"]] for r in report["records"] if r["status"] != "ok"]
    if not rows:
        return []
    return ["## Runs left out", ""] + markdown_table(["mesh", "run", "", "why"], rows, "llll") + [""]


def runs_lines(report: dict) -> list[str]:
    lines = ["## The runs", "",
             "- exactgeo: `exactgeo distance MESH --source 0 --out d.npy --stats s.json --threads T`, as its own "
             "process through `bench/launch.py` (peak RSS from `wait4`); the baseline the same with its own build."]
    for configuration in of_kind(report, "peer"):
        lines.append(f"- {configuration['name']}: {configuration['label']}; `bench/peer_worker.py --obj`: read: "
                     f"`{report['peer_reader']}` (every peer reads the OBJ with it); "
                     f"{kPeerSteps.get(configuration['name'], '')}; write: `np.save` of the distances.")
    return lines + [""]


def write_markdown(path: Path, report: dict) -> str:
    """Writes the report and returns its text."""
    records = ok_records(report)
    lines = ["# The whole command, end to end", "",
             run_line(report, "configuration") + f" · baseline: {report['baseline'] or 'none'} · load average "
             f"{load_text(report['load_average_at_start'])} at the start", ""]
    if report.get("interrupted"):
        lines += ["**Interrupted**: the meshes measured before it.", ""]
    lines += headline_lines(report, records)
    lines += steps_lines(report, records)
    lines += before_after_lines(report, records)
    lines += build_timings_lines(report, records)
    lines += distances_lines(report)
    lines += left_out_lines(report)
    lines += runs_lines(report)
    lines += machine_section(report)
    if report.get("baseline_build"):
        lines[-1:-1] = [f"- baseline: {compiler_text(report['baseline_build'])}"]
    text = "\n".join(lines)
    path.write_text(text)
    return text
