"""Choosing what to do: the behaviour and its parameters that make a goal most likely, from the effect models.

:class:`Planner` scores candidate actions, every behaviour with ``n_candidates`` parameter vectors (the canonical
action and a scrambled Sobol sequence over [-1, 1]^3), by P(goal) under each behaviour's
:class:`~affordance_learning.effect_model.ActionEffectModel`, and takes the most likely one that the arm can
reach (``feasible``, asked from the most likely down, so that the kinematics is asked a few times, not for every
candidate). Below ``threshold`` it abstains. :meth:`Planner.toward` chooses the next interaction of a multi-step
episode towards a place on the table: the action most likely to end within the tolerance, or, when none is
likely enough, the one whose predicted outcomes end nearest on average (re-planned after every interaction).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np
from scipy.stats import qmc

from affordance_learning.effect_model import ActionEffectModel
from affordance_learning.goals import Goal, Place

#: An outcome that leaves the table counts as this far from any place [m] when actions are ranked by distance.
OFF_TABLE_DISTANCE = 1.0


def candidate_params(n: int, random_state: int = 0) -> np.ndarray:
    """(n, 3) action parameters in [-1, 1]: the canonical action (zeros) and n - 1 points of a scrambled Sobol
    sequence seeded by ``random_state``."""
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
        raise ValueError(f"n must be an integer >= 1, got {n!r}.")
    power = int(np.ceil(np.log2(max(2, n - 1))))  # Sobol's balance holds for powers of 2: the first n - 1 of them
    sobol = qmc.Sobol(3, scramble=True, seed=random_state).random_base2(power)[: n - 1]
    return np.vstack([np.zeros((1, 3)), 2.0 * sobol - 1.0])


@dataclass(frozen=True)
class Choice:
    """A planner's decision.

    Attributes:
        behavior: The behaviour chosen (None when it abstained and nothing was feasible).
        params: Its parameters, (3,).
        probability: P(goal) of the choice under the model (for :meth:`Planner.toward` when no action is likely
            to reach the place: still P(within tolerance)).
        abstained: P(goal) was below the threshold.
        expected_distance: For :meth:`Planner.toward`: the mean predicted distance to the place [m]; else NaN.
        checked: How many candidates the kinematics was asked about.
    """

    behavior: str | None
    params: np.ndarray
    probability: float
    abstained: bool
    expected_distance: float = float("nan")
    checked: int = 0


class Planner:
    """Chooses the behaviour and parameters that maximise P(goal).

    Args:
        models: An :class:`~affordance_learning.effect_model.ActionEffectModel` per behaviour name.
        n_candidates: Parameter vectors scored per behaviour.
        threshold: Abstain below this P(goal).
        random_state: Seed of the candidates.
    """

    def __init__(self, models: Mapping[str, ActionEffectModel], n_candidates: int = 64, threshold: float = 0.5,
                 random_state: int = 0) -> None:
        if not models:
            raise ValueError("models must map at least one behaviour name to its fitted ActionEffectModel.")
        if not (isinstance(threshold, int | float) and 0.0 <= threshold <= 1.0):
            raise ValueError(f"threshold must be a probability in [0, 1], got {threshold!r}.")
        self.models = dict(models)
        self.threshold = float(threshold)
        self.params = candidate_params(n_candidates, random_state)

    def _inputs(self, features: np.ndarray) -> np.ndarray:
        x = np.asarray(features, dtype=np.float64).ravel()
        if not np.all(np.isfinite(x)):
            raise ValueError("features must be finite (the object must have been seen).")
        return np.hstack([np.repeat(x[None], len(self.params), axis=0), self.params])

    def scores(self, features: np.ndarray, goal: Goal, start_xy=None) -> dict[str, np.ndarray]:
        """P(goal) of every candidate, per behaviour: {behaviour: (n_candidates,)}."""
        X = self._inputs(features)
        return {name: model.goal_probability(X, goal, start_xy) for name, model in self.models.items()}

    def _first_feasible(self, ranked: list[tuple[float, str, int]], feasible: Callable[[str, np.ndarray], bool] | None
                        ) -> tuple[tuple[float, str, int] | None, int]:
        checked = 0
        for entry in ranked:
            if feasible is None:
                return entry, checked
            checked += 1
            if feasible(entry[1], self.params[entry[2]]):
                return entry, checked
        return None, checked

    def choose(self, features: np.ndarray, goal: Goal, start_xy=None,
               feasible: Callable[[str, np.ndarray], bool] | None = None) -> Choice:
        """The most likely feasible action for ``goal`` on the object seen with ``features`` at ``start_xy``."""
        scores = self.scores(features, goal, start_xy)
        ranked = sorted(((float(p), name, k) for name, ps in scores.items() for k, p in enumerate(ps)),
                        key=lambda e: (-e[0], e[1], e[2]))
        best, checked = self._first_feasible(ranked, feasible)
        if best is None:
            return Choice(None, np.zeros(3), 0.0, True, checked=checked)
        p, name, k = best
        return Choice(name, self.params[k].copy(), p, p < self.threshold, checked=checked)

    def toward(self, features: np.ndarray, start_xy, target_xy, tolerance: float,
               feasible: Callable[[str, np.ndarray], bool] | None = None) -> Choice:
        """The next interaction towards ``target_xy`` [m]: the feasible action most likely to end within
        ``tolerance`` if that is at least the threshold, else the one with the smallest mean predicted distance."""
        goal = Place(tuple(target_xy), tolerance)
        X = self._inputs(features)
        start = np.asarray(start_xy, dtype=np.float64)
        target = np.asarray(target_xy, dtype=np.float64)
        entries = []
        for name, model in self.models.items():
            weights = model.predictive_weights(X)
            outcomes = model.outcome_frame()
            end = start + outcomes[["dx", "dy"]].to_numpy()
            distance = np.where(outcomes["off_table"].to_numpy(bool), OFF_TABLE_DISTANCE,
                                np.linalg.norm(end - target, axis=1))
            within = goal.reached(outcomes, start).astype(np.float64)
            for k, (p, d) in enumerate(zip(weights @ within, weights @ distance, strict=True)):
                entries.append((float(p), float(d), name, k))
        likely = sorted((e for e in entries if e[0] >= self.threshold), key=lambda e: (-e[0], e[1], e[2], e[3]))
        nearest = sorted(entries, key=lambda e: (e[1], -e[0], e[2], e[3]))
        checked = 0
        for ranked in (likely, nearest):
            for p, d, name, k in ranked:
                checked += feasible is not None
                if feasible is None or feasible(name, self.params[k]):
                    return Choice(name, self.params[k].copy(), p, p < self.threshold, d, checked)
        return Choice(None, np.zeros(3), 0.0, True, float("nan"), checked)
