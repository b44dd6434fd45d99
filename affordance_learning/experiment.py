"""The paper's experiment on a dataset of interactions: uniformity, selected features, SVM accuracy.

:func:`run_protocol` takes a DataFrame with, for each feature name, columns ``initial_<name>`` and
``effect_<name>``, and the ground truth ``rolled`` (the paper's success label), ``type`` and ``size`` (used only
to evaluate, never to learn). For every trial and every number of clusters k it

1. clusters the standardised effects of all interactions with a 1 x k self-organising map and measures the
   uniformity of the clusters against ``rolled`` (and their purity and adjusted Rand index against ``type``);
2. splits the interactions at random into 70 % training and 30 % test rows (a new split per trial);
3. weighs the initial features by ReliefF on the training rows against their clusters (once per trial and k:
   the weights do not depend on the relevancy threshold);
4. for every relevancy threshold r keeps the features above r x the largest weight, records how many there
   are and which share of them are shape features, trains the SVM on the training rows and measures its
   accuracy on the test rows (and the accuracy of always answering the most common training cluster).

Trials run in parallel with joblib; each draws its seeds from ``(random_state, trial)`` only, so the results
do not depend on ``n_jobs``.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from joblib import Parallel, delayed
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler
from sklearn.svm import SVC

from affordance_learning.metrics import adjusted_rand, cluster_purity, uniformity
from affordance_learning.relieff import relieff_weights
from affordance_learning.som import SOMClustering

KS = tuple(range(2, 11))
RELEVANCIES = (0.0, 0.2, 0.4, 0.6, 0.8)
CASE_STUDY_KS = (2, 4)
TEST_SHARE = 0.3


def feature_columns(frame: pd.DataFrame) -> tuple[list[str], list[str], list[str]]:
    """Feature names, and the ``initial_`` and ``effect_`` columns of ``frame`` (in the same order)."""
    from affordance_env.features import FEATURE_NAMES

    names = [n for n in FEATURE_NAMES if f"initial_{n}" in frame.columns]
    missing = [f"effect_{n}" for n in names if f"effect_{n}" not in frame.columns]
    if not names or missing:
        raise ValueError(
            "the dataset needs initial_<name> and effect_<name> columns for every feature; "
            + (f"missing {missing[:5]}" if names else "found no initial_ columns")
        )
    for column in ("rolled", "type", "size"):
        if column not in frame.columns:
            raise ValueError(f"the dataset has no {column!r} column (ground truth used to evaluate the clusters).")
    return names, [f"initial_{n}" for n in names], [f"effect_{n}" for n in names]


def feature_groups(names: list[str]) -> list[str]:
    """Group (shape, size or relation) of every feature name, from ``affordance_env.FEATURE_GROUPS``."""
    from affordance_env.features import FEATURE_GROUPS

    unknown = [n for n in names if n not in FEATURE_GROUPS]
    if unknown:
        raise ValueError(f"unknown feature names {unknown[:5]}; expected names of affordance_env.FEATURE_NAMES.")
    return [FEATURE_GROUPS[n] for n in names]


def _trial(X, Z, rolled, types, sizes, shape, ks, relevancies, seed, n_neighbors, som_iterations, case_studies):
    rng = np.random.default_rng(seed)
    n = len(X)
    order = rng.permutation(n)
    n_test = max(1, int(round(TEST_SHARE * n)))
    test, train = order[:n_test], order[n_test:]
    out = {"uniformity": {}, "purity": {}, "ari": {}, "svm": {}, "baseline": {}, "shape": {}, "count": {},
           "cases": {}}
    for k in ks:
        som_seed = int(rng.integers(2**31 - 1))
        labels = SOMClustering(k, n_iterations=som_iterations, random_state=som_seed).fit(Z).labels_
        out["uniformity"][k] = uniformity(labels, rolled)
        out["purity"][k] = cluster_purity(labels, types)
        out["ari"][k] = adjusted_rand(labels, types)
        if k in case_studies:
            out["cases"][k] = [
                {
                    "cluster": int(c),
                    "rolled": int(np.sum(rolled[labels == c])),
                    "not_rolled": int(np.sum(~rolled[labels == c])),
                    "types": {str(t): int(v) for t, v in zip(*np.unique(types[labels == c], return_counts=True),
                                                            strict=True)},
                    "sizes": [round(float(s), 5) for s in sizes[labels == c]],
                }
                for c in range(k)
            ]
        y_train, y_test = labels[train], labels[test]
        classes, counts = np.unique(y_train, return_counts=True)
        out["baseline"][k] = float(np.mean(y_test == classes[np.argmax(counts)]))
        weights = (
            relieff_weights(X[train], y_train, n_neighbors=n_neighbors) if len(classes) >= 2 else np.zeros(X.shape[1])
        )
        best = int(np.argmax(weights))
        for r in relevancies:
            top = weights[best]
            chosen = np.union1d(np.flatnonzero(weights > r * top) if top > 0 else [], [best]).astype(int)
            out["count"][(r, k)] = len(chosen)
            out["shape"][(r, k)] = float(np.mean(shape[chosen]))
            if len(classes) >= 2:
                svm = make_pipeline(StandardScaler(), SVC(C=10.0, gamma="scale"))
                svm.fit(X[train][:, chosen], y_train)
                out["svm"][(r, k)] = float(np.mean(svm.predict(X[test][:, chosen]) == y_test))
            else:
                out["svm"][(r, k)] = out["baseline"][k]
    return out


def _stats(values) -> dict[str, float]:
    values = np.asarray(values, dtype=float)
    return {"mean": float(values.mean()), "std": float(values.std())}


def run_protocol(
    frame: pd.DataFrame,
    ks=KS,
    relevancies=RELEVANCIES,
    n_trials: int = 20,
    random_state: int = 0,
    n_jobs: int = 1,
    n_neighbors: int = 10,
    som_iterations: int = 2000,
) -> dict:
    """Run the paper's protocol on ``frame``; returns the results dict (JSON-ready).

    Schema: ``{"uniformity": {"<k>": {"mean", "std"}}, "svm_accuracy": {"<r>": {"<k>": {"mean", "std"}}},
    "shape_fraction": {...same...}, "n_selected": {...same...}, "case_studies": {"<k>": [{"cluster", "rolled",
    "not_rolled", "types": {type: count}, "sizes": [...]}]}, "purity": {"<k>": ...}, "adjusted_rand":
    {"<k>": ...}, "svm_majority_baseline": {"<k>": ...}, "config": {...}}``, with r written as ``"0.0"`` ... and
    k as ``"2"`` .... Case studies come from the first trial.
    """
    names, initial, effect = feature_columns(frame)
    ks = [int(k) for k in ks]
    relevancies = [float(r) for r in relevancies]
    if not ks or min(ks) < 1:
        raise ValueError(f"ks must be cluster counts >= 1, got {ks!r}.")
    if any(not 0.0 <= r <= 1.0 for r in relevancies):
        raise ValueError(f"relevancies must lie in [0, 1], got {relevancies!r}.")
    if not isinstance(n_trials, int) or n_trials < 1:
        raise ValueError(f"n_trials must be a positive integer, got {n_trials!r}.")
    if len(frame) < 10:
        raise ValueError(f"the protocol needs at least 10 interactions, got {len(frame)}.")
    X = frame[initial].to_numpy(np.float64)
    E = frame[effect].to_numpy(np.float64)
    if not (np.all(np.isfinite(X)) and np.all(np.isfinite(E))):
        raise ValueError("the dataset's initial and effect features must be finite (found NaN or inf).")
    Z = StandardScaler().fit_transform(E)
    rolled = frame["rolled"].to_numpy(bool)
    types = frame["type"].astype(str).to_numpy()
    sizes = frame["size"].to_numpy(np.float64)
    shape = np.array([g == "shape" for g in feature_groups(names)])
    seeds = [np.random.SeedSequence([random_state, t]).generate_state(1)[0] for t in range(n_trials)]
    trials = Parallel(n_jobs=n_jobs)(
        delayed(_trial)(X, Z, rolled, types, sizes, shape, ks, relevancies, int(seed), n_neighbors, som_iterations,
                        CASE_STUDY_KS if t == 0 else ())
        for t, seed in enumerate(seeds)
    )

    def per_k(key):
        return {str(k): _stats([t[key][k] for t in trials]) for k in ks}

    def per_rk(key):
        return {f"{r:.1f}": {str(k): _stats([t[key][(r, k)] for t in trials]) for k in ks} for r in relevancies}

    return {
        "uniformity": per_k("uniformity"),
        "svm_accuracy": per_rk("svm"),
        "shape_fraction": per_rk("shape"),
        "n_selected": per_rk("count"),
        "case_studies": {str(k): v for k, v in trials[0]["cases"].items()},
        "purity": per_k("purity"),
        "adjusted_rand": per_k("ari"),
        "svm_majority_baseline": per_k("baseline"),
        "config": {
            "n_interactions": int(len(frame)),
            "n_features": len(names),
            "ks": ks,
            "relevancies": relevancies,
            "n_trials": n_trials,
            "random_state": random_state,
            "n_neighbors": n_neighbors,
            "som_iterations": som_iterations,
            "test_share": TEST_SHARE,
            "rolled_share": float(rolled.mean()),
            "type_counts": {str(t): int(c) for t, c in zip(*np.unique(types, return_counts=True), strict=True)},
        },
    }
