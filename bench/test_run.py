"""Tests of run.py's command line and of its report's scaling fit (python3 -m pytest bench)."""

import os

from reports.peers import log_log_slope
from run import parse_args


def test_relative_paths_become_absolute_so_runs_in_other_directories_find_the_binaries(tmp_path):
    previous = os.getcwd()
    os.chdir(tmp_path)
    try:
        args = parse_args(["--build-dir", "build", "--work-dir", "work", "--results-dir", "results"])
    finally:
        os.chdir(previous)
    assert args.build_dir == tmp_path / "build"
    assert args.exactgeo == tmp_path / "build" / "cli" / "exactgeo"
    assert args.cgal_driver == tmp_path / "build" / "bench" / "exactgeo_cgal_driver"
    for path in (args.work_dir, args.results_dir, args.mesh_dir):
        assert path.is_absolute()


def test_log_log_slope_recovers_the_exponent_of_a_power_law():
    assert abs(log_log_slope([(10.0, 3 * 10.0**1.5), (1000.0, 3 * 1000.0**1.5), (4e5, 3 * 4e5**1.5)]) - 1.5) < 1e-12
    assert log_log_slope([(10.0, 1.0)]) is None  # one point fixes no slope
