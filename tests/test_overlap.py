"""twin.loop.overlap.ForkedTask: the task runs once, in a child where fork is safe, and its
failure reaches the parent; without fork the same code runs sequentially."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from twin.loop.overlap import ForkedTask, ForkedTaskError, fork_is_safe


@pytest.fixture
def needs_fork() -> None:
    """Checked when the test runs, not when it is collected: a test before it may have left
    threads running (a dask cluster's), and then this process may not fork."""
    if not fork_is_safe():
        pytest.skip("no safe os.fork in this process now (not Linux, or threads running)")


def _write_pid(path: Path) -> None:
    path.write_text(str(os.getpid()))


@pytest.mark.usefixtures("needs_fork")
def test_task_runs_in_a_child_after_start_and_sees_files_written_before(tmp_path):
    prepared = tmp_path / "prepared"
    source = tmp_path / "source.txt"

    def task(name: str) -> str:
        (tmp_path / name).write_text(source.read_text().upper())
        return f"pid {os.getpid()}: ünïcode"

    with ForkedTask(task, prepare=lambda: _write_pid(prepared)) as side:
        assert side.forked and side.fresh
        source.write_text("written after the fork")  # the task reads it only after start
        side.start("dône.txt")  # chosen after the fork too
        assert not side.fresh
        reply = side.join()
    assert (tmp_path / "dône.txt").read_text() == "WRITTEN AFTER THE FORK"
    assert reply == f"pid {prepared.read_text()}: ünïcode"
    assert int(prepared.read_text()) != os.getpid()


@pytest.mark.usefixtures("needs_fork")
def test_a_failing_task_raises_in_the_parent_with_its_message(tmp_path):
    def fail(_: str) -> None:
        raise ValueError("no keypoints.csv in the run folder")

    side = ForkedTask(fail)
    side.start()
    with pytest.raises(ForkedTaskError, match="ValueError: no keypoints.csv in the run folder"):
        side.join()


@pytest.mark.usefixtures("needs_fork")
def test_a_failing_preparation_fails_the_task(tmp_path):
    def prepare() -> None:
        raise ImportError("matplotlib is missing")

    done = tmp_path / "done"
    with pytest.raises(ForkedTaskError, match="ImportError: matplotlib is missing"):
        with ForkedTask(lambda _: done.write_text("x") and None, prepare=prepare) as side:
            side.start()
    assert not done.exists()


@pytest.mark.usefixtures("needs_fork")
def test_a_task_returning_no_text_is_an_error_forked_or_not():
    for fork in (True, False):
        side = ForkedTask(lambda _: 42, fork=fork)
        with pytest.raises((ForkedTaskError, TypeError), match="text or None, not int"):
            side.start()
            side.join()


@pytest.mark.usefixtures("needs_fork")
def test_a_task_never_started_never_runs_and_the_parents_error_passes(tmp_path):
    done = tmp_path / "done"
    with pytest.raises(KeyError, match="parent failed"):
        with ForkedTask(lambda _: done.write_text("x")) as side:
            pid = side._pid
            raise KeyError("parent failed")
    assert not done.exists() and not side.fresh
    with pytest.raises(ChildProcessError):  # reaped: no zombie left behind
        os.waitpid(pid, os.WNOHANG)


@pytest.mark.timeout(60)
@pytest.mark.usefixtures("needs_fork")
def test_a_start_that_fails_leaves_no_child_waiting(tmp_path):
    # start("bad\udcffname") failed encoding the name after the task counted as started:
    # the parent's join then waited for a reply from a child waiting for its start
    done = tmp_path / "done"
    with pytest.raises(UnicodeEncodeError):
        with ForkedTask(lambda _: done.write_text("x")) as side:
            side.start("bad\udcffname")
    assert side.join() is None and not done.exists()



@pytest.mark.usefixtures("needs_fork")
def test_a_ctrl_c_reaching_the_child_as_it_is_forked_stays_in_the_child(monkeypatch):
    # Ctrl-C goes to the whole process group: a child interrupted before its own code
    # began raised KeyboardInterrupt in the frames it shares with the parent and ran on as
    # a second copy of the parent (its handlers, its report, "interrupted" twice)
    import signal

    import twin.loop.overlap

    parent = os.getpid()
    real_fork = os.fork

    def fork_then_ctrl_c() -> int:
        pid = real_fork()
        if pid == 0:
            os.kill(os.getpid(), signal.SIGINT)
        return pid

    monkeypatch.setattr(twin.loop.overlap.os, "fork", fork_then_ctrl_c)
    try:
        with ForkedTask(lambda _: "done") as side:
            side.start()
            with pytest.raises(KeyboardInterrupt):
                side.join()
    except BaseException:
        if os.getpid() != parent:
            os._exit(3)  # the child came back here: the parent's join reports exit code 3
        raise


@pytest.mark.usefixtures("needs_fork")
def test_a_ctrl_c_that_ends_the_child_interrupts_the_parent():
    # it came back as ForkedTaskError('KeyboardInterrupt: '): a replay whose figures' child
    # took a Ctrl-C before the replay did reported the run as an internal error, and the
    # primary method's child as failed, which the replay then ran again itself
    def interrupted(_: str) -> str:
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt), ForkedTask(interrupted) as side:
        side.start()
        side.join()

def test_without_fork_start_runs_prepare_and_task_here_in_order(tmp_path):
    calls = []
    side = ForkedTask(lambda arg: calls.append(("task", arg, os.getpid())) or "done",
                      prepare=lambda: calls.append(("prepare", os.getpid())), fork=False)
    assert not side.forked
    assert calls == []
    side.start("run folder")
    assert calls == [("prepare", os.getpid()), ("task", "run folder", os.getpid())]
    assert side.join() == "done"
    with pytest.raises(RuntimeError, match="started or ended already"):
        side.start()


def test_method_replay_survives_its_json_exactly():
    from twin.correction.features import BoundaryValues
    from twin.correction.result import Correction
    from twin.loop.replay import (
        MethodReplay,
        WindowRecord,
        method_replay_from_json,
        method_replay_to_json,
    )

    rng = np.random.default_rng(3)
    T = rng.normal(30.0, 5.0, (30, 5))
    T[4, 2] = np.nan  # an invalid sensor sample stays NaN
    band = rng.random((30, 6)) / 3.0
    correction = Correction(1.1e6 / 3, 2.2e6, 1.2e-4, 1e-4 / 7, C_H=(1.01, 0.99),
                            C_C=(1.0, 1.0 / 3), factors={"motor": 1.07, "film_coolant": 0.93},
                            state_C=rng.normal(25.0, 1.0, 40), band_sd=band[:15],
                            sensor_offset_C=rng.normal(0.0, 0.5, 5))
    r = MethodReplay(
        method="estimator", time_s=4.0 * np.arange(1, 31), T_twin_C=T,
        drift_z_um=rng.normal(size=30), drift_r_um=rng.normal(size=30),
        windows=[WindowRecord(0, 0.0, 9000.0, 25.3, correction,
                              BoundaryValues(1e6, 2e6, 1e-4, 1e-4), "/SOLU\nSOLVE\n")],
        fields={60.0: rng.normal(size=40)}, T_initial_C=24.9, wall_s=0.123, band_sd=band)
    back = method_replay_from_json(method_replay_to_json(r))
    for name in ("time_s", "T_twin_C", "drift_z_um", "drift_r_um", "band_sd"):
        np.testing.assert_array_equal(getattr(back, name), getattr(r, name))
    assert (back.method, back.T_initial_C, back.wall_s) == (r.method, r.T_initial_C, r.wall_s)
    assert list(back.fields) == [60.0]
    np.testing.assert_array_equal(back.fields[60.0], r.fields[60.0])
    w, c = back.windows[0], back.windows[0].correction
    assert (w.window, w.start_s, w.speed_rpm, w.ambient_C, w.deck) == (0, 0.0, 9000.0, 25.3,
                                                                         "/SOLU\nSOLVE\n")
    assert w.nominal == r.windows[0].nominal and c == correction  # values, C_H, C_C, factors
    np.testing.assert_array_equal(c.state_C, correction.state_C)
    np.testing.assert_array_equal(c.band_sd, correction.band_sd)
    np.testing.assert_array_equal(c.sensor_offset_C, correction.sensor_offset_C)


_SAME_WITH_AND_WITHOUT_FORK = """
import sys
from twin.loop.overlap import fork_is_safe
from twin.loop.runfiles import replay_run_to_dir
from twin.spindle.model import SpindleModel

assert fork_is_safe()
run, out, methods = sys.argv[1], sys.argv[2], sys.argv[3].split(",")
model = SpindleModel.load()
for overlap in (True, False):
    replay_run_to_dir(run, f"{out}/{overlap}", methods, "examples/correction_model.safetensors",
                      snapshots="end", spindle=model, overlap=overlap)
"""


def test_replay_with_forked_helpers_writes_the_same_files_as_without(tmp_path):
    """bpnn (the primary, with its field files and snapshot) and the estimator (state, band
    and factors) replayed by a forked child, and the figures drawn by another, give
    byte-identical files."""
    import subprocess
    import sys

    from tests.test_replay import make_recorded_run
    from twin.spindle.model import SpindleModel

    run = make_recorded_run(tmp_path / "hot.csv", SpindleModel.load(), minutes=4)
    root = Path(__file__).resolve().parent.parent
    subprocess.run([sys.executable, "-c", _SAME_WITH_AND_WITHOUT_FORK, str(run), str(tmp_path),
                    "estimator,ratio,open_loop,bpnn"], check=True, cwd=root,
                   env={**os.environ, "PYTHONPATH": str(root)})
    forked, plain = tmp_path / "True" / "hot", tmp_path / "False" / "hot"
    names = sorted(p.relative_to(plain) for p in plain.rglob("*") if p.is_file())
    assert names == sorted(p.relative_to(forked) for p in forked.rglob("*") if p.is_file())
    assert {"keypoints.csv", "corrections.csv", "accuracy.json"} <= {str(n) for n in names}
    assert any(n.suffix == ".vtu" for n in names)
    assert {n.parent.name for n in names if n.suffix == ".png"} == {"plots", "snapshots"}
    for name in names:
        assert (forked / name).read_bytes() == (plain / name).read_bytes(), name


@pytest.mark.parametrize("platform", ["darwin", "win32"])
def test_off_linux_nothing_is_forked_and_the_task_still_runs_once(monkeypatch, platform):
    import sys

    monkeypatch.setattr(sys, "platform", platform)
    assert not fork_is_safe()
    calls = []
    side = ForkedTask(lambda arg: calls.append(arg) or arg.upper())
    assert not side.forked
    side.start("run folder")
    assert side.join() == "RUN FOLDER" and calls == ["run folder"]
