"""The `twin` console script: one module per command, wired here explicitly.

As in meshio's `_cli/_main.py`, this module imports each command module and adds its
function to the app; no command registers itself by being imported, and no command module
imports this one.  The command modules keep their heavy imports (torch, gmsh, pyvista,
matplotlib) inside their functions, so `twin --help` stays fast.  Every command runs under
`report_errors`: bad input (`InputError`) exits with code 2 and a one-line message;
anything else is an internal error, exit code 1.
"""

from __future__ import annotations

import gc

import typer

from twin.cli.drift import drift_app
from twin.cli.mesh import mesh
from twin.cli.model_info import model_info
from twin.cli.replay import replay
from twin.cli.report import report
from twin.cli.simulate import simulate_command
from twin.cli.snapshot import snapshot
from twin.cli.synth import synth
from twin.cli.train import train
from twin.errors import report_errors, run_console_script
from twin.helptext import PlainHelpCommand
from twin.log import send_warnings_to_log
from twin.version import version_option

COMMANDS = (
    ("replay", replay),
    ("snapshot", snapshot),
    ("report", report),
    ("simulate", simulate_command),
    ("synth", synth),
    ("train", train),
    ("model-info", model_info),
    ("mesh", mesh),
)
"""(name, function) of every `twin` command, in the order `twin --help` lists them."""


def _options(
    version: bool = typer.Option(False, "--version", callback=version_option("twin"),
                                 is_eager=True, help="Print the installed version and exit."),
) -> None:
    # the app's own options (typer's callback); the help text is the app's
    pass


def build_app() -> typer.Typer:
    """The `twin` app with every command of `COMMANDS` under the shared error handling."""
    app = typer.Typer(
        name="twin",
        help="Digital twin of a motorized spindle: replay recorded runs, simulate, train, "
        "report.",
        no_args_is_help=True,
        add_completion=False,
        pretty_exceptions_enable=False,
        # click's plain help: rich's table gave a long flag pair (--drift-assimilation/
        # --no-drift-assimilation) two columns, and at 80 columns the help text got 17
        # characters a line ("[default: open_loop,ratio…"); at 120 half the width was blank
        rich_markup_mode=None,
    )
    app.callback()(_options)
    for name, function in COMMANDS:
        app.command(name, cls=PlainHelpCommand)(report_errors(function))
    # a command group: its sub-commands carry report_errors themselves
    app.add_typer(drift_app, name="drift")
    return app


app = build_app()


def main() -> None:
    send_warnings_to_log()
    try:
        run_console_script(app, "twin")
    finally:
        # the process ends now: the interpreter's last garbage collections would walk every
        # object the run left (0.1-0.2 s after a replay), yet exiting frees them all anyway
        gc.freeze()

