"""The `--help` of the console scripts' commands: arguments by their plain names.

typer (0.2x) shows an argument with its Python type and braces: `Usage: twin replay
[OPTIONS] [RUN]...` became `{RUN}`-style usage lines (`twin report [OPTIONS] {DIR}`) and
an `Arguments:` list of `RUN <list[Path]>`, `DIR <path>`; an option of a number range read
`--time <float range>` (the range itself is told in the brackets, `[x>=0.0]`).  The
commands of `twin` and `apdl-like` are made with `PlainHelpCommand`, which names an
argument as DESIGN.md does and click did: `RUN...`, `[RUN]...` where it may be left out,
`DIR`.  What the help says of each parameter (its text, default, range, `required`) is
typer's own.
"""

from __future__ import annotations

from typing import Any

from typer.core import TyperCommand


def _is_argument(param: Any) -> bool:
    # click's word for a parameter kind, in the click typer vendors and in click itself
    return getattr(param, "param_type_name", None) == "argument"


def argument_name(param: Any) -> str:
    """An argument's name as its help lists it: its metavar (its name in capitals without
    one), `...` after it where it takes any number of values (`RUN...`)."""
    name = param.metavar or (param.name or "").upper()
    return f"{name}..." if param.nargs != 1 else name


def argument_usage(param: Any) -> str:
    """An argument in the usage line, as click writes it: `DIR`, `[RUN]...` where it may be
    left out, `RUN...` where one or more are required."""
    name = param.metavar or (param.name or "").upper()
    if not param.required:
        name = f"[{name}]"
    return f"{name}..." if param.nargs != 1 else name


def option_label(label: str) -> str:
    """An option's first help column without typer's range wording: `--time <float>`
    (the range is told in the help's brackets)."""
    return label.replace(" range>", ">")


class PlainHelpCommand(TyperCommand):
    """A typer command whose help names its arguments plainly (see the module doc)."""

    def collect_usage_pieces(self, ctx: Any) -> list[str]:
        pieces = [self.options_metavar] if self.options_metavar else []
        for param in self.get_params(ctx):
            if _is_argument(param):
                pieces.append(argument_usage(param))
            else:
                pieces.extend(param.get_usage_pieces(ctx))
        return pieces

    def format_options(self, ctx: Any, formatter: Any) -> None:
        arguments, options = [], []
        for param in self.get_params(ctx):
            record = param.get_help_record(ctx)
            if record is None:  # hidden
                continue
            label, text = record
            if _is_argument(param):
                arguments.append((argument_name(param), text))
            else:
                options.append((option_label(label), text))
        for title, rows in (("Arguments", arguments), ("Options", options)):
            if rows:
                with formatter.section(title):
                    formatter.write_dl(rows)
