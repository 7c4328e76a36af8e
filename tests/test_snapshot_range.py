"""`twin replay --snapshots every`: every frame of a run shares one colour range, the
temperature's range over all the run's window-end fields, also when --resume draws the
frames from the field files; one picture (`end`, `twin snapshot`) keeps its own range."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

from tests.test_replay import MINUTES, make_recorded_run

os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")


@pytest.fixture
def recorded_clims(tmp_path, monkeypatch):
    """Each render_snapshot call's picture name and clim, appended to a file (a forked
    child's calls too)."""
    import twin.loop.snapshot as snapshot

    log = tmp_path / "clims.jsonl"
    render = snapshot.render_snapshot

    def recording(model, T, out_png, *args, **kwargs):
        with log.open("a") as f:
            f.write(json.dumps({"png": os.path.basename(out_png),
                                "clim": kwargs.get("clim")}) + "\n")
        return render(model, T, out_png, *args, **kwargs)

    monkeypatch.setattr(snapshot, "render_snapshot", recording)

    def calls() -> dict[str, list[float] | None]:
        lines = log.read_text().splitlines() if log.exists() else []
        log.unlink(missing_ok=True)
        return {c["png"]: c["clim"] for c in map(json.loads, lines)}

    return calls


def _field_range(folder):
    from twin.io.vtk import read_vtu

    values = [read_vtu(p).point_data["temperature_C"]
              for p in sorted((folder / "fields").glob("open_loop_t*.vtu"))]
    assert len(values) == MINUTES
    return [float(min(v.min() for v in values)), float(max(v.max() for v in values))]


def test_every_frame_of_a_run_and_every_resumed_frame_share_the_runs_range(
        spindle_model, tmp_path, recorded_clims):
    from twin.loop.batch import replay_batch

    # heats up through the run: each frame's own range differs from the next one's
    run = make_recorded_run(tmp_path / "hot_9000.csv", spindle_model)
    fresh = tmp_path / "fresh" / "hot_9000"
    replay_batch([run], tmp_path / "fresh", ["open_loop"], None, snapshots="every")
    clims = recorded_clims()
    names = [f"open_loop_t{60 * k:05d}s.png" for k in range(1, MINUTES + 1)]
    assert sorted(clims) == names
    whole = _field_range(fresh)
    assert whole[1] - whole[0] > 1.0  # a range a frame of its own would not span
    for name in names:
        assert clims[name] == pytest.approx(whole, abs=0), name

    # --resume draws the missing frames from the field files: the same range (over every
    # field file, not only the frames it draws), so the same pictures
    drawn = {n: (fresh / "snapshots" / n).read_bytes() for n in names}
    for name in names[1:3]:
        (fresh / "snapshots" / name).unlink()
    resumed = replay_batch([run], tmp_path / "fresh", ["open_loop"], None, snapshots="every",
                           resume=True)
    assert resumed.skipped == ["hot_9000"]
    redrawn = recorded_clims()
    assert sorted(redrawn) == names[1:3]
    assert all(clim == pytest.approx(whole, abs=0) for clim in redrawn.values())
    for name in names:
        assert (fresh / "snapshots" / name).read_bytes() == drawn[name], name


def test_a_resume_stopped_part_way_leaves_no_frame_in_another_range(spindle_model, tmp_path,
                                                                    monkeypatch):
    """After an `end` batch, `--resume --snapshots every` draws that batch's end picture
    (its own field's range) again in the run's range, and first: stopped after two
    pictures (a Ctrl-C), the next resume draws only the frames still missing, and every
    frame is a fresh `every` replay's."""
    import twin.loop.snapshot as snapshot
    from twin.loop.batch import replay_batch
    from twin.loop.runfiles import add_snapshots

    run = make_recorded_run(tmp_path / "hot_9000.csv", spindle_model)
    replay_batch([run], tmp_path / "fresh", ["open_loop"], None, snapshots="every")
    out = tmp_path / "out" / "hot_9000"
    replay_batch([run], tmp_path / "out", ["open_loop"], None, snapshots="end")
    render = snapshot.render_snapshot
    drawn: list[str] = []

    def stopped(model, T, out_png, *args, **kwargs):
        if len(drawn) == 2:
            raise KeyboardInterrupt
        drawn.append(os.path.basename(out_png))
        return render(model, T, out_png, *args, **kwargs)

    monkeypatch.setattr(snapshot, "render_snapshot", stopped)
    with pytest.raises(KeyboardInterrupt):
        add_snapshots(run, out, ["open_loop"], "every", 60.0 * MINUTES)
    names = [f"open_loop_t{60 * k:05d}s.png" for k in range(1, MINUTES + 1)]
    assert drawn == [names[-1], names[0]]
    monkeypatch.setattr(snapshot, "render_snapshot", render)
    assert add_snapshots(run, out, ["open_loop"], "every", 60.0 * MINUTES) == MINUTES - 2
    for name in names:
        assert ((out / "snapshots" / name).read_bytes()
                == (tmp_path / "fresh" / "hot_9000" / "snapshots" / name).read_bytes()), name


def test_one_end_picture_keeps_its_own_fields_range(spindle_model, tmp_path,
                                                    recorded_clims):
    from twin.loop.batch import replay_batch

    run = make_recorded_run(tmp_path / "hot_9000.csv", spindle_model)
    replay_batch([run], tmp_path / "out", ["open_loop"], None, snapshots="end")
    assert recorded_clims() == {f"open_loop_t{60 * MINUTES:05d}s.png": None}


@pytest.mark.parametrize("clim", [None, (20.0, 50.0)])
def test_the_colour_bar_spans_the_range_given_and_says_whose_it_is(spindle_model, tmp_path,
                                                                   monkeypatch, clim):
    import pyvista as pv

    from twin.loop.snapshot import render_snapshot

    seen: list[tuple[tuple[float, float], str]] = []
    screenshot = pv.Plotter.screenshot

    def read_bar(self, *args, **kwargs):
        bar = self.scalar_bar  # the VTK actor as drawn
        seen.append((tuple(bar.GetLookupTable().GetRange()), bar.GetTitle()))
        return screenshot(self, *args, **kwargs)

    monkeypatch.setattr(pv.Plotter, "screenshot", read_bar)
    T = np.linspace(25.0, 40.0, spindle_model.n_dofs)
    render_snapshot(spindle_model, T, tmp_path / "s.png", section=True,
                    window_size=(300, 200), clim=clim)
    ((bar_range, title),) = seen
    assert bar_range == pytest.approx(clim or (25.0, 40.0))
    assert ("run's range" in title) == (clim is not None), title


def test_the_colour_range_is_over_all_the_fields(spindle_model):
    from twin.loop.snapshot import colour_range

    n = spindle_model.n_dofs
    frames = [np.full(n, 25.0), np.linspace(24.0, 30.0, n), np.linspace(26.0, 41.5, n)]
    assert colour_range(spindle_model, frames) == (24.0, 41.5)
    low, high = colour_range(spindle_model, frames, "displacement", T_initial_C=25.0)
    assert low == pytest.approx(0.0, abs=1e-9) and high > 1.0
    with pytest.raises(ValueError):
        colour_range(spindle_model, [])
