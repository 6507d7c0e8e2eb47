"""Building from source on a machine without a C++ compiler says what to install, not CMake's internals."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

from test_wheel import REPOSITORY, tools_without_compilers

CMAKE = "/usr/bin/cmake" if Path("/usr/bin/cmake").is_file() else shutil.which("cmake")


def configure(tmp_path: Path, env: dict) -> subprocess.CompletedProcess:
    if not CMAKE:
        pytest.skip("cmake not found")
    return subprocess.run([CMAKE, "-S", str(REPOSITORY), "-B", str(tmp_path / "build"), "-DEXACTGEO_BUILD_TESTS=OFF",
                           "-DEXACTGEO_BUILD_CLI=OFF", "-DEXACTGEO_BUILD_ORACLE=OFF"],
                          env=env, capture_output=True, text=True)


@pytest.mark.parametrize("how", ["CXX names no compiler", "no compiler on PATH"])
def test_a_missing_compiler_is_named_with_what_to_install(tmp_path, how):
    if how == "CXX names no compiler":
        env = dict(os.environ, CXX=str(tmp_path / "no-such-compiler"))
    else:
        env = {"PATH": str(tools_without_compilers(tmp_path / "tools")), "HOME": str(tmp_path)}
    done = configure(tmp_path, env)
    assert done.returncode != 0
    message = " ".join(done.stderr.split())
    assert "no working C++ compiler was found" in message and "apt-get install g++" in message, done.stderr
    if how == "CXX names no compiler":
        assert "no-such-compiler" in message
