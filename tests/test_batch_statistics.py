"""summary.json statistics over a batch (median, worst, failed) and the report's
per-method distribution (issue 12)."""

from __future__ import annotations

import json

import pytest

from twin.loop.metrics import batch_summary, median_metrics, worst_metrics
from twin.loop.report import DISTRIBUTION_MIN_RUNS, build_report


def fake_run(name: str, t_acc: float, d_acc: float | None, rmse_um: float) -> dict:
    metrics = {"temperature_accuracy_pct": t_acc, "temperature_rise_accuracy_pct": t_acc - 10,
               "deformation_accuracy_pct": d_acc, "rmse_C": {"T1": 0.1}, "rmse_um": rmse_um,
               "max_abs_C": 100 - t_acc}
    return {"run": name, "speed_rpm": 9000.0, "ambient_C": 25.0, "duration_s": 1800.0,
            "methods": {"open_loop": metrics,
                        "ratio": {**metrics, "temperature_accuracy_pct": t_acc + 0.5}}}


RUNS = [fake_run("a", 99.0, 90.0, 1.0), fake_run("b", 97.0, None, 3.0),
        fake_run("c", 98.0, 80.0, 2.0), fake_run("d", 96.0, 85.0, 0.5)]


def test_median_and_worst_per_method():
    median = median_metrics(RUNS)["open_loop"]
    assert median["temperature_accuracy_pct"] == pytest.approx(97.5)
    assert median["deformation_accuracy_pct"] == pytest.approx(85.0)  # b has none
    worst = worst_metrics(RUNS)
    assert worst["open_loop"]["temperature_accuracy_pct"] == 96.0  # lowest accuracy
    assert worst["ratio"]["temperature_accuracy_pct"] == 96.5
    assert worst["open_loop"]["deformation_accuracy_pct"] == 80.0
    assert worst["open_loop"]["rmse_um"] == 3.0  # largest error
    assert worst["open_loop"]["max_abs_C"] == 4.0


def test_summary_has_every_design_key():
    failed = [{"run": "bad", "error": "x.csv, row 3: ...", "kind": "input"}]
    summary = batch_summary(RUNS, failed)
    assert list(summary) == ["runs", "failed", "mean", "median", "worst"]
    assert summary["failed"] == failed
    assert summary["mean"]["open_loop"]["temperature_accuracy_pct"] == pytest.approx(97.5)
    assert batch_summary(RUNS, [])["failed"] == []
    json.dumps(summary)  # plain JSON


def replay_folder(tmp_path, n: int):  # noqa: ANN001, ANN201
    runs = [fake_run(f"run{i}", 95.0 + i * 0.4, 80.0 + i, 1.0 + i / 10) for i in range(n)]
    for r in runs:
        (tmp_path / r["run"]).mkdir()
        (tmp_path / r["run"] / "accuracy.json").write_text(json.dumps(r))
    return runs


def test_report_shows_the_distribution_for_a_larger_batch(tmp_path):
    replay_folder(tmp_path, 7)
    page = build_report(tmp_path).read_text()
    assert "distribution over the 7 runs" in page
    summary = json.loads((tmp_path / "summary.json").read_text())
    median = summary["median"]["ratio"]["temperature_accuracy_pct"]
    worst = summary["worst"]["open_loop"]["deformation_accuracy_pct"]
    assert median == pytest.approx(95.0 + 3 * 0.4 + 0.5) and worst == 80.0
    table = page[page.index("distribution over"):]
    assert f"{median:.2f}" in table and f"{worst:.2f}" in table
    assert table.count("data:image/png;base64,") == 1


def test_report_of_a_few_runs_has_no_distribution(tmp_path):
    replay_folder(tmp_path, DISTRIBUTION_MIN_RUNS - 1)
    page = build_report(tmp_path).read_text()
    assert "distribution over" not in page
    assert "median" in json.loads((tmp_path / "summary.json").read_text())
