"""The action every behaviour takes: three numbers in [-1, 1], 0 its canonical interaction."""

from __future__ import annotations

import numpy as np

from affordance_env.exceptions import InvalidValueError
from affordance_env.values import float_array

#: Length of every behaviour's action.
ACTION_DIM = 3


def check_action(action: np.ndarray) -> np.ndarray:
    """Return ``action`` as a float64 (3,) array, or raise InvalidValueError naming the problem."""
    a = float_array("action", action, expected=f"{ACTION_DIM} real numbers in [-1, 1]", finite=False)
    if a.shape != (ACTION_DIM,):
        raise InvalidValueError(f"action must have shape ({ACTION_DIM},), got shape {a.shape}: {action!r}.")
    if not np.all(np.isfinite(a)):
        raise InvalidValueError(f"action must be finite, got {action!r}.")
    if np.any(np.abs(a) > 1.0 + 1e-6):
        raise InvalidValueError(f"action must lie in [-1, 1] in every dimension, got {action!r}.")
    return np.clip(a, -1.0, 1.0)
