"""Where a replayed suite's estimator error comes from, and how much of it any causal twin
would have (issue 13: the estimator's worst runs).

    python tools/estimator_ceiling.py SUITE_DIR REPLAY_DIR [--method estimator] [--all]
                                      [--json FILE]

SUITE_DIR is a `twin synth --suite` folder (runs, `*.truth.csv`, `*.scenario.toml`,
`*.profile.csv`); REPLAY_DIR its `twin replay ... --methods open_loop,estimator` output.
Per run (by default only the runs that miss an issue-13 target; `--all`: every run):

- the five criteria: temperature accuracy ≥ 99.5 %, deformation ≥ 96 %, mean sensor RMSE
  ≤ 1/3 of open loop's, drift RMSE ≤ 1/2 of open loop's, 90 % band coverage 70–99 %;
- the accuracy lost (points of %) in four classes of windows, summing to 100 − accuracy:
  `step` windows with a speed change inside them (their loads were fixed at the window
  start, DESIGN.md causality), `after` the window right after one of those, `first`
  windows 1–2 (window 0 is not scored), `rest`;
- the noise ceiling: the accuracy of the noise-free truth (`*.truth.csv`: metal
  temperatures put through the run's thermocouple lag and read with its thermocouples'
  calibration offsets, and the nose drift) against the measurement — what a perfect twin
  scores, set by sensor noise alone (every ceiling here reads the metal with the
  offsets the truth file records: a twin that knew everything would know them too);
- the metal ceiling: the same with the truth's metal temperatures, no lag: what a perfect
  twin scores in temperature if it reports the metal at T1..T5 (as the twin does) while
  the thermocouples lag by 4–20 s;
- the causal-oracle ceiling: the truth everywhere except in the step windows, where it is
  the truth re-run from its own field at the window start with the window start's speed
  held to the window end (exactly the emulator's model, factors and tables, via the run's
  scenario and seed).  A twin that knows everything up to the window start and is bound to
  the window start's loads cannot beat it; `oracle step` is its loss in those windows.

The metrics are the replay's (`twin.loop.metrics`): scored after the first window, against
the measured samples in `keypoints.csv`, skipping the samples the quality check excluded.
Not a test and not a benchmark: a diagnosis table for the closing note of issue 13.
"""

from __future__ import annotations

import argparse
import csv
import json
import re
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from twin.contract import SENSOR_NAMES, WINDOW_S
from twin.lag import first_order_lag
from twin.loop.metrics import T_FLOOR_C
from twin.plant.emulator import synthesize
from twin.plant.profile import read_speed_profile
from twin.plant.scenario import load_scenario
from twin.plant.timetable import StepTable

FIRST_WINDOWS = 3
"""Windows 0..2 are the start-up class (window 0 itself is not scored)."""


def read_table(path: Path) -> tuple[dict[str, str], dict[str, np.ndarray]]:
    """`# key: value` metadata and the numeric columns of a CSV (text columns kept as str)."""
    meta, rows = {}, []
    with path.open() as fh:
        lines = [ln for ln in fh if ln.strip()]
    body = []
    for ln in lines:
        m = re.match(r"#\s*([^:]+):\s*(.*)", ln)
        if m:
            meta[m.group(1).strip()] = m.group(2).strip()
        elif not ln.startswith("#"):
            body.append(ln)
    reader = csv.reader(body)
    header = next(reader)
    rows = list(reader)
    cols = {}
    for j, name in enumerate(header):
        values = [r[j] for r in rows]
        try:
            cols[name] = np.array([float(v) if v != "" else np.nan for v in values])
        except ValueError:
            cols[name] = np.array(values)
    return meta, cols


def window_of(time_s: np.ndarray) -> np.ndarray:
    """Window index of solver steps at time_s (a step at 60k s ends window k − 1)."""
    return np.ceil(np.asarray(time_s) / WINDOW_S - 1e-9).astype(int) - 1


def step_windows(profile: Path, duration_s: float) -> set[int]:
    """Windows with a recorded speed change strictly inside them."""
    speed = read_speed_profile(profile).speed_rpm
    out = set()
    for c in speed.changes_in(0.0, duration_s):
        k, inside = divmod(float(c), WINDOW_S)
        if inside > 1e-9:
            out.add(int(k))
    return out


def losses(time_s: np.ndarray, twin: np.ndarray, meas: np.ndarray, drift_twin: np.ndarray,
           drift_meas: np.ndarray, classes: dict[str, np.ndarray]) -> dict:
    """Accuracy (%) and the points lost per class of steps (boolean masks over time_s)."""
    after = np.asarray(time_s) > WINDOW_S - 1e-9
    ok = np.isfinite(meas) & np.isfinite(twin) & after[:, None]
    rel = np.where(ok, np.abs(twin - meas) / np.maximum(np.abs(np.where(ok, meas, 0)),
                                                        T_FLOOR_C), 0.0)
    n = ok.sum()
    okd = np.isfinite(drift_meas) & np.isfinite(drift_twin) & after
    e_d = np.where(okd, np.abs(drift_twin - drift_meas), 0.0)
    scale_d = np.abs(np.where(okd, drift_meas, 0.0)).sum()
    sq = np.where(ok, (twin - meas) ** 2, 0.0)
    seen = ok.sum(axis=0)  # a sensor the quality check excluded throughout has no RMSE
    rmse = np.sqrt(sq.sum(axis=0)[seen > 0] / seen[seen > 0])
    out = {"T": 100 * (1 - rel.sum() / n),
           "rmse_C": float(rmse.mean()),
           "rmse_um": float(np.sqrt(np.mean(e_d[okd] ** 2))) if okd.any() else np.nan,
           "def": 100 * (1 - e_d.sum() / scale_d) if scale_d > 0 else np.nan}
    for name, mask in classes.items():
        out[f"T_{name}"] = 100 * rel[mask].sum() / n
        out[f"def_{name}"] = 100 * e_d[mask].sum() / scale_d if scale_d > 0 else np.nan
    return out


def reproduce_args(scenario_path: Path) -> dict[str, float]:
    """--seed/--ambient/--rate/--coolant of the scenario's `# reproduce:` header line."""
    text = scenario_path.read_text().splitlines()
    line = next(ln for ln in text if ln.startswith("# reproduce:"))
    args = dict(re.findall(r"--(seed|ambient|rate|coolant|minutes) (\S+)", line))
    return {k: float(v) for k, v in args.items()}


def oracle_windows(run_csv: Path, windows: set[int], lag_s: float
                   ) -> dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Per step window k: (time_s, lagged T1..T5, drift) of the truth re-run from its own
    state at 60k s with the speed of 60k s held to the window end (samples at 1 Hz)."""
    stem = run_csv.with_suffix("")
    scenario_path = Path(f"{stem}.scenario.toml")
    profile = read_speed_profile(Path(f"{stem}.profile.csv"))
    args = reproduce_args(scenario_path)
    scenario = load_scenario(scenario_path)
    table = profile.speed_rpm
    out = {}
    for k in sorted(windows):
        start = k * WINDOW_S
        keep = table.time_s < start - 1e-9
        held = StepTable(np.append(table.time_s[keep], start),
                         np.append(table.values[keep], float(table(start))))
        run = synthesize(minutes=(k + 1) * WINDOW_S / 60.0, ambient_C=args["ambient"],
                         seed=int(args["seed"]), profile=replace(profile, speed_rpm=held),
                         scenario=scenario, rate_hz=args.get("rate", 1.0),
                         coolant_C=args.get("coolant"))
        t = run.truth["time_s"]
        metal = np.column_stack([run.truth[f"{s}_true_C"] for s in SENSOR_NAMES])
        out[k] = (t, first_order_lag(metal, t, lag_s),
                  run.truth["disp_z_true_um"])
    return out


def analyse_run(run_csv: Path, replay_dir: Path, method: str) -> dict:
    name = run_csv.stem
    acc = json.loads((replay_dir / name / "accuracy.json").read_text())["methods"]
    _, kp = read_table(replay_dir / name / "keypoints.csv")
    meta, _ = read_table(run_csv)
    truth_meta, truth = read_table(Path(f"{run_csv.with_suffix('')}.truth.csv"))
    lag_s = float(meta.get("thermocouple_lag_s", 0.0))
    offsets_C = np.array([float(truth_meta.get(f"{s}_calibration_offset_C", 0.0))
                          for s in SENSOR_NAMES])
    tt = truth["time_s"]
    truth_T = first_order_lag(np.column_stack([truth[f"{s}_true_C"] for s in SENSOR_NAMES]),
                              tt, lag_s) + offsets_C
    rows = {m: kp["method"] == m for m in ("open_loop", method)}
    t = kp["time_s"][rows[method]]
    meas = np.column_stack([kp[f"{s}_meas_C"][rows[method]] for s in SENSOR_NAMES])
    drift_meas = kp["disp_z_meas_um"][rows[method]]
    win = window_of(t)
    steps = step_windows(Path(f"{run_csv.with_suffix('')}.profile.csv"), float(t[-1]))
    is_step = np.isin(win, sorted(steps))
    is_after = np.isin(win, [k + 1 for k in steps]) & ~is_step
    classes = {"step": is_step, "after": is_after,
               "first": (win < FIRST_WINDOWS) & ~is_step & ~is_after,
               "rest": (win >= FIRST_WINDOWS) & ~is_step & ~is_after}
    twin = {m: (np.column_stack([kp[f"{s}_twin_C"][r] for s in SENSOR_NAMES]),
                kp["disp_z_twin_um"][r]) for m, r in rows.items()}

    def at(values: np.ndarray) -> np.ndarray:
        return np.stack([np.interp(t, tt, v) for v in np.atleast_2d(values.T)], axis=-1
                        ).squeeze()

    noise_T, noise_d = at(truth_T), at(truth["disp_z_true_um"])
    metal_T = at(np.column_stack([truth[f"{s}_true_C"] for s in SENSOR_NAMES]) + offsets_C)
    oracle_T, oracle_d = noise_T.copy(), noise_d.copy()
    for k, (ot, oT, od) in oracle_windows(run_csv, steps, lag_s).items():
        oT = oT + offsets_C
        sel = win == k
        before = ot < k * WINDOW_S + 1e-9  # 1 Hz from 0 s in both files
        if not np.allclose(oT[before], truth_T[:before.sum()], atol=2e-4):
            raise RuntimeError(f"{name}: the oracle's truth before window {k} differs from "
                               f"the run's truth (scenario not reproduced)")
        oracle_T[sel] = np.stack([np.interp(t[sel], ot, oT[:, j]) for j in range(5)], axis=1)
        oracle_d[sel] = np.interp(t[sel], ot, od)
    res = {"run": name, "step_windows": sorted(steps)}
    for label, (T, d) in {**twin, "noise": (noise_T, noise_d),
                          "metal": (metal_T, noise_d), "oracle": (oracle_T, oracle_d)}.items():
        res[label] = losses(t, T, meas, d, drift_meas, classes)
    e, o = acc[method], acc["open_loop"]

    def mean_rmse(m: dict) -> float:
        v = [x for x in m["rmse_C"].values() if x is not None]
        return float(np.mean(v))

    res["criteria"] = {
        "T": e["temperature_accuracy_pct"] >= 99.5,
        "def": (e["deformation_accuracy_pct"] or 0.0) >= 96.0,
        "rmse": mean_rmse(e) <= mean_rmse(o) / 3,
        "drift": e["rmse_um"] is not None and e["rmse_um"] <= o["rmse_um"] / 2,
    }
    if e["band_coverage_pct"] is not None:  # a method with a band (bpnn, ratio have none)
        res["criteria"]["coverage"] = 70.0 <= e["band_coverage_pct"] <= 99.0
    res["rmse_ratio"] = mean_rmse(e) / mean_rmse(o)
    res["drift_ratio"] = e["rmse_um"] / o["rmse_um"] if e["rmse_um"] else np.nan
    res["coverage"] = e["band_coverage_pct"]
    ol = res["open_loop"]  # the ratio a noise-free twin reaches: the criteria's ceiling
    res["noise_rmse_ratio"] = res["noise"]["rmse_C"] / ol["rmse_C"]
    res["noise_drift_ratio"] = res["noise"]["rmse_um"] / ol["rmse_um"]
    res["oracle_rmse_ratio"] = res["oracle"]["rmse_C"] / ol["rmse_C"]
    res["oracle_drift_ratio"] = res["oracle"]["rmse_um"] / ol["rmse_um"]
    res["noise_um"] = float(meta.get("noise_um", "nan"))
    res["mean_drift_um"] = float(np.nanmean(np.abs(drift_meas[t > WINDOW_S])))
    return res


def summary_lines(results: list[dict], method: str) -> list[str]:
    T = np.array([r[method]["T"] for r in results])
    D = np.array([r[method]["def"] for r in results])
    counts = {c: sum(r["criteria"][c] for r in results) for c in results[0]["criteria"]}
    cov = [r["coverage"] for r in results if r["coverage"] is not None]
    coverage = f"; coverage {min(cov):.1f}–{max(cov):.1f} %" if cov else "; no band"
    return [f"{method}: temperature {np.median(T):.2f} / {T.min():.2f} (median / worst), "
            f"deformation {np.median(D):.2f} / {D.min():.2f}; runs meeting "
            + " · ".join(f"{c} {n}" for c, n in counts.items())
            + f" of {len(results)}" + coverage,
            "causal oracle (a ceiling): runs meeting T "
            f"{sum(r['oracle']['T'] >= 99.5 for r in results)} · def "
            f"{sum(r['oracle']['def'] >= 96.0 for r in results)} · rmse "
            f"{sum(r['oracle_rmse_ratio'] <= 1 / 3 for r in results)} · drift "
            f"{sum(r['oracle_drift_ratio'] <= 0.5 for r in results)}; a perfect metal twin: "
            f"T {sum(r['metal']['T'] >= 99.5 for r in results)}"]


def table_lines(results: list[dict], method: str) -> list[str]:
    head = ("| run | misses | T | lost step/after/first/rest | noise T | metal T | oracle T | "
            "deformation | "
            "lost step/after/first/rest | noise def | oracle def (step) | "
            "rmse/ol (noise, oracle) | drift/ol (noise, oracle) | drift µm (noise) |")
    out = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in results:
        e, n, o = r[method], r["noise"], r["oracle"]
        misses = ",".join(c for c, ok in r["criteria"].items() if not ok) or "—"
        out.append(
            f"| {r['run']} | {misses} | {e['T']:.2f} | {e['T_step']:.2f}/{e['T_after']:.2f}/"
            f"{e['T_first']:.2f}/"
            f"{e['T_rest']:.2f} | {n['T']:.2f} | {r['metal']['T']:.2f} | {o['T']:.2f} | "
            f"{e['def']:.2f} | "
            f"{e['def_step']:.2f}/{e['def_after']:.2f}/{e['def_first']:.2f}/"
            f"{e['def_rest']:.2f} | {n['def']:.2f} | "
            f"{o['def']:.2f} ({o['def_step']:.2f}) | {r['rmse_ratio']:.2f} "
            f"({r['noise_rmse_ratio']:.2f}, {r['oracle_rmse_ratio']:.2f}) | "
            f"{r['drift_ratio']:.2f} ({r['noise_drift_ratio']:.2f}, "
            f"{r['oracle_drift_ratio']:.2f}) | {r['mean_drift_um']:.1f} ({r['noise_um']:g}) |")
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("suite", type=Path)
    ap.add_argument("replay", type=Path)
    ap.add_argument("--method", default="estimator")
    ap.add_argument("--all", action="store_true", help="every run, not only those missing")
    ap.add_argument("--json", type=Path)
    a = ap.parse_args(argv)
    runs = sorted(p for p in a.suite.glob("*.csv")
                  if not p.name.endswith((".truth.csv", ".profile.csv")))
    results = [analyse_run(p, a.replay, a.method) for p in runs]
    print("\n".join(summary_lines(results, a.method)))
    shown = [r for r in results if a.all or not all(r["criteria"].values())]
    print("\n".join(table_lines(shown, a.method)))
    if a.json:
        a.json.write_text(json.dumps(results, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
