"""Report figures as PNG bytes: a matplotlib `Figure` on the Agg canvas, without pyplot.

pyplot is for interactive use: it keeps a process-wide registry of open figures (each must
be closed again) and chooses a GUI backend.  A report only needs a figure it can draw to
PNG, so it builds a `Figure` directly and draws it with the Agg (raster) canvas; matplotlib
itself is imported here, when the first figure is made, not when a report module loads.
"""

from __future__ import annotations

import io
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from matplotlib.figure import Figure


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
