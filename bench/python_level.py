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
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

import exactgeo
from run import machine_info

kBenchDir = Path(__file__).resolve().parent
kBatchSeconds = 0.02
kMatrixSources = 16
# libigl's exact_geodesic also traces the path back from every vertex: at 100K faces one call takes over a
# minute, so it runs on the meshes up to this size only.
kLibiglMaxFaces = 25_000
# Kirsanov's code marks unreachable vertices with 1e100.
kKirsanovInfinity = 1e99


class Peer:
    """One package's way of answering: `build` returns its prepared structure (None if it has none), `query`
    the distances from one source given that structure (or the arrays)."""

    def __init__(self, name: str, package: str, build: Callable | None, query: Callable, exact: bool) -> None:
        self.name, self.package, self.build, self.query, self.exact = name, package, build, query, exact

    def one_call(self, vertices: np.ndarray, faces: np.ndarray, source: int) -> np.ndarray:
        prepared = self.build(vertices, faces) if self.build else None
        return self.query(prepared, vertices, faces, source)


def make_peers() -> list[Peer]:
    import gdist
    import igl
    import potpourri3d
    import pygeodesic.geodesic

    return [
        Peer("exactgeo", "exactgeo", exactgeo.Mesh, lambda mesh, v, f, s: exactgeo.distance(mesh, s), True),
        Peer(
            "pygeodesic",
            "pygeodesic",
            pygeodesic.geodesic.PyGeodesicAlgorithmExact,
            lambda algorithm, v, f, s: algorithm.geodesicDistances(np.array([s]), None)[0],
            True,
        ),
        Peer(
            "gdist",
            "tvb-gdist",
            None,
            lambda _, v, f, s: gdist.compute_gdist(v, f, source_indices=np.array([s], dtype=np.int32)),
            True,
        ),
        Peer(
            "libigl",
            "libigl",
            None,
            lambda _, v, f, s: igl.exact_geodesic(v, f, np.array([s]), VT=np.arange(len(v))),
            True,
        ),
        Peer(
            "heat",
            "potpourri3d",
            potpourri3d.MeshHeatMethodDistanceSolver,
            lambda solver, v, f, s: solver.compute_distance(s),
            False,
        ),
    ]


def per_call_seconds(call: Callable[[], object]) -> Callable[[], float]:
    """A timer for `call`: each use runs a batch of at least kBatchSeconds and returns the time per call."""
    start = time.perf_counter()
    call()  # warm-up, and the size of a batch
    number = max(1, int(kBatchSeconds / max(time.perf_counter() - start, 1e-9)))

    def batch() -> float:
        start = time.perf_counter()
        for _ in range(number):
            call()
        return (time.perf_counter() - start) / number

    return batch


def median_times(calls: dict[str, Callable[[], object]], repeat: int) -> dict[str, float]:
    """Median time per call of each, batches taken round the calls."""
    timers = {name: per_call_seconds(call) for name, call in calls.items()}
    samples: dict[str, list[float]] = {name: [] for name in calls}
    for _ in range(repeat):
        for name, timer in timers.items():
            samples[name].append(timer())
    return {name: statistics.median(values) for name, values in samples.items()}


def difference(ours: np.ndarray, theirs: np.ndarray) -> dict:
    """Largest |theirs - ours| over the vertices finite in both, relative to our largest distance, and the
    count of vertices one calls unreachable and the other does not."""
    theirs = np.asarray(theirs, dtype=np.float64)
    theirs = np.where(np.abs(theirs) < kKirsanovInfinity, theirs, np.inf)
    both = np.isfinite(ours) & np.isfinite(theirs)
    largest = ours[np.isfinite(ours)].max()
    return {
        "max_relative_difference": float(np.abs(ours[both] - theirs[both]).max() / largest),
        "max_absolute_difference": float(np.abs(ours[both] - theirs[both]).max()),
        "reachability_disagreements": int(np.count_nonzero(np.isfinite(ours) != np.isfinite(theirs))),
    }


def bench_mesh(name: str, vertices: np.ndarray, faces: np.ndarray, peers: list[Peer], repeat: int) -> dict:
    source = int(np.unique(faces)[0])
    runnable = [p for p in peers if p.name != "libigl" or len(faces) <= kLibiglMaxFaces]
    prepared = {p.name: p.build(vertices, faces) if p.build else None for p in runnable}
    one_call = median_times({p.name: (lambda p=p: p.one_call(vertices, faces, source)) for p in runnable}, repeat)
    prepared_call = median_times(
        {p.name: (lambda p=p: p.query(prepared[p.name], vertices, faces, source)) for p in runnable if p.build}, repeat
    )
    ours = exactgeo.distance(prepared["exactgeo"], source)
    record = {"mesh": name, "vertices": len(vertices), "faces": len(faces), "source": source, "solvers": {}}
    for p in runnable:
        record["solvers"][p.name] = {
            "one_call_seconds": one_call[p.name],
            "prepared_seconds": prepared_call.get(p.name, one_call[p.name]),
            "rebuilds_every_call": p.build is None,
            **difference(ours, p.query(prepared[p.name], vertices, faces, source)),
        }
    skipped = [p.name for p in peers if p not in runnable]
    if skipped:
        record["skipped"] = {
            n: f"over {kLibiglMaxFaces:,} faces (one call traces every vertex's path)" for n in skipped
        }
    return record


def bench_matrix(name: str, vertices: np.ndarray, faces: np.ndarray, peers: list[Peer], repeat: int) -> dict:
    rng = np.random.default_rng(1)
    sources = rng.choice(np.unique(faces), size=kMatrixSources, replace=False)
    mesh = exactgeo.Mesh(vertices, faces)
    calls: dict[str, Callable[[], object]] = {
        "exactgeo": lambda: exactgeo.distance_matrix(mesh, sources),
        "exactgeo, 1 thread": lambda: exactgeo.distance_matrix(mesh, sources, threads=1),
    }
    for p in peers:
        if p.name == "exactgeo" or (p.name == "libigl" and len(faces) > kLibiglMaxFaces):
            continue
        prepared = p.build(vertices, faces) if p.build else None
        calls[p.name] = lambda p=p, prepared=prepared: [p.query(prepared, vertices, faces, int(s)) for s in sources]
    times = median_times(calls, repeat)
    return {
        "mesh": name,
        "vertices": len(vertices),
        "faces": len(faces),
        "sources": [int(s) for s in sources],
        "threads": os.cpu_count(),
        "seconds": times,
    }


def load_average() -> str:
    return ", ".join(f"{value:.2f}" for value in os.getloadavg())


def ratio(value: float, ours: float) -> str:
    return f"{value / ours:.3g}x"


def format_seconds(seconds: float) -> str:
    if seconds < 1e-3:
        return f"{seconds * 1e6:.3g} µs"
    if seconds < 1:
        return f"{seconds * 1e3:.3g} ms"
    return f"{seconds:.3g} s"


def write_markdown(path: Path, report: dict) -> None:
    peers = [p for p in report["solvers"] if p != "exactgeo"]
    lines = [
        "# Python-level comparison",
        "",
        f"Run {report['date']} by `bench/python_level.py` (see bench/README.md): one process, the same numpy arrays "
        f"(V float64, F int32) for every package, median of {report['settings']['repeat']} batches. "
        f"Load average at the start: {report['load_average']}; at the end: {report['load_average_at_end']}.",
        "",
        "Each cell is the package's time divided by exactgeo's (above 1: exactgeo is faster). "
        "† gdist and libigl have no prepared form: they rebuild the mesh in every call.",
        "",
    ]
    for key, title in (
        ("one_call_seconds", "One call from arrays (build the mesh, distances from one source)"),
        ("prepared_seconds", "Prepared mesh (one query on a mesh built beforehand)"),
    ):
        lines += [
            f"## {title}",
            "",
            "| mesh | faces | " + " | ".join(peers) + " | exactgeo itself |",
            "|---|---:|" + "---:|" * (len(peers) + 1),
        ]
        for record in report["meshes"]:
            solvers = record["solvers"]
            ours = solvers["exactgeo"][key]
            cells = []
            for peer in peers:
                if peer not in solvers:
                    cells.append("—")
                    continue
                mark = " †" if key == "prepared_seconds" and solvers[peer]["rebuilds_every_call"] else ""
                cells.append(ratio(solvers[peer][key], ours) + mark)
            lines.append(
                f"| {record['mesh']} | {record['faces']:,} | " + " | ".join(cells) + f" | {format_seconds(ours)} |"
            )
        lines.append("")
    matrix = report["matrix"]
    ours = matrix["seconds"]["exactgeo"]
    lines += [
        f"## Distance matrix: {len(matrix['sources'])} sources × every vertex of {matrix['mesh']} "
        f"({matrix['faces']:,} faces)",
        "",
        f"exactgeo.distance_matrix on {matrix['threads']} threads against each way of getting the same rows; "
        "the others one call per source on a prepared mesh.",
        "",
        "| solver | time ÷ exactgeo's |",
        "|---|---:|",
    ]
    for name, seconds in matrix["seconds"].items():
        lines.append(f"| {name} | {ratio(seconds, ours)} |")
    lines += [
        "",
        f"exactgeo's own time: {format_seconds(ours)}.",
        "",
        "## Agreement with exactgeo",
        "",
        "Largest difference over the vertices both call reachable, relative to the largest distance "
        "(Kirsanov's MMP in pygeodesic, gdist and libigl is exact; the heat method is not), and vertices one "
        "calls unreachable and the other does not.",
        "",
        "| mesh | " + " | ".join(peers) + " |",
        "|---|" + "---:|" * len(peers),
    ]
    for record in report["meshes"]:
        cells = []
        for peer in peers:
            entry = record["solvers"].get(peer)
            if entry is None:
                cells.append("—")
                continue
            disagreements = entry["reachability_disagreements"]
            cells.append(
                f"{entry['max_relative_difference']:.1e}"
                + (f", {disagreements} unreachable differ" if disagreements else "")
            )
        lines.append(f"| {record['mesh']} | " + " | ".join(cells) + " |")
    skipped = {n: r for record in report["meshes"] for n, r in record.get("skipped", {}).items()}
    lines += [
        "",
        *(f"— {name}: skipped {reason}." for name, reason in skipped.items()),
        "",
        "## Machine and software",
        "",
    ]
    machine = report["machine"]
    lines.append(f"{machine['cpu_model']}, {machine['logical_cores']} logical cores, Python {report['python']}.")
    lines.append(", ".join(f"{name} {version}" for name, version in report["versions"].items()) + ".")
    path.write_text("\n".join(lines) + "\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument(
        "--meshes",
        nargs="+",
        default=["woody", "spot", "homer", "rocker-arm", "nefertiti"],
        help="meshes of --mesh-dir, after the small grids",
    )
    parser.add_argument("--matrix-mesh", default="spot")
    parser.add_argument("--repeat", type=int, default=5, help="batches per time (median reported)")
    parser.add_argument("--quick", action="store_true", help="two small shared meshes, 3 batches: a check, not results")
    parser.add_argument("--mesh-dir", type=Path, default=kBenchDir.parent.parent / "shared" / "meshes")
    parser.add_argument("--results-dir", type=Path, default=kBenchDir / "results")
    parser.add_argument("--name", default="python-level")
    args = parser.parse_args()
    if args.quick:
        args.meshes, args.repeat, args.name = ["woody", "spot"], 3, args.name + "-quick"

    peers = make_peers()
    load_at_start = load_average()
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

    report = {
        "date": datetime.datetime.now().isoformat(timespec="seconds"),
        "settings": {"repeat": args.repeat, "batch_seconds": kBatchSeconds, "libigl_max_faces": kLibiglMaxFaces},
        "load_average": load_at_start,
        # Another process running meanwhile shows here, not in the load at the start.
        "load_average_at_end": load_average(),
        "machine": machine_info(),
        "python": ".".join(map(str, sys.version_info[:3])),
        "versions": {p.package: importlib.metadata.version(p.package) for p in peers} | {"numpy": np.__version__},
        "solvers": [p.name for p in peers],
        "meshes": records,
        "matrix": matrix,
    }
    args.results_dir.mkdir(parents=True, exist_ok=True)
    json_path = args.results_dir / f"{args.name}.json"
    json_path.write_text(json.dumps(report, indent=1) + "\n")
    write_markdown(args.results_dir / f"{args.name}.md", report)
    print(f"wrote {json_path} and {json_path.with_suffix('.md')}")


if __name__ == "__main__":
    main()
