"""Method `estimator`: joint, causal state–parameter estimation with an ensemble Kalman filter.

What it estimates
    The twin's temperature field (every dof) and log-factors φ on nominal boundary values
    (`twin.estimation.parameters.DEFAULT_PARAMETERS`): bearing heat (front, rear), ring/sleeve
    contact resistance (front, rear), motor loss, the film coefficients of the coolant jacket
    and of the rotor group (rotor ends, shaft, nose, internal air), and an effective
    thermal-expansion factor (every material's α; it scales the nose drift and moves no
    temperature, so only the recorded drift updates it), and the thermocouples' common time
    constant (a factor on the assumed 10 s, seen only through T1..T5's readings; see
    "Thermocouples") and each thermocouple's additive offset (K; "Thermocouple
    offsets").  The housing and air-gap film factors are available
    (`EstimatorConfig.parameters`) but not estimated by default.  On a run that records no
    coolant inlet (no `coolant_C` column), also the inlet's offset from the ambient, in K
    (`coolant_offset`; "Coolant inlet").

Why these (sensitivity and observability study, `python -m twin.estimation.sensitivity`,
run with the twin model itself: 30 min from a cold start, T1..T5 and the axial drift every
60 s, forward differences of 0.05 in each log-factor; J/σ with σ = 0.1 K per sample)
    Peak response per unit log-factor at 9000 rpm (K on T1..T5 | µm of drift):
        H_front 12.5 4.2 0.1 0.1 0.0 | 11.2     H_rear  0.0 0.0 17.6 12.4 0.0 | 0.1
        R_front  3.5 0.3 0.0 0.0 0.0 |  1.4     R_rear  0.0 0.0  2.3  0.8 0.0 | 0.0
        motor    0.8 0.3 2.8 2.1 0.6 |  1.3     rotor   2.1 0.7  4.8  3.4 0.0 | 6.2
        coolant  0.9 1.0 0.5 0.5 0.7 |  0.5     air gap 0.4 0.1  1.3  0.9 0.0 | 1.0
        housing  0.0 0.0 0.4 0.5 0.0 |  0.0
    Singular values of J/σ (all nine): 1010, 731, 101, 81, 71, 37, 8.7, 5.7, 2.9 (at 4000
    rpm: 330 … 4.0, 2.9, 1.0).  The last three directions are (v7) motor + coolant + rotor
    film together, (v8) air gap with housing and motor, (v9) housing film.  J/σ counts 30
    samples as independent; the model-form error that matters here (placement, mesh,
    conductivity) is correlated over the run and about 0.2–0.3 K, which divides these
    values by roughly 5–10: v7–v9 fall to about one noise unit — not identifiable.
    Consequences: the housing film is left out (it moves no sensor or drift measurably);
    the air-gap film is left out (weak, and confounded with the rotor film and motor loss,
    which carry the same rotor heat path).  Motor loss, coolant film and rotor film, which
    together form v7, are all estimated although a run at one steady speed cannot tell them
    apart: the runs that matter do.  A stop takes the motor loss away but not the jacket's
    cooling, and a speed step moves the motor loss and the rotor films but not the coolant
    film.  With the coolant film left out (the earlier default: it matters least for the
    drift, 0.5 µm against 1.3 and 6.2), a jacket film at 0.62× its correlation was
    explained while running by motor loss ≈ 2.2× and a rear contact at 0.44× (truths 1.22×
    and 0.77×); at the stop the motor heat that had stood in for the weak jacket vanished,
    and T3 ran 0.5–1.0 K warm for all eight stopped minutes, with the members' spread there
    down to 0.03 K so that no analysis could pull it back (suite 7777 run 12).  Estimated,
    the coolant film ends the run within 20 % of the truth on 19 of 24 runs (suites 7777,
    8888; the motor and rotor film mostly with it); the five misses (0.69×, 0.72×, 1.25×,
    1.30×, 1.38× the truth) move along v7 together with the motor and rotor film, two of
    them on runs whose air-gap film (not estimated) is 40 % off.  Measured
    (temperature and deformation accuracy, median / worst of 12 runs): suite 8888
    99.71 / 99.45 and 98.12 / 96.13 % → 99.75 / 99.45 and 98.21 / 96.16 %; suite 7777
    99.65 / 99.47 and 97.59 / 95.57 % → 99.67 / 99.52 and 97.96 / 95.61 % (with the
    inflation of 1.2, below; the coolant film alone gives 99.67 / 99.50 and 97.91 / 95.61
    on 7777).  Estimating all nine films and factors (housing and air gap too) measured no
    better (7777: 99.67 / 99.48, 97.90 / 95.61 %).
    Conductivity is not estimated: it is nearly collinear with the contact and film factors
    in T1..T5.  Expansion moves no temperature: with T1..T5 alone it is unobservable and
    keeps its prior (±5 %, which then widens the drift band); with the recorded drift it is
    the one factor the drift pins down beyond what T1..T5 already fix (its sensitivity is
    the drift itself, 5–18 µm per unit log-factor, against a probe noise of 0.05–0.3 µm),
    and it absorbs what else scales the drift uniformly (conductivity, the structural
    model).  The drift also sharpens the rotor film and motor loss (v7 above: the shaft,
    which no thermocouple sees, carries 6.2 µm per unit log-factor of rotor film).

The filter (Evensen 2009; REFERENCE.md §7)
    Ensemble of N members (default 24) as mean + anomalies of [T; φ] (`ensemble`; the
    initial anomalies have exactly the prior covariance, no spurious correlation).  Each
    window: (1) analysis with the measurements of the window just ended (ETKF, `analysis`;
    T1..T5 averaged over three 20 s bins: 15 observations; invalid samples — dead, stuck,
    dropped out per the data-quality check — are left out), updating field and log-factors
    through their ensemble covariance with the predicted sensor values inside the window;
    if the speed changed inside that window (after its loads were fixed), that window is
    first re-run from its start field with the recorded speed from the change on (all of it
    measured before the window now starting), so neither the innovations nor the analysed
    field carry the unforeseen input (`speed_change_s`, `_rerun`).  So is a window whose
    recorded coolant inlet moved more than `rerun_inlet_K` (0.2 K, in a 20 s bin's mean)
    from the inlet its forecast held: re-run with the recorded inlet step by step
    (`_moved_inlet`).  A chiller cycling ±2 K every 10 min cost 0.2–0.3 points of
    temperature accuracy (three runs: 99.48, 99.50, 99.09 → 99.68, 99.73, 99.41 %; motor
    loss read 1.9× where it was 0.9×); on suites 733104 and 381966, whose inlets drift
    slowly, no figure moved by more than 0.02.  With the loads held for
    each window (`loads_follow_rings=False`) the first window of a run is re-run too
    (with the default following loads its forecast already is that re-run): from a cold
    start the rings warm by kelvins in a minute and the
    Palmgren heat falls by a fifth with the oil's viscosity, which the forecast held at
    its cold value for 60 s; the first analysis read that as bearing heat 15–25 % low and
    the second window started 1–2 K cold (suite 112233 run 8).  A re-run re-evaluates the
    nominal bearing heat and contact resistance every solver step at its own temperatures,
    as the spindle's follow its rings (every 20 s in the measurements that follow).
    Measured on suites 8888, 7777, 909, 112233 (used to design it) and 2024, 60606,
    31415, 271828, 5150, 60221 (not): mean temperature
    accuracy +0.004 to +0.022 points on every suite, mean deformation +0.004 to +0.08;
    re-running every window this way measured the same at three factorizations per
    window.  After the analysis the loop's nominal bearing heat and contact resistance
    are re-evaluated at the analysed field's temperatures (Palmgren's viscosity follows
    the ring);
    (2) random walk of the log-factors (seeded draws: a replay is deterministic), spread
    capped at the prior, mean clipped to the bounds; (3) forecast of the next window
    (`forecast`): the mean by the FEM with the mean factors, members tangent-linear on one
    factorization, stepping 20 s.  The mean's nominal bearing heat and contact resistance
    follow its own ring and sleeve temperatures every 4 s solver step (`loads_follow_rings`,
    `twin.correction.rerun.LOAD_UPDATE_STEPS`, as a re-run takes them), the factors held:
    the factors are the correction, the nominal values' dependence on temperature is
    physics the spindle obeys within the minute too.  Held for 60 s instead, the first
    window at a new speed ran up to 3.8 K warm at the front ring after a step from 3100
    to 13 400 rpm on a window boundary, as the cold rings' Palmgren heat was kept while
    they warmed, and the next analysis read that as too much bearing heat (the window
    after ran 1.1 K cold).
    Multiplicative inflation (default 1.2) guards against
    collapse; the bounded log-space priors against drift.  1.2 rather than 1.05 because the
    model-form error keeps the members too sure of the drift after starts, steps and stops
    (prior drift spread 0.07–0.14 µm against misfits of 0.2–0.5 µm): deformation median
    +0.04 to +0.14 points on suites 7777 and 8888, temperature +0.01; 1.3 measured the same.

Iterated first analysis (`analysis_iterations`, `iterated_windows`)
    A run's first analysis is the one far from linear: the members carry the whole prior
    (±30–40 % on the heat and contact factors) through a cold start, where a ring's
    temperature answers its heat factor e^φ and its Palmgren heat follows the ring.  One
    ETKF step linearises at the prior mean; with a rear bearing at 1.8× its heat it took
    1.68×, put the rest into the rear contact (0.66×), and window 1 ran up to 1.7 K off
    (the test's emulated cold start; with the loads held for 20 s, before this stop's
    change to every step, the lag took a share too).  So the first analysis iterates,
    as the iterative ensemble Kalman filter does (Sakov, Oliver & Bertino 2012; Bocquet &
    Sakov 2014): the window is forecast again from its start moved by the weights found
    (x̄₀ + X₀ w: field, log-factors and the readings with the moved lag; held factors
    stay), the members linearised there, and a Gauss–Newton step taken on the cost in
    ensemble space J(w) = (N − 1)/(2ρ)|w|² + ½|y − ȳ(w)|²_R⁻¹ (`analysis.etkf_weights`).
    The analysis is the last forecast's end moved by its members times the last step,
    its anomalies those members through the last transform; with one iteration this is
    the plain ETKF exactly.  Measured (temperature accuracy median / worst, %; plain →
    three iterations): suites 424242 99.73 / 99.45 → 99.74 / 99.49, 141421 99.79 / 99.52
    → 99.81 / 99.52, 173205 99.74 / 99.46 → 99.76 / 99.50, 777000 99.73 / 99.64 → 99.74 /
    99.65, 2024 99.76 / 99.63 → 99.76 / 99.64, 11235 99.79 / 99.40 → 99.80 / 99.43, 86420
    99.78 / 99.53 → 99.79 / 99.55, 5150 99.80 / 99.59 → 99.81 / 99.60, 271828 99.77 /
    99.44 → 99.78 / 99.46 (the mean up on every suite, by 0.000–0.02 points; deformation
    within ±0.03 points; the first windows' loss beyond the causal oracle's roughly
    halved).  Two iterations measure nearly as three, five as three; iterating the first
    two or three analyses, or every one, gained at most 0.001 points: later priors are
    narrow enough for one step.  The cost is two more window forecasts per run.

Causality
    Window k's loads and starting field use measurements up to 60k s only: the analysis at
    the start of window k uses the samples in (60(k−1), 60k].

Deck, analysed state and members
    The window deck `decks/window_kkk.inp` carries the mean's loads (bearing heat and contact
    resistance in their usual commands, motor and film factors already applied to the
    rotor/stator heat and the film coefficients), as 15 load steps of 4 s whose bearing
    heat and contact resistance the loop took at the twin's temperatures at each one's
    start (`twin.loop.replay`, `Correction.loads_follow_rings`).  It runs from the
    analysed mean field at
    60k s (the session's state, set before the deck), so deck + analysed field reproduce the
    reported twin trajectory exactly.  The members never appear in decks: each is the mean
    plus a tangent-linear anomaly, and only their spread is reported (the 90 % band).

Drift (default where recorded)
    The recorded axial nose drift (three 20 s bins per window, valid samples only) joins the
    update, its error σ² = drift_model_sd_um² + (drift_rel_sd·drift)² + noise²/samples;
    the members' drift is e^φα·w·(T − T₀) with the expansion factor φα, and the loop
    scales each window's displacements by the estimated e^φα.  Window k's drift is then a
    0–60 s forecast from the drift measured up to 60k s (causal).  A run without a drift
    column, or whose drift the quality check rejects, is filtered on T1..T5 alone with no
    switch needed; `EstimatorConfig(assimilate_drift=False)` always filters on T1..T5
    alone (the twin then predicts the drift from temperatures, as on a machine without
    probes).  `make bench` and the README report both.
    Why drift_model_sd_um is small (0.05 µm): what the structural model gets wrong scales
    with the drift — the expansion factor (estimated) and drift_rel_sd carry it — so the
    absolute part is only what is left of a 20-sample bin mean, of the order of the probe
    noise over √20 (0.05–0.3 µm → 0.01–0.07 µm).  With 0.2 µm the gain on the drift was
    too low: offsets of 0.1–0.4 µm between twin and truth survived 5–10 windows after a
    start or a speed step (suite 77 run 12).  Measured (`tools/estimator_ceiling.py`;
    deformation median / worst; temperature within 0.01 points, no criterion count
    lower): suite 909 97.94 / 94.57 → 98.14 / 94.64 %, 77 98.06 / 94.45 → 98.10 / 94.50 %,
    2024 98.13 / 95.61 → 98.18 / 96.10 %, the bundled runs' mean 98.95 → 99.02 %.  0.02 µm,
    or drift_rel_sd halved as well, gained at most 0.05 points more (not kept).

Thermocouples (T1..T5 as reported)
    The field is the metal; a thermocouple in its bore follows with a first-order lag
    (`twin.lag`, τ = sensor_lag_s, 10 s: sheathed thermocouples are 4–20 s).  The filter
    compares the window's forecast with the samples through that lag, and with
    `report_readings` (default) the estimator also *reports* T1..T5 as readings:
    the readings at the window start (the lag's state) go with the correction, and the
    loop puts the deck's metal at the sensor points through the lag from there.  The
    readings are carried from window to window (never re-started at the metal, never set
    to a measurement) and move with the analysis: after it, by the analysed change of the
    metal at the sensor points.  The deck still reproduces the metal exactly; the reported
    T1..T5 are that metal through the stated lag.  Why: a twin that reports the metal
    loses to the lag what a perfect metal twin loses (`tools/estimator_ceiling.py`: 0.02–
    0.8 points of temperature accuracy per run, most in the windows after a speed step).
    Measured (temperature accuracy, median / worst): suite 271828 99.70 / 99.11 → 99.73 /
    99.25 % (every run up or equal), the fresh suite 5150 99.71 / 99.39 → 99.77 / 99.46 %;
    the drift within ±0.02 points, the band's coverage 88.6–91.8 % (was 89.1–91.9 %).
    The lag τ itself is estimated: one factor `sensor_lag` on the assumed 10 s, common to
    T1..T5 (thermocouples of one type; prior spread 0.45 in log space, so 4–20 s are within
    about 1.5 σ), in the ensemble like the boundary factors but moving no temperature: a
    member reads the mean's readings plus its field anomaly plus ∂(readings)/∂φ_τ times its
    own δφ_τ.  That derivative is a forward difference of the lag over the window, started
    from the readings' own derivative at the window start, which is carried from window to
    window like the readings (a thermocouple's reading remembers the lag it was read with).
    After an analysis the readings move by the analysed change of the metal and by that
    derivative times the analysed change of φ_τ.  Starts, steps and stops identify it; a
    window whose readings would move by less than `lag_update_min_C` (0.3 K) per unit of
    φ_τ leaves it where it was (its mean and spread, as a stop leaves the heat factors):
    in a slow drift τ only shifts the level by τ·dT/dt and would stand in for whatever else
    the twin gets wrong — on suite 24680 run 1 (one speed for 40 min) it crept from 22 s
    after the start to its bound of 40 s (truth 17.5 s); held, it stays at 22.8 s, with the
    suites' accuracy unchanged (24680, 13579, 4711, 2718, 8642, 7070, 271828: mean
    temperature within ±0.002 points).  Scoring
    candidate lags (3–28 s) by the misfit of the forecast through each had picked 3 s for
    a 16.5 s sensor and 14 s for 4.5–6.5 s ones; in the filter, against the other factors'
    covariance, the tests' emulated runs find 5.1 s for 5 s and 17.5 s for 18 s.

Thermocouple offsets (`bias_T1`..`bias_T5`, `estimate_sensor_bias`)
    A real thermocouple reads its metal with a calibration offset (±0.5–1 K) and from a
    point a millimetre or so off its nominal one.  Taken as the metal at the nominal point,
    an offset is a steady misfit the analysis can only explain with the boundary factors:
    with T2 0.7 K high and T4 0.7 K low on every run of suite 5524871 the last window's
    front and rear contact factors moved from the unbiased replay's by 45 and 46 % (median
    over the 12 runs; up to 150 %), motor loss by 29 %, the coolant and rotor films by 41
    and 22 %, the expansion factor by 8 %, and the deformation accuracy fell from 98.65 /
    96.19 to 98.53 / 95.81 % (median / worst).  So each thermocouple carries an additive
    offset, observation-only like the lag: a member reads its metal through the lag plus
    its own offsets; no temperature moves with them.  No random walk (an offset does not
    move within a run; the inflation keeps its spread up to the prior), bounds ±3 K.  They
    are reported: T1..T5 as reported are the readings plus the offsets
    (`Correction.sensor_offset_C`, `T1_offset_K`.. in corrections.csv), and the band
    includes their spread.
    Identifiability and the prior (0.15 K).  An offset is constant; a contact or film
    factor's effect follows the heat flow, so starts, speed steps and stops separate them
    and a run at one speed barely does: over 30 min at 9000 rpm from a cold start (`python
    -m twin.estimation.sensitivity --names …,bias_T1,…,bias_T5`) T1's offset has a cosine of
    0.99 with the front contact factor and 0.95 with the front bearing heat, T3's 0.96 with
    the rear contact, and what no combination of the factors and the other offsets can stand
    in for is 3 % of T1's offset's signature (RMS 0.013 of 0.447 K per K), 5 % of T2's and
    T3's, 15 % of T4's and T5's; the offsets add singular values of J/σ between 11.7 and
    1.4.  There the prior decides.  With a prior of 0.4 K (the size of real offsets) the
    offsets stood in for factors on the tests' runs of the twin model itself, which have
    none: at one speed T1 took 0.17 K against the front contact (1.40× found, truth 1.5×,
    1.52× without offsets) and the motor loss against the jacket's film read 1.14 (truth and
    without offsets 1.20; ensemble seeds 0–3: 1.14–1.17 against 1.195–1.20); a drift
    recorded 20 % larger than the temperatures imply went only to 1.11× on the expansion
    factor (1.2× without: the offsets took the temperatures while the rotor film took
    drift); a chiller stepping the inlet moved the motor factor up to 0.13 off its true 1
    (0.06 without).  0.25 and 0.2 K still failed the drift case (1.13×, 1.14×); holding the
    offsets through the first one or three analyses, or leaving them out of the inflation,
    did not help (ratio 1.07–1.16).  With 0.15 K all of them hold as before, and the suites
    measure as with 0.4 K (below): where speed changes and stops separate them the data
    carry an offset far beyond the prior.  On the test's emulated 14-min run with a step and
    a stop (T2 +0.7, T4 −0.7 K) it finds 0.67 and −0.64 K, every factor within 9 % of the
    truth (without offsets: front contact 0.44×, rear 1.80× for 0.8×, motor loss 1.91×),
    deformation 98.49 against 97.85 %, temperature 99.48 against 99.13 %.  At one speed
    (9000 rpm, 14 min) it finds 0.45 and −0.36 K, the contact factors 0.68× and 1.04× (truth
    1.0 and 0.8; without offsets 0.28× and 1.37×, with the 0.4 K prior 1.02× and 0.94×),
    deformation 99.52 against 99.41 %; without offsets in the data, at most 0.10 K and the
    contact factors 1.04× and 0.87× (1.01× and 0.81× without), accuracy the same.
    Only where the drift is assimilated.  From T1..T5 alone (`--no-drift-assimilation`,
    or a run without a probe the filter reads) the offsets took what the factors behind the
    unseen drift should: deformation on suite 5524871 95.37 / 91.86 → 95.28 / 89.98 %
    (median / worst; 7 of 12 runs down), on the bundled runs 94.06 → 91.70 % (mean; the
    warm start 83.85 → 70.29), temperature unchanged; there they are not estimated.
    Measured (median / worst of 12 runs, temperature and deformation accuracy; main →
    offsets estimated): suites 5524871 99.70 / 99.62 and 98.65 / 96.19 → 99.70 / 99.62 and
    98.67 / 96.18, 7311909 99.80 / 99.53 and 98.08 / 94.97 → 99.80 / 99.53 and 98.07 /
    94.95, 1618033 (90 min) 99.73 / 99.67 and 98.36 / 97.75 → 99.73 / 99.67 and 98.37 /
    97.75 (every run within −0.03 / +0.07 points, the same runs meeting each criterion,
    band coverage 89.2–91.6 %); with offsets added to every run, 5524871 (T2 +0.7, T4
    −0.7 K) 99.63 / 99.44 and 98.53 / 95.81 → 99.68 / 99.60 and 98.64 / 96.19 (every run
    up), 7311909 (T1 −0.5, T3 +0.8, T5 +0.4 K) 99.72 / 99.34 and 97.94 / 94.99 → 99.79 /
    99.53 and 98.07 / 94.94 (every run up but run 10's deformation, 94.99 → 94.94).  The
    factors' pull by the offsets (|ln| of the last window's factor over the unbiased
    replay's, median over the runs): front / rear contact 45 / 46 → 7 / 5 %, motor 29 →
    4 %, coolant film 41 → 6 %, expansion 8 → 2 % on 5524871; rear contact 48 → 9 %,
    motor 36 → 10 %, coolant film 36 → 8 %, expansion 10 → 2 % on 7311909 (front contact
    14 → 11 %).

Coolant inlet (runs without a `coolant_C` column)
    The nominal conditions then take the inlet at the ambient; a chiller usually holds the
    jacket 1–3 K off the room air, and the whole housing follows the jacket (T5 moves by
    0.99 K per K of inlet, T1/T2 by 0.8/0.9, the rear ring and sleeve by 0.5; the drift by
    0.25–0.35 µm per K).  So where the run does not record it the filter estimates the
    inlet as an offset from the ambient (`coolant_offset`, K, additive: `parameters`):
    prior N(0, 2.5 K), a random walk of 0.1 K per window (the suite's inlet and ambient
    drift independently by up to 2 and 2.5 K over a run), bounds ±8 K, analysed from
    T1..T5 (and the drift) like the log-factors; its tangent column is the jacket's
    Σ h ∫ v dA.  Runs that record the inlet are filtered exactly as before (the parameter
    is not in their ensemble), and `EstimatorConfig(estimate_coolant=False)` keeps the
    ambient everywhere.  The estimated inlet goes with the correction
    (`Correction.coolant_C`): the window's deck runs the jacket's films at it, and
    corrections.csv lists it (`coolant_C`).
    Observability (`python -m twin.estimation.sensitivity --names …,coolant_offset`, per
    K; 30 min from a cold start at one speed): the offset is nearly collinear with the
    jacket's film factor — a colder inlet looks like a stronger jacket:
    cos(J_offset, J_film_coolant) = −0.97 at 9000 rpm (−0.99 at 4000, −0.94 at 14 000),
    and of its 0.71 K per K of signature (RMS over T1..T5 and 30 samples) 0.16 K is left
    after the film factor alone and 0.05 K after all nine other factors; with it the ten
    singular values of J/σ gain one at 4.0 (offset against motor loss and jacket film).
    That is within the model-form error: a steady run at one speed cannot tell the two
    apart.  Two things do.  The film's effect is the jacket's wall-to-inlet difference,
    which follows the heat load, the offset's is not: over a profile (the same forward
    differences, loads following the rings) of 10 min each at 6000, 9000 and 12 000 rpm
    0.18 K per K is left after all others (cos with the film −0.93), over 15 min at
    14 000 rpm, a 10-min stop and 15 min at 4000 rpm 0.34 K (cos −0.83).  And the start:
    the spindle at rest is at the ambient, and an offset inlet pulls T5 by 0.75 K per K
    within the first minute, where the film's effect (no wall-to-inlet difference yet) is
    0.17 per unit log-factor.
    The linear-Gaussian posterior of the offset (σ 0.1–0.3 K per sample, the default
    priors) is 0.12–0.18 K for the one-speed run, 0.02–0.06 K with the stop, correlated
    0.7–0.8 with the film factor.  Consequence: the offset is estimated (it matters: 1 K
    of inlet moves the housing by 1 K, the film's ±25 % by 0.2–0.7 K), and on one-speed
    runs the pair is pinned only together; the factor recovery test therefore records the
    inlet.
    Measured (own seeds, not the fresh suite; temperature / deformation accuracy median,
    worst of 12 runs without the column: suite 97531 as drawn and with the inlet held
    ±1–3 K off the ambient): assumed at the ambient 98.78 / 95.64 and 95.46 / 68.57 % →
    estimated 99.83 / 99.46 and 97.71 / 95.33 %, band coverage 90.4–91.6 %; the inlet found
    within 0.3 K of the truth at the run's end on all 12.  The bundled runs without their
    column (inlet within 0.9 K of the ambient): 99.80 / 99.79 → 99.84 / 99.83 and 99.07 /
    98.87 → 99.11 / 98.96 %.  Walk 0.03–0.15 K and prior 2–3 K measured within 0.02
    points; 0.1 tracks a drifting inlet within 0.3 K where 0.05 lagged it by up to 1.1 K.

Band
    Per solver step, ±1.645 σ around the mean: σ² = member variance of the sensor value +
    a model-plus-noise variance; for the drift, the member variance (field and expansion
    factor) + the structural model's error (`drift_rel_sd` of the drift) + its own
    model-plus-noise variance.  Those two variances start at model_sd_C² + sensor_sd_C² and
    drift_model_sd_um² + drift_noise_um² and follow the run: after each window, the mean
    squared misfit of the twin to the samples just measured, less the members' variance,
    is blended in with weight `band_learning_rate` (causal: measured before the window
    starts).  The twin there is the window as re-run with its recorded speed where the
    speed changed inside it, as the analysis sees it: that variance is the model's error
    and the noise, not the input the loads could not know.  The whole band is then scaled
    by an adaptive conformal step (Gibbs & Candès 2021, "Adaptive conformal inference
    under distribution shift"): after each window, × exp(band_scale_rate·(share of its
    samples outside − 0.1)), counted on the band as reported, so a run of surprises still
    widens it.  Learned from the reported window, one surprise was counted twice: a speed
    drop inside a window (T1 7 K off at its end) left T1's band 3.1 K wide (half) in the
    next window and 2.1 K in the one after, the twin within 0.2 K (now 0.3 K; suite 381966
    run 5: 5.0 → 0.55 K).  Measured on suites 381966 and 9191 (24 runs, 40 min): the same
    coverage per sensor (87.4–93.7 %), the mean interval score (α = 0.1) 6–21 % lower on
    T1..T4 and the drift (T5, the housing, hardly moves at a speed change: unchanged),
    T1's median half-width 0.29 → 0.18 K on 381966.  Where the speed changes every
    20–40 s, every window a surprise, the pooled coverage is 86.4–86.7 % (was 88.7–89.7 %):
    the conformal step alone has to learn how often the speed changes, which it does in
    the run's first five minutes (coverage 63–76 % there, 70–100 % later).  Both steps are
    taken for each thermocouple and for the drift separately: the rings' misfit after a
    speed change is kelvins where the housing's is a tenth of one.  With a fixed model error
    a quiet run (0.02 K noise) was covered 100 % and a rough one 80 %; with both steps the
    suites' runs sit at 89–91 %.  With one variance and scale shared by T1..T5 (before
    2026-11-27) the pooled coverage was 90 % but the housing's T5 was covered 58–84 % and
    the rings' T1/T3 94–100 % on nearly every run, and where the speed changed every 20–40 s
    T5 (within 0.23 K of the twin) carried the rings' 4.3 K band.  Window 0 teaches the
    band nothing: its misfit is the prior's error, which the first analysis removes.
    Learned from it, a front bearing at 2.2× its nominal heat (2.6 prior σ) left T1's band
    35 K wide in window 1 and 8 K in window 5 while the twin was within 0.35 K.

Stops: at 0 rpm the bearing and motor heat are zero, so their factors have no effect; a
stopped window's analysis keeps their mean and spread (what would move them is only
correlation left from before the stop); the films and the field go on.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from threadpoolctl import threadpool_limits

from twin.contract import STEP_S, STEPS_PER_WINDOW, WINDOW_S
from twin.correction.features import (
    OBSERVATION_BINS,
    WindowFeatures,
    bin_mean,
    min_bin_samples,
    rows_between,
)
from twin.correction.rerun import (
    first_window_at_speed,
    recorded_step_speeds,
    rerun_window,
    speed_change_s,
)
from twin.correction.result import Correction
from twin.estimation.analysis import etkf_weights
from twin.estimation.ensemble import Ensemble, add_random_walk, cap_spread
from twin.estimation.forecast import WindowForecast, forecast_window
from twin.estimation.parameters import (
    BOUNDARY_VALUES,
    DEFAULT_PARAMETERS,
    DRIFT_ONLY,
    OBSERVATION_ONLY,
    OFFSETS,
    SENSOR_BIASES,
    TangentOperators,
    apply_factors,
    coolant_offset_of,
    factors_of,
    parameters,
)
from twin.lag import first_order_lag
from twin.spindle.conditions import BoundaryConditions, bearing_values_at

HEAT_FACTORS = frozenset({"H_front", "H_rear", "motor"})
"""The factors on heat that a stopped spindle does not generate."""

LAG_STEP = 0.05
"""Log-step of the forward difference by which the readings' lag sensitivity is taken."""

BAND_Z = 1.6448536269514722
"""Half-width of a central 90 % normal interval in σ."""


@dataclass(frozen=True)
class EstimatorConfig:
    """Settings of the ensemble filter (defaults measured on the synthetic suite)."""

    members: int = 24
    parameters: tuple[str, ...] = DEFAULT_PARAMETERS
    inflation: float = 1.2
    """Multiplicative covariance inflation per analysis (ρ)."""
    model_sd_C: float = 0.10
    """Model error of a predicted sensor value, °C (mesh, placement, lag, conductivity)."""
    sensor_sd_C: float = 0.05
    """Thermocouple noise per sample, °C."""
    sensor_lag_s: float = 10.0
    """Assumed thermocouple time constant, s (sheathed thermocouples: about 4–20 s)."""
    lag_sd_s: float = 3.0
    """What one first-order lag common to T1..T5 leaves unexplained, s (the sensors' own
    spread, their placement): a rate of change r adds lag_sd_s·r to the observation error.
    The lag itself is estimated (`sensor_lag`); with it fixed, 6 s was used."""
    lag_update_min_C: float = 0.3
    """The lag is updated only by a window whose readings would move by at least this much
    (°C, any sensor) for a unit change of its log-factor: starts, steps and stops.  A slow
    drift of the readings sees the lag only as a level (τ·dT/dt), where it would stand in
    for whatever else the twin gets wrong and creep."""
    report_readings: bool = True
    """Report T1..T5 as what the thermocouples read (the metal at their points through
    the lag sensor_lag_s); False: the metal temperature at their points."""
    bins_per_window: int = OBSERVATION_BINS
    """Observation bins per 60 s window; each bin's mean is one observation per sensor
    (one with fewer than `min_bin_samples` valid samples is none)."""
    initial_field_sd_C: float = 0.2
    """Uncertainty of the uniform start field (the mean of the first T1..T5)."""
    drift_rel_sd: float = 0.01
    """Relative model error of the drift beyond the field and the expansion factor (the
    structural model's own error: mesh, stiffness, the probe's point)."""
    drift_noise_um: float = 0.1
    step_s: float = STEP_S
    steps_per_window: int = STEPS_PER_WINDOW
    window_s: float = WINDOW_S
    seed: int = 0
    field_update: float = 1.0
    """Share of the analysis increment applied to the field (1: the full ETKF update)."""
    assimilate_drift: bool = True
    """Also update with the recorded axial nose drift where the run has it (valid samples of
    its disp_z_um column measured before the window starts): the drift of window k is then
    a 0–60 s forecast from the drift measured up to 60k s, and the expansion factor is
    estimated.  A run without a drift column, or with its drift invalid, is filtered on
    T1..T5 alone.  False: always T1..T5 alone (the twin predicts the drift from
    temperatures, as on a machine without probes)."""
    drift_model_sd_um: float = 0.05
    """Model error of a predicted drift bin, µm, besides drift_rel_sd of the drift (see
    "Drift" in the module doc for why it is this small)."""
    band_learning_rate: float = 0.3
    """Weight of the window just ended in the band's model-plus-noise variance (the running
    value starts at model_sd_C² + sensor_sd_C², drift_model_sd_um² + drift_noise_um²;
    0: fixed there)."""
    band_scale_rate: float = 2.0
    """Adaptive conformal step of the band's width: × exp(rate·(missed share − 0.1)) after
    each window (0: no feedback)."""
    band_floor_C: float = 0.02
    """Least model-plus-noise spread of the T1..T5 band, °C."""
    band_floor_um: float = 0.05
    """Least model-plus-noise spread of the drift band, µm."""
    rerun_inlet_K: float = 0.2
    """Re-run the window just ended with its recorded coolant inlet, step by step, where
    that moved more than this (K) from the inlet its forecast ran at (module doc, "The
    filter"); `inf`: never."""
    rerun_first_window: bool = True
    """With loads held for each window (not `loads_follow_rings`): re-run the first window
    of a run before its analysis (the cold start; module doc).  With the loads following
    the rings the forecast already is that re-run."""
    loads_follow_rings: bool = True
    """The window's nominal bearing heat and contact resistance follow the twin's ring and
    sleeve temperatures every solver step (module doc); False: held at the window start."""
    analysis_iterations: int = 3
    """Gauss–Newton iterations of the analysis of a run's first `iterated_windows` windows
    (1: the plain ETKF everywhere; module doc, "Iterated first analysis")."""
    iterated_windows: int = 1
    """How many of a run's first analyses are iterated (each costs one more window forecast
    per extra iteration)."""
    estimate_coolant: bool = True
    """On a run that records no coolant inlet (`WindowFeatures.coolant_recorded`), also
    estimate the inlet's offset from the ambient (`coolant_offset`; module doc, "Coolant
    inlet"); False: assume the inlet at the ambient, as the paper's methods do."""
    estimate_sensor_bias: bool = True
    """Also estimate each thermocouple's additive offset (`SENSOR_BIASES`; module doc,
    "Thermocouple offsets") where the drift is assimilated (a run with a probe it reads);
    False, or without the drift: T1..T5 read the metal at their nominal points."""

    def __post_init__(self) -> None:
        if self.analysis_iterations < 1:
            raise ValueError(f"analysis_iterations must be ≥ 1, got {self.analysis_iterations}")


@dataclass(frozen=True)
class WindowStart:
    """What a window's forecast started from: its readings and a re-forecast need it."""

    ensemble: Ensemble
    """The ensemble at the window start (after the random walk), as forecast."""
    conditions: BoundaryConditions
    """The loop's nominal conditions of the window (before the factors)."""
    readings_C: np.ndarray
    """T1..T5's readings at the window start (the lag's state), °C."""
    readings_slope_C: np.ndarray
    """∂(readings_C)/∂(log-factor of the lag), °C."""

    @property
    def field_C(self) -> np.ndarray:
        return self.ensemble.field_mean

    def moved(self, weights: np.ndarray, held_rows: list[int], lag: int | None,
              log_bounds: np.ndarray) -> WindowStart:
        """The start with its mean moved by the ensemble weights (x̄ + X w; `held_rows` of
        the log-factors stay, the others within `log_bounds` (p, 2): a Gauss–Newton step
        has no line search), the readings with the moved lag (a member's rule)."""
        ens = self.ensemble
        dphi = ens.log_factor_anomalies @ weights
        dphi[held_rows] = 0.0
        phi = np.clip(ens.log_factor_mean + dphi, log_bounds[:, 0], log_bounds[:, 1])
        dphi = phi - ens.log_factor_mean
        moved = Ensemble(ens.field_mean + ens.field_anomalies @ weights, ens.field_anomalies,
                         ens.log_factor_mean + dphi, ens.log_factor_anomalies)
        readings = self.readings_C
        if lag is not None:
            readings = readings + self.readings_slope_C * dphi[lag]
        return replace(self, ensemble=moved, readings_C=readings)


@dataclass(frozen=True)
class WindowObservations:
    """The window just ended as the analysis sees it: predicted observations (T1..T5 per
    bin, then the drift per bin where recorded), their anomalies, the measured values and
    their error; and the readings over the window with their lag derivative."""

    mean: np.ndarray  # (m,) ȳ
    anomalies: np.ndarray  # (m, N) Y
    observed: np.ndarray  # (m,) y, NaN where a bin has too few valid samples
    sd: np.ndarray  # (m,) observation error
    readings_C: np.ndarray  # (steps + 1, 5) the readings from the window start
    lag_slope_C: np.ndarray  # (steps + 1, 5) their derivative by the lag's log-factor
    drift_seen: bool  # whether the recorded drift had a valid bin


@dataclass
class EnsembleEstimator:
    """The `estimator` correction method (module doc); one instance replays runs one at a
    time (window 0 starts a new run)."""

    model: object = field(repr=False)  # twin.spindle.SpindleModel
    config: EstimatorConfig = EstimatorConfig()
    name: str = "estimator"
    _ensemble: Ensemble | None = field(default=None, init=False, repr=False)
    _forecast: WindowForecast | None = field(default=None, init=False, repr=False)
    _rng: np.random.Generator | None = field(default=None, init=False, repr=False)
    _drift_start_um: float = field(default=0.0, init=False, repr=False)
    _forecast_speed_rpm: float = field(default=0.0, init=False, repr=False)
    _band_var: np.ndarray | None = field(default=None, init=False, repr=False)
    _band_scale: np.ndarray | None = field(default=None, init=False, repr=False)
    _band_sd_used: np.ndarray | None = field(default=None, init=False, repr=False)
    _readings_C: np.ndarray | None = field(default=None, init=False, repr=False)
    """T1..T5's readings at the start of the window being forecast (the lag's state)."""
    _readings_slope_C: np.ndarray | None = field(default=None, init=False, repr=False)
    """∂(readings at the window start)/∂(log-factor of the lag), °C: the readings' memory of
    the lag they were read with, carried like the readings themselves."""
    _start: WindowStart | None = field(default=None, init=False, repr=False)
    """What the window being forecast started from."""

    def __post_init__(self) -> None:
        self._sensors = self.model.sensor_matrix
        self._drift_um = 1e6 * np.asarray(self.model.probe_vectors[0])
        self._estimate(self.config.parameters)

    def _estimate(self, names: tuple[str, ...]) -> None:
        """Estimate `names` in the run to come (the configured parameters, and the coolant
        inlet's offset where the run records no inlet)."""
        self._names = names
        self._params = parameters(names)
        self._prior_sd = np.array([p.prior_sd for p in self._params])
        self._walk_sd = np.array([p.walk_sd for p in self._params])
        self._bounds = np.array([p.state_bounds for p in self._params])
        self._expansion = names.index("expansion") if "expansion" in names else None
        self._lag = names.index("sensor_lag") if "sensor_lag" in names else None
        self._coolant = names.index("coolant_offset") if "coolant_offset" in names else None
        self._bias = ([names.index(b) for b in SENSOR_BIASES]
                      if all(b in names for b in SENSOR_BIASES) else None)

    @property
    def log_factors(self) -> dict[str, float]:
        """Current mean log-factors by name (after the last analysis; the coolant inlet's
        offset is `coolant_offset_K`)."""
        if self._ensemble is None:
            return {}
        return {n: v for n, v in zip(self._names, self._ensemble.log_factor_mean.tolist(),
                                     strict=True) if n not in OFFSETS}

    @property
    def coolant_offset_K(self) -> float | None:
        """Current mean offset of the coolant inlet from the ambient, K (None: the run
        records its inlet, or nothing has been estimated yet)."""
        if self._ensemble is None or self._coolant is None:
            return None
        return float(self._ensemble.log_factor_mean[self._coolant])

    @property
    def sensor_bias_K(self) -> np.ndarray | None:
        """Current mean offsets of T1..T5 from the metal at their points, K (None: not
        estimated, or nothing estimated yet)."""
        return None if self._ensemble is None else self._bias_mean(self._ensemble)

    def _bias_mean(self, ens: Ensemble) -> np.ndarray | None:
        """`ens`'s mean offsets of T1..T5, K, a copy (None: the run estimates none)."""
        return None if self._bias is None else ens.log_factor_mean[self._bias].copy()

    def correct(self, features: WindowFeatures) -> Correction:
        f = features
        cfg = self.config
        if f.twin_state is None:
            raise ValueError("the estimator needs the twin's state (run it through the loop)")
        if f.window == 0 or self._ensemble is None:
            names = cfg.parameters
            if (cfg.estimate_coolant and not f.coolant_recorded
                    and "coolant_offset" not in names):
                names = names + ("coolant_offset",)
            if (cfg.estimate_sensor_bias and cfg.assimilate_drift
                    and f.measured_drift_um is not None):
                # with the drift only: without it they stand in for the factors the
                # unseen drift hangs on (module doc, "Thermocouple offsets")
                names = names + tuple(b for b in SENSOR_BIASES if b not in names)
            self._estimate(names)
            self._rng = np.random.default_rng(cfg.seed)
            self._drift_start_um = float(self._drift_um @ f.twin_state.field_C)
            # one channel per thermocouple and one for the drift (`_adapt_band`)
            n_sensors = self._sensors.shape[0]
            self._band_var = np.r_[np.full(n_sensors, cfg.model_sd_C**2 + cfg.sensor_sd_C**2),
                                   cfg.drift_model_sd_um**2 + cfg.drift_noise_um**2]
            self._band_scale = np.ones(n_sensors + 1)
            self._readings_C = self._sensors @ np.asarray(f.twin_state.field_C, float)
            self._readings_slope_C = np.zeros_like(self._readings_C)
            self._ensemble = Ensemble.initial(
                f.twin_state.field_C, cfg.initial_field_sd_C, self._prior_sd, cfg.members,
                self._rng,
            )
        else:
            with threadpool_limits(1):
                self._ensemble = self._analysis(f)
        ens = self._ensemble
        ens.log_factor_anomalies = cap_spread(
            add_random_walk(ens.log_factor_anomalies, self._walk_sd, self._rng), self._prior_sd
        )
        ens.log_factor_mean = np.clip(ens.log_factor_mean, self._bounds[:, 0], self._bounds[:, 1])

        factors = factors_of(self._names, ens.log_factor_mean)
        self._forecast_speed_rpm = f.speed_rpm
        # the window's start: its readings, its re-run and a re-forecast need it
        self._start = WindowStart(ens, f.twin_state.conditions, self._readings_C.copy(),
                                  self._readings_slope_C.copy())
        with threadpool_limits(1):  # tiny dense blocks: BLAS threads only contend
            self._forecast, bc = self._forecast_from(self._start)
        extra = {k: v for k, v in factors.items()
                 if k not in BOUNDARY_VALUES and k not in OBSERVATION_ONLY}
        self._band_sd_used = self._band_sd(self._forecast)
        return Correction.relative_to(
            (bc.H_front, bc.H_rear, bc.R_front, bc.R_rear), f.carried_previous(),
            factors=extra, state_C=ens.field_mean.copy(), band_sd=self._band_sd_used.copy(),
            readings_start_C=self._readings_C.copy() if cfg.report_readings else None,
            sensor_offset_C=self._bias_mean(ens) if cfg.report_readings else None,
            sensor_lag_s=self._lag_of(self._start), loads_follow_rings=cfg.loads_follow_rings,
            coolant_C=bc.coolant_C if self._coolant is not None else None,
        )

    # ------------------------------------------------------------------ steps
    def _analysis(self, f: WindowFeatures) -> Ensemble:
        """Update the forecast ensemble with the samples of the window just ended."""
        cfg = self.config
        fc = self._forecast
        start = self._start
        prior = fc.end  # the window's own prior: held factors go back to it
        # the reported trajectory (the deck's) is the mean: use it for the innovations,
        # and the loop's field at the window end as the forecast mean
        prior.field_mean = np.asarray(f.twin_state.field_C, float)
        sim_C = np.asarray(f.simulated_C, float)
        changed_s = speed_change_s(f, self._forecast_speed_rpm)
        first = (cfg.rerun_first_window and not cfg.loads_follow_rings
                 and first_window_at_speed(f, self._forecast_speed_rpm))
        inlet = self._moved_inlet(f, start)  # the same for every start moved from it
        rerun = changed_s is not None or first or inlet is not None
        if rerun:
            # the speed changed inside the window just ended, after its loads were fixed:
            # that window is re-run with the speed it really had (all measured before now)
            # so the innovations and the analysed field are free of the unforeseen input;
            # so is a run's first window (its held cold-start heat, `twin.correction.rerun`)
            sim_C, prior.field_mean, fc = self._rerun(f, fc, start, inlet)
        if f.window > 1:  # window 0 missed by the prior's error: not the band's to learn
            self._calibrate_band(f, sim_C, fc)
        obs = self._observations(f, fc, sim_C, start)

        held = set()
        if self._forecast_speed_rpm == 0.0 and changed_s is None:
            # a stopped window: no bearing or motor heat, so the data say nothing about
            # their factors; what would move them is correlation left from before the stop
            held |= HEAT_FACTORS
        if not obs.drift_seen:
            held |= DRIFT_ONLY  # nothing but the drift sees the expansion factor
        if np.abs(obs.lag_slope_C).max() < cfg.lag_update_min_C:
            held.add("sensor_lag")  # no transient: the readings do not tell the lag
        # with the speed history, a speed at the window start other than the forecast's is
        # a change on the boundary: the window just ended ran at its forecast's speed
        unforeseen = (f.measured_speed_rpm is None
                      and abs(f.speed_rpm - self._forecast_speed_rpm) > 0.5)
        if unforeseen:
            # a speed change without the speed history to re-run it (features from another
            # caller): the misfit is the unforeseen input, not wrong factors.  The field
            # takes the update; the log-factors keep their forecast (mean and spread).
            # With the history, one on a window boundary held every factor too, so a run
            # whose speed changed every minute on the minute never updated one (the
            # suites' changes sit on a 10 s grid: one in six of them).
            held |= set(self._names)
        rows = [i for i, name in enumerate(self._names) if name in held]

        w, W = etkf_weights(obs.mean, obs.anomalies, obs.observed, obs.sd, cfg.inflation)
        w_forecast = np.zeros_like(w)  # the weights of the start `fc` was forecast from
        if f.window <= cfg.iterated_windows and not unforeseen:
            for _ in range(cfg.analysis_iterations - 1):
                # Gauss–Newton: forecast the window again from the start moved by w, and
                # linearise there (module doc, "Iterated first analysis")
                moved = start.moved(w, rows, self._lag, self._bounds)
                with threadpool_limits(1):
                    fc, _ = self._forecast_from(moved)
                if rerun:  # the mean again at the recorded speed, as the first pass
                    sim_C, fc.end.field_mean, fc = self._rerun(f, fc, moved, inlet)
                else:
                    sim_C = np.asarray(f.simulated_C, float).copy()
                    sim_C[-cfg.steps_per_window:] = fc.sensors_mean_C
                obs = self._observations(f, fc, sim_C, moved)
                w_forecast = w
                w, W = etkf_weights(obs.mean, obs.anomalies, obs.observed, obs.sd,
                                    cfg.inflation, prior_weights=w)
        end = fc.end
        prior_mean, anomalies = end.stacked()
        mean = prior_mean + anomalies @ (w - w_forecast)
        anomalies = anomalies @ W
        n = end.field_mean.size
        mean[:n] = prior_mean[:n] + cfg.field_update * (mean[:n] - prior_mean[:n])
        if rows:
            mean[[n + i for i in rows]] = prior.log_factor_mean[rows]
            anomalies[[n + i for i in rows]] = prior.log_factor_anomalies[rows]
        # the readings at the window end, moved with the analysed metal at the sensor
        # points (a thermocouple follows its metal; the analysis corrects the metal)
        self._readings_C = obs.readings_C[-1] + self._sensors @ (mean[:n] - prior_mean[:n])
        if self._lag is not None:
            # and with the analysed lag: the readings as that lag would have left them
            dlag = mean[n + self._lag] - prior_mean[n + self._lag]
            self._readings_C = self._readings_C + obs.lag_slope_C[-1] * dlag
            self._readings_slope_C = obs.lag_slope_C[-1]
        return Ensemble.from_stacked(mean, anomalies, n)

    def _observations(self, f: WindowFeatures, fc: WindowForecast, sim_C: np.ndarray,
                      start: WindowStart) -> WindowObservations:
        """The window just ended's observations as forecast by `fc` (mean T1..T5 history
        `sim_C`, the loop's rows with the window's replaced where it was re-run or
        re-forecast) from `start`: T1..T5 through the lag, averaged over the bins
        (invalid samples left out), then the drift's bins where recorded."""
        cfg = self.config
        steps = cfg.steps_per_window
        sim_t = np.asarray(f.simulated_time_s, float)
        in_window = sim_t > f.start_s - cfg.window_s + 1e-9
        read_t = sim_t[in_window]
        if len(read_t) != steps:  # the loop's history must hold the whole window
            raise ValueError(f"window {f.window}: expected {steps} simulated steps, "
                             f"got {len(read_t)}")
        # what the thermocouples would read of the mean over the window just ended: its
        # sensor values through the lag, from their readings at the window start
        reads = self._window_readings(sim_t, sim_C, start)
        slope = self._readings_lag_slope(sim_t, sim_C, reads, start)
        read = reads[1:]
        lag_anomalies = (start.ensemble.log_factor_anomalies[self._lag]
                         if self._lag is not None else None)
        # each thermocouple's offset: added to what it reads, by each member its own
        bias = self._bias_mean(start.ensemble)
        if bias is None:
            bias = np.zeros(read.shape[1])
        bias_anomalies = (start.ensemble.log_factor_anomalies[self._bias]
                          if self._bias is not None else 0.0)
        bins = np.array_split(np.arange(steps), cfg.bins_per_window)
        t_meas = np.asarray(f.measured_time_s, float)
        meas = np.asarray(f.measured_C, float)
        in_read = rows_between(t_meas, read_t[0] - cfg.step_s + 1e-9, read_t[-1] + 1e-9)
        needed = min_bin_samples(t_meas[in_read], cfg.window_s)
        y_mean, y_anom, observed, sd = [], [], [], []
        for i, b in enumerate(bins):
            lo, hi = read_t[b[0]] - cfg.step_s, read_t[b[-1]]
            m, counts = bin_mean(t_meas, meas, lo, hi)
            observed.append(np.where(counts >= needed, m, np.nan))
            y_mean.append(read[b].mean(axis=0) + bias)
            anom = 0.5 * (fc.sensors_anomalies_C[i] + fc.sensors_anomalies_C[i + 1])
            anom = anom + bias_anomalies
            if lag_anomalies is not None:  # a member reads its metal with its own lag
                anom = anom + np.outer(slope[1:][b].mean(axis=0), lag_anomalies)
            y_anom.append(anom)
            # the lag is known only roughly: its error grows with the rate of change
            rate = np.abs(read[b[-1]] - read[b[0]]) / max(hi - lo - cfg.step_s, cfg.step_s)
            sd.append(np.sqrt(cfg.model_sd_C**2 + (cfg.lag_sd_s * rate) ** 2
                              + cfg.sensor_sd_C**2 / np.maximum(counts, 1)))
        drift_seen = False
        if cfg.assimilate_drift and f.measured_drift_um is not None:
            drift, drift_anom = self._drift_forecast(fc)
            for i, b in enumerate(bins):
                lo, hi = read_t[b[0]] - cfg.step_s, read_t[b[-1]]
                m, counts = bin_mean(t_meas, np.asarray(f.measured_drift_um, float)[:, None],
                                     lo, hi)
                observed.append(np.where(counts >= needed, m, np.nan))
                drift_seen |= bool(counts[0] >= needed)
                y_mean.append(drift[b].mean(keepdims=True))
                y_anom.append(0.5 * (drift_anom[i] + drift_anom[i + 1])[None, :])
                sd.append(np.sqrt(cfg.drift_model_sd_um**2 + (cfg.drift_rel_sd * m) ** 2
                                  + cfg.drift_noise_um**2 / np.maximum(counts, 1)))
        return WindowObservations(np.concatenate(y_mean), np.vstack(y_anom),
                                  np.concatenate(observed), np.concatenate(sd), reads, slope,
                                  drift_seen)

    def _forecast_from(self, start: WindowStart) -> tuple[WindowForecast, BoundaryConditions]:
        """The window forecast from `start` (the mean by the FEM, loads following its rings
        where configured; the members tangent-linear) and the mean's conditions at the
        window start."""
        cfg = self.config
        factors = factors_of(self._names, start.ensemble.log_factor_mean)
        offset = coolant_offset_of(self._names, start.ensemble.log_factor_mean)

        def conditions_at(T: np.ndarray) -> BoundaryConditions:
            return apply_factors(self._conditions_at(start.conditions, T), factors, offset)

        bc = conditions_at(start.field_C)
        loads = bc.to_thermal_loads()
        thermal = self.model.thermal
        substeps = cfg.steps_per_window // cfg.bins_per_window
        forecast = forecast_window(
            thermal.transient(loads, cfg.step_s),
            thermal.transient(loads, cfg.step_s * substeps),
            substeps,
            TangentOperators(thermal, bc, self._names),
            start.ensemble, self._sensors, self._drift_um, cfg.steps_per_window,
            stepper_at=(lambda T: thermal.transient(conditions_at(T).to_thermal_loads(),
                                                    cfg.step_s))
            if cfg.loads_follow_rings else None,
        )
        return forecast, bc

    def _window_metal(self, time_s: np.ndarray, sensors_C: np.ndarray, start: WindowStart
                      ) -> tuple[np.ndarray, np.ndarray]:
        """The metal at the sensor points over the window just ended, its start and steps
        (the last steps + 1 rows of `time_s`, `sensors_C`), the start taken from the field
        the window started from (the analysed one, not the row the loop's history holds
        there); and those rows' times, s."""
        rows = slice(len(time_s) - self.config.steps_per_window - 1, len(time_s))
        metal = np.array(sensors_C[rows], float)
        metal[0] = self._sensors @ start.field_C
        return metal, np.asarray(time_s[rows], float)

    def _lag_of(self, start: WindowStart) -> float:
        """The thermocouples' time constant a window from `start` is read with, s."""
        cfg = self.config
        factors = factors_of(self._names, start.ensemble.log_factor_mean)
        return cfg.sensor_lag_s * factors.get("sensor_lag", 1.0)

    def _window_readings(self, time_s: np.ndarray, sensors_C: np.ndarray,
                         start: WindowStart) -> np.ndarray:
        """T1..T5's readings over the window just ended (rows as `_window_metal`): its
        metal through the window's lag, from their readings at its start."""
        metal, t = self._window_metal(time_s, sensors_C, start)
        return first_order_lag(metal, t, self._lag_of(start), start.readings_C)

    def _readings_lag_slope(self, time_s: np.ndarray, sensors_C: np.ndarray,
                            readings_C: np.ndarray, start: WindowStart) -> np.ndarray:
        """∂(`readings_C`, the window's readings)/∂(the lag's log-factor), same shape: a
        forward difference that carries the start readings' own derivative."""
        metal, t = self._window_metal(time_s, sensors_C, start)
        moved = first_order_lag(metal, t, self._lag_of(start) * np.exp(LAG_STEP),
                                start.readings_C + LAG_STEP * start.readings_slope_C)
        return (moved - readings_C) / LAG_STEP

    def _conditions_at(self, bc: BoundaryConditions, field_C: np.ndarray) -> BoundaryConditions:
        """The loop's nominal conditions with the bearing heat and contact resistance taken
        at the temperatures of `field_C` (the analysed field the window starts from, not the
        loop's last forecast: after a missed speed change they differ by kelvins, and the
        Palmgren heat with them)."""
        return bc.with_values(**bearing_values_at(self.model, bc.speed_rpm,
                                                  self._sensors @ field_C))

    def _rerun(self, f: WindowFeatures, fc: WindowForecast, start: WindowStart,
               inlet: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, WindowForecast]:
        """The window just ended re-run from its start field, each solver step at the speed
        recorded at its midpoint, with the nominal bearing heat and contact resistance
        re-evaluated every solver step at the re-run's own ring and sleeve temperatures, as the
        spindle's follow them (`twin.correction.rerun`): this window's nominal conditions
        at the current speed, nominal conditions for any other speed (a step up and a stop
        inside one window), all with the same factors (`start`'s).  Returns T1..T5 history
        with the window replaced, the end field and the forecast with that mean (the
        members' anomalies are kept).  `inlet`: the recorded coolant inlet per solver step
        where it moved inside the window (`_moved_inlet`), else None."""
        from twin.spindle.conditions import nominal_conditions

        cfg = self.config
        T0 = start.field_C
        factors = factors_of(self._names, start.ensemble.log_factor_mean)
        offset = coolant_offset_of(self._names, start.ensemble.log_factor_mean)
        current = f.twin_state.conditions
        steps = cfg.steps_per_window
        window_start_s = f.start_s - cfg.window_s

        def advance(speed: float, T: np.ndarray, n: int, start_s: float) -> np.ndarray:
            base = current
            if abs(speed - current.speed_rpm) > 0.5:
                base = nominal_conditions(self.model, speed, current.ambient_C,
                                          current.coolant_C)
            if inlet is not None:  # the inlet it had over these steps
                first = int(round((start_s - window_start_s) / cfg.step_s))
                base = base.with_coolant(float(np.mean(inlet[first:first + n])))
            bc = apply_factors(self._conditions_at(base, T), factors, offset)
            stepper = self.model.thermal.transient(bc.to_thermal_loads(), cfg.step_s)
            return np.array(list(stepper.march(T, n)))

        fields = rerun_window(T0, f.start_s - cfg.window_s,
                              recorded_step_speeds(f, steps, cfg.step_s), cfg.step_s, advance)
        sim_C = np.asarray(f.simulated_C, float).copy()
        # row by row, as the forecast computes them (a matrix product may round differently)
        sim_C[-steps:] = [self._sensors @ T for T in fields]
        drift = np.array([self._drift_um @ T for T in fields])
        return sim_C, fields[-1], replace(fc, drift_mean_um=drift)

    def _moved_inlet(self, f: WindowFeatures, start: WindowStart) -> np.ndarray | None:
        """The recorded coolant inlet (°C) at each solver step of the window just ended,
        the mean of its samples in the step's 20 s bin (as the thermocouples are read),
        where one bin's moved more than `rerun_inlet_K` from the inlet the window's
        forecast ran at (`start`'s conditions); else None (also where the run records no
        inlet or a bin holds no sample of it).  The forecast held the inlet read at its
        start through the window (causality); a chiller cycling ±2 K every 10 min then left
        T2 and T5 off by half the inlet's change, and the analysis read that as motor loss
        and coolant film (motor 1.9 against a true 0.9)."""
        if f.measured_coolant_C is None:
            return None
        cfg = self.config
        t = np.asarray(f.measured_time_s, float)
        recorded = np.asarray(f.measured_coolant_C, float)
        window_start_s = f.start_s - cfg.window_s
        inlet = np.empty(cfg.steps_per_window)
        for steps in np.array_split(np.arange(cfg.steps_per_window), cfg.bins_per_window):
            inlet[steps], _ = bin_mean(t, recorded, window_start_s + steps[0] * cfg.step_s,
                                       window_start_s + (steps[-1] + 1) * cfg.step_s)
        moved = np.abs(inlet - start.conditions.coolant_C)
        if not np.all(np.isfinite(inlet)) or moved.max() <= cfg.rerun_inlet_K:
            return None
        return inlet

    def _drift_forecast(self, fc: WindowForecast) -> tuple[np.ndarray, np.ndarray]:
        """The mean's axial nose drift since the run start at every solver step (s,) and
        the members' anomalies at the member steps (b + 1, N), µm, with the expansion
        factor e^φ: drift = e^φ · w·(T − T₀), so a member moves by
        e^φ̄ (w·δT + w·(T̄ − T₀) δφ) to first order."""
        rise = fc.drift_mean_um - self._drift_start_um
        anomalies = fc.drift_anomalies_um
        if self._expansion is None:
            return rise, anomalies
        ens = fc.end
        scale = float(np.exp(ens.log_factor_mean[self._expansion]))
        rise_members = fc.drift_mean_at_members() - self._drift_start_um
        dphi = ens.log_factor_anomalies[self._expansion]
        return scale * rise, scale * (anomalies + np.outer(rise_members, dphi))

    def _as_reported(self, fc: WindowForecast) -> WindowForecast:
        """`fc` with each member's T1..T5 as reported: with its own thermocouple offsets
        where they are estimated and reported (the band is the readings')."""
        if self._bias is None or not self.config.report_readings:
            return fc
        bias = fc.end.log_factor_anomalies[self._bias]
        return replace(fc, sensors_anomalies_C=fc.sensors_anomalies_C + bias)

    def _band_sd(self, fc: WindowForecast) -> np.ndarray:
        drift, drift_anom = self._drift_forecast(fc)
        var_T, var_d = self._as_reported(fc).spread_at_steps(drift_anom)
        sd_T = self._band_scale[:-1] * np.sqrt(var_T + self._band_var[:-1])
        sd_d = self._band_scale[-1] * np.sqrt(
            var_d + (self.config.drift_rel_sd * drift) ** 2 + self._band_var[-1])
        return np.column_stack([sd_T, sd_d])

    def _calibrate_band(self, f: WindowFeatures, model_C: np.ndarray,
                        model_fc: WindowForecast) -> None:
        """Update the band (T1..T5, drift) from the window just ended.  The conformal step
        counts the misses of the band as reported (the reported twin, the band used).  The
        model-plus-noise variance learns the mean of (measured − twin)² less the ensemble's
        own variance, over the valid samples, blended into the running value with weight
        `band_learning_rate`, where the twin is `model_C` (T1..T5 history) and `model_fc`:
        the window as re-run with its recorded speed where the speed changed inside it,
        else the reported one.  A fixed model error made the band of a quiet run (0.02 K
        noise, twin within 0.05 K) cover 100 % and that of a rough one too little."""
        cfg = self.config
        t = np.asarray(f.measured_time_s, float)
        rows = rows_between(t, f.start_s - cfg.window_s + 1e-9, np.inf)
        if rows.start == rows.stop:
            return
        tm = t[rows]
        steps = cfg.steps_per_window
        sim_t = np.asarray(f.simulated_time_s, float)[-steps - 1:]

        def at_samples(values: np.ndarray, times: np.ndarray = sim_t) -> np.ndarray:
            return np.column_stack([np.interp(tm, times, v) for v in np.atleast_2d(values.T)])

        def twin_and_spread(sim_C: np.ndarray, fc: WindowForecast
                            ) -> tuple[np.ndarray, np.ndarray]:
            """The twin and the members' variance at the samples: T1..T5, then the drift."""
            sim_C = np.asarray(sim_C, float)[-steps - 1:]
            if cfg.report_readings:  # T1..T5 were reported as readings: judge those
                sim_C = self._window_readings(sim_t, sim_C, self._start)
                offsets = self._bias_mean(self._start.ensemble)
                if offsets is not None:  # with the offsets they were reported with
                    sim_C = sim_C + offsets
            drift, drift_anom = self._drift_forecast(fc)
            var_T, var_d = self._as_reported(fc).spread_at_steps(drift_anom)
            var_T = np.vstack([var_T[:1], var_T])  # the window start: as its first step
            return (np.column_stack([at_samples(sim_C), at_samples(drift, sim_t[1:])]),
                    np.column_stack([at_samples(var_T), at_samples(var_d, sim_t[1:])]))

        reported, spread = twin_and_spread(np.asarray(f.simulated_C, float), self._forecast)
        model = reported
        if model_fc is not self._forecast:  # re-run: the variance learns the re-run's misfit
            model, spread = twin_and_spread(model_C, model_fc)
        band_sd = at_samples(self._band_sd_used, sim_t[1:])
        measured = np.asarray(f.measured_C, float)[rows]
        channels = [(j, measured[:, j], cfg.band_floor_C) for j in range(measured.shape[1])]
        if f.measured_drift_um is not None:
            channels.append((-1, np.asarray(f.measured_drift_um, float)[rows],
                             cfg.band_floor_um))
        for channel, samples, floor in channels:  # each thermocouple its own band
            self._adapt_band(channel, samples, reported[:, channel], band_sd[:, channel],
                             model[:, channel], spread[:, channel], floor)

    def _adapt_band(self, channel: int, measured: np.ndarray, reported: np.ndarray,
                    band_sd: np.ndarray, model: np.ndarray, spread: np.ndarray,
                    floor: float) -> None:
        """One channel's band feedback (0–4: T1..T5 in °C, −1: drift in µm) from the samples
        of the window just ended: the adaptive conformal step (Gibbs & Candès 2021) widens
        the band after a window whose reported band (`reported` ± BAND_Z·`band_sd`) missed
        more than 10 % of its valid samples and narrows it after one that missed fewer; the
        model-plus-noise variance takes in the mean of (measured − `model`)² beyond the
        members' `spread`, at least floor²."""
        cfg = self.config
        valid = np.isfinite(measured)
        if valid.any():
            miss = float((np.abs(measured - reported) > BAND_Z * band_sd)[valid].mean())
            self._band_scale[channel] *= np.exp(cfg.band_scale_rate * (miss - 0.1))
        excess = (measured - model) ** 2 - spread
        if np.isfinite(excess).any():
            a = cfg.band_learning_rate
            self._band_var[channel] = (1 - a) * self._band_var[channel] + a * max(
                float(np.nanmean(excess)), floor**2)
