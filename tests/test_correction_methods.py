"""The per-window correction methods, closed loop on a lumped plant with a known truth."""

import dataclasses

import numpy as np
import pytest

from twin.correction import (
    BoundaryValues,
    OpenLoop,
    RatioCorrection,
    WindowFeatures,
    make_corrector,
)
from twin.correction.features import rise_over_window, window_line_fit
from twin.correction.toy_plant import ToyPlant

PLANT = ToyPlant()
SPEED = 9000.0
AMBIENT = 25.0
TRUE_HEAT = np.array([1.10, 0.90])  # truth / nominal
TRUE_RES = np.array([1.30, 0.80])


def _measured(seed=0, noise=0.05, heat=TRUE_HEAT, res=TRUE_RES, plant=PLANT):
    t = np.arange(0, 1801, 2.0)
    H = plant.nominal_heat_W_m3(SPEED) * heat
    R = plant.nominal_resistance_m2K_W(SPEED) * res
    T = plant.simulate(t, SPEED, AMBIENT, H, R)
    return t, T + np.random.default_rng(seed).normal(0, noise, T.shape)


def _nominal():
    return BoundaryValues(*PLANT.nominal_heat_W_m3(SPEED), *PLANT.nominal_resistance_m2K_W(SPEED))


def _twin(method, t_meas, T_meas, windows=30, heat=TRUE_HEAT, res=TRUE_RES, plant=PLANT):
    """Window-by-window twin of the plant driven by `method`; returns the values as factors
    on nominal per window and the mean |error| of T1..T5 against the truth after 600 s."""
    nominal = _nominal()
    prev = nominal
    sim_t, sim_T = [0.0], [np.full(5, AMBIENT)]
    history = []
    for k in range(windows):
        start = 60.0 * k
        seen = t_meas <= start
        f = WindowFeatures(k, start, SPEED, AMBIENT, t_meas[seen], T_meas[seen],
                           np.array(sim_t), np.array(sim_T), nominal, prev)
        c = method.correct(f)
        prev = c.values
        history.append(np.array(c.values) / np.array(nominal))
        steps = start + np.arange(0, 61, 4.0)
        T = plant.simulate(steps, SPEED, AMBIENT, np.array(c.values[:2]),
                           np.array(c.values[2:]), initial_C=sim_T[-1])
        sim_t += list(steps[1:])
        sim_T += list(T[1:])
    sim_t, sim_T = np.array(sim_t), np.array(sim_T)
    truth = plant.simulate(sim_t, SPEED, AMBIENT, plant.nominal_heat_W_m3(SPEED) * heat,
                           plant.nominal_resistance_m2K_W(SPEED) * res)
    late = sim_t > 600
    return np.array(history), np.abs(sim_T - truth)[late].mean(axis=0)


def test_open_loop_returns_nominal():
    t, T = _measured()
    values, _ = _twin(OpenLoop(), t, T, windows=12)
    assert np.all(values == 1.0)


def test_ratio_recovers_truth_and_beats_open_loop():
    t, T = _measured()
    _, err_open = _twin(OpenLoop(), t, T)
    values, err_ratio = _twin(RatioCorrection(), t, T)
    # the front ring (T1) is 0.5 K off open loop; the ratio twin is at least 3x closer
    assert err_open[0] > 0.3
    assert err_ratio[0] < err_open[0] / 3
    assert np.all(err_ratio[:4] < err_open[:4])
    late = values[-10:].mean(axis=0)
    assert late[0] == pytest.approx(TRUE_HEAT[0], abs=0.03)
    assert late[1] == pytest.approx(TRUE_HEAT[1], abs=0.04)
    assert late[2] == pytest.approx(TRUE_RES[0], abs=0.1)


def test_ratio_is_causal_and_window0_is_nominal():
    t, T = _measured()
    nominal = _nominal()
    sim_t = np.arange(0, 301, 4.0)
    sim_T = PLANT.simulate(sim_t, SPEED, AMBIENT, np.array(nominal[:2]), np.array(nominal[2:]))
    method = RatioCorrection()
    f_past = WindowFeatures(5, 300.0, SPEED, AMBIENT, t[t <= 300], T[t <= 300], sim_t, sim_T,
                            nominal, nominal)
    future = T.copy()
    future[t > 300] += 50.0  # whatever happens later must not matter
    f_all = WindowFeatures(5, 300.0, SPEED, AMBIENT, t, future, sim_t, sim_T, nominal, nominal)
    assert tuple(method.correct(f_past)) == tuple(method.correct(f_all))
    f0 = WindowFeatures(0, 0.0, SPEED, AMBIENT, t[:1], T[:1], sim_t[:1], sim_T[:1],
                        nominal, nominal)
    assert tuple(method.correct(f0)) == tuple(nominal)


def test_ratio_dead_sensor_keeps_previous_value():
    t, T = _measured()
    nominal = _nominal()
    previous = BoundaryValues(*(np.array(nominal) * 1.07))
    T = T.copy()
    T[:, 0] = np.nan  # T1 lost: front heat and front resistance have no signal
    sim_t = np.arange(0, 601, 4.0)
    sim_T = PLANT.simulate(sim_t, SPEED, AMBIENT, np.array(nominal[:2]), np.array(nominal[2:]))
    f = WindowFeatures(10, 600.0, SPEED, AMBIENT, t[t <= 600], T[t <= 600], sim_t, sim_T,
                       nominal, previous)
    c = RatioCorrection().correct(f)
    assert c.H_front_W_m3 == pytest.approx(previous.H_front_W_m3)
    assert c.R_front_m2K_W == pytest.approx(previous.R_front_m2K_W)
    assert c.C_H[0] == pytest.approx(1.0)


class _ConstantNet:
    """A stand-in model of the paper's kind: every network answers nominal × 1.2."""

    anchored = False

    def predict(self, output, x, anchor=None):
        return np.asarray(x)[:, 5] * 1.2


def test_bpnn_dead_sensor_keeps_previous_factor_on_moving_nominal():
    t, T = _measured()
    nominal_old = _nominal()
    # the nominal resistance fell since the last window (Eq. 5: the fit tightened)
    nominal_new = BoundaryValues(*(np.array(nominal_old) * [1.0, 1.0, 0.6, 0.6]))
    previous = BoundaryValues(*(np.array(nominal_old) * 1.07))
    T = T.copy()
    T[:, 1] = np.nan  # T2 (front sleeve) dead: the front resistance net has no input
    f = WindowFeatures(10, 600.0, SPEED, AMBIENT, t[t <= 600], T[t <= 600], t[t <= 600],
                       T[t <= 600], nominal_new, previous, previous_nominal=nominal_old)
    c = make_corrector("bpnn", model=_ConstantNet()).correct(f)
    factor = np.array(c.values) / np.array(nominal_new)
    # front resistance: the previous factor 1.07 on the new nominal, not the held value
    assert factor[2] == pytest.approx(1.07, rel=1e-12)
    assert factor[[0, 1, 3]] == pytest.approx([1.2, 1.2, 1.2], rel=1e-12)


class _ConstantCorrection:
    """A stand-in anchored model: every network answers anchor × 1.2."""

    anchored = True

    def predict(self, output, x, anchor=None):
        return np.asarray(anchor) * 1.2


def test_anchored_bpnn_corrects_the_ratio_law_and_a_dead_ring_is_read_through_its_sleeve():
    from twin.correction.methods import ANCHOR_LAW, ratio_anchor

    t, T = _measured()
    T = T.copy()
    T[:, 2] = np.nan  # T3 (rear ring) stuck, excluded by the quality check
    nominal = _nominal()
    previous = BoundaryValues(*(np.array(nominal) * 1.05))
    sim = T + np.array([0.3, 0.2, 0.0, 0.4, 0.0])  # the twin runs hot on the rear sleeve
    sim[:, 2] = sim[:, 3] + 0.5
    upto = t <= 600
    f = WindowFeatures(10, 600.0, SPEED, AMBIENT, t[upto], T[upto], t[upto], sim[upto],
                       nominal, previous, previous_factors=(1.05, 1.05, 1.05, 1.05))
    assert f.dead_rings() == ("rear",)
    anchor = ratio_anchor(f, np.full(4, 1.05))
    # the ratio law alone has no T3 and holds the rear heat factor; the anchor reads the
    # ring as the twin's ring off by as much as its sleeve is (0.4 K hot): the heat comes
    # down, and the resistance, which no drop tells, is held
    ratio = np.array(RatioCorrection().correct(f).values)
    assert ratio[1] / nominal[1] == pytest.approx(1.05, rel=1e-12)
    assert anchor[1] / nominal[1] < 1.0
    assert anchor[3] / nominal[3] == pytest.approx(1.05, rel=1e-12)
    # the stand-in: the twin's ring off by the sleeve's error (−0.4 K) over the sleeve's
    # rise, which here is most of the ring's (the rear sleeve, well over ambient)
    now = sim[upto][-1]
    ring_rise, sleeve_rise = now[2] - AMBIENT, now[3] - AMBIENT
    assert sleeve_rise > 0.5 * ring_rise
    stand_in = T[upto].copy()
    stand_in[:, 2] = sim[upto][:, 2] + ring_rise / sleeve_rise * (T[upto][:, 3] - sim[upto][:, 3])
    read = WindowFeatures(10, 600.0, SPEED, AMBIENT, t[upto], stand_in, t[upto], sim[upto],
                          nominal, previous, previous_factors=(1.05, 1.05, 1.05, 1.05))
    assert anchor[:3] == pytest.approx(np.array(ANCHOR_LAW.correct(read).values)[:3],
                                       rel=1e-12)
    # which is Eq. 2 on the sleeve itself, as the anchor read it before 2026-11-27
    on_sleeve = WindowFeatures(10, 600.0, SPEED, AMBIENT, t[upto], T[upto][:, [0, 1, 3, 3, 4]],
                               t[upto], sim[upto][:, [0, 1, 3, 3, 4]], nominal, previous,
                               previous_factors=(1.05, 1.05, 1.05, 1.05))
    assert anchor[1] == pytest.approx(ANCHOR_LAW.correct(on_sleeve).values[1], rel=1e-3)
    # the networks correct the anchor (× 1.2 here) where their inputs exist; the rear
    # bearing's networks never saw a stand-in for a ring, the anchor stands there
    method = make_corrector("bpnn", model=_ConstantCorrection())
    method.anchor_factors = np.full(4, 1.05)
    values = np.array(method.correct(f).values)
    assert values[[0, 2]] == pytest.approx(1.2 * anchor[[0, 2]], rel=1e-12)
    assert values[[1, 3]] == pytest.approx(anchor[[1, 3]], rel=1e-12)


@pytest.mark.parametrize("twin_offset_C", [-0.3, 0.3])
def test_a_dead_rings_sleeve_below_ambient_moves_the_heat_towards_the_measurement(
        twin_offset_C):
    """A front sleeve on a cooling jacket 1.5 K below ambient, T1 dead.  The twin's sleeve
    colder than the measured one asks for more heat, warmer for less, whichever side of
    ambient the sleeve is on.  Read as the ring over ambient, (−1.5)/(−1.8) = 0.83 cut the
    heat of a twin already too cold (and that cooled it further, to the guard)."""
    from twin.correction.methods import ratio_anchor

    t = np.arange(0.0, 601.0, 2.0)
    T = np.column_stack([np.full_like(t, np.nan), np.full_like(t, AMBIENT - 1.5),
                         np.full_like(t, AMBIENT + 8.0), np.full_like(t, AMBIENT + 5.0),
                         np.full_like(t, AMBIENT + 1.0)])
    sim = T.copy()
    sim[:, 0] = AMBIENT + 2.0  # the twin's front ring, 3.5 K over its sleeve
    sim[:, 1] += twin_offset_C
    nominal = _nominal()
    f = WindowFeatures(10, 600.0, SPEED, AMBIENT, t, T, t, sim, nominal, nominal)
    assert f.dead_rings() == ("front",)
    factors = ratio_anchor(f, np.ones(4)) / np.array(nominal)
    # Eq. 2 on the stand-in: 1 − offset / (half the ring's 2 K rise); the rest of the twin
    # matches the measurement: neutral
    assert factors[0] == pytest.approx(1.0 - twin_offset_C / 1.0, rel=1e-9)
    assert factors[1:] == pytest.approx([1.0, 1.0, 1.0], rel=1e-9)
    # a twin ring at ambient has no rise to scale the error by: the heat is held
    sim[:, 0] = AMBIENT
    held = WindowFeatures(10, 600.0, SPEED, AMBIENT, t, T, t, sim, nominal, nominal)
    assert ratio_anchor(held, np.ones(4)) / np.array(nominal) == pytest.approx(np.ones(4))
    # window 0 before the twin has a sample: nothing measured through a window yet (no
    # sensor is read, none stands in for another), the nominal values
    first = WindowFeatures(0, 0.0, SPEED, AMBIENT, t[:1], T[:1], np.zeros(0), np.zeros((0, 5)),
                           nominal, nominal)
    assert first.dead_rings() == ()
    assert ratio_anchor(first, np.ones(4)) == pytest.approx(np.array(nominal))


def test_speed_change_carries_the_factor():
    t, T = _measured()
    nominal_old = _nominal()
    nominal_new = BoundaryValues(*(np.array(nominal_old) * [2, 2, 1, 1]))
    previous = BoundaryValues(*(np.array(nominal_old) * 1.1))
    # the twin matched the measurement exactly: every ratio neutral
    f = WindowFeatures(10, 600.0, SPEED, AMBIENT, t[t <= 600], T[t <= 600], t[t <= 600],
                       T[t <= 600], nominal_new, previous, previous_nominal=nominal_old)
    c = RatioCorrection().correct(f)
    ratio = np.array(c.values) / np.array(nominal_new)
    assert ratio[:2] == pytest.approx([1.1, 1.1], rel=1e-9)
    # the resistances also see the (small) Eq. 5 pressure change over the last window
    assert ratio[2:] == pytest.approx([1.1, 1.1], rel=0.01)
    # C_H, C_C are on the previous values carried to the new speed (Eq. 3's H'): the speed
    # doubled the nominal heat, not the correction.  On the previous values themselves
    # every method, open loop too, showed C_H 2 here (1.82 at the bundled run's step)
    assert c.C_H == pytest.approx((1.0, 1.0), rel=1e-9)
    assert c.C_C == pytest.approx((1.0, 1.0), rel=0.01)
    opened = OpenLoop().correct(dataclasses.replace(f, previous=nominal_old))
    assert (opened.C_H, opened.C_C) == ((1.0, 1.0), (1.0, 1.0))


def test_correction_unpacks_and_reports_factors():
    nominal = _nominal()
    previous = BoundaryValues(*(np.array(nominal) * 0.5))
    f = WindowFeatures(3, 180.0, SPEED, AMBIENT, np.zeros(1), np.zeros((1, 5)), np.zeros(1),
                       np.zeros((1, 5)), nominal, previous)
    H_front, H_rear, R_front, R_rear = OpenLoop().correct(f)
    assert (H_front, H_rear, R_front, R_rear) == tuple(nominal)
    assert OpenLoop().correct(f).C_H == (2.0, 2.0)


def test_make_corrector_names():
    assert make_corrector("open_loop").name == "open_loop"
    assert make_corrector("ratio").name == "ratio"
    with pytest.raises(ValueError, match="needs a model"):
        make_corrector("bpnn")
    with pytest.raises(ValueError, match="unknown correction method"):
        make_corrector("magic")


def test_window_line_fit_on_a_line():
    t = np.arange(0, 121, 2.0)
    T = np.column_stack([20 + 0.01 * t, np.full(t.size, 30.0)])
    T[5, 0] = np.nan
    level, rise = window_line_fit(t, T, 120.0, 60.0)
    assert level == pytest.approx([21.2, 30.0])
    assert rise == pytest.approx([0.6, 0.0], abs=1e-12)
    assert np.isnan(rise_over_window(t[:1], T[:1], 0.0)).all()


def test_paper_literal_law_is_worse_in_closed_loop():
    # the documented reason the default gains differ from the paper's literal product
    from twin.correction.methods import PAPER_GAINS

    t, T = _measured()
    values_paper, err_paper = _twin(RatioCorrection(gains=PAPER_GAINS), t, T)
    values_default, err_default = _twin(RatioCorrection(), t, T)
    assert err_paper[0] > 2 * err_default[0]
    assert np.std(values_paper[-10:, 0]) > 3 * np.std(values_default[-10:, 0])


def test_ratio_law_does_not_cut_the_heat_of_a_ring_below_ambient():
    # a slow bearing on a coolant jacket colder than the air: its ring is measured 2.4 K
    # below ambient, the twin's 4.2 K below (the twin too cold: too little heat).  Eq. 2 on
    # the two negative rises gave 0.57 and cut the heat, cooling the twin further; the
    # ratio law and bpnn's anchor now hold the heat there
    from twin.correction.methods import ratio_anchor

    t = np.arange(0.0, 601.0, 2.0)
    measured = np.tile([AMBIENT - 2.4, AMBIENT - 3.0, AMBIENT + 3.0, AMBIENT + 2.0, AMBIENT],
                       (t.size, 1))
    simulated = measured + np.array([-1.8, -1.8, 0.0, 0.0, 0.0])
    nominal = _nominal()
    f = WindowFeatures(10, 600.0, SPEED, AMBIENT, t, measured, t, simulated, nominal, nominal)
    for values in (RatioCorrection().correct(f).values, ratio_anchor(f, np.ones(4))):
        factors = np.array(values) / np.array(nominal)
        assert factors[0] == pytest.approx(1.0)  # the front heat is held, not 0.57
        assert factors[1] == pytest.approx(1.0)  # the rear ring matches: unchanged


def test_anchor_does_not_read_a_dead_sleeve_on_its_last_value():
    from twin.correction.methods import ANCHOR_LAW, ratio_anchor

    t, T = _measured()
    T = T.copy()
    T[(t > 300) & (t <= 600), 3] = np.nan  # T4 (rear sleeve) drops out while warming up
    nominal = _nominal()
    previous = BoundaryValues(*(np.array(nominal) * 1.05))
    sim = T + np.array([0.3, 0.2, 0.4, 0.1, 0.0])
    sim[:, 3] = np.where(np.isnan(sim[:, 3]), T[:, 2] - 1.0, sim[:, 3])  # the twin has T4
    upto = t <= 600
    factors = (1.05, 1.05, 1.05, 1.05)
    f = WindowFeatures(10, 600.0, SPEED, AMBIENT, t[upto], T[upto], t[upto], sim[upto],
                       nominal, previous, previous_factors=factors)
    absent = T[upto].copy()
    absent[:, 3] = np.nan  # as if the rear sleeve had never been recorded
    g = WindowFeatures(10, 600.0, SPEED, AMBIENT, t[upto], absent, t[upto], sim[upto],
                       nominal, previous, previous_factors=factors)
    anchor = ratio_anchor(f, np.array(factors))
    # read on T4 at 300 s as now, a ring-to-sleeve drop the twin's moving sleeve cannot
    # match landed on the rear resistance in this one window (in the `ratio` method, the
    # Eq. 5 pressure factor of the whole warm-up as well); the anchor, its law and the
    # `ratio` method hold what the dead sleeve would correct, as for a sensor never
    # recorded, and read the front bearing and the rear heat as before
    assert anchor[3] / nominal[3] == pytest.approx(1.05, rel=1e-12)
    assert anchor == pytest.approx(np.array(ANCHOR_LAW.correct(g).values), rel=1e-12)
    for law in (ANCHOR_LAW, RatioCorrection()):
        assert law.correct(f).values == pytest.approx(law.correct(g).values, rel=1e-12)
    assert anchor[[0, 1]] != pytest.approx(1.05 * np.array(nominal[:2]), rel=1e-3)


def test_anchored_inputs_are_relative_to_the_twins_rise_and_drop():
    """Twice the heat flux doubles every rise, drop and error; the networks' rows (their
    loop gain on a log factor) stay the same, as the ratio law's Eq. 2 and Eq. 6 do."""
    t, T = _measured(noise=0.0)
    sim = AMBIENT + (T - AMBIENT) * np.array([1.1, 0.95, 1.1, 1.0, 1.0])
    upto = t <= 900
    nominal = _nominal()
    anchor = np.array(nominal) * 1.1

    def rows(scale):
        f = WindowFeatures(15, 900.0, SPEED, AMBIENT, t[upto],
                           AMBIENT + scale * (T[upto] - AMBIENT), t[upto],
                           AMBIENT + scale * (sim[upto] - AMBIENT), nominal, nominal)
        return f.anchored_inputs(anchor)

    # (×4: the twin's rear drop, 0.4 K here, is then above the 0.5 K floor of the divisor)
    once, twice = rows(4.0), rows(8.0)
    for output in once:
        assert np.all(np.isfinite(once[output]))
        assert twice[output] == pytest.approx(once[output], rel=1e-9, abs=1e-12)
    # the resistance rows carry the drop error per unit of the twin's drop
    ring, sleeve = 0, 1
    level = window_line_fit(t[upto], AMBIENT + 4 * (T[upto] - AMBIENT), 900.0)[0]
    level_sim = window_line_fit(t[upto], AMBIENT + 4 * (sim[upto] - AMBIENT), 900.0)[0]
    drop_error = (level[ring] - level[sleeve]) - (level_sim[ring] - level_sim[sleeve])
    assert once["resistance_front"][0, 2] == pytest.approx(
        drop_error / (level_sim[ring] - level_sim[sleeve]), rel=1e-9)


class _AnchorOnly:
    """A stand-in anchored model whose networks all answer 0: bpnn is its anchor."""

    anchored = True

    def predict(self, output, x, anchor=None):
        return np.asarray(anchor, dtype=float)


def test_anchor_closes_a_doubled_rear_contact_under_a_heat_surge():
    """Closed loop on the lumped plant from a cold start, the rear bearing's heat 1.5× and
    its contact resistance 2× nominal (suite 7070 run 9's truth, rounded).  In the first
    windows the heat correction is large, and the ring-to-sleeve drop is heat flux ×
    resistance: what the heat change explains must come out of the drop ratio before the
    per-window clip, else a drop 3× the twin's (clip 1.25) over a heat change of 1.5 moves
    the resistance *down*, away from the truth (the law the `ratio` method keeps)."""
    from twin.correction.methods import ANCHOR_GAINS

    heat, res = np.array([1.0, 1.5]), np.array([1.0, 2.0])
    t, T = _measured(heat=heat, res=res)
    values, err = _twin(make_corrector("bpnn", model=_AnchorOnly()), t, T, heat=heat, res=res)
    rear = values[:, 3] / res[1]
    # the first correction moves the resistance towards the truth, by the guard's full
    # step (1.25); within 10 % of it after five windows, and it stays near it
    assert rear[1] == pytest.approx(1.25 / res[1], rel=1e-9)
    assert abs(rear[5] - 1) < 0.1
    assert rear[-10:].mean() == pytest.approx(1.0, abs=0.05)
    assert np.all(np.abs(rear[-10:] - 1) < 0.15)
    assert values[-10:, 1].mean() == pytest.approx(heat[1], rel=0.03)
    assert err[2:4].max() < 0.08  # T3, T4 after 10 min, K
    # clipped before the heat share (the `ratio` method's order), the first correction
    # lowers the doubled resistance to 0.6× nominal and the rear twin runs 2× further off
    clip_first = RatioCorrection(gains=ANCHOR_GAINS)
    old_values, old_err = _twin(clip_first, t, T, heat=heat, res=res)
    assert old_values[1, 3] < 0.7
    assert np.all(old_err[2:4] > 2 * err[2:4])


def test_the_ratio_law_and_the_anchor_count_the_contact_pressure_change_once():
    """The loop evaluates the nominal resistance every window with Eq. 4/5 at the twin's own
    ring and sleeve temperatures.  A twin that matches the measurement exactly while its
    rings warm ahead of the sleeves (the fit tightens, R falls) has that fall in its new
    nominal value already: the anchor keeps its factor on it (the ratio law leaves a value
    that matches unchanged), where applying the measured Eq. 5 change as well would lower
    the resistance by the same fall a second time."""
    from twin.correction.formulas import ContactFit, contact_pressure_factor
    from twin.correction.methods import ANCHOR_GAINS, ratio_anchor

    t = np.arange(0, 121, 2.0)
    T = PLANT.simulate(t, SPEED, AMBIENT, np.array(_nominal()[:2]), np.array(_nominal()[2:]))
    start = 60.0  # the first minute: the rings warm by kelvins, their sleeves hardly
    seen = t <= start
    cold = np.array(_nominal())
    # Eq. 5 of the twin's (= the measured) rings and sleeves, as the loop's nominal values
    fits = (ContactFit(), ContactFit(fit_radius_m=0.0425))
    now = T[seen][-1] - T[0]
    fall = np.array([float(contact_pressure_factor(now[r], now[r + 1], fit))
                     for r, fit in zip((0, 2), fits, strict=True)])
    assert np.all(fall < 0.98)  # the rings run ahead of their sleeves: R fell
    nominal = BoundaryValues(*cold[:2], *(cold[2:] * fall))
    factors = np.array([1.1, 0.9, 1.3, 0.8])
    previous = BoundaryValues(*(cold * factors))
    f = WindowFeatures(1, start, SPEED, AMBIENT, t[seen], T[seen], t[seen], T[seen], nominal,
                       previous, previous_factors=tuple(factors))
    anchor = ratio_anchor(f, factors) / np.array(nominal)
    assert anchor == pytest.approx(factors, rel=1e-12)
    # so does the `ratio` method: its resistances keep their factors (its heats are
    # Eq. 2 on a ring that matches: unchanged too)
    ratio = np.array(RatioCorrection().correct(f).values) / np.array(nominal)
    assert ratio == pytest.approx(factors, rel=1e-12)
    # the literal Eq. 5 step on top lowers both resistances by the fall a second time
    for gains in (ANCHOR_GAINS, (1.0, 0.0, 0.5)):
        with_eq5 = np.array(RatioCorrection(gains=gains, pressure_step=True).correct(f).values)
        assert np.all(with_eq5[2:] / np.array(nominal[2:]) < 0.99 * factors[2:])


def test_series_resistance_correction_is_newtons_step_beyond_the_noise():
    from twin.correction.formulas import series_resistance_correction

    limits = (0.8, 1.25)
    # a drop ∝ R + R_m (R_m = 1.27, R = 1 → the truth 0.8): the drop ratio is 2.07/2.27
    ratio = (0.8 + 1.27) / (1.0 + 1.27)
    assert series_resistance_correction(1.0, ratio, 1.27, 0.0, limits) == pytest.approx(0.8)
    assert series_resistance_correction(1.0, ratio, 0.0, 0.0, limits) == pytest.approx(ratio)
    # within the noise band the ratio moves R as Eq. 6; beyond it, R + R_m takes the rest
    assert series_resistance_correction(1.0, 0.97, 1.27, 0.05, limits) == pytest.approx(0.97)
    noisy = series_resistance_correction(1.0, ratio, 1.27, 0.05, limits)
    assert noisy == pytest.approx((np.exp(-0.05) + 1.27) * ratio * np.exp(0.05) - 1.27)
    assert 0.8 < noisy < ratio
    assert series_resistance_correction(1.0, 0.85, 1.27, 0.0, limits) == pytest.approx(0.8)
    assert series_resistance_correction(2.0, 1.2, 1.27, 0.0, limits) == pytest.approx(2.5)


def test_spindle_contact_metal_is_the_twins_drop_elasticity(spindle_model):
    """`SPINDLE_CONTACT_METAL` against the FEM twin: the steady ring-to-sleeve drop's
    elasticity to the contact resistance at nominal, e = R/(R + R_m)."""
    from twin.correction.methods import SPINDLE_CONTACT_METAL
    from twin.spindle.conditions import nominal_conditions

    bc = nominal_conditions(spindle_model, 9000.0, 20.0)

    def drops(factor):
        loads = bc.to_thermal_loads(R_front=bc.R_front * factor, R_rear=bc.R_rear * factor)
        T = spindle_model.sensor_matrix @ spindle_model.thermal.steady(loads)
        return np.array([T[0] - T[1], T[2] - T[3]])

    elasticity = np.log(drops(1.05) / drops(1.0)) / np.log(1.05)
    assert 1.0 / (1.0 + np.array(SPINDLE_CONTACT_METAL)) == pytest.approx(elasticity, abs=0.01)


def test_anchor_resistance_step_counts_the_metal_on_the_lumped_plant():
    """The lumped plant with the metal between the sensors and the contact in series with
    it, sized like the spindle's (e = 0.44 front, 0.50 rear) with drops of 1.5–3 K.  The
    resistance step alone (the heat known: Eq. 2 off) from a cold start: a contact at 0.5
    or 2× nominal is within 10 % for good in fewer windows with the metal counted than
    with Eq. 6, and at the truth the noise swings it no more."""
    import dataclasses

    from twin.correction.methods import ANCHOR_LAW

    plant = ToyPlant(contact_area_m2=(2.3e-3, 1.67e-3), contact_metal_W_K=(18.0, 13.9))
    contact_W_K = np.array(plant.contact_area_m2) / plant.nominal_resistance_m2K_W(SPEED)
    metal = tuple(float(m) for m in contact_W_K / np.array(plant.contact_metal_W_K))
    assert 1.0 / (1.0 + np.array(metal)) == pytest.approx([0.44, 0.50], abs=0.005)
    law = dataclasses.replace(ANCHOR_LAW, gains=(0.0, 0.0, 1.0), metal_factors=None)
    newton = dataclasses.replace(law, metal_factors=metal)

    def run(method, factor, seed):
        heat, res = np.ones(2), np.full(2, factor)
        t, T = _measured(seed=seed, heat=heat, res=res, plant=plant)
        values, _ = _twin(method, t, T, heat=heat, res=res, plant=plant)
        return np.log(values[:, 2:] / res)

    def windows_to_settle(log_error):
        inside = np.abs(log_error) < np.log(1.1)
        return [next(k for k in range(len(inside) + 1) if inside[k:, j].all()) for j in (0, 1)]

    seeds = (0, 1, 2)
    for factor in (0.5, 2.0):
        for seed in seeds:
            fast = windows_to_settle(run(newton, factor, seed))
            slow = windows_to_settle(run(law, factor, seed))
            assert max(fast) <= 5
            assert all(f <= s for f, s in zip(fast, slow, strict=True))
            assert sum(fast) < sum(slow)
    swing = {name: np.mean([run(m, 1.0, seed)[-15:].std(axis=0) for seed in seeds], axis=0)
             for name, m in (("law", law), ("newton", newton))}
    assert np.all(swing["newton"] <= swing["law"] * 1.0001)
    assert np.all(swing["law"] < 0.02)


def _gap_features(previous_factors=(1.07, 0.95, 1.2, 0.9)):
    """Window 10 of the lumped plant whose logger recorded nothing over its last minute
    (every T column NaN in (540, 600] s), the twin 0.3–0.6 K off the measurement."""
    t, T = _measured()
    upto = t <= 600
    T, sim = T[upto].copy(), T[upto] + np.array([0.6, 0.3, -0.4, 0.2, 0.0])
    T[t[upto] > 540] = np.nan
    nominal = _nominal()
    previous = BoundaryValues(*(np.array(nominal) * previous_factors))
    return WindowFeatures(10, 600.0, SPEED, AMBIENT, t[upto], T, t[upto], sim, nominal,
                          previous, previous_factors=previous_factors), nominal


def test_ratio_holds_its_factors_through_a_logger_gap():
    """Nothing measured in the window just ended: the law has nothing to compare the twin
    with and holds every value.  Read on the last values before the gap, it compared a
    ring a minute old with the twin's moving one, and the Eq. 5 pressure factor of the whole
    warm-up (the previous level's being unknown) cut both resistances in one window."""
    f, nominal = _gap_features()
    factors = np.array(RatioCorrection().correct(f).values) / np.array(nominal)
    assert factors == pytest.approx([1.07, 0.95, 1.2, 0.9], rel=1e-12)


def test_paper_bpnn_holds_its_factors_through_a_logger_gap():
    """A paper-configuration model's inputs are the measured key points at the window
    start: without a valid sample in the last window there are none, and every value keeps
    its previous factor instead of the networks reading the last values before the gap."""
    f, nominal = _gap_features()
    factors = np.array(make_corrector("bpnn", model=_ConstantNet()).correct(f).values)
    assert factors / np.array(nominal) == pytest.approx([1.07, 0.95, 1.2, 0.9], rel=1e-12)


def test_a_window_is_measured_through_only_with_two_samples_in_each_20_s_bin():
    """The estimator's rule for an observation (a bin of 20 s with at least two valid
    samples) over the whole window the ratio law's line reads."""
    from twin.correction.features import window_observed

    t = np.arange(0.0, 601.0, 1.0)
    T = np.column_stack([t, t, t])
    T[t > 541, 1] = np.nan  # a lone sample at the window's start: 59 s old
    T[t > 570, 2] = np.nan  # the last 30 s lost: a line would extrapolate them
    assert window_observed(t, T, 600.0).tolist() == [True, False, False]
    slow = np.arange(0.0, 601.0, 10.0)  # the slowest rate a recorded run may have
    assert window_observed(slow, slow, 600.0).tolist() == [True]


def test_ratio_holds_what_a_sensor_lost_mid_window_corrects():
    """The logger stops 30 s before the window start: the line through the first half
    would stand for the second; the law holds instead, as for a whole window lost."""
    f, nominal = _gap_features()
    t, T = _measured()
    T = T[t <= 600].copy()
    t = t[t <= 600]
    T[t > 570] = np.nan
    g = WindowFeatures(10, 600.0, SPEED, AMBIENT, t, T, f.simulated_time_s, f.simulated_C,
                       nominal, f.previous, previous_factors=f.previous_factors)
    factors = np.array(RatioCorrection().correct(g).values) / np.array(nominal)
    assert factors == pytest.approx([1.07, 0.95, 1.2, 0.9], rel=1e-12)


def test_anchored_bpnn_networks_read_nothing_of_a_sensor_lost_mid_window():
    """The logger stops 30 s before the window start: the anchor holds (ratio_anchor leaves
    the sensors out), and so must the networks: their inputs are lines through the same
    window, and read on the first half they stood for the second (the `ratio` method's and
    the paper configuration's rule, which quality.json's correction_held tells)."""
    f, nominal = _gap_features()
    t, T = _measured()
    T = T[t <= 600].copy()
    T[t[t <= 600] > 570] = np.nan
    g = dataclasses.replace(f, measured_C=T)
    assert not g.seen_in_last_window()[:4].any()
    method = make_corrector("bpnn", model=_ConstantCorrection())
    method.anchor_factors = np.array(f.previous_factors)
    factors = np.array(method.correct(g).values) / np.array(nominal)
    # held, not the networks' 1.2 on the anchor
    assert factors == pytest.approx([1.07, 0.95, 1.2, 0.9], rel=1e-12)


def test_a_slow_jittery_logger_still_observes_its_windows():
    # at 0.1 Hz (the slowest rate a run may have) a 20 s bin holds two rows, and ±0.3 s of
    # time-stamp jitter left one in every other bin: ratio and bpnn held their corrections
    # in 21 of 29 windows of a clean run (and the estimator dropped those bins)
    from twin.correction.features import min_bin_samples, window_observed

    rng = np.random.default_rng(3)
    slow = np.arange(0.0, 130.0, 10.0) + np.r_[0.0, rng.uniform(-0.3, 0.3, 12)]
    # (20, 40] holds one row (30.2; the one at 40 came out at 40.05)
    assert ((slow > 20) & (slow <= 40)).sum() == 1
    values = np.full((slow.size, 1), 25.0)
    assert min_bin_samples(slow[(slow > 0) & (slow <= 60)]) == 1
    assert window_observed(slow, values, 60.0).all()
    # 1 Hz: a lone valid sample in a bin is still too little
    fast = np.arange(0.0, 121.0)
    lone = np.full((fast.size, 1), np.nan)
    lone[(fast > 0) & (fast <= 60)] = 25.0
    lone[(fast > 20) & (fast <= 39)] = np.nan  # (20, 40] keeps only t = 40
    assert min_bin_samples(fast) == 2
    assert not window_observed(fast, lone, 60.0).all()
    lone[(fast > 20) & (fast <= 38)] = np.nan
    lone[38] = 25.0  # two valid samples: observed
    assert window_observed(fast, lone, 60.0).all()
    assert min_bin_samples(np.arange(0.0, 60.0, 5.0)) == 2  # 0.2 Hz: four rows a bin
    assert min_bin_samples(np.array([1.0])) == 2
