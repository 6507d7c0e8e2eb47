"""Tests of distributed_matrix.py and its report: a --quick run end to end, and the all-pairs store's figures from
a partial store (python3 -m pytest bench). Nothing here asserts a timing."""

import json
import shutil
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("distributed", reason="needs dask[distributed]: pip install 'dask[distributed]>=2023.1'")
pytest.importorskip("zarr", reason="needs zarr: pip install 'zarr>=3'")

import distributed_matrix  # noqa: E402
import exactgeo  # noqa: E402
from exactgeo import distributed  # noqa: E402
from reports.distributed import write_markdown  # noqa: E402

kMeshDir = Path(__file__).resolve().parent.parent.parent / "shared" / "meshes"


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    if not all((kMeshDir / f"{name}.obj").exists() for name in ("woody", "nefertiti")):
        pytest.skip(f"{kMeshDir} lacks woody.obj or nefertiti.obj")
    results = tmp_path_factory.mktemp("results")
    assert distributed_matrix.main(["--quick", "--results-dir", str(results), "--work-dir", str(results / "work"),
                                    "--name", "d"]) == 0
    return results, json.loads((results / "d.json").read_text())


def test_a_quick_run_measures_both_workloads_on_one_and_two_workers(quick_run):
    _, report = quick_run
    assert [w["label"] for w in report["workloads"]] == ["all-pairs", "many-sources"]
    for workload in report["workloads"]:
        assert all(len(samples) == 1 for samples in workload["samples"].values())
        assert all(seconds > 0 for seconds in workload["median_wall_seconds"].values())
        assert workload["dask_speedup"] > 0 and workload["in_process_speedup"] > 0
        assert workload["store_equals_in_process"]
        assert workload["block_float32_bytes"] == workload["block_rows"] * workload["targets"] * 4
        assert workload["blocks"] == -(-workload["sources"] // workload["block_rows"])
        assert workload["engine_bytes"] > 0 and workload["mesh_bytes"] > 0
        for memory in workload["memory"].values():
            assert memory["worker_baseline_rss_bytes"] > 0 and memory["worker_growth_bytes"] >= 0
            assert memory["worker_peak_rss_bytes"] >= memory["worker_baseline_rss_bytes"]
    all_pairs = report["workloads"][0]
    assert all_pairs["sources"] == all_pairs["targets"] == all_pairs["vertices"]  # woody: every vertex used


def test_the_nefertiti_store_is_measured_in_part_and_extrapolated_to_every_row(quick_run):
    _, report = quick_run
    part = report["nefertiti_all_pairs"]
    measured, whole = part["measured"], part["extrapolated"]
    assert measured["blocks_done"] == 2 and measured["rows_done"] == 2 * measured["block_rows"]
    assert measured["columns"] == part["vertices"]
    assert 0 < measured["fixed_disk_bytes"] < measured["disk_bytes"]
    rows = part["vertices"]
    assert whole["uncompressed_bytes"] == rows * rows * 4
    assert whole["disk_bytes"] > measured["disk_bytes"] and whole["core_seconds"] > measured["block_seconds_sum"]
    assert report["tiny_blocks"]["blocks"] == 128


def test_the_160k_extrapolation_divides_the_source_seconds_among_the_cores(quick_run):
    _, report = quick_run
    e = report["extrapolation"]
    assert e["output_bytes"] == 160_000**2 * 4 and len(e["points"]) == 2
    assert e["source_seconds"] == pytest.approx(160_000 * e["per_source_seconds"])
    assert set(e["cores"]) == {"64", "512"}
    assert e["cores"]["64"]["wall_seconds"] == pytest.approx(8 * e["cores"]["512"]["wall_seconds"])
    wall = e["cores"]["64"]["wall_seconds"]
    assert e["cores"]["64"]["output_bytes_per_second"] == pytest.approx(e["output_bytes"] / wall)


def test_the_markdown_is_made_from_the_json(quick_run, tmp_path):
    results, report = quick_run
    text = write_markdown(tmp_path / "d.md", report)
    assert text == (results / "d.md").read_text()
    for heading in ("## One worker against two", "## Scheduler overhead per block", "## Peak memory per worker",
                    "## Nefertiti all-pairs, float32", "## 160K-vertex all-pairs on 64 and 512 cores (extrapolated)"):
        assert heading in text
    assert "a check of the script, not results" in text


def test_a_partial_store_extrapolates_to_its_whole(tmp_path):
    mesh = exactgeo.Mesh(*exactgeo.make_bumpy_torus(16, 8))
    sources = np.arange(mesh.vertex_count)
    store = tmp_path / "all.zarr"
    with ThreadPoolExecutor(2) as executor:
        distributed.distance_matrix_to_zarr(mesh, sources, store, block_rows=16, client=executor)
    whole = distributed_matrix.store_figures(store)
    assert (whole["blocks"], whole["blocks_done"], whole["rows_done"]) == (8, 8, 128)
    for block in (1, 5, 6):  # as if never computed: no marker, no chunk (c/B/0)
        shutil.rmtree(store / "done" / f"block_{block:06d}")
        shutil.rmtree(store / "distances" / "c" / str(block))
    part = distributed_matrix.store_figures(store)
    assert (part["blocks_done"], part["rows_done"]) == (5, 80)
    estimate = distributed_matrix.extrapolated(part, part["rows"], part["blocks"], 2)
    assert estimate["uncompressed_bytes"] == 128 * 128 * 4
    assert estimate["core_seconds"] == pytest.approx(part["block_seconds_sum"] / 80 * 128)
    assert estimate["wall_seconds"] == pytest.approx(estimate["core_seconds"] / 2)
    # Chunks of a smooth torus compress alike, so the bytes per block carry over within a disk block or two.
    assert abs(estimate["disk_bytes"] - whole["disk_bytes"]) <= 4 * 4096 + 0.2 * whole["disk_bytes"]
    for block in range(8):
        shutil.rmtree(store / "done" / f"block_{block:06d}", ignore_errors=True)
    assert distributed_matrix.extrapolated(distributed_matrix.store_figures(store), 128, 8, 2) is None


def test_a_report_of_the_whole_store_alone_reads(quick_run, tmp_path):
    _, report = quick_run
    header = {key: report[key] for key in ("name", "date", "command", "settings", "machine", "software",
                                           "load_average_at_start")}
    figures = {"rows": 10, "columns": 10, "block_rows": 5, "blocks": 2, "blocks_done": 1, "rows_done": 5,
               "block_seconds_sum": 2.0, "disk_bytes": 9000, "fixed_disk_bytes": 1000}
    store = {"store": "s.zarr", "command": "python3 bench/distributed_matrix.py --nefertiti-all-pairs s.zarr",
             "date": "2026-01-01T00:00:00+00:00", "session_wall_seconds": 1.5, **figures,
             "extrapolated": distributed_matrix.extrapolated(figures, 10, 2, 2)}
    text = write_markdown(tmp_path / "s.md", {**header, "nefertiti_all_pairs_store": store})
    assert "## Nefertiti all-pairs, the whole store" in text and "in progress" in text
    assert "| core-seconds (extrapolated) | 4 s |" in text
    assert "## One worker against two" not in text


def test_memory_only_measures_the_workers_on_a_few_blocks_and_times_nothing(tmp_path):
    if not all((kMeshDir / f"{name}.obj").exists() for name in ("woody", "nefertiti")):
        pytest.skip(f"{kMeshDir} lacks woody.obj or nefertiti.obj")
    assert distributed_matrix.main(["--quick", "--memory-only", "--memory-blocks", "2", "--results-dir", str(tmp_path),
                                    "--work-dir", str(tmp_path / "work")]) == 0
    report = json.loads((tmp_path / "distributed-memory-quick.json").read_text())
    for workload in report["workloads"]:
        assert workload["blocks_measured"] == 2 and "median_wall_seconds" not in workload
        for memory in workload["memory"].values():
            assert memory["worker_peak_rss_bytes"] >= memory["worker_baseline_rss_bytes"] > 0
    text = (tmp_path / "distributed-memory-quick.md").read_text()
    assert "## Peak memory per worker" in text and "## One worker against two" not in text
    assert "the first 2 blocks of the all-pairs layout" in text
