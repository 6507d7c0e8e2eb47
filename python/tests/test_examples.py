"""The README's Python example runs as written, on the installed package."""

from __future__ import annotations

import re
import sys

import numpy as np
import pytest
from conftest import REPOSITORY


def test_the_readme_example_runs_with_the_required_dependencies_only(monkeypatch):
    # scipy is optional (pip install .[sparse]): a fresh `pip install .` must run the example without it.
    monkeypatch.setitem(sys.modules, "scipy", None)
    monkeypatch.setitem(sys.modules, "scipy.sparse", None)
    readme = REPOSITORY / "README.md"
    if not readme.is_file():
        pytest.skip(f"{readme} is absent")
    example = re.search(r"```python\n(.*?)```", readme.read_text(), re.S)
    assert example, "no Python example in the README"
    names: dict = {}
    exec(example.group(1), names)
    assert names["d"].dtype == np.float64 and names["d"].shape == (names["mesh"].vertex_count,)


def test_the_guide_opening_example_runs_and_says_what_is_true():
    guide = REPOSITORY / "docs" / "python.md"
    if not guide.is_file():
        pytest.skip(f"{guide} is absent")
    example = re.search(r"```python\n(.*?)```", guide.read_text(), re.S)
    assert example, "no Python example at the top of docs/python.md"
    names: dict = {}
    exec(example.group(1), names)
    d, p = names["d"], names["p"]
    assert abs(p.length - d[7]) <= 1e-12 * d[7]  # as its comment says
