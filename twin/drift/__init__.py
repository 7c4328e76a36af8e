"""Data-driven thermal-drift models on measured temperatures (no FEM).

    from twin.drift import fit_drift_model, read_drift_data
    data = read_drift_data(["examples/real/caiviac_step_tests.csv"],
                           targets=["ch1_um", "ch2_um"])
    model = fit_drift_model(data, seed=0)          # method chosen by blocked validation
    mean, lo, hi = model.predict(data)              # µm, 90 % interval

Modules, one concept each: `data` (reading, checks, causal gap bridging), `features`
(rises, first-order lags, speed history), `ranking` (grey relational grade, correlation
clusters), `folds` (time blocks), `linear`, `network`, `bayesian`, `rbf`, `stacking`
(the methods), `methods` (their registry), `intervals`, `metrics`, `validation`,
`model` (fit and predict), `modelfile` (safetensors + JSON), `report`.
"""
