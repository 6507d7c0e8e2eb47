"""The wheels `make wheel` writes work on their own: for every wheel and every interpreter it fits, a fresh
virtual environment (no system site-packages) with no compiler reachable installs it, imports exactgeo, runs the
Python test suite and the exactgeo command.

Run by `make test-wheel` (part of `make test`) and `make wheels`. Environment: EXACTGEO_WHEEL_DIR (where the
wheels are, default dist/), EXACTGEO_WHEEL_PYTHONS (the interpreters to test with, separated by spaces, default
this one). Skips, saying how to build them, when there is no wheel. numpy, scipy, pytest and tqdm come from
PyPI (or pip's cache), as binary wheels only: nothing may be compiled.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

REPOSITORY = Path(__file__).resolve().parents[2]
WHEEL_DIR = Path(os.environ.get("EXACTGEO_WHEEL_DIR", REPOSITORY / "dist"))
if not WHEEL_DIR.is_absolute():
    WHEEL_DIR = REPOSITORY / WHEEL_DIR
PYTHONS = os.environ.get("EXACTGEO_WHEEL_PYTHONS", sys.executable).split()

# Anything that could compile or link: C and C++ compilers under any of their names, and the assembler and
# linker they would call.
COMPILER = re.compile(r"(^|-)(cc|c\+\+|gcc|g\+\+|cpp|clang|clang\+\+|clang-cpp|ld|ld\.\w+|as|gfortran|nvcc|icx|icpx)"
                      r"(-[0-9.]+)?$")


def version_of(python: str) -> tuple[int, int]:
    done = subprocess.run([python, "-c", "import sys; print(*sys.version_info[:2])"], capture_output=True, text=True,
                          check=True)
    major, minor = done.stdout.split()
    return int(major), int(minor)


def fits(wheel: Path, version: tuple[int, int]) -> bool:
    """Whether CPython `version` installs `wheel`: cp3X-abi3 fits 3.X and later, cp3X-cp3X only 3.X."""
    _, _, python_tag, abi_tag, _ = wheel.name.split("-", 4)
    built_for = (3, int(python_tag.removeprefix("cp3")))
    return version >= built_for if abi_tag == "abi3" else version == built_for


def cases() -> list:
    """A test case per (wheel, interpreter) that fits; a wheel no interpreter given fits is a failing case."""
    wheels = sorted(WHEEL_DIR.glob("exactgeo-*-manylinux*.whl"))
    if not wheels:
        return [pytest.param((None, None), id="no-wheel")]
    versions = {python: version_of(python) for python in PYTHONS}
    found = []
    for wheel in wheels:
        fitting = [python for python in PYTHONS if fits(wheel, versions[python])]
        found += [pytest.param((wheel, python), id=f"{wheel.name.split('-')[3]}-py%d.%d" % versions[python])
                  for python in fitting]
        if not fitting:
            found.append(pytest.param((wheel, None), id=f"{wheel.name}-untested"))
    return found


def tools_without_compilers(folder: Path) -> Path:
    """A folder of links to every command in /usr/bin and /bin but the compilers, assemblers and linkers."""
    folder.mkdir()
    for system in (Path("/usr/bin"), Path("/bin")):
        for tool in system.iterdir():
            if not COMPILER.search(tool.name) and not (folder / tool.name).exists():
                (folder / tool.name).symlink_to(tool)
    return folder


@pytest.fixture(scope="module", params=cases())
def wheel_and_python(request) -> tuple[Path, str]:
    wheel, python = request.param
    if wheel is None:
        pytest.skip(f"no repaired wheel in {WHEEL_DIR}: `make wheel` builds one (`make test-wheel` builds and tests "
                    "it, `make wheels` those of every Python here)")
    assert python, f"none of the interpreters given ({' '.join(PYTHONS)}) installs {wheel.name}"
    return wheel, python


@pytest.fixture(scope="module")
def environment(tmp_path_factory, wheel_and_python):
    wheel, python = wheel_and_python
    work = tmp_path_factory.mktemp("wheel")
    subprocess.run([python, "-m", "venv", str(work / "venv")], check=True)
    tools = tools_without_compilers(work / "tools")
    env = {
        "PATH": f"{work / 'venv' / 'bin'}:{tools}",
        "HOME": os.environ.get("HOME", str(work)),  # pip's cache
        "CC": "/bin/false",
        "CXX": "/bin/false",
        "PIP_DISABLE_PIP_VERSION_CHECK": "1",
        "PYTHONDONTWRITEBYTECODE": "1",
        "LANG": "C.UTF-8",
    }
    for name in ("cc", "c++", "gcc", "g++", "clang", "clang++", "ld"):
        found = subprocess.run(["sh", "-c", f"command -v {name}"], env=env, capture_output=True, text=True)
        assert found.returncode != 0, f"a compiler is reachable in the test environment: {found.stdout}"
    # Binary wheels only: a source distribution would need the compiler that is not there.
    install = subprocess.run(["pip", "install", "--only-binary=:all:", str(wheel), "scipy", "pytest", "tqdm"],
                             env=env, capture_output=True, text=True)
    assert install.returncode == 0, install.stdout + install.stderr
    assert "Building wheel" not in install.stdout
    return work, env


def run(env: dict, *command: str, cwd: Path) -> subprocess.CompletedProcess:
    done = subprocess.run(list(command), env=env, cwd=cwd, capture_output=True, text=True)
    assert done.returncode == 0, f"{command} failed:\n{done.stdout}\n{done.stderr}"
    return done


def test_the_installed_wheel_imports_from_the_environment_and_is_not_the_source_tree(environment):
    work, env = environment
    where = run(env, "python", "-c", "import exactgeo, sys; print(exactgeo.__file__); print(sys.prefix)", cwd=work)
    module, prefix = where.stdout.split()
    assert module.startswith(str(work / "venv")) and prefix == str(work / "venv")


def test_the_command_comes_with_the_wheel_and_runs(environment):
    work, env = environment
    command = work / "venv" / "bin" / "exactgeo"
    assert command.is_file(), "the wheel did not install the exactgeo command"
    version = run(env, "exactgeo", "--version", cwd=work).stdout
    expected = run(env, "python", "-c", "import exactgeo; print(exactgeo.__version__)", cwd=work).stdout.strip()
    assert expected in version
    run(env, "exactgeo", "distance", "@torus", "--source", "0", "--out", "x.npy", cwd=work)
    check = ("import numpy as np, exactgeo; d = np.load('x.npy'); "
             "e = exactgeo.distance(exactgeo.Mesh(*exactgeo.make_bumpy_torus(64, 36)), 0); "
             "assert np.array_equal(d, e), abs(d - e).max(); print(len(d))")
    assert int(run(env, "python", "-c", check, cwd=work).stdout) > 0
    # Linked only against what a manylinux system has: no library of this machine's distribution.
    libraries = run(env, "ldd", str(command), cwd=work).stdout
    for line in libraries.splitlines():
        name = line.split()[0]
        assert re.match(r"(linux-vdso|/lib64/ld-linux|ld-linux|libc\.|libm\.|libstdc\+\+\.|libgcc_s\.|"
                        r"libpthread\.|libdl\.)", name), f"the command needs {name}"


def test_the_binaries_need_no_glibc_newer_than_the_tag_says(wheel_and_python):
    # auditwheel checks the module's symbol versions, not the command's: both are read here. Every glibc
    # version a binary needs is named in its dynamic string table as GLIBC_2.N.
    wheel, _ = wheel_and_python
    floor = int(re.search(r"manylinux_2_(\d+)_", wheel.name).group(1))
    with zipfile.ZipFile(wheel) as archive:
        binaries = [name for name in archive.namelist() if name.endswith((".so", "/scripts/exactgeo"))]
        assert len(binaries) == 2, binaries
        for name in binaries:
            needed = {int(minor) for minor in re.findall(rb"GLIBC_2\.(\d+)", archive.read(name))}
            assert needed and max(needed) <= floor, f"{name} needs GLIBC_2.{max(needed)}, the tag says 2.{floor}"


def test_the_python_test_suite_passes_against_the_wheel(environment):
    work, env = environment
    # The suite's command-line tests use the wheel's command, as EXACTGEO_BUILD_DIR/cli/exactgeo.
    build = work / "build"
    (build / "cli").mkdir(parents=True, exist_ok=True)
    link = build / "cli" / "exactgeo"
    if not link.exists():
        link.symlink_to(work / "venv" / "bin" / "exactgeo")
    suite_env = dict(env, EXACTGEO_BUILD_DIR=str(build))
    if "EXACTGEO_MESH_DIR" in os.environ:
        suite_env["EXACTGEO_MESH_DIR"] = os.environ["EXACTGEO_MESH_DIR"]
    # Run from outside the repository, so that `import exactgeo` can only find the installed wheel.
    done = subprocess.run(["python", "-m", "pytest", "-q", "-p", "no:cacheprovider", str(REPOSITORY / "python" / "tests")],
                          env=suite_env, cwd=work, capture_output=True, text=True)
    print(done.stdout[-3000:])
    assert done.returncode == 0, done.stdout[-6000:] + done.stderr[-3000:]
