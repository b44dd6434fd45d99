"""The results of ``affordance plan`` (:func:`~affordance_learning.planning.experiment.run_plan`, its ``results.json``):
:class:`PlanResults`, the typed, read-only view its report, figures and targets read them through.

Units: every share is a fraction in [0, 1] (with its Wilson 95 % interval where the results hold one), distances
are in metres, times in seconds.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

from affordance_learning.common.exceptions import InvalidValueError
from affordance_learning.common.json_reading import Path as _Path
from affordance_learning.common.json_reading import Reader, is_number

#: The ``format`` a plan's ``results.json`` names.
PLAN_RESULTS_FORMAT = "tap-affordance-plan-results"
_EXPECTED = "expected the results of affordance plan (run_plan)"

_READ = Reader("plan results", _EXPECTED)
_where, _mapping, _list, _entry = _READ.where, _READ.mapping, _READ.list, _READ.entry
_number, _count, _is_number = _READ.number, _READ.count, is_number


@dataclass(frozen=True)
class Share:
    """A share of ``n`` cases, a fraction in [0, 1].

    Attributes:
        value: The share; None for a share of nothing (0 of 0), which is no rate.
        n: The cases it is a share of.
        ci: Its Wilson 95 % interval (low, high), or None when the results hold none.
    """

    value: float | None
    n: int = 0
    ci: tuple[float, float] | None = None


#: A share of nothing: what a policy or goal kind the results do not hold shows.
NOTHING = Share(None)


@dataclass(frozen=True)
class PolicyOutcome:
    """How often one policy reached its goals (:func:`~affordance_learning.planning.experiment.summarize`).

    Attributes:
        reached: Its share of all the goals.
        feasible: Its share of the feasible goals (those the oracle reached).
        reached_any: Its share of the goals the oracle or the planner reached (:data:`NOTHING` in results written
            before it was recorded).
    """

    reached: Share
    feasible: Share
    reached_any: Share = NOTHING


@dataclass(frozen=True)
class Episode:
    """One multi-step episode of the planner.

    Attributes:
        type: The object type.
        start_xy: Where the object started on the table (x, y) [m].
        target_xy: Where it was to be brought (x, y) [m].
        success: Whether it got there.
        within_reach: Whether the episode's interactions could take it there at all
            (:func:`~affordance_learning.planning.experiment.within_reach`).
        gave_up: Whether the planner stopped because none of the candidates it asked ``feasible`` about (at most
            its ``max_checks``) was reachable.
        failures: The messages of its interactions that failed to reach.
        toward_robot: Whether its target lay toward the robot (within 45 degrees of +x from the object).
        pulls_at_start: For an episode toward the robot: whether each behaviour that brings objects toward it
            (the draw, the grasp) could act on the object where it started (``feasible`` of its canonical action);
            None otherwise (and for the episodes that reached their target, in results of version 2 written before
            it was recorded for them).
    """

    type: str
    start_xy: tuple[float, float]
    target_xy: tuple[float, float]
    success: bool
    within_reach: bool
    gave_up: bool
    failures: tuple[str, ...] = ()
    toward_robot: bool = False
    pulls_at_start: Mapping[str, bool] | None = field(default=None, hash=False)  # read-only


@dataclass(frozen=True)
class MultiStepOutcome:
    """How one policy did over the multi-step episodes.

    Attributes:
        reached: Its share of the episodes that reached their target.
        reach_failures: Interactions that failed to reach although the kinematics said they would, per
            interaction (a fraction).
        interactions: The interactions of all its episodes.
        median_final_distance_m: The median distance left to the target at the end [m].
        by_type: Its share of the episodes reached, per object type (the planner's only).
        episodes: Its episodes (the planner's only).
        within_reach: Its share of the episodes reached among those whose target was within reach (the
            planner's only; :data:`NOTHING` otherwise).
        toward_robot: Its share of the episodes reached among those whose target lay toward the robot (within 45
            degrees of +x; :data:`NOTHING` in results written before it was recorded).
    """

    reached: Share
    reach_failures: float
    interactions: int
    median_final_distance_m: float
    by_type: Mapping[str, Share]
    episodes: tuple[Episode, ...] = ()
    within_reach: Share = NOTHING
    toward_robot: Share = NOTHING

    @property
    def reach_failure_count(self) -> int:
        """How many interactions failed to reach."""
        return round(self.reach_failures * self.interactions)


@dataclass(frozen=True)
class MultiStep:
    """The multi-step evaluation.

    Attributes:
        policies: Each policy's outcome, in the order held.
        step_reach_p90_m: Per object type and direction ("+x", "-x", "+y", "-y"), how far 9 in 10 interactions
            move the object that way [m].
        max_interactions: The interactions an episode may take.
        tolerance_m: How close to its target an object must end [m]; None when the results do not say.
    """

    policies: Mapping[str, MultiStepOutcome]
    step_reach_p90_m: Mapping[str, Mapping[str, float]]
    max_interactions: int
    tolerance_m: float | None = None

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
    n: int


@dataclass(frozen=True)
class Calibration:
    """How well the planner's predicted probabilities match what happened: expected calibration error (a
    fraction; None without actions), AUROC (None with a single outcome), the actions, the reliability curve, what
    the actions are (``basis``: the planner's chosen actions of the single-step evaluation; results written before
    it pooled every executed action), and the same pooled over every action tried (``pooled``, or None)."""

    ece: float | None
    auroc: float | None
    n: int
    curve: tuple[CalibrationBin, ...]
    basis: str = "every action executed in the single-step evaluation"
    pooled: Calibration | None = None


@dataclass(frozen=True)
class GoalRecord:
    """One goal of the single-step evaluation and how it went.

    Attributes:
        kind: The goal's kind ("roll", "lift", "move", "place").
        type: The object type.
        object: The held-out object's index.
        planner: Whether the planner's action reached the goal.
        planner_p: The P(goal) the planner gave its action (0 where it chose none).
        planner_behavior: The behaviour it chose; None where no candidate it asked about was feasible.
        oracle: Whether some action of the oracle's set reached it (the goal is *feasible*).
        size: The object's size [m]; None in results written before it was recorded.
        oracle_hits: How many actions of the oracle's set reached it; None in results written before it was
            recorded.
        planner_left_out: Whether the planner fitted without the object's type reached it; None in results
            written before it was recorded.
    """

    kind: str
    type: str
    object: int
    planner: bool
    planner_p: float
    planner_behavior: str | None
    oracle: bool
    size: float | None = None
    oracle_hits: int | None = None
    planner_left_out: bool | None = None


@dataclass(frozen=True)
class DecisionTimes:
    """How long the planner's decisions took [s], ``feasible``'s calls included: median, 99th percentile and n
    (None without decisions)."""

    median: float | None
    p99: float | None
    n: int


@dataclass(frozen=True)
class PlanResults:
    """The results of ``affordance plan``, typed and read-only: build it with :meth:`from_dict`.

    Attributes:
        seed: The seed of the data and of the evaluation.
        settings: The run's settings (:class:`~affordance_learning.planning.experiment.PlanSettings`), as written.
        training: The training interactions per behaviour.
        timings_s: The time of each stage and the ``total`` [s].
        single_step: Each policy's outcome over the held-out single-step goals.
        single_step_by_goal: The same per goal kind.
        best_fixed_behavior: Per goal kind, the behaviour whose canonical action reached it most often.
        planner_over_oracle: The planner's success over the oracle's (a ratio); None when the oracle reached
            nothing.
        leave_one_shape_out: Per left-out shape, each policy's outcome on goals for it.
        multi_step: The multi-step evaluation.
        placement_error_median_m: The median placement error of the place goals the planner acted on [m]; None
            without any.
        placement_error_n: How many place goals the planner acted on (counted from the goals in results written
            before it was recorded).
        placement_error_committed: The median placement error [m] and n of the place goals the planner acted on
            without abstaining (P(goal) at least its threshold); (None, 0) without any, or in results written
            before it was recorded.
        calibration: The calibration of the planner's predicted probabilities.
        decision_seconds: The planner's decision times, single-step and multi-step together (n 0 in results
            written before they were recorded).
        workers: The worker processes of the run (None when not recorded).
        oracle: How the single-step evaluation was made: ``objects``, ``objects_per_shape``, ``goals_per_object``,
            ``actions_per_behavior``, ``levels`` (empty in results written before it was recorded).
        goals: The single-step goals, one record each (empty in results written without them).
    """

    seed: int
    settings: Mapping[str, Any]
    training: Mapping[str, int]
    timings_s: Mapping[str, float]
    single_step: Mapping[str, PolicyOutcome]
    single_step_by_goal: Mapping[str, Mapping[str, PolicyOutcome]]
    best_fixed_behavior: Mapping[str, str]
    planner_over_oracle: float | None
    leave_one_shape_out: Mapping[str, Mapping[str, PolicyOutcome]]
    multi_step: MultiStep
    placement_error_median_m: float | None
    placement_error_n: int
    calibration: Calibration
    decision_seconds: DecisionTimes = DecisionTimes(None, None, 0)
    workers: int | None = None
    oracle: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))
    placement_error_committed: tuple[float | None, int] = (None, 0)
    goals: tuple[GoalRecord, ...] = ()

    @classmethod
    def from_dict(cls, results: PlanResults | Mapping[str, Any]) -> PlanResults:
        """Read the results of ``affordance plan`` (the dict of
        :func:`~affordance_learning.planning.experiment.run_plan`, or its ``results.json`` read back) and check them.

        Raises:
            InvalidValueError: ``results`` are not a mapping, name another format, lack a section (naming every
                one they lack), or hold a part that is not of the format (naming where).
        """
        if isinstance(results, PlanResults):
            return results
        if not isinstance(results, Mapping):
            raise InvalidValueError(f"plan results must be a mapping, got {type(results).__name__}; {_EXPECTED}.")
        if results.get("format", PLAN_RESULTS_FORMAT) != PLAN_RESULTS_FORMAT:
            raise InvalidValueError(f"results of format {results['format']!r}, not {PLAN_RESULTS_FORMAT!r}; "
                                    f"{_EXPECTED}.")
        top = _entry(results, (), ("seed", "settings", "training", "timings_s", "single_step", "single_step_by_goal",
                                   "best_fixed_behavior", "planner_over_oracle", "leave_one_shape_out", "multi_step",
                                   "placement_error_median_m", "calibration"))
        timings = _entry(top["timings_s"], ("timings_s",), ("total",))
        return cls(
            seed=_count(top["seed"], ("seed",)),
            settings=MappingProxyType(dict(_mapping(top["settings"], ("settings",)))),
            training=_by_name(top["training"], ("training",), _count),
            timings_s=_by_name(timings, ("timings_s",), _number),
            single_step=_outcomes(top["single_step"], ("single_step",)),
            single_step_by_goal=_by_name(top["single_step_by_goal"], ("single_step_by_goal",), _outcomes),
            best_fixed_behavior=_by_name(top["best_fixed_behavior"], ("best_fixed_behavior",), _text),
            planner_over_oracle=_number(top["planner_over_oracle"], ("planner_over_oracle",), True),
            leave_one_shape_out=_by_name(top["leave_one_shape_out"], ("leave_one_shape_out",), _outcomes),
            multi_step=_multi_step(top["multi_step"], ("multi_step",)),
            placement_error_median_m=_number(top["placement_error_median_m"], ("placement_error_median_m",), True),
            placement_error_n=_placements(top),
            calibration=_calibration(top["calibration"], ("calibration",)),
            decision_seconds=_decisions(top.get("decision_seconds"), ("decision_seconds",)),
            workers=None if top.get("workers") is None else _count(top["workers"], ("workers",)),
            placement_error_committed=(
                _number(top.get("placement_error_committed_median_m"), ("placement_error_committed_median_m",), True),
                _count(top.get("placement_error_committed_n", 0), ("placement_error_committed_n",))),
            oracle=MappingProxyType(dict(_mapping(top.get("oracle", {}), ("oracle",)))),
            goals=tuple(_goal(g, ("goals", i)) for i, g in enumerate(_list(top.get("goals", []), ("goals",)))),
        )

    @property
    def episodes(self) -> int:
        """The goal episodes collected for training (``settings["episodes"]``)."""
        return _count(self.settings.get("episodes"), ("settings", "episodes"))

    @property
    def total_time_s(self) -> float:
        """The run's total time [s]."""
        return self.timings_s["total"]


# --- reading and checking -------------------------------------------------------------------------------------


def _text(value: Any, path: _Path) -> str:
    if not isinstance(value, str):
        raise InvalidValueError(f"{_where(path)} must be a name, got {value!r}; {_EXPECTED}.")
    return value


def _by_name(value: Any, path: _Path, read: Callable[[Any, _Path], Any]) -> Mapping[str, Any]:
    """A mapping of names (policies, shapes, goal kinds, behaviours) to what ``read`` makes of each value."""
    return MappingProxyType({str(name): read(v, (*path, name)) for name, v in _mapping(value, path).items()})


def _interval(value: Any, path: _Path) -> tuple[float, float] | None:
    if value is None:
        return None
    low_high = _list(value, path)
    if len(low_high) != 2:
        raise InvalidValueError(f"{_where(path)} must be an interval (low, high), got {value!r}; {_EXPECTED}.")
    return _number(low_high[0], path), _number(low_high[1], path)


def _share(value: Any, path: _Path, key: str = "success", n: str = "n", ci: str | None = "success_ci") -> Share:
    """The share ``key`` of an entry, of its ``n`` cases, with its interval ``ci`` when the entry holds one."""
    entry = _entry(value, path, (key, n))
    return Share(_number(entry[key], (*path, key), True), _count(entry[n], (*path, n)),
                 None if ci is None else _interval(entry.get(ci), (*path, ci)))


def _outcomes(value: Any, path: _Path) -> Mapping[str, PolicyOutcome]:
    """Each policy's outcome over a set of goals."""
    def outcome(entry: Any, where: _Path) -> PolicyOutcome:
        entry = _entry(entry, where, ("success", "success_ci", "n", "success_feasible", "success_feasible_ci",
                                      "n_feasible"))
        return PolicyOutcome(_share(entry, where),
                             _share(entry, where, "success_feasible", "n_feasible", "success_feasible_ci"),
                             _share(entry, where, "success_reached", "n_reached", "success_reached_ci")
                             if "n_reached" in entry else NOTHING)

    return _by_name(value, path, outcome)


def _xy(value: Any, path: _Path) -> tuple[float, float]:
    xy = _list(value, path)
    if len(xy) != 2:
        raise InvalidValueError(f"{_where(path)} must be a point (x, y) [m], got {value!r}; {_EXPECTED}.")
    return _number(xy[0], path), _number(xy[1], path)


def _episode(value: Any, path: _Path) -> Episode:
    entry = _entry(value, path, ("type", "start_xy", "target_xy", "success", "within_reach", "gave_up"))
    return Episode(type=_text(entry["type"], (*path, "type")), start_xy=_xy(entry["start_xy"], (*path, "start_xy")),
                   target_xy=_xy(entry["target_xy"], (*path, "target_xy")), success=bool(entry["success"]),
                   within_reach=bool(entry["within_reach"]), gave_up=bool(entry["gave_up"]),
                   failures=tuple(str(f) for f in _list(entry.get("failures", []), (*path, "failures"))),
                   toward_robot=bool(entry.get("toward_robot", False)),
                   pulls_at_start=_pulls(entry.get("pulls_at_start"), (*path, "pulls_at_start")))


def _pulls(value: Any, path: _Path) -> Mapping[str, bool] | None:
    if value is None:
        return None
    if not isinstance(value, Mapping) or not all(isinstance(v, bool) for v in value.values()):
        raise InvalidValueError(f"{_where(path)} must map behaviour names to true or false, got {value!r}; "
                                f"{_EXPECTED}.")
    return MappingProxyType({str(k): v for k, v in value.items()})


#: The entries of ``multi_step`` that describe the evaluation, not a policy.
_MULTI_STEP_SETTINGS = ("step_reach_p90_m", "max_interactions", "tolerance_m")


def _multi_step(value: Any, path: _Path) -> MultiStep:
    section = _entry(value, path, ("planner", "max_interactions"))
    policies = {}
    for name, entry in section.items():
        if name in _MULTI_STEP_SETTINGS:
            continue
        where = (*path, name)
        entry = _entry(entry, where, ("success", "n", "reach_failures", "interactions", "median_final_distance_m"))
        policies[str(name)] = MultiStepOutcome(
            reached=_share(entry, where),
            reach_failures=_number(entry["reach_failures"], (*where, "reach_failures")),
            interactions=_count(entry["interactions"], (*where, "interactions")),
            median_final_distance_m=_number(entry["median_final_distance_m"], (*where, "median_final_distance_m")),
            by_type=_by_name(entry.get("by_type", {}), (*where, "by_type"),
                             lambda v, p: _share(v, p, ci=None)),
            episodes=tuple(_episode(e, (*where, "episodes", i))
                           for i, e in enumerate(_list(entry.get("episodes", []), (*where, "episodes")))),
            within_reach=(NOTHING if entry.get("within_reach") is None
                          else _share(entry["within_reach"], (*where, "within_reach"), ci=None)),
            toward_robot=(_share(entry, where, "success_toward_robot", "n_toward_robot", "success_toward_robot_ci")
                          if "n_toward_robot" in entry else NOTHING),
        )
    reach = _by_name(section.get("step_reach_p90_m", {}), (*path, "step_reach_p90_m"),
                     lambda v, p: _by_name(v, p, _number))
    return MultiStep(policies=MappingProxyType(policies), step_reach_p90_m=reach,
                     max_interactions=_count(section["max_interactions"], (*path, "max_interactions")),
                     tolerance_m=_number(section.get("tolerance_m"), (*path, "tolerance_m"), True))


def _calibration(value: Any, path: _Path) -> Calibration:
    section = _entry(value, path, ("ece", "auroc", "n", "curve"))
    curve = []
    for i, b in enumerate(_list(section["curve"], (*path, "curve"))):
        where = (*path, "curve", i)
        entry = _entry(b, where, ("p", "observed", "n"))
        curve.append(CalibrationBin(_number(entry["p"], (*where, "p")),
                                    _number(entry["observed"], (*where, "observed")),
                                    _count(entry["n"], (*where, "n"))))
    pooled = section.get("pooled")
    return Calibration(ece=_number(section["ece"], (*path, "ece"), True),
                       auroc=_number(section["auroc"], (*path, "auroc"), True),
                       n=_count(section["n"], (*path, "n")), curve=tuple(curve),
                       basis=_text(section.get("basis", Calibration.basis), (*path, "basis")),
                       pooled=None if pooled is None else _calibration(pooled, (*path, "pooled")))


def _flag(value: Any, path: _Path) -> bool:
    """``value`` as a bool: true or false (a string such as "false" is neither)."""
    if isinstance(value, str) or value not in (True, False):
        raise InvalidValueError(f"{_where(path)} must be true or false, got {value!r}; {_EXPECTED}.")
    return bool(value)


def _goal(value: Any, path: _Path) -> GoalRecord:
    entry = _entry(value, path, ("kind", "type", "object", "planner", "planner_p", "planner_behavior", "oracle"))
    behavior, left_out = entry["planner_behavior"], entry.get("planner_left_out")
    hits = entry.get("oracle_hits")
    return GoalRecord(kind=_text(entry["kind"], (*path, "kind")), type=_text(entry["type"], (*path, "type")),
                      object=_count(entry["object"], (*path, "object")),
                      planner=_flag(entry["planner"], (*path, "planner")),
                      planner_p=_number(entry["planner_p"], (*path, "planner_p")),
                      planner_behavior=_text(behavior, (*path, "planner_behavior")) if behavior else None,
                      oracle=_flag(entry["oracle"], (*path, "oracle")),
                      size=_number(entry.get("size"), (*path, "size"), True),
                      oracle_hits=None if hits is None else _count(hits, (*path, "oracle_hits")),
                      planner_left_out=None if left_out is None else _flag(left_out, (*path, "planner_left_out")))


def _decisions(value: Any, path: _Path) -> DecisionTimes:
    if value is None:
        return DecisionTimes(None, None, 0)
    section = _entry(value, path, ("median", "p99", "n"))
    return DecisionTimes(_number(section["median"], (*path, "median"), True),
                         _number(section["p99"], (*path, "p99"), True), _count(section["n"], (*path, "n")))


def _placements(results: Mapping[str, Any]) -> int:
    """How many place goals the planner acted on (the n of the median placement error); counted from the goals
    for results written before ``placement_error_n``."""
    if "placement_error_n" in results:
        return _count(results["placement_error_n"], ("placement_error_n",))
    goals = _list(results.get("goals", []), ("goals",))
    return sum(_mapping(g, ("goals", i)).get("kind") == "place" and bool(g.get("planner_behavior"))
               for i, g in enumerate(goals))


__all__ = ["NOTHING", "PLAN_RESULTS_FORMAT", "Calibration", "CalibrationBin", "DecisionTimes", "Episode", "GoalRecord",
           "MultiStep", "MultiStepOutcome", "PlanResults", "PolicyOutcome", "Share"]
