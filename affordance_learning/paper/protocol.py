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

import copy
import functools
import numbers
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
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
from affordance_learning.paper.results import UNITS, Cluster, Config, Results, Stat, r_key
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


@dataclass(frozen=True)
class _Settings:
    """The protocol's settings, checked (:func:`_check_protocol_args`)."""

    ks: tuple[int, ...]
    relevancies: tuple[float, ...]
    n_trials: int
    random_state: int
    test_size: float
    n_neighbors: int
    som_iterations: int
    svm_C: float
    svm_gamma: float | str
    case_study_ks: tuple[int, ...]  # those of ks whose clusters are described


@dataclass(frozen=True)
class _Design:
    """What the frame decides: the behaviour and how its outcomes read, the train/test split, the object types."""

    behavior: str
    success_label: str
    fail_label: str
    stratify: bool
    split: str  # the split, for config["split"]
    type_counts: tuple[tuple[str, int], ...]  # (type, count), in the order the results list the types


#: The sections of the results measured per k, and per (r, k), in each trial.
_PER_K = ("uniformity", "purity", "adjusted_rand", "n_categories", "svm_baseline")
_PER_RK = ("svm_accuracy", "shape_fraction", "size_fraction", "n_selected")


@dataclass
class _Trial:
    """One trial's numbers, filled in as it runs: per k and per (r, k) by the section of the results they go to,
    the ReliefF weights per k, and for the first trial the case-study maps' labels and prototypes (in units)."""

    per_k: dict[str, dict[int, float]] = field(default_factory=lambda: {name: {} for name in _PER_K})
    per_rk: dict[str, dict[tuple[float, int], float]] = field(default_factory=lambda: {n: {} for n in _PER_RK})
    weights: dict[int, np.ndarray] = field(default_factory=dict)
    labels: dict[int, np.ndarray] = field(default_factory=dict)
    prototypes: dict[int, np.ndarray] = field(default_factory=dict)


@dataclass(frozen=True)
class _Split:
    """A trial's training and test rows, and their initial features."""

    train: np.ndarray
    test: np.ndarray
    X_train: np.ndarray
    X_test: np.ndarray


def _case_study(labels: np.ndarray, k: int, data: _Data, types: Sequence[str]) -> tuple[Cluster, ...]:
    """Per map node: success and fail counts, object type counts, object sizes [m] (sorted), and how many of its
    objects were not seen in the final snapshot (``left_view``: their effect is minus their initial features,
    not a motion)."""
    clusters = []
    for c in range(k):
        members = labels == c
        clusters.append(Cluster(
            index=c,
            success=int(np.sum(data.success[members])),
            fail=int(np.sum(~data.success[members])),
            types=MappingProxyType({t: int(np.sum(data.types[members] == t)) for t in types}),
            sizes=tuple(round(float(s), 6) for s in np.sort(data.sizes[members])),
            left_view=int(np.sum(data.left_view[members])),
        ))
    return tuple(clusters)


def _run_trial(data: _Data, trial: int, settings: _Settings, stratify: bool) -> _Trial:
    """One trial of the protocol (module docstring): every k and r on one train/test split."""
    split_seed = np.random.SeedSequence([settings.random_state, trial]).generate_state(1)[0]
    train, test = train_test_split(np.arange(len(data.X)), test_size=settings.test_size,
                                   stratify=data.types if stratify else None, random_state=int(split_seed))
    split = _Split(train, test, data.X[train], data.X[test])
    # ReliefF's distances over the training rows, once per trial, when a k first has two categories to weigh
    relieff = functools.cache(lambda: ReliefFScorer(StandardScaler().fit_transform(split.X_train)))
    out = _Trial()
    for k in settings.ks:
        labels = _map_effects(data, trial, k, settings, out)
        _select_and_learn(data, labels, split, k, settings, relieff, out)
    return out


def _map_effects(data: _Data, trial: int, k: int, settings: _Settings, out: _Trial) -> np.ndarray:
    """Step 1 for one k: a 1 x k map categorises every effect; its categories measured against the ground truth.
    Returns the category of each row."""
    seed = np.random.SeedSequence([settings.random_state, trial, k]).generate_state(1)[0]
    som = SOMClustering(n_clusters=k, n_iterations=settings.som_iterations, random_state=int(seed)).fit(data.Z)
    labels = som.labels_
    out.per_k["uniformity"][k] = uniformity(labels, data.success) / 100.0  # a fraction, as every share here
    out.per_k["purity"][k] = cluster_purity(labels, data.types)
    out.per_k["adjusted_rand"][k] = adjusted_rand(labels, data.types)
    out.per_k["n_categories"][k] = int(np.unique(labels).size)
    if trial == 0 and k in settings.case_study_ks:
        out.labels[k] = labels
        # the map's prototype effects, back in feature units (the SOM learned them standardised)
        out.prototypes[k] = som.cluster_centers_ * data.effect_scale + data.effect_mean
    return labels


def _select_and_learn(data: _Data, labels: np.ndarray, split: _Split, k: int, settings: _Settings,
                      relieff: Callable[[], ReliefFScorer], out: _Trial) -> None:
    """Steps 3 and 4 for one k: ReliefF weighs the features against the categories of the training rows; per r,
    the features kept, and the SVM's accuracy on the test rows next to the majority category's."""
    y_train, y_test = labels[split.train], labels[split.test]
    classes, counts = np.unique(y_train, return_counts=True)
    baseline = float(np.mean(y_test == classes[np.argmax(counts)]))
    out.per_k["svm_baseline"][k] = baseline
    # One category among the training rows: nothing to weigh or learn; like AffordanceModel, all weights are 0,
    # the rule keeps the first feature, and the answer is always that category.
    single = classes.size < 2
    weights = np.zeros(len(data.names)) if single else relieff().weights(y_train, settings.n_neighbors)
    out.weights[k] = weights
    shape, size = data.groups == "shape", data.groups == "size"
    accuracy: dict[tuple[int, ...], float] = {}  # thresholds that keep the same features share one SVM
    for r in settings.relevancies:
        selected = select_features(weights, r)
        key = tuple(selected.tolist())
        if not single and key not in accuracy:
            svm = make_svm(settings.svm_C, settings.svm_gamma).fit(split.X_train[:, selected], y_train)
            accuracy[key] = float(svm.score(split.X_test[:, selected], y_test))
        out.per_rk["svm_accuracy"][r, k] = baseline if single else accuracy[key]
        out.per_rk["shape_fraction"][r, k] = float(np.mean(shape[selected]))
        out.per_rk["size_fraction"][r, k] = float(np.mean(size[selected]))
        out.per_rk["n_selected"][r, k] = int(selected.size)


def _stats(values: Iterable[float]) -> Stat:
    """Mean and population standard deviation of the finite values; None for both when there are none."""
    array = np.asarray(list(values), dtype=np.float64)
    array = array[np.isfinite(array)]
    if array.size == 0:
        return Stat(None, None)
    return Stat(float(array.mean()), float(array.std()))


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


def _design(df: pd.DataFrame, data: _Data, behavior: str | None, test_size: float) -> _Design:
    """The behaviour (the frame's, or ``behavior``), its success and fail words, and the split: stratified by type
    when every type can be on both sides; otherwise (a tiny frame) a plain random split, and the config says so."""
    behavior = frame_behavior(df, behavior)
    if data.label == "rolled" and behavior not in ROLLED_IS_SUCCESS:
        raise InvalidValueError(
            f"the frame has no 'success' column, and the success of {behavior!r} is not 'rolled' (that stands in "
            f"only for {', '.join(ROLLED_IS_SUCCESS)}): load the dataset with an affordance_env that stores or "
            "derives 'success' (dataset schema 4)."
        )
    type_counts = pd.Series(data.types).value_counts()
    n_test = int(np.ceil(test_size * len(data.X)))
    if min(n_test, len(data.X) - n_test) < 2:
        raise InvalidValueError(
            f"{len(data.X)} rows with test_size={test_size} leave {n_test} test and {len(data.X) - n_test} "
            "training rows; expected at least 2 of each."
        )
    stratify = bool(type_counts.min() >= 2 and min(n_test, len(data.X) - n_test) >= type_counts.size)
    split = (
        "stratified by object type"
        if stratify
        else f"random, not stratified (type counts {type_counts.to_dict()} too small to stratify)"
    )
    type_order = [t for t in TYPE_ORDER if t in type_counts.index] + sorted(
        t for t in type_counts.index if t not in TYPE_ORDER
    )
    return _Design(behavior, *outcome_words(behavior, data.label), stratify, split,
                   tuple((t, int(type_counts[t])) for t in type_order))


def _config(data: _Data, settings: _Settings, design: _Design, extra: Mapping[str, Any]) -> Config:
    """The settings the results record: the protocol's, then ``extra`` (the caller's, such as ``affordance
    reproduce``'s dataset and seed), which may not restate one of the protocol's."""
    groups = feature_groups(data.names)
    entries = {
        "behavior": design.behavior,
        "label": data.label,
        "success_label": design.success_label,
        "fail_label": design.fail_label,
        "ks": list(settings.ks),
        "relevancies": list(settings.relevancies),
        "n_trials": settings.n_trials,
        "random_state": settings.random_state,
        "n_rows": int(len(data.X)),
        "n_features": len(data.names),
        "feature_groups": {g: groups.count(g) for g in dict.fromkeys(groups)},
        "type_counts": dict(design.type_counts),
        "success_fraction": float(np.mean(data.success)),
        "test_size": settings.test_size,
        "split": f"train/test split per trial, {design.split}, shared by every k and r",
        "clustering": "1 x k minisom map of the standardised effects of all rows, seeded per (trial, k)",
        "relieff": "skrebate-equivalent ReliefF, standardised initial features of the training rows",
        "n_neighbors": settings.n_neighbors,
        "som_iterations": settings.som_iterations,
        "svm": {"kernel": "rbf", "C": float(settings.svm_C), "gamma": settings.svm_gamma, "scaling": "standard"},
        "case_study_ks": list(settings.case_study_ks),
        "case_study_trial": 0,
        "std": "population standard deviation over trials (ddof=0)",
        "units": UNITS,
    }
    restated = [key for key in extra if key in entries]
    if restated:
        raise InvalidValueError(f"extra_config restates the protocol's own settings {restated}; give other keys.")
    return Config(MappingProxyType({**entries, **copy.deepcopy(dict(extra))}))


def _run_trials(data: _Data, settings: _Settings, stratify: bool, n_jobs: int | None,
                progress: bool | None) -> list[_Trial]:
    """Every trial, in parallel, gathered in trial order whatever the workers: the results do not depend on
    ``n_jobs``."""
    from affordance_env.progress import progress_bar

    jobs = (delayed(_run_trial)(data, t, settings, stratify) for t in range(settings.n_trials))
    with progress_bar(progress, total=settings.n_trials, unit="trial", desc="learning trials") as bar:
        trials = []
        for trial in Parallel(n_jobs=n_jobs, return_as="generator")(jobs):
            trials.append(trial)
            bar.update()
    return trials


def _over_trials(trials: Sequence[_Trial], data: _Data, settings: _Settings, design: _Design) -> dict[str, Any]:
    """The sections of the results drawn from the trials: the means and spreads per k and per (r, k), the mean
    ReliefF weights per k, and the first trial's case studies."""
    ks, rs, first = settings.ks, settings.relevancies, trials[0]
    types = [t for t, _ in design.type_counts]
    return {
        **{name: MappingProxyType({k: _stats(t.per_k[name][k] for t in trials) for k in ks}) for name in _PER_K},
        **{name: MappingProxyType({r: MappingProxyType({k: _stats(t.per_rk[name][r, k] for t in trials)
                                                        for k in ks}) for r in rs}) for name in _PER_RK},
        "case_studies": MappingProxyType({k: _case_study(first.labels[k], k, data, types)
                                          for k in settings.case_study_ks}),
        "prototypes": MappingProxyType({k: tuple(tuple(row) for row in first.prototypes[k].tolist())
                                        for k in settings.case_study_ks}),
        "feature_weights": MappingProxyType({
            k: MappingProxyType(dict(zip(data.names, np.mean([t.weights[k] for t in trials], axis=0).tolist(),
                                         strict=True)))
            for k in ks}),
    }


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
    extra_config: Mapping[str, Any] | None = None,
) -> Results:
    """Run the paper's protocol (module docstring) on a dataset frame.

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
        extra_config: Further settings to record in ``config`` after the protocol's own (``affordance
            reproduce`` records its dataset, episodes, seed, ...), JSON values; none may restate one of them.

    Returns:
        The :class:`~affordance_learning.paper.results.Results` of every section: per k the uniformity (against
        the success/fail labels; a fraction like every share here, :data:`affordance_learning.paper.results.UNITS`),
        purity and adjusted Rand index (against the object type), non-empty clusters and majority-category
        accuracy (``svm_baseline``); per r and k the SVM accuracy, the shares of shape and size features among
        the selected ones and their number; the case studies and prototypes of the first trial's maps of
        ``case_study_ks``; the feature names and their mean ReliefF weights per k; the effects
        (:func:`effect_summary`) and success by size (:func:`affordance_learning.paper.metrics.size_success`);
        and ``config``, which names the ``behavior``, the ``label`` column and how a success and a failure read
        (``success_label``, ``fail_label``). A mean over no finite value is None. The schema is the same for
        every behaviour; :meth:`~affordance_learning.paper.results.Results.to_dict` gives the ``results.json``
        (r keyed ``str(float(r))``, k ``str(k)``).
    """
    checked_ks, checked_rs = _check_protocol_args(ks, relevancies, n_trials, random_state, test_size, n_neighbors,
                                                  som_iterations)
    settings = _Settings(tuple(checked_ks), tuple(checked_rs), int(n_trials), int(random_state), float(test_size),
                         int(n_neighbors), int(som_iterations), svm_C, svm_gamma,
                         tuple(k for k in case_study_ks if k in checked_ks))
    data = _frame_data(df)
    design = _design(df, data, behavior, settings.test_size)
    config = _config(data, settings, design, extra_config or {})
    trials = _run_trials(data, settings, design.stratify, n_jobs, progress)
    return Results(**_over_trials(trials, data, settings, design), feature_names=tuple(data.names),
                   effects=effect_summary(df), size_success=size_success(data.sizes, data.success), config=config)
