"""Runs the solvers of commands.py one process at a time and keeps what each run measured.

Every run is its own process started through launch.py, which caps its time and address space and reads its
peak RSS (see launch.py for why a separate launcher). Repeats go round the solvers, a solver is skipped where
its earlier runs predict it would pass a cap, and each record gets the medians over its repeats and its error
against a reference solver's distances. The records are plain dicts: they go into the JSON as they are.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import shlex
import shutil
import signal
import statistics
import subprocess
import sys
import zlib
from pathlib import Path

import numpy as np

from meshes import BenchMesh
from reports.tables import format_bytes, format_seconds, kGiB
from solvers.commands import Solver, VariantSolver, kBenchDir, kReference

# Growth of run time with face count assumed until a solver has run on two meshes of clearly different
# size; measured exponents are clamped to this range so one noisy small mesh cannot veto a big one.
kDefaultTimeExponent = 1.5
kTimeExponentRange = (1.0, 2.5)
# Predictions are rough: a run predicted to use more than this fraction of a cap is skipped.
kPredictionMargin = 0.75

# Solvers that would take hours or more memory than the machine has above these sizes (--max-faces).
kDefaultMaxFaces = {"cgal": 400_000, "libigl": 150_000}

# Two runs agree when their distances differ by no more than this, relative to the largest distance.
kExactTolerance = 1e-9


def default_memory_limit_gb() -> float:
    """3/4 of the machine's memory: a run over that would push the machine into swap, not measure anything."""
    return round(0.75 * os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE") / kGiB, 1)


def default_threads() -> list[int]:
    """1, 2 and every core: one thread, the smallest parallel run, and what the machine offers."""
    return sorted({1, 2, os.cpu_count() or 1})


def add_build_and_folder_options(parser, exactgeo_option: bool = False) -> None:
    """The options the command-line benches share: which builds run (--build-dir, with --exactgeo if asked,
    and a baseline) and the folders they read and write."""
    bench_dir = Path(__file__).resolve().parent.parent
    repo_root = bench_dir.parent
    parser.add_argument("--build-dir", type=Path, default=repo_root / "build",
                        help="CMake build holding the command (default: build/)")
    if exactgeo_option:
        parser.add_argument("--exactgeo", type=Path, help="exactgeo CLI (default: BUILD_DIR/cli/exactgeo)")
    parser.add_argument("--baseline-build", type=Path, help="build folder of an earlier commit, run beside it")
    parser.add_argument("--baseline-name", default="", help="what the baseline is (its commit), for the report")
    parser.add_argument("--mesh-dir", type=Path, default=repo_root.parent / "shared" / "meshes",
                        help="the shared OBJ meshes (default: ../shared/meshes beside the repository)")
    parser.add_argument("--work-dir", type=Path, default=bench_dir / "work",
                        help="generated meshes and per-run files (default: bench/work/)")
    parser.add_argument("--results-dir", type=Path, default=bench_dir / "results",
                        help="where NAME.json and NAME.md go (default: bench/results/)")


@dataclasses.dataclass
class RunSettings:
    """How many runs, from which sources, under which caps (the runner's part of a script's options)."""

    repeat: int  # runs from the first source; their median is reported
    timeout: float  # seconds per run
    max_repeat_seconds: float  # a run longer than this is not repeated
    memory_limit_gb: float = dataclasses.field(default_factory=default_memory_limit_gb)  # address space per run
    sources: int = 1  # per mesh: vertex 0 plus seeded random ones
    seed: int = 1
    repeat_other: int = 1  # runs from each other source
    cgal_once_faces: int = 150_000  # CGAL runs once on meshes above this many faces
    # Skip a solver on meshes over this many faces (None: no limit).
    max_faces: dict[str, int | None] = dataclasses.field(default_factory=lambda: dict(kDefaultMaxFaces))
    # Whose distances the others' errors are against: the first of these that ran.
    reference_solvers: tuple[str, ...] = ("cgal", "exactgeo")


# ------------------------------------------------------------------------------------------ one process


def failure(launch: dict, stderr: str, settings: RunSettings) -> tuple[str, str] | None:
    """(kind, text) of a failed run; kind "limit" (time or memory) means larger meshes will fail too."""
    if launch["timed_out"]:
        return "limit", f"timed out (> {settings.timeout:g} s)"
    memory_words = ("bad_alloc", "MemoryError", "Unable to allocate", "Cannot allocate memory", "out of memory")
    if launch["exit_code"] != 0 and any(word in stderr for word in memory_words):
        return "limit", f"over the memory limit ({settings.memory_limit_gb:g} GB)"
    if launch["signal"] == signal.SIGKILL:
        return "limit", "killed (SIGKILL, likely out of memory)"
    if launch["signal"] is not None:
        return "crash", f"crashed ({signal.Signals(launch['signal']).name})"
    if launch["exit_code"] != 0:
        last_line = stderr.strip().splitlines()[-1] if stderr.strip() else ""
        return "error", f"exit code {launch['exit_code']}: {last_line[:160]}"
    return None


def run_once(solver: Solver, mesh: BenchMesh, source: int, repeat: int, run_dir: Path,
             settings: RunSettings) -> dict:
    """One process; the distances are written on the first repeat only."""
    prefix = run_dir / f"s{source}-r{repeat}"
    stats = prefix.with_suffix(".stats.json")
    launch_report = prefix.with_suffix(".launch.json")
    distances = solver.distances_file(run_dir, source) if repeat == 0 else None
    command = solver.command(mesh, source, distances, stats)
    launcher = [sys.executable, "-I", "-S", str(kBenchDir / "launch.py"), str(launch_report),
                str(settings.timeout), str(int(settings.memory_limit_gb * kGiB)), "--"]
    with open(prefix.with_suffix(".stdout.txt"), "w") as out, open(prefix.with_suffix(".stderr.txt"), "w") as err:
        err.write(shlex.join(command) + "\n")
        err.flush()
        subprocess.run(launcher + command, stdout=out, stderr=err, cwd=run_dir, check=True,
                       timeout=settings.timeout + 60)
    launch = json.loads(launch_report.read_text())
    stderr = prefix.with_suffix(".stderr.txt").read_text(errors="replace")
    outcome = {
        "peak_rss_bytes": launch["peak_rss_bytes"],
        "wall_seconds": launch["wall_seconds"],
        "cpu_seconds": launch["user_seconds"] + launch["system_seconds"],
    }
    if failed := failure(launch, stderr, settings):
        return {**outcome, "failure_kind": failed[0], "failure": failed[1]}
    try:
        return {**outcome, **solver.read_stats(stats)}
    except (OSError, KeyError, IndexError, ValueError) as error:
        return {**outcome, "failure_kind": "error", "failure": f"unreadable stats {stats.name}: {error}"}


def launcher_floor_bytes(work_dir: Path) -> int:
    """Peak RSS that launch.py itself passes on to a child: the smallest value any run can report."""
    work_dir.mkdir(parents=True, exist_ok=True)
    report = work_dir / "launcher-floor.json"
    subprocess.run([sys.executable, "-I", "-S", str(kBenchDir / "launch.py"), str(report), "10", "0", "--",
                    shutil.which("true")], check=True)
    return json.loads(report.read_text())["peak_rss_bytes"]


def describe(outcome: dict) -> str:
    """One run, for the progress lines."""
    if "failure" in outcome:
        return f"FAILED {outcome['failure']}"
    return (f"build {format_seconds(outcome['build_seconds'])}, "
            f"propagation {format_seconds(outcome['propagation_seconds'])}, "
            f"peak RSS {format_bytes(outcome['peak_rss_bytes'])}")


# ------------------------------------------------------------------------------------- which runs to make


def choose_sources(mesh: BenchMesh, count: int, seed: int) -> list[int]:
    """Vertex 0 (or the first vertex a face uses) plus seeded random vertices used by a proper triangle."""
    triangles = np.load(mesh.triangles_path)
    proper = triangles[(triangles[:, 0] != triangles[:, 1]) & (triangles[:, 1] != triangles[:, 2])
                       & (triangles[:, 2] != triangles[:, 0])]
    used = np.unique(proper)
    first = int(used[0])
    rng = np.random.default_rng([seed, zlib.crc32(mesh.name.encode())])
    others = rng.choice(used[used != first], size=min(count - 1, len(used) - 1), replace=False)
    return [first] + [int(vertex) for vertex in others]


@dataclasses.dataclass
class MeshRun:
    """One mesh a solver finished, from the first source: what predicts its cost on larger meshes."""

    faces: int
    solver_seconds: float  # build + propagation as the solver reports them
    overhead_seconds: float  # the rest of the process's wall time: start-up, loading, writing
    peak_rss_bytes: int


@dataclasses.dataclass
class SolverHistory:
    finished: list[MeshRun] = dataclasses.field(default_factory=list)  # in increasing face count
    fatal: tuple[str, str] | None = None  # (mesh, reason) of a timeout or memory failure


def skip_reason(solver: Solver, mesh: BenchMesh, history: SolverHistory, settings: RunSettings) -> str | None:
    if (reason := solver.unavailable_reason()) is not None:
        return reason
    max_faces = settings.max_faces.get(solver.name)
    if max_faces is not None and mesh.face_count > max_faces:
        why = f": {solver.size_limit_reason}" if solver.size_limit_reason else ""
        return f"runs only up to {max_faces:,} faces{why} (--max-faces {solver.name}=N)"
    if history.fatal:
        return f"{history.fatal[1]} on smaller mesh {history.fatal[0]}"
    if not history.finished:
        return None
    last = history.finished[-1]
    exponent = kDefaultTimeExponent
    half_size = [run for run in history.finished if run.faces * 2 <= last.faces and run.solver_seconds > 0.05]
    if half_size and last.solver_seconds > 0.05:
        earlier = half_size[-1]
        exponent = math.log(last.solver_seconds / earlier.solver_seconds) / math.log(last.faces / earlier.faces)
        exponent = min(max(exponent, kTimeExponentRange[0]), kTimeExponentRange[1])
    scale = mesh.face_count / last.faces
    predicted_seconds = last.overhead_seconds + last.solver_seconds * scale**exponent
    if predicted_seconds > kPredictionMargin * settings.timeout:
        return (f"predicted {predicted_seconds:,.0f} s, near or past the {settings.timeout:g} s timeout "
                f"({last.solver_seconds:.3g} s at {last.faces:,} faces, time ~ faces^{exponent:.2f})")
    predicted_bytes = last.peak_rss_bytes * scale
    if predicted_bytes > kPredictionMargin * settings.memory_limit_gb * kGiB:
        return (f"predicted {predicted_bytes / kGiB:.1f} GB, near or past the {settings.memory_limit_gb:g} GB "
                f"limit ({last.peak_rss_bytes / kGiB:.2f} GB at {last.faces:,} faces)")
    return None


def repeats_for(solver: Solver, mesh: BenchMesh, source_rank: int, settings: RunSettings) -> int:
    if source_rank > 0:
        return settings.repeat_other
    if solver.name == "cgal" and mesh.face_count > settings.cgal_once_faces:
        return 1
    return settings.repeat


# --------------------------------------------------------------------------------- what the runs measured


def summarize(record: dict) -> None:
    """Medians over the repeats; solver statistics and the run's distances come from the first repeat."""
    runs = record["runs"]
    for key in ["build_seconds", "propagation_seconds", "peak_rss_bytes", "wall_seconds"]:
        values = [run[key] for run in runs if run.get(key) is not None]
        record[key] = statistics.median(values) if values else None
    skip = {"build_seconds", "propagation_seconds", "peak_rss_bytes", "wall_seconds", "cpu_seconds"}
    record["solver_stats"] = {key: value for key, value in runs[0].items() if key not in skip}


def error_against(distances: np.ndarray, reference: np.ndarray) -> dict:
    """Max |d - ref| over vertices finite in both, relative to the largest finite reference distance."""
    if distances.shape != reference.shape:
        return {"failure": f"{distances.size} distances for {reference.size} vertices"}
    finite = np.isfinite(distances) & np.isfinite(reference)
    scale = float(reference[np.isfinite(reference)].max(initial=0.0))
    max_absolute = float(np.abs(distances[finite] - reference[finite]).max(initial=0.0))
    return {
        "max_absolute_error": max_absolute,
        "max_relative_error": max_absolute / scale if scale > 0 else None,
        "reachability_disagreements": int(np.count_nonzero(np.isfinite(distances) != np.isfinite(reference))),
        "compared_vertices": int(np.count_nonzero(finite)),
    }


def add_errors(records: list[dict], solvers: dict[str, Solver], run_dirs: dict[str, Path],
               reference_solvers: tuple[str, ...] = ("cgal", "exactgeo")) -> None:
    """Reference: the first of reference_solvers that ran. By default CGAL where it ran (its driver refuses
    meshes it cannot load as given), else exactgeo."""
    by_solver = {record["solver"]: record for record in records if record["status"] == "ok"}
    reference_name = next((name for name in reference_solvers if name in by_solver), None)
    if reference_name is None:
        return

    def load(name, record):
        path = solvers[name].distances_file(run_dirs[name], record["source"])
        return solvers[name].read_distances(path)

    try:
        reference = load(reference_name, by_solver[reference_name])
    except (OSError, ValueError) as error:
        for record in by_solver.values():
            record["error"] = {"reference": reference_name, "failure": f"reference unreadable: {error}"}
        return
    for name, record in by_solver.items():
        if name == reference_name:
            record["error"] = {"reference": reference_name, "is_reference": True}
            continue
        try:
            record["error"] = {"reference": reference_name, **error_against(load(name, record), reference)}
        except (OSError, ValueError) as error:
            record["error"] = {"reference": reference_name, "failure": f"distances unreadable: {error}"}


# ------------------------------------------------------------------------------------------------ a mesh


def bench_mesh(mesh: BenchMesh, solvers: list[Solver], histories: dict[str, SolverHistory], settings: RunSettings,
               runs_root: Path) -> tuple[list[int], list[dict]]:
    """Every solver from each source of the mesh; returns the sources and one record per solver and source.

    `histories` (per solver name) carries what earlier, smaller meshes said, and is updated here."""
    sources = choose_sources(mesh, settings.sources, settings.seed)
    print(f"\n{mesh.name}: {mesh.vertex_count:,} vertices, {mesh.face_count:,} faces, sources {sources}",
          flush=True)
    skipped = {solver.name: skip_reason(solver, mesh, histories[solver.name], settings) for solver in solvers}
    for name, reason in skipped.items():
        if reason:
            print(f"  {name}: skipped ({reason})", flush=True)
    active = [solver for solver in solvers if not skipped[solver.name]]
    run_dirs = {solver.name: runs_root / mesh.name / solver.name for solver in solvers}
    for run_dir in run_dirs.values():
        run_dir.mkdir(parents=True, exist_ok=True)

    records = []
    for rank, source in enumerate(sources):
        source_records = {
            solver.name: {"mesh": mesh.name, "faces": mesh.face_count, "vertices": mesh.vertex_count,
                          "solver": solver.name, "source": source, "source_rank": rank,
                          "status": "skipped" if skipped[solver.name] else "ok",
                          "reason": skipped[solver.name], "runs": []}
            for solver in solvers
        }
        # Repeats go round the solvers, so a slow drift in machine load spreads over all of them alike, every
        # other round in reverse order: on a virtual machine whose host takes freed memory back, a process that
        # starts right after another one freed its memory finds pages the host still backs and runs faster
        # (docs/performance.md), so no solver should always follow the same one.
        pending = list(active)
        repeat = 0
        while pending:
            for solver in list(pending) if repeat % 2 == 0 else list(reversed(pending)):
                record = source_records[solver.name]
                outcome = run_once(solver, mesh, source, repeat, run_dirs[solver.name], settings)
                record["runs"].append(outcome)
                print(f"  source {source} {solver.name:10} #{repeat + 1}: {describe(outcome)}", flush=True)
                done = len(record["runs"]) >= repeats_for(solver, mesh, rank, settings)
                if "failure" in outcome:
                    record["status"], record["reason"] = "failed", outcome["failure"]
                    if outcome["failure_kind"] == "limit":
                        histories[solver.name].fatal = (mesh.name, outcome["failure"])
                    done = True
                elif outcome["wall_seconds"] > settings.max_repeat_seconds:
                    done = True  # one long run says enough; repeating it would dominate the whole run
                if done:
                    pending.remove(solver)
            repeat += 1
        for record in source_records.values():
            if record["status"] == "ok":
                summarize(record)
        add_errors(list(source_records.values()), {s.name: s for s in solvers}, run_dirs, settings.reference_solvers)
        records.extend(source_records.values())

    for solver in active:
        first = next(r for r in records if r["solver"] == solver.name and r["source_rank"] == 0)
        if first["status"] == "ok":
            solver_seconds = (first["build_seconds"] or 0.0) + first["propagation_seconds"]
            histories[solver.name].finished.append(MeshRun(
                mesh.face_count, solver_seconds, max(first["wall_seconds"] - solver_seconds, 0.0),
                first["peak_rss_bytes"]))
    return sources, records


# ------------------------------------------------------------------------ exactgeo's variants, cross-checked


def bench_variants(mesh: BenchMesh, solvers: list[Solver], timer_solvers: list[VariantSolver],
                   settings: RunSettings, runs_root: Path,
                   histories: dict[str, SolverHistory]) -> tuple[list[dict], list[dict]]:
    """Timed runs (settings.repeat each, round the solvers) and then one run of each variant with its timers on.

    Returns the records of both, as bench_mesh makes them, each with the exactness check added."""
    timed = bench_mesh(mesh, solvers, histories, settings, runs_root)[1]
    timed_once = bench_mesh(mesh, timer_solvers, histories, dataclasses.replace(settings, repeat=1),
                            runs_root)[1] if timer_solvers else []
    everything = {s.name: s for s in [*solvers, *timer_solvers]}
    check_exactness(timed + timed_once, everything, runs_root / mesh.name)
    return timed, timed_once


def check_exactness(records: list[dict], solvers: dict[str, Solver], mesh_dir: Path) -> None:
    """Adds `exactness` to every run record: its distances against default VTP's. Only our variants are
    judged (`agrees`); for the other solvers the difference is information."""
    reference_record = next((r for r in records if r["solver"] == kReference and r["status"] == "ok"), None)

    def distances(record):
        solver = solvers[record["solver"]]
        return solver.read_distances(solver.distances_file(mesh_dir / record["solver"], record["source"]))

    for record in records:
        if record["status"] == "skipped":
            continue
        if record["status"] != "ok":
            difference = {"failure": record["reason"]}
        elif reference_record is None:
            difference = {"failure": f"no {kReference} distances to compare with"}
        else:
            try:
                difference = error_against(distances(record), distances(reference_record))
            except (OSError, ValueError) as error:
                difference = {"failure": f"distances unreadable: {error}"}
        agrees = ("failure" not in difference and difference["reachability_disagreements"] == 0
                  and (difference["max_relative_error"] or 0.0) <= kExactTolerance)
        judged = isinstance(solvers[record["solver"]], VariantSolver)
        record["exactness"] = {**difference, "agrees": agrees, "judged": judged}


def exactness_failures(records: list[dict]) -> list[str]:
    """'mesh solver: what' for every variant run whose distances disagree with VTP's, or that failed."""
    failures = []
    for record in records:
        check = record.get("exactness")
        if check and check["judged"] and not check["agrees"]:
            what = check.get("failure") or (f"max relative difference {check['max_relative_error']:.2e}, "
                                            f"{check['reachability_disagreements']} reachability disagreements")
            failures.append(f"{record['mesh']} {record['solver']}: {what}")
    return failures


def exactness_exit_status(records: list[dict]) -> int:
    """Prints every exactness failure; 1 if there was any (the paper scripts' exit status), else 0."""
    failures = exactness_failures(records)
    for failure in failures:
        print(f"EXACTNESS MISMATCH: {failure}", file=sys.stderr)
    return 1 if failures else 0
