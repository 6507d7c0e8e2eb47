"""exactgeo.distributed: distance matrices computed in blocks on Dask workers (a LocalCluster on loopback) or
executors, written into Zarr stores block by block, with done markers, resumption and the sparse layout."""

from __future__ import annotations

import contextlib
import functools
import json
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

import numpy as np
import pytest
from conftest import zarr3_or_skip

import exactgeo

try:
    import distributed as dask_distributed
    import zarr
except ImportError:
    pytest.skip("exactgeo.distributed needs dask[distributed] and zarr: pip install 'dask[distributed]' 'zarr>=3'",
                allow_module_level=True)
zarr3_or_skip()  # dask is there; zarr must be version 3

from exactgeo import distributed  # noqa: E402 (after the skip above, which needs zarr 3)


def two_tori() -> exactgeo.Mesh:
    """Two bumpy tori side by side: distances between them are inf."""
    vertices, faces = exactgeo.make_bumpy_torus(24, 12)
    moved = vertices + np.array([5.0, 0.0, 0.0])
    return exactgeo.Mesh(np.vstack([vertices, moved]), np.vstack([faces, faces + len(vertices)]))


MESH = two_tori()
SOURCES = np.concatenate([np.arange(0, 288, 11), [300, 450, 575]])  # rows on both tori
REFERENCE = exactgeo.distance_matrix(MESH, SOURCES)


@pytest.fixture(scope="module")
def client():
    with distributed.local_cluster(2) as cluster, dask_distributed.Client(cluster) as connected:
        yield connected


def dense(store) -> np.ndarray:
    return zarr.open_array(str(store / "distances"), mode="r")[...]


def test_importing_exactgeo_imports_neither_dask_nor_zarr():
    code = ("import sys, exactgeo, exactgeo.distributed; "
            "print(sorted(m for m in ('dask', 'distributed', 'zarr') if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"


def test_a_local_cluster_gives_distance_matrix_bit_for_bit(client, tmp_path):
    run = distributed.distance_matrix_to_zarr(MESH, SOURCES, tmp_path / "d.zarr", dtype="float64", block_rows=4,
                                              client=client)
    got = dense(tmp_path / "d.zarr")
    assert got.dtype == np.float64 and np.isinf(REFERENCE).any()
    assert np.array_equal(got, REFERENCE)  # inf included
    assert run.blocks == 8 and run.computed == tuple(range(8)) and run.reused == ()
    status = distributed.store_status(tmp_path / "d.zarr")
    assert status.complete and status.done == tuple(range(8)) and status.shape == REFERENCE.shape
    # float32: the float64 values rounded, chunk rows = block rows.
    distributed.distance_matrix_to_zarr(MESH, SOURCES, tmp_path / "f.zarr", block_rows=4, client=client)
    array = zarr.open_array(str(tmp_path / "f.zarr" / "distances"), mode="r")
    assert array.dtype == np.float32 and array.chunks == (4, MESH.vertex_count)
    assert np.array_equal(array[...], REFERENCE.astype(np.float32))
    attributes = zarr.open_group(str(tmp_path / "f.zarr"), mode="r").attrs["exactgeo"]
    assert attributes["sources"] == SOURCES.tolist() and attributes["targets"] is None
    assert attributes["mesh_sha256"] == distributed.mesh_hash(MESH) and attributes["version"] == exactgeo.__version__
    assert (attributes["dtype"], attributes["max_distance"], attributes["block_rows"]) == ("float32", None, 4)


def test_an_executor_gives_the_same_and_targets_select_columns(tmp_path):
    targets = [5, 500, 3, 17]
    with ProcessPoolExecutor(2) as executor:
        distributed.distance_matrix_to_zarr(MESH, SOURCES, tmp_path / "d.zarr", dtype="float64", block_rows=7,
                                            client=executor)
        distributed.distance_matrix_to_zarr(MESH, SOURCES, tmp_path / "t.zarr", targets=targets, dtype="float64",
                                            block_rows=5, client=executor)
    assert np.array_equal(dense(tmp_path / "d.zarr"), REFERENCE)
    assert np.array_equal(dense(tmp_path / "t.zarr"), REFERENCE[:, targets])
    assert zarr.open_array(str(tmp_path / "t.zarr" / "target"), mode="r")[...].tolist() == targets


def _die_once(flag: str, log: str, *arguments):
    """The block task, but the first attempt at block 2 kills its worker process halfway."""
    block = arguments[2]
    with open(log, "a") as file:
        file.write(f"{block}\n")
    if block == 2:
        try:
            os.close(os.open(flag, os.O_CREAT | os.O_EXCL))
        except FileExistsError:
            pass
        else:
            os._exit(1)
    from exactgeo import distributed as module  # in a worker: the module as it is, not the test's patch

    return module._compute_block(*arguments)


def test_a_worker_killed_mid_block_still_gives_the_whole_matrix(client, tmp_path, monkeypatch):
    flag, log = tmp_path / "killed", tmp_path / "attempts.txt"
    monkeypatch.setattr(distributed, "_compute_block", functools.partial(_die_once, str(flag), str(log)))
    run = distributed.distance_matrix_to_zarr(MESH, SOURCES, tmp_path / "d.zarr", dtype="float64", block_rows=4,
                                              client=client, retries=1)
    assert flag.exists() and np.array_equal(dense(tmp_path / "d.zarr"), REFERENCE)
    attempts = [int(line) for line in log.read_text().split()]
    assert attempts.count(2) == 2 and sorted(set(attempts)) == list(range(8))  # block 2 ran twice
    markers = sorted(p.name for p in (tmp_path / "d.zarr" / "done").iterdir() if p.name.startswith("block_"))
    assert markers == [f"block_{b:06d}" for b in range(8)] and run.computed == tuple(range(8))
    records = [zarr.open_group(str(tmp_path / "d.zarr" / "done" / m), mode="r").attrs["block"] for m in markers]
    assert records == list(range(8))


def test_an_interrupted_run_resumes_with_the_missing_blocks_only(tmp_path):
    store = tmp_path / "d.zarr"

    def stop_after_three_blocks(done, total):
        if done >= 3 * 4:
            raise KeyboardInterrupt

    with ThreadPoolExecutor(1) as executor, pytest.raises(KeyboardInterrupt):
        distributed.distance_matrix_to_zarr(MESH, SOURCES, store, dtype="float64", block_rows=4, client=executor,
                                            progress=stop_after_three_blocks)
    before = distributed.store_status(store)
    assert 3 <= len(before.done) < 8 and set(before.done) | set(before.missing) == set(range(8))
    rows = []
    with ThreadPoolExecutor(2) as executor:
        run = distributed.distance_matrix_to_zarr(MESH, SOURCES, store, dtype="float64", client=executor,
                                                  progress=lambda done, total: rows.append(done))
    assert run.computed == before.missing and run.reused == before.done  # block_rows taken from the store
    assert rows[0] == 4 * len(before.done) and rows[-1] == len(SOURCES)
    assert np.array_equal(dense(store), REFERENCE) and distributed.store_status(store).complete
    again = distributed.distance_matrix_to_zarr(MESH, SOURCES, store, dtype="float64", client=executor)
    assert again.computed == () and again.reused == tuple(range(8))


def test_a_half_written_block_is_computed_again_and_never_reported_done(tmp_path):
    store = tmp_path / "d.zarr"
    with ThreadPoolExecutor(1) as executor:
        distributed.distance_matrix_to_zarr(MESH, SOURCES, store, dtype="float64", block_rows=4, client=executor,
                                            retries=0)
    # What a crash between block 1's chunk and its marker leaves (the store component writes the marker last):
    # the chunk without its marker, here with other bytes too, as a write cut short leaves it.
    shutil.rmtree(store / "done" / "block_000001")
    zarr.open_array(str(store / "distances"), mode="r+")[4:8] = 0.0
    status = distributed.store_status(store)
    assert 1 in status.missing and 1 not in status.done and not status.complete
    with ThreadPoolExecutor(1) as executor:
        run = distributed.distance_matrix_to_zarr(MESH, SOURCES, store, dtype="float64", client=executor)
    assert run.computed == status.missing == (1,)
    assert np.array_equal(dense(store), REFERENCE)


def test_a_store_made_for_another_matrix_is_refused(tmp_path):
    store = tmp_path / "d.zarr"
    with ThreadPoolExecutor(2) as executor:
        distributed.distance_matrix_to_zarr(MESH, SOURCES[:8], store, block_rows=4, client=executor)
        other_mesh = exactgeo.Mesh(*exactgeo.make_bumpy_torus(24, 12))
        with pytest.raises(ValueError, match=r"was made for another mesh \(the store's: 576 vertices"):
            distributed.distance_matrix_to_zarr(other_mesh, SOURCES[:8], store, client=executor)
        with pytest.raises(ValueError, match=r"other sources \(the store's: 8 sources \[0, 11, 22, 33, 44, \.\.\.\]"):
            distributed.distance_matrix_to_zarr(MESH, SOURCES[:9], store, client=executor)
        with pytest.raises(ValueError, match="another dtype .*float32.*float64.*resume=False"):
            distributed.distance_matrix_to_zarr(MESH, SOURCES[:8], store, dtype="float64", client=executor)
        with pytest.raises(ValueError, match="another max_distance"):
            distributed.distance_matrix_to_zarr(MESH, SOURCES[:8], store, max_distance=0.5, client=executor)
        with pytest.raises(ValueError, match="another block_rows"):
            distributed.distance_matrix_to_zarr(MESH, SOURCES[:8], store, block_rows=3, client=executor)
        assert distributed.store_status(store).complete  # refused without a change
        # resume=False replaces it.
        run = distributed.distance_matrix_to_zarr(MESH, SOURCES[:9], store, dtype="float64", block_rows=3,
                                                  client=executor, resume=False)
        assert run.computed == (0, 1, 2) and np.array_equal(dense(store), REFERENCE[:9])
        # A folder that is not an exactgeo store is never touched.
        (tmp_path / "mine").mkdir()
        (tmp_path / "mine" / "notes.txt").write_text("keep me")
        with pytest.raises(ValueError, match="is not a Zarr store"):
            distributed.distance_matrix_to_zarr(MESH, SOURCES, tmp_path / "mine", client=executor, resume=False)
        assert (tmp_path / "mine" / "notes.txt").read_text() == "keep me"
    with pytest.raises(ValueError, match="dtype must be float32 or float64"):
        distributed.distance_matrix_to_zarr(MESH, SOURCES, tmp_path / "x.zarr", dtype="int32")
    with pytest.raises(ValueError, match="max_distance must be a finite number"):
        distributed.distance_matrix_to_zarr(MESH, SOURCES, tmp_path / "z.zarr", max_distance=-1.0)
    with pytest.raises(TypeError, match="client must be"):
        distributed.distance_matrix_to_zarr(MESH, SOURCES, tmp_path / "y.zarr", client=object())


def test_the_sparse_layout_equals_distance_matrix_with_max_distance(client, tmp_path):
    reference = exactgeo.distance_matrix(MESH, SOURCES, max_distance=0.6)
    distributed.distance_matrix_to_zarr(MESH, SOURCES, tmp_path / "s.zarr", dtype="float64", max_distance=0.6,
                                        block_rows=4, client=client)
    got = distributed.read_sparse(tmp_path / "s.zarr")
    assert got.shape == reference.shape and got.dtype == np.float64
    assert np.array_equal(got.indptr, reference.indptr) and np.array_equal(got.indices, reference.indices)
    assert np.array_equal(got.data, reference.data)
    part = distributed.read_sparse(tmp_path / "s.zarr", rows=slice(6, 13))
    assert np.array_equal(part.toarray(), reference[6:13].toarray())
    # Rows of block 0 only are read while block 3 is missing; rows in block 3 name it.
    marker = tmp_path / "s.zarr" / "done" / "block_000003" / "zarr.json"
    marker.rename(marker.with_name("moved"))
    assert np.array_equal(distributed.read_sparse(tmp_path / "s.zarr", rows=range(0, 4)).toarray(),
                          reference[0:4].toarray())
    with pytest.raises(ValueError, match=r"blocks \[3\] are not done"):
        distributed.read_sparse(tmp_path / "s.zarr", rows=slice(10, 14))
    # Resuming: block 3 again (its pieces, complete, were already in place: they are kept) and the pieces
    # of an attempt that died before renaming them into place are removed.
    leftover = tmp_path / "s.zarr" / "csr" / ".block_000005.1234.abc.tmp"
    leftover.mkdir()
    with ThreadPoolExecutor(1) as executor:
        run = distributed.distance_matrix_to_zarr(MESH, SOURCES, tmp_path / "s.zarr", dtype="float64",
                                                  max_distance=0.6, client=executor)
    assert run.computed == (3,) and not leftover.exists()
    again = distributed.read_sparse(tmp_path / "s.zarr")
    assert np.array_equal(again.data, reference.data) and np.array_equal(again.indices, reference.indices)
    assert sorted(p.name for p in (tmp_path / "s.zarr" / "csr").iterdir() if p.is_dir()) == \
        [f"block_{b:06d}" for b in range(8)]
    # float32 stores the rounded distances.
    with ThreadPoolExecutor(2) as executor:
        distributed.distance_matrix_to_zarr(MESH, SOURCES, tmp_path / "f.zarr", max_distance=0.6, block_rows=5,
                                            client=executor)
    single = distributed.read_sparse(tmp_path / "f.zarr")
    assert single.dtype == np.float32 and np.array_equal(single.data, reference.data.astype(np.float32))
    assert np.array_equal(single.indices, reference.indices)


def _slowly(*arguments):
    """The block task, a second longer: blocks still queued when the run is interrupted. (A fifth of a second
    was too little on a loaded machine: the client heard of the fourth block when all fifteen were done.)"""
    import time

    time.sleep(1.0)
    from exactgeo import distributed as module  # in a worker: the module as it is, not the test's patch

    return module._compute_block(*arguments)


def test_an_interrupted_dask_run_resumes_with_the_missing_blocks_only(client, tmp_path, monkeypatch):
    import time

    store = tmp_path / "d.zarr"
    monkeypatch.setattr(distributed, "_compute_block", _slowly)

    def stop_after_two_blocks(done, total):
        if done >= 2 * 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        distributed.distance_matrix_to_zarr(MESH, SOURCES, store, dtype="float64", block_rows=2, client=client,
                                            progress=stop_after_two_blocks)
    deadline = time.monotonic() + 20
    while any(client.processing().values()) and time.monotonic() < deadline:  # blocks already running end
        time.sleep(0.05)
    before = distributed.store_status(store)
    assert 2 <= len(before.done) < 15
    monkeypatch.undo()
    run = distributed.distance_matrix_to_zarr(MESH, SOURCES, store, dtype="float64", client=client)
    assert run.computed == before.missing and run.reused == before.done
    assert np.array_equal(dense(store), REFERENCE)


def test_the_local_cluster_slows_only_its_own_workers_housekeeping(client):
    import dask

    def settings():
        return (dask.config.get("distributed.admin.tick.interval"),
                dask.config.get("distributed.worker.profile.enabled"),
                dask.config.get("distributed.worker.memory.monitor-interval"))

    slowed = {("1s", False, "1s")}
    assert set(client.run(settings).values()) == slowed
    # A worker that dies is restarted by its nanny with the same settings.
    first = sorted(client.scheduler_info()["workers"])[0]
    with contextlib.suppress(Exception):
        client.run(os._exit, 1, workers=[first])
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        workers = client.scheduler_info()["workers"]
        if len(workers) == 2 and first not in workers:
            break
        time.sleep(0.1)
    assert len(workers) == 2 and first not in workers
    assert set(client.run(settings).values()) == slowed
    assert settings() != ("1s", False, "1s")  # this process keeps its configuration
    with pytest.raises(ValueError, match="workers must be at least 1"):
        distributed.local_cluster(0)


def test_without_a_client_a_local_cluster_is_started_and_closed(tmp_path):
    import psutil

    children = {p.pid for p in psutil.Process().children(recursive=True)}
    rows = []
    run = distributed.distance_matrix_to_zarr(MESH, SOURCES[:6], tmp_path / "d.zarr", dtype="float64", block_rows=3,
                                              progress=lambda done, total: rows.append((done, total)))
    assert run.computed == (0, 1) and rows[0] == (0, 6) and rows[-1] == (6, 6)
    assert np.array_equal(dense(tmp_path / "d.zarr"), REFERENCE[:6])
    assert {p.pid for p in psutil.Process().children(recursive=True)} <= children  # no worker left behind


def test_verify_finds_blocks_whose_data_is_not_what_their_marker_says(tmp_path):
    with ThreadPoolExecutor(2) as executor:
        distributed.distance_matrix_to_zarr(MESH, SOURCES, tmp_path / "d.zarr", dtype="float64", block_rows=4,
                                            client=executor)
        distributed.distance_matrix_to_zarr(MESH, SOURCES, tmp_path / "s.zarr", max_distance=0.6, block_rows=4,
                                            client=executor)
        assert distributed.store_status(tmp_path / "d.zarr", verify=True).corrupt == ()
        assert distributed.store_status(tmp_path / "s.zarr", verify=True).corrupt == ()
        zarr.open_array(str(tmp_path / "d.zarr" / "distances"), mode="r+")[9, 3] = 1.5  # block 2
        data = zarr.open_array(str(tmp_path / "s.zarr" / "csr" / "block_000005" / "data"), mode="r+")
        data[0] = data[0] + 1
        assert distributed.store_status(tmp_path / "d.zarr").complete  # markers alone say nothing
        for store, block in (("d.zarr", 2), ("s.zarr", 5)):
            status = distributed.store_status(tmp_path / store, verify=True)
            assert status.corrupt == (block,) and status.missing == (block,) and block not in status.done
            run = distributed.distance_matrix_to_zarr(MESH, SOURCES, tmp_path / store, client=executor, verify=True,
                                                      dtype="float64" if store == "d.zarr" else "float32",
                                                      max_distance=None if store == "d.zarr" else 0.6)
            assert run.computed == (block,)
            assert distributed.store_status(tmp_path / store, verify=True).corrupt == ()
    assert np.array_equal(dense(tmp_path / "d.zarr"), REFERENCE)
    reference = exactgeo.distance_matrix(MESH, SOURCES, max_distance=0.6)
    assert np.array_equal(distributed.read_sparse(tmp_path / "s.zarr").data, reference.data.astype(np.float32))


def test_blocks_are_computed_into_their_chunk_rounded_once_to_float32(tmp_path):
    from exactgeo._many_sources import fill_distance_matrix

    rounded = np.empty(REFERENCE.shape, dtype=np.float32)
    fill_distance_matrix(rounded, MESH, SOURCES, threads=2)
    assert np.isinf(rounded).any() and np.array_equal(rounded, REFERENCE.astype(np.float32))
    with pytest.raises(ValueError, match=r"out has shape \(30, 10\), not \(30, 576\)"):
        fill_distance_matrix(np.empty((30, 10), dtype=np.float32), MESH, SOURCES)
    with pytest.raises(ValueError, match="float64 or float32"):
        fill_distance_matrix(np.empty(REFERENCE.shape, dtype=np.float16), MESH, SOURCES)
    store = tmp_path / "d.zarr"
    with ThreadPoolExecutor(2) as executor:
        distributed.distance_matrix_to_zarr(MESH, SOURCES, store, block_rows=4, client=executor)
    assert np.array_equal(dense(store), REFERENCE.astype(np.float32))
    # The last block (2 rows) fills a whole chunk, the rows beyond the array's edge NaN, as Zarr pads it.
    last = np.fromfile(store / "distances" / "c" / "7" / "0", dtype="<f4").reshape(4, MESH.vertex_count)
    assert np.array_equal(last[:2], REFERENCE[28:].astype(np.float32)) and np.isnan(last[2:]).all()
    assert distributed.store_status(store, verify=True).corrupt == ()


def test_an_interrupt_while_the_store_is_made_leaves_nothing_behind(tmp_path):
    """A Ctrl-C that arrives while the store is built: the store component holds it back until the folder it builds
    in is removed, then lets it in. Here it is sent before the call, held by this thread until the component takes
    it over, so that it is surely there while the store is built."""
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    with pytest.raises(KeyboardInterrupt):
        signal.pthread_kill(threading.get_ident(), signal.SIGINT)
        try:
            with ThreadPoolExecutor(1) as executor:
                distributed.distance_matrix_to_zarr(MESH, SOURCES, tmp_path / "d.zarr", block_rows=4, client=executor)
        finally:
            signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})  # if the store component has not yet
            time.sleep(0.01)
    assert list(tmp_path.iterdir()) == []  # neither the store nor the hidden folder it was built in
    with ThreadPoolExecutor(1) as executor:
        run = distributed.distance_matrix_to_zarr(MESH, SOURCES, tmp_path / "d.zarr", block_rows=4, client=executor)
    assert run.computed == tuple(range(8)) and [p.name for p in tmp_path.iterdir()] == ["d.zarr"]


def test_stores_whose_chunks_blocks_cannot_write_are_refused(tmp_path):
    store = tmp_path / "d.zarr"
    with ThreadPoolExecutor(1) as executor:
        distributed.distance_matrix_to_zarr(MESH, SOURCES[:8], store, block_rows=4, client=executor)
        metadata_path = store / "distances" / "zarr.json"
        metadata = json.loads(metadata_path.read_text())
        metadata["codecs"].append({"name": "zstd", "configuration": {"level": 0, "checksum": False}})
        metadata_path.write_text(json.dumps(metadata))
        with pytest.raises(ValueError, match=r"codecs \[bytes, zstd\]"):
            distributed.distance_matrix_to_zarr(MESH, SOURCES[:8], store, client=executor, verify=True)
        # Zarr format 2 (what zarr-python 2 made): neither read nor written.
        zarr.open_group(str(tmp_path / "v2.zarr"), mode="w", zarr_format=2)
        with pytest.raises(ValueError, match="Zarr format 2 store"):
            distributed.distance_matrix_to_zarr(MESH, SOURCES[:8], tmp_path / "v2.zarr", client=executor)
        with pytest.raises(ValueError, match="Zarr format 2 store"):
            distributed.store_status(tmp_path / "v2.zarr")


def test_sparse_pieces_left_without_a_marker_are_replaced_not_vouched_for(tmp_path):
    store = tmp_path / "s.zarr"
    reference = exactgeo.distance_matrix(MESH, SOURCES, max_distance=0.6)
    with ThreadPoolExecutor(1) as executor:
        distributed.distance_matrix_to_zarr(MESH, SOURCES, store, max_distance=0.6, block_rows=4, client=executor)
        # Block 3's pieces overwritten and its marker gone: what a crash between the two leaves.
        data = zarr.open_array(str(store / "csr" / "block_000003" / "data"), mode="r+")
        data[:] = 7.0
        shutil.rmtree(store / "done" / "block_000003")
        run = distributed.distance_matrix_to_zarr(MESH, SOURCES, store, max_distance=0.6, client=executor)
    assert run.computed == (3,)
    assert (distributed.read_sparse(store) != reference.astype(np.float32)).nnz == 0
    assert distributed.store_status(store, verify=True).corrupt == ()
