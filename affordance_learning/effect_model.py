"""Action-conditioned effect models: for one behaviour, [initial features, action parameters] -> outcome, with a
predictive distribution.

:class:`ActionEffectModel` is a random forest used as a quantile regression forest (Meinshausen 2006, JMLR 7): its
trees are grown on the motion part of the outcome (:data:`~affordance_learning.outcomes.MOTION_COLUMNS`,
standardised), and a query's predictive distribution is the training outcomes weighted by how often they share a
leaf with it, averaged over the trees. The distribution is over whole outcomes (motion and perceptual effect
together), so the probability of any goal (:mod:`affordance_learning.goals`) is the weighted share of training
outcomes that reach it, and samples are training outcomes drawn by those weights: a distribution that keeps the
outcomes' real spread and their joint structure (a ball that rolls far also leaves the view), which a point
prediction would lose.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import sparse
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.ensemble import ExtraTreesRegressor, RandomForestRegressor
from sklearn.utils.validation import check_is_fitted, validate_data

from affordance_learning.exceptions import InvalidValueError
from affordance_learning.goals import Goal, Place


class _Rows:
    """Columns of a model's training outcomes at some rows, by name (what a goal reads), gathered when asked."""

    def __init__(self, model: ActionEffectModel, rows: np.ndarray) -> None:
        self._model, self._rows = model, rows

    def __getitem__(self, name: str) -> np.ndarray:
        return self._model.outcomes_[self._rows, self._model.outcome_names_.index(name)]


class ActionEffectModel(RegressorMixin, BaseEstimator):
    """Outcome of an interaction from the object's initial features and the action's parameters.

    Args:
        n_estimators: Trees of the forest.
        min_samples_leaf: Training outcomes per leaf at least: each tree's neighbourhood of a query.
        max_features: Share of the inputs tried at each split.
        split_columns: How many of the first outcome columns the trees are grown on (the motion: ``dx``, ``dy``,
            ``rolled``, ``off_table``, ``lifted``); None: all of them.
        trees: ``"random"`` (a random forest) or ``"extra"`` (extremely randomised trees; compared in
            ``benchmarks/effect_models.py``).
        random_state: Seed of the forest.
        n_jobs: Parallel jobs of the forest (joblib).

    ``fit(X, y)``: ``X`` (n, d) inputs (:func:`~affordance_learning.outcomes.model_inputs`: 49 features and 3
    parameters), ``y`` (n, m) outcomes (:func:`~affordance_learning.outcomes.outcome_table`; a DataFrame keeps its
    column names in ``outcome_names_``). ``predict(X)``: the mean outcome. :meth:`predictive_weights`,
    :meth:`goal_probability` and :meth:`sample` give the distribution.
    """

    def __init__(self, n_estimators: int = 200, min_samples_leaf: int = 3, max_features: float = 0.5,
                 split_columns: int | None = 5, trees: str = "random", random_state: int | None = None,
                 n_jobs: int | None = None) -> None:
        self.n_estimators = n_estimators
        self.min_samples_leaf = min_samples_leaf
        self.max_features = max_features
        self.split_columns = split_columns
        self.trees = trees
        self.random_state = random_state
        self.n_jobs = n_jobs

    def fit(self, X, y):
        forests = {"random": RandomForestRegressor, "extra": ExtraTreesRegressor}
        if self.trees not in forests:
            raise InvalidValueError(f"trees must be one of {sorted(forests)}, got {self.trees!r}.")
        names = list(y.columns) if isinstance(y, pd.DataFrame) else None
        X, y = validate_data(self, X, y, multi_output=True, y_numeric=True, dtype=np.float64)
        y = np.asarray(y, dtype=np.float64)
        y2 = y.reshape(len(y), -1)
        self.outcome_names_ = names if names is not None else [f"y{j}" for j in range(y2.shape[1])]
        #: The columns of the perceptual effect (``effect_<feature>``) among the outcomes.
        self.effect_columns_ = np.array([j for j, n in enumerate(self.outcome_names_) if str(n).startswith("effect_")],
                                        dtype=np.intp)
        split = y2 if self.split_columns is None else y2[:, : max(1, min(self.split_columns, y2.shape[1]))]
        scale = split.std(axis=0)
        scale[scale == 0] = 1.0
        self.forest_ = forests[self.trees](
            n_estimators=self.n_estimators, min_samples_leaf=self.min_samples_leaf, max_features=self.max_features,
            random_state=self.random_state, n_jobs=self.n_jobs,
        ).fit(X, (split - split.mean(axis=0)) / scale)
        self.outcomes_ = y2
        self._single_output = y.ndim == 1
        leaves = self.forest_.apply(X)  # (n, T): each training row's leaf in every tree
        trees = [self._leaf_onehot(leaves[:, t]) for t in range(leaves.shape[1])]
        # One table of every tree's leaves: leaf r of tree t is row leaf_offset[t] + r of a stacked CSR matrix.
        stacked = sparse.vstack([member for _, member in trees], format="csr")
        nodes = [tree.tree_.node_count for tree in self.forest_.estimators_]
        node_offset = np.cumsum([0] + nodes[:-1])
        node_row = np.full(sum(nodes), -1, dtype=np.int64)  # a leaf's row in ``stacked``; -1 for inner nodes
        first = 0
        for t, (ids, _) in enumerate(trees):
            node_row[node_offset[t] + ids] = first + np.arange(len(ids))
            first += len(ids)
        self._leaf_table = (stacked.indptr, stacked.indices, stacked.data, node_offset, node_row)
        return self

    def _apply(self, X: np.ndarray) -> np.ndarray:
        """(m, T) each query's leaf in every tree: the forest's ``apply``, tree by tree in this thread. The
        forest's own spreads its trees over joblib tasks, whose overhead (about 0.1 ms per tree) is most of a
        planner's decision when it scores a few hundred queries."""
        X32 = np.ascontiguousarray(X, dtype=np.float32)  # the trees' own input type, as the forest converts it
        return np.column_stack([tree.tree_.apply(X32) for tree in self.forest_.estimators_])

    @staticmethod
    def _leaf_onehot(leaf_ids: np.ndarray) -> tuple[np.ndarray, sparse.csr_matrix]:
        """(the tree's leaf ids, (n_leaves, n) row-normalised membership of the training rows)."""
        ids, index = np.unique(leaf_ids, return_inverse=True)
        member = sparse.csr_matrix((np.ones(len(leaf_ids)), (index, np.arange(len(leaf_ids)))),
                                   shape=(len(ids), len(leaf_ids)))
        counts = np.asarray(member.sum(axis=1)).ravel()
        return ids, sparse.diags(1.0 / counts) @ member

    def predictive_weights(self, X, *, as_sparse: bool = False) -> np.ndarray | sparse.csr_matrix:
        """(m, n) weights of the training outcomes for each query (rows sum to 1): the predictive distribution.
        ``as_sparse=True`` gives a CSR matrix (a query shares leaves with a few hundred training rows at most): what
        a planner scoring many thousands of queries wants; it may hold a training row more than once per query
        (once per tree whose leaf has it), which every sparse operation sums."""
        check_is_fitted(self)
        X = validate_data(self, X, reset=False, dtype=np.float64)
        leaves = self._apply(X)  # (m, T)
        indptr, indices, data, node_offset, node_row = self._leaf_table
        # The row of each query's leaf in every tree in one stacked table, then the training rows of those leaves.
        rows = node_row[(leaves + node_offset[None, :]).ravel()]
        start, counts = indptr[rows], indptr[rows + 1] - indptr[rows]
        total = int(counts.sum())
        within = np.arange(total) - np.repeat(np.cumsum(counts) - counts, counts)
        take = np.repeat(start, counts) + within
        # Entries stay grouped by query, one group per tree: a training row shared by several trees' leaves
        # appears once per tree (every sparse operation sums such duplicates; summing them here costs a sort).
        per_query = counts.reshape(len(X), leaves.shape[1]).sum(axis=1)
        weights = sparse.csr_matrix((data[take] / leaves.shape[1], indices[take],
                                     np.concatenate([[0], np.cumsum(per_query)])),
                                    shape=(len(X), len(self.outcomes_)))
        return weights if as_sparse else weights.toarray()

    def predict(self, X) -> np.ndarray:
        """The mean outcome under the predictive distribution, (m, n_outcomes) (or (m,) for a 1-d ``y``)."""
        mean = self.predictive_weights(X) @ self.outcomes_
        return mean[:, 0] if self._single_output else mean

    def outcome_frame(self) -> pd.DataFrame:
        """The training outcomes, with their names: the support of every predictive distribution."""
        check_is_fitted(self)
        return pd.DataFrame(self.outcomes_, columns=self.outcome_names_)

    def goal_probability(self, X, goal: Goal, start_xy=None) -> np.ndarray:
        """P(goal) for each query, (m,): the weighted share of training outcomes that reach ``goal`` from
        ``start_xy`` ((2,) or (m, 2) [m], where the object is; needed by :class:`~affordance_learning.goals.Place`)."""
        weights = self.predictive_weights(X, as_sparse=True)
        outcomes = self.outcome_frame()
        if not isinstance(goal, Place):
            return np.asarray(weights @ goal.reached(outcomes).astype(np.float64)).ravel()
        start = np.asarray(start_xy, dtype=np.float64)
        if start.ndim == 1:  # one start for every query: each training outcome reaches the goal or not, once
            return np.asarray(weights @ goal.reached(outcomes, start).astype(np.float64)).ravel()
        weights.sum_duplicates()
        start = np.broadcast_to(start, (weights.shape[0], 2))
        return self.weighted_share(weights, self.reached_at(weights, goal, start))

    def reached_at(self, weights: sparse.csr_matrix, goal: Goal, start_xy: np.ndarray) -> np.ndarray:
        """Whether each stored entry of ``weights`` (CSR, its training outcome for its query) reaches ``goal`` from
        the query's ``start_xy`` ((m, 2) [m])."""
        query = np.repeat(np.arange(weights.shape[0]), np.diff(weights.indptr))
        return np.asarray(goal.reached(_Rows(self, weights.indices), np.asarray(start_xy)[query]), dtype=bool)

    @staticmethod
    def weighted_share(weights: sparse.csr_matrix, hits: np.ndarray) -> np.ndarray:
        """(m,) the weighted share of each query's training outcomes that ``hits`` marks, ``hits`` given for the
        stored entries of ``weights`` (CSR, in its order)."""
        return np.add.reduceat(np.append(weights.data * hits, 0.0), weights.indptr[:-1])[: weights.shape[0]] \
            * (np.diff(weights.indptr) > 0)

    def sample(self, X, n_samples: int, random_state: int | np.random.Generator | None = None) -> np.ndarray:
        """(m, n_samples, n_outcomes) outcomes drawn from each query's predictive distribution."""
        rng = np.random.default_rng(random_state)
        weights = self.predictive_weights(X)
        picks = np.stack([rng.choice(len(w), size=n_samples, p=w) for w in weights])
        return self.outcomes_[picks]
