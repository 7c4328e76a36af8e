"""The benchmarks' child-process measurement (`bench.child`): a child's peak memory is its
own, not the memory of the process that started it."""

from __future__ import annotations

import os
import sys

import pytest

from bench.child import run_measured

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="Linux rusage semantics")


def _alloc(mb: int) -> str:
    # touch every page so the memory is resident
    return f"b = bytearray({mb} * 2**20); b[::4096] = b'x' * len(b[::4096]); print('ok')"


def test_a_child_measures_its_own_peak_not_its_parents() -> None:
    hog = bytearray(400 * 2**20)
    hog[::4096] = b"y" * len(hog[::4096])  # this process now holds 400 MB more
    env = dict(os.environ)
    # started straight from here (subprocess + os.wait4), a bare interpreter measured
    # > 400 MB on this machine's kernel: its peak started at this process's
    stdout, small = run_measured([sys.executable, "-c", "pass"], env)
    _, big = run_measured([sys.executable, "-c", _alloc(200)], env)
    del hog
    assert small.rss_MB < 60, small  # a bare interpreter: some 10-20 MB
    assert 200 < big.rss_MB < 280, big  # its own 200 MB and the interpreter
    assert small.wall_s > 0 and small.cpu_s > 0 and stdout == ""


def test_a_failing_child_is_an_error_with_its_stderr() -> None:
    with pytest.raises(RuntimeError, match="exited 3: .*boom"):
        run_measured([sys.executable, "-c", "import sys; sys.stderr.write('boom'); sys.exit(3)"],
                     dict(os.environ))
