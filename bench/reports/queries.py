"""queries.py's report: the memory the windows kept for queries take, the peak RSS of a run that keeps them
against an ordinary one, and the points answered per second, as NAME.md."""

from __future__ import annotations

from pathlib import Path

from reports.machine import machine_section, revision_text
from reports.tables import format_bytes, format_ratio, format_seconds, markdown_table, runs_text


def write_markdown(path: Path, report: dict) -> None:
    settings = report["settings"]
    lines = [
        "# Queries at any surface point after one run",
        "",
        f"{report['date']} · exactgeo {revision_text(report['software'])} · `{report['command']}` · "
        f"{runs_text(int(settings['runs']))}, source vertex 0, one thread.",
        "",
        "A run with `keep_windows` keeps the windows that reached each face and that nothing else beats there "
        "(docs/queries.md). Kept: the windows and their bytes after the run, per face. Peak RSS: the whole "
        "`exactgeo distance` process, ordinary and with `--query-points` (1,000 points). Solve: the propagation "
        "in the Python package, without and with `keep_windows`. Points per second: one `distance_at` call on "
        f"{int(settings['points']):,} random points inside faces, from the numpy arrays to the distances, per "
        "second of CPU time (the call runs on one core).",
        "",
    ]
    rows = []
    for record in report["meshes"]:
        faces = record["faces"]
        rows.append([
            record["mesh"], faces, f"{record['kept_windows'] / faces:.2f}",
            f"{record['kept_window_bytes'] / faces:.0f}",
            format_bytes(record["peak_rss_bytes"]), format_bytes(record["peak_rss_keep_bytes"]),
            format_ratio(record["peak_rss_keep_bytes"], record["peak_rss_bytes"]),
            format_seconds(record["solve_seconds"]),
            format_ratio(record["solve_keep_seconds"], record["solve_seconds"]),
            f"{record['points'] / record['query_seconds'] / 1e6:.2f}M",
        ])
    lines += markdown_table(
        ["mesh", "faces", "kept windows per face", "bytes per face", "peak RSS", "keeping", "ratio", "solve",
         "keeping ÷ ordinary", "points per second"],
        rows, "lrrrrrrrrr")
    lines += ["", *machine_section(report)]
    path.write_text("\n".join(lines) + "\n")
