"""Built-in motor losses (REFERENCE.md §2 and §3).

Q = P · (1 − η) · η': the part of the motor's power P that is lost (1 − η, η = 0.9) and of
that the share turned into heat inside the spindle (η' = 0.88).  The loss is split 1/3 into
the rotor and 2/3 into the stator (REFERENCE.md §2).

The power drawn at a speed follows the usual spindle-motor characteristic: constant torque
up to the base speed (P grows linearly with n), constant power above; `load_fraction` is
the share of the rated power the operating point draws (an idling thermal test still draws
part of it for the bearings' friction, windage and the magnetising current).
"""

from __future__ import annotations

import math

ROTOR_SHARE = 1.0 / 3.0
STATOR_SHARE = 2.0 / 3.0


def motor_loss_W(speed_rpm: float, *, rated_power_W: float, base_speed_rpm: float,
                 load_fraction: float, efficiency: float = 0.9,
                 heat_share: float = 0.88) -> float:
    """Motor heat Q = P(n) · (1 − η) · η' in W, P(n) = load · P_N · min(1, n/n_base)."""
    for name, value in (("speed_rpm", speed_rpm), ("rated_power_W", rated_power_W),
                        ("load_fraction", load_fraction)):
        if not math.isfinite(value) or value < 0.0:
            raise ValueError(f"{name} must be a finite non-negative number, got {value}")
    if not base_speed_rpm > 0.0:
        raise ValueError(f"base_speed_rpm must be positive, got {base_speed_rpm}")
    if not 0.0 < efficiency <= 1.0:
        raise ValueError(f"efficiency must be in (0, 1], got {efficiency}")
    if not 0.0 <= heat_share <= 1.0:
        raise ValueError(f"heat_share must be in [0, 1], got {heat_share}")
    power_W = load_fraction * rated_power_W * min(1.0, speed_rpm / base_speed_rpm)
    return power_W * (1.0 - efficiency) * heat_share


def motor_heat_split_W(loss_W: float) -> dict[str, float]:
    """Split a motor loss into {"rotor": Q/3, "stator": 2Q/3} in W (REFERENCE.md §2)."""
    if not math.isfinite(loss_W) or loss_W < 0.0:
        raise ValueError(f"loss_W must be a finite non-negative number, got {loss_W}")
    return {"rotor": ROTOR_SHARE * loss_W, "stator": STATOR_SHARE * loss_W}
