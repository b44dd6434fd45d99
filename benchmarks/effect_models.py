"""Which learner for the action-conditioned effect models: measured on held-out interactions of a goal-episode
dataset.

Each learner gives, for a query [49 features, 3 parameters], a distribution over training outcomes; P(goal) is the
weighted share of outcomes that reach the goal (roll, lift, move 5 cm in 4 directions, per behaviour). Compared on
the last quarter of each behaviour's interactions (by episode), trained on the rest:

- ``forest``: :class:`affordance_learning.effect_model.ActionEffectModel` (a random forest as a quantile
  regression forest);
- ``extra_trees``: the same with extremely randomised trees;
- ``knn``: the 15 nearest training interactions in standardised inputs, equally weighted.

Prints log-loss, Brier score, ECE and AUROC per learner (lower, lower, lower, higher are better) and fit time.

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
from affordance_learning.effect_model import ActionEffectModel
from affordance_learning.goals import Lift, Move, Roll
from affordance_learning.outcomes import model_inputs, outcome_table
from affordance_learning.plan_experiment import BEHAVIORS, calibration

GOALS = [Roll(), Lift(), *(Move(d, 0.05) for d in ((1, 0), (-1, 0), (0, 1), (0, -1)))]


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
        reached = goal.reached(self.outcomes_).astype(float)
        return reached[index].mean(axis=1)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dataset", help="a goal-episode dataset directory")
    args = parser.parse_args()
    frame = load_dataset(args.dataset).sort_values(["episode", "step"])
    learners = {"forest": lambda: ActionEffectModel(random_state=0), "extra_trees":
                lambda: ActionEffectModel(trees="extra", random_state=0), "knn": lambda: KnnEffectModel()}
    scores = {name: {"p": [], "y": [], "fit": 0.0} for name in learners}
    for behavior in BEHAVIORS:
        rows = frame[frame["behavior"] == behavior]
        split = int(0.75 * len(rows))
        train, test = rows.iloc[:split], rows.iloc[split:]
        X, Y, Xt, Yt = model_inputs(train), outcome_table(train), model_inputs(test), outcome_table(test)
        for name, make in learners.items():
            start = time.perf_counter()
            model = make().fit(X, Y)
            scores[name]["fit"] += time.perf_counter() - start
            for goal in GOALS:
                truth = goal.reached(Yt)
                if 0 < truth.mean() < 1:
                    scores[name]["p"].append(model.goal_probability(Xt, goal))
                    scores[name]["y"].append(truth)
    print(f"{'learner':<12} {'log-loss':>9} {'Brier':>7} {'ECE':>7} {'AUROC':>7} {'fit [s]':>8}")
    for name, s in scores.items():
        p, y = np.concatenate(s["p"]), np.concatenate(s["y"])
        clipped = np.clip(p, 1e-3, 1 - 1e-3)
        print(f"{name:<12} {log_loss(y, clipped):9.3f} {brier_score_loss(y, p):7.3f} "
              f"{calibration(p, y)['ece']:7.3f} {roc_auc_score(y, p):7.3f} {s['fit']:8.1f}")
    print(f"({len(p)} held-out (interaction, goal) pairs over {len(BEHAVIORS)} behaviours and {len(GOALS)} goals)")


if __name__ == "__main__":
    main()
