"""The noise estimate of the quality check (and `tools/sensor_noise.py`) against data of
known noise: a smooth warm-up plus Gaussian noise of a chosen σ."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from twin.runs.quality import noise_sigma

ROOT = Path(__file__).resolve().parent.parent


def load_tool():  # noqa: ANN201 - the tool module
    spec = importlib.util.spec_from_file_location("sensor_noise",
                                                  ROOT / "tools" / "sensor_noise.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def warm_up(t_s: np.ndarray, rise: float, tau_s: float) -> np.ndarray:
    return rise * (1.0 - np.exp(-t_s / tau_s))


@pytest.mark.parametrize("sigma", [0.01, 0.05, 0.3])
def test_noise_sigma_recovers_white_noise_under_a_warm_up(sigma):
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 7200.0, 1.0)
    x = 22.0 + warm_up(t, 15.0, 900.0) + rng.normal(0.0, sigma, t.size)
    assert noise_sigma(x) == pytest.approx(sigma, rel=0.05)


def test_noise_sigma_keeps_only_triples_of_kept_samples():
    # Quiet while stopped, rough while running: the mask must separate the two, and a
    # triple straddling a change must not count (the step itself is no noise).
    rng = np.random.default_rng(4)
    running = (np.arange(6000) // 1000) % 2 == 1
    x = np.where(running, 10.0, 0.0) + rng.normal(0.0, np.where(running, 0.2, 0.02))
    assert noise_sigma(x, running) == pytest.approx(0.2, rel=0.06)
    assert noise_sigma(x, ~running) == pytest.approx(0.02, rel=0.06)
    assert noise_sigma(x, np.zeros(x.size, dtype=bool)) == 0.0


def test_tool_reports_each_channel_and_the_running_and_stopped_stretches(tmp_path, capsys):
    rng = np.random.default_rng(5)
    t = np.arange(0.0, 16 * 3600.0, 15.0)
    speed = np.where((t // 3600) % 2 == 0, 3000.0, 0.0)
    T = 25.0 + warm_up(t, 8.0, 1800.0) + rng.normal(0.0, 0.01, t.size)
    disp = warm_up(t, 20.0, 2400.0) + rng.normal(0.0, np.where(speed > 0, 0.04, 0.015))
    path = tmp_path / "data.csv"
    rows = "\n".join(f"{a:g},{b:g},{c:.6f},{d:.6f}"
                     for a, b, c, d in zip(t, speed, T, disp, strict=True))
    path.write_text("time_s,speed_rpm,t1_C,ch1_um\n" + rows + "\n", encoding="utf-8")

    tool = load_tool()
    noise = tool.channel_noise(path)
    assert set(noise) == {"t1_C", "ch1_um"}
    assert noise["t1_C"]["all"] == pytest.approx(0.01, rel=0.1)
    assert noise["ch1_um"]["running"] == pytest.approx(0.04, rel=0.15)
    assert noise["ch1_um"]["stopped"] == pytest.approx(0.015, rel=0.15)

    assert tool.main([str(path), "--json", str(tmp_path / "noise.json")]) == 0
    assert "ch1_um" in capsys.readouterr().out
    assert (tmp_path / "noise.json").is_file()


def test_tool_names_a_bad_file_and_exits_2(tmp_path, capsys):
    path = tmp_path / "data.csv"
    path.write_text("time_s,t1_C\n0,abc\n", encoding="utf-8")
    assert load_tool().main([str(path)]) == 2
    err = capsys.readouterr().err
    assert "data.csv" in err and "t1_C" in err
