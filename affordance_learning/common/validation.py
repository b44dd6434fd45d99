"""Input checks shared by the learning modules."""

from __future__ import annotations

import numpy as np

from affordance_learning.common.exceptions import InvalidValueError

#: The largest float32: the models (their trees, scikit-learn's scalers) read their inputs as float32, so a finite
#: float64 beyond it becomes infinite there.
FLOAT32_MAX = float(np.finfo(np.float32).max)


def first_non_finite(values: np.ndarray) -> tuple[int, int, int, float] | None:
    """``(count, row, column, value)`` of the first NaN or inf of a 2-D array (row-major), or None if all finite."""
    bad = ~np.isfinite(values)
    if not bad.any():
        return None
    row, col = np.argwhere(bad)[0]
    return int(bad.sum()), int(row), int(col), float(values[row, col])


def check_float32_range(name: str, values: np.ndarray) -> None:
    """Raise InvalidValueError unless the finite ``values`` fit float32 (:data:`FLOAT32_MAX`), naming the largest."""
    largest = float(np.max(np.abs(values))) if np.size(values) else 0.0
    if largest > FLOAT32_MAX:
        raise InvalidValueError(f"{name} must be within +-{FLOAT32_MAX:.3g} (float32), got one of {largest!r}.")
