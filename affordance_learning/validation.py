"""Input checks shared by the learning modules."""

from __future__ import annotations

import numpy as np


def first_non_finite(values: np.ndarray) -> tuple[int, int, int, float] | None:
    """``(count, row, column, value)`` of the first NaN or inf of a 2-D array (row-major), or None if all finite."""
    bad = ~np.isfinite(values)
    if not bad.any():
        return None
    row, col = np.argwhere(bad)[0]
    return int(bad.sum()), int(row), int(col), float(values[row, col])
