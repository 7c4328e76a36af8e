"""Headless pictures of a field state (pyvista, off-screen).

The axisymmetric section is revolved by 270° about the spindle axis into a 3-D cut-away,
so the section itself shows on the two cut faces; `section=True` draws the flat r–z
view instead.  The scalar bar carries units; the shown field's largest value is marked
(the hottest point, or the largest displacement) and the hottest point and the nose
drift are stated.  `twin replay --snapshots` and `twin snapshot` both use `render_snapshot`.
"""

from __future__ import annotations

import os
import signal
import threading
from collections.abc import Iterator
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
    T_initial_C: float | None = None,
    section: bool = False,
    window_size: tuple[int, int] = (1200, 800),
) -> Path:
    """Render one field state to a PNG (written atomically); returns the path.  A Ctrl-C
    meanwhile is taken once the picture is done (`ctrl_c_after`)."""
    with ctrl_c_after():
        return _render(model, T, out_png, field, title, T_initial_C, section, window_size)


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
            T_initial_C: float | None, section: bool, window_size: tuple[int, int]) -> Path:
    os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")
    import pyvista as pv

    from twin.log import send_vtk_messages_to_log

    send_vtk_messages_to_log()

    from twin.io.atomic import atomic_target
    from twin.spindle.fields import field_arrays

    if field not in FIELDS:
        raise ValueError(f"field must be one of {', '.join(FIELDS)}, got {field!r}")
    key, label, cmap = FIELDS[field]
    arrays = field_arrays(model, T, T_initial_C)
    mesh = model.mesh
    n = mesh.thermal.p.shape[1]
    # r → x, z → z: the spindle axis is the 3-D z axis, revolved about it
    points = np.zeros((n, 3))
    points[:, 0] = 1e3 * mesh.thermal.p[0]
    points[:, 2] = 1e3 * mesh.thermal.p[1]
    cells = np.hstack([np.full((mesh.n_cells, 1), 3), mesh.thermal.t.T]).ravel()
    surf = pv.PolyData(points, cells)
    values = arrays[key]
    if values.ndim == 2:
        values = np.linalg.norm(values, axis=1)
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
        scalar_bar_args={
            "title": label,
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
        since = "" if T_initial_C is None else f" at {T_initial_C:.1f} °C"
        lines.append(f"shape undeformed; colour: thermal displacement since the uniform "
                     f"start{since}")
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
