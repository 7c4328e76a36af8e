"""Imports every module that registers a `twin` command (see twin/cli.py)."""

from __future__ import annotations

import importlib

# One module per command family; each owns its CLI signature.
_COMMAND_MODULES = [
    "twin.cli_mesh",
    "twin.cli_simulate",
    "twin.cli_synth",
    "twin.cli_train",
    "twin.cli_replay",
]

for _name in _COMMAND_MODULES:
    try:
        importlib.import_module(_name)
    except ModuleNotFoundError as exc:  # a family not built yet
        if exc.name != _name:
            raise
