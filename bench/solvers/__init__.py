"""The measuring half of the benchmark: how each solver is run and what is taken from the run.

commands.py says how each solver is started and how its output reads; runner.py runs them one process at a
time through launch.py (caps, peak RSS, repeats, medians, errors); in_process.py times the Python packages
inside one process; many_sources.py times exactgeo's many-source commands; end_to_end.py runs whole commands
from the mesh file and splits their wall time into steps. Nothing here writes a report (see reports/).
"""
