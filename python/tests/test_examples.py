"""The Python examples at the top of the README and of docs/python.md run as written, on the installed
package, and say what is true."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import REPOSITORY


def run_first_python_example(document: Path) -> dict:
    """Executes the first ```python block of `document` and returns the names it defined."""
    if not document.is_file():
        pytest.skip(f"{document} is absent")
    example = re.search(r"```python\n(.*?)```", document.read_text(), re.S)
    assert example, f"no Python example in {document}"
    names: dict = {}
    exec(example.group(1), names)
    return names


def test_the_readme_example_runs_with_the_required_dependencies_only(monkeypatch):
    # scipy is optional (pip install .[sparse]): a fresh `pip install .` must run the example without it.
    monkeypatch.setitem(sys.modules, "scipy", None)
    monkeypatch.setitem(sys.modules, "scipy.sparse", None)
    names = run_first_python_example(REPOSITORY / "README.md")
    assert names["d"].dtype == np.float64 and names["d"].shape == (names["mesh"].vertex_count,)


def test_the_guide_opening_example_runs_and_says_what_is_true():
    names = run_first_python_example(REPOSITORY / "docs" / "python.md")
    d, p = names["d"], names["p"]
    assert abs(p.length - d[7]) <= 1e-12 * d[7]  # as its comment says
