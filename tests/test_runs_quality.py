"""Recorded-run repairs: each defect, crafted in a small file, is repaired and reported."""

from __future__ import annotations

import numpy as np
import pytest

from tests.test_runs_reader import csv_text, warmup, write
from twin.runs import read_run


def kinds(run, column=None):
    return {f["kind"] for f in run.quality if column is None or f["column"] == column}


def one(run, kind, column):
    found = [f for f in run.quality if f["kind"] == kind and f["column"] == column]
    assert len(found) == 1, run.quality
    return found[0]


def noisy_warmup(seed=0, sigma=0.05, n=600):
    cols = warmup(n=n)
    rng = np.random.default_rng(seed)
    for k in range(1, 6):
        cols[f"T{k}_C"] = cols[f"T{k}_C"] + rng.normal(0.0, sigma, n)
    return cols


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_realistic_noise_is_not_a_defect(tmp_path, seed):
    run = read_run(write(tmp_path, csv_text(noisy_warmup(seed))))
    assert run.quality == []


def test_duplicate_timestamps_merged(tmp_path):
    lines = csv_text(warmup()).splitlines()
    # repeat sample t=20 s (line 22) with a different T1: merged into the mean
    dup = lines[21].split(",")
    dup[3] = f"{float(dup[3]) + 1.0:.4f}"
    lines.insert(22, ",".join(dup))
    run = read_run(write(tmp_path, "\n".join(lines)))
    f = one(run, "duplicate_timestamp", "time_s")
    assert f["rows"] == [23] and f["spans_s"] == [[20.0, 20.0]]
    assert run.time_s.size == 300
    expected = 25.0 + 8.0 * (1 - np.exp(-20.0 / 400.0)) + 0.5
    assert run.T_C[20, 0] == pytest.approx(expected, abs=1e-4)


def test_short_dropout_interpolated(tmp_path):
    cols = warmup()
    cols["T2_C"][100:110] = np.nan  # 10 s: interpolate
    run = read_run(write(tmp_path, csv_text(cols)))
    f = one(run, "dropout", "T2_C")
    assert f["rows"] == list(range(102, 112)) and f["spans_s"] == [[100.0, 109.0]]
    exact = 25.0 + 6.0 * (1 - np.exp(-np.arange(100, 110) / 400.0))
    np.testing.assert_allclose(run.T_C[100:110, 1], exact, atol=2e-3)  # chord of a slow curve
    assert run.valid["T2_C"].all()


def test_long_dropout_excluded(tmp_path):
    cols = warmup()
    cols["T4_C"][100:160] = np.nan  # 60 s > 30 s limit
    run = read_run(write(tmp_path, csv_text(cols)))
    f = one(run, "long_dropout", "T4_C")
    assert f["count"] == 60 and "excluded" in f["action"]
    assert not run.valid["T4_C"][100:160].any() and run.valid["T4_C"][:100].all()
    assert np.isfinite(run.T_C[:, 3]).all()
    s = run.at(np.array([50.0, 130.0, 250.0]))
    assert s.valid["T4_C"].tolist() == [True, False, True]


@pytest.mark.parametrize("name", ["coolant_C", "ambient_C"])
def test_the_air_and_coolant_hold_their_last_reading_through_a_gap(tmp_path, name):
    """The twin runs its boundaries at these: filled linearly, a 10-min gap in a coolant
    log ramped the inlet a window's forecast ran at towards a reading made after the
    window, which no causal twin has.  Held, as the speed is; a thermocouple's gap is
    still interpolated."""
    cols = warmup(n=900)
    cols["coolant_C"] = np.where(cols["time_s"] < 600.0, 22.0, 25.0)
    cols[name][300:600] = np.nan
    run = read_run(write(tmp_path, csv_text(cols)))
    f = one(run, "long_dropout", name)
    assert f["action"] == "held at the last reading for continuity; excluded from metrics"
    filled = run.coolant_C if name == "coolant_C" else run.ambient_C
    assert np.all(filled[300:600] == filled[299])
    assert not run.valid[name][300:600].any()
    cols["T3_C"][300:600] = np.nan
    run = read_run(write(tmp_path, csv_text(cols), "t3.csv"))
    assert one(run, "long_dropout", "T3_C")["action"] == (
        "linearly interpolated in time for continuity; excluded from metrics")


@pytest.mark.parametrize("name", ["T5_C", "speed_rpm"])
def test_the_samples_before_a_column_s_first_reading_are_invalid(tmp_path, name):
    """A missing first reading is a missing reading: no reading precedes it to hold, none
    to interpolate from, so it is invalid however short (it was a valid sample holding the
    next one's value, told as "linearly interpolated"); the first reading stands in."""
    cols = warmup()
    cols[name][:5] = np.nan
    cols["T5_C"][100:104] = np.nan  # a gap after the first reading is still interpolated
    run = read_run(write(tmp_path, csv_text(cols)))
    f = one(run, "leading_dropout", name)
    assert f["count"] == 5 and f["rows"] == [2, 3, 4, 5, 6] and f["spans_s"] == [[0.0, 4.0]]
    word = "speed" if name == "speed_rpm" else "reading"
    assert f["action"] == f"held at the first {word} for continuity; excluded from metrics"
    assert run.valid[name].tolist() == [False] * 5 + [True] * 295
    np.testing.assert_allclose(run.column(name)[:5], cols[name][5], atol=1e-4)
    assert one(run, "dropout", "T5_C")["rows"] == [102, 103, 104, 105]
    assert np.isnan(run.before(np.array([4.0])).T_valid_C[0, 4]) == (name == "T5_C")


def test_time_gaps(tmp_path):
    cols = warmup(n=400)
    keep = np.ones(400, dtype=bool)
    keep[50:60] = False    # 11 s without samples: short gap
    keep[200:260] = False  # 61 s: long gap
    cols = {k: v[keep] for k, v in cols.items()}
    run = read_run(write(tmp_path, csv_text(cols)))
    short = one(run, "short_gap", "time_s")
    assert short["spans_s"] == [[49.0, 60.0]]
    long = one(run, "long_gap", "time_s")
    assert long["spans_s"] == [[199.0, 260.0]] and run.gaps_s == [(199.0, 260.0)]
    s = run.at(np.array([55.0, 230.0]))
    assert s.valid_T[0].all() and not s.valid_T[1].any()
    b = run.before(np.array([240.0]))
    assert not b.valid["T1_C"][0]  # the last sample is older than the gap limit


def test_spikes_replaced(tmp_path):
    cols = noisy_warmup()
    cols["T1_C"][[80, 81, 300]] += [12.0, 11.0, -9.0]
    cols["ambient_C"][400] += 4.0
    run = read_run(write(tmp_path, csv_text(cols)))
    f = one(run, "spike", "T1_C")
    assert f["rows"] == [82, 83, 302]
    assert one(run, "spike", "ambient_C")["rows"] == [402]
    clean = noisy_warmup()["T1_C"]
    assert np.abs(run.T_C[[80, 81, 300], 0] - clean[[80, 81, 300]]).max() < 0.3
    assert kinds(run) == {"spike"}


def test_a_spikes_threshold_is_stated_with_its_unit(tmp_path):
    # quality.json and the report read "deviation above 0.5 from the running median"
    cols = noisy_warmup()
    cols["T1_C"][300] += 9.0
    cols["disp_z_um"] = np.linspace(0.0, 5.0, cols["time_s"].size)
    cols["disp_z_um"][200] += 6.0
    run = read_run(write(tmp_path, csv_text(cols)))
    assert one(run, "spike", "T1_C")["detail"].endswith(" K from the running median")
    assert one(run, "spike", "disp_z_um")["detail"].endswith(" µm from the running median")


def coarse_load_change(n=151, dt=4.0):
    """T1/T3 as `twin simulate` writes them at 0.25 Hz: a fast warm-up whose bearing load
    drops at 60 s (first-order responses, closed form), so the rings turn sharply there."""
    cols = warmup(n=n, dt=dt)
    t = cols["time_s"]
    for name, amp, low in (("T1_C", 16.0, 11.0), ("T3_C", 13.0, 9.0)):
        at_60 = amp * (1.0 - np.exp(-60.0 / 20.0))
        cols[name] = 22.0 + np.where(t <= 60.0, amp * (1.0 - np.exp(-t / 20.0)),
                                     low + (at_60 - low) * np.exp(-(t - 60.0) / 10.0))
        cols[name] += 2.0 * (1.0 - np.exp(-t / 400.0))  # the housing's slow warm-up
    return cols


def test_a_sharp_turn_at_coarse_sampling_is_not_a_spike(tmp_path):
    # the 11-sample median spans 40 s at 0.25 Hz: the samples just before the turn stand
    # 0.5-1.3 K off it, yet they continue the warm-up before them
    run = read_run(write(tmp_path, csv_text(coarse_load_change())))
    assert run.quality == []
    np.testing.assert_allclose(run.T_C[:, 0], coarse_load_change()["T1_C"], atol=1e-4)


def test_spikes_at_coarse_sampling_are_still_spikes(tmp_path):
    cols = coarse_load_change()
    clean = cols["T1_C"].copy()
    cols["T1_C"][[14, 60, 61]] += [3.0, -4.0, -3.5]  # one at the turn, one of two samples
    run = read_run(write(tmp_path, csv_text(cols)))
    assert one(run, "spike", "T1_C")["rows"] == [16, 62, 63]
    assert kinds(run) == {"spike"}
    assert np.abs(run.T_C[[60, 61], 0] - clean[[60, 61]]).max() < 0.05


def test_twin_simulate_output_reads_without_spikes(tmp_path, spindle_model):
    # `twin simulate`'s keypoints.csv is a clean run (disp_r_um is not a run column: ignored,
    # and said so), even with its loads held over 60 s windows, which turns each ring sharply
    # at 60 s: the samples of the warm-up before the turn are no spikes
    from twin.spindle import simulate
    from twin.spindle.output import keypoints_csv

    result = simulate(spindle_model, 15000.0, 5.0, 22.0, update_every_s=60.0)
    run = read_run(write(tmp_path, keypoints_csv(result)))
    assert {(f["column"], f["kind"]) for f in run.quality} == {("disp_r_um", "ignored_column")}


def test_speed_steps_are_not_spikes(tmp_path):
    cols = warmup()
    cols["speed_rpm"][150:] = 12000.0
    cols["speed_rpm"][151:156] = 0.0  # a real (if brief) stop is data, not a spike
    cols["speed_rpm"][200] = 6000.0  # a step of one sample up to a new speed: data too
    cols["speed_rpm"][201:] = 6000.0
    run = read_run(write(tmp_path, csv_text(cols)))
    assert run.quality == []
    np.testing.assert_array_equal(run.speed_rpm, cols["speed_rpm"])


@pytest.mark.parametrize("glitch", [0.0, 3000.0])
def test_one_sample_speed_glitch_takes_its_neighbours_speed(tmp_path, glitch):
    # A window takes its start sample's speed: one 0 rpm sample at 120 s stopped the
    # twin for the whole third minute.  No spindle stops and restarts within 2 s.
    cols = warmup()
    cols["speed_rpm"][120] = glitch
    run = read_run(write(tmp_path, csv_text(cols)))
    f = one(run, "glitch", "speed_rpm")
    assert f["rows"] == [122] and f["spans_s"] == [[120.0, 120.0]]
    assert (run.speed_rpm == 9000.0).all()
    assert run.before(np.array([120.0])).speed_rpm[0] == 9000.0


def test_one_sample_speed_change_is_data_when_its_neighbours_lie_far_apart(tmp_path):
    # at 0.1 Hz a single 0 rpm sample is a stop of 10-20 s: kept
    cols = warmup(n=60, dt=10.0)
    cols["speed_rpm"][30] = 0.0
    run = read_run(write(tmp_path, csv_text(cols)))
    assert run.quality == []
    assert run.speed_rpm[30] == 0.0


def test_speed_dropout_holds_the_last_speed(tmp_path):
    # a linear fill ramped across the step the gap hid: 9000 -> 3000 rpm in 10 s
    cols = warmup()
    cols["speed_rpm"][150:] = 3000.0
    cols["speed_rpm"][145:155] = np.nan
    run = read_run(write(tmp_path, csv_text(cols)))
    f = one(run, "dropout", "speed_rpm")
    assert f["action"] == "held at the last speed"
    np.testing.assert_array_equal(run.speed_rpm[145:155], 9000.0)
    assert run.speed_rpm[155] == 3000.0


def test_stuck_sensor_exact_value(tmp_path):
    cols = noisy_warmup()
    cols["T2_C"][:] = 25.0
    cols["T4_C"][300:] = cols["T4_C"][300]  # frozen halfway through the run
    run = read_run(write(tmp_path, csv_text(cols)))
    assert not run.valid["T2_C"].any()
    f4 = one(run, "stuck", "T4_C")
    assert f4["spans_s"] == [[300.0, 599.0]]
    assert run.valid["T4_C"][:300].all() and not run.valid["T4_C"][300:].any()
    assert {f["column"] for f in run.quality} == {"T2_C", "T4_C"}


def test_stuck_sensor_flat_with_noise(tmp_path):
    cols = noisy_warmup(n=1200)
    cols["T3_C"] = 25.0 + np.random.default_rng(5).normal(0, 0.05, 1200)
    run = read_run(write(tmp_path, csv_text(cols)))
    assert one(run, "stuck", "T3_C")["count"] == 1200
    assert not run.valid["T3_C"].any()


def test_a_thermocouple_without_values_is_dead_and_excluded(tmp_path):
    cols = noisy_warmup()
    cols["T3_C"][:] = np.nan
    run = read_run(write(tmp_path, csv_text(cols)))
    f = one(run, "dead", "T3_C")
    assert f["count"] == 600 and f["spans_s"] == [[0.0, 599.0]]
    assert "excluded" in f["action"]
    assert not run.valid["T3_C"].any() and all(run.valid[f"T{i}_C"].all() for i in (1, 2, 4, 5))
    assert np.isfinite(run.T_C).all()  # a stand-in nothing reads, never NaN in a solver
    assert kinds(run) == {"dead"}


def test_noisy_sensor_smoothed(tmp_path):
    cols = noisy_warmup()
    truth = warmup(n=600)["T5_C"]
    cols["T5_C"] = truth + np.random.default_rng(9).normal(0.0, 0.6, 600)
    run = read_run(write(tmp_path, csv_text(cols)))
    f = one(run, "noisy", "T5_C")
    assert "moving average" in f["action"]
    inner = slice(20, -20)
    assert np.std(run.T_C[inner, 4] - truth[inner]) < 0.2  # from 0.6 °C
    assert kinds(run) == {"noisy"}


def test_noisy_ambient_is_told_without_peers(tmp_path):
    # the ambient has no peer column: its finding said "(others 0 °C)"
    cols = noisy_warmup()
    cols["ambient_C"] = cols["ambient_C"] + np.random.default_rng(9).normal(0.0, 0.6, 600)
    run = read_run(write(tmp_path, csv_text(cols)))
    f = one(run, "noisy", "ambient_C")
    assert f["detail"].startswith("noise 0.") and "others" not in f["detail"]
    cols = noisy_warmup()
    cols["T5_C"] = cols["T5_C"] + np.random.default_rng(9).normal(0.0, 0.6, 600)
    f = one(read_run(write(tmp_path, csv_text(cols))), "noisy", "T5_C")
    assert "(others 0.0" in f["detail"]  # the thermocouples' median noise, about 0.05 °C


def test_time_offset_and_ignored_and_empty_columns(tmp_path):
    cols = warmup()
    cols["time_s"] = cols["time_s"] + 1000.0
    cols["vibration_g"] = np.zeros(300)
    cols["disp_x_um"] = np.full(300, np.nan)
    run = read_run(write(tmp_path, csv_text(cols)))
    assert run.time_s[0] == 0.0 and run.duration_s == 299.0
    assert kinds(run) == {"time_offset", "ignored_column", "empty_column"}
    assert run.disp_um is None


@pytest.mark.parametrize("size", [3, 11, 21])
def test_running_median_is_scipys_median_filter(size):
    # the spike filter's running median must be exactly scipy.ndimage's, edges included
    from scipy.ndimage import median_filter

    from twin.runs.quality import running_median

    rng = np.random.default_rng(size)
    for n in (size, size + 1, 600):
        v = np.round(rng.normal(20.0, 3.0, n), 1)  # rounded: ties, as in a 0.1 °C logger
        v[n // 2] += 50.0  # a spike
        np.testing.assert_array_equal(running_median(v, size),
                                      median_filter(v, size=size, mode="nearest"))


def test_a_report_tells_what_a_findings_count_counts_in_files_of_any_release():
    # correction_held counted windows under `count`, shown in the report's "samples"
    # column; it is `count_windows` now, and a quality.json written before still reads so
    from twin.loop.report import _finding_row

    held = {"column": "T1_C", "kind": "correction_held", "rows": [],
            "spans_s": [[180.0, 300.0]], "action": "held", "detail": ""}
    assert _finding_row({**held, "count_windows": 2})["count"] == "2 windows"
    assert _finding_row({**held, "count": 2})["count"] == "2 windows"  # an earlier file
    assert _finding_row({**held, "count_windows": 1})["count"] == "1 window"
    stuck = {**held, "kind": "stuck", "count": 76}
    assert _finding_row(stuck)["count"] == "76"
    assert _finding_row({"kind": "noisy"})["count"] == ""


def test_an_axial_probe_frozen_through_the_run_is_stuck_and_excluded(tmp_path):
    """A probe reading 20 µm (or exactly 0: a channel logging nothing) through 25 min at
    speed reads no drift: excluded from metrics and correction inputs as a stuck
    thermocouple is.  A probe that drifts, one next to 0 that moves a little (a column in
    mm, told elsewhere), and a flat probe of a spindle at rest or too short a run are
    left as they are."""
    cols = warmup(n=1500)
    rise = 1.0 - np.exp(-cols["time_s"] / 600.0)

    def probe(disp_um, speed=9000.0, n=1500):
        case = {k: v[:n] for k, v in cols.items()}
        case["speed_rpm"] = np.full(n, speed)
        case["disp_z_um"] = np.broadcast_to(disp_um, (1500,))[:n]
        return read_run(write(tmp_path, csv_text(case)))

    for level in (20.0, 0.0):
        run = probe(np.full(1500, level))
        found = one(run, "stuck", "disp_z_um")
        assert found["count"] == 1500 and found["spans_s"] == [[0.0, 1499.0]]
        assert found["action"] == "excluded from metrics and correction inputs"
        assert found["detail"] == (f"reads {level:g} µm throughout 25 min at speed: the nose "
                                   "drifts micrometres in minutes")
        assert not run.valid["disp_z_um"].any()
    assert kinds(probe(11.0 * rise), "disp_z_um") == set()  # drifts: µm
    assert kinds(probe(0.011 * rise), "disp_z_um") == set()  # in mm: not stuck
    # flat within a tenth of a micrometre of a level away from 0: stuck (logger noise)
    flat = 20.0 + 0.04 * np.sin(cols["time_s"])
    assert one(probe(flat), "stuck", "disp_z_um")["count"] == 1500
    assert kinds(probe(flat, speed=0.0), "disp_z_um") == set()  # at rest
    assert kinds(probe(flat, n=1100), "disp_z_um") == set()  # 18 min


def test_an_axial_probe_frozen_for_a_spell_is_stuck_there(tmp_path):
    """A logger channel that holds the probe's last reading for 5 min while the
    thermocouples warm: those samples are excluded as a stuck thermocouple's are, the rest
    kept.  A probe that resolves 0.1 µm repeats readings for tens of seconds as the drift
    levels off: not stuck."""
    cols = warmup(n=1500)
    drift = 11.0 * (1.0 - np.exp(-cols["time_s"] / 600.0))
    frozen = drift.copy()
    frozen[600:900] = frozen[600]
    run = read_run(write(tmp_path, csv_text({**cols, "disp_z_um": frozen})))
    found = one(run, "stuck", "disp_z_um")
    assert found["spans_s"] == [[600.0, 899.0]] and found["count"] == 300
    assert found["detail"] == "repeats one reading while the thermocouples move"
    assert np.flatnonzero(~run.valid["disp_z_um"]).tolist() == list(range(600, 900))
    for step_um in (0.1, 0.5, 1.0):  # a probe logged in steps repeats its readings
        resolved = step_um * np.round(drift / step_um)
        assert kinds(read_run(write(tmp_path, csv_text({**cols, "disp_z_um": resolved}))),
                     "disp_z_um") == set(), step_um


def test_a_flat_probe_is_frozen_or_in_mm_by_one_rule_and_a_log_gap_is_no_time_at_speed(
        tmp_path):
    """A probe in mm off 0 by 0.095 mm (0.095 to 0.106 in the column) was taken for stuck,
    the rules for 'stuck' and 'in mm' measuring it apart; and 20 min at speed could be 5
    min of samples and a gap in the log."""
    from twin.runs.quality import FLAT_FROZEN, FLAT_IN_MM, QualityConfig, flat_probe

    cfg = QualityConfig()
    t = np.arange(0.0, 1500.0, 1.0)
    speed, ok = np.full(t.size, 9000.0), np.ones(t.size, dtype=bool)
    drift_mm = 0.011 * (1.0 - np.exp(-t / 600.0))
    assert flat_probe(t, 0.095 + drift_mm, speed, ok, cfg)[0] == FLAT_IN_MM
    assert flat_probe(t, drift_mm, speed, ok, cfg)[0] == FLAT_IN_MM
    assert flat_probe(t, np.full(t.size, 0.0), speed, ok, cfg)[0] == FLAT_FROZEN
    assert flat_probe(t, 20.0 + 0.04 * np.sin(t), speed, ok, cfg)[0] == FLAT_FROZEN
    assert flat_probe(t, 11e3 * drift_mm, speed, ok, cfg) is None  # a drift in µm
    gap = np.r_[np.arange(0.0, 300.0, 1.0), np.arange(1500.0, 1800.0, 1.0)]
    assert flat_probe(gap, np.zeros(gap.size), np.full(gap.size, 9000.0),
                      np.ones(gap.size, dtype=bool), cfg) is None  # 10 min seen, not 30
