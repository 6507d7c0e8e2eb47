"""The store fuzz: every file of a small dense store (made by exactgeo.distributed) and a small sparse one (made by
the command), 5 rows in 3 blocks, is corrupted (bytes flipped), cut short or deleted in turn, and each JSON file
edited so that it stays valid JSON with one value changed (every value of the root's, a seeded one of each other
file's); each block's data is also overwritten with its marker gone, as a crash between the two leaves it. Then:

- verifying (store_status(verify=True) and `exactgeo matrix --status --verify`) vouches only for blocks whose values
  are right, and calls the store complete only if all a reader reads is right: the matrix, the source and target
  arrays, the mesh and the settings that say what the matrix is;
- resuming without verify computes every block left without a marker again;
- resuming with verify leaves the store complete and right;

or each stops with an error naming the store, and only where the file damaged is one every block depends on. The
two writers take turns at resuming, case by case. The command's writer is fuzzed on its own, on every case, in
tests/test_cli_store.cpp.
"""

from __future__ import annotations

import json
import os
import random
import re
import shutil
import subprocess
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import CLI, zarr3_or_skip

import exactgeo

zarr = zarr3_or_skip()

from exactgeo import distributed  # noqa: E402 (after the skip above, which needs zarr 3)

GRID = "@grid:4:4"
MESH = exactgeo.Mesh(*exactgeo.make_grid(4, 4, 4, 4))  # what GRID generates
SOURCES = [0, 3, 7, 12, 20]
BLOCK_ROWS, BLOCKS = 2, 3
CUT = 1.5
WRITERS = ("python", "command")
# The settings that say what the matrix is (not which version wrote it).
DEFINING = ("mesh_sha256", "vertex_count", "face_count", "weld_duplicate_positions", "sources", "targets", "shape",
            "dtype", "max_distance", "layout", "block_rows", "blocks")


@pytest.fixture
def scratch():
    """In memory where Linux offers it: each test copies a store a hundred times or more, and on a loaded disk making
    a folder takes half a millisecond."""
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


def block_files(block: int, sparse: bool) -> list[str]:
    """The files holding a block's values, and the metadata saying how to read them."""
    if not sparse:
        return ["distances/zarr.json", f"distances/c/{block}/0"]
    return [f"csr/block_{block:06d}/{piece}/{file}" for piece in ("data", "indices", "indptr")
            for file in ("zarr.json", "c/0")]


# What a reader reads, part by part, and the files each part is read from.
PARTS = {"source": ["source/zarr.json", "source/c/0"], "target": ["target/zarr.json", "target/c/0"],
         "mesh": ["mesh/zarr.json", *[f"mesh/{a}/{f}" for a in ("vertices", "faces") for f in ("zarr.json", "c/0/0")]],
         "settings": ["zarr.json"]}


class Pristine:
    """A store as its writer made it, and what each part of it reads as."""

    def __init__(self, path: Path, sparse: bool) -> None:
        self.path, self.sparse = path, sparse
        self.parts = {**{f"block {b}": block_files(b, sparse) for b in range(BLOCKS)}, **PARTS}
        self.values = {part: self.read(path, part) for part in self.parts}
        expected = exactgeo.distance_matrix(MESH, SOURCES, max_distance=CUT if sparse else None)
        for block in range(BLOCKS):  # the writer's values are distance_matrix's, as float32
            rows = slice(block * BLOCK_ROWS, (block + 1) * BLOCK_ROWS)
            wanted = expected[rows] if sparse else expected[rows].astype(np.float32)
            wanted = [wanted.data.astype(np.float32), wanted.indices, wanted.indptr] if sparse else [wanted]
            assert all(map(np.array_equal, self.values[f"block {block}"], wanted)), block

    def read(self, store: Path, part: str) -> list[Any] | None:
        """The part's values as a reader gets them through zarr; None if they cannot be read."""
        try:
            if part == "settings":
                settings = dict(zarr.open_group(str(store), mode="r").attrs)["exactgeo"]
                return [{key: settings[key] for key in DEFINING}]
            if part == "mesh":
                group = zarr.open_group(str(store / "mesh"), mode="r")
                return [group["vertices"][...], group["faces"][...]]
            if part.startswith("block"):
                block = int(part.split()[1])
                if self.sparse:
                    folder = store / "csr" / f"block_{block:06d}"
                    return [zarr.open_array(str(folder / piece), mode="r")[...]
                            for piece in ("data", "indices", "indptr")]
                rows = slice(block * BLOCK_ROWS, (block + 1) * BLOCK_ROWS)
                return [zarr.open_array(str(store / "distances"), mode="r")[rows]]
            return [zarr.open_array(str(store / part), mode="r")[...]]
        except Exception:
            return None

    def right(self, store: Path) -> set[str]:
        """The parts of `store` that read as the pristine store's: at once where their files are the same bytes,
        through zarr otherwise."""
        right = set()
        for part, files in self.parts.items():
            if all(same_bytes(store / file, self.path / file) for file in files):
                right.add(part)
            else:
                values = self.read(store, part)
                if values is not None and all(equal(a, b) for a, b in zip(values, self.values[part])):
                    right.add(part)
        return right

    def right_blocks(self, store: Path) -> set[int]:
        return {int(part.split()[1]) for part in self.right(store) if part.startswith("block")}


def same_bytes(a: Path, b: Path) -> bool:
    try:
        return a.read_bytes() == b.read_bytes()
    except FileNotFoundError:
        return not a.exists() and not b.exists()


def equal(a: Any, b: Any) -> bool:
    if isinstance(a, np.ndarray):
        return isinstance(b, np.ndarray) and a.dtype == b.dtype and np.array_equal(a, b)
    return a == b


# The damage.


def edited(value: Any) -> Any:
    """A leaf of JSON changed to another value of its type: a number plus one, a flag flipped, the last character
    of a text to the next one (a hex digit to the next hex digit), null to 0."""
    if isinstance(value, bool):
        return not value
    if isinstance(value, (int, float)):
        return value + 1
    if isinstance(value, str):
        if not value:
            return "x"
        last = value[-1]
        following = "0123456789abcdef0" if last in "0123456789abcdef" else None
        return value[:-1] + (following[following.index(last) + 1] if following else chr(ord(last) + 1))
    return 0  # null


def leaves(value: Any, path: tuple = ()) -> list[tuple]:
    """The paths to every value in `value` that holds no other."""
    if isinstance(value, dict):
        return [leaf for key, item in value.items() for leaf in leaves(item, (*path, key))]
    if isinstance(value, list):
        return [leaf for i, item in enumerate(value) for leaf in leaves(item, (*path, i))]
    return [path]


def cases(pristine: Path, sparse: bool) -> list[tuple[str, str, Any]]:
    """(file, how, detail): every file flipped, truncated and deleted; each value of the root zarr.json and a seeded
    one of each other JSON file edited; each block's values crashed (overwritten, marker gone)."""
    files = sorted(str(p.relative_to(pristine)) for p in pristine.rglob("*") if p.is_file())
    found = [(file, how, None) for file in files for how in ("flipped", "truncated", "deleted")]
    for file in (f for f in files if f.endswith(".json")):
        paths = leaves(json.loads((pristine / file).read_text()))
        chosen = paths if file == "zarr.json" else [random.Random(file).choice(paths)] if paths else []
        found += [(file, "edited", path) for path in chosen]
    found += [(block_files(block, sparse)[-1], "crashed", block) for block in range(BLOCKS)]
    return found


def damage(store: Path, file: str, how: str, detail: Any) -> None:
    target = store / file
    if how == "deleted":
        target.unlink()
        return
    if how == "edited":
        document = json.loads(target.read_text())
        *path, last = detail
        holder = document
        for key in path:
            holder = holder[key]
        holder[last] = edited(holder[last])
        target.write_text(json.dumps(document))
        return
    data = bytearray(target.read_bytes())
    if how == "truncated":
        del data[len(data) // 2:]
    else:  # flipped; crashed: the block's data overwritten and its marker never written
        middle = len(data) // 2
        data[middle:middle + 8] = bytes(b ^ 0x5A for b in data[middle:middle + 8])
    target.write_bytes(bytes(data))
    if how == "crashed":
        shutil.rmtree(store / "done" / f"block_{detail:06d}")


# The checks.


def command_status(store: Path) -> tuple[set[int] | None, bool, str]:
    """`matrix --status --verify`: the blocks it calls done and whether it calls the store complete, or None and the
    error it stopped with."""
    shown = subprocess.run([str(CLI), "matrix", "--status", str(store), "--verify"], capture_output=True, text=True)
    if shown.returncode == 2:
        return None, False, shown.stderr
    assert shown.returncode in (0, 4), shown.stderr
    blocks: set[int] = set()
    for part in re.search(r"done +\d+: (.*)\n", shown.stdout).group(1).split(", "):
        if part != "none":
            first, _, last = part.partition("-")
            blocks.update(range(int(first), int(last or first) + 1))
    return blocks, shown.returncode == 0, shown.stdout


# The files every block depends on: damaged, they may stop a verifier or a writer, with an error naming the store.
REFUSABLE = ("zarr.json", "distances/zarr.json")


def check_verifiers(pristine: Pristine, store: Path, file: str, context: str) -> None:
    """Both verifiers vouch only for right blocks, and for a complete store only if every part is right; or they
    stop with an error naming the store."""
    right = pristine.right(store)
    everything = set(pristine.parts)
    try:
        status = distributed.store_status(store, verify=True)
        assert {f"block {b}" for b in status.done} <= right, context
        assert not status.complete or right == everything, f"{context}: complete, but {everything - right} wrong"
    except ValueError as error:
        assert file in REFUSABLE and str(store) in str(error), f"{context}: {error}"
    done, complete, shown = command_status(store)
    if done is None:
        assert file in REFUSABLE and str(store) in shown, f"{context}: {shown}"
    else:
        assert {f"block {b}" for b in done} <= right, context
        assert not complete or right == everything, f"{context}: command says complete, but {everything - right} wrong"


def resumed(store: Path, writer: str, sparse: bool, verify: bool, file: str, context: str) -> bool:
    """Whether `writer` resumed the store; False if it stopped with an error naming it."""
    try:
        write(store, writer, sparse, verify=verify)
    except ValueError as error:
        assert file in REFUSABLE and str(store) in str(error), f"{context}: {error}"
        return False
    except subprocess.CalledProcessError as error:
        assert file in REFUSABLE and error.returncode == 2 and str(store) in error.stderr, f"{context}: {error.stderr}"
        return False
    return True


@pytest.mark.parametrize(("sparse", "maker"), [(False, "python"), (True, "command")], ids=["dense", "sparse"])
def test_a_damaged_store_is_repaired_or_refused_never_vouched_for(cli, scratch, sparse, maker):
    write(scratch / "pristine.zarr", maker, sparse)
    pristine = Pristine(scratch / "pristine.zarr", sparse)
    store = scratch / "store.zarr"
    for number, (file, how, detail) in enumerate(cases(pristine.path, sparse)):
        resumer = WRITERS[number % 2]  # each resumes every other case: both repair each kind of damage
        context = f"{maker}'s {'sparse' if sparse else 'dense'} store, {file} {how} {detail or ''}"
        shutil.rmtree(store, ignore_errors=True)
        shutil.copytree(pristine.path, store)
        damage(store, file, how, detail)
        check_verifiers(pristine, store, file, context + ", status")
        unmarked = {b for b in range(BLOCKS) if not (store / "done" / f"block_{b:06d}" / "zarr.json").is_file()}
        context += f", {resumer} resuming"
        if unmarked and resumed(store, resumer, sparse, False, file, context):
            assert pristine.right_blocks(store) >= unmarked, f"{context}: blocks {unmarked} not computed"
        if resumed(store, resumer, sparse, True, file, context + " with verify"):
            assert pristine.right(store) == set(pristine.parts), f"{context} with verify"
            assert distributed.store_status(store, verify=True).complete, context
            assert command_status(store)[1], context


def test_an_edited_block_count_is_refused_not_believed(cli, scratch):
    store = scratch / "store.zarr"
    write(store, "python", sparse=False)
    metadata = json.loads((store / "zarr.json").read_text())
    metadata["attributes"]["exactgeo"]["blocks"] = 1  # would hide blocks 1 and 2
    (store / "zarr.json").write_text(json.dumps(metadata))
    with pytest.raises(ValueError, match=r"zarr\.json': its exactgeo attribute has 1 blocks, but 5 rows in blocks"):
        distributed.store_status(store)
    shown = subprocess.run([str(CLI), "matrix", "--status", str(store)], capture_output=True, text=True)
    assert shown.returncode == 2 and "has 1 blocks, but 5 rows in blocks of 2 make 3" in shown.stderr
