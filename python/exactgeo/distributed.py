"""Distance matrices larger than one machine: rows computed in blocks on Dask workers (or any
concurrent.futures executor), each block written by its worker straight into a Zarr store.

    from exactgeo import distributed
    run = distributed.distance_matrix_to_zarr(mesh, sources, "d.zarr")   # a LocalCluster on every core
    distributed.store_status("d.zarr").complete                          # True
    zarr.open_array("d.zarr/distances")[:]                                # or dask.array.from_zarr

An optional extra (dask[distributed] and zarr: pip install 'dask[distributed]>=2023.1' 'zarr>=3'); `import exactgeo`
does not import it, and this module imports dask and zarr only when a function needs them. It needs zarr-python 3 (Zarr
format v3). See docs/distributed.md.

The store is a folder every worker can write to (a local disk for a LocalCluster, a shared filesystem for a
cluster). Its layout (docs/distributed.md, "The store") is written and read by one component, store/
(store/matrix_store.hpp), through exactgeo._core's store_* functions; the command `exactgeo matrix --out STORE
--shard I/N` calls the same component, so either can continue a store the other began. This module keeps the
scheduling (Dask or executors, retries, progress; _scheduling.py) and the computing of each block.

A block counts as done only through its marker, written after its data: an interrupted or killed run leaves at
most blocks without markers, which the next run with resume=True computes again, replacing whatever data they
left. verify=True (and `exactgeo matrix --verify`) checks the done blocks' data against the sha256 their markers
recorded, and the source, target and mesh arrays against the settings; a run with verify=True computes those
blocks and writes those arrays again.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import time
import uuid
from pathlib import Path
from typing import TYPE_CHECKING, Any, Union

import numpy as np

from . import _core, _inputs, _scheduling
from ._mesh import Mesh, checked_mesh
from ._progress import Progress, Reporter, checked as checked_progress
from ._scheduling import local_cluster

if TYPE_CHECKING:
    from numpy.typing import DTypeLike

DTYPES = ("float32", "float64")
StorePath = Union[str, "os.PathLike[str]"]


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
        return _block_rows(block, self.block_rows, self.shape[0])


def _block_rows(block: int, block_rows: int, rows: int) -> range:
    """The rows of `block` in a matrix of `rows` rows cut into blocks of `block_rows` (the last one shorter)."""
    start = block * block_rows
    return range(start, min(start + block_rows, rows))


# The optional extra: zarr is what readers open the stores with (the store component writes them itself).


def _zarr() -> Any:
    try:
        import zarr
    except ImportError:
        raise ImportError(_scheduling.MISSING_EXTRA) from None
    if int(zarr.__version__.split(".")[0]) < 3:
        raise ImportError(f"exactgeo.distributed needs zarr-python 3 or newer (Python 3.11+), not {zarr.__version__}: "
                          "pip install 'zarr>=3'")
    return zarr


# The store, through the store component in exactgeo._core.


def _mesh_arrays(mesh: Mesh) -> tuple[np.ndarray, np.ndarray, bool]:
    """The mesh as the store hashes and keeps it: vertices as float64, faces as uint32, C order; its welding."""
    return (np.ascontiguousarray(mesh.vertices, dtype=np.float64), np.ascontiguousarray(mesh.faces, dtype=np.uint32),
            bool(mesh._weld))


def mesh_hash(mesh: Mesh) -> str:
    """sha256 (hex) of the mesh's input: vertex and face counts, welding, vertices as float64 and faces as
    uint32, in C order. Equal meshes have equal hashes; stores record it."""
    return str(_core.store_mesh_sha256(*_mesh_arrays(checked_mesh(mesh))))


def _stored_settings(path: Path) -> dict[str, Any] | None:
    """The store's "exactgeo" attribute, None if there is no store at `path`; ValueError if `path` holds
    something else, or a store in Zarr format 2."""
    stored = _core.store_settings(str(path))
    if stored is None:
        return None
    settings, zarr_format = stored
    if zarr_format != 3:
        raise ValueError(f"{path} is a Zarr format {zarr_format} store: exactgeo.distributed reads and writes format 3 "
                         "only (zarr-python 3); choose another store (nothing was changed)")
    result: dict[str, Any] = json.loads(settings)
    return result


def _read_sparse_block(path: Path, block: int, dtype: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    data, indices, indptr = _core.store_read_sparse_block(str(path), block)
    return (np.frombuffer(data, dtype=np.dtype(dtype).newbyteorder("<")), np.frombuffer(indices, dtype="<u4"),
            np.frombuffer(indptr, dtype="<i8"))


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
        settings = _stored_settings(path)
        if settings is None:
            raise ValueError(f"{path} holds no exactgeo distance matrix store")
        if context.mesh_sha256 not in _meshes:
            vertices, faces, weld = _core.store_read_mesh(str(path))  # checked against the store's hash
            mesh = Mesh(vertices, faces, weld_duplicate_positions=weld)
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
                   sources: np.ndarray, options: dict[str, Any]) -> None:
    """Computes rows [rows[0], rows[1]) (block `block`) and writes them into the store, then the block's marker."""
    from ._many_sources import distance_matrix, fill_distance_matrix

    started = time.perf_counter()
    context = _context_of(context)
    dtype = np.dtype(options["dtype"]).newbyteorder("<")
    max_distance = options["max_distance"]
    if max_distance is None:
        # The block's chunk is the only copy of its rows: computed into it a few rows at a time (float32 rounded
        # from each float64 distance as it comes), then written from its own memory. The last block's chunk is
        # padded with the fill value, as Zarr stores a chunk at the array's edge.
        width = context.mesh.vertex_count if context.targets is None else len(context.targets)
        chunk = np.empty((options["block_rows"], width), dtype=dtype)
        values = chunk[:rows[1] - rows[0]]
        chunk[len(values):] = np.nan
        fill_distance_matrix(values, context.mesh, sources, targets=context.targets, threads=options["threads"])
        _core.store_write_dense_block(store, block, rows[0], rows[1], chunk, time.perf_counter() - started)
    else:
        matrix = distance_matrix(context.mesh, sources, targets=context.targets, max_distance=max_distance,
                                 threads=options["threads"])
        _core.store_write_sparse_block(store, block, rows[0], rows[1], max_distance,
                                       np.ascontiguousarray(matrix.data.astype(dtype, copy=False)),
                                       np.ascontiguousarray(matrix.indices.astype(np.uint32, copy=False)),
                                       np.ascontiguousarray(matrix.indptr.astype(np.int64, copy=False)),
                                       time.perf_counter() - started)


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
    _scheduling.check_client(client)
    path = _store_path(store)
    stored = _stored_settings(path)  # a Zarr format 2 store is refused before anything is replaced
    rows_per_block = 0 if block_rows is None else _inputs.count(block_rows, "block_rows", minimum=1)
    targets_u32 = None if target_array is None else target_array.astype(np.uint32)
    text, done, _, _ = _core.store_open(str(path), *_mesh_arrays(mesh), source_array.astype(np.uint32), targets_u32,
                                        dtype, cutoff, rows_per_block, stored is not None and not resume, verify)
    settings = json.loads(text)
    if cutoff is not None:
        _core.store_remove_unfinished_pieces(str(path))  # pieces of attempts that died before their rename
    blocks, rows_per_block = settings["blocks"], settings["block_rows"]
    todo = sorted(set(range(blocks)) - set(done))
    options = {"dtype": dtype, "max_distance": cutoff, "threads": threads, "block_rows": rows_per_block}
    ranges = {b: _block_rows(b, rows_per_block, len(source_array)) for b in todo}
    tasks = {b: (str(path), b, (r.start, r.stop), source_array[r.start:r.stop], options) for b, r in ranges.items()}

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
            _scheduling.run(client, _compute_block, tasks, context, reference, retries, finished)
    except BaseException:
        reporter.abandon()
        raise
    if reporter.active:
        reporter.finish(rows_total)
    return MatrixRun(str(path), blocks, tuple(todo), tuple(done))


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
    if _stored_settings(path) is None:
        raise ValueError(f"{path} holds no exactgeo distance matrix store")
    text, _, done, missing, corrupt, damaged = _core.store_status(str(path), verify)
    settings = json.loads(text)
    return StoreStatus(str(path), settings["layout"], tuple(settings["shape"]), settings["dtype"],
                       settings["block_rows"], settings["blocks"], tuple(done), tuple(missing),
                       tuple(block for block, _ in corrupt), tuple(damaged))


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
        piece_data, piece_indices, piece_ptr = _read_sparse_block(path, block, status.dtype)
        block_range = status.rows(block)
        low, high = max(start, block_range.start) - block_range.start, min(stop, block_range.stop) - block_range.start
        a, b = int(piece_ptr[low]), int(piece_ptr[high])
        data.append(piece_data[a:b])
        indices.append(piece_indices[a:b])
        indptr.append(piece_ptr[low + 1:high + 1] - a + offset)
        offset += b - a
    values = np.concatenate(data).astype(status.dtype, copy=False)
    columns = np.concatenate(indices).astype(np.int64)
    return scipy.sparse.csr_array((values, columns, np.concatenate(indptr)), shape=(stop - start, width))

__all__ = [
    "MatrixRun", "StoreStatus", "distance_matrix_to_zarr", "local_cluster", "mesh_hash", "read_sparse", "store_status"
]
