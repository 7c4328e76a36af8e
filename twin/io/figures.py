"""Report figures as PNG bytes: a matplotlib `Figure` on the Agg canvas, without pyplot.

pyplot is for interactive use: it keeps a process-wide registry of open figures (each must
be closed again) and chooses a GUI backend.  A report only needs a figure it can draw to
PNG, so it builds a `Figure` directly and draws it with the Agg (raster) canvas; matplotlib
itself is imported here, when the first figure is made, not when a report module loads.
"""

from __future__ import annotations

import io
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

Stretch = tuple[float, float, float]
"""(start_s, end_s, speed_rpm): a stretch of a run at one speed."""

MAX_SPEED_CHANGES_MARKED = 40
"""Speed changes a figure marks with a line; a run changing speed more often (a recorded
cutting cycle) gets its stops shaded only: a line a minute hid the curves."""


def new_figure(**figure_kwargs: Any) -> Figure:
    """A matplotlib `Figure` (figsize=(w, h) in inches, ...) attached to the Agg canvas;
    lay it out as usual (`fig.subplots`, `fig.subplots_adjust`)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(**figure_kwargs)
    FigureCanvasAgg(fig)
    return fig


def load_matplotlib() -> None:
    """Import what `new_figure` and `png_bytes` use and load the default font, so that the
    first figure costs only its drawing (a forked plotter does this while its parent works:
    about 0.4 s of a cold replay)."""
    fig = new_figure(figsize=(1, 1))
    fig.text(0.5, 0.5, "0")
    png_bytes(fig, dpi=10)


def png_bytes(fig: Figure, dpi: float) -> bytes:
    """The figure drawn to PNG at `dpi` pixels per inch."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return buf.getvalue()


def speed_stretches(start_s: np.ndarray, speed_rpm: np.ndarray, end_s: float) -> list[Stretch]:
    """Consecutive samples of one speed merged into stretches, each sample holding until the
    next one starts and the last until `end_s`; samples without a number are passed over."""
    start_s, speed_rpm = np.asarray(start_s, float), np.asarray(speed_rpm, float)
    ok = np.isfinite(start_s) & np.isfinite(speed_rpm)
    start_s, speed_rpm = start_s[ok], speed_rpm[ok]
    if start_s.size == 0:
        return []
    order = np.argsort(start_s, kind="stable")
    start_s, speed_rpm = start_s[order], speed_rpm[order]
    new = np.flatnonzero(np.concatenate(([True], np.diff(speed_rpm) != 0)))
    ends = [*start_s[new[1:]], max(float(end_s), float(start_s[-1]))]
    return [(float(start_s[i]), float(e), float(speed_rpm[i])) for i, e in zip(new, ends,
                                                                                 strict=True)]


def mark_speeds(ax: Axes, stretches: list[Stretch], seconds_per_unit: float,
                label: bool = False) -> None:
    """Shade the stops grey and draw a dotted line at each speed change, on an axis in
    units of `seconds_per_unit` (60: minutes); `label`: each running stretch's speed
    written at the top of the axes where it is wide enough."""
    for a, b, rpm in stretches:
        if rpm == 0:
            ax.axvspan(a / seconds_per_unit, b / seconds_per_unit, color="0.88", lw=0,
                       zorder=0)
    if len(stretches) - 1 <= MAX_SPEED_CHANGES_MARKED:
        for a, _, _ in stretches[1:]:
            ax.axvline(a / seconds_per_unit, color="0.45", ls=":", lw=0.9, zorder=0.5)
    if not label or not stretches:
        return
    span = stretches[-1][1] - stretches[0][0]
    for a, b, rpm in stretches:
        if b - a >= 0.06 * span:
            ax.text((a + b) / 2 / seconds_per_unit, 0.97,
                    "stopped" if rpm == 0 else f"{rpm:.0f} rpm",
                    transform=ax.get_xaxis_transform(), ha="center", va="top", fontsize=8,
                    color="0.3")
