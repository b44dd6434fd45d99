"""Measures of the paper and of clustering quality: uniformity, purity, adjusted Rand index."""

from __future__ import annotations

import numpy as np
from sklearn.metrics import adjusted_rand_score


def _pair(clusters, labels, name: str) -> tuple[np.ndarray, np.ndarray]:
    clusters = np.asarray(clusters)
    labels = np.asarray(labels)
    if clusters.ndim != 1 or clusters.shape != labels.shape or clusters.size == 0:
        raise ValueError(
            f"clusters and {name} must be non-empty 1-D arrays of the same length, got shapes "
            f"{clusters.shape} and {labels.shape}."
        )
    return clusters, labels


def uniformity(clusters, success) -> float:
    """The paper's uniformity: U = 100 * sum over clusters c of |S_c - F_c| / T [%].

    ``S_c`` and ``F_c`` are the numbers of successful (rolled) and failed interactions in cluster ``c``, ``T``
    all interactions. 100 when every cluster holds only successes or only failures; 0 when every cluster
    holds as many of each.
    """
    clusters, success = _pair(clusters, success, "success")
    if success.dtype != bool:
        values = set(np.unique(success).tolist())
        if not values <= {0, 1}:
            raise ValueError(f"success must be boolean (or 0/1), got values {sorted(values)}.")
        success = success.astype(bool)
    _, index = np.unique(clusters, return_inverse=True)
    s = np.bincount(index, weights=success.astype(float))
    f = np.bincount(index, weights=(~success).astype(float))
    return float(100.0 * np.abs(s - f).sum() / clusters.size)


def cluster_purity(clusters, labels) -> float:
    """Share of rows whose label is their cluster's most common label [0, 1]."""
    clusters, labels = _pair(clusters, labels, "labels")
    _, ci = np.unique(clusters, return_inverse=True)
    _, li = np.unique(labels, return_inverse=True)
    table = np.zeros((ci.max() + 1, li.max() + 1))
    np.add.at(table, (ci, li), 1)
    return float(table.max(axis=1).sum() / clusters.size)


def adjusted_rand(clusters, labels) -> float:
    """Adjusted Rand index of the clusters against known labels (1: identical partitions, ~0: chance)."""
    clusters, labels = _pair(clusters, labels, "labels")
    return float(adjusted_rand_score(labels, clusters))
