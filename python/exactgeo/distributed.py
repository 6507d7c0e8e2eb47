"""Distance matrices larger than one machine: rows computed in blocks on Dask workers (or any
concurrent.futures executor), each block written by its worker straight into a Zarr store.

    from exactgeo import distributed
    run = distributed.distance_matrix_to_zarr(mesh, sources, "d.zarr")   # a LocalCluster on every core
    distributed.store_status("d.zarr").complete                          # True
    zarr.open_array("d.zarr/distances")[:]                                # or dask.array.from_zarr

An optional extra (dask[distributed] and zarr: pip install 'dask[distributed]>=2023.1' 'zarr>=3'); `import exactgeo`
does not import it, and this module imports dask and zarr only when a function needs them. It needs zarr-python 3 (Zarr
format v3). See docs/distributed.md.

The store is a folder every worker can write to (a local disk for a LocalCluster, a shared filesystem for
a cluster):

    STORE/zarr.json                 root group; attribute "exactgeo": what the matrix is (mesh hash, sources,
                                    targets, dtype, max_distance, block_rows, exactgeo's version)
    STORE/distances                 (sources, targets) array, chunks of (block_rows, all columns): block b is
                                    chunk row b, rows [b * block_rows, (b + 1) * block_rows); NaN where no
                                    block was written yet (dense matrices only); uncompressed, so that a
                                    block's chunk (distances/c/B/0) is its rows' bytes, written as they are
    STORE/source, STORE/target      int64 vertex index of each row, of each column
    STORE/mesh/{vertices,faces}     the mesh, so that workers and later readers can rebuild it
    STORE/csr/block_000012/{data,indices,indptr}   block 12's rows as CSR (with max_distance only), the
                                    row pointers from 0; written in a hidden folder beside it, then renamed
    STORE/done/block_000012         a Zarr group with no arrays, made once block 12's data is complete: its
                                    metadata file (zarr.json) is renamed into place last and is the marker;
                                    its attributes hold the block's rows, its max_distance and the sha256 of
                                    the bytes written

Every array is uncompressed. A block counts as done only through its marker, written after its data: an
interrupted or killed run leaves at most blocks without markers, which the next run with resume=True computes
again, replacing whatever data they left (a block being written again loses its marker first). verify=True
(and `exactgeo matrix --verify`) checks the done blocks' data against the sha256 their markers recorded, and
the source, target and mesh arrays against the settings; a run with verify=True computes those blocks and
writes those arrays again.

The command `exactgeo matrix --out STORE --shard I/N` (cli/formats/zarr_store.cpp) writes this same layout (format
v3), so either can continue a store the other began. The store is built in a hidden folder beside its place and
renamed into it; an error or an interrupt (Ctrl-C) while building it removes that folder.
"""

from __future__ import annotations

import concurrent.futures
import dataclasses
import errno
import functools
import hashlib
import json
import math
import os
import shutil
import time
import uuid
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Union

import numpy as np

from . import _inputs
from ._mesh import Mesh, checked_mesh
from ._progress import Progress, Reporter, checked as checked_progress

if TYPE_CHECKING:
    from numpy.typing import DTypeLike

FORMAT = "exactgeo-distance-matrix/1"
DTYPES = ("float32", "float64")
StorePath = Union[str, "os.PathLike[str]"]

_MISSING_EXTRA = ("exactgeo.distributed needs its extra, dask[distributed] and zarr: "
                  "pip install 'dask[distributed]>=2023.1' 'zarr>=3'")
ZARR_FORMAT = 3
# The blocks a run computes: each block's arguments to _compute_block after the context, by block index.
_Tasks = dict[int, tuple[Any, ...]]
# Called with a block's index once the block is done.
_Finished = Callable[[int], None]


# What a run returns and what a store holds.


@dataclasses.dataclass(frozen=True)
class MatrixRun:
    """What distance_matrix_to_zarr did: the store, its block count, the blocks it computed (in order of
    block index) and those it found done and kept."""

    store: str
    blocks: int
    computed: tuple[int, ...]
    reused: tuple[int, ...]


@dataclasses.dataclass(frozen=True)
class StoreStatus:
    """Which blocks of a store are done (their marker written after their data) and which are missing."""

    store: str
    layout: str  # "dense" (the distances array) or "sparse" (csr/ pieces)
    shape: tuple[int, int]  # (sources, targets)
    dtype: str
    block_rows: int
    blocks: int
    done: tuple[int, ...]
    missing: tuple[int, ...]  # corrupt blocks included
    corrupt: tuple[int, ...] = ()  # with verify=True: marked done, but their data is not what the marker says
    # With verify=True: why the arrays every block shares (source, target, mesh/) do not hold what the store's
    # settings record, naming the files; a run with verify=True writes them again.
    damaged: tuple[str, ...] = ()

    @property
    def complete(self) -> bool:
        return not self.missing and not self.damaged

    def rows(self, block: int) -> range:
        """The matrix rows of `block`."""
        start = block * self.block_rows
        return range(start, min(start + self.block_rows, self.shape[0]))


# Lazy imports of the optional extra.


def _zarr() -> Any:
    try:
        import zarr
    except ImportError:
        raise ImportError(_MISSING_EXTRA) from None
    if int(zarr.__version__.split(".")[0]) < 3:
        raise ImportError(f"exactgeo.distributed needs zarr-python 3 or newer (Python 3.11+), not {zarr.__version__}: "
                          "pip install 'zarr>=3'")
    return zarr


def _open_group(path: Path, mode: str) -> Any:
    return _zarr().open_group(store=str(path), mode=mode)


def _open_array(path: Path, mode: str = "r") -> Any:
    return _zarr().open_array(store=str(path), mode=mode)


# Every array is stored uncompressed, its chunks raw little-endian bytes: the command
# (cli/formats/zarr_store.cpp) writes blocks into `distances` and reads every array back to verify it.


def _new_array(store: Path, shape: tuple[int, ...], chunks: tuple[int, ...], dtype: Any, fill_value: Any,
               dimensions: Sequence[str]) -> Any:
    """An array at `store` (replacing one there), with dimension names as xarray reads them."""
    chunks = tuple(max(1, c) for c in chunks)
    return _zarr().create_array(store=str(store), shape=shape, chunks=chunks, dtype=dtype, fill_value=fill_value,
                                dimension_names=list(dimensions), compressors=None, overwrite=True)


def _array_of(store: Path, values: np.ndarray, dimensions: Sequence[str]) -> None:
    """`values` as an array at `store` in one chunk."""
    array = _new_array(store, values.shape, values.shape, values.dtype, 0, dimensions)
    if values.size:
        array[...] = values


# The mesh, the settings and the markers.


def mesh_hash(mesh: Mesh) -> str:
    """sha256 (hex) of the mesh's input: vertex and face counts, welding, vertices as float64 and faces as
    uint32, in C order. Equal meshes have equal hashes; stores record it."""
    mesh = checked_mesh(mesh)
    return _mesh_digest(mesh.vertices, mesh.faces, mesh._weld)


def _mesh_digest(vertices: np.ndarray, faces: np.ndarray, weld: bool) -> str:
    """mesh_hash of a mesh given as its arrays, as a store keeps them."""
    digest = hashlib.sha256(b"exactgeo-mesh/1")
    vertices = np.ascontiguousarray(vertices, dtype="<f8")
    faces = np.ascontiguousarray(faces, dtype="<u4")
    digest.update(np.array([len(vertices), len(faces), int(weld)], dtype="<i8").tobytes())
    digest.update(vertices.tobytes())
    digest.update(faces.tobytes())
    return digest.hexdigest()


def _block_name(block: int) -> str:
    return f"block_{block:06d}"


def _beside(final: Path) -> Path:
    """A hidden name beside `final` for building it: the process and a random number keep attempts apart."""
    return final.parent / f".{final.name}.{os.getpid()}.{uuid.uuid4().hex}.tmp"


def _write_atomically(final: Path, data: str | bytes | np.ndarray) -> None:
    """The file appears whole or not at all, its bytes on disk before it does: written beside its final name,
    synced, then renamed. An array is written from its own memory, without a copy."""
    content = data.encode() if isinstance(data, str) else data.data if isinstance(data, np.ndarray) else data
    temporary = _beside(final)
    try:
        with open(temporary, "wb") as file:
            file.write(content)
            file.flush()
            os.fsync(file.fileno())
        os.replace(temporary, final)
    finally:
        if temporary.exists():  # stopped before the rename: an error or Ctrl-C
            temporary.unlink()


def _build_folder_into_place(final: Path, build: Callable[[Path], None], replace: bool = False) -> bool:
    """Builds a folder at a hidden name beside `final`, then renames it into place, so that it appears whole.
    rename fails on a full folder: one there first is kept (the result is then False), or with `replace` moved
    aside and removed, so that leftover pieces are never trusted. Whatever stops the building, an error or
    Ctrl-C (KeyboardInterrupt), nothing built is left behind."""
    building = _beside(final)
    try:
        build(building)
        while True:
            try:
                os.rename(building, final)
                return True
            except OSError as error:
                if error.errno not in (errno.EEXIST, errno.ENOTEMPTY):
                    raise
                if not replace:
                    return False
            aside = _beside(final)
            try:
                os.rename(final, aside)
            except FileNotFoundError:  # another attempt at the same block moved it aside first
                pass
            shutil.rmtree(aside, ignore_errors=True)
    finally:
        shutil.rmtree(building, ignore_errors=True)  # nothing there once renamed


def _remove_marker(path: Path, block: int) -> None:
    """A block whose data is about to be replaced is not done until its new marker: its old one goes first, so
    that a run stopped in between leaves the block missing, never marked done over other data."""
    try:
        shutil.rmtree(path / "done" / _block_name(block))
    except FileNotFoundError:
        pass


def _write_group(folder: Path, attributes: dict[str, Any]) -> None:
    """A Zarr group at `folder` whose attributes are `attributes`: its metadata file written whole."""
    folder.mkdir(parents=True, exist_ok=True)
    _write_atomically(folder / "zarr.json", json.dumps(
        {"zarr_format": ZARR_FORMAT, "node_type": "group", "attributes": attributes}))


def _write_marker(path: Path, block: int, record: dict[str, Any]) -> None:
    """done/block_NNNNNN: a Zarr group whose attributes are `record`; its metadata file, renamed into place
    after the block's data is written, is the marker."""
    _write_group(path / "done" / _block_name(block), record)


def _done_blocks(path: Path, blocks: int) -> list[int]:
    folder = path / "done"
    if not folder.is_dir():
        return []
    found = []
    for entry in folder.iterdir():
        number = entry.name[len("block_"):]
        if entry.name.startswith("block_") and number.isdigit() and int(number) < blocks \
                and (entry / "zarr.json").is_file():
            found.append(int(number))
    return sorted(found)


def _stored_settings(path: Path) -> dict[str, Any] | None:
    """The store's "exactgeo" attribute, None if there is no store at `path`; ValueError if `path` holds
    something else."""
    if not path.exists():
        return None
    if not path.is_dir():
        raise ValueError(f"{path} exists and is not a folder: choose another store")
    if not any(path.iterdir()):
        return None
    if not ((path / "zarr.json").is_file() or (path / ".zgroup").is_file()):
        raise ValueError(f"{path} exists and is not a Zarr store: choose another store (nothing was changed)")
    if not (path / "zarr.json").is_file():
        raise ValueError(f"{path} is a Zarr format 2 store: exactgeo.distributed reads and writes format 3 only "
                         "(zarr-python 3); choose another store (nothing was changed)")
    try:
        settings = dict(_open_group(path, "r").attrs).get("exactgeo")
    except Exception as error:  # zarr's own errors do not name the file
        raise ValueError(f"{path / 'zarr.json'} cannot be read as a Zarr group: {error}") from None
    if not isinstance(settings, dict) or settings.get("format") != FORMAT:
        raise ValueError(f"{path} is a Zarr store but not an exactgeo distance matrix: choose another store "
                         "(nothing was changed)")
    # The counts are checked against each other, so that an edited block count cannot hide blocks.
    try:
        rows, columns = settings["shape"]
        targets = settings["targets"]
        agree = len(settings["sources"]) == rows and settings["blocks"] == math.ceil(rows / settings["block_rows"]) \
            and columns == (settings["vertex_count"] if targets is None else len(targets))
    except (KeyError, TypeError, ValueError, ZeroDivisionError):
        agree = False
    if not agree:
        raise ValueError(f"{path / 'zarr.json'}: its exactgeo attribute's shape, sources, targets, blocks and "
                         "block_rows do not agree")
    if settings.get("layout") != ("dense" if settings.get("max_distance") is None else "sparse"):
        raise ValueError(f"{path / 'zarr.json'}: its exactgeo attribute's layout {settings.get('layout')!r} does not "
                         f"go with its max_distance {settings.get('max_distance')!r}")
    return settings


def _describe(values: list[Any] | None, noun: str) -> str:
    if values is None:
        return f"every vertex as {noun}"
    head = ", ".join(map(str, values[:5])) + (", ..." if len(values) > 5 else "")
    return f"{len(values)} {noun} [{head}]"


def _differences(stored: dict[str, Any], wanted: dict[str, Any], explicit_block_rows: bool) -> list[str]:
    found = []
    if any(stored[key] != wanted[key] for key in ("mesh_sha256", "vertex_count", "face_count",
                                                  "weld_duplicate_positions")):
        found.append(f"another mesh (the store's: {stored['vertex_count']} vertices, {stored['face_count']} faces, "
                     f"sha256 {stored['mesh_sha256'][:12]}...; this one: {wanted['vertex_count']} vertices, "
                     f"{wanted['face_count']} faces, sha256 {wanted['mesh_sha256'][:12]}...)")
    if stored["sources"] != wanted["sources"]:
        found.append(f"other sources (the store's: {_describe(stored['sources'], 'sources')}; these: "
                     f"{_describe(wanted['sources'], 'sources')})")
    if stored["targets"] != wanted["targets"]:
        found.append(f"other targets (the store's: {_describe(stored['targets'], 'targets')}; these: "
                     f"{_describe(wanted['targets'], 'targets')})")
    for key in ("dtype", "max_distance", "zarr_format"):
        if stored[key] != wanted[key]:
            found.append(f"another {key} (the store's: {stored[key]!r}; this run's: {wanted[key]!r})")
    if explicit_block_rows and stored["block_rows"] != wanted["block_rows"]:
        found.append(f"another block_rows (the store's: {stored['block_rows']}; this run's: {wanted['block_rows']})")
    return found


def _create_store(path: Path, settings: dict[str, Any], mesh: Mesh, sources: np.ndarray,
                  targets: np.ndarray | None) -> None:
    root = _open_group(path, "w")
    rows, width = settings["shape"]
    if settings["max_distance"] is None:
        _new_array(path / "distances", (rows, width), (settings["block_rows"], width), settings["dtype"], float("nan"),
                   ("source", "target"))
    else:
        root.create_group("csr")
    _write_shared_arrays(path, mesh, sources, targets)
    root.create_group("done")
    root.attrs["exactgeo"] = settings


def _write_shared_arrays(path: Path, mesh: Mesh, sources: np.ndarray, targets: np.ndarray | None) -> None:
    """The arrays every block shares (the rows' and columns' vertices, the mesh), each built beside its place and
    renamed into it, so that one written again while other workers read it appears whole."""
    arrays: dict[str, tuple[np.ndarray, tuple[str, ...]]] = {
        "source": (sources.astype(np.int64), ("source",)),
        "target": ((np.arange(mesh.vertex_count) if targets is None else targets).astype(np.int64), ("target",)),
        "mesh/vertices": (np.array(mesh.vertices, dtype=np.float64), ("vertex", "xyz")),
        "mesh/faces": (np.array(mesh.faces, dtype=np.uint32), ("face", "corner")),
    }
    _write_group(path / "mesh", {})
    for name, (values, dimensions) in arrays.items():
        _build_folder_into_place(path / name, functools.partial(_array_of, values=values, dimensions=dimensions),
                                 replace=True)


def _damaged_shared_arrays(path: Path, settings: dict[str, Any]) -> tuple[str, ...]:
    """Why the arrays every block shares do not hold what `settings` record (one reason per array, naming its
    file): `source` and `target` the sources and targets (every vertex without targets), mesh/vertices and
    mesh/faces the mesh whose sha256 they record."""
    targets = settings["targets"] if settings["targets"] is not None else np.arange(settings["vertex_count"])
    damaged = []
    for name, expected in (("source", settings["sources"]), ("target", targets)):
        try:
            if not np.array_equal(_whole_array(path / name, "int64", 1), np.asarray(expected, dtype=np.int64)):
                damaged.append(f"{path / name} does not hold the {name}s its store's zarr.json records")
        except ValueError as error:
            damaged.append(str(error))
    try:
        group = _read_json(path / "mesh" / "zarr.json")
        if group.get("zarr_format") != ZARR_FORMAT or group.get("node_type") != "group":
            raise ValueError(f"{path / 'mesh' / 'zarr.json'} is not the metadata of a Zarr format 3 group")
        vertices = _whole_array(path / "mesh" / "vertices", "float64", 2)
        faces = _whole_array(path / "mesh" / "faces", "uint32", 2)
    except ValueError as error:
        return (*damaged, str(error))
    if vertices.shape != (settings["vertex_count"], 3) or faces.shape != (settings["face_count"], 3) or \
            _mesh_digest(vertices, faces, settings["weld_duplicate_positions"]) != settings["mesh_sha256"]:
        damaged.append(f"{path / 'mesh'} does not hold the mesh whose sha256 its store's zarr.json records")
    return tuple(damaged)


# Verification reads what was written as the bytes it is, without zarr: the metadata must be the layout this module
# and the command write (uncompressed; a small array in one chunk, the dense matrix in one chunk per block), so that
# both verifiers hash the same bytes, and a store of many blocks is read at the speed of its files.

_RAW_CODECS = [{"name": "bytes", "configuration": {"endian": "little"}}]


def _read_json(path: Path) -> dict[str, Any]:
    """The JSON object in `path`; ValueError naming the file otherwise."""
    try:
        with open(path, "rb") as file:
            document = json.load(file)
    except (OSError, ValueError) as error:
        raise ValueError(f"{path} cannot be read: {error}") from None
    if not isinstance(document, dict):
        raise ValueError(f"{path} holds a JSON {type(document).__name__}, not an object")
    return document


def _check_layout(folder: Path, shape: Sequence[int], chunks: Sequence[int], data_type: str, fill_value: Any) -> None:
    """ValueError naming the first thing in the array metadata of `folder` that is not what an uncompressed array of
    this shape, chunks, data type and fill value has."""
    metadata_path = folder / "zarr.json"
    metadata = _read_json(metadata_path)
    codecs = metadata.get("codecs")
    if codecs != _RAW_CODECS:
        names = ", ".join(str(codec.get("name")) for codec in codecs or [] if isinstance(codec, dict))
        raise ValueError(f"{folder} stores its chunks with codecs [{names}]; blocks are written and read "
                         "uncompressed (codecs [bytes], little-endian)")
    expected = {"zarr_format": ZARR_FORMAT, "node_type": "array", "shape": list(shape), "data_type": data_type,
                "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": list(chunks)}},
                "chunk_key_encoding": {"name": "default", "configuration": {"separator": "/"}},
                "fill_value": fill_value}
    for key, value in expected.items():
        if metadata.get(key) != value:
            raise ValueError(f"{metadata_path}: its {key} is {metadata.get(key)!r}, not {value!r}")


def _whole_array(folder: Path, data_type: str, rank: int) -> np.ndarray:
    """The array in `folder` of `data_type` and `rank` dimensions, stored in one chunk as _array_of (and the
    command) write it, whatever its shape; ValueError naming the file otherwise. Zarr leaves out a chunk holding
    the fill value (0) alone: an absent chunk reads as zeros."""
    shape = _read_json(folder / "zarr.json").get("shape")
    if not isinstance(shape, list) or len(shape) != rank or \
            not all(isinstance(size, int) and not isinstance(size, bool) and size >= 0 for size in shape):
        raise ValueError(f"{folder / 'zarr.json'}: its shape is {shape!r}, not {rank} sizes")
    _check_layout(folder, shape, [max(1, size) for size in shape], data_type, 0)
    dtype = np.dtype(data_type).newbyteorder("<")
    chunk = folder / "c" / Path(*["0"] * rank)
    if not chunk.exists():
        return np.zeros(shape, dtype=dtype)
    data = _read_bytes(chunk)
    if len(data) != dtype.itemsize * math.prod(shape):
        raise ValueError(f"{chunk} has {len(data)} bytes, not {dtype.itemsize * math.prod(shape)}")
    return np.frombuffer(data, dtype=dtype).reshape(shape)


def _read_bytes(path: Path) -> bytes:
    try:
        return path.read_bytes()
    except OSError as error:
        raise ValueError(f"{path} cannot be read: {error}") from None


def _check_chunk_layout(path: Path, settings: dict[str, Any]) -> None:
    """Blocks write their chunk files themselves (_write_chunk) and verification reads them so: `distances` must be
    the array this module and the command make, (sources, targets) of the settings' dtype in chunks of block_rows
    rows, NaN where no block was written, uncompressed. ValueError naming what differs otherwise."""
    rows, width = settings["shape"]
    try:
        _check_layout(path / "distances", (rows, width), (settings["block_rows"], max(1, width)), settings["dtype"],
                      "NaN")
    except ValueError as error:
        raise ValueError(f"{error}: choose another store, or resume=False to replace this one") from None


def _default_block_rows(rows: int, width: int, itemsize: int) -> int:
    """At most 32 MiB a chunk, at most 4096 rows, and some 32 blocks or more when there are enough rows."""
    budget = (32 << 20) // max(1, width * itemsize)
    return max(1, min(math.ceil(rows / 32), budget, 4096))


# The work of one block, on a worker.


@dataclasses.dataclass
class _Context:
    """What every block needs besides its rows: sent to each Dask worker once (scatter, broadcast)."""

    mesh: Mesh
    targets: np.ndarray | None


@dataclasses.dataclass(frozen=True)
class _StoreReference:
    """Stands for a _Context on executors: each process reads the mesh (once per mesh) and the targets (once
    per run) from the store."""

    path: str
    mesh_sha256: str
    has_targets: bool
    run: str  # tells runs apart: a store replaced (resume=False) may keep its path and mesh


_meshes: dict[str, Mesh] = {}  # per process: mesh hash -> the mesh, the last one only
_contexts: dict[_StoreReference, _Context] = {}  # per process: the last run's context


def _context_of(context: _Context | _StoreReference) -> _Context:
    if isinstance(context, _Context):
        return context
    if context not in _contexts:
        path = Path(context.path)
        settings = _open_group(path, "r").attrs["exactgeo"]
        if context.mesh_sha256 not in _meshes:
            try:
                vertices, faces = (_open_array(path / "mesh" / name)[...] for name in ("vertices", "faces"))
            except Exception as error:  # zarr's own errors do not name the file
                raise ValueError(f"the mesh stored in {path / 'mesh'} cannot be read: {error}") from None
            mesh = Mesh(vertices, faces, weld_duplicate_positions=bool(settings["weld_duplicate_positions"]))
            if mesh_hash(mesh) != context.mesh_sha256:
                raise ValueError(f"the mesh stored in {path} is not the one of this run (its sha256 differs)")
            _meshes.clear()
            _meshes[context.mesh_sha256] = mesh
        # From the attribute the driver checked against this run's targets, not the `target` array, which
        # nothing checks.
        targets = np.asarray(settings["targets"], dtype=np.int64) if context.has_targets else None
        _contexts.clear()
        _contexts[context] = _Context(_meshes[context.mesh_sha256], targets)
    return _contexts[context]


def _compute_block(context: _Context | _StoreReference, store: str, block: int, rows: tuple[int, int],
                   sources: np.ndarray, options: dict[str, Any]) -> dict[str, Any]:
    """Computes rows [rows[0], rows[1]) (block `block`), writes them into the store, then the block's marker."""
    from ._many_sources import distance_matrix, fill_distance_matrix

    started = time.perf_counter()
    path = Path(store)
    context = _context_of(context)
    _remove_marker(path, block)
    dtype = np.dtype(options["dtype"])
    max_distance = options["max_distance"]
    digest = hashlib.sha256()
    record: dict[str, Any] = {"block": block, "rows": list(rows), "max_distance": max_distance}
    if max_distance is None:
        # The block's chunk is the only copy of its rows: computed into it a few rows at a time (float32 rounded
        # from each float64 distance as it comes), then written from its own memory. The last block's chunk is
        # padded with the fill value, as Zarr stores a chunk at the array's edge.
        width = context.mesh.vertex_count if context.targets is None else len(context.targets)
        chunk = np.empty((options["block_rows"], width), dtype=dtype)
        values = chunk[:rows[1] - rows[0]]
        chunk[len(values):] = np.nan
        fill_distance_matrix(values, context.mesh, sources, targets=context.targets, threads=options["threads"])
        little_endian = chunk.astype(dtype.newbyteorder("<"), copy=False)  # no copy on little-endian hosts
        _write_chunk(path, block, little_endian)
        digest.update(little_endian[:len(values)].data)
    else:
        matrix = distance_matrix(context.mesh, sources, targets=context.targets, max_distance=max_distance,
                                 threads=options["threads"])
        pieces = {"data": np.ascontiguousarray(matrix.data.astype(dtype, copy=False)),
                  "indices": np.ascontiguousarray(matrix.indices.astype(np.uint32, copy=False)),
                  "indptr": np.ascontiguousarray(matrix.indptr.astype(np.int64, copy=False))}
        for values in pieces.values():
            digest.update(values.data)

        def build(folder: Path) -> None:
            _open_group(folder, "w")
            for name, values in pieces.items():
                _array_of(folder / name, values, (name,))

        # Built whole beside its place, then renamed into it: csr/block_NNNNNN, once there, is complete. Pieces
        # already there (an earlier attempt stopped before its marker, or pieces that failed verification) are
        # replaced: the marker that follows vouches for these bytes only.
        _build_folder_into_place(path / "csr" / _block_name(block), build, replace=True)
        record["nnz"] = int(len(pieces["data"]))
    record["sha256"] = digest.hexdigest()
    record["seconds"] = time.perf_counter() - started
    _write_marker(path, block, record)
    return record


def _write_chunk(path: Path, block: int, chunk: np.ndarray) -> None:
    """Block `block`'s chunk of `distances` (chunk (block, 0), key c/block/0), written beside its place and
    renamed into it."""
    folder = path / "distances" / "c" / str(block)
    folder.mkdir(parents=True, exist_ok=True)
    _write_atomically(folder / "0", chunk)


# The driver.


def _vertices(values: object, mesh: Mesh, what: str) -> np.ndarray:
    array = _inputs.vertex_array(values, mesh.vertex_count, what, lambda i: f"{what}: vertex").astype(np.int64)
    if array.size and array.max() >= mesh.vertex_count:
        raise ValueError(f"{what}: vertex {int(array.max())} is out of range (mesh has {mesh.vertex_count} vertices)")
    return array


def _dtype_name(dtype: DTypeLike) -> str:
    """"float32" or "float64", from their names or numpy's types; ValueError naming what was given otherwise."""
    try:
        name = str(np.dtype(dtype)) if dtype is not None else None
    except TypeError:
        name = None
    if name not in DTYPES:
        raise ValueError(f"dtype must be float32 or float64, not {dtype!r}")
    return name


def _store_path(store: object) -> Path:
    return Path(os.fsdecode(_inputs.path(store, "store"))).absolute()


def distance_matrix_to_zarr(
    mesh: Mesh,
    sources: object,
    store: StorePath,
    *,
    targets: object = None,
    max_distance: float | None = None,
    dtype: DTypeLike = "float32",
    block_rows: int | None = None,
    client: Any = None,
    resume: bool = True,
    progress: Progress = False,
    threads: int = 1,
    retries: int = 2,
    verify: bool = False,
) -> MatrixRun:
    """exactgeo.distance_matrix(mesh, sources, targets=..., max_distance=...) into the Zarr store `store` (a
    folder), computed block by block on Dask workers, each block written by its worker.

    Rows go in blocks of `block_rows` (default: 32 MiB a chunk, at most 4096 rows, at least some 32 blocks;
    an existing store's value when resuming); the dense array's chunks are exactly the blocks, so workers
    never write the same chunk. `dtype`: "float32" (the float64 distances rounded) or "float64" (bit for bit
    distance_matrix's values); inf stays inf. With `max_distance`, each block is stored as CSR pieces
    instead (read them with read_sparse).

    `client`: None starts a LocalCluster on 127.0.0.1 (one single-threaded worker process per core) and
    closes it afterwards; a dask.distributed Client is used as it is (tasks retried `retries` times after
    a Python exception; a dead worker's tasks are rerun by Dask); any concurrent.futures.Executor too
    (ProcessPoolExecutor, mpi4py's MPIPoolExecutor), where each process reads the mesh from the store
    once. `threads`: threads of distance_matrix within a block (0: one per core).

    `resume=True` keeps the blocks marked done in an existing store made for the same mesh, sources,
    targets, dtype and max_distance (ValueError naming what differs otherwise) and computes the others;
    `resume=False` replaces an existing exactgeo store. A path holding anything else raises ValueError.
    `verify=True` reads the done blocks first and computes again those whose data does not match the sha256
    their marker recorded, and writes the source, target and mesh arrays again if they do not hold what the
    store's settings record. `progress`: True for a tqdm bar, or a function called with (rows done, rows).
    Returns a MatrixRun.
    """
    _zarr()
    mesh = checked_mesh(mesh)
    source_array = _vertices(sources, mesh, "sources")
    target_array = None if targets is None else _vertices(targets, mesh, "targets")
    dtype = _dtype_name(dtype)
    cutoff = None if max_distance is None else _inputs.cutoff(max_distance)
    if cutoff is not None and not (0 <= cutoff < math.inf):
        raise ValueError(f"max_distance must be a finite number of at least 0, not {max_distance!r}")
    threads = _inputs.count(threads, "threads")
    retries = _inputs.count(retries, "retries")
    resume = _inputs.flag(resume, "resume")
    verify = _inputs.flag(verify, "verify")
    progress = checked_progress(progress)
    _check_client(client)
    width = mesh.vertex_count if target_array is None else len(target_array)
    path = _store_path(store)
    stored = _stored_settings(path)
    if block_rows is None:
        rows_per_block = stored["block_rows"] if stored and resume else _default_block_rows(
            len(source_array), width, np.dtype(dtype).itemsize)
    else:
        rows_per_block = _inputs.count(block_rows, "block_rows", minimum=1)
    from . import __version__

    settings = {
        "format": FORMAT,
        "version": __version__,
        "mesh_sha256": mesh_hash(mesh),
        "vertex_count": mesh.vertex_count,
        "face_count": mesh.face_count,
        "weld_duplicate_positions": bool(mesh._weld),
        "sources": source_array.tolist(),
        "targets": None if target_array is None else target_array.tolist(),
        "shape": [len(source_array), width],
        "dtype": dtype,
        "max_distance": cutoff,
        "layout": "dense" if cutoff is None else "sparse",
        "block_rows": rows_per_block,
        "blocks": math.ceil(len(source_array) / rows_per_block),
        "zarr_format": ZARR_FORMAT,
    }
    if stored is not None and not resume:
        shutil.rmtree(path)
        stored = None
    if stored is None:
        path.parent.mkdir(parents=True, exist_ok=True)
        if not _build_folder_into_place(path, lambda building: _create_store(building, settings, mesh, source_array,
                                                                             target_array)):
            stored = _stored_settings(path)  # another driver made it first: joined below if it is for this matrix
    if stored is not None:
        differences = _differences(stored, settings, block_rows is not None)
        if differences:
            raise ValueError(f"the store {path} was made for " + "; ".join(differences) +
                             ". Use another store, or resume=False to replace this one.")
        if cutoff is None:
            _check_chunk_layout(path, stored)
    blocks = settings["blocks"]
    for leftover in (path / "csr").glob(".block_*.tmp") if cutoff is not None else ():
        shutil.rmtree(leftover, ignore_errors=True)  # pieces of attempts that died before their rename
    done = _done_blocks(path, blocks)
    if verify:
        if stored is not None and _damaged_shared_arrays(path, stored):
            _write_shared_arrays(path, mesh, source_array, target_array)  # the mesh and axes the settings record
        for block in [b for b in done if not _block_intact(path, settings, b)]:
            _remove_marker(path, block)  # computed again below
            done.remove(block)
    todo = sorted(set(range(blocks)) - set(done))
    options = {"dtype": settings["dtype"], "max_distance": cutoff, "threads": threads, "block_rows": rows_per_block}
    tasks = {b: (str(path), b, (b * rows_per_block, min((b + 1) * rows_per_block, len(source_array))),
                 source_array[b * rows_per_block:(b + 1) * rows_per_block], options) for b in todo}

    reporter = Reporter(progress, "rows")
    rows_total = len(source_array)
    rows_done = rows_total - sum(t[2][1] - t[2][0] for t in tasks.values())
    if reporter.active:
        reporter(rows_done, rows_total)

    def finished(block: int) -> None:
        nonlocal rows_done
        rows_done += tasks[block][2][1] - tasks[block][2][0]
        if reporter.active:
            reporter(rows_done, rows_total)

    try:
        if tasks:
            context = _Context(mesh, target_array)
            reference = _StoreReference(str(path), settings["mesh_sha256"], target_array is not None, uuid.uuid4().hex)
            _run(client, tasks, context, reference, retries, finished)
    except BaseException:
        reporter.abandon()
        raise
    if reporter.active:
        reporter.finish(rows_total)
    return MatrixRun(str(path), blocks, tuple(sorted(todo)), tuple(done))


def _dask_client_type() -> type | None:
    try:
        from distributed import Client
    except ImportError:
        return None
    return Client


# Dask's housekeeping is tuned for interactive work: every worker ticks its event loop every 20 ms, samples its
# threads' stacks every 10 ms for the profiler and checks its memory every 100 ms. Beside blocks that keep
# every core busy for seconds, that took about 4% of the CPU time on 2 cores (the workers' main threads:
# 0.13 s each in 6 s, 650 wake-ups), and each wake-up preempts a block. The cluster exactgeo starts checks
# once a second and does not profile (0.02 s, 30 wake-ups).
_UNHURRIED_HOUSEKEEPING = {
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "1s",
    "distributed.admin.system-monitor.gil.enabled": False,
    "distributed.worker.profile.enabled": False,
    "distributed.worker.memory.monitor-interval": "1s",
}


def local_cluster(workers: int | None = None) -> Any:
    """The LocalCluster distance_matrix_to_zarr starts when given no client: `workers` single-threaded worker
    processes (default: one per core) on 127.0.0.1, no dashboard, Dask's housekeeping slowed to once a second
    so that it takes little from the blocks. Use it as a context manager, with a Client on it, to run several
    matrices on one cluster:

        with distributed.local_cluster() as cluster, dask.distributed.Client(cluster) as client:
            distributed.distance_matrix_to_zarr(mesh, sources, "d.zarr", client=client)
    """
    try:
        import dask
        from distributed import LocalCluster
    except ImportError:
        raise ImportError(_MISSING_EXTRA) from None
    count = _inputs.count((os.cpu_count() or 1) if workers is None else workers, "workers", minimum=1)
    # The scheduler takes the configuration set while it starts. The nannies hand `config` to every worker
    # process they start, a worker restarted after a crash included, which sets it key by key (dotted keys: a
    # nested dictionary would replace whole sections). No dashboard; the scheduler's HTTP server (health
    # checks) on a free loopback port, not 8787.
    with dask.config.set(_UNHURRIED_HOUSEKEEPING):
        return LocalCluster(n_workers=count, threads_per_worker=1, processes=True, host="127.0.0.1",
                            dashboard_address="127.0.0.1:0", scheduler_kwargs={"dashboard": False},
                            config=_UNHURRIED_HOUSEKEEPING)


def _is_dask_client(client: Any) -> bool:
    client_type = _dask_client_type()
    return client_type is not None and isinstance(client, client_type)


def _check_client(client: Any) -> None:
    """Before the store is touched: a client that cannot run the blocks leaves it as it was."""
    if client is not None and not _is_dask_client(client) and not isinstance(client, concurrent.futures.Executor):
        raise TypeError(f"client must be None, a dask.distributed Client or a concurrent.futures.Executor, "
                        f"not {type(client).__name__}")


def _run(client: Any, tasks: _Tasks, context: _Context, reference: _StoreReference, retries: int,
         finished: _Finished) -> None:
    if client is None:
        try:
            from distributed import Client
        except ImportError:
            raise ImportError(_MISSING_EXTRA) from None
        with local_cluster() as cluster, Client(cluster) as own:
            _run_dask(own, tasks, context, retries, finished)
    elif _is_dask_client(client):
        _run_dask(client, tasks, context, retries, finished)
    else:
        _run_executor(client, tasks, reference, retries, finished)


def _run_dask(client: Any, tasks: _Tasks, context: _Context, retries: int, finished: _Finished) -> None:
    from distributed import as_completed

    shared = client.scatter(context, broadcast=True, hash=False)  # the mesh goes to each worker once
    run = uuid.uuid4().hex[:8]
    futures = {}
    for block, arguments in tasks.items():
        future = client.submit(_compute_block, shared, *arguments, key=f"exactgeo-block-{run}-{block}",
                               retries=retries, pure=False)
        futures[future] = block
    try:
        for future in as_completed(list(futures)):
            future.result()  # raises the block's error once its retries are spent
            finished(futures[future])
    except BaseException:
        client.cancel(list(futures))
        raise


def _run_executor(executor: concurrent.futures.Executor, tasks: _Tasks, reference: _StoreReference, retries: int,
                  finished: _Finished) -> None:
    attempts = {block: 0 for block in tasks}
    pending = {executor.submit(_compute_block, reference, *arguments): block for block, arguments in tasks.items()}
    try:
        while pending:
            complete, _ = concurrent.futures.wait(pending, return_when=concurrent.futures.FIRST_COMPLETED)
            for future in complete:
                block = pending.pop(future)
                error = future.exception()
                if error is None:
                    finished(block)
                elif isinstance(error, concurrent.futures.BrokenExecutor) or attempts[block] >= retries:
                    raise error
                else:
                    attempts[block] += 1
                    pending[executor.submit(_compute_block, reference, *tasks[block])] = block
    except BaseException:
        for future in pending:
            future.cancel()
        raise


# Reading a store.


def store_status(store: StorePath, *, verify: bool = False) -> StoreStatus:
    """Which blocks of the store are done and which are missing (a run with resume=True computes those).
    `verify=True` also reads each done block's data and checks it against the sha256 its marker recorded:
    blocks that differ are `corrupt` and counted as missing (a run with verify=True computes them again); and
    the source, target and mesh arrays against the settings: those that differ are `damaged` (a run with
    verify=True writes them again). ValueError if `store` is not an exactgeo distance matrix store, or
    (verifying) if its distances array is not stored as blocks are written."""
    path = _store_path(store)
    verify = _inputs.flag(verify, "verify")
    settings = _stored_settings(path)
    if settings is None:
        raise ValueError(f"{path} holds no exactgeo distance matrix store")
    if verify and settings["max_distance"] is None:
        _check_chunk_layout(path, settings)
    done = _done_blocks(path, settings["blocks"])
    corrupt = tuple(b for b in done if not _block_intact(path, settings, b)) if verify else ()
    damaged = _damaged_shared_arrays(path, settings) if verify else ()
    done = [b for b in done if b not in corrupt]
    missing = tuple(sorted(set(range(settings["blocks"])) - set(done)))
    return StoreStatus(str(path), settings["layout"], tuple(settings["shape"]), settings["dtype"],
                       settings["block_rows"], settings["blocks"], tuple(done), missing, corrupt, damaged)


def _marker_record(path: Path, block: int) -> object:
    try:
        with open(path / "done" / _block_name(block) / "zarr.json") as file:
            return json.load(file).get("attributes")
    except (OSError, ValueError):
        return None


def _block_intact(path: Path, settings: dict[str, Any], block: int) -> bool:
    """The block's marker records its rows and the store's max_distance (which no other file repeats), and its data
    hashes to the sha256 the marker recorded."""
    record = _marker_record(path, block)
    start = block * settings["block_rows"]
    stop = min(start + settings["block_rows"], settings["shape"][0])
    if not isinstance(record, dict) or "sha256" not in record or record.get("rows") != [start, stop] or \
            record.get("max_distance", "none recorded") != settings["max_distance"]:
        return False
    digest = hashlib.sha256()
    try:
        if settings["max_distance"] is None:  # the layout was checked: the chunk is block_rows rows, raw
            row_bytes = settings["shape"][1] * np.dtype(settings["dtype"]).itemsize
            chunk = _read_bytes(path / "distances" / "c" / str(block) / "0")
            if len(chunk) != settings["block_rows"] * row_bytes:
                return False
            digest.update(chunk[:(stop - start) * row_bytes])
        else:
            group = path / "csr" / _block_name(block)
            for name, data_type in (("data", settings["dtype"]), ("indices", "uint32"), ("indptr", "int64")):
                digest.update(_whole_array(group / name, data_type, 1).tobytes())
    except ValueError:  # a chunk or piece that cannot be read as it was written is not intact either
        return False
    recorded: object = record["sha256"]
    return digest.hexdigest() == recorded


def read_sparse(store: StorePath, rows: slice | range | None = None) -> Any:
    """The sparse matrix of a store made with max_distance, as a scipy.sparse.csr_array: all rows, or
    `rows` (a slice or range with step 1), reading only the blocks that hold them. ValueError naming the
    blocks not done if some are needed."""
    import scipy.sparse

    status = store_status(store)
    path = Path(status.store)
    if status.layout != "sparse":
        raise ValueError(f"{path} holds a dense matrix (no max_distance): read its 'distances' array with zarr")
    total, width = status.shape
    if rows is None:
        start, stop = 0, total
    else:
        if isinstance(rows, range):
            rows = slice(rows.start, rows.stop, rows.step)
        if not isinstance(rows, slice):
            raise TypeError(f"rows must be a slice or a range, not {type(rows).__name__}")
        start, stop, step = rows.indices(total)
        if step != 1:
            raise ValueError(f"rows must be consecutive (step 1), not {rows!r}")
        stop = max(start, stop)
    first, last = start // status.block_rows, (stop - 1) // status.block_rows if stop > start else -1
    needed = range(first, last + 1)
    missing = [b for b in needed if b in set(status.missing)]
    if missing:
        raise ValueError(f"{path}: blocks {missing} are not done (rows {start} to {stop}); run "
                         "distance_matrix_to_zarr again with resume=True")
    data, indices, indptr = [], [], [np.zeros(1, dtype=np.int64)]
    offset = 0
    for block in needed:
        group = path / "csr" / _block_name(block)
        piece_ptr = np.asarray(_open_array(group / "indptr")[...], dtype=np.int64)
        low = max(start, block * status.block_rows) - block * status.block_rows
        high = min(stop, (block + 1) * status.block_rows) - block * status.block_rows
        a, b = int(piece_ptr[low]), int(piece_ptr[high])
        nnz_data = _open_array(group / "data")
        nnz_indices = _open_array(group / "indices")
        data.append(np.asarray(nnz_data[a:b]) if b > a else np.zeros(0, dtype=status.dtype))
        indices.append(np.asarray(nnz_indices[a:b]) if b > a else np.zeros(0, dtype=np.uint32))
        indptr.append(piece_ptr[low + 1:high + 1] - a + offset)
        offset += b - a
    values = np.concatenate(data).astype(status.dtype, copy=False)
    columns = np.concatenate(indices).astype(np.int64)
    return scipy.sparse.csr_array((values, columns, np.concatenate(indptr)), shape=(stop - start, width))

__all__ = [
    "MatrixRun", "StoreStatus", "distance_matrix_to_zarr", "local_cluster", "mesh_hash", "read_sparse", "store_status"
]
