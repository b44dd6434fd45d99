"""The paper's learning model for one behaviour: SOM of effects -> ReliefF -> SVM.

``fit(X_initial, E_effect)`` (scikit-learn's ``fit(X, y)``, with the effects as ``y``):

1. standardise the effects (each effect dimension to zero mean and unit variance; constant dimensions stay 0);
2. cluster them with a 1 x k self-organising map: the cluster of each interaction is its effect category;
3. weigh the initial features with ReliefF against those categories, keep the features whose weight exceeds
   ``relevancy`` x the largest weight (always at least the best one): perceptual economy;
4. train a multi-class RBF SVM (on standardised selected features) to predict the category from the object's
   look before the interaction.

``predict_effect(X)`` answers with the category and the category's prototype effect: the mean effect of its
training members, in the effect's own units.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from sklearn.base import BaseEstimator
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler
from sklearn.svm import SVC
from sklearn.utils.validation import check_is_fitted, check_random_state, validate_data

from affordance_learning.relieff import relieff_weights
from affordance_learning.som import SOMClustering


@dataclass(frozen=True)
class EffectPrediction:
    """What :meth:`AffordanceModel.predict_effect` predicts.

    Attributes:
        category: Effect category of each row, (n,) int.
        effect: Prototype effect of that category, (n, n_effects), in the effect's units.
    """

    category: np.ndarray
    effect: np.ndarray


class AffordanceModel(BaseEstimator):
    """Unsupervised affordance learning of Akgun et al. (2009) for one behaviour.

    Args:
        n_clusters: Nodes of the 1 x k self-organising map of effects (k >= 1; k = 1 is one category).
        relevancy: Relevancy threshold r in [0, 1]: keep the features whose ReliefF weight exceeds r x the largest
            weight.
        n_neighbors: ReliefF's nearest hits and misses per class.
        som_iterations: Training iterations of the map.
        svm_C: Regularisation of the SVM.
        svm_gamma: RBF width of the SVM (``"scale"`` or a positive float).
        random_state: Seed of the map (initial weights and training order).

    Fitted attributes:
        labels_: Effect category of each training row.
        n_categories_: Number of categories that hold training rows.
        feature_weights_: ReliefF weight of every initial feature.
        selected_features_: Indices of the kept initial features.
        selected_feature_names_: Their names (``feature_names_in_`` when X had column names, else ``x0``, ...).
        cluster_effects_: (n_clusters, n_effects) prototype effect of each category (the mean effect of its
            members; the map node, in effect units, for a node that won no row).
        effect_names_: Names of the effect dimensions (E's columns, or ``e0``, ...).
        som_: The fitted :class:`SOMClustering`; effect_scaler_: its standardisation; svm_: the classifier.
    """

    def __init__(
        self,
        n_clusters: int = 2,
        relevancy: float = 0.4,
        n_neighbors: int = 10,
        som_iterations: int = 2000,
        svm_C: float = 10.0,
        svm_gamma="scale",
        random_state=None,
    ) -> None:
        self.n_clusters = n_clusters
        self.relevancy = relevancy
        self.n_neighbors = n_neighbors
        self.som_iterations = som_iterations
        self.svm_C = svm_C
        self.svm_gamma = svm_gamma
        self.random_state = random_state

    def _check_params(self) -> None:
        if not isinstance(self.n_clusters, int | np.integer) or self.n_clusters < 1:
            raise ValueError(f"n_clusters must be an integer >= 1, got {self.n_clusters!r}.")
        if not isinstance(self.relevancy, int | float | np.number) or not 0.0 <= float(self.relevancy) <= 1.0:
            raise ValueError(f"relevancy must be a number in [0, 1], got {self.relevancy!r}.")
        if not isinstance(self.n_neighbors, int | np.integer) or self.n_neighbors < 1:
            raise ValueError(f"n_neighbors must be a positive integer, got {self.n_neighbors!r}.")

    def fit(self, X, y):
        """Learn effect categories from the effects and their prediction from the initial features.

        Args:
            X: Initial features, (n, n_features), array or DataFrame.
            y: Effects, (n, n_effects) or (n,), array or DataFrame (named ``y`` for scikit-learn's contract).
        """
        self._check_params()
        effect_columns = getattr(y, "columns", None)
        X, E = validate_data(self, X, y, multi_output=True, y_numeric=True, dtype=np.float64)
        E = np.asarray(E, dtype=np.float64)
        if E.ndim == 1:
            E = E[:, None]
        self.effect_names_ = (
            [str(c) for c in effect_columns] if effect_columns is not None else [f"e{i}" for i in range(E.shape[1])]
        )
        rng = check_random_state(self.random_state)
        seed = int(rng.randint(0, 2**31 - 1))

        self.effect_scaler_ = StandardScaler().fit(E)
        Z = self.effect_scaler_.transform(E)
        self.som_ = SOMClustering(self.n_clusters, n_iterations=self.som_iterations, random_state=seed).fit(Z)
        labels = self.som_.labels_
        self.labels_ = labels
        categories = np.unique(labels)
        self.n_categories_ = len(categories)
        nodes = self.effect_scaler_.inverse_transform(self.som_.cluster_centers_)
        self.cluster_effects_ = np.array(
            [E[labels == c].mean(axis=0) if np.any(labels == c) else nodes[c] for c in range(self.n_clusters)]
        )

        n_features = X.shape[1]
        if self.n_categories_ >= 2 and len(X) >= 3:
            k = int(min(self.n_neighbors, len(X) - 1))
            self.feature_weights_ = relieff_weights(X, labels, n_neighbors=k)
        else:  # one category: nothing to separate
            self.feature_weights_ = np.zeros(n_features)
        best = int(np.argmax(self.feature_weights_))
        top = self.feature_weights_[best]
        selected = np.flatnonzero(self.feature_weights_ > float(self.relevancy) * top) if top > 0 else np.array([])
        self.selected_features_ = np.union1d(selected, [best]).astype(int)
        names = list(getattr(self, "feature_names_in_", [f"x{i}" for i in range(n_features)]))
        self.selected_feature_names_ = [str(names[i]) for i in self.selected_features_]

        if self.n_categories_ >= 2:
            self.svm_ = make_pipeline(
                StandardScaler(), SVC(C=self.svm_C, gamma=self.svm_gamma, random_state=seed)
            ).fit(X[:, self.selected_features_], labels)
        else:  # a single category: every prediction is that category
            self.svm_ = None
        self.single_category_ = int(categories[0])
        return self

    def _transform(self, X) -> np.ndarray:
        check_is_fitted(self, "selected_features_")
        X = validate_data(self, X, reset=False, dtype=np.float64)
        return X[:, self.selected_features_]

    def predict(self, X) -> np.ndarray:
        """Effect category of each row of ``X`` (initial features)."""
        Xs = self._transform(X)
        if self.svm_ is None:
            return np.full(len(Xs), self.single_category_, dtype=int)
        return self.svm_.predict(Xs).astype(int)

    def predict_effect(self, X) -> EffectPrediction:
        """Effect category and its prototype effect (in the effect's units) for each row of ``X``."""
        category = self.predict(X)
        return EffectPrediction(category=category, effect=self.cluster_effects_[category])

    def score(self, X, y) -> float:
        """Accuracy of the categories predicted from ``X`` against those the map gives the effects ``y``."""
        predicted = self.predict(X)
        E = np.asarray(y, dtype=np.float64)
        if E.ndim == 1:
            E = E[:, None]
        target = self.som_.predict(self.effect_scaler_.transform(E))
        return float(np.mean(predicted == target))

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.target_tags.required = True
        tags.target_tags.multi_output = True
        tags.target_tags.single_output = True
        return tags
