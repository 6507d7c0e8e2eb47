"""distributed_matrix.py's report: distance matrices on one and two Dask workers into Zarr stores, the overhead
per block, the workers' memory, nefertiti's all-pairs store and the 160K-vertex extrapolation, as distributed.md.

Every section is written only when the report holds its measurements: --nefertiti-all-pairs alone makes a
report of the whole store only, --memory-only one of the workers' memory only.
"""

from __future__ import annotations

from pathlib import Path
from statistics import median

from reports.machine import cpu_text, load_text, revision_text
from reports.tables import (
    format_bytes,
    format_percent,
    format_seconds,
    format_times,
    kMissing,
    markdown_table,
    runs_text,
)

kTargetSpeedup = 1.85
# What distributed_matrix.py measures, in its order: Dask on 1 and 2 workers, then in-process on 1 and 2 threads.
kConfigurations = ["dask, 1 worker", "dask, 2 workers", "in-process, 1 thread", "in-process, 2 threads"]


def duration(seconds: float | None) -> str:
    """format_seconds up to two minutes, then minutes up to two hours, then hours."""
    if seconds is None or seconds < 120:
        return format_seconds(seconds)
    if seconds < 7200:
        return f"{seconds / 60:.3g} min"
    return f"{seconds / 3600:.3g} h"


def bandwidth(bytes_per_second: float) -> str:
    return f"{format_bytes(bytes_per_second)}/s"


def speedup_section(report: dict) -> list[str]:
    workloads = report["workloads"]
    lines = ["## One worker against two", "",
             "Wall time of `distance_matrix_to_zarr` into a fresh float32 store with the library's default blocks "
             "(store creation and the mesh's scatter included, the cluster's start not), on a LocalCluster of 1 and "
             "of 2 single-threaded worker processes, beside the in-process `exactgeo.distance_matrix` on 1 and 2 "
             f"threads; {runs_text(report['settings']['runs'])}, the four configurations taken in turn.", ""]
    rows = []
    for w in workloads:
        wall = w["median_wall_seconds"]
        rows.append([w["label"], w["mesh"], w["vertices"], f"{w['sources']:,} × {w['targets']:,}",
                     f"{w['blocks']} × {w['block_rows']}", *(format_seconds(wall[c]) for c in kConfigurations),
                     format_times(w["dask_speedup"]), format_times(w["in_process_speedup"]),
                     format_times(wall["dask, 1 worker"] / wall["in-process, 1 thread"])])
    lines += markdown_table(["workload", "mesh", "vertices", "sources × targets", "blocks × rows", *kConfigurations,
                             "2 workers vs 1", "2 threads vs 1", "1 worker ÷ in-process 1 thread"], rows,
                            "llrrrrrrrrrr")
    met = [w["label"] for w in workloads if w["dask_speedup"] >= kTargetSpeedup]
    lines += ["", f"Target: 2 workers at least {kTargetSpeedup}x faster than 1. Met by: {', '.join(met) or 'none'}. "
              "The last store of each workload holds the in-process matrix rounded to float32: "
              + ", ".join(f"{w['label']} {'yes' if w['store_equals_in_process'] else 'NO'}" for w in workloads)
              + ".", ""]
    return lines


def overhead_section(report: dict) -> list[str]:
    lines = ["## Scheduler overhead per block", "",
             "Overhead per block = (wall time × workers − the sum of the blocks' own seconds) / blocks, a block's "
             "own seconds being what its marker records (its rows computed, rounded and written into the store). It "
             "charges to the blocks everything else the workers' time went to: the scheduler, the mesh's scatter, "
             "the store's creation, idle workers at the end. The tiny blocks are one row each on a "
             f"{report['tiny_blocks']['vertices']}-vertex torus on 2 workers: their work is trivial, so their "
             "overhead is the scheduler's and the store's per block.", ""]
    rows = []
    for w in report["workloads"]:
        for c in kConfigurations[:2]:
            work = median(s["block_seconds_sum"] for s in w["samples"][c]) / w["blocks"]
            overhead = w["overhead_per_block_seconds"][c]
            rows.append([w["label"], w["blocks"], format_seconds(work), format_seconds(overhead), c[len("dask, "):],
                         format_percent(overhead / work)])
    tiny = report["tiny_blocks"]
    rows.append(["tiny blocks", tiny["blocks"], format_seconds(tiny["block_seconds_mean"]),
                 format_seconds(tiny["overhead_per_block_seconds"]), "2 workers", kMissing])
    lines += markdown_table(["workload", "blocks", "one block's own seconds (mean)", "overhead per block",
                             "cluster", "overhead ÷ work"], rows, "lrrrlr")
    return lines + [""]


def memory_section(report: dict) -> list[str]:
    workloads = report["workloads"]
    measured = ("Each run computes the first "
                + ", ".join(f"{w['blocks_measured']} blocks of the {w['label']} layout" for w in workloads)
                + " (a worker's peak comes with its first blocks; no time is measured). "
                if "blocks_measured" in workloads[0] else "")
    lines = ["## Peak memory per worker", "",
             "Growth = a worker process's peak RSS during the run (VmHWM, reset before it) less its RSS at that point "
             "(the baseline: the worker started, exactgeo, numpy, zarr and dask imported, and a tiny store of two "
             "one-row blocks written by the worker itself, so that what a first write imports or sets up once is "
             "in the baseline, as any worker pays it); the largest over the workers, median over the runs. "
             f"{measured}It is compared with one block as stored (float32) plus the mesh (its arrays and the RSS "
             "building the Mesh adds to a fresh process); target: at most 1. A block's rows are computed straight "
             "into its float32 chunk and written from it, so the block is held once; what comes on top is the "
             "engine's working memory (the RSS one row of `distance_matrix` adds to a fresh process holding the "
             "mesh: the solver's buffers, proportional to the mesh, and its windows) and dask's state of the tasks.",
             ""]
    rows = []
    for w in workloads:
        for c in kConfigurations[:2]:
            m = w["memory"][c]
            block_and_mesh_bytes = w["block_float32_bytes"] + w["mesh_bytes"] + w["engine_bytes"]
            rows.append([w["label"], w["mesh"], c[len("dask, "):], format_bytes(m["worker_baseline_rss_bytes"]),
                         format_bytes(m["worker_peak_rss_bytes"]), format_bytes(m["worker_growth_bytes"]),
                         format_bytes(w["block_float32_bytes"]), format_bytes(w["mesh_bytes"]),
                         format_bytes(w["engine_bytes"]), f"{m['growth_vs_block_and_mesh']:.2f}",
                         f"{m['worker_growth_bytes'] / block_and_mesh_bytes:.2f}"])
    lines += markdown_table(["workload", "mesh", "cluster", "baseline RSS", "peak RSS", "growth", "block (float32)",
                             "mesh", "engine's working memory", "growth ÷ (block + mesh)",
                             "growth ÷ (block + mesh + engine)"], rows, "lllrrrrrrrr")
    return lines + [""]


def extrapolated_rows(extrapolated: dict | None) -> list[list]:
    if extrapolated is None:
        return [["extrapolated", "no block done yet"]]
    return [["core-seconds (extrapolated)", duration(extrapolated["core_seconds"])],
            [f"wall time on {extrapolated['workers']} workers (extrapolated)", duration(extrapolated["wall_seconds"])],
            ["size on disk, du (extrapolated)", format_bytes(extrapolated["disk_bytes"])],
            ["rows × columns × 4 (exact, uncompressed)", format_bytes(extrapolated["uncompressed_bytes"])]]


def store_rows(figures: dict) -> list[list]:
    return [["rows × columns", f"{figures['rows']:,} × {figures['columns']:,}"],
            ["blocks × rows", f"{figures['blocks']:,} × {figures['block_rows']:,}"],
            ["blocks done (measured)", f"{figures['blocks_done']:,} ({figures['rows_done']:,} rows)"],
            ["their own seconds, summed (measured)", duration(figures["block_seconds_sum"])],
            ["size on disk, du (measured)", format_bytes(figures["disk_bytes"])],
            ["of which the mesh and the column indices (measured)", format_bytes(figures["fixed_disk_bytes"])]]


def nefertiti_section(report: dict) -> list[str]:
    part = report["nefertiti_all_pairs"]
    measured = part["measured"]
    lines = ["## Nefertiti all-pairs, float32", "",
             f"Every vertex as source and as target ({part['vertices']:,} vertices). Measured: the first "
             f"{measured['blocks_done']} blocks of the whole store's layout on {measured['workers']} workers. "
             "Extrapolated from them: time as their seconds per row times the rows, size as their bytes on disk per "
             "block times the blocks plus what does not grow with the rows (the distances are stored uncompressed, so "
             "du is rows × columns × 4 plus the mesh, the indices and the metadata).", ""]
    rows = store_rows(measured) + [["wall time of the measured blocks (measured)", duration(measured["wall_seconds"])]]
    lines += markdown_table(["", "nefertiti all-pairs"], rows + extrapolated_rows(part["extrapolated"]), "lr")
    return lines + [""]


def whole_store_section(report: dict) -> list[str]:
    store = report["nefertiti_all_pairs_store"]
    complete = store["blocks_done"] == store["blocks"]
    lines = ["## Nefertiti all-pairs, the whole store", "",
             f"`{store['command']}` ({store['date']}): the store `{store['store']}` "
             f"{'complete' if complete else 'in progress'}; this session's wall time "
             f"{duration(store['session_wall_seconds'])}." + ("" if complete else " Run the same command again to "
                                                              "continue it."), ""]
    rows = store_rows(store) + ([] if complete else extrapolated_rows(store["extrapolated"]))
    lines += markdown_table(["", "nefertiti all-pairs store"], rows, "lr")
    return lines + [""]


def extrapolation_section(report: dict) -> list[str]:
    e = report["extrapolation"]
    lines = ["## 160K-vertex all-pairs on 64 and 512 cores (extrapolated)", "",
             "Per-source time of the in-process `distance_matrix` on one thread, measured at each mesh below, fitted "
             f"as a · vertices^b (least squares in log-log: b = {e['exponent']:.2f}):", ""]
    lines += markdown_table(["mesh", "vertices", "sources", "per source (measured)"],
                            [[p["mesh"], p["vertices"], p["sources"], format_seconds(p["per_source_seconds"])]
                             for p in e["points"]], "lrrr")
    lines += ["", f"At {e['vertices']:,} vertices: {format_seconds(e['per_source_seconds'])} per source, "
              f"{duration(e['source_seconds'])} of source-seconds; {e['blocks']:,} blocks of {e['block_rows']} rows "
              f"(the library's default), each charged the measured overhead per block "
              f"({format_seconds(e['overhead_per_block_seconds'])}, 2 workers, median of the workloads); output "
              f"{format_bytes(e['output_bytes'])} of float32.", ""]
    lines += markdown_table(["cores", "wall time", "output bandwidth needed"],
                            [[int(cores), duration(c["wall_seconds"]), bandwidth(c["output_bytes_per_second"])]
                             for cores, c in e["cores"].items()], "rrr")
    lines += ["", "Assumptions: one single-threaded worker per core, each as fast as one core here; perfect scaling "
              "across nodes (blocks independent, each node holding the mesh once); the shared filesystem takes the "
              "output at the bandwidth above (the chunks are uncompressed); the sources' cost as the fitted "
              "per-source time, whatever their spread on the surface.", ""]
    return lines


def write_markdown(path: Path, report: dict) -> str:
    """Writes the report and returns its text (the script also prints it)."""
    machine, software = report["machine"], report["software"]
    end = report.get("load_average_at_end")
    lines = ["# Distance matrices on Dask workers into Zarr stores", "",
             f"{report['date']} · {machine['cpu_model']}, {machine['logical_cores']} logical cores · exactgeo "
             f"{revision_text(software)} · `{report['command']}` · load average "
             f"{load_text(report['load_average_at_start'])} at the start, {load_text(end) if end else kMissing} at "
             "the end", ""]
    if report["settings"]["quick"]:
        lines += ["**--quick: tiny sizes, one run: a check of the script, not results.**", ""]
    if "workloads" in report:
        timed = "median_wall_seconds" in report["workloads"][0]  # not with --memory-only
        lines += speedup_section(report) + overhead_section(report) if timed else []
        if "memory" in report["workloads"][0]:  # not in reports made before the blocks were computed in place
            lines += memory_section(report)
    if "nefertiti_all_pairs" in report:
        lines += nefertiti_section(report)
    if "nefertiti_all_pairs_store" in report:
        lines += whole_store_section(report)
    if "extrapolation" in report:
        lines += extrapolation_section(report)
    packages = ", ".join(f"{name} {version}" for name, version in software["distributed_packages"].items())
    lines += ["## Machine and software", "", f"- {cpu_text(machine)}",
              f"- exactgeo {revision_text(software)}; Python {software['python']}; {packages}", ""]
    text = "\n".join(lines)
    path.write_text(text)
    return text
