"""Measures of the paper and of clustering quality: uniformity, purity, adjusted Rand index, SVM accuracy.

Akgun et al. 2009, section V.A: the uniformity of the effect clusters against the hand-attached success/fail
(rolled/not rolled) labels is ``U = 100 x sum over clusters c of |S_c - F_c| / T``, with ``S_c`` and ``F_c``
the successes and failures in cluster ``c`` and ``T`` all instances: 100 when every cluster holds only
successes or only failures, 0 when every cluster holds as many of each.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike
from sklearn.metrics import adjusted_rand_score
from sklearn.metrics.cluster import contingency_matrix
from sklearn.model_selection import StratifiedKFold, cross_val_score
from sklearn.pipeline import Pipeline, make_pipeline
from sklearn.preprocessing import StandardScaler
from sklearn.svm import SVC

from affordance_env.values import is_integer
from affordance_learning.common.exceptions import InvalidValueError
from affordance_learning.paper.results import Logistic, SizeBin, SizeSide, SizeSuccess, SizeTest


def _paired(clusters: ArrayLike, labels: ArrayLike, name: str) -> tuple[np.ndarray, np.ndarray]:
    clusters = np.asarray(clusters)
    labels = np.asarray(labels)
    if clusters.ndim != 1 or labels.ndim != 1 or clusters.shape != labels.shape or clusters.size == 0:
        raise InvalidValueError(
            f"clusters and {name} must be non-empty 1-D arrays of the same length, got shapes "
            f"{clusters.shape} and {labels.shape}."
        )
    for label, values in (("clusters", clusters), (name, labels)):
        if values.dtype.kind == "f" and np.isnan(values).any():
            raise InvalidValueError(f"{label} contains NaN; expected a label for every instance.")
    return clusters, labels


def _as_success(success: np.ndarray) -> np.ndarray:
    if success.dtype == bool:
        return success
    values = np.unique(success)
    if values.dtype.kind not in "iuf" or not set(values.tolist()) <= {0, 1}:
        raise InvalidValueError(f"success must be boolean or 0/1, got values {values.tolist()[:10]}.")
    return success.astype(bool)


def uniformity(clusters: ArrayLike, success: ArrayLike) -> float:
    """The paper's uniformity of clusters against success/fail labels, in percent [0, 100].

    Args:
        clusters: Cluster of each instance, (n,), any hashable labels.
        success: Success (True, 1: the object rolled) or failure (False, 0) of each instance, (n,).

    Returns:
        ``100 x sum_c |S_c - F_c| / T`` [%].
    """
    clusters, success = _paired(clusters, success, "success")
    success = _as_success(success)
    _, index = np.unique(clusters, return_inverse=True)
    n_success = np.bincount(index, weights=success.astype(np.float64))
    n_failure = np.bincount(index, weights=(~success).astype(np.float64))
    return float(100.0 * np.abs(n_success - n_failure).sum() / clusters.size)


def cluster_purity(clusters: ArrayLike, labels: ArrayLike) -> float:
    """Share of instances whose label is the most common label of their cluster, in [0, 1].

    Args:
        clusters: Cluster of each instance, (n,).
        labels: Known class of each instance (for example the object type), (n,).
    """
    clusters, labels = _paired(clusters, labels, "labels")
    return float(contingency_matrix(clusters, labels).max(axis=1).sum() / clusters.size)  # rows: clusters


def adjusted_rand(clusters: ArrayLike, labels: ArrayLike) -> float:
    """Adjusted Rand index of the clusters against known labels: 1 for the same partition, about 0 by chance.

    Args:
        clusters: Cluster of each instance, (n,).
        labels: Known class of each instance, (n,).
    """
    clusters, labels = _paired(clusters, labels, "labels")
    return float(adjusted_rand_score(labels, clusters))


def make_svm(C: float = 1.0, gamma: float | str = "scale") -> Pipeline:
    """The model's classifier: standardisation, then a multi-class (one-vs-one) RBF support vector machine.

    Args:
        C: Regularisation (larger fits the training rows more closely), > 0.
        gamma: RBF kernel coefficient [1 / (standardised feature unit)^2], ``"scale"``, ``"auto"`` or > 0.
    """
    return make_pipeline(StandardScaler(), SVC(C=C, gamma=gamma, kernel="rbf"))


def svm_cv_accuracy(
    X: ArrayLike,
    y: ArrayLike,
    *,
    n_splits: int = 5,
    C: float = 1.0,
    gamma: float | str = "scale",
    random_state: int | None = 0,
) -> float:
    """Mean stratified k-fold accuracy of :func:`make_svm` predicting ``y`` from ``X``, in [0, 1].

    Args:
        X: Features, (n, d).
        y: Classes, (n,); every class needs at least ``n_splits`` members.
        n_splits: Folds.
        C: SVM regularisation.
        gamma: RBF kernel coefficient.
        random_state: Seed of the fold shuffling.
    """
    X = np.asarray(X, dtype=np.float64)
    y = np.asarray(y)
    if X.ndim != 2 or y.shape != (X.shape[0],):
        raise InvalidValueError(f"X must be (n, d) and y (n,), got shapes {X.shape} and {y.shape}.")
    classes, counts = np.unique(y, return_counts=True)
    if classes.size < 2:
        raise InvalidValueError(f"y needs at least 2 classes for an SVM, got only {classes.tolist()}.")
    if counts.min() < n_splits:
        raise InvalidValueError(
            f"every class needs at least n_splits={n_splits} members for stratified folds; class "
            f"{classes[np.argmin(counts)]!r} has {counts.min()}."
        )
    folds = StratifiedKFold(n_splits=n_splits, shuffle=True, random_state=random_state)
    return float(np.mean(cross_val_score(make_svm(C, gamma), X, y, cv=folds)))


#: Success depends on object size when a likelihood-ratio test of the logistic fit against a constant rejects
#: the constant at this level ...
SIZE_TEST_ALPHA = 0.01
#: ... and the fitted share of successes differs by at least this much between the smallest and the largest
#: object seen (a fit that only drifts from 47 % to 56 % across the sizes gives no critical size).
SIZE_MIN_SPAN = 0.5


def size_success(sizes: ArrayLike, success: ArrayLike, n_bins: int = 6) -> SizeSuccess:
    """How success depends on object size: the share of successes per size bin, a logistic fit, a test of
    whether success depends on size at all, and the critical size where it does.

    A behaviour whose outcome is decided by size (the paper's grasp: small objects are held, large ones are not)
    has a critical size where the chance of success crosses 50 %. It is estimated by a logistic regression of
    success on size (practically unregularised: ``C = 1e6`` on the standardised sizes), ``P(success) =
    1 / (1 + exp(-(intercept + slope x size)))``, as ``-intercept / slope``, and reported only where success
    depends on size: the fit is significant (likelihood-ratio test against a constant share, p <
    :data:`SIZE_TEST_ALPHA`) and large (the fitted share differs by at least :data:`SIZE_MIN_SPAN` between the
    smallest and the largest object seen).

    Args:
        sizes: Object size of each interaction [m], (n,), finite.
        success: Success of each interaction, (n,), boolean or 0/1.
        n_bins: Equal-width bins over the sizes seen.

    Returns:
        The share of successes per bin (``low``, ``high`` [m], ``n``, ``success``: None for an empty bin); the
        logistic fit (``intercept``, ``slope`` [1/m]), None with only one outcome (nothing to fit); the test
        (``p_value``, ``span``: the fitted share at the largest size minus at the smallest, ``depends_on_size``,
        ``rule``), None without a fit; the critical size [m], None when success does not depend on size or the
        fit does not cross 50 % within the sizes seen; and the interactions with objects smaller, and not
        smaller, than it (``below``, ``above``: ``n`` and their share of successes), None without one.
    """
    from scipy.stats import chi2
    from sklearn.linear_model import LogisticRegression

    sizes, success = _paired(np.asarray(sizes, dtype=np.float64), success, "success")
    success = _as_success(success)
    if not np.all(np.isfinite(sizes)):
        raise InvalidValueError("sizes must be finite [m].")
    if not is_integer(n_bins) or n_bins < 1:
        raise InvalidValueError(f"n_bins must be an integer >= 1, got {n_bins!r}.")
    low, high = float(sizes.min()), float(sizes.max())
    edges = np.linspace(low, high, n_bins + 1) if high > low else np.array([low, high])
    index = np.clip(np.searchsorted(edges, sizes, side="right") - 1, 0, edges.size - 2)

    def side(members: np.ndarray) -> tuple[int, float | None]:
        return int(members.sum()), float(success[members].mean()) if members.any() else None

    bins = tuple(SizeBin(float(edges[b]), float(edges[b + 1]), *side(index == b)) for b in range(edges.size - 1))
    if success.all() or not success.any() or high == low:
        return SizeSuccess(bins)
    mean, scale = sizes.mean(), sizes.std()
    fit = LogisticRegression(C=1e6, max_iter=1000).fit(((sizes - mean) / scale)[:, None], success)
    slope = float(fit.coef_[0, 0] / scale)
    intercept = float(fit.intercept_[0] - fit.coef_[0, 0] * mean / scale)

    def log_likelihood(p: np.ndarray) -> float:
        p = np.clip(p, 1e-12, 1.0 - 1e-12)
        return float(np.sum(np.where(success, np.log(p), np.log1p(-p))))

    fitted = 1.0 / (1.0 + np.exp(-(intercept + slope * np.array([low, high]))))
    ratio = 2.0 * (log_likelihood(1.0 / (1.0 + np.exp(-(intercept + slope * sizes))))
                   - log_likelihood(np.full(sizes.shape, success.mean())))
    p_value, span = float(chi2.sf(max(ratio, 0.0), df=1)), float(fitted[1] - fitted[0])
    depends = p_value < SIZE_TEST_ALPHA and abs(span) >= SIZE_MIN_SPAN
    fit, test = Logistic(intercept, slope), SizeTest(
        p_value, span, bool(depends), f"likelihood-ratio test of the fit p < {SIZE_TEST_ALPHA:g} and the fitted "
        f"share changing by at least {100 * SIZE_MIN_SPAN:.0f} points across the sizes seen")
    if not (depends and slope != 0.0 and low <= -intercept / slope <= high):
        return SizeSuccess(bins, fit, test)
    critical = float(-intercept / slope)
    return SizeSuccess(bins, fit, test, critical, SizeSide(*side(sizes < critical)),
                       SizeSide(*side(sizes >= critical)))
