"""Re-running a window with a missed speed change (twin.correction.rerun)."""

from __future__ import annotations

import numpy as np

from twin.correction.rerun import rerun_window, speed_stretches


def test_stretches_of_equal_speed_are_solved_one_after_another():
    speeds = np.array([6000.0] * 4 + [12000.0] * 6 + [3000.0] * 5)
    assert speed_stretches(speeds) == [(6000.0, 0, 4), (12000.0, 4, 6), (3000.0, 10, 5)]
    calls = []

    def advance(speed, T, n, start_s):  # each step adds the speed in krpm
        calls.append((speed, n, start_s))
        return T + 1e-3 * speed * np.arange(1, n + 1)[:, None]

    fields = rerun_window(np.zeros(2), 60.0, speeds, 4.0, advance)
    assert calls == [(6000.0, 4, 60.0), (12000.0, 6, 76.0), (3000.0, 5, 100.0)]
    assert fields.shape == (15, 2)
    np.testing.assert_allclose(fields[:, 0], np.cumsum(1e-3 * speeds))
