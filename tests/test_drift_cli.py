"""`twin drift`: fit → predict → report → select on a small synthetic machine; exit codes."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
from typer.testing import CliRunner

from tests.drift_synthetic import synthetic_columns, write_csv
from twin.cli import app


def run(*args: str):
    return CliRunner().invoke(app, ["drift", *args])


@pytest.fixture(scope="module")
def machine(tmp_path_factory):
    folder = tmp_path_factory.mktemp("drift_cli")
    data = folder / "machine.csv"
    write_csv(data, synthetic_columns(hours=3.0))
    model = folder / "model.safetensors"
    result = run("fit", str(data), "--target", "drift_um", "--out", str(model),
                 "--method", "ridge_dynamic", "--sensors", "all", "--seed", "3")
    assert result.exit_code == 0, result.output
    return folder, data, model


def test_fit_predict_report_select(machine):
    folder, data, model = machine
    assert "ridge_dynamic" in result_text(run("fit", "--help"))
    pred = folder / "pred.csv"
    result = run("predict", str(model), str(data), "--out", str(pred))
    assert result.exit_code == 0, result.output
    with open(pred) as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0]) == ["time_s", "drift_um", "drift_um_lo", "drift_um_hi"]
    lo, mid, hi = (np.array([float(r[k]) for r in rows])
                   for k in ("drift_um_lo", "drift_um", "drift_um_hi"))
    assert np.all(lo < mid) and np.all(mid < hi)

    result = run("report", str(model), str(data), "--out", str(folder / "report"))
    assert result.exit_code == 0, result.output
    metrics = json.loads((folder / "report" / "metrics.json").read_text())
    m = metrics["targets"]["drift_um"]
    assert set(m) >= {"rmse_um", "mae_um", "max_abs_um", "r2", "coverage_90_pct"}
    assert m["r2"] > 0.95 and 70.0 <= m["coverage_90_pct"] <= 100.0
    html = (folder / "report" / "report.html").read_text()
    # drift, its out-of-fold validation, sensor ranking
    assert html.count("data:image/png;base64,") == 3
    assert "<script" not in html and "src='http" not in html

    result = run("select", str(data), "--target", "drift_um", "--out",
                 str(folder / "ranking.json"))
    assert result.exit_code == 0, result.output
    ranking = json.loads((folder / "ranking.json").read_text())
    assert {r["sensor"] for r in ranking["sensors"]} == {"A_C", "B_C", "C_C"}


def result_text(result) -> str:
    assert result.exit_code == 0, result.output
    return result.output


def test_fit_is_deterministic_for_a_seed(machine, tmp_path):
    _, data, model = machine
    again = tmp_path / "again.safetensors"
    result = run("fit", str(data), "--target", "drift_um", "--out", str(again),
                 "--method", "ridge_dynamic", "--sensors", "all", "--seed", "3", "--quiet")
    assert result.exit_code == 0, result.output
    assert again.read_bytes() == model.read_bytes()


def _bad(tmp_path, change):
    columns = synthetic_columns(hours=0.5)
    change(columns)
    path = tmp_path / "bad.csv"
    write_csv(path, columns)
    return path


@pytest.mark.parametrize(("change", "target", "expected"), [
    (lambda c: None, "nope_um", "bad.csv, line 1, column 'nope_um'"),
    (lambda c: [c.pop(k) for k in ("A_C", "B_C", "C_C")], "drift_um",
     "bad.csv, line 1: no temperature columns"),
    (lambda c: c["time_s"].__setitem__(5, 0.0), "drift_um", "bad.csv, line 7, column 'time_s'"),
    (lambda c: c["C_C"].__setitem__(slice(None), np.nan), "drift_um",
     "bad.csv, line 2, column 'C_C'"),
])
def test_bad_data_exits_2_naming_file_line_and_column(tmp_path, change, target, expected):
    data = _bad(tmp_path, change)
    result = run("fit", str(data), "--target", target, "--out", str(tmp_path / "m.safetensors"))
    assert result.exit_code == 2, result.output
    assert expected in result.output
    assert "Traceback" not in result.output
    assert not (tmp_path / "m.safetensors").exists()


def test_predict_needs_the_models_sensors(machine, tmp_path):
    _, _, model = machine
    data = _bad(tmp_path, lambda c: c.pop("B_C"))
    result = run("predict", str(model), str(data), "--out", str(tmp_path / "p.csv"))
    assert result.exit_code == 2 and "column 'B_C'" in result.output


def test_out_refuses_an_input_and_a_folder(machine, tmp_path):
    _, data, _ = machine
    result = run("fit", str(data), "--target", "drift_um", "--out", str(tmp_path))
    assert result.exit_code == 2 and "--out" in result.output
    result = run("select", str(data), "--target", "drift_um", "--out", str(data))
    assert result.exit_code == 2 and "also an input" in result.output


def test_unknown_method_and_sensor_are_bad_input(machine, tmp_path):
    _, data, _ = machine
    out = str(tmp_path / "m.safetensors")
    result = run("fit", str(data), "--target", "drift_um", "--out", out, "--method", "magic")
    assert result.exit_code == 2 and "unknown method" in result.output
    result = run("fit", str(data), "--target", "drift_um", "--out", out, "--sensors", "Z_C")
    assert result.exit_code == 2 and f"{data}, line 1, column 'Z_C'" in result.output
    for listed in ("A_C,drift_um", ",", "speed_rpm"):
        result = run("fit", str(data), "--target", "drift_um", "--out", out, "--sensors", listed)
        assert result.exit_code == 2 and "option '--sensors'" in result.output, result.output


def test_more_sensors_than_the_data_hold_is_bad_input(machine, tmp_path):
    # --sensors 5 on data with three temperature columns fitted on those three and said
    # nothing: the user asked for five
    _, data, _ = machine
    out = tmp_path / "m.safetensors"
    result = run("fit", str(data), "--target", "drift_um", "--out", str(out), "--sensors", "5",
                 "--method", "mlr", "--quiet")
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in result.output, result.output
    assert "--sensors" in lines[0] and "5" in lines[0] and "at most 3" in lines[0], lines[0]
    assert not out.exists()
    # the count of the clusters' best sensors is still accepted
    result = run("fit", str(data), "--target", "drift_um", "--out", str(out), "--sensors", "3",
                 "--method", "mlr", "--quiet")
    assert result.exit_code == 0, result.output


def test_a_sensor_listed_twice_is_fitted_once(machine, tmp_path):
    # --sensors A_C,A_C,B_C fitted on three columns, two of them the same sensor (and said
    # "sensors: A_C, A_C, B_C"); --target and --methods already take each name once
    from twin.drift.modelfile import load_drift_model

    _, data, _ = machine
    out = tmp_path / "m.safetensors"
    result = run("fit", str(data), "--target", "drift_um", "--out", str(out), "--sensors",
                 "A_C, A_C,B_C", "--method", "mlr", "--quiet")
    assert result.exit_code == 0, result.output
    assert load_drift_model(out).spec.sensors == ("A_C", "B_C")


def test_drift_group_is_listed_with_its_commands():
    result = CliRunner().invoke(app, ["--help"])
    assert result.exit_code == 0 and "drift" in result.output
    result = run("--help")
    assert result.exit_code == 0
    for name in ("fit", "predict", "report", "select"):
        assert name in result.output


@pytest.mark.parametrize("command", ["fit", "select"])
def test_a_target_must_be_a_displacement_column(machine, tmp_path, command):
    # a temperature named as target is also a sensor: the model read it back (RMSE 0.00)
    _, data, _ = machine
    result = run(command, str(data), "--target", "drift_um,A_C",
                 "--out", str(tmp_path / ("m.safetensors" if command == "fit" else "s.json")))
    assert result.exit_code == 2, result.output
    assert "option '--target'" in result.output and "'A_C'" in result.output
    assert "_um" in result.output and "Traceback" not in result.output
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("command", ["fit", "select", "report"])
def test_the_same_data_given_twice_is_bad_input(machine, tmp_path, command):
    # time-blocked validation holds one file out per block: a file given twice (or its
    # copy) was scored against a model fitted on itself, 0.10 µm RMSE where the file
    # alone validates at 0.24 µm (examples/real, first 400 rows), and fit wrote the model
    folder, data, model = machine
    copy = tmp_path / "copy.csv"
    copy.write_text(data.read_text().replace("\n", "\r\n"))  # same rows, other bytes
    for second in (str(data), str(copy)):
        args = {"fit": [str(data), second, "--target", "drift_um",
                        "--out", str(tmp_path / "m.safetensors")],
                "select": [str(data), second, "--target", "drift_um",
                           "--out", str(tmp_path / "s.json")],
                "report": [str(model), str(data), second, "--out", str(tmp_path / "r")]}
        result = run(command, *args[command])
        assert result.exit_code == 2, result.output
        assert f"{second}: holds the same data as {data}" in " ".join(result.output.split())
        assert "Traceback" not in result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["copy.csv"]


def test_a_probe_that_never_moves_is_bad_input_and_reports_still_work(machine, tmp_path):
    # a dead probe (every row 0 µm) had NaN grades for every sensor: select printed 'nan',
    # fit wrote a model, and its report ended in 'internal error: Axis limits cannot be NaN'
    folder, _, model = machine
    columns = synthetic_columns(hours=3.0)
    columns["drift_um"] = np.zeros_like(columns["drift_um"])
    dead = tmp_path / "dead.csv"
    write_csv(dead, columns)
    for command, out in (("fit", "m.safetensors"), ("select", "s.json")):
        result = run(command, str(dead), "--target", "drift_um", "--out", str(tmp_path / out))
        assert result.exit_code == 2, result.output
        assert f"{dead}, column 'drift_um': never changes" in " ".join(result.output.split())
    # a good model's report on a stretch where the probe reads flat is no error
    result = run("report", str(model), str(dead), "--out", str(tmp_path / "report"))
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dead.csv", "report"]


def test_the_reports_figures_show_the_speeds_and_its_images_say_what_they_are(
        machine, tmp_path, monkeypatch):
    # the measured-vs-predicted figure showed no speed: a step test's stops and speeds
    # were left to be guessed from the drift; the page's images had no alt text
    import re

    import twin.drift.report

    folder, data, model = machine
    figures = []
    draw = twin.drift.report._png
    monkeypatch.setattr(twin.drift.report, "_png", lambda fig: figures.append(fig) or draw(fig))
    assert run("report", str(model), str(data), "--out", str(tmp_path / "r")).exit_code == 0
    top, bottom = figures[0].axes
    labels = [t.get_text() for t in top.texts]
    # the machine: 3000 rpm, stop, 6000 rpm, stop, 3000 rpm, 40 min each
    assert labels == ["3000 rpm", "stopped", "6000 rpm", "stopped", "3000 rpm"]
    for ax in (top, bottom):
        stops = sorted((round(p.get_x() * 60), round((p.get_x() + p.get_width()) * 60))
                       for p in ax.patches if p.get_width() > 0 and p.get_height() == 1)
        assert stops == [(40, 80), (120, 160)]  # minutes
    renderer = figures[0].canvas.get_renderer()
    legend = top.get_legend().get_window_extent(renderer)
    assert legend.y0 >= top.get_window_extent(renderer).y1 - 1  # above the curves
    html = (tmp_path / "r" / "report.html").read_text()
    tags = re.findall(r"<img [^>]*>", html)
    assert len(tags) == 3 and all(re.search(r"alt='[^']+'", t) for t in tags)


def test_a_stop_while_the_report_is_drawn_leaves_the_earlier_pair(machine, tmp_path,
                                                                  monkeypatch):
    # metrics.json was written before the figures were drawn: Ctrl-C while drawing left
    # the new metrics beside the earlier report.html
    import twin.drift.report

    folder, data, model = machine
    out = tmp_path / "report"
    assert run("report", str(model), str(data), "--out", str(out)).exit_code == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    (out / "metrics.json").write_text("{}")  # the earlier pair, told apart from the new
    (out / "report.html").write_text("<p>earlier</p>")

    def interrupted(*args, **kwargs):  # noqa: ANN002, ANN003, ANN202
        raise KeyboardInterrupt

    monkeypatch.setattr(twin.drift.report, "_figures", interrupted)
    assert run("report", str(model), str(data), "--out", str(out)).exit_code == 130
    assert (out / "metrics.json").read_text() == "{}"
    assert (out / "report.html").read_text() == "<p>earlier</p>"
    assert sorted(before) == sorted(p.name for p in out.iterdir())


def _two_files(tmp_path, change_second):
    """Two hours of the synthetic machine, as two files of one hour each (the second
    changed by `change_second`)."""
    columns = synthetic_columns(hours=2.0)
    half = columns["time_s"].size // 2
    first = tmp_path / "first.csv"
    second = tmp_path / "second.csv"
    write_csv(first, {k: v[:half] for k, v in columns.items()})
    later = {k: v[half:].copy() for k, v in columns.items()}
    change_second(later)
    write_csv(second, later)
    return first, second


def test_a_file_too_short_for_a_validation_block_is_bad_input(tmp_path):
    # a one-row second file is a validation block of its own: holding the first file out
    # left one row to fit on ('internal error: ValueError: Found array with 0 sample(s)')
    first, second = _two_files(tmp_path, lambda c: [c.__setitem__(k, v[:1])
                                                    for k, v in list(c.items())])
    out = tmp_path / "m.safetensors"
    result = run("fit", str(first), str(second), "--target", "drift_um", "--out", str(out),
                 "--method", "ridge_dynamic")
    assert result.exit_code == 2, result.output
    assert (f"{second}, column 'drift_um': only 1 sample holds every target; need at least 20 "
            "in every file") in " ".join(result.output.split())
    assert "Traceback" not in result.output and not out.exists()


def test_data_without_speed_fit_with_the_methods_that_need_none(tmp_path):
    # speed_rpm is optional (DESIGN): without it in every file, fit validated the speed
    # methods too and ended in 'internal error: ValueError: the features need speed_rpm'
    first, second = _two_files(tmp_path, lambda c: c.pop("speed_rpm"))
    out = tmp_path / "m.safetensors"
    result = run("fit", str(first), str(second), "--target", "drift_um", "--out", str(out))
    assert result.exit_code == 0, result.output
    assert "ridge_lagged" in result.output and "ridge_dynamic" not in result.output
    assert "no speed_rpm in every file" in result.output
    pred = tmp_path / "p.csv"
    assert run("predict", str(out), str(second), "--out", str(pred)).exit_code == 0
    result = run("fit", str(first), str(second), "--target", "drift_um", "--out", str(out),
                 "--method", "bp")
    assert result.exit_code == 2, result.output
    message = " ".join(result.output.split())
    assert f"{first}, {second}, option '--method': method 'bp' needs speed_rpm" in message
    assert "Traceback" not in result.output


def test_listed_sensors_need_not_be_the_first_files_every_column(tmp_path):
    # --sensors A_C,B_C was refused because the second file lacks C_C, a column not asked
    # for (the first file's temperature columns were required in every file)
    first, second = _two_files(tmp_path, lambda c: c.pop("C_C"))
    out = tmp_path / "m.safetensors"
    result = run("fit", str(first), str(second), "--target", "drift_um", "--out", str(out),
                 "--method", "ridge_dynamic", "--sensors", "A_C,B_C", "--quiet")
    assert result.exit_code == 0, result.output
    result = run("fit", str(first), str(second), "--target", "drift_um", "--out", str(out),
                 "--method", "ridge_dynamic", "--sensors", "A_C,C_C", "--quiet")
    assert result.exit_code == 2, result.output
    assert f"{second}, line 1, column 'C_C': missing required column" in result.output


def test_an_empty_speed_column_is_no_speed_column(tmp_path):
    # a logger exporting every channel wrote speed_rpm without a value: fit refused it
    # ('the column holds no value in any row') where a file without the column fitted
    # with the methods that need no speed
    first, second = _two_files(tmp_path, lambda c: c["speed_rpm"].__setitem__(slice(None),
                                                                              np.nan))
    out = tmp_path / "m.safetensors"
    result = run("fit", str(first), str(second), "--target", "drift_um", "--out", str(out))
    assert result.exit_code == 0, result.output
    assert "ridge_lagged" in result.output and "ridge_dynamic" not in result.output
    message = " ".join(result.output.split())
    assert (f"note: {second}, lines 2–241, column 'speed_rpm': no value at all: read as "
            "no speed column") in message
    pred = tmp_path / "p.csv"
    assert run("predict", str(out), str(second), "--out", str(pred)).exit_code == 0
    # a model that uses the speed still needs its values
    speed_model = tmp_path / "speed.safetensors"
    assert run("fit", str(first), "--target", "drift_um", "--out", str(speed_model),
               "--method", "ridge_dynamic", "--quiet").exit_code == 0
    result = run("predict", str(speed_model), str(second), "--out", str(pred))
    assert result.exit_code == 2, result.output
    assert f"{second}, line 2, column 'speed_rpm': column has no values" in result.output


@pytest.mark.parametrize("sensors", ["auto", "all", "2"])
def test_a_temperature_column_one_file_lacks_is_left_out_whichever_file_comes_first(
        tmp_path, sensors):
    # the first file's columns were required in every file: a second file without C_C
    # was refused ('required column is missing'), a first one without it fitted in
    # silence without C_C
    first, second = _two_files(tmp_path, lambda c: c.pop("C_C"))
    models = []
    for k, files in enumerate(((first, second), (second, first))):
        out = tmp_path / f"m{k}.safetensors"
        result = run("fit", *map(str, files), "--target", "drift_um", "--out", str(out),
                     "--method", "ridge_dynamic", "--sensors", sensors)
        assert result.exit_code == 0, result.output
        message = " ".join(result.output.split())
        assert f"note: temperature column 'C_C' left out: not in {second}" in message
        models.append(out)
    from twin.drift.modelfile import load_drift_model

    for out in models:
        model = load_drift_model(out)
        assert set(model.spec.sensors) <= {"A_C", "B_C"}
        assert model.metadata["sensors_left_out"] == {
            "C_C": f"not in {second} (a sensor is in every file)"}
    result = run("select", str(second), str(first), "--target", "drift_um")
    assert result.exit_code == 0, result.output
    assert "'C_C' left out" in result.output and "C_C " not in result.output


def test_files_without_a_common_temperature_column_are_bad_input(tmp_path):
    first, second = _two_files(tmp_path, lambda c: [c.__setitem__(f"{k[0]}2_C", c.pop(k))
                                                    for k in ("A_C", "B_C", "C_C")])
    result = run("fit", str(first), str(second), "--target", "drift_um", "--out",
                 str(tmp_path / "m.safetensors"))
    assert result.exit_code == 2, result.output
    message = " ".join(result.output.split())
    assert (f"{first}, {second}: no temperature column is in every file ({first}: A_C, B_C, "
            f"C_C; {second}: A2_C, B2_C, C2_C)") in message


def test_predict_reads_no_target_so_an_empty_one_is_no_error(machine, tmp_path):
    # a file with the probe's column left blank (the drift yet to come) was refused:
    # 'column has no values'; predict needs time, speed and temperatures only
    _, _, model = machine
    columns = synthetic_columns(hours=0.5)
    full, blank = tmp_path / "full.csv", tmp_path / "blank.csv"
    write_csv(full, columns)
    columns["drift_um"][:] = np.nan
    write_csv(blank, columns)
    pred, again = tmp_path / "p_blank.csv", tmp_path / "p_full.csv"
    result = run("predict", str(model), str(blank), "--out", str(pred))
    assert result.exit_code == 0, result.output
    assert run("predict", str(model), str(full), "--out", str(again)).exit_code == 0
    assert pred.read_bytes() == again.read_bytes()
    result = run("report", str(model), str(blank), "--out", str(tmp_path / "report"))
    assert result.exit_code == 2 and "column 'drift_um': column has no values" in result.output


def test_a_temperature_column_that_never_changes_is_no_sensor(tmp_path):
    # a thermocouple reading 21 °C throughout got a grade (0.59, its normalised series all
    # zero) and a cluster of its own, so 'auto' fitted on it
    columns = synthetic_columns(hours=3.0)
    columns["K_C"] = np.full(columns["time_s"].size, 21.0)
    columns["K_C"][5:9] = np.nan                       # gaps aside
    data = tmp_path / "machine.csv"
    write_csv(data, columns)
    out = tmp_path / "m.safetensors"
    for sensors in ("auto", "all"):
        result = run("fit", str(data), "--target", "drift_um", "--out", str(out),
                     "--method", "ridge_dynamic", "--sensors", sensors)
        assert result.exit_code == 0, result.output
        assert ("note: temperature column 'K_C' left out: reads 21 in every sample (tells "
                "nothing)") in " ".join(result.output.split())
        assert "K_C" not in result.output.split("sensors:")[1]
    result = run("select", str(data), "--target", "drift_um")
    assert result.exit_code == 0 and "K_C " not in result.output
    result = run("fit", str(data), "--target", "drift_um", "--out", str(out), "--quiet",
                 "--method", "ridge_dynamic", "--sensors", "A_C,K_C")   # asked for: used
    assert result.exit_code == 0, result.output
    for name in ("A_C", "B_C", "C_C"):
        columns[name][:] = 20.0 + len(name)
    write_csv(data, columns)
    result = run("fit", str(data), "--target", "drift_um", "--out", str(out))
    assert result.exit_code == 2, result.output
    assert "every temperature column (A_C, B_C, C_C, K_C) reads one value" in " ".join(
        result.output.split())


def test_predictions_keep_a_unix_time_as_read(machine, tmp_path):
    # PRED.csv wrote time_s to 6 digits: every row of a logger's Unix time read 1.7e+09
    _, _, model = machine
    columns = synthetic_columns(hours=0.5)

    def write_exactly(path):
        path.write_text("\n".join([",".join(columns)] + [
            ",".join(repr(float(v)) for v in row) for row in zip(*columns.values(),
                                                                   strict=True)]))

    predictions = []
    for start in (0.0, 1_700_000_000.25):
        columns["time_s"] += start
        data = tmp_path / f"from_{start:.0f}.csv"
        write_exactly(data)
        pred = tmp_path / f"p_{start:.0f}.csv"
        assert run("predict", str(model), str(data), "--out", str(pred)).exit_code == 0
        with open(pred) as fh:
            predictions.append(list(csv.reader(fh))[1:])
    np.testing.assert_array_equal([float(r[0]) for r in predictions[1]], columns["time_s"])
    assert [r[1:] for r in predictions[0]] == [r[1:] for r in predictions[1]]
    columns["time_s"][7] = columns["time_s"][6]        # and an error names the time read
    write_exactly(data)
    result = run("predict", str(model), str(data), "--out", str(pred))
    assert result.exit_code == 2 and "time 1700000090.25 s repeats that of line 8" in (
        " ".join(result.output.split()))


def test_notes_name_file_line_and_column_as_the_error_messages_do(machine, tmp_path):
    # the notes said "column 'A_C', rows 22–27" of a CSV file's lines, in the reverse order
    # of an error ("data.csv, line 4, column 'time_s': ..."), and a gap at the start told
    # "the rows before it" beside those line numbers
    import pyarrow as pa
    import pyarrow.parquet as pq

    _, _, model = machine
    columns = synthetic_columns(hours=0.5)
    columns["A_C"][20:26] = np.nan  # samples 21-26: lines 22-27 under the header
    columns["A_C"][:1] = np.nan
    again = {k: np.concatenate([v[:60], v[50:60], v[60:]]) for k, v in columns.items()}
    data = tmp_path / "gaps.csv"
    write_csv(data, again)
    pred = tmp_path / "p.csv"
    result = run("predict", str(model), str(data), "--out", str(pred))
    assert result.exit_code == 0, result.output
    notes = [line for line in result.output.splitlines() if line.startswith("note:")]
    assert notes == [
        f"note: {data}, lines 62–71, column 'time_s': exact copies of earlier lines: dropped",
        f"note: {data}, line 2, column 'A_C': leading gap: first reading used for the "
        "samples before it",
        f"note: {data}, lines 22–27, column 'A_C': gap bridged causally: last reading held",
    ]
    # a Parquet file's place is its data row, as in its errors
    parquet = tmp_path / "gaps.parquet"
    pq.write_table(pa.table(columns), parquet)
    result = run("predict", str(model), str(parquet), "--out", str(pred))
    assert result.exit_code == 0, result.output
    assert f"note: {parquet}, rows 21–26, column 'A_C': gap bridged causally" in result.output
    # the report's data findings say the same
    report = tmp_path / "report"
    assert run("report", str(model), str(data), "--out", str(report)).exit_code == 0
    page = (report / "report.html").read_text()
    assert f"{data}, lines 22–27, column &#39;A_C&#39;: gap bridged causally" in page
    metrics = json.loads((report / "metrics.json").read_text())
    found = metrics["data_findings"][-1]
    assert (found["first_row"], found["last_row"], found["row_unit"]) == (22, 27, "line")


def test_a_column_drift_does_not_read_is_told(tmp_path):
    # a speed logged as 'speed' was dropped without a word: fit chose among the two
    # methods that need no speed, and the user never heard the speed was not used
    cols = synthetic_columns(hours=1.0)
    cols["speed"] = cols.pop("speed_rpm")
    cols["operator"] = np.zeros(cols["time_s"].size)
    path = tmp_path / "logged.csv"
    write_csv(path, cols)
    result = run("fit", str(path), "--target", "drift_um", "--out",
                 str(tmp_path / "m.safetensors"))
    assert result.exit_code == 0, result.output
    message = " ".join(result.output.split())
    assert (f"note: {path}: column(s) 'speed', 'operator' not read (drift data: time_s, "
            "speed_rpm, *_C temperatures, *_um displacements)") in message
    assert "ridge_dynamic" not in message  # what the note explains
    cols["speed_rpm"] = cols.pop("speed")
    del cols["operator"]
    write_csv(path, cols)
    result = run("fit", str(path), "--target", "drift_um", "--out",
                 str(tmp_path / "m.safetensors"), "--method", "mlr")
    assert result.exit_code == 0 and "not read" not in result.output


def test_a_stretch_of_time_without_rows_is_told(tmp_path):
    # a logger stopped for 45 min: the lagged features held the last reading across it,
    # as for a missing reading, which was told, while the gap in time was not
    cols = synthetic_columns(hours=2.0)
    keep = (cols["time_s"] < 1800.0) | (cols["time_s"] >= 4500.0)
    path = tmp_path / "gap.csv"
    write_csv(path, {k: v[keep] for k, v in cols.items()}, "# logger: one\n")
    result = run("fit", str(path), "--target", "drift_um", "--out",
                 str(tmp_path / "m.safetensors"), "--method", "mlr")
    assert result.exit_code == 0, result.output
    message = " ".join(result.output.split())
    # the row at 1785 s is data row 120, on line 122 under the metadata line and the header
    assert (f"note: {path}, lines 122–123, column 'time_s': 2715 s without rows: the "
            "lagged features hold the last reading across it") in message
    write_csv(path, cols)
    result = run("fit", str(path), "--target", "drift_um", "--out",
                 str(tmp_path / "m.safetensors"), "--method", "mlr")
    assert result.exit_code == 0 and "without rows" not in result.output


def test_report_tells_in_sample_figures_from_unseen_ones(machine, tmp_path):
    """On the real step tests `report` on the fitting data printed 0.3 µm RMSE beside a
    validation of 3 µm, and nothing said which was which."""
    folder, data, model = machine
    result = run("report", str(model), str(data), "--out", str(tmp_path / "same"))
    assert result.exit_code == 0, result.output
    assert "note: in-sample: 100 % of these rows are from data the model was fitted on" in (
        result.output)
    assert json.loads((tmp_path / "same" / "metrics.json").read_text())["fitted_rows_pct"] == 100
    assert "<b>In-sample:</b>" in (tmp_path / "same" / "report.html").read_text()
    other = tmp_path / "other.csv"                     # the same machine, another day
    write_csv(other, synthetic_columns(hours=3.0, seed=5))
    result = run("report", str(model), str(other), "--out", str(tmp_path / "other"))
    assert result.exit_code == 0, result.output
    assert "in-sample" not in result.output
    assert json.loads((tmp_path / "other" / "metrics.json").read_text())["fitted_rows_pct"] == 0
    # the fitting data as Parquet under another name, beside a file starting as it does
    # (the same first hour: rows alike, another run) — one file of two in-sample
    import pyarrow as pa
    import pyarrow.parquet as pq

    with open(data) as fh:
        rows = list(csv.DictReader(fh))
    copy = tmp_path / "copy.parquet"
    pq.write_table(pa.table({k: [float(r[k]) for r in rows] for k in rows[0]}), copy)
    fitted, other_run = synthetic_columns(hours=3.0), synthetic_columns(hours=3.0, seed=5)
    hour = fitted["time_s"] < 3600
    write_csv(other, {k: np.where(hour, fitted[k], other_run[k]) for k in fitted})
    result = run("report", str(model), str(copy), str(other), "--out", str(tmp_path / "two"))
    assert result.exit_code == 0, result.output
    metrics = json.loads((tmp_path / "two" / "metrics.json").read_text())
    assert metrics["fitted_rows_pct"] == pytest.approx(50.0)


def test_fit_tells_the_worst_blocks_coverage_and_older_models_still_report(machine, tmp_path):
    folder, data, _ = machine
    model = tmp_path / "m.safetensors"
    result = run("fit", str(data), "--target", "drift_um", "--out", str(model), "--method",
                 "mlr", "--sensors", "all")
    assert result.exit_code == 0, result.output
    line = next(x for x in result.output.splitlines() if x.lstrip().startswith("mlr"))
    assert "worst" in line
    from twin.drift.modelfile import load_drift_model, save_drift_model

    fitted = load_drift_model(model)                  # as written before the per-block shares
    del fitted.metadata["validation"]["methods"]["mlr"]["coverage_90_pct_per_block"]
    save_drift_model(fitted, tmp_path / "old.safetensors")
    result = run("report", str(tmp_path / "old.safetensors"), str(data), "--out",
                 str(tmp_path / "report"))
    assert result.exit_code == 0, result.output


def test_a_one_row_file_is_refused_for_its_length(tmp_path):
    """It was 'every temperature column reads one value throughout', true of one row and
    no help: the file is too short."""
    data = tmp_path / "one.csv"
    write_csv(data, {k: v[:1] for k, v in synthetic_columns(hours=0.5).items()})
    for args in (["fit", str(data), "--out", str(tmp_path / "m.safetensors")],
                 ["select", str(data)]):
        result = run(*args, "--target", "drift_um")
        assert result.exit_code == 2
        assert result.output.strip().splitlines()[-1] == (
            f"error: {data}, column 'drift_um': only 1 sample holds every target; need at "
            "least 20")


def test_no_temperature_column_tells_what_the_header_has(tmp_path):
    """A logger's own names ('T front bearing') are not read: the message lists them."""
    columns = synthetic_columns(hours=0.5)
    data = tmp_path / "logger.csv"
    write_csv(data, {"time_s": columns["time_s"], "T front bearing": columns["A_C"],
                     "drift_um": columns["drift_um"]})
    result = run("fit", str(data), "--target", "drift_um", "--out",
                 str(tmp_path / "m.safetensors"))
    assert result.exit_code == 2 and "Traceback" not in result.output
    assert result.output.strip().splitlines()[-1] == (
        f"error: {data}, line 1: no temperature columns (names ending in _C) (the header has "
        "time_s, drift_um, T front bearing)")


def test_rows_without_a_measured_drift_are_told(machine, tmp_path):
    """A probe's dropout left its rows out of fitting and of the metrics without a word."""
    _, _, model = machine
    columns = synthetic_columns(hours=1.0)
    columns["drift_um"][30:41] = np.nan                   # samples 31-41: lines 32-42
    data = tmp_path / "dropout.csv"
    write_csv(data, columns)
    note = (f"note: {data}, lines 32–42, column 'drift_um': no drift measured: left out of "
            "fitting and of the metrics")
    result = run("fit", str(data), "--target", "drift_um", "--method", "mlr", "--out",
                 str(tmp_path / "m.safetensors"))
    assert result.exit_code == 0, result.output
    assert note in result.output.splitlines()
    result = run("report", str(model), str(data), "--out", str(tmp_path / "report"))
    assert note in result.output.splitlines()
    metrics = json.loads((tmp_path / "report" / "metrics.json").read_text())
    assert metrics["targets"]["drift_um"]["n"] == columns["time_s"].size - 11
    # predict reads no drift: nothing to tell
    result = run("predict", str(model), str(data), "--out", str(tmp_path / "p.csv"))
    assert "no drift measured" not in result.output


def test_fit_help_says_what_a_validation_block_is():
    text = " ".join(result_text(run("fit", "--help")).split())
    assert "A block is a file, or a quarter of the rows when one file is given" in text
