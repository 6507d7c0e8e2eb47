"""Many-source work on one mesh: the distance matrix on 1 thread and on every core, and one multi-source run
against as many single-source runs. Writes bench/results/many-sources.{json,md}.

usage: python3 bench/many_sources.py [--mesh nefertiti] [--sources 16] [--build-dir build]

All times come from runs of the `exactgeo` command in this process's run, one after the other:
- matrix: the wall time of `exactgeo matrix --threads T` (mesh loading included, the same in every run);
- multi-source: propagation_seconds of one `exactgeo distance` with every source, against the sum of
  propagation_seconds of one run per source. The matrix rows are checked bit for bit across thread counts,
  and their minimum against the multi-source distances.
"""

from __future__ import annotations

import argparse
import datetime
import json
from pathlib import Path

from meshes import prepare_meshes
from reports.machine import machine_info
from reports.many_sources import write_markdown
from solvers.many_sources import measure_many_sources
from solvers.runner import choose_sources

kBenchDir = Path(__file__).resolve().parent


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--mesh", default="nefertiti", help="a mesh of ../shared/meshes (default nefertiti)")
    parser.add_argument("--sources", type=int, default=16, help="seeded source vertices (default 16)")
    parser.add_argument("--build-dir", type=Path, default=kBenchDir.parent / "build")
    parser.add_argument("--mesh-dir", type=Path, default=kBenchDir.parent.parent / "shared" / "meshes")
    parser.add_argument("--work-dir", type=Path, default=kBenchDir / "work")
    parser.add_argument("--results-dir", type=Path, default=kBenchDir / "results")
    args = parser.parse_args()
    exactgeo = (args.build_dir / "cli" / "exactgeo").resolve()
    mesh = next(m for m in prepare_meshes(args.mesh_dir.resolve(), args.work_dir.resolve(), {}) if m.name == args.mesh)
    sources = choose_sources(mesh, args.sources, seed=1)
    report = {
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "machine": machine_info(),
        **measure_many_sources(exactgeo, mesh, sources, args.work_dir.resolve() / "runs" / "many-sources"),
    }
    args.results_dir.mkdir(parents=True, exist_ok=True)
    (args.results_dir / "many-sources.json").write_text(json.dumps(report, indent=1))
    print(write_markdown(args.results_dir / "many-sources.md", report))


if __name__ == "__main__":
    main()
