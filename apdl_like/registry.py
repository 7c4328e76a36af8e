"""The one table of APDL commands: name -> `CommandSpec`, built from the command families.

Each family module (`apdl_like.commands.*`) lists its commands as plain data in `COMMANDS`;
this module gathers them.  Only the interpreter imports it, so importing a family never
registers anything, and no family imports the table back.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from types import MappingProxyType

from apdl_like.call import CommandSpec
from apdl_like.commands import begin, blocks, loads, post1, prep7, selection, solution

FAMILIES = (begin, blocks, loads, post1, prep7, selection, solution)


def build_registry(specs: Iterable[CommandSpec]) -> Mapping[str, CommandSpec]:
    """A read-only name -> spec table; a name defined twice is a programming error."""
    table: dict[str, CommandSpec] = {}
    for spec in specs:
        if spec.name in table:
            raise ValueError(f"command {spec.name} is defined twice")
        table[spec.name] = spec
    return MappingProxyType(table)


REGISTRY: Mapping[str, CommandSpec] = build_registry(
    spec for family in FAMILIES for spec in family.COMMANDS)
