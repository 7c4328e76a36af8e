"""Drift data checks, fitting, causal prediction and the model file (synthetic machine)."""

from __future__ import annotations

import numpy as np
import pytest
from typer.testing import CliRunner

from tests.drift_synthetic import synthetic_columns, write_csv
from twin.data import bundled_path
from twin.drift.data import read_drift_data
from twin.drift.features import FeatureSpec, dynamic_features, reference_temperatures
from twin.drift.folds import block_labels
from twin.drift.methods import METHODS, FitRows
from twin.drift.model import fit_drift_model
from twin.drift.modelfile import load_drift_model, save_drift_model
from twin.errors import InputError


@pytest.fixture(scope="module")
def data_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("drift") / "machine.csv"
    write_csv(path, synthetic_columns(), metadata="# machine: synthetic\n")
    return path


@pytest.fixture(scope="module")
def ridge_model(data_file):
    data = read_drift_data([data_file], targets=["drift_um"])
    return fit_drift_model(data, method="ridge_dynamic", sensors="all", seed=0)


def test_dynamic_ridge_beats_the_rises_baseline_on_unseen_blocks(data_file):
    data = read_drift_data([data_file], targets=["drift_um"])
    model = fit_drift_model(data, sensors="all", seed=0, candidates=["mlr", "ridge_dynamic"])
    v = model.metadata["validation"]["methods"]
    assert model.method == "ridge_dynamic"
    assert v["ridge_dynamic"]["mean_rmse_um"] < 0.5 * v["mlr"]["mean_rmse_um"]
    assert v["ridge_dynamic"]["mean_rmse_um"] < 0.025 * float(np.ptp(data.targets_um))


@pytest.mark.parametrize("method", ["bp", "bayes", "stack"])
def test_network_methods_predict_a_later_hour(data_file, method):
    """Fit on the first 3 h, predict the 4th (the methods' own fit, no validation)."""
    data = read_drift_data([data_file], targets=["drift_um"])
    spec = FeatureSpec(tuple(data.sensors), tuple(reference_temperatures(data.T_C)),
                       groups=METHODS[method].groups)
    X = dynamic_features(spec, data.time_s, data.T_C, data.speed_rpm)
    Y = data.targets_um
    train = data.time_s < 3 * 3600
    blocks = block_labels(int(train.sum()))
    params = METHODS[method].fit(FitRows(X[train], Y[train], data.time_s[train], blocks, 1))
    mean, std = METHODS[method].predict(params, X[~train])
    rmse = float(np.sqrt(np.mean((mean - Y[~train]) ** 2)))
    assert rmse < 0.1 * float(np.ptp(Y))           # drift spans ~25 µm
    if method == "bayes":
        assert std is not None and np.all(std > 0)
        assert params["alpha"][0] > 0 and 0 < params["gamma"][0] < X.shape[1] * 10


def test_prediction_is_causal(ridge_model, data_file, tmp_path):
    columns = synthetic_columns()
    later = columns["time_s"] > 2 * 3600
    columns["A_C"][later] += 5.0
    columns["speed_rpm"][later] = 8000.0
    changed = tmp_path / "changed.csv"
    write_csv(changed, columns)
    names = list(ridge_model.spec.sensors)
    a = ridge_model.predict(read_drift_data([data_file], sensors=names, require_targets=False))
    b = ridge_model.predict(read_drift_data([changed], sensors=names, require_targets=False))
    for x, y in zip(a, b, strict=True):
        np.testing.assert_array_equal(x[~later], y[~later])
        assert not np.allclose(x[later], y[later])


def test_model_file_round_trip_without_pickle(ridge_model, data_file, tmp_path):
    path = save_drift_model(ridge_model, tmp_path / "model.safetensors")
    assert b"pickle" not in path.read_bytes() and path.read_bytes()[:1] != b"\x80"
    loaded = load_drift_model(path)
    data = read_drift_data([data_file], targets=["drift_um"])
    for x, y in zip(ridge_model.predict(data), loaded.predict(data), strict=True):
        np.testing.assert_array_equal(x, y)
    assert loaded.interval == ridge_model.interval
    assert loaded.validation.keys() == ridge_model.validation.keys() and loaded.validation
    for key, value in ridge_model.validation.items():
        np.testing.assert_array_equal(loaded.validation[key], value)
    raw = bytearray(path.read_bytes())
    raw[-3] ^= 0xFF                                  # flip bits in the last tensor
    (tmp_path / "bad.safetensors").write_bytes(bytes(raw))
    with pytest.raises(InputError, match="bad.safetensors.*(checksum|finite)"):
        load_drift_model(tmp_path / "bad.safetensors")


def _read(tmp_path, columns, targets=("drift_um",)):
    path = tmp_path / "bad.csv"
    write_csv(path, columns)
    return read_drift_data([path], targets=list(targets))


def test_missing_target_column_names_file_row_and_column(tmp_path):
    with pytest.raises(InputError) as err:
        _read(tmp_path, synthetic_columns(hours=0.5), targets=("ch9_um",))
    assert (err.value.row, err.value.column) == (1, "ch9_um")
    assert err.value.file.endswith("bad.csv")


def test_no_temperature_columns(tmp_path):
    columns = {k: v for k, v in synthetic_columns(hours=0.5).items() if not k.endswith("_C")}
    with pytest.raises(InputError, match="no temperature columns") as err:
        _read(tmp_path, columns)
    assert err.value.row == 1


def test_time_going_back_names_the_line(tmp_path):
    columns = synthetic_columns(hours=0.5)
    columns["time_s"][10] = columns["time_s"][8]
    with pytest.raises(InputError, match="goes back from 135 s .line 11. to 120 s") as err:
        _read(tmp_path, columns)
    assert (err.value.row, err.value.column) == (12, "time_s")   # header is line 1


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_drift_data_errors_name_a_csv_files_line_and_a_parquet_files_row(tmp_path, suffix):
    # the location said "row 13" of a CSV file whose message spoke of "line 12"
    import pyarrow as pa
    import pyarrow.parquet as pq

    columns = synthetic_columns(hours=0.5)
    columns["time_s"][10] = columns["time_s"][8]
    path = tmp_path / f"bad{suffix}"
    if suffix == ".csv":
        write_csv(path, columns, metadata="# machine: m1\n")  # header line 2, sample 10 line 13
        where, before = "line 13", "line 12"
    else:
        pq.write_table(pa.table(columns), path)
        where, before = "row 11", "row 10"
    with pytest.raises(InputError) as err:
        read_drift_data([path], targets=["drift_um"])
    assert str(err.value) == (f"{path}, {where}, column 'time_s': time goes back from 135 s "
                              f"({before}) to 120 s; samples must be in time order")
    del columns["A_C"], columns["B_C"], columns["C_C"]
    path.unlink()
    held = "(the header has time_s, speed_rpm, drift_um)"
    if suffix == ".csv":  # the header's line; a Parquet file has none to name
        write_csv(path, columns, metadata="# machine: m1\n")
        message = f"{path}, line 2: no temperature columns (names ending in _C) {held}"
    else:
        pq.write_table(pa.table(columns), path)
        message = f"{path}: no temperature columns (names ending in _C) {held}"
    with pytest.raises(InputError) as err:
        read_drift_data([path], targets=["drift_um"])
    assert str(err.value) == message


def test_a_repeated_time_is_an_error(tmp_path):
    columns = synthetic_columns(hours=0.5)
    columns["time_s"][10] = columns["time_s"][9]
    with pytest.raises(InputError, match="time 135 s repeats that of line 11") as err:
        _read(tmp_path, columns)
    assert (err.value.row, err.value.column) == (12, "time_s")


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
@pytest.mark.parametrize("change", [
    lambda c: c.pop("time_s"),
    lambda c: c.pop("T3_C"),
    lambda c: c["speed_rpm"].__setitem__(slice(None), np.nan),
    lambda c: c["time_s"].__setitem__(7, np.nan),
    lambda c: c["time_s"].__setitem__(7, 1.0),
], ids=["no_time", "no_T3", "empty_speed", "time_missing", "time_back"])
def test_the_drift_and_run_readers_refuse_a_file_in_the_same_words(tmp_path, suffix, change):
    # each reader had its own words for the same fault: 'no time column' / 'missing
    # required column', 'the column holds no value in any row' / 'column has no values',
    # 'time does not increase (1 s after 10 s)' / 'time goes back from 10 s (line 20) to 1 s'
    import pyarrow as pa
    import pyarrow.parquet as pq

    from twin.runs import read_run, read_table

    columns = dict(read_table(bundled_path("runs", "spindle_9000rpm_30min.csv")).columns)
    change(columns)
    path = tmp_path / f"bad{suffix}"
    if suffix == ".parquet":
        pq.write_table(pa.table(columns), path)
    else:
        write_csv(path, columns)
    with pytest.raises(InputError) as run_error:
        read_run(path)
    with pytest.raises(InputError) as drift_error:
        read_drift_data([path], sensors=["T1_C", "T3_C"], targets=["disp_x_um"],
                        require_speed=True)
    assert str(drift_error.value) == str(run_error.value)


def test_rows_a_logger_sent_twice_are_dropped_as_a_runs_are(ridge_model, tmp_path):
    # a logger re-sending its buffer wrote rows 50-59 again: the run reader drops such
    # copies, the drift reader refused the file ('time ... does not increase')
    columns = synthetic_columns(hours=0.5)
    again = {k: np.concatenate([v[:60], v[50:60], v[60:]]) for k, v in columns.items()}
    once, twice = tmp_path / "once.csv", tmp_path / "twice.csv"
    write_csv(once, columns)
    write_csv(twice, again)
    names = list(ridge_model.spec.sensors)
    a = read_drift_data([once], sensors=names, targets=["drift_um"])
    b = read_drift_data([twice], sensors=names, targets=["drift_um"])
    for x, y in zip(ridge_model.predict(a), ridge_model.predict(b), strict=True):
        np.testing.assert_array_equal(x, y)
    assert [(f["column"], f["first_row"], f["last_row"], f["n_rows"]) for f in b.findings] == [
        ("time_s", 62, 71, 10)]                   # header is line 1, the copies lines 62-71
    assert "exact copies" in b.findings[0]["repair"]
    columns["A_C"][9] += 0.5                      # the same time with other values
    columns["time_s"][9] = columns["time_s"][8]
    write_csv(once, columns)
    with pytest.raises(InputError, match="time 120 s repeats that of line 10"):
        read_drift_data([once], sensors=names, targets=["drift_um"])


def test_all_nan_column_is_an_error(tmp_path):
    columns = synthetic_columns(hours=0.5)
    columns["B_C"][:] = np.nan
    with pytest.raises(InputError, match="no value") as err:
        _read(tmp_path, columns)
    assert (err.value.row, err.value.column) == (2, "B_C")


def test_temperature_gaps_are_bridged_causally_and_reported(tmp_path):
    columns = synthetic_columns(hours=0.5)
    columns["A_C"][20:26] = np.nan
    columns["A_C"][:2] = np.nan
    data = _read(tmp_path, columns)
    a = data.T_C[:, data.sensors.index("A_C")]
    np.testing.assert_array_equal(a[20:26], a[19])
    np.testing.assert_array_equal(a[:2], a[2])
    assert a[26] != a[19]
    found = {(f["column"], f["first_row"], f["last_row"]) for f in data.findings}
    assert found == {("A_C", 2, 3), ("A_C", 22, 27)}


def test_parquet_data_read_like_csv(data_file, tmp_path):
    import pyarrow as pa
    import pyarrow.parquet as pq

    columns = synthetic_columns()
    path = tmp_path / "machine.parquet"
    pq.write_table(pa.table(columns), path)
    a = read_drift_data([path], targets=["drift_um"])
    b = read_drift_data([data_file], targets=["drift_um"])
    assert a.sensors == b.sensors and a.rows[0] == 1
    np.testing.assert_allclose(a.T_C, b.T_C, rtol=1e-5)


def test_bp_fit_is_repeatable_for_a_seed(data_file):
    data = read_drift_data([data_file], targets=["drift_um"])
    spec = FeatureSpec(tuple(data.sensors), tuple(reference_temperatures(data.T_C)))
    X = dynamic_features(spec, data.time_s, data.T_C, data.speed_rpm)[::8]
    Y = data.targets_um[::8]
    rows = FitRows(X, Y, data.time_s[::8], block_labels(len(X)), seed=5)
    a, b = METHODS["bp"].fit(rows), METHODS["bp"].fit(rows)
    assert a.keys() == b.keys()
    for key in a:
        np.testing.assert_array_equal(a[key], b[key])


def test_the_two_kinds_of_model_file_are_named_where_the_other_is_expected(ridge_model,
                                                                          tmp_path):
    # both are .safetensors; each said only "not a spindle-twin ... model" of the other
    from twin.cli import app
    from twin.correction.modelfile import load_model
    from twin.data import bundled_path

    drift = save_drift_model(ridge_model, tmp_path / "drift.safetensors")
    with pytest.raises(InputError, match="is a drift model .twin drift fit., not a correction"):
        load_model(drift)
    with pytest.raises(InputError, match="is a correction model .twin train., not a drift"):
        load_drift_model(bundled_path("correction_model.safetensors"))
    result = CliRunner().invoke(app, ["model-info", str(drift)])
    assert result.exit_code == 2 and "twin drift predict" in result.output


def _safetensors(metadata: dict[str, str] | None) -> bytes:
    from safetensors.numpy import save

    return save({"w": np.zeros(2)}, metadata=metadata)


@pytest.mark.parametrize("data", [
    b"",
    b"not a model\n",
    b"\xff" * 64,
    _safetensors(None),  # safetensors, but no model's metadata
    _safetensors({"other_tool": "{}"}),
], ids=["empty", "text", "bytes", "no-metadata", "foreign-metadata"])
def test_the_two_model_loaders_refuse_a_file_that_is_neither_in_the_same_words(tmp_path,
                                                                                data):
    # the correction loader said "not a readable safetensors model file (Error while
    # deserializing header: ...)" and "no 'spindle_twin' metadata: not a spindle-twin
    # correction model", the drift loader "not a spindle-twin drift model file
    # (safetensors with 'spindle_twin_drift' metadata)" of any of these
    from twin.correction.modelfile import load_model

    path = tmp_path / "m.safetensors"
    path.write_bytes(data)
    with pytest.raises(InputError) as as_correction:
        load_model(path)
    with pytest.raises(InputError) as as_drift:
        load_drift_model(path)
    words = as_correction.value.reason.replace("'spindle_twin' metadata", "KEY metadata")
    assert words.replace("correction model", "MODEL") == as_drift.value.reason.replace(
        "'spindle_twin_drift' metadata", "KEY metadata").replace("drift model", "MODEL")
    assert as_drift.value.file == str(path)


def _with_document(raw: bytes, change, path, checksum: bool = True):
    """A copy of the model file bytes `raw` at `path`, its JSON changed by `change`, and
    without the JSON's checksum unless `checksum` (a file written before it existed)."""
    import json

    size = int.from_bytes(raw[:8], "little")
    header = json.loads(raw[8 : 8 + size])
    doc = json.loads(header["__metadata__"]["spindle_twin_drift"])
    if not checksum:
        del doc["metadata_sha256"]
    change(doc)
    header["__metadata__"]["spindle_twin_drift"] = json.dumps(doc, sort_keys=True)
    text = json.dumps(header).encode()
    text += b" " * (-len(text) % 8)
    path.write_bytes(len(text).to_bytes(8, "little") + text + raw[8 + size:])
    return path


def test_damaged_model_metadata_is_refused(ridge_model, data_file, tmp_path):
    # the checksum covered the tensors only: a damaged digit of a reference temperature
    # moved every prediction without a word, a damaged interval rule ended in
    # 'internal error: KeyError'
    raw = save_drift_model(ridge_model, tmp_path / "model.safetensors").read_bytes()
    for damage in (lambda d: d["features"]["reference_C"].__setitem__(0, 99.0),
                   lambda d: d.__setitem__("interval", {})):
        bad = _with_document(raw, damage, tmp_path / "bad.safetensors")
        with pytest.raises(InputError, match="bad.safetensors: checksum mismatch: the metadata"):
            load_drift_model(bad)


def _set(*keys_value):
    *keys, last, value = keys_value

    def change(doc):
        for key in keys:
            doc = doc[key]
        doc[last] = value
    return change


@pytest.mark.parametrize(("change", "field", "message"), [
    (_set("features", "taus_min", "10,30,90"), "features.taus_min", "valid list"),
    (_set("features", "taus_min", []), "features.taus_min", "at least 1 item"),
    (_set("features", "taus_min", [10.0, -30.0, 90.0]), "features.taus_min[1]", "greater than 0"),
    (_set("features", "taus_min", [10.0, 30.0]), "features",
     "3 sensors and 2 lags make 15 feature columns; the weights take 20"),
    (_set("features", "reference_C", [20.0]), "features", "1 reference temperatures"),
    (_set("features", "reference_C", 2, "20.5"), "features.reference_C[2]", "valid number"),
    (_set("features", "reference_C", 0, float("nan")), "features.reference_C[0]", "finite"),
    (_set("features", "sensors", []), "features.sensors", "at least 1 item"),
    (_set("features", "sensors", "A_C"), "features.sensors", "valid list"),
    (_set("features", "sensors", 1, "A_C"), "features.sensors", "'A_C' is listed twice"),
    (_set("features", "sensors", 0, "drift_um"), "features.sensors", "does not end in _C"),
    (_set("features", "groups", ["rise"]), "features.groups", "takes the feature groups rise, "
     "lag, speed"),
    (_set("features", "groups", ["rise", "lags"]), "features.groups[1]", "'rise', 'lag'"),
    (_set("features", "cache", 1), "features.cache", "unknown field"),
    (_set("interval", {}), "interval.kind", "missing"),
    (_set("interval", "kind", "gauss"), "interval.kind", "'conformal' or 'scaled_posterior'"),
    (_set("interval", "kind", "scaled_posterior"), "interval", "kind 'scaled_posterior' needs "
     "factor"),
    (_set("interval", "half_width_um", [0.4, 0.4]), "interval.half_width_um", "2 values for 1"),
    (_set("interval", "half_width_um", "0.4"), "interval.half_width_um", "valid list"),
    (_set("interval", "half_width_um", [-0.4]), "interval.half_width_um[0]",
     "greater than or equal to 0"),
    (_set("interval", "operating_range", "lo", [0.0]), "interval.operating_range",
     "1 lower (lo) and 8 upper (hi) ends for 8 features"),
    (_set("interval", "operating_range", "hi", 0, -1e9), "interval.operating_range",
     "upper end (hi) below its lower end"),
    (_set("interval", "operating_range", "features", 0, "speed_krpm2"),
     "interval.operating_range.features", "'speed_krpm2' is listed twice"),
    (_set("interval", "operating_range", "features", 0, "speed_rpm"),
     "interval.operating_range.features", "'speed_rpm' is none of the model's features"),
    (_set("interval", "operating_range", "stopped_state_hi", [0.0]), "interval.operating_range",
     "12 lower (stopped_state_lo) and 1 upper (stopped_state_hi) ends for 12 state_features"),
    (lambda d: d["interval"]["operating_range"].pop("stopped_state_lo"),
     "interval.operating_range", "needs its features and both ends"),
    (_set("interval", "operating_range", "state_features", 0, "B_C:rise"),
     "interval.operating_range.state_features", "'B_C:rise' is listed twice"),
    (_set("interval", "operating_range", "state_features", 0, "speed_krpm"),
     "interval.operating_range", "'speed_krpm' is both an operating and a state feature"),
    (_set("interval", "operating_range", "state_features", 0, "A_C"),
     "interval.operating_range.state_features", "'A_C' is none of the model's features"),
    (_set("interval", "operating_range", "state_span", [1.0]), "interval.operating_range",
     "1 spans (state_span) for 12 state_features"),
    (_set("interval", "operating_range", "state_span", 3, -0.5),
     "interval.operating_range.state_span[3]", "greater than or equal to 0"),
    (lambda d: [d["interval"]["operating_range"].pop(k) for k in
                ("state_features", "stopped_state_lo", "stopped_state_hi")],
     "interval.operating_range", "spans of a thermal state (state_span) without its features"),
    (_set("interval", "extrapolation_gain", -2.0), "interval.extrapolation_gain",
     "greater than or equal to 0"),
    (_set("targets", "drift_um"), "targets", "valid list"),
    (_set("targets", ["drift_um", "tilt_um"]), "interval.half_width_um", "1 value for 2"),
    (_set("method", "bayes"), "method", "not those of method 'bayes'"),
    (_set("method", "mlr"), "features.groups", "'mlr' takes the feature groups rise"),
    (_set("metadata", []), "metadata", "valid dictionary"),
    (_set("metadata", "validation", "blocks", "4"), "metadata.validation.blocks", "integer"),
    (_set("metadata", "validation", "methods", "ridge_dynamic", "rmse_um", {}),
     "metadata.validation.methods.ridge_dynamic.rmse_um", "no value for target 'drift_um'"),
    (_set("metadata", "ranking", "sensors", 0, "mean_grade", None),
     "metadata.ranking.sensors[0].mean_grade", "valid number"),
])
def test_damaged_metadata_of_a_file_without_its_checksum_names_the_field(
        ridge_model, data_file, tmp_path, change, field, message):
    # a file written before the JSON had a checksum loads unchecked by it: a damaged lag
    # list or interval rule ended in 'internal error: ...', a damaged width moved the band
    from twin.errors import MetadataError

    raw = save_drift_model(ridge_model, tmp_path / "model.safetensors").read_bytes()
    older = _with_document(raw, lambda d: None, tmp_path / "older.safetensors", checksum=False)
    assert load_drift_model(older).interval == ridge_model.interval     # still loads
    bad = _with_document(raw, change, tmp_path / "bad.safetensors", checksum=False)
    with pytest.raises(MetadataError) as err:
        load_drift_model(bad)
    assert (err.value.file, err.value.column) == (str(bad), field)
    assert message in err.value.reason
    assert f"bad.safetensors, metadata field '{field}': " in str(err.value)
    result = CliRunner().invoke(app_of_twin(), ["drift", "predict", str(bad), str(data_file),
                                                "--out", str(tmp_path / "p.csv")])
    assert result.exit_code == 2, result.output
    assert field in result.output and "Traceback" not in result.output


def app_of_twin():
    from twin.cli import app

    return app


def test_metadata_nested_too_deeply_is_bad_input(ridge_model, tmp_path):
    # json.loads of 10^5 nested lists raised RecursionError: 'internal error'
    raw = save_drift_model(ridge_model, tmp_path / "model.safetensors").read_bytes()
    bad = tmp_path / "deep.safetensors"
    bad.write_bytes(raw)
    deep = _with_document(raw, _set("metadata", "x", []), bad, checksum=False).read_bytes()
    size = int.from_bytes(deep[:8], "little")
    text = deep[8 : 8 + size].replace(b'\\"x\\": []', b'\\"x\\": ' + b"[" * 100_000
                                      + b"]" * 100_000)
    assert len(text) > size
    text += b" " * (-len(text) % 8)
    bad.write_bytes(len(text).to_bytes(8, "little") + text + deep[8 + size:])
    with pytest.raises(InputError, match="deep.safetensors"):
        load_drift_model(bad)


def test_validation_picks_the_sensors_of_each_fold_on_its_training_rows(tmp_path):
    """--sensors auto|K are chosen by their grade on the drift: picked on every row, the
    left-out block's drift chose the sensors that predict it (a leak into the validation).
    Here runs 0–2 follow sensor A and run 3, with a ten times larger drift, sensor B: on
    every row B grades best, on runs 0–2 A does."""
    rng = np.random.default_rng(1)
    t = np.arange(0.0, 2 * 3600.0, 30.0)
    files = []
    for k in range(4):
        a = 20 + 5 * (1 - np.exp(-t / 1500.0)) + rng.normal(0, 0.02, t.size)
        b = 20 + 2 * np.sin(2 * np.pi * t / 3000.0 + k) + rng.normal(0, 0.02, t.size)
        drift = 2.0 * (a - 20) if k < 3 else 20.0 * (b - 20)
        files.append(tmp_path / f"run{k}.csv")
        write_csv(files[-1], {"time_s": t, "A_C": a, "B_C": b,
                              "d_um": drift + rng.normal(0, 0.05, t.size)})
    data = read_drift_data(files, targets=["d_um"])
    model = fit_drift_model(data, method="mlr", sensors="1")
    assert model.spec.sensors == ("B_C",)                # the final model: every row
    assert model.metadata["validation"]["sensors_per_block"][3] == ["A_C"]
    # run 3's out-of-fold prediction is that of a fit on A over runs 0–2
    later = data.segment_ids() == 3
    spec = FeatureSpec(("A_C",), tuple(reference_temperatures(data.T_C[:, :1])),
                       groups=METHODS["mlr"].groups)
    X = dynamic_features(spec, data.time_s, data.T_C[:, :1], None, data.segment_starts)
    params = METHODS["mlr"].fit(FitRows(X[~later], data.targets_um[~later], data.time_s[~later],
                                        data.segment_ids()[~later], 0))
    expected, _ = METHODS["mlr"].predict(params, X[later])
    v = model.validation
    np.testing.assert_allclose(v["predicted_um"][v["block"] == 3], expected, rtol=1e-9)


def test_validation_tells_the_interval_coverage_of_every_block(ridge_model):
    """The pooled coverage (86 % on the real step tests) hid blocks whose band missed most
    of them (27 % of ch2 in the first step test) behind blocks covered whole."""
    v = ridge_model.metadata["validation"]["methods"]["ridge_dynamic"]
    per_block = v["coverage_90_pct_per_block"]["drift_um"]
    val = ridge_model.validation
    block = val["block"].astype(int)
    assert len(per_block) == 4
    y, lo, hi = (val[k].reshape(len(block), -1)[:, 0] for k in ("measured_um", "lo_um", "hi_um"))
    for b, share in enumerate(per_block):
        rows = block == b
        inside = (y[rows] >= lo[rows]) & (y[rows] <= hi[rows])
        assert share == pytest.approx(100.0 * np.mean(inside))
    assert np.average(per_block, weights=np.bincount(block)) == pytest.approx(
        v["coverage_90_pct"]["drift_um"])


@pytest.mark.parametrize("method", ["mlr", "ridge_lagged", "ridge_dynamic", "bp", "bayes",
                                    "stack"])
def test_a_rows_prediction_does_not_change_when_later_rows_are_cut(data_file, tmp_path,
                                                                   method):
    """DESIGN: the prediction at a row uses rows up to it only.  Cut the file after a row:
    the predictions and bands up to it stay (to rounding: a batch of other length sums in
    another order, ~1e-7 µm of the Bayesian band in single precision)."""
    data = read_drift_data([data_file], targets=["drift_um"])
    model = fit_drift_model(data, method=method, sensors="all", seed=0)
    path = save_drift_model(model, tmp_path / "m.safetensors")
    full = [a.copy() for a in load_drift_model(path).predict(data)]
    lines = data_file.read_text().splitlines(keepends=True)
    header = next(k for k, line in enumerate(lines) if not line.startswith("#"))
    for n in (1, 2, 37, 500):
        cut = tmp_path / f"first{n}.csv"
        cut.write_text("".join(lines[: header + 1 + n]))
        part = model.predict(read_drift_data([cut], sensors=list(model.spec.sensors),
                                             require_targets=False))
        for whole, head in zip(full, part, strict=True):
            assert head.shape == (n, 1)
            np.testing.assert_allclose(head, whole[:n], rtol=0, atol=1e-6)


@pytest.mark.parametrize(("sensors", "method"), [("all", "bp"), ("auto", "bp"),
                                                 ("A_C,B_C,C_C", "bayes")])
def test_the_order_of_the_temperature_columns_changes_nothing(tmp_path, sensors, method):
    """The same data with the temperature columns in another order (in the file, or in
    --sensors LIST) is the same model: the features took the file's order, so a network
    started from other weights on each column and another validation and predictions came
    out (0.2 µm RMSE apart on this machine)."""
    columns = synthetic_columns(hours=3.0)
    permuted = {k: columns[k] for k in ("time_s", "C_C", "drift_um", "B_C", "speed_rpm",
                                        "A_C")}
    write_csv(tmp_path / "a.csv", columns)
    write_csv(tmp_path / "b.csv", permuted)
    listed = ",".join(reversed(sensors.split(","))) if "," in sensors else sensors
    models, predictions = [], []
    for name, option in (("a.csv", sensors), ("b.csv", listed)):
        data = read_drift_data([tmp_path / name], targets=["drift_um"])
        models.append(fit_drift_model(data, method=method, sensors=option, seed=0))
        predictions.append(models[-1].predict(data))
    a, b = models
    assert a.spec == b.spec
    assert a.metadata["validation"] == b.metadata["validation"]
    for x, y in zip(predictions[0], predictions[1], strict=True):
        np.testing.assert_array_equal(x, y)
