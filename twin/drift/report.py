"""The drift report: measured vs predicted with the 90 % band, residuals, sensor ranking.

One self-contained HTML page (`report.html`, figures embedded as PNG data URIs) beside
`metrics.json` in the output folder.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from twin.drift.data import DriftData
from twin.drift.model import DriftModel
from twin.drift.output import drift_metrics, write_metrics
from twin.io.atomic import write_text
from twin.io.figures import mark_speeds, new_figure, png_bytes, speed_stretches
from twin.io.html_pages import png_data_uri, render_page

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def _png(fig: Figure) -> bytes:
    return png_bytes(fig, dpi=90)


def _figures(model: DriftModel, data: DriftData, mean: np.ndarray, lo: np.ndarray,
             hi: np.ndarray) -> list[dict]:
    hours = (data.time_s - data.time_s[0]) / 3600.0
    segments = data.segment_ids()
    images = []
    for j, target in enumerate(model.targets):
        fig = new_figure(figsize=(10, 5.5))
        top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=[2, 1])
        y = data.targets_um[:, j]
        for s in np.unique(segments):
            rows = segments == s
            if data.speed_rpm is not None:  # the stops shaded, the speeds written on top
                stretches = speed_stretches(3600.0 * hours[rows], data.speed_rpm[rows],
                                            3600.0 * hours[rows][-1])
                mark_speeds(top, stretches, 3600.0, label=True)
                mark_speeds(bottom, stretches, 3600.0)
            top.fill_between(hours[rows], lo[rows, j], hi[rows, j], color="tab:blue",
                             alpha=0.25, lw=0, label="90 % interval" if s == 0 else None)
            top.plot(hours[rows], y[rows], color="k", lw=1,
                     label="measured" if s == 0 else None)
            top.plot(hours[rows], mean[rows, j], color="tab:blue", lw=1,
                     label=f"predicted ({model.method})" if s == 0 else None)
            bottom.plot(hours[rows], mean[rows, j] - y[rows], color="tab:red", lw=0.8)
        top.set_ylabel(f"{target} [µm]")
        if data.speed_rpm is not None:
            top.set_title("grey: spindle stopped; dotted: speed change", fontsize=9,
                          loc="right")
            top.set_ylim(top.get_ylim()[0], top.get_ylim()[1] + 0.12 * np.ptp(top.get_ylim()))
        # above the axes, left of that note: inside it covered the first speed's label
        top.legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=3, fontsize=8,
                   frameon=False, borderaxespad=0.2)
        bottom.axhline(0.0, color="k", lw=0.5)
        bottom.set_ylabel("residual [µm]")
        bottom.set_xlabel("time from the first row [h]" if segments.max() == 0
                          else "time [h] (files back to back)")
        fig.tight_layout()
        images.append({"title": f"{target}: measured and predicted, residuals",
                       "src": png_data_uri(_png(fig))})
    images += _validation_figures(model)
    ranking = model.metadata.get("ranking", {}).get("sensors", [])
    if ranking:
        fig = new_figure(figsize=(10, 3.2))
        ax = fig.subplots()
        names = [r["sensor"] for r in ranking]
        grades = [r["mean_grade"] for r in ranking]
        colours = ["tab:green" if r["sensor"] in model.spec.sensors else "tab:gray"
                   for r in ranking]
        ax.bar(names, grades, color=colours)
        ax.set_ylim(min(grades) - 0.05, 1.0)
        ax.set_ylabel("grey relational grade")
        ax.set_title("sensor ranking (green: used by the model)")
        ax.tick_params(axis="x", rotation=60, labelsize=8)
        fig.tight_layout()
        images.append({"title": "Sensor ranking", "src": png_data_uri(_png(fig))})
    return images


def _validation_figures(model: DriftModel) -> list[dict]:
    """Out-of-fold predictions of the time-blocked validation at fitting, per target."""
    v = model.validation
    if not v:
        return []
    t = v["time_s"]
    step = np.diff(t, prepend=t[0])
    hours = np.cumsum(np.where(step > 0, step, 0.0)) / 3600.0   # files back to back
    images = []
    for j, target in enumerate(model.targets):
        fig = new_figure(figsize=(10, 3.6))
        ax = fig.subplots()
        for b in np.unique(v["block"]):
            rows = v["block"] == b
            if int(b) % 2:
                ax.axvspan(hours[rows][0], hours[rows][-1], color="0.92", lw=0)
            ax.fill_between(hours[rows], v["lo_um"][rows, j], v["hi_um"][rows, j],
                            color="tab:orange", alpha=0.3, lw=0,
                            label="90 % interval" if b == 0 else None)
            ax.plot(hours[rows], v["predicted_um"][rows, j], color="tab:orange", lw=1,
                    label="out-of-fold prediction" if b == 0 else None)
        ax.plot(hours, v["measured_um"][:, j], color="k", lw=0.8, label="measured")
        ax.set_ylabel(f"{target} [µm]")
        ax.set_xlabel("time [h] (each block predicted by a model fitted on the others)")
        ax.legend(loc="best", fontsize=8)
        fig.tight_layout()
        images.append({"title": f"{target}: time-blocked validation at fitting "
                       f"({model.method})", "src": png_data_uri(_png(fig))})
    return images


def write_drift_report(out_dir: str | os.PathLike[str], model: DriftModel, data: DriftData,
                       model_name: str) -> tuple[dict, Path, Path]:
    """Write metrics.json and report.html into `out_dir`: (metrics, their paths)."""
    mean, lo, hi, excess, furthest = model.predict_data(data)
    metrics = drift_metrics(model, data, mean, lo, hi, model.outside_range(excess, furthest))
    out = Path(out_dir)
    validation = model.metadata.get("validation", {}).get("methods", {})
    html = render_page(
        "drift_report.html.j2", model_name=model_name, metrics=metrics,
        uses_speed=model.spec.uses_speed,
        targets=model.targets, validation=validation,
        chosen=model.metadata.get("validation", {}).get("chosen", model.method),
        ranking=model.metadata.get("ranking", {}).get("sensors", []),
        images=_figures(model, data, mean, lo, hi))
    # both written once the page is drawn (the slow part): a stop while drawing left the
    # new metrics.json beside the earlier report.html
    metrics_path = write_metrics(out / "metrics.json", metrics)
    html_path = write_text(out / "report.html", html)
    return metrics, metrics_path, html_path
