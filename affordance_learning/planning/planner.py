"""Choosing what to do: the behaviour and its parameters that make a goal most likely, from the effect models.

:class:`Planner` chooses every behaviour's parameters in [-1, 1]^3 by an optimiser over the action (``optimizer``
``"cem"``, the default): a cross-entropy search per behaviour, seeded by ``n_candidates`` parameter vectors (the
canonical action and a scrambled Sobol sequence), that refits a Gaussian to its elite actions
(:data:`CEM_ELITES`) and draws :data:`CEM_SAMPLES` more from it, :data:`CEM_ITERATIONS` times. Its score is the
cheap one of :meth:`~affordance_learning.planning.effect_model.ActionEffectModel.kind_moments` (each kind of
outcome's weight and the mean and covariance of its displacement at the action): P(goal), for a goal with a
distance from a Gaussian per kind, then how far the predicted outcomes go towards the goal less
:data:`SPREAD_WEIGHT` times their spread. A decision scores (64 + 2 x 96) x 5 = 1280 actions so (summed over the
behaviours: :data:`EVALUATIONS`); the best few of each behaviour, and the best of other regions of its parameters
(:data:`FINALISTS`, :data:`FINALIST_REGIONS`) and its canonical action, are then scored on their whole predictive
outcomes (:meth:`~affordance_learning.planning.effect_model.ActionEffectModel.predictive_outcomes`), which says
the P(goal) a choice reports. ``optimizer="grid"`` scores the ``n_candidates`` vectors alone on their whole
predictive outcomes, and for a goal with a distance :data:`REFINE_POINTS` more around the best of them: the
planner as it was, for comparison at equal time (``benchmarks/planner.py``).

Of the actions scored, the planner takes the most likely one that the arm can reach: ``feasible`` (the
kinematics, tens of milliseconds a call) is asked from the most likely down, at most ``max_checks`` times per
decision, keeping one of those checks for the canonical action of every behaviour not asked about yet, so that no
behaviour is passed over for the refusals of another's. Actions of equal P (every one near 0 for a goal out of
reach) are ranked by how far their predicted outcomes go towards the goal, then action by action across the
behaviours. Below ``threshold`` the choice is flagged ``abstained`` (it still names the most likely action); where
no action it asked about is feasible it names none (``behavior`` and ``params`` None, and a ``reason``).
:meth:`Planner.toward` chooses the next interaction of a multi-step episode towards a place on the table: a search
over two interactions where more are left (``steps_left``), where the behaviours' workspaces say a second one can
act, re-planned after every interaction.

The planner remembers the actions that failed (:meth:`Planner.note_failure`: they failed to reach, or left the
object where it was): on an object still where one failed (within ``FAILURE_RADIUS``), no action within
``REFUSAL_RADIUS`` of it is chosen again, since a reach or a grasp fails for a region of the parameters, not for one
point; :meth:`forget_failures` clears what it remembers (a new episode or object).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np
from scipy.special import ndtr
from scipy.stats import qmc

from affordance_env.registry import BEHAVIOR_NAMES
from affordance_env.table import table_extent
from affordance_env.values import float_array, is_integer
from affordance_learning.common.exceptions import InvalidValueError
from affordance_learning.common.validation import check_float32_range
from affordance_learning.planning.effect_model import ActionEffectModel, KindMoments, PredictiveOutcomes
from affordance_learning.planning.goals import OFF_TABLE_DISTANCE, Goal, Move, Place, check_goal, check_start

#: The scene's table top, ((x_low, y_low), (x_high, y_high)) [m] in the robot's root frame: the planner's default
#: ``table``.
SCENE_TABLE = table_extent()
#: Where the object is (``start_xy``) may lie this far [m] beyond the table top's edge: the centre of an object on
#: the table is over it, but where the camera sees it (its top's mean) may hang a few centimetres over the edge.
SEEN_MARGIN = 0.05
#: The search over two interactions (:meth:`Planner.toward`): first actions looked at (the nearest on average,
#: and half as many of the most likely), predicted outcomes followed from each, and parameter vectors per
#: behaviour for the second interaction (the first of the planner's candidates), besides each behaviour's nearest
#: first action. 8 and 4 instead of 16 and 8 made the same first choice in 39 of 40 decisions on ``affordance
#: plan``'s models of seed 0, in half the time (measured with the fixed candidates, before the search).
LOOKAHEAD_ROOTS, LOOKAHEAD_OUTCOMES, LOOKAHEAD_SECOND = 8, 4, 8
#: A first action is chosen for its value over two interactions when that value is at least this.
MIN_SEQUENCE_VALUE = 0.1
#: Of the calls to ``feasible`` per decision (:meth:`Planner._search`), the most that the ranked candidates and
#: the canonical actions get, of which one per behaviour is kept for its canonical action.
RANKED_CHECKS = 12
#: Where none of the ranked candidates nor any canonical action is feasible, the planner asks about these actions,
#: spread over the parameters (the six at 0.75 along each parameter's axis, then the eight corners at 0.75), every
#: behaviour's, in the order the goal ranks them, until one is feasible or :data:`MAX_CHECKS` are spent; none within
#: :data:`PROBE_RADIUS` of an action refused in the decision. A behaviour is often feasible in one region of its
#: parameters only where the object lies at the edge of its reach (a tap only with its contact point shifted one
#: way, a tap back only the other), far from the canonical action and from the finalists of a goal beyond it:
#: on 64 of ``affordance plan``'s multi-step episodes (seed 0, the shipped models) the planner named no action in
#: three, with 12 of the oracle's 325 actions feasible in one (taps, all with the second parameter at 0.75) and 24
#: in another (taps back with it at -0.25 or less).
PROBES = np.vstack([np.vstack([0.75 * np.eye(3)[i] * s for i in range(3) for s in (1.0, -1.0)]),
                    0.75 * np.array([[a, b, c] for a in (1, -1) for b in (1, -1) for c in (1, -1)], float)])
PROBE_RADIUS = 0.5
#: Calls to ``feasible`` per decision at most: :data:`RANKED_CHECKS`, then every behaviour's :data:`PROBES` (82
#: for the five behaviours). A call costs 3-20 ms (the kinematics alone, the grasp's the most; measured on
#: ``affordance plan``'s multi-step episodes), so that a decision that asks them all, where nothing is feasible,
#: still takes under a second; with 24 (12 probes for five behaviours) one episode of 64 (``affordance plan --seed
#: 1``) stopped where taps with the second parameter at 0.75 and the first at 0.25 or less were feasible: the two
#: taps its probes could ask about were corners outside that region.
MAX_CHECKS = RANKED_CHECKS + len(PROBES) * len(BEHAVIOR_NAMES)
#: :meth:`Planner.choose` ranks candidates by P(goal) in steps of this, then by their expected progress towards the
#: goal: P is a weighted share of a few hundred training outcomes, and differences under a few per cent are its
#: noise, whereas a place nearer the target is a real difference.
P_RESOLUTION = 0.05
#: In one decision, a candidate nearer than this (Euclidean, in the parameters' [-1, 1] units) to one that
#: ``feasible`` refused is not asked: a reach fails for a region of the parameters (a place beyond the arm's
#: reach, a stroke that starts beyond it), or for every action of a behaviour where the object lies out of its
#: arm's reach, so that the checks go to other regions and other behaviours rather than to the refused one's
#: neighbours.
REFUSAL_RADIUS = 1.0
#: The search's actions lie closer together than the grid's, and where its best ones are refused the feasible
#: alternative often lies nearer than REFUSAL_RADIUS (a grasp's place refused at the edge of the arm's reach, a
#: feasible one half a unit nearer the object): after a ranking's actions beyond REFUSAL_RADIUS of every refused
#: one, a decision asks at most NEAR_REFUSAL_CHECKS more per behaviour of those beyond NEAR_REFUSAL_RADIUS. On
#: ``examples/use_affordances.py``'s episode (seed 3) the first interaction is then a grasp that brings the
#: cylinder 6 cm from its target (a push that moved it 1 cm without), and the episode reaches the target.
NEAR_REFUSAL_RADIUS, NEAR_REFUSAL_CHECKS = 0.5, 2
#: With the search, a behaviour of which a decision's checks refused this many actions gets no more of them
#: (but for its canonical action, kept for last): where the object lies out of a behaviour's reach every action
#: of it is refused, and its seeds (the first actions of :meth:`Planner.toward`, spread over the parameters)
#: would take every check from the behaviours that can act.
BEHAVIOR_REFUSALS = 3
#: :meth:`Planner.toward` with the search ranks, besides its finalists, this many of the seeds per behaviour (the
#: canonical action and the first Sobol points): first actions spread over the parameters, that bring the object
#: elsewhere for a second interaction. On ``examples/use_affordances.py``'s episode (seed 3) 24 miss the grasp
#: that brings the cylinder within reach of its target; all 64 cost about as much (``benchmarks/planner.py
#: --objects 8 --goals 2 --toward 16 --search-only``: toward's median 112 ms with 24, 124 ms with 64).
TOWARD_SEEDS = 64
#: :meth:`Planner.choose` refines a goal with a distance (a move, a place): around the action it found, it scores
#: REFINE_POINTS more within REFINE_RADIUS of it (per parameter, a scrambled Sobol set) and takes the best of them
#: that ranks above it, asking ``feasible`` about REFINE_CHECKS of them at most. The Sobol candidates lie about
#: 0.25 apart in the two parameters that aim a stroke or a place: 5 cm of a pick and place's 20 cm range, coarser
#: than a place's 3 cm tolerance.
REFINE_POINTS, REFINE_RADIUS, REFINE_CHECKS = 16, 0.15, 2
#: The optimisers :class:`Planner` takes (``optimizer``): a cross-entropy search over each behaviour's parameters,
#: or the fixed candidates and a refinement around the best.
OPTIMIZERS = ("cem", "grid")
#: The cross-entropy search: iterations after the seed candidates, actions drawn per behaviour and iteration, and
#: the elite actions (the best of all scored so far) whose mean and per-parameter spread the next draw follows.
#: With the 64 seed candidates, (64 + 2 x 96) x 5 behaviours = 1280 actions scored per decision: two iterations
#: of 96 rather than three of 64, since a call of a model costs about 2 ms whatever its size (a hundred trees).
CEM_ITERATIONS, CEM_SAMPLES, CEM_ELITES = 2, 96, 8
#: The spread of a draw is kept at least this (per parameter, in [-1, 1] units): 0.01 of a pick and place's
#: 0.2 m per unit is 2 mm, under the arm's own precision of a place, so the search does not collapse sooner.
CEM_MIN_STD = 0.01
#: Per behaviour, the actions the search scored best (``FINALISTS``) and the best of other regions of its
#: parameters (at most ``FINALIST_REGIONS``, each at least REFUSAL_RADIUS from the others), with its canonical
#: action, are scored on their whole predictive outcomes and ranked for ``feasible``: the others give the checks
#: somewhere to go where the best region is out of reach.
FINALISTS, FINALIST_REGIONS = 4, 3
#: Model evaluations per decision of the default optimiser, summed over the five behaviours: the cross-entropy
#: search's cheap scores and the finalists' whole predictive outcomes.
EVALUATIONS = 5 * (64 + CEM_ITERATIONS * CEM_SAMPLES + FINALISTS + FINALIST_REGIONS + 1)  # 1320
#: For a goal with a distance, an action's expected progress towards the goal is taken less this many times its
#: spread (the standard deviation of the progress under the predictive distribution): of two actions as likely to
#: reach the goal and that end as near on average, the one the model is surer of (P(goal) first, itself lower where
#: the outcomes spread, is the larger part of the penalty). ``python benchmarks/planner.py --objects 24 --goals 3
#: --seed 1 --execute --spread 0 0.25 1 --search-only`` and the same with ``--objects 16 --seed 2`` (72 and 48
#: place goals, the shipped models, each choice run in the simulator) put the object within 3 cm of the place in
#: 56 / 57 / 56 / 57 % and 69 / 71 / 71 / 69 % of the goals with weights 0 / 0.25 / 0.5 / 1, and its median
#: landing error rose with the weight in the second (1.2 / 1.4 / 1.5 / 2.0 cm; 0.6 / 0.7 / 0.9 / 0.9 cm where
#: P reached the threshold): 0.25 is as often within as any, its median within 0.2 cm of none's.
SPREAD_WEIGHT = 0.25
#: An action that failed (to reach, or to move the object) is not chosen again, nor one within REFUSAL_RADIUS of
#: it, on an object that is still within this distance [m] of where it failed (:meth:`Planner.note_failure`); an
#: object that moved further is a new situation.
FAILURE_RADIUS = 0.01


def in_workspace(behavior: str, xy: np.ndarray) -> np.ndarray:
    """Whether each point ``xy`` (n, 2) [m] lies in the workspace of ``behavior``
    (:func:`affordance_env.workspace.in_workspace`): :meth:`Planner.toward`'s default ``reachable``."""
    from affordance_env.workspace import in_workspace as inside

    return np.asarray(inside(behavior, np.asarray(xy, dtype=np.float64)), dtype=bool)


def _reached_by_any(reachable: Callable[[str, np.ndarray], np.ndarray], names: list[str], xy: np.ndarray
                    ) -> np.ndarray:
    """Whether some behaviour of ``names`` reaches each point ``xy`` (n, 2) [m]; each behaviour is asked only
    about the points no behaviour before it reaches."""
    out = np.zeros(len(xy), dtype=bool)
    for name in names:
        rest = np.flatnonzero(~out)
        if not rest.size:
            break
        out[rest] = np.asarray(reachable(name, xy[rest]), dtype=bool)
    return out


def _check_on_table(name: str, value, xy: np.ndarray, table=None) -> None:
    (x0, y0), (x1, y1) = SCENE_TABLE if table is None else table
    if xy.shape != (2,) or not np.all(np.isfinite(xy)) or not (x0 <= xy[0] <= x1 and y0 <= xy[1] <= y1):
        raise InvalidValueError(f"{name} must be (x, y) [m] on the table top, x in [{x0:.2f}, {x1:.2f}] and y in "
                         f"[{y0:.2f}, {y1:.2f}], got {value!r}.")


def _check_start(start_xy) -> np.ndarray:
    start = check_start(start_xy)
    if start.shape != (2,):
        raise InvalidValueError(f"start_xy must be where the object is, one (x, y) [m], got shape {start.shape}.")
    return start


def _distinct(params: np.ndarray) -> np.ndarray:
    """``params`` (n, 3) without repeated rows, in their first order."""
    _, first = np.unique(params, axis=0, return_index=True)
    return params[np.sort(first)]


def candidate_params(n: int, random_state: int = 0) -> np.ndarray:
    """(n, 3) action parameters in [-1, 1]: the canonical action (zeros) and n - 1 points of a scrambled Sobol
    sequence seeded by ``random_state``."""
    if not is_integer(n) or n < 1:
        raise InvalidValueError(f"n must be an integer >= 1, got {n!r}.")
    power = int(np.ceil(np.log2(max(2, n - 1))))  # Sobol's balance holds for powers of 2: the first n - 1 of them
    sobol = qmc.Sobol(3, scramble=True, seed=random_state).random_base2(power)[: n - 1]
    return np.vstack([np.zeros((1, 3)), 2.0 * sobol - 1.0])


@dataclass(frozen=True)
class Choice:
    """A planner's decision.

    Attributes:
        behavior: The behaviour chosen; None where the planner names no action (none it asked ``feasible`` about
            was, or every action failed there before): ``reason`` says which.
        params: Its parameters, (3,); None where ``behavior`` is None.
        probability: P(goal) of the choice under the model (for :meth:`Planner.toward` when no action is likely
            to reach the place: still P(within tolerance)); 0 without an action.
        abstained: P(goal) was below the threshold, or there is no action.
        expected_distance: For :meth:`Planner.toward`: the mean predicted distance to the place [m]; else NaN.
        checked: How many actions the kinematics was asked about (at most the planner's ``max_checks``).
        value: For :meth:`Planner.toward`: P(within the tolerance) after this interaction and, where more are
            left, after the best second one (:meth:`Planner.toward`); else NaN.
        reason: Why the planner abstained or names no action; empty where it is confident.
        evaluations: The model evaluations the decision made (actions scored, summed over the behaviours).
    """

    behavior: str | None
    params: np.ndarray | None
    probability: float
    abstained: bool
    expected_distance: float = float("nan")
    checked: int = 0
    value: float = float("nan")
    reason: str = ""
    evaluations: int = 0


def _below(p: float, threshold: float) -> str:
    return f"P(goal) {p:.2f} is below the threshold {threshold:.2f}" if p < threshold else ""


class Planner:
    """Chooses the behaviour and parameters that maximise P(goal).

    Args:
        models: A fitted :class:`~.effect_model.ActionEffectModel` per behaviour name (one of
            :data:`affordance_env.registry.BEHAVIOR_NAMES`, in any order), each of the same inputs: the object's
            features (the 49 of ``affordance_env.FEATURE_NAMES``) and the 3 action parameters.
        n_candidates: Parameter vectors scored per behaviour: the optimiser's seed, or (``"grid"``) all of them.
        threshold: Abstain below this P(goal).
        random_state: Seed of the candidates and of the optimiser's draws: a decision is the same for the same
            seed and inputs.
        max_checks: Calls to ``feasible`` per decision at most (:data:`MAX_CHECKS`); when none of the candidates
            asked is feasible the choice is None (``behavior`` None, abstained).
        table: The table top's extent, ((x_low, y_low), (x_high, y_high)) [m] in the frame of the positions the
            methods are given (default :data:`SCENE_TABLE`, the scene's): a predicted outcome that leaves the
            object's centre beyond it leaves the object off the table, whatever the neighbour it comes from says
            (a place beyond the edge was never executed, so no training outcome says what it does). None: no table.
        optimizer: ``"cem"`` (a cross-entropy search over each behaviour's parameters, :data:`EVALUATIONS` model
            evaluations a decision) or ``"grid"`` (the ``n_candidates`` alone, refined around the best):
            :data:`OPTIMIZERS`.

    Every method checks its inputs before any work: ``features`` must have as many values as the models take
    (ValueError), the goal must be a goal of :mod:`affordance_learning.planning.goals` (TypeError), a
    :class:`~affordance_learning.planning.goals.Place` needs ``start_xy``; with a ``table``, a place's target (and
    :meth:`toward`'s) must lie on the table top, and ``start_xy`` within :data:`SEEN_MARGIN` of it (ValueError).
    """

    def __init__(self, models: Mapping[str, ActionEffectModel], n_candidates: int = 64, threshold: float = 0.5,
                 random_state: int = 0, max_checks: int = MAX_CHECKS,
                 table: tuple[tuple[float, float], tuple[float, float]] | None = SCENE_TABLE,
                 optimizer: str = "cem") -> None:
        if optimizer not in OPTIMIZERS:
            raise InvalidValueError(f"optimizer must be one of {', '.join(OPTIMIZERS)}, got {optimizer!r}.")
        #: How each behaviour's parameters are chosen (:data:`OPTIMIZERS`).
        self.optimizer = optimizer
        if not models:
            raise InvalidValueError("models must map at least one behaviour name to its fitted ActionEffectModel.")
        if not (isinstance(threshold, int | float) and 0.0 <= threshold <= 1.0):
            raise InvalidValueError(f"threshold must be a probability in [0, 1], got {threshold!r}.")
        if not is_integer(max_checks) or max_checks < 1:
            raise InvalidValueError(f"max_checks must be an integer >= 1, got {max_checks!r}.")
        unknown = [name for name in models if name not in BEHAVIOR_NAMES]
        if unknown:
            raise InvalidValueError(f"Unknown behavior(s) {', '.join(map(repr, unknown))} in models. Valid behaviors: "
                             f"{', '.join(BEHAVIOR_NAMES)}.")
        for name, model in models.items():
            if not isinstance(model, ActionEffectModel) or not hasattr(model, "forest_"):
                raise TypeError(f"models[{name!r}] must be a fitted ActionEffectModel, got {type(model).__name__}.")
        inputs = {name: model.n_features_in_ for name, model in models.items()}
        if len(set(inputs.values())) > 1:
            raise InvalidValueError(f"the models must take the same inputs, got {inputs} input columns per behaviour.")
        #: The models by behaviour, in the registry's order (:data:`affordance_env.registry.BEHAVIOR_NAMES`)
        #: whatever the order of ``models``: the order of :meth:`scores`, and candidates that rank equal go to the
        #: earlier behaviour.
        self.models = {name: models[name] for name in BEHAVIOR_NAMES if name in models}
        self.threshold = float(threshold)
        self.max_checks = int(max_checks)
        if not is_integer(random_state) or random_state < 0:
            raise InvalidValueError(f"random_state must be an integer >= 0, got {random_state!r}.")
        self.params = candidate_params(n_candidates, random_state)
        #: The seed of the candidates and of the optimiser's draws.
        self.random_state = int(random_state)
        if table is not None:
            corners = float_array("table", table, finite=False, error=InvalidValueError,
                                  expected="the table top's ((x_low, y_low), (x_high, y_high)) [m]")
            if corners.shape != (2, 2) or not np.all(np.isfinite(corners)) or np.any(corners[0] >= corners[1]):
                raise InvalidValueError(f"table must be the table top's ((x_low, y_low), (x_high, y_high)) [m], "
                                        f"got {table!r}.")
            table = (corners[0], corners[1])
        #: The table top's extent, (x, y) low and high [m], or None: an outcome that leaves the object's centre
        #: beyond it leaves the object off the table (:meth:`on_table`).
        self.table = table
        # The offsets of a refinement (REFINE_POINTS within REFINE_RADIUS), drawn once.
        local = qmc.Sobol(self.params.shape[1], scramble=True, seed=random_state + 1).random_base2(
            int(np.log2(REFINE_POINTS)))
        self._offsets = REFINE_RADIUS * (2.0 * local - 1.0)
        #: How many feature values each method's ``features`` must have: the models' inputs but the parameters.
        self.n_features = next(iter(inputs.values())) - self.params.shape[1]
        #: The actions that failed to reach, each (behaviour, params or None for all of them, where the object was
        #: (x, y) or None, its features): :meth:`note_failure`.
        self.failures: list[tuple[str, np.ndarray | None, np.ndarray | None, np.ndarray]] = []

    # --- what failed ---------------------------------------------------------------------------------------------
    def note_failure(self, behavior: str, params, start_xy=None, features=None) -> None:
        """Remember that ``behavior`` with ``params`` failed on the object at ``start_xy`` [m] (or, without a
        position, seen with ``features``): it failed to reach it, or left it where it was. No later decision on that
        object there chooses it, or an action of ``behavior`` within :data:`REFUSAL_RADIUS` of it, again.
        ``params`` None: every action of ``behavior`` failed there (a grasp that held nothing: its parameters
        name where to put the object down, and the hand takes it as the canonical grasp does whatever they are)."""
        if behavior not in self.models:
            raise InvalidValueError(f"Unknown behavior {behavior!r}: the planner's are {', '.join(self.models)}.")
        if params is not None:
            params = float_array("params", params, (self.params.shape[1],), error=InvalidValueError,
                                 expected=f"the behaviour's {self.params.shape[1]} finite parameters, or None")
        where = None if start_xy is None else _check_start(start_xy)
        seen = (np.zeros(0) if features is None
                else self._inputs(features, self.params[:1])[0, : self.n_features])
        self.failures.append((str(behavior), None if params is None else params.copy(), where, seen))

    def _check_where(self, start_xy) -> np.ndarray:
        """``start_xy``, where the object is: one (x, y) [m], on the table top (:attr:`table`, widened by
        :data:`SEEN_MARGIN`) if there is one."""
        start = _check_start(start_xy)
        if self.table is not None:
            low, high = self.table
            _check_on_table("start_xy", start_xy, start, (low - SEEN_MARGIN, high + SEEN_MARGIN))
        return start

    def forget_failures(self) -> None:
        """Forget every failure noted (:meth:`note_failure`): for a new object or episode."""
        self.failures.clear()

    def _excluded(self, features: np.ndarray, start: np.ndarray | None,
                  candidates: Mapping[str, np.ndarray]) -> set[tuple[str, int]]:
        """The candidates (behaviour, index in ``candidates[behaviour]``) that failed on this object where it is
        now."""
        out = set()
        for name, params, where, seen in self.failures:
            if name not in candidates:
                continue
            if where is not None and start is not None:
                here = np.linalg.norm(where - start) <= FAILURE_RADIUS
            else:
                here = seen.shape == features.shape and np.allclose(seen, features, rtol=1e-3, atol=1e-6)
            if here:
                near = (np.arange(len(candidates[name])) if params is None
                        else np.flatnonzero(np.linalg.norm(candidates[name] - params, axis=1) < REFUSAL_RADIUS))
                out.update((name, int(k)) for k in near)
        return out

    # --- scoring -------------------------------------------------------------------------------------------------
    def _inputs(self, features: np.ndarray, params: np.ndarray | None = None) -> np.ndarray:
        """The models' inputs: ``features`` beside every row of ``params`` (default: the candidates)."""
        params = self.params if params is None else params
        named = " (affordance_env.FEATURE_NAMES)" if self.n_features == 49 else ""
        x = float_array("features", features, finite=False, error=InvalidValueError,
                        expected=f"the object's {self.n_features} feature values{named}")
        if x.size != self.n_features or x.ndim > 2:
            raise InvalidValueError(
                f"features must be the object's {self.n_features} feature values{named}, the models' "
                             f"inputs but the {self.params.shape[1]} action parameters; got shape {x.shape}.")
        x = x.ravel()
        if not np.all(np.isfinite(x)):
            raise InvalidValueError("features must be finite (the object must have been seen).")
        check_float32_range("features", x)
        return np.hstack([np.repeat(x[None], len(params), axis=0), params])

    def on_table(self, outcomes: PredictiveOutcomes, start) -> PredictiveOutcomes:
        """``outcomes`` as the planner reads them: every entry that leaves the object's centre beyond the table top's
        edge (:attr:`table`) counted off the table
        (:meth:`~.effect_model.PredictiveOutcomes.off_beyond`); as they are without ``start``
        (where the object is: (2,), or (m, 2) one per query) or without a table."""
        return outcomes if start is None or self.table is None else outcomes.off_beyond(start, *self.table)

    def _score(self, features: np.ndarray, goal: Goal, start_xy, candidates: Mapping[str, np.ndarray] | None = None
               ) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Per behaviour, every candidate's P(goal) and expected progress towards it less :data:`SPREAD_WEIGHT`
        times its spread (the goal's :meth:`~affordance_learning.planning.goals.Goal.progress`; 0 where it has no
        distance), from the models' predictive outcomes (each neighbour's displacement at the candidate's action:
        :meth:`~.effect_model.ActionEffectModel.predictive_outcomes`, read with the table: :meth:`on_table`).
        ``candidates``: the actions per behaviour (default: :attr:`params` for every behaviour). ``start_xy`` (where
        the object is) is needed for a goal that :attr:`~affordance_learning.planning.goals.Goal.needs_start` (a
        :class:`Place`), and for any goal, when given, says which outcomes leave the object beyond the table's
        edge; the places the goal names must lie on the table top."""
        start = self._check_goal(goal, start_xy)
        if candidates is None:
            candidates = dict.fromkeys(self.models, self.params)
        out = {}
        for name, params in candidates.items():
            outcomes = self.on_table(self.models[name].predictive_outcomes(self._inputs(features, params)), start)
            p = outcomes.probability(goal, start)
            progress = goal.progress(outcomes, start)
            if progress is None:
                out[name] = (p, np.zeros(len(p)))
                continue
            mean = outcomes.share(progress)
            spread = np.sqrt(np.maximum(outcomes.share(progress**2) - mean**2, 0.0))
            out[name] = (p, mean - SPREAD_WEIGHT * spread)
        return out

    def _check_goal(self, goal: Goal, start_xy) -> np.ndarray | None:
        """``start_xy`` checked (None where the goal needs none and none is given); the goal's places on the
        table."""
        check_goal(goal)
        start = self._check_where(start_xy) if goal.needs_start or start_xy is not None else None
        if self.table is not None:
            for what, xy in goal.positions().items():
                _check_on_table(f"the goal's {what}", xy, np.asarray(xy), self.table)
        return start

    def scores(self, features: np.ndarray, goal: Goal, start_xy=None) -> dict[str, np.ndarray]:
        """P(goal) of every candidate, per behaviour: {behaviour: (n_candidates,)}; ``start_xy`` as for
        :meth:`choose` (outcomes that leave the object beyond the table's edge are off the table)."""
        return {name: p for name, (p, _) in self._score(features, goal, start_xy).items()}

    # --- the cross-entropy search --------------------------------------------------------------------------------
    def _moment_score(self, name: str, features: np.ndarray, goal: Goal, start: np.ndarray | None,
                      params: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The search's cheap score of ``params`` (n, 3) of behaviour ``name``: P(goal) and progress less
        :data:`SPREAD_WEIGHT` times its spread, as :meth:`_score` gives them, from each kind of outcome's weight,
        mean and covariance (:meth:`~.effect_model.ActionEffectModel.kind_moments`). P of a goal with a distance
        comes from a Gaussian per kind (a place's disc as a square of the same area); a goal without one reads
        no displacement, and its P is the exact share of the training outcomes that reach it."""
        model, X = self.models[name], self._inputs(features, params)
        if not goal.has_distance:
            reached = goal.reached(model.outcome_frame(), start).astype(np.float64)
            return model.leaf_share(X, reached), np.zeros(len(params))
        moments = model.kind_moments(X, check_input=False)  # _inputs checked the features
        return _gaussian_score(moments, goal, start, self.table)

    def _optimise(self, features: np.ndarray, goal: Goal, start: np.ndarray | None, excluded_near
                  ) -> tuple[dict[str, np.ndarray], int]:
        """Per behaviour, the actions to score on their whole predictive outcomes: the search's finalists (the
        best it found, the best of other regions, the canonical action), and the cheap scores it made.
        ``excluded_near(name, params)``: (n,) bool, the actions that failed here before (never elites)."""
        finalists, evaluations = {}, 0
        step = P_RESOLUTION if goal.ranks_by_progress else 0.0
        for index, name in enumerate(self.models):
            rng = np.random.default_rng([self.random_state, index])
            tried = [self.params]
            p, g = self._moment_score(name, features, goal, start, self.params)
            scores = [(p, g)]
            for _ in range(CEM_ITERATIONS):
                order = _order(np.concatenate([s[0] for s in scores]), np.concatenate([s[1] for s in scores]),
                               step, excluded_near(name, np.vstack(tried)))
                elites = np.vstack(tried)[order[:CEM_ELITES]]
                spread = np.maximum(elites.std(axis=0), CEM_MIN_STD)
                draw = np.clip(elites.mean(axis=0) + spread * rng.standard_normal((CEM_SAMPLES, elites.shape[1])),
                               -1.0, 1.0)
                tried.append(draw)
                scores.append(self._moment_score(name, features, goal, start, draw))
            every = np.vstack(tried)
            evaluations += len(every)
            failed = excluded_near(name, every)
            order = _order(np.concatenate([s[0] for s in scores]), np.concatenate([s[1] for s in scores]), step,
                           failed)
            order = order[~failed[order]] if not failed.all() else order  # none that failed here, if any other
            chosen: list[np.ndarray] = []
            for k in order:  # the best, distinct
                if len(chosen) == FINALISTS:
                    break
                if not any(np.array_equal(every[k], c) for c in chosen):
                    chosen.append(every[k])
            ranked = every[order]
            for _ in range(FINALIST_REGIONS):  # then the best of other regions
                far = np.min(np.linalg.norm(ranked[:, None, :] - np.array(chosen)[None], axis=2), axis=1)
                others = np.flatnonzero(far >= REFUSAL_RADIUS)
                if not others.size:
                    break
                chosen.append(ranked[others[0]])
            if not any(np.array_equal(c, self.params[0]) for c in chosen):
                chosen.append(self.params[0])  # the canonical action: what the checks fall back on
            finalists[name] = np.array(chosen)
        return finalists, evaluations

    def _excluded_near(self, features: np.ndarray, start: np.ndarray | None):
        """``excluded_near(name, params)``: which of ``params`` (n, 3) of ``name`` lie within
        :data:`REFUSAL_RADIUS` of an action that failed on this object where it is."""
        failed = [(name, params) for name, params, where, seen in self.failures
                  if (np.linalg.norm(where - start) <= FAILURE_RADIUS if where is not None and start is not None
                      else seen.shape == features.shape and np.allclose(seen, features, rtol=1e-3, atol=1e-6))]

        def excluded_near(name: str, params: np.ndarray) -> np.ndarray:
            out = np.zeros(len(params), dtype=bool)
            for other, failed_params in failed:
                if other == name:
                    out |= (True if failed_params is None
                            else np.linalg.norm(params - failed_params, axis=1) < REFUSAL_RADIUS)
            return out

        return excluded_near

    def _candidates(self, features: np.ndarray, goal: Goal, start: np.ndarray | None
                    ) -> tuple[dict[str, np.ndarray], int]:
        """Per behaviour, the actions a decision ranks (the optimiser's finalists, or :attr:`params`), and the
        model evaluations that cost before they are scored on their whole predictive outcomes."""
        if self.optimizer == "grid":
            return dict.fromkeys(self.models, self.params), 0
        return self._optimise(features, goal, start, self._excluded_near(features, start))

    # --- asking feasible -----------------------------------------------------------------------------------------
    def _search(self, rankings, feasible, excluded: set[tuple[str, int]], candidates: Mapping[str, np.ndarray],
                asked: dict[tuple[str, int], bool] | None = None, fallback: bool = True):
        """The first entry, over ``rankings`` in turn (each a list of entries ending with behaviour and index in
        ``candidates``, the last of them every candidate), that is not ``excluded`` and that ``feasible`` accepts;
        and how many times ``feasible`` was asked.

        ``feasible`` is asked at most :data:`RANKED_CHECKS` times (or ``max_checks``, if fewer), never about a ranked
        candidate within
        :data:`REFUSAL_RADIUS` of one it refused, and one check is kept for the canonical action (the candidate of
        zeros, where there is one) of every behaviour: where the ranked candidates run out of checks, the
        canonical actions not asked about yet are, the most promising behaviour first, whatever was refused near
        them (the behaviours' workspaces are made around their canonical actions). With fewer checks than
        behaviours, the ranked candidates get one and the canonical actions of the behaviours ranked first the
        others. With the search, each ranking is gone through a second time for the actions within REFUSAL_RADIUS
        but beyond :data:`NEAR_REFUSAL_RADIUS` of every refused one (:data:`NEAR_REFUSAL_CHECKS` per behaviour), and a
        behaviour with :data:`BEHAVIOR_REFUSALS` refused gets no more checks but its canonical action's.
        Without ``fallback`` no check is kept (a refinement around an action already found). Without
        ``feasible`` the first entry not excluded."""
        asked = {} if asked is None else asked
        limit = min(self.max_checks, RANKED_CHECKS)
        refused: list[tuple[str, np.ndarray]] = [(n, candidates[n][k]) for (n, k), ok in asked.items() if not ok]
        canonical = {name: int(np.flatnonzero(np.all(params == 0.0, axis=1))[0]) for name, params in
                     candidates.items() if fallback and np.any(np.all(params == 0.0, axis=1))}

        def open_reserve() -> list[str]:
            return [n for n, k in canonical.items() if (n, k) not in asked and (n, k) not in excluded]

        def ask(key, near_refused: bool = False, radius: float = REFUSAL_RADIUS) -> bool | None:
            """feasible's answer about ``key``, asking if need be; None where it may not be asked (within
            ``radius`` of one refused, unless ``near_refused``)."""
            if key in asked:
                return asked[key]
            params = candidates[key[0]][key[1]]
            if not near_refused and any(n == key[0] and np.linalg.norm(params - other) < radius
                                        for n, other in refused):
                return None
            if (not near_refused and self.optimizer != "grid"
                    and sum(n == key[0] for n, _ in refused) >= BEHAVIOR_REFUSALS):
                return None  # this behaviour likely cannot act here: the checks go to the others
            asked[key] = bool(feasible(key[0], params))
            if not asked[key]:
                refused.append((key[0], params))
            return asked[key]

        # The search's actions lie closer together than the grid's: where its best ones were refused, a ranked
        # action near them is asked after the far ones (a second pass), rather than passed over for a worse
        # ranking (a grasp's place refused at the arm's reach, a feasible one 0.5 nearer the object).
        radii = (REFUSAL_RADIUS,) if self.optimizer == "grid" else (REFUSAL_RADIUS, NEAR_REFUSAL_RADIUS)
        for ranked in rankings:
            for radius in radii:
                second: dict[str, int] = {}  # the second pass's checks per behaviour
                for entry in ranked:
                    key = (entry[-2], entry[-1])
                    if key in excluded:
                        continue
                    if feasible is None:
                        return entry, 0
                    kept = min(len(open_reserve()) - (canonical.get(key[0]) == key[1]), limit - 1)
                    if key not in asked and len(asked) + kept >= limit:
                        break  # the remaining checks are kept for the canonical actions not asked about
                    near = radius < REFUSAL_RADIUS and key not in asked
                    if near and second.get(key[0], 0) >= NEAR_REFUSAL_CHECKS:
                        continue
                    n_before = len(asked)
                    found = ask(key, radius=radius)
                    if near:
                        second[key[0]] = second.get(key[0], 0) + len(asked) - n_before
                    if found:
                        return entry, len(asked)
        if feasible is None:
            return None, 0
        last = {(e[-2], e[-1]): e for e in rankings[-1]} if rankings else {}
        order = {}
        for entry in rankings[-1] if rankings else ():
            order.setdefault(entry[-2], len(order))
        for name in sorted(open_reserve(), key=lambda n: order.get(n, len(order))):
            if len(asked) >= limit:
                break
            key = (name, canonical[name])
            if ask(key, near_refused=True) and key in last:  # the canonical action, whatever was refused near it
                return last[key], len(asked)
        return None, len(asked)

    def _probe(self, rank: Callable[[dict[str, np.ndarray]], tuple[list[tuple], int]], feasible,
               asked: dict[tuple[str, int], bool], candidates: Mapping[str, np.ndarray], features: np.ndarray,
               start: np.ndarray | None) -> tuple[tuple | None, int, dict[str, np.ndarray]]:
        """Where :meth:`_search` found nothing: a feasible one of the :data:`PROBES` of every behaviour (or None),
        the model evaluations ranking them took, and ``candidates`` with the probes after each behaviour's (the
        entry's index is into these). ``rank(probes)`` gives the probes' entries, best first (each ending with
        behaviour and index in ``probes``), and the model evaluations it made. The behaviours take turns, in the
        order of their best probe; each asks about its probe farthest from its actions refused so far (of equally
        far ones, the farthest from all of them on average, then the better ranked), never one within
        :data:`PROBE_RADIUS` of them, until one is feasible or :attr:`max_checks` are spent: where a behaviour
        reaches only one region of its parameters, the checks go where it has not been refused yet. ``asked`` gets
        the answers."""
        ranked, evaluations = rank({name: PROBES for name in candidates})
        offset = {name: len(params) for name, params in candidates.items()}
        candidates = {name: np.vstack([params, PROBES]) for name, params in candidates.items()}
        excluded = self._excluded(features, start, candidates)
        refused = {name: [candidates[n][k] for (n, k), ok in asked.items() if n == name and not ok]
                   for name in candidates}
        left = {}  # per behaviour, its probes (entry, index in candidates) not asked yet, best ranked first
        for entry in ranked:
            name, k = entry[-2], entry[-1] + offset[entry[-2]]
            if (name, k) not in asked and (name, k) not in excluded:
                left.setdefault(name, []).append((entry, k))
        while left and len(asked) < self.max_checks:
            for name in list(left):
                if len(asked) >= self.max_checks:
                    break
                gaps = [np.linalg.norm(candidates[name][k] - np.array(refused[name]), axis=1) if refused[name]
                        else np.full(1, np.inf) for _, k in left[name]]
                # the farthest from the nearest refused action; of equally far ones, from all of them on average
                i = max(range(len(gaps)), key=lambda j: (round(float(gaps[j].min()), 2), float(gaps[j].mean()), -j))
                entry, k = left[name].pop(i)
                if gaps[i].min() < PROBE_RADIUS:  # the farthest is near a refused one: so are all the others
                    del left[name]
                    continue
                if not left[name]:
                    del left[name]
                asked[(name, k)] = bool(feasible(name, candidates[name][k]))
                if asked[(name, k)]:
                    return (*entry[:-1], k), evaluations, candidates
                refused[name].append(candidates[name][k])
        return None, evaluations, candidates

    def _ranked(self, scores: Mapping[str, tuple[np.ndarray, np.ndarray]], goal: Goal) -> list[tuple]:
        """Every candidate (P, progress, behaviour, index), best first: by P(goal), for a goal that
        :attr:`~affordance_learning.planning.goals.Goal.ranks_by_progress` (a place) in steps of P_RESOLUTION (the
        nearer expected end decides among them), then by progress (less its spread), then the earlier candidate,
        behaviour after behaviour."""
        step = P_RESOLUTION if goal.ranks_by_progress else 0.0
        ranked = sorted(((float(p), float(g), k, i, name) for i, name in enumerate(scores)
                         for k, (p, g) in enumerate(zip(*scores[name], strict=True))),
                        key=lambda e: (-np.floor(e[0] / step + 1e-9) if step else -e[0], -e[1], e[2], e[3]))
        return [(p, g, name, k) for p, g, k, _, name in ranked]

    def _nothing(self, asked: int, evaluations: int) -> Choice:
        """The choice that names no action, and why."""
        if asked:
            why = (f"none of the {asked} actions asked about was feasible (the best ranked, each behaviour's "
                   f"canonical action and actions spread over its parameters; at most {self.max_checks} a decision)")
        else:
            why = "every action scored failed on this object where it is before (note_failure)"
        return Choice(None, None, 0.0, True, checked=asked, value=0.0, reason=why, evaluations=evaluations)

    # --- deciding ------------------------------------------------------------------------------------------------
    def choose(self, features: np.ndarray, goal: Goal, start_xy=None,
               feasible: Callable[[str, np.ndarray], bool] | None = None) -> Choice:
        """The most likely feasible action for ``goal`` on the object seen with ``features`` at ``start_xy``, not
        one that failed there (:meth:`note_failure`), ranked as :meth:`_ranked` says among the optimiser's
        finalists (module docstring); ``feasible`` is asked at most ``max_checks`` times (:meth:`_search`, then
        where none of those is feasible the :data:`PROBES`: :meth:`_probe`), and where none of those is feasible
        the choice names no action (``behavior`` and ``params`` None, with a ``reason``). With ``optimizer="grid"``
        and a goal with a distance (:class:`Move`, :class:`Place`), the actions around the one found are scored
        too (:data:`REFINE_POINTS` within :data:`REFINE_RADIUS`), and the best of them that ranks above it is taken
        if feasible (at most :data:`REFINE_CHECKS` asked, within ``max_checks``)."""
        start = self._check_goal(goal, start_xy)
        seen = self._inputs(features)[0, : self.n_features]
        candidates, evaluations = self._candidates(seen, goal, start)
        scores = self._score(features, goal, start_xy, candidates)
        evaluations += sum(len(c) for c in candidates.values())
        excluded = self._excluded(seen, start, candidates)
        asked: dict[tuple[str, int], bool] = {}
        best, checked = self._search([self._ranked(scores, goal)], feasible, excluded, candidates, asked)
        if best is None and feasible is not None and checked < self.max_checks:
            def rank(probes):  # the probes ranked as the candidates are, each scored once
                return self._ranked(self._score(features, goal, start_xy, probes), goal), sum(map(len, probes.values()))

            best, more, candidates = self._probe(rank, feasible, asked, candidates, seen, start)
            checked, evaluations = len(asked), evaluations + more
        if best is None:
            return self._nothing(checked, evaluations)
        p, _, name, k = best
        params = candidates[name][k]
        if goal.has_distance and self.optimizer == "grid":
            local = {name: np.clip(params + self._offsets, -1.0, 1.0)}
            p_local, g_local = self._score(features, goal, start_xy, local)[name]
            evaluations += len(p_local)
            around = {name: (np.append(p_local, p), np.append(g_local, best[1]))}  # the one found last
            local[name] = np.vstack([local[name], params])
            excluded, refined = self._excluded(seen, start, local), {}
            for entry in self._ranked(around, goal):
                if entry[-1] == len(p_local) or len(refined) >= min(REFINE_CHECKS, self.max_checks - checked):
                    break  # none better than the one found, or enough asked
                found = self._search([[entry]], feasible, excluded, local, refined, fallback=False)[0]
                if found is not None:
                    p, params = found[0], local[name][found[-1]]
                    break
            checked += len(refined)
        return Choice(name, params.copy(), p, p < self.threshold, checked=checked,
                      reason=_below(p, self.threshold), evaluations=evaluations)

    def toward(self, features: np.ndarray, start_xy, target_xy, tolerance: float,
               feasible: Callable[[str, np.ndarray], bool] | None = None, steps_left: int | None = None,
               reachable: Callable[[str, np.ndarray], np.ndarray] | None = in_workspace) -> Choice:
        """The next interaction towards ``target_xy`` [m], a place on the table top (:attr:`table`, the scene's
        :func:`table_extent` without one; another is a ValueError), re-planned after every interaction.

        The horizon follows ``steps_left``: with 2 or more (or None: more interactions may follow) a search over
        sequences of two interactions (the planner looks no further): an action's value is its P(within
        ``tolerance``) plus the share of its predicted outcomes that neither end within nor leave the table times
        the best P(within) of a second interaction from there, averaged over the most likely of those outcomes
        (the object where the outcome leaves it, seen with the initial features plus the outcome's perceptual
        effect, or unchanged where the models have none); and its expected distance is the one after the best
        second interaction where that is nearer, so that an action that brings the object where a behaviour can
        act toward the target ranks before one that leaves it where none can. With ``steps_left`` 1 (this
        interaction is the last) the value is P(within) and the distance this interaction's. An action likely
        enough to end within (the threshold) is taken at once; else the most valuable one, if its value reaches
        ``MIN_SEQUENCE_VALUE``; else the one whose predicted outcomes end nearest on average (less
        :data:`SPREAD_WEIGHT` times their spread). The actions are the optimiser's finalists for the place
        (:meth:`choose`) and :data:`TOWARD_SEEDS` of its seeds (:attr:`params`, spread over the parameters: first
        actions that bring the object elsewhere, for a second interaction from there). Actions that failed on the
        object where it is (:meth:`note_failure`) are left out, and
        ``feasible`` is asked at most ``max_checks`` times (:meth:`_search`: every behaviour's canonical action
        gets a check where the ranked ones are refused; then the :data:`PROBES`, :meth:`_probe`); the choice names
        no action only where none of those was feasible.

        Args:
            steps_left: Interactions left in the episode, this one included; None: more than one.
            reachable: ``reachable(behavior, xy)``, (n, 2) [m] -> (n,) bool: where a behaviour can act; by default
                the behaviours' workspaces (:func:`in_workspace`). A second interaction counts only where its
                behaviour reaches, and outcomes that leave the object where no behaviour reaches count as
                ``OFF_TABLE_DISTANCE`` away when actions are ranked by distance. None: everywhere.
        """
        if steps_left is not None and (not is_integer(steps_left) or steps_left < 1):
            raise InvalidValueError(f"steps_left must be None or an integer >= 1, got {steps_left!r}.")
        goal = Place(target_xy, tolerance)
        target = np.asarray(goal.target_xy)
        _check_on_table("target_xy", target_xy, target, self.table)
        start = self._check_where(start_xy)
        features = self._inputs(features)[0, : self.n_features]
        candidates, evaluations = self._candidates(features, goal, start)
        if self.optimizer != "grid":  # the seeds too: first actions that lead elsewhere, for the second interaction
            seeds = self.params[:TOWARD_SEEDS]
            candidates = {name: _distinct(np.vstack([found, seeds])) for name, found in candidates.items()}
        ranked, evaluations = self._toward_ranked(features, goal, start, candidates, steps_left, reachable,
                                                  evaluations)
        excluded = self._excluded(features, start, candidates)
        asked: dict[tuple[str, int], bool] = {}
        found, checked = self._search(ranked, feasible, excluded, candidates, asked)
        if found is None and feasible is not None and checked < self.max_checks:
            def rank(probes):  # the probes' rankings one after the other, each probe at its first place
                first: dict[tuple[str, int], tuple] = {}
                rankings, spent = self._toward_ranked(features, goal, start, probes, steps_left, reachable, 0)
                for ranking in rankings:
                    for entry in ranking:
                        first.setdefault(entry[-2:], entry)
                return list(first.values()), spent

            found, more, candidates = self._probe(rank, feasible, asked, candidates, features, start)
            checked, evaluations = len(asked), evaluations + more
        if found is None:
            return self._nothing(checked, evaluations)
        v, p, d, name, k = found
        return Choice(name, candidates[name][k].copy(), p, p < self.threshold, d, checked, v,
                      reason=_below(p, self.threshold), evaluations=evaluations)

    def _toward_ranked(self, features: np.ndarray, goal: Place, start: np.ndarray, candidates: Mapping[str, np.ndarray],
                       steps_left: int | None, reachable, evaluations: int) -> tuple[list[list[tuple]], int]:
        """:meth:`toward`'s rankings of ``candidates`` (per behaviour): those likely enough to end within, the most
        valuable over two interactions, the nearest on average, each of entries (value, P(within), expected
        distance, behaviour, index); and ``evaluations`` plus the model evaluations made."""
        target = np.asarray(goal.target_xy)
        names = list(self.models)
        predicted, p1, distance, ends = {}, {}, {}, {}
        for name, model in self.models.items():
            outcomes = self.on_table(model.predictive_outcomes(self._inputs(features, candidates[name])), start)
            end, off = start + outcomes.displacement, outcomes["off_table"].astype(bool)
            within = goal.reached(outcomes, start).astype(np.float64)
            dist = np.where(off, OFF_TABLE_DISTANCE, np.linalg.norm(end - target, axis=1))
            if reachable is not None:  # an end no behaviour reaches counts as off the table, unless within
                open_ = np.flatnonzero((within == 0) & ~off)
                dist[open_[~_reached_by_any(reachable, names, end[open_])]] = OFF_TABLE_DISTANCE
            predicted[name], ends[name] = outcomes, (end, off, within)
            mean = outcomes.share(dist)
            spread = np.sqrt(np.maximum(outcomes.share(dist**2) - mean**2, 0.0))
            p1[name], distance[name] = outcomes.share(within), mean + SPREAD_WEIGHT * spread
            evaluations += len(candidates[name])
        value = {name: p1[name].copy() for name in names}
        if steps_left is None or steps_left >= 2:
            evaluations += self._look_ahead(features, goal, predicted, ends, p1, distance, value, reachable,
                                            candidates)
        entries = [(float(value[n][k]), float(p1[n][k]), float(distance[n][k]), n, k)
                   for n in names for k in range(len(candidates[n]))]
        entries.sort(key=lambda e: e[-1])  # action by action across the behaviours, as ties go
        finish = sorted((e for e in entries if e[1] >= self.threshold), key=lambda e: (-e[1], e[2]))
        sequence = sorted((e for e in entries if e[0] >= MIN_SEQUENCE_VALUE), key=lambda e: (-e[0], e[2]))
        nearest = sorted(entries, key=lambda e: (e[2], -e[0]))
        return [finish, sequence, nearest], evaluations

    def _look_ahead(self, features, goal, predicted, ends, p1, distance, value, reachable, candidates) -> int:
        """Add to ``value`` (P(within) of each first action) the chance of a second interaction (see
        :meth:`toward`), and bring ``distance`` down to the expected distance after the best second interaction
        where that is nearer, over the ``LOOKAHEAD_ROOTS`` first actions nearest on average, half as many most
        likely and each behaviour's nearest (a behaviour that brings the object nowhere near may bring it where
        another can act), their ``LOOKAHEAD_OUTCOMES`` most likely outcomes each, and ``LOOKAHEAD_SECOND``
        parameter vectors per behaviour for the second (scored by the search's cheap score:
        :meth:`_moment_score`). ``predicted`` and ``ends``: per behaviour, the first actions' predictive outcomes
        and, per entry, where it ends, whether it left the table and whether it ends within the tolerance.
        Returns the model evaluations it made."""
        names = list(self.models)
        flat = [(n, k) for n in names for k in range(len(candidates[n]))]
        p_all = np.concatenate([p1[n] for n in names])
        d_all = np.concatenate([distance[n] for n in names])
        roots = list(dict.fromkeys([flat[i] for i in np.argsort(d_all, kind="stable")[:LOOKAHEAD_ROOTS]]
                                   + [flat[i] for i in np.argsort(-p_all, kind="stable")[:LOOKAHEAD_ROOTS // 2]]
                                   + [(n, int(np.argmin(distance[n]))) for n in names]))  # each behaviour's nearest
        # The outcomes (root, training row) the roots lead to: where each ends and the training row of its effect.
        states: dict[tuple[str, int, int], int] = {}
        where: list[np.ndarray] = []
        # Per root: the mass of its outcomes that leave something to do (neither within nor off the table), and
        # the most likely of them with their weights: a sample of where the second interaction starts.
        links: list[tuple[str, int, float, list[tuple[int, float]]]] = []
        for name, k in roots:
            weights = predicted[name].weights
            entries = np.arange(weights.indptr[k], weights.indptr[k + 1])  # each training outcome once
            end, off, within = ends[name]
            open_ = entries[~within[entries].astype(bool) & ~off[entries]]
            if not open_.size:
                continue
            data = weights.data[open_]
            top = open_[np.argsort(-data, kind="stable")[:LOOKAHEAD_OUTCOMES]]
            followed = []
            for e in top:
                key = (name, k, int(weights.indices[e]))
                if key not in states:
                    states[key] = len(states)
                    where.append(end[e])
                followed.append((states[key], float(weights.data[e])))
            links.append((name, k, float(data.sum()), followed))
        if not states:
            return 0
        keys = list(states)
        for name in {n for n, _, _ in keys}:
            if len(self.models[name].effect_columns_) not in (0, len(features)):
                raise InvalidValueError(
                    f"the model of {name!r} has {len(self.models[name].effect_columns_)} effect columns "
                                 f"for {len(features)} features: looking ahead needs models fitted on outcome tables "
                                 "with the perceptual effect (affordance_learning.planning.outcomes.outcome_table), "
                                  "or none.")

        def effect(name: str, j: int) -> np.ndarray | float:  # a model without the perceptual effect: unchanged
            columns = self.models[name].effect_columns_
            return self.models[name].outcomes_[j, columns] if len(columns) else 0.0

        xy = np.array(where)
        # The models' inputs at a state are the features it is seen with (the root's behaviour and the training
        # outcome's effect), not where it is: states that share them share the models' moments.
        inputs: dict[tuple[str, int], int] = {}
        row = np.array([inputs.setdefault((n, j), len(inputs)) for n, _, j in keys])
        seen = np.array([features + effect(n, j) for n, j in inputs])
        second = self.params[: LOOKAHEAD_SECOND]
        best = np.zeros(len(keys))
        nearest = np.full(len(keys), np.inf)  # the expected distance after the best second interaction
        target = np.asarray(goal.target_xy)
        evaluations = 0
        for name, model in self.models.items():
            acts = np.flatnonzero(np.ones(len(keys), bool) if reachable is None else reachable(name, xy))
            if not acts.size:  # the behaviour reaches none of the states: it scores none of them
                continue
            needed = np.unique(row[acts])
            X2 = np.hstack([np.repeat(seen[needed], len(second), axis=0), np.tile(second, (len(needed), 1))])
            found = model.kind_moments(X2, check_input=False)
            at = (np.searchsorted(needed, row[acts])[:, None] * len(second) + np.arange(len(second))).ravel()
            moments = KindMoments(found.mass[at], found.mean[at], found.covariance[at], found.flags)
            p2, g2 = _gaussian_score(moments, goal, np.repeat(xy[acts], len(second), axis=0), self.table)
            best[acts] = np.maximum(best[acts], p2.reshape(len(acts), len(second)).max(axis=1))
            nearest[acts] = np.minimum(nearest[acts], -g2.reshape(len(acts), len(second)).max(axis=1))
            evaluations += len(X2)
        here = np.linalg.norm(xy - target, axis=1)
        for name, k, mass, followed in links:  # the followed outcomes stand for all that leave something to do
            total = sum(w for _, w in followed)
            value[name][k] += mass * sum(w * best[state] for state, w in followed) / total
            gain = sum(w * min(nearest[state] - here[state], 0.0) for state, w in followed) / total
            distance[name][k] += mass * gain
        return evaluations


def _order(p: np.ndarray, g: np.ndarray, step: float, excluded: np.ndarray) -> np.ndarray:
    """The indices of actions scored (P, progress), best first as :meth:`Planner._ranked` ranks them, those
    ``excluded`` last."""
    first = -np.floor(p / step + 1e-9) if step else -p
    return np.lexsort((-g, first, excluded))


def _gaussian_score(moments: KindMoments, goal: Goal, start, table) -> tuple[np.ndarray, np.ndarray]:
    """(P(goal), progress less :data:`SPREAD_WEIGHT` times its spread) of each query from its kinds' moments, for a
    :class:`Move` or a :class:`Place` from ``start`` ((2,) or (m, 2) [m]; a kind whose mean end lies beyond the
    ``table``'s edge counts as off it). Each kind's displacement is taken as a Gaussian: P that it moves at least
    the distance along the direction, or (the disc of the tolerance as a square of the same area, axis by axis)
    that it ends within the tolerance; the progress's mean and spread from the kinds' means and covariances."""
    mass, mean, cov = moments.mass, moments.mean, moments.covariance
    off = np.broadcast_to(moments.flag("off_table")[None, :], mass.shape)
    sd = np.sqrt(np.maximum(np.diagonal(cov, axis1=-2, axis2=-1), 1e-12))  # (m, kinds, 2)
    if start is not None:
        start = np.asarray(start, dtype=np.float64)
        end = (start[:, None, :] if start.ndim == 2 else start) + mean
        if table is not None:
            off = off | np.any((end < table[0]) | (end > table[1]), axis=-1)
    if isinstance(goal, Move):
        direction = np.asarray(goal.direction)
        along = mean @ direction
        var = np.einsum("i,mcij,j->mc", direction, cov, direction)
        p_kind = ndtr((along - goal.min_distance) / np.sqrt(np.maximum(var, 1e-12)))
        progress, second = np.where(off, -OFF_TABLE_DISTANCE, along), np.where(off, OFF_TABLE_DISTANCE**2,
                                                                               along**2 + var)
    else:
        miss = end - np.asarray(goal.target_xy)
        half = goal.tolerance * np.sqrt(np.pi) / 2.0
        p_kind = np.prod(ndtr((half - miss) / sd) - ndtr((-half - miss) / sd), axis=-1)
        square = np.sum(miss**2, axis=-1) + np.trace(cov, axis1=-2, axis2=-1)  # E |end - target|^2 of the kind
        progress = -np.where(off, OFF_TABLE_DISTANCE, np.sqrt(square))
        second = np.where(off, OFF_TABLE_DISTANCE**2, square)
    p = np.minimum(np.sum(mass * np.where(off, 0.0, p_kind), axis=1), 1.0)
    mean_progress = np.sum(mass * progress, axis=1)
    spread = np.sqrt(np.maximum(np.sum(mass * second, axis=1) - mean_progress**2, 0.0))
    return p, mean_progress - SPREAD_WEIGHT * spread
