"""`twin synth --record-from M`: a recording begun on a warm spindle, M minutes into the
emulated run (the replay starts it from a fitted field, `twin.loop.start_field`)."""

from __future__ import annotations

import numpy as np
from typer.testing import CliRunner

from twin.cli import app
from twin.runs import read_run

ARGS = ["synth", "--speed", "9000", "--minutes", "6", "--ambient", "22", "--seed", "7",
        "--quiet"]


def test_the_recording_is_the_runs_tail_with_time_and_probes_zeroed_where_it_starts(tmp_path):
    whole = CliRunner().invoke(app, [*ARGS, "--out", str(tmp_path / "whole.csv")])
    assert whole.exit_code == 0, whole.output
    tail = CliRunner().invoke(app, [*ARGS, "--record-from", "2.5",
                                    "--out", str(tmp_path / "tail.csv")])
    assert tail.exit_code == 0, tail.output
    full, late = read_run(tmp_path / "whole.csv"), read_run(tmp_path / "tail.csv")
    from_s = 150.0
    keep = full.time_s >= from_s
    np.testing.assert_allclose(late.time_s, full.time_s[keep] - from_s, atol=1e-9)
    np.testing.assert_allclose(late.T_C, full.T_C[keep], atol=1e-4)  # CSV digits
    assert late.metadata["record_from_s"] == "150"
    assert "warm start" in late.metadata["displacement_reference"]
    # the probes read their change from where the logger started (the true drift there),
    # with their noise: the same offset on every sample
    offset = full.disp_um[keep, 2] - late.disp_um[:, 2]
    assert np.ptp(offset) < 2e-4 and offset[0] > 1.0
    # a recording begun warm: its first readings spread far more than a cold start's
    assert np.ptp(late.T_C[0]) > 3.0 and np.ptp(full.T_C[0]) < 0.5
    lines = [x for x in (tmp_path / "tail.truth.csv").read_text().splitlines()
             if not x.startswith("#")]
    first = dict(zip(lines[0].split(","), map(float, lines[1].split(",")), strict=True))
    assert first["time_s"] == 0.0 and abs(first["disp_z_true_um"]) < 1e-9


def test_a_recording_that_leaves_less_than_two_windows_is_refused(tmp_path):
    result = CliRunner().invoke(app, [*ARGS, "--record-from", "4.5",
                                      "--out", str(tmp_path / "x.csv")])
    assert result.exit_code == 2
    assert "--record-from" in result.output and "Traceback" not in result.output
    assert not list(tmp_path.iterdir())
    suite = CliRunner().invoke(app, ["synth", "--suite", "2", "--seed", "1", "--record-from",
                                     "3", "--out", str(tmp_path / "s")])
    assert suite.exit_code == 2 and "--record-from" in suite.output
