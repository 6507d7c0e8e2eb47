"""Distances: closed-form cases, the command-line tool's values, the forms sources and targets take, cut-offs,
unreachable vertices, options, statistics, the reusable solver and the GIL."""

from __future__ import annotations

import gc
import pickle
import threading

import numpy as np
import pytest
from conftest import bumpy_sheet, longest_pause_of_python_while, read_json, run_cli, write_obj

import exactgeo


@pytest.fixture(scope="module")
def flat():
    vertices, faces = exactgeo.make_grid(8, 5, 2.0, 1.25)
    return exactgeo.Mesh(vertices, faces)


@pytest.fixture(scope="module")
def sheet():
    return exactgeo.Mesh(*bumpy_sheet(12))


def test_on_a_flat_grid_distance_is_euclidean(flat):
    for source in (0, 23, 53):
        expected = np.linalg.norm(flat.vertices - flat.vertices[source], axis=1)
        np.testing.assert_allclose(exactgeo.distance(flat, source), expected, rtol=0, atol=1e-14)


def test_on_a_flat_grid_distance_from_a_surface_point_is_euclidean(flat):
    point = exactgeo.SurfacePoint(17, (0.2, 0.3, 0.5))
    position = exactgeo.point_position(flat, point)
    assert position.shape == (3,)
    expected = np.linalg.norm(flat.vertices - position, axis=1)
    np.testing.assert_allclose(exactgeo.distance(flat, point), expected, rtol=0, atol=1e-14)
    target = exactgeo.SurfacePoint(60, (0.6, 0.2, 0.2))
    found = exactgeo.distance(flat, point, targets=target)
    assert found.shape == (1,)
    assert found[0] == pytest.approx(np.linalg.norm(exactgeo.point_position(flat, target) - position), abs=1e-14)


def test_several_sources_give_the_nearest_one(sheet):
    sources = [0, 77, 160]
    rows = np.array([exactgeo.distance(sheet, s) for s in sources])
    distances, nearest = exactgeo.distance(sheet, sources, return_nearest=True)
    np.testing.assert_allclose(distances, rows.min(axis=0), rtol=1e-13, atol=0)
    assert nearest.dtype == np.int64
    np.testing.assert_allclose(rows[nearest, np.arange(len(nearest))], distances, rtol=1e-13)


def test_values_match_the_command_line(cli, tmp_path, sheet):
    mesh_file = write_obj(tmp_path / "sheet.obj", sheet.vertices, sheet.faces)
    run_cli(
        "distance",
        mesh_file,
        "--source",
        0,
        "--source",
        99,
        "--source-point",
        "40:0.2,0.3,0.5",
        "--targets",
        "5;130:0.1,0.1,0.8",
        "--labels",
        "--out",
        tmp_path / "d.csv",
        "--target-out",
        tmp_path / "t.csv",
        "--stats",
        tmp_path / "s.json",
        "--quiet",
    )
    table = np.genfromtxt(tmp_path / "d.csv", delimiter=",", names=True)
    targets = np.genfromtxt(tmp_path / "t.csv", delimiter=",", names=True)

    # The command line numbers --source vertices first, then --source-point points; in Python the same
    # sources are SurfacePoints in that order.
    sources = [
        exactgeo.vertex_point(sheet, 0),
        exactgeo.vertex_point(sheet, 99),
        exactgeo.SurfacePoint(40, (0.2, 0.3, 0.5)),
    ]
    result = exactgeo.GeodesicSolver(sheet).solve(
        sources, [exactgeo.vertex_point(sheet, 5), exactgeo.SurfacePoint(130, (0.1, 0.1, 0.8))]
    )
    # Targets stop the run early, so only vertices up to the farthest target are final.
    final = np.isfinite(result.distances)
    np.testing.assert_allclose(result.distances[final], table["distance"][final], rtol=1e-13, atol=0)
    np.testing.assert_array_equal(result.nearest_source[final], table["nearest_source"][final])
    np.testing.assert_allclose(result.target_distances, targets["distance"], rtol=1e-13, atol=0)

    stats = read_json(tmp_path / "s.json")
    for name, value in result.stats.to_dict().items():
        if not name.endswith("_seconds"):
            assert value == stats[name], name


def test_full_runs_match_the_command_line_bit_for_bit(cli, tmp_path, sheet):
    mesh_file = write_obj(tmp_path / "sheet.obj", sheet.vertices, sheet.faces)
    run_cli("distance", mesh_file, "--source", 31, "--out", tmp_path / "d.npy", "--quiet")
    np.testing.assert_array_equal(exactgeo.distance(sheet, 31), np.load(tmp_path / "d.npy"))


def test_unreachable_and_unused_vertices_are_inf_with_no_nearest_source():
    vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 0, 0], [6, 0, 0], [5, 1, 0], [9, 9, 9]]
    mesh = exactgeo.Mesh(vertices, [[0, 1, 2], [3, 4, 5]])
    distances, nearest = exactgeo.distance(mesh, 0, return_nearest=True)
    np.testing.assert_array_equal(np.isinf(distances), [False, False, False, True, True, True, True])
    np.testing.assert_array_equal(nearest, [0, 0, 0, -1, -1, -1, -1])
    assert exactgeo.distance(mesh, 0, targets=[4, 1]).tolist() == [np.inf, 1.0]
    # A target inside a face of the other piece: no nearest source either, from one source or from two.
    for sources in (0, [0, 1]):
        result = exactgeo.GeodesicSolver(mesh).solve(sources, targets=[exactgeo.SurfacePoint(1, (0.2, 0.3, 0.5))])
        assert result.target_distances.tolist() == [np.inf]
        assert result.target_nearest_source.tolist() == [-1]


def test_max_distance_cuts_off_and_costs_less(sheet):
    solver = exactgeo.GeodesicSolver(sheet)
    full = solver.solve(0)
    cut = solver.solve(0, max_distance=0.4)
    inside = full.distances <= 0.4
    np.testing.assert_array_equal(cut.distances[inside], full.distances[inside])
    assert np.isinf(cut.distances[~inside]).all() and (~inside).any()
    assert cut.stats.window_propagations < full.stats.window_propagations
    assert np.isinf(exactgeo.distance(sheet, 0, max_distance=0.0)[1:]).all()


def test_targets_return_their_distances_and_stop_early(sheet):
    full = exactgeo.GeodesicSolver(sheet).solve(0)
    near = np.flatnonzero((full.distances > 0) & (full.distances < 0.2))[:3]
    result = exactgeo.GeodesicSolver(sheet).solve(0, targets=near)
    np.testing.assert_allclose(result.target_distances, full.distances[near], rtol=1e-14)
    assert result.stats.vertex_pops < full.stats.vertex_pops
    np.testing.assert_allclose(exactgeo.distance(sheet, 0, targets=near), full.distances[near], rtol=1e-14)
    distances, nearest = exactgeo.distance(sheet, [0, 5], targets=near, return_nearest=True)
    assert distances.shape == nearest.shape == near.shape
    assert exactgeo.distance(sheet, 0, targets=[]).shape == (0,)


@pytest.mark.parametrize(
    "sources",
    [
        7,
        np.int64(7),
        np.uint8(7),
        [7],
        (7, 7),
        np.array([7], dtype=np.int16),
        np.array([7], dtype=np.uint64),
        np.array([7.0]),
        np.array([[7, 7]])[:, 0],  # a strided view
    ],
)
def test_source_vertices_of_any_integer_form(sheet, sources):
    np.testing.assert_array_equal(exactgeo.distance(sheet, sources), exactgeo.distance(sheet, 7))


def test_sources_as_points_equal_sources_as_vertices(sheet):
    expected = exactgeo.distance(sheet, [3, 50])
    points = [exactgeo.vertex_point(sheet, 3), exactgeo.vertex_point(sheet, 50)]
    np.testing.assert_allclose(exactgeo.distance(sheet, points), expected, rtol=1e-14)
    many = exactgeo.SurfacePoints([p.face for p in points], np.array([p.barycentric for p in points], dtype=np.float32))
    assert len(many) == 2 and many[1] == points[1]
    np.testing.assert_allclose(exactgeo.distance(sheet, many), expected, rtol=1e-14)
    edge = exactgeo.edge_point(sheet, 3, 4, 0.0)
    np.testing.assert_allclose(exactgeo.distance(sheet, edge), exactgeo.distance(sheet, 3), rtol=1e-14)


def test_barycentric_rounding_is_forgiven(flat):
    exact = exactgeo.distance(flat, exactgeo.SurfacePoint(3, (0.5, 0.5, 0.0)))
    noisy = exactgeo.distance(flat, exactgeo.SurfacePoint(3, (0.5, 0.5, -1e-17)))
    np.testing.assert_array_equal(exact, noisy)


@pytest.mark.parametrize(
    ("call", "error", "message"),
    [
        # The library's messages (C++ exactgeo::Error).
        (
            lambda m: exactgeo.distance(m, 10_000),
            ValueError,
            r"source vertex 10000 is out of range \(mesh has 169 vertices\)",
        ),
        (lambda m: exactgeo.distance(m, []), ValueError, "no source vertex given"),
        (
            lambda m: exactgeo.distance(m, exactgeo.SurfacePoint(999)),
            ValueError,
            r"source 0: face 999 is out of range \(mesh has 288 faces\)",
        ),
        (
            lambda m: exactgeo.distance(m, [exactgeo.SurfacePoint(0), exactgeo.SurfacePoint(1, (0.7, 0.7, 0))]),
            ValueError,
            r"source 1: \(0.69999999999999996, 0.69999999999999996, 0\) are not barycentric coordinates on face 1",
        ),
        (
            lambda m: exactgeo.distance(m, 0, targets=[1, 10_000]),
            ValueError,
            r"target 1: vertex 10000 is out of range \(mesh has 169 vertices\)",
        ),
        (
            lambda m: exactgeo.distance(m, 0, targets=exactgeo.SurfacePoint(300)),
            ValueError,
            "target 0: face 300 is out of range",
        ),
        (
            lambda m: exactgeo.distance(m, 0, targets=[exactgeo.SurfacePoint(0), 10_000]),
            ValueError,
            r"target 1: vertex 10000 is out of range \(mesh has 169 vertices\)",
        ),
        (lambda m: exactgeo.distance(m, 0, max_distance=-1), ValueError, "max_distance must be a non-negative number"),
        (
            lambda m: exactgeo.distance(m, 0, max_distance=float("nan")),
            ValueError,
            "max_distance must be a non-negative number",
        ),
        (
            lambda m: exactgeo.distance(m, 0, algorithm="dijkstra"),
            ValueError,
            "unknown algorithm 'dijkstra' \\(known: vtp",
        ),
        (
            lambda m: exactgeo.vertex_point(m, 500),
            ValueError,
            r"^vertex 500 is out of range \(mesh has 169 vertices\)$",
        ),
        (lambda m: exactgeo.edge_point(m, 0, 100, 0.5), ValueError, r"edge \(0, 100\) is not an edge of any face"),
        (
            lambda m: exactgeo.edge_point(m, 0, 1, 1.5),
            ValueError,
            r"edge \(0, 1\): parameter 1.500000 is outside \[0, 1\]",
        ),
        # What the library cannot receive, in its wording.
        (lambda m: exactgeo.distance(m, -1), ValueError, r"source vertex -1 is out of range \(mesh has 169 vertices\)"),
        (lambda m: exactgeo.distance(m, 0, targets=[-2]), ValueError, r"target 0: vertex -2 is out of range"),
        (lambda m: exactgeo.distance(m, [0.5]), ValueError, "sources must be whole numbers: source vertex 0.5"),
        (
            lambda m: exactgeo.distance(m, np.ones(169, dtype=bool)),
            ValueError,
            "sources must be integer indices, not booleans",
        ),
        (
            lambda m: exactgeo.distance(m, [[0, 1]]),
            ValueError,
            r"sources must be a single index or a 1-D array of indices",
        ),
        (lambda m: exactgeo.distance(m, "0"), ValueError, "sources must be integer indices, not dtype <U1"),
        (
            lambda m: exactgeo.distance(m, [0, exactgeo.SurfacePoint(0)]),
            ValueError,
            "sources mix vertex indices and SurfacePoints",
        ),
        (lambda m: exactgeo.SurfacePoint(-1), ValueError, "SurfacePoint: face -1 is not a face index"),
        (lambda m: exactgeo.SurfacePoint(0, (0.5, 0.5)), ValueError, "SurfacePoint: 2 barycentric coordinates, not 3"),
        (lambda m: exactgeo.SurfacePoints([0, 1], [[1, 0, 0]]), ValueError, "SurfacePoints: 2 faces but 1 rows"),
        (lambda m: exactgeo.distance(m, 0, rule4=False), TypeError, "unexpected keyword argument 'rule4'"),
    ],
)
def test_bad_queries_raise_with_the_element_named(sheet, call, error, message):
    with pytest.raises(error, match=message):
        call(sheet)


def test_a_vertex_used_by_no_face_is_not_a_source():
    mesh = exactgeo.Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [3, 3, 3]], [[0, 1, 2]])
    with pytest.raises(ValueError, match="^source vertex 3 is used by no face$"):
        exactgeo.distance(mesh, 3)


def test_every_algorithm_and_ablation_gives_the_same_distances(sheet):
    expected = exactgeo.distance(sheet, [0, 100])
    assert "vtp" in exactgeo.ALGORITHMS
    for algorithm in exactgeo.ALGORITHMS:
        for rule1 in (True, False):
            for rule23 in (True, False):
                found = exactgeo.distance(sheet, [0, 100], algorithm=algorithm, rule1=rule1, rule23=rule23)
                np.testing.assert_allclose(found, expected, rtol=1e-12, err_msg=f"{algorithm} {rule1} {rule23}")


def test_stats_are_typed_documented_attributes_of_the_engine_counters(sheet):
    stats = exactgeo.GeodesicSolver(sheet).solve(0).stats
    assert isinstance(stats, exactgeo.GeodesicStats)
    assert stats.window_propagations > 0 and stats.vertex_pops == sheet.vertex_count
    assert stats.peak_windows > 0 and stats.peak_window_bytes > 0
    assert stats.propagation_seconds >= 0
    assert isinstance(stats.window_propagations, int) and isinstance(stats.propagation_seconds, float)
    assert stats.pruning_seconds == 0  # phases are timed only when asked for
    timed = exactgeo.GeodesicSolver(sheet).solve(0, collect_timings=True).stats
    assert timed.window_propagation_seconds > 0 and timed.pruning_seconds > 0
    assert "Rules 2 and 3" in type(stats).pruning_seconds.__doc__


def test_stats_and_report_convert_compare_and_pickle(sheet):
    stats = exactgeo.GeodesicSolver(sheet).solve(0).stats
    as_dict = stats.to_dict()
    assert list(as_dict)[:2] == ["window_propagations", "prime_propagations"]  # declaration order
    assert as_dict["window_propagations"] == stats.window_propagations
    assert pickle.loads(pickle.dumps(stats)) == stats
    assert "window_propagations=" in repr(stats)
    changed = pickle.loads(pickle.dumps(stats))
    changed.queue_seconds += 1
    assert changed != stats
    report = sheet.report
    assert isinstance(report, exactgeo.MeshReport)
    assert pickle.loads(pickle.dumps(report)) == report
    assert report.to_dict()["vertices"] == sheet.vertex_count


def test_a_solver_is_reusable_and_its_results_stay_valid(sheet):
    solver = exactgeo.GeodesicSolver(sheet)
    first = solver.solve(0)
    second = solver.solve(100)
    again = solver.solve(0)
    np.testing.assert_array_equal(first.distances, again.distances)
    np.testing.assert_array_equal(first.distances, exactgeo.distance(sheet, 0))  # not overwritten by later runs
    assert not np.array_equal(first.distances, second.distances)
    assert first.stats.window_propagations == again.stats.window_propagations


def test_a_solver_keeps_its_mesh_alive():
    solver = exactgeo.GeodesicSolver(exactgeo.Mesh(*exactgeo.make_grid(3, 3, 1.0, 1.0)))
    gc.collect()
    assert solver.solve(0).distances[15] == pytest.approx(np.sqrt(2))
    assert solver.mesh.vertex_count == 16


def test_threads_share_a_mesh_and_a_solver(sheet):
    expected = {s: exactgeo.distance(sheet, s) for s in range(0, 160, 20)}
    shared = exactgeo.GeodesicSolver(sheet)
    found, shared_found = {}, {}

    def work(s):
        found[s] = exactgeo.distance(sheet, s)
        shared_found[s] = shared.solve(s).distances  # one call at a time on the shared solver

    threads = [threading.Thread(target=work, args=(s,)) for s in expected]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for s, values in expected.items():
        np.testing.assert_array_equal(found[s], values)
        np.testing.assert_array_equal(shared_found[s], values)


def test_the_gil_is_released_while_propagating():
    big = exactgeo.Mesh(*bumpy_sheet(160))
    duration, pause = longest_pause_of_python_while(lambda: [exactgeo.distance(big, s) for s in (0, 5000, 20000)])
    assert pause < duration / 3, (duration, pause)
    duration, pause = longest_pause_of_python_while(lambda: exactgeo.distance_matrix(big, [0, 5000, 20000], threads=1))
    assert pause < duration / 3, (duration, pause)


def test_targets_beyond_the_cut_off_are_inf_or_exact():
    mesh = exactgeo.Mesh(*bumpy_sheet(12))
    targets = [5, 168, 30, 100]
    truth = exactgeo.distance(mesh, 0)[targets]
    cutoff = float(np.median(truth))
    beyond = truth > cutoff
    cut = exactgeo.distance(mesh, 0, targets=targets, max_distance=cutoff)
    np.testing.assert_array_equal(np.isinf(cut), beyond)
    np.testing.assert_array_equal(cut[~beyond], truth[~beyond])
    exact, nearest = exactgeo.distance(
        mesh, 0, targets=targets, max_distance=cutoff, targets_beyond="exact", return_nearest=True
    )
    np.testing.assert_array_equal(exact, truth)
    assert nearest.tolist() == [0] * len(targets)
    # Without targets or without a cut-off the option changes nothing.
    np.testing.assert_array_equal(
        exactgeo.distance(mesh, 0, max_distance=cutoff, targets_beyond="exact"),
        exactgeo.distance(mesh, 0, max_distance=cutoff),
    )
    np.testing.assert_array_equal(exactgeo.distance(mesh, 0, targets=targets, targets_beyond="exact"), truth)
    with pytest.raises(ValueError, match="targets_beyond must be 'inf' or 'exact', not 'all'"):
        exactgeo.distance(mesh, 0, targets=targets, max_distance=cutoff, targets_beyond="all")


@pytest.mark.parametrize(
    ("options", "error", "message"),
    [
        ({"threads": 2**40}, ValueError, "threads must be at most 4294967295, not 1099511627776"),
        ({"threads": -1}, ValueError, "threads must be at least 0, not -1"),
        ({"threads": 1.5}, TypeError, "threads must be an integer, not 1.5"),
        ({"threads": True}, TypeError, "threads must be an integer, not True"),
        ({"rule1": "no"}, TypeError, "rule1 must be True or False, not 'no'"),
        ({"rule23": 0}, TypeError, "rule23 must be True or False, not 0"),
        ({"collect_timings": None}, TypeError, "collect_timings must be True or False, not None"),
        ({"algorithm": 1}, TypeError, "algorithm must be a string, not 1"),
        ({"max_distance": "far"}, TypeError, "max_distance must be a number or None, not 'far'"),
    ],
)
def test_options_of_the_wrong_kind_are_named_by_every_entry_point(sheet, options, error, message):
    # These raised "RuntimeError: std::bad_cast", or took "no" for true.
    calls = [
        lambda: exactgeo.distance(sheet, 0, **options),
        lambda: exactgeo.GeodesicSolver(sheet).solve(0, **options),
        lambda: exactgeo.distance_matrix(sheet, [0, 5], **options),
        lambda: exactgeo.farthest_point_sampling(sheet, 3, **options),
    ]
    for call in calls:
        with pytest.raises(error, match=message):
            call()


def test_numpy_booleans_and_integers_are_options_too(sheet):
    expected = exactgeo.distance(sheet, 0, rule1=False, threads=2)
    np.testing.assert_array_equal(exactgeo.distance(sheet, 0, rule1=np.False_, threads=np.int64(2)), expected)


def test_stats_give_the_threads_a_run_shared(sheet):
    # The face-sorted variants are sequential, whatever the option asks for.
    assert exactgeo.GeodesicSolver(sheet).solve(0, algorithm="ftp", threads=4).stats.threads == 1
    assert exactgeo.GeodesicSolver(sheet).solve(0, algorithm="opftp", threads=4).stats.threads == 1
    assert exactgeo.GeodesicSolver(sheet).solve(0, threads=2).stats.threads == 2
    assert exactgeo.GeodesicSolver(sheet).solve(0, threads=1).stats.threads == 1
