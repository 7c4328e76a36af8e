"""The one table of APDL commands: name -> `CommandSpec`, built from the command families.

Each family module (`apdl_like.commands.*`) lists its commands as plain data in `COMMANDS`;
this module gathers them.  Only the interpreter imports it, so importing a family never
registers anything, and no family imports the table back.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from types import MappingProxyType

from apdl_like.call import CommandSpec
from apdl_like.commands import (
    aux12,
    begin,
    blocks,
    etable,
    generate,
    loads,
    post1,
    post26,
    prep7,
    selection,
    solid,
    solution,
    tables,
)

FAMILIES = (aux12, begin, blocks, etable, generate, loads, post1, post26, prep7, selection,
            solid, solution, tables)


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

ABBREVIATION_LENGTH = 4  # MAPDL reads a command by its first four characters


def lookup(name: str) -> CommandSpec | None:
    """The command `name` stands for: exact, or the same first four characters.

    `FINI` is FINISH, `ANTY` ANTYPE, `/SOLUTION` /SOLU (a longer spelling), `/SOL` /SOLU
    (MAPDL counts a command's slash or star among the four: users' decks write `/SOL`); a
    name that fits several commands stands for none.
    """
    spec = REGISTRY.get(name)
    if spec is not None:
        return spec
    if len(name) < ABBREVIATION_LENGTH:
        return None
    # a longer name is matched on its first four letters after the slash or star, so
    # `/OUTP` is /OUTPUT and not also /OUT
    core = name.lstrip("/*")
    prefix = name[: len(name) - len(core) + ABBREVIATION_LENGTH]
    matches = [spec for key, spec in REGISTRY.items()
               if key.startswith(prefix) and (key.startswith(name) or name.startswith(key))]
    return matches[0] if len(matches) == 1 else None
