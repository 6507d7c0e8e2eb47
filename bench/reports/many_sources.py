"""many_sources.py's report: the distance matrix on one thread and on every core, and one multi-source run
against as many single-source runs, as many-sources.md."""

from __future__ import annotations

from pathlib import Path

from reports.tables import markdown_table


def write_markdown(path: Path, report: dict) -> str:
    """Writes the report and returns its text (the script also prints it)."""
    matrix_seconds = report["matrix_wall_seconds"]  # keyed by thread count, as text (JSON keys)
    one, every = sorted(matrix_seconds, key=int)[0], sorted(matrix_seconds, key=int)[-1]
    single, multi = report["single_source_propagation_seconds"], report["multi_source_propagation_seconds"]
    sources = len(report["sources"])
    machine = report["machine"]
    lines = [
        f"# Many sources on {report['mesh']} ({report['faces']:,} faces), {sources} sources",
        "",
        f"{report['date']} · {machine['cpu_model']}, {machine['logical_cores']} logical cores · "
        "`python3 bench/many_sources.py`",
        "",
    ]
    lines += markdown_table(["what", "time", "ratio"], [
        [f"`exactgeo matrix`, {one} thread (wall)", f"{matrix_seconds[one]:.3f} s", "1x"],
        [f"`exactgeo matrix`, {every} threads (wall)", f"{matrix_seconds[every]:.3f} s",
         f"{report['matrix_speedup']:.2f}x faster"],
        [f"{sources} single-source runs (propagation, summed)", f"{sum(single):.3f} s", "1x"],
        [f"one run from all {sources} sources (propagation)", f"{multi:.3f} s",
         f"{report['multi_vs_singles']:.2f}x faster"],
    ], "lrr")
    lines += [
        "",
        f"Matrix rows identical across thread counts: "
        f"{'yes' if report['matrix_rows_identical_across_threads'] else 'NO'}. Multi-source distances against the "
        f"minimum of the matrix rows: max relative error {report['multi_source_vs_min_of_rows_relative_error']:.1e}.",
        "",
    ]
    text = "\n".join(lines)
    path.write_text(text)
    return text
