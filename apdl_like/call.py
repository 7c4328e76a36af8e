"""What a command is: its spec (name, processors, field count, handler) and its call.

Handlers are plain functions `handler(state, call)` on the session's `SessionState`; `call`
gives typed access to the fields with APDL's 1-based numbering (field 1 is the first after
the command name).  The table of all commands is built by `apdl_like.registry`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

from apdl_like.errors import ApdlError
from apdl_like.expressions import compile_expression
from apdl_like.parser import Statement

if TYPE_CHECKING:
    from apdl_like.state import SessionState

ANY = frozenset({"BEGIN", "PREP7", "SOLU", "POST1", "POST26", "AUX12"})
PREP7 = frozenset({"PREP7"})
SOLU = frozenset({"SOLU"})
LOADS = frozenset({"PREP7", "SOLU"})
POST = frozenset({"POST1"})
POST26 = frozenset({"POST26"})
MODEL = frozenset({"PREP7", "SOLU", "POST1", "POST26", "AUX12"})
AUX12 = frozenset({"AUX12"})
MAX_ENTITY_NUMBER = 2**31 - 1  # MAPDL numbers entities with 32-bit signed integers

Handler = Callable[["SessionState", "Call"], None]


def existing(numbers: list[int], table: Mapping[int, object], what: str) -> list[int]:
    """`numbers` as given, once each is checked to name an entity of `table` (its keys)."""
    for num in numbers:
        if num not in table:
            raise ApdlError(f"{what} {num} does not exist")
    return numbers


@dataclass(frozen=True)
class CommandSpec:
    """One APDL command: its name, where it may run, how many fields, what runs it."""

    name: str
    processors: frozenset[str]
    max_fields: int
    handler: Handler


def command(name: str, processors: frozenset[str],
            max_fields: int) -> Callable[[Handler], Handler]:
    """Decorator: the handler runs APDL command `name` (in `processors`, with at most
    `max_fields` fields); its family lists it in `COMMANDS` through `specs_of`."""

    def mark(handler: Handler) -> Handler:
        spec = CommandSpec(name, processors, max_fields, handler)
        handler.apdl_spec = spec  # type: ignore[attr-defined]
        return handler

    return mark


def specs_of(*handlers: Handler) -> tuple[CommandSpec, ...]:
    """The specs of handlers marked by `command`, in order (a family's table)."""
    return tuple(h.apdl_spec for h in handlers)  # type: ignore[attr-defined]


def ignored(s: SessionState, c: Call) -> None:
    """Handler of commands that are accepted and change nothing here (output controls)."""


class Call:
    """The fields of one command, evaluated on demand."""

    __slots__ = ("statement", "state")

    def __init__(self, statement: Statement, state: SessionState) -> None:
        self.statement = statement
        self.state = state

    @property
    def name(self) -> str:
        return self.statement.name

    def raw(self, i: int) -> str:
        f = self.statement.fields
        return f[i - 1] if 0 < i <= len(f) else ""

    def given(self, i: int) -> bool:
        return self.raw(i) != ""

    def label(self, i: int, default: str = "") -> str:
        text = self.raw(i)
        return text.upper() if text else default

    def num(self, i: int, default: float | None = None, what: str = "") -> float:
        text = self.raw(i)
        if not text:
            if default is None:
                raise ApdlError(f"field {i}{f' ({what})' if what else ''} is required")
            return default
        try:
            return compile_expression(text)(self.state.params, self.state.model_functions)
        except ApdlError as exc:
            reason = exc.reason
            if self.table(i) is not None:
                reason = (f"a table ({text.strip()}) is not accepted here (tabular values: "
                          "D,,TEMP, F,,HEAT, SF/SFE CONV and HFLUX, BF/BFE HGEN)")
            raise ApdlError(f"field {i}{f' ({what})' if what else ''}: {reason}") from None

    def table(self, i: int) -> str | None:
        """The table field `i` names as `%NAME%` (a tabular load value), else None."""
        text = self.raw(i).strip()
        if len(text) > 2 and text[0] == "%" and text[-1] == "%":
            return text[1:-1].strip().upper()
        return None

    def int(self, i: int, default: int | None = None, what: str = "") -> int:
        value = self.num(i, None if default is None else float(default), what)
        if not math.isfinite(value) or abs(value - round(value)) > 1e-9 * max(1.0, abs(value)) \
                or abs(value) >= 2**31:
            label = f" ({what})" if what else ""
            raise ApdlError(f"field {i}{label} must be an integer, got {value!r}")
        return int(round(value))

    def int_in(self, i: int, low: int, high: int, default: int | None = None,
               what: str = "") -> int:
        """Field `i` as an integer in `low`..`high` (both included)."""
        value = self.int(i, default, what)
        if not low <= value <= high:
            raise ApdlError(f"field {i} ({what}) must lie in {low}..{high}, got {value}")
        return value

    def entity(self, i: int, what: str) -> int:
        """Field `i` as an entity number (node, element, keypoint, line, set, type)."""
        return self.int_in(i, 1, MAX_ENTITY_NUMBER, what=what)

    def count(self) -> int:
        return len(self.statement.fields)
