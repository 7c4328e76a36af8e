"""A small synthetic machine for the drift tests: speed steps, lagging sensors, a drift.

Two sensors follow the heat input with first-order responses (closed form for held
inputs); the drift follows sensor A through a further 20-min lag plus a share of B, so a
model needs the lagged features.  15 s sampling.
"""

from __future__ import annotations

import numpy as np

from twin.lag import first_order_lag


def synthetic_columns(hours: float = 4.0, seed: int = 0, noise_um: float = 0.05
                      ) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, hours * 3600.0, 15.0)
    speed = np.where((t // 2400) % 2 == 0, 3000.0, 0.0) * (1 + (t // 4800) % 2)
    heat = (speed / 1000.0) ** 1.5
    a = 20.0 + first_order_lag(heat, t, 900.0, between="held")
    b = 20.0 + 0.5 * first_order_lag(heat, t, 2400.0, between="held")
    c = 20.0 + 0.1 * np.sin(t / 3000.0)
    drift = (3.0 * (first_order_lag(a - 20.0, t, 1200.0, between="held"))
             + 1.5 * (b - 20.0) + rng.normal(0.0, noise_um, t.size))
    return {"time_s": t, "speed_rpm": speed, "A_C": a + rng.normal(0, 0.01, t.size),
            "B_C": b + rng.normal(0, 0.01, t.size), "C_C": c, "drift_um": drift}


def write_csv(path, columns: dict[str, np.ndarray], metadata: str = "") -> None:
    names = list(columns)
    lines = [metadata + ",".join(names)]
    for row in zip(*(columns[n] for n in names), strict=True):
        lines.append(",".join("nan" if np.isnan(v) else f"{v:.6g}" for v in row))
    path.write_text("\n".join(lines) + "\n")
