"""Keep this process's signal dispositions across a library that changes them.

gmsh's `initialize` sets SIGPIPE from ignored (as CPython starts every process) back to
the default, at C level, and never restores it; interruptible gmsh (pygmsh's) sets SIGINT
to the default too.  A process that had meshed once was then *killed* by the next write
into a closed pipe (the pipe of a worker process that Ctrl-C ended, say), where Python
raises BrokenPipeError, and by Ctrl-C, where Python raises KeyboardInterrupt: the test
suite died by SIGPIPE in a Ctrl-C test long after a deck's AMESH had run in it.

    with signals_kept():
        gmsh.initialize()
        ...
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager

KEPT_SIGNALS = (signal.SIGINT, signal.SIGPIPE)


@contextmanager
def signals_kept(signums: tuple[int, ...] = KEPT_SIGNALS) -> Iterator[None]:
    """Restore the handlers of `signums` on leaving, as they were on entering.

    Only the main thread may set handlers (Python's rule); elsewhere nothing is done.
    Setting a handler again from Python also sets it at C level, which is what a library
    changed behind Python's back (`signal.getsignal` still shows the old one).
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    saved = {signum: signal.getsignal(signum) for signum in signums}
    try:
        yield
    finally:
        for signum, handler in saved.items():
            if handler is not None:  # None: set outside Python, nothing to restore it to
                signal.signal(signum, handler)
