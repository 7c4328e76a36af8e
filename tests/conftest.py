"""Shared fixtures: the bundled spindle spec and model are loaded once per test session.

Loading the model reads the committed mesh and assembles every operator (about 0.5 s);
tests only read from it, so one instance serves them all.
"""

from __future__ import annotations

import signal

import pytest


def pytest_configure(config: pytest.Config) -> None:
    """Make Ctrl-C deliverable, as in a terminal: a test run started in the background by a
    non-interactive shell, or under nohup, begins with SIGINT ignored, and Python then
    installs no KeyboardInterrupt handler, so every test of what Ctrl-C does failed there
    (the code leaves an ignored SIGINT alone, as it should for a background job)."""
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.fixture(scope="session")
def spindle_spec():  # noqa: ANN201 - twin.spindle.SpindleSpec
    """The bundled reference-spindle spec (validated)."""
    from twin.spindle import load_spec

    return load_spec()


@pytest.fixture(scope="session")
def spindle_model():  # noqa: ANN201 - twin.spindle.SpindleModel
    """The reference spindle on the committed mesh, operators assembled."""
    from twin.spindle import SpindleModel

    return SpindleModel.load()
