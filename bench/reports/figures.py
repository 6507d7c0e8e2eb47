"""The one way the reports make and write a matplotlib figure: off-screen, laid out, closed once written.

matplotlib is imported only when a figure is made, so the scripts' --help and the reports' tests run
without it.
"""

from __future__ import annotations

from pathlib import Path


def pyplot():
    """matplotlib.pyplot on the Agg backend: the benchmark runs without a display."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(figure, path: Path, dpi: int = 100) -> Path:
    """Lays out, writes and closes a matplotlib figure; returns the path."""
    figure.tight_layout()
    figure.savefig(path, dpi=dpi)
    pyplot().close(figure)
    return path
