"""Where the numbers came from: the machine, the build, the software versions, the command and its settings.

Every report's JSON opens with these, and its Markdown ends with them: timings mean little without the CPU,
the compiler flags and the load the machine was under.
"""

from __future__ import annotations

import argparse
import datetime
import importlib.metadata
import json
import os
import platform
import shlex
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path

from reports.tables import format_bytes, kGiB, kMissing, runs_text

kRepoRoot = Path(__file__).resolve().parent.parent.parent

# The packages whose versions the process-per-run reports record (the peers and what draws the plots).
kPackages = ["numpy", "matplotlib", "pygeodesic", "tvb-gdist", "libigl", "potpourri3d"]


def first_line(command: list[str]) -> str | None:
    """The first line a command prints, or None if it cannot run or fails."""
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


def software_info() -> dict:
    packages = {}
    for package in kPackages:
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


def setting_text(value):
    """A command-line setting as JSON can hold it: anything but plain data (a path, a configuration) as its
    str()."""
    if isinstance(value, list):
        return [setting_text(item) for item in value]
    if value is None or isinstance(value, (str, int, float, dict)):
        return value
    return str(value)


def command_text(script: str, argv: Sequence[str] | None) -> str:
    """How to repeat the run from the repository root (argv None: this process's own arguments)."""
    return shlex.join(["python3", f"bench/{script}", *(sys.argv[1:] if argv is None else argv)])


def report_header(args: argparse.Namespace, script: str, argv: Sequence[str] | None,
                  launcher_floor_bytes: int) -> dict:
    """Everything about a process-per-run report but its results: settings, machine, build, software, load.

    launcher_floor_bytes: the least peak RSS a run can report (solvers.runner.launcher_floor_bytes)."""
    return {
        "name": args.name,
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "command": command_text(script, argv),
        "settings": {key: setting_text(value) for key, value in vars(args).items()},
        "machine": machine_info(),
        "build": build_info(args.build_dir),
        "software": software_info(),
        "launcher_floor_bytes": launcher_floor_bytes,
        "load_average_at_start": os.getloadavg(),
    }


# -------------------------------------------------------------------------------------- Markdown pieces


def revision_text(software: dict) -> str:
    return software["exactgeo_revision"] or "(no commit)"


def run_line(report: dict, runs_per: str) -> str:
    """The line under a paper-reproduction report's title: when, on what, which commit and command, how many
    runs."""
    machine = report["machine"]
    return (f"{report['date']} · {machine['cpu_model']}, {machine['logical_cores']} logical cores · exactgeo "
            f"{revision_text(report['software'])} · `{report['command']}` · {runs_text(report['settings']['repeat'])} "
            f"per {runs_per}, source vertex 0")


def load_text(load_average: Sequence[float]) -> str:
    return ", ".join(f"{value:.2f}" for value in load_average)


def cpu_text(machine: dict) -> str:
    return (f"CPU: {machine['cpu_model']}, {machine['logical_cores']} logical cores; memory "
            f"{machine['memory_bytes'] / kGiB:.1f} GiB; Linux {machine['kernel']}")


def compiler_text(build: dict) -> str:
    return (f"compiler: {build.get('compiler_version', kMissing)}; build type "
            f"{build.get('CMAKE_BUILD_TYPE', kMissing)}; engine compiled with "
            f"`{build.get('engine_compile_flags', kMissing)}`")


def versions_text(software: dict) -> str:
    return ", ".join(f"{name} {version}" for name, version in software["packages"].items() if version)


def machine_section(report: dict) -> list[str]:
    """The "Machine and software" section of the paper-reproduction reports, with the load at both ends."""
    software = report["software"]
    end_load = load_text(report.get("load_average_at_end", []))
    return [
        "## Machine and software",
        "",
        f"- {cpu_text(report['machine'])}; load average {load_text(report['load_average_at_start'])} at the "
        f"start, {end_load or kMissing} at the end (other work on the machine makes single timings noisy)",
        f"- {compiler_text(report['build'])}",
        f"- exactgeo {revision_text(software)}; Python {software['python']}; "
        f"{versions_text(software)}; CGAL (libcgal-dev) {software['cgal'] or kMissing}",
        f"- peak RSS cannot read below the launcher's {format_bytes(report['launcher_floor_bytes'])}",
        "",
    ]
