"""The `twin` and `apdl-like` command lines: wiring, help, exit codes, light imports."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import pytest
import typer
from typer.testing import CliRunner

from twin.cli import COMMANDS, app
from twin.errors import InputError, TomlError, report_errors

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


def _command_paths(group, prefix=()):  # noqa: ANN001, ANN202 - a click group of typer's
    """Every command path of the app, sub-commands of groups (`drift fit`, …) included."""
    for name, command in group.commands.items():
        yield (*prefix, name)
        if hasattr(command, "commands"):
            yield from _command_paths(command, (*prefix, name))


COMMAND_PATHS = list(_command_paths(typer.main.get_command(app)))


def test_command_paths_cover_groups():
    assert {("replay",), ("drift",), ("drift", "fit")} <= set(COMMAND_PATHS)


@pytest.mark.parametrize("path", COMMAND_PATHS, ids=" ".join)
def test_every_command_has_help(path):
    result = CliRunner().invoke(app, [*path, "--help"])
    assert result.exit_code == 0, result.output
    assert "--help" in result.output
    assert "Usage: twin " + " ".join(path) in " ".join(result.output.split())


def _leaf_commands():  # noqa: ANN202 - (usage prefix, click command) pairs
    from apdl_like.cli import app as apdl_app

    for prog, typer_app in (("twin", app), ("apdl-like", apdl_app)):
        group = typer.main.get_command(typer_app)
        for path in _command_paths(group):
            command = group
            for name in path:
                command = command.commands[name]
            if not hasattr(command, "commands"):
                yield " ".join((prog, *path)), command


@pytest.mark.parametrize("usage, command", list(_leaf_commands()),
                         ids=[usage for usage, _ in _leaf_commands()])
def test_readme_usage_lists_every_option(usage, command):
    # a user reads the README's usage block first: simulate's --spec and --size-factor,
    # synth's --coolant and most commands' --quiet were in --help only
    from pathlib import Path

    readme = (Path(__file__).parents[1] / "README.md").read_text(encoding="utf-8")
    block = readme.split("## Usage", 1)[1].split("```")[1]
    lines, inside = [], False
    for line in block.splitlines():
        inside = line.startswith(usage + " ") or (inside and line.startswith(" "))
        if inside:
            lines.append(line)
    text = " ".join(lines)
    assert text, f"{usage} is not in the README's usage block"
    for param in command.params:
        names = [o for o in (*param.opts, *getattr(param, "secondary_opts", ()))
                 if o.startswith("--")]
        if names and "--help" not in names:
            assert any(n in text for n in names), f"{usage}: {names[0]} is not in the README"


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
        # an option is not a column of the file (the message said "option '--time'")
        (InputError("time 400 s is outside the replayed span", file="run.csv",
                    column="--time"), 2,
         "error: run.csv, option '--time': time 400 s is outside the replayed span"),
        (RuntimeError("boom"), 1, "internal error: RuntimeError: boom"),
        (KeyboardInterrupt(), 130, "interrupted"),
    ],
)
def test_report_errors_maps_errors_to_exit_codes(error, code, message):
    result = CliRunner().invoke(_wrapped_app(error), ["fail"])
    assert result.exit_code == code
    assert result.stderr.strip() == message
    assert "Traceback" not in result.output


def test_an_errors_row_is_told_in_its_files_unit():
    # a CSV file's row is its line (RawTable.row_unit); a Parquet file's, a data row
    assert str(InputError("bad", file="run.csv", row=4, column="T1_C", row_unit="line")) == (
        "run.csv, line 4, column 'T1_C': bad")
    assert str(InputError("bad", file="run.parquet", row=4)) == "run.parquet, row 4: bad"
    # located() fills in a row with its unit, and keeps a row already known with its own
    err = InputError("bad", column="T1_C").located("run.csv", 7, row_unit="line")
    assert str(err) == "run.csv, line 7, column 'T1_C': bad"
    err = InputError("bad", row=4, row_unit="line").located("run.csv", 9, "T1_C", "row")
    assert str(err) == "run.csv, line 4, column 'T1_C': bad"
    assert str(TomlError("bad", file="s.toml", line=2, key="a")) == "s.toml, line 2, key 'a': bad"


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


def test_cli_choices_match_the_modules_that_act_on_them():
    from twin.cli.inputs import Field, Method, WindowEnds
    from twin.correction.methods import METHODS
    from twin.loop.runfiles import WINDOW_END_CHOICES
    from twin.loop.snapshot import FIELDS

    assert tuple(Method) == METHODS
    assert tuple(WindowEnds) == WINDOW_END_CHOICES
    assert tuple(Field) == tuple(FIELDS)


def test_a_folder_lists_its_runs_in_any_case_and_no_hidden_file(tmp_path):
    # a folder's RUN1.CSV (or run.pq) was passed over without a word, while the same file
    # named alone was replayed: the readers take the suffix in any case
    from twin.cli.inputs import RUN_SUFFIXES, runs_in
    from twin.runs.run import _READERS

    assert set(RUN_SUFFIXES) == set(_READERS)
    # and hidden files are no runs: a Mac's ._RUN1.CSV, a killed writer's temporary file
    for name in ("RUN1.CSV", "run2.pq", "Run3.Parquet", "run3.truth.csv", "notes.txt",
                 "._RUN1.CSV", ".run4.123.abcd1234.csv"):
        (tmp_path / name).write_text("")
    (tmp_path / "folder.csv").mkdir()
    assert [p.name for p in runs_in(tmp_path)] == ["RUN1.CSV", "Run3.Parquet", "run2.pq"]


@pytest.mark.parametrize(
    ("argv", "option"),
    [
        (["replay", "--out", "OUT", "--methods", "open_loop,magic"], "--methods"),
        (["replay", "--out", "OUT", "--methods", " , "], "--methods"),
        (["replay", "--out", "OUT", "--snapshots", "sometimes"], "--snapshots"),
        (["replay", "--out", "OUT", "--jobs", "0"], "--jobs"),
        (["snapshot", "RUN.csv", "--time", "60", "--out", "OUT.png", "--field", "stress"],
         "--field"),
        (["snapshot", "RUN.csv", "--time", "60", "--out", "OUT.png", "--method", "magic"],
         "--method"),
        (["snapshot", "RUN.csv", "--time", "-1", "--out", "OUT.png"], "--time"),
        (["train", "RUN.csv", "--out", "OUT.safetensors", "--targets", "guess"], "--targets"),
        (["train", "RUN.csv", "--out", "OUT.safetensors", "--seed", "-1"], "--seed"),
        (["train", "RUN.csv", "--out", "OUT.safetensors", "--epochs", "0"], "--epochs"),
        # torch takes seeds below 2**64, k-means below 2**32: beyond, an internal error
        # after the work (train 18 s in), so the option is bounded (MAX_SEED)
        (["train", "RUN.csv", "--out", "OUT.safetensors", "--seed", str(2**64)], "--seed"),
        (["drift", "fit", "D.csv", "--target", "x_um", "--out", "M.safetensors", "--seed",
          "-1"], "--seed"),
        (["drift", "fit", "D.csv", "--target", "x_um", "--out", "M.safetensors", "--seed",
          str(2**32)], "--seed"),
        (["synth", "--speed", "9000", "--minutes", "1", "--ambient", "25", "--seed", "1",
          "--out", "OUT.csv"], "--minutes"),
        (["synth", "--speed", "9000", "--minutes", "nan", "--ambient", "25", "--seed", "1",
          "--out", "OUT.csv"], "--minutes"),
        (["synth", "--speed", "9000", "--minutes", "3", "--ambient", "25", "--seed", "-2",
          "--out", "OUT.csv"], "--seed"),
        # numpy takes any seed >= 0; a suite's runs are seeded below 2**32, and a longer
        # suite seed made file names the file system refused after the draw
        (["synth", "--speed", "9000", "--minutes", "3", "--ambient", "25", "--seed",
          str(2**32), "--out", "OUT.csv"], "--seed"),
        (["synth", "--suite", "2", "--minutes", "3", "--seed", "9" * 300, "--out", "OUT"],
         "--seed"),
        (["synth", "--suite", "2", "--minutes", "3", "--seed", "-1", "--out", "OUT"],
         "--seed"),
        (["synth", "--speed", "-5", "--minutes", "3", "--ambient", "25", "--seed", "1",
          "--out", "OUT.csv"], "--speed"),
        (["synth", "--speed", "9000", "--minutes", "3", "--ambient", "25", "--seed", "1",
          "--rate", "0.01", "--out", "OUT.csv"], "--rate"),
        (["simulate", "--speed", "9000", "--minutes", "0", "--ambient", "25", "--out", "OUT"],
         "--minutes"),
        (["simulate", "--speed", "9000", "--minutes", "3", "--ambient", "25", "--out", "OUT",
          "--field-every", "-1"], "--field-every"),
        (["simulate", "--speed", "9000", "--minutes", "3", "--ambient", "25", "--out", "OUT",
          "--size-factor", "100"], "--size-factor"),
        (["mesh", "--out", "OUT.msh", "--size-factor", "0"], "--size-factor"),
    ],
)
def test_bad_choice_or_bound_exits_2_naming_the_option(argv, option, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # nothing may be written, and nowhere but here
    result = CliRunner().invoke(app, argv)
    assert result.exit_code == 2, result.output
    assert f"Invalid value for '{option}'" in result.output
    assert "Traceback" not in result.output
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("value", ["inf", "nan", "-inf"])
def test_a_bound_refuses_a_value_that_is_no_finite_number_in_those_words(value, tmp_path):
    # 'must be above 0, got inf' read as if infinity were not above 0
    result = CliRunner().invoke(app, ["simulate", "--speed", "9000", "--minutes", value,
                                      "--ambient", "25", "--out", str(tmp_path / "OUT")])
    assert result.exit_code == 2, result.output
    assert (f"Invalid value for '--minutes': must be a finite number above 0, got {value}"
            in result.output)
    assert list(tmp_path.iterdir()) == []


def test_methods_are_normalised_before_the_command_runs():
    from twin.cli.inputs import method_list

    assert method_list(" ratio,open_loop ,ratio") == "ratio,open_loop"


@pytest.mark.parametrize("args", [[], ["run"], ["export-cdb"]], ids=lambda a: " ".join(a) or "-")
def test_apdl_like_help(args):
    from apdl_like.cli import app as apdl_app

    result = CliRunner().invoke(apdl_app, [*args, "--help"])
    assert result.exit_code == 0, result.output
    assert "Usage: " in result.output


def test_synth_profile_over_the_speed_limit_names_its_line(tmp_path):
    profile = tmp_path / "p.csv"
    profile.write_text("time_s,speed_rpm\n0,6000\n60,99000\n120,6000\n")
    result = CliRunner().invoke(app, [
        "synth", "--profile", str(profile), "--minutes", "3", "--ambient", "25", "--seed", "1",
        "--out", str(tmp_path / "run.csv"), "--quiet"])
    assert result.exit_code == 2, result.output
    assert f"{profile}, line 3, column 'speed_rpm'" in result.output
    assert "15000 rpm" in result.output and "Traceback" not in result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.csv"]


def test_synth_tells_the_profile_columns_it_does_not_read(tmp_path):
    # a coolant_C or a misspelt ambient column was read past without a word: the run was
    # emulated at --ambient and the inlet at the ambient, not what the file gave
    profile = tmp_path / "p.csv"
    profile.write_text("time_s,speed_rpm,Ambient_C,coolant_C\n0,6000,21,19\n")
    args = ["synth", "--profile", str(profile), "--minutes", "2", "--ambient", "25",
            "--seed", "1", "--out", str(tmp_path / "run.csv")]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    warning = f"warning: {profile}: column(s) Ambient_C, coolant_C ignored"
    assert warning in result.output
    quiet = CliRunner().invoke(app, [*args, "--quiet"])  # --quiet silences progress only
    assert quiet.exit_code == 0 and quiet.output.startswith(warning)
    assert quiet.output.count("\n") == 1


def test_synth_suite_refuses_a_run_file_name_for_its_folder(tmp_path):
    # --suite 2 --out runs.csv made a folder named runs.csv holding the suite
    result = CliRunner().invoke(app, ["synth", "--suite", "2", "--seed", "1", "--minutes",
                                      "2", "--out", str(tmp_path / "runs.csv"), "--quiet"])
    assert result.exit_code == 2, result.output
    assert f"{tmp_path / 'runs.csv'}, option '--out': --suite writes a folder" in " ".join(
        result.output.split())
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", ["run.truth.csv", "run.profile.csv"])
def test_synth_refuses_a_run_named_as_a_companion_file(tmp_path, name):
    # --out run.truth.csv wrote the run over the truth of run.csv, and 'twin replay DIR'
    # then left the new run out as the truth it is named after
    result = CliRunner().invoke(app, [
        "synth", "--speed", "9000", "--minutes", "2", "--ambient", "25", "--seed", "1",
        "--out", str(tmp_path / name), "--quiet"])
    assert result.exit_code == 2, result.output
    assert f"{tmp_path / name}, option '--out': a run may not be named" in result.output
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("address", ["notanaddress", "tcp://127.0.0.1:port", "tcp://"])
def test_replay_refuses_a_malformed_dask_address_before_any_work(address, tmp_path):
    run = tmp_path / "run.csv"
    run.write_text("time_s,speed_rpm,ambient_C,T1_C,T2_C,T3_C,T4_C,T5_C\n0,0,20,20,20,20,20,20\n")
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["replay", str(run), "--out", str(out), "--dask", address,
                                      "--methods", "ratio", "--quiet"])
    assert result.exit_code == 2, result.output
    assert "Invalid value for '--dask'" in result.output and address in result.output
    assert "internal error" not in result.output
    assert not out.exists()


def test_an_unreachable_dask_scheduler_is_bad_input_naming_the_option(monkeypatch):
    import dask.distributed

    from twin.loop import batch

    def refuse(address, timeout):  # noqa: ANN001, ANN202 - stands in for Client
        raise OSError(f"Timed out trying to connect to {address} after {timeout}")

    monkeypatch.setattr(dask.distributed, "Client", refuse)
    with pytest.raises(InputError) as info:
        batch.dask_client("tcp://127.0.0.1:1")
    assert info.value.column == "--dask" and "tcp://127.0.0.1:1" in str(info.value)


def test_an_unreachable_dask_scheduler_leaves_no_out_folder(monkeypatch, tmp_path):
    # the batch made DIR, then waited 20 s for the scheduler and left DIR empty behind it
    import dask.distributed

    from twin.loop.batch import replay_batch

    def refuse(address, timeout):  # noqa: ANN001, ANN202 - stands in for Client
        raise OSError(f"Timed out trying to connect to {address} after {timeout}")

    monkeypatch.setattr(dask.distributed, "Client", refuse)
    run = tmp_path / "run.csv"
    run.write_text("time_s,speed_rpm,ambient_C,T1_C,T2_C,T3_C,T4_C,T5_C\n")
    with pytest.raises(InputError, match="cannot reach the dask scheduler"):
        replay_batch([run], tmp_path / "out", ["ratio"], None,
                     dask_address="tcp://127.0.0.1:1")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.csv"]


def test_ctrl_c_while_connecting_to_the_dask_scheduler_leaves_no_out_folder(monkeypatch,
                                                                           tmp_path):
    # the connection (up to 20 s, "connecting to the dask scheduler at ...") comes before
    # DIR is made; a Ctrl-C there rebuilt the report of a DIR nothing had been written to
    # and so made it, with an empty summary.json and report.html
    import dask.distributed

    from twin.data import bundled_path

    def interrupted(address, timeout):  # noqa: ANN001, ANN202 - stands in for Client
        raise KeyboardInterrupt

    monkeypatch.setattr(dask.distributed, "Client", interrupted)
    run = bundled_path("runs", "spindle_9000rpm_30min.csv")
    result = CliRunner().invoke(app, ["replay", str(run), "--out", str(tmp_path / "out"),
                                      "--dask", "tcp://127.0.0.1:8786"])
    assert result.exit_code == 130, result.output
    assert "interrupted" in result.output
    assert list(tmp_path.iterdir()) == []


def test_model_info_reads_well_and_says_which_networks_the_gate_kept():
    # R² printed to 16 digits, and nothing said that the gate had zeroed every network
    from twin.correction.modelfile import load_model

    meta = load_model(_bundled_model(), option=None).metadata
    r2 = meta["r2"]["resistance_front"]["value"]
    anchor = meta["held_out_temperature_accuracy_pct"]["anchor"]
    result = CliRunner().invoke(app, ["model-info", str(_bundled_model())])
    assert result.exit_code == 0, result.output
    line = next(ln for ln in result.output.splitlines() if "resistance_front" in ln)
    assert f"R² {r2:.2f} " in line and f"R² {r2:.3f}" not in line, line
    assert "networks kept by the closed-loop gate: none (bpnn gives the anchor)" in result.output
    assert f"anchor {anchor:.2f} %" in result.output and f"{anchor:.3f}" not in result.output


def test_model_info_says_one_run_and_one_sample_in_the_singular(tmp_path):
    # a model trained on one run was told as "1 runs"
    import dataclasses

    from twin.correction.modelfile import load_model, save_model

    model = load_model(_bundled_model(), option=None)
    meta = {**model.metadata, "training_runs": ["only.csv"], "samples": 1}
    one = save_model(dataclasses.replace(model, metadata=meta), tmp_path / "one.safetensors")
    result = CliRunner().invoke(app, ["model-info", str(one)])
    assert result.exit_code == 0, result.output
    first = result.output.splitlines()[0]
    assert ", 1 sample, 1 run, seed " in first, first
    result = CliRunner().invoke(app, ["model-info", str(_bundled_model())])
    runs = len(model.metadata["training_runs"])
    assert f" samples, {runs} runs, seed " in result.output.splitlines()[0]


def test_the_bundled_model_is_replaced_only_on_purpose(tmp_path, monkeypatch):
    # `twin train --out twin/data/correction_model.safetensors` replaced the model every
    # replay without --model reads, without a word; `make model` still writes it
    import hashlib

    from twin.cli.inputs import bundled_runs, check_not_bundled_model
    from twin.data import bundled_path

    monkeypatch.chdir(tmp_path)
    model = _bundled_model()
    before = hashlib.sha256(model.read_bytes()).hexdigest()
    beside = sorted(p.name for p in model.parent.iterdir())
    run = str(bundled_runs()[0])
    for out in (bundled_path("correction_model.safetensors"), model):  # the link, the file
        result = CliRunner().invoke(app, ["train", run, "--out", str(out), "--epochs", "1"])
        assert result.exit_code == 2
        assert result.output == (
            f"error: {out}, option '--out': is the bundled correction model, which every "
            "replay without --model reads: write elsewhere and pass --model, or pass "
            "--replace-bundled-model to replace it (as `make model` does)\n")
        result = CliRunner().invoke(app, ["drift", "fit", run, "--target", "disp_z_um",
                                          "--out", str(out)])
        assert result.exit_code == 2 and result.output.count("\n") == 1, result.output
        assert "is the bundled correction model" in result.output
    # the option is for the bundled model only: elsewhere its writer may think it updates it
    result = CliRunner().invoke(app, ["train", run, "--out", "m.safetensors",
                                      "--replace-bundled-model"])
    assert result.exit_code == 2 and result.output.count("\n") == 1, result.output
    assert "option '--replace-bundled-model': is for --out the bundled model" in result.output
    assert list(tmp_path.iterdir()) == []
    assert hashlib.sha256(model.read_bytes()).hexdigest() == before
    assert sorted(p.name for p in model.parent.iterdir()) == beside
    check_not_bundled_model(model, replace=True)  # what `make model` passes: allowed
    assert "--replace-bundled-model" in CliRunner().invoke(app, ["train", "--help"]).output


def test_counts_are_said_in_the_singular_for_one():
    from twin.wording import counted

    assert [counted(n, "run") for n in (0, 1, 2)] == ["0 runs", "1 run", "2 runs"]
    assert counted(1, "run file") == "1 run file" and counted(3, "run file") == "3 run files"


def test_model_info_names_no_option_it_does_not_have(tmp_path, monkeypatch):
    # MODEL is model-info's argument: the error named a '--model' option the user never gave
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(app, ["model-info", "absent.safetensors"])
    assert result.exit_code == 2
    assert result.output == ("error: absent.safetensors: cannot read file: No such file or "
                             "directory\n")
    result = CliRunner().invoke(app, ["replay", "--model", "absent.safetensors", "--out", "o"])
    assert result.exit_code == 2 and "option '--model'" in result.output


def test_apdl_like_run_says_why_a_deck_cannot_be_read(tmp_path):
    # a folder given as DECK was reported as "deck not found"
    from apdl_like.cli import app as apdl_app

    folder = tmp_path / "decks"
    folder.mkdir()
    for deck, words in ((folder, "is a folder, not a file"),
                        (tmp_path / "absent.inp", "No such file or directory")):
        result = CliRunner().invoke(apdl_app, ["run", str(deck), "--out", str(tmp_path / "o")])
        assert result.exit_code == 2, result.output
        assert f"{deck}: " in result.output and words in result.output
        assert not (tmp_path / "o").exists()


def _commands(command, path):
    yield path, command
    for name, sub in getattr(command, "commands", {}).items():
        yield from _commands(sub, f"{path} {name}")


def test_help_paragraphs_fit_an_80_column_terminal():
    # typer keeps the line breaks of a help text's later paragraphs: a longer line wrapped
    # on its own and left a stub line ("(loss curves, R²" / "of both configurations")
    import inspect

    from apdl_like.cli import app as apdl_app

    long = []
    for root, name in ((app, "twin"), (apdl_app, "apdl-like")):
        for path, command in _commands(typer.main.get_command(root), name):
            paragraphs = inspect.cleandoc(command.help or "").split("\n\n")[1:]
            long += [(path, line) for p in paragraphs for line in p.split("\n")
                     if len(line) > 77]
    assert long == []


def test_replay_names_both_runs_that_would_share_a_folder(tmp_path):
    # "two runs share the output folder name 'run'" named neither file
    header = "time_s,speed_rpm,ambient_C,T1_C,T2_C,T3_C,T4_C,T5_C\n"
    runs = []
    for folder in ("monday", "tuesday"):
        (tmp_path / folder).mkdir()
        runs.append(tmp_path / folder / "run.csv")
        runs[-1].write_text(header + "0,0,20,20,20,20,20,20\n")
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["replay", *map(str, runs), "--out", str(out),
                                      "--methods", "ratio", "--quiet"])
    assert result.exit_code == 2, result.output
    assert f"{runs[0]}, {runs[1]}" in result.output and "'run'" in result.output
    assert not out.exists()


def test_train_refuses_a_model_file_not_named_safetensors(tmp_path):
    # `--out model.txt` trained for minutes and wrote model.txt, model.txt.report.json...
    out = tmp_path / "model.txt"
    result = CliRunner().invoke(app, ["train", str(tmp_path / "run.csv"), "--out", str(out)])
    assert result.exit_code == 2, result.output
    assert f"{out}, option '--out'" in result.output and ".safetensors" in result.output
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(("argv", "first_words", "command"), [
    (["twin", "replay", "--out", "OUT", "--methods", "magic"],
     "error: Invalid value for '--methods': unknown method 'magic'", "twin replay"),
    (["twin", "replay", "--out", "OUT", "--jobs", "0"], "error: Invalid value for '--jobs'",
     "twin replay"),
    # a choice's message is the choices, without pydantic's "Value error, " before them
    (["twin", "replay", "--out", "OUT", "--snapshots", "some"],
     "error: Invalid value for '--snapshots': 'some' is not one of 'none', 'end', 'every'",
     "twin replay"),
    (["twin", "snapshot", "RUN.csv", "--time", "60", "--out", "S.png", "--field", "heat"],
     "error: Invalid value for '--field': 'heat' is not one of", "twin snapshot"),
    (["twin", "drift", "fit", "DATA.csv", "--out", "M.safetensors"],
     "error: Missing option '--target'", "twin drift fit"),
    (["apdl-like", "run", "DECK.inp"], "error: Missing option '--out'", "apdl-like run"),
    (["twin", "simulate", "--speeed", "9000"], "error: No such option: --speeed",
     "twin simulate"),
])
def test_a_bad_option_is_one_line_on_the_console(argv, first_words, command, tmp_path):
    # click's usage block and rich's box wrapped the message over several lines, unlike
    # every other bad input ("error: file, row, column: what"): one line, exit 2
    module = "apdl_like.cli" if argv[0] == "apdl-like" else "twin.cli"
    code = f"import sys\nfrom {module} import main\nsys.argv = {argv!r}\nmain()"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=tmp_path, timeout=120)
    assert done.returncode == 2, done.stderr
    assert done.stderr.startswith(first_words), done.stderr
    assert done.stderr.count("\n") == 1 and done.stdout == ""
    assert done.stderr.rstrip().endswith(f"see '{command} --help'"), done.stderr
    assert list(tmp_path.iterdir()) == []


def test_help_and_no_arguments_still_show_the_help_once():
    # `twin` alone printed the help twice: the error typer raises had printed it already
    code = "import sys\nfrom {} import main\nsys.argv = {!r}\nmain()"
    for argv, status in ((["twin"], 2), (["twin", "drift"], 2), (["twin", "replay", "--help"], 0),
                         (["apdl-like"], 2)):
        module = "apdl_like.cli" if argv[0] == "apdl-like" else "twin.cli"
        done = subprocess.run([sys.executable, "-c", code.format(module, argv)],
                              capture_output=True, text=True, timeout=120)
        assert done.returncode == status, done.stderr
        assert (done.stdout + done.stderr).count("Usage: ") == 1, done.stdout + done.stderr
        assert f"Usage: {' '.join(argv[:2])} " in done.stdout


def test_synth_creates_the_run_file_folder_as_every_other_out_does(tmp_path):
    # replay, simulate, train and drift create a missing --out folder; synth refused it
    out = tmp_path / "new" / "deeper" / "run.csv"
    result = CliRunner().invoke(app, [
        "synth", "--speed", "9000", "--minutes", "2", "--ambient", "25", "--seed", "1",
        "--out", str(out), "--quiet"])
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in out.parent.iterdir()) == ["run.csv", "run.truth.csv"]


@pytest.mark.parametrize("make, message", [
    (lambda p: None, "missing: no such folder"),
    (lambda p: p.write_text("time_s\n"),
     "missing: is a file; a replay folder (twin replay --out DIR) is expected"),
    (lambda p: p.mkdir(), "missing: not a replay folder (no <run>/accuracy.json inside)"),
    # one run's folder of a replay: what to give instead was left to the user
    (lambda p: (p.mkdir(), (p / "accuracy.json").write_text("{}")),
     "missing: is one run's folder of a replay (it holds accuracy.json): give the replay's "
     "folder, ."),
])
def test_report_says_what_is_wrong_with_its_folder(make, message, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    make(tmp_path / "missing")
    result = CliRunner().invoke(app, ["report", "missing"])
    assert result.exit_code == 2 and result.output == f"error: {message}\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == (
        [] if message.endswith("no such folder") else ["missing"])


def test_report_names_no_option_it_does_not_have(tmp_path):
    # a folder where summary.json goes was "DIR/summary.json, option '--out': ...", an
    # option twin report does not take
    run = tmp_path / "run"
    run.mkdir()
    (run / "accuracy.json").write_text("{}")
    (tmp_path / "summary.json").mkdir()
    result = CliRunner().invoke(app, ["report", str(tmp_path)])
    assert result.exit_code == 2, result.output
    assert result.output == f"error: {tmp_path / 'summary.json'}: is a folder, not a file\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run", "summary.json"]


@pytest.mark.parametrize("command", [
    ["simulate", "--out", "OUT"],
    ["synth", "--minutes", "3", "--seed", "1", "--out", "OUT.csv"],
])
@pytest.mark.parametrize("options, option, words", [
    (["--speed", "20000", "--ambient", "25"], "--speed", "exceeds the spindle's limit"),
    (["--speed", "9000", "--ambient", "25", "--coolant", "90"], "--coolant", "got 90"),
    # one range for both (twin.contract.OPERATING_TEMPERATURE_C): simulate took an ambient
    # up to 80 °C and synth down to -30 only
    (["--speed", "9000", "--ambient", "60"], "--ambient", "between -40 and 45 °C, got 60"),
    (["--speed", "9000", "--ambient", "-41"], "--ambient", "between -40 and 45 °C, got -41"),
    (["--speed", "9000", "--ambient", "25", "--coolant", "46"], "--coolant", "got 46"),
])
def test_an_impossible_operating_point_names_the_option(command, options, option, words,
                                                         tmp_path, monkeypatch):
    # simulate named the run column ('speed_rpm'), which its user never typed
    monkeypatch.chdir(tmp_path)
    argv = [*command, *options] + (["--minutes", "3"] if command[0] == "simulate" else [])
    result = CliRunner().invoke(app, argv)
    assert result.exit_code == 2, result.output
    assert result.output.startswith(f"error: option '{option}': ") and words in result.output
    assert list(tmp_path.iterdir()) == []


def test_version_prints_the_installed_package_version():
    from importlib.metadata import version

    code = "import sys\nfrom twin.cli import main\nsys.argv = ['twin', '--version']\nmain()"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout == f"twin {version('spindle-twin')}\n" and done.stderr == ""
    # a command still runs, and its own options are not shadowed
    result = CliRunner().invoke(app, ["--version", "simulate", "--help"])
    assert result.exit_code == 0 and result.output.startswith("twin ")
    result = CliRunner().invoke(app, ["simulate", "--help"])
    assert result.exit_code == 0 and "Open-loop transient" in result.output


def test_apdl_like_tells_its_version_and_still_runs_its_commands():
    from importlib.metadata import version

    from apdl_like.cli import app as apdl_app

    result = CliRunner().invoke(apdl_app, ["--version"])
    assert result.exit_code == 0 and result.output == f"apdl-like {version('spindle-twin')}\n"
    result = CliRunner().invoke(apdl_app, ["run", "--help"])
    assert result.exit_code == 0 and "--strict" in result.output


@pytest.mark.parametrize("argv", [
    ["replay", "RUN", "--methods", "open_loop,estimator", "--snapshots", "none", "--out", "OUT"],
    ["snapshot", "RUN", "--time", "60", "--method", "ratio", "--out", "S.png"],
])
def test_a_model_given_is_checked_whatever_the_methods(argv, tmp_path, monkeypatch):
    # without bpnn a mistyped --model was silently ignored: the user believed it was used
    from twin.cli.inputs import bundled_runs_dir

    run = str(bundled_runs_dir().resolve() / "spindle_9000rpm_30min.csv")
    argv = [run if a == "RUN" else a for a in argv]
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(app, [*argv, "--model", "modle.safetensors"])
    assert result.exit_code == 2, result.output
    assert ("modle.safetensors, option '--model': cannot read file: No such file or "
            "directory") in result.output
    (tmp_path / "models").mkdir()  # 'model file not found' of a folder that is there
    result = CliRunner().invoke(app, [*argv, "--model", "models"])
    assert result.exit_code == 2, result.output
    assert "models, option '--model': is a folder, not a file" in result.output
    (tmp_path / "models").rmdir()
    (tmp_path / "notes.safetensors").write_text("not a model")
    result = CliRunner().invoke(app, [*argv, "--model", "notes.safetensors"])
    assert result.exit_code == 2, result.output
    assert "notes.safetensors: not a readable safetensors model file" in result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.safetensors"]


def test_export_cdb_names_what_is_wrong_with_its_mesh(tmp_path):
    # a folder or a fifo given as --mesh was 'mesh file not found', naming no option
    from apdl_like.cli import app as apdl_app

    (tmp_path / "meshes").mkdir()
    os.mkfifo(tmp_path / "pipe.msh")
    for name, words in (("meshes", "is a folder, not a file"),
                        ("pipe.msh", "is not a regular file"),
                        ("none.msh", "cannot read mesh: No such file or directory")):
        result = CliRunner().invoke(apdl_app, ["export-cdb", "--mesh", str(tmp_path / name),
                                               "--out", str(tmp_path / "x.cdb")])
        assert result.exit_code == 2, result.output
        assert result.output.startswith(f"error: {tmp_path / name}, option '--mesh': {words}")
    assert not (tmp_path / "x.cdb").exists()


def _run_module(tmp_path, name: str, source: str, *args: str) -> subprocess.CompletedProcess:
    """`python -m NAME ARGS` of a module written into tmp_path, with this checkout importable."""
    (tmp_path / name).mkdir()
    (tmp_path / name / "__main__.py").write_text(source)
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path), root]))
    return subprocess.run([sys.executable, "-m", name, *args], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=120)


def test_ctrl_c_ending_a_string_exec_still_exits_130_under_python_m(tmp_path):
    # a Ctrl-C that lands in a string exec (a dataclass's generated methods, compiled while
    # a module loads) leaves CPython noting an unhandled KeyboardInterrupt, and under
    # `python -m` the process then killed itself by SIGINT after printing "interrupted":
    # about one Ctrl-C in four of `python -m twin replay` ended so (returncode -2)
    source = (
        "import typer\n"
        "from twin.errors import report_errors, run_console_script\n"
        "def go() -> None:\n"
        "    exec('raise KeyboardInterrupt')\n"
        "app = typer.Typer()\n"
        "app.command('go')(report_errors(go))\n"
        "app.command('other')(lambda: None)\n"
        "run_console_script(app, 'probe')\n"
    )
    proc = _run_module(tmp_path, "ctrlc_probe", source, "go")
    assert proc.returncode == 130, proc.stderr
    assert proc.stderr == "interrupted\n"


_INTERRUPTING_LOADER = (
    "import sys\n"
    "class Interrupting:  # a Ctrl-C as the module loads\n"
    "    def find_spec(self, name, path=None, target=None):\n"
    "        if name == {module!r}:\n"
    "            exec('raise KeyboardInterrupt')\n"
    "sys.meta_path.insert(0, Interrupting())\n"
    "sys.argv = ['prog', '--help']\n"
)


@pytest.mark.parametrize("entry, module", [
    ("import runpy; runpy.run_module('twin', run_name='__main__')", "twin.cli"),  # python -m
    ("from twin.console import twin_main; twin_main()", "twin.cli"),  # the `twin` script
    ("from twin.console import apdl_like_main; apdl_like_main()", "apdl_like.cli"),
    ("from twin.console import twin_main; twin_main()", "platformdirs"),  # as main() starts
])
def test_ctrl_c_while_a_console_script_loads_its_commands_exits_130(tmp_path, entry, module):
    # a console script interrupted while importing its commands (their first 40-100 ms),
    # or as its main() set up the warning log: a traceback, then death by SIGINT
    source = _INTERRUPTING_LOADER.format(module=module) + entry + "\n"
    proc = _run_module(tmp_path, "load_probe", source)
    assert proc.returncode == 130, proc.stderr
    assert proc.stderr == "interrupted\n"


def test_ctrl_c_while_the_options_are_read_is_told(capsys, monkeypatch):
    # typer turns a KeyboardInterrupt while it reads the options into exit code 130 without
    # a word (a Ctrl-C some 0.1 s into `twin replay` ended so)
    def interrupted(value: int) -> int:
        raise KeyboardInterrupt

    assert _console_exit(lambda x=typer.Option(0, callback=interrupted): None, monkeypatch) == 130
    assert capsys.readouterr().err == "interrupted\n"


def _console_exit(command, monkeypatch) -> int:  # noqa: ANN001
    """The exit code of `command` run as a console script's subcommand (`probe go`)."""
    from twin.errors import run_console_script

    probe = typer.Typer()
    probe.command("go")(report_errors(command))
    probe.command("other")(lambda: None)
    monkeypatch.setattr(sys, "argv", ["probe", "go"])
    with pytest.raises(SystemExit) as exit_:
        run_console_script(probe, "probe")
    return exit_.value.code


def _ctrl_c_swallowed() -> None:
    try:  # as a library's bare `except:` around an import does
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(5)
    except BaseException:  # noqa: BLE001
        pass


def _ctrl_c_wrapped() -> None:
    try:  # as pydantic's schema builder does (SchemaError: ... KeyboardInterrupt)
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(5)
    except KeyboardInterrupt as exc:
        raise RuntimeError('Error building "literal" validator') from exc


class _InterruptedWhileCollected:
    def __del__(self) -> None:
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(5)


def _ctrl_c_unraisable() -> None:
    # a weakref callback or __del__ (importlib's module locks have one): "Exception
    # ignored in ..." and a traceback, and the Ctrl-C was lost
    _InterruptedWhileCollected()


@pytest.mark.parametrize("command", [_ctrl_c_swallowed, _ctrl_c_wrapped, _ctrl_c_unraisable])
def test_a_ctrl_c_a_library_swallows_or_wraps_is_still_told(command, capsys, monkeypatch):
    # a Ctrl-C early in `twin replay --jobs 2` was lost (the whole batch ran, exit 0), or
    # was 'internal error: SchemaError: ...' with exit code 1
    assert _console_exit(command, monkeypatch) == 130
    assert capsys.readouterr().err == "interrupted\n"
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_a_ctrl_c_does_not_outlive_the_console_script_that_saw_it(capsys, monkeypatch):
    # what a run saw of Ctrl-C is its own: a second run in the same process (a test, an
    # embedding tool) neither stops at raise_if_interrupted nor stays silent on its own Ctrl-C
    from twin.errors import raise_if_interrupted

    assert _console_exit(_ctrl_c_swallowed, monkeypatch) == 130
    raise_if_interrupted()  # outside any run: nothing pressed
    assert _console_exit(raise_if_interrupted, monkeypatch) == 0
    assert _console_exit(_ctrl_c_wrapped, monkeypatch) == 130
    assert capsys.readouterr().err == "interrupted\ninterrupted\n"


def test_simulate_at_a_standstill_tells_no_negative_zero(tmp_path):
    # 0 rpm: "nose drift axial 0.00 µm, radial -0.00 µm" (a rounding of -1e-17)
    result = CliRunner().invoke(app, ["simulate", "--speed", "0", "--minutes", "1",
                                      "--ambient", "22", "--field-every", "0",
                                      "--out", str(tmp_path / "sim")])
    assert result.exit_code == 0, result.output
    assert "nose drift axial 0.00 µm, radial 0.00 µm" in result.output, result.output
    assert "-0.00" not in result.output


def test_synth_says_the_run_length_apart_from_its_own_time(tmp_path):
    # "wrote run.csv (1801 samples, 1.4 s)" read as a 1.4 s run or a 1.4 s sample interval
    out = tmp_path / "run.csv"
    result = CliRunner().invoke(app, ["synth", "--speed", "9000", "--minutes", "2",
                                      "--ambient", "25", "--seed", "1", "--out", str(out)])
    assert result.exit_code == 0, result.output
    import re

    assert re.fullmatch(rf"wrote {re.escape(str(out))} \(121 samples over 2 min, emulated in "
                        rf"\d+\.\d s\) and {re.escape(str(tmp_path / 'run.truth.csv'))}\n",
                        result.output), result.output


@pytest.mark.parametrize("args, ends", [
    (["simulate", "--speed", "-100", "--minutes", "2", "--ambient", "20"],
     "option '--speed': speed_rpm must be a non-negative number, got -100.0; "
     "see 'twin simulate --help'"),
    (["simulate", "--speed", "100", "--minutes", "99999", "--ambient", "20"],
     "got 99999; see 'twin simulate --help'"),
])
def test_a_bad_option_value_the_command_finds_ends_as_clicks_own(tmp_path, args, ends):
    # click's usage errors (`--jobs 0`) end with "; see 'twin CMD --help'", as the README
    # promises for every bad option value; those the command itself found did not
    proc = subprocess.run([sys.executable, "-m", "twin", *args, "--out", str(tmp_path / "o")],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert proc.stderr.startswith("error: ") and proc.stderr.rstrip("\n").endswith(ends), \
        proc.stderr
    # a value read against a file keeps its file's place, without the hint
    from twin.errors import InputError, _help_hint

    assert _help_hint(InputError("beyond the run", file="run.csv", column="--time")) == ""


@pytest.mark.parametrize("usage, command", list(_leaf_commands()),
                         ids=[usage for usage, _ in _leaf_commands()])
def test_help_names_arguments_plainly_at_80_columns(usage, command):
    # typer 0.2x wrote `Usage: twin report [OPTIONS] {DIR}`, listed `RUN <list[Path]>` and
    # `DIR <path>` under Arguments, and `--time <float range>`: a Python type where
    # DESIGN.md names the argument
    import re

    from apdl_like.cli import app as apdl_app

    prog, *path = usage.split()
    root = apdl_app if prog == "apdl-like" else app
    result = CliRunner().invoke(root, [*path, "--help"], env={"COLUMNS": "80"})
    assert result.exit_code == 0, result.output
    text = result.output
    assert not re.search(r"[{}]|<list\[| range>|\[Path\]", text), text
    # an option's value is named as DESIGN.md names it (`--out DIR`, `--speed RPM`), not by
    # its Python type (typer's `--out <path>`, `--speed <float>`); choices stay `<a|b>`
    assert not re.search(r"<(path|float|int|integer|str|text)>", text), text
    assert max(len(line) for line in text.splitlines()) <= 80
    usage_line = " ".join(text.split("\n\n")[0].split())
    assert "<" not in usage_line, usage_line
    arguments = text.split("Arguments:\n")[1].split("\n\n")[0] if "Arguments:" in text else ""
    # each argument row starts with its bare name: no type after it
    for row in arguments.splitlines():
        if row.startswith("  ") and not row.startswith("   "):
            assert re.match(r"  [A-Z]+(\.\.\.)?  +\S", row) and "<" not in row.split("  ")[1], row


@pytest.mark.parametrize("path, usage, rows", [
    (["replay"], "twin replay [OPTIONS] [RUN]...",
     ["  RUN...  recorded runs", "  --out DIR ", "  --model MODEL ", "  --jobs N ",
      "  --dask ADDRESS "]),
    (["report"], "twin report [OPTIONS] DIR", ["  DIR  a replay output folder"]),
    (["train"], "twin train [OPTIONS] RUN...", ["  RUN...  Recorded runs", "--gate-runs RUN "]),
    (["snapshot"], "twin snapshot [OPTIONS] RUN", ["  --time S ", "  --out FILE.png "]),
    (["simulate"], "twin simulate [OPTIONS]",
     ["  --speed RPM ", "  --minutes M ", "  --ambient C ", "  --out DIR "]),
    (["synth"], "twin synth [OPTIONS]", ["  --seed N ", "  --profile CSV ", "  --scenario TOML "]),
    (["drift", "predict"], "twin drift predict [OPTIONS] MODEL DATA",
     ["  MODEL  Drift model file.", "  DATA   Data file"]),
    (["drift", "report"], "twin drift report [OPTIONS] MODEL DATA...", ["  DATA...  Data"]),
])
def test_help_shows_arguments_as_design_names_them(path, usage, rows):
    result = CliRunner().invoke(app, [*path, "--help"], env={"COLUMNS": "80"})
    assert result.exit_code == 0, result.output
    assert f"Usage: {usage}\n" in result.output, result.output
    for row in rows:
        assert row in result.output, (row, result.output)


@pytest.mark.parametrize("args, message", [
    (["replay", "run.csv", "--out", ""],
     "an empty argument after '--out' (an unset shell variable?); see 'twin replay --help'"),
    (["replay", "", "--out", "x"],
     "an empty argument after 'replay' (an unset shell variable?); see 'twin replay --help'"),
    (["drift", "fit", "d.csv", "--target", "a_um", "--out="],
     "option '--out' is empty (an unset shell variable?); see 'twin drift fit --help'"),
    (["simulate", "--speed", "9000", "--minutes", "1", "--ambient", "22", "--out", ""],
     "an empty argument after '--out' (an unset shell variable?); see 'twin simulate --help'"),
])
def test_an_empty_argument_is_bad_input(tmp_path, monkeypatch, capsys, args, message):
    # typer reads "" as the path '.': `twin replay run.csv --out "$DIR"` with DIR unset
    # wrote run folders, summary.json and report.html into the current folder, `twin
    # simulate` its fields there, and `twin replay ""` replayed the current folder's runs
    from twin.cli import main

    monkeypatch.chdir(tmp_path)
    (tmp_path / "run.csv").write_text("time_s,speed_rpm,ambient_C,T1_C,T2_C,T3_C,T4_C,T5_C\n"
                                      + "".join(f"{t},9000,22,22,22,22,22,22\n"
                                                for t in range(0, 200, 2)))
    monkeypatch.setattr(sys, "argv", ["twin", *args])
    with pytest.raises(SystemExit) as exit_:
        main()
    assert exit_.value.code == 2
    assert capsys.readouterr().err == f"error: {message}\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.csv"]  # nothing written


def test_a_dot_is_still_the_current_folder(tmp_path, monkeypatch):
    # only the empty text is refused: '.' written out stays a folder like any other
    from twin.cli import main

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "argv", ["twin", "simulate", "--speed", "6000", "--minutes",
                                      "0.2", "--ambient", "22", "--out", ".", "--quiet"])
    with pytest.raises(SystemExit) as exit_:
        main()
    assert exit_.value.code == 0
    assert (tmp_path / "summary.json").is_file()


def _bundled_runs_listing() -> dict[str, str]:
    import hashlib

    from twin.cli.inputs import bundled_runs_dir

    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(bundled_runs_dir().iterdir())}


@pytest.mark.parametrize("argv", [
    ["synth", "--speed", "9000", "--minutes", "3", "--ambient", "25", "--seed", "1",
     "--out", "RUNS/spindle_9000rpm_30min.csv"],
    ["synth", "--speed", "9000", "--minutes", "3", "--ambient", "25", "--seed", "1",
     "--out", "RUNS/new.csv"],
    ["synth", "--suite", "1", "--seed", "1", "--minutes", "3", "--out", "RUNS"],
    ["simulate", "--speed", "9000", "--minutes", "1", "--ambient", "25", "--out", "RUNS/sim"],
    ["replay", "--methods", "open_loop", "--out", "RUNS"],
    ["drift", "fit", "RUN", "--target", "disp_z_um", "--out", "RUNS/d.safetensors"],
    ["drift", "report", "MODEL", "RUN", "--out", "RUNS/report"],
    ["mesh", "--out", "RUNS/reference_spindle.msh"],
    ["snapshot", "RUN", "--time", "60", "--out", "RUNS/s.png"],
])
@pytest.mark.parametrize("runs", ["package", "repository"])
def test_the_bundled_runs_are_replaced_only_on_purpose(argv, runs, tmp_path, monkeypatch):
    # `twin synth --out examples/runs/spindle_9000rpm_30min.csv` replaced a run every
    # default replay reads, without a word; `make examples` still writes them
    from twin.cli.inputs import bundled_runs_dir
    from twin.data import bundled_path

    monkeypatch.chdir(tmp_path)
    folder = bundled_path("runs") if runs == "package" else bundled_runs_dir()
    run = str(folder / "spindle_9000rpm_30min.csv")
    model = str(_bundled_model())
    before = _bundled_runs_listing()
    argv = [a.replace("RUNS", str(folder)) for a in argv]
    argv = [run if a == "RUN" else model if a == "MODEL" else a for a in argv]
    result = CliRunner().invoke(app, argv)
    assert result.exit_code == 2, result.output
    out = argv[argv.index("--out") + 1]
    assert result.output == (
        f"error: {out}, option '--out': lies in the bundled runs ({bundled_runs_dir()}), "
        "which every `twin replay` without RUN reads: write elsewhere"
        + (", or pass --replace-bundled-runs to replace them (as `make examples` does)"
           if argv[0] == "synth" else "") + "\n")
    assert _bundled_runs_listing() == before
    assert list(tmp_path.iterdir()) == []


def test_synth_replaces_a_bundled_run_with_the_option_only(tmp_path, monkeypatch):
    import pathlib

    from twin.cli.inputs import bundled_runs_dir
    from twin.io.destinations import check_not_bundled_runs

    monkeypatch.chdir(tmp_path)
    synth = ["synth", "--speed", "9000", "--minutes", "3", "--ambient", "25", "--seed", "1"]
    # the option is for the bundled runs only: elsewhere its writer may think it updates them
    result = CliRunner().invoke(app, [*synth, "--out", "r.csv", "--replace-bundled-runs"])
    assert result.exit_code == 2 and result.output.count("\n") == 1, result.output
    assert "option '--replace-bundled-runs': is for an --out in the bundled runs" \
        in result.output
    assert list(tmp_path.iterdir()) == []
    # what `make examples` passes (examples/make_runs.py): allowed, for a run and a suite
    check_not_bundled_runs(bundled_runs_dir() / "spindle_9000rpm_30min.csv", replace=True)
    check_not_bundled_runs(bundled_runs_dir(), replace=True)
    check_not_bundled_runs(tmp_path / "r.csv")  # elsewhere, without the option: allowed
    assert "--replace-bundled-runs" in CliRunner().invoke(app, ["synth", "--help"]).output
    make_runs = pathlib.Path(__file__).resolve().parents[1] / "examples" / "make_runs.py"
    assert "--replace-bundled-runs" in make_runs.read_text()
