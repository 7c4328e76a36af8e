"""`twin replay --fields every|end|none`: which window ends get field files."""

from __future__ import annotations

import os

import pytest
from typer.testing import CliRunner

from twin.cli import app

os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")
METHODS = "open_loop,ratio"


@pytest.fixture(scope="module")
def run(tmp_path_factory, spindle_model):
    from tests.test_replay import make_recorded_run

    return make_recorded_run(tmp_path_factory.mktemp("runs") / "hot.csv", spindle_model,
                             minutes=3)


def replay(run, out, *options):
    return CliRunner().invoke(app, ["replay", str(run), "--out", str(out), "--methods",
                                    METHODS, "--quiet", *options])


@pytest.fixture(scope="module")
def every(run, tmp_path_factory):
    out = tmp_path_factory.mktemp("every")
    result = replay(run, out, "--snapshots", "none")
    assert result.exit_code == 0, result.output
    return out / "hot"


def _vtus(run_dir):
    return sorted(p.name for p in (run_dir / "fields").glob("*.vtu"))


def test_default_writes_every_window_end(every):
    assert _vtus(every) == [f"ratio_t{t:05d}s.vtu" for t in (60, 120, 180)]
    pvd = (every / "fields.pvd").read_text()
    assert pvd.count("<DataSet ") == 3


def test_fields_end_writes_the_last_window_only_with_the_same_results(run, every, tmp_path):
    result = replay(run, tmp_path, "--fields", "end", "--snapshots", "every")
    assert result.exit_code == 0, result.output
    folder = tmp_path / "hot"
    assert _vtus(folder) == ["ratio_t00180s.vtu"]
    pvd = (folder / "fields.pvd").read_text()
    assert pvd.count("<DataSet ") == 1 and 'file="fields/ratio_t00180s.vtu"' in pvd
    # the one file is the one `every` wrote at that time, byte for byte
    assert (folder / "fields" / "ratio_t00180s.vtu").read_bytes() == \
        (every / "fields" / "ratio_t00180s.vtu").read_bytes()
    # snapshots are drawn from the replay's fields, not from the field files: every window
    assert sorted(p.name for p in (folder / "snapshots").glob("*.png")) == \
        [f"ratio_t{t:05d}s.png" for t in (60, 120, 180)]
    for name in ("keypoints.csv", "corrections.csv", "accuracy.json"):
        assert (folder / name).read_bytes() == (every / name).read_bytes(), name


def test_fields_none_writes_no_field_file_and_snapshots_still(run, every, tmp_path):
    result = replay(run, tmp_path, "--fields", "none", "--snapshots", "end")
    assert result.exit_code == 0, result.output
    folder = tmp_path / "hot"
    assert not (folder / "fields").exists() and not (folder / "fields.pvd").exists()
    assert [p.name for p in (folder / "snapshots").glob("*.png")] == ["ratio_t00180s.png"]
    # the decks and their start states are the deck interface: written as before
    assert sorted(p.name for p in (folder / "decks").rglob("*")) == \
        sorted(p.name for p in (every / "decks").rglob("*"))
    for name in ("keypoints.csv", "corrections.csv", "accuracy.json"):
        assert (folder / name).read_bytes() == (every / name).read_bytes(), name
    assert (tmp_path / "report.html").is_file()


def test_resume_replays_a_run_whose_fields_were_not_written(run, tmp_path):
    # a folder replayed with --fields none lacks what --fields every asks for: --resume
    # must not keep it; one replayed as asked is kept
    assert replay(run, tmp_path, "--fields", "none", "--snapshots", "none").exit_code == 0
    folder = tmp_path / "hot"
    assert replay(run, tmp_path, "--resume", "--snapshots", "none").exit_code == 0
    assert len(_vtus(folder)) == 3
    stamp = (folder / "accuracy.json").stat().st_mtime_ns
    assert replay(run, tmp_path, "--resume", "--snapshots", "none").exit_code == 0
    assert (folder / "accuracy.json").stat().st_mtime_ns == stamp
    # and the reverse: asked for none, a folder with every field is replayed as asked
    assert replay(run, tmp_path, "--resume", "--fields", "none",
                  "--snapshots", "none").exit_code == 0
    assert not (folder / "fields").exists()
    stamp = (folder / "accuracy.json").stat().st_mtime_ns
    assert replay(run, tmp_path, "--resume", "--fields", "none",
                  "--snapshots", "none").exit_code == 0
    assert (folder / "accuracy.json").stat().st_mtime_ns == stamp


def test_a_resume_token_of_the_default_fields_says_nothing_of_them(run):
    # the default --fields adds nothing to the token, as before --fields existed (those
    # folders are replayed again all the same: their token names no code)
    from twin.loop.runfiles import resume_token

    assert "fields" not in resume_token(run, ["ratio"], None)
    assert resume_token(run, ["ratio"], None, fields="end")["fields"] == "end"


def test_bad_fields_value_is_one_line_and_exit_2(run, tmp_path):
    result = replay(run, tmp_path / "x", "--fields", "last")
    assert result.exit_code == 2
    assert "--fields" in result.output and "Traceback" not in result.output
    assert not (tmp_path / "x").exists()
    help_text = CliRunner().invoke(app, ["replay", "--help"]).output
    assert "--fields" in help_text
