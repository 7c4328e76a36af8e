"""`twin train` end to end on small synthetic runs (lumped plant stands in for the twin)."""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from twin.correction.modelfile import load_model
from twin.correction.toy_plant import ToyPlant
from twin.correction.training_data import SimulatedRun
from twin.loop import training
from twin.runs import write_run

PLANT = ToyPlant()


def _toy_simulator(run, anchored=True):
    """The toy plant's open-loop run with window-fit-like targets (the truth factors) and,
    for the anchored networks, an anchor 5 % above nominal and input rows made of the
    measured-minus-simulated T1..T4 at each window start."""
    speed = float(run.speed_rpm[0])
    ambient = float(run.ambient_C[0])
    t = np.arange(0.0, run.time_s[-1] + 1e-9, 4.0)
    H, R = PLANT.nominal_heat_W_m3(speed), PLANT.nominal_resistance_m2K_W(speed)
    T = PLANT.simulate(t, speed, ambient, H, R)
    windows = int(np.ceil(t[-1] / 60.0))
    nominal = np.tile(np.r_[H, R], (windows, 1))
    if not anchored:
        return [SimulatedRun(t, T, nominal, nominal, "open_loop")]
    starts = 60.0 * np.arange(windows)
    error = (np.array([np.interp(starts, run.time_s, run.T_C[:, j]) for j in range(4)])
             - np.array([np.interp(starts, t, T[:, j]) for j in range(4)])).T
    rows = np.stack([np.column_stack([np.full(windows, speed), np.full(windows, 0.05),
                                      error[:, j], error[:, (j + 1) % 4], starts,
                                      np.zeros(windows)]) for j in range(4)], axis=1)
    return [SimulatedRun(t, T, nominal, nominal, "fit", fitted=nominal * [1.1, 1.1, 1.2, 1.2],
                         anchors=nominal * 1.05, anchored_inputs=rows)]


@pytest.fixture
def runs(tmp_path, monkeypatch):
    monkeypatch.setattr(training, "training_simulator",
                        lambda rule="fit", spindle=None: _toy_simulator)
    return [_toy_run(tmp_path / f"run_{speed:.0f}.csv", speed, seed=i)
            for i, speed in enumerate((6000.0, 8000.0, 11000.0))]


def _toy_run(path, speed, seed):
    """A 15-min run of the toy plant at `speed` with the sensor noise drawn from `seed`."""
    t = np.arange(0, 901, 5.0)
    H, R = PLANT.nominal_heat_W_m3(speed), PLANT.nominal_resistance_m2K_W(speed)
    T = PLANT.simulate(t, speed, 25.0, H * 1.1, R * 1.2)
    T += np.random.default_rng(seed).normal(0, 0.05, T.shape)
    cols = {"time_s": t, "speed_rpm": np.full(t.size, speed),
            "ambient_C": np.full(t.size, 25.0)}
    cols.update({f"T{j + 1}_C": T[:, j] for j in range(5)})
    write_run(path, cols)
    return path


def _invoke(args):
    from twin.cli import app

    return CliRunner().invoke(app, args)


@pytest.mark.slow
def test_train_writes_model_and_report(runs, tmp_path):
    out = tmp_path / "model" / "m.safetensors"
    before = [p.read_bytes() for p in runs]
    # a run only the closed-loop check replays (another recording, not a copy of a run)
    gate = _toy_run(tmp_path / "gate_6000.csv", 6000.0, seed=9)
    result = _invoke(["train", *map(str, runs), "--out", str(out), "--epochs", "60",
                      "--seed", "3", "--gate-runs", str(gate), "--quiet"])
    assert result.exit_code == 0, result.output
    model = load_model(out)
    assert model.metadata["gate_runs"] == ["gate_6000.csv"]
    assert model.config_name == "anchored"
    assert model.metadata["training_runs"] == ["run_11000", "run_6000", "run_8000"]
    # the closed-loop check replayed the held-out run with every group of networks
    assert set(model.metadata["networks_kept"]) <= {"heat", "resistance"}
    assert set(model.metadata["held_out_temperature_accuracy_pct"]) == {
        "anchor", "resistance", "heat", "heat+resistance"}
    report = json.loads((out.parent / "m.safetensors.report.json").read_text())
    assert set(report["configs"]) == {"anchored", "paper"}
    assert report["configs"]["anchored"]["r2"]["heat_front"]["epochs"] <= 60
    page = (out.parent / "m.safetensors.report.html").read_text()
    assert page.count("data:image/png;base64,") == 3
    assert [p.read_bytes() for p in runs] == before  # inputs never modified

    # the same seed gives the same weights; --paper-config saves the paper's networks
    again = tmp_path / "again.safetensors"
    _invoke(["train", *map(str, runs), "--out", str(again), "--epochs", "60", "--seed", "3",
             "--quiet"])
    assert load_model(again).metadata["sha256"] == model.metadata["sha256"]
    paper = tmp_path / "paper.safetensors"
    assert _invoke(["train", *map(str, runs), "--out", str(paper), "--epochs", "20",
                    "--paper-config", "--quiet"]).exit_code == 0
    assert load_model(paper).config_name == "paper"


@pytest.mark.slow
def test_anchored_networks_need_the_fit_targets(runs, tmp_path, monkeypatch):
    # the ratio-rule simulation records no anchor: the default networks cannot learn from
    # it (exit 2, naming --targets); the paper's configuration can
    monkeypatch.setattr(training, "training_simulator",
                        lambda rule="fit", spindle=None: lambda run: _toy_simulator(run, False))
    out = tmp_path / "m.safetensors"
    result = _invoke(["train", *map(str, runs), "--out", str(out), "--targets", "ratio",
                      "--epochs", "5", "--quiet"])
    assert result.exit_code == 2 and "--targets" in result.output
    assert not out.exists()
    assert _invoke(["train", *map(str, runs), "--out", str(out), "--targets", "ratio",
                    "--epochs", "5", "--paper-config", "--quiet"]).exit_code == 0


def test_train_bad_run_exits_2(tmp_path, monkeypatch):
    monkeypatch.setattr(training, "training_simulator",
                        lambda rule="fit", spindle=None: _toy_simulator)
    bad = tmp_path / "bad.csv"
    bad.write_text("time_s,speed_rpm\n0,9000\n")
    result = _invoke(["train", str(bad), "--out", str(tmp_path / "m.safetensors")])
    assert result.exit_code == 2
    assert "bad.csv" in result.output


def test_runs_are_told_apart_by_their_files_not_their_name_lines(runs, tmp_path):
    # a logger writes the same `# name:` into every file: the runs were one "run" to the
    # held-out split and the model said "1 runs"
    from twin.runs import read_run

    for path in runs:
        run = read_run(path)
        cols = {"time_s": run.time_s, "speed_rpm": run.speed_rpm, "ambient_C": run.ambient_C,
                **{f"T{j + 1}_C": run.T_C[:, j] for j in range(5)}}
        write_run(path, cols, {"name": "machine 3"})
    out = tmp_path / "m.safetensors"
    result = _invoke(["train", *map(str, runs), "--out", str(out), "--epochs", "5",
                      "--paper-config", "--quiet"])
    assert result.exit_code == 0, result.output
    assert load_model(out).metadata["training_runs"] == ["run_11000", "run_6000", "run_8000"]


def test_two_runs_of_one_file_name_are_refused_naming_both(runs, tmp_path):
    other = tmp_path / "other"
    other.mkdir()
    twin_file = other / runs[0].name
    twin_file.write_bytes(runs[0].read_bytes())
    out = tmp_path / "m.safetensors"
    result = _invoke(["train", *map(str, runs), str(twin_file), "--out", str(out),
                      "--paper-config", "--quiet"])
    assert result.exit_code == 2, result.output
    assert f"{runs[0]}, {twin_file}" in result.output and not out.exists()


def test_a_folder_of_runs_trains_as_its_runs(runs, tmp_path):
    # as `twin replay SUITE_DIR`: a `twin synth --suite` folder is the natural input
    out = tmp_path / "model" / "m.safetensors"
    result = _invoke(["train", str(runs[0].parent), "--out", str(out), "--epochs", "5",
                      "--paper-config", "--quiet"])
    assert result.exit_code == 0, result.output
    assert load_model(out).metadata["training_runs"] == ["run_11000", "run_6000", "run_8000"]
    empty = tmp_path / "empty"
    empty.mkdir()
    result = _invoke(["train", str(empty), "--out", str(out), "--quiet"])
    assert result.exit_code == 2 and "empty: no recorded runs" in result.output


def test_runs_too_short_or_stopped_to_train_on_exit_2_saying_so(tmp_path, monkeypatch):
    # the runs' data falls short, not the code: one line, exit 2 (it was an internal error)
    monkeypatch.setattr(training, "training_simulator",
                        lambda rule="fit", spindle=None: _toy_simulator)
    t = np.arange(0, 301, 5.0)
    cases = {"short": [(9000.0, 130)], "stopped": [(0.0, 300), (0.0, 300), (0.0, 300)]}
    for case, specs in cases.items():
        paths = []
        for k, (speed, seconds) in enumerate(specs):
            keep = t <= seconds
            cols = {"time_s": t[keep], "speed_rpm": np.full(keep.sum(), speed),
                    "ambient_C": np.full(keep.sum(), 25.0 + 0.1 * k)}  # three runs, no copy
            cols.update({f"T{j + 1}_C": 25.0 + 0.01 * j + 0.001 * t[keep] for j in range(5)})
            paths.append(tmp_path / f"{case}_{k}.csv")
            write_run(paths[-1], cols)
        out = tmp_path / f"{case}.safetensors"
        result = _invoke(["train", *map(str, paths), "--out", str(out), "--quiet"])
        assert result.exit_code == 2, result.output
        assert "too few" in result.output and "longer runs" in result.output
        assert result.output.count("\n") == 1 and not out.exists()


def test_a_gate_run_that_is_also_a_training_run_is_refused(runs, tmp_path, monkeypatch):
    # the gate is to replay runs never trained on: the same file given as a training run
    # (here through its folder) and as --gate-runs trained on it and gated on it, silently
    monkeypatch.setattr(training, "training_simulator", lambda *a, **k: pytest.fail("ran"))
    out = tmp_path / "m.safetensors"
    result = _invoke(["train", str(runs[0].parent), "--out", str(out),
                      "--gate-runs", str(runs[1]), "--quiet"])
    assert result.exit_code == 2, result.output
    assert str(runs[1]) in result.output and "--gate-runs" in result.output
    assert "trained on" in result.output and len(result.output.strip().splitlines()) == 1
    assert not out.exists()


@pytest.mark.parametrize("as_gate", [False, True])
def test_a_copy_of_a_run_is_refused(runs, tmp_path, monkeypatch, as_gate):
    # a run copied under another name was trained on twice, and as --gate-runs it passed
    # the gate's "never trained on" check (made on the path); other line ends, same data
    monkeypatch.setattr(training, "training_simulator", lambda *a, **k: pytest.fail("ran"))
    copy = tmp_path / "copy.csv"
    copy.write_text(runs[1].read_text().replace("\n", "\r\n"))
    out = tmp_path / "m.safetensors"
    given = [*map(str, runs), "--gate-runs", str(copy)] if as_gate else [*map(str, runs),
                                                                        str(copy)]
    result = _invoke(["train", *given, "--out", str(out), "--quiet"])
    assert result.exit_code == 2, result.output
    assert f"{copy}: holds the same data as {runs[1]}" in " ".join(result.output.split())
    assert len(result.output.strip().splitlines()) == 1 and not out.exists()


def test_a_stop_while_the_report_is_drawn_leaves_no_earlier_report_beside_the_model(
        runs, tmp_path, monkeypatch):
    # the model was replaced, then Ctrl-C while the report was drawn (about 1 s) left the
    # earlier model's report beside the new model, as its report
    import twin.correction.report

    out = tmp_path / "m.safetensors"
    args = ["train", *map(str, runs), "--out", str(out), "--epochs", "5", "--quiet",
            "--paper-config", "--targets", "ratio"]
    assert _invoke(args).exit_code == 0
    assert (tmp_path / "m.safetensors.report.json").exists()

    def interrupted(*args, **kwargs):  # noqa: ANN002, ANN003, ANN202
        raise KeyboardInterrupt

    monkeypatch.setattr(twin.correction.report, "write_report", interrupted)
    result = _invoke([*args, "--seed", "1"])
    assert result.exit_code == 130, result.output
    assert load_model(out).metadata["seed"] == 1
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith("m.")) == [
        "m.safetensors"]


@pytest.mark.slow
def test_one_run_is_not_told_as_held_out(runs, tmp_path):
    # one run is split by its windows, so the gate replays the run the networks were
    # trained on: train and model-info told it as "the held-out runs"
    out = tmp_path / "one.safetensors"
    result = _invoke(["train", str(runs[0]), "--out", str(out), "--epochs", "20"])
    assert result.exit_code == 0, result.output
    told = ("the run they were trained on (a single run: none is held out)")
    assert f"checking the networks in closed loop on {told} …" in result.output
    assert "held-out runs" not in result.output
    info = _invoke(["model-info", str(out)])
    assert info.exit_code == 0, info.output
    assert f"temperature accuracy on {told}: anchor " in info.output, info.output
    # several runs: whole runs are held out, and a gate run is named as one
    out = tmp_path / "three.safetensors"
    gate = _toy_run(tmp_path / "gate_6000.csv", 6000.0, seed=9)
    result = _invoke(["train", *map(str, runs), "--out", str(out), "--epochs", "20",
                      "--gate-runs", str(gate)])
    assert result.exit_code == 0, result.output
    told = "the held-out runs and the gate runs"
    assert f"checking the networks in closed loop on {told} …" in result.output
    assert f"temperature accuracy on {told}: anchor " in _invoke(["model-info", str(out)]).output
