"""The paper's experiment on a dataset of interactions: uniformity, selected features, SVM accuracy.

Akgun et al. 2009, section V, on a pandas DataFrame in the project's dataset schema: for each feature name
(``affordance_env.features.FEATURE_NAMES``) the columns ``initial_<name>``, ``final_<name>`` and
``effect_<name>``, and the ground truth ``type`` (sphere | box | horizontal_cylinder | vertical_cylinder),
``size`` [m], ``rolled`` (bool) and ``displacement`` [m]. The ground truth is used only to evaluate, never to
learn. :func:`run_protocol` repeats, for every trial t and every number of clusters k:

1. A 1 x k self-organising map, seeded from ``(random_state, t, k)``, clusters the standardised effects of
   all interactions (the categories are the robot's, over all its experience). Measured against the ground
   truth: uniformity against ``rolled`` (the paper's metric), purity and adjusted Rand index against ``type``.
2. The interactions are split once per trial into training and test rows (``test_size``, 30 % by default),
   stratified by object type and seeded from ``(random_state, t)``; every k and r of a trial use the same
   split, so differences across k and r are not split noise. (Stratifying by cluster is not possible for
   every k: a 1 x 10 map can leave a cluster with a single member.) A frame too small to stratify (a type
   with a single row) gets a plain random split, and ``config["split"]`` says so.
3. ReliefF weighs the standardised initial features of the training rows against their categories, once per
   (t, k): the weights do not depend on the relevancy threshold. The test rows take no part in it.
4. For every relevancy threshold r the model keeps the features whose weight exceeds r x the largest weight
   (:func:`affordance_learning.model.select_features`); recorded are their number and the share of them that
   are shape features; the SVM (standardisation + RBF ``SVC``) is trained on the training rows and its
   accuracy measured on the test rows, next to the accuracy of always answering the training rows' most
   common category (``svm_baseline``).

Trials run in parallel with joblib; a trial's seeds come from ``(random_state, t)`` and k only (so a run
over fewer k gives the same numbers for those k), and the results are gathered in trial order, so they do
not depend on ``n_jobs``. Means and standard deviations (population, ddof = 0) are over trials.

:func:`make_synthetic_frame` builds a frame in the same schema without the simulator (for tests, benchmarks
and demonstrations): spheres and lying cylinders roll, boxes and standing cylinders do not.
"""

from __future__ import annotations

import numbers
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from joblib import Parallel, delayed
from sklearn.model_selection import train_test_split
from sklearn.preprocessing import StandardScaler

from affordance_learning.metrics import adjusted_rand, cluster_purity, make_svm, uniformity
from affordance_learning.model import _check_int, select_features
from affordance_learning.relieff import MULTICLASS_THRESHOLD, ReliefFScorer
from affordance_learning.som import SOMClustering
from affordance_learning.validation import first_non_finite

#: The object types of the paper, in the order figures and case studies list them.
OBJECT_TYPES = ("sphere", "horizontal_cylinder", "box", "vertical_cylinder")
#: Feature groups and their sizes in the order of ``FEATURE_NAMES`` (paper, section III.B).
GROUP_SIZES = (("shape", 24), ("size", 18), ("relation", 7))
DEFAULT_KS = tuple(range(2, 11))
DEFAULT_RELEVANCIES = (0.0, 0.2, 0.4, 0.6, 0.8)
CASE_STUDY_KS = (2, 4)


def feature_names(frame: pd.DataFrame) -> list[str]:
    """Names of the features of a dataset frame.

    ``affordance_env.features.FEATURE_NAMES`` when the frame has ``initial_<name>`` and ``effect_<name>``
    for all of them; otherwise every name with both columns, in the frame's column order.
    """
    columns = set(frame.columns)
    try:
        from affordance_env.features import FEATURE_NAMES
    except ImportError:
        FEATURE_NAMES = ()
    if FEATURE_NAMES and all(f"initial_{n}" in columns and f"effect_{n}" in columns for n in FEATURE_NAMES):
        return list(FEATURE_NAMES)
    names = [
        c.removeprefix("initial_") for c in frame.columns if isinstance(c, str) and c.startswith("initial_")
    ]
    if not names:
        raise ValueError(
            "the frame has no initial_<name> columns; expected the dataset schema (initial_, final_, effect_ "
            f"columns per feature), got columns {list(frame.columns)[:8]}..."
        )
    missing = [f"effect_{n}" for n in names if f"effect_{n}" not in columns]
    if missing:
        raise ValueError(f"the frame lacks effect columns {missing[:5]} for its initial_ columns.")
    return names


def feature_groups(names: Sequence[str]) -> list[str]:
    """Group ("shape", "size" or "relation") of every feature name.

    From ``affordance_env.features.FEATURE_GROUPS`` when it knows every name; otherwise, for 49 features, by
    position (the first 24 shape, the next 18 size, the last 7 relation, as in the paper).
    """
    try:
        from affordance_env.features import FEATURE_GROUPS
    except ImportError:
        FEATURE_GROUPS = {}
    if all(n in FEATURE_GROUPS for n in names):
        return [FEATURE_GROUPS[n] for n in names]
    total = sum(size for _, size in GROUP_SIZES)
    if len(names) != total:
        unknown = [n for n in names if n not in FEATURE_GROUPS]
        raise ValueError(
            f"cannot tell the group of features {unknown[:5]}: they are not in affordance_env's "
            f"FEATURE_GROUPS and there are {len(names)} features, not the paper's {total} (24 shape, "
            "18 size, 7 relation)."
        )
    return [group for group, size in GROUP_SIZES for _ in range(size)]


@dataclass(frozen=True)
class _Data:
    """The arrays of a dataset frame that the protocol uses."""

    names: list[str]
    shape: np.ndarray  # (d,) bool: shape feature
    X: np.ndarray  # (n, d) initial features
    Z: np.ndarray  # (n, d) standardised effects
    rolled: np.ndarray  # (n,) bool
    types: np.ndarray  # (n,) str
    sizes: np.ndarray  # (n,) float [m]
    effect_mean: np.ndarray  # (d,) the standardisation of the effects, to turn prototypes back into units
    effect_scale: np.ndarray  # (d,)


def _frame_data(frame: pd.DataFrame) -> _Data:
    if not isinstance(frame, pd.DataFrame):
        raise ValueError(f"expected a pandas DataFrame in the dataset schema, got {type(frame).__name__}.")
    for column in ("type", "size", "rolled"):
        if column not in frame.columns:
            raise ValueError(
                f"the frame has no {column!r} column (ground truth the protocol evaluates against)."
            )
    names = feature_names(frame)
    X = frame[[f"initial_{n}" for n in names]].to_numpy(dtype=np.float64)
    E = frame[[f"effect_{n}" for n in names]].to_numpy(dtype=np.float64)
    for prefix, values in (("initial_", X), ("effect_", E)):
        found = first_non_finite(values)
        if found:
            count, row, col, value = found
            raise ValueError(
                f"{count} non-finite value(s) in the {prefix} columns, the first in row {row}, "
                f"column {prefix}{names[col]}: {value}; expected finite features."
            )
    rolled = frame["rolled"].to_numpy()
    if rolled.dtype != bool:
        if not set(pd.unique(rolled).tolist()) <= {0, 1}:
            raise ValueError(f"'rolled' must be boolean, got values {pd.unique(rolled).tolist()[:5]}.")
        rolled = rolled.astype(bool)
    sizes = frame["size"].to_numpy(dtype=np.float64)
    if not np.all(np.isfinite(sizes)):
        raise ValueError("'size' must be finite [m] for every row.")
    scaler = StandardScaler().fit(E)
    return _Data(
        names=names,
        shape=np.array([g == "shape" for g in feature_groups(names)]),
        X=X,
        Z=scaler.transform(E),
        rolled=rolled,
        types=frame["type"].astype(str).to_numpy(),
        sizes=sizes,
        effect_mean=scaler.mean_,
        effect_scale=scaler.scale_,
    )


def _case_study(labels: np.ndarray, k: int, data: _Data, types: Sequence[str]) -> list[dict[str, Any]]:
    """Per map node: rolled and not-rolled counts, object type counts, object sizes [m] (sorted)."""
    clusters = []
    for c in range(k):
        members = labels == c
        clusters.append(
            {
                "cluster": c,
                "rolled": int(np.sum(data.rolled[members])),
                "not_rolled": int(np.sum(~data.rolled[members])),
                "types": {t: int(np.sum(data.types[members] == t)) for t in types},
                "sizes": [round(float(s), 6) for s in np.sort(data.sizes[members])],
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
    out.update({key: {} for key in ("accuracy", "shape_fraction", "n_selected")})
    for k in ks:
        seed = np.random.SeedSequence([random_state, trial, k]).generate_state(1)[0]
        som = SOMClustering(n_clusters=k, n_iterations=som_iterations, random_state=int(seed)).fit(data.Z)
        labels = som.labels_
        out["uniformity"][k] = uniformity(labels, data.rolled)
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
                out["shape_fraction"][r, k] = float(np.mean(data.shape[selected]))
                out["n_selected"][r, k] = int(selected.size)
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
            out["shape_fraction"][r, k] = float(np.mean(data.shape[selected]))
            out["n_selected"][r, k] = int(selected.size)
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
        isinstance(k, bool) or not isinstance(k, numbers.Integral) or not 2 <= k <= MULTICLASS_THRESHOLD
        for k in ks
    ):
        raise ValueError(f"ks must be integers in [2, {MULTICLASS_THRESHOLD}] (map sizes), got {ks!r}.")
    if len(set(ks)) != len(ks):
        raise ValueError(f"ks must not repeat a value, got {ks!r}.")
    relevancies = list(relevancies)
    if not relevancies or any(
        isinstance(r, bool) or not isinstance(r, numbers.Real) or not 0.0 <= r <= 1.0 for r in relevancies
    ):
        raise ValueError(f"relevancies must be numbers in [0, 1], got {relevancies!r}.")
    if len({str(float(r)) for r in relevancies}) != len(relevancies):
        raise ValueError(f"relevancies must not repeat a value, got {relevancies!r}.")
    if isinstance(n_trials, bool) or not isinstance(n_trials, numbers.Integral) or n_trials < 1:
        raise ValueError(f"n_trials must be an integer >= 1, got {n_trials!r}.")
    if isinstance(random_state, bool) or not isinstance(random_state, numbers.Integral) or random_state < 0:
        raise ValueError(
            f"random_state must be an integer >= 0 (the protocol is always seeded), got {random_state!r}."
        )
    if isinstance(test_size, bool) or not isinstance(test_size, numbers.Real) or not 0.0 < test_size < 1.0:
        raise ValueError(f"test_size must be a share in (0, 1), got {test_size!r}.")
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
    progress: bool = False,
) -> dict[str, Any]:
    """Run the paper's protocol (module docstring) on a dataset frame; returns a JSON-ready results dict.

    Args:
        df: Interactions in the dataset schema (at least the initial_ and effect_ columns, type, size,
            rolled).
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
        progress: Draw a progress bar over the trials.

    Returns:
        ``{"uniformity": {"<k>": {"mean", "std"}}`` [%], ``"svm_accuracy": {"<r>": {"<k>": {"mean", "std"}}}``
        [0, 1], ``"shape_fraction"`` (same keys) [0, 1], ``"n_selected"`` (same keys), ``"case_studies":
        {"<k>": [{"cluster", "rolled", "not_rolled", "types": {type: count}, "sizes": [m, ...]}]}``,
        ``"purity"``, ``"adjusted_rand"`` (against the object type), ``"n_categories"`` (non-empty clusters),
        ``"svm_baseline"`` (majority-category accuracy), all ``{"<k>": {"mean", "std"}}``,
        ``"feature_weights": {"<k>": {name: mean ReliefF weight}}``, and ``"config"``. r is written as
        ``str(float(r))`` ("0.0", "0.2", ...), k as ``str(k)``. A mean over no finite value is None.
    """
    ks, relevancies = _check_protocol_args(
        ks, relevancies, n_trials, random_state, test_size, n_neighbors, som_iterations
    )
    case_study_ks = [k for k in case_study_ks if k in ks]
    data = _frame_data(df)
    type_counts = pd.Series(data.types).value_counts()
    n_test = int(np.ceil(test_size * len(data.X)))
    if min(n_test, len(data.X) - n_test) < 2:
        raise ValueError(
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
    type_order = [t for t in OBJECT_TYPES if t in type_counts.index] + sorted(
        t for t in type_counts.index if t not in OBJECT_TYPES
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
    from tqdm.auto import tqdm

    # in trial order whatever the workers: the results do not depend on n_jobs
    trials = list(tqdm(Parallel(n_jobs=n_jobs, return_as="generator")(jobs), total=n_trials, unit="trial",
                       desc="learning trials", disable=not progress, dynamic_ncols=True))

    def per_k(key: str) -> dict[str, dict[str, float | None]]:
        return {str(k): _stats(trial[key][k] for trial in trials) for k in ks}

    def per_rk(key: str) -> dict[str, dict[str, dict[str, float | None]]]:
        return {
            str(r): {str(k): _stats(trial[key][r, k] for trial in trials) for k in ks} for r in relevancies
        }

    groups = feature_groups(data.names)
    return {
        "uniformity": per_k("uniformity"),
        "svm_accuracy": per_rk("accuracy"),
        "shape_fraction": per_rk("shape_fraction"),
        "n_selected": per_rk("n_selected"),
        "case_studies": {str(k): trials[0]["cases"][k] for k in case_study_ks},
        "prototypes": {str(k): trials[0]["prototypes"][k] for k in case_study_ks},
        "feature_names": list(data.names),
        "effects": effect_summary(df),
        "purity": per_k("purity"),
        "adjusted_rand": per_k("ari"),
        "n_categories": per_k("n_categories"),
        "svm_baseline": per_k("baseline"),
        "feature_weights": {
            str(k): dict(
                zip(
                    data.names,
                    np.mean([trial["weights"][k] for trial in trials], axis=0).tolist(),
                    strict=True,
                )
            )
            for k in ks
        },
        "config": {
            "ks": ks,
            "relevancies": relevancies,
            "n_trials": int(n_trials),
            "random_state": int(random_state),
            "n_rows": int(len(data.X)),
            "n_features": len(data.names),
            "feature_groups": {g: groups.count(g) for g in dict.fromkeys(groups)},
            "type_counts": {t: int(type_counts[t]) for t in type_order},
            "rolled_fraction": float(np.mean(data.rolled)),
            "test_size": float(test_size),
            "split": f"train/test split per trial, {split}, shared by every k and r",
            "clustering": "1 x k minisom map of the standardised effects of all rows, seeded per (trial, k)",
            "relieff": "skrebate-equivalent ReliefF, standardised initial features of the training rows",
            "n_neighbors": int(n_neighbors),
            "som_iterations": int(som_iterations),
            "svm": {"kernel": "rbf", "C": float(svm_C), "gamma": svm_gamma, "scaling": "standard"},
            "case_study_trial": 0,
            "std": "population standard deviation over trials (ddof=0)",
        },
    }


def effect_summary(frame: pd.DataFrame) -> dict[str, Any]:
    """What the effects of a dataset contain, for a reader to check before any verdict.

    Per object type (``by_type``): interactions, the shares rolled, at rest and seen in the final snapshot
    (``visible_final``), and left the table (``outcome == "off_table"``); the median travel (``displacement``)
    [m], the median 3-D motion seen, ``|effect of (mean_x, mean_y, mean_z)|`` [m], over the objects seen at
    the end, the median ``|effect of pixel_count|`` [pixels] and the median change of the normal histograms
    (sum of ``|effect|`` over the 24 shape features). Overall: the share of rolled objects seen at the end
    (``rolled_visible``), the share of rolled objects whose effect is just minus their initial features
    (``rolled_effect_is_minus_initial``: they vanished), and the Spearman correlation of the travel with the
    3-D motion seen (``travel_vs_seen_motion``). Columns the frame lacks give None.
    """
    names = feature_names(frame)
    groups = feature_groups(names)
    xyz = [f"effect_{n}" for n in ("mean_x", "mean_y", "mean_z") if n in names]
    seen_motion = (np.linalg.norm(frame[xyz].to_numpy(dtype=np.float64), axis=1) if len(xyz) == 3
                   else np.full(len(frame), np.nan))
    shape_change = np.abs(frame[[f"effect_{n}" for n, g in zip(names, groups, strict=True) if g == "shape"]]
                          .to_numpy(dtype=np.float64)).sum(axis=1)
    initial = frame[[f"initial_{n}" for n in names]].to_numpy(dtype=np.float64)
    effect = frame[[f"effect_{n}" for n in names]].to_numpy(dtype=np.float64)
    vanished = np.abs(effect + initial).max(axis=1) < 1e-6
    visible = frame["visible_final"].to_numpy(dtype=bool) if "visible_final" in frame else None
    outcome = frame["outcome"].astype(str).to_numpy() if "outcome" in frame else None
    travel = frame["displacement"].to_numpy(dtype=np.float64) if "displacement" in frame else None
    rolled = frame["rolled"].to_numpy(dtype=bool)
    pixels = (np.abs(frame["effect_pixel_count"].to_numpy(dtype=np.float64)) if "pixel_count" in names
              else np.full(len(frame), np.nan))

    def share(mask: np.ndarray | None, rows: np.ndarray) -> float | None:
        return None if mask is None or not rows.any() else float(np.mean(mask[rows]))

    def median(values: np.ndarray | None, rows: np.ndarray) -> float | None:
        if values is None or not rows.any():
            return None
        finite = values[rows][np.isfinite(values[rows])]
        return float(np.median(finite)) if finite.size else None

    types = frame["type"].astype(str).to_numpy()
    by_type = {}
    for t in [t for t in OBJECT_TYPES if t in set(types)] + sorted(set(types) - set(OBJECT_TYPES)):
        rows = types == t
        seen = rows & visible if visible is not None else rows
        by_type[t] = {
            "n": int(rows.sum()),
            "rolled": share(rolled, rows),
            "rest": share(None if outcome is None else outcome == "rest", rows),
            "visible_final": share(visible, rows),
            "off_table": share(None if outcome is None else outcome == "off_table", rows),
            "displacement": median(travel, rows),
            "seen_motion": median(seen_motion, seen),
            "pixel_count_change": median(pixels, rows),
            "shape_change": median(shape_change, rows),
        }
    correlation = None
    if travel is not None and visible is not None and visible.sum() >= 3:
        from scipy.stats import spearmanr

        correlation = float(spearmanr(travel[visible], seen_motion[visible]).statistic)
    return {
        "by_type": by_type,
        "rolled_visible": share(visible, rolled),
        "rolled_rest_visible": None if visible is None or outcome is None else share(
            visible & (outcome == "rest"), rolled),
        "rolled_effect_is_minus_initial": share(vanished, rolled),
        "travel_vs_seen_motion": correlation,
    }


def make_synthetic_frame(n_rows: int = 1000, random_state: int = 0) -> pd.DataFrame:
    """A dataset frame in the project's schema with tapping-like structure, made without the simulator.

    Objects of the four types, sizes uniform in [0.04, 0.10] m. Spheres and lying cylinders roll (95 %),
    boxes and standing cylinders do not (97 %). Shape features (normal histograms, fractions) depend on the
    type, size features on the size, relation features are jitter. As on the simulated table, a rolled object
    travels 5-22 cm and is seen where it stops: its effect moves its position, range, pixel count and image
    offsets by its travel; 3 % of the rolled objects leave the table instead (``outcome == "off_table"``,
    ``visible_final`` False, final features all zeros, so their effect is minus their initial features); a
    resting object slides about 1.5 cm. Feature names are ``affordance_env.features.FEATURE_NAMES`` when
    available, else ``f00`` ... ``f48``.

    Args:
        n_rows: Interactions, >= 8.
        random_state: Seed.
    """
    if isinstance(n_rows, bool) or not isinstance(n_rows, numbers.Integral) or n_rows < 8:
        raise ValueError(f"n_rows must be an integer >= 8, got {n_rows!r}.")
    try:
        from affordance_env.features import FEATURE_NAMES

        names = list(FEATURE_NAMES)
    except ImportError:
        names = [f"f{i:02d}" for i in range(49)]
    rng = np.random.default_rng(random_state)
    types = np.array(OBJECT_TYPES)[np.arange(n_rows) % 4]
    rng.shuffle(types)
    kind = np.searchsorted(np.array(sorted(OBJECT_TYPES)), types)  # 0 box, 1 horizontal, 2 sphere, 3 vertical
    size = rng.uniform(0.04, 0.10, n_rows)
    rollable = np.isin(types, ("sphere", "horizontal_cylinder"))
    rolled = np.where(rollable, rng.random(n_rows) < 0.95, rng.random(n_rows) < 0.03)

    # Shape: a latitude and a longitude histogram per type, 12 bins each, perturbed and renormalised.
    bins = np.arange(12)
    lat_profiles = np.stack(
        [
            np.exp(-0.5 * ((bins - 11) / 0.8) ** 2)
            + np.exp(-0.5 * ((bins - 6) / 0.5) ** 2),  # box: top + sides
            np.exp(-0.5 * ((bins - 8) / 2.5) ** 2),  # lying cylinder: a band of latitudes
            np.exp(-0.5 * ((bins - 8) / 3.5) ** 2),  # sphere: every latitude facing the camera
            np.exp(-0.5 * ((bins - 6) / 0.6) ** 2)
            + 0.6 * np.exp(-0.5 * ((bins - 11) / 0.6) ** 2),  # standing
        ]
    )
    lon_profiles = np.stack(
        [
            np.exp(-0.5 * ((bins - 6) / 0.7) ** 2),
            np.exp(-0.5 * ((bins - 6) / 0.9) ** 2) + 0.3,
            np.exp(-0.5 * ((bins - 6) / 3.0) ** 2),
            np.exp(-0.5 * ((bins - 6) / 2.5) ** 2),
        ]
    )

    def histogram(profiles: np.ndarray) -> np.ndarray:
        h = profiles[kind] * rng.gamma(20.0, 1 / 20.0, (n_rows, 12))
        return h / h.sum(axis=1, keepdims=True)

    shape = np.hstack([histogram(lat_profiles), histogram(lon_profiles)])
    jitter = rng.normal(0.0, 0.02, (n_rows, 3))
    mean_xyz = np.column_stack([-0.30 + jitter[:, 0], 0.05 + jitter[:, 1], size / 2 + jitter[:, 2] * 0.1])
    mean_range = np.linalg.norm(mean_xyz - [0.0, 0.0, 0.35], axis=1)
    pixels = 2.0e4 * size**2 / mean_range**2 * rng.normal(1.0, 0.03, n_rows)
    orientation = rng.uniform(-np.pi / 2, np.pi / 2, n_rows)
    extents = (
        size[:, None]
        * rng.normal(1.0, 0.05, (n_rows, 12))
        * np.array([0.7, 0.7, 0.5, 1.0, 0.3] * 2 + [40, 40])
    )
    size_features = np.column_stack([mean_xyz, mean_range, pixels, orientation, extents])
    relation = rng.normal(0.0, 1.0, (n_rows, 7)) * np.array([5, 5, 7, 0.02, 0.02, 0.02, 0.03])
    initial = np.hstack([shape, size_features, relation])

    # Effects: travel along the tap direction for rolling objects, a 1.5 cm slide otherwise.
    roll = np.where(types == "sphere", rng.uniform(0.10, 0.22, n_rows), rng.uniform(0.05, 0.20, n_rows))
    travel = np.where(rolled, roll, rng.normal(0.015, 0.003, n_rows))
    off_table = rolled & (rng.random(n_rows) < 0.03)
    effect = rng.normal(0.0, 1.0, initial.shape) * 0.01 * (np.abs(initial).mean(axis=0) + 1e-3)
    effect[:, 24] += 0.1 * travel  # mean_x
    effect[:, 25] += travel  # mean_y
    effect[:, 27] += 0.6 * travel  # mean_range
    effect[:, 28] -= pixels * 0.8 * travel  # pixel_count: seen from a little further away
    effect[:, 42:45] += np.column_stack([10, 300, 300]).ravel() * travel[:, None]  # image offsets [pixels]
    effect[:, 46] += travel  # hand_dy
    effect[:, 48] += travel  # hand_distance
    spin = np.where(types == "horizontal_cylinder", 1.0, 0.0) * rolled
    effect[:, 12:24] += 0.05 * spin[:, None] * rng.normal(0.0, 1.0, (n_rows, 12))
    final = initial + effect
    final[off_table] = 0.0  # not visible: the documented zeros
    effect[off_table] = -initial[off_table]

    columns: dict[str, Any] = {}
    for prefix, values in (("initial_", initial), ("final_", final), ("effect_", effect)):
        columns.update({f"{prefix}{n}": values[:, j] for j, n in enumerate(names)})
    columns.update({"type": types, "size": size, "rolled": rolled, "displacement": np.abs(travel),
                    "rolling_distance": np.where(rolled, np.abs(travel), 0.0), "visible_final": ~off_table,
                    "outcome": np.where(off_table, "off_table", "rest")})
    return pd.DataFrame(columns)
