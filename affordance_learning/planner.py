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

from affordance_env.scene import table_extent
from affordance_learning.behaviors import BEHAVIORS
from affordance_learning.effect_model import ActionEffectModel
from affordance_learning.exceptions import InvalidValueError
from affordance_learning.goals import Goal, Place, check_goal, check_start

#: An outcome that leaves the table counts as this far from any place [m] when actions are ranked by distance.
OFF_TABLE_DISTANCE = 1.0
#: The search over two interactions (:meth:`Planner.toward`): first actions looked at (the nearest on average,
#: and half as many of the most likely), predicted outcomes followed from each, and parameter vectors per
#: behaviour for the second interaction (the first of the planner's candidates).
LOOKAHEAD_ROOTS, LOOKAHEAD_OUTCOMES, LOOKAHEAD_SECOND = 16, 8, 8
#: A first action is chosen for its value over two interactions when that value is at least this.
MIN_SEQUENCE_VALUE = 0.1


def _ends(model: ActionEffectModel, start: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Where each training outcome of ``model`` leaves an object that was at ``start`` [m], and whether it left
    the table."""
    frame = model.outcome_frame()
    return start + frame[["dx", "dy"]].to_numpy(), frame["off_table"].to_numpy(bool)


def _reached_by_any(reachable: Callable[[str, np.ndarray], np.ndarray], names: list[str], xy: np.ndarray
                    ) -> np.ndarray:
    return np.any([np.asarray(reachable(name, xy), dtype=bool) for name in names], axis=0)


def _check_on_table(name: str, value, xy: np.ndarray) -> None:
    (x0, y0), (x1, y1) = table_extent()
    if xy.shape != (2,) or not np.all(np.isfinite(xy)) or not (x0 <= xy[0] <= x1 and y0 <= xy[1] <= y1):
        raise InvalidValueError(f"{name} must be (x, y) [m] on the table top, x in [{x0:.2f}, {x1:.2f}] and y in "
                         f"[{y0:.2f}, {y1:.2f}], got {value!r}.")


def _check_start(start_xy) -> np.ndarray:
    start = check_start(start_xy)
    if start.shape != (2,):
        raise InvalidValueError(f"start_xy must be where the object is, one (x, y) [m], got shape {start.shape}.")
    return start


def candidate_params(n: int, random_state: int = 0) -> np.ndarray:
    """(n, 3) action parameters in [-1, 1]: the canonical action (zeros) and n - 1 points of a scrambled Sobol
    sequence seeded by ``random_state``."""
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
        raise InvalidValueError(f"n must be an integer >= 1, got {n!r}.")
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
        value: For :meth:`Planner.toward`: P(within the tolerance) after this interaction and, where more are
            left, after the best second one (:meth:`Planner.toward`); else NaN.
    """

    behavior: str | None
    params: np.ndarray
    probability: float
    abstained: bool
    expected_distance: float = float("nan")
    checked: int = 0
    value: float = float("nan")


class Planner:
    """Chooses the behaviour and parameters that maximise P(goal).

    Args:
        models: A fitted :class:`~affordance_learning.effect_model.ActionEffectModel` per behaviour name (one of
            :data:`affordance_learning.behaviors.BEHAVIORS`), each of the same inputs: the object's features (the
            49 of ``affordance_env.FEATURE_NAMES``) and the 3 action parameters.
        n_candidates: Parameter vectors scored per behaviour.
        threshold: Abstain below this P(goal).
        random_state: Seed of the candidates.

    Every method checks its inputs before any work: ``features`` must have as many values as the models take
    (ValueError), the goal must be a goal of :mod:`affordance_learning.goals` (TypeError), a
    :class:`~affordance_learning.goals.Place` needs ``start_xy`` and :meth:`toward` a target on the table top
    (ValueError).
    """

    def __init__(self, models: Mapping[str, ActionEffectModel], n_candidates: int = 64, threshold: float = 0.5,
                 random_state: int = 0) -> None:
        if not models:
            raise InvalidValueError("models must map at least one behaviour name to its fitted ActionEffectModel.")
        if not (isinstance(threshold, int | float) and 0.0 <= threshold <= 1.0):
            raise InvalidValueError(f"threshold must be a probability in [0, 1], got {threshold!r}.")
        unknown = [name for name in models if name not in BEHAVIORS]
        if unknown:
            raise InvalidValueError(f"Unknown behavior(s) {', '.join(map(repr, unknown))} in models. Valid behaviors: "
                             f"{', '.join(BEHAVIORS)}.")
        for name, model in models.items():
            if not isinstance(model, ActionEffectModel) or not hasattr(model, "forest_"):
                raise TypeError(f"models[{name!r}] must be a fitted ActionEffectModel, got {type(model).__name__}.")
        inputs = {name: model.n_features_in_ for name, model in models.items()}
        if len(set(inputs.values())) > 1:
            raise InvalidValueError(f"the models must take the same inputs, got {inputs} input columns per behaviour.")
        self.models = dict(models)
        self.threshold = float(threshold)
        self.params = candidate_params(n_candidates, random_state)
        #: How many feature values each method's ``features`` must have: the models' inputs but the parameters.
        self.n_features = next(iter(inputs.values())) - self.params.shape[1]

    def _inputs(self, features: np.ndarray) -> np.ndarray:
        x = np.asarray(features, dtype=np.float64)
        if x.size != self.n_features or x.ndim > 2:
            named = " (affordance_env.FEATURE_NAMES)" if self.n_features == 49 else ""
            raise InvalidValueError(
                f"features must be the object's {self.n_features} feature values{named}, the models' "
                             f"inputs but the {self.params.shape[1]} action parameters; got shape {x.shape}.")
        x = x.ravel()
        if not np.all(np.isfinite(x)):
            raise InvalidValueError("features must be finite (the object must have been seen).")
        return np.hstack([np.repeat(x[None], len(self.params), axis=0), self.params])

    def scores(self, features: np.ndarray, goal: Goal, start_xy=None) -> dict[str, np.ndarray]:
        """P(goal) of every candidate, per behaviour: {behaviour: (n_candidates,)}."""
        check_goal(goal)
        if isinstance(goal, Place):
            _check_start(start_xy)
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
               feasible: Callable[[str, np.ndarray], bool] | None = None, steps_left: int = 1,
               reachable: Callable[[str, np.ndarray], np.ndarray] | None = None) -> Choice:
        """The next interaction towards ``target_xy`` [m], a place on the table top (:func:`table_extent`; another
        is a ValueError), re-planned after every interaction.

        With ``steps_left`` 1 (this interaction is the last): the feasible action most likely to end within
        ``tolerance``, if that is at least the threshold, else the one whose predicted outcomes end nearest on
        average. With 2 or more, a search over sequences of two interactions: an action's value is its
        P(within) plus the share of its predicted outcomes that neither end within nor leave the table times the
        best P(within) of a second interaction from there, averaged over the most likely of those outcomes (the
        object where the outcome leaves it, seen with the initial features plus the outcome's perceptual
        effect). An action likely enough to end within is taken at once; else the most valuable one, if its value
        reaches ``MIN_SEQUENCE_VALUE``; else the nearest.

        Args:
            reachable: ``reachable(behavior, xy)``, (n, 2) [m] -> (n,) bool: where a behaviour can act (for
                example :func:`affordance_env.workspace.in_workspace`). A second interaction counts only where its
                behaviour reaches, and outcomes that leave the object where no behaviour reaches count as
                ``OFF_TABLE_DISTANCE`` away when actions are ranked by distance. None: everywhere.
        """
        if isinstance(steps_left, bool) or not isinstance(steps_left, int | np.integer) or steps_left < 1:
            raise InvalidValueError(f"steps_left must be an integer >= 1, got {steps_left!r}.")
        goal = Place(target_xy, tolerance)
        target = np.asarray(goal.target_xy)
        _check_on_table("target_xy", target_xy, target)
        start = _check_start(start_xy)
        X = self._inputs(features)
        features = X[0, : self.n_features]
        names = list(self.models)
        weights, p1, distance, ends = {}, {}, {}, {}
        for name, model in self.models.items():
            W = model.predictive_weights(X, as_sparse=True)
            W.sum_duplicates()
            end, off = _ends(model, start)
            within = goal.reached(model.outcome_frame(), start).astype(np.float64)
            dist = np.where(off, OFF_TABLE_DISTANCE, np.linalg.norm(end - target, axis=1))
            if reachable is not None:
                stuck = ~_reached_by_any(reachable, names, end) & (within == 0)
                dist = np.where(stuck, OFF_TABLE_DISTANCE, dist)
            weights[name], ends[name] = W, (end, off, within)
            p1[name], distance[name] = W @ within, W @ dist
        value = {name: p1[name].copy() for name in names}
        if steps_left >= 2:
            self._look_ahead(features, goal, weights, ends, p1, distance, value, reachable)
        entries = [(float(value[n][k]), float(p1[n][k]), float(distance[n][k]), n, k)
                   for n in names for k in range(len(self.params))]
        finish = sorted((e for e in entries if e[1] >= self.threshold), key=lambda e: (-e[1], e[2], e[3], e[4]))
        sequence = sorted((e for e in entries if e[0] >= MIN_SEQUENCE_VALUE), key=lambda e: (-e[0], e[2], e[3], e[4]))
        nearest = sorted(entries, key=lambda e: (e[2], -e[0], e[3], e[4]))
        checked = 0
        for ranked in (finish, sequence, nearest):
            for v, p, d, name, k in ranked:
                checked += feasible is not None
                if feasible is None or feasible(name, self.params[k]):
                    return Choice(name, self.params[k].copy(), p, p < self.threshold, d, checked, v)
        return Choice(None, np.zeros(3), 0.0, True, float("nan"), checked, 0.0)

    def _look_ahead(self, features, goal, weights, ends, p1, distance, value, reachable) -> None:
        """Add to ``value`` (P(within) of each first action) the chance of a second interaction (see
        :meth:`toward`), over the ``LOOKAHEAD_ROOTS`` first actions nearest on average and most likely, their
        ``LOOKAHEAD_OUTCOMES`` most likely outcomes each, and ``LOOKAHEAD_SECOND`` parameter vectors per
        behaviour for the second."""
        names = list(self.models)
        flat = [(n, k) for n in names for k in range(len(self.params))]
        p_all = np.concatenate([p1[n] for n in names])
        d_all = np.concatenate([distance[n] for n in names])
        roots = list(dict.fromkeys([flat[i] for i in np.argsort(d_all, kind="stable")[:LOOKAHEAD_ROOTS]]
                                   + [flat[i] for i in np.argsort(-p_all, kind="stable")[:LOOKAHEAD_ROOTS // 2]]))
        # The distinct outcomes (behaviour, training row) the roots lead to, and each root's share of them.
        states: dict[tuple[str, int], int] = {}
        # Per root: the mass of its outcomes that leave something to do (neither within nor off the table), and
        # the most likely of them with their weights: a sample of where the second interaction starts.
        links: list[tuple[str, int, float, list[tuple[int, float]]]] = []
        for name, k in roots:
            row = weights[name].getrow(k)
            end, off, within = ends[name]
            open_ = ~within[row.indices].astype(bool) & ~off[row.indices]
            if not open_.any():
                continue
            indices, data = row.indices[open_], row.data[open_]
            top = np.argsort(-data, kind="stable")[:LOOKAHEAD_OUTCOMES]
            followed = [(states.setdefault((name, int(j)), len(states)), float(w))
                        for j, w in zip(indices[top], data[top], strict=True)]
            links.append((name, k, float(data.sum()), followed))
        if not states:
            return
        keys = list(states)
        for name in {n for n, _ in keys}:
            if len(self.models[name].effect_columns_) != len(features):
                raise InvalidValueError(
                    f"the model of {name!r} has {len(self.models[name].effect_columns_)} effect columns "
                                 f"for {len(features)} features: looking ahead needs models fitted on outcome tables "
                                 "with the perceptual effect (affordance_learning.outcomes.outcome_table).")
        xy = np.array([ends[n][0][j] for n, j in keys])
        seen = np.array([features + self.models[n].outcomes_[j, self.models[n].effect_columns_] for n, j in keys])
        second = self.params[: LOOKAHEAD_SECOND]
        best = np.zeros(len(keys))
        for name, model in self.models.items():
            X2 = np.hstack([np.repeat(seen, len(second), axis=0), np.tile(second, (len(keys), 1))])
            W2 = model.predictive_weights(X2, as_sparse=True)
            end2, off2 = _ends(model, np.zeros(2))  # displacements; each state adds its own start below
            hits = (np.linalg.norm(xy[:, None, :] + end2[None] - np.asarray(goal.target_xy), axis=2)
                    <= goal.tolerance) & ~off2[None]
            query = np.repeat(np.arange(W2.shape[0]), np.diff(W2.indptr))
            p2 = np.bincount(query, weights=W2.data * hits[query // len(second), W2.indices], minlength=W2.shape[0])
            p2 = p2.reshape(len(keys), len(second)).max(axis=1)
            if reachable is not None:
                p2 = p2 * np.asarray(reachable(name, xy), dtype=bool)
            best = np.maximum(best, p2)
        for name, k, mass, followed in links:  # the followed outcomes stand for all that leave something to do
            value[name][k] += mass * sum(w * best[state] for state, w in followed) / sum(w for _, w in followed)

