"""What the replay report's figures show a reader (twin.loop.report): every panel says
which sensor and where, every axis its unit, the stops and speed changes are visible,
the title names the run, and no text is cut off at the figure's edge."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from twin.contract import SENSOR_LOCATIONS, SENSOR_NAMES
from twin.loop.report import (
    _read_csv,
    drift_figure,
    speed_profile,
    speed_segments,
    temperature_figure,
)

METHODS = ("open_loop", "ratio", "estimator")
SPEEDS = [8000] * 5 + [0] * 3 + [6000] * 2  # ten windows: a stop at 5..8 min


def _write(path, header, rows):
    with open(path, "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        w.writerows(rows)


@pytest.fixture()
def run(tmp_path):
    """keypoints.csv and corrections.csv of a ten-minute run with a stop, T2 dead."""
    kp_head = ["time_s", "method", *[f"{s}_twin_C" for s in SENSOR_NAMES],
               *[f"{s}_meas_C" for s in SENSOR_NAMES], "disp_z_twin_um", "disp_z_meas_um",
               *[f"{s}_twin_{b}_C" for s in SENSOR_NAMES for b in ("lo", "hi")],
               "disp_z_twin_lo_um", "disp_z_twin_hi_um"]
    rows = []
    for m in METHODS:
        for t in range(4, 601, 4):
            T = [25 + t / 100 + i for i in range(5)]
            meas = [f"{v + 0.1:.3f}" if i != 1 else "" for i, v in enumerate(T)]
            band = [f"{v + d:.3f}" if m == "estimator" else "" for v in T for d in (-0.3, 0.3)]
            dz = [f"{t / 60:.3f}" if m == "estimator" else "" for _ in (0, 1)]
            rows.append([t, m, *[f"{v:.3f}" for v in T], *meas, f"{t / 60:.3f}",
                         f"{t / 61:.3f}", *band, *dz])
    _write(tmp_path / "keypoints.csv", kp_head, rows)
    corr_head = ["window", "method", "start_s", "speed_rpm", "H_front", "H_rear",
                 "C_H_front", "C_H_rear", "C_C_front", "C_C_rear"]
    rows = [[k, m, 60 * k, rpm, 100.0 if rpm else 0.0, 90.0 if rpm else 0.0, 1.1, 0.9, 1.2, 0.8]
            for m in METHODS for k, rpm in enumerate(SPEEDS)]
    _write(tmp_path / "corrections.csv", corr_head, rows)
    return _read_csv(tmp_path / "keypoints.csv"), _read_csv(tmp_path / "corrections.csv")


def _texts(fig):
    out = [fig._suptitle.get_text()] if fig._suptitle else []
    for ax in fig.axes:
        out += [ax.get_title(), ax.get_xlabel(), ax.get_ylabel()]
        out += [t.get_text() for t in ax.texts]
    return out


def _spans(ax):
    """(x0, x1) of the shaded vertical spans (axvspan) of an axes, in data units."""
    from matplotlib.patches import Polygon, Rectangle
    spans = []
    for p in ax.patches:
        if isinstance(p, Rectangle):
            spans.append((float(p.get_x()), float(p.get_x() + p.get_width())))
        elif isinstance(p, Polygon):  # matplotlib before 3.9
            xy = np.asarray(p.get_xy())
            spans.append((float(xy[:, 0].min()), float(xy[:, 0].max())))
    return spans


def test_speed_segments_and_profile_say_the_speeds_and_the_stop(run):
    _, corr = run
    segments = speed_segments(corr)
    assert segments == [(0.0, 300.0, 8000.0), (300.0, 480.0, 0.0), (480.0, 600.0, 6000.0)]
    assert speed_profile(segments) == "8000 → stop → 6000 rpm"
    many = [(60.0 * k, 60.0 * k + 60, 3000.0 + 100 * (k % 9) if k % 7 else 0.0)
            for k in range(30)]
    assert speed_profile(many) == "3000–3800 rpm in 30 stretches, 5 stops"


def test_temperature_panels_name_sensor_place_and_units_and_shade_the_stop(run):
    kp, corr = run
    fig = temperature_figure(kp, corr, "my_run")
    texts = _texts(fig)
    for s in SENSOR_NAMES:
        assert f"{s}: {SENSOR_LOCATIONS[s]}" in texts
    assert "temperature [°C]" in texts
    assert texts.count("time [min]") == 5
    title = fig._suptitle.get_text()
    assert "my_run" in title and "window 8000 → stop → 6000 rpm" in title
    assert "grey: stopped" in title
    for ax in fig.axes:  # the stop, 5..8 min, shaded on every panel
        assert (5.0, 8.0) in _spans(ax)
        assert {line.get_xdata()[0] for line in ax.get_lines()
                if line.get_linestyle() == ":"} == {5.0, 8.0}
    # one legend row under the title, none inside a panel to cover the curves
    assert all(ax.get_legend() is None for ax in fig.axes)
    (legend,) = fig.legends
    assert [t.get_text() for t in legend.get_texts()] == [
        "measured", *METHODS, "estimator 90 % band"]
    # T2 has no valid sample: its panel says so rather than showing nothing unexplained
    assert any("no valid measurement" in t.get_text() for t in fig.axes[1].texts)
    assert not any("no valid measurement" in t.get_text() for t in fig.axes[0].texts)


def test_drift_figure_has_units_a_factor_axis_and_a_legend_beside_the_axes(run):
    kp, corr = run
    fig = drift_figure(kp, corr, "my_run")
    ax1, ax2 = fig.axes
    assert ax1.get_ylabel() == "drift [µm]" and ax1.get_xlabel() == "time [min]"
    assert ax2.get_ylabel() == "factor [–]" and "time [min]" in ax2.get_xlabel()
    labels = [t.get_text() for t in ax2.get_legend().get_texts()]
    assert "ratio: bearing heat front" in labels and "estimator: contact resistance rear" in labels
    assert ax2.get_legend().get_bbox_to_anchor().transformed(ax2.transAxes.inverted()).x0 > 1
    assert (5.0, 8.0) in _spans(ax1) and (5.0, 8.0) in _spans(ax2)
    # the factors share the drift's time axis: window k drawn from k minutes
    x = [line.get_xdata() for line in ax2.get_lines() if line.get_label().startswith("ratio")]
    assert list(x[0][:3]) == [0.0, 1.0, 2.0]


@pytest.mark.parametrize("which", ["temperature", "drift"])
def test_no_text_is_cut_off_at_the_figures_edge(run, which):
    from twin.loop.report import _png
    kp, corr = run
    fig = (temperature_figure if which == "temperature" else drift_figure)(kp, corr, "r" * 40)
    _png(fig)  # drawn as the report draws it (its dpi and margins)
    renderer = fig.canvas.get_renderer()
    width, height = fig.bbox.width, fig.bbox.height
    artists = [fig._suptitle, *fig.legends]
    for ax in fig.axes:
        artists += [ax.title, ax.xaxis.label, ax.yaxis.label, *ax.texts]
        if ax.get_legend():
            artists.append(ax.get_legend())
    for a in artists:
        box = a.get_window_extent(renderer)
        assert box.x0 >= 0 and box.y0 >= 0 and box.x1 <= width and box.y1 <= height, (
            a, box, width, height)


@pytest.mark.parametrize("which", ["temperature", "drift"])
def test_the_title_the_legend_row_and_the_panel_titles_do_not_overlap(run, which):
    from twin.loop.report import _png
    kp, corr = run
    fig = (temperature_figure if which == "temperature" else drift_figure)(kp, corr, "run")
    _png(fig)
    renderer = fig.canvas.get_renderer()
    title = fig._suptitle.get_window_extent(renderer)
    legend = fig.legends[0].get_window_extent(renderer)
    assert legend.y1 <= title.y0
    for ax in fig.axes:
        assert ax.title.get_window_extent(renderer).y1 <= legend.y0


def test_figures_drawn_in_a_replays_staging_folder_name_the_run(run, tmp_path, monkeypatch):
    # a replay draws its figures in `.NAME.PID.HEX.partial` before renaming it NAME: the
    # titles read ".spindle_10800rpm_30min.20170.7619aab9.partial: T1–T5 ..."
    import shutil

    import twin.loop.report
    from twin.io.atomic import output_name, temporary_name
    from twin.loop.report import render_run_plots

    staging = tmp_path / temporary_name("spindle_9000rpm_30min", ".partial")
    staging.mkdir()
    for name in ("keypoints.csv", "corrections.csv"):
        shutil.copy(tmp_path / name, staging / name)
    titles = []
    draw = twin.loop.report._png
    monkeypatch.setattr(twin.loop.report, "_png",
                        lambda fig: titles.append(fig._suptitle.get_text()) or draw(fig))
    render_run_plots(staging)
    assert len(titles) == 2
    assert all(t.startswith("spindle_9000rpm_30min: ") for t in titles), titles
    assert output_name("run.v2") == "run.v2"  # any other name is itself


def test_open_loop_alone_says_it_has_no_factors_and_draws_no_empty_legend(run, recwarn):
    # the speed marks are lines too: an open-loop run with a speed change drew an empty
    # legend ("No artists with labels found to put in legend")
    kp, corr = run
    keep = np.array(kp["method"]) == "open_loop"
    only = type(kp)(kp.path, {k: list(np.array(v)[keep]) for k, v in kp.items()})
    fig = drift_figure(only, corr, "run")
    ax2 = fig.axes[1]
    assert ax2.get_legend() is None
    assert [t.get_text() for t in ax2.texts] == ["no correction (open loop only)"]
    assert not [w for w in recwarn if "legend" in str(w.message)]
