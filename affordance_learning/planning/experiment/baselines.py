"""The baselines the planner is measured against, beside the random policy and the oracle: the planner with a
fixed grid of candidates instead of its search, the paper's effect categories as a planner, the best fixed
behaviour per goal kind, and a direction heuristic.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from affordance_env.dataset import learning_data
from affordance_env.registry import BEHAVIOR_NAMES
from affordance_learning.paper.model import AffordanceModel
from affordance_learning.planning.experiment.settings import GOAL_KINDS
from affordance_learning.planning.goals import Goal
from affordance_learning.planning.outcomes import outcome_table
from affordance_learning.planning.planner import Planner

#: Candidates of the grid planner set beside the search (:func:`grid_planner`): as many as take the search's time.
#: Five runs of ``benchmarks/planner.py`` (seeds 0-2, 24-72 place goals, the shipped models, one thread, on a
#: machine others shared) found the search's median decision to take as long as a grid of 87, 93, 96, 103 and 112
#: candidates: 96, their median.
GRID_CANDIDATES = 96


def grid_planner(planner: Planner) -> Planner:
    """``planner``'s models and settings with the fixed candidates (``optimizer="grid"``, :data:`GRID_CANDIDATES`
    of them, refined around the best) instead of the search: the choice of parameters the search replaced, at
    equal time."""
    return Planner(planner.models, n_candidates=GRID_CANDIDATES, threshold=planner.threshold,
                   random_state=planner.random_state, max_checks=planner.max_checks, table=planner.table,
                   optimizer="grid")


@dataclass
class SomBaseline:
    """The paper's categories as a planner: per behaviour, its fitted AffordanceModel and the training outcomes
    with their categories."""

    models: dict[str, Any]
    outcomes: dict[str, pd.DataFrame]
    labels: dict[str, np.ndarray]

    @classmethod
    def fit(cls, frames: Mapping[str, pd.DataFrame], n_clusters: int, random_state: int) -> SomBaseline:
        models, outcomes, labels = {}, {}, {}
        for b, f in frames.items():
            X, E, _ = learning_data(f, b)
            models[b] = AffordanceModel(n_clusters=n_clusters, relevancy=0.4, random_state=random_state).fit(X, E)
            outcomes[b], labels[b] = outcome_table(f), models[b].labels_
        return cls(models, outcomes, labels)

    def choose(self, features: np.ndarray, goal: Goal, start_xy: np.ndarray) -> tuple[str, float]:
        """The behaviour whose predicted category reached ``goal`` most often in training, and that share."""
        best = (next(iter(self.models)), -1.0)
        for b, model in self.models.items():
            x = pd.DataFrame(np.asarray(features, dtype=np.float64)[None], columns=model.feature_names_in_)
            category = int(model.predict(x)[0])
            members = self.labels[b] == category
            if not members.any():
                continue
            share = float(goal.reached(self.outcomes[b][members], start_xy).mean())
            if share > best[1]:
                best = (b, share)
        return best


def best_fixed(records: list[dict[str, Any]]) -> dict[str, str]:
    """Per goal kind, the behaviour whose canonical action reached it most often; sets ``best_fixed`` in each
    record."""
    choice = {}
    for kind in GOAL_KINDS:
        rows = [r for r in records if r["kind"] == kind]
        if rows:
            choice[kind] = max(BEHAVIOR_NAMES, key=lambda b: sum(r["canonical"][b] for r in rows))
    for r in records:
        r["best_fixed"] = r["canonical"][choice[r["kind"]]]
    return choice


def direction_heuristic(start: np.ndarray, target: np.ndarray) -> str:
    """The behaviour that moves an object the way the target lies: push away (-x), draw toward the robot (+x)
    where the env has it, tap to -y, tap back to +y."""
    d = target - start
    if -d[0] > abs(d[1]) and "push" in BEHAVIOR_NAMES:
        return "push"
    if d[0] > abs(d[1]) and "draw" in BEHAVIOR_NAMES:
        return "draw"
    return "tap" if d[1] < 0 else "tap_back"
