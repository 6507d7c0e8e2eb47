"""Many-source work on one mesh: the distance matrix on 1 thread and on every core, and one multi-source run
against as many single-source runs. Writes bench/results/many-sources.{json,md}.

usage: python3 bench/many_sources.py [--mesh nefertiti] [--sources 16] [--build-dir build]

All times come from runs of the `exactgeo` command in this process's run, one after the other:
- matrix: the wall time of `exactgeo matrix --threads T` (mesh loading included, the same in every run);
- multi-source: propagation_seconds of one `exactgeo distance` with every source, against the sum of
  propagation_seconds of one run per source. The matrix rows are checked bit for bit across thread counts,
  and their minimum against the multi-source distances.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import subprocess
import time
from pathlib import Path

import numpy as np

from meshes import prepare_meshes
from run import choose_sources, machine_info

kBenchDir = Path(__file__).resolve().parent


def timed(command: list[str]) -> float:
    start = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def propagation_seconds(exactgeo: Path, mesh: Path, sources: list[int], stats: Path) -> float:
    command = [str(exactgeo), "distance", str(mesh), "--stats", str(stats), "--out", str(stats.with_suffix(".npy"))]
    for source in sources:
        command += ["--source", str(source)]
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    return json.loads(stats.read_text())["propagation_seconds"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--mesh", default="nefertiti", help="a mesh of ../shared/meshes (default nefertiti)")
    parser.add_argument("--sources", type=int, default=16, help="seeded source vertices (default 16)")
    parser.add_argument("--build-dir", type=Path, default=kBenchDir.parent / "build")
    parser.add_argument("--mesh-dir", type=Path, default=kBenchDir.parent.parent / "shared" / "meshes")
    parser.add_argument("--work-dir", type=Path, default=kBenchDir / "work")
    parser.add_argument("--results-dir", type=Path, default=kBenchDir / "results")
    args = parser.parse_args()
    exactgeo = (args.build_dir / "cli" / "exactgeo").resolve()
    mesh = next(m for m in prepare_meshes(args.mesh_dir.resolve(), args.work_dir.resolve(), {}) if m.name == args.mesh)
    sources = choose_sources(mesh, args.sources, seed=1)
    run_dir = args.work_dir.resolve() / "runs" / "many-sources"
    run_dir.mkdir(parents=True, exist_ok=True)
    source_list = ",".join(str(s) for s in sources)

    cores = os.cpu_count() or 1
    matrix_seconds, matrices = {}, {}
    for threads in sorted({1, cores}):
        out = run_dir / f"matrix-{threads}.npy"
        matrix_seconds[threads] = timed([str(exactgeo), "matrix", str(mesh.obj_path), "--sources", source_list,
                                         "--threads", str(threads), "--quiet", "--out", str(out)])
        matrices[threads] = np.load(out)
    rows_agree = all(np.array_equal(matrices[1], m, equal_nan=True) for m in matrices.values())

    single = [propagation_seconds(exactgeo, mesh.obj_path, [s], run_dir / f"single-{s}.json") for s in sources]
    multi = propagation_seconds(exactgeo, mesh.obj_path, sources, run_dir / "multi.json")
    nearest = np.load(run_dir / "multi.npy")
    minimum = matrices[1].min(axis=0)
    finite = np.isfinite(minimum)
    min_error = float(np.max(np.abs(nearest[finite] - minimum[finite])) / np.max(minimum[finite]))

    report = {
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "machine": machine_info(),
        "mesh": mesh.name, "faces": mesh.face_count, "sources": sources,
        "matrix_wall_seconds": matrix_seconds,
        "matrix_speedup": matrix_seconds[1] / matrix_seconds[cores],
        "matrix_rows_identical_across_threads": rows_agree,
        "single_source_propagation_seconds": single,
        "multi_source_propagation_seconds": multi,
        "multi_vs_singles": sum(single) / multi,
        "multi_source_vs_min_of_rows_relative_error": min_error,
    }
    args.results_dir.mkdir(parents=True, exist_ok=True)
    (args.results_dir / "many-sources.json").write_text(json.dumps(report, indent=1))
    lines = [
        f"# Many sources on {mesh.name} ({mesh.face_count:,} faces), {len(sources)} sources",
        "",
        f"{report['date']} · {report['machine']['cpu_model']}, {cores} logical cores · `python3 bench/many_sources.py`",
        "",
        "| what | time | ratio |",
        "|---|---:|---:|",
        f"| `exactgeo matrix`, 1 thread (wall) | {matrix_seconds[1]:.3f} s | 1x |",
        f"| `exactgeo matrix`, {cores} threads (wall) | {matrix_seconds[cores]:.3f} s | "
        f"{report['matrix_speedup']:.2f}x faster |",
        f"| {len(sources)} single-source runs (propagation, summed) | {sum(single):.3f} s | 1x |",
        f"| one run from all {len(sources)} sources (propagation) | {multi:.3f} s | "
        f"{report['multi_vs_singles']:.2f}x faster |",
        "",
        f"Matrix rows identical across thread counts: {'yes' if rows_agree else 'NO'}. Multi-source distances "
        f"against the minimum of the matrix rows: max relative error {min_error:.1e}.",
        "",
    ]
    (args.results_dir / "many-sources.md").write_text("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
