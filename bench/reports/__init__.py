"""The reporting half of the benchmark: what a run measured, turned into JSON, Markdown tables and figures.

tables.py is the one way every report writes a table and formats its numbers.
"""
