"""Tests of end_to_end.py: the split of a run's wall time into steps (both meanings of exactgeo's build_seconds),
its options, its report from a small made-up JSON, and a tiny real run where the CLI is built
(python3 -m pytest bench). None of them needs a peer installed."""

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

import end_to_end
from meshes import BenchMesh, anisotropic_height_field, write_obj
from reports.end_to_end import threads_text, write_markdown
from solvers.end_to_end import (
    WholeExactgeoRun,
    WholePeerRun,
    add_steps,
    exactgeo_steps,
    later_repeat_distances,
    median_build_timings,
    median_steps,
    split_wall,
    whole_runs,
)
from solvers.runner import RunSettings, run_once

kNewStats = {"read_seconds": 0.1, "build_seconds": 0.3, "propagation_seconds": 0.5, "write_seconds": 0.05,
             "build_timings": {"weld": 0.1, "match_twins": 0.2}}
kOldStats = {"read_seconds": 0.1, "build_seconds": 0.3, "propagation_seconds": 0.5}


# ------------------------------------------------------------------------------------------- the split


def test_stats_of_the_new_contract_give_each_step_apart_and_carry_the_build_timings():
    steps = exactgeo_steps(kNewStats)
    assert steps == {"read_seconds": 0.1, "build_seconds": 0.3, "propagation_seconds": 0.5, "write_seconds": 0.05,
                     "build_counts_read": False, "build_timings": {"weld": 0.1, "match_twins": 0.2}}


def test_stats_without_write_seconds_count_the_read_in_the_build():
    steps = exactgeo_steps(kOldStats)
    assert steps["build_seconds"] == pytest.approx(0.2)
    assert steps["write_seconds"] is None and steps["build_counts_read"]
    assert "build_timings" not in steps


def test_a_new_build_shorter_than_its_read_is_not_taken_for_an_old_one():
    # The meaning comes from the fields the stats have, not from comparing the two times.
    assert exactgeo_steps({**kNewStats, "build_seconds": 0.05})["build_seconds"] == 0.05
    assert exactgeo_steps({**kOldStats, "build_seconds": 0.4})["build_seconds"] == pytest.approx(0.3)


def run_outcome(wall, stats):
    return {"wall_seconds": wall, "peak_rss_bytes": 1, **stats}


def test_start_is_the_wall_time_left_after_the_timed_steps():
    new = split_wall(run_outcome(1.0, exactgeo_steps(kNewStats)))
    assert new == pytest.approx({"start": 0.05, "read": 0.1, "build": 0.3, "solve": 0.5, "write": 0.05})
    old = split_wall(run_outcome(1.0, exactgeo_steps(kOldStats)))  # the write stays in start
    assert old["write"] is None and old["start"] == pytest.approx(0.2) and old["build"] == pytest.approx(0.2)
    gdist = split_wall(run_outcome(1.0, {"read_seconds": 0.1, "build_seconds": None, "propagation_seconds": 0.6,
                                         "write_seconds": 0.01}))
    assert gdist["build"] is None and gdist["start"] == pytest.approx(0.29)


def test_each_step_has_its_own_median_and_the_build_timings_theirs():
    runs = [{"steps": {"start": s, "read": r, "build": 1.0, "solve": 2.0, "write": None},
             "build_timings": {"a": r, "b": s}} for s, r in [(0.1, 0.3), (0.9, 0.1), (0.2, 0.2)]]
    assert median_steps(runs) == {"start": 0.2, "read": 0.2, "build": 1.0, "solve": 2.0, "write": None}
    assert median_build_timings(runs) == {"a": 0.2, "b": 0.2}
    assert median_build_timings([{"steps": {}}]) is None


def test_only_records_that_ran_get_steps():
    ran = {"status": "ok", "runs": [run_outcome(1.0, exactgeo_steps(kOldStats))]}
    skipped = {"status": "skipped", "runs": []}
    add_steps([ran, skipped])
    assert ran["steps"]["start"] == pytest.approx(0.2) and ran["build_counts_read"] and ran["build_timings"] is None
    assert "steps" not in skipped


# ------------------------------------------------------------------------------------------ the commands


kMesh = BenchMesh("m", Path("/meshes/m.obj"), Path("/m.vertices.npy"), Path("/m.triangles.npy"), 4, 4)


def test_the_runs_take_turns_build_by_build_then_the_peers():
    runs = whole_runs(["gdist", "exactgeo", "heat"], [1, 4], Path("/new/exactgeo"), Path("/old/exactgeo"))
    assert [run.name for run in runs] == ["exactgeo-t1", "baseline-t1", "exactgeo-t4", "baseline-t4", "heat", "gdist"]
    assert runs[3].label == "baseline, 4 threads" and runs[3].baseline
    assert isinstance(runs[5], WholePeerRun) and runs[5].build_in_propagation
    without_threads = whole_runs(["exactgeo"], [1, 2], Path("/new/exactgeo"), Path("/old/exactgeo"), False)
    assert [(run.name, run.threads) for run in without_threads] == [("exactgeo-t1", 1), ("baseline-t1", None),
                                                                     ("exactgeo-t2", 2)]
    with pytest.raises(ValueError, match="unknown solver"):
        whole_runs(["cgal"], [1], Path("exactgeo"))


def test_every_repeat_writes_its_distances_as_a_user_would(tmp_path):
    exactgeo = WholeExactgeoRun("exactgeo-t2", "exactgeo, 2 threads", True, executable=Path("/x/exactgeo"), threads=2)
    stats = tmp_path / "s0-r1.stats.json"
    assert exactgeo.command(kMesh, 0, None, stats) == [
        "/x/exactgeo", "distance", "/meshes/m.obj", "--source", "0", "--out", str(later_repeat_distances(stats)),
        "--stats", str(stats), "--threads", "2"]
    old = WholeExactgeoRun("baseline-t1", "baseline", True, executable=Path("/x/exactgeo"), threads=None)
    assert "--threads" not in old.command(kMesh, 0, tmp_path / "d.npy", stats)
    [peer] = whole_runs(["pygeodesic"], [1], Path("exactgeo"))
    command = peer.command(kMesh, 0, None, stats)
    assert command[command.index("--obj") + 1] == "/meshes/m.obj" and "--vertices" not in command
    assert command[command.index("--out") + 1] == str(later_repeat_distances(stats))


def test_a_peer_is_left_out_without_the_common_reader(monkeypatch):
    [peer] = whole_runs(["gdist"], [1], Path("exactgeo"))
    find_spec = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name: None if name == "potpourri3d"
                        else (object() if name == "gdist" else find_spec(name)))
    assert "every peer reads the mesh with potpourri3d.read_mesh" in peer.unavailable_reason()


def test_exactgeo_stats_read_back_as_steps(tmp_path):
    stats = tmp_path / "s.json"
    stats.write_text(json.dumps({**kNewStats, "window_propagations": 7, "threads": 2}))
    exactgeo = WholeExactgeoRun("exactgeo-t2", "exactgeo, 2 threads", True, executable=Path("exactgeo"), threads=2)
    read = exactgeo.read_stats(stats)
    assert read["window_propagations"] == 7 and read["write_seconds"] == 0.05 and read["build_timings"]["weld"] == 0.1


# -------------------------------------------------------------------------------------------- options


def test_the_thread_counts_default_to_one_two_and_every_core(monkeypatch):
    monkeypatch.setattr(end_to_end.os, "cpu_count", lambda: 16)
    assert end_to_end.parse_args([]).threads == [1, 2, 16]
    monkeypatch.setattr(end_to_end.os, "cpu_count", lambda: 2)
    assert end_to_end.parse_args([]).threads == [1, 2]
    assert end_to_end.parse_args(["--threads", "4", "1", "4"]).threads == [1, 4]


def test_the_options_are_checked_and_the_paths_made_absolute(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    args = end_to_end.parse_args(["--build-dir", "new", "--baseline-build", "old", "--meshes", "nefertiti-sub3"])
    assert args.exactgeo == tmp_path / "new" / "cli" / "exactgeo"
    assert args.baseline_exactgeo == tmp_path / "old" / "cli" / "exactgeo"
    assert args.meshes == ["nefertiti-sub3"] and args.name == "end-to-end" and args.repeat == 3
    assert "nefertiti-sub3" not in end_to_end.kDefaultMeshes
    for wrong in (["--solvers", "libigl"], ["--threads", "0"], ["--repeat", "0"]):
        with pytest.raises(SystemExit):
            end_to_end.parse_args(wrong)


# --------------------------------------------------------------------------------------------- report


def made_up_record(mesh, solver, wall, steps, rss=100 * 2**20, counts_read=False, build_timings=None):
    return {"mesh": mesh, "solver": solver, "source": 0, "status": "ok", "reason": None, "wall_seconds": wall,
            "peak_rss_bytes": rss, "steps": steps, "build_counts_read": counts_read, "build_timings": build_timings,
            "error": {"reference": "exactgeo-t1", "is_reference": True} if solver == "exactgeo-t1" else
            {"reference": "exactgeo-t1", "max_relative_error": 1e-15, "reachability_disagreements": 0}}


def steps(start, read, build, solve, write):
    return {"start": start, "read": read, "build": build, "solve": solve, "write": write}


def made_up_report():
    configurations = [
        {"name": "exactgeo-t1", "label": "exactgeo, 1 thread", "kind": "exactgeo", "threads": 1},
        {"name": "baseline-t1", "label": "baseline, 1 thread", "kind": "baseline", "threads": 1},
        {"name": "exactgeo-t2", "label": "exactgeo, 2 threads", "kind": "exactgeo", "threads": 2},
        {"name": "baseline-t2", "label": "baseline, 2 threads", "kind": "baseline", "threads": 2},
        {"name": "heat", "label": "the heat method", "kind": "peer", "threads": 1},
        {"name": "pygeodesic", "label": "MMP", "kind": "peer", "threads": 1},
        {"name": "gdist", "label": "MMP", "kind": "peer", "threads": 1, "build_in_propagation": True},
    ]
    for configuration in configurations:
        configuration.setdefault("build_in_propagation", False)
        configuration["exact"] = configuration["name"] != "heat"
    timings = {"sort": 0.1, "twins": 0.2}
    records = [
        made_up_record("m", "exactgeo-t1", 1.0, steps(0.1, 0.2, 0.3, 0.35, 0.05), build_timings=timings),
        made_up_record("m", "baseline-t1", 3.0, steps(0.4, 0.6, 1.5, 0.5, None), rss=200 * 2**20, counts_read=True),
        made_up_record("m", "exactgeo-t2", 0.5, steps(0.1, 0.1, 0.1, 0.15, 0.05)),
        made_up_record("m", "baseline-t2", 2.0, steps(0.4, 0.6, 0.75, 0.25, None), counts_read=True),
        made_up_record("m", "heat", 4.0, steps(0.5, 0.5, 2.5, 0.4, 0.1)),
        made_up_record("m", "gdist", 8.0, steps(0.5, 0.5, None, 6.9, 0.1)),
        {"mesh": "m", "solver": "pygeodesic", "source": 0, "status": "skipped", "runs": [],
         "reason": "pygeodesic not installed (pip install -r bench/requirements.txt)"},
    ]
    return {
        "name": "end-to-end", "date": "2026-01-01T00:00:00+00:00", "command": "python3 bench/end_to_end.py",
        "settings": {"repeat": 3}, "baseline": "af81e3a", "peer_reader": "potpourri3d.read_mesh",
        "machine": {"cpu_model": "CPU", "logical_cores": 2, "memory_bytes": 2**34, "kernel": "6"},
        "build": {}, "baseline_build": {"CMAKE_BUILD_TYPE": "Release"},
        "software": {"exactgeo_revision": "abc1234", "python": "3.11", "packages": {"numpy": "2"}, "cgal": None},
        "launcher_floor_bytes": 6 * 2**20, "load_average_at_start": [0.1, 0.1, 0.1],
        "load_average_at_end": [0.2, 0.2, 0.2], "configurations": configurations,
        "meshes": [{"name": "m", "faces": 2000, "vertices": 1000, "source": 0}], "records": records,
    }


def table_row(text, heading, first_cells):
    """The cells of the row starting with first_cells in the table under `heading`."""
    section = text.split(heading, 1)[1].split("\n## ", 1)[0]
    for line in section.splitlines():
        cells = [cell.strip() for cell in line.strip("|").split("|")]
        if line.startswith("|") and cells[:len(first_cells)] == first_cells:
            return cells
    raise AssertionError(f"no row {first_cells} under {heading}")


def test_the_headline_gives_exactgeo_over_each_peer_and_the_baseline_over_exactgeo(tmp_path):
    text = write_markdown(tmp_path / "e.md", made_up_report())
    assert (tmp_path / "e.md").read_text() == text
    heading = "## exactgeo against the peers, end to end"
    assert table_row(text, heading, ["mesh"])[3:] == ["exactgeo ÷ heat", "exactgeo ÷ pygeodesic", "exactgeo ÷ gdist",
                                                      "baseline ÷ exactgeo"]
    assert table_row(text, heading, ["m", "2,000", "1"])[3:] == ["0.25x", "—", "0.125x", "3x"]
    assert table_row(text, heading, ["m", "2,000", "2 (every core)"])[3:] == ["0.125x", "—", "0.0625x", "4x"]
    assert "| m | pygeodesic | skipped | pygeodesic not installed" in text


def test_the_steps_table_says_where_an_untimed_step_went(tmp_path):
    text = write_markdown(tmp_path / "e.md", made_up_report())
    heading = "## Where the time goes"
    assert table_row(text, heading, ["m", "exactgeo, 1 thread"])[2:] == [
        "100 ms", "200 ms", "300 ms", "350 ms", "50 ms", "1 s", "65.0%", "100 MB"]
    assert table_row(text, heading, ["m", "baseline, 1 thread"])[6] == "in start"
    assert table_row(text, heading, ["m", "gdist"])[4] == "in solve"
    assert "The stats of the baseline have no `write_seconds`" in text


def test_before_and_after_divides_the_baseline_by_the_current_build_per_step(tmp_path):
    text = write_markdown(tmp_path / "e.md", made_up_report())
    heading = "## Before and after, per step"
    assert table_row(text, heading, ["m", "1"])[2:] == ["4x", "3x", "5x", "1.43x", "—", "3x", "0.5x"]
    assert table_row(text, heading, ["m", "2 (every core)"])[2:7] == ["4x", "6x", "7.5x", "1.67x", "—"]


def test_the_build_timings_appear_where_a_build_reports_them(tmp_path):
    report = made_up_report()
    text = write_markdown(tmp_path / "e.md", report)
    heading = "## The mesh build's steps"
    assert table_row(text, heading, ["mesh"])[2:] == ["exactgeo, 1 thread"]
    assert table_row(text, heading, ["m", "twins"])[2:] == ["200 ms"]
    assert table_row(text, heading, ["m", "build"])[2:] == ["300 ms"]
    report["records"][0]["build_timings"] = None
    assert heading not in write_markdown(tmp_path / "e.md", report)


def test_a_report_without_baseline_or_peers_leaves_their_tables_out(tmp_path):
    report = made_up_report()
    report["configurations"] = [c for c in report["configurations"] if c["kind"] == "exactgeo"]
    report["records"] = [r for r in report["records"] if r["solver"].startswith("exactgeo")]
    report["baseline"] = report["baseline_build"] = None
    text = write_markdown(tmp_path / "e.md", report)
    assert "## Before and after" not in text and "## Runs left out" not in text
    assert table_row(text, "## exactgeo against the peers", ["mesh"]) == ["mesh", "faces", "threads"]


# ------------------------------------------------------------------------------------------- real runs


def test_one_real_run_of_the_command_on_a_built_in_mesh_splits_its_wall_time(tmp_path, exactgeo_cli):
    grid = BenchMesh("@grid:20:20", Path("@grid:20:20"), Path(), Path(), 441, 800)  # the CLI makes the mesh
    run = WholeExactgeoRun("exactgeo-t2", "exactgeo, 2 threads", True, executable=exactgeo_cli, threads=2)
    settings = RunSettings(repeat=2, timeout=60, max_repeat_seconds=60)
    outcomes = [run_once(run, grid, 0, repeat, tmp_path, settings) for repeat in range(2)]
    add_steps([{"status": "ok", "runs": outcomes}])
    stats = json.loads((tmp_path / "s0-r0.stats.json").read_text())
    assert stats["threads"] == 2
    for outcome in outcomes:
        assert "failure" not in outcome, outcome
        assert outcome["build_counts_read"] == ("write_seconds" not in stats)
        parts = outcome["steps"]
        assert all(parts[step] > 0 for step in ("start", "read", "build", "solve"))
        assert (parts["write"] is None) == outcome["build_counts_read"]
        assert parts["start"] < outcome["wall_seconds"]
    assert np.load(run.distances_file(tmp_path, 0)).shape == (441,)
    assert np.load(later_repeat_distances(tmp_path / "s0-r1.stats.json")).shape == (441,)


def test_a_tiny_run_of_the_script_writes_its_json_and_markdown(tmp_path, exactgeo_cli):
    mesh_dir = tmp_path / "meshes"
    mesh_dir.mkdir()
    write_obj(mesh_dir / "grid.obj", *anisotropic_height_field(800, 1.0))
    # The build stands in for its own baseline: the pairing and the ratios are what is tested, not the times.
    end_to_end.main(["--meshes", "grid", "--solvers", "exactgeo", "--threads", "1", "2", "--repeat", "1",
                     "--build-dir", str(exactgeo_cli.parent.parent), "--baseline-build",
                     str(exactgeo_cli.parent.parent), "--baseline-name", "itself", "--mesh-dir", str(mesh_dir),
                     "--work-dir", str(tmp_path / "work"), "--results-dir", str(tmp_path), "--name", "e2e"])
    report = json.loads((tmp_path / "e2e.json").read_text())
    assert [r["solver"] for r in report["records"]] == ["exactgeo-t1", "baseline-t1", "exactgeo-t2", "baseline-t2"]
    assert all(r["status"] == "ok" and r["steps"]["solve"] > 0 for r in report["records"])
    assert all(r["error"]["reference"] == "exactgeo-t1" for r in report["records"])
    assert all(r["error"].get("max_relative_error", 0) < 1e-12 for r in report["records"])
    text = (tmp_path / "e2e.md").read_text()
    assert write_markdown(tmp_path / "again.md", report) == text  # the Markdown is the JSON's alone
    assert table_row(text, "## Before and after, per step", ["grid", threads_text(report, {"threads": 2})])
