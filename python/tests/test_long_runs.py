"""Long runs: progress (a tqdm bar or a function), Ctrl-C stopping the engine within milliseconds, and a
solver shared between threads refusing to answer about another thread's run."""

from __future__ import annotations

import subprocess
import sys
import textwrap
import threading

import numpy as np
import pytest
from conftest import bumpy_sheet

import exactgeo


@pytest.fixture(scope="module")
def sheet():
    return exactgeo.Mesh(*bumpy_sheet(12))


@pytest.fixture(scope="module")
def large():
    """Large enough that a single run goes to a worker thread (and so reports progress and stops on Ctrl-C)."""
    return exactgeo.Mesh(*exactgeo.make_bumpy_torus(200, 120))


def test_a_progress_function_hears_the_work_up_to_its_end(sheet, large):
    reports: list[tuple[int, int]] = []
    exactgeo.distance_matrix(sheet, list(range(40)), threads=2,
                             progress=lambda done, total: reports.append((done, total)))
    assert reports and reports[-1] == (40, 40)
    assert all(total == 40 for _, total in reports) and [d for d, _ in reports] == sorted(d for d, _ in reports)

    reports.clear()
    exactgeo.farthest_point_sampling(sheet, 10, progress=lambda done, total: reports.append((done, total)))
    assert reports[-1] == (10, 10)

    reports.clear()
    expected = exactgeo.distance(large, 0)
    found = exactgeo.distance(large, 0, progress=lambda done, total: reports.append((done, total)))
    np.testing.assert_array_equal(found, expected)  # the worker thread computes the same distances
    assert reports[-1] == (1000, 1000)


def test_building_a_mesh_reports_progress_up_to_its_end(large):
    reports: list[tuple[int, int]] = []
    rebuilt = exactgeo.Mesh(large.vertices, large.faces, progress=lambda done, total: reports.append((done, total)))
    assert rebuilt.report == large.report
    assert reports and reports[-1] == (1000, 1000)
    assert [d for d, _ in reports] == sorted(d for d, _ in reports)


def test_progress_true_draws_a_tqdm_bar(sheet, capsys):
    exactgeo.distance_matrix(sheet, list(range(20)), progress=True)
    assert "rows" in capsys.readouterr().err


def test_an_exception_in_the_progress_function_stops_the_work(large):
    def fail(done: int, total: int) -> None:
        raise LookupError("stop here")

    with pytest.raises(LookupError, match="stop here"):
        exactgeo.distance_matrix(large, [0] * 1000, threads=1, progress=fail)


def test_bad_progress_arguments(sheet):
    with pytest.raises(TypeError, match="progress must be True, False, None or a function"):
        exactgeo.distance_matrix(sheet, [0], progress="yes")


CTRL_C = textwrap.dedent(
    """
    import os, signal, sys, threading, time
    import exactgeo
    mesh = exactgeo.Mesh(*exactgeo.make_bumpy_torus(200, 120))
    call = sys.argv[1]
    def interrupt():
        time.sleep(0.5)
        global sent
        sent = time.perf_counter()
        os.kill(os.getpid(), signal.SIGINT)
    threading.Thread(target=interrupt, daemon=True).start()
    try:
        if call == "matrix":
            small = exactgeo.Mesh(*exactgeo.make_bumpy_torus(100, 60))  # 6,000 vertices, 5,000 rows: 240 MB
            exactgeo.distance_matrix(small, [0] * 5000, threads=2)  # a minute of work
        elif call == "sampling":
            exactgeo.farthest_point_sampling(mesh, mesh.vertex_count)
        elif call == "mesh":
            vertices, faces = mesh.vertices.copy(), mesh.faces.copy()
            while True:
                exactgeo.Mesh(vertices, faces)
        else:
            while True:
                exactgeo.distance(mesh, 0)
    except KeyboardInterrupt:
        print(f"interrupted after {time.perf_counter() - sent:.3f} s")
        sys.exit(0)
    sys.exit(1)
    """
)


@pytest.mark.parametrize("call", ["matrix", "sampling", "single", "mesh"])
def test_ctrl_c_raises_keyboard_interrupt_in_long_calls(call):
    # Without the interrupt each call runs for a minute or more; the latency is printed, not asserted.
    done = subprocess.run([sys.executable, "-c", CTRL_C, call], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "interrupted after" in done.stdout
    print(call, done.stdout.strip())


def test_a_solver_shared_by_threads_refuses_paths_of_the_other_threads_run(sheet):
    solver = exactgeo.GeodesicSolver(sheet)
    solver.solve(0)
    other = threading.Thread(target=solver.solve, args=(100,))
    other.start()
    other.join()
    with pytest.raises(RuntimeError, match="one GeodesicSolver per thread"):
        solver.path_to_vertex(50)
    result = solver.solve(0)  # this thread's own run again: its paths are answered
    assert solver.path_to_vertex(50).length == pytest.approx(result.distances[50], rel=1e-9)


def test_one_solver_per_thread_gives_each_thread_its_own_paths(sheet):
    expected = {s: exactgeo.path(sheet, s, 77).length for s in (0, 168)}
    lengths: dict[int, list[float]] = {0: [], 168: []}

    def work(source: int) -> None:
        solver = exactgeo.GeodesicSolver(sheet)
        for _ in range(30):
            solver.solve(source)
            lengths[source].append(solver.path_to_vertex(77).length)

    threads = [threading.Thread(target=work, args=(s,)) for s in (0, 168)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for source, found in lengths.items():
        assert found == [expected[source]] * 30


LIMITED_THREADS = textwrap.dedent(
    """
    import exactgeo, numpy as np
    mesh = exactgeo.Mesh(*exactgeo.make_bumpy_torus(40, 20))
    many, one = exactgeo.distance(mesh, 0, threads=64), exactgeo.distance(mesh, 0, threads=1)
    print(bool(np.max(np.abs(many - one)) <= 1e-14 * one.max()))
    """
)


def test_a_run_goes_on_with_the_threads_the_system_starts():
    # Under an address-space limit (common on clusters) the system refuses most of 64 threads; the run used to
    # wait for them forever. The timeout turns a hang into a failure.
    import os
    import resource

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (300 << 20, 300 << 20))

    done = subprocess.run([sys.executable, "-c", LIMITED_THREADS], preexec_fn=limit, capture_output=True, text=True,
                          timeout=120, env={**os.environ, "OPENBLAS_NUM_THREADS": "1"})
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "True"
