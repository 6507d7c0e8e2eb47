"""Shared fixtures of the benchmark tests."""

from pathlib import Path

import pytest

kRepoRoot = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="session")
def exactgeo_cli() -> Path:
    """The built exactgeo CLI; the test is skipped if there is none."""
    exactgeo = kRepoRoot / "build" / "cli" / "exactgeo"
    if not exactgeo.exists():
        pytest.skip(f"{exactgeo} not built (cmake --build build --target exactgeo_cli)")
    return exactgeo


@pytest.fixture(scope="session")
def exactgeo_with_variants(exactgeo_cli: Path) -> Path:
    """The built exactgeo CLI, if it offers the paper's variants; the test is skipped otherwise."""
    from solvers.commands import missing_cli_options

    if missing := missing_cli_options(exactgeo_cli):
        pytest.skip(f"{exactgeo_cli} lacks {', '.join(missing)}")
    return exactgeo_cli
