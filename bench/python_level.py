"""Python-level benchmark: exactgeo's package against pygeodesic, gdist, libigl and potpourri3d (heat method),
in one process, on the same numpy arrays. Writes bench/results/python-level.{json,md}.

usage: python3 bench/python_level.py [--quick] [--meshes woody spot ...] [--repeat 5]

What a numpy user sees, per call, from arrays to distances:
- one call: build the peer's mesh structure from (V float64, F int32) and get every vertex's distance from
  one source. On tiny meshes this is the call overhead (argument conversion, setup, result arrays).
- prepared: the same query on a structure built beforehand, where the API has one (exactgeo.Mesh,
  pygeodesic's PyGeodesicAlgorithmExact, potpourri3d's MeshHeatMethodDistanceSolver). gdist and libigl
  rebuild on every call: their prepared time is their one-call time (marked †).
- matrix: distances from 16 sources to every vertex, as a user of each package would get them: exactgeo's
  distance_matrix (every core, and one thread), the others one call per source on a prepared structure.
- local matrices: every vertex a source, out to 3 and 6 mean edge lengths, as a sparse matrix from the arrays:
  exactgeo.distance_matrix(Mesh(V, F), every vertex, max_distance=r) (one thread, every core) against
  gdist.local_gdist_matrix(V, F, max_distance=r), the one peer with such a call.

exactgeo answers single sources on one thread, as the others do (bench/results/threads.md has two threads).
Every solver gets the same V and F arrays; conversions a peer needs happen inside its timed call, as they
would for its users. Each time is the median over --repeat batches of calls (a batch lasts at least 20 ms),
batches going round the solvers so a drift in machine load hits all alike. Ratios are peer time divided by
exactgeo's: above 1, exactgeo is faster. Each peer's largest difference to exactgeo is reported beside it
(Kirsanov's MMP exact, the heat method approximate).
"""

from __future__ import annotations

import argparse
import datetime
import importlib.metadata
import json
import os
import sys
from pathlib import Path

import numpy as np

import exactgeo
from reports.machine import load_text, machine_info
from reports.python_level import write_markdown
from solvers.in_process import (
    bench_local_matrix,
    bench_matrix,
    bench_mesh,
    kBatchSeconds,
    kLibiglMaxFaces,
    kLocalRadiiEdges,
    make_peers,
)

kBenchDir = Path(__file__).resolve().parent


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument(
        "--meshes",
        nargs="+",
        default=["woody", "spot", "homer", "rocker-arm", "nefertiti"],
        help="meshes of --mesh-dir, after the small grids",
    )
    parser.add_argument("--matrix-mesh", default="spot")
    parser.add_argument("--local-meshes", nargs="+", default=["spot", "homer", "rocker-arm"],
                        help="meshes of --mesh-dir for the local matrices")
    parser.add_argument("--local-repeat", type=int, default=3, help="batches per local matrix time")
    parser.add_argument("--repeat", type=int, default=5, help="batches per time (median reported)")
    parser.add_argument("--quick", action="store_true", help="two small shared meshes, 3 batches: a check, not results")
    parser.add_argument("--mesh-dir", type=Path, default=kBenchDir.parent.parent / "shared" / "meshes")
    parser.add_argument("--results-dir", type=Path, default=kBenchDir / "results")
    parser.add_argument("--name", default="python-level")
    args = parser.parse_args()
    if args.quick:
        args.meshes, args.repeat, args.name = ["woody", "spot"], 3, args.name + "-quick"
        args.local_meshes, args.local_repeat = ["woody"], 2

    peers = make_peers()
    load_at_start = load_text(os.getloadavg())
    # Flat grids of unit squares: the small meshes that show the per-call overhead.
    meshes = [(f"grid {n}x{n}", *exactgeo.make_grid(n, n, n, n)) for n in (1, 4, 16)]
    for name in args.meshes:
        mesh = exactgeo.Mesh.load(args.mesh_dir / f"{name}.obj")
        meshes.append((name, mesh.vertices, mesh.faces))
    records = []
    for name, vertices, faces in meshes:
        print(f"{name}: {len(faces):,} faces", flush=True)
        # gdist takes only float64 and int32, so those are the arrays every package gets.
        records.append(bench_mesh(name, np.array(vertices), faces.astype(np.int32), peers, args.repeat))
    matrix_mesh = exactgeo.Mesh.load(args.mesh_dir / f"{args.matrix_mesh}.obj")
    print(f"matrix: {args.matrix_mesh}", flush=True)
    matrix = bench_matrix(
        args.matrix_mesh, np.array(matrix_mesh.vertices), matrix_mesh.faces.astype(np.int32), peers, args.repeat
    )
    local_matrices = []
    for name in args.local_meshes:
        mesh = exactgeo.Mesh.load(args.mesh_dir / f"{name}.obj")
        print(f"local matrices: {name}", flush=True)
        local_matrices.append(
            bench_local_matrix(name, np.array(mesh.vertices), mesh.faces.astype(np.int32), args.local_repeat))

    report = {
        "date": datetime.datetime.now().isoformat(timespec="seconds"),
        "settings": {"repeat": args.repeat, "batch_seconds": kBatchSeconds, "libigl_max_faces": kLibiglMaxFaces,
                     "local_repeat": args.local_repeat, "local_radii_edges": list(kLocalRadiiEdges)},
        "load_average": load_at_start,
        # Another process running meanwhile shows here, not in the load at the start.
        "load_average_at_end": load_text(os.getloadavg()),
        "machine": machine_info(),
        "python": ".".join(map(str, sys.version_info[:3])),
        "versions": {p.package: importlib.metadata.version(p.package) for p in peers} | {"numpy": np.__version__},
        "solvers": [p.name for p in peers],
        "meshes": records,
        "matrix": matrix,
        "local_matrices": local_matrices,
    }
    args.results_dir.mkdir(parents=True, exist_ok=True)
    json_path = args.results_dir / f"{args.name}.json"
    json_path.write_text(json.dumps(report, indent=1) + "\n")
    write_markdown(args.results_dir / f"{args.name}.md", report)
    print(f"wrote {json_path} and {json_path.with_suffix('.md')}")


if __name__ == "__main__":
    main()
