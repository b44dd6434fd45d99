"""``affordance plan`` end to end: collect, fit, evaluate every policy, and write ``results.json``.

:func:`run_plan` is a list of stages, each a function of what the ones before it made; the evaluation's objects and
episodes go to the worker processes in one queue (:func:`affordance_env.workers.map_in_processes`).
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np
import pandas as pd

from affordance_env.goal_env import TapAffordanceGoalEnv
from affordance_env.objects import OBJECT_TYPES
from affordance_env.registration import GOAL_MAX_EPISODE_STEPS
from affordance_env.workers import map_in_processes
from affordance_learning.common.statistics import share_text
from affordance_learning.common.typed_json import to_json
from affordance_learning.planning.experiment.baselines import SomBaseline, best_fixed
from affordance_learning.planning.experiment.multi_step import evaluate_episode, step_reach, within_reach
from affordance_learning.planning.experiment.settings import (
    GOAL_KINDS,
    GOALS_PER_OBJECT,
    MULTI_POLICIES,
    ORACLE_LEVELS,
    POLICIES,
    PlanSettings,
    evaluation_items,
    oracle_params,
)
from affordance_learning.planning.experiment.single_step import evaluate_object
from affordance_learning.planning.experiment.statistics import (
    calibrations,
    seconds_summary,
    summarize,
    wilson,
    within_shares,
)
from affordance_learning.planning.experiment.training import (
    TOP_UP_EPISODES,
    collect_training,
    fit_models,
    load_training,
    training_frames,
)
from affordance_learning.planning.planner import Planner
from affordance_learning.planning.results import (
    PLAN_RESULTS_FORMAT,
    PLAN_RESULTS_VERSION,
    SUCCESS_DISTANCES_M,
    Episode,
    GoalRecord,
    MultiStep,
    MultiStepOutcome,
    PlanResults,
    PolicyOutcome,
    Rate,
    ReachFailures,
    WithinDistance,
)

#: The format ``results.json`` of ``affordance plan`` declares, and its version.
RESULTS_FORMAT, RESULTS_VERSION = PLAN_RESULTS_FORMAT, PLAN_RESULTS_VERSION
#: Where in its output directory ``affordance plan`` collects its training data.
DATASET_DIR = "dataset"


def _evaluate(task: tuple[str | None, Mapping[str, Any]], planner: Planner, shape_planners: Mapping[str, Planner],
              som: SomBaseline | None, camera: tuple[int, int]) -> tuple[Any, float]:
    """One task of the evaluation and the CPU seconds its process spent on it (what it costs on a core of its own,
    however loaded the machine): ``(None, item)`` an object of the single step (:func:`evaluate_object`),
    ``(policy, item)`` a multi-step episode of that policy (:func:`evaluate_episode`)."""
    policy, item = task
    t = time.process_time()
    if policy is None:
        done = evaluate_object(item, planner, shape_planners, som, camera)
    else:
        done = evaluate_episode(item, planner, policy, camera)
    return done, time.process_time() - t


@dataclass
class _Stages:
    """What one run's stages share: its settings, where it writes, and the time each stage took [s]."""

    out: Path
    settings: PlanSettings
    seed: int
    workers: int
    camera: tuple[int, int]
    say: Callable[[str], None]
    start: float
    timings: dict[str, float]

    def planner(self, frames: Mapping[str, pd.DataFrame]) -> Planner:
        """A planner over effect models fitted on ``frames``, with the run's sizes."""
        return Planner(fit_models(frames, self.seed, n_jobs=self.workers, n_estimators=self.settings.trees),
                       n_candidates=self.settings.candidates,
                       threshold=self.settings.threshold, random_state=self.seed)


def _collect(run: _Stages) -> tuple[pd.DataFrame, dict[str, pd.DataFrame]]:
    """Step 1: the training data, and each behaviour's first ``max_per_behavior`` interactions of it."""
    settings = run.settings
    run.say(f"[1/5] collecting goal episodes with random actions into {run.out / DATASET_DIR} until every behaviour "
            f"has {settings.max_per_behavior} interactions (at most {settings.max_episodes} episodes)")
    frame = collect_training(run.out / DATASET_DIR, settings, run.seed, run.workers, run.camera, run.say,
                             run.timings)
    frames = training_frames(frame, settings.max_per_behavior)
    run.timings["collect"] = time.perf_counter() - run.start
    run.say(f"      {_goal_episodes(frame)} goal episodes and their top-ups ({run.timings['collect']:.0f} s); "
            + ", ".join(f"{b} {len(f)}" for b, f in frames.items()) + " interactions for training")
    return frame, frames


def _goal_episodes(frame: pd.DataFrame) -> int:
    """The goal episodes of a training frame (:func:`~.training.load_training`), not counting the top-ups' single
    interactions (numbered from ``TOP_UP_EPISODES``, each top-up from there)."""
    return int(frame.loc[frame["episode"] < TOP_UP_EPISODES, "episode"].nunique())


def _fit(run: _Stages, frame: pd.DataFrame, frames: Mapping[str, pd.DataFrame]
         ) -> tuple[Planner, dict[str, Planner], SomBaseline]:
    """Step 2: the planner, each shape's planner fitted without it, and the paper's categories."""
    t = time.perf_counter()
    planner = run.planner(frames)
    som = SomBaseline.fit(frames, run.settings.som_clusters, run.seed)
    shape_planners = {shape: run.planner(training_frames(frame, run.settings.max_per_behavior, exclude_type=shape))
                      for shape in OBJECT_TYPES}
    run.timings["fit"] = time.perf_counter() - t
    run.say(f"[2/5] fitted the effect models, each shape's without it, and the paper's categories "
            f"({run.timings['fit']:.1f} s)")
    return planner, shape_planners, som


def _evaluate_all(run: _Stages, planner: Planner, shape_planners: Mapping[str, Planner], som: SomBaseline
                  ) -> tuple[list, list[list[dict]]]:
    """Steps 3 and 5 in one queue: the objects first (20-60 s each, most of it the grasp's oracle), then the
    multi-step episodes (about a second each), so that no process waits while the other finishes its last object.
    Returns each object's records (None for an object not seen) and each multi-step policy's episodes."""
    t = time.perf_counter()
    items = evaluation_items(run.seed, 0, run.settings.objects)
    multi_items = evaluation_items(run.seed, 9, run.settings.multi_episodes)
    done = map_in_processes(_evaluate, [(None, item) for item in items]
                            + [(policy, item) for policy in MULTI_POLICIES for item in multi_items],
                            run.workers, planner=planner, shape_planners=shape_planners, som=som, camera=run.camera)
    run.timings["evaluate"] = time.perf_counter() - t
    # the CPU seconds the processes spent on each part, together (what the evaluation costs on one core)
    run.timings["evaluate_single_step_cpu"] = sum(s for _, s in done[: len(items)])
    run.timings["evaluate_multi_step_cpu"] = sum(s for _, s in done[len(items):])
    done = [d for d, _ in done]
    objects, multi_done = done[: len(items)], done[len(items):]
    n = len(multi_items)
    return objects, [multi_done[i * n: (i + 1) * n] for i in range(len(MULTI_POLICIES))]


def _single_step(run: _Stages, objects: list) -> tuple[list[dict], dict[str, PolicyOutcome], dict[str, str]]:
    """Step 3's summary: every goal's record, each policy's success, and the best fixed behaviour per goal kind."""
    records = [r for rs in objects if rs is not None for r in rs]
    fixed_choice = best_fixed(records)
    single = summarize(records, POLICIES)
    run.say(f"[3/5] single step: {len(records)} goals on {sum(rs is not None for rs in objects)} held-out objects "
            f"(with step 5: {run.timings['evaluate']:.0f} s): "
            + ", ".join(f"{p} {share_text(single[p].success, single[p].n, single[p].success_ci)}"
                        for p in POLICIES)
            + f"; {single['oracle'].n_feasible} goals feasible; place goals within "
            + _within_text(within_shares([r["planner_within"] for r in records if "planner_within" in r])))
    return records, single, fixed_choice


def _within_text(shares: Sequence[WithinDistance]) -> str:
    """Shares within each distance as the console shows them: ``"1 cm 10 %, 3 cm 30 %, 5 cm 45 % (n=240)"``."""
    if not shares or not shares[0].n:
        return "not measured (n=0)"
    return (", ".join(f"{100 * w.distance_m:.0f} cm {100 * w.success:.0f} %" for w in shares)
            + f" (n={shares[0].n})")


def _leave_one_shape_out(run: _Stages, records: Sequence[Mapping[str, Any]]
                         ) -> dict[str, dict[str, PolicyOutcome]]:
    """Step 4: on each shape's goals, the planner fitted without it, beside the baselines."""
    loso: dict[str, dict[str, PolicyOutcome]] = {}
    for shape in OBJECT_TYPES:
        shape_records = [{**r, "planner": r.get("planner_left_out", False)} for r in records if r["type"] == shape]
        loso[shape] = summarize(shape_records, ("planner", "best_fixed", "random", "oracle"))
    run.say("[4/5] leaving each shape out (judged in step 3): "
            + ", ".join(f"{s} " + share_text(loso[s]["planner"].success_feasible, loso[s]["planner"].n_feasible,
                                             loso[s]["planner"].success_feasible_ci, "feasible")
                        for s in OBJECT_TYPES))
    return loso


def _policy_summary(episodes: Sequence[Mapping[str, Any]], **planner_only: Any) -> MultiStepOutcome:
    """One policy's multi-step episodes: success (and toward the robot) with Wilson intervals, reach failures per
    interaction, episodes given up, the median final distance [m], the share that ended on the table within each
    of :data:`SUCCESS_DISTANCES_M` of the target; ``planner_only``: the planner's details
    (:func:`_planner_episodes`)."""
    n = len(episodes)
    k = sum(e["success"] for e in episodes)
    toward = [e for e in episodes if e["toward_robot"]]
    kt = sum(e["success"] for e in toward)
    interactions = sum(e["steps"] for e in episodes)
    return MultiStepOutcome(
        success=k / n if n else None, success_ci=wilson(k, n), n=n,
        reach_failures=sum(e["reach_failures"] for e in episodes) / max(interactions, 1),
        interactions=interactions, gave_up=sum(e["gave_up"] for e in episodes),
        median_final_distance_m=float(np.median([e["final_distance"] for e in episodes])),
        success_toward_robot=kt / len(toward) if toward else None,
        success_toward_robot_ci=wilson(kt, len(toward)), n_toward_robot=len(toward),
        success_within=within_shares([[not e["off_table"] and e["final_distance"] <= d for d in SUCCESS_DISTANCES_M]
                                      for e in episodes]), **planner_only)


def _episode(e: Mapping[str, Any], reach: Mapping[str, Mapping[str, float]], tolerance: float, most: int
             ) -> Episode:
    """One of the planner's episodes (:func:`evaluate_episode`) as the results keep it, with whether its target was
    within reach of ``most`` interactions (:func:`within_reach`)."""
    pulls = e["pulls_at_start"]
    return Episode(type=e["type"], start_xy=tuple(e["start_xy"]), target_xy=tuple(e["target_xy"]),
                   initial_distance=e["initial_distance"], final_distance=e["final_distance"], steps=e["steps"],
                   success=e["success"], gave_up=e["gave_up"], feasible_at_stop=e.get("feasible_at_stop"),
                   reach_failures=e["reach_failures"],
                   failures=tuple(e["failures"]), toward_robot=e["toward_robot"],
                   pulls_at_start=None if pulls is None else MappingProxyType(dict(pulls)),
                   within_reach=e["type"] in reach and within_reach(e["start_xy"], e["target_xy"], reach[e["type"]],
                                                                    tolerance, most))


def _planner_episodes(episodes: Sequence[Mapping[str, Any]], reach: Mapping[str, Mapping[str, float]],
                      tolerance: float, most: int) -> dict[str, Any]:
    """What the report reads of the planner's episodes (:class:`MultiStepOutcome`'s ``planner_*``): success per
    object type, each episode, and success on the targets within reach of ``most`` interactions."""
    by_type = _view({shape: Rate(len(eps), sum(e["success"] for e in eps) / len(eps))
                     for shape in OBJECT_TYPES if (eps := [e for e in episodes if e["type"] == shape])})
    listed = tuple(_episode(e, reach, tolerance, most) for e in episodes)
    inside = [e for e in listed if e.within_reach]
    return {"planner_by_type": by_type, "planner_episodes": listed,
            "planner_within_reach": Rate(len(inside), sum(e.success for e in inside) / len(inside) if inside else None)}


def _multi_step(run: _Stages, by_policy: Sequence[Sequence[Mapping[str, Any]]], frame: pd.DataFrame
                ) -> MultiStep:
    """Step 5's summary: each policy's episodes, and the planner's in detail."""
    episodes = by_policy[MULTI_POLICIES.index("planner")]
    reach, tolerance = step_reach(frame), episodes[0]["tolerance"]  # the goal env's
    details = {"planner": _planner_episodes(episodes, reach, tolerance, GOAL_MAX_EPISODE_STEPS)}
    multi = MultiStep(**{policy: _policy_summary(found, **details.get(policy, {}))
                         for policy, found in zip(MULTI_POLICIES, by_policy, strict=True)},
                      step_reach_p90_m=_view({t: _view(r) for t, r in reach.items()}), tolerance_m=tolerance,
                      max_interactions=GOAL_MAX_EPISODE_STEPS)
    run.say(f"[5/5] multi-step on {run.settings.multi_episodes} episodes (with step 3): "
            + ", ".join(f"{p} {share_text(o.success, o.n, o.success_ci)}" for p, o in multi.policies.items())
            + "; toward the robot: planner " + share_text(multi.planner.success_toward_robot,
                                                           multi.planner.n_toward_robot,
                                                           multi.planner.success_toward_robot_ci)
            + "; planner within " + _within_text(multi.planner.success_within))
    return multi


def _placement(records: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """The median distance [m] of the object's end from a place goal's target, over the place goals the planner
    acted on (the median's n), and over those it acted on without abstaining (P(goal) >= its threshold); and the
    share of every place goal that the planner and the oracle brought within each of :data:`SUCCESS_DISTANCES_M`."""
    placement = [r["placement_error"] for r in records if "placement_error" in r]
    committed = [r["placement_error"] for r in records if r.get("placement_committed")]
    places = [r for r in records if "planner_within" in r]
    return {"placement_error_median_m": float(np.median(placement)) if placement else None,
            "placement_error_n": len(placement),
            "placement_error_committed_median_m": float(np.median(committed)) if committed else None,
            "placement_error_committed_n": len(committed),
            "place_success_within": _view({policy: within_shares([r[f"{policy}_within"] for r in places])
                                           for policy in ("planner", "oracle")})}


#: What results.json keeps of each single-step goal's record.
GOAL_FIELDS = ("kind", "type", "object", "size", "goal", "planner", "planner_p", "planner_behavior", "oracle",
               "oracle_hits", "planner_left_out", "placement_error")


def _results(run: _Stages, frame: pd.DataFrame, frames: Mapping[str, pd.DataFrame], objects: list,
             single: dict[str, PolicyOutcome], fixed_choice: dict[str, str], loso: dict[str, dict[str, PolicyOutcome]],
             multi: MultiStep, planner_episodes: Sequence[Mapping[str, Any]]) -> PlanResults:
    """The results of the run (``objects``: each object's records, None for one not seen)."""
    records = [r for rs in objects if rs is not None for r in rs]
    n_objects = sum(rs is not None for rs in objects)
    acted = [r for r in records if r["planner_behavior"]]
    oracle = single["oracle"].success or 0.0
    choose_s = [r["decision_s"] for r in records]
    toward_s = [s for e in planner_episodes for s in e["decision_s"]]
    return PlanResults(
        seed=run.seed, settings=_view(asdict(run.settings)),
        training=_view({b: len(f) for b, f in frames.items()}),
        training_episodes=_goal_episodes(frame),
        workers=run.workers, cpu_count=os.cpu_count(),
        oracle=_view({"actions_per_behavior": len(oracle_params()), "levels": list(ORACLE_LEVELS),
                      "objects": n_objects, "goals_per_object": dict(GOALS_PER_OBJECT),
                      "objects_per_shape": {s: len({r["object"] for r in records if r["type"] == s})
                                            for s in OBJECT_TYPES}}),
        single_step=_view(single),
        single_step_by_goal=_view({kind: _view(summarize([r for r in records if r["kind"] == kind], POLICIES))
                                   for kind in GOAL_KINDS}),
        best_fixed_behavior=_view(fixed_choice),
        planner_over_oracle=(single["planner"].success / oracle) if oracle else None,
        single_step_reach_failures=ReachFailures(len(acted), sum(r["planner_reach_failure"] for r in acted)),
        leave_one_shape_out=_view({shape: _view(outcomes) for shape, outcomes in loso.items()}),
        multi_step=multi,
        **_placement(records),
        calibration=calibrations(records),
        decision_seconds=seconds_summary(choose_s + toward_s, seconds_summary(choose_s), seconds_summary(toward_s)),
        timings_s=_view(run.timings),
        goals=tuple(GoalRecord(**{k: r.get(k) for k in GOAL_FIELDS}) for r in records),
    )


def _view(mapping: Mapping[str, Any]) -> Mapping[str, Any]:
    """A read-only copy of ``mapping``, as the results hold their mappings."""
    return MappingProxyType(dict(mapping))


def run_plan(out: str | os.PathLike, seed: int = 0, workers: int = 2, settings: PlanSettings | None = None,
             camera: tuple[int, int] = (160, 120), say: Callable[[str], None] = print) -> PlanResults:
    """Run the whole experiment into ``out`` (``dataset/``, ``results.json``: ``to_json`` of the results); returns
    the results."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    run = _Stages(out, settings or PlanSettings(), seed, workers, camera, say, time.perf_counter(), {})
    frame, frames = _collect(run)
    planner, shape_planners, som = _fit(run, frame, frames)
    objects, by_policy = _evaluate_all(run, planner, shape_planners, som)
    records, single, fixed_choice = _single_step(run, objects)
    loso = _leave_one_shape_out(run, records)
    multi = _multi_step(run, by_policy, frame)
    run.timings["total"] = time.perf_counter() - run.start
    results = _results(run, frame, frames, objects, single, fixed_choice, loso, multi,
                       by_policy[MULTI_POLICIES.index("planner")])
    (out / "results.json").write_text(json.dumps(to_json(results), indent=1, default=float))
    return results


def record_episode(out: str | os.PathLike, results: PlanResults | Mapping[str, Any], seed: int = 0
                   ) -> list[tuple[str, np.ndarray]]:
    """Pictures of one multi-step planner episode (the first of the evaluation's), with the models refitted from
    ``out/dataset`` and its top-ups (:func:`~.training.load_training`, as the run fitted them): the start, then
    the scene after each interaction, titled with the behaviour."""
    settings = PlanSettings(**PlanResults.from_dict(results).settings)
    frames = training_frames(load_training(Path(out) / DATASET_DIR), settings.max_per_behavior)
    planner = Planner(fit_models(frames, seed, n_estimators=settings.trees), n_candidates=settings.candidates,
                      threshold=settings.threshold, random_state=seed)
    env = TapAffordanceGoalEnv(position_range="workspace", render_mode="rgb_array", render_width=320,
                               render_height=240)
    try:
        pictures: list[tuple[str, np.ndarray]] = []
        evaluate_episode(evaluation_items(seed, 9, 1)[0], planner, "planner", (160, 120), frames=pictures, env=env)
        return pictures
    finally:
        env.close()
