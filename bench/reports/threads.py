"""threads.py's report: one source on one and two threads against a baseline build and the heat method, as
threads.md."""

from __future__ import annotations

from pathlib import Path

from reports.tables import markdown_table

kPredictedThreads = (8, 16)


def ratio(numerator: float | None, denominator: float | None) -> str:
    if not numerator or not denominator:
        return "—"
    return f"{numerator / denominator:.2f}x"


def seconds(value: float | None) -> str:
    return "—" if value is None else f"{value:.4f} s"


def prediction(mesh: dict) -> dict[int, float]:
    """Predicted propagation time on p threads, from the 2-thread run: what stays on one thread, plus the
    part the threads share (its wall time times 2: the work of both) divided by p, but never below the
    critical path's share of that work (its crossings in a row, at the mean cost of a crossing)."""
    two = mesh["phases"]["2"]
    counts = mesh["results"]["2-threads"]
    alone = two["propagation_seconds"] - two["parallel_seconds"]
    shared = 2 * two["parallel_seconds"]
    chain = shared * counts["parallel_critical_path"] / max(1, counts["list_crossings"])
    return {p: alone + max(shared / p, chain) for p in kPredictedThreads}


def write_markdown(path: Path, report: dict) -> str:
    """Writes the report and returns its text (the script also prints it)."""
    machine = report["machine"]
    baseline = report["baseline"]
    lines = [
        "# One source on one and two threads",
        "",
        f"{report['date']} · {machine['cpu_model']}, {machine['logical_cores']} logical cores · "
        f"`{report['command']}` · baseline: {baseline or 'none'} · load average "
        f"{', '.join(f'{v:.2f}' for v in report['load_average_at_start'])} at the start, "
        f"{', '.join(f'{v:.2f}' for v in report['load_average_at_end'])} at the end",
        "",
        "Propagation time (`propagation_seconds`: reading and building the mesh excluded) from vertex 0, median "
        "over the runs, the configurations run in turn. Ratios are how many times faster.",
        "",
    ]
    rows = []
    for mesh in report["meshes"]:
        r = mesh["results"]
        base, one, two = r.get("baseline", {}), r["1-thread"], r["2-threads"]
        rows.append([mesh["name"], f"{mesh['faces']:,}",
                     f"{base['window_propagations']:,}" if base else "—", f"{one['window_propagations']:,}",
                     seconds(base.get("propagation_seconds")), seconds(one["propagation_seconds"]),
                     seconds(two["propagation_seconds"]),
                     ratio(base.get("propagation_seconds"), one["propagation_seconds"]),
                     ratio(one["propagation_seconds"], two["propagation_seconds"]),
                     ratio(base.get("propagation_seconds"), two["propagation_seconds"]),
                     f"{two['peak_rss_bytes'] / one['peak_rss_bytes']:.2f}"])
    lines += markdown_table(["mesh", "faces", "propagations, baseline", "propagations", "baseline", "1 thread",
                             "2 threads", "1 thread vs baseline", "2 threads vs 1", "2 threads vs baseline",
                             "peak RSS, 2 threads ÷ 1"], rows, "lrrrrrrrrrr")
    lines += ["", "Distances: " + "; ".join(
        f"{m['name']} 2 threads vs 1: {m['parallel_vs_sequential_relative_error']:.1e} of the largest"
        + ("" if m["same_reachability"] else " (REACHABILITY DIFFERS)")
        + (f", 1 thread vs baseline: {m['sequential_vs_baseline_relative_error']:.1e}"
           if "sequential_vs_baseline_relative_error" in m else "")
        for m in report["meshes"]) + ".", ""]

    lines += ["## Exact against the heat method", "",
              "potpourri3d's MeshHeatMethodDistanceSolver, factorised once (not counted in its solve), then one "
              "solve from vertex 0; its error against the exact distances, relative to the largest distance.", ""]
    missing = [mesh["name"] for mesh in report["meshes"] if mesh["heat"] is None]
    if missing:
        lines += [f"No heat figures for {', '.join(missing)}: potpourri3d was not installed "
                  "(`pip install -r bench/requirements.txt`).", ""]
    rows = []
    for mesh in report["meshes"]:
        heat = mesh["heat"]
        if heat is None:
            continue
        one, two = mesh["results"]["1-thread"], mesh["results"]["2-threads"]
        rows.append([mesh["name"], seconds(heat["factor_seconds"]), seconds(heat["solve_seconds"]),
                     seconds(one["propagation_seconds"]), seconds(two["propagation_seconds"]),
                     f"{one['propagation_seconds'] / heat['solve_seconds']:.2f}",
                     f"{two['propagation_seconds'] / heat['solve_seconds']:.2f}",
                     f"{heat['max_relative_error']:.1e}", f"{heat['mean_relative_error']:.1e}"])
    lines += markdown_table(["mesh", "heat: factorise", "heat: solve", "exact, 1 thread", "exact, 2 threads",
                             "exact 1 thread ÷ heat solve", "exact 2 threads ÷ heat solve", "heat error, max",
                             "heat error, mean"], rows, "lrrrrrrrr")

    lines += ["", "## Available parallelism", "",
              "The parallel engine advances the wavefront by bands of about half an edge length; the threads "
              "share each band's vertices and the list crossings they set off, a crossing often waiting for "
              "another that reaches its list. The critical path is the longest such chain in each band, summed "
              "over the bands; crossings per step of it are the width. The prediction takes the 2-thread run "
              "apart (--timers): what stays on one thread (setting the run up, gathering each band's vertices, "
              "writing the result) stays; the shared part (twice its wall time is the work of both threads) is divided by "
              "the thread count. It assumes the threads keep as busy and the locks stay as cheap with more "
              "threads, and no band waits longer than its critical path, so it is an upper bound on the gain.", ""]
    rows = []
    for mesh in report["meshes"]:
        two = mesh["results"]["2-threads"]
        one = mesh["results"]["1-thread"]
        predicted = prediction(mesh)
        phases_two = mesh["phases"]["2"]
        rows.append([mesh["name"], f"{two['vertex_pops'] / max(1, two['parallel_bands']):.0f}",
                     f"{two['parallel_critical_path']:,}",
                     f"{two['list_crossings'] / max(1, two['parallel_critical_path']):.0f}",
                     f"{1 - phases_two['parallel_seconds'] / phases_two['propagation_seconds']:.0%}",
                     *(f"{one['propagation_seconds'] / predicted[p]:.1f}x" for p in kPredictedThreads)])
    lines += markdown_table(["mesh", "vertices per band", "critical path (crossings)", "crossings per step",
                             "share on one thread (2 threads)",
                             *(f"predicted {p} threads vs 1" for p in kPredictedThreads)], rows, "lrrrrrr")
    lines.append("")
    text = "\n".join(lines)
    path.write_text(text)
    return text
