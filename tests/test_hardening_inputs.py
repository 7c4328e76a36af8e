"""Issue 14 regressions on exit codes and messages (defects 6, 12, 15): bad input is an
`InputError` (exit 2) naming the file, row and field; synth writes only what replay reads;
warnings go to the log."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from tests.test_fuzz_inputs import model_with_metadata
from twin.cli import app
from twin.correction.modelfile import load_model
from twin.errors import InputError
from twin.plant.scenario import parse_scenario
from twin.runs import read_run
from twin.spindle.spec import load_spec


def cli(*args):
    result = CliRunner().invoke(app, [str(a) for a in args])
    assert "Traceback" not in result.output
    return result


def with_metadata(tmp_path, change):
    path = tmp_path / "m.safetensors"
    path.write_bytes(model_with_metadata(change))
    return path


@pytest.mark.parametrize(("key", "value"), [("hidden_sizes", 5), ("r2", {"heat_front": 5}),
                                            ("training_runs", 7), ("config", [])])
def test_defect6_model_metadata_of_wrong_type(tmp_path, key, value):
    path = with_metadata(tmp_path, lambda m: m.__setitem__(key, value))
    with pytest.raises(InputError, match=f"m.safetensors, metadata field '{key}") as info:
        load_model(path)
    assert info.value.file == str(path)
    result = cli("model-info", path)
    assert result.exit_code == 2 and "m.safetensors" in result.output


def test_defect15_model_checksum_is_documented_as_corruption_not_forgery():
    import twin.correction.modelfile as modelfile

    assert "detects corruption, not forgery" in modelfile.__doc__


@pytest.mark.parametrize("args", [
    ["--speed", "inf"], ["--speed", "nan"], ["--speed", "20000"], ["--coolant", "nan"],
    ["--coolant", "150"], ["--coolant", "50"], ["--seed=-1"], ["--ambient", "50"],
    ["--ambient", "nan"], ["--minutes", "nan"],
])
def test_defect6_and_12_synth_arguments_refused_before_any_work(tmp_path, args):
    base = {"--speed": "9000", "--minutes": "3", "--ambient": "25", "--seed": "1"}
    given = args[0].split("=")[0]
    argv = ["synth", "--out", tmp_path / "r.csv", *args]
    for key, value in base.items():
        if key != given:
            argv += [key, value]
    result = cli(*argv)
    assert result.exit_code == 2, result.output
    assert given in result.output or "seed" in result.output
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(("toml", "where"), [
    ("[coolant]\ntime_s = [0, inf]\ninlet_C = [22, 23]\n", "coolant.time_s"),
    ("[faults]\nspikes = [{sensor = \"T1\", time_s = 60, size = inf}]\n", "faults.spikes"),
    ("[faults]\nspikes = [{sensor = \"T1\", time_s = 60, size = 1e300}]\n", "faults.spikes"),
    ("a = " + "[" * 5000 + "]" * 5000 + "\n", None),
])
def test_defect6_and_12_scenario_values_synth_cannot_write(toml, where):
    with pytest.raises(InputError) as info:
        parse_scenario(toml, "s.toml")
    assert info.value.file == "s.toml"
    assert where is None or info.value.column.startswith(where)


def test_deeply_nested_spec_toml_refused(tmp_path):
    spec = tmp_path / "spec.toml"
    spec.write_text("a = " + "[" * 5000 + "]" * 5000 + "\n")
    with pytest.raises(InputError, match="nested too deeply"):
        load_spec(spec)


def test_defect12_synth_refuses_dropouts_that_empty_every_sensor(tmp_path):
    """A scenario that empties every thermocouple makes a run replay refuses; synth says so
    and writes nothing.  One emptied sensor is a dead channel replay leaves out."""
    scenario = tmp_path / "s.toml"
    every = ", ".join(f'{{sensor = "T{i}", start_s = 0, end_s = 100000}}' for i in range(1, 6))
    scenario.write_text(f"[faults]\ndropouts = [{every}]\n")
    result = cli("synth", "--speed", 9000, "--minutes", 2, "--ambient", 25, "--seed", 1,
                 "--scenario", scenario, "--out", tmp_path / "r.csv", "--quiet")
    assert result.exit_code == 2 and "s.toml" in result.output and "T1_C" in result.output
    assert "refused by replay" in result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]
    scenario.write_text('[faults]\ndropouts = [{sensor = "T4", start_s = 0, end_s = 100000}]\n')
    result = cli("synth", "--speed", 9000, "--minutes", 2, "--ambient", 25, "--seed", 1,
                 "--scenario", scenario, "--out", tmp_path / "r.csv", "--quiet")
    assert result.exit_code == 0, result.output
    run = read_run(tmp_path / "r.csv")
    assert not run.valid["T4_C"].any()
    assert [f["kind"] for f in run.quality if f["column"] == "T4_C"] == ["dead"]


def test_defect15_warnings_go_to_the_log_not_the_terminal(tmp_path):
    code = ("import warnings, numpy as np\n"
            "from twin.log import send_warnings_to_log, send_vtk_messages_to_log\n"
            "send_warnings_to_log()\n"
            "np.mean(np.array([]))\n"
            "send_vtk_messages_to_log()\n"
            "from vtkmodules.vtkCommonCore import vtkLogger\n"
            "vtkLogger.Log(vtkLogger.VERBOSITY_WARNING, 'x.cxx', 1, 'bad X server connection')\n")
    _runs_silently(code, log_dir=tmp_path)
    log = (tmp_path / "twin.log").read_text()
    assert "Mean of empty slice" in log and "bad X server connection" in log



def test_vtk_errors_pyvista_logs_go_to_the_log_not_the_terminal(tmp_path):
    # pyvista sends VTK's errors to the root logger, which printed them on the terminal
    # ('ERROR:root:Algorithm vtkPythonAlgorithm ... returned failure' and the request's
    # eight lines, after a Ctrl-C during a snapshot)
    code = ("from twin.log import send_warnings_to_log\n"
            "send_warnings_to_log()\n"
            "import pyvista\n"
            "from vtkmodules.vtkCommonCore import vtkOutputWindow\n"
            "vtkOutputWindow.GetInstance().DisplayErrorText('Algorithm returned failure')\n")
    _runs_silently(code, log_dir=tmp_path)
    assert "Algorithm returned failure" in (tmp_path / "twin.log").read_text()

def test_a_log_file_that_cannot_be_opened_drops_the_warnings(tmp_path):
    # the log folder was there but twin.log could not be opened (a read-only home in CI;
    # here a folder of that name): the first warning ended the command with exit 1
    (tmp_path / "twin.log").mkdir()
    code = ("import numpy as np\n"
            "from twin.log import send_warnings_to_log\n"
            "send_warnings_to_log()\n"
            "np.mean(np.array([]))\n"
            "np.mean(np.array([]))\n")
    _runs_silently(code, log_dir=tmp_path)


def _runs_silently(code: str, log_dir: Path) -> None:
    """Run Python `code` in a fresh process logging to `log_dir`: exit 0, nothing on stderr."""
    env = {**os.environ, "TWIN_LOG_DIR": str(log_dir)}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=env, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""


@pytest.mark.parametrize("args", [
    ["simulate", "--speed", 9000, "--minutes", "1e9", "--ambient", 25, "--out", "OUT"],
    ["simulate", "--speed", 9000, "--minutes", "nan", "--ambient", 25, "--out", "OUT"],
    ["simulate", "--speed", 9000, "--minutes", 2, "--ambient", 25, "--size-factor", "1e-6",
     "--out", "OUT"],
    ["mesh", "--size-factor", "1e-6", "--out", "OUT.msh"],
    ["mesh", "--size-factor", "nan", "--out", "OUT.msh"],
    ["replay", "--jobs", 100000, "--methods", "open_loop", "--out", "OUT"],
])
def test_defect5_unbounded_work_from_arguments_refused(tmp_path, args):
    result = cli(*[str(tmp_path / "OUT") + a[3:] if isinstance(a, str) and a.startswith("OUT")
                   else a for a in args])
    assert result.exit_code == 2, result.output
    assert list(tmp_path.iterdir()) == []


def test_synth_refuses_an_ambient_from_both_profile_and_scenario(tmp_path):
    # the scenario's [ambient] won and the profile's ambient_C column was read for nothing
    profile, scenario = tmp_path / "p.csv", tmp_path / "s.toml"
    profile.write_text("time_s,speed_rpm,ambient_C\n0,6000,24\n60,9000,26\n")
    scenario.write_text("[ambient]\ntime_s = [0]\nambient_C = [20.0]\n")
    args = ["synth", "--profile", profile, "--minutes", 2, "--ambient", 25, "--seed", 1,
            "--quiet"]
    result = cli(*args, "--scenario", scenario, "--out", tmp_path / "r.csv")
    assert result.exit_code == 2, result.output
    assert "s.toml" in result.output and "'ambient'" in result.output
    assert "p.csv" in result.output and not (tmp_path / "r.csv").exists()
    # either one alone is fine
    scenario.write_text("[coolant]\ntime_s = [0]\ninlet_C = [20.0]\n")
    result = cli(*args, "--scenario", scenario, "--out", tmp_path / "r2.csv")
    assert result.exit_code == 0, result.output


def test_synth_profile_with_an_ambient_column(tmp_path):
    profile = tmp_path / "p.csv"
    profile.write_text("time_s,speed_rpm,ambient_C\n0,6000,24\n60,9000,25\n")
    result = cli("synth", "--profile", profile, "--minutes", 2, "--ambient", 25, "--seed", 1,
                 "--out", tmp_path / "r.csv", "--quiet")
    assert result.exit_code == 0, result.output
    # 50 °C is above the plausible range: refused where it is written (row and column),
    # not after the run was emulated as a run replay would read as Fahrenheit
    profile.write_text("time_s,speed_rpm,ambient_C\n0,6000,25\n60,6000,50\n")
    result = cli("synth", "--profile", profile, "--minutes", 2, "--ambient", 25, "--seed", 1,
                 "--out", tmp_path / "r2.csv", "--quiet")
    assert result.exit_code == 2 and "p.csv" in result.output, result.output
    assert "3" in result.output and "ambient_C" in result.output and "-40..45" in result.output
    assert not (tmp_path / "r2.csv").exists()


def test_twin_mesh_never_replaces_the_bundled_mesh_with_another(tmp_path):
    """`twin mesh --out meshes/reference_spindle.msh --size-factor 2` overwrote the mesh
    every replay of the reference spindle reads, without a word."""
    from twin.spindle.model import DEFAULT_MESH_PATH
    from twin.spindle.spec import DEFAULT_SPEC_PATH

    before = DEFAULT_MESH_PATH.read_bytes()
    link = tmp_path / "link.msh"
    link.symlink_to(DEFAULT_MESH_PATH)
    spec = tmp_path / "spec.toml"  # another spec file, even with the same text
    spec.write_bytes(DEFAULT_SPEC_PATH.read_bytes())
    for extra in (("--size-factor", 2), ("--spec", spec)):
        for out in (DEFAULT_MESH_PATH, link):
            result = cli("mesh", "--out", out, *extra, "--quiet")
            assert result.exit_code == 2, result.output
            assert "bundled mesh" in result.output and "--out" in result.output
    assert DEFAULT_MESH_PATH.read_bytes() == before


def test_train_epochs_are_bounded(tmp_path):
    result = cli("train", "examples/runs/spindle_9000rpm_30min.csv", "--out",
                 tmp_path / "m.safetensors", "--epochs", 10**20)
    assert result.exit_code == 2 and "--epochs" in result.output
    assert list(tmp_path.iterdir()) == []
