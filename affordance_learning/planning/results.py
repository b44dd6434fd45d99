"""The results of ``affordance plan`` (:func:`~affordance_learning.planning.experiment.run_plan`, its ``results.json``):
:class:`PlanResults`, frozen dataclasses that the experiment's stages build and that mirror ``results.json`` key for
key, with typed queries on top (a policy's :class:`Share` of its goals, its episodes, ...).

One generic writer and reader (:mod:`affordance_learning.common.typed_json`) goes between them and the JSON:
``json.dumps(to_json(results), indent=1, default=float)`` is the file, :meth:`PlanResults.from_dict` reads it back.
Results of an older version are brought to the current one first (:func:`current_plan_results`).

Units: every share is a fraction in [0, 1] (with its Wilson 95 % interval where the results hold one), distances
are in metres, times in seconds.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Annotated, Any

from affordance_learning.common.exceptions import InvalidValueError
from affordance_learning.common.typed_json import from_json, json_options

#: The ``format`` a plan's ``results.json`` names, and its ``version``: version 1 lacks what later runs recorded
#: (``placement_error_n``, the goals' sizes, ...); both are read.
PLAN_RESULTS_FORMAT, PLAN_RESULTS_VERSION = "tap-affordance-plan-results", 2
_EXPECTED = "expected the results of affordance plan (run_plan)"
#: The units ``results.json`` declares.
UNITS = MappingProxyType({"fractions": "[0, 1]", "distances": "m", "times": "s"})

Interval = tuple[float, float]
Count = Annotated[int, "a count"]
_EMPTY: Mapping[str, Any] = MappingProxyType({})


def _by_default(mapping: Mapping[str, Any]) -> Any:
    """A mapping field that defaults to ``mapping`` (read-only, so shared)."""
    return field(default_factory=lambda: mapping)


def _omitted() -> Any:
    """A field the JSON leaves out when None (a section only some entries hold)."""
    return field(default=None, metadata=json_options(omit_none=True))


@dataclass(frozen=True)
class Share:
    """A share of ``n`` cases, a fraction in [0, 1] (a query on the results, not a part of their JSON).

    Attributes:
        value: The share; None for a share of nothing (0 of 0), which is no rate.
        n: The cases it is a share of.
        ci: Its Wilson 95 % interval (low, high), or None when the results hold none.
    """

    value: float | None
    n: Count = 0
    ci: Interval | None = None


#: A share of nothing: what a policy or goal kind the results do not hold shows.
NOTHING = Share(None)


#: The distances [m] at which the results give the share of place goals and of multi-step targets reached: 1 cm,
#: the 3 cm of the place goals' and the goal env's tolerance, and 5 cm, the success threshold of Gymnasium-Robotics'
#: FetchPush (``distance_threshold=0.05``) and of Meta-World's push and pick-place tasks.
SUCCESS_DISTANCES_M = (0.01, 0.03, 0.05)


@dataclass(frozen=True)
class WithinDistance:
    """The share of ``n`` cases whose object came to rest on the table within ``distance_m`` [m] of its target, with
    its Wilson 95 % interval (``success`` None for a share of nothing)."""

    distance_m: float
    success: float | None
    success_ci: Interval
    n: Count

    @property
    def share(self) -> Share:
        return Share(self.success, self.n, self.success_ci)


@dataclass(frozen=True)
class PolicyOutcome:
    """How often one policy reached its goals (:func:`~affordance_learning.planning.experiment.summarize`): its
    share of all the goals (``success``, ``success_ci``, ``n``), of the feasible ones (those the oracle reached:
    ``*_feasible``) and of those the oracle or the planner reached (``*_reached``; None and 0 in results written
    before it was recorded)."""

    success: float | None
    success_ci: Interval | None
    success_feasible: float | None
    success_feasible_ci: Interval | None
    n: Count
    n_feasible: Count
    success_reached: float | None = None
    success_reached_ci: Interval | None = None
    n_reached: Count = 0

    @property
    def reached(self) -> Share:
        """Its share of all the goals."""
        return Share(self.success, self.n, self.success_ci)

    @property
    def feasible(self) -> Share:
        """Its share of the feasible goals."""
        return Share(self.success_feasible, self.n_feasible, self.success_feasible_ci)

    @property
    def reached_any(self) -> Share:
        """Its share of the goals the oracle or the planner reached (:data:`NOTHING` where not recorded)."""
        return Share(self.success_reached, self.n_reached, self.success_reached_ci)


@dataclass(frozen=True)
class Rate:
    """The share of ``n`` cases that succeeded, without an interval: ``{"n": 10, "success": 0.4}``."""

    n: Count
    success: float | None

    @property
    def share(self) -> Share:
        return Share(self.success, self.n)


@dataclass(frozen=True, kw_only=True)
class Episode:
    """One multi-step episode of the planner.

    Attributes:
        type: The object type.
        start_xy: Where the object started on the table (x, y) [m].
        target_xy: Where it was to be brought (x, y) [m].
        initial_distance: Its distance to the target at the start [m] (None where not recorded).
        final_distance: Its distance to the target at the end [m] (None where not recorded).
        steps: Its interactions (None where not recorded).
        success: Whether it got there.
        gave_up: Whether the planner stopped because none of the actions it asked ``feasible`` about (at most
            its ``max_checks``) was reachable.
        feasible_at_stop: Where it stopped so: how many of the oracle's actions (every behaviour's) were feasible
            there (0: no behaviour could act, and stopping was right); None where it did not stop, or in results
            written before it was recorded.
        reach_failures: Its interactions that failed to reach (None where not recorded).
        failures: The messages of its interactions that failed to reach.
        toward_robot: Whether its target lay toward the robot (within 45 degrees of +x from the object).
        pulls_at_start: For an episode toward the robot: whether each behaviour that brings objects toward it
            (the draw, the grasp) could act on the object where it started (``feasible`` of its canonical action);
            None otherwise (and for the episodes that reached their target, in results of version 2 written before
            it was recorded for them).
        within_reach: Whether the episode's interactions could take it there at all
            (:func:`~affordance_learning.planning.experiment.within_reach`).
    """

    type: str
    start_xy: tuple[float, float]
    target_xy: tuple[float, float]
    initial_distance: float | None = None
    final_distance: float | None = None
    steps: Count | None = None
    success: bool
    gave_up: bool
    feasible_at_stop: Count | None = None
    reach_failures: Count | None = None
    failures: tuple[str, ...] = ()
    toward_robot: bool = False
    pulls_at_start: Mapping[str, bool] | None = field(default=None, hash=False)  # read-only
    within_reach: bool


@dataclass(frozen=True, kw_only=True)
class MultiStepOutcome:
    """How one policy did over the multi-step episodes: the share reached (``success``, ``success_ci``, ``n``),
    the reach failures per interaction (a fraction), its ``interactions``, the episodes it gave up, the median
    distance left at the end [m], the share reached toward the robot (``*_toward_robot``; None and 0 in results
    written before it was recorded), the share that ended within each of :data:`SUCCESS_DISTANCES_M` of the target
    (``success_within``; an episode ends within the goal env's 3 cm or after its last interaction, so at 1 cm this
    counts where it came to rest, not what a policy aiming at 1 cm would reach; empty in results written before
    it was recorded), and, for the planner only, ``planner_by_type``, ``planner_episodes`` and
    ``planner_within_reach`` (read through :attr:`by_type`, :attr:`episodes` and :attr:`within_reach`)."""

    success: float | None
    success_ci: Interval | None = None
    n: Count
    reach_failures: float
    interactions: Count
    gave_up: Count = 0
    median_final_distance_m: float
    success_toward_robot: float | None = None
    success_toward_robot_ci: Interval | None = None
    n_toward_robot: Count = 0
    planner_by_type: Mapping[str, Rate] | None = field(default=None, metadata=json_options("by_type", True))
    planner_episodes: tuple[Episode, ...] | None = field(default=None, metadata=json_options("episodes", True))
    planner_within_reach: Rate | None = field(default=None, metadata=json_options("within_reach", True))
    success_within: tuple[WithinDistance, ...] = ()

    @property
    def reached(self) -> Share:
        """Its share of the episodes that reached their target."""
        return Share(self.success, self.n, self.success_ci)

    def within(self, distance_m: float) -> Share:
        """Its share of the episodes that ended with the object on the table within ``distance_m`` [m] of the target
        (one of :data:`SUCCESS_DISTANCES_M`; :data:`NOTHING` in results written before it was recorded)."""
        return _within(self.success_within, distance_m)

    @property
    def toward_robot(self) -> Share:
        """Its share of the episodes reached among those whose target lay toward the robot (:data:`NOTHING` where
        not recorded)."""
        return Share(self.success_toward_robot, self.n_toward_robot, self.success_toward_robot_ci)

    @property
    def by_type(self) -> Mapping[str, Share]:
        """Its share of the episodes reached, per object type (the planner's only)."""
        return MappingProxyType({t: r.share for t, r in (self.planner_by_type or {}).items()})

    @property
    def episodes(self) -> tuple[Episode, ...]:
        """Its episodes (the planner's only)."""
        return self.planner_episodes or ()

    @property
    def within_reach(self) -> Share:
        """Its share of the episodes reached among those whose target was within reach (the planner's only;
        :data:`NOTHING` otherwise)."""
        return NOTHING if self.planner_within_reach is None else self.planner_within_reach.share

    @property
    def reach_failure_count(self) -> int:
        """How many interactions failed to reach."""
        return round(self.reach_failures * self.interactions)


@dataclass(frozen=True, kw_only=True)
class MultiStep:
    """The multi-step evaluation: each policy's outcome (the planner's, the direction heuristic's, random
    actions'), per object type and direction ("+x", "-x", "+y", "-y") how far 9 in 10 interactions move the object
    that way [m], how close to its target an object must end [m] (None when the results do not say), and the
    interactions an episode may take."""

    planner: MultiStepOutcome
    direction: MultiStepOutcome | None = _omitted()
    random: MultiStepOutcome | None = _omitted()
    step_reach_p90_m: Mapping[str, Mapping[str, float]] = _by_default(_EMPTY)
    tolerance_m: float | None = None
    max_interactions: Count

    @property
    def policies(self) -> Mapping[str, MultiStepOutcome]:
        """Each policy's outcome, of those run."""
        held = {"planner": self.planner, "direction": self.direction, "random": self.random}
        return MappingProxyType({name: outcome for name, outcome in held.items() if outcome is not None})

    def policy(self, name: str) -> MultiStepOutcome:
        """The outcome of policy ``name``; InvalidValueError naming the policies held when it was not run."""
        if name not in self.policies:
            raise InvalidValueError(f"the plan results hold no multi-step outcome of policy {name!r}, only of "
                                    f"{', '.join(self.policies)}; {_EXPECTED}.")
        return self.policies[name]


@dataclass(frozen=True)
class CalibrationBin:
    """One bin of the reliability curve: the mean predicted probability of reaching the goal, the share of goals
    reached (a fraction) and the actions in the bin."""

    p: float
    observed: float
    n: Count


@dataclass(frozen=True)
class Calibration:
    """How well the planner's predicted probabilities match what happened: expected calibration error (a
    fraction; None without actions), AUROC (None with a single outcome), the actions, the reliability curve, what
    the actions are (``basis``: the planner's chosen actions of the single-step evaluation; results written before
    it pooled every executed action), and the same pooled over every action tried (``pooled``, or None)."""

    ece: float | None
    auroc: float | None
    n: Count
    curve: tuple[CalibrationBin, ...]
    basis: str = "every action executed in the single-step evaluation"
    pooled: Calibration | None = _omitted()


@dataclass(frozen=True, kw_only=True)
class GoalRecord:
    """One goal of the single-step evaluation and how it went.

    Attributes:
        kind: The goal's kind ("roll", "lift", "move", "place").
        type: The object type.
        object: The held-out object's index.
        size: The object's size [m]; None in results written before it was recorded.
        goal: The goal (:meth:`~affordance_learning.planning.goals.Goal.to_dict`); None where not recorded.
        planner: Whether the planner's action reached the goal.
        planner_p: The P(goal) the planner gave its action (0 where it chose none).
        planner_behavior: The behaviour it chose; None where no candidate it asked about was feasible.
        oracle: Whether some action of the oracle's set reached it (the goal is *feasible*).
        oracle_hits: How many actions of the oracle's set reached it; None in results written before it was
            recorded.
        planner_left_out: Whether the planner fitted without the object's type reached it; None in results
            written before it was recorded.
        placement_error: For a place goal the planner acted on: how far from the target its action left the
            object [m]; None for other goals, where it named no action, or in results written before it was recorded.
    """

    kind: str
    type: str
    object: Count
    size: float | None = None
    goal: Any = field(default=None, hash=False, metadata=json_options(omit_none=True))
    planner: bool
    planner_p: float
    planner_behavior: str | None
    oracle: bool
    oracle_hits: Count | None = None
    planner_left_out: bool | None = None
    placement_error: float | None = None


@dataclass(frozen=True, kw_only=True)
class DecisionTimes:
    """How long the planner's decisions took [s], ``feasible``'s calls included: median, 99th percentile, the
    most, and n (None without decisions); for all of them, the single step's (``choose``) and the multi-step's
    (``toward``)."""

    median: float | None
    p99: float | None
    max: float | None = None
    n: Count
    choose: DecisionTimes | None = _omitted()
    toward: DecisionTimes | None = _omitted()


@dataclass(frozen=True)
class ReachFailures:
    """The single-step goals the planner acted on, and how many of its actions failed to reach."""

    n: Count
    failures: Count


@dataclass(frozen=True, kw_only=True)
class PlanResults:
    """The results of ``affordance plan``, typed and read-only, each field a key of ``results.json`` in its order;
    :meth:`from_dict` reads them.

    Attributes:
        format: :data:`PLAN_RESULTS_FORMAT`.
        version: :data:`PLAN_RESULTS_VERSION` (what older results were read as).
        seed: The seed of the data and of the evaluation.
        settings: The run's settings (:class:`~affordance_learning.planning.experiment.PlanSettings`), as written.
        units: The units of its numbers (:data:`UNITS`).
        training: The training interactions per behaviour.
        training_episodes: The goal episodes they came from (None when not recorded).
        workers: The worker processes of the run (None when not recorded).
        cpu_count: The machine's CPUs (None when not recorded).
        oracle: How the single-step evaluation was made: ``objects``, ``objects_per_shape``, ``goals_per_object``,
            ``actions_per_behavior``, ``levels`` (empty in results written before it was recorded).
        single_step: Each policy's outcome over the held-out single-step goals.
        single_step_by_goal: The same per goal kind.
        best_fixed_behavior: Per goal kind, the behaviour whose canonical action reached it most often.
        planner_over_oracle: The planner's success over the oracle's (a ratio); None when the oracle reached
            nothing.
        single_step_reach_failures: The planner's single-step actions that failed to reach (None when not
            recorded).
        leave_one_shape_out: Per left-out shape, each policy's outcome on goals for it.
        multi_step: The multi-step evaluation.
        placement_error_median_m: The median placement error of the place goals the planner acted on [m]; None
            without any.
        placement_error_n: How many place goals the planner acted on (counted from the goals in results written
            before it was recorded).
        placement_error_committed_median_m, placement_error_committed_n: The same over the place goals it acted on
            without abstaining (P(goal) at least its threshold); None and 0 without any, or in results written
            before it was recorded.
        place_success_within: Per policy (the planner's and the oracle's), the share of the single-step place
            goals whose object came to rest on the table within each of :data:`SUCCESS_DISTANCES_M` of the target
            (the planner's one action; the oracle: any of its actions), n every place goal; empty in results written
            before it was recorded.
        calibration: The calibration of the planner's predicted probabilities.
        decision_seconds: The planner's decision times, single-step and multi-step together (n 0 in results
            written before they were recorded).
        timings_s: The time of each stage and the ``total`` [s]; where recorded, the collection's parts
            (``collect_goal_episodes``, ``collect_top_up_<behaviour>``) and the CPU seconds the evaluation's
            processes spent on the single step and on the multi-step episodes (``evaluate_*_cpu``).
        goals: The single-step goals, one record each (empty in results written without them).
    """

    format: str = PLAN_RESULTS_FORMAT
    version: Count = PLAN_RESULTS_VERSION
    seed: Count
    settings: Mapping[str, Any]
    units: Mapping[str, str] = _by_default(UNITS)
    training: Mapping[str, Count]
    training_episodes: Count | None = None
    workers: Count | None = None
    cpu_count: Count | None = None
    oracle: Mapping[str, Any] = _by_default(_EMPTY)
    single_step: Mapping[str, PolicyOutcome]
    single_step_by_goal: Mapping[str, Mapping[str, PolicyOutcome]]
    best_fixed_behavior: Mapping[str, str]
    planner_over_oracle: float | None
    single_step_reach_failures: ReachFailures | None = _omitted()
    leave_one_shape_out: Mapping[str, Mapping[str, PolicyOutcome]]
    multi_step: MultiStep
    placement_error_median_m: float | None
    placement_error_n: Count
    placement_error_committed_median_m: float | None = None
    placement_error_committed_n: Count = 0
    place_success_within: Mapping[str, tuple[WithinDistance, ...]] = _by_default(_EMPTY)
    calibration: Calibration
    decision_seconds: DecisionTimes = DecisionTimes(median=None, p99=None, n=0)
    timings_s: Mapping[str, float]
    goals: tuple[GoalRecord, ...] = ()

    @classmethod
    def from_dict(cls, results: PlanResults | Mapping[str, Any]) -> PlanResults:
        """Read the results of ``affordance plan`` (its ``results.json`` read back, or a dict of that shape) and
        check them; PlanResults are returned as they are.

        Raises:
            InvalidValueError: ``results`` are not a mapping, name another format or a version this package does
                not read, lack a section (naming every one they lack), or hold a part that is not of the format
                (naming where).
        """
        if isinstance(results, PlanResults):
            return results
        read = from_json(cls, current_plan_results(results), name="plan results", expected=_EXPECTED)
        if "total" not in read.timings_s:
            raise InvalidValueError(f"plan results['timings_s'] lacks 'total'; {_EXPECTED}.")
        return read

    @property
    def episodes(self) -> int:
        """The goal episodes collected for training (``settings["episodes"]``)."""
        episodes = self.settings.get("episodes")
        if isinstance(episodes, bool) or not isinstance(episodes, int | float) or not float(episodes).is_integer():
            raise InvalidValueError(f"plan results['settings']['episodes'] must be a count (a whole number), got "
                                    f"{episodes!r}; {_EXPECTED}.")
        return int(episodes)

    @property
    def total_time_s(self) -> float:
        """The run's total time [s]."""
        return self.timings_s["total"]

    def place_within(self, policy: str, distance_m: float) -> Share:
        """The share of the single-step place goals that ``policy`` ("planner" or "oracle") brought within
        ``distance_m`` [m] of the target (one of :data:`SUCCESS_DISTANCES_M`; :data:`NOTHING` where not recorded)."""
        return _within(self.place_success_within.get(policy, ()), distance_m)

    @property
    def placement_error_committed(self) -> tuple[float | None, int]:
        """The median placement error [m] and n of the place goals the planner acted on without abstaining."""
        return self.placement_error_committed_median_m, self.placement_error_committed_n


def _within(shares: tuple[WithinDistance, ...], distance_m: float) -> Share:
    """The share of ``shares`` at ``distance_m`` [m]; :data:`NOTHING` where the results hold none."""
    return next((w.share for w in shares if abs(w.distance_m - distance_m) < 1e-9), NOTHING)


# --- older results ---------------------------------------------------------------------------------------------
def current_plan_results(results: Any) -> Mapping[str, Any]:
    """``results`` as the current version holds them, for the generic read: a copy where an older one lacks what
    the reader cannot default (``placement_error_n``, counted from the goals; ``decision_seconds`` written as
    None), ``results`` themselves otherwise.

    Raises:
        InvalidValueError: ``results`` are not a mapping, name another format, or a version newer than
            :data:`PLAN_RESULTS_VERSION`.
    """
    if not isinstance(results, Mapping):
        raise InvalidValueError(f"plan results must be a mapping, got {type(results).__name__}; {_EXPECTED}.")
    if results.get("format", PLAN_RESULTS_FORMAT) != PLAN_RESULTS_FORMAT:
        raise InvalidValueError(f"results of format {results['format']!r}, not {PLAN_RESULTS_FORMAT!r}; "
                                f"{_EXPECTED}.")
    version = results.get("version", 1)
    if version not in range(1, PLAN_RESULTS_VERSION + 1) or isinstance(version, bool):
        raise InvalidValueError(f"plan results of version {version!r}; this tap-affordance reads versions 1 to "
                                f"{PLAN_RESULTS_VERSION} of {PLAN_RESULTS_FORMAT!r}: upgrade the package.")
    if "placement_error_n" in results and results.get("decision_seconds", {}) is not None:
        return results
    upgraded = dict(results)
    if upgraded.get("decision_seconds", {}) is None:
        del upgraded["decision_seconds"]
    if "placement_error_n" not in upgraded:
        goals = upgraded.get("goals", [])
        countable = isinstance(goals, list | tuple) and all(isinstance(g, Mapping) for g in goals)
        # the goals a reader refuses are named by it; the count then does not matter
        upgraded["placement_error_n"] = sum(g.get("kind") == "place" and bool(g.get("planner_behavior"))
                                            for g in goals) if countable else 0
    return upgraded


__all__ = ["NOTHING", "PLAN_RESULTS_FORMAT", "PLAN_RESULTS_VERSION", "SUCCESS_DISTANCES_M", "UNITS", "Calibration",
           "CalibrationBin", "DecisionTimes", "Episode", "GoalRecord", "MultiStep", "MultiStepOutcome", "PlanResults",
           "PolicyOutcome", "Rate", "ReachFailures", "Share", "WithinDistance", "current_plan_results"]
