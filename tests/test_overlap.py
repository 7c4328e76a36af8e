"""twin.loop.overlap.ForkedTask: the task runs once, in a child where fork is safe, and its
failure reaches the parent; without fork the same code runs sequentially."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from twin.loop.overlap import ForkedTask, ForkedTaskError, fork_is_safe

needs_fork = pytest.mark.skipif(not fork_is_safe(), reason="no safe os.fork here")


def _write_pid(path: Path) -> None:
    path.write_text(str(os.getpid()))


@needs_fork
def test_task_runs_in_a_child_after_start_and_sees_files_written_before(tmp_path):
    prepared = tmp_path / "prepared"
    source, done = tmp_path / "source.txt", tmp_path / "done.txt"
    with ForkedTask(lambda: done.write_text(source.read_text().upper()),
                    prepare=lambda: _write_pid(prepared)) as side:
        assert side.forked
        source.write_text("written after the fork")  # the task reads it only after start
        side.start()
        side.join()
    assert done.read_text() == "WRITTEN AFTER THE FORK"
    assert int(prepared.read_text()) != os.getpid()


@needs_fork
def test_a_failing_task_raises_in_the_parent_with_its_message(tmp_path):
    def fail() -> None:
        raise ValueError("no keypoints.csv in the run folder")

    side = ForkedTask(fail)
    side.start()
    with pytest.raises(ForkedTaskError, match="ValueError: no keypoints.csv in the run folder"):
        side.join()


@needs_fork
def test_a_failing_preparation_fails_the_task(tmp_path):
    def prepare() -> None:
        raise ImportError("matplotlib is missing")

    done = tmp_path / "done"
    with pytest.raises(ForkedTaskError, match="ImportError: matplotlib is missing"):
        with ForkedTask(lambda: done.write_text("x"), prepare=prepare) as side:
            side.start()
    assert not done.exists()


@needs_fork
def test_a_task_never_started_never_runs_and_the_parents_error_passes(tmp_path):
    done = tmp_path / "done"
    with pytest.raises(KeyError, match="parent failed"):
        with ForkedTask(lambda: done.write_text("x")) as side:
            pid = side._pid
            raise KeyError("parent failed")
    assert not done.exists()
    with pytest.raises(ChildProcessError):  # reaped: no zombie left behind
        os.waitpid(pid, os.WNOHANG)


def test_without_fork_start_runs_prepare_and_task_here_in_order(tmp_path):
    calls = []
    side = ForkedTask(lambda: calls.append(("task", os.getpid())),
                      prepare=lambda: calls.append(("prepare", os.getpid())), fork=False)
    assert not side.forked
    assert calls == []
    side.start()
    assert calls == [("prepare", os.getpid()), ("task", os.getpid())]
    side.join()
    with pytest.raises(RuntimeError, match="started already"):
        side.start()
