"""Shared helpers of the Python package's tests. They run against the installed package (pip install .).

Paths can be overridden: EXACTGEO_BUILD_DIR (the CMake build with the command-line tool and the CGAL
driver, default build/), EXACTGEO_MESH_DIR (the shared meshes, default ../shared/meshes beside the
repository). Tests needing them skip when they are absent.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import exactgeo

REPOSITORY = Path(__file__).resolve().parents[2]
BUILD_DIR = Path(os.environ.get("EXACTGEO_BUILD_DIR", REPOSITORY / "build")).resolve()  # the tests change folders
CLI = BUILD_DIR / "cli" / "exactgeo"
MESH_DIR = Path(os.environ.get("EXACTGEO_MESH_DIR", REPOSITORY.parent / "shared" / "meshes"))

# A suite started in the background by a shell without job control (`make test &`, nohup) inherits SIGINT
# ignored, and Python then never raises KeyboardInterrupt, here or in the processes the tests start: the Ctrl-C
# tests need SIGINT as a terminal delivers it.
if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


def bumpy_sheet(n: int, seed: int = 7) -> tuple[np.ndarray, np.ndarray]:
    """A curved open surface: the unit grid lifted by a smooth bump plus seeded noise, so that it has saddle
    vertices and pseudo-sources, with coordinates that need all 17 digits."""
    vertices, faces = exactgeo.make_grid(n, n, 1.0, 1.0)
    rng = np.random.default_rng(seed)
    x, y = vertices[:, 0], vertices[:, 1]
    vertices[:, 2] = 0.3 * np.sin(3 * x) * np.cos(2 * y) + 0.02 * rng.standard_normal(len(vertices))
    return vertices, faces


def write_obj(path: Path, vertices: np.ndarray, faces: np.ndarray) -> Path:
    """%.17g round-trips every double: the command-line tool reads exactly the arrays Python has."""
    with open(path, "w") as file:
        np.savetxt(file, vertices, fmt="v %.17g %.17g %.17g")
        np.savetxt(file, np.asarray(faces, dtype=np.int64) + 1, fmt="f %d %d %d")
    return path


def run_cli(*arguments: object) -> subprocess.CompletedProcess:
    return subprocess.run([str(CLI), *map(str, arguments)], capture_output=True, text=True, check=True)


def longest_pause_of_python_while(call) -> tuple[float, float]:
    """Runs `call` in a thread while this one counts; returns the call's duration and the longest time this
    thread went without running. Holding the GIL through the call would make that pause the whole call."""
    done = threading.Event()
    worker = threading.Thread(target=lambda: (call(), done.set()))
    start = time.perf_counter()
    worker.start()
    last, pause = time.perf_counter(), 0.0
    while not done.is_set():
        now = time.perf_counter()
        pause, last = max(pause, now - last), now
    worker.join()
    return time.perf_counter() - start, pause


def read_json(path: Path) -> dict:
    with open(path) as file:
        return json.load(file)


@pytest.fixture
def cli() -> Path:
    if not CLI.is_file():
        pytest.skip(f"command-line tool not built at {CLI} (make build)")
    return CLI


def shared_mesh(name: str) -> Path:
    path = MESH_DIR / f"{name}.obj"
    if not path.is_file():
        pytest.skip(f"shared mesh {path} is absent")
    return path


def zarr3_or_skip():
    """zarr-python 3, which the Zarr stores need, or a skip of the calling test module saying what to install."""
    zarr = pytest.importorskip("zarr", reason="reading Zarr stores needs zarr: pip install 'zarr>=3'")
    if int(zarr.__version__.split(".")[0]) < 3:
        pytest.skip(f"exactgeo.distributed needs zarr-python 3, not {zarr.__version__}", allow_module_level=True)
    return zarr
