"""Where warnings go: a log file, not the user's terminal.

The terminal gets results and real errors (one line, `twin.errors`).  Library chatter —
numpy's RuntimeWarnings on an empty slice, VTK's "bad X server connection" when rendering
off-screen — goes to `twin.log` in `$TWIN_LOG_DIR` or else the platform's user log folder
(`~/.local/state/spindle-twin/log` on Linux).  If that folder cannot be written, the
warnings are dropped rather than shown.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path

LOGGER = "twin"


def log_path() -> Path:
    """The log file of the command lines."""
    root = os.environ.get("TWIN_LOG_DIR")
    if root:
        return Path(root) / "twin.log"
    import platformdirs

    return platformdirs.user_log_path("spindle-twin") / "twin.log"


class _LogFile(logging.FileHandler):
    """The log file, opened at the first record (most runs write none); a file that then
    cannot be opened or written drops its records, as the module doc says: a log folder
    that exists but may not be written in (a read-only home in CI) ended the command in
    an internal error at its first warning."""

    def emit(self, record: logging.LogRecord) -> None:
        try:
            super().emit(record)
        except OSError:
            pass

    def handleError(self, record: logging.LogRecord) -> None:  # noqa: N802 - logging's name
        pass  # a failed write: dropped, not logging's "--- Logging error ---" on stderr


def _handler() -> logging.Handler:
    try:
        path = log_path()
        path.parent.mkdir(parents=True, exist_ok=True)
        handler: logging.Handler = _LogFile(path, encoding="utf-8", delay=True)
    except OSError:
        return logging.NullHandler()
    handler.setFormatter(logging.Formatter("%(asctime)s %(process)d %(name)s: %(message)s"))
    return handler


def send_warnings_to_log() -> None:
    """Route Python warnings (and the `twin` logger) to the log file, once per process;
    and the root logger, where pyvista sends VTK's errors and warnings (with no handler
    of its own, a record there printed itself on the terminal)."""
    logging.captureWarnings(True)
    for name in ("py.warnings", LOGGER):
        logger = logging.getLogger(name)
        if not logger.handlers:
            logger.addHandler(_handler())
            logger.propagate = False
            logger.setLevel(logging.INFO)
    root = logging.getLogger()
    if not root.handlers:
        root.addHandler(_handler())


def send_vtk_messages_to_log() -> None:
    """VTK writes its warnings to stderr itself (not through Python): point them at the
    log file instead.  Call before rendering."""
    from vtkmodules.vtkCommonCore import vtkLogger

    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)
    try:
        path = log_path()
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError:
        return
    vtkLogger.LogToFile(str(path), vtkLogger.APPEND, vtkLogger.VERBOSITY_WARNING)
