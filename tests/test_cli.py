"""The `twin` and `apdl-like` command lines: wiring, help, exit codes, light imports."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
import typer
from typer.testing import CliRunner

from twin.cli import COMMANDS, app
from twin.errors import InputError, report_errors

COMMAND_NAMES = [name for name, _ in COMMANDS]


def test_every_command_is_wired():
    registered = [c.name for c in app.registered_commands]
    assert registered == COMMAND_NAMES
    assert {"replay", "snapshot", "report", "simulate", "synth", "train", "model-info",
            "mesh"} <= set(COMMAND_NAMES)


def test_top_level_help_lists_every_command():
    result = CliRunner().invoke(app, ["--help"])
    assert result.exit_code == 0, result.output
    for name in COMMAND_NAMES:
        assert name in result.output


@pytest.mark.parametrize("name", COMMAND_NAMES)
def test_every_command_has_help(name):
    result = CliRunner().invoke(app, [name, "--help"])
    assert result.exit_code == 0, result.output
    assert "--help" in result.output
    assert "Usage: " in result.output and name in result.output


def _loaded_modules(code: str) -> set[str]:
    """The modules a fresh interpreter has loaded after running `code`."""
    probe = code + "\nimport json, sys\nprint(json.dumps(sorted(sys.modules)))"
    out = subprocess.run([sys.executable, "-c", probe], check=True, capture_output=True,
                         text=True).stdout
    return set(json.loads(out.splitlines()[-1]))


def test_apdl_like_cli_does_not_load_twin_commands():
    loaded = _loaded_modules("import apdl_like.cli")
    assert "apdl_like.cli" in loaded
    assert not {m for m in loaded if m == "twin.cli" or m.startswith("twin.cli.")}


def test_twin_help_loads_no_heavy_library():
    loaded = _loaded_modules(
        "import sys\nfrom twin.cli import app\nsys.argv = ['twin', '--help']\n"
        "try:\n    app(prog_name='twin')\nexcept SystemExit:\n    pass"
    )
    assert "twin.cli.replay" in loaded  # the probe really ran the CLI
    heavy = {"torch", "pyvista", "gmsh", "matplotlib", "skfem", "scipy", "vtk"}
    assert not heavy & {m.split(".")[0] for m in loaded}


def _wrapped_app(error: BaseException) -> typer.Typer:
    def fail() -> None:
        raise error

    wrapped = typer.Typer()
    wrapped.command("fail")(report_errors(fail))
    wrapped.command("other")(lambda: None)  # two commands: `fail` stays a subcommand
    return wrapped


@pytest.mark.parametrize(
    ("error", "code", "message"),
    [
        (InputError("speed must be >= 0", file="run.csv", row=3, column="speed_rpm"), 2,
         "error: run.csv, row 3, column 'speed_rpm': speed must be >= 0"),
        (RuntimeError("boom"), 1, "internal error: RuntimeError: boom"),
        (KeyboardInterrupt(), 130, "interrupted"),
    ],
)
def test_report_errors_maps_errors_to_exit_codes(error, code, message):
    result = CliRunner().invoke(_wrapped_app(error), ["fail"])
    assert result.exit_code == code
    assert result.stderr.strip() == message
    assert "Traceback" not in result.output


def test_report_errors_lets_typer_exit_through():
    result = CliRunner().invoke(_wrapped_app(typer.Exit(3)), ["fail"])
    assert result.exit_code == 3
    assert result.stderr == ""


def test_closed_pipe_exits_141_silently(tmp_path):
    # `twin model-info M | head -0`: the reader is gone before the first line is written
    code = (
        "import sys\nfrom twin.cli import main\n"
        f"sys.argv = ['twin', 'model-info', {str(_bundled_model())!r}]\nmain()"
    )
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE)
    proc.stdout.close()
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 141, err
    assert b"Traceback" not in err


def _bundled_model():
    from twin.cli.inputs import bundled_model

    model = bundled_model()
    assert model is not None
    return model
