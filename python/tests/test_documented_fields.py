"""The options and statistics are defined once, in the field tables of include/exactgeo/geodesic.hpp
(for_each_option_field, for_each_stats_field): the compiled module's option names, the GeodesicStats
attributes and their docstrings, and the command's JSON come from them. What is written by hand about them is
checked here against the tables, so that a field added, renamed or removed fails a test until the texts say so:
the guide's lists (docs/python.md), the Python keyword arguments (AlgorithmOptions, each with its comment), and
the command's flags in `exactgeo distance --help` and in the README's synopsis, where every flag must exist."""

from __future__ import annotations

import dataclasses
import inspect
import re
import subprocess

import pytest
from conftest import REPOSITORY

import exactgeo
from exactgeo import _core, _geodesic

OPTION_FIELDS = set(_core.GeodesicOptions.fields)
STATS_FIELDS = set(exactgeo.GeodesicStats().to_dict())

# The flag of `exactgeo distance` that sets each option (cli/distance.cpp).
DISTANCE_FLAGS = {
    "algorithm": "--algorithm",
    "rule1": "--no-rule1",
    "rule23": "--no-rule23",
    "max_distance": "--max-distance",
    "collect_timings": "--timers",
    "threads": "--threads",
    "keep_windows": "--query-points",  # the queries after the run are what keeping the windows is for
}
# Options that are arguments of their own in Python rather than keyword options of AlgorithmOptions:
# max_distance of every call, keep_windows of GeodesicSolver.solve (the run that distance_at queries).
OWN_ARGUMENTS = {"max_distance", "keep_windows"}

# Names the guide's paragraphs may write in backquotes besides the fields: the package's public names and the
# attributes of a result (`stats`).
OTHER_NAMES = set(exactgeo.__all__) | {field.name for field in dataclasses.fields(exactgeo.GeodesicResult)}


def guide_paragraph(start: str) -> str:
    """The paragraph of docs/python.md that starts with `start`."""
    guide = (REPOSITORY / "docs" / "python.md").read_text()
    paragraphs = [p for p in guide.split("\n\n") if p.startswith(start)]
    assert len(paragraphs) == 1, f"docs/python.md has {len(paragraphs)} paragraphs starting with {start!r}"
    return paragraphs[0]


def names_in_backquotes(text: str) -> set[str]:
    """The plain identifiers written in backquotes (`rule1`, not `exactgeo.ALGORITHMS` or `"vtp"`)."""
    return {name for name in re.findall(r"`([^`]+)`", text) if name.isidentifier()}


def synopsis() -> dict[str, set[str]]:
    """The flags of each command in the README's synopsis (the first block under "## Command line")."""
    readme = (REPOSITORY / "README.md").read_text()
    block = re.search(r"^## Command line\n.*?^```sh\n(.*?)^```", readme, re.MULTILINE | re.DOTALL)
    assert block, "README.md: no ```sh block under ## Command line"
    commands: dict[str, set[str]] = {}
    command = ""
    for line in block.group(1).splitlines():
        if line.startswith("exactgeo "):
            command = line.split()[1]
        assert command, f"README.md synopsis: {line!r} continues no command"
        commands.setdefault(command, set()).update(re.findall(r"(?<![\w-])--[a-z][a-z0-9-]*", line))
    return commands


def help_flags(cli, command: str) -> set[str]:
    """The flags `exactgeo COMMAND --help` lists."""
    text = subprocess.run([str(cli), command, "--help"], capture_output=True, text=True, check=True).stdout
    return set(re.findall(r"^\s+(?:-\w,)?(--[a-z][a-z0-9-]*)", text, re.MULTILINE))


def has_comment(name: str) -> bool:
    """Whether the keyword argument `name` is declared with a comment on its line or on the line above."""
    for declaring in (_geodesic.AlgorithmOptions, _geodesic.RunOptions):
        lines = inspect.getsource(declaring).splitlines()
        for i, line in enumerate(lines):
            if re.match(rf"\s*{name}: ", line):
                return "#" in line or lines[i - 1].lstrip().startswith("#")
    return False


def test_every_option_has_a_flag_of_the_distance_command():
    assert set(DISTANCE_FLAGS) == OPTION_FIELDS


def test_every_option_is_a_keyword_argument_with_a_comment():
    assert set(exactgeo.AlgorithmOptions.__annotations__) | OWN_ARGUMENTS == OPTION_FIELDS
    uncommented = sorted(name for name in exactgeo.AlgorithmOptions.__annotations__ if not has_comment(name))
    assert not uncommented, f"AlgorithmOptions: no comment says what {uncommented} do"


def test_the_guide_lists_every_option_and_only_options():
    paragraph = guide_paragraph("**Options**")
    named = names_in_backquotes(paragraph)
    missing = sorted(OPTION_FIELDS - OWN_ARGUMENTS - named)
    assert not missing, f"docs/python.md's Options paragraph does not name {missing}"
    unknown = sorted(named - OPTION_FIELDS - OTHER_NAMES)
    assert not unknown, f"docs/python.md's Options paragraph names {unknown}, which are no options"


def test_the_guide_lists_every_statistic_and_only_statistics():
    paragraph = guide_paragraph("**Statistics.**")
    named = names_in_backquotes(paragraph)
    missing = sorted(STATS_FIELDS - named)
    assert not missing, f"docs/python.md's Statistics paragraph does not name {missing}"
    unknown = sorted(named - STATS_FIELDS - OTHER_NAMES)
    assert not unknown, f"docs/python.md's Statistics paragraph names {unknown}, which are no statistics"


def test_every_statistic_has_its_description_as_docstring():
    for name in STATS_FIELDS:
        assert getattr(exactgeo.GeodesicStats, name).__doc__, f"GeodesicStats.{name} has no docstring"


def test_the_distance_command_and_its_synopsis_have_every_option(cli):
    flags = set(DISTANCE_FLAGS.values())
    missing = sorted(flags - help_flags(cli, "distance"))
    assert not missing, f"exactgeo distance --help lacks {missing}"
    missing = sorted(flags - synopsis()["distance"])
    assert not missing, f"README.md's synopsis of exactgeo distance lacks {missing}"


@pytest.mark.parametrize("command", sorted(synopsis()))
def test_every_flag_of_the_synopsis_exists(cli, command):
    gone = sorted(synopsis()[command] - help_flags(cli, command))
    assert not gone, f"README.md's synopsis of exactgeo {command} names {gone}, which its --help does not list"
