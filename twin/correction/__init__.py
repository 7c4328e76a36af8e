"""Correction of bearing heat and bearing/sleeve contact resistance (REFERENCE.md §1).

- `formulas`: the analytic corrections (Eq. 2, 3, 5, 6) with their guards.
- `features`: what a method sees of one window (`WindowFeatures`), network inputs.
- `methods`: `open_loop`, `ratio`, `bpnn` behind `Corrector.correct(features)`.
- `curvefit`, `samples`, `training_data`: training samples from recorded + simulated runs.
- `network`, `training`, `modelfile`, `report`: the BP networks, Rprop training, the model
  file (safetensors + JSON) and the training report.

Heavy modules (torch, scipy, matplotlib) are imported where they are used.
"""

from twin.correction.features import (
    OUTPUTS,
    WINDOW_S,
    BoundaryValues,
    WindowFeatures,
)
from twin.correction.formulas import ContactFit, RatioGuard, RatioGuards
from twin.correction.methods import (
    METHODS,
    BpnnCorrection,
    Correction,
    Corrector,
    OpenLoop,
    RatioCorrection,
    make_corrector,
)
from twin.correction.modelfile import CorrectionModel, load_model, save_model

__all__ = [
    "METHODS",
    "OUTPUTS",
    "WINDOW_S",
    "BoundaryValues",
    "BpnnCorrection",
    "ContactFit",
    "Correction",
    "CorrectionModel",
    "Corrector",
    "OpenLoop",
    "RatioCorrection",
    "RatioGuard",
    "RatioGuards",
    "WindowFeatures",
    "load_model",
    "make_corrector",
    "save_model",
]
