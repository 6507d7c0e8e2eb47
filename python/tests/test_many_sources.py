"""Distance matrices (dense, sparse with a cut-off, on one or two threads) and farthest-point sampling."""

from __future__ import annotations

import sys

import numpy as np
import pytest
import scipy.sparse
from conftest import bumpy_sheet

import exactgeo


@pytest.fixture(scope="module")
def sheet():
    return exactgeo.Mesh(*bumpy_sheet(12))


SOURCES = [0, 13, 84, 168, 99, 7]


def test_dense_rows_are_the_single_source_distances(sheet):
    matrix = exactgeo.distance_matrix(sheet, SOURCES)
    assert matrix.shape == (len(SOURCES), sheet.vertex_count) and matrix.dtype == np.float64
    np.testing.assert_array_equal(matrix, np.array([exactgeo.distance(sheet, s) for s in SOURCES]))


def test_rows_are_identical_whatever_the_thread_count(sheet):
    one = exactgeo.distance_matrix(sheet, SOURCES, threads=1)
    two = exactgeo.distance_matrix(sheet, SOURCES, threads=2)
    np.testing.assert_array_equal(one, two)
    np.testing.assert_array_equal(one, exactgeo.distance_matrix(sheet, np.array(SOURCES, dtype=np.int16)))
    sparse_one = exactgeo.distance_matrix(sheet, SOURCES, max_distance=0.3, threads=1)
    sparse_two = exactgeo.distance_matrix(sheet, SOURCES, max_distance=0.3, threads=2)
    assert (sparse_one != sparse_two).nnz == 0


def test_a_cut_off_gives_a_sparse_matrix_of_the_near_entries(sheet):
    radius = 0.3
    dense = exactgeo.distance_matrix(sheet, SOURCES)
    sparse = exactgeo.distance_matrix(sheet, SOURCES, max_distance=radius)
    assert isinstance(sparse, scipy.sparse.csr_array) and sparse.shape == dense.shape
    near = dense <= radius
    assert sparse.nnz == near.sum()
    rows, columns = sparse.nonzero()  # the 0 at each source is stored but is not "nonzero"
    assert len(rows) == sparse.nnz - len(SOURCES)
    filled = np.full(dense.shape, np.inf)
    coo = sparse.tocoo()
    filled[coo.row, coo.col] = coo.data
    np.testing.assert_array_equal(filled[near], dense[near])
    assert np.isinf(filled[~near]).all()
    assert filled[np.arange(len(SOURCES)), SOURCES].tolist() == [0.0] * len(SOURCES)


def test_bad_matrix_arguments(sheet):
    with pytest.raises(ValueError, match=r"source vertex 169 is out of range \(mesh has 169 vertices\)"):
        exactgeo.distance_matrix(sheet, [0, 169])
    with pytest.raises(ValueError, match="sources must be integer indices, not objects"):
        exactgeo.distance_matrix(sheet, [object()])
    with pytest.raises(ValueError, match="max_distance must be a non-negative number"):
        exactgeo.distance_matrix(sheet, SOURCES, max_distance=-0.5)


def test_farthest_point_sampling(sheet):
    sampling = exactgeo.farthest_point_sampling(sheet, 10, first=5)
    assert sampling.samples.dtype == np.int64 and sampling.samples[0] == 5
    assert len(set(sampling.samples.tolist())) == 10
    assert sampling.radii[0] == np.inf and (np.diff(sampling.radii[1:]) <= 0).all()
    rows = exactgeo.distance_matrix(sheet, sampling.samples)
    np.testing.assert_allclose(sampling.distances, rows.min(axis=0), rtol=1e-14)
    np.testing.assert_allclose(
        rows[sampling.nearest_sample, np.arange(sheet.vertex_count)], sampling.distances, rtol=1e-14
    )
    # Each sample was the farthest vertex from the ones before it.
    for k in range(1, 10):
        assert rows[:k, sampling.samples[k]].min() == pytest.approx(sampling.radii[k], rel=1e-14)
        assert rows[:k].min(axis=0).max() == pytest.approx(sampling.radii[k], rel=1e-14)


def test_sampling_stops_once_the_reachable_vertices_are_taken_and_says_so():
    mesh = exactgeo.Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 0, 0], [6, 0, 0], [5, 1, 0]], [[0, 1, 2], [3, 4, 5]])
    with pytest.warns(UserWarning, match=r"took 3 of the 6 samples asked for: every vertex reachable") as caught:
        sampling = exactgeo.farthest_point_sampling(mesh, 6)
    assert [w.filename for w in caught] == [__file__]  # the caller's line
    assert sorted(sampling.samples.tolist()) == [0, 1, 2]
    np.testing.assert_array_equal(sampling.nearest_sample[3:], -1)
    with pytest.warns(UserWarning, match=r"took 1 of the 3 .* within max_distance=0.5"):
        exactgeo.farthest_point_sampling(mesh, 3, max_distance=0.5)
    assert len(exactgeo.farthest_point_sampling(mesh, 0).samples) == 0
    with pytest.raises(ValueError, match="count must be at least 0, not -1"):
        exactgeo.farthest_point_sampling(mesh, -1)


def test_sampling_more_vertices_than_the_mesh_has_is_refused(sheet):
    with pytest.raises(ValueError, match=rf"count 1000000 exceeds the mesh's {sheet.vertex_count} vertices"):
        exactgeo.farthest_point_sampling(sheet, 10**6)
    assert len(exactgeo.farthest_point_sampling(sheet, sheet.vertex_count).samples) == sheet.vertex_count


def test_surface_point_sources_say_which_call_takes_them(sheet):
    points = [exactgeo.SurfacePoint(3, (0.2, 0.3, 0.5))]
    for sources in (points, points[0], exactgeo.SurfacePoints.of(points)):
        with pytest.raises(TypeError, match=r"takes source vertex indices, not surface points: .*exactgeo.distance"):
            exactgeo.distance_matrix(sheet, sources)
    with pytest.raises(TypeError, match=r"takes target vertex indices, not surface points: .*targets=points"):
        exactgeo.distance_matrix(sheet, [0, 1], targets=points)
    # What the message points to gives the row.
    assert exactgeo.distance(sheet, points[0]).shape == (sheet.vertex_count,)


def test_sampling_repr_is_one_short_line(sheet):
    sampling = exactgeo.farthest_point_sampling(sheet, 10)
    assert repr(sampling) == (
        f"exactgeo.Sampling(samples=10, vertices={sheet.vertex_count}, last_radius={sampling.radii[-1]:.6g})"
    )
    assert repr(exactgeo.farthest_point_sampling(sheet, 0)) == "exactgeo.Sampling(samples=0, vertices=0)"


def test_without_scipy_a_cut_off_matrix_says_what_to_install(sheet, monkeypatch):
    monkeypatch.setitem(sys.modules, "scipy", None)
    monkeypatch.setitem(sys.modules, "scipy.sparse", None)
    with pytest.raises(ImportError, match="pip install scipy"):
        exactgeo.distance_matrix(sheet, SOURCES, max_distance=0.3)
    assert exactgeo.distance_matrix(sheet, SOURCES).shape == (len(SOURCES), sheet.vertex_count)


def test_several_first_samples_are_taken_in_their_order(sheet):
    plain = exactgeo.farthest_point_sampling(sheet, 6, first=5)
    seeded = exactgeo.farthest_point_sampling(sheet, 6, first=plain.samples[:3])
    np.testing.assert_array_equal(seeded.samples, plain.samples)
    np.testing.assert_array_equal(seeded.radii, plain.radii)
    chosen = exactgeo.farthest_point_sampling(sheet, 4, first=[7, 100])
    assert list(chosen.samples[:2]) == [7, 100]
    assert chosen.radii[1] == exactgeo.distance(sheet, 7)[100]


def test_counts_out_of_range_are_named(sheet):
    with pytest.raises(ValueError, match=r"threads must be at most 4294967295, not 1099511627776"):
        exactgeo.distance_matrix(sheet, SOURCES, threads=2**40)
    with pytest.raises(ValueError, match=r"count must be at most 18446744073709551615"):
        exactgeo.farthest_point_sampling(sheet, 2**70)
    with pytest.raises(ValueError, match="count must be at least 0, not -1"):
        exactgeo.farthest_point_sampling(sheet, -1)


TARGETS = [40, 3, 13, 168, 40, 0]


@pytest.mark.parametrize("threads", [1, 2])
def test_target_columns_are_the_full_matrix_columns(sheet, threads):
    full = exactgeo.distance_matrix(sheet, SOURCES)
    block = exactgeo.distance_matrix(sheet, SOURCES, targets=TARGETS, threads=threads)
    assert block.shape == (len(SOURCES), len(TARGETS)) and block.dtype == np.float64
    np.testing.assert_array_equal(block, full[:, TARGETS])  # bit for bit: the same runs, stopped early
    # Sparse with a cut-off: the targets' columns of the sparse full matrix.
    sparse_full = exactgeo.distance_matrix(sheet, SOURCES, max_distance=0.5)
    sparse = exactgeo.distance_matrix(
        sheet, SOURCES, targets=np.array(TARGETS, dtype=np.int16), max_distance=0.5, threads=threads
    )
    assert isinstance(sparse, scipy.sparse.csr_array) and sparse.shape == (len(SOURCES), len(TARGETS))
    assert 0 < sparse.nnz < block.size
    assert (sparse != sparse_full[:, TARGETS]).nnz == 0
    assert sparse.nnz == (full[:, TARGETS] <= 0.5).sum()
    # targets_beyond="exact": every target stored, however far (gdist's distance_matrix_of_selected_points).
    exact = exactgeo.distance_matrix(sheet, SOURCES, targets=TARGETS, max_distance=0.5, targets_beyond="exact")
    assert exact.nnz == block.size
    np.testing.assert_array_equal(exact.toarray(), block)


def test_no_targets_and_bad_targets(sheet):
    assert exactgeo.distance_matrix(sheet, SOURCES, targets=[]).shape == (len(SOURCES), 0)
    assert exactgeo.distance_matrix(sheet, SOURCES, targets=[], max_distance=1).shape == (len(SOURCES), 0)
    with pytest.raises(ValueError, match="169"):
        exactgeo.distance_matrix(sheet, SOURCES, targets=[0, 169])
    with pytest.raises(ValueError, match="targets_beyond must be 'inf' or 'exact'"):
        exactgeo.distance_matrix(sheet, SOURCES, targets=[0], max_distance=1, targets_beyond="approximate")


def test_the_command_lines_npz_names_its_rows_and_columns(sheet, tmp_path):
    from conftest import CLI, run_cli, write_obj

    if not CLI.is_file():
        pytest.skip(f"command-line tool not built at {CLI}")
    mesh_file = write_obj(tmp_path / "sheet.obj", sheet.vertices, sheet.faces)
    out = tmp_path / "m.npz"
    run_cli("matrix", mesh_file, "--sources", *SOURCES, "--targets", *TARGETS, "--max-distance", 0.5, "--out", out)
    with np.load(out) as archive:
        assert archive["sources"].tolist() == SOURCES and archive["targets"].tolist() == TARGETS
    loaded = scipy.sparse.load_npz(out)  # the extra arrays do not disturb scipy
    ours = exactgeo.distance_matrix(sheet, SOURCES, targets=TARGETS, max_distance=0.5)
    assert loaded.shape == ours.shape and (loaded != ours).nnz == 0
    run_cli("matrix", mesh_file, "--sources", *SOURCES, "--max-distance", 0.5, "--out", out)
    with np.load(out) as archive:
        assert archive["sources"].tolist() == SOURCES and "targets" not in archive


def test_threads_0_means_one_per_core_as_everywhere_else(sheet):
    # distance_matrix refused 0, which Mesh, distance and the command line take as one per core.
    from exactgeo._many_sources import fill_distance_matrix

    expected = exactgeo.distance_matrix(sheet, SOURCES, threads=1)
    np.testing.assert_array_equal(exactgeo.distance_matrix(sheet, SOURCES, threads=0), expected)
    sparse = exactgeo.distance_matrix(sheet, SOURCES, max_distance=0.3, threads=0)
    expected_sparse = exactgeo.distance_matrix(sheet, SOURCES, max_distance=0.3, threads=1)
    np.testing.assert_array_equal(sparse.toarray(), expected_sparse.toarray())
    filled = np.empty_like(expected)
    fill_distance_matrix(filled, sheet, SOURCES, threads=0)
    np.testing.assert_array_equal(filled, expected)
