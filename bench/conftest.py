"""Shared fixtures of the benchmark tests."""

from pathlib import Path

import pytest

kRepoRoot = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="session")
def exactgeo_with_variants() -> Path:
    """The built exactgeo CLI, if it offers the paper's variants; the test is skipped otherwise."""
    from solvers.commands import missing_cli_options

    exactgeo = kRepoRoot / "build" / "cli" / "exactgeo"
    if not exactgeo.exists():
        pytest.skip(f"{exactgeo} not built")
    if missing := missing_cli_options(exactgeo):
        pytest.skip(f"{exactgeo} lacks {', '.join(missing)}")
    return exactgeo
