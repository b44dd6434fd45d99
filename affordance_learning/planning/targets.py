"""The targets of ``affordance plan``, each a spec of the one verdict vocabulary both experiments share.

:data:`TARGETS` holds each target once: its bound, the least data a verdict is given on, how its value is measured
and shown, and why it is missed, from the data. :func:`evaluate_targets` judges them all by the rule of
:mod:`affordance_learning.common.verdicts`: "met" or "missed" only on enough data, "too few data" below it, and
"not measured" for a share of nothing (never 0 %). The results are read through
:class:`~affordance_learning.planning.results.PlanResults`.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from affordance_learning.common.exceptions import InvalidValueError
from affordance_learning.common.verdicts import (
    TOO_FEW,
    Basis,
    Count,
    Judgement,
    NotMeasured,
    Spec,
    Verdict,
    judge_all,
)
from affordance_learning.planning.experiment import GOAL_KINDS, PULLING, calibration, share_text, wilson
from affordance_learning.planning.planner import MAX_CHECKS
from affordance_learning.planning.results import NOTHING, SUCCESS_DISTANCES_M, GoalRecord, PlanResults, Share

#: The left-out shapes' bound on their feasible goals (the target "each left-out shape, success on its feasible
#: goals").
SHAPE_BOUND = 0.80


# The least data a verdict is given on; below it the verdict is "too few (n=...)". A share's Wilson 95 % interval
# is shown beside it, so a verdict close to its bound can be read as the near thing it is.
#: Feasible single-step goals: a share near the 95 % target is then known within +-3 points (Wilson 95 %).
MIN_FEASIBLE_GOALS = 200


#: Feasible goals of each left-out shape: from 30, one goal is at most 3 points of the share and the interval around
#: 80 % is about +-14 points; with fewer, both grow fast (one goal met or missed the target before).
MIN_FEASIBLE_PER_SHAPE = 30


#: Place goals the oracle reaches, for the planner's median placement error and its share within 3 cm: at 30 the
#: median's 95 % interval already spans the 10th to the 21st of the sorted errors; with fewer it is set by a
#: handful of goals.
MIN_PLACEMENTS = 30


#: The planner's chosen actions, for the calibration: the ECE over 10 bins is biased upwards by sampling alone (a
#: perfectly calibrated model shows up to about 0.8 x sqrt(2.5 / n)); from 400 actions that is 0.06 at most, and
#: far less where most chosen actions sit in one or two bins near P = 1, as a good planner's do.
MIN_CALIBRATION_ACTIONS = 400


#: Multi-step episodes: a share near the 85 % target is then known within +-9 points. The reach failures per
#: interaction are judged on the same episodes (the interactions of one episode are not independent).
MIN_EPISODES = 60


#: Multi-step episodes whose target lies toward the robot: around 80 %, +-18 points.
MIN_TOWARD_ROBOT = 15


#: Planner decisions, for their median and 99th percentile: from 100, the 99th percentile is the second largest.
MIN_DECISIONS = 100


class Measured(NamedTuple):
    """A target's measured value and what it was measured on.

    Attributes:
        value: The value (a fraction, metres, the ECE or the AUROC); None when nothing was measured.
        n: How many goals, place goals, actions or episodes it was measured on (the target's ``minimum`` applies to it).
        unit: What ``n`` counts, for the report ("feasible goals", "episodes, 212 interactions").
        ci: The Wilson 95 % interval of a share, or None.
        detail: What the report shows instead of the value, or None (the shape target lists every shape).
    """

    value: float | None
    n: int
    unit: str
    ci: tuple[float, float] | None = None
    detail: str | None = None


def share_cell(share: Share, unit: str = "") -> str:
    """A share in the report: value, Wilson 95 % interval and n (:func:`share_text`)."""
    return share_text(share.value, share.n, share.ci, unit, digits=1)


def _worst_shape(results: PlanResults) -> Measured:
    """The shape target: the worst share among the shapes judged on enough feasible goals if one misses the
    bound (one such shape misses the target, whatever the others); else the worst share measured, with the
    smallest n of the shapes (every shape must be measured on enough goals for the target to be met)."""
    shapes = {s: _measured(r["planner"].feasible, f"feasible goals of {s}")
              for s, r in results.leave_one_shape_out.items()}
    bound = SHAPE_BOUND
    detail = "; ".join(f"{s} {share_text(m.value, m.n, m.ci, digits=1)}" for s, m in shapes.items())
    missing = [m for m in shapes.values() if m.n >= MIN_FEASIBLE_PER_SHAPE and m.value < bound]
    if missing:
        return min(missing, key=lambda m: m.value)._replace(detail=detail)
    measured = [m for m in shapes.values() if m.value is not None]
    if not measured:
        return Measured(None, 0, "feasible goals of any shape", detail=detail)
    worst, fewest = min(measured, key=lambda m: m.value), min(shapes.values(), key=lambda m: m.n)
    return worst._replace(n=fewest.n, unit=fewest.unit, ci=None, detail=detail)


def _shape_gap(results: PlanResults) -> Measured:
    """The smallest margin of the left-out planner over the best fixed behaviour on a shape's feasible goals
    (a difference of shares), with the fewest feasible goals of the shapes as n."""
    gaps = {s: (r["planner"].feasible, r["best_fixed"].feasible) for s, r in results.leave_one_shape_out.items()}
    measured = {s: (p.value - b.value, p.n) for s, (p, b) in gaps.items() if p.value is not None}
    detail = "; ".join(f"{s} {100 * g:+.1f} points (n={n} feasible goals)" for s, (g, n) in measured.items())
    if not measured:
        return Measured(None, 0, "feasible goals of any shape", detail=detail or None)
    worst = min(measured, key=lambda s: measured[s][0])
    fewest = min(n for _, n in measured.values())
    return Measured(measured[worst][0], fewest, f"feasible goals of the fewest shape (worst: {worst})",
                    detail=detail)


def _measured(share: Share, unit: str) -> Measured:
    """A target's share, with its n and interval."""
    return Measured(share.value, share.n, unit, share.ci)


def policy_outcome(outcomes: Mapping[str, Any], name: str, where: str) -> Any:
    """The outcome of policy ``name`` in ``outcomes`` (``where`` names them); InvalidValueError when it was not
    run."""
    if name not in outcomes:
        raise InvalidValueError(f"the plan results hold no {where} outcome of policy {name!r}, only of "
                                f"{', '.join(outcomes)}.")
    return outcomes[name]


def _actions(calibration) -> str:
    """What the calibration's n counts."""
    return "chosen actions" if "chosen" in calibration.basis else "actions (pooled)"


def _reached(outcomes: Mapping[str, Any], policy: str) -> Share:
    """How often ``policy`` reached its goals among ``outcomes``; :data:`NOTHING` when it was not run."""
    outcome = outcomes.get(policy)
    return NOTHING if outcome is None else outcome.reached


#: A feasible goal that at most this many of the oracle's actions reached is *narrow*: an action within a few
#: centimetres, or degrees, of the few that reach it may not.
NARROW_HITS = 3


#: The calibration's why names at most this many objects, those whose chosen actions were the most overconfident.
WORST_OBJECTS = 3


def _object_name(goals: list[GoalRecord]) -> str:
    """An object as the report names it: its type and size, from one of its goals."""
    g = goals[0]
    return g.type.replace("_", " ") + (f" (object {g.object})" if g.size is None else f" of {100 * g.size:.2f} cm")


def _by_object(goals: list[GoalRecord]) -> dict[int, list[GoalRecord]]:
    out: dict[int, list[GoalRecord]] = {}
    for g in goals:
        out.setdefault(g.object, []).append(g)
    return out


def single_step_why(results: PlanResults | Mapping[str, Any]) -> str | None:
    """Why the planner missed feasible single-step goals, from its goals: how many of the oracle's actions reached
    the goals it missed and those it reached, how many of the missed were narrow (:data:`NARROW_HITS`), how many it
    chose below its threshold (expecting to miss), and on which objects it missed the others; None for results
    without the oracle's hits per goal."""
    results = PlanResults.from_dict(results)
    feasible = [g for g in results.goals if g.oracle]
    missed = [g for g in feasible if not g.planner]
    if not missed or any(g.oracle_hits is None for g in feasible):
        return None
    reached = [g for g in feasible if g.planner]
    actions = results.oracle.get("actions_per_behavior")  # for every behaviour trained
    of = f"of the oracle's {actions * len(results.training)} actions" if actions else "of the oracle's actions"
    narrow = [g for g in missed if g.oracle_hits <= NARROW_HITS]
    kinds = ", ".join(f"{k} {n}" for k, n in Counter(g.kind for g in narrow).most_common())
    threshold = float(results.settings.get("threshold", 0.5))
    nothing = sum(g.planner_behavior is None for g in missed)
    unsure = sum(g.planner_behavior is not None and g.planner_p < threshold for g in missed)
    sure = [g for g in missed if g.planner_behavior is not None and g.planner_p >= threshold]
    groups = [gs for gs in sorted(_by_object(sure).values(), key=len, reverse=True)[:WORST_OBJECTS] if len(gs) > 1]
    named = ", ".join(f"{_object_name(gs)} {len(gs)}" for gs in groups)
    text = (f"the {len(missed)} feasible goals it missed were reached by a median of "
            f"{np.median([g.oracle_hits for g in missed]):g} {of}")
    if reached:
        text += f", the {len(reached)} it reached by {np.median([g.oracle_hits for g in reached]):g}"
    text += (f"; {len(narrow)} of the missed by at most {NARROW_HITS} (narrow goals: {kinds})" if narrow else "")
    chose = [f"{unsure} at P below its threshold {threshold:g} (it expected to miss)" if unsure else "",
             f"{len(sure)} at P >= {threshold:g}" if sure else "",
             f"nothing for {nothing} (none of the candidates it asked about was feasible)" if nothing else ""]
    text += "; of the missed it chose " + " and ".join(c for c in chose if c)
    return text + (f", {sum(map(len, groups))} of those on {len(groups)} objects ({named})" if groups else "")


def calibration_why(results: PlanResults | Mapping[str, Any], auroc: bool = False) -> str | None:
    """Where the planner's P(goal) on its chosen actions is off, from its goals: the largest miscalibration of the
    reliability curve, the :data:`WORST_OBJECTS` objects whose chosen actions were the most overconfident (the
    sum of P minus reached), and the ECE (or, with ``auroc``, the AUROC) without them; None for results without
    the goals."""
    results = PlanResults.from_dict(results)
    acted = [g for g in results.goals if g.planner_behavior]
    if not acted:
        return None
    curve = () if auroc else results.calibration.curve  # the curve's largest gap is the ECE's, not the AUROC's
    off = max(curve, key=lambda c: abs(c.p - c.observed) * c.n) if curve else None
    text = ("" if off is None else f"the largest miscalibration is at P = {off.p:.2f}: observed {off.observed:.2f} "
            f"over {off.n} actions")
    objects = _by_object(acted)
    excess = {o: sum(g.planner_p - g.planner for g in gs) for o, gs in objects.items()}
    key = "auroc" if auroc else "ece"
    name = "calibration AUROC" if auroc else "calibration ECE"
    ranked = [o for o in sorted(objects, key=lambda o: -excess[o])[:WORST_OBJECTS] if excess[o] > 1e-9]
    if not ranked:
        return text
    best = None  # the fewest of them without which the rest meets the target, else those leaving it best
    for k in range(1, len(ranked) + 1):
        rest = [g for g in acted if g.object not in ranked[:k]]
        metric = calibration([g.planner_p for g in rest], [g.planner for g in rest])[key]
        if best is None or (metric is not None and (best[1] is None or (metric > best[1] if auroc
                                                                        else metric < best[1]))):
            best = (k, metric, len(rest))
        if metric is not None and TARGETS[name].holds(metric):
            break
    worst, (_, metric, n_rest) = ranked[: best[0]], best

    def described(goals: list[GoalRecord]) -> str:
        chosen = ", ".join(f"{b} {n}" for b, n in Counter(g.planner_behavior for g in goals).most_common())
        return (f"{_object_name(goals)}: {len(goals)} actions ({chosen}) at a mean P "
                f"{np.mean([g.planner_p for g in goals]):.2f}, {sum(g.planner for g in goals)} reached")

    value = "not measured" if metric is None else f"{metric:.3f}"
    named = "; ".join(described(objects[o]) for o in worst)
    objects_text = "object" if len(worst) == 1 else "objects"
    return (f"{text + '. ' if text else ''}The most overconfident {objects_text}: {named}; without "
            f"{'it' if len(worst) == 1 else 'them'} the {'AUROC' if auroc else 'ECE'} is {value} "
            f"(n={n_rest} chosen actions)")


def left_out_why(results: PlanResults | Mapping[str, Any]) -> str | None:
    """Per left-out shape, its success on its feasible goals beside the same goals' with the shape in the
    training data (the planner of every other target) and the best fixed behaviour's; None for results without
    the left-out planner's outcome per goal."""
    results = PlanResults.from_dict(results)
    loso = results.leave_one_shape_out
    parts = []
    for shape in loso:
        goals = [g for g in results.goals if g.type == shape and g.oracle]
        if not goals or any(g.planner_left_out is None for g in goals):
            return None
        k, n = sum(g.planner for g in goals), len(goals)
        named = shape.replace("_", " ")
        parts.append(f"{named}: {share_cell(loso[shape]['planner'].feasible, 'feasible')} left out, "
                     f"{share_text(k / n, n, wilson(k, n), 'feasible', digits=1)} with {named}s in the training "
                     f"data (best fixed {share_cell(loso[shape]['best_fixed'].feasible, 'feasible')})")
    return "; ".join(parts)


#: What an interaction's failure message (up to its measure) says, for the report.
_FAILURE_KINDS = {
    "reach: the arm moved the object": "where the arm moved the object before the stroke",
    "reach: the stroke started": "where the stroke started more than 1 cm from its pose",
    "ik: the grasp was not reachable": "where a grasp's pose was out of reach once the hand had touched",
    "ik: the stroke was not reachable": "where a stroke's pose was out of reach",
}


def _reached_where(towards, behaviors: tuple[str, ...]) -> str | None:
    """The share reached (:func:`share_text`) of the episodes toward the robot that started where one of
    ``behaviors`` could act on the object (``pulls_at_start``); None where that was not recorded for every one."""
    if not towards or any(e.pulls_at_start is None for e in towards):
        return None
    able = [e for e in towards if any(e.pulls_at_start.get(b, False) for b in behaviors)]
    k, n = sum(e.success for e in able), len(able)
    return share_text(k / n if n else None, n, wilson(k, n), "episodes", digits=1)


def multi_step_why(results: PlanResults | Mapping[str, Any]) -> str:
    """Why multi-step episodes miss their targets: per object type, success and how far one interaction moves it;
    how many missed targets lay beyond what the episode's interactions can do (:func:`within_reach`), and the
    planner's success on the others."""
    results = PlanResults.from_dict(results)
    multi = results.multi_step.policy("planner")
    reach = results.multi_step.step_reach_p90_m
    most = results.multi_step.max_interactions
    missed = [e for e in multi.episodes if not e.success]
    beyond = [e for e in missed if not e.within_reach]
    per_type = "; ".join(
        f"{t}: {share_text(r.value, r.n, digits=1)} (9 in 10 interactions move it at most "
        + ", ".join(f"{100 * v:.1f}" for v in reach.get(t, {}).values()) + " cm along +x, -x, +y, -y)"
        for t, r in multi.by_type.items())
    towards = sum(e.target_xy[0] - e.start_xy[0] > reach.get(e.type, {}).get("+x", 0.0) * most for e in beyond)
    inside = multi.within_reach
    gave_up = sum(e.gave_up for e in missed)
    return (f"{share_cell(multi.reached, unit='episodes')} reach the target (median final distance "
            f"{100 * multi.median_final_distance_m:.1f} cm). By type: {per_type}. {len(beyond)} of the "
            f"{len(missed)} missed targets lay further along an axis than {most} such interactions take the object "
            f"({towards} of them towards the robot); on the "
            f"{inside.n} targets within that reach the planner reached "
            f"{share_text(inside.value, inside.n, digits=1)}. In "
            f"{gave_up} missed episodes the planner stopped where none of the candidates it asked about (at most "
            f"{MAX_CHECKS} a decision, the most promising first) was reachable")


# --- how a target's value and bound read ----------------------------------------------------------------------
@dataclass(frozen=True)
class Unit:
    """How a target's value (with its n) and its bound read in the report."""

    value: Callable[[Measured], str]
    bound: Callable[[float], str]


SHARE = Unit(lambda m: share_text(m.value, m.n, m.ci, m.unit, digits=1), lambda b: f"{100 * b:.0f} %")
POINTS = Unit(SHARE.value, lambda b: f"{100 * b:.0f} points")
METRES = Unit(lambda m: f"{100 * m.value:.1f} cm (n={m.n} {m.unit})", lambda b: f"{100 * b:.0f} cm")
SECONDS = Unit(lambda m: f"{1000 * m.value:.0f} ms (n={m.n} {m.unit})", lambda b: f"{1000 * b:.0f} ms")
MINUTES = Unit(lambda m: f"{m.value:.1f} min ({m.unit})", lambda b: f"{b:.0f} min")
SCORE = Unit(lambda m: f"{m.value:.3f} (n={m.n} {m.unit})", lambda b: f"{b}")
COUNT = Unit(lambda m: f"{m.value:.0f} of {m.n} {m.unit}", lambda b: f"{b:.0f}")


@dataclass(frozen=True)
class Target:
    """One target of the planner.

    Attributes:
        name: The target as the report names it.
        direction: ">=" or "<=": the side of ``bound`` that meets it.
        bound: The bound, in the unit of the measured value (a fraction, metres, seconds, minutes).
        minimum: The least n a verdict is given on.
        measure: The measured value with its n, from the results.
        unit: How the value and the bound read.
        why: Why the target is missed, from the data (None where nothing more can be said).
    """

    name: str
    direction: str
    bound: float
    minimum: int
    measure: Callable[[PlanResults], Measured]
    unit: Unit = SHARE
    why: Callable[[PlanResults], str | None] | None = None

    def holds(self, value: float) -> bool:
        """Whether ``value`` lies on the target's side of its bound, whatever its n."""
        return value >= self.bound if self.direction == ">=" else value <= self.bound

    @property
    def rule(self) -> str:
        return f"{self.direction} {self.unit.bound(self.bound)}"

    def spec(self) -> Spec[PlanResults]:
        """The target as a spec of the shared verdicts (:func:`affordance_learning.common.verdicts.judge`)."""
        def judge(results: PlanResults) -> Judgement:
            measured = self.measure(results)
            if measured.value is None:
                raise NotMeasured(measured.detail or share_text(None, measured.n, unit=measured.unit))
            return Judgement(measured.detail or self.unit.value(measured), self.holds(measured.value))

        def basis(results: PlanResults) -> Basis:
            measured = self.measure(results)
            return Basis((Count(measured.n, self.minimum, measured.unit),))

        return Spec(self.name, f"{self.name} {self.rule}", self.rule, judge, basis, self.why)


# --- why a target is missed --------------------------------------------------------------------------------------
def _single_step_gap_why(results: PlanResults) -> str:
    """Why single-step goals are missed: :func:`single_step_why` where the goals say, else the goal kinds where
    the planner trails the oracle most."""
    if text := single_step_why(results):
        return text
    single = results.single_step_by_goal
    gaps = sorted(((single[k]["oracle"].reached.value or 0) - (single[k]["planner"].reached.value or 0), k)
                  for k in GOAL_KINDS if single.get(k))
    worst = ", ".join(f"{k}: planner {share_cell(single[k]['planner'].reached)} vs oracle "
                      f"{share_cell(single[k]['oracle'].reached)}" for _, k in reversed(gaps[-2:]))
    return f"the gap to the oracle is largest for {worst}"


def _placement_why(results: PlanResults) -> str:
    """Why the planner misses place goals that the oracle reaches: how near its actions left the object, and at
    what P it chose them."""
    places = _oracle_places(results)
    if not places or all(g.placement_error is None for g in places):
        place = _reached(results.single_step_by_goal.get("place", {}), "oracle")
        return f"the oracle reached {share_cell(place)} of the place goals; the goals' errors were not recorded"
    threshold = float(results.settings.get("threshold", 0.5))
    acted = [g for g in places if g.placement_error is not None]
    missed = [g for g in acted if not g.planner]
    sure = [g for g in missed if g.planner_p >= threshold]
    within5 = sum(g.placement_error <= 0.05 for g in missed)
    text = (f"of the {len(places)} place goals the oracle reaches, the planner acted on {len(acted)} and left the "
            f"object within 3 cm in {len(acted) - len(missed)}")
    if missed:
        text += (f"; of the {len(missed)} it missed, {within5} ended within 5 cm (median error "
                 f"{100 * np.median([g.placement_error for g in missed]):.1f} cm), {len(missed) - len(sure)} were "
                 f"chosen at P below its threshold {threshold:g} (it expected to miss), and by behaviour "
                 + ", ".join(f"{b} {n}" for b, n in Counter(g.planner_behavior for g in missed).most_common()))
    hits = [g.oracle_hits for g in missed if g.oracle_hits is not None]
    reached = [g.oracle_hits for g in acted if g.planner and g.oracle_hits is not None]
    if hits:
        text += f"; the missed were reached by a median of {np.median(hits):g} of the oracle's actions"
        text += f", the reached by {np.median(reached):g}" if reached else ""
    return text


def _left_out_listing_why(results: PlanResults) -> str:
    """Why a left-out shape misses: :func:`left_out_why` where the goals say, else each shape beside the best
    fixed behaviour."""
    if text := left_out_why(results):
        return text
    loso = results.leave_one_shape_out
    return "; ".join(f"{s}: {share_cell(loso[s]['planner'].feasible, 'feasible')} (best fixed "
                     f"{share_cell(loso[s]['best_fixed'].feasible, 'feasible')})" for s in loso)


def _calibration_why(auroc: bool) -> Callable[[PlanResults], str | None]:
    def why(results: PlanResults) -> str | None:
        if text := calibration_why(results, auroc):
            return text
        curve = results.calibration.curve
        off = max(curve, key=lambda c: abs(c.p - c.observed) * c.n) if curve else None
        return None if off is None else (f"the largest miscalibration is at P = {off.p:.2f}: observed "
                                         f"{off.observed:.2f} over {off.n} actions")
    return why


def _toward_robot_why(results: PlanResults) -> str:
    multi = results.multi_step.policy("planner")
    towards = [e for e in multi.episodes if e.toward_robot]
    beyond = sum(not e.within_reach for e in towards)
    missed = [e for e in towards if not e.success and e.pulls_at_start is not None]
    no_draw = [e for e in missed if not e.pulls_at_start.get("draw", True)]
    neither = sum(not e.pulls_at_start.get("grasp", True) for e in no_draw)
    where = (f" (the nearest {100 * min(-e.start_xy[0] for e in no_draw):.0f} cm in front of the robot)"
             if no_draw else "")
    pulls = (f"of the {len(missed)} missed, {len(no_draw)} started where the draw, the one behaviour that pulls, "
             f"cannot reach behind the object{where}, {neither} of them out of the grasp's reach too (their "
             "canonical actions not feasible); " if missed else "")
    draw = _reached_where(towards, ("draw",))
    reached = ("" if draw is None else f"; where the draw could act on the object at the start, the planner "
               f"reached {draw}, where the draw or the grasp could, {_reached_where(towards, PULLING)}")
    return (f"{pulls}{beyond} of the {len(towards)} targets toward the robot lay further than the episode's "
            "interactions took any object of their type toward it in training" + reached)


def _reach_failures_why(results: PlanResults) -> str:
    multi = results.multi_step.policy("planner")
    kinds: dict[str, int] = {}
    for e in multi.episodes:
        for failure in e.failures:
            kind = _FAILURE_KINDS.get(failure.split(" by ")[0].split(" (")[0], failure.split(":")[0])
            kinds[kind] = kinds.get(kind, 0) + 1
    listed = ", ".join(f"{n} {kind}" for kind, n in sorted(kinds.items(), key=lambda item: -item[1]))
    return (f"{multi.reach_failure_count} of {multi.interactions} "
            f"interactions failed to reach although the kinematics said they would: {listed}")


def _decision_time_why(results: PlanResults) -> str:
    times = results.decision_seconds
    parts = [f"{name}'s median {1000 * t.median:.0f} ms and 99th percentile {1000 * t.p99:.0f} ms (n={t.n})"
             for name, t in (("choose", times.choose), ("toward", times.toward)) if t is not None and t.n]
    return ((", ".join(parts) + "; " if parts else "") + "a decision scores about 1,300 actions of the five "
            "behaviours on the effect models' trees, toward's over two interactions, and asks the kinematics "
            "(``feasible``, 3-20 ms a call) about the best ones; the slowest are those whose best actions are out "
            "of reach")


def _plan_time_why(results: PlanResults) -> str:
    """The stages' times, the collection's parts (``collect_*``) in brackets after it, and the processes' seconds
    on each part of the evaluation (``*_cpu``)."""
    timings = results.timings_s
    parts = {k: v for k, v in timings.items() if k.startswith("collect_")}
    cpu = {k: v for k, v in timings.items() if k.endswith("_cpu")}
    stages = []
    for k, v in timings.items():
        if k == "total" or k in parts or k in cpu:
            continue
        text = f"{k} {v / 60:.1f} min"
        if k == "collect" and parts:
            text += " (" + ", ".join(f"{p.removeprefix('collect_')} {s / 60:.1f}" for p, s in parts.items()) + ")"
        if k == "evaluate" and cpu:
            text += (" (the processes' own: " + ", ".join(f"{c.removeprefix('evaluate_').removesuffix('_cpu')} "
                                                          f"{s / 60:.1f}" for c, s in cpu.items()) + " min)")
        stages.append(text)
    return "the stages took " + ", ".join(stages)


# --- the targets ----------------------------------------------------------------------------------------------
def _oracle_places(results: PlanResults) -> list[GoalRecord]:
    """The single-step place goals that some action of the oracle's reached."""
    return [g for g in results.goals if g.kind == "place" and g.oracle]


def _placement_error(results: PlanResults) -> Measured:
    """The planner's median placement error on the place goals the oracle reaches [m], a goal it named no action
    for counting as missed by any distance; not measured in results without the goals' errors."""
    places = _oracle_places(results)
    unit = "place goals the oracle reaches"
    if not places or all(g.placement_error is None for g in places):
        return Measured(None, len(places), unit)
    errors = [np.inf if g.placement_error is None else g.placement_error for g in places]
    return Measured(float(np.median(errors)), len(errors), unit)


def _placed_within(results: PlanResults) -> Measured:
    """The share of the place goals the oracle reaches that the planner's action reached (within the place's
    tolerance, 3 cm)."""
    places = _oracle_places(results)
    k, n = sum(g.planner for g in places), len(places)
    return Measured(k / n if n else None, n, "place goals the oracle reaches", wilson(k, n))


def _stopped_while_feasible(results: PlanResults) -> Measured:
    """The planner's multi-step episodes that ended with no action where some action of the oracle's was feasible;
    not measured where a stop's feasible actions were not recorded."""
    episodes = _multi(results).episodes
    stops = [e for e in episodes if e.gave_up]
    if any(e.feasible_at_stop is None for e in stops):
        return Measured(None, len(episodes), "episodes", detail=f"{len(stops)} stops, what was feasible there "
                        "not recorded")
    return Measured(float(sum(e.feasible_at_stop > 0 for e in stops)), len(episodes), "episodes")


def _stops_why(results: PlanResults) -> str:
    stops = [e for e in _multi(results).episodes if e.gave_up]
    early = [e for e in stops if (e.feasible_at_stop or 0) > 0]
    actions = results.oracle.get("actions_per_behavior")
    of = f"of its {actions * len(results.training)} actions" if actions else "of its actions"
    return (f"the planner stopped with no action in {len(stops)} episodes; in {len(early)} of them the oracle "
            f"found feasible actions ({', '.join(str(e.feasible_at_stop) for e in early)} {of}) where none of "
            f"those the planner asked about (at most {MAX_CHECKS}) was")


def _multi(results: PlanResults):
    return results.multi_step.policy("planner")


def _single(results: PlanResults):
    return policy_outcome(results.single_step, "planner", "single-step")


def _reach_failures(results: PlanResults) -> Measured:
    multi = _multi(results)
    return Measured(multi.reach_failures if multi.interactions else None, multi.reached.n,
                    f"episodes, {multi.interactions} interactions",
                    wilson(multi.reach_failure_count, multi.interactions))


def _seconds(which: str) -> Callable[[PlanResults], Measured]:
    return lambda r: Measured(getattr(r.decision_seconds, which), r.decision_seconds.n, "decisions")


def _plan_time(results: PlanResults) -> Measured:
    """The run's time [min], on one full run: a quick run (``settings["quick"]``) is none (n=0), its time not the
    one the bound is for."""
    workers = f"on {results.workers or '?'} workers"
    if results.settings.get("quick"):
        return Measured(results.total_time_s / 60, 0, "full runs")
    return Measured(results.total_time_s / 60, 1, f"run {workers}")


def _quick_time(results: PlanResults) -> Measured:
    """A quick run's time [min] (``affordance plan --quick``); a full run is none (n=0)."""
    if not results.settings.get("quick"):
        return Measured(None, 0, "runs of --quick", detail="a full run: `affordance plan --quick` measures it")
    return Measured(results.total_time_s / 60, 1, f"quick run on {results.workers or '?'} workers")


_TARGET_LIST = (
    Target("single-step success on feasible goals", ">=", 0.95, MIN_FEASIBLE_GOALS,
           lambda r: _measured(_single(r).feasible, "feasible goals"), why=_single_step_gap_why),
    Target("place goals the oracle reaches: median error [m]", "<=", 0.01, MIN_PLACEMENTS, _placement_error,
           METRES, _placement_why),
    Target("place goals the oracle reaches: within 3 cm", ">=", 0.90, MIN_PLACEMENTS, _placed_within,
           why=_placement_why),
    Target("each left-out shape, success on its feasible goals", ">=", SHAPE_BOUND, MIN_FEASIBLE_PER_SHAPE,
           lambda r: _worst_shape(r), why=_left_out_listing_why),
    Target("each left-out shape, planner minus best fixed behaviour", ">=", 0.0, MIN_FEASIBLE_PER_SHAPE,
           lambda r: _shape_gap(r), POINTS, _left_out_listing_why),
    Target("calibration ECE", "<=", 0.05, MIN_CALIBRATION_ACTIONS,
           lambda r: Measured(r.calibration.ece, r.calibration.n, _actions(r.calibration)), SCORE,
           _calibration_why(False)),
    Target("calibration AUROC", ">=", 0.95, MIN_CALIBRATION_ACTIONS,
           lambda r: Measured(r.calibration.auroc, r.calibration.n, _actions(r.calibration)), SCORE,
           _calibration_why(True)),
    Target("multi-step targets reached", ">=", 0.85, MIN_EPISODES,
           lambda r: _measured(_multi(r).reached, "episodes"), why=lambda r: multi_step_why(r)),
    Target("multi-step targets toward the robot reached", ">=", 0.80, MIN_TOWARD_ROBOT,
           lambda r: _measured(_multi(r).toward_robot, "episodes toward the robot"), why=_toward_robot_why),
    Target("multi-step episodes ended with no action while one was feasible", "<=", 0.0, MIN_EPISODES,
           _stopped_while_feasible, COUNT, _stops_why),
    Target("multi-step reach failures per interaction", "<=", 0.01, MIN_EPISODES, _reach_failures,
           why=_reach_failures_why),
    Target("decision time, median [s]", "<=", 0.1, MIN_DECISIONS, _seconds("median"), SECONDS,
           _decision_time_why),
    Target("decision time, 99th percentile [s]", "<=", 1.0, MIN_DECISIONS, _seconds("p99"), SECONDS,
           _decision_time_why),
    Target("affordance plan's time [min]", "<=", 15.0, 1, lambda r: _plan_time(r), MINUTES, _plan_time_why),
    Target("affordance plan --quick's time [min]", "<=", 3.0, 1, _quick_time, MINUTES, _plan_time_why),
)
#: Every target of the planner by name, in the order the report lists them.
TARGETS: Mapping[str, Target] = {t.name: t for t in _TARGET_LIST}


class WithinRow(NamedTuple):
    """One row of the shares within 1, 3 and 5 cm of a target (:func:`success_within`).

    Attributes:
        name: What the shares are of ("single-step place goals, planner").
        unit: What their n counts ("place goals", "episodes").
        minimum: The least n the share is read on; below it the report says "too few data", as for a target.
        shares: The share within each of :data:`~affordance_learning.planning.results.SUCCESS_DISTANCES_M`.
    """

    name: str
    unit: str
    minimum: int
    shares: tuple[Share, ...]


def success_within(results: PlanResults | Mapping[str, Any]) -> list[WithinRow]:
    """The shares of the single-step place goals (the planner's and the oracle's, on every place goal: at least
    :data:`MIN_PLACEMENTS`) and of the multi-step targets (each policy's, on its episodes: at least
    :data:`MIN_EPISODES`) that ended within 1, 3 and 5 cm of the target (5 cm: FetchPush's and Meta-World's
    threshold); empty for results written before they were recorded. A measure beside the targets, without a
    bound of its own.

    Raises:
        InvalidValueError: ``results`` are not those of ``affordance plan`` (naming what they lack).
    """
    results = PlanResults.from_dict(results)
    rows = [WithinRow(f"single-step place goals, {policy}", "place goals", MIN_PLACEMENTS,
                      tuple(results.place_within(policy, d) for d in SUCCESS_DISTANCES_M))
            for policy in results.place_success_within]
    rows += [WithinRow(f"multi-step targets, {policy}", "episodes", MIN_EPISODES,
                       tuple(outcome.within(d) for d in SUCCESS_DISTANCES_M))
             for policy, outcome in results.multi_step.policies.items() if outcome.success_within]
    return rows


def within_cell(share: Share, unit: str, minimum: int) -> str:
    """A share within a distance in the report (:func:`share_cell`), marked "too few data" below ``minimum``."""
    return share_cell(share, unit) + (f": {TOO_FEW}" if share.value is not None and share.n < minimum else "")


def measured_targets(results: PlanResults | Mapping[str, Any]) -> dict[str, Measured]:
    """The value of every target in ``results`` with its n (for the shape target see :func:`_worst_shape`).

    Raises:
        InvalidValueError: ``results`` are not those of ``affordance plan`` (naming what they lack).
    """
    results = PlanResults.from_dict(results)
    return {name: target.measure(results) for name, target in TARGETS.items()}


def evaluate_targets(results: PlanResults | Mapping[str, Any]) -> dict[str, Verdict]:
    """Every target judged on ``results`` (:func:`affordance_learning.common.verdicts.judge`), by name.

    Raises:
        InvalidValueError: ``results`` are not those of ``affordance plan`` (naming what they lack).
    """
    results = PlanResults.from_dict(results)
    return {v.topic: v for v in judge_all([t.spec() for t in TARGETS.values()], results)}


__all__ = ["TARGETS", "Measured", "Target", "Unit", "WithinRow", "evaluate_targets", "measured_targets",
           "single_step_why", "calibration_why", "left_out_why", "multi_step_why", "success_within", "within_cell"]
