"""threads.py's runs: `exactgeo distance` of one build on each thread count, timed or with its timers on.

Only the built command is run: nothing here imports the exactgeo package, so the script runs on a machine that
has the binaries and the meshes alone.
"""

from __future__ import annotations

import dataclasses
import json
import statistics
from pathlib import Path
from typing import ClassVar

from solvers.end_to_end import WholeExactgeoRun

# What a timed run (--timers, more than one thread) reports of where the threads' time went.
kTimerKeys = ["setup_seconds", "queue_seconds", "parallel_seconds", "parallel_busy_seconds",
              "parallel_busiest_thread_seconds", "parallel_start_seconds", "parallel_starved_seconds",
              "parallel_lock_wait_seconds", "parallel_lock_waits", "parallel_bands", "parallel_critical_path"]


@dataclasses.dataclass
class ThreadsRun(WholeExactgeoRun):
    """`exactgeo distance MESH --source S --quiet --threads T --stats S.json --out D.npy`, with --timers when
    `timers`; its stats as the report reads them, the band timeline summed up."""

    stats_keys: ClassVar[list[str]] = [*WholeExactgeoRun.stats_keys, "list_crossings", *kTimerKeys]

    timers: bool = False

    def command(self, mesh, source, distances, stats):
        return super().command(mesh, source, distances, stats) + ["--quiet"] + (["--timers"] if self.timers else [])

    def read_stats(self, stats):
        read = super().read_stats(stats)
        if self.timers and self.threads:
            timeline = json.loads(stats.read_text()).get("band_timeline")
            if timeline:  # the whole timeline stays in the run's stats file; the report needs a typical band
                read["band_crossings_per_thread"] = statistics.median(timeline["crossings"]) / self.threads
        return read


def threads_runs(threads: list[int], exactgeo: Path, baseline: Path | None = None, baseline_threads: bool = True,
                 timers: bool = False) -> list[ThreadsRun]:
    """The runs of one mesh, in the order they take turns: exactgeo on each thread count, each followed by the
    baseline on as many (on one, without --threads, if it has no such option: baseline_threads False). With
    `timers`, exactgeo alone on the counts above one, its timers on (they cost a little, so apart)."""
    runs = []
    for count in threads:
        label = f"{count} thread" + ("" if count == 1 else "s")
        if timers:
            if count > 1:
                runs.append(ThreadsRun(f"timers-t{count}", f"exactgeo, {label}, timers on", True,
                                       executable=exactgeo, threads=count, timers=True))
            continue
        runs.append(ThreadsRun(f"exactgeo-t{count}", f"exactgeo, {label}", True, executable=exactgeo, threads=count))
        if baseline is not None and (baseline_threads or count == 1):
            runs.append(ThreadsRun(f"baseline-t{count}", f"baseline, {label}" if baseline_threads
                                   else "baseline (no --threads)", True, executable=baseline,
                                   threads=count if baseline_threads else None, baseline=True))
    return runs
