"""How the training targets of the correction networks are made (`twin train --targets`).

Kept apart from `twin.loop.training` so that the command line can list the rules without
loading the loop (numpy, scikit-fem).
"""

from __future__ import annotations

from enum import StrEnum


class TargetRule(StrEnum):
    """A target rule; its value is the name users type."""

    FIT = "fit"
    """Each window's values fitted to the measured window by the twin (`WindowFit`), with
    extra passes driven off the fit (the default)."""
    RATIO = "ratio"
    """The paper's Eq. 2/5/6 on fitted curves of a ratio-corrected simulation."""
