"""Benchmark exactgeo against the geodesic solvers users would pick instead; write JSON, Markdown and plots.

Every run of every solver is a separate process started through launch.py, which measures its peak RSS
and enforces the time and memory caps. See bench/README.md for what is measured and how to read it.
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime
import importlib.metadata
import importlib.util
import json
import math
import os
import platform
import shlex
import shutil
import signal
import statistics
import subprocess
import sys
import zlib
from pathlib import Path

import numpy as np

from meshes import BenchMesh, prepare_meshes

kBenchDir = Path(__file__).resolve().parent
kRepoRoot = kBenchDir.parent

# 1-to-4 midpoint subdivisions of the workhorse mesh: 400K and 1.6M faces.
kSubdivided = {"nefertiti-sub1": ("nefertiti", 1), "nefertiti-sub2": ("nefertiti", 2)}
kQuickMeshes = ["beetle", "spot", "rocker-arm", "nefertiti"]

# Growth of run time with face count assumed until a solver has run on two meshes of clearly different
# size; measured exponents are clamped to this range so one noisy small mesh cannot veto a big one.
kDefaultTimeExponent = 1.5
kTimeExponentRange = (1.0, 2.5)
# Predictions are rough: a run predicted to use more than this fraction of a cap is skipped.
kPredictionMargin = 0.75

kGiB = 1024**3

# Solvers that would take hours or more memory than the machine has above these sizes (--max-faces).
kDefaultMaxFaces = {"cgal": 400_000, "libigl": 150_000}


# ---------------------------------------------------------------------------------------------- solvers


@dataclasses.dataclass
class Solver:
    name: str  # key in --solvers, the JSON and the tables
    label: str  # what it is, for the tables
    exact: bool
    build_in_propagation: bool = False  # one call does both: its propagation time includes the mesh build
    size_limit_reason: str = ""  # why it has a default --max-faces, if it has one

    def unavailable_reason(self) -> str | None:
        raise NotImplementedError

    def command(self, mesh: BenchMesh, source: int, distances: Path | None, stats: Path) -> list[str]:
        raise NotImplementedError

    def distances_file(self, run_dir: Path, source: int) -> Path:
        return run_dir / f"s{source}.distances.npy"

    def read_stats(self, stats: Path) -> dict:
        """build_seconds, propagation_seconds and whatever else the solver reports, from its stats file."""
        raise NotImplementedError

    def read_distances(self, path: Path) -> np.ndarray:
        return np.load(path)


@dataclasses.dataclass
class BinarySolver(Solver):
    executable: Path = Path()
    build_hint: str = ""  # how to get the executable

    def unavailable_reason(self):
        if not os.access(self.executable, os.X_OK):
            return f"binary not found: {self.executable} ({self.build_hint})"
        return None


@dataclasses.dataclass
class ExactgeoSolver(BinarySolver):
    def command(self, mesh, source, distances, stats):
        command = [str(self.executable), "distance", str(mesh.obj_path), "--source", str(source)]
        command += ["--stats", str(stats)]
        return command + (["--out", str(distances)] if distances else [])

    def read_stats(self, stats):
        data = json.loads(stats.read_text())
        keys = ["read_seconds", "window_propagations", "peak_windows", "peak_window_bytes", "vertex_pops",
                "pseudo_source_emissions"]
        return {
            "build_seconds": data["build_seconds"],
            "propagation_seconds": data["propagation_seconds"],
            **{key: data[key] for key in keys if key in data},
        }


@dataclasses.dataclass
class CgalSolver(BinarySolver):
    def command(self, mesh, source, distances, stats):
        command = [str(self.executable), str(mesh.obj_path), "--source", str(source), "--repeat", "1"]
        command += ["--stats", str(stats)]
        return command + (["--out", str(distances)] if distances else [])

    def distances_file(self, run_dir, source):
        return run_dir / f"s{source}.distances.txt"

    def read_stats(self, stats):
        data = json.loads(stats.read_text())
        return {"build_seconds": data["build_seconds"][0], "propagation_seconds": data["query_seconds"][0]}

    def read_distances(self, path):
        return np.loadtxt(path, dtype=np.float64, ndmin=1)  # one line per vertex, "inf" where unreachable


@dataclasses.dataclass
class PeerSolver(Solver):
    module: str = ""  # what peer_worker.py imports
    package: str = ""  # the PyPI package that provides it

    def unavailable_reason(self):
        if importlib.util.find_spec(self.module.split(".")[0]) is None:
            return f"{self.package} not installed (pip install -r bench/requirements.txt)"
        return None

    def command(self, mesh, source, distances, stats):
        command = [sys.executable, str(kBenchDir / "peer_worker.py"), "--solver", self.name]
        command += ["--vertices", str(mesh.vertices_path), "--triangles", str(mesh.triangles_path)]
        command += ["--source", str(source), "--stats", str(stats)]
        return command + (["--out", str(distances)] if distances else [])

    def read_stats(self, stats):
        data = json.loads(stats.read_text())
        return {key: data[key] for key in ["build_seconds", "propagation_seconds", "rss_at_start_bytes"]}


def make_solvers(args) -> list[Solver]:
    solvers = [
        ExactgeoSolver("exactgeo", "VTP, the `exactgeo distance` CLI", True,
                       executable=args.exactgeo, build_hint="build with CMake first"),
        CgalSolver("cgal", "CGAL's Surface_mesh_shortest_path (Xin-Wang, ICH family) through bench/cgal_driver.cpp",
                   True, size_limit_reason="it needs ~11 GB at 400K faces and about 4x that at 1.6M",
                   executable=args.cgal_driver, build_hint="built when CMake finds libcgal-dev"),
        PeerSolver("pygeodesic", "Kirsanov's MMP from PyPI pygeodesic", True, module="pygeodesic.geodesic",
                   package="pygeodesic"),
        PeerSolver("gdist", "Kirsanov's MMP from PyPI tvb-gdist", True, build_in_propagation=True,
                   module="gdist", package="tvb-gdist"),
        PeerSolver("libigl", "Kirsanov's MMP inside libigl's exact_geodesic (PyPI libigl), which then traces a "
                   "path back from every vertex to measure it", True, build_in_propagation=True,
                   size_limit_reason="tracing a path to every vertex takes ~70 s at 100K faces, growing ~faces^2",
                   module="igl", package="libigl"),
        PeerSolver("heat", "the heat method from PyPI potpourri3d (approximate)", False, module="potpourri3d",
                   package="potpourri3d"),
    ]
    chosen = [solver for solver in solvers if solver.name in args.solvers]
    unknown = set(args.solvers) - {solver.name for solver in solvers}
    if unknown:
        sys.exit(f"run.py: unknown solver(s) {', '.join(sorted(unknown))}")
    return chosen


# ----------------------------------------------------------------------------------------------- running


def failure(launch: dict, stderr: str, args) -> tuple[str, str] | None:
    """(kind, text) of a failed run; kind "limit" (time or memory) means larger meshes will fail too."""
    if launch["timed_out"]:
        return "limit", f"timed out (> {args.timeout:g} s)"
    memory_words = ("bad_alloc", "MemoryError", "Unable to allocate", "Cannot allocate memory", "out of memory")
    if launch["exit_code"] != 0 and any(word in stderr for word in memory_words):
        return "limit", f"over the memory limit ({args.memory_limit_gb:g} GB)"
    if launch["signal"] == signal.SIGKILL:
        return "limit", "killed (SIGKILL, likely out of memory)"
    if launch["signal"] is not None:
        return "crash", f"crashed ({signal.Signals(launch['signal']).name})"
    if launch["exit_code"] != 0:
        last_line = stderr.strip().splitlines()[-1] if stderr.strip() else ""
        return "error", f"exit code {launch['exit_code']}: {last_line[:160]}"
    return None


def run_once(solver: Solver, mesh: BenchMesh, source: int, repeat: int, run_dir: Path, args) -> dict:
    """One process; the distances are written on the first repeat only."""
    prefix = run_dir / f"s{source}-r{repeat}"
    stats = prefix.with_suffix(".stats.json")
    launch_report = prefix.with_suffix(".launch.json")
    distances = solver.distances_file(run_dir, source) if repeat == 0 else None
    command = solver.command(mesh, source, distances, stats)
    launcher = [sys.executable, "-I", "-S", str(kBenchDir / "launch.py"), str(launch_report),
                str(args.timeout), str(int(args.memory_limit_gb * kGiB)), "--"]
    with open(prefix.with_suffix(".stdout.txt"), "w") as out, open(prefix.with_suffix(".stderr.txt"), "w") as err:
        err.write(shlex.join(command) + "\n")
        err.flush()
        subprocess.run(launcher + command, stdout=out, stderr=err, cwd=run_dir, check=True,
                       timeout=args.timeout + 60)
    launch = json.loads(launch_report.read_text())
    stderr = prefix.with_suffix(".stderr.txt").read_text(errors="replace")
    outcome = {
        "peak_rss_bytes": launch["peak_rss_bytes"],
        "wall_seconds": launch["wall_seconds"],
        "cpu_seconds": launch["user_seconds"] + launch["system_seconds"],
    }
    if failed := failure(launch, stderr, args):
        return {**outcome, "failure_kind": failed[0], "failure": failed[1]}
    try:
        return {**outcome, **solver.read_stats(stats)}
    except (OSError, KeyError, IndexError, ValueError) as error:
        return {**outcome, "failure_kind": "error", "failure": f"unreadable stats {stats.name}: {error}"}


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


def skip_reason(solver: Solver, mesh: BenchMesh, history: SolverHistory, args) -> str | None:
    if (reason := solver.unavailable_reason()) is not None:
        return reason
    max_faces = args.max_faces.get(solver.name)
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
    if predicted_seconds > kPredictionMargin * args.timeout:
        return (f"predicted {predicted_seconds:,.0f} s, near or past the {args.timeout:g} s timeout "
                f"({last.solver_seconds:.3g} s at {last.faces:,} faces, time ~ faces^{exponent:.2f})")
    predicted_bytes = last.peak_rss_bytes * scale
    if predicted_bytes > kPredictionMargin * args.memory_limit_gb * kGiB:
        return (f"predicted {predicted_bytes / kGiB:.1f} GB, near or past the {args.memory_limit_gb:g} GB limit "
                f"({last.peak_rss_bytes / kGiB:.2f} GB at {last.faces:,} faces)")
    return None


def repeats_for(solver: Solver, mesh: BenchMesh, source_rank: int, args) -> int:
    if source_rank > 0:
        return args.repeat_other
    if solver.name == "cgal" and mesh.face_count > args.cgal_once_faces:
        return 1
    return args.repeat


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


def add_errors(records: list[dict], solvers: dict[str, Solver], run_dirs: dict[str, Path]) -> None:
    """Reference: CGAL where it ran (its driver refuses meshes it cannot load as given), else exactgeo."""
    by_solver = {record["solver"]: record for record in records if record["status"] == "ok"}
    reference_name = next((name for name in ("cgal", "exactgeo") if name in by_solver), None)
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


def bench_mesh(mesh: BenchMesh, solvers: list[Solver], histories: dict, args,
               runs_root: Path) -> tuple[list[int], list[dict]]:
    sources = choose_sources(mesh, args.sources, args.seed)
    print(f"\n{mesh.name}: {mesh.vertex_count:,} vertices, {mesh.face_count:,} faces, sources {sources}",
          flush=True)
    skipped = {solver.name: skip_reason(solver, mesh, histories[solver.name], args) for solver in solvers}
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
        # Repeats go round the solvers, so a slow drift in machine load spreads over all of them alike.
        pending = list(active)
        repeat = 0
        while pending:
            for solver in list(pending):
                record = source_records[solver.name]
                outcome = run_once(solver, mesh, source, repeat, run_dirs[solver.name], args)
                record["runs"].append(outcome)
                print(f"  source {source} {solver.name:10} #{repeat + 1}: {describe(outcome)}", flush=True)
                done = len(record["runs"]) >= repeats_for(solver, mesh, rank, args)
                if "failure" in outcome:
                    record["status"], record["reason"] = "failed", outcome["failure"]
                    if outcome["failure_kind"] == "limit":
                        histories[solver.name].fatal = (mesh.name, outcome["failure"])
                    done = True
                elif outcome["wall_seconds"] > args.max_repeat_seconds:
                    done = True  # one long run says enough; repeating it would dominate the whole run
                if done:
                    pending.remove(solver)
            repeat += 1
        for record in source_records.values():
            if record["status"] == "ok":
                summarize(record)
        add_errors(list(source_records.values()), {s.name: s for s in solvers}, run_dirs)
        records.extend(source_records.values())

    for solver in active:
        first = next(r for r in records if r["solver"] == solver.name and r["source_rank"] == 0)
        if first["status"] == "ok":
            solver_seconds = (first["build_seconds"] or 0.0) + first["propagation_seconds"]
            histories[solver.name].finished.append(MeshRun(
                mesh.face_count, solver_seconds, max(first["wall_seconds"] - solver_seconds, 0.0),
                first["peak_rss_bytes"]))
    return sources, records


def describe(outcome: dict) -> str:
    if "failure" in outcome:
        return f"FAILED {outcome['failure']}"
    return (f"build {format_seconds(outcome['build_seconds'])}, "
            f"propagation {format_seconds(outcome['propagation_seconds'])}, "
            f"peak RSS {format_bytes(outcome['peak_rss_bytes'])}")


def launcher_floor_bytes(work_dir: Path) -> int:
    """Peak RSS that launch.py itself passes on to a child: the smallest value any run can report."""
    report = work_dir / "launcher-floor.json"
    subprocess.run([sys.executable, "-I", "-S", str(kBenchDir / "launch.py"), str(report), "10", "0", "--",
                    shutil.which("true")], check=True)
    return json.loads(report.read_text())["peak_rss_bytes"]


# -------------------------------------------------------------------------------------- machine, versions


def first_line(command: list[str]) -> str | None:
    try:
        result = subprocess.run(command, capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        return None
    lines = result.stdout.strip().splitlines()
    return lines[0] if result.returncode == 0 and lines else None


def machine_info() -> dict:
    cpu_model = platform.processor() or None
    with open("/proc/cpuinfo") as cpuinfo:
        for line in cpuinfo:
            if line.startswith("model name"):
                cpu_model = line.split(":", 1)[1].strip()
                break
    memory_bytes = None
    with open("/proc/meminfo") as meminfo:
        for line in meminfo:
            if line.startswith("MemTotal:"):
                memory_bytes = int(line.split()[1]) * 1024
    return {"cpu_model": cpu_model, "logical_cores": os.cpu_count(), "memory_bytes": memory_bytes,
            "kernel": platform.release()}


def build_info(build_dir: Path) -> dict:
    """Compiler and the flags the engine was really compiled with (compile_commands.json)."""
    info: dict = {"build_dir": str(build_dir)}
    cache = build_dir / "CMakeCache.txt"
    if cache.exists():
        for line in cache.read_text(errors="replace").splitlines():
            key, _, value = line.partition("=")
            name = key.split(":", 1)[0]
            if name in ("CMAKE_CXX_COMPILER", "CMAKE_BUILD_TYPE", "CMAKE_CXX_FLAGS"):
                info[name] = value
        if "CMAKE_CXX_COMPILER" in info:
            info["compiler_version"] = first_line([info["CMAKE_CXX_COMPILER"], "--version"])
    commands = build_dir / "compile_commands.json"
    if commands.exists():
        for entry in json.loads(commands.read_text()):
            if entry["file"].endswith("src/propagation.cpp"):
                words = shlex.split(entry.get("command") or shlex.join(entry["arguments"]))
                info["engine_compile_flags"] = " ".join(
                    word for word in words[1:] if word.startswith(("-O", "-f", "-m", "-g", "-std", "-D")))
    return info


def software_info(args) -> dict:
    packages = {}
    for package in ["numpy", "matplotlib", "pygeodesic", "tvb-gdist", "libigl", "potpourri3d"]:
        try:
            packages[package] = importlib.metadata.version(package)
        except importlib.metadata.PackageNotFoundError:
            packages[package] = None
    revision = first_line(["git", "-C", str(kRepoRoot), "rev-parse", "--short", "HEAD"])
    dirty = first_line(["git", "-C", str(kRepoRoot), "status", "--porcelain", "--untracked-files=no"])
    return {
        "python": platform.python_version(),
        "packages": packages,
        "cgal": first_line(["dpkg-query", "-W", "-f", "${Version}", "libcgal-dev"]),
        "exactgeo_revision": (revision + ("-dirty" if dirty else "")) if revision else None,
    }


# ---------------------------------------------------------------------------------------------- reports


def format_seconds(seconds: float | None) -> str:
    if seconds is None:
        return "—"
    if seconds < 1e-3:
        return f"{seconds * 1e6:.3g} µs"
    if seconds < 1:
        return f"{seconds * 1e3:.3g} ms"
    return f"{seconds:.3g} s"


def format_bytes(count: float | None, floor: int = 0) -> str:
    if count is None:
        return "—"
    prefix = "≤ " if count <= floor * 1.05 else ""
    if count < kGiB:
        return f"{prefix}{count / 1024**2:.3g} MB"
    return f"{prefix}{count / kGiB:.3g} GB"


def format_ratio(value: float | None, ours: float | None) -> str:
    if value is None or not ours:
        return "—"
    return f"{value / ours:.3g}x"


def format_error(error: dict | None) -> str:
    if not error:
        return "—"
    if error.get("is_reference"):
        return "reference"
    if "failure" in error:
        return error["failure"]
    relative = error["max_relative_error"]
    return "0" if relative == 0 else f"{relative:.1e}"


def write_markdown(path: Path, report: dict) -> None:
    records, solvers, meshes = report["records"], report["solvers"], report["meshes"]
    machine, build, software, settings = report["machine"], report["build"], report["software"], report["settings"]
    floor = report["launcher_floor_bytes"]
    records_by_key = {(r["mesh"], r["solver"], r["source_rank"]): r for r in records}

    def record(mesh, solver, rank=0):
        return records_by_key.get((mesh, solver, rank))

    def ok(r):
        return r if r and r["status"] == "ok" else None

    def heading(solver):
        return solver["name"] + (" †" if solver["build_in_propagation"] else "")

    load = ", ".join(f"{value:.2f}" for value in report["load_average_at_start"])
    lines = [
        f"# exactgeo benchmark `{report['name']}`",
        "",
        f"{report['date']} · {machine['cpu_model']}, {machine['logical_cores']} logical cores, "
        f"{machine['memory_bytes'] / kGiB:.0f} GiB · load average at start {load} · "
        f"exactgeo {software['exactgeo_revision'] or '(no commit)'} · `{report['command']}`",
        "",
        "## Ratios to exactgeo",
        "",
        f"First source of each mesh (vertex 0), {runs_text(settings['repeat'])}. Each cell is "
        "**propagation time ÷ exactgeo's** · **peak RSS ÷ exactgeo's**, both from this run; above 1x, exactgeo "
        "is faster or smaller.",
        "",
    ]
    others = [solver for solver in solvers if solver["name"] != "exactgeo"]
    lines.append("| mesh | faces | " + " | ".join(heading(solver) for solver in others) + " |")
    lines.append("|---|---:|" + "---:|" * len(others))
    for mesh in meshes:
        ours = ok(record(mesh["name"], "exactgeo"))
        cells = []
        for solver in others:
            theirs = record(mesh["name"], solver["name"])
            if theirs and theirs["status"] != "ok":
                cells.append(theirs["status"])
            elif theirs and ours:
                cells.append(f"{format_ratio(theirs['propagation_seconds'], ours['propagation_seconds'])} · "
                             f"{format_ratio(theirs['peak_rss_bytes'], ours['peak_rss_bytes'])}")
            else:
                cells.append("—")
        lines.append(f"| {mesh['name']} | {mesh['faces']:,} | " + " | ".join(cells) + " |")

    lines += [
        "",
        "## Per mesh and solver, first source",
        "",
        "| mesh | solver | runs | build | propagation | ÷ exactgeo | peak RSS | ÷ exactgeo | window propagations "
        "| peak windows | max error | reachability disagreements | notes |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|",
    ]
    for mesh in meshes:
        ours = ok(record(mesh["name"], "exactgeo"))
        for solver in solvers:
            r = record(mesh["name"], solver["name"])
            if r is None:
                continue
            row = f"| {mesh['name']} ({mesh['faces']:,}) | {heading(solver)} | {len(r['runs'])} "
            if r["status"] != "ok":
                lines.append(row + "| — " * 9 + f"| {r['status']}: {r['reason']} |")
                continue
            stats, error = r["solver_stats"], r.get("error") or {}
            note = ""
            if "rss_at_start_bytes" in stats:
                note = f"{format_bytes(stats['rss_at_start_bytes'])} before the build (Python, numpy, mesh)"
            lines.append(
                row + f"| {format_seconds(r['build_seconds'])} | {format_seconds(r['propagation_seconds'])} "
                f"| {format_ratio(r['propagation_seconds'], ours and ours['propagation_seconds'])} "
                f"| {format_bytes(r['peak_rss_bytes'], floor)} "
                f"| {format_ratio(r['peak_rss_bytes'], ours and ours['peak_rss_bytes'])} "
                f"| {format_count(stats.get('window_propagations'))} | {format_count(stats.get('peak_windows'))} "
                f"| {format_error(error)} | {format_count(error.get('reachability_disagreements'))} | {note} |")

    if settings["sources"] > 1:
        lines += [
            "",
            "## All sources",
            "",
            f"Every source of each mesh ({runs_text(settings['repeat'])} from the first, "
            f"{runs_text(settings['repeat_other'])} from each other): geometric mean and range of the per-source propagation-time ratio to exactgeo, "
            "the worst max error, and the reachability disagreements summed over the sources.",
            "",
            "| mesh | solver | sources | propagation ÷ exactgeo: mean (min–max) | worst max error "
            "| reachability disagreements |",
            "|---|---|---:|---:|---:|---:|",
        ]
        for mesh in meshes:
            for solver in solvers:
                mine = [r for r in records if r["mesh"] == mesh["name"] and r["solver"] == solver["name"]
                        and r["status"] == "ok"]
                if not mine:
                    continue
                ratios = []
                for r in mine:
                    ours = ok(record(mesh["name"], "exactgeo", r["source_rank"]))
                    if ours and ours["propagation_seconds"] and r["propagation_seconds"]:
                        ratios.append(r["propagation_seconds"] / ours["propagation_seconds"])
                ratio_text = "—"
                if ratios:
                    mean = math.exp(sum(math.log(ratio) for ratio in ratios) / len(ratios))
                    ratio_text = f"{mean:.3g}x ({min(ratios):.3g}–{max(ratios):.3g})"
                errors = [r.get("error") or {} for r in mine]
                relative = [e["max_relative_error"] for e in errors if e.get("max_relative_error") is not None]
                if errors and all(e.get("is_reference") for e in errors):
                    worst = "reference"
                else:
                    worst = format_error({"max_relative_error": max(relative)}) if relative else "—"
                disagreements = sum(e.get("reachability_disagreements", 0) for e in errors)
                lines.append(f"| {mesh['name']} | {heading(solver)} | {len(mine)} | {ratio_text} | {worst} "
                             f"| {disagreements:,} |")

    lines += scaling_lines(report)

    versions = ", ".join(f"{name} {version}" for name, version in software["packages"].items() if version)
    lines += ["", "## Solvers", ""]
    lines += [f"- **{solver['name']}**: {solver['label']}." for solver in solvers]
    lines += [
        "",
        "† builds the mesh and propagates in one call: its propagation time includes the mesh build.",
        "",
        "## Machine and software",
        "",
        f"- CPU: {machine['cpu_model']}, {machine['logical_cores']} logical cores; memory "
        f"{machine['memory_bytes'] / kGiB:.1f} GiB; Linux {machine['kernel']}",
        f"- compiler: {build.get('compiler_version', '—')}; build type {build.get('CMAKE_BUILD_TYPE', '—')}; "
        f"engine compiled with `{build.get('engine_compile_flags', '—')}`",
        f"- Python {software['python']}; {versions}; CGAL (libcgal-dev) {software['cgal'] or '—'}",
        f"- caps per run: {settings['timeout']:g} s, {settings['memory_limit_gb']:g} GB of address space; "
        f"peak RSS cannot read below the launcher's {format_bytes(floor)} (values marked ≤ are at that floor)",
        "",
        "bench/README.md says what each column measures and how.",
        "",
    ]
    path.write_text("\n".join(lines))


def log_log_slope(points: list[tuple[float, float]]) -> float | None:
    """Least-squares slope of log(y) against log(x): the exponent k of y ~ x^k."""
    points = [(math.log(x), math.log(y)) for x, y in points if x and y]
    if len(points) < 2:
        return None
    mean_x = sum(x for x, _ in points) / len(points)
    mean_y = sum(y for _, y in points) / len(points)
    spread = sum((x - mean_x) ** 2 for x, _ in points)
    return sum((x - mean_x) * (y - mean_y) for x, y in points) / spread if spread else None


def scaling_lines(report: dict) -> list[str]:
    """How each solver's propagation time and peak RSS grow with the face count, first source of each mesh."""
    faces = {mesh["name"]: mesh["faces"] for mesh in report["meshes"]}
    lines = [
        "",
        "## Scaling",
        "",
        "Exponent k of a least-squares fit `y ~ faces^k` over every mesh a solver finished (first source), and "
        "the meshes it spans. Peak RSS includes each process's fixed start-up (Python and numpy for the peers), "
        "which flattens the memory exponent on small meshes.",
        "",
        "| solver | meshes | faces | time exponent | memory exponent |",
        "|---|---:|---:|---:|---:|",
    ]
    for solver in report["solvers"]:
        mine = [r for r in report["records"] if r["solver"] == solver["name"] and r["source_rank"] == 0
                and r["status"] == "ok" and r["mesh"] in faces]
        if not mine:
            continue
        sizes = sorted(faces[r["mesh"]] for r in mine)
        time_slope = log_log_slope([(faces[r["mesh"]], r["propagation_seconds"]) for r in mine])
        memory_slope = log_log_slope([(faces[r["mesh"]], r["peak_rss_bytes"]) for r in mine])
        text = lambda slope: "—" if slope is None else f"{slope:.2f}"
        lines.append(f"| {solver['name']} | {len(mine)} | {sizes[0]:,}–{sizes[-1]:,} | {text(time_slope)} "
                     f"| {text(memory_slope)} |")

    # One shape at growing resolution: each subdivision has 4x the faces of the mesh before it.
    family = [name for name in ["nefertiti", *kSubdivided] if name in faces]
    if len(family) > 1:
        lines += [
            "",
            "One shape at growing resolution (each mesh has 4x the faces of the one before): propagation time "
            "and peak RSS.",
            "",
            "| solver | " + " | ".join(f"{name} ({faces[name]:,})" for name in family) + " |",
            "|---|" + "---:|" * len(family),
        ]
        for solver in report["solvers"]:
            cells = []
            for name in family:
                r = next((r for r in report["records"] if r["solver"] == solver["name"] and r["mesh"] == name
                          and r["source_rank"] == 0), None)
                ok = r is not None and r["status"] == "ok"
                cells.append(f"{format_seconds(r['propagation_seconds'])} · {format_bytes(r['peak_rss_bytes'])}"
                             if ok else (r["status"] if r else "—"))
            lines.append(f"| {solver['name']} | " + " | ".join(cells) + " |")
    return lines


def runs_text(count: int) -> str:
    return "1 run" if count == 1 else f"median of {count} runs"


def format_count(value) -> str:
    return "—" if value is None else f"{value:,}"


def write_plots(results_dir: Path, report: dict) -> list[Path]:
    """Log-log, one line per solver through its first-source medians; the approximate solver dashed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter, NullFormatter

    def face_count_text(value, _):
        for factor, suffix in [(1e6, "M"), (1e3, "K")]:
            if value >= factor:
                return f"{value / factor:g}{suffix}"
        return f"{value:g}"

    plots = []
    # (record key, what it is, unit the values are plotted in, tick label)
    quantities = [("propagation_seconds", "propagation time", 1, format_seconds),
                  ("peak_rss_bytes", "peak RSS", 1024**2, lambda megabytes: f"{megabytes:g} MB")]
    for key, quantity, unit, format_value in quantities:
        figure, axes = plt.subplots(figsize=(8, 5.5))
        for solver in report["solvers"]:
            points = sorted((r["faces"], r[key]) for r in report["records"]
                            if r["solver"] == solver["name"] and r["source_rank"] == 0 and r["status"] == "ok"
                            and r.get(key))
            if points:
                faces = [face_count for face_count, _ in points]
                values = [value / unit for _, value in points]
                axes.plot(faces, values, marker="o", linestyle="-" if solver["exact"] else "--",
                          label=solver["name"])
        axes.set_xscale("log")
        axes.set_yscale("log")
        axes.xaxis.set_major_formatter(FuncFormatter(face_count_text))
        axes.yaxis.set_major_formatter(FuncFormatter(lambda value, _: format_value(value)))
        for axis in (axes.xaxis, axes.yaxis):
            axis.set_minor_formatter(NullFormatter())
        axes.set_xlabel("faces")
        axes.set_ylabel(f"{quantity} (median of runs)")
        axes.set_title(f"{quantity} vs faces, first source of each mesh ({report['name']})")
        axes.grid(True, which="both", alpha=0.3)
        axes.legend()
        path = results_dir / f"{report['name']}-{'time' if key == 'propagation_seconds' else 'memory'}.png"
        plots.append(save_figure(figure, path, dpi=110))
    return plots


def save_figure(figure, path: Path, dpi: int = 100) -> Path:
    """Lays out, writes and closes a matplotlib figure; returns the path."""
    import matplotlib.pyplot as plt
    figure.tight_layout()
    figure.savefig(path, dpi=dpi)
    plt.close(figure)
    return path


# ------------------------------------------------------------------------------------------------- main


def parse_args(argv=None):
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true",
                        help=f"meshes {', '.join(kQuickMeshes)}; 1 source; 3 runs; 60 s timeout")
    parser.add_argument("--name", help="results file stem (default: quick or full)")
    parser.add_argument("--meshes", nargs="+", help="mesh names to run (default: all, or the quick set)")
    parser.add_argument("--solvers", nargs="+", default=["exactgeo", "cgal", "pygeodesic", "gdist", "libigl", "heat"],
                        help="solvers to run (default: all)")
    parser.add_argument("--sources", type=int,
                        help="sources per mesh: vertex 0 plus seeded random ones (default 3; quick 1)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the random sources (default 1)")
    parser.add_argument("--repeat", type=int, help="runs per solver from the first source; median reported "
                        "(default 5; quick 3)")
    parser.add_argument("--repeat-other", type=int, default=1,
                        help="runs per solver from the other sources (default 1)")
    parser.add_argument("--max-repeat-seconds", type=float, default=60.0,
                        help="a run longer than this is not repeated (default 60)")
    parser.add_argument("--timeout", type=float, help="seconds per run (default 600; quick 60)")
    parser.add_argument("--memory-limit-gb", type=float,
                        help="address-space limit per run (default: 3/4 of the machine's memory)")
    parser.add_argument("--max-faces", nargs="+", default=[], metavar="SOLVER=N",
                        help="skip SOLVER on meshes with more than N faces (0: no limit); defaults: "
                        + ", ".join(f"{name}={count}" for name, count in kDefaultMaxFaces.items()))
    parser.add_argument("--cgal-once-faces", type=int, default=150_000,
                        help="CGAL runs once (not --repeat times) on meshes above this many faces (default 150000)")
    parser.add_argument("--mesh-dir", type=Path, default=kRepoRoot.parent / "shared" / "meshes",
                        help="the shared OBJ meshes (default: ../shared/meshes beside the repository)")
    parser.add_argument("--build-dir", type=Path, default=kRepoRoot / "build",
                        help="CMake build holding the binaries (default: build/)")
    parser.add_argument("--exactgeo", type=Path, help="exactgeo CLI (default: BUILD_DIR/cli/exactgeo)")
    parser.add_argument("--cgal-driver", type=Path,
                        help="CGAL driver (default: BUILD_DIR/bench/exactgeo_cgal_driver)")
    parser.add_argument("--work-dir", type=Path, default=kBenchDir / "work",
                        help="generated meshes and per-run files (default: bench/work/)")
    parser.add_argument("--results-dir", type=Path, default=kBenchDir / "results",
                        help="where NAME.json, NAME.md and the plots go (default: bench/results/)")
    args = parser.parse_args(argv)

    quick = args.quick
    args.name = args.name or ("quick" if quick else "full")
    args.sources = args.sources or (1 if quick else 3)
    args.repeat = args.repeat or (3 if quick else 5)
    args.timeout = args.timeout or (60.0 if quick else 600.0)
    if args.memory_limit_gb is None:
        args.memory_limit_gb = round(0.75 * machine_info()["memory_bytes"] / kGiB, 1)
    # Runs start in their own directories: every path must survive a change of working directory.
    for key in ("build_dir", "mesh_dir", "work_dir", "results_dir"):
        setattr(args, key, getattr(args, key).resolve())
    args.exactgeo = (args.exactgeo or args.build_dir / "cli" / "exactgeo").resolve()
    args.cgal_driver = (args.cgal_driver or args.build_dir / "bench" / "exactgeo_cgal_driver").resolve()
    max_faces = dict(kDefaultMaxFaces)
    for item in args.max_faces:
        name, _, count = item.partition("=")
        if not count.isdigit():
            parser.error(f"--max-faces {item}: expected SOLVER=N")
        max_faces[name] = int(count) or None
    args.max_faces = max_faces
    if quick and not args.meshes:
        args.meshes = kQuickMeshes
    return args


def select_meshes(args, subdivided_specs: dict, script: str) -> list:
    """The shared meshes and the subdivisions in subdivided_specs, prepared, limited to args.meshes if given."""
    subdivided = {name: spec for name, spec in subdivided_specs.items() if not args.meshes or name in args.meshes}
    meshes = prepare_meshes(args.mesh_dir, args.work_dir, subdivided)
    if not args.meshes:
        return meshes
    unknown = set(args.meshes) - {mesh.name for mesh in meshes}
    if unknown:
        sys.exit(f"{script}: no mesh named {', '.join(sorted(unknown))} in {args.mesh_dir}")
    return [mesh for mesh in meshes if mesh.name in args.meshes]


def main(argv=None) -> None:
    args = parse_args(argv)
    solvers = make_solvers(args)
    if importlib.util.find_spec("matplotlib") is None:
        sys.exit("run.py: matplotlib is needed for the plots (pip install -r bench/requirements.txt)")
    if not args.mesh_dir.is_dir():
        sys.exit(f"run.py: mesh directory {args.mesh_dir} not found (--mesh-dir)")
    print(f"preparing meshes in {args.work_dir / 'meshes'}", flush=True)
    meshes = select_meshes(args, kSubdivided, "run.py")

    runs_root = args.work_dir / "runs" / args.name
    shutil.rmtree(runs_root, ignore_errors=True)
    args.results_dir.mkdir(parents=True, exist_ok=True)
    settings = {key: (str(value) if isinstance(value, Path) else value) for key, value in vars(args).items()}
    report = {
        "name": args.name,
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "command": shlex.join(["python3", "bench/run.py"] + (sys.argv[1:] if argv is None else argv)),
        "settings": settings,
        "machine": machine_info(),
        "build": build_info(args.build_dir),
        "software": software_info(args),
        "launcher_floor_bytes": launcher_floor_bytes(args.work_dir),
        "load_average_at_start": os.getloadavg(),
        "solvers": [{"name": s.name, "label": s.label, "exact": s.exact,
                     "build_in_propagation": s.build_in_propagation} for s in solvers],
        "meshes": [],
        "records": [],
    }
    json_path = args.results_dir / f"{args.name}.json"
    histories = {solver.name: SolverHistory() for solver in solvers}
    try:
        for mesh in meshes:
            sources, records = bench_mesh(mesh, solvers, histories, args, runs_root)
            report["meshes"].append({"name": mesh.name, "path": os.path.relpath(mesh.obj_path, kRepoRoot),
                                     "vertices": mesh.vertex_count, "faces": mesh.face_count, "sources": sources})
            report["records"].extend(records)
            json_path.write_text(json.dumps(report, indent=1))
    except KeyboardInterrupt:
        print("\ninterrupted: writing the results so far", flush=True)
        report["interrupted"] = True
    report["load_average_at_end"] = os.getloadavg()
    json_path.write_text(json.dumps(report, indent=1))
    markdown_path = args.results_dir / f"{args.name}.md"
    write_markdown(markdown_path, report)
    plots = write_plots(args.results_dir, report)
    print(f"\nwrote {json_path}, {markdown_path}, " + ", ".join(str(p) for p in plots))


if __name__ == "__main__":
    main()
