"""The store layout of docs/distributed.md ("The store") is the specification of the store component (store/): a
store of each layout written by each caller (exactgeo.distributed and the command) holds exactly the files that
its table lists and, in each metadata file, exactly the keys its second table lists. And the stores written before
the component (tests/data/stores-0.1.0, by the Python writer over zarr-python and by the command's own) still read,
verify and resume, by either writer, to distance_matrix's values."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest
from conftest import CLI, REPOSITORY, zarr3_or_skip

import exactgeo

zarr = zarr3_or_skip()

from exactgeo import distributed  # noqa: E402 (after the skip above, which needs zarr 3)

SPEC = (REPOSITORY / "docs" / "distributed.md").read_text()
FIXTURES = REPOSITORY / "tests" / "data" / "stores-0.1.0"


def spec_table(first_header: str) -> list[list[str]]:
    """The rows of the Markdown table of the store section whose first column is headed `first_header`."""
    section = SPEC[SPEC.index("## The store\n"):]
    lines = section[section.index(f"| {first_header} |"):].splitlines()
    rows = []
    for line in lines[2:]:
        if not line.startswith("|"):
            break
        rows.append([cell.strip() for cell in line.strip("|").split("|")])
    return rows


def documented_files(layout: str) -> set[str]:
    return {path.strip("`") for path, where, _ in spec_table("path") if where in ("both", layout)}


def documented_keys() -> dict[str, list[str]]:
    """The keys of each kind of metadata, by the kind's first word ("group", "array", "settings", "dense", "sparse")."""
    return {kind.split()[0]: re.findall(r"`(\w+)`", keys) for kind, keys in spec_table("metadata")}


def pattern_of(relative: str) -> str:
    """A file's path with its block numbers as the table writes them."""
    relative = re.sub(r"block_\d{6}", "block_NNNNNN", relative)
    return re.sub(r"^distances/c/\d+/0$", "distances/c/B/0", relative)


# A grid of 64 vertices; 7 rows in blocks of 3, so that the last block is short; a cut-off leaving some rows empty.
GRID = "@grid:7:7"
MESH = exactgeo.Mesh(*exactgeo.make_grid(7, 7, 7, 7))  # what GRID generates
SOURCES = [0, 9, 18, 27, 36, 45, 63]
CUT = 2.5


def write(store: Path, writer: str, sparse: bool) -> None:
    if writer == "python":
        with ThreadPoolExecutor(1) as executor:
            distributed.distance_matrix_to_zarr(MESH, SOURCES, store, max_distance=CUT if sparse else None,
                                                block_rows=3, client=executor, retries=0)
        return
    cut = ["--max-distance", str(CUT)] if sparse else []
    subprocess.run([str(CLI), "matrix", GRID, "--sources", ",".join(map(str, SOURCES)), *cut,
                    "--block-rows", "3", "--out", str(store), "--quiet"], capture_output=True, text=True, check=True)


@pytest.mark.parametrize("writer", ["python", "command"])
@pytest.mark.parametrize("layout", ["dense", "sparse"])
def test_a_store_holds_the_documented_files_and_keys(cli, tmp_path, writer, layout):
    store = tmp_path / "m.zarr"
    write(store, writer, layout == "sparse")
    files = {str(p.relative_to(store)) for p in store.rglob("*") if p.is_file()}
    found = {pattern_of(f) for f in files}
    documented = documented_files(layout)
    assert found <= documented, f"files the layout does not document: {found - documented}"
    # A chunk holding only the fill value may be left out (an empty sparse piece); every metadata file is there.
    assert {f for f in documented if f.endswith("zarr.json")} <= found
    assert {f for f in documented if not f.endswith("zarr.json")} - found <= {
        "csr/block_NNNNNN/data/c/0", "csr/block_NNNNNN/indices/c/0"}
    blocks = -(-len(SOURCES) // 3)
    assert sorted(f for f in files if f.startswith("done/block_")) == \
        [f"done/block_{b:06d}/zarr.json" for b in range(blocks)]
    if layout == "dense":
        assert sorted(f for f in files if f.startswith("distances/c/")) == [f"distances/c/{b}/0" for b in range(blocks)]
    keys = documented_keys()
    for relative in (f for f in files if f.endswith("zarr.json")):
        metadata = json.loads((store / relative).read_text())
        kind = metadata["node_type"]
        assert list(metadata) == keys[kind], relative
        if kind == "array":
            assert metadata["codecs"] == [{"name": "bytes", "configuration": {"endian": "little"}}], relative
            assert metadata["zarr_format"] == 3 and metadata["chunk_grid"]["name"] == "regular", relative
        if relative == "zarr.json":
            assert list(metadata["attributes"]) == ["exactgeo"]
            assert list(metadata["attributes"]["exactgeo"]) == keys["settings"]
        if relative.startswith("done/block_"):
            assert list(metadata["attributes"]) == keys[layout], relative


def test_the_spec_tables_are_read_whole():
    """The tables the test above reads: a table cut short would make it vouch for less."""
    assert len(documented_files("dense")) == 14 and len(documented_files("sparse")) == 20
    assert set(documented_keys()) == {"group", "array", "settings", "dense", "sparse"}


# The stores written before the component.

FIXTURE_MESH = exactgeo.Mesh(*exactgeo.make_grid(3, 3, 3, 3))
FIXTURE_SOURCES = [0, 4, 8]


def fixture_reference(sparse: bool) -> np.ndarray:
    return exactgeo.distance_matrix(FIXTURE_MESH, FIXTURE_SOURCES, max_distance=1.5 if sparse else None)


@pytest.mark.parametrize("resumer", ["python", "command"])
@pytest.mark.parametrize("name", ["python-dense", "python-sparse", "command-dense", "command-sparse"])
def test_a_store_written_before_the_component_reads_verifies_and_resumes(cli, tmp_path, name, resumer):
    store = tmp_path / f"{name}.zarr"
    shutil.copytree(FIXTURES / f"{name}.zarr", store)
    sparse = name.endswith("sparse")
    status = distributed.store_status(store, verify=True)
    assert (status.done, status.missing, status.corrupt, status.damaged) == ((0,), (1,), (), ())
    shown = subprocess.run([str(CLI), "matrix", "--status", str(store), "--verify"], capture_output=True, text=True)
    assert shown.returncode == 4 and re.search(r"done +1: 0\n", shown.stdout), shown.stdout + shown.stderr
    block_0 = {p: p.read_bytes() for p in store.rglob("*") if p.is_file() and "block_000000" in str(p) or
               str(p).endswith("distances/c/0/0")}
    if resumer == "python":
        with ThreadPoolExecutor(1) as executor:
            run = distributed.distance_matrix_to_zarr(FIXTURE_MESH, FIXTURE_SOURCES, store, client=executor,
                                                      max_distance=1.5 if sparse else None, verify=True)
        assert (run.computed, run.reused) == ((1,), (0,))
    else:
        cut = ["--max-distance", "1.5"] if sparse else []
        subprocess.run([str(CLI), "matrix", "@grid:3:3", "--sources", "0,4,8", *cut, "--out", str(store), "--resume",
                        "--verify", "--quiet"], capture_output=True, text=True, check=True)
    assert all(path.read_bytes() == data for path, data in block_0.items())  # block 0 kept as it was written
    assert distributed.store_status(store, verify=True).complete
    expected = fixture_reference(sparse)
    if sparse:
        assert (distributed.read_sparse(store) != expected.astype(np.float32)).nnz == 0
    else:
        assert np.array_equal(zarr.open_array(str(store / "distances"), mode="r")[...], expected.astype(np.float32))
