"""Tests of threads.py's report (python3 -m pytest bench)."""

from reports.threads import prediction, write_markdown


def mesh_record(name, baseline, one, two):
    def result(seconds, propagations, rss):
        return {"propagation_seconds": seconds, "propagation_seconds_min": seconds, "peak_rss_bytes": rss,
                "window_propagations": propagations, "vertex_pops": 1000, "parallel_bands": 10,
                "parallel_critical_path": 50, "list_crossings": 5000}

    return {
        "name": name, "faces": 2000, "vertices": 1000,
        "results": {"baseline": result(baseline, 300, 100), "1-thread": result(one, 200, 100),
                    "2-threads": result(two, 210, 110)},
        "phases": {"2": {"propagation_seconds": 0.6, "window_propagation_seconds": 0.25, "pruning_seconds": 0.2,
                         "queue_seconds": 0.05, "parallel_seconds": 0.4}},
        "parallel_vs_sequential_relative_error": 1e-16, "same_reachability": True,
        "sequential_vs_baseline_relative_error": 0.0,
        "heat": {"factor_seconds": 2.0, "solve_seconds": 0.1, "max_relative_error": 0.02, "mean_relative_error": 0.005},
    }


def report(*meshes):
    return {"date": "2026-01-01T00:00:00+00:00", "command": "python3 bench/threads.py --runs 5", "baseline": "abc1234",
            "machine": {"cpu_model": "CPU", "logical_cores": 2}, "load_average_at_start": [0.1, 0.1, 0.1],
            "load_average_at_end": [0.2, 0.2, 0.2], "meshes": list(meshes)}


def test_the_ratios_say_how_many_times_faster(tmp_path):
    text = write_markdown(tmp_path / "threads.md", report(mesh_record("m", baseline=2.0, one=1.0, two=0.5)))
    row = next(line for line in text.splitlines() if line.startswith("| m |"))
    cells = [cell.strip() for cell in row.strip("|").split("|")]
    assert cells[2:4] == ["300", "200"]  # propagations: baseline, now
    assert cells[7:10] == ["2.00x", "2.00x", "4.00x"]  # 1 thread vs baseline, 2 vs 1, 2 vs baseline
    assert cells[10] == "1.10"  # peak RSS, 2 threads ÷ 1
    assert (tmp_path / "threads.md").read_text() == text


def test_the_heat_table_divides_the_exact_time_by_the_heat_solve(tmp_path):
    text = write_markdown(tmp_path / "threads.md", report(mesh_record("m", baseline=2.0, one=1.0, two=0.5)))
    heat_row = [line for line in text.splitlines() if line.startswith("| m |")][1]
    assert "| 10.00 | 5.00 | 2.0e-02 | 5.0e-03 |" in heat_row


def test_the_prediction_divides_only_the_shared_phases():
    # Of the 2-thread run's 0.6 s, 0.4 s are shared phases (0.8 s of work for the two threads) and 0.2 s stay
    # on one thread.
    predicted = prediction(mesh_record("m", 2.0, 1.0, 0.5))
    assert abs(predicted[8] - (0.2 + 0.8 / 8)) < 1e-12
    assert abs(predicted[16] - (0.2 + 0.8 / 16)) < 1e-12


def test_the_prediction_stops_at_the_critical_path():
    # 5000 crossings, 500 of them in a row: on 16 threads the shared 0.8 s of work cannot take less than a
    # tenth of it.
    record = mesh_record("m", 2.0, 1.0, 0.5)
    record["results"]["2-threads"]["parallel_critical_path"] = 500
    predicted = prediction(record)
    assert abs(predicted[8] - (0.2 + 0.8 / 8)) < 1e-12
    assert abs(predicted[16] - (0.2 + 0.8 / 10)) < 1e-12


def test_a_run_without_baseline_or_heat_leaves_those_cells_empty(tmp_path):
    record = mesh_record("m", 2.0, 1.0, 0.5)
    del record["results"]["baseline"], record["sequential_vs_baseline_relative_error"]
    record["heat"] = None
    text = write_markdown(tmp_path / "threads.md", {**report(record), "baseline": None})
    row = next(line for line in text.splitlines() if line.startswith("| m |"))
    assert row.count("—") == 4  # baseline propagations, time, and both ratios against it
    assert "No heat figures for m: potpourri3d was not installed" in text
    assert len([line for line in text.splitlines() if line.startswith("| m |")]) == 2  # no heat row
