"""Issue 14 regressions on the run reader and the metrics (one test per defect)."""

from __future__ import annotations

import os

import numpy as np
import pytest

from tests.test_runs_reader import csv_text, warmup, write
from twin.errors import InputError
from twin.loop.metrics import T_FLOOR_C, accuracy_metrics
from twin.runs import read_run
from twin.runs.schema import MAX_DURATION_S


def refused(path, row, column, text, **kwargs):
    with pytest.raises(InputError, match=text) as info:
        read_run(path, **kwargs)
    assert (info.value.file, info.value.row, info.value.column) == (str(path), row, column)


# --- defect 3: a measured 0.0 °C gave -inf accuracy; the score depended on 0 °C -------------

def _metrics(T_meas, error_C):
    k = T_meas.shape[0]
    time = np.arange(k) * 4.0
    return accuracy_metrics(time, T_meas + error_C, T_meas, T_meas[0], np.zeros(k), None)


def test_defect3_zero_celsius_measured_gives_finite_accuracy():
    T = np.zeros((60, 5))
    acc = _metrics(T, 0.1)["temperature_accuracy_pct"]
    assert acc == pytest.approx(100.0 * (1.0 - 0.1 / T_FLOOR_C))


def test_defect3_paper_definition_kept_above_floor_and_shift_does_not_collapse():
    t = np.arange(60)[:, None] * 4.0
    warm = 25.0 + 20.0 * (1.0 - np.exp(-t / 100.0)) * np.ones((1, 5))
    error = 0.15
    paper = 100.0 * (1.0 - np.mean(error / warm[t[:, 0] > 59.0]))
    assert _metrics(warm, error)["temperature_accuracy_pct"] == pytest.approx(paper)
    shifted = _metrics(warm - 22.0, error)["temperature_accuracy_pct"]
    assert 100.0 * (1.0 - error / T_FLOOR_C) <= shifted <= paper
    below = _metrics(warm - 60.0, error)["temperature_accuracy_pct"]  # every value < 0 °C
    assert below == pytest.approx(100.0 * (1.0 - np.mean(error / np.abs(
        (warm - 60.0)[t[:, 0] > 59.0]).clip(T_FLOOR_C))))


# --- defect 5: unbounded work from a far time stamp --------------------------------------

@pytest.mark.parametrize("last_time", [1e6, 1e9])
def test_defect5_run_longer_than_max_duration_refused_before_allocating(tmp_path, last_time):
    cols = warmup()
    cols["time_s"][-1] = last_time
    path = write(tmp_path, csv_text(cols))
    refused(path, 301, "time_s", "at most 24 h")
    assert last_time > MAX_DURATION_S


# --- defect 6: exit 1 for bad cells ---------------------------------------------------------

def test_defect6_cell_longer_than_csv_field_limit(tmp_path):
    lines = csv_text(warmup()).splitlines()
    lines[10] = lines[10] + ',"' + "x" * 140_000 + '"'
    lines[0] += ",note"
    for i in range(1, len(lines)):
        if i != 10:
            lines[i] += ","
    refused(write(tmp_path, "\n".join(lines)), 11, None, "not a readable CSV line")


def test_defect6_long_number_cell(tmp_path):
    lines = csv_text(warmup()).splitlines()
    fields = lines[5].split(",")
    fields[3] = "1" * 100
    lines[5] = ",".join(fields)
    refused(write(tmp_path, "\n".join(lines)), 6, "T1_C", "100 characters is not a number")


def test_defect6_parquet_padded_text_cell_reads_like_csv(tmp_path):
    pa = pytest.importorskip("pyarrow")
    pq = pytest.importorskip("pyarrow.parquet")
    cols = warmup()
    table = {n: pa.array(v) for n, v in cols.items()}
    table["T1_C"] = pa.array([f" {v:.4f} " for v in cols["T1_C"]])
    path = tmp_path / "padded.parquet"
    pq.write_table(pa.table(table), path)
    np.testing.assert_allclose(read_run(path).T_C[:, 0], cols["T1_C"], atol=1e-4)
    table["T1_C"] = pa.array([" 31.9 "] * 299 + ["hot"])
    pq.write_table(pa.table(table), path)
    refused(path, 300, "T1_C", "cannot read 'hot'")


def test_defect6_parquet_huge_uint64(tmp_path):
    pa = pytest.importorskip("pyarrow")
    pq = pytest.importorskip("pyarrow.parquet")
    cols = warmup()
    table = {n: pa.array(v) for n, v in cols.items()}
    speed = np.full(300, 9000, dtype=np.uint64)
    speed[7] = np.uint64(2**64 - 1)
    table["speed_rpm"] = pa.array(speed)
    path = tmp_path / "u64.parquet"
    pq.write_table(pa.table(table), path)
    refused(path, 8, "speed_rpm", "exceeds the spindle's limit", max_speed_rpm=15000.0)


# --- defect 7: out-of-range values found only during replay ----------------------------------

@pytest.mark.parametrize(("column", "value", "text"), [
    ("speed_rpm", 20000.0, "exceeds the spindle's limit 15000"),
    ("ambient_C", -50.0, "outside the -40..45"),
    ("coolant_C", 150.0, "outside the -40..45"),
    # above the plausible range but not the median (not read as Fahrenheit): was accepted
    ("coolant_C", 50.0, "outside the -40..45"),
])
def test_defect7_out_of_range_refused_at_read_time_naming_row(tmp_path, column, value, text):
    cols = warmup()
    cols["coolant_C"] = np.full(300, 22.0)
    cols[column] = np.where(np.arange(300) >= 200, value, cols[column])
    refused(write(tmp_path, csv_text(cols)), 202, column, text, max_speed_rpm=15000.0)


# --- defect 14: a block of rows repeated verbatim -------------------------------------------

def test_defect14_repeated_block_dropped_and_reported(tmp_path):
    lines = csv_text(warmup()).splitlines()
    # rows 290..299 of the data (lines 291..300) sent again after the last row
    text = "\n".join(lines + lines[291:301]) + "\n"
    run = read_run(write(tmp_path, text))
    assert run.time_s.size == 300
    (found,) = [f for f in run.quality if f["kind"] == "repeated_rows"]
    assert found["count"] == 10 and found["rows"] == list(range(302, 312))
    assert found["spans_s"] == [[290.0, 299.0]]
    np.testing.assert_allclose(run.time_s, np.arange(300.0))


def test_defect14_time_going_back_with_other_values_still_refused(tmp_path):
    lines = csv_text(warmup()).splitlines()
    copy = lines[295].split(",")
    copy[3] = "99.0"
    text = "\n".join([*lines, ",".join(copy)]) + "\n"
    refused(write(tmp_path, text), 302, "time_s", "time goes back")


# --- defect 15: numbers Python reads but a logger never writes -------------------------------

@pytest.mark.parametrize("cell", ["9_000", "infinity", "0x10", "1e5e3", "٣"])
def test_defect15_only_plain_decimal_numbers(tmp_path, cell):
    lines = csv_text(warmup()).splitlines()
    fields = lines[3].split(",")
    fields[1] = cell
    lines[3] = ",".join(fields)
    with pytest.raises(InputError) as info:
        read_run(write(tmp_path, "\n".join(lines)))
    assert info.value.row == 4 and info.value.column == "speed_rpm"


def test_defect15_quoted_cell_over_two_lines_is_not_joined(tmp_path):
    lines = csv_text(warmup()).splitlines()
    fields = lines[3].split(",")
    fields[1] = '"1'
    lines[3] = ",".join(fields)
    lines.insert(4, '2"' + "," * 6 + "0")
    refused(write(tmp_path, "\n".join(lines)), 4, None, "runs over several lines")


# --- inputs that are not regular files ---------------------------------------------------------

def test_fifo_and_folder_as_run_refused_without_blocking(tmp_path):
    fifo = tmp_path / "run.csv"
    os.mkfifo(fifo)
    refused(fifo, None, None, "not a regular file")
    folder = tmp_path / "dir.csv"
    folder.mkdir()
    refused(folder, None, None, "is a folder")

