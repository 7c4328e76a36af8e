"""gmsh changes signal handlers process-wide; meshing must leave this process's as it found
them.  Read from the kernel (/proc/self/status), since `signal.getsignal` keeps showing
what Python set: after gmsh, SIGPIPE was no longer ignored (Python's start-up choice), so
the next write into a closed pipe killed the process (the test suite, once, mid-run).

gmsh does it on its first initialize in a process only, so each check runs in a fresh
interpreter: in this one some earlier test may have meshed already.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"),
                                reason="reads /proc/self/status")

PRELUDE = """
import signal
from pathlib import Path

def ignored_by_kernel(signum):
    status = Path("/proc/self/status").read_text()
    line = next(ln for ln in status.splitlines() if ln.startswith("SigIgn:"))
    return bool(int(line.split()[1], 16) >> (signum - 1) & 1)

assert ignored_by_kernel(signal.SIGPIPE)
int_handler = signal.getsignal(signal.SIGINT)  # the default, or ignored in a background job
"""

KEPT = """
assert ignored_by_kernel(signal.SIGPIPE), "SIGPIPE no longer ignored"
assert signal.getsignal(signal.SIGINT) is int_handler, "SIGINT changed"
print("kept")
"""


def fresh_python(code: str, then: str = "") -> str:
    result = subprocess.run([sys.executable, "-c", PRELUDE + textwrap.dedent(code) + then],
                            capture_output=True, text=True, timeout=120, check=False)
    assert result.returncode == 0, result.stderr
    return result.stdout


def test_gmsh_itself_changes_them():
    # the premise: without the guard, gmsh leaves SIGPIPE at the default
    out = fresh_python("""
        import gmsh
        gmsh.initialize(readConfigFiles=False, interruptible=False)
        gmsh.finalize()
        print("changed" if not ignored_by_kernel(signal.SIGPIPE) else "kept")
    """)
    assert out.strip() == "changed"


def test_spindle_mesher_keeps_the_signal_handlers():
    out = fresh_python("""
        from twin.spindle.mesher import build_mesh
        from twin.spindle.spec import load_spec
        build_mesh(load_spec(), size_factor=3.0)
    """, then=KEPT)
    assert out.strip() == "kept"


def test_a_decks_amesh_keeps_the_signal_handlers():
    out = fresh_python("""
        from apdl_like.session import Session
        Session().run_text("\\n".join(["/PREP7", "ET,1,PLANE55", "K,1,0,0", "K,2,1,0",
                                       "K,3,1,1", "K,4,0,1", "A,1,2,3,4", "ESIZE,0.5",
                                       "MSHAPE,1,2D", "AMESH,ALL", "FINISH"]))
    """, then=KEPT)
    assert out.strip() == "kept"
