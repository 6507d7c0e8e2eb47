"""Every code block of README.md and docs/*.md runs as a user would run it, so the documentation cannot drift
from the code. New blocks and new pages are picked up by themselves.

Conventions (for whoever writes docs):

- A fenced block tagged ```python, ```sh (or bash, shell) or ```cpp is run; other tags (text, json, none)
  are not.
- A block right after the line `<!-- docs-test: skip -->` (a reason may follow: `<!-- docs-test: skip
  synopsis -->`) is not run: synopses, `make` and `pip install` lines, anything long or that needs the
  network. Skip as little as possible.
- The blocks of one page run in order, one program per language, so a later block may use what an earlier
  one made:
  - Python: the page's blocks are one script file, run by this Python in a fresh process (`python
    recipes_md.py` for recipes.md), as a reader who pastes them into a file runs them. Its `__name__` is
    `"__main__"` and worker processes (Dask's, multiprocessing's) import it again, so code that starts them
    needs the
    `if __name__ == "__main__":` guard there as it does in the reader's file. Each line of the script sits
    at its line number in the page, so a traceback names the page's line.
  - Shell: each block in bash (`-euo pipefail`), all in one folder.
  - C++: lines starting with `#include` go to the top of the file, the rest into one `int main()` (each
    block its own scope would hide the names the next one uses; a block that has its own `int main` is
    compiled as it is, alone).
- Everything runs in a fresh folder holding `bunny.obj` (a 3,072-vertex bumpy torus and one vertex no face
  uses, standing in for the Stanford bunny the examples name, which has 1,113 of those) and `mesh.obj` (the
  torus alone), with `exactgeo` (EXACTGEO_BUILD_DIR/cli) and this Python on PATH.
- A page whose Python needs a module that is not installed (OPTIONAL_MODULES below, or an extra that
  exactgeo names with `pip install`) is skipped, as in the wheel's test environment.
- C++ is compiled against the library as a user installs it: `cmake --install EXACTGEO_BUILD_DIR` into a
  fresh prefix (once per test session), then a CMake project per page that finds it with
  `find_package(exactgeo CONFIG REQUIRED)` and links `exactgeo::exactgeo`, as the README says. Skipped
  without a built library, CMake or a C++ compiler (CXX, else c++), as in the wheel's test, which has none.
"""

from __future__ import annotations

import json
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
TIMEOUT = 600  # seconds for one page's program: the distributed page starts several clusters


@dataclass
class Block:
    language: str
    code: str
    line: int  # where the block's opening fence is in its page; its code starts on the next line


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


def page_name(document: Path) -> str:
    return str(document.relative_to(REPOSITORY) if document.is_relative_to(REPOSITORY) else document.name)


@pytest.fixture
def workdir(tmp_path):
    vertices, faces = exactgeo.make_bumpy_torus(64, 48)
    write_obj(tmp_path / "mesh.obj", vertices, faces)
    # The real bunny has vertices no face uses (distance inf): the examples must cope with them.
    write_obj(tmp_path / "bunny.obj", np.vstack([vertices, [[0.0, 0.0, 5.0]]]), faces)
    return tmp_path


def user_environment(**extra: str) -> dict[str, str]:
    """The environment a user of the installed package has: the command and this Python on PATH."""
    path = f"{CLI.parent}:{Path(sys.executable).parent}:{os.environ.get('PATH', '')}"
    return dict(os.environ, PATH=path, **extra)


# Libraries the guides use that exactgeo does not need (extras and other packages' meshes): a page using one
# that is not installed is skipped, as in the wheel's test environment; where they are, the page runs.
OPTIONAL_MODULES = {"trimesh", "meshio", "pyvista", "open3d", "matplotlib", "mpl_toolkits", "dask", "distributed",
                    "zarr", "xarray", "gdist", "pygeodesic", "potpourri3d", "igl"}
MISSING_MODULE = re.compile(r"^ModuleNotFoundError: No module named '([\w.]+)'")


def python_script(blocks: list[Block], epilogue: str = "") -> str:
    """The blocks as one script, each line at its line number in the page (the lines between blocks left
    empty), so that a traceback's line numbers are the page's; then the epilogue."""
    lines: list[str] = []
    for block in blocks:
        lines += [""] * (block.line - len(lines))
        lines += block.code.splitlines()
    return "\n".join(lines + epilogue.splitlines()) + "\n"


def skip_if_an_optional_module_is_missing(stderr: str, page: str) -> None:
    """A script stopped by a missing optional module, or by exactgeo saying which extra to install, is
    skipped: the user was told what to install."""
    last = stderr.strip().splitlines()[-1] if stderr.strip() else ""
    missing = MISSING_MODULE.match(last)
    if missing and missing.group(1).split(".")[0] in OPTIONAL_MODULES:
        pytest.skip(f"{page} needs {missing.group(1)} (not installed)")
    if last.startswith("ImportError:") and "pip install" in last:
        pytest.skip(f"{page}: {last}")


def run_python(blocks: list[Block], document: Path, workdir: Path, epilogue: str = "",
               environment: dict[str, str] | None = None) -> str:
    """Runs the blocks as one script in a fresh process in workdir; returns what it printed."""
    # Named after the page, but not as any module is: the script's folder is first on sys.path, so a script
    # called distributed.py would be what `import distributed` finds.
    script = workdir / f"{document.stem}_md.py"
    script.write_text(python_script(blocks, epilogue))
    done = subprocess.run([sys.executable, script.name], cwd=workdir, env=environment or user_environment(),
                          capture_output=True, text=True, timeout=TIMEOUT)
    if done.returncode != 0:
        page = page_name(document)
        skip_if_an_optional_module_is_missing(done.stderr, page)
        lines = re.findall(rf'File "{re.escape(str(script))}", line (\d+)', done.stderr)
        where = f"{page}:{lines[-1]}" if lines else page
        pytest.fail(f"{where}: the page's Python, run as a script, failed (exit code {done.returncode}):\n"
                    f"{done.stdout[-2000:]}\n{done.stderr[-4000:]}")
    return done.stdout


def run_shell(blocks: list[Block], document: Path, workdir: Path) -> None:
    if not CLI.is_file():
        pytest.skip(f"command-line tool not built at {CLI} (make build)")
    for block in blocks:
        done = subprocess.run(["bash", "-euo", "pipefail", "-c", block.code], cwd=workdir, env=user_environment(),
                              capture_output=True, text=True, timeout=TIMEOUT)
        assert done.returncode == 0, (f"{page_name(document)}:{block.line} failed:\n{block.code}\n{done.stdout}\n"
                                      f"{done.stderr}")


def library() -> Path | None:
    for name in ("libexactgeo.a", "libexactgeo.so"):
        if (BUILD_DIR / name).is_file():
            return BUILD_DIR / name
    return None


@pytest.fixture(scope="session")
def installed_package(tmp_path_factory) -> Path:
    """The build folder's library, headers and CMake package installed into a fresh prefix."""
    if not library():
        pytest.skip(f"the library is not built in {BUILD_DIR} (make build)")
    cmake = shutil.which("cmake")
    if not cmake:
        pytest.skip("no cmake to install the package with")
    prefix = tmp_path_factory.mktemp("prefix")
    done = subprocess.run([cmake, "--install", str(BUILD_DIR), "--prefix", str(prefix)], capture_output=True,
                          text=True)
    assert done.returncode == 0, f"cmake --install {BUILD_DIR} failed:\n{done.stdout}\n{done.stderr}"
    return prefix


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


def consumer_project(source_count: int) -> str:
    """A user's CMakeLists.txt: find the installed package, link each program against its target."""
    lines = ["cmake_minimum_required(VERSION 3.20)", "project(documentation_examples LANGUAGES CXX)",
             "find_package(exactgeo CONFIG REQUIRED)"]
    for k in range(source_count):
        lines += [f"add_executable(example{k} example{k}.cpp)",
                  f"target_link_libraries(example{k} PRIVATE exactgeo::exactgeo)"]
    return "\n".join(lines) + "\n"


def run_cpp(blocks: list[Block], document: Path, workdir: Path, prefix: Path) -> None:
    compiler = os.environ.get("CXX") or shutil.which("c++")
    if not compiler or not shutil.which(compiler):
        pytest.skip("no C++ compiler to build the C++ examples with")
    sources = cpp_program(blocks, document)
    project, build = workdir / "cpp", workdir / "cpp" / "build"
    project.mkdir()
    for k, source in enumerate(sources):
        (project / f"example{k}.cpp").write_text(source)
    (project / "CMakeLists.txt").write_text(consumer_project(len(sources)))
    generator = ["-G", "Ninja"] if shutil.which("ninja") else []
    for step in ([*generator, "-S", str(project), "-B", str(build), f"-DCMAKE_PREFIX_PATH={prefix}",
                  f"-DCMAKE_CXX_COMPILER={compiler}"], ["--build", str(build)]):
        done = subprocess.run(["cmake", *step], capture_output=True, text=True, timeout=TIMEOUT)
        assert done.returncode == 0, (f"{page_name(document)}'s C++ does not build against the installed package:\n"
                                      f"{done.stdout[-4000:]}\n{done.stderr[-4000:]}")
    for k in range(len(sources)):
        done = subprocess.run([str(build / f"example{k}")], cwd=workdir, capture_output=True, text=True,
                              timeout=TIMEOUT)
        assert done.returncode == 0, f"{page_name(document)}'s C++ failed:\n{done.stdout}\n{done.stderr}"


@pytest.mark.parametrize(("document", "language"), CASES, ids=[f"{page_name(d)}-{lang}" for d, lang in CASES])
def test_the_documentation_code_runs(document, language, workdir, request):
    blocks = [b for b in blocks_of(document) if b.language == language]
    if language == "python":
        run_python(blocks, document, workdir)
    elif language == "shell":
        run_shell(blocks, document, workdir)
    else:
        run_cpp(blocks, document, workdir, request.getfixturevalue("installed_package"))


def test_the_collector_finds_the_blocks_and_honours_the_skip_mark(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("text\n\n```python\nx = 1\n```\n\n<!-- docs-test: skip synopsis -->\n```sh\nexit 1\n```\n\n"
                    "```text\nnot code\n```\n\n```cpp\n#include <vector>\nstd::vector<int> v;\n```\n")
    found = blocks_of(page)
    assert [(b.language, b.line) for b in found] == [("python", 3), ("cpp", 16)]
    assert python_script(found[:1]).splitlines().index("x = 1") == 3  # line 4, as in the page
    assert cpp_program(found[1:], page)[0].startswith("#include <exactgeo/exactgeo.hpp>")
    # Every page with code has runnable blocks: nothing was dropped by a malformed fence.
    assert any(lang == "python" for d, lang in CASES if d.name == "README.md")


def test_a_script_stopped_by_a_missing_optional_module_is_skipped(tmp_path, monkeypatch):
    monkeypatch.setattr(sys.modules[__name__], "OPTIONAL_MODULES", OPTIONAL_MODULES | {"an_absent_extra"})
    page = tmp_path / "page.md"
    for code, reason in (("import an_absent_extra.part", r"needs an_absent_extra \(not installed\)"),
                         ('raise ImportError("plot needs matplotlib: pip install matplotlib")', "pip install")):
        page.write_text(f"```python\n{code}\n```\n")
        with pytest.raises(pytest.skip.Exception, match=reason):
            run_python(blocks_of(page), page, tmp_path)


def test_a_failing_script_names_the_page_and_line(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("# A page\n\n```python\nx = 1\n```\n\nText.\n\n```python\nassert x == 2\n```\n")
    with pytest.raises(pytest.fail.Exception, match=r"page\.md:10: "):
        run_python(blocks_of(page), page, tmp_path)


# What the examples say, beyond running.


def first_python_block(document: Path) -> Block:
    if not document.is_file():
        pytest.skip(f"{document} is absent")
    block = next((b for b in blocks_of(document) if b.language == "python"), None)
    assert block, f"no Python example in {document}"
    return block


def printed_json(stdout: str):
    return json.loads(stdout.strip().splitlines()[-1])


def test_the_readme_example_runs_with_the_required_dependencies_only(workdir):
    # scipy is optional (pip install .[sparse]): a fresh `pip install .` must run the example without it. A
    # package of that name that cannot be imported, first on the path, stands in for its absence.
    stand_in = workdir / "without-scipy" / "scipy"
    stand_in.mkdir(parents=True)
    (stand_in / "__init__.py").write_text("raise ModuleNotFoundError(\"No module named 'scipy'\", name='scipy')\n")
    document = REPOSITORY / "README.md"
    shows = "import json\nprint(json.dumps([str(d.dtype), d.shape, mesh.vertex_count]))"
    shown = printed_json(run_python([first_python_block(document)], document, workdir, epilogue=shows,
                                    environment=user_environment(PYTHONPATH=str(stand_in.parent))))
    assert shown == ["float64", [4], 4]  # float64, one per vertex


def test_the_guide_opening_example_runs_and_says_what_is_true(workdir):
    document = REPOSITORY / "docs" / "python.md"
    length, distance = printed_json(run_python([first_python_block(document)], document, workdir,
                                               epilogue="import json\nprint(json.dumps([p.length, d[7]]))"))
    assert abs(length - distance) <= 1e-12 * distance  # as its comment says


def test_the_farthest_vertex_line_names_a_reachable_vertex(workdir, cli):
    line = next(line for block in blocks_of(REPOSITORY / "README.md") if block.language == "shell"
                for line in block.code.splitlines() if "# the farthest" in line)
    done = subprocess.run(["bash", "-euo", "pipefail", "-c", line], cwd=workdir, env=user_environment(),
                          capture_output=True, text=True, check=True)
    vertex, distance = done.stdout.strip().split(",")
    d = exactgeo.distance(exactgeo.Mesh.load(workdir / "bunny.obj"), 0)
    assert np.isinf(d).any()  # as on the real bunny
    assert float(distance) == d[int(vertex)] == d[np.isfinite(d)].max()


def project_version() -> str:
    found = re.search(r"project\(exactgeo VERSION ([0-9.]+)", (REPOSITORY / "CMakeLists.txt").read_text())
    assert found, "CMakeLists.txt has no project(exactgeo VERSION ...) line"
    return found.group(1)


def test_the_docs_name_the_current_version():
    # Wheel and sdist names, the version line quoted from CMakeLists.txt and release tags.
    named = re.compile(r"\bexactgeo[- ](\d+\.\d+\.\d+)\b|\bVERSION (\d+\.\d+\.\d+)\b|\bv(\d+\.\d+\.\d+)\b")
    version = project_version()
    stale = [f"{page_name(document)}:{number}: {line.strip()}" for document in documents()
             for number, line in enumerate(document.read_text().splitlines(), 1)
             if any(version not in match.groups() for match in named.finditer(line))]
    assert not stale, f"the version is {version}, but these lines name another:\n" + "\n".join(stale)
