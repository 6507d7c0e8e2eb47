"""The command's .npz (written by cli/npy.cpp, no zip library) is a valid stored zip that numpy and
scipy.sparse.load_npz read, holding what distance_matrix computes."""

from __future__ import annotations

import zipfile

import numpy as np
import scipy.sparse
from conftest import run_cli

import exactgeo


def test_the_commands_npz_is_a_valid_zip_with_the_sparse_matrix(cli, tmp_path):
    out = tmp_path / "m.npz"
    run_cli("matrix", "@torus:24:10", "--sources", "0,17,100", "--max-distance", "1.5", "--out", out, "--quiet")
    with zipfile.ZipFile(out) as archive:
        assert archive.testzip() is None  # every member's CRC-32 checks out
        members = archive.infolist()
        assert sorted(m.filename for m in members) == sorted(
            f"{n}.npy" for n in ("indices", "indptr", "format", "shape", "data", "sources"))
        assert all(m.compress_type == zipfile.ZIP_STORED for m in members)
    mesh = exactgeo.Mesh(*exactgeo.make_bumpy_torus(24, 10))
    expected = exactgeo.distance_matrix(mesh, [0, 17, 100], max_distance=1.5)
    got = scipy.sparse.load_npz(out)
    assert got.shape == expected.shape and got.nnz == expected.nnz
    np.testing.assert_array_equal(got.toarray(), expected.toarray())
    assert set(np.load(out).files) == {"indices", "indptr", "format", "shape", "data", "sources"}
    np.testing.assert_array_equal(np.load(out)["sources"], [0, 17, 100])  # the rows' source vertices
