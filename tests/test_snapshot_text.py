"""What a snapshot states beside its colours (twin.loop.snapshot): the run, method, time
and the speed then, where the nose is, that a displacement picture is not deformed, and
round scales on the flat section."""

from __future__ import annotations

import os
from types import SimpleNamespace

import numpy as np
import pytest

from twin.loop.snapshot import nice_axis, render_snapshot, snapshot_title

os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")


def test_the_title_gives_the_time_in_minutes_and_the_speed_then():
    run = SimpleNamespace(time_s=np.array([0.0, 600.0, 1080.0, 1440.0]),
                          speed_rpm=np.array([8000.0, 12000.0, 0.0, 6000.0]))
    assert snapshot_title("r", "bpnn", 1200.0, run) == (
        "r · bpnn · t = 1200 s (20.0 min) · stopped (0 rpm)")
    assert snapshot_title("r", "ratio", 900.0, run).endswith("(15.0 min) · 12000 rpm")
    assert snapshot_title("r", "ratio", 1080.0, run).endswith("stopped (0 rpm)")  # from then
    nan = SimpleNamespace(time_s=np.array([0.0]), speed_rpm=np.array([np.nan]))
    assert snapshot_title("r", "m", 60.0, nan) == "r · m · t = 60 s (1.0 min)"


@pytest.mark.parametrize(("high", "expected"), [
    (155.0, (200.0, 5)), (450.0, (500.0, 6)), (37.0, (40.0, 5)), (100.0, (100.0, 6)),
])
def test_the_section_scale_ends_on_a_round_tick(high, expected):
    # the r axis read 0, 38.8, 77.5, 116.2, 155
    top, labels = nice_axis(high)
    assert (top, labels) == expected
    step = top / (labels - 1)
    assert step in (10.0, 20.0, 50.0, 100.0)


@pytest.mark.parametrize("field", ["temperature", "displacement"])
def test_a_snapshot_marks_the_nose_and_says_a_displacement_shape_is_undeformed(
        spindle_model, tmp_path, monkeypatch, field):
    import pyvista as pv

    said: list[str] = []
    add_text, add_labels = pv.Plotter.add_text, pv.Plotter.add_point_labels

    def text(self, value, *args, **kwargs):
        said.append(value)
        return add_text(self, value, *args, **kwargs)

    def labels(self, points, values, *args, **kwargs):
        said.extend(values)
        return add_labels(self, points, values, *args, **kwargs)

    monkeypatch.setattr(pv.Plotter, "add_text", text)
    monkeypatch.setattr(pv.Plotter, "add_point_labels", labels)
    T = np.linspace(25.0, 40.0, spindle_model.n_dofs)
    render_snapshot(spindle_model, T, tmp_path / "s.png", field=field, title="run · m",
                    T_initial_C=22.0, section=True, window_size=(300, 200))
    assert "nose" in said
    undeformed = "shape undeformed; colour: thermal displacement since the uniform start " \
                 "at 22.0 °C"
    assert any(undeformed in s for s in said) == (field == "displacement"), said
