"""`exactgeo matrix --out M.zarr --shard I/N`: the command writes the store layout of exactgeo.distributed (both
through the store component, store/), which zarr-python and exactgeo.distributed read and continue, and the other
way round."""

from __future__ import annotations

import json
import os
import random
import re
import shutil
import signal
import subprocess
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest
from conftest import CLI, run_cli, write_obj, zarr3_or_skip

import exactgeo

zarr = zarr3_or_skip()

from exactgeo import distributed  # noqa: E402 (after the skip above, which needs zarr 3)

TORUS = "@torus:24:12"
MESH = exactgeo.Mesh(*exactgeo.make_bumpy_torus(24, 12))  # what TORUS generates: the same arrays, the same hash
SOURCES = list(range(0, 288, 9))  # 32 rows
SOURCE_LIST = ",".join(map(str, SOURCES))
REFERENCE = exactgeo.distance_matrix(MESH, SOURCES)


def cli_run(*arguments: object) -> subprocess.CompletedProcess:
    """The command, whatever its exit code."""
    return subprocess.run([str(CLI), *map(str, arguments)], capture_output=True, text=True)


def dense(store: Path) -> np.ndarray:
    return zarr.open_array(str(store / "distances"), mode="r")[...]


def computed_blocks(stderr: str) -> int:
    """The count in the command's summary line: '... shard I/N: C blocks computed, R reused ...'."""
    return int(re.search(r"(\d+) blocks computed", stderr).group(1))


def tree(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.mark.parametrize("dtype", ["float32", "float64"])
def test_zarr_reads_the_commands_dense_store_as_distance_matrix(cli, tmp_path, dtype):
    store = tmp_path / "d.zarr"
    run_cli("matrix", TORUS, "--sources", SOURCE_LIST, "--dtype", dtype, "--block-rows", 5, "--out", store)
    array = zarr.open_array(str(store / "distances"), mode="r")
    assert array.dtype == np.dtype(dtype) and array.chunks == (5, MESH.vertex_count)
    assert np.array_equal(array[...], REFERENCE.astype(dtype))  # float32: the float64 values rounded; inf kept
    settings = zarr.open_group(str(store), mode="r").attrs["exactgeo"]
    assert settings["mesh_sha256"] == distributed.mesh_hash(MESH)
    assert (settings["sources"], settings["targets"]) == (SOURCES, None)
    assert (settings["dtype"], settings["blocks"]) == (dtype, 7)
    assert zarr.open_array(str(store / "source"), mode="r")[...].tolist() == SOURCES
    assert np.array_equal(zarr.open_array(str(store / "mesh" / "vertices"), mode="r")[...], MESH.vertices)
    status = distributed.store_status(store, verify=True)  # the markers' sha256 are the chunks' bytes
    assert status.complete and status.corrupt == () and status.done == tuple(range(7))


def test_the_commands_sparse_store_and_targets_read_back_as_distance_matrix(cli, tmp_path):
    store = tmp_path / "s.zarr"
    run_cli("matrix", TORUS, "--sources", SOURCE_LIST, "--max-distance", 0.6, "--dtype", "float64", "--block-rows", 6,
            "--out", store, "--quiet")
    reference = exactgeo.distance_matrix(MESH, SOURCES, max_distance=0.6)
    got = distributed.read_sparse(store)
    assert got.dtype == np.float64 and got.shape == reference.shape
    assert np.array_equal(got.indptr, reference.indptr) and np.array_equal(got.indices, reference.indices)
    assert np.array_equal(got.data, reference.data)
    assert distributed.store_status(store, verify=True).corrupt == ()
    targets = [5, 200, 3]
    run_cli("matrix", TORUS, "--sources", SOURCE_LIST, "--targets", "5,200,3", "--out", tmp_path / "t.zarr", "--quiet")
    assert np.array_equal(dense(tmp_path / "t.zarr"), REFERENCE[:, targets].astype(np.float32))
    assert zarr.open_array(str(tmp_path / "t.zarr" / "target"), mode="r")[...].tolist() == targets


def test_shards_in_shuffled_order_some_at_once_give_the_whole_matrix(cli, tmp_path):
    store = tmp_path / "m.zarr"
    shards = list(range(5))
    random.Random(17).shuffle(shards)
    command = [str(CLI), "matrix", TORUS, "--sources", SOURCE_LIST, "--dtype", "float64", "--block-rows", 3,
               "--threads", 1, "--out", store]
    # Three shards start together on a path with no store yet: one makes it, the others join it.
    together = [subprocess.Popen([*map(str, command), "--shard", f"{i}/5"], stderr=subprocess.PIPE, text=True)
                for i in shards[:3]]
    errors = [process.communicate()[1] for process in together]
    assert [process.returncode for process in together] == [0, 0, 0], errors
    for i in shards[3:]:
        run_cli(*command[1:], "--shard", f"{i}/5")
    assert np.array_equal(dense(store), REFERENCE)
    assert distributed.store_status(store).done == tuple(range(11))
    assert [p.name for p in tmp_path.iterdir()] == ["m.zarr"]  # the losers' stores were removed
    status = cli_run("matrix", "--status", store)
    assert status.returncode == 0 and re.search(r"done +11: 0-10\n", status.stdout)
    assert re.search(r"missing +0: none", status.stdout) and "dense" in status.stdout


def test_an_interrupted_run_resumed_computes_exactly_the_missing_blocks(cli, tmp_path):
    store = tmp_path / "m.zarr"
    sources = ",".join(map(str, range(0, 642, 3)))  # 214 rows, 54 blocks
    command = [str(CLI), "matrix", "@icosphere:3", "--sources", sources, "--block-rows", "4", "--threads", "1",
               "--out", str(store)]
    process = subprocess.Popen(command, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and process.poll() is None:
        if len(list((store / "done").glob("block_*/zarr.json"))) >= 3:
            break
        time.sleep(0.005)
    process.send_signal(signal.SIGINT)
    process.communicate()
    assert process.returncode == -signal.SIGINT  # stopped by the signal, not finished
    before = distributed.store_status(store)
    assert len(before.done) >= 3 and before.missing
    assert not [p for p in store.rglob(".*")]  # no half-written chunk or marker left
    resumed = cli_run(*command[1:], "--resume")
    assert resumed.returncode == 0, resumed.stderr
    assert computed_blocks(resumed.stderr) == len(before.missing)
    assert re.search(rf"{len(before.done)} reused", resumed.stderr)
    mesh = exactgeo.Mesh(*exactgeo.make_icosphere(3))
    expected = exactgeo.distance_matrix(mesh, list(range(0, 642, 3))).astype(np.float32)
    assert np.array_equal(dense(store), expected)
    # Without --resume, every block of the shard is computed again (and replaced whole).
    again = cli_run(*command[1:], "--shard", "1/2")
    assert computed_blocks(again.stderr) == 27 and np.array_equal(dense(store), expected)


def interrupt_pending_at_start() -> None:
    """In the child before exec: SIGINT held back and already sent, so the command starts with an interrupt
    pending (a blocked signal stays pending, and blocked, across exec)."""
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    os.kill(os.getpid(), signal.SIGINT)


@pytest.mark.parametrize("max_distance", [None, 0.6])
def test_an_interrupt_while_the_store_is_built_leaves_nothing_behind(cli, tmp_path, max_distance):
    # The command holds interrupts back while it builds a folder (the new store, a sparse block's pieces) and
    # then removes what it built: an interrupt arriving at any moment of the building does what one pending
    # from the start does once the building is over. The first folder built is the store itself.
    store = tmp_path / "stores" / "m.zarr"
    cut = [] if max_distance is None else ["--max-distance", max_distance]
    command = [str(CLI), "matrix", TORUS, "--sources", SOURCE_LIST, "--block-rows", 4, *cut, "--out", store, "--quiet"]
    process = subprocess.run(list(map(str, command)), preexec_fn=interrupt_pending_at_start, capture_output=True,
                             text=True)
    assert process.returncode == -signal.SIGINT, process.stderr
    assert list((tmp_path / "stores").iterdir()) == []  # neither the store nor its hidden folder
    # Once the store is made, an interrupt while a sparse block's pieces are built leaves no hidden folder either.
    if max_distance is not None:
        run_cli(*command[1:], "--shard", "0/8")
        process = subprocess.run(list(map(str, command)) + ["--resume"], preexec_fn=interrupt_pending_at_start,
                                 capture_output=True, text=True)
        assert process.returncode == -signal.SIGINT, process.stderr
        assert [p.name for p in (store / "csr").iterdir()] == ["block_000000", "zarr.json"]
        assert distributed.store_status(store).done == (0,)


def test_the_command_and_python_continue_each_others_stores(cli, tmp_path):
    mesh_file = write_obj(tmp_path / "torus.obj", *exactgeo.make_bumpy_torus(24, 12))
    mesh = exactgeo.Mesh.load(mesh_file)
    # Shards 0 and 2 of 3 by the command, then Python's resume computes shard 1's blocks, and only those.
    store = tmp_path / "c.zarr"
    for shard in ("2/3", "0/3"):
        run_cli("matrix", mesh_file, "--sources", SOURCE_LIST, "--block-rows", 4, "--out", store, "--shard", shard)
    with ThreadPoolExecutor(2) as executor:
        run = distributed.distance_matrix_to_zarr(mesh, SOURCES, store, client=executor)
    assert run.computed == (1, 4, 7) and len(run.reused) == 5
    assert np.array_equal(dense(store), REFERENCE.astype(np.float32))
    # A store Python started (stopped after 3 blocks), finished by the command with --resume.
    for max_distance, layout in ((None, "dense"), (0.6, "sparse")):
        store = tmp_path / f"p-{layout}.zarr"

        def stop_after_three_blocks(done, total):
            if done >= 3 * 4:
                raise KeyboardInterrupt

        with ThreadPoolExecutor(1) as executor, pytest.raises(KeyboardInterrupt):
            distributed.distance_matrix_to_zarr(mesh, SOURCES, store, block_rows=4, max_distance=max_distance,
                                                dtype="float64", client=executor, progress=stop_after_three_blocks)
        before = distributed.store_status(store)
        cut = [] if max_distance is None else ["--max-distance", max_distance]
        finished = cli_run("matrix", mesh_file, "--sources", SOURCE_LIST, *cut, "--dtype", "float64", "--out", store,
                           "--resume")
        assert finished.returncode == 0, finished.stderr
        assert computed_blocks(finished.stderr) == len(before.missing) and before.missing
        status = distributed.store_status(store, verify=True)
        assert status.complete and status.corrupt == ()
        if max_distance is None:
            assert np.array_equal(dense(store), REFERENCE)
        else:
            reference = exactgeo.distance_matrix(mesh, SOURCES, max_distance=max_distance)
            assert (distributed.read_sparse(store) != reference).nnz == 0


@pytest.mark.parametrize("dtype", ["float32", "float64"])
def test_the_command_and_python_write_the_same_chunks_and_hashes(cli, tmp_path, dtype):
    stores = {"command": tmp_path / "command.zarr", "python": tmp_path / "python.zarr"}
    run_cli("matrix", TORUS, "--sources", SOURCE_LIST, "--dtype", dtype, "--block-rows", 5, "--out", stores["command"])
    with ThreadPoolExecutor(2) as executor:  # 7 blocks, the last one of 2 rows: a chunk padded with NaN
        distributed.distance_matrix_to_zarr(MESH, SOURCES, stores["python"], dtype=dtype, block_rows=5, client=executor)
    chunks = {name: tree(store / "distances" / "c") for name, store in stores.items()}
    assert len(chunks["python"]) == 7 and chunks["python"] == chunks["command"]
    hashes = {name: [zarr.open_group(str(store / "done" / f"block_{b:06d}"), mode="r").attrs["sha256"]
                     for b in range(7)]
              for name, store in stores.items()}
    assert hashes["python"] == hashes["command"]


def test_a_store_made_for_another_matrix_is_refused_unchanged(cli, tmp_path):
    store = tmp_path / "m.zarr"
    with ThreadPoolExecutor(2) as executor:
        distributed.distance_matrix_to_zarr(MESH, SOURCES, store, block_rows=4, client=executor)
    original = tree(store)
    refusals = {
        ("--sources", "0,9,18"): r"made for other sources \(the store's: 32 sources \[0, 9, 18, 27, 36, \.\.\.\]; "
                                 r"these: 3 sources \[0, 9, 18\]\)",
        ("--sources", SOURCE_LIST, "--dtype", "float64"): r"another dtype \(the store's: \"float32\"",
        ("--sources", SOURCE_LIST, "--block-rows", 5): r"another block_rows \(the store's: 4; this run's: 5\)",
        ("--sources", SOURCE_LIST, "--max-distance", 1):
            r"another max_distance \(the store's: null; this run's: 1\.0\)",
        ("--sources", SOURCE_LIST, "--targets", "1,2"): r"other targets \(the store's: every vertex as targets",
    }
    for arguments, message in refusals.items():
        refused = cli_run("matrix", TORUS, *arguments, "--out", store, "--shard", "0/2")
        assert refused.returncode == 2 and re.search(message, refused.stderr), refused.stderr
    other_mesh = cli_run("matrix", "@torus:24:14", "--sources", SOURCE_LIST, "--out", store, "--resume")
    assert other_mesh.returncode == 2
    assert re.search(r"another mesh \(the store's: 288 vertices, 576 faces, sha256 \w{12}\.\.\.; this one: 336 "
                     r"vertices", other_mesh.stderr)
    welded = cli_run("matrix", TORUS, "--weld", "--sources", SOURCE_LIST, "--out", store)
    assert welded.returncode == 2 and "another mesh" in welded.stderr
    assert tree(store) == original
    # A dense array stored with codecs the command does not write (as stores made before they were
    # uncompressed) is refused, not written into.
    metadata_file = store / "distances" / "zarr.json"
    metadata = json.loads(metadata_file.read_text())
    metadata["codecs"].append({"name": "zstd", "configuration": {"level": 0, "checksum": False}})
    metadata_file.write_text(json.dumps(metadata))
    compressed = cli_run("matrix", TORUS, "--sources", SOURCE_LIST, "--out", store)
    assert compressed.returncode == 2 and "stored with codecs [bytes, zstd]" in compressed.stderr
    assert "uncompressed chunks only" in compressed.stderr


def test_a_half_written_block_is_never_reported_done(cli, tmp_path):
    store = tmp_path / "m.zarr"
    run_cli("matrix", TORUS, "--sources", SOURCE_LIST, "--block-rows", 4, "--out", store)
    # Block 1: its chunk written, its marker not. Block 2: its marker still at its temporary name. Block 5: a
    # temporary chunk file left beside its place.
    shutil.rmtree(store / "done" / "block_000001")
    marker = store / "done" / "block_000002" / "zarr.json"
    marker.rename(marker.with_name(".zarr.json.partial-Xy12ab"))
    shutil.rmtree(store / "done" / "block_000005")
    (store / "distances" / "c" / "5" / ".0.partial-Ab34cd").write_bytes(b"\0" * 100)
    status = cli_run("matrix", "--status", store)
    assert status.returncode == 4
    assert re.search(r"done +5: 0, 3-4, 6-7\n", status.stdout) and re.search(r"missing +3: 1-2, 5\n", status.stdout)
    assert re.search(r"shape +32 x 288\n", status.stdout) and re.search(r"dtype +float32\n", status.stdout)
    assert distributed.store_status(store).missing == (1, 2, 5)
    resumed = cli_run("matrix", TORUS, "--sources", SOURCE_LIST, "--out", store, "--resume")
    assert computed_blocks(resumed.stderr) == 3
    assert cli_run("matrix", "--status", store).returncode == 0
    assert np.array_equal(dense(store), REFERENCE.astype(np.float32))


def test_bad_input_is_refused_with_a_clear_message(cli, tmp_path):
    base = ["matrix", TORUS, "--sources", "0,1", "--out"]
    usage = {
        ("--shard", "1-4"): "not a shard I/N",
        ("--shard", "4/4"): "I must be below 4",
        ("--shard", "0/0"): "N, the number of shards, is 0",
        ("--block-rows", "0"): "must be at least 1",
    }
    for arguments, message in usage.items():
        done = cli_run(*base, tmp_path / "m.zarr", *arguments)
        assert done.returncode == 1 and message in done.stderr, done.stderr
    for option in (["--shard", "0/2"], ["--resume"], ["--dtype", "float64"], ["--block-rows", "2"]):
        done = cli_run(*base, tmp_path / "m.npy", *option)
        assert done.returncode == 1 and "applies to .zarr stores only" in done.stderr, done.stderr
    assert not (tmp_path / "m.zarr").exists() and not (tmp_path / "m.npy").exists()
    # --status on anything but a store.
    (tmp_path / "mine.zarr").mkdir()
    (tmp_path / "mine.zarr" / "notes.txt").write_text("keep me")
    for path, message in ((tmp_path / "none.zarr", "holds no exactgeo distance matrix store"),
                          (tmp_path / "mine.zarr", "is not a Zarr store")):
        done = cli_run("matrix", "--status", path)
        assert done.returncode == 2 and message in done.stderr, done.stderr
    # A folder that is not a store is never written into.
    done = cli_run(*base, tmp_path / "mine.zarr")
    assert done.returncode == 2 and "is not a Zarr store" in done.stderr and "nothing was changed" in done.stderr
    assert [p.name for p in (tmp_path / "mine.zarr").iterdir()] == ["notes.txt"]
    assert cli_run("matrix", "--status", tmp_path / "mine.zarr", "--sources", "0").returncode == 1


def test_verify_reports_a_chunk_corrupted_in_place_and_resume_repairs_it(cli, tmp_path):
    store = tmp_path / "m.zarr"
    command = ["matrix", TORUS, "--sources", SOURCE_LIST, "--block-rows", 4, "--out", store]
    run_cli(*command, "--quiet")
    with open(store / "distances" / "c" / "2" / "0", "r+b") as chunk:  # block 2: a value changed, its marker kept
        chunk.seek(100)
        chunk.write(b"\x00\x00\x80\x3f")
    plain = cli_run("matrix", "--status", store)
    assert plain.returncode == 0  # a marker alone says the block is done
    shown = cli_run("matrix", "--status", store, "--verify")
    assert shown.returncode == 4, shown.stderr
    assert re.search(r"done +7: 0-1, 3-7\n", shown.stdout) and re.search(r"missing +1: 2\n", shown.stdout)
    assert re.search(r"corrupt +1: 2\n", shown.stdout)
    assert re.search(rf"block 2 +'{re.escape(str(store))}/distances/c/2/0' does not hash to the sha256 in "
                     rf"'{re.escape(str(store))}/done/block_000002/zarr.json'", shown.stdout)
    assert distributed.store_status(store, verify=True).corrupt == (2,)  # both verifiers agree
    resumed = cli_run(*command, "--resume")  # without --verify: the marker is trusted
    assert computed_blocks(resumed.stderr) == 0
    repaired = cli_run(*command, "--resume", "--verify")
    assert repaired.returncode == 0, repaired.stderr
    assert "block 2 failed verification" in repaired.stderr and computed_blocks(repaired.stderr) == 1
    assert "(1 of them failed verification), 7 reused (done before, verified)" in repaired.stderr
    assert cli_run("matrix", "--status", store, "--verify").returncode == 0
    assert np.array_equal(dense(store), REFERENCE.astype(np.float32))
    # --verify checks the done blocks of a store: with --status or --resume only.
    alone = cli_run(*command, "--verify")
    assert alone.returncode == 1 and "use it with --status or --resume" in alone.stderr


def test_verify_reports_a_damaged_target_array_and_resume_writes_it_again(cli, tmp_path):
    """Readers take each column's vertex from `target`: every block intact, the store is not complete with a
    wrong one (issue 34's store fuzz found nothing checked it)."""
    store = tmp_path / "m.zarr"
    command = ["matrix", TORUS, "--sources", SOURCE_LIST, "--block-rows", 4, "--out", store]
    run_cli(*command, "--quiet")
    targets = store / "target" / "c" / "0"
    columns = targets.read_bytes()
    targets.write_bytes(columns[8:] + columns[:8])  # the columns' vertices rotated by one
    shown = cli_run("matrix", "--status", store, "--verify")
    assert shown.returncode == 4 and re.search(r"corrupt +0: none\n", shown.stdout)
    assert re.search(r"damaged +1: target\n", shown.stdout)
    assert re.search(rf"target +'{re.escape(str(store))}/target' does not hold the targets", shown.stdout)
    status = distributed.store_status(store, verify=True)  # both verifiers agree
    assert not status.complete and status.missing == () and len(status.damaged) == 1 and "target" in status.damaged[0]
    repaired = cli_run(*command, "--resume", "--verify")
    assert repaired.returncode == 0 and "/target' does not hold the targets" in repaired.stderr
    assert targets.read_bytes() == columns and computed_blocks(repaired.stderr) == 0
    assert distributed.store_status(store, verify=True).complete
