"""ReliefF feature weights, vectorised, equal to skrebate's ``ReliefF`` on the cases this project meets.

Akgun et al. 2009, section IV: "ReliefF ... gives weights to the features according to their contribution in
classification"; the features whose weight exceeds ``relevancy x (largest weight)`` are kept. The reference
implementation is scikit-rebate 0.8.4 (``skrebate.ReliefF(n_neighbors=10)``), which takes about 8 s on
1000 x 49 because it walks every instance, neighbour and feature in Python. :func:`relieff_weights` gives the
same numbers (to rounding, about 1e-15 relative) in tens of milliseconds by replicating skrebate's algorithm
exactly:

- Feature types: a feature with at most ``discrete_threshold`` (10) distinct values is discrete, any other
  is continuous. The data are "continuous", "discrete" or "mixed" accordingly.
- Distances between instances (used only to find neighbours), computed with the same scipy calls so that
  ties fall the same way: continuous features min-max scaled to [0, 1] and summed as a Manhattan distance;
  discrete features as a Hamming fraction; for mixed data ``hamming x n_features + manhattan``. An
  instance's distance to itself is ``sys.maxsize``, so it sorts last.
- Neighbours: for every instance, the ``n_neighbors`` nearest instances of its own class (hits) and of every
  other class (misses), in the order of ``numpy.argsort`` of its distance row. A class with ``n_neighbors``
  or fewer other members gives all of them, and the instance itself is then counted as one of its own hits
  (skrebate reaches it last); its difference to itself is 0.
- Feature differences: discrete features 0 or 1 (different values); continuous features
  ``|a - b| / (max - min)``, and for mixed data 1 when ``|a - b|`` exceeds the feature's standard deviation
  (skrebate's simplified ramp).
- Scores, with ``n`` instances: two classes: ``(-sum(hit diffs) / n_hits + sum(miss diffs) / n_misses) / n``.
  Three to ten classes: ``(-sum(hit diffs) / n_hits + sum_c (C - 1) * (m_c / M) * sum(diffs to class c) /
  M) / n`` with ``m_c`` the misses of class ``c`` among the neighbours, ``M`` all misses and ``C`` the
  number of classes. skrebate weighs each miss class by its observed share among the neighbours, not by its
  prior (its class-prior map is built but never read); this module does the same.

One deliberate difference: skrebate counts a constant feature (a single value) as discrete, so one constant
column among continuous ones switches the whole data set to the mixed mode, where any continuous difference
larger than the feature's standard deviation counts as 1 and the weights saturate. Here a constant feature has
weight 0 and takes no part in choosing the data type or in the distances: the weights are skrebate's on the data
without the constant columns (and equal to skrebate's outright when no column is constant).

Not replicated, and refused with a ``ValueError``: missing values (skrebate's missing-data distances), more
than ``multiclass_threshold`` (10) classes (skrebate's continuous-endpoint ReliefF), a single class, and
non-integer ``n_neighbors`` (skrebate's "fraction of the data" form).

Neighbour search uses :func:`numpy.partition` per class; only a row whose ``n_neighbors``-th and next-nearest
members of a class are at exactly the same distance is ranked by a full :func:`numpy.argsort` of its distance
row, as skrebate ranks it, so ties are broken the same way.
"""

from __future__ import annotations

import sys
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial.distance import pdist, squareform
from sklearn.base import BaseEstimator
from sklearn.utils.validation import check_is_fitted, validate_data

from affordance_env.values import is_integer
from affordance_learning.common.exceptions import InvalidValueError
from affordance_learning.common.validation import first_non_finite

#: Distance skrebate gives an instance to itself, so that it sorts after every other instance.
SELF_DISTANCE = float(sys.maxsize)
#: skrebate's default: features with at most this many distinct values are discrete.
DISCRETE_THRESHOLD = 10
#: skrebate's default: more distinct labels than this make the endpoint continuous (not replicated here).
MULTICLASS_THRESHOLD = 10
#: Number of (instance, neighbour) pairs whose feature differences are held in memory at once.
_PAIR_CHUNK = 32768

DataType = Literal["continuous", "discrete", "mixed", "constant"]


def _check_n_neighbors(n_neighbors: object) -> int:
    if not is_integer(n_neighbors) or n_neighbors < 1:
        raise InvalidValueError(
            f"n_neighbors must be an integer >= 1 (neighbours per class), got {n_neighbors!r}; skrebate's "
            "float form (a fraction of the instances) is not replicated."
        )
    return int(n_neighbors)


def _check_features(X: ArrayLike) -> np.ndarray:
    X = np.asarray(X)
    if X.ndim != 2:
        raise InvalidValueError(f"X must be a 2-D array (n_samples, n_features), got shape {X.shape}.")
    if X.shape[0] < 2 or X.shape[1] < 1:
        raise InvalidValueError(f"X needs at least 2 rows and 1 feature, got shape {X.shape}.")
    if not (np.issubdtype(X.dtype, np.number) or X.dtype == bool) or np.iscomplexobj(X):
        raise InvalidValueError(f"X must hold real numbers, got dtype {X.dtype}.")
    X = X.astype(np.float64)
    found = first_non_finite(X)
    if found:
        count, row, col, value = found
        raise InvalidValueError(
            f"X has {count} non-finite value(s), the first X[{row}, {col}] = {value}; "
            "missing data (skrebate's NaN handling) is not replicated, expected finite values."
        )
    return X


class ReliefFScorer:
    """What ReliefF needs from the instances alone, so that many labelings of the same rows are cheap.

    The feature types, ranges, standard deviations and the instance distance matrix depend only on ``X``;
    :meth:`weights` then scores any labeling of those rows. The experiment scores the same training rows
    against the clusters of every k this way.

    Args:
        X: Instances, (n_samples, n_features), finite; any units (features are scaled by their range).
        discrete_threshold: Features with at most this many distinct values are discrete.
    """

    def __init__(self, X: ArrayLike, *, discrete_threshold: int = DISCRETE_THRESHOLD) -> None:
        if not is_integer(discrete_threshold):
            raise InvalidValueError(f"discrete_threshold must be an integer, got {discrete_threshold!r}.")
        X = _check_features(X)
        self.X = X
        self.n_samples, self.n_features = X.shape
        n_unique = np.array([np.unique(X[:, j]).size for j in range(self.n_features)])
        #: True for the features with a single value: weight 0, and no part in the data type or distances.
        self.constant = n_unique == 1
        #: True for the features treated as discrete, (n_features,).
        self.discrete = (n_unique <= discrete_threshold) & ~self.constant
        continuous = ~self.discrete & ~self.constant
        self._continuous = continuous
        if self.constant.all():  # nothing varies, nothing separates the classes: every weight is 0
            self.data_type: DataType = "constant"
        elif not self.discrete.any():
            self.data_type = "continuous"
        elif not continuous.any():
            self.data_type = "discrete"
        else:
            self.data_type = "mixed"
        # Per-column statistics computed the way skrebate computes them (column views, population std).
        self.minimum = np.array([np.min(X[:, j]) if continuous[j] else 0.0 for j in range(self.n_features)])
        self.maximum = np.array([np.max(X[:, j]) if continuous[j] else 0.0 for j in range(self.n_features)])
        self.range = self.maximum - self.minimum
        self.std = np.array([np.std(X[:, j]) if continuous[j] else 0.0 for j in range(self.n_features)])
        self.distances = self._distance_matrix()
        self._ranks: dict[int, np.ndarray] = {}

    def _distance_matrix(self) -> np.ndarray:
        """Instance distances as skrebate's ``_distarray_no_missing`` on the non-constant features, self-distance
        ``sys.maxsize``."""
        cidx = np.flatnonzero(self._continuous)
        didx = np.flatnonzero(self.discrete)
        if self.data_type == "constant":
            dist = np.zeros((self.n_samples, self.n_samples))
        elif self.data_type == "discrete":
            dist = squareform(pdist(self.X[:, didx], metric="hamming"))
        else:
            xc = (self.X[:, cidx] - self.minimum[cidx]) / self.range[cidx]
            c_dist = squareform(pdist(xc, metric="cityblock"))
            if self.data_type == "mixed":
                d_dist = squareform(pdist(self.X[:, didx], metric="hamming"))
                dist = np.add(d_dist * (cidx.size + didx.size), c_dist)
            else:
                dist = c_dist
        np.fill_diagonal(dist, SELF_DISTANCE)
        return dist

    def _rank_row(self, i: int) -> np.ndarray:
        """Position of every instance in skrebate's ``argsort`` of row ``i`` of the distance matrix."""
        rank = self._ranks.get(i)
        if rank is None:
            order = np.argsort(np.array(self.distances[i]))
            rank = np.empty(self.n_samples, dtype=np.intp)
            rank[order] = np.arange(self.n_samples)
            self._ranks[i] = rank
        return rank

    def _neighbour_pairs(self, codes: np.ndarray, n_classes: int, k: int) -> tuple[np.ndarray, np.ndarray]:
        """(instance, neighbour) index pairs: the k nearest members of every class for every instance."""
        rows: list[np.ndarray] = []
        cols: list[np.ndarray] = []
        n = self.n_samples
        for c in range(n_classes):
            members = np.flatnonzero(codes == c)
            if members.size <= k:
                # Every member is a neighbour; the instance itself counts too (skrebate reaches it last).
                rows.append(np.repeat(np.arange(n), members.size))
                cols.append(np.tile(members, n))
                continue
            sub = self.distances[:, members]
            nearest = np.argpartition(sub, (k - 1, k), axis=1)
            edge = np.take_along_axis(sub, nearest[:, k - 1 : k + 1], axis=1)
            chosen = nearest[:, :k]
            for i in np.flatnonzero(edge[:, 0] == edge[:, 1]):
                # A tie across the k-th place: rank as skrebate's argsort of the whole row does.
                chosen[i] = np.argsort(self._rank_row(int(i))[members])[:k]
            rows.append(np.repeat(np.arange(n), k))
            cols.append(members[chosen].ravel())
        return np.concatenate(rows), np.concatenate(cols)

    def _weighted_differences(
        self, pair_weight: np.ndarray, rows: np.ndarray, cols: np.ndarray
    ) -> np.ndarray:
        """``sum over pairs of pair_weight x (skrebate's difference of the pair)`` per feature, (n_features,).

        A pair's difference is 0 or 1 for a discrete feature (values differ), ``|a - b| / (max - min)`` for a
        continuous one, and 1 instead when the data are mixed and ``|a - b|`` exceeds the feature's standard
        deviation.
        """
        total = np.zeros(self.n_features)
        cont = self._continuous
        for start in range(0, rows.size, _PAIR_CHUNK):
            stop = start + _PAIR_CHUNK
            raw = np.take(self.X, rows[start:stop], axis=0)
            raw -= np.take(self.X, cols[start:stop], axis=0)
            np.abs(raw, out=raw)
            w = pair_weight[start:stop]
            if self.data_type in ("continuous", "mixed"):
                spread = raw[:, cont]
                if self.data_type == "mixed":
                    spread = np.where(spread > self.std[cont], self.range[cont], spread)
                total[cont] += w @ spread
            if self.data_type in ("discrete", "mixed"):
                # Exact for finite floats: a - b == 0 exactly when a == b.
                total[self.discrete] += w @ (raw[:, self.discrete] != 0).astype(np.float64)
        total[cont] /= self.range[cont]
        return total

    def weights(self, y: ArrayLike, n_neighbors: int = 10) -> np.ndarray:
        """ReliefF weight of every feature for the labels ``y``.

        Args:
            y: Class label of every instance, (n_samples,); 2 to 10 distinct values.
            n_neighbors: Nearest hits, and nearest misses per other class, used for each instance.

        Returns:
            Weights, (n_features,), dimensionless; larger means more relevant. In [-1, 1] for two classes;
            with C classes skrebate's miss normalisation can reach up to C - 1 when a class has fewer
            members than ``n_neighbors``.
        """
        k = _check_n_neighbors(n_neighbors)
        y = np.asarray(y)
        if y.ndim != 1 or y.shape[0] != self.n_samples:
            raise InvalidValueError(
                f"y must be 1-D with one label per row of X ({self.n_samples}), got shape {y.shape}."
            )
        if y.dtype.kind == "f" and np.isnan(y).any():
            raise InvalidValueError("y contains NaN; expected a class label for every instance.")
        classes, codes = np.unique(y, return_inverse=True)
        n_classes = classes.size
        if n_classes < 2:
            raise InvalidValueError(f"ReliefF needs at least 2 classes, but every label is {classes[0]!r}.")
        if n_classes > MULTICLASS_THRESHOLD:
            raise InvalidValueError(
                f"y has {n_classes} classes; skrebate treats more than {MULTICLASS_THRESHOLD} distinct "
                "labels as a continuous endpoint, which is not replicated here. Expected 2 to 10 classes."
            )
        rows, cols = self._neighbour_pairs(codes, n_classes, k)
        hit = codes[rows] == codes[cols]
        n = self.n_samples
        n_hits = np.bincount(rows[hit], minlength=n).astype(np.float64)
        with np.errstate(divide="ignore"):
            hit_weight = -1.0 / n_hits[rows]
            if n_classes == 2:
                n_misses = np.bincount(rows[~hit], minlength=n).astype(np.float64)
                miss_weight = 1.0 / n_misses[rows]
            else:
                per_class = np.bincount(rows * n_classes + codes[cols], minlength=n * n_classes).reshape(
                    n, -1
                )
                per_class[np.arange(n), codes] = 0
                n_misses = per_class.sum(axis=1).astype(np.float64)
                miss_weight = per_class[rows, codes[cols]] * (n_classes - 1) / n_misses[rows] ** 2
        pair_weight = np.where(hit, hit_weight, miss_weight)
        return self._weighted_differences(pair_weight, rows, cols) / n


def relieff_weights(
    X: ArrayLike, y: ArrayLike, n_neighbors: int = 10, *, discrete_threshold: int = DISCRETE_THRESHOLD
) -> np.ndarray:
    """ReliefF weights of the features of ``X`` for the class labels ``y``, as skrebate's ``ReliefF``.

    Equal to ``skrebate.ReliefF(n_neighbors=n_neighbors).fit(X, y).feature_importances_`` to about 1e-15
    relative, for finite data with continuous and/or discrete features and 2 to 10 classes; see the module
    docstring for the algorithm and what is refused.

    Args:
        X: Instances, (n_samples, n_features), finite; any units.
        y: Class labels, (n_samples,), 2 to 10 distinct values.
        n_neighbors: Nearest hits, and nearest misses per other class, used for each instance.
        discrete_threshold: Features with at most this many distinct values are discrete.

    Returns:
        Weights, (n_features,), dimensionless: in [-1, 1] for two classes, up to C - 1 with C classes when a
        class has fewer members than ``n_neighbors`` (see :meth:`ReliefFScorer.weights`).
    """
    return ReliefFScorer(X, discrete_threshold=discrete_threshold).weights(y, n_neighbors)


class ReliefF(BaseEstimator):
    """scikit-learn style ReliefF feature weighting (skrebate's algorithm, vectorised).

    Args:
        n_neighbors: Nearest hits, and nearest misses per other class, used for each instance.
        discrete_threshold: Features with at most this many distinct values are discrete.

    Attributes:
        feature_importances_: ReliefF weight of each feature, (n_features,).
        top_features_: Feature indices from the most to the least relevant, (n_features,).
        n_features_in_: Number of features seen in ``fit``.
        feature_names_in_: Column names, when ``X`` has string column names.
    """

    def __init__(self, n_neighbors: int = 10, discrete_threshold: int = DISCRETE_THRESHOLD) -> None:
        self.n_neighbors = n_neighbors
        self.discrete_threshold = discrete_threshold

    def fit(self, X: ArrayLike, y: ArrayLike) -> ReliefF:
        """Weigh the features of ``X`` by how well they separate the classes ``y``; returns ``self``."""
        X, y = validate_data(self, X, y, dtype=np.float64)
        self.feature_importances_ = relieff_weights(
            X, y, self.n_neighbors, discrete_threshold=self.discrete_threshold
        )
        self.top_features_ = np.argsort(-self.feature_importances_, kind="stable")
        return self

    def transform(self, X: ArrayLike) -> np.ndarray:
        """Columns of ``X`` ordered from the most to the least relevant feature."""
        check_is_fitted(self)
        X = validate_data(self, X, reset=False, dtype=np.float64)
        return X[:, self.top_features_]
