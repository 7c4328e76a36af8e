"""The `twin` console script.

Each command lives in the module of its domain and is imported lazily, so that
`twin --help` does not pay for torch, gmsh or VTK.  Bad input (`InputError`) exits with
code 2 and a one-line message; anything else is an internal error, exit code 1.
"""

from __future__ import annotations

import functools
import os
import sys
from collections.abc import Callable
from typing import Any

import typer

from twin.errors import InputError

app = typer.Typer(
    name="twin",
    help="Digital twin of a motorized spindle: replay recorded runs, simulate, train, report.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)


def report_errors(func: Callable[..., Any]) -> Callable[..., Any]:
    """Map user errors to exit 2 and internal errors to exit 1, both without a traceback."""

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return func(*args, **kwargs)
        except InputError as exc:
            typer.echo(f"error: {exc}", err=True)
            raise typer.Exit(2) from None
        except typer.Exit:
            raise
        except KeyboardInterrupt:
            typer.echo("interrupted", err=True)
            raise typer.Exit(130) from None
        except BrokenPipeError:
            # the reader went away (`twin model-info M | head`): not an error of ours;
            # silence the final flush and exit as a SIGPIPE'd process would
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
            raise typer.Exit(141) from None
        except Exception as exc:  # noqa: BLE001 - the last line of defence of a CLI
            typer.echo(f"internal error: {type(exc).__name__}: {exc}", err=True)
            raise typer.Exit(1) from None

    return wrapper


def command(name: str) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Register a CLI command with the shared error handling."""

    def decorate(func: Callable[..., Any]) -> Callable[..., Any]:
        app.command(name)(report_errors(func))
        return func

    return decorate


def main() -> None:
    app(prog_name="twin")


# Command modules register themselves on import (they keep heavy imports inside their
# functions); imported last because they use `command` from this module.
from twin import commands  # noqa: E402, F401

if __name__ == "__main__":
    sys.exit(main())
