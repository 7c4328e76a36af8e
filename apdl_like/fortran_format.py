"""Fortran format lines of `*VWRITE`: `(1X,A8,A8,'   ',F10.5,'  ',1F15.3)`.

Edit descriptors: `Aw` (text, right-justified in w, or its first w characters), `Fw.d`,
`Ew.d`, `Gw.d`, `Iw`, `nX` (blanks), quoted literals, `/` (new line), repeat counts (`3F10.2`,
`2(A8,F8.3)`).  A number too wide for its field prints as w asterisks, as Fortran does.
Output stops at the first data descriptor with no value left.  Values left when the format
ends are written by Fortran's format reversion: a new record (line), the format taken up again
from the start of its last top-level parenthesized group, repeat count included (`(1X,'T=',
F5.1,2(1X,F4.1))`), or from its start when it has no group.  A C-style line
(`%14.5G %I %C`) is accepted too; *MSG's lines are C-style, their bare `%I`, `%G`, `%C` the
Fortran `I9` (NINT), `1PG16.9` and `A8` MAPDL documents for them.  Every integer edit
(`Iw`, `%I`, `%wI`) takes the nearest integer, halves away from zero (`integer`).
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass

from apdl_like.errors import ApdlError
from apdl_like.expressions import nint
from apdl_like.parser import split_fields

Item = tuple[str, int, int]  # (kind, width, decimals): kind in A F E G I X ' /
DATA_KINDS = "AFEGI"  # the data edit descriptors: each takes one value

_DESCRIPTOR = re.compile(r"(\d*)([AFEGIXD])(\d*)(?:\.(\d+))?\Z", re.I)
_C_SPEC = re.compile(r"%(-?\d*)(?:\.(\d+))?([IGEFCSX/%])", re.I)


def _split_top(text: str) -> list[str]:
    """The items of a format: split at top-level commas and slashes (a slash is an item)."""
    return [p.strip() for p in split_fields(text, ",/", "/") if p.strip()]


@dataclass(frozen=True)
class FortranFormat:
    """A parsed format: its items (kind, width, decimals, literal text), groups expanded,
    and `revert`, the index of the item format reversion goes back to (the first item of
    the last top-level group's repetitions, 0 when there is no group)."""

    items: list[tuple[str, int, int, str]]
    revert: int = 0


def parse_format(line: str) -> FortranFormat:
    """A format line -> its items and reversion point."""
    text = line.strip()
    if not (text.startswith("(") and text.endswith(")")):
        raise ApdlError(f"format line must be a Fortran format in parentheses, got {text!r}")
    revert: list[int] = [0]
    items = _items(text[1:-1], revert)
    return FortranFormat(items, revert[0])


def _items(body: str, revert: list[int] | None = None) -> list[tuple[str, int, int, str]]:
    """The items of a format body; `revert[0]` is set to where its last group starts."""
    out: list[tuple[str, int, int, str]] = []
    for part in _split_top(body):
        if part == "/":
            out.append(("/", 0, 0, ""))
        elif part.startswith("'") and part.endswith("'") and len(part) >= 2:
            out.append(("'", 0, 0, part[1:-1].replace("''", "'")))
        elif "(" in part:
            m = re.match(r"(\d*)\((.*)\)\Z", part, re.S)
            if m is None:
                raise ApdlError(f"format item {part!r} is not understood")
            if revert is not None:
                revert[0] = len(out)
            out += _items(m.group(2)) * int(m.group(1) or 1)
        else:
            m = _DESCRIPTOR.match(part)
            if m is None:
                raise ApdlError(f"format item {part!r} is not understood")
            repeat, kind = int(m.group(1) or 1), m.group(2).upper()
            width, decimals = int(m.group(3) or 0), int(m.group(4) or 0)
            if kind == "X":
                out.append(("'", 0, 0, " " * (repeat if not m.group(3) else width)))
                continue
            kind = "E" if kind == "D" else kind
            if kind in "FEG" and width == 0:
                raise ApdlError(f"format item {part!r} needs a width")
            out += [(kind, width, decimals, "")] * repeat
    return out


def _stars(text: str, width: int) -> str:
    return text.rjust(width) if len(text) <= width else "*" * width


def fixed(value: float, width: int, decimals: int) -> str:
    """Fw.d: `1100.` for F6.0, `0.998` -> ` 1.00` for F5.2."""
    if not math.isfinite(value):
        return _stars("NaN" if math.isnan(value) else "Inf", width)
    text = f"{value:.{decimals}f}"
    if decimals == 0:
        text += "."
    if text.startswith("-") and float(text) == 0.0:
        text = text[1:]
    if len(text) > width and text.lstrip("-").startswith("0."):
        text = text.replace("0.", ".", 1)  # Fortran's leading zero is optional
    return _stars(text, width)


def exponential(value: float, width: int, decimals: int) -> str:
    """Ew.d: `0.12345E+03`."""
    if not math.isfinite(value):
        return _stars("NaN" if math.isnan(value) else "Inf", width)
    if value == 0.0:
        return _stars(f"0.{'0' * decimals}E+00", width)
    exp = math.floor(math.log10(abs(value))) + 1
    mant = round(abs(value) / 10.0**exp, decimals)
    if mant >= 1.0:
        mant, exp = mant / 10.0, exp + 1
    sign = "-" if value < 0 else ""
    text = f"{sign}{mant:.{decimals}f}E{exp:+03d}"
    if len(text) > width and text.lstrip("-").startswith("0."):
        text = text.replace("0.", ".", 1)
    return _stars(text, width)


def general(value: float, width: int, decimals: int, scale: int = 0) -> str:
    """Gw.d: F editing with d significant digits for 0.1 ≤ |v| < 10^d, else E; with the
    scale factor 1 (`1PGw.d`) the E form has one digit before the point."""
    if math.isfinite(value) and value != 0.0:
        exp = math.floor(math.log10(abs(value))) + 1
        if 0 <= exp <= decimals:
            return fixed(value, width - 4, max(decimals - exp, 0)) + "    "
    elif value == 0.0:
        return fixed(0.0, width - 4, max(decimals - 1, 0)) + "    "
    if scale == 1 and math.isfinite(value):
        return _stars(f"{value:.{decimals}E}", width)
    return exponential(value, width, decimals)


def integer(value: float) -> str:
    """The digits an integer edit (`Iw`, `%I`, `%wI`) writes for a real value: MAPDL's
    values are all double precision and it forms the integer with Fortran's NINT (*MSG's
    documentation, which *VWRITE's C formats refer to), halves away from zero: 2.5 -> 3,
    -2.5 -> -3, 3.5 -> 4 (Python's round() gives 2, -2, 4).  NaN and Inf are written as
    such, as F editing writes them."""
    if not math.isfinite(value):
        return "NaN" if math.isnan(value) else ("Inf" if value > 0 else "-Inf")
    return str(int(nint(value)))


# *MSG's bare descriptors as the Fortran edits MAPDL names for them
_MSG_BARE = {"I": lambda v: _stars(integer(v), 9),
             "G": lambda v: general(v, 16, 9, scale=1)}


def format_line(fmt: FortranFormat, values: Sequence[float | str]) -> list[str]:
    """The record(s) written by `fmt` with `values`: several lines if the format has `/`,
    or when values are left at its end (format reversion: a new line, the format again
    from `fmt.revert`).  A format whose reverted part has no data descriptor writes the
    values it has descriptors for, once."""
    items = fmt.items
    reusable = any(kind in DATA_KINDS for kind, *_ in items[fmt.revert:])
    lines, current, k, i = [], "", 0, 0
    while True:
        if i == len(items):
            if k >= len(values) or not reusable:
                break
            lines.append(current)
            current, i = "", fmt.revert
        kind, width, decimals, literal = items[i]
        i += 1
        if kind == "'":
            current += literal
            continue
        if kind == "/":
            lines.append(current)
            current = ""
            continue
        if k >= len(values):
            break
        value = values[k]
        k += 1
        current += _edit(kind, width, decimals, value)
    lines.append(current)
    return lines


def _edit(kind: str, width: int, decimals: int, value: float | str) -> str:
    """One value by one data edit descriptor (A, F, E, G, I)."""
    if kind == "A":
        text = str(value)
        return text if width == 0 else (text[:width] if len(text) >= width
                                        else text.rjust(width))
    if isinstance(value, str):
        raise ApdlError(f"format item {kind}{width}: {value!r} is text, a number is needed")
    if kind == "F":
        return fixed(value, width, decimals)
    if kind == "E":
        return exponential(value, width, decimals)
    if kind == "G":
        return general(value, width, decimals)
    return _stars(integer(value), width)  # I


def c_descriptors(line: str) -> int:
    """How many values a C-style line reads (its %I, %G, %E, %F, %C and %S)."""
    return sum(m.group(3).upper() in "IGEFCS" for m in _C_SPEC.finditer(line))


def normal_descriptors(line: str) -> bool:
    """Whether a *MSG format holds only MAPDL's normal descriptors (%I, %G, %C with no
    width, %/), or none: no enhanced one (a width or precision, %E, %F, %S, %X, %%)."""
    return all(m.group(3).upper() in "IGC/" and not m.group(1) and m.group(2) is None
               for m in _C_SPEC.finditer(line))


def format_c_line(line: str, values: Sequence[float | str],
                  bare_fortran: bool = False) -> list[str]:
    """A C-style *VWRITE line: %w.dG/E/F, %wI, %wC or %wS, %wX, %/ (new line).  With
    `bare_fortran` (*MSG) a descriptor with no width is MAPDL's Fortran one: %I is I9 of the
    nearest integer, %G 1PG16.9, %C A8."""
    out, k, pos = [""], 0, 0
    for m in _C_SPEC.finditer(line):
        out[-1] += line[pos:m.start()]
        pos = m.end()
        width, decimals, kind = m.group(1), m.group(2), m.group(3).upper()
        if kind == "%":
            out[-1] += "%"
            continue
        if kind == "/":
            out.append("")
            continue
        if kind == "X":
            out[-1] += " " * int(width or 1)
            continue
        if k >= len(values):
            break
        value = values[k]
        k += 1
        w = int(width) if width and width != "-" else 0
        if bare_fortran and not width and decimals is None and kind in "IGC":
            if kind == "C":
                out[-1] += _edit("A", 8, 0, value)  # A8
                continue
            if isinstance(value, str):
                raise ApdlError(f"%{kind}: {value!r} is text, a number is needed")
            out[-1] += _MSG_BARE[kind](value)
            continue
        if kind in ("C", "S"):
            text = str(value)
            out[-1] += text.ljust(abs(w)) if width.startswith("-") else text.rjust(w)
            continue
        if isinstance(value, str):
            raise ApdlError(f"%{kind}: {value!r} is text, a number is needed")
        d = int(decimals) if decimals is not None else 6
        spec = {"G": "g", "E": "E", "F": "f"}.get(kind, "")
        body = integer(value) if kind == "I" else f"{value:.{d}{spec}}".upper()
        out[-1] += body.ljust(abs(w)) if width.startswith("-") else body.rjust(w)
    out[-1] += line[pos:]
    return out
