"""CSV files separated by `;` (Excel's export in German and most European locales, with
decimal commas) or tabs read as the comma files they stand for (`twin.runs.csv_format`).
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.test_runs_reader import csv_text, expect_error, warmup, write
from twin.errors import InputError
from twin.runs import read_run
from twin.runs.csv_format import read_csv_table


def other_dialect(text: str, separator: str, excel: bool = False) -> str:
    """`text` (a comma CSV with decimal points) with `separator` and decimal commas; with
    `excel` as a spreadsheet's General format writes the numbers: without trailing zeros
    ("24,59" for 24.5900, "2" for 2.000, "9000" for 9000.0)."""
    def cell(value: str) -> str:
        if excel and "." in value:
            value = value.rstrip("0").rstrip(".")
        return value.replace(".", ",")

    return "\n".join(line if line.startswith("#") or not line else
                     separator.join(cell(c) for c in line.split(","))
                     for line in text.split("\n"))


def semicolon_run(tmp_path, edit=None, name: str = "semi.csv"):  # noqa: ANN001, ANN201
    """A warm-up run in `;` and decimal commas, its lines changed by `edit(lines)`."""
    lines = other_dialect(csv_text(warmup(30, 5.0)), ";").splitlines()
    if edit is not None:
        edit(lines)
    return write(tmp_path, "\n".join(lines) + "\n", name)


def set_cell(lines: list[str], line: int, column: int, value: str) -> None:
    cells = lines[line - 1].split(";")
    cells[column] = value
    lines[line - 1] = ";".join(cells)


@pytest.mark.parametrize("separator", [";", "\t"])
@pytest.mark.parametrize("excel", [False, True])
def test_decimal_commas_read_as_the_comma_file(tmp_path, separator, excel):
    clean = csv_text(warmup(), "# name: demo\n")
    a = read_run(write(tmp_path, clean, "clean.csv"))
    b = read_run(write(tmp_path, other_dialect(clean, separator, excel)))
    for name in ("time_s", "speed_rpm", "ambient_C", *(f"T{k}_C" for k in range(1, 6))):
        assert np.array_equal(a.column(name), b.column(name)), name
    assert b.metadata == a.metadata
    name = {";": "semicolon", "\t": "tab"}[separator]
    assert b.quality == [{"column": "", "kind": "csv_dialect", "count": 300, "rows": [],
                          "spans_s": [], "action": f"read as {name}-separated, with decimal "
                          "commas", "detail": "the twin writes its files comma-separated, "
                          "with decimal points"}]


def test_a_plain_comma_file_is_read_as_before(tmp_path):
    # a one-column comma file stays one (no ';' or tab in its header), and a comma file is
    # told nothing about its dialect
    table = read_csv_table(write(tmp_path, "time_s\n0\n1.5\n"), "time_s".__eq__)
    assert table.dialect == "" and table.columns["time_s"].tolist() == [0.0, 1.5]
    assert read_run(write(tmp_path, csv_text(warmup()), "c.csv")).quality == []


def test_spreadsheet_rules_hold_for_each_separator(tmp_path):
    """The rules written for ',' first: rows of separators (also above the header), the
    padding a spreadsheet writes after a row and after a `;` file's metadata lines, the
    header written again, a units row."""
    clean = csv_text(warmup(30, 5.0), "# name: demo\n")
    lines = other_dialect(clean, ";").splitlines()
    padded = ([";;;;", lines[0] + ";;;;", lines[1] + ";;;"] + [ln + ";;" for ln in lines[2:6]]
              + [";;;;;;;;;;", " ;; ;"] + lines[6:] + [";;;;;;;;"])
    a = read_run(write(tmp_path, clean, "clean.csv"))
    b = read_run(write(tmp_path, "\n".join(padded) + "\n", "padded.csv"))
    assert np.array_equal(a.T_C, b.T_C) and np.array_equal(a.time_s, b.time_s)
    assert b.metadata == {"name": "demo"} and b.name == "demo"
    # the lines keep their editor's numbers; a stray value under no name is still told
    broken = list(padded)
    broken[10] = broken[10].replace(broken[10].split(";")[0], "x", 1)
    expect_error(write(tmp_path, "\n".join(broken) + "\n"), 11, "time_s",
                 "cannot read 'x' as a number")
    expect_error(write(tmp_path, "\n".join(lines[:5] + [lines[5] + ";;7"] + lines[6:]) + "\n"),
                 6, None, "expected 8 fields")
    # a ',' row is no blank row of a `;` file
    expect_error(write(tmp_path, "\n".join(lines[:5] + [",,,,,,,"] + lines[5:]) + "\n"), 6,
                 None, "expected 8 fields as in the header, found 1")
    expect_error(write(tmp_path, "\n".join(lines[:5] + [lines[1]] + lines[5:]) + "\n"), 6,
                 None, "the header again (line 2 holds it)")
    units = ";".join(["s", "rpm", "°C", "°C", "°C", "°C", "°C", "°C"])
    expect_error(write(tmp_path, "\n".join(lines[:2] + [units] + lines[2:]) + "\n"), 3,
                 "time_s", "a units row?")


def test_a_header_holding_both_semicolons_and_tabs_needs_a_hint(tmp_path):
    text = "time_s;speed_rpm;ambient_C\tT1_C;T2_C;T3_C;T4_C;T5_C\n0;9000;25;25;25;25;25;25\n"
    expect_error(write(tmp_path, text), 1, None, "the header holds both ';' and tabs")
    table = read_csv_table(write(tmp_path, "sep=;\n" + text.replace("\t", ";"), "h.csv"))
    assert table.columns["T1_C"].tolist() == [25.0] and table.header_row == 2


@pytest.mark.parametrize(("cell", "words"), [
    ("1.234,5", "cannot read '1.234,5' as a number (thousands separators? write numbers "
                "without them: 9000, 22,5)"),
    ("9,000.5", "cannot read '9,000.5' as a number (thousands separators?"),
    ("1.234.567", "cannot read '1.234.567' as a number (thousands separators?"),
    ("2,5,1", "cannot read '2,5,1' as a number"),
    ("22,5 °C", "cannot read '22,5 °C' as a number"),
])
def test_a_cell_with_thousands_separators_is_refused(tmp_path, cell, words):
    path = semicolon_run(tmp_path, lambda lines: set_cell(lines, 12, 4, cell))
    expect_error(path, 12, "T2_C", words)


def test_a_speed_that_reads_as_thousands_or_decimals_is_refused_unless_the_file_tells(
        tmp_path):
    """'9.000' is 9000 rpm in a German export formatted with thousands separators, or 9.0;
    '9,000' is 9000 in an English one, or 9.0.  The file's other numbers tell which mark
    is the decimal one; where they do not, the cell is refused."""
    # the warm-up's other cells have decimal commas ("25,0000"): '9.000' is refused, as
    # the first such cell
    path = semicolon_run(tmp_path, lambda lines: [set_cell(lines, n, 1, "9.000")
                                                  for n in (7, 9)])
    expect_error(path, 7, "speed_rpm", "cannot read '9.000' as a number: 9000 with a "
                 "thousands separator, or 9 with a decimal point? the file's other numbers "
                 "have decimal commas (line 2, column 'time_s': '0,0000'); write 9000 or 9,0")
    # ... and '9,000' is 9.0 there, as '12,500' is 12.5
    table = read_csv_table(semicolon_run(
        tmp_path, lambda lines: [set_cell(lines, 7, 1, "9,000"), set_cell(lines, 8, 1, "12,500")],
        "comma.csv"))
    assert table.columns["speed_rpm"][4:8].tolist() == [9000.0, 9.0, 12.5, 9000.0]

    def points(lines: list[str]) -> None:
        lines[:] = [ln.replace(",", ".") for ln in lines]

    # in a file of decimal points '9.000' is 9.0, and '9,000' the refused one
    table = read_csv_table(semicolon_run(
        tmp_path, lambda lines: [points(lines), set_cell(lines, 7, 1, "9.000")], "points.csv"))
    assert table.columns["speed_rpm"][5] == 9.0 and table.dialect == "semicolon-separated"
    path = semicolon_run(tmp_path, lambda lines: [points(lines),
                                                  set_cell(lines, 7, 1, "9,000")])
    expect_error(path, 7, "speed_rpm", "9000 with a thousands separator, or 9 with a decimal "
                 "comma? the file's other numbers have decimal points (line 2, column "
                 "'time_s': '0.0000'); write 9000 or 9.0")
    # a file of both marks, or of neither, tells nothing
    path = semicolon_run(tmp_path, lambda lines: [set_cell(lines, 5, 3, "25.5"),
                                                  set_cell(lines, 7, 1, "9,000")])
    expect_error(path, 7, "speed_rpm", "have decimal commas (line 2, column 'time_s': "
                 "'0,0000') and decimal points (line 5, column 'T1_C': '25.5')")
    profile = write(tmp_path, "time_s;speed_rpm\n0;0\n60;9.000\n120;0\n", "profile.csv")
    with pytest.raises(InputError, match="no other number in the file has a decimal mark to "
                       "tell; write 9000 or 9,0"):
        read_csv_table(profile, max_rows=None)


@pytest.mark.parametrize("cell", ["0,500", "1234,567", "9,0001", "9,000e3", "-0,125", ",5"])
def test_a_cell_a_thousands_separator_cannot_make_is_a_decimal_comma(tmp_path, cell):
    # in a file of decimal points: these are decimal commas all the same (mixed, each
    # unambiguous), and so no '9,000' in it is read
    def edit(lines: list[str]) -> None:
        lines[:] = [ln.replace(",", ".") for ln in lines]
        set_cell(lines, 7, 3, cell)

    table = read_csv_table(semicolon_run(tmp_path, edit))
    assert table.columns["T1_C"][5] == float(cell.replace(",", "."))
    assert table.dialect == "semicolon-separated, with decimal commas"
