"""Distance matrices on Dask workers into Zarr stores (exactgeo.distributed): one local worker against two, the
scheduler's overhead per block, the workers' peak memory, the time and size of nefertiti's all-pairs float32
store, and what a 160K-vertex all-pairs would take on 64 and 512 cores. Writes bench/results/distributed.{json,md}.
(Not named distributed.py: run from bench/, that would hide the dask package of the same name.)

usage: python3 bench/distributed_matrix.py [--quick] [--runs 3] [--name distributed]
       python3 bench/distributed_matrix.py --memory-only [--memory-blocks 4] [--runs 3]
       python3 bench/distributed_matrix.py --nefertiti-all-pairs STORE [--workers 2]

Measured, in this process:
- workloads: all-pairs on --all-pairs-mesh (every vertex a face uses, as source and as target; by default
  homer-sub1, homer 1-to-4 subdivided once: 24,002 vertices, the closed, well-shaped surface nearest the ~16K
  vertices asked for among the shared meshes and their subdivisions; cow-sub1, 11,609 vertices, is the one
  just below, a fifth of the work) and --sources seeded sources on nefertiti, each into a fresh float32 store
  with the library's default blocks, on a
  LocalCluster of 1 and of 2 single-threaded worker processes (a fresh cluster for each run, its start not
  timed), and in-process exactgeo.distance_matrix on 1 and 2 threads; the four configurations taken in turn,
  --runs times, medians reported;
- overhead per block: (wall time x workers - the sum of the blocks' own seconds, from their markers) / blocks,
  for every Dask run above and for blocks of one row on a 128-vertex torus (trivial work);
- peak memory per worker: each worker process's peak RSS during the run (VmHWM, reset once the worker has
  exactgeo, numpy, zarr and dask imported and has written a tiny store of its own, so that what a first write
  imports or sets up once is in it), less its RSS at that point (the baseline, reported too), against one
  block's float32 bytes plus the mesh's bytes (its arrays and the RSS that building the Mesh adds to a fresh
  process), with the engine's working memory beside them (the RSS one row of distance_matrix adds to a fresh
  process holding the mesh: the solver's buffers and windows). --memory-only measures this alone, on the
  first --memory-blocks blocks of each workload's layout (a worker's peak comes with its first blocks), and
  writes results/distributed-memory.{json,md};
- nefertiti all-pairs: the first --subset-blocks blocks of the all-pairs store's layout on 2 workers; time and
  size (du) of the whole store extrapolated from them. --nefertiti-all-pairs STORE runs the whole store (or
  continues it: resume=True), then adds what the store says (blocks done, their seconds, du) to the report;
- 160K vertices: the per-source time of in-process distance_matrix on one thread at every mesh measured
  (--scaling-meshes added), fitted as a * vertices^b, times 160K sources over 64 and 512 cores, plus the
  overhead per block.
"""

from __future__ import annotations

import argparse
import concurrent.futures
import contextlib
import datetime
import importlib.metadata
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import zarr
from distributed import Client

import exactgeo
from exactgeo import distributed
from meshes import BenchMesh, kSubdivided, select_meshes
from reports.distributed import kConfigurations, write_markdown
from reports.files import write_json_and_markdown
from reports.machine import command_text, machine_info, setting_text, software_info
from solvers.runner import choose_sources

kBenchDir = Path(__file__).resolve().parent
kWorkerCounts = (1, 2)
kTinyTorus = (16, 4)  # make_bumpy_torus(16, 4): 64 vertices, 128 faces
kTinyBlocks = 128
kExtrapolatedVertices = 160_000
kExtrapolatedCores = (64, 512)
kDistributedPackages = ["numpy", "dask", "distributed", "zarr"]
# The all-pairs workload's mesh, beside the subdivided meshes the other benchmarks share.
kSubdividedMeshes = {**kSubdivided, "homer-sub1": ("homer", 1), "cow-sub1": ("cow", 1)}


# ------------------------------------------------------------------------------------------ on the workers


def status_bytes(field: str) -> int:
    """A memory figure of this process from /proc/self/status (VmRSS: now, VmHWM: peak), in bytes."""
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith(field + ":"):
                return int(line.split()[1]) * 1024
    raise ValueError(f"no {field} in /proc/self/status")


def worker_baseline_rss() -> int:
    """A worker's RSS once it has what a block needs imported (the interpreter's and dask's share) and has
    written a tiny store itself (two blocks of one row on a 64-vertex torus), so that what the first write
    imports or sets up once counts in the baseline, not in the growth; its peak is reset to it. The peak is the
    process's own (VmHWM), unlike ru_maxrss, which starts at the RSS of the process that forked it."""
    from exactgeo import distributed as module

    tiny = exactgeo.Mesh(*exactgeo.make_bumpy_torus(*kTinyTorus))
    with tempfile.TemporaryDirectory() as folder, concurrent.futures.ThreadPoolExecutor(1) as executor:
        module.distance_matrix_to_zarr(tiny, [0, 1], Path(folder) / "warm-up.zarr", block_rows=1, client=executor)
    with open("/proc/self/clear_refs", "w") as clear:
        clear.write("5")  # resets VmHWM to VmRSS
    return status_bytes("VmRSS")


def worker_peak_rss() -> int:
    return status_bytes("VmHWM")


# ------------------------------------------------------------------------------------------ measurements


@contextlib.contextmanager
def local_cluster(workers: int) -> Iterator:
    """The LocalCluster exactgeo.distributed starts itself (single-threaded worker processes on loopback, Dask's
    housekeeping slowed down), with `workers` workers, and its client."""
    with distributed.local_cluster(workers) as cluster, Client(cluster) as client:
        yield client


def block_seconds(store: Path) -> list[float]:
    """Each done block's own time (its marker's "seconds": the rows computed, rounded and written)."""
    status = distributed.store_status(store)
    return [zarr.open_group(str(store / "done" / f"block_{block:06d}"), mode="r").attrs["seconds"]
            for block in status.done]


def disk_bytes(path: Path) -> int:
    """What `du` says the folder occupies on disk, in bytes."""
    return int(subprocess.run(["du", "-s", "--block-size=1", str(path)], capture_output=True, text=True,
                              check=True).stdout.split()[0])


def into_store(client, mesh: exactgeo.Mesh, sources: np.ndarray, store: Path, workers: int,
               block_rows: int | None = None) -> dict:
    """One run into a fresh store: wall time (store creation and the mesh's scatter included), the blocks' own
    seconds and the overhead per block."""
    shutil.rmtree(store, ignore_errors=True)
    start = time.perf_counter()
    run = distributed.distance_matrix_to_zarr(mesh, sources, store, client=client, resume=False,
                                              block_rows=block_rows)
    wall = time.perf_counter() - start
    seconds = block_seconds(store)
    return {"wall_seconds": wall, "blocks": run.blocks, "block_seconds_sum": sum(seconds),
            "overhead_per_block_seconds": (wall * workers - sum(seconds)) / run.blocks}


def on_dask(mesh: exactgeo.Mesh, sources: np.ndarray, store: Path, workers: int) -> dict:
    """into_store on a fresh cluster of `workers`, with each worker's baseline and peak RSS."""
    with local_cluster(workers) as client:
        baseline = client.run(worker_baseline_rss)
        result = into_store(client, mesh, sources, store, workers)
        peak = client.run(worker_peak_rss)
    return {**result, "worker_baseline_rss_bytes": [baseline[w] for w in sorted(peak)],
            "worker_peak_rss_bytes": [peak[w] for w in sorted(peak)]}


def in_process(mesh: exactgeo.Mesh, sources: np.ndarray, threads: int) -> tuple[dict, np.ndarray]:
    start = time.perf_counter()
    matrix = exactgeo.distance_matrix(mesh, sources, threads=threads)
    return {"wall_seconds": time.perf_counter() - start}, matrix


kMeshBytesCode = """
import sys
import numpy as np
import exactgeo
from distributed_matrix import status_bytes

vertices, faces = np.load(sys.argv[1]), np.load(sys.argv[2])
before = status_bytes("VmRSS")
mesh = exactgeo.Mesh(vertices, faces)
mesh_bytes = vertices.nbytes + faces.nbytes + status_bytes("VmRSS") - before
with open("/proc/self/clear_refs", "w") as clear:
    clear.write("5")
before = status_bytes("VmRSS")
exactgeo.distance_matrix(mesh, [int(sys.argv[3])], threads=1)
print(mesh_bytes, status_bytes("VmHWM") - before)
"""


def mesh_and_engine_bytes(mesh: BenchMesh, source: int) -> tuple[int, int]:
    """What a Mesh holds (its vertex and face arrays plus the RSS building it adds), then what one row of
    distance_matrix from `source` adds to the peak (the engine's working memory: the solver's buffers and
    windows, the row), in a fresh process: in this one, memory freed earlier would hide part of it."""
    done = subprocess.run([sys.executable, "-c", kMeshBytesCode, str(mesh.vertices_path), str(mesh.triangles_path),
                           str(source)], capture_output=True, text=True, check=True, cwd=kBenchDir)
    mesh_size, engine = map(int, done.stdout.split())
    return mesh_size, engine


def load_mesh(mesh: BenchMesh) -> exactgeo.Mesh:
    return exactgeo.Mesh(np.load(mesh.vertices_path), np.load(mesh.triangles_path))


def used_vertices(faces: np.ndarray) -> np.ndarray:
    """The vertices a face uses: the all-pairs sources (distance_matrix refuses a vertex no face uses)."""
    return np.unique(faces).astype(np.int64)


def memory_figures(label: str, bench_mesh: BenchMesh, mesh: exactgeo.Mesh, sources: np.ndarray,
                   samples: dict[str, list[dict]], status: distributed.StoreStatus) -> dict:
    """The workers' growth over their baseline (the largest over the workers, median over the runs) against one
    float32 block plus the mesh, with the engine's working memory beside them."""
    size, engine = mesh_and_engine_bytes(bench_mesh, int(sources[0]))
    block_float32 = status.block_rows * status.shape[1] * 4
    memory = {}
    for name in kConfigurations[:2]:
        growth = [max(p - b for p, b in zip(s["worker_peak_rss_bytes"], s["worker_baseline_rss_bytes"]))
                  for s in samples[name]]
        memory[name] = {
            "worker_baseline_rss_bytes": statistics.median(max(s["worker_baseline_rss_bytes"]) for s in samples[name]),
            "worker_peak_rss_bytes": statistics.median(max(s["worker_peak_rss_bytes"]) for s in samples[name]),
            "worker_growth_bytes": statistics.median(growth),
            "growth_vs_block_and_mesh": statistics.median(growth) / (block_float32 + size),
        }
    return {"label": label, "mesh": bench_mesh.name, "vertices": mesh.vertex_count, "faces": mesh.face_count,
            "sources": len(sources), "targets": status.shape[1], "block_rows": status.block_rows,
            "blocks": math.ceil(len(sources) / status.block_rows), "block_float32_bytes": block_float32,
            "mesh_bytes": size, "engine_bytes": engine, "memory": memory}


def measure_workload(label: str, bench_mesh: BenchMesh, sources: np.ndarray, runs: int, work: Path) -> dict:
    """The four configurations in turn, `runs` times; medians, ratios, memory against one block plus the mesh,
    and whether the last store holds the in-process matrix rounded to float32."""
    mesh = load_mesh(bench_mesh)
    samples: dict[str, list[dict]] = {name: [] for name in kConfigurations}
    store = work / f"{label}.zarr"
    same = True
    for run in range(runs):
        for name, workers in zip(kConfigurations[:2], kWorkerCounts):
            samples[name].append(on_dask(mesh, sources, store, workers))
        for name, threads in zip(kConfigurations[2:], kWorkerCounts):
            result, matrix = in_process(mesh, sources, threads)
            samples[name].append(result)
        same = same and bool(np.array_equal(zarr.open_array(str(store / "distances"), mode="r")[...],
                                            matrix.astype(np.float32)))
        print(f"{label} run {run + 1}: " + ", ".join(f"{name} {s[-1]['wall_seconds']:.2f} s"
                                                     for name, s in samples.items()), flush=True)
    wall = {name: statistics.median(s["wall_seconds"] for s in runs_of) for name, runs_of in samples.items()}
    return {
        **memory_figures(label, bench_mesh, mesh, sources, samples, distributed.store_status(store)),
        "samples": samples, "median_wall_seconds": wall,
        "dask_speedup": wall["dask, 1 worker"] / wall["dask, 2 workers"],
        "in_process_speedup": wall["in-process, 1 thread"] / wall["in-process, 2 threads"],
        "overhead_per_block_seconds": {name: statistics.median(s["overhead_per_block_seconds"] for s in samples[name])
                                       for name in kConfigurations[:2]},
        "per_source_seconds": wall["in-process, 1 thread"] / len(sources),
        "store_equals_in_process": same,
    }


def measure_memory(label: str, bench_mesh: BenchMesh, sources: np.ndarray, blocks: int, runs: int,
                   work: Path) -> dict:
    """The workers' memory alone: the first `blocks` blocks of the workload's layout (its default block_rows)
    on 1 and 2 workers, `runs` times; no time is reported."""
    mesh = load_mesh(bench_mesh)
    block_rows = exactgeo._core.store_default_block_rows(len(sources), mesh.vertex_count, 4)
    part = sources[:blocks * block_rows]
    store = work / f"{label}-memory.zarr"
    samples: dict[str, list[dict]] = {name: [] for name in kConfigurations[:2]}
    for run in range(runs):
        for name, workers in zip(kConfigurations[:2], kWorkerCounts):
            with local_cluster(workers) as client:
                baseline = client.run(worker_baseline_rss)
                shutil.rmtree(store, ignore_errors=True)
                distributed.distance_matrix_to_zarr(mesh, part, store, client=client, resume=False,
                                                    block_rows=block_rows)
                peak = client.run(worker_peak_rss)
            samples[name].append({"worker_baseline_rss_bytes": [baseline[w] for w in sorted(peak)],
                                  "worker_peak_rss_bytes": [peak[w] for w in sorted(peak)]})
        print(f"{label} memory run {run + 1} done", flush=True)
    figures = memory_figures(label, bench_mesh, mesh, sources, samples, distributed.store_status(store))
    return {**figures, "blocks": math.ceil(len(sources) / block_rows), "blocks_measured": len(part) // block_rows,
            "samples": samples}


def tiny_blocks(client, work: Path, runs: int) -> dict:
    """128 blocks of one row on a 64-vertex torus, on 2 workers: the work is trivial, what is left is overhead."""
    mesh = exactgeo.Mesh(*exactgeo.make_bumpy_torus(*kTinyTorus))
    sources = np.resize(np.arange(mesh.vertex_count), kTinyBlocks)
    results = [into_store(client, mesh, sources, work / "tiny.zarr", 2, block_rows=1) for _ in range(runs)]
    return {"vertices": mesh.vertex_count, "blocks": kTinyBlocks, "workers": 2,
            "overhead_per_block_seconds": statistics.median(r["overhead_per_block_seconds"] for r in results),
            "block_seconds_mean": statistics.median(r["block_seconds_sum"] / r["blocks"] for r in results),
            "wall_seconds": statistics.median(r["wall_seconds"] for r in results)}


def store_figures(store: Path) -> dict:
    """What a (possibly partial) all-pairs store says: blocks and rows done, their summed seconds, its size on
    disk, and the part of that size that does not grow with the rows (the mesh and the column indices)."""
    status = distributed.store_status(store)
    rows_done = sum(len(status.rows(block)) for block in status.done)
    return {"rows": status.shape[0], "columns": status.shape[1], "block_rows": status.block_rows,
            "blocks": status.blocks, "blocks_done": len(status.done), "rows_done": rows_done,
            "block_seconds_sum": sum(block_seconds(store)), "disk_bytes": disk_bytes(store),
            "fixed_disk_bytes": disk_bytes(store / "mesh") + disk_bytes(store / "target")}


def extrapolated(figures: dict, rows: int, blocks: int, workers: int) -> dict | None:
    """The whole all-pairs store from a part of it: seconds per row and bytes per block times the whole (None
    before any block is done)."""
    if not figures["blocks_done"]:
        return None
    core_seconds = figures["block_seconds_sum"] / figures["rows_done"] * rows
    growing = figures["disk_bytes"] - figures["fixed_disk_bytes"]
    return {"core_seconds": core_seconds, "wall_seconds": core_seconds / workers, "workers": workers,
            "disk_bytes": figures["fixed_disk_bytes"] + growing / figures["blocks_done"] * blocks,
            "uncompressed_bytes": rows * figures["columns"] * 4}


def nefertiti_subset(nefertiti: BenchMesh, blocks: int, block_rows: int | None, work: Path, runs: int) -> dict:
    """The first `blocks` blocks of nefertiti's all-pairs layout on 2 workers (then the tiny blocks on the same
    cluster), and the whole store extrapolated from them."""
    mesh = load_mesh(nefertiti)
    sources = used_vertices(mesh.faces)
    rows = block_rows or exactgeo._core.store_default_block_rows(len(sources), mesh.vertex_count, 4)
    store = work / "nefertiti-all-pairs-subset.zarr"
    with local_cluster(2) as client:
        result = into_store(client, mesh, sources[:blocks * rows], store, 2, block_rows=rows)
        tiny = tiny_blocks(client, work, runs)
    figures = store_figures(store)
    total_blocks = math.ceil(len(sources) / rows)
    return {"tiny_blocks": tiny, "nefertiti_all_pairs": {
        "vertices": mesh.vertex_count, "measured": {**figures, "wall_seconds": result["wall_seconds"], "workers": 2},
        "extrapolated": extrapolated(figures, len(sources), total_blocks, 2)}}


def per_source_seconds(bench_mesh: BenchMesh, count: int, runs: int) -> dict:
    """In-process distance_matrix on one thread from `count` seeded sources: the median time per source."""
    mesh = load_mesh(bench_mesh)
    sources = np.array(choose_sources(bench_mesh, count, seed=1))
    times = [in_process(mesh, sources, 1)[0]["wall_seconds"] / len(sources) for _ in range(runs)]
    return {"mesh": bench_mesh.name, "vertices": mesh.vertex_count, "sources": len(sources),
            "per_source_seconds": statistics.median(times)}


def extrapolation(points: list[dict], overhead_per_block: float) -> dict:
    """160K-vertex all-pairs: per-source seconds fitted as a * vertices^b through the points (least squares in
    log-log), times the sources, over the cores, plus each core's share of the blocks' overhead."""
    exponent, log_factor = np.polyfit(np.log([p["vertices"] for p in points]),
                                      np.log([p["per_source_seconds"] for p in points]), 1)
    per_source = math.exp(log_factor) * kExtrapolatedVertices**exponent
    block_rows = exactgeo._core.store_default_block_rows(kExtrapolatedVertices, kExtrapolatedVertices, 4)
    blocks = math.ceil(kExtrapolatedVertices / block_rows)
    output = kExtrapolatedVertices**2 * 4
    cores = {}
    for count in kExtrapolatedCores:
        wall = (kExtrapolatedVertices * per_source + blocks * overhead_per_block) / count
        cores[str(count)] = {"wall_seconds": wall, "output_bytes_per_second": output / wall}
    return {"points": points, "exponent": float(exponent), "vertices": kExtrapolatedVertices,
            "per_source_seconds": per_source, "source_seconds": kExtrapolatedVertices * per_source,
            "block_rows": block_rows, "blocks": blocks, "overhead_per_block_seconds": overhead_per_block,
            "output_bytes": output, "cores": cores}


# ---------------------------------------------------------------------------------------------- the runs


def header(args: argparse.Namespace, argv: list[str] | None) -> dict:
    versions = {package: importlib.metadata.version(package) for package in kDistributedPackages}
    return {"name": args.name, "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
            "command": command_text("distributed_matrix.py", argv),
            "settings": {key: setting_text(value) for key, value in vars(args).items()},
            "machine": machine_info(), "software": {**software_info(), "distributed_packages": versions},
            "load_average_at_start": os.getloadavg()}


def workload_sources(args: argparse.Namespace, meshes: dict[str, BenchMesh]) -> list[tuple[str, BenchMesh, np.ndarray]]:
    """The two workloads: all-pairs on --all-pairs-mesh, --sources seeded sources on nefertiti."""
    all_pairs_mesh = meshes[args.all_pairs_mesh]
    return [("all-pairs", all_pairs_mesh, used_vertices(np.load(all_pairs_mesh.triangles_path))),
            ("many-sources", meshes["nefertiti"], np.array(choose_sources(meshes["nefertiti"], args.sources, seed=1)))]


def memory_only(args: argparse.Namespace, argv: list[str] | None, meshes: dict[str, BenchMesh]) -> dict:
    report = header(args, argv)
    work = args.work_dir.resolve() / "runs" / "distributed"
    work.mkdir(parents=True, exist_ok=True)
    report["workloads"] = [measure_memory(label, mesh, sources, args.memory_blocks, args.runs, work)
                           for label, mesh, sources in workload_sources(args, meshes)]
    report["load_average_at_end"] = os.getloadavg()
    return report


def benchmark(args: argparse.Namespace, argv: list[str] | None, meshes: dict[str, BenchMesh]) -> dict:
    report = header(args, argv)
    work = args.work_dir.resolve() / "runs" / "distributed"
    work.mkdir(parents=True, exist_ok=True)
    report["workloads"] = [measure_workload(label, mesh, sources, args.runs, work)
                           for label, mesh, sources in workload_sources(args, meshes)]
    report.update(nefertiti_subset(meshes["nefertiti"], args.subset_blocks, args.subset_block_rows, work, args.runs))
    points = [{"mesh": w["mesh"], "vertices": w["vertices"], "sources": w["sources"],
               "per_source_seconds": w["per_source_seconds"]} for w in report["workloads"]]
    points += [per_source_seconds(meshes[name], args.scaling_sources, args.runs) for name in args.scaling_meshes]
    overhead = statistics.median(w["overhead_per_block_seconds"]["dask, 2 workers"] for w in report["workloads"])
    report["extrapolation"] = extrapolation(points, overhead)
    report["load_average_at_end"] = os.getloadavg()
    return report


def all_pairs_store(args: argparse.Namespace, argv: list[str] | None, nefertiti: BenchMesh) -> dict:
    """Runs or continues nefertiti's all-pairs store; Ctrl-C stops it, keeping the blocks done. The report of
    --name gets what the store says (a new report holds that alone)."""
    mesh = load_mesh(nefertiti)
    sources = used_vertices(mesh.faces)
    path = args.results_dir / f"{args.name}.json"
    report = json.loads(path.read_text()) if path.exists() else header(args, argv)
    start = time.perf_counter()
    with contextlib.suppress(KeyboardInterrupt), local_cluster(args.workers) as client:
        distributed.distance_matrix_to_zarr(mesh, sources, args.nefertiti_all_pairs, client=client, resume=True,
                                            progress=lambda done, rows: print(f"\r{done:,} of {rows:,} rows", end="",
                                                                              flush=True))
    print()
    figures = store_figures(args.nefertiti_all_pairs)
    report["nefertiti_all_pairs_store"] = {
        "store": str(args.nefertiti_all_pairs), "command": command_text("distributed_matrix.py", argv),
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "session_wall_seconds": time.perf_counter() - start, **figures,
        "extrapolated": extrapolated(figures, figures["rows"], figures["blocks"], args.workers)}
    return report


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true",
                        help="woody all-pairs, 8 sources, 1 run, tiny nefertiti blocks: a check, not results")
    parser.add_argument("--runs", type=int, default=3, help="runs of each configuration (median reported)")
    parser.add_argument("--all-pairs-mesh", default="homer-sub1")
    parser.add_argument("--memory-only", action="store_true",
                        help="the workers' peak memory alone, on the first --memory-blocks blocks of each workload "
                             "(no time measured); writes results/distributed-memory.{json,md}")
    parser.add_argument("--memory-blocks", type=int, default=4, help="blocks of each workload with --memory-only")
    parser.add_argument("--sources", type=int, default=256, help="seeded sources of the nefertiti workload")
    parser.add_argument("--subset-blocks", type=int, default=2,
                        help="blocks of nefertiti's all-pairs layout measured, the rest extrapolated")
    parser.add_argument("--subset-block-rows", type=int, help="their rows (default: the library's choice)")
    parser.add_argument("--scaling-meshes", nargs="*", default=["nefertiti-sub1", "nefertiti-sub2"],
                        help="more meshes whose per-source time the 160K extrapolation fits")
    parser.add_argument("--scaling-sources", type=int, default=4)
    parser.add_argument("--nefertiti-all-pairs", type=Path, metavar="STORE",
                        help="run or continue nefertiti's whole all-pairs store instead, then report it")
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1, help="with --nefertiti-all-pairs")
    parser.add_argument("--mesh-dir", type=Path, default=kBenchDir.parent.parent / "shared" / "meshes")
    parser.add_argument("--work-dir", type=Path, default=kBenchDir / "work")
    parser.add_argument("--results-dir", type=Path, default=kBenchDir / "results")
    parser.add_argument("--name", default="distributed")
    args = parser.parse_args(argv)
    if args.quick:
        args.all_pairs_mesh, args.sources, args.runs, args.subset_block_rows = "woody", 8, 1, 4
        args.scaling_meshes = []
    if args.memory_only and args.name == "distributed":
        args.name = "distributed-memory"
    if args.quick and args.name in ("distributed", "distributed-memory"):
        args.name += "-quick"
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    names = ["nefertiti"]
    if not args.nefertiti_all_pairs:
        names += [args.all_pairs_mesh] + ([] if args.memory_only else args.scaling_meshes)
    meshes = {m.name: m for m in select_meshes(args.mesh_dir.resolve(), args.work_dir.resolve(), names,
                                               kSubdividedMeshes)}
    if args.nefertiti_all_pairs:
        report = all_pairs_store(args, argv, meshes["nefertiti"])
    elif args.memory_only:
        report = memory_only(args, argv, meshes)
    else:
        report = benchmark(args, argv, meshes)
    args.results_dir.mkdir(parents=True, exist_ok=True)
    _, markdown = write_json_and_markdown(args.results_dir, report, write_markdown)
    print(markdown.read_text())
    return 0


if __name__ == "__main__":
    sys.exit(main())
