"""Action-conditioned effect models: for one behaviour, [initial features, action parameters] -> outcome, with a
predictive distribution.

:class:`ActionEffectModel` is a random forest used as a quantile regression forest (Meinshausen 2006, JMLR 7): its
trees are grown on the motion part of the outcome (:data:`~affordance_learning.planning.outcomes.MOTION_COLUMNS`,
standardised), and a query's predictive distribution is the training outcomes weighted by how often they share a
leaf with it, averaged over the trees. The distribution is over whole outcomes (motion and perceptual effect
together), so the probability of any goal (:mod:`affordance_learning.planning.goals`) is the weighted share of training
outcomes that reach it, and samples are training outcomes drawn by those weights: a distribution that keeps the
outcomes' real spread and their joint structure (a ball that rolls far also leaves the view), which a point
prediction would lose.

A leaf holds neighbours whose actions differ from the query's a little, and where the displacement follows the
action closely (a pick and place puts the object where its parameters say) those differences blur the prediction
by centimetres. :meth:`ActionEffectModel.predictive_outcomes` therefore moves each neighbour's displacement to the
query's action along the local slope of displacement on the action parameters: a weighted least-squares fit over
the query's neighbours of the same kind of outcome (rolled, left the table, lifted), as a local linear forest does
(Friedberg, Tibshirani, Athey and Wager 2020, "Local linear forests", J. Comput. Graph. Stat. 30(2)), here applied
to every neighbour's outcome rather than to the mean alone, so that the distribution keeps its spread.
"""

from __future__ import annotations

import copy
import functools
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import sparse
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.ensemble import ExtraTreesRegressor, RandomForestRegressor
from sklearn.utils.validation import check_is_fitted, validate_data

from affordance_env.values import is_integer
from affordance_learning.common.exceptions import InvalidValueError
from affordance_learning.planning.goals import Goal

#: The displacement columns that :meth:`ActionEffectModel.predictive_outcomes` moves to the query's action, and the
#: flags whose combinations are the kinds of outcome that each get their own slope.
DISPLACEMENT_COLUMNS, KIND_COLUMNS = ("dx", "dy"), ("rolled", "off_table", "lifted")
#: Ridge of the local slopes, in squared action units (the parameters span [-1, 1]): a neighbourhood whose actions
#: spread over less than about sqrt(SLOPE_RIDGE) = 0.03 of that span gets a slope shrunk toward 0, not one fitted
#: to its noise.
SLOPE_RIDGE = 1e-3
#: A kind of outcome gets a slope in a query's neighbourhood only where it has at least this many effective
#: neighbours (Kish's (sum w)^2 / sum w^2); fewer fix no slope, and their displacements are kept as they are.
MIN_SLOPE_NEIGHBOURS = 4.0
#: The trees are grown on the standardised motion columns, the flags (rolled, left the table, lifted) weighing this
#: many times a displacement: whether a grasp lifts or a ball rolls is what most goals turn on, and the local slopes
#: take the displacement's dependence on the action off the trees. On the goal episodes of ``affordance plan`` (seed
#: 0, a quarter of the objects held out), weights 1 / 2 / 4 gave Brier scores of "the grasp lifts it" of
#: 0.112 / 0.099 / 0.089, of a grasp's move goals 0.046 / 0.042 / 0.038 and of its place goals 0.102 / 0.095 / 0.090;
#: the strokes' and the draw's stayed within 0.002 but rose with 4 (the draw's place goals 0.049 / 0.050 / 0.052),
#: and the single-step planner of that run did worst with 4: 2 is the middle, for all but the grasp, whose flags
#: weigh more (:data:`BEHAVIOR_FLAG_WEIGHTS`).
FLAG_WEIGHT = 2.0
#: Behaviours whose flags weigh otherwise (:func:`behavior_model`). The grasp's: whether it lifts the object turns
#: on its size against the hand's span (in training, boxes over 7 cm are never held, under 7 cm four in five times),
#: which the trees split on only where the flag outweighs the place's displacement, itself linear in the action (the
#: local slopes carry it). Over 5 folds of the 1000 training grasps of ``affordance plan``'s seeds 0 and 1, flags at
#: 2 / 5 / 10 gave "the grasp lifts it" Brier scores of 0.084 / 0.075 / 0.075 and 0.082 / 0.076 / 0.074, and a
#: grasp's end within 3 cm of where it ended a mean P of 0.768 / 0.787 / 0.788 and 0.763 / 0.780 / 0.783; the
#: single-step planner's chosen actions (24 held-out objects) an AUROC of 0.945 / 0.953 / 0.951 and 0.933 / 0.951 /
#: 0.952.
BEHAVIOR_FLAG_WEIGHTS: Mapping[str, float] = {"grasp": 5.0}


#: Queries times training outcomes up to which :func:`_summed` adds duplicates in a dense count (8 bytes each).
_DENSE_SUM_LIMIT = 1 << 23


def _summed(weights: sparse.csr_matrix) -> sparse.csr_matrix:
    """``weights`` (CSR) with each (query, training outcome) once, its duplicates summed, in order of the training
    outcomes: as ``sum_duplicates``, without its sort where a dense count of queries x outcomes is small."""
    m, n = weights.shape
    if m * n > _DENSE_SUM_LIMIT:
        weights.sum_duplicates()
        return weights
    query = np.repeat(np.arange(m), np.diff(weights.indptr))
    dense = np.bincount(query * n + weights.indices, weights=weights.data, minlength=m * n)
    stored = np.flatnonzero(dense)  # every weight is positive: a stored entry sums to more than 0
    indptr = np.concatenate([[0], np.cumsum(np.bincount(stored // n, minlength=m))])
    return sparse.csr_matrix((dense[stored], stored % n, indptr), shape=(m, n))


@functools.lru_cache(maxsize=8)
def _upper(k: int) -> tuple[np.ndarray, np.ndarray]:
    """``np.triu_indices(k)``, made once per k."""
    return np.triu_indices(k)


def _symmetric(upper: np.ndarray, k: int) -> np.ndarray:
    """(..., k, k) the symmetric matrices whose upper triangles (``np.triu_indices(k)`` order) are ``upper``."""
    out = np.empty(upper.shape[:-1] + (k, k))
    i, j = _upper(k)
    out[..., i, j] = upper
    out[..., j, i] = upper
    return out


def _solve(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.linalg.solve(a, b)`` for stacks of symmetric positive definite ``a`` (..., k, k); for k = 3 (the
    action's parameters) by the adjugate, several times faster than LAPACK's loop over small matrices."""
    if a.shape[-1] != 3:
        return np.linalg.solve(a, b)
    c00 = a[..., 1, 1] * a[..., 2, 2] - a[..., 1, 2] * a[..., 2, 1]
    c01 = a[..., 1, 2] * a[..., 2, 0] - a[..., 1, 0] * a[..., 2, 2]
    c02 = a[..., 1, 0] * a[..., 2, 1] - a[..., 1, 1] * a[..., 2, 0]
    c11 = a[..., 0, 0] * a[..., 2, 2] - a[..., 0, 2] * a[..., 2, 0]
    c12 = a[..., 0, 1] * a[..., 2, 0] - a[..., 0, 0] * a[..., 2, 1]
    c22 = a[..., 0, 0] * a[..., 1, 1] - a[..., 0, 1] * a[..., 1, 0]
    det = a[..., 0, 0] * c00 + a[..., 0, 1] * c01 + a[..., 0, 2] * c02
    inverse = np.stack([np.stack([c00, c01, c02], -1), np.stack([c01, c11, c12], -1),
                        np.stack([c02, c12, c22], -1)], -2) / det[..., None, None]
    return inverse @ b


@dataclass(frozen=True)
class KindMoments:
    """Queries' predictive distributions summed up per kind of outcome (:meth:`ActionEffectModel.kind_moments`).

    Attributes:
        mass: (m, kinds) each kind's weight in each query's distribution (rows sum to 1).
        mean: (m, kinds, 2) the mean displacement (dx, dy) [m] of each kind's neighbours at the query's action.
        covariance: (m, kinds, 2, 2) its covariance [m^2].
        flags: (kinds, len(KIND_COLUMNS)) each kind's flags (rolled, left the table, lifted).
    """

    mass: np.ndarray
    mean: np.ndarray
    covariance: np.ndarray
    flags: np.ndarray

    def flag(self, name: str) -> np.ndarray:
        """(kinds,) bool: whether each kind has the flag ``name`` (one of :data:`KIND_COLUMNS`)."""
        return self.flags[:, KIND_COLUMNS.index(name)]


class PredictiveOutcomes:
    """The predictive distributions of some queries as weighted training outcomes: :meth:`ActionEffectModel.
    predictive_outcomes`.

    Each stored entry of ``weights`` (CSR, (queries, training outcomes), every training outcome at most once per
    query, rows summing to 1) is one training outcome of one query; ``outcomes[name]`` gives a column of the
    outcome table (``dx``, ``rolled``, ``effect_<feature>``, ...) at every entry, in the entries' order, with the
    displacement (``dx``, ``dy``) moved to the query's action. A goal (:mod:`.goals`) reads it
    as it reads an outcome table: ``probability(goal, start_xy)`` is each query's weighted share of entries that
    reach it.

    Attributes:
        weights: The CSR weights, (m, n).
        query: The query of every entry, (nnz,).
        displacement: ``dx`` and ``dy`` of every entry at the query's action, (nnz, 2) [m].
    """

    def __init__(self, model: ActionEffectModel, weights: sparse.csr_matrix, displacement: np.ndarray) -> None:
        self._model, self.weights, self.displacement = model, weights, displacement
        self.query = np.repeat(np.arange(weights.shape[0]), np.diff(weights.indptr))
        self._off_table: np.ndarray | None = None  # ``off_table`` as off_beyond left it; None: the outcomes'

    def _starts(self, start_xy) -> np.ndarray:
        """Where each entry's object started: ``start_xy`` ((2,), or (m, 2) one per query) per entry."""
        start = np.asarray(start_xy, dtype=np.float64)
        if start.shape not in ((2,), (len(self), 2)):
            raise InvalidValueError(f"start_xy must be where the object is, (2,) or one (x, y) per query "
                                    f"({len(self)}, 2) [m], got shape {start.shape}.")
        return start[self.query] if start.ndim == 2 else start

    def off_beyond(self, start_xy, low, high) -> PredictiveOutcomes:
        """These outcomes, with every entry whose object's centre ends (``start_xy`` plus its displacement, [m])
        outside the rectangle ``low`` .. ``high`` (x, y) [m] counted off the table.

        An object whose centre of mass is beyond the table top's edge does not rest on it, yet a displacement moved
        to the query's action can carry a neighbour's outcome there while it still says "on the table" (an action
        never executed, such as a place beyond the edge, leaves no outcome that says otherwise)."""
        end = self._starts(start_xy) + self.displacement
        outside = np.any((end < np.asarray(low)) | (end > np.asarray(high)), axis=1)
        out = copy.copy(self)
        out._off_table = self["off_table"].astype(bool) | outside
        return out

    def __len__(self) -> int:
        return self.weights.shape[0]

    def __getitem__(self, name: str) -> np.ndarray:
        if name == "off_table" and self._off_table is not None:
            return self._off_table.copy()
        if name in DISPLACEMENT_COLUMNS and self.displacement.shape[1]:
            return self.displacement[:, DISPLACEMENT_COLUMNS.index(name)]
        try:
            column = self._model.outcome_names_.index(name)
        except ValueError:
            raise KeyError(name) from None
        return self._model.outcomes_[self.weights.indices, column]

    def values(self) -> np.ndarray:
        """(nnz, n_outcomes) every entry's whole outcome row, its displacement at the query's action."""
        rows = self._model.outcomes_[self.weights.indices]
        rows[:, self._model.displacement_columns_] = self.displacement
        if self._off_table is not None:
            rows[:, self._model.outcome_names_.index("off_table")] = self._off_table
        return rows

    def share(self, values: np.ndarray) -> np.ndarray:
        """(m,) each query's weighted mean of ``values`` given for every entry (a weighted share for booleans)."""
        return ActionEffectModel.weighted_share(self.weights, np.asarray(values, dtype=np.float64))

    def probability(self, goal: Goal, start_xy=None) -> np.ndarray:
        """(m,) P(goal) of each query; ``start_xy``: where the object is ((2,), or (m, 2) one per query) [m]."""
        if start_xy is not None:
            start_xy = self._starts(start_xy)
        return self.share(goal.reached(self, start_xy))


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
        flag_weight: How much the flags among the split columns (:data:`KIND_COLUMNS`) weigh in the trees'
            splits against a standardised displacement (:data:`FLAG_WEIGHT`).
        action_inputs: How many of the last inputs are the action's parameters, along which each neighbour's
            displacement is moved to the query's action (:meth:`predictive_outcomes`; only for outcomes named
            ``dx`` and ``dy``); 0: the neighbours' displacements as they were.
        random_state: Seed of the forest.
        n_jobs: Parallel jobs of the forest (joblib).

    ``fit(X, y)``: ``X`` (n, d) inputs (:func:`~affordance_learning.planning.outcomes.model_inputs`: 49 features and 3
    parameters), ``y`` (n, m) outcomes (:func:`~.outcomes.outcome_table`; a DataFrame keeps its
    column names in ``outcome_names_``). ``predict(X)``: the mean outcome. :meth:`predictive_outcomes`,
    :meth:`goal_probability` and :meth:`sample` give the distribution; :meth:`predictive_weights` the forest's
    weights of the training outcomes as they were.
    """

    def __init__(self, n_estimators: int = 200, min_samples_leaf: int = 3, max_features: float = 0.5,
                 split_columns: int | None = 5, trees: str = "random", action_inputs: int = 3,
                 flag_weight: float = FLAG_WEIGHT, random_state: int | None = None, n_jobs: int | None = None
                 ) -> None:
        self.n_estimators = n_estimators
        self.min_samples_leaf = min_samples_leaf
        self.max_features = max_features
        self.split_columns = split_columns
        self.trees = trees
        self.action_inputs = action_inputs
        self.flag_weight = flag_weight
        self.random_state = random_state
        self.n_jobs = n_jobs

    def fit(self, X, y):
        forests = {"random": RandomForestRegressor, "extra": ExtraTreesRegressor}
        if self.trees not in forests:
            raise InvalidValueError(f"trees must be one of {sorted(forests)}, got {self.trees!r}.")
        names = list(y.columns) if isinstance(y, pd.DataFrame) else None
        X, y = validate_data(self, X, y, multi_output=True, y_numeric=True, dtype=np.float64)
        if not (isinstance(self.flag_weight, int | float) and self.flag_weight > 0):
            raise InvalidValueError(f"flag_weight must be a positive number, got {self.flag_weight!r}.")
        k = self.action_inputs
        if not is_integer(k) or not 0 <= k <= X.shape[1]:
            raise InvalidValueError(f"action_inputs must be an integer in [0, {X.shape[1]}] (how many of the last "
                                    f"inputs are the action's parameters), got {k!r}.")
        y = np.asarray(y, dtype=np.float64)
        y2 = y.reshape(len(y), -1)
        self.outcome_names_ = names if names is not None else [f"y{j}" for j in range(y2.shape[1])]
        #: The columns of the perceptual effect (``effect_<feature>``) among the outcomes.
        self.effect_columns_ = np.array([j for j, n in enumerate(self.outcome_names_) if str(n).startswith("effect_")],
                                        dtype=np.intp)
        split = y2 if self.split_columns is None else y2[:, : max(1, min(self.split_columns, y2.shape[1]))]
        scale = split.std(axis=0)
        scale[scale == 0] = 1.0
        # the flags (rolled, left the table, lifted) weigh flag_weight times a standardised displacement
        flags = [j for j, name in enumerate(self.outcome_names_[: split.shape[1]]) if name in KIND_COLUMNS]
        scale[flags] /= self.flag_weight
        self.forest_ = forests[self.trees](
            n_estimators=self.n_estimators, min_samples_leaf=self.min_samples_leaf, max_features=self.max_features,
            random_state=self.random_state, n_jobs=self.n_jobs,
        ).fit(X, (split - split.mean(axis=0)) / scale)
        self.outcomes_ = y2
        self._single_output = y.ndim == 1
        has_displacement = all(name in self.outcome_names_ for name in DISPLACEMENT_COLUMNS)
        #: The columns of ``dx`` and ``dy`` among the outcomes (empty without them), and the training actions
        #: (n, action_inputs) along which they are moved (None: they are not).
        self.displacement_columns_ = np.array([self.outcome_names_.index(n) for n in DISPLACEMENT_COLUMNS]
                                              if has_displacement else [], dtype=np.intp)
        self.action_params_ = X[:, X.shape[1] - k:].copy() if has_displacement and k > 0 else None
        # The kind of every training outcome, numbered 0, 1, ... over the combinations of the flags of
        # KIND_COLUMNS that occur (a behaviour that never lifts has half as many kinds to fit slopes for).
        codes = np.zeros(len(y2), dtype=np.intp)
        for bit, name in enumerate(KIND_COLUMNS):
            if name in self.outcome_names_:
                codes |= (y2[:, self.outcome_names_.index(name)] > 0.5).astype(np.intp) << bit
        self.kinds_ = np.unique(codes, return_inverse=True)[1].astype(np.intp).ravel()
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
        leaves = np.empty((len(X32), len(self.forest_.estimators_)), dtype=np.intp)
        for t, tree in enumerate(self.forest_.estimators_):
            leaves[:, t] = tree.tree_.apply(X32)
        return leaves

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

    def predictive_outcomes(self, X) -> PredictiveOutcomes:
        """Each query's predictive distribution (:class:`PredictiveOutcomes`): the forest's weights
        (:meth:`predictive_weights`, every training outcome once per query), and every neighbour's displacement
        moved to the query's action along the local slope of displacement on the action parameters.

        The slope is fitted per query and per kind of outcome (the flags of :data:`KIND_COLUMNS`: a ball that
        rolls moves with the action otherwise than one that slides), by weighted least squares over the query's
        neighbours of that kind, with an intercept and the ridge :data:`SLOPE_RIDGE`; a kind with fewer than
        :data:`MIN_SLOPE_NEIGHBOURS` effective neighbours keeps its displacements. Without ``action_params_``
        (``action_inputs`` 0, or outcomes without ``dx`` and ``dy``) the displacements stay as they were."""
        weights = _summed(self.predictive_weights(X, as_sparse=True))  # the slopes' sums see each outcome once
        rows = weights.indices
        outcomes = PredictiveOutcomes(self, weights, self.outcomes_[rows[:, None], self.displacement_columns_])
        if self.action_params_ is None:
            return outcomes
        X = validate_data(self, X, reset=False, dtype=np.float64)
        actions = X[:, X.shape[1] - self.action_params_.shape[1]:]
        slopes = self._slopes(weights, actions)  # (m, kinds, k, 2)
        query = outcomes.query
        offset = actions[query] - self.action_params_[rows]  # (nnz, k): the query's action minus the neighbour's
        outcomes.displacement += np.einsum("ek,ekj->ej", offset, slopes[query, self.kinds_[rows]])
        return outcomes

    def _slopes(self, weights: sparse.csr_matrix, actions: np.ndarray) -> np.ndarray:
        """(m, kinds, k, 2) the slope of ``dx`` and ``dy`` on the k action parameters among each query's neighbours
        of each kind (``weights``: CSR without duplicates), 0 where a kind has too few of them."""
        P, Y = self.action_params_, self.outcomes_[:, self.displacement_columns_]
        n, k = P.shape
        kinds = int(self.kinds_.max()) + 1
        # Per training outcome, the terms of the weighted sums, in the block of its kind: 1, p, p p^T, y, p y^T.
        terms = np.hstack([np.ones((n, 1)), P, (P[:, :, None] * P[:, None, :]).reshape(n, -1), Y,
                           (P[:, :, None] * Y[:, None, :]).reshape(n, -1)])
        width = terms.shape[1]
        blocks = np.zeros((n, kinds, width))
        blocks[np.arange(n), self.kinds_] = terms
        sums = np.asarray(weights @ blocks.reshape(n, -1)).reshape(len(actions), kinds, width)
        squares = weights.copy()
        squares.data = squares.data ** 2
        onehot = blocks[:, :, 0]  # the term 1 in its kind's block
        kish = sums[:, :, 0] ** 2 / np.maximum(np.asarray(squares @ onehot), 1e-300)  # effective neighbours
        fitted = (sums[:, :, 0] > 0) & (kish >= MIN_SLOPE_NEIGHBOURS)
        total = np.where(fitted, sums[:, :, 0], 1.0)[:, :, None]
        mean_p = sums[:, :, 1 : 1 + k] / total
        second = sums[:, :, 1 + k : 1 + k + k * k].reshape(len(actions), kinds, k, k) / total[..., None]
        mean_y = sums[:, :, 1 + k + k * k : 3 + k + k * k] / total
        cross = sums[:, :, 3 + k + k * k :].reshape(len(actions), kinds, k, 2) / total[..., None]
        covariance = second - mean_p[..., :, None] * mean_p[..., None, :] + SLOPE_RIDGE * np.eye(k)
        slopes = np.linalg.solve(covariance, cross - mean_p[..., :, None] * mean_y[..., None, :])
        slopes[~fitted] = 0.0
        return slopes

    def _query_leaves(self, X: np.ndarray) -> sparse.csr_matrix:
        """(m, leaves) each query's leaf in every tree, 1 / T each, as rows of the stacked table of leaves: the
        forest's weights are this times the leaves' row-normalised membership (:meth:`predictive_weights`)."""
        leaves = self._apply(X)  # (m, T)
        node_offset, node_row = self._leaf_table[3:]
        rows = node_row[(leaves + node_offset[None, :]).ravel()]
        m, trees = leaves.shape
        return sparse.csr_matrix((np.full(m * trees, 1.0 / trees), rows, np.arange(0, m * trees + 1, trees)),
                                 shape=(m, len(self._leaf_table[0]) - 1))

    def _leaf_means(self, values: np.ndarray) -> np.ndarray:
        """(leaves, ...) the mean of ``values`` (one row per training outcome) over every leaf of every tree."""
        indptr, indices, data = self._leaf_table[:3]
        members = sparse.csr_matrix((data, indices, indptr), shape=(len(indptr) - 1, len(self.outcomes_)))
        return np.asarray(members @ values.reshape(len(self.outcomes_), -1)).reshape(-1, *values.shape[1:])

    def leaf_share(self, X, values) -> np.ndarray:
        """(m,) each query's weighted mean of ``values`` (one per training outcome, (n,)): what
        :meth:`PredictiveOutcomes.share` gives for values that do not depend on the query's action (a flag, the
        perceptual effect; not the displacement, which :meth:`kind_moments` follows), to float tolerance, from
        the mean of ``values`` in each leaf, without the query's neighbours one by one."""
        check_is_fitted(self)
        X = validate_data(self, X, reset=False, dtype=np.float64)
        values = np.asarray(values, dtype=np.float64)
        if values.shape != (len(self.outcomes_),):
            raise InvalidValueError(f"values must be one number per training outcome ({len(self.outcomes_)},), got "
                                    f"shape {values.shape}.")
        return np.asarray(self._query_leaves(X) @ self._leaf_means(values)).ravel()

    def kind_moments(self, X, *, check_input: bool = True) -> KindMoments:
        """Each query's predictive distribution summed up per kind of outcome (:class:`KindMoments`): the weight
        of each kind, and the mean and covariance of its displacement at the query's action, the neighbours'
        displacements moved along the slopes :meth:`predictive_outcomes` fits.

        Every sum the slopes and moments need is linear in the forest's weights, so it is the mean over the
        query's leaves of sums stored per leaf (computed once, at the first call): a query costs one sparse
        row of T leaves, not the few hundred neighbours of :meth:`predictive_outcomes` (on the shipped models,
        1000 queries over the five behaviours took 85 ms of CPU time against 293 ms: ``benchmarks/planner.py``,
        which times both). The weights, means and covariances are those of
        :meth:`predictive_outcomes`' entries to float tolerance, but for one thing: whether a kind has the
        :data:`MIN_SLOPE_NEIGHBOURS` effective neighbours a slope needs is judged from the leaves' sums of
        squared weights, which do not add up a training outcome that several trees share (more effective
        neighbours than there are: a kind of a handful of neighbours may get a slope here and none there).
        ``check_input=False`` takes ``X`` as it is, a finite float64 array of the model's inputs (a caller that
        made it so spares the check, about a millisecond a call).
        """
        check_is_fitted(self)
        if not len(self.displacement_columns_):
            raise InvalidValueError(f"kind_moments needs outcomes with {' and '.join(DISPLACEMENT_COLUMNS)}; the "
                                    f"model's are {self.outcome_names_[:6]}.")
        if check_input:
            X = validate_data(self, X, reset=False, dtype=np.float64)
        if getattr(self, "_kind_table", None) is None:
            self._kind_table = self._kind_sums()
        flags, sums = self._kind_table
        kinds, k = len(flags), 0 if self.action_params_ is None else self.action_params_.shape[1]
        query = self._query_leaves(X)
        trees = len(self.forest_.estimators_)
        totals = np.asarray(query @ sums).reshape(len(X), kinds, -1)
        mass, squares = totals[:, :, 0], totals[:, :, -1] / trees  # sum w and (as the leaves see it) sum w^2
        total = np.where(mass > 0, mass, 1.0)[:, :, None]
        mean_p, mean_y = totals[:, :, 1 : 1 + k] / total, totals[:, :, 1 + k : 3 + k] / total
        tri = 3 + k
        second_p = _symmetric(totals[:, :, tri : tri + k * (k + 1) // 2] / total, k)
        tri += k * (k + 1) // 2
        second_y = _symmetric(totals[:, :, tri : tri + 3] / total, 2)
        cross = totals[:, :, tri + 3 : tri + 3 + 2 * k].reshape(len(X), kinds, k, 2) / total[..., None]
        cov_p = second_p - mean_p[..., :, None] * mean_p[..., None, :]
        cov_py = cross - mean_p[..., :, None] * mean_y[..., None, :]
        cov_y = second_y - mean_y[..., :, None] * mean_y[..., None, :]
        if k:
            fitted = (mass > 0) & (mass**2 / np.maximum(squares, 1e-300) >= MIN_SLOPE_NEIGHBOURS)
            slopes = _solve(cov_p + SLOPE_RIDGE * np.eye(k), cov_py)  # (m, kinds, k, 2)
            slopes[~fitted] = 0.0
            actions = X[:, X.shape[1] - k:]
            mean_y = mean_y + np.einsum("mck,mckj->mcj", actions[:, None, :] - mean_p, slopes)
            # the covariance of y - S^T p: each neighbour's displacement moved to the same action
            moved = np.einsum("mcki,mckj->mcij", slopes, cov_py)
            cov_y = cov_y - moved - np.swapaxes(moved, -1, -2) + np.einsum(
                "mcki,mckl,mclj->mcij", slopes, cov_p, slopes)
        return KindMoments(mass, mean_y, cov_y, flags)

    def _kind_sums(self) -> tuple[np.ndarray, np.ndarray]:
        """The flags of every kind (kinds, len(KIND_COLUMNS)) and, per leaf, the mean over its training outcomes
        of each kind's terms (1, p, p p^T, y, y y^T, p y^T, 1 / leaf size; the upper triangles of the symmetric
        ones), (leaves, kinds * terms): what :meth:`kind_moments` sums over a query's leaves."""
        y = self.outcomes_[:, self.displacement_columns_]
        n = len(y)
        p = np.zeros((n, 0)) if self.action_params_ is None else self.action_params_
        k = p.shape[1]
        flags = np.zeros((int(self.kinds_.max()) + 1, len(KIND_COLUMNS)), dtype=bool)
        for j, name in enumerate(KIND_COLUMNS):
            if name in self.outcome_names_:
                flags[self.kinds_, j] = self.outcomes_[:, self.outcome_names_.index(name)] > 0.5
        upper_p, upper_y = np.triu_indices(k), np.triu_indices(2)
        terms = np.hstack([np.ones((n, 1)), p, y, (p[:, :, None] * p[:, None, :])[:, upper_p[0], upper_p[1]],
                           (y[:, :, None] * y[:, None, :])[:, upper_y[0], upper_y[1]],
                           (p[:, :, None] * y[:, None, :]).reshape(n, -1)])
        indptr = self._leaf_table[0]
        size = np.diff(indptr)  # each leaf's training outcomes, once per entry of the leaf
        blocks = np.zeros((n, len(flags), terms.shape[1] + 1))
        blocks[np.arange(n), self.kinds_, :-1] = terms
        sums = self._leaf_means(blocks.reshape(n, -1)).reshape(len(size), len(flags), -1)
        # sum over a leaf's outcomes of its weight squared, T^2 times: its kind's count over the leaf's size^2
        sums[:, :, -1] = sums[:, :, 0] / size[:, None]
        return flags, sums.reshape(len(size), -1)

    def predict(self, X) -> np.ndarray:
        """The mean outcome under the predictive distribution (:meth:`predictive_outcomes`), (m, n_outcomes) (or
        (m,) for a 1-d ``y``)."""
        outcomes = self.predictive_outcomes(X)
        values = outcomes.values()
        mean = np.column_stack([outcomes.share(values[:, j]) for j in range(values.shape[1])])
        return mean[:, 0] if self._single_output else mean

    def outcome_frame(self) -> pd.DataFrame:
        """The training outcomes, with their names: the support of every predictive distribution."""
        check_is_fitted(self)
        return pd.DataFrame(self.outcomes_, columns=self.outcome_names_)

    def goal_probability(self, X, goal: Goal, start_xy=None) -> np.ndarray:
        """P(goal) for each query, (m,): the weighted share of its outcomes (:meth:`predictive_outcomes`) that
        reach ``goal`` from ``start_xy`` ((2,) or (m, 2) [m], where the object is; needed by
        :class:`~affordance_learning.planning.goals.Place`)."""
        return self.predictive_outcomes(X).probability(goal, start_xy)

    @staticmethod
    def weighted_share(weights: sparse.csr_matrix, hits: np.ndarray) -> np.ndarray:
        """(m,) the weighted share of each query's training outcomes that ``hits`` marks, ``hits`` given for the
        stored entries of ``weights`` (CSR, in its order). At most 1: weights that sum to 1 may add up to an ulp
        more in floating point."""
        share = np.add.reduceat(np.append(weights.data * hits, 0.0), weights.indptr[:-1])[: weights.shape[0]] \
            * (np.diff(weights.indptr) > 0)
        return np.minimum(share, 1.0, out=share)

    def sample(self, X, n_samples: int, random_state: int | np.random.Generator | None = None) -> np.ndarray:
        """(m, n_samples, n_outcomes) outcomes drawn from each query's predictive distribution
        (:meth:`predictive_outcomes`: training outcomes, their displacement at the query's action)."""
        rng = np.random.default_rng(random_state)
        outcomes = self.predictive_outcomes(X)
        weights, values = outcomes.weights, outcomes.values()
        picks = []
        for i in range(weights.shape[0]):
            entries = slice(weights.indptr[i], weights.indptr[i + 1])
            w = weights.data[entries]
            picks.append(entries.start + rng.choice(len(w), size=n_samples, p=w / w.sum()))
        return values[np.stack(picks)]


def behavior_model(behavior: str, **kwargs) -> ActionEffectModel:
    """The unfitted effect model of ``behavior``: its flags weighing :data:`BEHAVIOR_FLAG_WEIGHTS` (else
    :data:`FLAG_WEIGHT`) unless ``kwargs`` say otherwise, ``kwargs`` the arguments of :class:`ActionEffectModel`.
    What ``affordance plan`` and the shipped action-conditioned default models fit."""
    kwargs.setdefault("flag_weight", BEHAVIOR_FLAG_WEIGHTS.get(behavior, FLAG_WEIGHT))
    return ActionEffectModel(**kwargs)
