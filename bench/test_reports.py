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

from reports import (
    anisotropy,
    distributed,
    end_to_end,
    files,
    many_sources,
    pairs,
    peers,
    python_level,
    queries,
    threads,
    variants,
)

kResults = Path(__file__).resolve().parent / "results"
kWriters = {"full": peers, "paper": variants, "anisotropy": anisotropy, "python-level": python_level,
            "many-sources": many_sources, "threads": threads, "threads-sub2": threads, "distributed": distributed,
            "distributed-memory": distributed, "end-to-end": end_to_end, "pairs": pairs,
            "queries": queries}


def cells_spaced_alike(text: str) -> str:
    """An empty table cell may be written "| |" or "|  |"."""
    return re.sub(r"(?<=\|)  +(?=\|)", " ", text)


@pytest.mark.parametrize("name", [name for name in kWriters if (kResults / f"{name}.json").exists()])
def test_the_markdown_is_what_the_json_says(name, tmp_path):
    written = tmp_path / f"{name}.md"
    kWriters[name].write_markdown(written, json.loads((kResults / f"{name}.json").read_text()))
    assert cells_spaced_alike(written.read_text()) == cells_spaced_alike((kResults / f"{name}.md").read_text())


def test_an_interrupted_bench_still_writes_what_it_measured(tmp_path):
    report = {"name": "partial", "meshes": []}
    with files.until_interrupted(report):
        report["meshes"].append("first")
        raise KeyboardInterrupt
    json_path, markdown_path = files.finish_report(
        tmp_path, report, lambda path, written: path.write_text(f"{len(written['meshes'])} mesh\n"))
    written = json.loads(json_path.read_text())
    assert written["interrupted"] is True and written["meshes"] == ["first"]
    assert len(written["load_average_at_end"]) == 3
    assert markdown_path.read_text() == "1 mesh\n"


def test_a_bench_that_runs_through_is_not_marked_interrupted(tmp_path):
    report = {"name": "whole"}
    with files.until_interrupted(report):
        pass
    json_path, _ = files.finish_report(tmp_path, report, lambda path, written: path.write_text(""))
    assert "interrupted" not in json.loads(json_path.read_text())
