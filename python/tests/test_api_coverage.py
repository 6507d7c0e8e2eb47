"""The package keeps up with the C++ API. The compiled module is generated from the library's tables (the
algorithm names, the option, statistic and mesh-report fields), so what is left to check is the Python layer
written by hand over it: the typed keyword arguments."""

from __future__ import annotations

import exactgeo
from exactgeo import _core, _geodesic


def test_every_option_is_a_keyword_argument_with_a_checked_conversion():
    # keep_windows belongs to GeodesicSolver.solve alone: only a solver answers queries after its run.
    keywords = set(exactgeo.AlgorithmOptions.__annotations__) | {"max_distance", "keep_windows"}
    assert set(_core.GeodesicOptions.fields) == keywords
    assert set(_geodesic._OPTION_CONVERSIONS) == set(exactgeo.AlgorithmOptions.__annotations__)


def test_options_are_documented_and_checked():
    assert "Rule 1" in _core.GeodesicOptions.rule1.__doc__
    options = _core.GeodesicOptions(algorithm="ftp", rule1=False, max_distance=2)
    assert (options.algorithm, options.rule1, options.rule23, options.max_distance) == ("ftp", False, True, 2.0)
    try:
        _core.GeodesicOptions(rule3=True)
    except TypeError as error:
        assert "unknown option 'rule3'" in str(error)
    else:
        raise AssertionError("an unknown option was accepted")


def test_every_algorithm_name_runs():
    mesh = exactgeo.Mesh(*exactgeo.make_grid(2, 2, 1.0, 1.0))
    for name in exactgeo.ALGORITHMS:
        assert exactgeo.distance(mesh, 0, algorithm=name)[8] > 0


def test_every_public_name_is_in_the_guide():
    import re

    from conftest import REPOSITORY

    guide = (REPOSITORY / "docs" / "python.md").read_text()
    names = set(exactgeo.__all__) - {"AlgorithmOptions", "__version__"}  # a typing aid; the version
    names |= {name for name in vars(exactgeo.Mesh) if name.startswith(("from_", "load"))}
    missing = sorted(name for name in names if not re.search(rf"\b{re.escape(name)}\b", guide))
    assert not missing, f"not in docs/python.md: {missing}"
