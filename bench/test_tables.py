"""Tests of the shared Markdown table helper and number formats (python3 -m pytest bench)."""

import pytest

from reports.tables import (
    format_bytes,
    format_count,
    format_megabytes,
    format_percent,
    format_ratio,
    format_relative_error,
    format_seconds,
    format_times,
    markdown_table,
    runs_text,
)


def test_a_table_has_a_header_a_separator_aligned_per_column_and_one_line_per_row():
    assert markdown_table(["mesh", "faces", "time"], [["woody", 1267, "1.2 ms"], ["spot", 5856, "4 ms"]], "lrr") == [
        "| mesh | faces | time |",
        "|---|---:|---:|",
        "| woody | 1,267 | 1.2 ms |",
        "| spot | 5,856 | 4 ms |",
    ]


def test_a_table_without_rows_is_its_header():
    assert markdown_table(["solver"], [], "l") == ["| solver |", "|---|"]


def test_a_pipe_in_a_cell_or_heading_is_escaped_so_it_cannot_split_the_cell():
    lines = markdown_table(["a|b"], [["exit code 1: x | y"]], "l")
    assert lines[0] == r"| a\|b |"
    assert lines[2] == r"| exit code 1: x \| y |"


def test_missing_values_show_as_a_dash_and_integers_with_thousands_separators():
    assert markdown_table(["n", "m"], [[None, 1_599_008]], "rr")[2] == "| — | 1,599,008 |"
    assert markdown_table(["empty"], [[""]], "l")[2] == "|  |"


def test_a_float_must_be_formatted_before_it_goes_into_a_table():
    with pytest.raises(TypeError, match="format 0.5"):
        markdown_table(["x"], [[0.5]], "r")
    with pytest.raises(TypeError):
        markdown_table(["x"], [[True]], "r")


def test_alignment_and_row_length_must_match_the_header():
    with pytest.raises(ValueError, match="l or r"):
        markdown_table(["a", "b"], [], "l")
    with pytest.raises(ValueError, match="l or r"):
        markdown_table(["a"], [], "c")
    with pytest.raises(ValueError, match="row of 1 cells"):
        markdown_table(["a", "b"], [["x"]], "ll")


def test_seconds_take_three_significant_digits_in_the_unit_that_fits():
    assert format_seconds(None) == "—"
    assert format_seconds(7.4573e-06) == "7.46 µs"
    assert format_seconds(0.0231) == "23.1 ms"
    assert format_seconds(0.5) == "500 ms"
    assert format_seconds(1.0) == "1 s"
    assert format_seconds(123.4) == "123 s"


def test_bytes_are_megabytes_below_a_gibibyte_and_marked_at_the_launchers_floor():
    assert format_bytes(None) == "—"
    assert format_bytes(6.79 * 1024**2) == "6.79 MB"
    assert format_bytes(11.2 * 1024**3) == "11.2 GB"
    floor = 6_500_000
    assert format_bytes(floor * 1.05, floor) == f"≤ {floor * 1.05 / 1024**2:.3g} MB"
    assert not format_bytes(floor * 1.06, floor).startswith("≤")
    assert format_megabytes(2 * 1024**3) == "2.05e+03 MB"  # the paper's unit, however large


def test_counts_ratios_percentages_and_errors_format_as_the_reports_print_them():
    assert format_count(4_943_670) == "4,943,670"
    assert format_count(None) == "—"
    assert format_times(3.8123) == "3.81x"
    assert format_ratio(2.0, 4.0) == "0.5x"
    assert format_ratio(2.0, 0.0) == format_ratio(None, 4.0) == "—"
    assert format_percent(0.9625) == "96.2%"
    assert format_percent(-0.5) == "-50.0%"
    assert format_relative_error(0.0) == "0"
    assert format_relative_error(1.2345e-15) == "1.2e-15"
    assert runs_text(1) == "1 run" and runs_text(5) == "median of 5 runs"
