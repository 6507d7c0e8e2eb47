"""Every committed report rewritten from its committed JSON reads as the committed Markdown
(python3 -m pytest bench).

The scripts write NAME.json and NAME.md together, so each Markdown writer must depend on the JSON alone: this
rewrites them and compares, up to the spaces around table cells. After changing a writer, rewrite the
committed reports from their JSON (that is what this test does) rather than rerunning the benchmark.
"""

import json
import re
from pathlib import Path

import pytest

from reports import anisotropy, distributed, end_to_end, many_sources, pairs, peers, python_level, threads, variants

kResults = Path(__file__).resolve().parent / "results"
kWriters = {"full": peers, "paper": variants, "anisotropy": anisotropy, "python-level": python_level,
            "many-sources": many_sources, "threads": threads, "threads-sub2": threads, "distributed": distributed,
            "distributed-memory": distributed, "end-to-end": end_to_end, "pairs": pairs}


def cells_spaced_alike(text: str) -> str:
    """An empty table cell may be written "| |" or "|  |"."""
    return re.sub(r"(?<=\|)  +(?=\|)", " ", text)


@pytest.mark.parametrize("name", [name for name in kWriters if (kResults / f"{name}.json").exists()])
def test_the_markdown_is_what_the_json_says(name, tmp_path):
    written = tmp_path / f"{name}.md"
    kWriters[name].write_markdown(written, json.loads((kResults / f"{name}.json").read_text()))
    assert cells_spaced_alike(written.read_text()) == cells_spaced_alike((kResults / f"{name}.md").read_text())
