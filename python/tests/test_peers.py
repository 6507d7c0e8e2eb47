"""What docs/python.md ("Coming from pygeodesic, gdist, libigl or potpourri3d") and docs/recipes.md say the other
geodesic packages do, checked against the packages themselves: the calls the tables map to ours, and each
difference in behaviour the bullets state. A test skips when its package is not installed (all four are in
python/requirements-test.txt, at the benchmark's pins: the figures the guide quotes come from those versions).

Agreement on the shared meshes, and gdist's and pygeodesic's targets beyond max_distance, are in
test_agreement.py. What may crash a package is run in a process of its own.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from conftest import bumpy_sheet, shared_mesh

import exactgeo

TOLERANCE = 1e-12  # of the largest distance: two exact solvers in double precision
KIRSANOV_INFINITY = 1e100  # what Kirsanov's code (gdist, pygeodesic) calls unreachable


def pygeodesic():
    return pytest.importorskip("pygeodesic.geodesic", reason="pygeodesic not installed (python/requirements-test.txt)")


def gdist():
    return pytest.importorskip("gdist", reason="gdist not installed (tvb-gdist, python/requirements-test.txt)")


def igl():
    return pytest.importorskip("igl", reason="libigl not installed (python/requirements-test.txt)")


def potpourri3d():
    return pytest.importorskip("potpourri3d", reason="potpourri3d not installed (python/requirements-test.txt)")


def sheet() -> tuple[np.ndarray, np.ndarray, exactgeo.Mesh]:
    """A curved open surface with saddles: the arrays, float64 and uint32, and our mesh of them."""
    vertices, faces = bumpy_sheet(12)
    return vertices, faces, exactgeo.Mesh(vertices, faces)


def two_sheets() -> tuple[np.ndarray, np.ndarray, int]:
    """Two copies of a sheet side by side, not joined: the second copy's vertices, from the returned index on,
    are unreachable from the first's."""
    vertices, faces = bumpy_sheet(4)
    apart = vertices + [5.0, 0.0, 0.0]
    return np.vstack([vertices, apart]), np.vstack([faces, faces + len(vertices)]).astype(np.int32), len(vertices)


def assert_close(theirs, ours) -> None:
    theirs, ours = np.asarray(theirs, dtype=np.float64), np.asarray(ours)
    assert np.abs(theirs - ours).max() <= TOLERANCE * ours[np.isfinite(ours)].max()


def run_alone(code: str) -> subprocess.CompletedProcess:
    """Runs code in a Python process of its own, so that a crash would take only that process down."""
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)


# A source vertex past the end of homer's vertices, given to a package in a process of its own: how many distinct
# values it returns, if it returns, and the smallest.
OUT_OF_RANGE = """
import numpy as np, exactgeo
mesh = exactgeo.Mesh.load({path!r})
V, F, source = mesh.vertices, mesh.faces, mesh.vertex_count + {past}
{call}
values = np.unique(d)
print(len(values), values[0])
"""


def assert_the_source_is_not_checked(call: str, just_past_returns: float | None = None) -> None:
    """No error for a source out of range: the process reads past the end of an array, and either a signal
    (SIGSEGV, SIGBUS) ends it or it returns whatever it computed from there, which differs from run to run for
    some packages. Only what the guide states for a source just past the end is checked beyond that: the one
    value it then gives every vertex."""
    for past in (1, 100_000):
        run = run_alone(OUT_OF_RANGE.format(path=str(shared_mesh("homer")), past=past, call=call))
        assert run.returncode <= 0, run.stderr  # a signal or nothing: no exception
        if run.returncode == 0 and past == 1 and just_past_returns is not None:
            assert run.stdout.split() == ["1", str(just_past_returns)]


# pygeodesic


def test_pygeodesic_calls_in_the_table():
    geodesic = pygeodesic()
    vertices, faces, mesh = sheet()
    solver = geodesic.PyGeodesicAlgorithmExact(vertices, faces)
    sources, targets = [0, 143], np.array([5, 70, 100])
    d, best = solver.geodesicDistances(np.array(sources))
    ours, nearest = exactgeo.distance(mesh, sources, return_nearest=True)
    assert_close(d, ours)
    np.testing.assert_array_equal(best, nearest)
    d, best = solver.geodesicDistances(np.array(sources), targets)
    ours, nearest = exactgeo.distance(mesh, sources, targets=targets, return_nearest=True)
    assert_close(d, ours)
    np.testing.assert_array_equal(best, nearest)
    length, points = solver.geodesicDistance(0, 100)
    path = exactgeo.path(mesh, 0, 100)
    assert abs(length - path.length) <= TOLERANCE * path.length
    # Theirs runs from the target to the source, ours from the source to the target.
    np.testing.assert_allclose(points[0], vertices[100], rtol=0, atol=1e-12)
    np.testing.assert_allclose(points[-1], vertices[0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(path.points[0], vertices[0], rtol=0, atol=1e-12)


def test_pygeodesic_prints_errors_and_returns_none(capfd):
    geodesic = pygeodesic()
    vertices, faces, mesh = sheet()
    assert geodesic.PyGeodesicAlgorithmExact(vertices, faces).geodesicDistances(np.array([mesh.vertex_count])) == (
        None, None)
    assert "outside limits of mesh" in capfd.readouterr().out
    broken = faces.astype(np.int32)
    broken[0, 0] = mesh.vertex_count + 5
    solver = geodesic.PyGeodesicAlgorithmExact(vertices, broken)  # a solver all the same
    assert "Error in PyGeodesicAlgorithmExact" in capfd.readouterr().out
    assert solver.geodesicDistances(np.array([0])) == (None, None)
    assert solver.geodesicDistance(0, 1) == (None, None)
    assert "not initialized correctly" in capfd.readouterr().out
    with pytest.raises(ValueError, match="out of range|vertex"):
        exactgeo.distance(mesh, mesh.vertex_count)


def test_pygeodesic_unreachable_vertices():
    geodesic = pygeodesic()
    vertices, faces, apart = two_sheets()
    solver = geodesic.PyGeodesicAlgorithmExact(vertices, faces)
    length, points = solver.geodesicDistance(0, apart)
    assert length == 0.0 and len(points) == 0
    d, best = solver.geodesicDistances(np.array([0]))
    assert np.isinf(d[apart:]).all() and (best[apart:] == 0).all()
    # With a cut-off, an unreachable target is inf, not Kirsanov's 1e100.
    d, _ = solver.geodesicDistances(np.array([0]), np.array([1, apart]), 0.5)
    assert np.isfinite(d[0]) and np.isinf(d[1])
    mesh = exactgeo.Mesh(vertices, faces)
    ours, nearest = exactgeo.distance(mesh, 0, return_nearest=True)
    assert np.isinf(ours[apart:]).all() and (nearest[apart:] == -1).all()
    path = exactgeo.path(mesh, 0, apart)
    assert path.length == np.inf and len(path.points) == 0 and path.source == -1


def test_pygeodesic_computes_on_with_nan_coordinates():
    geodesic = pygeodesic()
    vertices, faces = exactgeo.make_grid(10, 10, 1.0, 1.0)
    vertices[:, 2] = 0.05 * np.random.default_rng(3).standard_normal(len(vertices))
    truth = exactgeo.distance(exactgeo.Mesh(vertices, faces), 0)
    middle = 5 * 11 + 5
    vertices[middle] = np.nan
    d, _ = geodesic.PyGeodesicAlgorithmExact(vertices, faces.astype(np.int32)).geodesicDistances(np.array([0]))
    assert not np.isnan(d).any()
    assert np.isinf(d[middle]) and np.isinf(np.delete(d, middle)).any()  # inf there and around it
    finite = np.isfinite(d)
    assert (d[finite] >= truth[finite] - 1e-12).all() and (d[finite] > truth[finite] + 0.1).any()  # too long
    with pytest.raises(ValueError, match=f"vertex {middle}"):
        exactgeo.Mesh(vertices, faces)


# gdist


def test_gdist_calls_in_the_table():
    gd = gdist()
    vertices, faces, mesh = sheet()
    faces32 = faces.astype(np.int32)
    assert_close(gd.compute_gdist(vertices, faces32, source_indices=np.array([7], dtype=np.int32)),
                 exactgeo.distance(mesh, 7))
    cutoff = 0.4
    near = gd.compute_gdist(vertices, faces32, np.array([0, 143], np.int32), max_distance=cutoff)
    ours = exactgeo.distance(mesh, [0, 143], max_distance=cutoff)
    beyond = np.isinf(ours)
    assert beyond.any() and (near[beyond] == KIRSANOV_INFINITY).all()  # 1e100 beyond the cut-off
    assert_close(near[~beyond], ours[~beyond])
    # Every vertex a source within a radius: CSC there, CSR here with the zero at each source stored.
    local = gd.local_gdist_matrix(vertices, faces32, max_distance=0.2)
    matrix = exactgeo.distance_matrix(mesh, np.arange(mesh.vertex_count), max_distance=0.2)
    assert local.format == "csc" and matrix.format == "csr"
    assert matrix.nnz == local.nnz + mesh.vertex_count
    assert_close(local.toarray(), matrix.toarray())


def test_gdist_distances_between_selected_points():
    scipy_sparse = pytest.importorskip("scipy.sparse")
    gd = gdist()
    vertices, faces, mesh = sheet()
    points = np.array([3, 17, 40, 60, 120], dtype=np.int32)
    n = mesh.vertex_count
    dense = exactgeo.distance_matrix(mesh, points, targets=points)
    for cutoff in (0.1, np.inf):  # every pair exact, whatever the cut-off
        theirs = gd.distance_matrix_of_selected_points(vertices, faces.astype(np.int32), points, max_distance=cutoff)
        assert theirs.shape == (n, n) and not theirs.diagonal().any()
        assert abs(theirs - theirs.T).max() == 0
        # The guide's conversion of our matrix to their layout.
        P, Q = np.indices(dense.shape)
        off = P != Q
        converted = scipy_sparse.csc_array((dense[off], (points[P[off]], points[Q[off]])), shape=(n, n))
        assert_close(theirs.toarray(), converted.toarray())


def test_gdist_takes_float64_and_int32_only():
    gd = gdist()
    vertices, faces, mesh = sheet()
    source = np.array([0], dtype=np.int32)
    for coordinates, indices in ((vertices.astype(np.float32), faces.astype(np.int32)), (vertices, faces),
                                 (vertices, faces.astype(np.int64))):
        with pytest.raises(ValueError, match="Buffer dtype mismatch"):
            gd.compute_gdist(coordinates, indices, source)
    exactgeo.distance(exactgeo.Mesh(vertices.astype(np.float32), faces.astype(np.int64)), 0)


def test_gdist_cut_off_values():
    gd = gdist()
    vertices, faces, apart = two_sheets()
    source = np.array([0], dtype=np.int32)
    targets = np.array([1, apart], dtype=np.int32)
    # An unreachable target: 1e100 with a finite cut-off, inf without one.
    assert gd.compute_gdist(vertices, faces, source, targets, max_distance=0.5)[1] == KIRSANOV_INFINITY
    assert np.isinf(gd.compute_gdist(vertices, faces, source, targets)[1])
    # A target exactly at the cut-off gets inf: gdist replaces values equal to max_distance.
    at = gd.compute_gdist(vertices, faces, source, targets[:1])[0]
    assert np.isinf(gd.compute_gdist(vertices, faces, source, targets[:1], max_distance=at)[0])
    mesh = exactgeo.Mesh(vertices, faces)
    ours = exactgeo.distance(mesh, 0, targets=[1])[0]
    assert exactgeo.distance(mesh, 0, targets=[1], max_distance=ours)[0] == ours
    assert np.isinf(exactgeo.distance(mesh, 0, targets=[apart], max_distance=0.5)[0])


def test_gdist_does_not_check_the_source():
    gdist()
    assert_the_source_is_not_checked(
        "import gdist\nd = gdist.compute_gdist(V, F.astype(np.int32), np.array([source], np.int32))", np.inf)


# libigl


def test_libigl_calls_in_the_table():
    ig = igl()
    vertices, faces, mesh = sheet()
    sources, targets = np.array([0, 143]), np.array([5, 70, 100])
    assert_close(ig.exact_geodesic(vertices, faces, VS=sources, VT=targets),
                 exactgeo.distance(mesh, sources, targets=targets))
    assert_close(ig.exact_geodesic(vertices, faces, VS=sources, VT=np.arange(mesh.vertex_count)),
                 exactgeo.distance(mesh, sources))
    source_faces = np.array([10, 200])
    centroids = exactgeo.SurfacePoints(source_faces, np.full((len(source_faces), 3), 1 / 3))
    assert_close(ig.exact_geodesic(vertices, faces, FS=source_faces, VT=np.arange(mesh.vertex_count)),
                 exactgeo.distance(mesh, centroids))


def test_libigl_unreachable_vertices_are_zero():
    ig = igl()
    vertices, faces, apart = two_sheets()
    d = ig.exact_geodesic(vertices, faces, VS=np.array([0]), VT=np.arange(len(vertices)))
    assert (d[apart:] == 0.0).all() and (d[1:apart] > 0).all()
    assert np.isinf(exactgeo.distance(exactgeo.Mesh(vertices, faces), 0)[apart:]).all()


def test_libigl_does_not_check_the_source():
    igl()
    assert_the_source_is_not_checked(
        "import igl\nd = igl.exact_geodesic(V, F, VS=np.array([source]), VT=np.arange(len(V)))", 0.0)


# potpourri3d


# The guide's figures for the heat method's error: 1.8-7.8% on the manifold meshes (those here among them, the
# larger ones from the benchmark), 11% and 21% on the non-manifold beetle and suzanne.
HEAT_MESHES = {"woody": (0.018, 0.078), "cow": (0.018, 0.078), "spot": (0.018, 0.078), "homer": (0.018, 0.078),
               "beetle": (0.105, 0.115), "suzanne": (0.205, 0.215)}


@pytest.mark.filterwarnings("ignore:.*vertices are unreachable:UserWarning")
@pytest.mark.parametrize("name", HEAT_MESHES)
def test_the_heat_method_error(name):
    pp3d = potpourri3d()
    mesh = exactgeo.Mesh.load(shared_mesh(name))
    exact = exactgeo.distance(mesh, 0)
    heat = pp3d.MeshHeatMethodDistanceSolver(mesh.vertices, mesh.faces).compute_distance(0)
    reached = np.isfinite(exact)
    error = np.abs(heat[reached] - exact[reached]).max() / exact[reached].max()
    low, high = HEAT_MESHES[name]
    assert low <= error <= high


def test_potpourri3d_calls_in_the_table():
    pp3d = potpourri3d()
    vertices, faces, mesh = sheet()
    solver = pp3d.MeshHeatMethodDistanceSolver(vertices, faces)
    np.testing.assert_array_equal(solver.compute_distance(7), pp3d.compute_distance(vertices, faces, 7))
    for theirs, ours in ((solver.compute_distance(7), exactgeo.distance(mesh, 7)),
                         (solver.compute_distance_multisource([0, 143]), exactgeo.distance(mesh, [0, 143]))):
        assert np.abs(theirs - ours).max() <= 0.08 * ours.max()  # approximately
    points = pp3d.EdgeFlipGeodesicSolver(vertices, faces).find_geodesic_path(0, 100)
    np.testing.assert_allclose(points[[0, -1]], vertices[[0, 100]], rtol=0, atol=1e-12)


def test_the_edge_flip_path_is_locally_shortest_not_always_shortest():
    pp3d = potpourri3d()
    mesh = exactgeo.Mesh.load(shared_mesh("homer"))
    solver = pp3d.EdgeFlipGeodesicSolver(mesh.vertices, mesh.faces)
    targets = np.arange(1, mesh.vertex_count, 200)  # 31 vertices
    distances = exactgeo.distance(mesh, 0)[targets]
    lengths = np.array([np.linalg.norm(np.diff(solver.find_geodesic_path(0, int(t)), axis=0), axis=1).sum()
                        for t in targets])
    excess = lengths / distances - 1
    assert (excess >= -1e-12).all()  # never shorter than the shortest
    assert (excess > 1e-9).sum() == 22 and round(excess.max(), 3) == 0.049  # as the guide says
    ours = np.array([exactgeo.path(mesh, 0, int(t)).length for t in targets])
    np.testing.assert_allclose(ours, distances, rtol=1e-12)


def test_the_heat_method_reaches_every_component():
    pp3d = potpourri3d()
    vertices, faces, apart = two_sheets()
    heat = pp3d.compute_distance(vertices, faces, 0)
    assert np.isfinite(heat[apart:]).all()
    assert np.isinf(exactgeo.distance(exactgeo.Mesh(vertices, faces), 0)[apart:]).all()


def test_potpourri3d_does_not_check_the_source():
    potpourri3d()
    assert_the_source_is_not_checked("import potpourri3d\nd = potpourri3d.compute_distance(V, F, source)")


def test_potpourri3d_refuses_vertices_used_by_no_face():
    pp3d = potpourri3d()
    vertices, faces = exactgeo.make_grid(2, 2, 1.0, 1.0)
    unused_inside = np.insert(vertices, 4, [9.0, 9.0, 9.0], axis=0)  # vertex 4, the others renumbered
    renumbered = np.where(faces >= 4, faces + 1, faces)
    with pytest.raises(RuntimeError, match="unreferenced vertex 4"):
        pp3d.compute_distance(unused_inside, renumbered, 0)
    # After the last used vertex, one is dropped instead: a value fewer than there are vertices.
    unused_last = np.vstack([vertices, [9.0, 9.0, 9.0]])
    assert len(pp3d.compute_distance(unused_last, faces, 0)) == len(vertices)
    ours = exactgeo.distance(exactgeo.Mesh(unused_inside, renumbered), 0)
    assert len(ours) == len(unused_inside) and np.isinf(ours[4]) and np.isfinite(np.delete(ours, 4)).all()


# docs/recipes.md, "Moving from gdist, pygeodesic or potpourri3d": the peer calls in its comments


def test_the_recipe_comments_name_calls_that_give_the_same_values():
    gd, geodesic, pp3d = gdist(), pygeodesic(), potpourri3d()
    V, F = exactgeo.make_icosphere(3)
    mesh = exactgeo.Mesh(V, F)
    F32 = F.astype(np.int32)
    d = exactgeo.distance(mesh, 0)
    assert_close(gd.compute_gdist(V, F32, np.array([0], np.int32)), d)
    assert_close(geodesic.PyGeodesicAlgorithmExact(V, F).geodesicDistances(np.array([0]))[0], d)
    assert np.abs(pp3d.compute_distance(V, F, 0) - d).max() <= 0.08 * d.max()
    near = exactgeo.distance(mesh, [0, 1], targets=[5, 6, 7], max_distance=0.5, targets_beyond="exact")
    assert (near > 0.5).all()  # beyond the cut-off, all three
    assert_close(gd.compute_gdist(V, F32, np.array([0, 1], np.int32), np.array([5, 6, 7], np.int32),
                                  max_distance=0.5), near)
    length, points = geodesic.PyGeodesicAlgorithmExact(V, F).geodesicDistance(0, 7)
    p = exactgeo.path(mesh, 0, 7)
    assert abs(length - p.length) <= TOLERANCE * p.length
    np.testing.assert_allclose(points[::-1], p.points, rtol=0, atol=1e-9)  # the same points, the other way
    S = exactgeo.distance_matrix(mesh, np.arange(mesh.vertex_count), max_distance=0.2)
    local = gd.local_gdist_matrix(V, F32, max_distance=0.2)
    assert_close(local.toarray(), S.toarray())
