"""The aggregate replay report: one self-contained HTML page (images embedded).

Built from a replay folder only (summary.json and each run's files), so `twin report DIR`
can rebuild it at any time:
- a per-run table in the style of the reference paper's Table 2 (speed, ambient,
  temperature and deformation accuracy per method, with averages);
- per run: T1–T5 measured vs twin over time (the paper's Fig. 11), the nose drift, the
  correction factors per window, the data-quality notes and any snapshots.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import TYPE_CHECKING
from urllib.parse import quote

import numpy as np

from twin.contract import SENSOR_LOCATIONS, SENSOR_NAMES, STEP_S, WINDOW_S
from twin.errors import InputError
from twin.io.atomic import output_name, write_bytes, write_json, write_text
from twin.io.figures import (
    MAX_SPEED_CHANGES_MARKED,
    Stretch,
    load_matplotlib,
    mark_speeds,
    new_figure,
    png_bytes,
    speed_stretches,
)
from twin.io.html_pages import png_data_uri, render_page
from twin.loop.folders import folder_lock
from twin.loop.metrics import DISTRIBUTION_METRICS, batch_summary, metric_values
from twin.loop.overlap import ForkedTask
from twin.loop.summary import collect_summary, run_folder
from twin.runs.quality import SAMPLES, finding_count
from twin.wording import counted

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

METHOD_COLORS = {
    "open_loop": "#7f7f7f", "ratio": "#1f77b4", "bpnn": "#d62728", "estimator": "#2ca02c"
}


class _Columns(dict[str, list[str]]):
    """A run's CSV (keypoints.csv, corrections.csv) as its columns of text by name; a
    column it lacks or a cell that is no number is an InputError naming the file, line
    and column: a damaged file was an internal error of the report."""

    def __init__(self, path: Path, columns: dict[str, list[str]]) -> None:
        super().__init__(columns)
        self.path = path

    def __missing__(self, column: str) -> list[str]:
        raise InputError("column missing (replay the run again)", file=str(self.path),
                         column=column)

    def numbers(self, column: str) -> np.ndarray:
        """The column as floats, NaN where a cell is empty."""
        cells = self[column]
        try:
            return np.array([float(v) if v not in ("", None) else np.nan for v in cells])
        except ValueError:
            row = next(i for i, v in enumerate(cells) if not _is_number(v))
            raise InputError(f"{cells[row]!r} is not a number (replay the run again)",
                             file=str(self.path), row=row + 2, column=column,
                             row_unit="line") from None


def _is_number(cell: str | None) -> bool:
    try:
        float(cell or "nan")
    except ValueError:
        return False
    return True


def _read_csv(path: Path) -> _Columns:
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            rows = list(csv.DictReader(fh))
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        why = exc.strerror if isinstance(exc, OSError) and exc.strerror else exc
        raise InputError(f"cannot be read (replay the run again): {why}",
                         file=str(path)) from None
    return _Columns(path, {k: [r[k] for r in rows] for k in (rows[0].keys() if rows else [])})


PLOTS = ("temperatures.png", "drift_corrections.png")


def _layout(fig: Figure, top: float = 0.9, right: float = 0.99) -> None:
    """Fixed margins: a "tight" bounding box draws the figure twice (a third of a replay).
    top and right leave room for a title line and a legend beside the axes."""
    fig.subplots_adjust(left=0.05, right=right, bottom=0.17, top=top, wspace=0.25)


def _png(fig: Figure) -> bytes:
    return png_bytes(fig, dpi=80)


def _shade_band(ax: Axes, kp: _Columns, sel: np.ndarray, t_min: np.ndarray, lo: str, hi: str,
                method: str) -> None:
    """The method's 90 % band, shaded, where keypoints.csv has one."""
    if lo not in kp and hi not in kp:
        return
    low, high = kp.numbers(lo)[sel], kp.numbers(hi)[sel]
    if np.isfinite(low).any():
        ax.fill_between(t_min[sel], low, high, color=METHOD_COLORS.get(method), alpha=0.2,
                        lw=0, label=f"{method} 90 % band")


def render_run_plots(run_dir: Path, split: bool = False) -> list[Path]:
    """Draw a run's report figures into run_dir/plots/ (done by the batch worker that
    replayed the run, so a parallel batch also draws in parallel).

    split: draw the second figure in a forked child meanwhile (`twin.loop.overlap`; a
    figure is some 0.2 s of matplotlib's Python, at the end of a replay's critical path).
    """
    kp = _read_csv(run_dir / "keypoints.csv")
    if not kp:
        return []
    corr = _read_csv(run_dir / "corrections.csv")
    paths = [run_dir / "plots" / name for name in PLOTS]
    name = output_name(run_dir.name)  # a replay draws in its staging folder

    def draw_drift(_: str) -> None:
        write_bytes(paths[1], _png(drift_figure(kp, corr, name)))

    with ForkedTask(draw_drift, fork=split) as drift:
        drift.start()
        write_bytes(paths[0], _png(temperature_figure(kp, corr, name)))
        drift.join()
    return paths


def speed_segments(corr: _Columns) -> list[Stretch]:
    """The speeds the twin ran (corrections.csv: one per window, the first method's rows;
    window k from 60 k s) as stretches of one speed, in time order; [] without them."""
    if not corr:
        return []
    first = np.array(corr["method"]) == corr["method"][0]
    start = corr.numbers("window")[first] * WINDOW_S
    if "speed_rpm" not in corr:
        return []
    ends = start[np.isfinite(start)]
    return speed_stretches(start, corr.numbers("speed_rpm")[first],
                           float(ends.max()) + WINDOW_S if ends.size else 0.0)


MAX_SPEEDS_LISTED = 8
"""Speed stretches `speed_profile` lists one by one; more are summarised."""


def speed_profile(segments: list[Stretch]) -> str:
    """The run's speeds in words: "8000 → 12000 → stop → 6000 rpm" (the twin's window
    speeds), or a summary for a run of many speed changes; "" without segments."""
    if not segments:
        return ""
    if len(segments) <= MAX_SPEEDS_LISTED:
        return " → ".join("stop" if rpm == 0 else f"{rpm:.0f}" for _, _, rpm in segments) + (
            " rpm" if any(rpm for _, _, rpm in segments) else "")
    running = [rpm for _, _, rpm in segments if rpm > 0]
    stops = sum(1 for _, _, rpm in segments if rpm == 0)
    span = f"{min(running):.0f}–{max(running):.0f} rpm" if running else "stopped"
    return (f"{span} in {len(segments)} stretches"
            + (f", {stops} stop{'s' if stops > 1 else ''}" if stops else ""))


def _speed_note(segments: list[Stretch]) -> str:
    if not segments:
        return ""
    marks = []
    if any(rpm == 0 for _, _, rpm in segments):
        marks.append("grey: stopped")
    if 1 < len(segments) <= MAX_SPEED_CHANGES_MARKED + 1:
        marks.append("dotted: speed change")
    return (f"speed per 60 s window {speed_profile(segments)}"
            + (f" ({', '.join(marks)})" if marks else ""))


def temperature_figure(kp: _Columns, corr: _Columns, run: str) -> Figure:
    """T1..T5 measured and per method over time, one panel per sensor (the paper's Fig. 11),
    the stops shaded and the speed changes marked."""
    methods = list(dict.fromkeys(kp["method"]))
    method_col = np.array(kp["method"])
    t_min = kp.numbers("time_s") / 60.0
    segments = speed_segments(corr)
    fig = new_figure(figsize=(17, 3.6))
    axes = fig.subplots(1, 5, sharex=True)
    for i, s in enumerate(SENSOR_NAMES):
        ax = axes[i]
        mark_speeds(ax, segments, 60.0)
        first = method_col == methods[0]
        measured = kp.numbers(f"{s}_meas_C")[first]
        ax.plot(t_min[first], measured, "k.", ms=2, label="measured")
        for m in methods:
            sel = method_col == m
            ax.plot(
                t_min[sel],
                kp.numbers(f"{s}_twin_C")[sel],
                color=METHOD_COLORS.get(m),
                lw=1.3,
                label=m,
            )
            _shade_band(ax, kp, sel, t_min, f"{s}_twin_lo_C", f"{s}_twin_hi_C", m)
        ax.set_title(f"{s}: {SENSOR_LOCATIONS[s]}", y=1.0, fontsize=10)
        if not np.isfinite(measured).any():  # a stuck or dead channel: left out
            ax.text(0.5, 0.04, "no valid measurement\n(excluded, see data quality)",
                    transform=ax.transAxes, ha="center", va="bottom", fontsize=8,
                    color="#b00")
        ax.set_xlabel("time [min]")
        ax.grid(alpha=0.3)
        # four intervals suit a panel 3.4 in wide, and halve the ticks matplotlib builds
        # and draws (a quarter of the figure's cost, which ends a replay's critical path)
        ax.locator_params(axis="y", nbins=4)
    axes[0].set_ylabel("temperature [°C]")
    _legend_row(fig, axes[0])
    note = _speed_note(segments)
    fig.suptitle(f"{run}: T1–T5 measured and twin" + (f"; {note}" if note else ""),
                 fontsize=11, y=0.985)
    _layout(fig, top=TOP_UNDER_LEGEND)
    return fig


TOP_UNDER_LEGEND = 0.76
"""The axes' top (figure fraction) under the title and the legend row."""


def _legend_row(fig: Figure, ax: Axes) -> None:
    """The measured points, the methods and the band as one row under the figure's title:
    inside a panel the legend covered curves whichever corner it took."""
    handles, labels = ax.get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, 0.925),
               ncol=max(len(labels), 1), fontsize=8, frameon=False, markerscale=2)


FACTOR_NAMES = {"C_H_front": "bearing heat front", "C_H_rear": "bearing heat rear",
                "C_C_front": "contact resistance front", "C_C_rear": "contact resistance rear"}
"""corrections.csv's factor columns in words, for the legend."""


def drift_figure(kp: _Columns, corr: _Columns, run: str) -> Figure:
    """The axial nose drift measured and per method, and the correction factors per window,
    both over the run's time with the stops shaded and the speed changes marked."""
    methods = list(dict.fromkeys(kp["method"]))
    method_col = np.array(kp["method"])
    t_min = kp.numbers("time_s") / 60.0
    segments = speed_segments(corr)
    fig = new_figure(figsize=(13, 3.6))
    ax1, ax2 = fig.subplots(1, 2, sharex=True)
    mark_speeds(ax1, segments, 60.0)
    mark_speeds(ax2, segments, 60.0)
    first = method_col == methods[0]
    meas = kp.numbers("disp_z_meas_um")[first]
    if np.isfinite(meas).any():
        ax1.plot(t_min[first], meas, "k.", ms=2, label="measured")
    else:
        ax1.text(0.5, 0.04, "no drift measurement in the run", transform=ax1.transAxes,
                 ha="center", va="bottom", fontsize=8, color="#b00")
    for m in methods:
        sel = method_col == m
        ax1.plot(
            t_min[sel], kp.numbers("disp_z_twin_um")[sel], color=METHOD_COLORS.get(m), label=m
        )
        _shade_band(ax1, kp, sel, t_min, "disp_z_twin_lo_um", "disp_z_twin_hi_um", m)
    ax1.set_title("axial thermal drift of the spindle nose", y=1.0, fontsize=10)
    ax1.set_xlabel("time [min]")
    ax1.set_ylabel("drift [µm]")
    ax1.grid(alpha=0.3)
    _legend_row(fig, ax1)
    if corr:
        cm = np.array(corr["method"])
        for m in methods:
            sel = cm == m
            if m == "open_loop":
                continue
            # a window's factor holds from its start for the window: drawn as steps
            w_min = corr.numbers("window")[sel] * (WINDOW_S / 60.0)
            for key, style in (
                ("C_H_front", "-"),
                ("C_H_rear", "--"),
                ("C_C_front", ":"),
                ("C_C_rear", "-."),
            ):
                ax2.plot(
                    w_min,
                    _running_factor(corr, key, sel),
                    style,
                    drawstyle="steps-post",
                    color=METHOD_COLORS.get(m),
                    label=f"{m}: {FACTOR_NAMES[key]}",
                )
    ax2.set_title("correction factors per 60 s window (1 = nominal model)", y=1.0,
                  fontsize=10)
    ax2.set_xlabel("time [min] (window start)")
    ax2.set_ylabel("factor [–]")
    ax2.grid(alpha=0.3)
    if ax2.get_legend_handles_labels()[0]:  # (the speed marks are lines without a label)
        # beside the axes: inside, its twelve entries hid the factors' spikes
        ax2.legend(fontsize=6.5, loc="upper left", bbox_to_anchor=(1.01, 1.0),
                   borderaxespad=0.0)
    else:  # open loop alone has no factors to show
        ax2.text(0.5, 0.5, "no correction (open loop only)", transform=ax2.transAxes,
                 ha="center", va="center", fontsize=9, color="0.4")
    note = _speed_note(segments)
    fig.suptitle(f"{run}: nose drift and corrections" + (f"; {note}" if note else ""),
                 fontsize=11, y=0.985)
    _layout(fig, top=TOP_UNDER_LEGEND, right=0.8)
    return fig


def _running_factor(corr: _Columns, key: str, sel: np.ndarray) -> np.ndarray:
    """corrections.csv's `key` for the rows `sel`, with a gap where a C_H is a stopped
    bearing's (heat 0): its fallback 1 there is no correction (and on the previous values
    themselves, before C_H was on the carried ones, the line fell to 0 at every stop as if
    the correction had).  The window after a stop compares with the factor from before
    the stop, a correction like any other."""
    values = corr.numbers(key)[sel]
    if not key.startswith("C_H_"):
        return values
    running = corr.numbers("H_" + key.removeprefix("C_H_"))[sel] > 0
    return np.where(running, values, np.nan)


def run_plotter(fork: bool = True) -> ForkedTask:
    """A forked child that imports matplotlib now and draws one run's figures once started
    with the run folder (`start(str(run_dir))`, when keypoints.csv and corrections.csv are
    written); without fork (`fork=False`, or where it is unsafe) `start` draws them here,
    forking nothing either: a --jobs worker, which the batch ends on Ctrl-C, left the
    child drawing its second figure running, to write into the run's removed folder."""
    def draw(run_dir: str) -> None:
        render_run_plots(Path(run_dir), split=fork)

    return ForkedTask(draw, prepare=load_matplotlib, fork=fork)


PLOT_ALTS = {"temperatures.png": "T1–T5 measured and twin over time, per method",
             "drift_corrections.png": "axial nose drift measured and twin, and the "
                                      "correction factors per window"}


def _image(png: Path) -> dict[str, str]:
    return {"alt": PLOT_ALTS.get(png.name, png.stem), "src": png_data_uri(png.read_bytes())}


def _plots(run_dir: Path) -> list[dict[str, str]]:
    """The run's figures (alt text, data URI), drawn now if the replay did not leave them."""
    paths = [run_dir / "plots" / name for name in PLOTS]
    if not all(p.is_file() for p in paths):
        paths = render_run_plots(run_dir)
    return [_image(p) for p in paths]


RUN_FILES = (
    ("keypoints.csv", "T1–T5 and drift per step"),
    ("corrections.csv", "corrections per window"),
    ("accuracy.json", "accuracy"),
    ("quality.json", "data quality"),
    ("fields.pvd", "fields (ParaView)"),
    ("decks", "window decks"),
)
"""A run folder's files the page links to, where they exist, with what they hold."""


def _run_links(run_dir: Path) -> list[dict[str, str]]:
    """Links (relative to the page, beside the run folder) to the run's files that exist: the page
    is one file, the numbers and fields stay beside it."""
    return [{"href": quote(f"{run_dir.name}/{name}"), "text": name, "title": what}
            for name, what in RUN_FILES if (run_dir / name).exists()]


def _snapshot_caption(png: Path) -> str:
    """What a snapshot file `<method>_t<seconds>s.png` shows, in words."""
    method, sep, rest = png.stem.rpartition("_t")
    if sep and rest.endswith("s") and rest[:-1].isdigit():
        t = int(rest[:-1])
        return f"temperature field of {method} at t = {t} s ({t / 60:.1f} min)"
    return png.name


DISTRIBUTION_MIN_RUNS = 5
"""A batch of at least this many runs gets the per-method distribution (table and plot)."""
METRIC_LABELS = {"temperature_accuracy_pct": "T acc [%]",
                 "temperature_rise_accuracy_pct": "rise acc [%]",
                 "deformation_accuracy_pct": "deform acc [%]"}


def distribution_plot(runs: list[dict], methods: list[str]) -> bytes:
    """One small box plot per metric, every run's value drawn over it as a point."""
    values = metric_values(runs)
    fig = new_figure(figsize=(12, 3.2))
    axes = fig.subplots(1, len(DISTRIBUTION_METRICS))
    jitter = np.random.default_rng(0)  # fixed: the same folder draws the same picture
    for ax, key in zip(axes, DISTRIBUTION_METRICS, strict=True):
        data = [values.get(m, {}).get(key, []) for m in methods]
        shown = [i for i, d in enumerate(data) if d]
        if shown:
            ax.boxplot([data[i] for i in shown], positions=shown, widths=0.5,
                       showfliers=False)
        for i in shown:
            x = i + jitter.uniform(-0.15, 0.15, len(data[i]))
            ax.plot(x, data[i], "o", ms=4, alpha=0.7,
                    color=METHOD_COLORS.get(methods[i], "k"))
        ax.set_xticks(range(len(methods)), methods)
        ax.set_title(METRIC_LABELS[key], fontsize=10)
        ax.grid(axis="y", alpha=0.3)
    _layout(fig)
    return _png(fig)


def distribution_rows(summary: dict, methods: list[str]) -> list[list[str]]:
    """Rows (method, then median / worst / mean of each distribution metric)."""
    rows = []
    for m in methods:
        cells = []
        for key in DISTRIBUTION_METRICS:
            cells += [_fmt(summary.get(stat, {}).get(m, {}).get(key))
                      for stat in ("median", "worst", "mean")]
        rows.append([m, *cells])
    return rows


def _fmt(v: float | None, digits: int = 2) -> str:
    return "–" if v is None else f"{v:.{digits}f}"


def _accuracy_cells(metrics: dict) -> list[str]:
    return [_fmt(metrics.get(key)) for key in
            ("temperature_accuracy_pct", "temperature_rise_accuracy_pct",
             "deformation_accuracy_pct")]


MAX_SPANS_SHOWN = 4
"""Time spans a finding's row lists in the report before '…' (quality.json has them all)."""


def _findings(run_dir: Path) -> list[dict[str, str]] | None:
    """The run's data-quality findings as table rows (column, kind, samples, time spans,
    action, detail: quality.json's fields, spans in s); None without a quality.json."""
    try:
        findings = json.loads((run_dir / "quality.json").read_text())
    except (OSError, ValueError):
        return None
    if isinstance(findings, dict):
        findings = findings.get("findings", findings)
    # anything else a hand-edited file holds (a text, a number) is a row shown as it is
    items = findings if isinstance(findings, list) else [findings] if findings else []
    return [_finding_row(f) for f in items]


def _finding_row(finding: object) -> dict[str, str]:
    if not isinstance(finding, dict):  # a hand-edited file: shown as it is
        return {"column": "", "kind": "", "count": "", "spans": "", "action": "",
                "detail": json.dumps(finding, ensure_ascii=False)}
    spans = [f"{a:g}" if a == b else f"{a:g}–{b:g}" for a, b in finding.get("spans_s") or []]
    shown = ", ".join(spans[:MAX_SPANS_SHOWN]) + (" …" if len(spans) > MAX_SPANS_SHOWN else "")
    # the column is "samples": a count of anything else says what it counts ("2 windows")
    count, what = finding_count(finding)
    if count is None or what == SAMPLES:
        count_cell = "" if count is None else str(count)
    elif isinstance(count, int):  # "2 windows", "1 window"
        count_cell = counted(count, what.removesuffix("s"), what)
    else:  # a hand-edited file: shown as it is
        count_cell = f"{count} {what}"
    return {"column": str(finding.get("column", "")), "kind": str(finding.get("kind", "")),
            "count": count_cell, "spans": shown,
            "action": str(finding.get("action", "")), "detail": str(finding.get("detail", ""))}


def _summary_of_batch(out_root: Path) -> dict | None:
    """summary.json as the batch just wrote it, or None when it must be rebuilt."""
    try:
        summary = json.loads((out_root / "summary.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return summary if isinstance(summary, dict) else None


def _distribution(summary: dict, runs: list[dict], methods: list[str]) -> dict | None:
    """The batch's per-method distribution for the page (None for a batch of a few runs)."""
    if len(runs) < DISTRIBUTION_MIN_RUNS or not methods:
        return None
    if "median" not in summary:  # a summary.json written before the statistics existed
        summary = {**summary, **batch_summary(runs, summary.get("failed", []))}
    return {"n_runs": len(runs), "labels": [METRIC_LABELS[k] for k in DISTRIBUTION_METRICS],
            "rows": distribution_rows(summary, methods),
            "plot": png_data_uri(distribution_plot(runs, methods))}


REDRAWS = 3
"""How often `build_report` draws the page again for runs a batch swapped in meanwhile
(then it writes the page it has: batches that never stop would keep it drawing)."""


def build_report(out_root: str | Path, rebuild_summary: bool = True) -> Path:
    """Write DIR/report.html (and DIR/summary.json when rebuilding) from a replay folder.

    A rebuilt summary.json is written with the page, once that is drawn: a run file the
    page cannot read (a damaged keypoints.csv) stops the command before either file is
    replaced.  Both are written under the folder's lock from the run folders as they are
    then; a batch that swapped a run in while the page was drawn gets it drawn again."""
    out_root = Path(out_root)
    path = out_root / "report.html"
    summary = None if rebuild_summary else _summary_of_batch(out_root)
    if summary is not None:
        write_text(path, _page(out_root, summary))
        return path
    with folder_lock(out_root):
        summary = collect_summary(out_root)
    redraws = REDRAWS
    while True:
        page = _page(out_root, summary)
        with folder_lock(out_root):
            latest = collect_summary(out_root)
            # as JSON: a NaN in an accuracy equals itself there, never as a float
            if redraws == 0 or json.dumps(latest) == json.dumps(summary):
                write_json(out_root / "summary.json", latest)
                write_text(path, page)
                return path
        summary, redraws = latest, redraws - 1


def _page(out_root: Path, summary: dict) -> str:
    """report.html's text for `summary` (summary.json's form) of the folder `out_root`."""
    runs = summary.get("runs", [])
    methods = list(dict.fromkeys(m for r in runs for m in r["methods"]))
    mean = summary.get("mean", {})
    page_runs = []
    for r in runs:
        run_dir = run_folder(out_root, r["run"])
        if run_dir is None:  # a name, never a path: nothing is read or drawn outside DIR
            continue
        snapshots = sorted(p for p in (run_dir / "snapshots").glob("*.png") if p.is_file())[-2:]
        # the speeds the twin ran, in words: the mean alone hid the steps and stops
        profile = (speed_profile(speed_segments(_read_csv(run_dir / "corrections.csv")))
                   if (run_dir / "corrections.csv").is_file() else "")
        page_runs.append({
            "name": r["run"],
            "anchor": f"run-{len(page_runs) + 1}",
            # accuracy.json's speed and ambient are the run's means (of a run with speed
            # steps or a stop too): said so
            "caption": f"mean {r['speed_rpm']:.0f} rpm, mean ambient {r['ambient_C']:.2f} °C, "
                       f"{r['duration_s'] / 60:.1f} min"
                       + (f"; speed {profile}" if profile else ""),
            "plots": _plots(run_dir) if (run_dir / "keypoints.csv").is_file() else [],
            "findings": _findings(run_dir),
            "links": _run_links(run_dir),
            "snapshots": [{"alt": _snapshot_caption(p), "caption": _snapshot_caption(p),
                           "src": png_data_uri(p.read_bytes())} for p in snapshots],
        })
    anchors = {pr["name"]: pr["anchor"] for pr in page_runs}
    return render_page(
        "replay_report.html.j2",
        step_s=STEP_S, window_s=WINDOW_S, methods=methods,
        rows=[{"name": r["run"], "anchor": anchors.get(r["run"]),
               "cells": [f"{r['speed_rpm']:.0f}", f"{r['ambient_C']:.2f}",
                         *(c for m in methods
                           for c in _accuracy_cells(r["methods"].get(m, {})))]}
              for r in runs],
        average=["", "", *(c for m in methods for c in _accuracy_cells(mean.get(m, {})))],
        failed=[{"run": f.get("run", "?"), "error": f.get("error", "")}
                for f in summary.get("failed", [])],
        runs=page_runs,
        distribution=_distribution(summary, runs, methods),
    )
