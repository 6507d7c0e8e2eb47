"""threads.py's report: one source on every thread count, where the threads' time goes, the baseline, the heat
method beside the exact solve, and what the two-thread run predicts for more threads, as NAME.md."""

from __future__ import annotations

import math
import statistics
from pathlib import Path

from reports.machine import cpu_text, load_text, machine_section, revision_text
from reports.tables import (
    format_percent,
    format_ratio,
    format_relative_error,
    format_seconds,
    markdown_table,
    runs_text,
)

# The prediction's constants, measured on a 16-CPU Xeon VM (16 cores, one thread each, one NUMA node) on the
# bunny, nefertiti and its 400K and 1.6M subdivisions at 2, 4, 8, 12 and 16 threads (test_threads.py holds the
# figures). The threads' busy time grew by 1.20-1.25x per doubling of the threads from two (least squares of
# log busy against log2 threads, per mesh; 1.22 over all four), and the threads were busy 0.90 of their time in
# the shared part on average at 4 threads and more (0.68-1.05 per run, with no trend in the thread count).
kWorkGrowthPerDoubling = 1.22
kEfficiency = 0.90
kPredictedThreads = (4, 8, 16)


def prediction(two: dict, threads: list[int]) -> dict[int, float]:
    """Predicted propagation seconds on each of `threads` (above 2) from a two-thread run with timers on (its
    stats: propagation, parallel, parallel_busy seconds, parallel_critical_path, list_crossings):

        predicted(T) = serial + max(work(T) / (T × kEfficiency), work(T) × critical path / crossings)
        work(T) = busy(2) × kWorkGrowthPerDoubling ^ log2(T / 2)

    serial (propagation − parallel: set-up, gathering the bands, the result) stays as on two threads. work(T)
    is the threads' busy time summed, which grows with the threads (more lists crossed again, more cache lines
    another core wrote, more hand-overs); kEfficiency is the share of their time in the shared part the threads
    are busy rather than joining a band, starved or waiting at its end. The shared part never takes less than
    its critical path: the longest chains of crossings at the mean cost of a crossing. On the 16-CPU
    measurements the prediction is within 28% of every measured time (test_threads.py)."""
    serial = two["propagation_seconds"] - two["parallel_seconds"]
    predicted = {}
    for count in threads:
        work = two["parallel_busy_seconds"] * kWorkGrowthPerDoubling ** math.log2(count / 2)
        chain = work * two["parallel_critical_path"] / max(1, two["list_crossings"])
        predicted[count] = serial + max(work / (count * kEfficiency), chain)
    return predicted


def paired_ratios(one: dict, other: dict) -> list[float]:
    """Each round's one-thread propagation time ÷ the other run's in the same round (the runs take turns, so a
    slow spell of the machine hits both)."""
    return [a["propagation_seconds"] / b["propagation_seconds"] for a, b in zip(one["runs"], other["runs"])
            if "propagation_seconds" in a and "propagation_seconds" in b]


def record(records: list[dict], mesh: str, name: str) -> dict | None:
    """The mesh's record of a configuration, if it ran."""
    return next((r for r in records if r["mesh"] == mesh and r["solver"] == name and r["status"] == "ok"), None)


def thread_word(count: int) -> str:
    return f"{count} thread" + ("" if count == 1 else "s")


def propagation_rows(report: dict, mesh: dict) -> list[list]:
    records, name = report["records"], mesh["name"]
    one = record(records, name, "exactgeo-t1")
    rows = []
    for count in report["threads"]:
        run = record(records, name, f"exactgeo-t{count}")
        baseline = record(records, name, f"baseline-t{count}")
        if run is None:
            continue
        per_round = paired_ratios(one, run) if one and count > 1 else []
        error = run.get("error", {})
        if error.get("is_reference"):
            distances, reachability = "(reference)", None
        else:
            distances = format_relative_error(error.get("max_relative_error"))
            differ = error.get("reachability_disagreements")
            reachability = None if differ is None else "same" if differ == 0 else f"{differ:,} differ"
        rows.append([
            name, str(count), format_seconds(run["propagation_seconds"]),
            format_ratio(one and one["propagation_seconds"], run["propagation_seconds"]),
            f"{statistics.median(per_round):.3g}x ({min(per_round):.3g}–{max(per_round):.3g})" if per_round else None,
            format_seconds(baseline and baseline["propagation_seconds"]),
            format_ratio(baseline and baseline["propagation_seconds"], run["propagation_seconds"]),
            distances, reachability, f"{run['peak_rss_bytes'] / one['peak_rss_bytes']:.2f}" if one else None,
        ])
    return rows


def split_rows(report: dict, mesh: dict) -> list[list]:
    name = mesh["name"]
    one = record(report["records"], name, "exactgeo-t1")
    rows = []
    for count in report["threads"][1:]:
        timed = record(report["timer_records"], name, f"timers-t{count}")
        if timed is None:
            continue
        stats = timed["solver_stats"]
        parallel = stats["parallel_seconds"]
        thread_time = count * parallel
        rows.append([
            name, str(count), format_seconds(timed["propagation_seconds"]),
            format_percent((timed["propagation_seconds"] - parallel) / timed["propagation_seconds"]),
            format_percent(stats["setup_seconds"] / timed["propagation_seconds"]) if "setup_seconds" in stats else None,
            format_percent(stats["parallel_busy_seconds"] / thread_time),
            format_ratio(stats["parallel_busy_seconds"], one and one["propagation_seconds"]),
            format_percent(stats["parallel_starved_seconds"] / thread_time),
            format_percent(stats["parallel_start_seconds"] / thread_time),
            format_percent(stats["parallel_lock_wait_seconds"] / thread_time),
            stats["parallel_lock_waits"],
            format_ratio(stats["list_crossings"], one and one["solver_stats"].get("list_crossings")),
            f"{stats['band_crossings_per_thread']:.3g}" if "band_crossings_per_thread" in stats else None,
            f"{stats['list_crossings'] / max(1, stats['parallel_critical_path']):.0f}",
        ])
    return rows


def heat_rows(report: dict, mesh: dict) -> list[list]:
    heat = mesh["heat"]
    if heat is None:
        return []
    runs = [record(report["records"], mesh["name"], f"exactgeo-t{count}") for count in report["threads"]]
    return [[mesh["name"], format_seconds(heat["factor_seconds"]), format_seconds(heat["solve_seconds"]),
             format_relative_error(heat["max_relative_error"]), format_relative_error(heat["mean_relative_error"]),
             *(f"{run['propagation_seconds'] / heat['solve_seconds']:.2f}" if run else None for run in runs)]]


def prediction_rows(report: dict, mesh: dict) -> list[list]:
    name = mesh["name"]
    one = record(report["records"], name, "exactgeo-t1")
    two = record(report["timer_records"], name, "timers-t2")
    if one is None or two is None:
        return []
    counts = sorted(set(kPredictedThreads) | {count for count in report["threads"] if count > 2})
    predicted = prediction({**two["solver_stats"], "propagation_seconds": two["propagation_seconds"]}, counts)
    rows = []
    for count in counts:
        measured = record(report["records"], name, f"exactgeo-t{count}")
        measured_seconds = measured and measured["propagation_seconds"]
        rows.append([name, str(count), format_seconds(predicted[count]),
                     format_ratio(one["propagation_seconds"], predicted[count]), format_seconds(measured_seconds),
                     format_ratio(one["propagation_seconds"], measured_seconds),
                     format_ratio(predicted[count], measured_seconds)])
    return rows


def write_markdown(path: Path, report: dict) -> None:
    threads = report["threads"]
    lines = [
        "# One source on every thread count",
        "",
        f"{report['date']} · {cpu_text(report['machine'])} · exactgeo {revision_text(report['software'])} · "
        f"`{report['command']}` · {runs_text(report['settings']['runs'])} · baseline: "
        f"{report['baseline'] or 'none'} · load average {load_text(report['load_average_at_start'])} at the start",
        "",
        "## Propagation",
        "",
        "`propagation_seconds` (reading and building the mesh excluded) from the source vertex, median over the "
        "rounds, the configurations taking turns in each. Ratios are how many times faster. *Per round*: each "
        "round's one-thread time ÷ that round's time on T threads, their median and range. Distances: max |d_T − "
        "d_1| over the vertices reached, relative to the largest one-thread distance, and whether the same "
        "vertices are reached.",
        "",
    ]
    rows = [row for mesh in report["meshes"] for row in propagation_rows(report, mesh)]
    lines += markdown_table(["mesh", "threads", "propagation", "vs 1 thread", "per round", "baseline",
                             "vs baseline", "distances vs 1 thread", "reachability", "peak RSS ÷ 1 thread"], rows,
                            "lrrrrrrrlr")
    left_out = [f"{r['mesh']} {r['solver']}: {r['reason']}" for r in report["records"] + report["timer_records"]
                if r["status"] != "ok"]
    if left_out:
        lines += ["", "Left out: " + "; ".join(left_out) + "."]

    lines += ["", "## Where the threads' time goes", "",
              "One run per thread count with `--timers` (the timers cost a little, so these runs are apart). "
              "*Serial*: (propagation − `parallel_seconds`) ÷ propagation, what runs on one thread (set-up, "
              "gathering each band, the result); *of which set-up*: `setup_seconds` ÷ propagation, the run's "
              "arrays written before the first band (their first touch of fresh memory, on the threads). Of the "
              "threads' time in the shared part (T × `parallel_seconds`): "
              "*busy* (`parallel_busy_seconds`, the thread efficiency), *starved* (out of lists, waiting to be "
              "handed some), *start* (from a band's start until a thread joined it) and *lock wait* (spinning on "
              "a face's or vertex's lock, part of busy); the rest is the wait at the bands' ends. *Work ÷ 1 "
              "thread*: the busy time summed over the threads ÷ the one-thread propagation time; above 1 the "
              "threads together do more than one thread alone. *Crossed ÷ 1 thread*: list crossings ÷ one "
              "thread's (lists crossed again because windows joined them meanwhile). *Crossings per band per "
              "thread*: the median over the bands of a band's crossings ÷ T. *Crossings per step*: crossings ÷ "
              "the critical path, the parallelism the bands offer.", ""]
    rows = [row for mesh in report["meshes"] for row in split_rows(report, mesh)]
    lines += markdown_table(["mesh", "threads", "propagation, timers on", "serial", "of which set-up", "busy",
                             "work ÷ 1 thread", "starved", "start", "lock wait", "lock waits", "crossed ÷ 1 thread",
                             "crossings per band per thread", "crossings per step"], rows, "lrrrrrrrrrrrrr")

    lines += ["", "## Exact against the heat method", "",
              "potpourri3d's MeshHeatMethodDistanceSolver, factorised once (not counted in its solve), then the "
              "prefactored solve from the same vertex, median of the runs; its error against the exact distances "
              "relative to the largest. The last columns: the exact propagation on T threads ÷ the heat solve "
              "(below 1: the exact solve takes less time).", ""]
    missing = [mesh["name"] for mesh in report["meshes"] if mesh["heat"] is None]
    if missing:
        lines += [f"No heat figures for {', '.join(missing)}: potpourri3d was not installed "
                  "(`pip install -r bench/requirements.txt`).", ""]
    rows = [row for mesh in report["meshes"] for row in heat_rows(report, mesh)]
    lines += markdown_table(["mesh", "heat: factorise", "heat: solve", "heat error, max", "heat error, mean",
                             *(f"exact {thread_word(count)} ÷ heat" for count in threads)], rows,
                            "lrrrr" + "r" * len(threads))

    lines += ["", "## More threads, predicted from two", "",
              "From the two-thread run with timers: what runs on one thread stays; the threads' busy time grows "
              f"{kWorkGrowthPerDoubling}x per doubling of the threads and they are busy {kEfficiency:.0%} of their "
              "time in the shared part (both measured on a 16-CPU machine), and the shared part takes no less than "
              "its critical path (`reports/threads.py`, `prediction`). *Predicted ÷ measured* where that count ran.",
              ""]
    rows = [row for mesh in report["meshes"] for row in prediction_rows(report, mesh)]
    lines += markdown_table(["mesh", "threads", "predicted", "predicted vs 1 thread", "measured",
                             "measured vs 1 thread", "predicted ÷ measured"], rows, "lrrrrrr")
    lines += ["", *machine_section(report)]
    path.write_text("\n".join(lines))
