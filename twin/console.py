"""The console scripts' entry points (`twin`, `apdl-like`, and `python -m` of either).

Each loads its command line under a Ctrl-C guard: the first thing a console script does is
import its CLI (some 40-100 ms of modules), and a Ctrl-C there was Python's traceback and a
death by SIGINT instead of the one line `interrupted` and exit code 130.  This module
imports nothing at its start, so the unguarded moment is the interpreter's start only.
"""

from __future__ import annotations

from importlib import import_module  # loaded with the interpreter already


def _run(module: str) -> None:
    try:
        main = import_module(module).main
    except KeyboardInterrupt:  # while the commands load: nothing has run yet
        _exit_interrupted()
    try:
        main()
    except KeyboardInterrupt:  # before the command line runs (its own Ctrl-C it tells)
        _exit_interrupted()


def _exit_interrupted() -> None:
    # imported here: twin.errors takes some 10 ms to load, a moment unguarded above
    from twin.errors import exit_interrupted

    exit_interrupted()


def twin_main() -> None:
    """`twin`."""
    _run("twin.cli")


def apdl_like_main() -> None:
    """`apdl-like`."""
    _run("apdl_like.cli")
