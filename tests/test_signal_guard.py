"""gmsh changes signal handlers process-wide; meshing must leave this process's as it found
them.  Read from the kernel (/proc/self/status), since `signal.getsignal` keeps showing
what Python set: after gmsh, SIGPIPE was no longer ignored (Python's start-up choice), so
the next write into a closed pipe killed the process (the test suite, once, mid-run)."""

from __future__ import annotations

import signal
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"),
                                reason="reads /proc/self/status")


def ignored_by_kernel(signum: int) -> bool:
    status = Path("/proc/self/status").read_text()
    mask = int(next(ln for ln in status.splitlines() if ln.startswith("SigIgn:")).split()[1], 16)
    return bool(mask >> (signum - 1) & 1)


def test_gmsh_itself_does_change_them():
    # the premise (if a gmsh release stops doing it, the guard is merely idle)
    import gmsh

    from twin.signal_guard import signals_kept

    assert ignored_by_kernel(signal.SIGPIPE)
    with signals_kept():
        gmsh.initialize(readConfigFiles=False, interruptible=True)
        changed = not ignored_by_kernel(signal.SIGPIPE)
        int_handler = signal.getsignal(signal.SIGINT)
        gmsh.finalize()
    assert changed and int_handler is signal.SIG_DFL
    assert ignored_by_kernel(signal.SIGPIPE)
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_spindle_mesher_keeps_the_signal_handlers():
    from twin.spindle.mesher import build_mesh
    from twin.spindle.spec import load_spec

    build_mesh(load_spec(), size_factor=3.0)
    assert ignored_by_kernel(signal.SIGPIPE)
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_a_decks_amesh_keeps_the_signal_handlers():
    from apdl_like.session import Session

    deck = "\n".join(["/PREP7", "ET,1,PLANE55", "K,1,0,0", "K,2,1,0", "K,3,1,1", "K,4,0,1",
                      "A,1,2,3,4", "ESIZE,0.5", "MSHAPE,1,2D", "AMESH,ALL", "FINISH"])
    session = Session()
    session.run_text(deck)
    assert ignored_by_kernel(signal.SIGPIPE)
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
