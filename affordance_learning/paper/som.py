"""A 1 x k Kohonen self-organising map (minisom) as a scikit-learn clusterer.

Akgun et al. 2009, section IV: the effects are clustered with a self-organising map of 1-D neighbourhood;
its number of nodes k is a parameter of the model, and every node is an effect category.
"""

from __future__ import annotations

import numbers

import numpy as np
from minisom import MiniSom
from numpy.typing import ArrayLike
from sklearn.base import BaseEstimator, ClusterMixin
from sklearn.utils.validation import check_is_fitted, validate_data

from affordance_env.values import is_integer
from affordance_learning.common.exceptions import InvalidValueError

#: Largest seed minisom's ``numpy.random.RandomState`` accepts.
_MAX_SEED = 2**32 - 1


def som_seed(random_state: int | np.random.RandomState | np.random.Generator | None) -> int | None:
    """The ``random_seed`` handed to minisom for a scikit-learn style ``random_state``.

    An integer is used as it is (so ``SOMClustering(random_state=s)`` trains exactly as
    ``MiniSom(..., random_seed=s)``); a generator gives a seed drawn from it; None gives None (fresh entropy).
    """
    if random_state is None:
        return None
    if is_integer(random_state):
        if not 0 <= int(random_state) <= _MAX_SEED:
            raise InvalidValueError(f"random_state must be an integer in [0, 2**32 - 1], got {random_state!r}.")
        return int(random_state)
    if isinstance(random_state, np.random.RandomState):
        return int(random_state.randint(0, 2**31 - 1))
    if isinstance(random_state, np.random.Generator):
        return int(random_state.integers(0, 2**31 - 1))
    raise InvalidValueError(
        f"random_state must be None, an integer, a numpy RandomState or Generator, got {random_state!r}."
    )


def _distances(X: np.ndarray, centers: np.ndarray) -> np.ndarray:
    """Euclidean distance of every row to every node, (n_samples, n_clusters), in the units of ``X``."""
    return np.linalg.norm(X[:, None, :] - centers[None, :, :], axis=-1)


class SOMClustering(ClusterMixin, BaseEstimator):
    """Cluster rows with a one-dimensional (1 x ``n_clusters``) self-organising map, trained by minisom.

    The map's node weights start at random unit vectors and are trained for ``n_iterations`` steps of one
    row each, the rows taken in a random order (minisom's ``train(random_order=True)``); the initial weights
    and the order both come from minisom's ``random_seed``, which ``random_state`` sets. Learning rate and
    neighbourhood radius decay as ``value / (1 + 2 t / n_iterations)`` (minisom's asymptotic decay); the
    neighbourhood is Gaussian over the node index.

    Every node is a cluster, and a row belongs to the node nearest to it (Euclidean). Node indices follow the
    map, so neighbouring clusters hold similar rows; a node that wins no training row stays empty, so
    ``labels_`` may skip values.

    Args:
        n_clusters: Number of map nodes k, >= 1 (the learning model uses k >= 2).
        n_iterations: Training steps (one row each), >= 1.
        sigma: Initial radius of the Gaussian neighbourhood [nodes], > 0.
        learning_rate: Initial learning rate, > 0.
        random_state: Seed of the initial weights and of the training order (int, generator or None).
        n_init: Maps trained, each from its own seed; the one whose rows lie nearest to their nodes (lowest
            quantization error) is kept, as k-means keeps its run of lowest inertia (scikit-learn's ``n_init``).
            An integer ``random_state`` s seeds them with s, s + 1, ...; a generator draws their seeds.
            A map's training is a stochastic descent from random weights, and one run can settle with two kinds
            of effect in one node and a few outliers in another.

    Attributes:
        cluster_centers_: Node weights, (n_clusters, n_features), in the units of ``X``.
        labels_: Node of each training row, (n_samples,) int.
        quantization_error_: Mean distance of the training rows to their node, in the units of ``X``.
        seed_: minisom's ``random_seed`` of the map kept (None when unseeded).
        n_iter_: Training steps run.
        n_features_in_: Number of features seen in ``fit``.
        feature_names_in_: Column names, when ``X`` has string column names.
    """

    def __init__(
        self,
        n_clusters: int = 2,
        n_iterations: int = 5000,
        sigma: float = 1.0,
        learning_rate: float = 0.5,
        random_state: int | np.random.RandomState | np.random.Generator | None = None,
        n_init: int = 1,
    ) -> None:
        self.n_clusters = n_clusters
        self.n_iterations = n_iterations
        self.sigma = sigma
        self.learning_rate = learning_rate
        self.random_state = random_state
        self.n_init = n_init

    def _check_params(self) -> None:
        for name, low in (("n_clusters", 1), ("n_iterations", 1), ("n_init", 1)):
            value = getattr(self, name)
            if not is_integer(value) or value < low:
                raise InvalidValueError(f"{name} must be an integer >= {low}, got {value!r}.")
        for name in ("sigma", "learning_rate"):
            value = getattr(self, name)
            if (
                isinstance(value, bool)
                or not isinstance(value, numbers.Real)
                or not np.isfinite(value)
                or value <= 0
            ):
                raise InvalidValueError(f"{name} must be a finite number > 0, got {value!r}.")

    def fit(self, X: ArrayLike, y: object = None) -> SOMClustering:
        """Train the map on the rows of ``X`` (n_samples, n_features) and label them; returns ``self``.

        ``y`` is ignored (present for the scikit-learn API).
        """
        self._check_params()
        X = validate_data(self, X, dtype=np.float64)
        best = None
        for seed in self._seeds():
            som = MiniSom(
                1,
                int(self.n_clusters),
                X.shape[1],
                sigma=float(self.sigma),
                learning_rate=float(self.learning_rate),
                random_seed=seed,
            )
            som.train(X, int(self.n_iterations), random_order=True)
            centers = np.array(som.get_weights()[0], dtype=np.float64)
            distances = _distances(X, centers)
            labels = np.argmin(distances, axis=1).astype(np.int64)
            error = float(distances[np.arange(len(X)), labels].mean())
            if best is None or error < best[0]:  # the first of equals
                best = (error, seed, centers, labels)
        self.quantization_error_, self.seed_, self.cluster_centers_, self.labels_ = best
        self.n_iter_ = int(self.n_iterations)
        return self

    def _seeds(self) -> list[int | None]:
        """minisom's ``random_seed`` of each of the ``n_init`` maps."""
        first = som_seed(self.random_state)
        if first is None or isinstance(self.random_state, np.random.RandomState | np.random.Generator):
            return [first] + [som_seed(self.random_state) for _ in range(int(self.n_init) - 1)]
        return [(first + i) % (_MAX_SEED + 1) for i in range(int(self.n_init))]

    def predict(self, X: ArrayLike) -> np.ndarray:
        """Nearest node of every row of ``X``, (n_samples,) int."""
        check_is_fitted(self)
        X = validate_data(self, X, dtype=np.float64, reset=False)
        return np.argmin(_distances(X, self.cluster_centers_), axis=1).astype(np.int64)
