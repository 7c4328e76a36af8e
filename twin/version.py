"""`--version` of the console scripts (`twin`, `apdl-like`): the installed distribution's."""

from __future__ import annotations

from collections.abc import Callable

import typer

PACKAGE = "spindle-twin"
"""The distribution whose metadata `--version` reads (pyproject.toml's name)."""


def version_option(program: str) -> Callable[[bool], None]:
    """A typer callback for `program --version`: prints `program X.Y.Z` and exits 0, or,
    run from a checkout that was never installed, says so and exits 1."""

    def print_version(value: bool) -> None:
        if not value:
            return
        from importlib.metadata import PackageNotFoundError, version

        try:
            typer.echo(f"{program} {version(PACKAGE)}")
        except PackageNotFoundError:
            typer.echo(f"{program}: the {PACKAGE} package is not installed; no version to tell",
                       err=True)
            raise typer.Exit(1) from None
        raise typer.Exit(0)

    return print_version
