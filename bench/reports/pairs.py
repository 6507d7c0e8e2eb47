"""pairs.py's report: a pair's goal-directed search against a full run and against a run stopping at the named
target, overall and by quartile of the pair's distance, as pairs.md."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from reports.tables import format_seconds, format_times, markdown_table


def write_markdown(path: Path, report: dict) -> str:
    """Writes the report and returns its text (the script also prints it)."""
    settings, machine = report["settings"], report["machine"]
    seconds = {way: np.array(times) for way, times in report["seconds"].items()}
    distances = np.array(report["distances"])
    finite = np.isfinite(distances)
    over_full = seconds["full"] / seconds["pair"]
    over_named = seconds["named_target"] / seconds["pair"]
    lines = [
        f"# Pair distances on {settings['mesh']} ({report['faces']:,} faces), {settings['pairs']} random vertex pairs",
        "",
        f"{report['date']} · {machine['cpu_model']}, {machine['logical_cores']} logical cores · load "
        f"{report['load_average']} at the start, {report['load_average_at_end']} at the end · "
        f"`python3 bench/pairs.py` · one thread, each time the median of {settings['rounds']} rounds",
        "",
        "Per pair: a full run from a (every vertex), the run from a that stops once b is final (`targets=[b]`), "
        "and `exactgeo.pair_distances` (a goal-directed search, docs/pairs.md). Speed-ups are same-run ratios per "
        "pair, then the median (and the range) over the pairs.",
        "",
    ]
    rows = [
        ["full run", format_seconds(float(np.median(seconds["full"]))), "1x", "—"],
        ["stop at the named target", format_seconds(float(np.median(seconds["named_target"]))), "—", "1x"],
        ["pair_distances", format_seconds(float(np.median(seconds["pair"]))),
         f"{format_times(float(np.median(over_full)))} ({format_times(float(over_full.min()))}–"
         f"{format_times(float(over_full.max()))})",
         f"{format_times(float(np.median(over_named)))} ({format_times(float(over_named.min()))}–"
         f"{format_times(float(over_named.max()))})"],
    ]
    lines += markdown_table(["way", "median time", "pair faster than full", "pair faster than named target"],
                            rows, "lrrr")
    lines += ["", "## By the pair's distance", ""]
    edges = np.quantile(distances[finite], [0, 0.25, 0.5, 0.75, 1.0])
    quartile_rows = []
    for q in range(4):
        below_top = (distances < edges[q + 1]) if q < 3 else (distances <= edges[q + 1])
        inside = finite & (distances >= edges[q]) & below_top
        quartile_rows.append([
            f"{25 * q}–{25 * (q + 1)}%", f"{edges[q]:.4g}–{edges[q + 1]:.4g}", int(inside.sum()),
            format_seconds(float(np.median(seconds["pair"][inside]))),
            format_times(float(np.median(over_full[inside]))), format_times(float(np.median(over_named[inside]))),
        ])
    lines += markdown_table(["distance percentile", "distance", "pairs", "pair time", "faster than full",
                             "faster than named target"], quartile_rows, "lrrrrr")
    lines += [
        "",
        f"All {settings['pairs']} pairs in one call: {format_seconds(report['all_pairs_in_one_call_seconds'])} "
        f"({format_seconds(report['all_pairs_in_one_call_seconds'] / settings['pairs'])} a pair). Distances against "
        f"the named-target runs: max difference {report['max_relative_difference_to_named_target']:.1e} of the "
        f"largest, {report['pairs_equal_to_named_target_bit_for_bit']} of {settings['pairs']} equal bit for bit.",
        "",
    ]
    text = "\n".join(lines)
    path.write_text(text)
    return text
