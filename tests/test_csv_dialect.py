"""CSV files separated by `;` (Excel's export in German and most European locales, with
decimal commas) or tabs read as the comma files they stand for (`twin.runs.csv_format`).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from tests.test_runs_reader import csv_text, expect_error, warmup, write
from twin.cli import app
from twin.data import bundled_path
from twin.errors import InputError
from twin.plant.profile import read_speed_profile
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
    # a German thousands separator in a comma file (a quoted cell) is told as one there too
    lines = csv_text(warmup()).splitlines()
    lines[9] = '"1.234,5",' + lines[9].split(",", 1)[1]
    expect_error(write(tmp_path, "\n".join(lines) + "\n"), 10, "time_s",
                 "cannot read '1.234,5' as a number (a thousands separator, or a decimal comma?")


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
    # the first such cell, before a later bad cell (told in file order)
    path = semicolon_run(tmp_path, lambda lines: [
        *(set_cell(lines, n, 1, "9.000") for n in (7, 9)), set_cell(lines, 12, 3, "1.234,5")])
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


def test_a_temperature_with_three_decimals_is_a_decimal_and_a_refusal_says_what_decides(
        tmp_path):
    """A ';' logger writing integer times and speeds and three-decimal temperatures had
    every '22,125' refused (no other number showed the mark), and the message's way out
    was the refused cell itself.  A temperature is never grouped: read as 22.125 °C.  A
    speed still is refused, and told a fourth decimal decides."""
    text = ("time_s;speed_rpm;ambient_C;T1_C;T2_C;T3_C;T4_C;T5_C\n"
            + "".join(f"{60 * k};9000;22,125;{22 + k},125;22,250;22,375;22,500;22,625\n"
                      for k in range(4)))
    table = read_csv_table(write(tmp_path, text, "three.csv"))
    assert table.columns["T1_C"].tolist() == [22.125, 23.125, 24.125, 25.125]
    assert table.columns["ambient_C"][0] == 22.125
    profile = write(tmp_path, "time_s;speed_rpm\n0;0\n60;9,125\n120;0\n", "profile.csv")
    with pytest.raises(InputError, match="tell; write 9125 or 9,1250$"):
        read_csv_table(profile, max_rows=None)


# Through the commands, as a user runs them: every CSV input goes through the one reader.

BUNDLED_RUN = "spindle_steps_faults_30min.csv"  # its faults: gaps, nan cells, a dead sensor
REAL_DATA = Path(__file__).resolve().parent.parent / "examples" / "real" / "train.csv"


def twin(*args: str):  # noqa: ANN201 - click's Result
    return CliRunner().invoke(app, list(args))


def copy_as(source: Path, folder: Path, separator: str, excel: bool = False) -> Path:
    """`source` written in `separator` and decimal commas under the same name in `folder`
    (the name a command writes into its outputs)."""
    folder.mkdir(exist_ok=True)
    path = folder / source.name
    path.write_text(other_dialect(source.read_text(), separator, excel))
    return path


@pytest.mark.slow
def test_replay_of_a_semicolon_or_tab_copy_of_a_bundled_run_scores_the_same(tmp_path):
    source = bundled_path("runs", BUNDLED_RUN)
    copies = {"comma": tmp_path / "comma" / BUNDLED_RUN,
              # as German Excel's "CSV (Trennzeichen-getrennt)" writes General-format cells
              "semicolon": copy_as(source, tmp_path / "semicolon", ";", excel=True),
              # decimal commas with every digit kept: '2,000' s, which the others decide
              "tab": copy_as(source, tmp_path / "tab", "\t")}
    copies["comma"].parent.mkdir()
    copies["comma"].write_bytes(source.read_bytes())
    assert "\n2,000;" not in copies["semicolon"].read_text()  # "2;6000;24,6366;..."
    assert "\n2,000\t6000,0\t" in copies["tab"].read_text()
    out = {}
    for name, path in copies.items():
        out[name] = tmp_path / f"out_{name}" / path.stem
        result = twin("replay", str(path), "--out", str(out[name].parent), "--snapshots",
                      "none", "--fields", "none", "--quiet")
        assert result.exit_code == 0, result.output
    for name, dialect in (("semicolon", "semicolon"), ("tab", "tab")):
        for file in ("accuracy.json", "keypoints.csv", "corrections.csv"):
            assert (out[name] / file).read_bytes() == (out["comma"] / file).read_bytes(), file
        quality = json.loads((out[name] / "quality.json").read_text())["findings"]
        plain = json.loads((out["comma"] / "quality.json").read_text())["findings"]
        assert quality[1:] == plain and quality[0]["kind"] == "csv_dialect"
        assert quality[0]["action"] == f"read as {dialect}-separated, with decimal commas"
    assert "csv_dialect" not in {f["kind"] for f in plain}


@pytest.mark.parametrize(("command", "cell", "column", "words"), [
    ("replay", "1.234,5", 6, "cannot read '1.234,5' as a number (thousands separators?"),
    ("snapshot", "9.000", 1, "cannot read '9.000' as a number: 9000 with a thousands "
                             "separator, or 9 with a decimal point? the file's other numbers "
                             "have decimal commas (line 2, column 'time_s': '0,0000')"),
    ("train", "25,5,1", 4, "cannot read '25,5,1' as a number"),
])
def test_a_bad_cell_of_a_semicolon_run_exits_2_naming_file_line_and_column(
        tmp_path, command, cell, column, words):
    path = semicolon_run(tmp_path, lambda lines: set_cell(lines, 9, column, cell))
    before = path.read_bytes()
    out = tmp_path / "out"
    args = {"replay": ["--out", str(out), "--methods", "open_loop"],
            "snapshot": ["--time", "60", "--out", str(tmp_path / "s.png")],
            "train": ["--out", str(tmp_path / "m.safetensors")]}[command]
    result = twin(command, str(path), *args)
    assert result.exit_code == 2, result.output
    name = ["time_s", "speed_rpm", "ambient_C", "T1_C", "T2_C", "T3_C", "T4_C", "T5_C"][column]
    assert f"{path}, line 9, column '{name}': {words}" in result.output
    assert "Traceback" not in result.output
    assert path.read_bytes() == before
    assert not (tmp_path / "s.png").exists() and not (tmp_path / "m.safetensors").exists()


def test_drift_fit_on_a_semicolon_copy_of_the_real_data_writes_the_same_model(
        tmp_path, monkeypatch):
    comma = tmp_path / "comma"
    comma.mkdir()
    (comma / REAL_DATA.name).write_bytes(REAL_DATA.read_bytes())
    copy_as(REAL_DATA, tmp_path / "semicolon", ";")
    outputs = {}
    for folder in ("comma", "semicolon"):
        monkeypatch.chdir(tmp_path / folder)  # the model names its training files
        result = twin("drift", "fit", REAL_DATA.name, "--target",
                      "ch1_um,ch2_um,ch3_um,ch4_um,ch5_um", "--method", "ridge_dynamic",
                      "--seed", "0", "--out", "model.safetensors")
        assert result.exit_code == 0, result.output
        outputs[folder] = result.output
    model = (tmp_path / "semicolon" / "model.safetensors").read_bytes()
    assert model == (tmp_path / "comma" / "model.safetensors").read_bytes()
    note = "note: train.csv: read as semicolon-separated, with decimal commas"
    assert note in outputs["semicolon"] and "read as" not in outputs["comma"]
    # a bad cell names file, line and column there too
    bad = tmp_path / "semicolon" / "bad.csv"
    lines = (tmp_path / "semicolon" / REAL_DATA.name).read_text().splitlines()
    cells = lines[40].split(";")
    lines[40] = ";".join([cells[0], "1.000,5", *cells[2:]])
    bad.write_text("\n".join(lines) + "\n")
    result = twin("drift", "fit", str(bad), "--target", "ch1_um", "--out", "m.safetensors")
    assert result.exit_code == 2, result.output
    assert f"{bad}, line 41, column 'speed_rpm': cannot read '1.000,5'" in result.output


def test_synth_reads_a_semicolon_speed_profile_as_the_comma_one(tmp_path, monkeypatch):
    profiles = {"comma": "time_s,speed_rpm,ambient_C\n0,6000,24.5\n60.5,12000,24.75\n",
                "semicolon": "sep=;\ntime_s;speed_rpm;ambient_C;;\n0;6000;24,5;;\n"
                             "60,5;12000;24,75;;\n;;;;\n"}
    for folder, text in profiles.items():
        (tmp_path / folder).mkdir()
        monkeypatch.chdir(tmp_path / folder)  # the run's metadata name the profile
        Path("profile.csv").write_text(text)
        result = twin("synth", "--profile", "profile.csv", "--minutes", "2", "--ambient",
                      "24.5", "--seed", "1", "--out", "run.csv")
        assert result.exit_code == 0, result.output
    for file in ("run.csv", "run.truth.csv"):
        assert (tmp_path / "semicolon" / file).read_bytes() == (
            tmp_path / "comma" / file).read_bytes()
    # the speed steps at 60.5 s: the decimal comma was read as one
    run = read_run(tmp_path / "semicolon" / "run.csv")
    assert run.speed_rpm[run.time_s < 60.5].max() == 6000.0
    assert run.speed_rpm[run.time_s > 62].min() == 12000.0
    Path("bad.csv").write_text("time_s;speed_rpm\n0;0\n60;9.000\n")
    result = twin("synth", "--profile", "bad.csv", "--minutes", "2", "--ambient", "24.5",
                  "--seed", "1", "--out", "bad_run.csv")
    assert result.exit_code == 2 and "Traceback" not in result.output
    assert "bad.csv, line 3, column 'speed_rpm': cannot read '9.000'" in result.output
    assert not Path("bad_run.csv").exists()


SPREADSHEET = Path(__file__).resolve().parent / "data" / "spreadsheet_exports"


def test_a_german_spreadsheets_export_reads_and_its_thousands_separators_are_refused():
    # written by LibreOffice Calc in de-DE (tests/data/spreadsheet_exports/README.md):
    # General-format cells have no thousands separator, and decimal commas
    profile = read_speed_profile(SPREADSHEET / "profile_de.csv")
    assert profile.speed_rpm.time_s.tolist() == [0.0, 600.5, 1200.0]
    assert profile.speed_rpm(np.array([600.0, 601.0, 1300.0])).tolist() == [6000.0, 12000.0,
                                                                             0.0]
    assert profile.ambient_C(700.0) == 25.25
    # the speed column formatted with separators: '6.000' is 6000 rpm here, not 6
    with pytest.raises(InputError) as info:
        read_speed_profile(SPREADSHEET / "profile_de_grouped.csv")
    assert (info.value.row, info.value.column) == (2, "speed_rpm")
    assert "cannot read '6.000' as a number: 6000 with a thousands separator, or 6" in str(
        info.value)
