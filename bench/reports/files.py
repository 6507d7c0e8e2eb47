"""Where a process-per-run report goes: NAME.json (everything measured) beside NAME.md (what it means)."""

from __future__ import annotations

import json
import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path


def write_json(results_dir: Path, report: dict) -> Path:
    """NAME.json; run.py also calls this after every mesh, so a crash keeps what was measured."""
    path = results_dir / f"{report['name']}.json"
    path.write_text(json.dumps(report, indent=1))
    return path


def write_json_and_markdown(results_dir: Path, report: dict,
                            write_markdown: Callable[[Path, dict], None]) -> tuple[Path, Path]:
    """NAME.json, then NAME.md made from the same dict by the report's writer."""
    json_path = write_json(results_dir, report)
    markdown_path = results_dir / f"{report['name']}.md"
    write_markdown(markdown_path, report)
    return json_path, markdown_path


@contextmanager
def until_interrupted(report: dict) -> Iterator[None]:
    """Around a bench's loop over its meshes: Ctrl-C ends the loop, and the report says so, so that what was
    measured until then is still written."""
    try:
        yield
    except KeyboardInterrupt:
        print("\ninterrupted: writing the results so far", flush=True)
        report["interrupted"] = True


def finish_report(results_dir: Path, report: dict,
                  write_markdown: Callable[[Path, dict], None]) -> tuple[Path, Path]:
    """The load average at the end into the report, then NAME.json and NAME.md."""
    report["load_average_at_end"] = os.getloadavg()
    return write_json_and_markdown(results_dir, report, write_markdown)
