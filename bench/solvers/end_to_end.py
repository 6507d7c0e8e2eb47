"""Whole processes, from the mesh file to the distances written: `exactgeo distance` as a user runs it, and each
peer's script doing the same (peer_worker.py --obj), with the steps their wall time splits into.

The steps are read (parsing the file), build (the solver's mesh structure), solve, write (the distances), each
as the process timed it, and start: launch.py's wall time of the process less the other four, which is starting
the process and loading its code, whatever it does between the steps, and its teardown. runner.py runs these
solvers like any other; what is here says how they are started, how their stats read back, and how the steps
of their runs are taken apart and summed up.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import json
import statistics
from pathlib import Path
from typing import ClassVar

from meshes import BenchMesh
from solvers.commands import ExactgeoSolver, PeerSolver, make_solvers

# The steps of a run, in the order the reports list them.
kSteps = ["start", "read", "build", "solve", "write"]

# The peers a user runs instead, end to end, in the order the reports list them.
kPeers = ["heat", "pygeodesic", "gdist"]

# The one reader every peer's run starts with, so that they all pay the same for the file (peer_worker.py).
kPeerReader = "potpourri3d.read_mesh"


def later_repeat_distances(stats: Path) -> Path:
    """Where a run writes its distances after the first repeat: writing is one of the steps, so every repeat
    writes, but over one file per run folder, which keeps the first repeat's (the runner's) for the checks."""
    return stats.parent / "later-repeats.distances.npy"


# --------------------------------------------------------------------------------------- exactgeo's stats


def exactgeo_steps(stats: dict) -> dict:
    """read, build, propagation and write seconds from `exactgeo distance --stats`, each its own step.

    The contract (issue 38): read_seconds is reading the file, build_seconds building the mesh alone,
    propagation_seconds the solve, write_seconds writing --out, and build_timings (optional) the build's own
    steps. Builds from before it have no write_seconds, and their build_seconds counts from the start, read
    included: for those the build is build_seconds - read_seconds, and the write is left in start.
    `build_counts_read` says which meaning the stats had. (Comparing build_seconds with read_seconds cannot
    tell them apart: a mesh whose build takes longer than its read satisfies both.)"""
    counts_read = "write_seconds" not in stats
    steps = {
        "read_seconds": stats["read_seconds"],
        "build_seconds": stats["build_seconds"] - (stats["read_seconds"] if counts_read else 0.0),
        "propagation_seconds": stats["propagation_seconds"],
        "write_seconds": stats.get("write_seconds"),
        "build_counts_read": counts_read,
    }
    if "build_timings" in stats:
        steps["build_timings"] = stats["build_timings"]
    return steps


# ------------------------------------------------------------------------------------------ the processes


@dataclasses.dataclass
class WholeExactgeoRun(ExactgeoSolver):
    """`exactgeo distance MESH --source S --out D.npy --stats S.json --threads T` of one build."""

    threads: int | None = 1  # None: a build without --threads, whose engine runs on one thread
    baseline: bool = False  # an earlier build, run beside the current one for before/after ratios

    def command(self, mesh, source, distances, stats):
        out = distances or later_repeat_distances(stats)
        command = [str(self.executable), "distance", str(mesh.obj_path), "--source", str(source), "--out", str(out),
                   "--stats", str(stats)]
        return command + ([] if self.threads is None else ["--threads", str(self.threads)])

    def read_stats(self, stats):
        data = json.loads(stats.read_text())
        return {**{key: data[key] for key in self.stats_keys if key in data}, **exactgeo_steps(data)}


@dataclasses.dataclass
class WholePeerRun(PeerSolver):
    """A peer's whole script: read the OBJ, build, solve once, write the distances (peer_worker.py --obj)."""

    stats_keys: ClassVar[list[str]] = [*PeerSolver.stats_keys, "read_seconds", "write_seconds"]

    def unavailable_reason(self):
        if (reason := super().unavailable_reason()) is not None:
            return reason
        if importlib.util.find_spec(kPeerReader.split(".")[0]) is None:
            return (f"potpourri3d not installed: every peer reads the mesh with {kPeerReader} "
                    "(pip install -r bench/requirements.txt)")
        return None

    def mesh_arguments(self, mesh: BenchMesh) -> list[str]:
        return ["--obj", str(mesh.obj_path)]

    def command(self, mesh, source, distances, stats):
        return super().command(mesh, source, distances or later_repeat_distances(stats), stats)


def whole_runs(names: list[str], threads: list[int], exactgeo: Path, baseline: Path | None = None,
               baseline_threads: bool = True) -> list[WholeExactgeoRun | WholePeerRun]:
    """The runs of one mesh, in the order they take turns: exactgeo (--solvers "exactgeo") on each thread count,
    each followed by the baseline on as many (on one, without --threads, if it has no such option:
    baseline_threads False), then the named peers of kPeers. ValueError for a name that is none of these."""
    unknown = set(names) - {"exactgeo", *kPeers}
    if unknown:
        raise ValueError(f"unknown solver(s) {', '.join(sorted(unknown))}: choose from exactgeo, {', '.join(kPeers)}")
    runs: list[WholeExactgeoRun | WholePeerRun] = []
    for count in threads:
        label = f"{count} thread" + ("" if count == 1 else "s")
        if "exactgeo" in names:
            runs.append(WholeExactgeoRun(f"exactgeo-t{count}", f"exactgeo, {label}", True, executable=exactgeo,
                                         build_hint="cmake --build build --target exactgeo_cli", threads=count))
        if baseline is not None and (baseline_threads or count == 1):
            runs.append(WholeExactgeoRun(
                f"baseline-t{count}", f"baseline, {label}" if baseline_threads else "baseline (no --threads)",
                True, executable=baseline, build_hint="--baseline-build", threads=count if baseline_threads else None,
                baseline=True))
    # The peers' names, labels and packages are the other scripts' (make_solvers); only the command differs.
    peers = {peer.name: peer for peer in make_solvers([name for name in kPeers if name in names], Path(), Path())}
    for name in [name for name in kPeers if name in peers]:
        fields = {field.name: getattr(peers[name], field.name) for field in dataclasses.fields(peers[name])}
        runs.append(WholePeerRun(**fields))
    return runs


def configuration(run: WholeExactgeoRun | WholePeerRun) -> dict:
    """What the JSON says of a run, for the reports."""
    is_exactgeo = isinstance(run, WholeExactgeoRun)
    return {"name": run.name, "label": run.label, "exact": run.exact, "build_in_propagation": run.build_in_propagation,
            "kind": ("baseline" if run.baseline else "exactgeo") if is_exactgeo else "peer",
            "threads": run.threads if is_exactgeo else 1}


# ------------------------------------------------------------------------------------------ the steps


def split_wall(run: dict) -> dict[str, float | None]:
    """The steps of one run (a runner outcome: wall_seconds and what read_stats gave): read, build, solve and
    write as the process timed them, None where it has none of its own (gdist builds inside its solve; an
    older exactgeo does not time its write), and start, the rest of the wall time."""
    timed = {"read": run.get("read_seconds"), "build": run.get("build_seconds"),
             "solve": run["propagation_seconds"], "write": run.get("write_seconds")}
    return {"start": run["wall_seconds"] - sum(value for value in timed.values() if value is not None), **timed}


def median_steps(runs: list[dict]) -> dict[str, float | None]:
    """Each step's median over the runs that have it (their "steps"), taken on its own: the medians need not add
    up to the median wall time."""
    medians = {}
    for step in kSteps:
        values = [run["steps"][step] for run in runs if run["steps"][step] is not None]
        medians[step] = statistics.median(values) if values else None
    return medians


def median_build_timings(runs: list[dict]) -> dict[str, float] | None:
    """The build's own steps (build_timings), each its median over the runs that report it, in the order the
    first run gives them; None if no run does."""
    timed = [run["build_timings"] for run in runs if run.get("build_timings")]
    if not timed:
        return None
    names = list(dict.fromkeys(name for timings in timed for name in timings))
    return {name: statistics.median(t[name] for t in timed if name in t) for name in names}


def add_steps(records: list[dict]) -> None:
    """Adds to every record that ran its runs' steps, their medians (`steps`) and the build's own steps'
    (`build_timings`, where the stats have them)."""
    for record in records:
        if record["status"] != "ok":
            continue
        for run in record["runs"]:
            run["steps"] = split_wall(run)
        record["steps"] = median_steps(record["runs"])
        record["build_timings"] = median_build_timings(record["runs"])
        record["build_counts_read"] = record["runs"][0].get("build_counts_read")
