"""Statistics both experiments report: a share's Wilson interval and how a share reads, and the calibration of
predicted probabilities (expected calibration error, AUROC, the reliability curve)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from sklearn.metrics import roc_auc_score

from affordance_learning.common.exceptions import InvalidValueError

#: The standard normal quantile of a two-sided 95 % interval.
Z_95 = 1.959963984540054


def wilson_interval(successes: int, n: int, z: float = Z_95) -> tuple[float, float]:
    """Wilson score interval of a share ``successes / n`` (95 % by default), without continuity correction.

    Unlike the normal approximation ``p +- z sqrt(p (1 - p) / n)`` it stays within [0, 1] and does not shrink to a
    point at 0 of n or n of n. ``n = 0`` gives (0, 1): nothing is known.

    Args:
        successes: How many of the ``n`` succeeded, 0 <= successes <= n.
        n: How many there were, >= 0.
        z: Standard normal quantile of the interval's confidence (1.96 for 95 %).

    Returns:
        (low, high), fractions in [0, 1].
    """
    if n < 0 or not 0 <= successes <= n:
        raise InvalidValueError(f"need 0 <= successes <= n, got {successes} of {n}.")
    if n == 0:
        return 0.0, 1.0
    p = successes / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    low = 0.0 if successes == 0 else max(0.0, centre - half)  # exactly, where rounding would leave 1e-16
    high = 1.0 if successes == n else min(1.0, centre + half)
    return float(low), float(high)


def share_text(value: float | None, n: int, ci: Sequence[float] | None = None, unit: str = "",
               digits: int = 0) -> str:
    """A share as the console and the report show it: ``"80 % [62, 91] (n=35 feasible goals)"``, the Wilson 95 %
    interval when given; "not measured (n=0)" for a share of nothing (0 of 0 is no rate, not 0 %)."""
    count = f"n={n}" + (f" {unit}" if unit else "")
    if value is None or n == 0:
        return f"not measured ({count})"
    interval = "" if ci is None else f" [{100 * ci[0]:.0f}, {100 * ci[1]:.0f}]"
    return f"{100 * value:.{digits}f} %{interval} ({count})"


def calibration(p: np.ndarray, y: np.ndarray, bins: int = 10) -> dict[str, Any]:
    """Expected calibration error over ``bins`` equal-width bins, AUROC, and the reliability curve."""
    p, y = np.asarray(p, dtype=float), np.asarray(y, dtype=bool)
    if not len(p):
        return {"ece": None, "auroc": None, "n": 0, "curve": []}
    index = np.clip((p * bins).astype(int), 0, bins - 1)
    curve, ece = [], 0.0
    for b in range(bins):
        members = index == b
        if members.any():
            ece += members.mean() * abs(p[members].mean() - y[members].mean())
            curve.append({"p": float(p[members].mean()), "observed": float(y[members].mean()),
                          "n": int(members.sum())})
    auroc = float(roc_auc_score(y, p)) if 0 < y.mean() < 1 else None
    return {"ece": float(ece), "auroc": auroc, "n": int(len(p)), "curve": curve}
