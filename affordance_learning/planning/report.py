"""The report and figures of ``affordance plan``: its results set beside the targets, and why a target is missed.

:data:`TARGETS` holds each target once; the check and the report's text both read it. A target is judged "met" or
"missed" only on enough data (:data:`MIN_N`); below that it is "too few (n=...)", and a share of nothing is "not
measured", never 0 %. The results are read through :class:`~affordance_learning.planning.results.PlanResults`.
"""

from __future__ import annotations

import os
from collections import Counter
from collections.abc import Mapping
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from affordance_learning.common.exceptions import InvalidValueError
from affordance_learning.planning.experiment import (
    GOAL_KINDS,
    MULTI_POLICIES,
    POLICIES,
    PULLING,
    calibration,
    share_text,
    wilson,
)
from affordance_learning.planning.planner import MAX_CHECKS
from affordance_learning.planning.results import NOTHING, GoalRecord, PlanResults, Share

#: The targets of the planner, each a (direction, value): ">=" or "<=".
TARGETS: dict[str, tuple[str, float]] = {
    "single-step success on feasible goals": (">=", 0.92),
    "single-step success over the oracle's": (">=", 0.95),
    "median placement error [m]": ("<=", 0.02),
    "each left-out shape, success on its feasible goals": (">=", 0.75),
    "each left-out shape, planner minus best fixed behaviour": (">=", 0.0),
    "calibration ECE": ("<=", 0.05),
    "calibration AUROC": (">=", 0.95),
    "multi-step targets reached": (">=", 0.85),
    "multi-step targets toward the robot reached": (">=", 0.75),
    "multi-step reach failures per interaction": ("<=", 0.01),
    "decision time, median [s]": ("<=", 0.1),
    "decision time, 99th percentile [s]": ("<=", 1.0),
    "affordance plan's time [min]": ("<=", 15.0),
}

# The least data a verdict is given on; below it the verdict is "too few (n=...)". A share's Wilson 95 % interval
# is shown beside it, so a verdict close to its bound can be read as the near thing it is.
#: Feasible single-step goals: a share near the 92 % target is then known within +-4 points (Wilson 95 %).
MIN_FEASIBLE_GOALS = 200
#: Feasible goals of each left-out shape: from 30, one goal is at most 3 points of the share and the interval around
#: 75 % is about +-15 points; with fewer, both grow fast (one goal met or missed the target before).
MIN_FEASIBLE_PER_SHAPE = 30
#: Place goals the planner acted on, for the median placement error: at 30 the median's 95 % interval already spans
#: the 10th to the 21st of the sorted errors; with fewer it is set by a handful of goals.
MIN_PLACEMENTS = 30
#: The planner's chosen actions, for the calibration: the ECE over 10 bins is biased upwards by sampling alone (a
#: perfectly calibrated model shows up to about 0.8 x sqrt(2.5 / n)); from 400 actions that is 0.06 at most, and
#: far less where most chosen actions sit in one or two bins near P = 1, as a good planner's do.
MIN_CALIBRATION_ACTIONS = 400
#: Multi-step episodes: a share near the 85 % target is then known within +-9 points. The reach failures per
#: interaction are judged on the same episodes (the interactions of one episode are not independent).
MIN_EPISODES = 60
#: Multi-step episodes whose target lies toward the robot: around 75 %, +-19 points.
MIN_TOWARD_ROBOT = 15
#: Planner decisions, for their median and 99th percentile: from 100, the 99th percentile is the second largest.
MIN_DECISIONS = 100
#: The minimum n of each target's verdict.
MIN_N: dict[str, int] = {
    "single-step success on feasible goals": MIN_FEASIBLE_GOALS,
    "single-step success over the oracle's": MIN_FEASIBLE_GOALS,
    "median placement error [m]": MIN_PLACEMENTS,
    "each left-out shape, success on its feasible goals": MIN_FEASIBLE_PER_SHAPE,
    "each left-out shape, planner minus best fixed behaviour": MIN_FEASIBLE_PER_SHAPE,
    "calibration ECE": MIN_CALIBRATION_ACTIONS,
    "calibration AUROC": MIN_CALIBRATION_ACTIONS,
    "multi-step targets reached": MIN_EPISODES,
    "multi-step targets toward the robot reached": MIN_TOWARD_ROBOT,
    "multi-step reach failures per interaction": MIN_EPISODES,
    "decision time, median [s]": MIN_DECISIONS,
    "decision time, 99th percentile [s]": MIN_DECISIONS,
    "affordance plan's time [min]": 1,
}

MET, MISSED, TOO_FEW, NOT_MEASURED = "met", "missed", "too few", "not measured"


class Measured(NamedTuple):
    """A target's measured value and what it was measured on.

    Attributes:
        value: The value (a fraction, metres, the ECE or the AUROC); None when nothing was measured.
        n: How many goals, place goals, actions or episodes it was measured on (:data:`MIN_N` applies to it).
        unit: What ``n`` counts, for the report ("feasible goals", "episodes, 212 interactions").
        ci: The Wilson 95 % interval of a share, or None.
        detail: What the report shows instead of the value, or None (the shape target lists every shape).
    """

    value: float | None
    n: int
    unit: str
    ci: tuple[float, float] | None = None
    detail: str | None = None


def _share(share: Share, unit: str = "") -> str:
    """A share in the report: value, Wilson 95 % interval and n (:func:`share_text`)."""
    return share_text(share.value, share.n, share.ci, unit, digits=1)


def _worst_shape(results: PlanResults) -> Measured:
    """The shape target: the worst share among the shapes judged on enough feasible goals if one misses the
    bound (one such shape misses the target, whatever the others); else the worst share measured, with the
    smallest n of the shapes (every shape must be measured on enough goals for the target to be met)."""
    shapes = {s: _measured(r["planner"].feasible, f"feasible goals of {s}")
              for s, r in results.leave_one_shape_out.items()}
    name = "each left-out shape, success on its feasible goals"
    _, bound = TARGETS[name]
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


def _policy(outcomes: Mapping[str, Any], name: str, where: str) -> Any:
    """The outcome of policy ``name`` in ``outcomes`` (``where`` names them); InvalidValueError when it was not
    run."""
    if name not in outcomes:
        raise InvalidValueError(f"the plan results hold no {where} outcome of policy {name!r}, only of "
                                f"{', '.join(outcomes)}.")
    return outcomes[name]


def measured_targets(results: PlanResults | Mapping[str, Any]) -> dict[str, Measured]:
    """The value of every target in ``results`` with its n (for the shape target see :func:`_worst_shape`).

    Raises:
        InvalidValueError: ``results`` are not those of ``affordance plan`` (naming what they lack).
    """
    results = PlanResults.from_dict(results)
    single = _policy(results.single_step, "planner", "single-step")
    multi = results.multi_step.policy("planner")
    calibration = results.calibration
    return {
        "single-step success on feasible goals": _measured(single.feasible, "feasible goals"),
        "single-step success over the oracle's": Measured(results.planner_over_oracle, single.feasible.n,
                                                          "feasible goals"),
        "median placement error [m]": Measured(results.placement_error_median_m, results.placement_error_n,
                                               "place goals acted on"),
        "each left-out shape, success on its feasible goals": _worst_shape(results),
        "each left-out shape, planner minus best fixed behaviour": _shape_gap(results),
        "calibration ECE": Measured(calibration.ece, calibration.n, _actions(calibration)),
        "calibration AUROC": Measured(calibration.auroc, calibration.n, _actions(calibration)),
        "multi-step targets reached": _measured(multi.reached, "episodes"),
        "multi-step targets toward the robot reached": _measured(multi.toward_robot, "episodes toward the robot"),
        "multi-step reach failures per interaction": Measured(
            multi.reach_failures if multi.interactions else None, multi.reached.n,
            f"episodes, {multi.interactions} interactions", wilson(multi.reach_failure_count, multi.interactions)),
        "decision time, median [s]": Measured(results.decision_seconds.median, results.decision_seconds.n,
                                              "decisions"),
        "decision time, 99th percentile [s]": Measured(results.decision_seconds.p99, results.decision_seconds.n,
                                                       "decisions"),
        "affordance plan's time [min]": Measured(results.total_time_s / 60, 1,
                                                 f"run on {results.workers or '?'} workers"),
    }


def _actions(calibration) -> str:
    """What the calibration's n counts."""
    return "chosen actions" if "chosen" in calibration.basis else "actions (pooled)"


def target_verdict(name: str, measured: Measured) -> str:
    """"met" or "missed" by the target's bound when ``measured`` has at least :data:`MIN_N` of its n; "too few"
    below; "not measured" when there is no value (0 of 0)."""
    if measured.value is None:
        return NOT_MEASURED
    if measured.n < MIN_N[name]:
        return TOO_FEW
    return MET if _within_bound(name, measured.value) else MISSED


def _within_bound(name: str, value: float) -> bool:
    """Whether ``value`` lies on the right side of target ``name``'s bound (whatever its n)."""
    direction, bound = TARGETS[name]
    return value >= bound if direction == ">=" else value <= bound


def target_met(name: str, measured: Measured | float | None) -> bool | None:
    """True if the target is met, False if missed, None without a verdict (too few, not measured, or a bare value
    without its n)."""
    if not isinstance(measured, Measured):
        return None
    verdict = target_verdict(name, measured)
    return True if verdict == MET else False if verdict == MISSED else None


def verdict_text(name: str, measured: Measured) -> str:
    """The verdict with its n, as the report shows it: "met (n=212 feasible goals)", "too few (n=12 feasible
    goals; 200 needed)", "not measured (n=0 ...)"."""
    verdict = target_verdict(name, measured)
    needed = f"; {MIN_N[name]} needed" if verdict == TOO_FEW else ""
    return f"{verdict} (n={measured.n} {measured.unit}{needed})"


def _value_text(name: str, measured: Measured) -> str:
    if measured.detail is not None:
        return measured.detail
    if measured.value is None:
        return share_text(None, measured.n, unit=measured.unit)
    if "[m]" in name:
        return f"{100 * measured.value:.1f} cm (n={measured.n} {measured.unit})"
    if "[s]" in name:
        return f"{1000 * measured.value:.0f} ms (n={measured.n} {measured.unit})"
    if "[min]" in name:
        return f"{measured.value:.1f} min ({measured.unit})"
    if name.startswith("calibration"):
        return f"{measured.value:.3f} (n={measured.n} {measured.unit})"
    return share_text(measured.value, measured.n, measured.ci, measured.unit, digits=1)


def _bound_text(name: str, bound: float) -> str:
    """A target's bound as the report shows it."""
    if "[m]" in name:
        return f"{100 * bound:.0f} cm"
    if "[s]" in name:
        return f"{1000 * bound:.0f} ms"
    if "[min]" in name:
        return f"{bound:.0f} min"
    if name.startswith("calibration"):
        return f"{bound}"
    if "minus" in name:
        return f"{100 * bound:.0f} points"
    return f"{100 * bound:.0f} %"


def _reached(outcomes: Mapping[str, Any], policy: str) -> Share:
    """How often ``policy`` reached its goals among ``outcomes``; :data:`NOTHING` when it was not run."""
    outcome = outcomes.get(policy)
    return NOTHING if outcome is None else outcome.reached


def _why(name: str, results: PlanResults) -> str:
    """Why a target is missed, from the data."""
    single = results.single_step_by_goal
    if name.startswith("single-step") and (text := single_step_why(results)):
        return text
    if name.startswith("calibration") and (text := calibration_why(results, name.endswith("AUROC"))):
        return text
    if name.startswith("each left-out") and (text := left_out_why(results)):
        return text
    if name.startswith("single-step"):
        gaps = sorted(((single[k]["oracle"].reached.value or 0) - (single[k]["planner"].reached.value or 0), k)
                      for k in GOAL_KINDS if single.get(k))
        worst = ", ".join(f"{k}: planner {_share(single[k]['planner'].reached)} vs oracle "
                          f"{_share(single[k]['oracle'].reached)}" for _, k in reversed(gaps[-2:]))
        return f"the gap to the oracle is largest for {worst}"
    if name.startswith("median placement"):
        place = _reached(single.get("place", {}), "oracle")
        median, n = results.placement_error_committed
        committed = ("" if median is None else
                     f"; on the {n} place goals it did not abstain from (P >= its threshold) the median error is "
                     f"{100 * median:.1f} cm")
        return (f"place goals are reached in {_share(place)} of cases even by the oracle: most targets 5-15 cm "
                "away are beyond what one interaction does to the object (a grasp holds only objects under about "
                "7 cm), and the planner acts on every place goal, also where it predicts it will miss" + committed)
    if name.startswith("decision time"):
        return ("a decision scores every candidate of every behaviour and asks the kinematics (``feasible``, "
                "2-70 ms a call) about the best ones; the slowest are those whose best candidates are out of reach")
    if name.startswith("affordance plan"):
        timings = results.timings_s
        parts = ", ".join(f"{k} {v / 60:.1f} min" for k, v in timings.items() if k != "total")
        return f"the stages took {parts}"
    if name.startswith("multi-step targets toward"):
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
    if name.startswith("each left-out"):
        loso = results.leave_one_shape_out
        parts = [f"{s}: {_share(loso[s]['planner'].feasible, 'feasible')} (best fixed "
                 f"{_share(loso[s]['best_fixed'].feasible, 'feasible')})" for s in loso]
        return "; ".join(parts)
    if name.startswith("calibration"):
        curve = results.calibration.curve
        off = max(curve, key=lambda c: abs(c.p - c.observed) * c.n) if curve else None
        return ("" if off is None else f"the largest miscalibration is at P = {off.p:.2f}: observed "
                f"{off.observed:.2f} over {off.n} actions")
    multi = results.multi_step.policy("planner")
    if name.startswith("multi-step reach"):
        kinds: dict[str, int] = {}
        for e in multi.episodes:
            for failure in e.failures:
                kind = _FAILURE_KINDS.get(failure.split(" by ")[0].split(" (")[0], failure.split(":")[0])
                kinds[kind] = kinds.get(kind, 0) + 1
        listed = ", ".join(f"{n} {kind}" for kind, n in sorted(kinds.items(), key=lambda item: -item[1]))
        return (f"{multi.reach_failure_count} of {multi.interactions} "
                f"interactions failed to reach although the kinematics said they would: {listed}")
    return multi_step_why(results)


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
        if metric is not None and _within_bound(name, metric):
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
        parts.append(f"{named}: {_share(loso[shape]['planner'].feasible, 'feasible')} left out, "
                     f"{share_text(k / n, n, wilson(k, n), 'feasible', digits=1)} with {named}s in the training "
                     f"data (best fixed {_share(loso[shape]['best_fixed'].feasible, 'feasible')})")
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
    return (f"{_share(multi.reached, unit='episodes')} reach the target (median final distance "
            f"{100 * multi.median_final_distance_m:.1f} cm). By type: {per_type}. {len(beyond)} of the "
            f"{len(missed)} missed targets lay further along an axis than {most} such interactions take the object "
            f"({towards} of them towards the robot); on the "
            f"{inside.n} targets within that reach the planner reached "
            f"{share_text(inside.value, inside.n, digits=1)}. In "
            f"{gave_up} missed episodes the planner stopped where none of the candidates it asked about (at most "
            f"{MAX_CHECKS} a decision, the most promising first) was reachable")


def write_plan_report(results: PlanResults | Mapping[str, Any], out: str | os.PathLike) -> Path:
    """Write ``REPORT.md`` into ``out``.

    Raises:
        InvalidValueError: ``results`` are not those of ``affordance plan`` (naming what they lack).
    """
    results = PlanResults.from_dict(results)
    out = Path(out)
    lines = ["# Using the affordances: planning with action-conditioned effect models", ""]
    lines += [f"Seed {results.seed}; training interactions per behaviour: "
              + ", ".join(f"{b} {n}" for b, n in results.training.items())
              + f" (random actions from {results.episodes} goal episodes, objects over the workspaces). "
              f"Total time {results.total_time_s / 60:.1f} min.", ""]
    oracle = results.oracle
    if oracle:
        lines += [f"Single step: {oracle.get('objects')} held-out objects ("
                  + ", ".join(f"{n} {s}" for s, n in oracle.get("objects_per_shape", {}).items())
                  + f"), {sum(oracle.get('goals_per_object', {}).values())} goals each ("
                  + ", ".join(f"{n} {k}" for k, n in oracle.get("goals_per_object", {}).items())
                  + f"). The oracle runs {oracle.get('actions_per_behavior')} actions per behaviour on every object "
                  f"from its snapshot, the same fixed set for all (the canonical action and the grid of levels "
                  f"{oracle.get('levels')} along each parameter), and every goal of the object is judged against "
                  "those outcomes: a goal is *feasible* when one of them reached it. The goals of one object are "
                  "not independent; the intervals treat them as if they were.", ""]
    lines += ["## Targets", "",
              "A target is judged only on enough data, else it is *too few* (a share of nothing is *not measured*): "
              f"at least {MIN_FEASIBLE_GOALS} feasible single-step goals, {MIN_FEASIBLE_PER_SHAPE} feasible goals "
              f"of each left-out shape, {MIN_PLACEMENTS} place goals acted on, {MIN_CALIBRATION_ACTIONS} chosen "
              f"actions for the calibration, {MIN_EPISODES} multi-step episodes ({MIN_TOWARD_ROBOT} toward the "
              f"robot) and {MIN_DECISIONS} decisions. Shares carry their Wilson 95 % interval and n.", "",
              "| target | bound | measured | verdict | why not |", "|---|---|---|---|---|"]
    for name, measured in measured_targets(results).items():
        direction, bound = TARGETS[name]
        verdict = target_verdict(name, measured)
        lines.append(f"| {name} | {direction} {_bound_text(name, bound)} | {_value_text(name, measured)} | "
                     f"**{verdict_text(name, measured)}** | {_why(name, results) if verdict == MISSED else ''} |")
    single = results.single_step
    lines += ["", f"## Single step ({_policy(single, 'planner', 'single-step').reached.n} goals; "
              f"{_policy(single, 'oracle', 'single-step').feasible.n} feasible)", "",
              "| policy | success [95 % CI] | on feasible goals [95 % CI] | on goals the oracle or the planner "
              "reached [95 % CI] |", "|---|---|---|---|"]
    for p in POLICIES:
        r = _policy(single, p, "single-step")
        lines.append(f"| {p} | {_share(r.reached)} | {_share(r.feasible)} | {_share(r.reached_any)} |")
    lines += ["", "Per goal kind (success [95 % CI]):", "", "| goal | " + " | ".join(POLICIES) + " |",
              "|---|" + "---|" * len(POLICIES)]
    for kind, by in results.single_step_by_goal.items():
        lines.append(f"| {kind} | " + " | ".join(_share(_policy(by, p, kind).reached) for p in POLICIES) + " |")
    lines += ["", f"Best fixed behaviour per goal kind: {dict(results.best_fixed_behavior)}.", ""]
    lines += ["## Leaving each shape out", "", "Models refitted without the shape, judged on goals for it only.", "",
              "| shape | planner on feasible [95 % CI] | best fixed on feasible [95 % CI] | random [95 % CI] |",
              "|---|---|---|---|"]
    for shape, r in results.leave_one_shape_out.items():
        lines.append(f"| {shape} | {_share(r['planner'].feasible)} | "
                     f"{_share(r['best_fixed'].feasible)} | {_share(r['random'].reached)} |")
    lines += ["", "## Multi-step", "", "| policy | targets reached [95 % CI] | toward the robot [95 % CI] | reach "
              "failures per interaction [95 % CI] | median final distance |", "|---|---|---|---|---|"]
    for p in MULTI_POLICIES:
        r = results.multi_step.policy(p)
        lines.append(f"| {p} | {_share(r.reached, unit='episodes')} | {_share(r.toward_robot, unit='episodes')} | "
                     + share_text(r.reach_failures, r.interactions, wilson(r.reach_failure_count, r.interactions),
                                  "interactions", digits=1)
                     + f" | {100 * r.median_final_distance_m:.1f} cm (n={r.reached.n} episodes) |")
    cal = results.calibration
    lines += ["", "## Calibration", "", f"On {cal.basis} ({cal.n}): {_calibration_text(cal)}."]
    if cal.pooled is not None:
        lines += ["", f"Pooled over {cal.pooled.basis} ({cal.pooled.n}), most of them at P near 0: "
                  f"{_calibration_text(cal.pooled)}. The pooled figure says how well the model ranks actions in "
                  "general; the chosen actions' says whether the planner's P(goal) can be believed."]
    if cal.curve:
        lines += ["", "| predicted P | observed | n |", "|---|---|---|"]
        lines += [f"| {c.p:.2f} | {c.observed:.2f} | {c.n} |" for c in cal.curve]
    times = results.decision_seconds
    if times.n:
        lines += ["", "## Decision time", "",
                  f"{times.n} decisions (single step and multi-step, ``feasible``'s calls included, measured in the "
                  f"workers of the run): median {1000 * times.median:.0f} ms, 99th percentile "
                  f"{1000 * times.p99:.0f} ms."]
    lines += ["", "![success](success.png)", "![reliability](reliability.png)", "![episode](episode.png)", ""]
    (out / "REPORT.md").write_text("\n".join(lines))
    return out / "REPORT.md"


def _calibration_text(cal) -> str:
    ece = "-" if cal.ece is None else f"{cal.ece:.3f}"
    auroc = "-" if cal.auroc is None else f"{cal.auroc:.3f}"
    return f"ECE {ece}, AUROC {auroc}"


def write_plan_figures(results: PlanResults | Mapping[str, Any], out: str | os.PathLike,
                       episode_frames: list[tuple[str, np.ndarray]] | None = None) -> list[Path]:
    """``success.png`` (success per goal kind and policy, Wilson 95 % intervals), ``reliability.png`` and, given
    the frames of an episode, ``episode.png``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    results = PlanResults.from_dict(results)
    out = Path(out)
    written = []
    fig, ax = plt.subplots(figsize=(10, 4))
    width = 0.8 / len(POLICIES)
    for j, p in enumerate(POLICIES):
        values = [_policy(_goal_kind(results, k), p, k).reached for k in GOAL_KINDS]
        x = np.arange(len(GOAL_KINDS)) + (j - len(POLICIES) / 2 + 0.5) * width
        y = np.array([np.nan if v.value is None else v.value for v in values])  # nothing measured: no bar
        lo = y - np.array([_interval(v)[0] for v in values])
        hi = np.array([_interval(v)[1] for v in values]) - y
        ax.bar(x, 100 * y, width, yerr=100 * np.vstack([lo, hi]), capsize=2, label=p)
    ax.set_xticks(np.arange(len(GOAL_KINDS)), GOAL_KINDS)
    ax.set_ylabel("goals reached [%]")
    ax.set_title("Single step, per goal kind (Wilson 95 % intervals)")
    ax.legend(fontsize=8, ncol=3)
    fig.tight_layout()
    fig.savefig(out / "success.png", dpi=100)
    plt.close(fig)
    written.append(out / "success.png")

    fig, ax = plt.subplots(figsize=(4.5, 4.5))
    curve = results.calibration.curve
    ax.plot([0, 1], [0, 1], "k--", lw=1)
    ax.scatter([c.p for c in curve], [c.observed for c in curve], s=[10 + c.n / 2 for c in curve])
    ax.set_xlabel("predicted P(goal)")
    ax.set_ylabel("observed share reached")
    ax.set_title(f"Reliability on chosen actions ({_calibration_text(results.calibration)})")
    fig.tight_layout()
    fig.savefig(out / "reliability.png", dpi=100)
    plt.close(fig)
    written.append(out / "reliability.png")

    if episode_frames:
        fig, axes = plt.subplots(1, len(episode_frames), figsize=(3 * len(episode_frames), 2.6))
        for ax, (title, image) in zip(np.atleast_1d(axes), episode_frames, strict=True):
            ax.imshow(image)
            ax.set_title(title, fontsize=9)
            ax.axis("off")
        fig.tight_layout()
        fig.savefig(out / "episode.png", dpi=90)
        plt.close(fig)
        written.append(out / "episode.png")
    return written


def _goal_kind(results: PlanResults, kind: str) -> Mapping[str, Any]:
    """Each policy's single-step outcome on goals of ``kind``; InvalidValueError when the results hold none."""
    if kind not in results.single_step_by_goal:
        raise InvalidValueError(f"the plan results hold no single-step outcomes of goal kind {kind!r}, only of "
                                f"{', '.join(results.single_step_by_goal)}.")
    return results.single_step_by_goal[kind]


def _interval(share: Share) -> tuple[float, float]:
    """The Wilson 95 % interval of a share; InvalidValueError when the results hold none."""
    if share.ci is None:
        raise InvalidValueError(f"a share of {share.n} in the plan results has no Wilson interval (success_ci).")
    return share.ci


__all__ = ["TARGETS", "MIN_N", "Measured", "measured_targets", "target_verdict", "target_met", "verdict_text",
           "write_plan_report", "write_plan_figures", "MULTI_POLICIES"]
