"""docs/architecture.md names every file of the public headers, the engine, the readers, the matrix store, the
command and the Python package (the tests, the benchmark and the docs are described by folder), so that a file
added, renamed or removed fails here until the page says where it belongs."""

from __future__ import annotations

import re
import shutil
import subprocess

import pytest
from conftest import REPOSITORY

FOLDERS = ["include/exactgeo", "src", "io", "store", "cli", "python"]
DESCRIBED_BY_FOLDER = ("python/tests/",)


def tracked_files() -> list[str]:
    """The files git tracks in FOLDERS, as paths from the repository's root."""
    listed = subprocess.run(["git", "ls-files", "--", *FOLDERS], cwd=REPOSITORY, capture_output=True, text=True,
                            check=True).stdout.split()
    return [path for path in listed if not path.startswith(DESCRIBED_BY_FOLDER)]


def is_named(path: str, page: str) -> bool:
    """Whether the page names the file in backquotes, with or without its folder: by its name (`windows.hpp`,
    `cli/outputs.hpp`), or by its stem for all its extensions (`propagation.*`)."""
    name = path.rsplit("/", 1)[-1]
    stem = name.split(".", 1)[0]
    patterns = [rf"`(?:[\w./]*/)?{re.escape(name)}`", rf"`(?:[\w./]*/)?{re.escape(stem)}\.\*`"]
    return any(re.search(pattern, page) for pattern in patterns)


def in_git_checkout() -> bool:
    return shutil.which("git") is not None and subprocess.run(
        ["git", "rev-parse", "--is-inside-work-tree"], cwd=REPOSITORY, capture_output=True
    ).returncode == 0


@pytest.mark.skipif(not in_git_checkout(), reason="needs a git checkout of the repository")
def test_every_file_is_named_in_the_architecture_page():
    page = (REPOSITORY / "docs" / "architecture.md").read_text()
    files = tracked_files()
    assert len(files) > 50, f"git ls-files found only {files}"
    missing = [path for path in files if not is_named(path, page)]
    assert not missing, f"docs/architecture.md does not say where these belong: {missing}"
