"""Recorded-run reader: schema round trip, hard errors, sampling helpers."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from twin.errors import InputError
from twin.runs import read_run, write_quality, write_run

HEADER = "time_s,speed_rpm,ambient_C,T1_C,T2_C,T3_C,T4_C,T5_C"


def warmup(n: int = 300, dt: float = 1.0) -> dict[str, np.ndarray]:
    """A clean exponential warm-up (closed form), 1 Hz by default."""
    t = np.arange(n) * dt
    rise = 1.0 - np.exp(-t / 400.0)
    cols = {"time_s": t, "speed_rpm": np.full(n, 9000.0), "ambient_C": np.full(n, 25.0)}
    for k, amp in enumerate([8.0, 6.0, 5.0, 4.0, 1.5], start=1):
        cols[f"T{k}_C"] = 25.0 + amp * rise
    return cols


def csv_text(cols: dict[str, np.ndarray], meta: str = "") -> str:
    names = list(cols)
    lines = [",".join(names)]
    for row in zip(*(cols[n] for n in names), strict=True):
        lines.append(",".join(f"{v:.4f}" for v in row))
    return meta + "\n".join(lines) + "\n"


def write(tmp_path, text: str, name: str = "run.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_clean_csv_reads_without_findings(tmp_path):
    cols = warmup()
    path = write(tmp_path, csv_text(cols, "# name: demo\n# speed_rpm: 9000\n"))
    before = path.read_bytes()
    run = read_run(path)
    assert run.name == "demo"
    assert run.metadata == {"name": "demo", "speed_rpm": "9000"}
    assert run.T_C.shape == (300, 5)
    assert run.coolant_C is None and run.disp_um is None
    np.testing.assert_allclose(run.T_C[:, 0], cols["T1_C"], atol=1e-4)
    assert run.quality == []
    assert all(v.all() for v in run.valid.values())
    assert path.read_bytes() == before  # the input is never modified


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_round_trip(tmp_path, suffix):
    cols = warmup()
    cols["coolant_C"] = np.full(300, 22.0)
    cols["disp_z_um"] = np.linspace(0.0, 5.0, 300)
    meta = {"name": "rt", "seed": 7}
    path = tmp_path / f"run{suffix}"
    write_run(path, cols, meta)
    run = read_run(path)
    assert run.metadata == {"name": "rt", "seed": "7"}
    for j, k in enumerate(["T1_C", "T2_C", "T3_C", "T4_C", "T5_C"]):
        np.testing.assert_allclose(run.T_C[:, j], cols[k], atol=1e-4)
    np.testing.assert_allclose(run.coolant_C, 22.0)
    np.testing.assert_allclose(run.disp_um[:, 2], cols["disp_z_um"], atol=1e-4)
    assert np.isnan(run.disp_um[:, 0]).all() and not run.valid["disp_x_um"].any()
    assert run.valid["disp_z_um"].all()


def test_at_interpolates_and_before_is_causal(tmp_path):
    cols = warmup()
    run = read_run(write(tmp_path, csv_text(cols)))
    s = run.at(np.array([10.5, 200.25]))
    expected = 25.0 + 8.0 * (1.0 - np.exp(-np.array([10.5, 200.25]) / 400.0))
    np.testing.assert_allclose(s.T_C[:, 0], expected, atol=2e-4)
    assert s.valid_T.all()
    b = run.before(np.array([60.0, 60.9, -1.0]))
    np.testing.assert_array_equal(b.time_s[:2], [60.0, 60.0])
    assert b.valid["T1_C"].tolist() == [True, True, False]
    outside = run.at(np.array([1000.0]))
    assert not outside.valid["T1_C"][0]


def test_quality_json_is_serialisable(tmp_path):
    cols = warmup()
    cols["T3_C"][100:104] = np.nan
    run = read_run(write(tmp_path, csv_text(cols).replace("nan", "")))
    out = tmp_path / "quality.json"
    write_quality(run, out)
    doc = json.loads(out.read_text())
    assert doc["findings"][0]["kind"] == "dropout"


# --- hard errors: each names the file, the line and the column --------------------------

def expect_error(path, row, column, words):
    with pytest.raises(InputError) as info:
        read_run(path)
    err = info.value
    assert err.file == str(path)
    assert err.row == row
    assert err.column == column
    assert words in err.reason, err.reason
    return err


def test_missing_required_column(tmp_path):
    cols = warmup()
    del cols["T4_C"]
    path = write(tmp_path, csv_text(cols, "# a: b\n"))
    expect_error(path, 2, "T4_C", "missing required column")


def test_a_missing_column_is_told_beside_the_name_the_file_has(tmp_path):
    # 'missing required column' for a header of TIME_S or Time_s: the names are
    # case-sensitive, and the message now says which name the file has
    cols = warmup()
    cols["Time_s"] = cols.pop("time_s")
    path = write(tmp_path, csv_text(cols))
    err = expect_error(path, 1, "time_s", "missing required column")
    assert err.reason.endswith("(the header has 'Time_s'; column names are case-sensitive)")


def test_a_missing_column_without_a_near_name_lists_the_header(tmp_path):
    # a logger's own time column (a timestamp, minutes): the header is listed, so the user
    # sees what the reader found
    cols = warmup()
    cols["timestamp"] = cols.pop("time_s")
    path = write(tmp_path, csv_text(cols))
    err = expect_error(path, 1, "time_s", "missing required column")
    assert err.reason.endswith("(the header has speed_rpm, ambient_C, T1_C, T2_C, T3_C, "
                               "T4_C, T5_C, timestamp)"), err.reason


def test_a_units_row_under_the_header_is_told_as_one(tmp_path):
    # a spreadsheet's export with a row of units under the names (s, rpm, °C ...) failed
    # as "cannot read 's' as a number", leaving the user to guess why
    lines = csv_text(warmup()).splitlines()
    lines.insert(1, "s,rpm,°C,°C,°C,°C,°C,°C")
    path = write(tmp_path, "\n".join(lines) + "\n")
    err = expect_error(path, 2, "time_s", "cannot read 's' as a number")
    assert err.reason.endswith("; no cell of line 2 is a number: a units row? remove it "
                               "(the names carry the units: time_s, T1_C)"), err.reason
    # a text cell among numbers is told as before
    fields = lines[2].split(",")
    fields[3] = "open"
    lines[1] = ",".join(fields)
    path = write(tmp_path, "\n".join(lines) + "\n")
    err = expect_error(path, 2, "T1_C", "cannot read 'open' as a number")
    assert err.reason == "cannot read 'open' as a number"


def test_unparseable_number_names_editor_line(tmp_path):
    text = csv_text(warmup(), "# name: x\n\n").splitlines()
    # line 1 metadata, 2 blank, 3 header, 4.. data: sample 10 sits on line 13
    fields = text[12].split(",")
    fields[5] = "2x.5"
    text[12] = ",".join(fields)
    path = write(tmp_path, "\n".join(text) + "\n")
    expect_error(path, 13, "T3_C", "cannot read '2x.5'")


def test_wrong_field_count(tmp_path):
    text = csv_text(warmup()).splitlines()
    text[5] += ",1.0"
    expect_error(write(tmp_path, "\n".join(text)), 6, None, "expected 8 fields")


def test_empty_file(tmp_path):
    path = write(tmp_path, "")
    with pytest.raises(InputError, match="empty file"):
        read_run(path)
    path = write(tmp_path, "# name: x\n" + HEADER + "\n", "header_only.csv")
    expect_error(path, 2, None, "no data rows")


def test_time_going_back(tmp_path):
    cols = warmup()
    cols["time_s"][50] = 10.0
    path = write(tmp_path, csv_text(cols))
    err = expect_error(path, 52, "time_s", "time goes back")
    # the CSV's editor lines, in the location as in the words: the location said "row 52"
    # of a message that spoke of "line 51"
    assert str(err).startswith(f"{path}, line 52, column 'time_s': time goes back from 49 s "
                               "(line 51) to 10 s")
    path = tmp_path / "back.parquet"
    write_run(path, cols)
    err = expect_error(path, 51, "time_s", "time goes back")
    # a Parquet file has rows, no lines
    assert str(err).startswith(f"{path}, row 51, column 'time_s': time goes back from 49 s "
                               "(row 50) to 10 s")


def _ambient_out_of_range(cols: dict[str, np.ndarray]) -> None:
    cols["ambient_C"][10:60] = 50.0  # over 45 °C; the median stays 25 °C: not Fahrenheit


def _kelvin(cols: dict[str, np.ndarray]) -> None:
    cols["T2_C"] += 273.15
    cols["T2_C"][:10] = np.nan  # named at its first value


@pytest.mark.parametrize(("change", "column", "words", "limit"), [
    (lambda c: c["speed_rpm"].__setitem__(10, -5.0), "speed_rpm", "negative speed -5 rpm",
     math.inf),
    (lambda c: c["speed_rpm"].__setitem__(10, 99000.0), "speed_rpm",
     "speed 99000 rpm exceeds the spindle's limit 15000 rpm", 15000.0),
    (_ambient_out_of_range, "ambient_C", "50 °C is outside the -40..45 °C", math.inf),
    (_kelvin, "T2_C", "values look like Kelvin", math.inf),
    (lambda c: c["time_s"].__setitem__(10, np.nan), "time_s", "time is missing", math.inf),
], ids=["negative_speed", "speed_limit", "ambient_range", "kelvin", "no_time"])
def test_a_csv_error_names_the_line_a_parquet_error_the_data_row(tmp_path, change, column,
                                                                   words, limit):
    """The same fault at sample 10 is at line 14 of a CSV file (two metadata lines and
    the header before it) and at row 11 of a Parquet file: the location says which, as
    an editor and a table viewer number them (a CSV error said "row 14")."""
    cols = warmup()
    change(cols)
    csv_path = write(tmp_path, csv_text(cols, "# name: x\n\n"))
    parquet_path = tmp_path / "run.parquet"
    write_run(parquet_path, cols, {"name": "x"})
    found = []
    for path, where in ((csv_path, "line 14"), (parquet_path, "row 11")):
        with pytest.raises(InputError) as info:
            read_run(path, max_speed_rpm=limit)
        assert str(info.value).startswith(f"{path}, {where}, column '{column}': "), info.value
        assert words in info.value.reason, info.value.reason
        found.append(info.value.reason)
    assert found[0] == found[1]  # told in the same words but for the place


def test_a_bad_cell_is_at_a_csv_files_line_and_a_parquet_files_row(tmp_path):
    import pyarrow as pa
    import pyarrow.parquet as pq

    cols = warmup()
    text = csv_text(cols, "# name: x\n").splitlines()
    fields = text[12].split(",")  # sample 10 on line 13: the header is line 2
    fields[1] = "fast"
    text[12] = ",".join(fields)
    path = write(tmp_path, "\n".join(text) + "\n")
    with pytest.raises(InputError) as info:
        read_run(path)
    assert str(info.value) == f"{path}, line 13, column 'speed_rpm': cannot read 'fast' as a number"
    table = {k: list(v) for k, v in cols.items()}
    table["speed_rpm"] = [str(v) for v in cols["speed_rpm"]]
    table["speed_rpm"][10] = "fast"
    path = tmp_path / "run.parquet"
    pq.write_table(pa.table(table), path)
    with pytest.raises(InputError) as info:
        read_run(path)
    assert str(info.value) == f"{path}, row 11, column 'speed_rpm': cannot read 'fast' as a number"


def test_too_short_for_two_windows(tmp_path):
    cols = {k: v[:100] for k, v in warmup().items()}
    expect_error(write(tmp_path, csv_text(cols)), 101, "time_s", "two 60 s windows")


def test_sample_interval_too_long(tmp_path):
    cols = warmup(n=30, dt=20.0)
    expect_error(write(tmp_path, csv_text(cols)), None, "time_s", "sample interval")


def test_kelvin_column(tmp_path):
    cols = warmup()
    cols["T2_C"] = cols["T2_C"] + 273.15
    expect_error(write(tmp_path, csv_text(cols)), 2, "T2_C", "Kelvin")


def test_fahrenheit_ambient(tmp_path):
    cols = warmup()
    cols["ambient_C"] = cols["ambient_C"] * 1.8 + 32.0
    expect_error(write(tmp_path, csv_text(cols)), 2, "ambient_C", "Fahrenheit")


def test_fahrenheit_ambient_from_mid_run_names_the_first_row_in_fahrenheit(tmp_path):
    # a logger switched to °F at sample 60: the error points there, not at the first row
    cols = warmup()
    cols["ambient_C"][60:] = cols["ambient_C"][60:] * 1.8 + 32.0
    expect_error(write(tmp_path, csv_text(cols)), 62, "ambient_C", "Fahrenheit")


def test_fahrenheit_sensor(tmp_path):
    cols = warmup()
    cols["T5_C"] = cols["T5_C"] * 1.8 + 32.0
    expect_error(write(tmp_path, csv_text(cols)), 2, "T5_C", "Fahrenheit")


def test_negative_speed(tmp_path):
    cols = warmup()
    cols["speed_rpm"][7] = -9000.0
    expect_error(write(tmp_path, csv_text(cols)), 9, "speed_rpm", "negative speed")


def test_required_column_without_values(tmp_path):
    cols = warmup()
    cols["ambient_C"][:] = np.nan
    expect_error(write(tmp_path, csv_text(cols)), 2, "ambient_C", "no values")


def test_a_run_without_any_temperature_is_refused(tmp_path):
    cols = warmup()
    for i in range(1, 6):
        cols[f"T{i}_C"][:] = np.nan
    expect_error(write(tmp_path, csv_text(cols)), 2, "T1_C", "no temperature sensor")


def test_missing_time(tmp_path):
    text = csv_text(warmup()).splitlines()
    text[3] = "," + text[3].split(",", 1)[1]
    expect_error(write(tmp_path, "\n".join(text)), 4, "time_s", "time is missing")


def test_unknown_suffix_and_bad_parquet(tmp_path):
    with pytest.raises(InputError, match="unknown run format"):
        read_run(write(tmp_path, "x", "run.txt"))
    # a mistyped folder name was "unknown run format ''", as if the file were there
    with pytest.raises(InputError, match="cannot read file: No such file or directory"):
        read_run(tmp_path / "my_runs")
    with pytest.raises(InputError, match="Parquet"):
        read_run(write(tmp_path, "not parquet", "run.parquet"))


def test_parquet_hard_error_names_row(tmp_path):
    cols = warmup()
    cols["speed_rpm"][4] = -1.0
    path = tmp_path / "neg.parquet"
    write_run(path, cols)
    expect_error(path, 5, "speed_rpm", "negative speed")


@pytest.mark.parametrize("separator", [";", "\t"])
def test_a_run_separated_otherwise_than_by_commas_is_read(tmp_path, separator):
    # a logger's semicolon export was refused ("the header is one column holding ';'");
    # its numbers here have decimal points, which a `;` or tab file may have too
    clean = csv_text(warmup(), "# a: b\n")
    a = read_run(write(tmp_path, clean, "clean.csv"))
    b = read_run(write(tmp_path, clean.replace(",", separator)))
    assert np.array_equal(a.T_C, b.T_C) and np.array_equal(a.time_s, b.time_s)
    assert b.metadata == {"a": "b"}
    name = {";": "semicolon", "\t": "tab"}[separator]
    assert [(f["kind"], f["action"]) for f in b.quality] == [
        ("csv_dialect", f"read as {name}-separated")]


def test_a_folder_given_as_a_run_is_named_a_folder(tmp_path):
    # `twin snapshot DIR`: it said "unknown run format ''"
    with pytest.raises(InputError, match="is a folder, not a run file") as info:
        read_run(tmp_path)
    assert info.value.file == str(tmp_path)


def test_files_with_bare_cr_line_ends_read_as_with_lf(tmp_path):
    # Excel's "CSV (Macintosh)" ends lines in a bare CR: the whole file was one line, so a
    # run was "an empty file", a speed profile "not a readable CSV line" and a scenario
    # not TOML
    from twin.drift.data import read_drift_table
    from twin.plant.profile import read_speed_profile
    from twin.plant.scenario import load_scenario

    text = csv_text(warmup(), "# name: demo\n")
    lf, cr = write(tmp_path, text), write(tmp_path, text.replace("\n", "\r"), "mac.csv")
    before = cr.read_bytes()
    a, b = read_run(lf), read_run(cr)
    np.testing.assert_array_equal(a.T_C, b.T_C)
    assert (a.name, a.metadata) == (b.name, b.metadata)
    assert read_drift_table(cr).columns.keys() == read_drift_table(lf).columns.keys()
    profile = write(tmp_path, "time_s,speed_rpm\r0,6000\r60,9000\r", "p.csv")
    assert read_speed_profile(profile).speed_rpm(np.array([30.0, 90.0])).tolist() == [
        6000.0, 9000.0]
    scenario = write(tmp_path, "[motor_heat]\rtime_s = [0]\rfactor = [1.2]\r", "s.toml")
    assert load_scenario(scenario).motor_heat.factor == [1.2]
    assert cr.read_bytes() == before
    # an error names the line an editor shows
    bad = write(tmp_path, text.replace("\n", "\r").replace("\r5.0000,", "\rx,", 1), "bad.csv")
    with pytest.raises(InputError) as info:
        read_run(bad)
    assert info.value.row == 8 and info.value.column == "time_s"


@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-be"])
def test_a_utf16_file_is_told_as_such(tmp_path, encoding):
    # Excel's "Unicode text" is UTF-16: "line 1: not UTF-8 text" left the user guessing
    path = tmp_path / "run.csv"
    text = csv_text(warmup(), "# name: Prüfstand\n")
    path.write_bytes(("\ufeff" if encoding.endswith("be") else "").encode(encoding)
                     + text.encode(encoding))
    with pytest.raises(InputError) as info:
        read_run(path)
    assert str(info.value) == f"{path}: UTF-16 text; save it as UTF-8"
    path.write_bytes(text.encode("latin-1"))  # not UTF-8, but no UTF-16 either
    with pytest.raises(InputError) as info:
        read_run(path)
    # Excel's "CSV (Comma delimited)" on Windows: the byte and what to do were not said
    assert str(info.value) == (f"{path}, line 1: not UTF-8 text (byte 0xFC, 'ü' in "
                               "Windows-1252 or Latin-1); save it as UTF-8 (Excel: 'CSV UTF-8')")
    path.write_bytes(b"time_s,speed_rpm\n\x81\n")  # a byte Windows-1252 leaves undefined
    with pytest.raises(InputError) as info:
        read_run(path)
    assert str(info.value) == f"{path}, line 2: not UTF-8 text (byte 0x81); save it as UTF-8"


def test_a_spreadsheets_trailing_separators_are_read_past(tmp_path):
    """Excel pads every line of its used range with separators ("T5_C,,," and "25.1,,,");
    the run was refused ("header field 9 is empty").  A value under no name still is."""
    clean = csv_text(warmup())
    lines = clean.splitlines()
    padded = "\n".join([lines[0] + ",,,"] + [ln + ",," for ln in lines[1:]]) + "\n"
    a = read_run(write(tmp_path, clean, "clean.csv"))
    b = read_run(write(tmp_path, padded, "padded.csv"))
    assert np.array_equal(a.T_C, b.T_C) and np.array_equal(a.time_s, b.time_s)
    assert b.quality == []
    lines[5] += ",,7"
    expect_error(write(tmp_path, "\n".join([lines[0] + ",,,"] + lines[1:]) + "\n"), 6, None,
                 "expected 8 fields")
    inner = lines[0].replace("speed_rpm,", "speed_rpm,,")
    expect_error(write(tmp_path, "\n".join([inner] + lines[1:]) + "\n"), 1, None,
                 "header field 3 is empty")


def test_a_spreadsheets_rows_of_separators_are_read_past(tmp_path):
    """Excel writes ",,,,,," for the empty rows of its used range below (or between) the
    data; the run was refused ("line 903, column 'time_s': time is missing") though such a
    row holds no value.  A row with a value in it is still read, and still refused."""
    clean = csv_text(warmup())
    lines = clean.splitlines()
    width = lines[0].count(",")
    padded = "\n".join(lines[:4] + ["," * width] + lines[4:] + ["," * width, " ,, ,"]) + "\n"
    a = read_run(write(tmp_path, clean, "clean.csv"))
    b = read_run(write(tmp_path, padded, "padded.csv"))
    assert np.array_equal(a.T_C, b.T_C) and np.array_equal(a.time_s, b.time_s)
    assert b.quality == []
    # the lines after a row of separators keep their editor's numbers
    broken = lines[:4] + ["," * width] + lines[4:]
    broken[6] = broken[6].replace(broken[6].split(",")[0], "x", 1)
    expect_error(write(tmp_path, "\n".join(broken) + "\n"), 7, "time_s",
                 "cannot read 'x' as a number")
    # a row holding one value under blank cells is a sample with no time
    expect_error(write(tmp_path, "\n".join(lines + ["," * (width - 1) + ",7"]) + "\n"),
                 len(lines) + 1, "time_s", "time is missing")


def test_a_spreadsheets_cell_texts(tmp_path):
    """Excel writes #N/A for a reading not available (its NA() and failed lookups): the
    run was refused ("cannot read '#N/A' as a number") where 'n/a' read as a dropout.  A
    formula's error value and a quoted decimal comma stay errors, saying what they are."""
    clean = csv_text(warmup())
    lines = clean.splitlines()

    def with_T1(line: int, cell: str) -> str:
        edited = list(lines)
        fields = edited[line - 1].split(",")
        fields[3] = cell
        edited[line - 1] = ",".join(fields)
        return "\n".join(edited) + "\n"

    run = read_run(write(tmp_path, with_T1(51, "#N/A")))
    assert [(f["column"], f["kind"], f["rows"]) for f in run.quality] == [
        ("T1_C", "dropout", [51])]  # repaired and reported, as an empty cell is
    same = read_run(write(tmp_path, with_T1(51, " n/a "), "same.csv"))
    assert np.array_equal(run.T_C, same.T_C, equal_nan=True)
    err = expect_error(write(tmp_path, with_T1(51, "#DIV/0!")), 51, "T1_C",
                       "cannot read '#DIV/0!' as a number (a spreadsheet's error value")
    assert "leave the cell empty" in err.reason
    expect_error(write(tmp_path, with_T1(51, '"31,25"')), 51, "T1_C",
                 "cannot read '31,25' as a number (a decimal comma? write decimal points)")
    # a thousands separator is no decimal comma: "9,000" rpm is 9000, not 9.000
    expect_error(write(tmp_path, with_T1(51, '"9,000"')), 51, "T1_C",
                 "cannot read '9,000' as a number (a thousands separator, or a decimal "
                 "comma? write plain numbers with a decimal point: 9000, 25.4)")
    expect_error(write(tmp_path, with_T1(51, '"12,000.5"')), 51, "T1_C",
                 "(a thousands separator, or a decimal comma?")
    err = expect_error(write(tmp_path, with_T1(51, "31.2 C")), 51, "T1_C",
                       "cannot read '31.2 C' as a number")
    assert "(" not in err.reason  # no guess where there is nothing to say


def test_a_spreadsheets_separator_line_is_read_past(tmp_path):
    """An export for Excel may start with `sep=,` (the separator Excel is to use): it was
    taken for the header ("line 2: expected 1 fields as in the header, found 8")."""
    clean = csv_text(warmup())
    a = read_run(write(tmp_path, clean, "clean.csv"))
    b = read_run(write(tmp_path, "# name: hint\nsep=,\n" + clean, "hint.csv"))
    assert np.array_equal(a.T_C, b.T_C) and np.array_equal(a.time_s, b.time_s)
    lines = clean.splitlines()
    lines[2] = "x" + lines[2][1:]
    expect_error(write(tmp_path, "SEP=,\n" + "\n".join(lines) + "\n"), 4, "time_s",
                 "cannot read 'x")  # the lines keep their editor's numbers
    # `sep=;` and a tab (Excel's hint for a tab-separated export) name the separator:
    # the tab was stripped with the blanks and "sep=" taken for the header
    for separator in (";", "\t"):
        c = read_run(write(tmp_path, f"sep={separator}\n" + clean.replace(",", separator),
                           "other.csv"))
        assert np.array_equal(a.T_C, c.T_C) and np.array_equal(a.time_s, c.time_s)
    # a hint the header belies is told at the header, naming the hint's line
    expect_error(write(tmp_path, "# x: y\nsep=,\n" + clean.replace(",", ";")), 3, None,
                 "the header is one column holding ';': line 2 says the file is separated "
                 "by ','")
    expect_error(write(tmp_path, "sep=|\n" + clean.replace(",", "|")), 1, None,
                 "this 'sep=' line says the file is separated by '|'")
    # below the header it is a data line like any other
    expect_error(write(tmp_path, clean + "sep=,\n"), len(lines) + 1, None,
                 "expected 8 fields as in the header, found 2")


@pytest.mark.parametrize("cell", ["00:00:02", "0:02", "2026-11-27 10:00:02",
                                  "27.11.2026 10:00:02.5", "2026-11-27T10:00:02"])
def test_a_time_column_of_dates_or_clock_times_is_told_as_such(tmp_path, cell):
    # a logger's or a spreadsheet's time column ("00:00:02") was "cannot read '00:00:02' as
    # a number", the user left to find that time_s wants seconds
    lines = csv_text(warmup()).splitlines()
    lines[1] = cell + lines[1][lines[1].index(","):]
    err = expect_error(write(tmp_path, "\n".join(lines) + "\n"), 2, "time_s",
                       f"cannot read {cell!r} as a number (a date or clock time? time_s "
                       "holds seconds from the run's start: convert the column)")
    assert err.reason.endswith("convert the column)")
    # the same text in another column is no time to convert
    lines = csv_text(warmup()).splitlines()
    fields = lines[1].split(",")
    fields[3] = cell
    lines[1] = ",".join(fields)
    err = expect_error(write(tmp_path, "\n".join(lines) + "\n", "other.csv"), 2, "T1_C",
                       f"cannot read {cell!r} as a number")
    assert "time_s holds" not in err.reason


@pytest.mark.parametrize("kind", ["timestamp[ms]", "duration[s]", "date32[day]"])
def test_a_parquet_time_column_of_time_stamps_is_told_as_such(tmp_path, kind):
    # as a CSV file's '2026-11-27 10:00:02': "column type timestamp[us] is not numeric"
    import pyarrow as pa
    import pyarrow.parquet as pq

    cols = warmup()
    seconds = cols.pop("time_s").astype("int64")
    if kind.startswith("date"):
        time = pa.array(seconds // 86400, pa.int32()).cast(pa.date32())
    else:
        time = pa.array(seconds * (1000 if "ms" in kind else 1)).cast(pa.type_for_alias(kind))
    path = tmp_path / "run.parquet"
    pq.write_table(pa.table({"time_s": time, **cols}), path)
    err = expect_error(path, None, "time_s", f"column type {kind} is not numeric: time_s "
                       "holds seconds from the run's start, convert the column")
    assert err.reason.endswith("convert the column")
    cols["T1_C"] = cols["T1_C"] > 30  # another column of another type: no such hint
    pq.write_table(pa.table({"time_s": seconds.astype(float), **cols}), path)
    err = expect_error(path, None, "T1_C", "column type bool is not numeric")
    assert "time_s holds" not in err.reason


def test_a_second_header_says_the_files_were_joined(tmp_path):
    # `cat monday.csv tuesday.csv` repeats the header mid-file: "line 302, column 'time_s':
    # cannot read 'time_s' as a number" left the user reading a number column
    lines = csv_text(warmup()).splitlines()
    joined = lines[:100] + [" " + lines[0].replace(",", ", ")] + lines[100:]
    expect_error(write(tmp_path, "# name: two days\n" + "\n".join(joined) + "\n"), 102,
                 None, "the header again (line 2 holds it): files joined one after the "
                 "other? keep the first header only")
