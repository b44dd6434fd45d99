"""The paper's protocol on a dataset of interactions: uniformity, selected features, SVM accuracy.

Akgun et al. 2009, section V, on a pandas DataFrame in the project's dataset schema: for each feature name
(``affordance_env.features.FEATURE_NAMES``) the columns ``initial_<name>``, ``final_<name>`` and
``effect_<name>``, the ``behavior`` and the ground truth ``type`` (sphere | box | horizontal_cylinder |
vertical_cylinder), ``size`` [m], ``success`` (bool, the paper's success/fail label of the behaviour, here
measured by the simulator: the tap rolled the object, the grasp lifted and held it, ...; a tap or tap_back frame
without it is evaluated against ``rolled``, their success) and ``displacement`` [m]. The ground truth is used
only to evaluate, never to learn. One frame holds one behaviour's interactions: the paper learns "a separate SOM
and SVM for each behavior".
:func:`run_protocol` repeats, for every trial t and every number of clusters k:

1. A 1 x k self-organising map, seeded from ``(random_state, t, k)``, clusters the standardised effects of
   all interactions (the categories are the robot's, over all its experience). Measured against the ground
   truth: uniformity against ``success`` (the paper's metric), purity and adjusted Rand index against
   ``type``.
2. The interactions are split once per trial into training and test rows (``test_size``, 30 % by default),
   stratified by object type and seeded from ``(random_state, t)``; every k and r of a trial use the same
   split, so differences across k and r are not split noise. (Stratifying by cluster is not possible for
   every k: a 1 x 10 map can leave a cluster with a single member.) A frame too small to stratify (a type
   with a single row) gets a plain random split, and ``config["split"]`` says so.
3. ReliefF weighs the standardised initial features of the training rows against their categories, once per
   (t, k): the weights do not depend on the relevancy threshold. The test rows take no part in it.
4. For every relevancy threshold r the model keeps the features whose weight exceeds r x the largest weight
   (:func:`affordance_learning.paper.model.select_features`); recorded are their number and the shares of them that
   are shape and size features; the SVM (standardisation + RBF ``SVC``) is trained on the training rows and its
   accuracy measured on the test rows, next to the accuracy of always answering the training rows' most
   common category (``svm_baseline``).

Trials run in parallel with joblib; a trial's seeds come from ``(random_state, t)`` and k only (so a run
over fewer k gives the same numbers for those k), and the results are gathered in trial order, so they do
not depend on ``n_jobs``. Means and standard deviations (population, ddof = 0) are over trials.

Besides, once over all rows: how success depends on object size (:func:`affordance_learning.paper.metrics.size_success`,
the grasp's critical size) and what the effects contain (:func:`affordance_learning.paper.diagnostics.effect_summary`).

:func:`affordance_learning.paper.synthetic.make_synthetic_frame` builds a frame in the same schema without the
simulator.
"""

import numbers
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from joblib import Parallel, delayed
from sklearn.model_selection import train_test_split
from sklearn.preprocessing import StandardScaler

from affordance_env.values import is_integer
from affordance_learning.common.behaviors import ROLLED_IS_SUCCESS, outcome_words
from affordance_learning.common.exceptions import InvalidValueError
from affordance_learning.common.schema import TYPE_ORDER, feature_groups, feature_names, frame_behavior, label_column
from affordance_learning.common.validation import first_non_finite
from affordance_learning.paper.diagnostics import effect_summary
from affordance_learning.paper.metrics import adjusted_rand, cluster_purity, make_svm, size_success, uniformity
from affordance_learning.paper.model import _check_int, select_features
from affordance_learning.paper.relieff import MULTICLASS_THRESHOLD, ReliefFScorer
from affordance_learning.paper.results import RESULTS_FORMAT, UNITS, k_key, r_key
from affordance_learning.paper.som import SOMClustering

DEFAULT_KS = tuple(range(2, 11))
DEFAULT_RELEVANCIES = (0.0, 0.2, 0.4, 0.6, 0.8)
#: Map sizes whose clusters are described: the paper's tap case studies (k = 2, 4) and the grasp's k = 3.
CASE_STUDY_KS = (2, 3, 4)


@dataclass(frozen=True)
class _Data:
    """The arrays of a dataset frame that the protocol uses."""

    names: list[str]
    groups: np.ndarray  # (d,) str: group of each feature (shape, size, relation)
    X: np.ndarray  # (n, d) initial features
    Z: np.ndarray  # (n, d) standardised effects
    label: str  # the column the success/fail labels come from ("success" or "rolled")
    success: np.ndarray  # (n,) bool
    types: np.ndarray  # (n,) str
    sizes: np.ndarray  # (n,) float [m]
    left_view: np.ndarray  # (n,) bool: the object was not seen in the final snapshot (left the view or the table)
    effect_mean: np.ndarray  # (d,) the standardisation of the effects, to turn prototypes back into units
    effect_scale: np.ndarray  # (d,)


def _frame_data(frame: pd.DataFrame) -> _Data:
    if not isinstance(frame, pd.DataFrame):
        raise InvalidValueError(f"expected a pandas DataFrame in the dataset schema, got {type(frame).__name__}.")
    for column in ("type", "size"):
        if column not in frame.columns:
            raise InvalidValueError(
                f"the frame has no {column!r} column (ground truth the protocol evaluates against)."
            )
    label = label_column(frame)
    names = feature_names(frame)
    X = frame[[f"initial_{n}" for n in names]].to_numpy(dtype=np.float64)
    E = frame[[f"effect_{n}" for n in names]].to_numpy(dtype=np.float64)
    for prefix, values in (("initial_", X), ("effect_", E)):
        found = first_non_finite(values)
        if found:
            count, row, col, value = found
            raise InvalidValueError(
                f"{count} non-finite value(s) in the {prefix} columns, the first in row {row}, "
                f"column {prefix}{names[col]}: {value}; expected finite features."
            )
    success = frame[label].to_numpy()
    if success.dtype != bool:
        if not set(pd.unique(success).tolist()) <= {0, 1}:
            raise InvalidValueError(f"{label!r} must be boolean, got values {pd.unique(success).tolist()[:5]}.")
        success = success.astype(bool)
    sizes = frame["size"].to_numpy(dtype=np.float64)
    if not np.all(np.isfinite(sizes)):
        raise InvalidValueError("'size' must be finite [m] for every row.")
    scaler = StandardScaler().fit(E)
    return _Data(
        names=names,
        groups=np.array(feature_groups(names)),
        X=X,
        Z=scaler.transform(E),
        label=label,
        success=success,
        types=frame["type"].astype(str).to_numpy(),
        sizes=sizes,
        left_view=(~frame["visible_final"].to_numpy(dtype=bool) if "visible_final" in frame.columns
                   else np.zeros(len(frame), dtype=bool)),
        effect_mean=scaler.mean_,
        effect_scale=scaler.scale_,
    )


def _case_study(labels: np.ndarray, k: int, data: _Data, types: Sequence[str]) -> list[dict[str, Any]]:
    """Per map node: success and fail counts, object type counts, object sizes [m] (sorted), and how many of its
    objects were not seen in the final snapshot (``left_view``: their effect is minus their initial features,
    not a motion)."""
    clusters = []
    for c in range(k):
        members = labels == c
        clusters.append(
            {
                "cluster": c,
                "success": int(np.sum(data.success[members])),
                "fail": int(np.sum(~data.success[members])),
                "types": {t: int(np.sum(data.types[members] == t)) for t in types},
                "sizes": [round(float(s), 6) for s in np.sort(data.sizes[members])],
                "left_view": int(np.sum(data.left_view[members])),
            }
        )
    return clusters


def _run_trial(
    data: _Data,
    trial: int,
    random_state: int,
    ks: Sequence[int],
    relevancies: Sequence[float],
    test_size: float,
    n_neighbors: int,
    som_iterations: int,
    svm_C: float,
    svm_gamma: float | str,
    case_study_ks: Sequence[int],
    type_order: Sequence[str],
    stratify: bool,
) -> dict[str, Any]:
    """One trial of the protocol: every k and r; plain numbers keyed by k and (r, k)."""
    split_seed = np.random.SeedSequence([random_state, trial]).generate_state(1)[0]
    rows = np.arange(len(data.X))
    train, test = train_test_split(
        rows, test_size=test_size, stratify=data.types if stratify else None, random_state=int(split_seed)
    )
    X_train, X_test = data.X[train], data.X[test]
    scorer: ReliefFScorer | None = None
    out: dict[str, Any] = {
        key: {} for key in ("uniformity", "purity", "ari", "n_categories", "baseline", "weights", "cases",
                            "prototypes")
    }
    out.update({key: {} for key in ("accuracy", "shape_fraction", "size_fraction", "n_selected")})
    shape, size = data.groups == "shape", data.groups == "size"

    def record_selection(r: float, k: int, selected: np.ndarray) -> None:
        out["shape_fraction"][r, k] = float(np.mean(shape[selected]))
        out["size_fraction"][r, k] = float(np.mean(size[selected]))
        out["n_selected"][r, k] = int(selected.size)

    for k in ks:
        seed = np.random.SeedSequence([random_state, trial, k]).generate_state(1)[0]
        som = SOMClustering(n_clusters=k, n_iterations=som_iterations, random_state=int(seed)).fit(data.Z)
        labels = som.labels_
        out["uniformity"][k] = uniformity(labels, data.success) / 100.0  # a fraction, as every share here
        out["purity"][k] = cluster_purity(labels, data.types)
        out["ari"][k] = adjusted_rand(labels, data.types)
        out["n_categories"][k] = int(np.unique(labels).size)
        if trial == 0 and k in case_study_ks:
            out["cases"][k] = _case_study(labels, k, data, type_order)
            # the map's prototype effects, back in feature units (the SOM learned them standardised)
            out["prototypes"][k] = (som.cluster_centers_ * data.effect_scale + data.effect_mean).tolist()
        y_train, y_test = labels[train], labels[test]
        classes, counts = np.unique(y_train, return_counts=True)
        majority = classes[np.argmax(counts)]
        out["baseline"][k] = float(np.mean(y_test == majority))
        if classes.size < 2:
            # One category among the training rows: nothing to weigh or learn; like AffordanceModel, all
            # weights are 0, the rule keeps the first feature, and the answer is always that category.
            out["weights"][k] = np.zeros(len(data.names))
            for r in relevancies:
                selected = select_features(out["weights"][k], r)
                out["accuracy"][r, k] = out["baseline"][k]
                record_selection(r, k, selected)
            continue
        if scorer is None:
            scorer = ReliefFScorer(StandardScaler().fit_transform(X_train))
        weights = scorer.weights(y_train, n_neighbors)
        out["weights"][k] = weights
        accuracy: dict[tuple[int, ...], float] = {}  # thresholds that keep the same features share one SVM
        for r in relevancies:
            selected = select_features(weights, r)
            key = tuple(selected.tolist())
            if key not in accuracy:
                svm = make_svm(svm_C, svm_gamma).fit(X_train[:, selected], y_train)
                accuracy[key] = float(svm.score(X_test[:, selected], y_test))
            out["accuracy"][r, k] = accuracy[key]
            record_selection(r, k, selected)
    return out


def _stats(values: Iterable[float]) -> dict[str, float | None]:
    """Mean and population standard deviation of the finite values; None for both when there are none."""
    array = np.asarray(list(values), dtype=np.float64)
    array = array[np.isfinite(array)]
    if array.size == 0:
        return {"mean": None, "std": None}
    return {"mean": float(array.mean()), "std": float(array.std())}


def _check_protocol_args(
    ks: Iterable[int],
    relevancies: Iterable[float],
    n_trials: int,
    random_state: int,
    test_size: float,
    n_neighbors: int,
    som_iterations: int,
) -> tuple[list[int], list[float]]:
    ks = list(ks)
    if not ks or any(
        not is_integer(k) or not 2 <= k <= MULTICLASS_THRESHOLD
        for k in ks
    ):
        raise InvalidValueError(f"ks must be integers in [2, {MULTICLASS_THRESHOLD}] (map sizes), got {ks!r}.")
    if len(set(ks)) != len(ks):
        raise InvalidValueError(f"ks must not repeat a value, got {ks!r}.")
    relevancies = list(relevancies)
    if not relevancies or any(
        isinstance(r, bool) or not isinstance(r, numbers.Real) or not 0.0 <= r <= 1.0 for r in relevancies
    ):
        raise InvalidValueError(f"relevancies must be numbers in [0, 1], got {relevancies!r}.")
    if len({r_key(r) for r in relevancies}) != len(relevancies):
        raise InvalidValueError(f"relevancies must not repeat a value, got {relevancies!r}.")
    if not is_integer(n_trials) or n_trials < 1:
        raise InvalidValueError(f"n_trials must be an integer >= 1, got {n_trials!r}.")
    if not is_integer(random_state) or random_state < 0:
        raise InvalidValueError(
            f"random_state must be an integer >= 0 (the protocol is always seeded), got {random_state!r}."
        )
    if isinstance(test_size, bool) or not isinstance(test_size, numbers.Real) or not 0.0 < test_size < 1.0:
        raise InvalidValueError(f"test_size must be a share in (0, 1), got {test_size!r}.")
    _check_int("n_neighbors", n_neighbors, 1)
    _check_int("som_iterations", som_iterations, 1)
    return [int(k) for k in ks], [float(r) for r in relevancies]


def run_protocol(
    df: pd.DataFrame,
    ks: Iterable[int] = DEFAULT_KS,
    relevancies: Iterable[float] = DEFAULT_RELEVANCIES,
    n_trials: int = 20,
    random_state: int = 0,
    n_jobs: int | None = None,
    *,
    test_size: float = 0.3,
    n_neighbors: int = 10,
    som_iterations: int = 5000,
    svm_C: float = 1.0,
    svm_gamma: float | str = "scale",
    case_study_ks: Iterable[int] = CASE_STUDY_KS,
    progress: bool | None = False,
    behavior: str | None = None,
) -> dict[str, Any]:
    """Run the paper's protocol (module docstring) on a dataset frame; returns a JSON-ready results dict.

    Args:
        df: One behaviour's interactions in the dataset schema (at least the initial_ and effect_ columns,
            type, size, and success or rolled).
        ks: Map sizes k (numbers of effect categories), each in [2, 10].
        relevancies: Relevancy thresholds r, each in [0, 1].
        n_trials: Repetitions with different map seeds and train/test splits.
        random_state: Seed of the whole protocol, an integer >= 0.
        n_jobs: joblib workers over trials (None: 1, -1: all cores); the results do not depend on it.
        test_size: Share of the interactions held out to measure the SVM accuracy, in (0, 1).
        n_neighbors: ReliefF's neighbours per class.
        som_iterations: Training steps of each map.
        svm_C: SVM regularisation.
        svm_gamma: SVM RBF coefficient.
        case_study_ks: Map sizes whose clusters of the first trial are described in ``case_studies``.
        progress: Draw a progress bar over the trials; None: a bar on a terminal, else a line every 10 s
            (:func:`affordance_env.progress.progress_bar`).
        behavior: The behaviour of the interactions; by default the frame's ``behavior`` column says it (and
            when given, it must agree with that column); needed for a frame without the column.

    Returns:
        ``{"uniformity": {"<k>": {"mean", "std"}}`` [0, 1] (against the success/fail labels; a fraction like
        every share here, :data:`affordance_learning.paper.results.UNITS`),
        ``"svm_accuracy": {"<r>": {"<k>": {"mean", "std"}}}`` [0, 1], ``"shape_fraction"`` and
        ``"size_fraction"`` (same keys; shares of shape and size features among the selected ones) [0, 1],
        ``"n_selected"`` (same keys), ``"case_studies": {"<k>": [{"cluster", "success", "fail", "types":
        {type: count}, "sizes": [m, ...], "left_view": count}]}``, ``"prototypes": {"<k>": [[effect per
        feature], ...]}``,
        ``"feature_names"``, ``"effects"`` (:func:`effect_summary`), ``"size_success"``
        (:func:`affordance_learning.paper.metrics.size_success`), ``"purity"``, ``"adjusted_rand"`` (against the
        object type), ``"n_categories"`` (non-empty clusters), ``"svm_baseline"`` (majority-category
        accuracy), all ``{"<k>": {"mean", "std"}}``, ``"feature_weights": {"<k>": {name: mean ReliefF
        weight}}``, and ``"config"``, which names the ``behavior``, the ``label`` column and how a success and
        a failure read (``success_label``, ``fail_label``). r is written as ``str(float(r))`` ("0.0", "0.2",
        ..., :func:`~.results.r_key`), k as ``str(k)`` (:func:`~.results.k_key`).
        The schema is the same for every behaviour. A mean over no finite value is None.
        :meth:`affordance_learning.paper.results.Results.from_dict` reads it.
    """
    ks, relevancies = _check_protocol_args(
        ks, relevancies, n_trials, random_state, test_size, n_neighbors, som_iterations
    )
    case_study_ks = [k for k in case_study_ks if k in ks]
    data = _frame_data(df)
    behavior = frame_behavior(df, behavior)
    if data.label == "rolled" and behavior not in ROLLED_IS_SUCCESS:
        raise InvalidValueError(
            f"the frame has no 'success' column, and the success of {behavior!r} is not 'rolled' (that stands in "
            f"only for {', '.join(ROLLED_IS_SUCCESS)}): load the dataset with an affordance_env that stores or "
            "derives 'success' (dataset schema 4)."
        )
    success_label, fail_label = outcome_words(behavior, data.label)
    type_counts = pd.Series(data.types).value_counts()
    n_test = int(np.ceil(test_size * len(data.X)))
    if min(n_test, len(data.X) - n_test) < 2:
        raise InvalidValueError(
            f"{len(data.X)} rows with test_size={test_size} leave {n_test} test and {len(data.X) - n_test} "
            "training rows; expected at least 2 of each."
        )
    # Stratified by type when every type can be on both sides; otherwise (a tiny frame) a plain random
    # split, and the config says so.
    stratify = bool(type_counts.min() >= 2 and min(n_test, len(data.X) - n_test) >= type_counts.size)
    split = (
        "stratified by object type"
        if stratify
        else f"random, not stratified (type counts {type_counts.to_dict()} too small to stratify)"
    )
    type_order = [t for t in TYPE_ORDER if t in type_counts.index] + sorted(
        t for t in type_counts.index if t not in TYPE_ORDER
    )
    jobs = (
        delayed(_run_trial)(
            data,
            t,
            int(random_state),
            ks,
            relevancies,
            float(test_size),
            n_neighbors,
            som_iterations,
            svm_C,
            svm_gamma,
            case_study_ks,
            type_order,
            stratify,
        )
        for t in range(n_trials)
    )
    from affordance_env.progress import progress_bar

    # in trial order whatever the workers: the results do not depend on n_jobs
    with progress_bar(progress, total=n_trials, unit="trial", desc="learning trials") as bar:
        trials = []
        for trial in Parallel(n_jobs=n_jobs, return_as="generator")(jobs):
            trials.append(trial)
            bar.update()

    def per_k(key: str) -> dict[str, dict[str, float | None]]:
        return {k_key(k): _stats(trial[key][k] for trial in trials) for k in ks}

    def per_rk(key: str) -> dict[str, dict[str, dict[str, float | None]]]:
        return {
            r_key(r): {k_key(k): _stats(trial[key][r, k] for trial in trials) for k in ks} for r in relevancies
        }

    groups = feature_groups(data.names)
    return {
        "results_format": RESULTS_FORMAT,
        "uniformity": per_k("uniformity"),
        "svm_accuracy": per_rk("accuracy"),
        "shape_fraction": per_rk("shape_fraction"),
        "size_fraction": per_rk("size_fraction"),
        "n_selected": per_rk("n_selected"),
        "case_studies": {k_key(k): trials[0]["cases"][k] for k in case_study_ks},
        "prototypes": {k_key(k): trials[0]["prototypes"][k] for k in case_study_ks},
        "feature_names": list(data.names),
        "effects": effect_summary(df),
        "size_success": size_success(data.sizes, data.success),
        "purity": per_k("purity"),
        "adjusted_rand": per_k("ari"),
        "n_categories": per_k("n_categories"),
        "svm_baseline": per_k("baseline"),
        "feature_weights": {
            k_key(k): dict(
                zip(
                    data.names,
                    np.mean([trial["weights"][k] for trial in trials], axis=0).tolist(),
                    strict=True,
                )
            )
            for k in ks
        },
        "config": {
            "behavior": behavior,
            "label": data.label,
            "success_label": success_label,
            "fail_label": fail_label,
            "ks": ks,
            "relevancies": relevancies,
            "n_trials": int(n_trials),
            "random_state": int(random_state),
            "n_rows": int(len(data.X)),
            "n_features": len(data.names),
            "feature_groups": {g: groups.count(g) for g in dict.fromkeys(groups)},
            "type_counts": {t: int(type_counts[t]) for t in type_order},
            "success_fraction": float(np.mean(data.success)),
            "test_size": float(test_size),
            "split": f"train/test split per trial, {split}, shared by every k and r",
            "clustering": "1 x k minisom map of the standardised effects of all rows, seeded per (trial, k)",
            "relieff": "skrebate-equivalent ReliefF, standardised initial features of the training rows",
            "n_neighbors": int(n_neighbors),
            "som_iterations": int(som_iterations),
            "svm": {"kernel": "rbf", "C": float(svm_C), "gamma": svm_gamma, "scaling": "standard"},
            "case_study_ks": list(case_study_ks),
            "case_study_trial": 0,
            "std": "population standard deviation over trials (ddof=0)",
            "units": UNITS,
        },
    }
