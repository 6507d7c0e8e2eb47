"""How each solver is started as its own process and how what it wrote reads back.

The peers: the exactgeo CLI, the CGAL driver (cgal_driver.cpp) and the Python packages through
peer_worker.py; and exactgeo's algorithm variants with their pruning rules on or off (the paper scripts).
runner.py runs these commands; nothing here starts a process but missing_cli_options' `--help`.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import json
import os
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import ClassVar

import numpy as np

from meshes import BenchMesh

kBenchDir = Path(__file__).resolve().parent.parent

# Every peer, in the order the reports list them.
kSolverNames = ["exactgeo", "cgal", "pygeodesic", "gdist", "libigl", "heat"]


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
    # What the reports use of `exactgeo distance --stats`, besides the build and propagation times.
    stats_keys: ClassVar[list[str]] = ["read_seconds", "window_propagations", "peak_windows", "peak_window_bytes",
                                       "vertex_pops", "pseudo_source_emissions"]

    def command(self, mesh, source, distances, stats):
        # One thread, as every peer and every variant runs: the command's default shares a run among the cores
        # from 20,000 faces on. threads.py measures the threads.
        command = [str(self.executable), "distance", str(mesh.obj_path), "--source", str(source), "--threads", "1"]
        command += ["--stats", str(stats)]
        return command + (["--out", str(distances)] if distances else [])

    def read_stats(self, stats):
        data = json.loads(stats.read_text())
        return {
            "build_seconds": data["build_seconds"],
            "propagation_seconds": data["propagation_seconds"],
            **{key: data[key] for key in self.stats_keys if key in data},
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
    # What the reports use of peer_worker.py's stats.
    stats_keys: ClassVar[list[str]] = ["build_seconds", "propagation_seconds", "rss_at_start_bytes"]

    module: str = ""  # what peer_worker.py imports
    package: str = ""  # the PyPI package that provides it

    def unavailable_reason(self):
        if importlib.util.find_spec(self.module.split(".")[0]) is None:
            return f"{self.package} not installed (pip install -r bench/requirements.txt)"
        return None

    def mesh_arguments(self, mesh: BenchMesh) -> list[str]:
        """How peer_worker.py gets the mesh: the arrays bench/meshes.py made, loaded before its clocks start."""
        return ["--vertices", str(mesh.vertices_path), "--triangles", str(mesh.triangles_path)]

    def command(self, mesh, source, distances, stats):
        command = [sys.executable, str(kBenchDir / "peer_worker.py"), "--solver", self.name]
        command += self.mesh_arguments(mesh) + ["--source", str(source), "--stats", str(stats)]
        return command + (["--out", str(distances)] if distances else [])

    def read_stats(self, stats):
        data = json.loads(stats.read_text())
        return {key: data[key] for key in self.stats_keys}


def make_solvers(names: list[str], exactgeo: Path, cgal_driver: Path) -> list[Solver]:
    """The named peers (kSolverNames), in that order; ValueError for a name that is none of them."""
    solvers = [
        ExactgeoSolver("exactgeo", "VTP, the `exactgeo distance` CLI", True,
                       executable=exactgeo, build_hint="build with CMake first"),
        CgalSolver("cgal", "CGAL's Surface_mesh_shortest_path (Xin-Wang, ICH family) through bench/cgal_driver.cpp",
                   True, size_limit_reason="it needs ~11 GB at 400K faces and about 4x that at 1.6M",
                   executable=cgal_driver, build_hint="built when CMake finds libcgal-dev"),
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
    unknown = set(names) - {solver.name for solver in solvers}
    if unknown:
        raise ValueError(f"unknown solver(s) {', '.join(sorted(unknown))}")
    return [solver for solver in solvers if solver.name in names]


# ------------------------------------------------------------------------------ exactgeo's own variants

kAlgorithms = ["vtp", "opvtp", "ftp", "opftp"]
kAlgorithmLabels = {"vtp": "VTP", "opvtp": "OPVTP", "ftp": "FTP", "opftp": "OPFTP"}
kReference = "vtp"  # the paper's final algorithm: ratios, savings and the exactness check are against it


@dataclasses.dataclass(frozen=True)
class Configuration:
    """One algorithm variant with its pruning rules on or off."""

    algorithm: str
    rule1: bool = True
    rule23: bool = True

    @property
    def name(self) -> str:
        return self.algorithm + ("" if self.rule1 else "-no-rule1") + ("" if self.rule23 else "-no-rule23")

    @property
    def label(self) -> str:
        off = [rule for rule, on in (("Rule 1", self.rule1), ("Rules 2+3", self.rule23)) if not on]
        return kAlgorithmLabels[self.algorithm] + (" without " + " and ".join(off) if off else "")

    @property
    def flags(self) -> list[str]:
        return (["--algorithm", self.algorithm] + ([] if self.rule1 else ["--no-rule1"])
                + ([] if self.rule23 else ["--no-rule23"]))

    def __str__(self) -> str:
        return self.name  # how the command line and the JSON settings name it


def all_configurations() -> list[Configuration]:
    """Every variant with all rules, with Rule 1 off and with Rules 2+3 off; VTP and FTP also with both off."""
    configurations = []
    for algorithm in kAlgorithms:
        configurations += [Configuration(algorithm), Configuration(algorithm, rule1=False),
                           Configuration(algorithm, rule23=False)]
        if algorithm in ("vtp", "ftp"):
            configurations.append(Configuration(algorithm, rule1=False, rule23=False))
    return configurations


@dataclasses.dataclass
class VariantSolver(ExactgeoSolver):
    """The exactgeo CLI running one configuration; with timers, its phase timers on."""

    # The engine's counters and phase timers that the paper reports use.
    stats_keys: ClassVar[list[str]] = [
        "read_seconds", "window_propagations", "prime_propagations", "secondary_propagations", "prime_merges",
        "secondary_merges", "peak_windows", "peak_window_bytes", "vertex_pops", "face_pops",
        "pseudo_source_emissions", "window_propagation_seconds", "pruning_seconds", "queue_seconds",
    ]

    configuration: Configuration = Configuration(kReference)
    timers: bool = False

    def command(self, mesh, source, distances, stats):
        command = super().command(mesh, source, distances, stats) + self.configuration.flags + ["--quiet"]
        return command + (["--timers"] if self.timers else [])


def variant_solver(configuration: Configuration, exactgeo: Path, timers: bool = False) -> VariantSolver:
    suffix = "+timers" if timers else ""
    return VariantSolver(configuration.name + suffix, configuration.label + (" (phase timers on)" if timers else ""),
                         True, executable=exactgeo, build_hint="build with CMake first",
                         configuration=configuration, timers=timers)


kVariantOptions = ("--algorithm", "--no-rule1", "--no-rule23", "--timers")


def missing_cli_options(exactgeo: Path, wanted: Sequence[str] = kVariantOptions) -> list[str]:
    """The options of `wanted` (by default the variants') that this exactgeo binary's `distance` does not offer
    (all of them if it does not run)."""
    wanted = list(wanted)
    try:
        help_text = subprocess.run([str(exactgeo), "distance", "--help"], capture_output=True, text=True,
                                   timeout=30).stdout
    except OSError:
        return wanted
    return [option for option in wanted if option not in help_text]
