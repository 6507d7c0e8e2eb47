"""The command's .npz (written by cli/formats/npy.cpp, no zip library) is a valid stored zip that numpy and
scipy.sparse.load_npz read, holding what distance_matrix computes; and the .npy index files numpy writes are
read by the command (cli/formats/npy.cpp too)."""

from __future__ import annotations

import io
import subprocess
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


def test_the_command_reads_numpys_npy_files_and_standard_input(cli, tmp_path):
    """Index arrays as numpy.save writes them, of any integer dtype and byte order, name the matrix's rows and
    columns, from a file or piped in; what numpy cannot hold as indices is refused, naming the element."""
    mesh = exactgeo.Mesh(*exactgeo.make_bumpy_torus(24, 10))
    sources, targets = [0, 17, 100], [5, 200]
    expected = exactgeo.distance_matrix(mesh, sources, targets=targets)
    for dtype in ("<i2", ">i4", "<u8", ">u2", "i1", "u1"):
        np.save(tmp_path / "s.npy", np.array(sources, dtype=dtype))
        run_cli("matrix", "@torus:24:10", "--sources", tmp_path / "s.npy", "--targets", *map(str, targets),
                "--out", tmp_path / "m.npy", "--quiet")
        np.testing.assert_array_equal(np.load(tmp_path / "m.npy"), expected, err_msg=dtype)
    buffer = io.BytesIO()
    np.save(buffer, np.array(targets, dtype=np.int64))
    subprocess.run([str(cli), "matrix", "@torus:24:10", "--sources", *map(str, sources), "--targets", "-", "--out",
                    str(tmp_path / "piped.npy"), "--quiet"], input=buffer.getvalue(), check=True)
    np.testing.assert_array_equal(np.load(tmp_path / "piped.npy"), expected)
    np.save(tmp_path / "bad.npy", np.array([3, -7], dtype=np.int32))
    refused = subprocess.run([str(cli), "matrix", "@torus:24:10", "--sources", str(tmp_path / "bad.npy"), "--out",
                              str(tmp_path / "x.npy")], capture_output=True, text=True)
    assert refused.returncode == 2 and "bad.npy': element [1] is -7, not an index" in refused.stderr
