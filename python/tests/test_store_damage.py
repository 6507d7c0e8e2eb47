"""Distance-matrix stores damaged file by file: whatever is corrupted, cut short or deleted (metadata, chunks,
pieces, markers), verifying (store_status(verify=True) and `exactgeo matrix --status --verify`) never vouches
for wrong values, resuming computes every block without a marker again, and resuming with verify restores the
whole matrix or stops with an error naming the file. The command's writer is damaged on its own in
tests/test_cli_store.cpp; here each writer's store is continued by the other."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest
from conftest import CLI, zarr3_or_skip

import exactgeo

zarr = zarr3_or_skip()

from exactgeo import distributed

GRID = "@grid:4:4"
MESH = exactgeo.Mesh(*exactgeo.make_grid(4, 4, 4, 4))  # what GRID generates
SOURCES = [0, 3, 7, 12, 20]
BLOCK_ROWS, BLOCKS = 2, 3
CUT = 1.5


@pytest.fixture
def scratch():
    """In memory where Linux offers it: each test copies a store some 40 times, and on a loaded disk making a
    folder takes half a millisecond."""
    folder = Path(tempfile.mkdtemp(dir="/dev/shm" if os.path.isdir("/dev/shm") else None))
    yield folder
    shutil.rmtree(folder)


def write(store: Path, writer: str, sparse: bool, verify: bool = False) -> None:
    """The matrix into `store` (resuming it if there is one) by exactgeo.distributed or by the command; an
    error names what stopped it (ValueError, or the command's message as a CalledProcessError's stderr)."""
    if writer == "python":
        with ThreadPoolExecutor(1) as executor:
            distributed.distance_matrix_to_zarr(MESH, SOURCES, store, max_distance=CUT if sparse else None,
                                                block_rows=BLOCK_ROWS, client=executor, retries=0, verify=verify)
        return
    cut = ["--max-distance", str(CUT)] if sparse else []
    subprocess.run([str(CLI), "matrix", GRID, "--sources", ",".join(map(str, SOURCES)), *cut, "--block-rows",
                    str(BLOCK_ROWS), "--out", str(store), "--resume", *(["--verify"] if verify else []), "--quiet"],
                   capture_output=True, text=True, check=True)


def right_blocks(store: Path, sparse: bool) -> set[int]:
    """The blocks whose values, read back through zarr, are distance_matrix's (float32)."""
    right = set()
    for block in range(BLOCKS):
        rows = slice(block * BLOCK_ROWS, min((block + 1) * BLOCK_ROWS, len(SOURCES)))
        try:
            if sparse:
                expected = exactgeo.distance_matrix(MESH, SOURCES[rows], max_distance=CUT)
                group = store / "csr" / f"block_{block:06d}"
                pieces = [zarr.open_array(str(group / name), mode="r")[...] for name in ("data", "indices", "indptr")]
                wanted = [expected.data.astype(np.float32), expected.indices, expected.indptr]
                same = pieces[0].dtype == np.float32 and all(map(np.array_equal, pieces, wanted))
            else:
                expected = exactgeo.distance_matrix(MESH, SOURCES[rows]).astype(np.float32)
                same = np.array_equal(zarr.open_array(str(store / "distances"), mode="r")[rows], expected)
        except Exception:  # unreadable: not right
            same = False
        if same:
            right.add(block)
    return right


def command_status(store: Path) -> subprocess.CompletedProcess:
    return subprocess.run([str(CLI), "matrix", "--status", str(store), "--verify"], capture_output=True, text=True)


def ranges(text: str) -> set[int]:
    """'0, 2-3' -> {0, 2, 3}; 'none' -> {}."""
    blocks: set[int] = set()
    for part in text.split(", "):
        if part != "none":
            first, _, last = part.partition("-")
            blocks.update(range(int(first), int(last or first) + 1))
    return blocks


def damage(store: Path, file: str, how: str, block: int) -> None:
    target = store / file
    if how == "deleted":
        target.unlink()
        return
    data = bytearray(target.read_bytes())
    if how == "truncated":
        del data[len(data) // 2:]
    else:  # corrupted; crashed: the block's data overwritten and its marker never written
        middle = len(data) // 2
        data[middle:middle + 8] = bytes(b ^ 0x5A for b in data[middle:middle + 8])
    target.write_bytes(bytes(data))
    if how == "crashed":
        shutil.rmtree(store / "done" / f"block_{block:06d}")


@pytest.mark.parametrize("writer", ["python", "command"])
@pytest.mark.parametrize("sparse", [False, True], ids=["dense", "sparse"])
def test_a_damaged_store_is_repaired_or_refused_never_vouched_for(cli, scratch, writer, sparse):
    other = "command" if writer == "python" else "python"
    pristine, store = scratch / "pristine.zarr", scratch / "store.zarr"
    write(pristine, writer, sparse)
    assert right_blocks(pristine, sparse) == set(range(BLOCKS))
    # A file of each kind (block 1's for the blocks, and the last dense chunk, which is padded), corrupted, cut
    # short (but metadata, which either cuts into invalid JSON) or deleted; each block's data damaged with its
    # marker gone, as a crash between the two leaves it.
    like_others = ("block_000000", "block_000002", "distances/c/0/", "indices", "source/", "mesh/faces/")
    files = sorted(str(p.relative_to(pristine)) for p in pristine.rglob("*")
                   if p.is_file() and not any(kind in str(p.relative_to(pristine)) for kind in like_others))
    data_files = {1: "csr/block_000001/data/c/0" if sparse else "distances/c/1/0",
                  2: "csr/block_000002/indices/c/0" if sparse else "distances/c/2/0"}
    cases = [(file, how, -1) for file in files for how in ("corrupted", "truncated", "deleted")
             if how != "truncated" or not file.endswith(".json")]
    cases += [(file, "crashed", block) for block, file in data_files.items()]

    def refused(error: str, file: str, context: str) -> None:
        """Only the files every block depends on may stop the store being used, and the error names them."""
        assert file in ("zarr.json", "distances/zarr.json") or file.startswith("mesh/"), f"{context}: {error}"
        assert str(store) in error, f"{context}: {error}"

    for file, how, block in cases:
        context = f"{writer} {'sparse' if sparse else 'dense'} store, {file} {how}"
        shutil.rmtree(store, ignore_errors=True)
        shutil.copytree(pristine, store)
        damage(store, file, how, block)
        right = right_blocks(store, sparse)
        # Both verifiers vouch only for blocks whose values are right.
        try:
            status = distributed.store_status(store, verify=True)
            assert set(status.done) <= right, context
        except ValueError as error:
            refused(str(error), file, context)
        shown = command_status(store)
        if shown.returncode == 2:
            refused(shown.stderr, file, context)
        else:
            assert shown.returncode in (0, 4), f"{context}: {shown.stderr}"
            assert ranges(re.search(r"done +\d+: (.*)\n", shown.stdout).group(1)) <= right, context
        # The other writer resumes: the blocks without a marker come back right; with verify, every block.
        unmarked = {b for b in range(BLOCKS) if not (store / "done" / f"block_{b:06d}" / "zarr.json").is_file()}
        for resumer, verify in ((other, False), (writer, True)):
            try:
                write(store, resumer, sparse, verify=verify)
            except ValueError as error:
                refused(str(error), file, context)
                continue
            except subprocess.CalledProcessError as error:
                assert error.returncode == 2, f"{context}: {error.stderr}"
                refused(error.stderr, file, context)
                continue
            wanted = set(range(BLOCKS)) if verify else unmarked
            assert not wanted or right_blocks(store, sparse) >= wanted, f"{context}, {resumer} resuming"
            if verify:
                assert distributed.store_status(store, verify=True).complete, context


def test_an_edited_block_count_is_refused_not_believed(cli, scratch):
    store = scratch / "store.zarr"
    write(store, "python", sparse=False)
    metadata = json.loads((store / "zarr.json").read_text())
    metadata["attributes"]["exactgeo"]["blocks"] = 1  # would hide blocks 1 and 2
    (store / "zarr.json").write_text(json.dumps(metadata))
    with pytest.raises(ValueError, match=r"zarr\.json: its exactgeo attribute's shape, sources, blocks and block_rows"):
        distributed.store_status(store)
    shown = subprocess.run([str(CLI), "matrix", "--status", str(store)], capture_output=True, text=True)
    assert shown.returncode == 2 and "has 1 blocks, but 5 rows in blocks of 2 make 3" in shown.stderr
