"""Reproduce the shape of the VTP paper's variant comparison and ablations (Qin et al. 2016, Section 6.2).

Runs every algorithm variant (VTP, OPVTP, FTP, OPFTP) and every rule ablation on the shared meshes and the
nefertiti subdivisions, from vertex 0, and writes bench/results/NAME.{json,md} and NAME-*.png:

- Table 3 shape: time, window propagations and peak window memory per variant, and their ratios to VTP;
- Figure 12 shape: time and propagations with and without Rule 1 and Rules 2+3, and the savings;
- the share of prime propagations (inside the newly added triangles) among all window propagations;
- Figure 8 shape: propagation time split into window propagation, pruning and queue management, from
  separate runs with the engine's phase timers on (the timers cost a little, so the timed runs go without);
- an exactness cross-check: every variant's distances against default VTP's.

Every run is its own process started through launch.py (peak RSS, time and memory caps), as in run.py,
whose runner, solver classes and formatting this reuses. See bench/README.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime
import json
import os
import shlex
import statistics
import subprocess
import sys
from pathlib import Path

import numpy as np

import run

kBenchDir = Path(__file__).resolve().parent
kRepoRoot = kBenchDir.parent

kAlgorithms = ["vtp", "opvtp", "ftp", "opftp"]
kAlgorithmLabels = {"vtp": "VTP", "opvtp": "OPVTP", "ftp": "FTP", "opftp": "OPFTP"}
kReference = "vtp"  # the paper's final algorithm: ratios, savings and the exactness check are against it

# Meshes of the full run: every shared mesh plus nefertiti at 400K and 1.6M faces (the paper's Figure 12
# uses 345K and 1.4M faces). The quick run keeps small meshes that finish in seconds.
kPaperSubdivided = run.kSubdivided
kQuickMeshes = ["woody", "cow", "spot", "homer", "fandisk"]

# Averages over meshes this large or larger: the paper's smallest model has 10K faces, and on smaller ones
# whole runs last well under a millisecond, where timing noise swamps the differences being measured.
kSummaryMinFaces = 10_000

# Two solvers agree when their distances differ by no more than this, relative to the largest distance.
kExactTolerance = 1e-9

# The engine's counters and phase timers that the report uses, from `exactgeo distance --stats`.
kStatsKeys = [
    "read_seconds", "window_propagations", "prime_propagations", "secondary_propagations", "prime_merges",
    "secondary_merges", "peak_windows", "peak_window_bytes", "vertex_pops", "face_pops",
    "pseudo_source_emissions", "window_propagation_seconds", "pruning_seconds", "queue_seconds",
]
kPhases = [("window_propagation_seconds", "window propagation"), ("pruning_seconds", "pruning"),
           ("queue_seconds", "queue management")]

# The paper's Table 3 (an i7-3770 at 3.4 GHz; source: the first vertex): seconds, window propagations and
# peak memory in MB, for the variants we also implement.
kPaperTable3 = {
    "Bunny": (144_000, {"ftp": (1.044, 4_755_872, 1.20), "opvtp": (0.908, 4_875_712, 1.22),
                        "vtp": (0.78, 4_943_670, 1.24)}),
    "Rocker Arm": (482_000, {"ftp": (4.84, 25_013_422, 3.68), "opvtp": (5.173, 25_723_669, 3.71),
                             "vtp": (4.13, 25_654_638, 3.70)}),
    "Asian Dragon": (1_400_000, {"ftp": (13.223, 46_525_313, 4.10), "opvtp": (11.42, 47_573_341, 4.20),
                                 "vtp": (9.495, 48_217_896, 4.373)}),
    "Neptune": (4_008_000, {"ftp": (64.113, 243_102_435, 15.9), "opvtp": (60.192, 244_586_129, 16.19),
                            "vtp": (47.629, 246_364_008, 16.38)}),
    "Lucy": (14_464_000, {"ftp": (617.343, 2_668_122_127, 67.81), "opvtp": (608.414, 2_734_517_299, 68.01),
                          "vtp": (549.934, 2_808_823_718, 69.42)}),
}
# What the paper's text states (Section 6.2), averaged over its test models.
kPaperClaims = {
    "prime_share": 0.9625,
    "rule1_time_saving": 0.25, "rule1_propagation_saving": 0.50,
    "rule23_time_saving": 0.15, "rule23_propagation_saving": 0.30,
}


# ------------------------------------------------------------------------------------------ configurations


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
class VariantSolver(run.ExactgeoSolver):
    """The exactgeo CLI running one configuration; with timers, its phase timers on."""

    configuration: Configuration = Configuration(kReference)
    timers: bool = False

    def command(self, mesh, source, distances, stats):
        command = super().command(mesh, source, distances, stats) + self.configuration.flags + ["--quiet"]
        return command + (["--timers"] if self.timers else [])

    def read_stats(self, stats):
        data = json.loads(stats.read_text())
        return {"build_seconds": data["build_seconds"], "propagation_seconds": data["propagation_seconds"],
                **{key: data[key] for key in kStatsKeys if key in data}}


def variant_solver(configuration: Configuration, exactgeo: Path, timers: bool = False) -> VariantSolver:
    suffix = "+timers" if timers else ""
    return VariantSolver(configuration.name + suffix, configuration.label + (" (phase timers on)" if timers else ""),
                         True, executable=exactgeo, build_hint="build with CMake first",
                         configuration=configuration, timers=timers)


def missing_cli_options(exactgeo: Path) -> list[str]:
    """The variant options this exactgeo binary does not offer yet (all of them if it does not run)."""
    wanted = ["--algorithm", "--no-rule1", "--no-rule23", "--timers"]
    try:
        help_text = subprocess.run([str(exactgeo), "distance", "--help"], capture_output=True, text=True,
                                   timeout=30).stdout
    except OSError:
        return wanted
    return [option for option in wanted if option not in help_text]


# -------------------------------------------------------------------------------------------------- runs


def runner_args(args, repeat: int, solvers: tuple[str, ...] | list[str] = ("exactgeo",)) -> argparse.Namespace:
    """run.py's settings for its runner and solvers: our caps and paths, one source (vertex 0), `repeat` runs
    each; `solvers` are the names run.make_solvers would make."""
    argv = ["--build-dir", str(args.build_dir), "--exactgeo", str(args.exactgeo), "--work-dir", str(args.work_dir), "--results-dir", str(args.results_dir), "--sources", "1",
            "--repeat", str(repeat), "--max-repeat-seconds", str(args.max_repeat_seconds), "--timeout",
            str(args.timeout), "--name", args.name]
    if args.memory_limit_gb:
        argv += ["--memory-limit-gb", str(args.memory_limit_gb)]
    return run.parse_args(argv + ["--solvers", *solvers])


def bench_variants(mesh, solvers: list[run.Solver], timer_solvers: list[VariantSolver], args, runs_root: Path,
                   histories: dict[str, run.SolverHistory]) -> tuple[list[dict], list[dict]]:
    """Timed runs (args.repeat each, round the solvers) and then one run of each variant with its timers on.

    Returns the records of both, as run.py's runner makes them, each with the exactness check added.
    `histories` (per solver name) carries what earlier meshes said, so a solver that timed out is skipped."""
    timed = run.bench_mesh(mesh, solvers, histories, runner_args(args, args.repeat), runs_root)[1]
    timed_once = run.bench_mesh(mesh, timer_solvers, histories, runner_args(args, 1), runs_root)[1] \
        if timer_solvers else []
    everything = {s.name: s for s in [*solvers, *timer_solvers]}
    check_exactness(timed + timed_once, everything, runs_root / mesh.name)
    return timed, timed_once


def check_exactness(records: list[dict], solvers: dict[str, run.Solver], mesh_dir: Path) -> None:
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
                difference = run.error_against(distances(record), distances(reference_record))
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


def setting_text(value):
    """A command-line setting as JSON can hold it."""
    if isinstance(value, Path):
        return str(value)
    if isinstance(value, list):
        return [setting_text(item) for item in value]
    return value.name if isinstance(value, Configuration) else value


def report_header(args, name: str) -> dict:
    """Everything about the run but its results: settings, machine, build, software, load."""
    args.work_dir.mkdir(parents=True, exist_ok=True)  # the launcher's floor is measured there
    return {
        "name": name,
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "command": shlex.join(["python3", os.path.relpath(sys.argv[0], kRepoRoot), *sys.argv[1:]]),
        "settings": {key: setting_text(value) for key, value in vars(args).items()},
        "machine": run.machine_info(),
        "build": run.build_info(args.build_dir),
        "software": run.software_info(args),
        "launcher_floor_bytes": run.launcher_floor_bytes(args.work_dir),
        "load_average_at_start": os.getloadavg(),
    }


# -------------------------------------------------------------------------------------------- arithmetic


def saving(with_rule: float | None, without_rule: float | None) -> float | None:
    """What a rule saves: 1 - with/without (0.25 means the run with the rule takes 25% less)."""
    if with_rule is None or not without_rule:
        return None
    return 1.0 - with_rule / without_rule


def ratio(value: float | None, reference: float | None) -> float | None:
    return None if value is None or not reference else value / reference


def summary(values: list[float | None]) -> dict | None:
    """Mean, minimum and maximum of the values that exist."""
    values = [value for value in values if value is not None]
    if not values:
        return None
    return {"mean": statistics.fmean(values), "min": min(values), "max": max(values), "count": len(values)}


def paper_table3_summary() -> dict:
    """Mean and range over the paper's Table 3 models of FTP/VTP and OPVTP/VTP, in time and propagations."""
    result = {}
    for variant in ("ftp", "opvtp"):
        for index, quantity in ((0, "time"), (1, "propagation")):
            result[f"{variant}_{quantity}_ratio"] = summary(
                [numbers[variant][index] / numbers["vtp"][index] for _, numbers in kPaperTable3.values()])
    result["propagations_per_face"] = summary(
        [numbers["vtp"][1] / faces for faces, numbers in kPaperTable3.values()])
    result["nanoseconds_per_propagation"] = summary(
        [1e9 * numbers["vtp"][0] / numbers["vtp"][1] for _, numbers in kPaperTable3.values()])
    return result


def measured(records: list[dict]) -> dict[tuple[str, str], dict]:
    """(mesh, configuration name) -> what the report uses of that record: time, counters, peak RSS."""
    table = {}
    for record in records:
        if record["status"] != "ok":
            continue
        stats = record["solver_stats"]
        run_seconds = [r["propagation_seconds"] for r in record["runs"] if r.get("propagation_seconds") is not None]
        table[(record["mesh"], record["solver"])] = {
            "faces": record["faces"],
            "seconds": record["propagation_seconds"],
            # Other work on the machine only ever slows a run down, so the fastest run is the least disturbed.
            "fastest_seconds": min(run_seconds, default=None),
            # How far apart the repeated runs were: the noise any time difference must beat.
            "spread": (max(run_seconds) - min(run_seconds)) / record["propagation_seconds"]
            if len(run_seconds) > 1 and record["propagation_seconds"] else None,
            "peak_rss_bytes": record["peak_rss_bytes"],
            **{key: stats.get(key) for key in kStatsKeys},
        }
    return table


# What the savings and ratios compare: the median time, the fastest run's time, the window propagations.
kQuantities = [("time", "seconds"), ("fastest_time", "fastest_seconds"), ("propagation", "window_propagations")]


def ablation_savings(table: dict, mesh: str, algorithm: str) -> dict:
    """Savings of Rule 1 and of Rules 2+3 on one mesh and variant, in time and window propagations."""
    default = table.get((mesh, algorithm))
    result = {}
    for rule, configuration in (("rule1", Configuration(algorithm, rule1=False)),
                                ("rule23", Configuration(algorithm, rule23=False))):
        without = table.get((mesh, configuration.name))
        for quantity, key in kQuantities:
            result[f"{rule}_{quantity}_saving"] = saving(default and default[key], without and without[key])
    return result


def prime_share(entry: dict | None) -> float | None:
    if not entry or entry.get("prime_propagations") is None or not entry.get("window_propagations"):
        return None
    return entry["prime_propagations"] / entry["window_propagations"]


def comparison(table: dict, meshes: list[dict]) -> dict:
    """Our numbers for the paper's claims, as mean and range over the meshes of kSummaryMinFaces or more."""
    large = [mesh["name"] for mesh in meshes if mesh["faces"] >= kSummaryMinFaces]
    reference = {mesh: table.get((mesh, kReference)) for mesh in large}
    result = {"meshes": large, "prime_share": summary([prime_share(reference[mesh]) for mesh in large])}
    savings = [ablation_savings(table, mesh, kReference) for mesh in large]
    for key in (f"{rule}_{quantity}_saving" for rule in ("rule1", "rule23") for quantity, _ in kQuantities):
        result[key] = summary([entry[key] for entry in savings])
    for variant in ("ftp", "opvtp", "opftp"):
        for quantity, key in kQuantities:
            result[f"{variant}_{quantity}_ratio"] = summary(
                [ratio((table.get((mesh, variant)) or {}).get(key), (reference[mesh] or {}).get(key))
                 for mesh in large])
    result["time_spread"] = summary([entry["spread"] for entry in reference.values() if entry])
    result["propagations_per_face"] = summary(
        [entry["window_propagations"] / entry["faces"] for entry in reference.values() if entry])
    result["nanoseconds_per_propagation"] = summary(
        [1e9 * entry["seconds"] / entry["window_propagations"] for entry in reference.values()
         if entry and entry["window_propagations"]])
    return result


# ----------------------------------------------------------------------------------------------- reports


def percent(value: float | None) -> str:
    return "—" if value is None else f"{100 * value:.1f}%"


def times(value: float | None) -> str:
    return "—" if value is None else f"{value:.3g}x"


def summary_text(entry: dict | None, format_value) -> str:
    if not entry:
        return "—"
    if entry["count"] == 1:
        return format_value(entry["mean"])
    return f"{format_value(entry['mean'])} ({format_value(entry['min'])} – {format_value(entry['max'])})"


def megabytes(count: float | None) -> str:
    return "—" if count is None else f"{count / 1024**2:.3g} MB"


def machine_lines(report: dict) -> list[str]:
    machine, build, software = report["machine"], report["build"], report["software"]
    versions = ", ".join(f"{name} {version}" for name, version in software["packages"].items() if version)
    load = ", ".join(f"{value:.2f}" for value in report["load_average_at_start"])
    end_load = ", ".join(f"{value:.2f}" for value in report.get("load_average_at_end", []))
    return [
        "## Machine and software",
        "",
        f"- CPU: {machine['cpu_model']}, {machine['logical_cores']} logical cores; memory "
        f"{machine['memory_bytes'] / run.kGiB:.1f} GiB; Linux {machine['kernel']}; load average {load} at the "
        f"start, {end_load or '—'} at the end (other work on the machine makes single timings noisy)",
        f"- compiler: {build.get('compiler_version', '—')}; build type {build.get('CMAKE_BUILD_TYPE', '—')}; "
        f"engine compiled with `{build.get('engine_compile_flags', '—')}`",
        f"- exactgeo {software['exactgeo_revision'] or '(no commit)'}; Python {software['python']}; {versions}; "
        f"CGAL (libcgal-dev) {software['cgal'] or '—'}",
        f"- peak RSS cannot read below the launcher's {run.format_bytes(report['launcher_floor_bytes'])}",
        "",
    ]


def exactness_lines(records: list[dict], columns: list[str]) -> list[str]:
    """One row per mesh, one column per solver: max relative difference of its distances from VTP's."""
    failures = exactness_failures(records)
    lines = ["## Exactness cross-check", ""]
    if failures:
        lines += ["**MISMATCH: these runs disagree with VTP or failed:**", ""]
        lines += [f"- **{failure}**" for failure in failures] + [""]
    else:
        lines += [f"Every exact run agrees with default VTP to {kExactTolerance:g} of the largest distance, with "
                  "the same vertices reachable.", ""]
    lines += ["Max |d − d_VTP| over the vertices, relative to the largest VTP distance (“+timers”: the run with "
              "the phase timers on).", ""]
    lines += ["| mesh | " + " | ".join(columns) + " |", "|---|" + "---:|" * len(columns)]
    by_key = {(r["mesh"], r["solver"]): r for r in records}
    for mesh in dict.fromkeys(r["mesh"] for r in records):
        cells = []
        for column in columns:
            check = (by_key.get((mesh, column)) or {}).get("exactness")
            if not check:
                cells.append("—")
            else:
                text = check.get("failure") or ("0" if check["max_relative_error"] == 0
                                                else f"{check['max_relative_error']:.1e}")
                cells.append(f"**{text} MISMATCH**" if check["judged"] and not check["agrees"] else text)
        lines.append(f"| {mesh} | " + " | ".join(cells) + " |")
    return lines + [""]


def write_markdown(path: Path, report: dict) -> None:
    meshes, configurations = report["meshes"], [Configuration(**c) for c in report["configurations"]]
    table, timers = measured(report["records"]), measured(report["timer_records"])
    ours, paper = report["comparison"], report["paper"]
    names = [c.name for c in configurations]
    algorithms = [a for a in kAlgorithms if a in names]
    runs_text = run.runs_text(report["settings"]["repeat"])
    lines = [
        "# VTP variants and ablations",
        "",
        f"{report['date']} · {report['machine']['cpu_model']}, {report['machine']['logical_cores']} logical "
        f"cores · exactgeo {report['software']['exactgeo_revision'] or '(no commit)'} · `{report['command']}` · "
        f"{runs_text} per configuration, source vertex 0",
        "",
        "The shape of Tables 1/3 and Figures 8 and 12 of Qin et al. 2016 on our meshes. Times are the engine's "
        "propagation time (`propagation_seconds`, mesh build excluded), median over the runs; counts come from "
        "the engine's statistics. docs/paper-reproduction.md discusses the numbers.",
        "",
        "## The paper's claims next to ours",
        "",
        f"Ours: mean (range) over the {len(ours['meshes'])} meshes of {kSummaryMinFaces:,} faces or more "
        f"({', '.join(ours['meshes'])}). Paper: Section 6.2's text, or the mean (range) over Table 3's five "
        "models.",
        "",
        "| quantity | paper | ours |",
        "|---|---:|---:|",
        f"| prime propagations, share of all (VTP) | {percent(kPaperClaims['prime_share'])} (mean of 55 models) "
        f"| {summary_text(ours['prime_share'], percent)} |",
    ]
    # Ours per quantity: time from the medians, time from the fastest runs, window propagations.
    quantity_labels = {"time": "time", "fastest_time": "time, fastest runs", "propagation": "window propagations"}
    for rule, label in (("rule1", "Rule 1 saves"), ("rule23", "Rules 2+3 save")):
        for quantity, quantity_label in quantity_labels.items():
            claimed = kPaperClaims[f"{rule}_{'time' if 'time' in quantity else 'propagation'}_saving"]
            lines.append(f"| {label}, {quantity_label} (VTP) | ~{percent(claimed)} "
                         f"| {summary_text(ours[f'{rule}_{quantity}_saving'], percent)} |")
    for variant in ("ftp", "opvtp", "opftp"):
        for quantity, quantity_label in quantity_labels.items():
            theirs = paper.get(f"{variant}_{'time' if 'time' in quantity else 'propagation'}_ratio")
            lines.append(f"| {kAlgorithmLabels[variant]} ÷ VTP, {quantity_label} | {summary_text(theirs, times)} "
                         f"| {summary_text(ours.get(f'{variant}_{quantity}_ratio'), times)} |")
    lines += [
        f"| window propagations per face (VTP) | {summary_text(paper['propagations_per_face'], lambda v: f'{v:.3g}')} "
        f"| {summary_text(ours['propagations_per_face'], lambda v: f'{v:.3g}')} |",
        f"| nanoseconds per window propagation (VTP) | "
        f"{summary_text(paper['nanoseconds_per_propagation'], lambda v: f'{v:.3g}')} "
        f"| {summary_text(ours['nanoseconds_per_propagation'], lambda v: f'{v:.3g}')} |",
        "",
        "Savings are 1 − with/without: 25% means the run with the rule takes a quarter less. “Fastest runs” "
        "compares each configuration's fastest run instead of its median: other work on the machine only slows "
        "runs down, so the fastest is the least disturbed (the paper's one time per cell stands on both rows). "
        "OPFTP is not in the paper's Table 3.",
        "",
        f"Timing noise: VTP's repeated runs lay {summary_text(ours['time_spread'], percent)} of their median apart "
        "(max − min ÷ median; mean and range over the same meshes). Time differences smaller than that are "
        "noise; the counts are exact and repeatable.",
        "",
    ]
    lines += exactness_lines(report["records"] + report["timer_records"],
                             names + [f"{name}+timers" for name in algorithms])

    # Table 3 shape: one row per mesh and quantity, one column per variant.
    lines += ["## Variants (Table 3 shape)", "",
              "Propagation time, window propagations, peak window memory (the engine's `peak_window_bytes`, "
              "what the paper's “peak memory” counts) and peak RSS of the whole process; ratios to VTP in "
              "brackets.", "",
              "| mesh | quantity | " + " | ".join(kAlgorithmLabels[a] for a in algorithms) + " |",
              "|---|---|" + "---:|" * len(algorithms)]
    quantities = [("time", "seconds", run.format_seconds), ("window propagations", "window_propagations",
                                                            run.format_count),
                  ("peak window memory", "peak_window_bytes", megabytes),
                  ("peak RSS", "peak_rss_bytes", lambda b: run.format_bytes(b, report["launcher_floor_bytes"]))]
    for mesh in meshes:
        reference = table.get((mesh["name"], kReference)) or {}
        for quantity, key, format_value in quantities:
            cells = []
            for algorithm in algorithms:
                value = (table.get((mesh["name"], algorithm)) or {}).get(key)
                relation = ratio(value, reference.get(key)) if algorithm != kReference else None
                cells.append(format_value(value) + (f" ({times(relation)})" if relation is not None else ""))
            lines.append(f"| {mesh['name']} ({mesh['faces']:,}) | {quantity} | " + " | ".join(cells) + " |")
    lines.append("")

    # Figure 12 shape.
    lines += ["## Rule ablations (Figure 12 shape)", "",
              "Time and window propagations of each variant with every rule, without Rule 1, without Rules 2+3 "
              "(and without all three), and what each rule saves (1 − with/without).", "",
              "| mesh | variant | time: all rules · −R1 · −R2+3 · −all | propagations: all · −R1 · −R2+3 · −all "
              "| Rule 1 saves: time · propagations | Rules 2+3 save: time · propagations |",
              "|---|---|---:|---:|---:|---:|"]
    for mesh in meshes:
        for algorithm in algorithms:
            variants = [Configuration(algorithm), Configuration(algorithm, rule1=False),
                        Configuration(algorithm, rule23=False), Configuration(algorithm, False, False)]
            entries = [table.get((mesh["name"], c.name)) for c in variants]
            time_cells = " · ".join(run.format_seconds(e["seconds"]) if e else "—" for e in entries)
            count_cells = " · ".join(run.format_count(e["window_propagations"]) if e else "—" for e in entries)
            savings = ablation_savings(table, mesh["name"], algorithm)
            lines.append(f"| {mesh['name']} ({mesh['faces']:,}) | {kAlgorithmLabels[algorithm]} | {time_cells} "
                         f"| {count_cells} | {percent(savings['rule1_time_saving'])} · "
                         f"{percent(savings['rule1_propagation_saving'])} | {percent(savings['rule23_time_saving'])}"
                         f" · {percent(savings['rule23_propagation_saving'])} |")
    lines.append("")

    # Distribution of window propagations and merges.
    lines += ["## Prime and secondary propagations", "",
              "Prime propagations cross triangles being added to the traversed area; secondary ones cross "
              "triangles already in it (paper, Section 6.2: 96.25% prime on average). Merges likewise: prime "
              "mergers on new wavefront edges (Rule 3), secondary mergers on older ones.", "",
              "| mesh | variant | prime share | prime propagations | secondary propagations | prime merges "
              "| secondary merges | vertex pops | face pops | pseudo-source emissions |",
              "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for mesh in meshes:
        for algorithm in algorithms:
            entry = table.get((mesh["name"], algorithm))
            if not entry:
                continue
            counts = " | ".join(run.format_count(entry.get(key)) for key in (
                "prime_propagations", "secondary_propagations", "prime_merges", "secondary_merges", "vertex_pops",
                "face_pops", "pseudo_source_emissions"))
            lines.append(f"| {mesh['name']} ({mesh['faces']:,}) | {kAlgorithmLabels[algorithm]} "
                         f"| {percent(prime_share(entry))} | {counts} |")
    lines.append("")

    # Figure 8 shape.
    lines += ["## Where the time goes (Figure 8 shape)", "",
              "One run per variant with the engine's phase timers on (`--timers`), apart from the timed runs: "
              "window propagation (crossing window lists over triangles, with Rule 1 and the checks against "
              "vertex distances done on the way), pruning (the pairwise checks of Rules 2 and 3), queue "
              "management (the vertex or face priority queue), and the rest of the propagation time (moving "
              "lists between edges, secondary merges, pseudo-source emission, distance updates, the clock "
              "reads). Shares of that run's propagation time.", "",
              "| mesh | variant | propagation time (timers on) | window propagation | pruning | queue management "
              "| rest |", "|---|---|---:|---:|---:|---:|---:|"]
    for mesh in meshes:
        for algorithm in algorithms:
            entry = timers.get((mesh["name"], f"{algorithm}+timers"))
            if not entry:
                continue
            parts = [entry.get(key) for key, _ in kPhases]
            if None in parts:
                cells = ["—"] * 4
            else:
                rest = max(entry["seconds"] - sum(parts), 0.0)
                cells = [f"{run.format_seconds(part)} ({percent(part / entry['seconds'])})" for part in parts + [rest]]
            lines.append(f"| {mesh['name']} ({mesh['faces']:,}) | {kAlgorithmLabels[algorithm]} "
                         f"| {run.format_seconds(entry['seconds'])} | " + " | ".join(cells) + " |")
    lines += ["", "Plots: `" + "`, `".join(Path(p).name for p in report.get("plots", [])) + "`.", ""]
    lines += machine_lines(report)
    path.write_text("\n".join(lines))


def largest_meshes(meshes: list[dict], count: int = 2) -> list[dict]:
    return sorted(meshes, key=lambda mesh: mesh["faces"])[-count:]


def write_plots(results_dir: Path, report: dict) -> list[Path]:
    """NAME-ablation.png (Figure 12 shape) and NAME-phases.png (Figure 8 shape)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    table, timers = measured(report["records"]), measured(report["timer_records"])
    names = {c["algorithm"] for c in report["configurations"]}
    algorithms = [a for a in kAlgorithms if a in names]
    shown = largest_meshes(report["meshes"])
    plots = []

    # Figure 12: per large mesh, VTP with and without the rules; time bars on the left axis, propagations on
    # the right. Last panel: the savings on every mesh of kSummaryMinFaces or more.
    figure, panels = plt.subplots(1, len(shown) + 1, figsize=(5.5 * (len(shown) + 1), 4.8))
    ablations = [Configuration(kReference), Configuration(kReference, rule1=False),
                 Configuration(kReference, rule23=False), Configuration(kReference, False, False)]
    short = ["all rules", "no Rule 1", "no Rules 2+3", "none"]
    for axes, mesh in zip(panels, shown):
        entries = [table.get((mesh["name"], c.name)) for c in ablations]
        positions = np.arange(len(ablations))
        axes.bar(positions - 0.2, [e["seconds"] if e else 0 for e in entries], 0.4, color="tab:blue", label="time")
        counts_axes = axes.twinx()
        counts_axes.bar(positions + 0.2, [e["window_propagations"] if e else 0 for e in entries], 0.4,
                        color="tab:orange", label="window propagations")
        axes.set_xticks(positions, short)
        axes.set_ylabel("propagation time (s)", color="tab:blue")
        counts_axes.set_ylabel("window propagations", color="tab:orange")
        axes.set_title(f"{kAlgorithmLabels[kReference]} on {mesh['name']} ({mesh['faces']:,} faces)")
    axes = panels[-1]
    large = [mesh for mesh in report["meshes"] if mesh["faces"] >= kSummaryMinFaces]
    keys = [("rule1_time_saving", "Rule 1, time"), ("rule1_propagation_saving", "Rule 1, propagations"),
            ("rule23_time_saving", "Rules 2+3, time"), ("rule23_propagation_saving", "Rules 2+3, propagations")]
    width = 0.8 / len(keys)
    for index, (key, label) in enumerate(keys):
        # The paper's approximate averages stand as the last group, beside ours.
        values = [ablation_savings(table, mesh["name"], kReference)[key] for mesh in large] + [kPaperClaims[key]]
        axes.bar(np.arange(len(large) + 1) + (index - (len(keys) - 1) / 2) * width,
                 [100 * v if v is not None else 0 for v in values], width, label=label)
    axes.set_xticks(np.arange(len(large) + 1), [mesh["name"] for mesh in large] + ["paper (~)"], rotation=45,
                    ha="right")
    axes.axhline(0, color="black", linewidth=0.8)
    axes.set_ylabel("saving (%)")
    axes.set_title(f"{kAlgorithmLabels[kReference]}: what each rule saves")
    axes.legend(fontsize="small")
    plots.append(run.save_figure(figure, results_dir / f"{report['name']}-ablation.png"))

    # Figure 8: stacked phase times per variant on the large meshes.
    figure, panels = plt.subplots(1, len(shown), figsize=(5.5 * len(shown), 4.5), squeeze=False)
    for axes, mesh in zip(panels[0], shown):
        bottoms = np.zeros(len(algorithms))
        entries = [timers.get((mesh["name"], f"{a}+timers")) or {} for a in algorithms]
        phases = kPhases + [("rest", "rest")]
        for key, label in phases:
            if key == "rest":
                values = [max(e["seconds"] - sum(e.get(k) or 0 for k, _ in kPhases), 0) if e else 0 for e in entries]
            else:
                values = [e.get(key) or 0 for e in entries]
            axes.bar([kAlgorithmLabels[a] for a in algorithms], values, bottom=bottoms, label=label)
            bottoms += values
        axes.set_ylabel("seconds (run with timers on)")
        axes.set_title(f"{mesh['name']} ({mesh['faces']:,} faces)")
        axes.legend(fontsize="small")
    plots.append(run.save_figure(figure, results_dir / f"{report['name']}-phases.png"))
    return plots


# ------------------------------------------------------------------------------------------------- main


def parse_args(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true",
                        help=f"meshes {', '.join(kQuickMeshes)}; 1 run each; a minute or two")
    parser.add_argument("--name", help="results file stem (default: paper, or paper-quick)")
    parser.add_argument("--meshes", nargs="+", help="mesh names (default: every shared mesh and "
                        f"{', '.join(kPaperSubdivided)}; quick: {', '.join(kQuickMeshes)})")
    parser.add_argument("--configurations", nargs="+", metavar="NAME",
                        help="configurations to run, e.g. vtp ftp-no-rule1 (default: all; "
                        f"{kReference} is always run, as the reference)")
    parser.add_argument("--repeat", type=int, help="timed runs per configuration; median reported (default 3; quick 1)")
    parser.add_argument("--max-repeat-seconds", type=float, default=60.0,
                        help="a run longer than this is not repeated (default 60)")
    parser.add_argument("--timeout", type=float, default=600.0, help="seconds per run (default 600)")
    parser.add_argument("--memory-limit-gb", type=float, help="address-space limit per run (default: run.py's)")
    parser.add_argument("--mesh-dir", type=Path, default=kRepoRoot.parent / "shared" / "meshes")
    parser.add_argument("--build-dir", type=Path, default=kRepoRoot / "build")
    parser.add_argument("--exactgeo", type=Path, help="exactgeo CLI (default: BUILD_DIR/cli/exactgeo)")
    parser.add_argument("--work-dir", type=Path, default=kBenchDir / "work")
    parser.add_argument("--results-dir", type=Path, default=kBenchDir / "results")
    args = parser.parse_args(argv)
    args.name = args.name or ("paper-quick" if args.quick else "paper")
    args.repeat = args.repeat or (1 if args.quick else 3)
    for key in ("build_dir", "mesh_dir", "work_dir", "results_dir"):
        setattr(args, key, getattr(args, key).resolve())
    args.exactgeo = (args.exactgeo or args.build_dir / "cli" / "exactgeo").resolve()
    if args.quick and not args.meshes:
        args.meshes = kQuickMeshes
    known = {c.name: c for c in all_configurations()}
    chosen = args.configurations or list(known)
    unknown = set(chosen) - set(known)
    if unknown:
        parser.error(f"unknown configuration(s) {', '.join(sorted(unknown))}; known: {', '.join(known)}")
    args.configurations = [known[name] for name in dict.fromkeys([kReference, *chosen])]
    return args


def main(argv=None) -> int:
    args = parse_args(argv)
    if missing := missing_cli_options(args.exactgeo):
        sys.exit(f"paper.py: {args.exactgeo} lacks {', '.join(missing)}: rebuild it (cmake --build build)")
    meshes = run.select_meshes(args, kPaperSubdivided, "paper.py")

    solvers = [variant_solver(c, args.exactgeo) for c in args.configurations]
    timer_solvers = [variant_solver(c, args.exactgeo, timers=True) for c in args.configurations
                     if c.rule1 and c.rule23]
    runs_root = args.work_dir / "runs" / args.name
    args.results_dir.mkdir(parents=True, exist_ok=True)
    report = {**report_header(args, args.name),
              "configurations": [dataclasses.asdict(c) for c in args.configurations],
              "meshes": [], "records": [], "timer_records": []}
    histories = {solver.name: run.SolverHistory() for solver in solvers + timer_solvers}
    for mesh in meshes:
        timed, timed_once = bench_variants(mesh, solvers, timer_solvers, args, runs_root, histories)
        report["meshes"].append({"name": mesh.name, "vertices": mesh.vertex_count, "faces": mesh.face_count,
                                 "path": os.path.relpath(mesh.obj_path, kRepoRoot)})
        report["records"] += timed
        report["timer_records"] += timed_once
    report["load_average_at_end"] = os.getloadavg()
    report["comparison"] = comparison(measured(report["records"]), report["meshes"])
    report["paper"] = {"claims": kPaperClaims, "table3": kPaperTable3, **paper_table3_summary()}
    report["plots"] = [str(p) for p in write_plots(args.results_dir, report)]
    json_path = args.results_dir / f"{args.name}.json"
    json_path.write_text(json.dumps(report, indent=1))
    markdown_path = args.results_dir / f"{args.name}.md"
    write_markdown(markdown_path, report)
    print(f"\nwrote {json_path}, {markdown_path}, " + ", ".join(report["plots"]))
    failures = exactness_failures(report["records"] + report["timer_records"])
    for failure in failures:
        print(f"EXACTNESS MISMATCH: {failure}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
