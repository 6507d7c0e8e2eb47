"""The reporting half of the benchmark: what a run measured, turned into JSON, Markdown tables and figures.

tables.py and figures.py are the one way every report writes a table or a plot; machine.py says where the
numbers came from; the other modules are one report each. Nothing here runs a solver (see solvers/).
"""
