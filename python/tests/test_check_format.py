"""scripts/check-format.sh, run by `make lint`: in a scratch git repository holding the script and the tree's
.clang-format, it passes on a clean tree and on well formatted changes, and fails, printing the fix, on a badly
formatted changed line (and only on changed lines)."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest
from conftest import REPOSITORY

pytestmark = pytest.mark.skipif(
    shutil.which("git") is None or shutil.which("git-clang-format") is None,
    reason="needs git and git-clang-format (apt-get install clang-format)",
)

FORMATTED = """#include <cmath>

namespace demo {

// Half the hypotenuse.
double half_hypotenuse(double a, double b) { return 0.5 * std::hypot(a, b); }

}  // namespace demo
"""


def git(repository: Path, *arguments: str) -> None:
    subprocess.run(["git", "-c", "user.name=test", "-c", "user.email=test@example.com", *arguments],
                   cwd=repository, check=True, capture_output=True)


def check(repository: Path, *base: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(["bash", str(repository / "scripts" / "check-format.sh"), *base], cwd=repository,
                          capture_output=True, text=True)


@pytest.fixture
def repository(tmp_path: Path) -> Path:
    """A scratch repository on branch main with the script, the style file and one formatted source."""
    (tmp_path / "scripts").mkdir()
    shutil.copy(REPOSITORY / "scripts" / "check-format.sh", tmp_path / "scripts")
    shutil.copy(REPOSITORY / ".clang-format", tmp_path)
    (tmp_path / "demo.cpp").write_text(FORMATTED)
    git(tmp_path, "init", "-q")
    git(tmp_path, "symbolic-ref", "HEAD", "refs/heads/main")  # what `init -b main` does, on any git
    git(tmp_path, "add", ".")
    git(tmp_path, "commit", "-q", "-m", "start")
    return tmp_path


def test_a_clean_tree_passes(repository):
    result = check(repository)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "are formatted" in result.stdout


def test_a_badly_formatted_change_fails_with_the_fix(repository):
    source = repository / "demo.cpp"
    source.write_text(FORMATTED.replace("return 0.5 * std::hypot(a, b);", "return 0.5*std::hypot( a,b );"))
    result = check(repository)
    assert result.returncode == 1
    assert "+double half_hypotenuse(double a, double b) { return 0.5 * std::hypot(a, b); }" in result.stdout
    assert "not formatted" in result.stderr
    # Committed on a branch: still a change since where the branch left main.
    git(repository, "checkout", "-q", "-b", "feature")
    git(repository, "commit", "-q", "-am", "unformatted")
    assert check(repository).returncode == 1
    assert check(repository, "HEAD").returncode == 0  # nothing changed since HEAD itself


def test_well_formatted_changes_pass_and_only_changed_lines_count(repository):
    # A line the style would change, committed on main before the check: it is not part of the change.
    source = repository / "demo.cpp"
    source.write_text(FORMATTED.replace("namespace demo {\n", "namespace demo {\nint   legacy;\n"))
    git(repository, "commit", "-q", "-am", "legacy")
    source.write_text(source.read_text().replace("}  // namespace demo", "int added = 1;\n\n}  // namespace demo"))
    result = check(repository)
    assert result.returncode == 0, result.stdout + result.stderr
    source.write_text(source.read_text().replace("int added = 1;", "int added=1;"))
    assert check(repository).returncode == 1
