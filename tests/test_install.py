"""A non-editable install carries its data: the wheel holds the default mesh and spec,
the example runs, the default model and the report templates, and `twin replay` with no
RUN works from an unrelated folder without the source tree."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def _run(args: list[str], **kwargs) -> subprocess.CompletedProcess:  # noqa: ANN003
    return subprocess.run(args, capture_output=True, text=True, timeout=900, **kwargs)


@pytest.mark.slow
def test_wheel_install_replays_the_bundled_runs(tmp_path):
    wheels, target, work = tmp_path / "wheels", tmp_path / "site", tmp_path / "elsewhere"
    work.mkdir()
    # build from a copy: an in-tree build leaves build/ and *.egg-info in the checkout
    source = tmp_path / "source"
    shutil.copytree(ROOT, source, symlinks=True, ignore=shutil.ignore_patterns(
        ".git", ".venv", "build", "*.egg-info", "__pycache__", ".pytest_cache", "out",
        "tests", "docs", "bench"))
    built = _run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
                  "--quiet", "--wheel-dir", str(wheels), str(source)], cwd=tmp_path)
    assert built.returncode == 0, built.stderr
    (wheel,) = wheels.glob("spindle_twin-*.whl")
    installed = _run([sys.executable, "-m", "pip", "install", "--no-deps", "--quiet",
                      "--target", str(target), str(wheel)], cwd=tmp_path)
    assert installed.returncode == 0, installed.stderr

    data = target / "twin" / "data"
    for name in ("meshes/reference_spindle.toml", "meshes/reference_spindle.msh",
                 "correction_model.safetensors"):
        file = data / name
        assert file.is_file() and not file.is_symlink(), name
        assert file.read_bytes() == (ROOT / "twin" / "data" / name).read_bytes(), name
    assert (target / "twin" / "io" / "templates" / "replay_report.html.j2").is_file()
    assert not (target / "meshes").exists()  # no top-level `meshes` package any more
    bundled = sorted(p.stem for p in (ROOT / "examples" / "runs").glob("*.csv")
                     if not p.name.endswith(".truth.csv"))

    # only the install on the path (the shared venv provides the dependencies)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update(PYTHONPATH=str(target), PYVISTA_OFF_SCREEN="true")
    where = _run([sys.executable, "-c", "import twin; print(twin.__file__)"], cwd=work, env=env)
    assert Path(where.stdout.strip()).is_relative_to(target), where.stdout + where.stderr

    out = work / "out"
    replay = _run([sys.executable, "-m", "twin", "replay", "--out", str(out), "--methods",
                   "bpnn", "--snapshots", "none", "--quiet"], cwd=work, env=env)
    assert replay.returncode == 0, replay.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert sorted(r["run"] for r in summary["runs"]) == bundled
    assert not summary.get("failed")
    for run in summary["runs"]:
        assert 90.0 < run["methods"]["bpnn"]["temperature_accuracy_pct"] <= 100.0, run["run"]
    assert (out / "report.html").stat().st_size > 10_000
    assert sorted(p.name for p in work.iterdir()) == ["out"]  # nothing written beside it
