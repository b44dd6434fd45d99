"""Which learner for the action-conditioned effect models: measured on held-out interactions of a goal-episode
dataset.

Each learner gives, for a query [49 features, 3 parameters], a distribution over training outcomes; P(goal) is the
weighted share of outcomes that reach the goal (roll, lift, move 5 cm in 4 directions, and, per held-out
interaction, 2 places 5-15 cm from where the object was, 3 cm tolerance, as ``affordance plan`` draws them).
Compared on the last quarter of each behaviour's interactions (by episode), trained on the rest:

- ``forest``: :class:`affordance_learning.planning.effect_model.ActionEffectModel` as ``affordance plan`` fits it
  (:func:`~affordance_learning.planning.effect_model.behavior_model`:
   a random forest as a quantile regression forest; each
  neighbour's displacement moved to the query's action along the local slopes; the grasp's flags weighing 5 times
  a displacement in the splits, the others' twice);
- ``forest_flags_2``: the same with every behaviour's flags weighing twice a displacement;
- ``forest_as_were``: the same forest with the neighbours' displacements as they were and the flags weighing as
  much as a displacement in the splits (``action_inputs=0, flag_weight=1``: the model before the local slopes);
- ``extra_trees``: the forest with extremely randomised trees;
- ``knn``: the 15 nearest training interactions in standardised inputs, equally weighted.

Prints log-loss, Brier score, ECE and AUROC per learner (lower, lower, lower, higher are better) over every goal
and over the place goals alone, and fit time.

    python benchmarks/effect_models.py DATASET   # e.g. OUT/dataset of `affordance plan`
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from sklearn.metrics import brier_score_loss, log_loss, roc_auc_score
from sklearn.neighbors import NearestNeighbors
from sklearn.preprocessing import StandardScaler

from affordance_env import load_dataset
from affordance_env.registry import BEHAVIOR_NAMES
from affordance_learning.planning.effect_model import FLAG_WEIGHT, ActionEffectModel, behavior_model
from affordance_learning.planning.experiment import calibration
from affordance_learning.planning.goals import Lift, Move, Place, Roll
from affordance_learning.planning.outcomes import model_inputs, outcome_table

GOALS = [Roll(), Lift(), *(Move(d, 0.05) for d in ((1, 0), (-1, 0), (0, 1), (0, -1)))]
#: Place goals per held-out interaction, their distance from where the object was [m] and tolerance [m].
PLACES, PLACE_DISTANCE, PLACE_TOLERANCE = 2, (0.05, 0.15), 0.03
#: Where the places are, on the table (x, y) [m]: only the offset from the object's start matters.
PLACE_AT = (-0.46, 0.0)


class KnnEffectModel:
    def __init__(self, k: int = 15) -> None:
        self.k = k

    def fit(self, X, y):
        self.scaler_ = StandardScaler().fit(X)
        self.nn_ = NearestNeighbors(n_neighbors=self.k).fit(self.scaler_.transform(X))
        self.outcomes_ = y.reset_index(drop=True)
        return self

    def goal_probability(self, X, goal, start_xy=None):
        _, index = self.nn_.kneighbors(self.scaler_.transform(X))
        if start_xy is None:
            return goal.reached(self.outcomes_).astype(float)[index].mean(axis=1)
        start = np.repeat(np.asarray(start_xy, dtype=float), index.shape[1], axis=0)  # one start per query
        neighbours = self.outcomes_.iloc[index.ravel()].reset_index(drop=True)
        return goal.reached(neighbours, start).astype(float).reshape(index.shape).mean(axis=1)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dataset", help="a goal-episode dataset directory")
    args = parser.parse_args()
    frame = load_dataset(args.dataset).sort_values(["episode", "step"])
    learners = {"forest": lambda b: behavior_model(b, random_state=0),
                "forest_flags_2": lambda b: ActionEffectModel(flag_weight=FLAG_WEIGHT, random_state=0),
                "forest_as_were": lambda b: ActionEffectModel(action_inputs=0, flag_weight=1.0, random_state=0),
                "extra_trees": lambda b: behavior_model(b, trees="extra", random_state=0),
                "knn": lambda b: KnnEffectModel()}
    scores = {name: {"p": [], "y": [], "place_p": [], "place_y": [], "fit": 0.0} for name in learners}
    rng = np.random.default_rng(0)
    for behavior in BEHAVIOR_NAMES:
        rows = frame[frame["behavior"] == behavior]
        split = int(0.75 * len(rows))
        train, test = rows.iloc[:split], rows.iloc[split:]
        X, Y, Xt, Yt = model_inputs(train), outcome_table(train), model_inputs(test), outcome_table(test)
        # Places relative to where each object was: a place on the table seen from it minus the target's offset
        angle = rng.uniform(-np.pi, np.pi, (PLACES, len(Yt)))
        offsets = rng.uniform(*PLACE_DISTANCE, (PLACES, len(Yt)))[..., None] * np.stack([np.cos(angle),
                                                                                          np.sin(angle)], -1)
        place = Place(PLACE_AT, PLACE_TOLERANCE)
        for name, make in learners.items():
            start = time.perf_counter()
            model = make(behavior).fit(X, Y)
            scores[name]["fit"] += time.perf_counter() - start
            for goal in GOALS:
                truth = goal.reached(Yt)
                if 0 < truth.mean() < 1:
                    scores[name]["p"].append(model.goal_probability(Xt, goal))
                    scores[name]["y"].append(truth)
            for offset in offsets:
                for key in ("", "place_"):
                    scores[name][f"{key}p"].append(model.goal_probability(Xt, place, PLACE_AT - offset))
                    scores[name][f"{key}y"].append(place.reached(Yt, PLACE_AT - offset))
    print(f"{'learner':<15} {'goals':<6} {'log-loss':>9} {'Brier':>7} {'ECE':>7} {'AUROC':>7} {'fit [s]':>8}")
    for name, s in scores.items():
        for key, goals in (("", "all"), ("place_", "place")):
            p, y = np.concatenate(s[f"{key}p"]), np.concatenate(s[f"{key}y"])
            clipped = np.clip(p, 1e-3, 1 - 1e-3)
            print(f"{name:<15} {goals:<6} {log_loss(y, clipped):9.3f} {brier_score_loss(y, p):7.3f} "
                  f"{calibration(p, y)['ece']:7.3f} {roc_auc_score(y, p):7.3f} {s['fit']:8.1f}")
        if name == "forest":
            n_all, n_place = len(np.concatenate(s["p"])), len(p)
    print(f"({n_all} held-out (interaction, goal) pairs over {len(BEHAVIOR_NAMES)} behaviours, {len(GOALS)} goals and "
          f"{PLACES} places per interaction, {n_place} of them places)")


if __name__ == "__main__":
    main()
