"""The twin loop and `twin replay` / `snapshot` / `report` (issue 7), end to end.

The recorded run used here is made by the spindle model itself with a bearing heat 15 %
above nominal and a front contact resistance 30 % below (a known, physical mismatch), so
the correcting methods have something real to correct and the expectations below are
about behaviour (corrections move the twin towards the measurement), not fixed numbers.
"""

from __future__ import annotations

import json
import os
import shutil
import time

import numpy as np
import pytest
from typer.testing import CliRunner

from twin.cli import app
from twin.estimation.parameters import apply_factors
from twin.runs import write_run
from twin.spindle.conditions import nominal_conditions

os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")
MINUTES = 5


def make_recorded_run(
    path, model, speed_rpm=9000.0, minutes=MINUTES, ambient_C=25.0, heat=1.15, resistance=0.7,
    seed=0, factors=None, noise_C=0.02, edit=None, load_update_steps=1, record_coolant=False,
):
    """`factors` (twin.estimation.parameters names → multiplier) replaces heat/resistance;
    the coolant inlet is at the ambient, as the nominal model assumes (`record_coolant`:
    and the run records it in a coolant_C column);
    `edit(time_s, temps)` may change the measured temperatures in place before writing;
    `model` is the SpindleModel that plays the spindle; its bearing heat and contact
    resistance are taken at its ring and sleeve temperatures every `load_update_steps`
    4 s steps (1: every step, as the twin's follow its rings; 15: held for each minute)."""
    if factors is None:
        factors = {"H_front": heat, "H_rear": heat, "R_front": resistance}
    T = np.full(model.n_dofs, ambient_C)
    T0 = T.copy()
    times, temps, drift = [0.0], [model.sensor_matrix @ T], [0.0]
    for _ in range(minutes * 15 // load_update_steps):
        s = model.sensor_matrix @ T
        bc = nominal_conditions(
            model, speed_rpm, ambient_C, None, T_bearings_C=(s[0], s[2]), T_sleeves_C=(s[1], s[3])
        )
        loads = apply_factors(bc, factors).to_thermal_loads()
        for T_step in model.thermal.transient(loads, 4.0).march(T, load_update_steps):
            times.append(times[-1] + 4.0)
            temps.append(model.sensor_matrix @ T_step)
            drift.append(1e6 * model.probe_vectors[0] @ (T_step - T0))
        T = T_step
    rng = np.random.default_rng(seed)
    t = np.array(times)
    temps = np.array(temps) + noise_C * rng.standard_normal((t.size, 5))
    if edit is not None:
        edit(t, temps)
    cols = {
        "time_s": t,
        "speed_rpm": np.full(t.size, speed_rpm),
        "ambient_C": np.full(t.size, ambient_C),
        **{f"T{i + 1}_C": temps[:, i] for i in range(5)},
        "disp_z_um": np.array(drift) + 0.05 * rng.standard_normal(t.size),
    }
    if record_coolant:
        cols["coolant_C"] = np.full(t.size, ambient_C)
    write_run(path, cols, {"source": "test: spindle model with +15 % heat, -30 % R_front"})
    return path


@pytest.fixture(scope="module")
def runs_dir(tmp_path_factory, spindle_model):
    d = tmp_path_factory.mktemp("runs")
    make_recorded_run(d / "hot_9000.csv", spindle_model)
    make_recorded_run(d / "hot_12000.csv", spindle_model, speed_rpm=12000.0, seed=1)
    return d


def invoke(*args):
    return CliRunner().invoke(app, list(args), catch_exceptions=False)


def replay(*runs, out, methods, snapshots="none"):
    """`twin replay RUNS --out OUT --methods M --snapshots S --quiet`."""
    return invoke("replay", *map(str, runs), "--out", str(out), "--methods", methods,
                  "--snapshots", snapshots, "--quiet")


@pytest.fixture(scope="module")
def replayed(runs_dir, tmp_path_factory):
    out = tmp_path_factory.mktemp("replay")
    result = replay(runs_dir / "hot_9000.csv", out=out, methods="open_loop,ratio",
                    snapshots="end")
    assert result.exit_code == 0, result.output
    return out


def test_replay_writes_the_design_layout_and_schemas(replayed, runs_dir):
    run_dir = replayed / "hot_9000"
    for name in (
        "keypoints.csv",
        "corrections.csv",
        "accuracy.json",
        "quality.json",
        "fields.pvd",
        "decks",
    ):
        assert (run_dir / name).exists(), name
    acc = json.loads((run_dir / "accuracy.json").read_text())
    assert set(acc) == {"run", "speed_rpm", "ambient_C", "duration_s", "methods"}
    assert acc["speed_rpm"] == 9000.0 and acc["duration_s"] == 60.0 * MINUTES
    assert set(acc["methods"]) == {"open_loop", "ratio"}
    for metrics in acc["methods"].values():
        assert set(metrics) == {
            "temperature_accuracy_pct",
            "temperature_rise_accuracy_pct",
            "deformation_accuracy_pct",
            "rmse_C",
            "rmse_um",
            "max_abs_C",
            "band_coverage_pct",
        }
        assert metrics["band_coverage_pct"] is None  # these methods have no band
        assert set(metrics["rmse_C"]) == {"T1", "T2", "T3", "T4", "T5"}
    summary = json.loads((replayed / "summary.json").read_text())
    assert [r["run"] for r in summary["runs"]] == ["hot_9000"]
    assert set(summary["mean"]) == {"open_loop", "ratio"}
    html = (replayed / "report.html").read_text()
    assert "data:image/png;base64," in html and "hot_9000" in html
    kp = (run_dir / "keypoints.csv").read_text().splitlines()
    assert kp[0].startswith("time_s,method,T1_twin_C")
    assert len(kp) == 1 + 2 * MINUTES * 15  # every solver step, both methods


def test_corrections_move_the_twin_towards_the_measurement(replayed):
    acc = json.loads((replayed / "hot_9000" / "accuracy.json").read_text())["methods"]
    # the plant runs 15 % hotter than nominal: open loop must under-predict the rise
    assert acc["open_loop"]["temperature_rise_accuracy_pct"] < 97.0
    assert (
        acc["ratio"]["temperature_rise_accuracy_pct"]
        > acc["open_loop"]["temperature_rise_accuracy_pct"]
    )
    assert acc["ratio"]["deformation_accuracy_pct"] > acc["open_loop"]["deformation_accuracy_pct"]


def test_vtu_fields_read_back_with_the_expected_arrays(replayed):
    import pyvista as pv

    run_dir = replayed / "hot_9000"
    pvd = (run_dir / "fields.pvd").read_text()
    files = sorted((run_dir / "fields").glob("*.vtu"))
    assert len(files) == MINUTES and all(f.name in pvd for f in files)
    grid = pv.read(files[-1])
    for name in ("temperature_C", "displacement_um", "von_mises_MPa"):
        assert name in grid.point_data, name
    T = grid.point_data["temperature_C"]
    assert 25.0 < T.max() < 120.0 and T.min() > 24.0
    assert grid.point_data["displacement_um"].shape == (grid.n_points, 3)


def test_snapshot_png_is_not_blank_and_has_the_size(replayed, runs_dir, tmp_path):
    from PIL import Image

    png = next((replayed / "hot_9000" / "snapshots").glob("*.png"))
    image = np.asarray(Image.open(png).convert("RGB"), dtype=float)
    assert image.shape == (800, 1200, 3)
    assert image.std() > 10.0  # a field, not a blank canvas
    out = tmp_path / "t120.png"
    result = invoke(
        "snapshot",
        str(runs_dir / "hot_9000.csv"),
        "--time",
        "120",
        "--out",
        str(out),
        "--method",
        "ratio",
        "--field",
        "displacement",
        "--section",
    )
    assert result.exit_code == 0, result.output
    assert np.asarray(Image.open(out).convert("RGB"), dtype=float).std() > 10.0



def test_a_ctrl_c_while_a_snapshot_renders_is_taken_when_it_is_done(spindle_model, tmp_path,
                                                                    monkeypatch):
    # a KeyboardInterrupt raised while VTK renders (in a call VTK makes back into Python)
    # crashed the replay in VTK's Python wrapping (SIGSEGV); the picture now finishes first
    import signal
    import time

    import twin.spindle.fields
    from twin.loop.snapshot import render_snapshot

    real = twin.spindle.fields.field_arrays

    def ctrl_c_meanwhile(*args, **kwargs):  # noqa: ANN002, ANN003, ANN202
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.2)  # Python code runs on meanwhile, as pyvista's does
        return real(*args, **kwargs)

    monkeypatch.setattr(twin.spindle.fields, "field_arrays", ctrl_c_meanwhile)
    out = tmp_path / "t.png"
    with pytest.raises(KeyboardInterrupt):
        render_snapshot(spindle_model, np.full(spindle_model.n_dofs, 25.0), out)
    assert out.is_file() and out.stat().st_size > 10_000
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_figures_drawn_without_fork_fork_nothing(replayed, tmp_path, monkeypatch):
    # a --jobs worker (no forked helpers: the workers fill the cores) still drew a run's
    # second figure in a forked child; a Ctrl-C ends the workers, and that child, left
    # running, wrote into the run's staging folder after the batch had removed it
    import twin.loop.overlap
    from twin.loop.report import run_plotter

    run_dir = shutil.copytree(replayed / "hot_9000", tmp_path / "hot_9000")
    shutil.rmtree(run_dir / "plots")

    def no_fork() -> int:
        raise AssertionError("forked")

    monkeypatch.setattr(twin.loop.overlap.os, "fork", no_fork)
    with run_plotter(fork=False) as plots:
        plots.start(str(run_dir))
        plots.join()
    assert sorted(p.name for p in (run_dir / "plots").iterdir()) == [
        "drift_corrections.png", "temperatures.png"]

def test_bad_run_in_a_batch_is_reported_and_the_others_finish(runs_dir, tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("time_s,speed_rpm,ambient_C,T1_C,T2_C,T3_C,T4_C\n0,9000,25,25,25,25,25\n")
    before = bad.read_bytes()
    out = tmp_path / "out"
    result = replay(bad, runs_dir / "hot_9000.csv", out=out, methods="open_loop")
    assert result.exit_code == 2
    assert "bad.csv" in result.output and "T5_C" in result.output
    assert "Traceback" not in result.output
    summary = json.loads((out / "summary.json").read_text())
    assert [r["run"] for r in summary["runs"]] == ["hot_9000"]
    assert summary["failed"][0]["run"] == "bad" and summary["failed"][0]["kind"] == "input"
    assert bad.read_bytes() == before  # input never modified


def test_the_progress_keeps_run_names_whole_beside_a_long_failure(runs_dir, tmp_path):
    # a failed run's message took the line and cut the names ("spindle_9… done")
    bad = tmp_path / ("a_logger_export_with_a_long_name_" + "x" * 20 + ".csv")
    bad.write_text("time_s,speed_rpm,ambient_C,T1_C,T2_C,T3_C,T4_C\n0,9000,25,25,25,25,25\n")
    result = invoke("replay", str(bad), str(runs_dir / "hot_9000.csv"), "--out",
                    str(tmp_path / "out"), "--methods", "open_loop", "--snapshots", "none")
    assert result.exit_code == 2
    lines = result.output.splitlines()
    assert any(line.startswith("hot_9000 ") and " done" in line for line in lines), lines
    # the failed run is its error line alone (its row, cut, stood above it)
    told = [line for line in lines if bad.stem in line]
    assert len(told) == 1 and told[0].startswith(f"error: {bad}, line 1, column 'T5_C': "
                                                 "missing required column"), lines


def test_resume_skips_finished_runs_and_redoes_interrupted_ones(runs_dir, tmp_path):
    out = tmp_path / "out"
    runs = [runs_dir / "hot_9000.csv", runs_dir / "hot_12000.csv"]
    assert replay(*runs, out=out, methods="open_loop").exit_code == 0
    # an interrupted run: its done-token never got written
    (out / "hot_12000" / ".done.json").unlink()
    stamp = (out / "hot_9000" / "accuracy.json").stat().st_mtime_ns
    from twin.loop.batch import replay_batch

    seen = []
    result = replay_batch(
        runs,
        out,
        ["open_loop"],
        None,
        resume=True,
        progress=lambda n, s: seen.append((n, s)),
    )
    assert result.skipped == ["hot_9000"]
    assert ("hot_12000", "done") in seen
    assert (out / "hot_9000" / "accuracy.json").stat().st_mtime_ns == stamp
    assert [a["run"] for a in result.accuracies] == ["hot_9000", "hot_12000"]




def test_resume_replays_a_run_that_other_code_replayed(runs_dir, tmp_path, monkeypatch):
    """The resume token names the code: a folder whose token an earlier release wrote
    (input, methods and model only, as before 2026-11-27) or that code with other sources
    wrote is replayed again, not kept silently with results the methods no longer give;
    one the same code wrote is kept."""
    from twin.loop import runfiles
    from twin.loop.batch import replay_batch

    out = tmp_path / "out"
    run = runs_dir / "hot_9000.csv"
    assert replay(run, out=out, methods="open_loop").exit_code == 0
    done = out / "hot_9000" / ".done.json"
    token = json.loads(done.read_text())
    assert token["code"] == runfiles.code_identity()
    assert len(token["code"]["sources_sha256"]) == 64

    def resumed() -> list[str]:
        return replay_batch([run], out, ["open_loop"], None, resume=True).skipped

    assert resumed() == ["hot_9000"]
    # the token the code before this one wrote
    done.write_text(json.dumps({"input_sha256": token["input_sha256"],
                                "methods": ["open_loop"]}))
    assert resumed() == []
    assert json.loads(done.read_text()) == token  # written anew by this code
    # other sources, same version string
    other = {**token["code"], "sources_sha256": "0" * 64}
    monkeypatch.setattr(runfiles, "code_identity", lambda: other)
    assert resumed() == []
    assert json.loads(done.read_text())["code"] == other
    assert resumed() == ["hot_9000"]


def test_the_sources_digest_follows_the_bytes_not_the_place(tmp_path):
    from twin.version import sources_digest

    def package(where):  # noqa: ANN001, ANN202
        root = where / "twin"
        (root / "loop" / "__pycache__").mkdir(parents=True)
        (root / "data" / "meshes").mkdir(parents=True)
        (root / "__init__.py").write_text("")
        (root / "loop" / "replay.py").write_text("HOLD = True\n")
        (root / "loop" / "__pycache__" / "replay.cpython-311.pyc").write_bytes(b"\0")
        (root / "data" / "meshes" / "spindle.toml").write_text("[spindle]\n")
        (root / "data" / "runs.csv").write_text("time_s\n")
        return root

    a, b = package(tmp_path / "a"), package(tmp_path / "b")
    digest = sources_digest({"twin": a})
    assert digest == sources_digest({"twin": b})  # another install of the same code
    (b / "loop" / "__pycache__" / "replay.cpython-311.pyc").write_bytes(b"\1")
    (b / "data" / "runs.csv").write_text("time_s,x\n")  # no source, no mesh
    assert sources_digest({"twin": b}) == digest
    (b / "loop" / "replay.py").write_text("HOLD = False\n")
    assert sources_digest({"twin": b}) != digest
    (b / "loop" / "replay.py").write_text("HOLD = True\n")
    (b / "data" / "meshes" / "spindle.toml").write_text("[spindle]\nr = 1\n")
    assert sources_digest({"twin": b}) != digest
    (b / "data" / "meshes" / "spindle.toml").write_text("[spindle]\n")
    (b / "loop" / "replay.py").rename(b / "loop" / "other.py")  # a module's name counts
    assert sources_digest({"twin": b}) != digest


@pytest.mark.parametrize("before", ["none", "end"])
def test_resume_draws_the_snapshots_asked_for_from_the_skipped_runs_fields(runs_dir, tmp_path,
                                                                           before):
    # `--resume --snapshots every` after a `--snapshots none` batch skipped every run and
    # left it without a single picture; after an `end` batch it kept the end frame in its
    # own field's range beside frames in the run's
    from twin.loop.batch import replay_batch

    run = runs_dir / "hot_9000.csv"
    fresh = replay_batch([run], tmp_path / "fresh", ["open_loop"], None, snapshots="every")
    out = tmp_path / "out"
    replay_batch([run], out, ["open_loop"], None, snapshots=before)
    end = out / "hot_9000" / "snapshots" / f"open_loop_t{60 * MINUTES:05d}s.png"
    assert end.is_file() == (before == "end")
    assert not end.is_file() or end.read_bytes() != (
        tmp_path / "fresh" / "hot_9000" / "snapshots" / end.name).read_bytes()
    stamp = (out / "hot_9000" / "accuracy.json").stat().st_mtime_ns
    resumed = replay_batch([run], out, ["open_loop"], None, snapshots="every", resume=True)
    assert resumed.skipped == ["hot_9000"]
    assert (out / "hot_9000" / "accuracy.json").stat().st_mtime_ns == stamp  # not solved
    pictures = sorted(p.name for p in (out / "hot_9000" / "snapshots").iterdir())
    assert pictures == [f"open_loop_t{60 * k:05d}s.png" for k in range(1, MINUTES + 1)]
    for name in pictures:  # drawn from the field files: the pictures a replay draws
        assert ((out / "hot_9000" / "snapshots" / name).read_bytes()
                == (tmp_path / "fresh" / "hot_9000" / "snapshots" / name).read_bytes())
    assert fresh.accuracies == resumed.accuracies


@pytest.mark.parametrize("fields", ["every", "end"])
def test_resume_replays_a_run_whose_fields_cannot_give_the_snapshots(runs_dir, tmp_path,
                                                                     fields):
    # a damaged field file, or one `--fields end` never wrote
    from twin.loop.batch import replay_batch

    run = runs_dir / "hot_9000.csv"
    out = tmp_path / "out"
    replay_batch([run], out, ["open_loop"], None, snapshots="none", fields=fields)
    if fields == "every":
        (out / "hot_9000" / "fields" / "open_loop_t00300s.vtu").write_text("damaged")
    snapshots = "end" if fields == "every" else "every"
    resumed = replay_batch([run], out, ["open_loop"], None, snapshots=snapshots,
                           fields=fields, resume=True)
    assert resumed.skipped == [] and not resumed.failed
    pictures = sorted(p.name for p in (out / "hot_9000" / "snapshots").iterdir())
    assert pictures == [f"open_loop_t{60 * k:05d}s.png"
                        for k in range(1 if snapshots == "every" else MINUTES, MINUTES + 1)]


def test_resume_keeps_a_run_that_has_the_snapshots_asked_for_without_fields(runs_dir,
                                                                            tmp_path):
    from twin.loop.batch import replay_batch

    run = runs_dir / "hot_9000.csv"
    out = tmp_path / "out"
    replay_batch([run], out, ["open_loop"], None, snapshots="end", fields="none")
    resumed = replay_batch([run], out, ["open_loop"], None, snapshots="end", fields="none",
                           resume=True)
    assert resumed.skipped == ["hot_9000"]


@pytest.mark.parametrize("when", ["after a run", "as the workers start"])
def test_ctrl_c_stops_the_worker_processes_and_their_queued_runs(runs_dir, tmp_path, when,
                                                                 monkeypatch):
    # Ctrl-C in a --jobs batch: the pool was shut down waiting for every queued run, so the
    # batch went on replaying (and a worker caught between runs printed a traceback)
    import multiprocessing
    from contextlib import contextmanager

    import twin.loop.batch
    from twin.loop.batch import replay_batch

    runs = []
    for k in range(8):
        runs.append(tmp_path / f"run{k}.csv")
        shutil.copy(runs_dir / "hot_9000.csv", runs[-1])
    out = tmp_path / "out"

    def ctrl_c(name: str, status: str) -> None:
        raise KeyboardInterrupt

    @contextmanager
    def ctrl_c_held_back():  # a Ctrl-C held back while the workers were forked
        yield
        raise KeyboardInterrupt

    if when != "after a run":
        monkeypatch.setattr(twin.loop.batch, "held_interrupts", ctrl_c_held_back)
    with pytest.raises(KeyboardInterrupt):
        replay_batch(runs, out, ["open_loop"], None, jobs=2, progress=ctrl_c)
    assert multiprocessing.active_children() == []
    done = [p.name for p in out.iterdir() if (p / ".done.json").exists()]
    # the one told, and at most one per worker finishing then
    assert len(done) <= (3 if when == "after a run" else 0), done
    assert [p.name for p in out.iterdir() if p.name.startswith(".")] == []
    assert all(p.name in done for p in out.iterdir() if p.is_dir())

def _batch_clients(cluster, earlier: set) -> list[str]:  # noqa: ANN001 - a LocalCluster
    """The clients a batch left connected to the cluster's scheduler: those beside
    `earlier` but the workers' own (a run's stop `Event` opens one in its worker)."""
    return [c for c in cluster.scheduler.clients
            if c not in earlier and not c.startswith("Client-worker-")]


class _FakeClient:
    """Stands in for a connected dask client where a batch stops before it runs a job."""

    def __init__(self) -> None:
        self.closed = 0

    def close(self) -> None:
        self.closed += 1

    def __enter__(self) -> _FakeClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


@pytest.mark.parametrize("stop", ["out is a file", "ctrl-c while planning"])
def test_a_dask_batch_that_stops_before_its_runs_closes_its_client(runs_dir, tmp_path,
                                                                   monkeypatch, stop):
    # the client's lifetime was split: replay_batch closed it when the set-up failed,
    # _execute after the runs; one owner (`dask_session`) closes it once on every path
    import twin.loop.batch as batch

    client = _FakeClient()
    monkeypatch.setattr(batch, "dask_client", lambda address: client)
    out = tmp_path / "out"
    if stop == "out is a file":
        out.write_text("")
        expected: type[BaseException] = FileExistsError
    else:
        def interrupted(*args, **kwargs):  # noqa: ANN002, ANN003, ANN202
            raise KeyboardInterrupt

        monkeypatch.setattr(batch, "_finished", interrupted)
        expected = KeyboardInterrupt
    with pytest.raises(expected):
        batch.replay_batch([runs_dir / "hot_9000.csv"], out, ["open_loop"], None,
                           dask_address="tcp://127.0.0.1:8786", resume=True)
    assert client.closed == 1
    # nothing was replayed, so nothing was cleaned up (no lock file made)
    assert out.is_file() or sorted(p.name for p in out.iterdir()) == []


@pytest.mark.slow
def test_local_processes_and_dask_give_the_same_results(runs_dir, tmp_path):
    from dask.distributed import Client, LocalCluster

    runs = [runs_dir / "hot_9000.csv", runs_dir / "hot_12000.csv"]
    from twin.loop.batch import replay_batch

    seq = replay_batch(runs, tmp_path / "seq", ["ratio"], None, jobs=1)
    par = replay_batch(runs, tmp_path / "par", ["ratio"], None, jobs=2)
    with (
        LocalCluster(
            n_workers=1,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=None,
        ) as cluster,
        Client(cluster),
    ):
        clients = set(cluster.scheduler.clients)
        dsk = replay_batch(
            runs, tmp_path / "dask", ["ratio"], None, dask_address=cluster.scheduler_address
        )
        assert _batch_clients(cluster, clients) == []  # the batch closed its client
    assert not seq.failed and not par.failed and not dsk.failed
    # deterministic: the same inputs give the same numbers whichever way they ran
    assert seq.accuracies == par.accuracies == dsk.accuracies


@pytest.mark.slow
def test_ctrl_c_of_a_dask_batch_ends_the_runs_the_cluster_had_started(runs_dir, spindle_model,
                                                                       tmp_path):
    # a cluster runs a started task to its end whatever its client does: after a Ctrl-C of
    # `twin replay --dask`, the runs the workers were on appeared in --out seconds later,
    # missing from the summary the stopped batch had written
    from dask.distributed import Client, LocalCluster

    from twin.loop.batch import replay_batch

    short = tmp_path / "short.csv"
    make_recorded_run(short, spindle_model, minutes=2)
    runs = [short] + [tmp_path / f"long{k}.csv" for k in range(2)]
    for run in runs[1:]:
        make_recorded_run(run, spindle_model, minutes=30)
    out = tmp_path / "out"

    reported = []

    def ctrl_c(name: str, status: str) -> None:
        # the first run done (the short one, unless a loaded machine started its worker
        # late): the long one next to it is still running
        reported.append(name)
        raise KeyboardInterrupt

    with (
        LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                     dashboard_address=None) as cluster,
        Client(cluster) as client,
    ):
        clients = set(cluster.scheduler.clients)
        with pytest.raises(KeyboardInterrupt):
            replay_batch(runs, out, ["open_loop", "ratio"], None, fields="none",
                         dask_address=cluster.scheduler_address, progress=ctrl_c)
        assert _batch_clients(cluster, clients) == []
        deadline = time.monotonic() + 60
        while any(client.processing().values()) and time.monotonic() < deadline:
            time.sleep(0.2)
        assert not any(client.processing().values())
    time.sleep(0.5)  # the stopped task's staging folder is removed as it unwinds
    assert len(reported) == 1
    assert sorted(p.name for p in out.iterdir() if p.is_dir()) == reported
    assert [p.name for p in out.iterdir() if p.name.startswith(".")] == []


def test_report_rebuilds_from_a_folder(replayed):
    (replayed / "report.html").unlink()
    result = invoke("report", str(replayed))
    assert result.exit_code == 0
    assert "Table" not in result.output
    assert (replayed / "report.html").stat().st_size > 10_000


def test_cli_bad_input_is_exit_2_with_the_field(runs_dir, tmp_path):
    result = invoke(
        "replay",
        str(runs_dir / "hot_9000.csv"),
        "--out",
        str(tmp_path),
        "--methods",
        "open_loop,magic",
    )
    assert result.exit_code == 2 and "--methods" in result.output and "magic" in result.output
    result = invoke(
        "snapshot",
        str(runs_dir / "hot_9000.csv"),
        "--time",
        "99999",
        "--out",
        str(tmp_path / "x.png"),
        "--method",
        "ratio",
    )
    assert result.exit_code == 2 and "--time" in result.output
    result = invoke("report", str(tmp_path / "nothing"))
    assert result.exit_code == 2


def test_a_replays_window_decks_run_alone_on_the_spindle(replayed, tmp_path):
    # `apdl-like run decks/window_000.inp` stopped at its first line (no contact real set
    # 101: the decks hold loads only) and nothing said how to run them
    import meshio

    from apdl_like.cli import app as apdl_app

    run_dir = replayed / "hot_9000"
    decks = shutil.copytree(run_dir / "decks", tmp_path / "decks")
    fields = sorted((run_dir / "fields").glob("ratio_t*.vtu"))

    def run_deck(deck, out):
        return CliRunner().invoke(apdl_app, ["run", str(deck), "--spindle", "--out", str(out),
                                             "--quiet"])

    def temperature(vtu, name):
        return meshio.read(vtu).point_data[name]

    result = run_deck(decks / "window_000.inp", tmp_path / "w0")
    assert result.exit_code == 0, result.output
    # 15 load steps of 4 s (the loads follow the twin's rings): the last is the window end
    np.testing.assert_array_equal(temperature(tmp_path / "w0" / "result_015.vtu", "TEMP"),
                                  temperature(fields[0], "temperature_C"))
    # later windows restart from the field the run carried: run in order, they give it
    (decks / "chain.inp").write_text("".join(f"/INPUT,window_{k:03d},inp\n" for k in range(3)))
    result = run_deck(decks / "chain.inp", tmp_path / "chain")
    assert result.exit_code == 0, result.output
    np.testing.assert_array_equal(temperature(tmp_path / "chain" / "result_045.vtu", "TEMP"),
                                  temperature(fields[2], "temperature_C"))
    alone = run_deck(decks / "window_001.inp", tmp_path / "w1")
    assert alone.exit_code == 2 and "no previous solution" in alone.output


def test_report_names_an_unreadable_run_folder_and_exits_2(replayed, tmp_path):
    # it wrote the report without that run, said only "wrote report.html" and exited 0
    folder = shutil.copytree(replayed, tmp_path / "replay")
    accuracy = folder / "hot_9000" / "accuracy.json"
    accuracy.write_text('{"run": "hot_9000", "methods": {')  # cut short
    result = invoke("report", str(folder))
    assert result.exit_code == 2, result.output
    assert f"error: {accuracy}: unreadable accuracy.json" in result.output
    assert (folder / "report.html").is_file()
    summary = json.loads((folder / "summary.json").read_text())
    assert [f["run"] for f in summary["failed"]] == ["hot_9000"]



@pytest.mark.parametrize(("file", "text", "message"), [
    ("keypoints.csv", "time_s,method,T1_twin_C\n0,ratio,20\nabc,ratio,21\n",
     "keypoints.csv, line 3, column 'time_s': 'abc' is not a number"),
    ("keypoints.csv", "a,b\n1,2\n", "keypoints.csv, column 'method': column missing"),
    ("keypoints.csv", b"\xfa\xfb,\xfc\n", "keypoints.csv: cannot be read"),
    ("corrections.csv", "window,method\nx,ratio\n",
     "corrections.csv, line 2, column 'window': 'x' is not a number"),
    ("corrections.csv", None, "corrections.csv: cannot be read (replay the run again): No such"),
])
def test_report_names_a_damaged_run_file_it_draws_from(replayed, tmp_path, file, text,
                                                       message):
    # a run folder whose figures the report draws again (plots/ gone) with a damaged
    # keypoints.csv or corrections.csv was an internal error (ValueError, KeyError, ...);
    # then it stopped with summary.json rewritten and the old report.html beside it
    folder = shutil.copytree(replayed, tmp_path / "replay")
    (folder / "summary.json").write_text('{"runs": [], "failed": []}')
    (folder / "report.html").write_text("the earlier report")
    run_dir = folder / "hot_9000"
    shutil.rmtree(run_dir / "plots")
    if text is None:
        (run_dir / file).unlink()
    elif isinstance(text, bytes):
        (run_dir / file).write_bytes(text)
    else:
        (run_dir / file).write_text(text)
    result = invoke("report", str(folder))
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {run_dir}/{message}"), lines
    assert (folder / "summary.json").read_text() == '{"runs": [], "failed": []}'
    assert (folder / "report.html").read_text() == "the earlier report"


def test_report_draws_again_a_run_a_batch_swapped_in_meanwhile(replayed, tmp_path,
                                                               monkeypatch):
    # the page is drawn outside the folder's lock (it takes seconds); a run another batch
    # put in meanwhile must be in both files, which are written together under the lock
    import twin.loop.report

    folder = shutil.copytree(replayed, tmp_path / "replay")
    shutil.move(folder / "hot_9000", tmp_path / "hot_9000")
    (folder / "other").mkdir()  # keeps it a replay folder with a run in it
    shutil.copy(replayed / "hot_9000" / "accuracy.json", folder / "other")
    drawn = []
    page = twin.loop.report._page

    def draw(out_root, summary):  # noqa: ANN001, ANN202
        drawn.append([r["run"] for r in summary["runs"]])
        if len(drawn) == 1:
            shutil.move(tmp_path / "hot_9000", folder / "hot_9000")
        return page(out_root, summary)

    monkeypatch.setattr(twin.loop.report, "_page", draw)
    twin.loop.report.build_report(folder)
    assert len(drawn) == 2 and "hot_9000" not in drawn[0] and "hot_9000" in drawn[1]
    summary = json.loads((folder / "summary.json").read_text())
    assert "hot_9000" in [r["run"] for r in summary["runs"]]
    assert "hot_9000" in (folder / "report.html").read_text()


@pytest.mark.parametrize("quality", ['"stuck sensor T2"', "42"])
def test_report_shows_a_hand_edited_quality_file_as_it_is(replayed, tmp_path, quality):
    # a quality.json holding a text or a number: internal error (AttributeError)
    folder = shutil.copytree(replayed, tmp_path / "replay")
    (folder / "hot_9000" / "quality.json").write_text(quality)
    result = invoke("report", str(folder))
    assert result.exit_code == 0, result.output
    assert quality.strip('"') in (folder / "report.html").read_text()


def test_report_passes_over_a_folder_among_the_snapshots(replayed, tmp_path):
    # snapshots/old.png being a folder: internal error (IsADirectoryError)
    folder = shutil.copytree(replayed, tmp_path / "replay")
    (folder / "hot_9000" / "snapshots" / "zz.png").mkdir()
    result = invoke("report", str(folder))
    assert result.exit_code == 0, result.output
    assert 'alt="temperature field of ratio at t = 300 s (5.0 min)"' in (
        folder / "report.html").read_text()

def test_a_runs_files_all_know_it_by_its_file_name(runs_dir, tmp_path):
    # quality.json (and the snapshots' titles) took the run's `# name:` line while
    # accuracy.json, summary.json and the folder took the file name
    run = tmp_path / "monday.csv"
    run.write_text("# name: machine 3\n" + (runs_dir / "hot_9000.csv").read_text())
    out = tmp_path / "out"
    assert replay(run, out=out, methods="open_loop").exit_code == 0
    quality = json.loads((out / "monday" / "quality.json").read_text())
    accuracy = json.loads((out / "monday" / "accuracy.json").read_text())
    assert quality["run"] == accuracy["run"] == "monday"


def test_an_unreadable_run_is_named_and_the_batch_goes_on(runs_dir, tmp_path, monkeypatch):
    # as root, chmod 000 does not stop a read: the permission error is raised here instead
    from pathlib import Path

    locked = tmp_path / "locked.csv"
    locked.write_bytes((runs_dir / "hot_9000.csv").read_bytes())
    read_bytes = Path.read_bytes

    def refuse_locked(path):
        if path == locked:
            raise PermissionError(13, "Permission denied", str(path))
        return read_bytes(path)

    monkeypatch.setattr(Path, "read_bytes", refuse_locked)
    out = tmp_path / "out"
    result = replay(locked, runs_dir / "hot_9000.csv", out=out, methods="open_loop")
    assert result.exit_code == 2, result.output
    assert f"{locked}: cannot read file: Permission denied" in result.output
    summary = json.loads((out / "summary.json").read_text())
    assert [f["run"] for f in summary["failed"]] == ["locked"]
    assert [r["run"] for r in summary["runs"]] == ["hot_9000"]


def test_snapshot_tells_a_time_outside_the_run_from_an_internal_error(runs_dir, tmp_path,
                                                                       monkeypatch):
    # every ValueError of the replay was reported as bad input naming --time (exit 2)
    from twin.loop import replay as loop_replay

    out = tmp_path / "t.png"
    args = ("snapshot", str(runs_dir / "hot_9000.csv"), "--out", str(out), "--method",
            "open_loop", "--time")
    late = CliRunner().invoke(app, [*args, "400"])
    assert late.exit_code == 2, late.output
    assert "option '--time'" in late.output and "(0, 300] s" in late.output

    def broken(*args, **kwargs):
        raise ValueError("a window at t = 0 starts from a uniform temperature (TUNIF)")

    monkeypatch.setattr(loop_replay, "replay_method", broken)
    inside = CliRunner().invoke(app, [*args, "120"])
    assert inside.exit_code == 1, inside.output
    assert "internal error: ValueError" in inside.output and "--time" not in inside.output
    assert not out.exists()


def test_open_loop_replay_of_the_twins_own_simulation_reproduces_it(tmp_path, spindle_model):
    """`twin simulate`'s output replayed with `open_loop` is the same twin, model and nominal
    loads: it must come back.  With each window's loads held at the window start's ring
    temperatures (the paper's literal per-window values) a cold start at 13 500 rpm kept
    the cold oil's Palmgren heat for 60 s and T1 ran 5.0 K warm by 60 s (T3 3.7 K); the
    loads follow the rings every step, as in `simulate`: the same to the last digit."""
    import dataclasses

    from twin.correction.methods import OpenLoop
    from twin.loop.replay import replay_method
    from twin.runs import read_run
    from twin.spindle.simulate import simulate

    sim = simulate(spindle_model, 13500.0, 5.0, 22.0)
    columns = {k: v for k, v in sim.keypoints().items() if k != "disp_r_um"}
    columns.update(speed_rpm=np.full(sim.time_s.size, 13500.0),
                   ambient_C=np.full(sim.time_s.size, 22.0))
    write_run(tmp_path / "sim.csv", columns)
    run = read_run(tmp_path / "sim.csv")
    replay = replay_method(run, spindle_model, OpenLoop(), keep_fields=False)
    measured = sim.sensors_C[1:]
    assert np.abs(replay.T_twin_C - measured).max() < 1e-9
    assert np.abs(replay.drift_z_um - sim.disp_z_um[1:]).max() < 1e-9
    held = replay_method(run, spindle_model, dataclasses.replace(OpenLoop(),
                                                                  loads_follow_rings=False),
                         keep_fields=False)
    assert np.abs(held.T_twin_C - measured).max() > 1.0


def test_snapshot_png_with_an_upper_case_suffix(spindle_model, tmp_path):
    # twin snapshot takes --out S.PNG (its check is case-blind) but pyvista picks the
    # format from the suffix as written: 'internal error: Unsupported extension .PNG'
    from PIL import Image

    from twin.loop.snapshot import render_snapshot

    out = tmp_path / "S.PNG"
    T = np.linspace(25.0, 40.0, spindle_model.n_dofs)
    render_snapshot(spindle_model, T, out, section=True, window_size=(300, 200))
    assert Image.open(out).format == "PNG"
    assert [p.name for p in tmp_path.iterdir()] == ["S.PNG"]  # no temporary file left


def test_a_dead_thermocouple_is_left_out_as_a_stuck_one_is(tmp_path, spindle_model):
    """A thermocouple column with no value in the whole run (a dead channel) is excluded
    like a sensor frozen from the start: every method's outputs are the stuck run's, byte
    for byte, and the run is no longer refused (it was: "column has no values")."""

    def frozen(t, temps):
        temps[:, 1] = temps[0, 1]

    def dead(t, temps):
        temps[:, 1] = np.nan

    make_recorded_run(tmp_path / "stuck.csv", spindle_model, edit=frozen)
    make_recorded_run(tmp_path / "dead.csv", spindle_model, edit=dead)
    methods = "open_loop,ratio,bpnn,estimator"
    result = replay(tmp_path / "stuck.csv", tmp_path / "dead.csv", out=tmp_path / "out",
                    methods=methods)
    assert result.exit_code == 0, result.output
    out = {name: tmp_path / "out" / name for name in ("stuck", "dead")}
    kinds = {name: {(f["column"], f["kind"]) for f in
                    json.loads((d / "quality.json").read_text())["findings"]}
             for name, d in out.items()}
    assert ("T2_C", "stuck") in kinds["stuck"] and ("T2_C", "dead") in kinds["dead"]
    for name in ("keypoints.csv", "corrections.csv"):
        assert (out["dead"] / name).read_bytes() == (out["stuck"] / name).read_bytes(), name
    acc = {n: json.loads((d / "accuracy.json").read_text())["methods"] for n, d in out.items()}
    assert acc["dead"] == acc["stuck"]
    assert all(m["rmse_C"]["T2"] is None for m in acc["dead"].values())
    # the report tells both findings as table rows, not JSON text
    page = (tmp_path / "out" / "report.html").read_text()
    for kind in ("dead", "stuck"):
        assert f"<td>T2_C</td><td>{kind}</td><td>76</td><td>0–300</td>" in page, kind
    assert "&#34;" not in page


def test_a_snapshots_marker_names_the_shown_fields_largest_value():
    from twin.loop.snapshot import field_marker

    values = np.array([3.0, 96.42, 12.0])
    assert field_marker("displacement", values) == (1, "max 96.4 µm")
    assert field_marker("temperature", np.array([25.0, 50.83, 40.0])) == (1, "max 50.8 °C")


def test_a_logger_gap_holds_ratio_and_bpnn_and_quality_json_says_which_windows(
        tmp_path, spindle_model, replayed):
    """Every thermocouple lost from 120 to 250 s (the quality check excludes the fill):
    windows 3 and 4 read nothing measured, so ratio and bpnn keep window 2's factors and
    quality.json names the windows per ring and sleeve sensor; a run without a gap has no
    such finding."""
    from twin.correction.methods import make_corrector
    from twin.data import bundled_path
    from twin.loop.findings import HELD_CORRECTION
    from twin.loop.replay import replay_method
    from twin.runs import read_run

    def gap(t, temps):
        temps[(t > 120) & (t < 250)] = np.nan

    path = make_recorded_run(tmp_path / "gap.csv", spindle_model, minutes=6, edit=gap)
    result = replay(path, out=tmp_path / "out", methods="open_loop,ratio")
    assert result.exit_code == 0, result.output
    findings = json.loads((tmp_path / "out" / "gap" / "quality.json").read_text())["findings"]
    held = {f["column"]: f for f in findings if f["kind"] == HELD_CORRECTION}
    assert sorted(held) == ["T1_C", "T2_C", "T3_C", "T4_C"]
    # two windows, told as windows: every other finding's `count` is of samples
    assert all(f["spans_s"] == [[180.0, 300.0]] and f["count_windows"] == 2
               and "count" not in f for f in held.values())
    assert all("count" in f for f in findings if f["kind"] != HELD_CORRECTION)
    assert "window 3-4" in held["T1_C"]["detail"]
    # the methods that held, and only those
    assert held["T1_C"]["action"] == ("ratio computes nothing from this sensor in these "
                                      "windows and holds what it corrects")
    assert "<td>T1_C</td><td>correction_held</td><td>2 windows</td><td>180–300</td>" in \
        (tmp_path / "out" / "report.html").read_text()
    # no method that holds a correction ran: nothing was held
    result = replay(path, out=tmp_path / "none", methods="open_loop,estimator")
    assert result.exit_code == 0, result.output
    findings = json.loads((tmp_path / "none" / "gap" / "quality.json").read_text())["findings"]
    assert [f for f in findings if f["kind"] == HELD_CORRECTION] == []
    assert {f["kind"] for f in findings} == {
        f["kind"] for f in json.loads((tmp_path / "out" / "gap" / "quality.json")
                                      .read_text())["findings"]} - {HELD_CORRECTION}
    clean = json.loads((replayed / "hot_9000" / "quality.json").read_text())["findings"]
    assert not [f for f in clean if f["kind"] == HELD_CORRECTION]

    run = read_run(path)
    for method in ("ratio", "bpnn"):
        model = bundled_path("correction_model.safetensors") if method == "bpnn" else None
        r = replay_method(run, spindle_model, make_corrector(method, model), keep_fields=False)
        factors = [np.array(w.correction.values) / np.array(w.nominal) for w in r.windows]
        assert factors[3] == pytest.approx(factors[2], rel=1e-12), method
        assert factors[4] == pytest.approx(factors[2], rel=1e-12), method
        assert factors[5] != pytest.approx(factors[2], rel=1e-6), method  # read again


def test_a_run_tells_its_progress_window_by_window(runs_dir, tmp_path):
    # a replay told nothing until its run was done: a 4-h run stood at 0:00:00 for a minute
    # (the windows' callback turned the fork off, so the CLI never passed one)
    from twin.loop.batch import replay_batch

    told = []
    result = replay_batch([runs_dir / "hot_9000.csv"], tmp_path / "out",
                          ["open_loop", "ratio"], None,
                          on_window=lambda *args: told.append(args))
    assert result.failed == []
    # where it may fork, the primary (ratio) is replayed by a forked child meanwhile, as
    # without a callback, and this process tells its own windows only
    total = told[-1][3]
    assert total in (MINUTES, 2 * MINUTES)
    methods = ["open_loop"] * MINUTES + ["ratio"] * (total - MINUTES)
    assert told == [("hot_9000", m, k, total) for k, m in enumerate(methods, start=1)]


def test_the_progress_bar_moves_before_the_run_is_done(runs_dir, tmp_path, monkeypatch):
    from rich.progress import Progress

    statuses = []
    update = Progress.update

    def recorded(self, task, **kw):  # noqa: ANN001, ANN003, ANN202
        statuses.append((kw.get("completed"), kw.get("status")))
        return update(self, task, **kw)

    monkeypatch.setattr(Progress, "update", recorded)
    result = invoke("replay", str(runs_dir / "hot_9000.csv"), "--out", str(tmp_path / "out"),
                    "--methods", "open_loop,ratio", "--snapshots", "none")
    assert result.exit_code == 0, result.output
    assert statuses[-1] == (1, "done")
    moving = statuses[:-1]
    assert moving and moving[-1][0] == 1
    assert [c for c, _ in moving] == sorted({c for c, _ in moving})  # forward, each once
    assert moving[0] in ((1 / MINUTES, f"{100 // MINUTES} % (open_loop)"),  # forked
                         (0.5 / MINUTES, f"{50 // MINUTES} % (open_loop)"))  # alone


def test_the_report_says_its_speed_and_ambient_are_a_runs_means(replayed):
    # a 6000/9000/12000 rpm run showed as "9003 rpm" under "speed [rpm]"
    page = (replayed / "report.html").read_text()
    assert "<th rowspan=2>mean speed [rpm]</th><th rowspan=2>mean ambient [°C]</th>" in page
    assert "mean 9000 rpm, mean ambient 25.00 °C, 5.0 min" in page


def test_the_report_page_links_only_what_exists_and_needs_no_network(replayed, tmp_path):
    """Every link of report.html resolves: in-page anchors to a heading, file links to a
    run's files beside the page; every image is embedded; nothing is fetched from another
    host (the page is read offline, mailed, archived).  The run's caption gives its speeds
    and the snapshot says what it shows."""
    import re
    from urllib.parse import unquote

    folder = shutil.copytree(replayed, tmp_path / "replay")
    shutil.rmtree(folder / "hot_9000" / "decks")  # a link to it must go with it
    assert invoke("report", str(folder)).exit_code == 0
    page = (folder / "report.html").read_text()
    assert not re.search(r"""(?:src|href)\s*=\s*["']?(?:https?:)?//""", page), "external"
    assert "@import" not in page and "url(" not in page
    srcs = re.findall(r'<img [^>]*src="([^"]*)"', page)
    assert srcs and all(s.startswith("data:image/png;base64,") for s in srcs)
    assert all(re.search(r'alt="[^"]+"', tag) for tag in re.findall(r"<img [^>]*>", page))
    ids = set(re.findall(r'id="([^"]+)"', page))
    hrefs = re.findall(r'href="([^"]+)"', page)
    files = [h for h in hrefs if not h.startswith("#")]
    assert {h[1:] for h in hrefs if h.startswith("#")} == ids == {"run-1"}
    assert sorted(files) == sorted(f"hot_9000/{n}" for n in (
        "keypoints.csv", "corrections.csv", "accuracy.json", "quality.json", "fields.pvd"))
    assert all((folder / unquote(h)).exists() for h in files)
    assert "; speed 9000 rpm</p>" in page
    assert "<figcaption>temperature field of ratio at t = 300 s (5.0 min)</figcaption>" in page


def test_the_mean_line_says_over_how_many_runs_a_method_is_averaged(runs_dir, tmp_path):
    # a folder holding one run replayed with open_loop and another with open_loop and
    # ratio printed both means side by side, one over two runs and one over one
    out = tmp_path / "out"
    assert replay(runs_dir / "hot_9000.csv", out=out, methods="open_loop").exit_code == 0
    result = invoke("replay", str(runs_dir / "hot_12000.csv"), "--out", str(out),
                    "--methods", "open_loop,ratio", "--snapshots", "none")
    assert result.exit_code == 0, result.output
    line = " ".join(result.output.split())  # rich wraps it
    assert "mean accuracy — open_loop: T " in line and "open_loop (" not in line
    assert "; ratio (1 of 2 runs): T " in line, line


def test_the_report_leaves_a_gap_in_c_h_at_a_stop():
    # C_H is on the previous heat carried to this window's nominal level: the fallback 1
    # at a stop, no correction; the window after it compares with the factor from before
    # the stop.  (On the previous heat itself it was 0 at a stop, and the report drew the
    # line down to 0 at every stop, "the correction went to zero".)
    from pathlib import Path

    from twin.loop.report import _Columns, _running_factor

    corr = _Columns(Path("corrections.csv"), {
        "H_front": ["1e6", "1.1e6", "0", "0", "9e5", "1e6"],
        "C_H_front": ["1", "1.1", "1", "1", "0.98", "1.11"],
        "C_C_front": ["1", "0.9", "1", "1", "1", "1.2"],
    })
    sel = np.ones(6, dtype=bool)
    np.testing.assert_array_equal(_running_factor(corr, "C_H_front", sel),
                                  [1, 1.1, np.nan, np.nan, 0.98, 1.11])
    np.testing.assert_array_equal(_running_factor(corr, "C_C_front", sel),
                                  [1, 0.9, 1, 1, 1, 1.2])


def test_quality_json_names_the_tail_after_the_last_whole_window(runs_dir, replayed, tmp_path):
    """A replay solves and scores whole 60 s windows: a 152 s run was replayed and scored
    over 120 s, and neither quality.json nor the report said its last 32 s were left."""
    from twin.loop.findings import NOT_REPLAYED

    lines = (runs_dir / "hot_9000.csv").read_text().splitlines()
    header = next(k for k, line in enumerate(lines) if line.startswith("time_s"))
    kept = [line for line in lines[header + 1:] if float(line.split(",")[0]) <= 152.0]
    short = tmp_path / "short.csv"
    short.write_text("\n".join(lines[:header + 1] + kept) + "\n")
    assert replay(short, out=tmp_path / "out", methods="open_loop").exit_code == 0
    quality = json.loads((tmp_path / "out" / "short" / "quality.json").read_text())
    tail = [f for f in quality["findings"] if f["kind"] == NOT_REPLAYED]
    first = next(k for k, line in enumerate(kept) if float(line.split(",")[0]) > 120.0)
    assert tail == [{
        "column": "time_s", "kind": NOT_REPLAYED, "count": len(kept) - first,
        "rows": [header + 2 + first],  # its line in the file
        "spans_s": [[120.0, 152.0]],
        "action": "not replayed and not scored: a replay solves whole 60 s windows",
        "detail": "the 32 s after the last whole window (ends at 120 s)"}]
    assert float(lines[header + 1 + first].split(",")[0]) > 120.0
    assert float(lines[header + first].split(",")[0]) <= 120.0
    keypoints = (tmp_path / "out" / "short" / "keypoints.csv").read_text().splitlines()
    assert float(keypoints[-1].split(",")[0]) == 120.0  # what the finding says
    # a run of whole windows has no such finding
    whole = json.loads((replayed / "hot_9000" / "quality.json").read_text())["findings"]
    assert not [f for f in whole if f["kind"] == NOT_REPLAYED]


def test_quality_json_tells_a_run_that_warms_far_more_than_the_twin_at_its_speeds(
        runs_dir, replayed, tmp_path):
    """A speed logged in rev/s (150 for 9000 rpm) was replayed as 150 rpm, with next to no
    bearing heat: every method scored far off and nothing said why.  Told now (the
    thermocouples rise many times more than open loop's twin), and the speeds are still
    replayed as recorded; the same run in rpm tells nothing."""
    from twin.loop.findings import WARMS_UNLIKE_TWIN

    lines = (runs_dir / "hot_9000.csv").read_text().splitlines()
    header = next(k for k, line in enumerate(lines) if line.startswith("time_s"))
    speed = lines[header].split(",").index("speed_rpm")

    def in_rev_per_s(line: str) -> str:
        cells = line.split(",")
        cells[speed] = f"{float(cells[speed]) / 60.0:g}"
        return ",".join(cells)

    rps = tmp_path / "rps.csv"
    rps.write_text("\n".join(lines[:header + 1] + [in_rev_per_s(line)
                                                   for line in lines[header + 1:] if line])
                   + "\n")
    assert replay(rps, out=tmp_path / "out", methods="open_loop").exit_code == 0
    findings = json.loads((tmp_path / "out" / "rps" / "quality.json").read_text())["findings"]
    told = [f for f in findings if f["kind"] == WARMS_UNLIKE_TWIN]
    assert [(f["column"], f["action"]) for f in told] == [
        ("speed_rpm", "scored as recorded: every method replays the speeds as recorded")]
    assert told[0]["detail"].endswith("speed_rpm in rpm? (a speed in rev/s reads 60 times, "
                                      "one in krpm 1000 times too slow)")
    whole = json.loads((replayed / "hot_9000" / "quality.json").read_text())["findings"]
    assert not [f for f in whole if f["kind"] == WARMS_UNLIKE_TWIN]


def test_warming_is_told_only_many_times_above_the_twin_and_with_open_loop():
    """The rule's edges on key points alone: three times the twin's rise and 3 K told,
    just under either not; a run that starts warm (rising less than the twin) not; no
    open loop, nothing; a dead ring sensor leaves the others' median."""
    from twin.loop.findings import warming_findings

    steps = np.linspace(0.0, 1.0, 50)[:, None]
    start = np.full(5, 20.0)

    def told(measured_rise: float, twin_rise: float, dead: bool = False) -> bool:
        measured = 20.0 + measured_rise * steps * np.ones(5)
        if dead:
            measured[:, 0] = np.nan
        twin = 20.0 + twin_rise * steps * np.ones(5)
        return warming_findings(twin, np.full(5, 20.0), measured, start) != []

    assert told(6.0, 2.0) and not told(5.9, 2.0)
    assert told(3.0, 0.5) and not told(2.9, 0.5)
    assert not told(1.0, 9.0)  # started warm: rises less, not told
    assert told(6.0, 2.0, dead=True)
    assert warming_findings(None, np.full(5, 20.0), 20.0 + 9.0 * steps * np.ones(5), start) == []


def test_quality_json_tells_an_axial_probe_not_zeroed_at_the_start(runs_dir, replayed,
                                                                   tmp_path):
    """The twin's drift starts at 0 µm with the run; a probe zeroed elsewhere (50 µm off)
    was scored as recorded, deformation accuracy some 15 %, without a word of the cause."""
    from twin.loop.findings import PROBE_NOT_ZEROED

    lines = (runs_dir / "hot_9000.csv").read_text().splitlines()
    header = next(k for k, line in enumerate(lines) if line.startswith("time_s"))
    column = lines[header].split(",").index("disp_z_um")

    def shifted(by: float) -> list[str]:
        out = []
        for line in lines[header + 1:]:
            cells = line.split(",")
            cells[column] = f"{float(cells[column]) + by:.4f}"
            out.append(",".join(cells))
        return lines[:header + 1] + out

    off = tmp_path / "off.csv"
    off.write_text("\n".join(shifted(50.0)) + "\n")
    assert replay(off, out=tmp_path / "out", methods="open_loop").exit_code == 0
    quality = json.loads((tmp_path / "out" / "off" / "quality.json").read_text())
    told = [f for f in quality["findings"] if f["kind"] == PROBE_NOT_ZEROED]
    first = float(lines[header + 1].split(",")[column]) + 50.0
    assert told == [{
        "column": "disp_z_um", "kind": PROBE_NOT_ZEROED, "count": 1,
        "rows": [header + 2], "spans_s": [],
        "action": "scored as recorded: the twin's drift starts at 0 µm at the run start; "
                  "zero the probe there (or subtract its first reading). The estimator "
                  "reads the change from that reading",
        "detail": f"reads {first:.3g} µm at the start, more than 2 µm from 0"}]
    # a probe a little off (noise) is nothing to tell; nor is one zeroed at the start
    near = tmp_path / "near.csv"
    near.write_text("\n".join(shifted(1.5)) + "\n")
    assert replay(near, out=tmp_path / "out", methods="open_loop").exit_code == 0
    quality = json.loads((tmp_path / "out" / "near" / "quality.json").read_text())
    assert not [f for f in quality["findings"] if f["kind"] == PROBE_NOT_ZEROED]
    whole = json.loads((replayed / "hot_9000" / "quality.json").read_text())["findings"]
    assert not [f for f in whole if f["kind"] == PROBE_NOT_ZEROED]


def test_a_run_whose_first_thermocouple_and_probe_cells_are_empty_replays_from_its_readings(
        runs_dir, tmp_path):
    """A logger whose first row lacks T1 and the probe (empty cells): the replay runs every
    method (exit 0) and quality.json tells those samples as missing before the first
    reading, excluded, not as interpolated; the start is the spindle at rest, found from
    T2..T5; the probe's start reading, 50 µm off zero, is its first real one, 4 s in.  The
    missing samples held the next ones' values as if read at the start: T1 4 s warmer
    than the others made the cold start a fitted warm one (`warm_start`)."""
    lines = (runs_dir / "hot_9000.csv").read_text().splitlines()
    header = next(k for k, line in enumerate(lines) if line.startswith("time_s"))
    names = lines[header].split(",")
    rows = [line.split(",") for line in lines[header + 1:]]
    probe = names.index("disp_z_um")
    for cells in rows:
        cells[probe] = f"{float(cells[probe]) + 50.0:.4f}"
    for name in ("T1_C", "disp_z_um"):
        rows[0][names.index(name)] = ""
    run = tmp_path / "late.csv"
    run.write_text("\n".join(lines[:header + 1] + [",".join(c) for c in rows]) + "\n")
    result = replay(run, out=tmp_path / "out", methods="open_loop,ratio,bpnn,estimator")
    assert result.exit_code == 0, result.output
    found = json.loads((tmp_path / "out" / "late" / "quality.json").read_text())["findings"]
    assert [(f["column"], f["kind"], f["rows"], f["action"]) for f in found
            if f["column"] in ("T1_C", "disp_z_um") and f["kind"] != "probe_not_zeroed"] == [
        (name, "leading_dropout", [header + 2],
         "held at the first reading for continuity; excluded from metrics")
        for name in ("T1_C", "disp_z_um")]
    # T1 at 4 s read as the first reading spread T1..T5 over 2 K: a cold start fitted warm
    assert not [f for f in found if f["kind"] == "warm_start"], found
    told = [f for f in found if f["kind"] == "probe_not_zeroed"]
    assert len(told) == 1 and told[0]["rows"] == [header + 3], told
    assert told[0]["detail"].startswith(f"reads {float(rows[1][probe]):.3g} µm at 4 s")
    accuracy = json.loads((tmp_path / "out" / "late" / "accuracy.json").read_text())
    for metrics in accuracy["methods"].values():
        assert 95.0 < metrics["temperature_accuracy_pct"] <= 100.0, accuracy


def test_the_estimator_reads_a_probe_not_zeroed_at_the_start_from_its_first_reading(
        runs_dir, spindle_model, tmp_path):
    """Assimilated as recorded, a probe 50 µm off at the start (the twin's drift starts at
    0 there) pulled the estimator's temperatures from 99.86 to 96.80 % on a bundled run;
    it now reads the probe's change from its first reading, and its temperatures are
    those of the same run zeroed (to the first reading's noise), the score still as
    recorded."""
    from twin.correction.methods import make_corrector
    from twin.loop.replay import replay_method
    from twin.loop.runfiles import measured_reference, method_accuracy
    from twin.runs import read_run

    zeroed = read_run(runs_dir / "hot_9000.csv")
    columns = {"time_s": zeroed.time_s, "speed_rpm": zeroed.speed_rpm,
               "ambient_C": zeroed.ambient_C,
               **{f"T{i + 1}_C": zeroed.T_C[:, i] for i in range(5)},
               "disp_z_um": zeroed.disp_um[:, 2] - zeroed.disp_um[0, 2] + 50.0}
    write_run(tmp_path / "off.csv", columns, {"source": "test: probe zeroed elsewhere"})
    scores = {}
    for name, run in (("zeroed", zeroed), ("off", read_run(tmp_path / "off.csv"))):
        result = replay_method(run, spindle_model,
                               make_corrector("estimator", spindle=spindle_model),
                               keep_fields=False)
        scores[name] = (result, method_accuracy(result,
                                                *measured_reference(run, result.time_s)))
    (zeroed_result, zeroed_score), (off_result, off_score) = scores["zeroed"], scores["off"]
    assert np.max(np.abs(off_result.T_twin_C - zeroed_result.T_twin_C)) < 0.05
    assert abs(off_score["temperature_accuracy_pct"]
               - zeroed_score["temperature_accuracy_pct"]) < 0.02
    assert off_score["deformation_accuracy_pct"] < 50.0  # scored as recorded


def test_quality_json_tells_an_axial_probe_read_the_other_way_round(tmp_path, spindle_model):
    """A probe that falls as the spindle warms reads the twin's drift negated (mounted or
    logged the other way round): told, with the correlation.  Not told: a probe that grows
    (with a stop's cooling in it), one that moves within 2 µm, one of too short a run."""
    from twin.loop.findings import PROBE_REVERSED, probe_direction_findings
    from twin.runs import read_run

    t = np.arange(0.0, 2400.0, 2.0)
    speed = np.where((t > 1200) & (t < 1800), 0.0, 9000.0)  # a 10-min stop
    heat = np.cumsum(np.where(speed > 0, 1.0, -1.6)) * 2.0 / 1800.0
    warm = np.clip(heat, 0.0, None)
    cols = {"time_s": t, "speed_rpm": speed, "ambient_C": np.full(t.size, 22.0),
            **{f"T{k}_C": 22.0 + amp * warm for k, amp in enumerate([8, 6, 5, 4, 1], 1)}}

    def told(disp_um: np.ndarray, minutes: float = 40.0) -> list[dict]:
        keep = t < 60.0 * minutes
        path = tmp_path / "run.csv"
        write_run(path, {k: v[keep] for k, v in {**cols, "disp_z_um": disp_um}.items()})
        return probe_direction_findings(read_run(path), spindle_model)

    found = told(-12.0 * warm)
    assert [(f["kind"], f["column"], f["detail"]) for f in found] == [
        (PROBE_REVERSED, "disp_z_um", "falls as the thermocouples warm (correlation -1.00 "
                                      "with their mean)")]
    assert told(12.0 * warm) == []
    assert told(-1.5 * warm) == []  # within 2 µm: noise and offsets, nothing to tell
    assert told(-12.0 * warm, minutes=18.0) == []


def test_quality_json_tells_an_axial_probe_that_reads_next_to_nothing_at_speed(tmp_path):
    """A disp_z_um column written in mm (the reference spindle's 11 µm as 0.011) scored
    -82 381 % deformation accuracy and pulled the estimator's temperatures off, without a
    word of the cause."""
    from twin.loop.findings import PROBE_IN_MM, probe_scale_findings
    from twin.runs import read_run

    t = np.arange(0.0, 1502.0, 2.0)
    rise = 1.0 - np.exp(-t / 600.0)
    cols = {"time_s": t, "speed_rpm": np.full(t.size, 9000.0),
            "ambient_C": np.full(t.size, 22.0),
            **{f"T{k}_C": 22.0 + amp * rise for k, amp in enumerate([8, 6, 5, 4, 1], 1)}}

    def findings(disp_um: np.ndarray, speed: float = 9000.0) -> list[dict]:
        path = tmp_path / "run.csv"
        write_run(path, {**cols, "speed_rpm": np.full(t.size, speed), "disp_z_um": disp_um})
        return [f for f in probe_scale_findings(read_run(path)) if f["kind"] == PROBE_IN_MM]

    told = findings(0.011 * rise)  # 11 µm, written in mm
    assert [(f["column"], f["count"], f["detail"]) for f in told] == [
        ("disp_z_um", t.size, "every reading within ±0.0101 µm through 25 min at speed: "
                              "in mm?")]
    assert findings(11.0 * rise) == []  # in µm
    assert findings(0.011 * rise, speed=0.0) == []  # a stopped spindle drifts nothing
    assert findings(np.where(t < 1100, 0.011 * rise, np.nan)) == []  # 18 min of readings


def test_the_estimator_leaves_out_a_probe_in_mm_frozen_or_reversed(spindle_model, tmp_path):
    """Assimilated, a probe column in mm (1000 times too small) or one frozen at 20 µm
    pulled the estimator's temperatures from 99.86 to 97.33 % on a bundled run (the
    twin's drift driven towards a flat line), one negated to 97.40 %.  They are now left
    out of its inputs: its temperatures are those of the same run without a probe; the
    mm and negated columns are still scored as recorded, the frozen one not at all."""
    from twin.correction.methods import make_corrector
    from twin.loop.replay import replay_method
    from twin.loop.runfiles import measured_reference, method_accuracy
    from twin.runs import read_run

    # the rules need 20 min at speed: a spindle drifts micrometres in minutes
    run = read_run(make_recorded_run(tmp_path / "hot.csv", spindle_model, minutes=21))
    columns = {"time_s": run.time_s, "speed_rpm": run.speed_rpm, "ambient_C": run.ambient_C,
               **{f"T{i + 1}_C": run.T_C[:, i] for i in range(5)}}
    probes = {"none": None, "mm": run.disp_um[:, 2] / 1000.0,
              "frozen": np.full(run.time_s.size, 20.0), "reversed": -run.disp_um[:, 2]}
    results = {}
    for name, disp in probes.items():
        write_run(tmp_path / f"{name}.csv",
                  columns if disp is None else {**columns, "disp_z_um": disp})
        case = read_run(tmp_path / f"{name}.csv")
        result = replay_method(case, spindle_model,
                               make_corrector("estimator", spindle=spindle_model),
                               keep_fields=False)
        results[name] = (result, method_accuracy(result,
                                                 *measured_reference(case, result.time_s)))
    for name in ("mm", "frozen", "reversed"):
        np.testing.assert_allclose(results[name][0].T_twin_C, results["none"][0].T_twin_C,
                                   atol=1e-9)
    assert results["none"][1]["temperature_accuracy_pct"] > 99.7
    assert [f["kind"] for f in read_run(tmp_path / "frozen.csv").quality] == ["stuck"]
    assert results["mm"][1]["deformation_accuracy_pct"] < -1000.0  # scored as recorded
    assert results["reversed"][1]["deformation_accuracy_pct"] < -50.0
    assert results["frozen"][1]["deformation_accuracy_pct"] is None


def test_a_probe_not_zeroed_whose_first_samples_are_missing_is_read_from_its_first_reading(
        tmp_path):
    """A probe 50 µm off whose log starts a few seconds late (its first cells blank, a gap
    too long to fill) was taken as zeroed: no probe_not_zeroed finding, and the estimator
    assimilated it as recorded.  Its first valid reading, inside the run's first window, is
    its start reading."""
    from twin.loop.findings import PROBE_NOT_ZEROED, probe_offset_findings, probe_start_offset_um
    from twin.runs import read_run

    t = np.arange(0.0, 600.0, 1.0)
    rise = 1.0 - np.exp(-t / 600.0)
    disp = 50.0 + 3.0 * rise
    late = 40  # the probe logs from 40 s on
    cols = {"time_s": t, "speed_rpm": np.full(t.size, 9000.0),
            "ambient_C": np.full(t.size, 22.0),
            **{f"T{k}_C": 22.0 + amp * rise for k, amp in enumerate([8, 6, 5, 4, 1], 1)},
            "disp_z_um": np.where(t < late, np.nan, disp)}
    write_run(tmp_path / "late.csv", cols)
    run = read_run(tmp_path / "late.csv")
    assert not run.valid["disp_z_um"][0]  # the leading gap is not filled in
    assert probe_start_offset_um(run) == pytest.approx(disp[late], abs=1e-3)
    told = probe_offset_findings(run)
    assert [(f["kind"], f["rows"]) for f in told] == [(PROBE_NOT_ZEROED, [int(run.rows[late])])]
    assert told[0]["detail"].startswith("reads 50.2 µm at 40 s,")
    # a probe that starts logging after the first window is not read as zeroed there
    write_run(tmp_path / "later.csv", {**cols, "disp_z_um": np.where(t < 90, np.nan, disp)})
    assert probe_start_offset_um(read_run(tmp_path / "later.csv")) == 0.0
