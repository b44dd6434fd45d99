"""The evaluation's statistics: success per policy with Wilson intervals, success within 1, 3 and 5 cm of a target,
calibration of the chosen actions, and decision times.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from affordance_learning.common.statistics import calibration, wilson_interval
from affordance_learning.planning.results import (
    SUCCESS_DISTANCES_M,
    Calibration,
    CalibrationBin,
    DecisionTimes,
    PolicyOutcome,
    WithinDistance,
)


def wilson(successes: int, n: int) -> tuple[float, float]:
    """Wilson 95 % interval of a share (:func:`~affordance_learning.common.statistics.wilson_interval`); (0, 1)
    for 0 of 0."""
    return wilson_interval(int(successes), int(n))


def _calibration(p: Any, y: Any, basis: str, pooled: Calibration | None = None) -> Calibration:
    """The calibration of probabilities ``p`` against outcomes ``y``
    (:func:`~affordance_learning.common.statistics.calibration`), over the actions ``basis`` names."""
    found = calibration(p, y)
    return Calibration(found["ece"], found["auroc"], found["n"], tuple(CalibrationBin(**b) for b in found["curve"]),
                       basis, pooled)


def calibrations(records: Sequence[Mapping[str, Any]]) -> Calibration:
    """The calibration of P(goal) on the planner's chosen actions (each goal it acted on: ``planner_p`` against
    ``planner``), and beside it (``pooled``) over every action of the oracle's set for every goal (``pooled``: P
    and reached per action)."""
    acted = [r for r in records if r["planner_behavior"]]
    pooled_p = np.concatenate([r["pooled"][0] for r in records]) if records else np.zeros(0)
    pooled_y = np.concatenate([r["pooled"][1] for r in records]) if records else np.zeros(0, bool)
    return _calibration([r["planner_p"] for r in acted], [r["planner"] for r in acted],
                        "the planner's chosen actions",
                        _calibration(pooled_p, pooled_y, "every action of the oracle's set, for every goal"))


def summarize(records: Sequence[Mapping[str, Any]], policies: Sequence[str]) -> dict[str, PolicyOutcome]:
    """Per policy, with Wilson intervals: success on every goal, on the feasible goals (those the oracle reached),
    and on the goals the oracle or the planner reached (``success_reached``)."""
    feasible = np.array([r["oracle"] for r in records], dtype=bool)
    either = feasible | np.array([bool(r.get("planner", False)) for r in records], dtype=bool)
    out = {}
    for policy in policies:
        values = np.array([bool(r.get(policy, False)) for r in records], dtype=bool)
        n, k = len(values), int(values.sum())
        nf, kf = int(feasible.sum()), int(values[feasible].sum())
        ne, ke = int(either.sum()), int(values[either].sum())
        out[policy] = PolicyOutcome(
            success=k / n if n else None, success_ci=wilson(k, n), success_feasible=kf / nf if nf else None,
            success_feasible_ci=wilson(kf, nf), n=n, n_feasible=nf, success_reached=ke / ne if ne else None,
            success_reached_ci=wilson(ke, ne), n_reached=ne)
    return out


def within_shares(within: Sequence[Sequence[bool]]) -> tuple[WithinDistance, ...]:
    """Per distance of :data:`~affordance_learning.planning.results.SUCCESS_DISTANCES_M`, the share of the cases
    that ended within it of their target, with its Wilson interval; ``within``: per case, whether it did at each
    distance, in that order."""
    hits = np.asarray(within, dtype=bool).reshape(len(within), len(SUCCESS_DISTANCES_M))
    n = len(hits)
    return tuple(WithinDistance(d, int(k) / n if n else None, wilson(int(k), n), n)
                 for d, k in zip(SUCCESS_DISTANCES_M, hits.sum(axis=0), strict=True))


def seconds_summary(seconds: Sequence[float], choose: DecisionTimes | None = None,
                    toward: DecisionTimes | None = None) -> DecisionTimes:
    """Median, 99th percentile and the most of decision times [s], and their n; None for no decision. ``choose``
    and ``toward``: the same of the single step's and the multi-step's decisions, where ``seconds`` are both."""
    s = np.asarray(seconds, dtype=float)
    if not len(s):
        return DecisionTimes(median=None, p99=None, max=None, n=0, choose=choose, toward=toward)
    return DecisionTimes(median=float(np.median(s)), p99=float(np.quantile(s, 0.99)), max=float(s.max()), n=len(s),
                         choose=choose, toward=toward)
