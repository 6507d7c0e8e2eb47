"""The package keeps up with the C++ API: every Algorithm value has a name, every GeodesicOptions field a
keyword argument. Read from the public header in the repository, so a field added there and forgotten in
python/src/bindings.cpp fails here rather than going missing. (GeodesicStats and MeshReport need no such
check: their Python classes are generated from the library's field tables.)"""

from __future__ import annotations

import re

import pytest
from conftest import REPOSITORY

import exactgeo

HEADER = REPOSITORY / "include" / "exactgeo" / "geodesic.hpp"


def declaration_body(kind: str, name: str) -> str:
    if not HEADER.is_file():
        pytest.skip(f"{HEADER} is absent")
    text = re.sub(r"//[^\n]*", "", HEADER.read_text())
    match = re.search(rf"\b{kind}\s+{name}\s*\{{(.*?)\}};", text, re.S)
    assert match, f"{kind} {name} not found in {HEADER}"
    return match.group(1)


def field_names(struct: str) -> set[str]:
    return set(re.findall(r"(\w+)\s*(?:=[^;]*)?;", declaration_body("struct", struct)))


def test_every_algorithm_has_a_name():
    enumerators = set(re.findall(r"\b(\w+)\b", declaration_body("enum class", "Algorithm")))
    assert enumerators == set(exactgeo.ALGORITHMS)


def test_every_option_is_a_keyword_argument():
    keywords = set(exactgeo.AlgorithmOptions.__annotations__) | {"max_distance"}
    assert field_names("GeodesicOptions") == keywords
