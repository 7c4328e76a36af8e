"""Headless pictures of a field state (pyvista, off-screen).

The axisymmetric section is revolved by 270° about the spindle axis into a 3-D cut-away,
so the section itself shows on the two cut faces; `section=True` draws the flat r–z
view instead.  The scalar bar carries units; the shown field's largest value is marked
(the hottest point, or the largest displacement) and the hottest point and the nose
drift are stated.  `twin replay --snapshots` and `twin snapshot` both use `render_snapshot`.
A picture's colours span its own field's range unless it is given `clim`: the frames of
`twin replay --snapshots every` share the run's range (`colour_range`), so that one colour
is one value in all of them.
"""

from __future__ import annotations

import os
import signal
import threading
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from types import FrameType
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from twin.runs.run import RecordedRun
    from twin.spindle.model import SpindleModel

FIELDS = {
    "temperature": ("temperature_C", "Temperature [°C]", "inferno"),
    # "|u|" came out of VTK's title font as a raised "u": the word says it
    "displacement": ("displacement_um", "Displacement magnitude [µm]", "viridis"),
}


def snapshot_title(name: str, method: str, t: float, run: RecordedRun) -> str:
    """A snapshot's first line: the run, the method, the time in s and min, and the speed
    recorded then ("stopped" at 0 rpm): a picture taken in a stop looked like one at speed."""
    title = f"{name} · {method} · t = {t:.0f} s ({t / 60:.1f} min)"
    k = int(np.searchsorted(run.time_s, t, side="right")) - 1
    rpm = float(run.speed_rpm[max(k, 0)]) if run.speed_rpm.size else float("nan")
    if not np.isfinite(rpm):
        return title
    return f"{title} · " + ("stopped (0 rpm)" if rpm == 0 else f"{rpm:.0f} rpm")


def render_snapshot(
    model: SpindleModel,
    T: np.ndarray,
    out_png: str | Path,
    field: str = "temperature",
    title: str = "",
    T_initial_C: float | np.ndarray | None = None,
    section: bool = False,
    window_size: tuple[int, int] = (1200, 800),
    clim: tuple[float, float] | None = None,
) -> Path:
    """Render one field state to a PNG (written atomically); returns the path.  A Ctrl-C
    meanwhile is taken once the picture is done (`ctrl_c_after`).  `clim`: the colour
    range (the field's unit), stated on the colour bar as the run's; None: this field's."""
    with ctrl_c_after():
        return _render(model, T, out_png, field, title, T_initial_C, section, window_size,
                       clim)


def shown_values(arrays: dict[str, np.ndarray], field: str) -> np.ndarray:
    """What a picture of `field` colours, from `field_arrays`' point arrays: the
    temperature, or the displacement's magnitude."""
    if field not in FIELDS:
        raise ValueError(f"field must be one of {', '.join(FIELDS)}, got {field!r}")
    values = arrays[FIELDS[field][0]]
    return np.linalg.norm(values, axis=1) if values.ndim == 2 else values


def colour_range(model: SpindleModel, fields: Iterable[np.ndarray], field: str = "temperature",
                 T_initial_C: float | np.ndarray | None = None) -> tuple[float, float]:
    """The colour range of a run's frames: the lowest and highest value `field` takes over
    all the `fields` (temperature vectors, `render_snapshot`'s T).  The frames of a replay
    each spanned their own field's range (23.0–45.2 °C in one, 23.3–42.2 °C in the next),
    so that a colour meant another temperature in each.  The temperature is read off the
    vectors; the displacement needs `field_arrays`' structural solve of each."""
    from twin.spindle.fields import field_arrays

    n = model.mesh.thermal.p.shape[1]
    low, high = np.inf, -np.inf
    for T in fields:
        arrays = ({"temperature_C": np.asarray(T[:n], float)} if field == "temperature"
                  else field_arrays(model, T, T_initial_C))
        values = shown_values(arrays, field)
        low, high = min(low, float(values.min())), max(high, float(values.max()))
    if not low <= high:
        raise ValueError("no field to take a colour range from")
    return low, high


@contextmanager
def ctrl_c_after() -> Iterator[None]:
    """Take a Ctrl-C only when the block is done: VTK calls back into Python while it
    renders (pyvista's error observer), and a KeyboardInterrupt raised in such a call
    crashed the process in VTK's Python wrapping (SIGSEGV, a Ctrl-C 7 s into a replay).
    In the main thread, and while Ctrl-C raises at all; else the block runs as it is."""
    handler = signal.getsignal(signal.SIGINT)
    if threading.current_thread() is not threading.main_thread() or not callable(handler):
        yield
        return
    pressed: list[tuple[int, FrameType | None]] = []
    signal.signal(signal.SIGINT, lambda signum, frame: pressed.append((signum, frame)))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, handler)
        if pressed:
            handler(*pressed[0])  # the handler's own KeyboardInterrupt, now


def _render(model: SpindleModel, T: np.ndarray, out_png: str | Path, field: str, title: str,
            T_initial_C: float | np.ndarray | None, section: bool,
            window_size: tuple[int, int],
            clim: tuple[float, float] | None) -> Path:
    os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")
    import pyvista as pv

    from twin.log import send_vtk_messages_to_log

    send_vtk_messages_to_log()

    from twin.io.atomic import atomic_target
    from twin.spindle.fields import field_arrays

    if field not in FIELDS:
        raise ValueError(f"field must be one of {', '.join(FIELDS)}, got {field!r}")
    _, label, cmap = FIELDS[field]
    arrays = field_arrays(model, T, T_initial_C)
    mesh = model.mesh
    n = mesh.thermal.p.shape[1]
    # r → x, z → z: the spindle axis is the 3-D z axis, revolved about it
    points = np.zeros((n, 3))
    points[:, 0] = 1e3 * mesh.thermal.p[0]
    points[:, 2] = 1e3 * mesh.thermal.p[1]
    cells = np.hstack([np.full((mesh.n_cells, 1), 3), mesh.thermal.t.T]).ravel()
    surf = pv.PolyData(points, cells)
    values = shown_values(arrays, field)
    surf.point_data[label] = values
    if section:
        body = surf
    else:
        body = surf.extrude_rotate(
            resolution=72, angle=270.0, capping=True, rotation_axis=(0.0, 0.0, 1.0)
        )

    plotter = pv.Plotter(off_screen=True, window_size=list(window_size))
    plotter.set_background("white")
    plotter.add_mesh(
        body,
        scalars=label,
        cmap=cmap,
        show_edges=False,
        smooth_shading=True,
        clim=None if clim is None else list(clim),
        scalar_bar_args={
            # the bar's ends are the run's range then, not this frame's: said on it
            "title": label if clim is None else f"{label}\nrun's range, every frame",
            "color": "black",
            "fmt": "%.1f",
            "vertical": True,
            "position_x": 0.82,
            "position_y": 0.1,
            "title_font_size": 16,
            "label_font_size": 14,
        },
    )
    hot = int(np.argmax(arrays["temperature_C"]))
    hot_xyz = points[hot]
    t_max = float(arrays["temperature_C"][hot])
    drift_z = float(arrays["displacement_um"][:, 1][_nose_vertex(model)])
    top, marker = field_marker(field, values)
    plotter.add_point_labels(
        [points[top]],
        [marker],
        point_size=14,
        font_size=16,
        point_color="red",
        text_color="black",
        shape_opacity=0.6,
        always_visible=True,
    )
    nose = _nose_vertex(model)
    plotter.add_point_labels(
        [points[nose]], ["nose"], point_size=10, font_size=14, point_color="black",
        text_color="black", shape_opacity=0.6, always_visible=True,
    )
    lines = [title] if title else []
    lines.append(f"hottest {t_max:.1f} °C at r = {hot_xyz[0]:.0f} mm, z = {hot_xyz[2]:.0f} mm")
    lines.append(f"nose drift (axial) {drift_z:+.2f} µm")
    if field == "displacement":  # the colours are the drift; the shape is not deformed
        since = ("the uniform start" if T_initial_C is None
                 else "the start (a warm start's fitted field)" if np.ndim(T_initial_C)
                 else f"the uniform start at {float(T_initial_C):.1f} °C")
        lines.append(f"shape undeformed; colour: thermal displacement since {since}")
    plotter.add_text("\n".join(lines), position="upper_left", font_size=11, color="black")
    if section:
        plotter.view_xz()
        # the flat section gets its r and z scales (mm, round ticks), the 3-D view its nose
        # marker only; zoomed out so the text lines above do not cover the nose
        r_top, r_labels = nice_axis(float(points[:, 0].max()))
        z_top, z_labels = nice_axis(float(points[:, 2].max()))
        plotter.show_bounds(bounds=[0.0, r_top, 0.0, 0.0, 0.0, z_top], xtitle="r [mm]",
                            ytitle="", ztitle="z [mm]", n_xlabels=r_labels,
                            n_zlabels=z_labels, fmt="%.0f", color="black", font_size=12,
                            location="outer", ticks="outside", show_yaxis=False,
                            show_ylabels=False)
        plotter.camera.zoom(0.8)
    else:
        # look into the removed quadrant (x > 0, y < 0), so both cut faces show
        cx, cy, cz = body.center
        d = 2.2 * max(body.length, 1.0)
        plotter.camera_position = [
            (cx + 0.55 * d, cy - 0.55 * d, cz + 0.25 * d),
            (cx, cy, cz),
            (0.0, 0.0, 1.0),
        ]
    try:
        with atomic_target(out_png) as tmp:
            # pyvista picks the format from the suffix as written: S.PNG is no format to it
            png = tmp.with_suffix(".png")
            try:
                plotter.screenshot(str(png))
                png.replace(tmp)
            finally:
                if png != tmp:
                    png.unlink(missing_ok=True)
    finally:
        plotter.close()
    return Path(out_png)


def nice_axis(high: float, intervals: int = 5) -> tuple[float, int]:
    """An axis from 0 to `high` rounded up to round ticks (a step of 1, 2 or 5 × 10^n,
    about `intervals` of them): (the axis end, how many labels).  The section's r axis
    read 0, 38.8, 77.5, 116.2, 155."""
    if not high > 0:
        return 1.0, 2
    raw = high / intervals
    power = 10.0 ** np.floor(np.log10(raw))
    step = next(m * power for m in (1.0, 2.0, 5.0, 10.0) if m * power >= raw * (1 - 1e-9))
    steps = int(np.ceil(high / step - 1e-9))
    return float(steps * step), steps + 1


def field_marker(field: str, values: np.ndarray) -> tuple[int, str]:
    """The vertex of the shown field's largest value and its label, in the field's unit:
    the marker names what the colours show (a displacement picture marked the hottest
    point in °C)."""
    top = int(np.argmax(values))
    unit = "°C" if field == "temperature" else "µm"
    return top, f"max {float(values[top]):.1f} {unit}"


def _nose_vertex(model: SpindleModel) -> int:
    """Thermal-mesh vertex nearest the axial nose probe."""
    probe = model.spec.probes["nose_axial"]
    p = model.mesh.thermal.p
    d = (p[0] - probe.r_mm * 1e-3) ** 2 + (p[1] - probe.z_mm * 1e-3) ** 2
    return int(np.argmin(d))
