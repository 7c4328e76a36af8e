"""Imports every module that registers a `twin` command (see twin/cli.py)."""

from __future__ import annotations

# One module per command family; each owns its CLI signature.
from twin import cli_mesh, cli_replay, cli_simulate, cli_synth, cli_train  # noqa: F401
