"""The `apdl-like` console script (also `python -m apdl_like`).

    apdl-like run DECK --out DIR       params.json, result_NNN.vtu, log.txt
                  [--spindle]        on the reference spindle (a replay's window decks)
                  [--start FILE.vtu] from that temperature state (window_kkk_start.vtu,
                                     result_NNN.vtu): what ANTYPE,,REST continues
    apdl-like export-cdb --out FILE    the default spindle mesh as an ANSYS archive

Bad input (an `ApdlError`, or any `twin.errors.InputError`) prints one line and exits 2;
anything else is an internal error, exit 1; neither prints a traceback.  A deck that stops
at a bad line still leaves what ran before it in DIR (the files it wrote, the load steps it
solved, params.json as they stood, log.txt ending with the error), as MAPDL keeps its
output files when a batch run stops.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from twin.errors import InputError, report_errors, run_console_script
from twin.helptext import PlainHelpCommand
from twin.io.destinations import check_out_dir, check_out_file
from twin.log import send_warnings_to_log
from twin.paths import check_input_file, regular_file_info
from twin.version import version_option

if TYPE_CHECKING:
    from apdl_like.session import Session

app = typer.Typer(
    name="apdl-like",
    help="Run APDL-subset decks on the spindle twin's axisymmetric FEM; export the mesh as CDB.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # click's plain help: readable at 80 columns (see twin.cli)
)


@app.callback()
def _options(
    version: bool = typer.Option(False, "--version", callback=version_option("apdl-like"),
                                 is_eager=True, help="Print the installed version and exit."),
) -> None:
    # the app's own options (typer's callback); the help text is the app's
    pass


@app.command("run", cls=PlainHelpCommand)
@report_errors
def run(
    deck: Path = typer.Argument(..., metavar="DECK", help="The APDL deck (.inp, .mac, "
                                ".cdb); /INPUT is resolved in its folder."),
    out: Path = typer.Option(..., "--out", metavar="DIR",
                             help="Output folder (created if missing)."),
    quiet: bool = typer.Option(False, "--quiet", help="No summary on success (warnings are "
                               "still told, on stderr)."),
    strict: bool = typer.Option(False, "--strict", help="An unknown or unsupported command "
                                                        "is an error (exit 2), not a warning."),
    spindle: bool = typer.Option(False, "--spindle", help="Start with the reference spindle "
                                 "loaded as the twin loads it (nodes, elements, materials, "
                                 "components, contact real sets 101..): the database a "
                                 "replay's decks/window_kkk.inp run on."),
    start: Path = typer.Option(None, "--start", metavar="FILE",
                               help="With --spindle: the temperature state "
                               "(a replay's decks/window_kkk_start.vtu, or a result_NNN.vtu "
                               "of an earlier run) at its TIME, which a deck's "
                               "ANTYPE,TRANS,REST continues from."),
) -> None:
    """Run a deck statement by statement, as MAPDL does.

    Writes DIR/params.json, DIR/result_NNN.vtu per solved load step, DIR/log.txt
    and the files the deck writes (/OUT, *CFOPEN), inside DIR only."""
    from apdl_like.outputs import output_names, write_outputs
    from apdl_like.session import Session

    regular_file_info(deck, use="read deck")  # a folder, a fifo, nothing there: say which
    if start is not None:
        if not spindle:
            raise InputError("--start needs --spindle (a state of the reference spindle's "
                             "nodes)")
        check_input_file(start, column="--start")  # a folder, a fifo, too large to read
    check_out_dir(out, inputs=[deck, *([start] if start is not None else [])],
                  files=["params.json", "log.txt"])
    session = _spindle_session(deck.parent, strict) if spindle else Session(
        base_dir=deck.parent, strict=strict)
    if start is not None:
        from apdl_like.outputs import read_state_vtu

        session.start_from_nodes(*read_state_vtu(start), source=str(start))
    stopped: InputError | None = None
    try:
        session.run_file(deck)
    except InputError as exc:
        # a bad line stops the run, not what came before it: the files the deck wrote, the
        # load steps it solved and the log (ending with the error) are kept, then exit 2
        stopped = exc
        session.state.listing.log.append(f"*** ERROR *** {exc}")
    finally:
        # told with or without --quiet, which silences the summary only: a deck whose
        # command was skipped must not pass in CI as if it had run in full
        for warning in session.state.listing.warnings:
            typer.echo(warning, err=True)
    read = [deck, *session.state.inputs]  # with --out the deck's folder, /OUT,sub,inp
    for name in output_names(session.state):  # would replace the sub.inp /INPUT read
        check_out_file(out / name, inputs=read)
    written = write_outputs(session.state, out)
    if stopped is not None:
        raise stopped
    if not quiet:
        errors = session.state.listing.errors
        told = f"; {errors} *MSG,ERROR message(s), told on stderr" if errors else ""
        typer.echo(f"{deck}: {len(session.results)} load step(s) solved; wrote "
                   f"{len(written)} files to {out}{told}")


def _spindle_session(base_dir: Path, strict: bool) -> Session:
    """A session holding the reference spindle as the twin's loop builds it
    (`twin.loop.replay.spindle_session`)."""
    from twin.loop.replay import spindle_session
    from twin.spindle.model import SpindleModel

    session = spindle_session(SpindleModel.load(), base_dir=base_dir)
    session.state.strict = strict
    return session


@app.command("export-cdb", cls=PlainHelpCommand)
@report_errors
def export_cdb(
    out: Path = typer.Option(..., "--out", metavar="FILE.cdb", help="The archive to write (.cdb)."),
    mesh: Path = typer.Option(None, "--mesh", metavar="FILE.msh",
                              help="A gmsh .msh instead of the default "
                                                   "spindle mesh (materials then omitted; "
                                                   "a spindle mesh's contact faces are kept "
                                                   "apart, as in the default)."),
    quiet: bool = typer.Option(False, "--quiet", help="Print nothing on success."),
) -> None:
    """Write the default spindle mesh as an ANSYS archive (NBLOCK, EBLOCK, CMBLOCK)."""
    from apdl_like.cdb import write_cdb
    from twin.fem import AxiMesh

    check_out_file(out, inputs=[mesh], suffixes=(".cdb",))

    from twin.spindle.spec import load_spec

    spec = load_spec()
    if mesh is None:
        from twin.spindle.model import DEFAULT_MESH_PATH, fem_material

        axi = AxiMesh.from_msh(DEFAULT_MESH_PATH, interfaces=spec.interfaces())
        materials = {region: fem_material(spec, region) for region in spec.regions}
        title = spec.spindle.name
    else:
        regular_file_info(mesh, use="read mesh", column="--mesh")
        try:  # a spindle mesh (`twin mesh`) keeps its contact faces apart, as the default
            axi = AxiMesh.from_msh(mesh, interfaces=spec.interfaces(), present_only=True)
        except ValueError as exc:
            raise InputError(str(exc), file=str(mesh)) from None
        materials, title = None, mesh.stem
    write_cdb(axi, out, materials, title)
    if not quiet:
        typer.echo(f"wrote {out}: {axi.thermal.p.shape[1]} nodes, {axi.n_cells} elements, "
                   f"{len(axi.regions) + len(axi.boundaries) + 2 * len(axi.interfaces)} "
                   "components")


def main() -> None:
    send_warnings_to_log()
    run_console_script(app, "apdl-like")


if __name__ == "__main__":
    sys.exit(main())
