"""Markdown tables and the number formats every report uses, so that all of bench/results/ reads alike.

A cell is text, an integer (written with thousands separators) or None (a dash: nothing measured). Other
numbers must be formatted first, with the functions below or an explicit format: how many digits a time or a
ratio deserves is the report's decision, not the table's.
"""

from __future__ import annotations

import numbers
from collections.abc import Iterable, Sequence

kGiB = 1024**3
kMiB = 1024**2
kMissing = "—"  # a value that was not measured, or does not apply

Cell = str | int | None


def markdown_table(header: Sequence[str], rows: Iterable[Sequence[Cell]], align: str) -> list[str]:
    """The lines of a Markdown table; `align` has one letter per column: "l" left or "r" right (numbers)."""
    if len(align) != len(header) or set(align) - {"l", "r"}:
        raise ValueError(f"align {align!r} must give l or r for each of the {len(header)} columns")
    separator = "|" + "".join("---:|" if side == "r" else "---|" for side in align)
    lines = [_row(header), separator]
    for row in rows:
        if len(row) != len(header):
            raise ValueError(f"row of {len(row)} cells in a table of {len(header)} columns: {row!r}")
        lines.append(_row(row))
    return lines


def cell_text(cell: Cell) -> str:
    """What a cell shows; a `|` in the text is escaped so it cannot split the cell."""
    if cell is None:
        return kMissing
    if isinstance(cell, bool) or not isinstance(cell, (str, numbers.Integral)):
        raise TypeError(f"format {cell!r} before putting it in a table")
    text = cell if isinstance(cell, str) else f"{cell:,}"
    return text.replace("|", r"\|")


def _row(cells: Sequence[Cell]) -> str:
    return "| " + " | ".join(cell_text(cell) for cell in cells) + " |"


# ------------------------------------------------------------------------------------------------ numbers


def format_seconds(seconds: float | None) -> str:
    """Three significant digits in µs, ms or s."""
    if seconds is None:
        return kMissing
    if seconds < 1e-3:
        return f"{seconds * 1e6:.3g} µs"
    if seconds < 1:
        return f"{seconds * 1e3:.3g} ms"
    return f"{seconds:.3g} s"


def format_bytes(count: float | None, floor: int = 0) -> str:
    """MB or GB, three significant digits; ≤ marks a value within 5% of `floor`, the least a run can report."""
    if count is None:
        return kMissing
    prefix = "≤ " if count <= floor * 1.05 else ""
    if count < kGiB:
        return f"{prefix}{count / kMiB:.3g} MB"
    return f"{prefix}{count / kGiB:.3g} GB"


def format_megabytes(count: float | None) -> str:
    """Always MB, as the VTP paper gives its memory figures."""
    return kMissing if count is None else f"{count / kMiB:.3g} MB"


def format_count(value: int | None) -> str:
    return kMissing if value is None else f"{value:,}"


def format_times(value: float | None) -> str:
    """A ratio as a multiple: 2.5x."""
    return kMissing if value is None else f"{value:.3g}x"


def ratio(value: float | None, reference: float | None) -> float | None:
    """value ÷ reference, or None when either is missing or the reference is zero."""
    return None if value is None or not reference else value / reference


def format_ratio(value: float | None, reference: float | None) -> str:
    return format_times(ratio(value, reference))


def format_percent(value: float | None) -> str:
    return kMissing if value is None else f"{100 * value:.1f}%"


def format_relative_error(value: float | None) -> str:
    """An error relative to the largest distance: 0 when exactly equal, else two significant digits."""
    if value is None:
        return kMissing
    return "0" if value == 0 else f"{value:.1e}"


def runs_text(count: int) -> str:
    return "1 run" if count == 1 else f"median of {count} runs"
