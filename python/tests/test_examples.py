"""Every code block of README.md and docs/*.md runs as written, so the documentation cannot drift from the
code. New blocks and new pages are picked up by themselves.

Conventions (for whoever writes docs):

- A fenced block tagged ```python, ```sh (or bash, shell) or ```cpp is run; other tags (text, json, none)
  are not.
- A block right after the line `<!-- docs-test: skip -->` (a reason may follow: `<!-- docs-test: skip
  synopsis -->`) is not run: synopses, `make` and `pip install` lines, anything long or that needs the
  network. Skip as little as possible.
- The blocks of one page run in order and share their state: the Python blocks one namespace, the C++ blocks
  one `main()` (each block its own scope would hide the names the next one uses), the shell blocks one
  folder. So a later block may use what an earlier one made.
- Everything runs in a fresh folder holding `bunny.obj` (a 3,072-vertex bumpy torus standing in for the
  Stanford bunny the examples name) and `mesh.obj` (the same), with `exactgeo` (EXACTGEO_BUILD_DIR/cli) and
  this Python on PATH.
- C++ blocks: lines starting with `#include` go to the top of the file, the rest into `int main()` (a block
  that has its own `int main` is compiled as it is, alone). Compiled with the C++ compiler (CXX, else c++)
  against EXACTGEO_BUILD_DIR's library; skipped when either is absent (as in the wheel's test, which has no
  compiler).
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from conftest import BUILD_DIR, CLI, REPOSITORY, write_obj

import exactgeo

SKIP_MARK = re.compile(r"<!--\s*docs-test:\s*skip\b[^>]*-->\s*$")
FENCE = re.compile(r"^```([A-Za-z+]*)\s*$")
LANGUAGES = {"python": "python", "py": "python", "sh": "shell", "bash": "shell", "shell": "shell", "cpp": "cpp",
             "c++": "cpp"}


@dataclass
class Block:
    language: str
    code: str
    line: int  # where the block starts in its page, for messages


def documents() -> list[Path]:
    return [REPOSITORY / "README.md", *sorted((REPOSITORY / "docs").glob("*.md"))]


def blocks_of(document: Path) -> list[Block]:
    """The page's runnable blocks, in order, less those marked to be skipped."""
    lines = document.read_text().splitlines()
    found, i = [], 0
    while i < len(lines):
        opening = FENCE.match(lines[i])
        if not opening:
            i += 1
            continue
        end = next((j for j in range(i + 1, len(lines)) if lines[j].startswith("```")), len(lines))
        previous = next((lines[j] for j in range(i - 1, -1, -1) if lines[j].strip()), "")
        language = LANGUAGES.get(opening.group(1).lower())
        if language and not SKIP_MARK.search(previous):
            found.append(Block(language, "\n".join(lines[i + 1:end]) + "\n", i + 1))
        i = end + 1
    return found


CASES = [(doc, language) for doc in documents() for language in ("python", "shell", "cpp")
         if any(b.language == language for b in blocks_of(doc))]


@pytest.fixture
def workdir(tmp_path, monkeypatch):
    vertices, faces = exactgeo.make_bumpy_torus(64, 48)
    for name in ("bunny.obj", "mesh.obj"):
        write_obj(tmp_path / name, vertices, faces)
    monkeypatch.chdir(tmp_path)
    return tmp_path


# Libraries the guides use that exactgeo does not need (extras and other packages' meshes): a page using one
# that is not installed is skipped, as in the wheel's test environment; where they are, the page runs.
OPTIONAL_MODULES = {"trimesh", "meshio", "pyvista", "open3d", "matplotlib", "mpl_toolkits", "dask", "distributed",
                    "zarr", "xarray", "gdist", "pygeodesic", "potpourri3d", "igl"}


def run_python(blocks: list[Block], document: Path) -> dict:
    names: dict = {"__name__": "__main__"}  # so that `if __name__ == "__main__":` guards run
    for block in blocks:
        code = compile(block.code, f"{document.name}:{block.line}", "exec")
        try:
            exec(code, names)
        except ImportError as error:
            missing = getattr(error, "name", None) or ""
            # A module not installed, or exactgeo saying which to install for an extra.
            if missing.split(".")[0] in OPTIONAL_MODULES or "pip install" in str(error):
                pytest.skip(f"{document.name}:{block.line} needs {missing or error} (not installed)")
            raise
    return names


def run_shell(blocks: list[Block], document: Path, workdir: Path) -> None:
    if not CLI.is_file():
        pytest.skip(f"command-line tool not built at {CLI} (make build)")
    env = dict(os.environ, PATH=f"{CLI.parent}:{Path(sys.executable).parent}:{os.environ.get('PATH', '')}")
    for block in blocks:
        done = subprocess.run(["bash", "-euo", "pipefail", "-c", block.code], cwd=workdir, env=env,
                              capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, f"{document.name}:{block.line} failed:\n{block.code}\n{done.stdout}\n{done.stderr}"


def library() -> Path | None:
    for name in ("libexactgeo.a", "libexactgeo.so"):
        if (BUILD_DIR / name).is_file():
            return BUILD_DIR / name
    return None


def cpp_program(blocks: list[Block], document: Path) -> list[str]:
    """One source per block that has its own main, and one for all the others, in order, in one main."""
    whole = [b for b in blocks if re.search(r"\bint\s+main\s*\(", b.code)]
    includes, body = ["#include <exactgeo/exactgeo.hpp>", "#include <cstdint>", "#include <span>"], []
    for block in blocks:
        if block in whole:
            continue
        body.append(f'#line {block.line + 1} "{document.name}"')
        for line in block.code.splitlines():
            is_include = line.lstrip().startswith("#include")
            (includes if is_include else body).append(line)
            if is_include:
                body.append("")  # keeps the #line numbering
    sources = [b.code for b in whole]
    if body:
        sources.append("\n".join(includes) + "\nint main() {\n" + "\n".join(body) + "\n}\n")
    return sources


def run_cpp(blocks: list[Block], document: Path, workdir: Path) -> None:
    lib = library()
    if not lib:
        pytest.skip(f"the library is not built in {BUILD_DIR} (make build)")
    compiler = os.environ.get("CXX") or shutil.which("c++")
    if not compiler or not shutil.which(compiler):
        pytest.skip("no C++ compiler to build the C++ examples with")
    for k, source in enumerate(cpp_program(blocks, document)):
        path = workdir / f"example{k}.cpp"
        path.write_text(source)
        static = ["-DEXACTGEO_STATIC_DEFINE"] if lib.suffix == ".a" else []  # as the CMake target says
        build = subprocess.run([compiler, "-std=c++20", "-O1", f"-I{REPOSITORY / 'include'}", f"-I{BUILD_DIR / 'include'}",
                                *static, str(path), str(lib), "-pthread", f"-Wl,-rpath,{BUILD_DIR}",
                                "-o", str(workdir / f"example{k}")], capture_output=True, text=True)
        assert build.returncode == 0, f"{document.name}'s C++ does not compile:\n{source}\n{build.stderr[-4000:]}"
        done = subprocess.run([str(workdir / f"example{k}")], cwd=workdir, capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, f"{document.name}'s C++ failed:\n{done.stdout}\n{done.stderr}"


@pytest.mark.parametrize(("document", "language"), CASES,
                         ids=[f"{d.relative_to(REPOSITORY)}-{lang}" for d, lang in CASES])
def test_the_documentation_code_runs(document, language, workdir):
    blocks = [b for b in blocks_of(document) if b.language == language]
    if language == "python":
        run_python(blocks, document)
    elif language == "shell":
        run_shell(blocks, document, workdir)
    else:
        run_cpp(blocks, document, workdir)


def test_the_collector_finds_the_blocks_and_honours_the_skip_mark(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("text\n\n```python\nx = 1\n```\n\n<!-- docs-test: skip synopsis -->\n```sh\nexit 1\n```\n\n"
                    "```text\nnot code\n```\n\n```cpp\n#include <vector>\nstd::vector<int> v;\n```\n")
    found = blocks_of(page)
    assert [(b.language, b.line) for b in found] == [("python", 3), ("cpp", 16)]
    assert cpp_program(found[1:], page)[0].startswith("#include <exactgeo/exactgeo.hpp>")
    # Every page with code has runnable blocks: nothing was dropped by a malformed fence.
    assert any(lang == "python" for d, lang in CASES if d.name == "README.md")


# What the opening examples say, beyond running.


def first_python_block(document: Path) -> Block:
    if not document.is_file():
        pytest.skip(f"{document} is absent")
    block = next((b for b in blocks_of(document) if b.language == "python"), None)
    assert block, f"no Python example in {document}"
    return block


def test_the_readme_example_runs_with_the_required_dependencies_only(monkeypatch):
    # scipy is optional (pip install .[sparse]): a fresh `pip install .` must run the example without it.
    monkeypatch.setitem(sys.modules, "scipy", None)
    monkeypatch.setitem(sys.modules, "scipy.sparse", None)
    document = REPOSITORY / "README.md"
    names = run_python([first_python_block(document)], document)
    assert names["d"].dtype == np.float64 and names["d"].shape == (names["mesh"].vertex_count,)


def test_the_guide_opening_example_runs_and_says_what_is_true():
    document = REPOSITORY / "docs" / "python.md"
    names = run_python([first_python_block(document)], document)
    d, p = names["d"], names["p"]
    assert abs(p.length - d[7]) <= 1e-12 * d[7]  # as its comment says
