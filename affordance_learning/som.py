"""A 1 x k Kohonen self-organising map (minisom) as a scikit-learn clusterer."""

from __future__ import annotations

import numpy as np
from minisom import MiniSom
from sklearn.base import BaseEstimator, ClusterMixin
from sklearn.utils.validation import check_is_fitted, check_random_state, validate_data


class SOMClustering(ClusterMixin, BaseEstimator):
    """Cluster rows with a one-dimensional (1 x ``n_clusters``) self-organising map.

    Each map node is a cluster; a row belongs to its best-matching node. Nodes that win no training row stay
    empty, so ``labels_`` may use fewer than ``n_clusters`` values.

    Args:
        n_clusters: Number of map nodes, k >= 1.
        n_iterations: Training iterations (one random row each).
        sigma: Neighbourhood radius at the start [nodes]; default ``max(k / 4, 0.5)``.
        learning_rate: Initial learning rate.
        random_state: Seed of the initial weights and of the order of training rows.
    """

    def __init__(
        self,
        n_clusters: int = 2,
        n_iterations: int = 2000,
        sigma: float | None = None,
        learning_rate: float = 0.5,
        random_state=None,
    ) -> None:
        self.n_clusters = n_clusters
        self.n_iterations = n_iterations
        self.sigma = sigma
        self.learning_rate = learning_rate
        self.random_state = random_state

    def fit(self, X, y=None):
        """Train the map on ``X`` (n, d) and label every row."""
        X = validate_data(self, X, dtype=np.float64)
        if not isinstance(self.n_clusters, int | np.integer) or self.n_clusters < 1:
            raise ValueError(f"n_clusters must be an integer >= 1, got {self.n_clusters!r}.")
        if not isinstance(self.n_iterations, int | np.integer) or self.n_iterations < 1:
            raise ValueError(f"n_iterations must be a positive integer, got {self.n_iterations!r}.")
        rng = check_random_state(self.random_state)
        seed = int(rng.integers(0, 2**31 - 1)) if hasattr(rng, "integers") else int(rng.randint(0, 2**31 - 1))
        sigma = max(self.n_clusters / 4.0, 0.5) if self.sigma is None else float(self.sigma)
        som = MiniSom(1, int(self.n_clusters), X.shape[1], sigma=sigma, learning_rate=self.learning_rate,
                      random_seed=seed)
        som.random_weights_init(X)
        # One random row per iteration, drawn from the seeded generator (as minisom's train(random_order=True)).
        order = np.random.default_rng(seed).integers(0, X.shape[0], int(self.n_iterations))
        for t, row in enumerate(order):
            som.update(X[row], som.winner(X[row]), t, int(self.n_iterations))
        self.cluster_centers_ = som.get_weights()[0].copy()
        self.labels_ = self.predict(X)
        return self

    def predict(self, X) -> np.ndarray:
        """Index of the best-matching node of every row of ``X``."""
        check_is_fitted(self, "cluster_centers_")
        X = validate_data(self, X, dtype=np.float64, reset=False)
        d2 = ((X[:, None, :] - self.cluster_centers_[None, :, :]) ** 2).sum(axis=2)
        return np.argmin(d2, axis=1)
