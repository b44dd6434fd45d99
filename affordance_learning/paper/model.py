"""The paper's learning model for one behaviour: SOM of effects -> ReliefF -> SVM.

Akgun et al. 2009, section IV, as a scikit-learn estimator. ``fit(X, y)`` takes the initial features as ``X``
and the effects E (final minus initial features) as ``y``; scikit-learn's contract names the second argument
``y``, and E plays its role:

1. standardise the effects (each effect dimension to zero mean and unit variance; a constant dimension is
   only centred, so it stays 0 rather than becoming NaN);
2. cluster them with a 1 x k self-organising map (:class:`SOMClustering`): the map node of each interaction
   is its effect category;
3. standardise the initial features and weigh them with ReliefF (:func:`relieff_weights`) by how well they
   separate the categories; keep the features whose weight exceeds ``relevancy`` x the largest weight, and
   always at least the best one (:func:`select_features`): perceptual economy;
4. train a multi-class RBF SVM (standardisation + ``SVC``, :func:`make_svm`) to predict the category from the
   selected initial features.

``predict(X)`` gives the categories; ``predict_effect(X)`` also what each category's effect looks like: its
prototype, the mean effect of the category's training interactions in the effect's own units.

If the map puts every interaction in one node there is nothing to separate: every feature weight is 0 (so
the selection rule keeps only the first feature, unused), no SVM is trained, and ``predict`` answers that
single category for every row.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from sklearn.base import BaseEstimator
from sklearn.pipeline import Pipeline
from sklearn.preprocessing import StandardScaler
from sklearn.utils import Tags
from sklearn.utils.validation import check_is_fitted, validate_data

from affordance_env.values import is_integer
from affordance_learning.common.exceptions import InvalidValueError
from affordance_learning.paper.metrics import make_svm
from affordance_learning.paper.relieff import MULTICLASS_THRESHOLD, relieff_weights
from affordance_learning.paper.som import SOMClustering, som_seed


@dataclass(frozen=True)
class EffectPrediction:
    """What :meth:`AffordanceModel.predict_effect` predicts for n rows of initial features.

    Attributes:
        category: Effect category (map node index) of each row, (n,) int.
        effect: Prototype effect of that category, (n, n_effects) float, in the effect's own units (for the
            49 features of this project: final minus initial feature, in each feature's unit).

    :func:`affordance_learning.predict_effect` given one feature vector gives one result: ``category`` an int and
    ``effect`` (n_effects,).
    """

    category: np.ndarray | int
    effect: np.ndarray


def select_features(weights: ArrayLike, relevancy: float) -> np.ndarray:
    """Indices of the features whose weight exceeds ``relevancy`` x the largest weight, plus the best one.

    The paper's relevancy threshold. With ``relevancy = 0`` the features of positive weight are kept. When
    no weight passes the threshold (for example all weights <= 0, or ``relevancy = 1``) only the feature of
    largest weight (the first one on a tie) is kept, so the classifier always has an input.

    Args:
        weights: ReliefF weight of every feature, (d,).
        relevancy: Threshold r in [0, 1] (dimensionless).

    Returns:
        Sorted feature indices, (m,) int, 1 <= m <= d.
    """
    weights = np.asarray(weights, dtype=np.float64)
    if weights.ndim != 1 or weights.size == 0 or not np.all(np.isfinite(weights)):
        raise InvalidValueError(
            f"weights must be a non-empty 1-D array of finite numbers, got shape {weights.shape}."
        )
    relevancy = _check_relevancy(relevancy)
    best = int(np.argmax(weights))
    kept = np.flatnonzero(weights > relevancy * weights[best])
    return np.union1d(kept, [best]).astype(np.intp)


def _check_relevancy(relevancy: object) -> float:
    if (
        isinstance(relevancy, bool)
        or not isinstance(relevancy, numbers.Real)
        or not np.isfinite(relevancy)
        or not 0.0 <= float(relevancy) <= 1.0
    ):
        raise InvalidValueError(
            f"relevancy must be a number in [0, 1] (a share of the largest weight), got {relevancy!r}."
        )
    return float(relevancy)


def _check_int(name: str, value: object, low: int, high: int | None = None) -> int:
    if (
        not is_integer(value)
        or value < low
        or (high is not None and value > high)
    ):
        bound = f"in [{low}, {high}]" if high is not None else f">= {low}"
        raise InvalidValueError(f"{name} must be an integer {bound}, got {value!r}.")
    return int(value)


class AffordanceModel(BaseEstimator):
    """Unsupervised affordance learning of Akgun et al. (2009) for one behaviour (see the module docstring).

    Args:
        n_clusters: Nodes k of the 1 x k self-organising map of effects, in [2, 10] (ReliefF is replicated
            for at most 10 classes).
        relevancy: Relevancy threshold r in [0, 1]: keep the features whose ReliefF weight exceeds r x the
            largest weight (always at least the best one).
        n_neighbors: ReliefF's nearest hits, and nearest misses per other category, >= 1.
        som_iterations: Training steps of the map (one effect each), >= 1.
        som_n_init: Maps trained from successive seeds, of which the one of lowest quantization error is kept
            (:class:`SOMClustering`'s ``n_init``), >= 1.
        svm_C: SVM regularisation, > 0.
        svm_gamma: RBF kernel coefficient of the SVM on standardised features: ``"scale"``, ``"auto"`` or > 0.
        random_state: Seed of the map (initial weights and training order): int, generator or None.

    Attributes:
        labels_: Effect category (map node) of each training row, (n_samples,) int.
        cluster_sizes_: Training rows in each category, (n_clusters,) int; a node can stay empty.
        cluster_effects_: Prototype effect of each category, (n_clusters, n_effects), in the effect's units:
            the mean effect of its training rows; for an empty node (never predicted) its map weight, brought
            back to the effect's units.
        feature_weights_: ReliefF weight of every initial feature, (n_features,).
        selected_features_: Indices of the kept initial features, sorted, (m,) int.
        selected_feature_names_: Their names: ``feature_names_in_`` when X had string column names, else
            ``"x0"`` ... ``"x{d-1}"``.
        n_features_in_: Number of initial features.
        feature_names_in_: Initial feature names, when X had string column names.
        n_effects_: Number of effect dimensions (1 when E was 1-D).
        effect_names_: Effect names, when E had string column names (a DataFrame or a named Series).
        effect_scaler_: The fitted standardisation of the effects.
        som_: The fitted :class:`SOMClustering` (on standardised effects).
        classifier_: The fitted SVM pipeline on the selected features; None with a single category.
    """

    def __init__(
        self,
        n_clusters: int = 2,
        relevancy: float = 0.4,
        n_neighbors: int = 10,
        som_iterations: int = 5000,
        som_n_init: int = 1,
        svm_C: float = 1.0,
        svm_gamma: float | str = "scale",
        random_state: int | np.random.RandomState | np.random.Generator | None = None,
    ) -> None:
        self.n_clusters = n_clusters
        self.relevancy = relevancy
        self.n_neighbors = n_neighbors
        self.som_iterations = som_iterations
        self.som_n_init = som_n_init
        self.svm_C = svm_C
        self.svm_gamma = svm_gamma
        self.random_state = random_state

    def _check_params(self) -> None:
        _check_int("n_clusters", self.n_clusters, 2, MULTICLASS_THRESHOLD)
        _check_relevancy(self.relevancy)
        _check_int("n_neighbors", self.n_neighbors, 1)
        _check_int("som_iterations", self.som_iterations, 1)
        _check_int("som_n_init", self.som_n_init, 1)
        C = self.svm_C
        if isinstance(C, bool) or not isinstance(C, numbers.Real) or not np.isfinite(C) or C <= 0:
            raise InvalidValueError(f"svm_C must be a finite number > 0, got {C!r}.")
        gamma = self.svm_gamma
        if isinstance(gamma, str):
            if gamma not in ("scale", "auto"):
                raise InvalidValueError(f"svm_gamma must be 'scale', 'auto' or a number > 0, got {gamma!r}.")
        elif (
            isinstance(gamma, bool)
            or not isinstance(gamma, numbers.Real)
            or not np.isfinite(gamma)
            or gamma <= 0
        ):
            raise InvalidValueError(f"svm_gamma must be 'scale', 'auto' or a number > 0, got {gamma!r}.")

    def fit(self, X: ArrayLike, y: ArrayLike) -> AffordanceModel:
        """Learn effect categories from the effects, and their prediction from the initial features.

        Args:
            X: Initial features, (n_samples, n_features), array or DataFrame, finite.
            y: Effects E, (n_samples, n_effects) or (n_samples,) for a single effect, array or DataFrame,
                finite; in any units (they are standardised).

        Returns:
            self.
        """
        self._check_params()
        effect_names = _column_names(y)
        X, E = validate_data(self, X, y, multi_output=True, y_numeric=True, dtype=np.float64)
        E = np.asarray(E, dtype=np.float64)
        if E.ndim == 1:
            E = E[:, None]
        self.n_effects_ = E.shape[1]
        if effect_names is not None:
            self.effect_names_ = np.asarray(effect_names, dtype=object)

        self.effect_scaler_ = StandardScaler().fit(E)
        self.som_ = SOMClustering(
            n_clusters=self.n_clusters,
            n_iterations=self.som_iterations,
            random_state=som_seed(self.random_state),
            n_init=self.som_n_init,
        ).fit(self.effect_scaler_.transform(E))
        labels = self.som_.labels_
        self.labels_ = labels
        self.cluster_sizes_ = np.bincount(labels, minlength=self.n_clusters).astype(np.int64)
        nodes = self.effect_scaler_.inverse_transform(self.som_.cluster_centers_)
        self.cluster_effects_ = np.array(
            [
                E[labels == c].mean(axis=0) if self.cluster_sizes_[c] else nodes[c]
                for c in range(self.n_clusters)
            ]
        )

        names = getattr(self, "feature_names_in_", None)
        if names is None:
            names = np.array([f"x{i}" for i in range(X.shape[1])], dtype=object)
        categories = np.flatnonzero(self.cluster_sizes_)
        if categories.size >= 2:
            standardised = StandardScaler().fit_transform(X)
            self.feature_weights_ = relieff_weights(standardised, labels, n_neighbors=self.n_neighbors)
            self.selected_features_ = select_features(self.feature_weights_, self.relevancy)
            self.classifier_: Pipeline | None = make_svm(self.svm_C, self.svm_gamma).fit(
                X[:, self.selected_features_], labels
            )
        else:
            self.feature_weights_ = np.zeros(X.shape[1])
            self.selected_features_ = select_features(self.feature_weights_, self.relevancy)
            self.classifier_ = None
        self.selected_feature_names_ = np.asarray(names, dtype=object)[self.selected_features_]
        return self

    def predict(self, X: ArrayLike) -> np.ndarray:
        """Effect category of each row of initial features ``X`` (n_samples, n_features): (n_samples,) int."""
        check_is_fitted(self)
        X = validate_data(self, X, reset=False, dtype=np.float64)
        if self.classifier_ is None:
            return np.full(X.shape[0], int(np.argmax(self.cluster_sizes_)), dtype=np.int64)
        return self.classifier_.predict(X[:, self.selected_features_]).astype(np.int64)

    def predict_effect(self, X: ArrayLike) -> EffectPrediction:
        """Effect category and its prototype effect (in the effect's units) for each row of ``X``."""
        category = self.predict(X)
        return EffectPrediction(category=category, effect=self.cluster_effects_[category])

    def categorize_effects(self, y: ArrayLike) -> np.ndarray:
        """Category the fitted map gives observed effects ``y`` (n_samples, n_effects) or (n_samples,)."""
        check_is_fitted(self)
        E = np.asarray(y, dtype=np.float64)
        if E.ndim == 1:
            E = E[:, None]
        if E.ndim != 2 or E.shape[1] != self.n_effects_:
            raise InvalidValueError(f"effects must have {self.n_effects_} column(s), got shape {np.shape(y)}.")
        if not np.all(np.isfinite(E)):
            raise InvalidValueError("effects contain NaN or inf; expected finite values.")
        return self.som_.predict(self.effect_scaler_.transform(E))

    def score(self, X: ArrayLike, y: ArrayLike) -> float:
        """Accuracy in [0, 1] of the categories predicted from ``X`` against those of the effects ``y``."""
        predicted = self.predict(X)
        observed = self.categorize_effects(y)
        if observed.shape != predicted.shape:
            raise InvalidValueError(f"X has {predicted.size} rows but y has {observed.size}.")
        return float(np.mean(predicted == observed))

    def __sklearn_tags__(self) -> Tags:
        """scikit-learn's tags: the effects (``y``) are required and may have one or many columns."""
        tags = super().__sklearn_tags__()
        tags.target_tags.required = True
        tags.target_tags.single_output = True
        tags.target_tags.multi_output = True
        return tags


def _column_names(y: object) -> list[str] | None:
    """String column names of a DataFrame, or the name of a named Series; None otherwise."""
    columns = getattr(y, "columns", None)
    if columns is not None:
        names = list(columns)
        return [str(c) for c in names] if all(isinstance(c, str) for c in names) else None
    name = getattr(y, "name", None)
    if getattr(y, "ndim", None) == 1 and isinstance(name, str):
        return [name]
    return None
