"""Tests of the paper-reproduction report: configurations, savings arithmetic, the exactness check and a
quick end-to-end run (python3 -m pytest bench)."""

import json
from pathlib import Path

import numpy as np
import pytest

import paper
from reports import variants
from solvers import runner
from solvers.commands import Configuration, PeerSolver, all_configurations, kAlgorithms, variant_solver

kMeshDir = Path(__file__).resolve().parent.parent.parent / "shared" / "meshes"


def test_configurations_name_their_switched_off_rules_and_pass_the_matching_flags():
    both_off = Configuration("ftp", rule1=False, rule23=False)
    assert both_off.name == "ftp-no-rule1-no-rule23"
    assert both_off.label == "FTP without Rule 1 and Rules 2+3"
    assert both_off.flags == ["--algorithm", "ftp", "--no-rule1", "--no-rule23"]
    assert Configuration("opvtp").flags == ["--algorithm", "opvtp"]


def test_every_variant_runs_with_each_rule_off_and_vtp_and_ftp_also_with_both_off():
    names = [c.name for c in all_configurations()]
    assert len(names) == len(set(names)) == 4 * 3 + 2
    assert "vtp-no-rule1-no-rule23" in names and "ftp-no-rule1-no-rule23" in names
    assert "opvtp-no-rule1-no-rule23" not in names
    assert paper.parse_args(["--configurations", "ftp"]).configurations == [Configuration("vtp"), Configuration("ftp")]


def test_savings_are_what_the_rule_takes_off_the_run_without_it():
    table = {("m", "vtp"): {"seconds": 3.0, "fastest_seconds": 2.0, "window_propagations": 50},
             ("m", "vtp-no-rule1"): {"seconds": 4.0, "fastest_seconds": 4.0, "window_propagations": 100},
             ("m", "vtp-no-rule23"): {"seconds": 2.0, "fastest_seconds": 1.0, "window_propagations": 50}}
    savings = variants.ablation_savings(table, "m", "vtp")
    assert savings == {"rule1_time_saving": 0.25, "rule1_fastest_time_saving": 0.5, "rule1_propagation_saving": 0.5,
                       "rule23_time_saving": -0.5, "rule23_fastest_time_saving": -1.0,
                       "rule23_propagation_saving": 0.0}
    assert variants.ablation_savings(table, "m", "ftp")["rule1_time_saving"] is None


def test_summary_skips_missing_values():
    assert variants.summary([None, 1.0, 3.0]) == {"mean": 2.0, "min": 1.0, "max": 3.0, "count": 2}
    assert variants.summary([None]) is None


def test_paper_table3_ratios_match_the_published_numbers():
    summary = variants.paper_table3_summary()
    # Bunny: FTP 1.044 s against VTP 0.78 s; Lucy: 617.343 s against 549.934 s.
    assert summary["ftp_time_ratio"]["max"] == pytest.approx(13.223 / 9.495)
    assert summary["ftp_time_ratio"]["min"] == pytest.approx(617.343 / 549.934)
    assert summary["opvtp_propagation_ratio"]["count"] == 5
    assert summary["propagations_per_face"]["min"] == pytest.approx(4_943_670 / 144_000)


def fake_record(solver, status="ok"):
    return {"mesh": "m", "solver": solver, "source": 0, "status": status, "reason": "crashed (SIGSEGV)"}


def test_exactness_check_flags_a_variant_that_differs_or_failed_but_only_reports_peers(tmp_path):
    reference = np.array([0.0, 1.0, 2.0, np.inf])
    distances = {"vtp": reference, "ftp": reference + [0, 1e-13, 0, 0], "opvtp": reference + [0, 0, 1e-6, 0],
                 "heat": reference + [0, 0.1, 0, 0]}
    solvers = {name: variant_solver(Configuration(name), Path("exactgeo")) for name in kAlgorithms}
    solvers["heat"] = PeerSolver("heat", "heat", False)
    for name, values in distances.items():
        (tmp_path / name).mkdir()
        np.save(tmp_path / name / "s0.distances.npy", values)
    records = [fake_record(name) for name in distances] + [fake_record("opftp", status="failed")]
    runner.check_exactness(records, solvers, tmp_path)
    checks = {r["solver"]: r["exactness"] for r in records}
    assert checks["vtp"]["agrees"] and checks["vtp"]["max_relative_error"] == 0
    assert checks["ftp"]["agrees"] and checks["ftp"]["max_relative_error"] == pytest.approx(0.5e-13)
    assert not checks["opvtp"]["agrees"]
    assert not checks["heat"]["agrees"] and not checks["heat"]["judged"]
    failures = runner.exactness_failures(records)
    assert len(failures) == 2
    assert failures[0].startswith("m opvtp: max relative difference 5.00e-07")
    assert failures[1] == "m opftp: crashed (SIGSEGV)"


def test_quick_run_on_one_mesh_writes_tables_plots_and_agreeing_distances(tmp_path, exactgeo_with_variants):
    pytest.importorskip("matplotlib")
    if not (kMeshDir / "woody.obj").exists():
        pytest.skip(f"{kMeshDir} has no woody.obj")
    status = paper.main(["--meshes", "woody", "--configurations", "vtp-no-rule1", "vtp-no-rule23", "ftp",
                         "--repeat", "1", "--build-dir", str(exactgeo_with_variants.parent.parent),
                         "--mesh-dir", str(kMeshDir), "--work-dir", str(tmp_path / "work"),
                         "--results-dir", str(tmp_path), "--name", "p"])
    assert status == 0
    report = json.loads((tmp_path / "p.json").read_text())
    assert {r["solver"] for r in report["records"]} == {"vtp", "vtp-no-rule1", "vtp-no-rule23", "ftp"}
    assert {r["solver"] for r in report["timer_records"]} == {"vtp+timers", "ftp+timers"}
    timed = report["timer_records"][0]["solver_stats"]
    assert timed["window_propagation_seconds"] is not None and timed["queue_seconds"] is not None
    vtp = next(r for r in report["records"] if r["solver"] == "vtp")["solver_stats"]
    assert vtp["prime_propagations"] + vtp["secondary_propagations"] == vtp["window_propagations"]
    markdown = (tmp_path / "p.md").read_text()
    for heading in ("## The paper's claims next to ours", "## Exactness cross-check", "## Variants (Table 3 shape)",
                    "## Rule ablations (Figure 12 shape)", "## Where the time goes (Figure 8 shape)"):
        assert heading in markdown
    assert "MISMATCH" not in markdown
    assert all(Path(plot).stat().st_size > 0 for plot in report["plots"])
