"""Pair distances: exactgeo.pair_distances against a full single-source run and against today's run that stops
at a named target, per pair, in one process. Writes bench/results/pairs.{json,md}.

usage: python3 bench/pairs.py [--mesh nefertiti] [--pairs 100] [--rounds 3]

For each of --pairs seeded random vertex pairs (a, b), on one thread, each timed as one call of the Python
package on a mesh loaded beforehand:
- full: GeodesicSolver.solve(a), every vertex's distance (a reused solver, which keeps its buffers);
- named target: GeodesicSolver.solve(a, targets=[b]), the run that stops once b is final;
- pair: exactgeo.pair_distances(mesh, [a], [b]), the goal-directed search (a call of its own per pair, its
  engine set up in the call).
Each pair's time is the median of --rounds rounds; the rounds go round the three ways pair by pair, so that a
drift in the machine's load hits all alike. Speed-ups are same-run ratios: per pair, full (or named target) time
over pair time, then the median over the pairs, overall and by quartile of the pair's distance. All 100 pairs
in one call are timed too (the mean pair). Every pair's distance is compared with the named-target run's.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import time
from pathlib import Path

import numpy as np

import exactgeo
from reports.machine import load_text, machine_info
from reports.pairs import write_markdown

kBenchDir = Path(__file__).resolve().parent


def timed(call) -> tuple[float, object]:
    start = time.perf_counter()
    value = call()
    return time.perf_counter() - start, value


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--mesh", default="nefertiti", help="a mesh of --mesh-dir (default nefertiti)")
    parser.add_argument("--pairs", type=int, default=100, help="seeded random vertex pairs (default 100)")
    parser.add_argument("--rounds", type=int, default=3, help="rounds per pair, median reported (default 3)")
    parser.add_argument("--seed", type=int, default=35)
    parser.add_argument("--mesh-dir", type=Path, default=kBenchDir.parent.parent / "shared" / "meshes")
    parser.add_argument("--results-dir", type=Path, default=kBenchDir / "results")
    parser.add_argument("--name", default="pairs")
    args = parser.parse_args()

    mesh = exactgeo.Mesh.load(args.mesh_dir / f"{args.mesh}.obj")
    used = np.unique(mesh.faces)
    rng = np.random.default_rng(args.seed)
    a, b = rng.choice(used, size=(2, args.pairs))
    load_at_start = load_text(os.getloadavg())
    solver = exactgeo.GeodesicSolver(mesh)
    seconds = {way: np.empty((args.rounds, args.pairs)) for way in ("full", "named_target", "pair")}
    named, paired = np.empty(args.pairs), np.empty(args.pairs)
    for round_ in range(args.rounds):
        for i in range(args.pairs):
            source, target = int(a[i]), int(b[i])
            # Each lambda runs at once; the pair is bound to it all the same, as a default argument.
            seconds["full"][round_, i], _ = timed(lambda source=source: solver.solve(source, threads=1))
            seconds["named_target"][round_, i], result = timed(
                lambda source=source, target=target: solver.solve(source, targets=[target], threads=1))
            named[i] = result.target_distances[0]
            seconds["pair"][round_, i], pair = timed(
                lambda source=source, target=target: exactgeo.pair_distances(mesh, [source], [target], threads=1))
            paired[i] = pair[0]
        print(f"round {round_ + 1} of {args.rounds} done", flush=True)
    together = min(timed(lambda: exactgeo.pair_distances(mesh, a, b, threads=1))[0] for _ in range(args.rounds))
    median = {way: np.median(times, axis=0) for way, times in seconds.items()}
    report = {
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "settings": {"mesh": args.mesh, "pairs": args.pairs, "rounds": args.rounds, "seed": args.seed},
        "faces": mesh.face_count,
        "load_average": load_at_start,
        "load_average_at_end": load_text(os.getloadavg()),
        "machine": machine_info(),
        "a": a.tolist(),
        "b": b.tolist(),
        "distances": paired.tolist(),
        "seconds": {way: times.tolist() for way, times in median.items()},
        "all_pairs_in_one_call_seconds": together,
        "max_relative_difference_to_named_target": float(np.max(np.abs(paired - named)) / np.max(named)),
        "pairs_equal_to_named_target_bit_for_bit": int(np.sum(paired == named)),
    }
    args.results_dir.mkdir(parents=True, exist_ok=True)
    json_path = args.results_dir / f"{args.name}.json"
    json_path.write_text(json.dumps(report, indent=1) + "\n")
    print(write_markdown(args.results_dir / f"{args.name}.md", report))


if __name__ == "__main__":
    main()
