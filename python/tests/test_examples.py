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
