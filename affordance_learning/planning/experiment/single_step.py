"""The single step: every policy on the goals of one held-out object, from one snapshot.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from typing import Any

import numpy as np

from affordance_env.registry import BEHAVIOR_NAMES
from affordance_learning.planning.experiment.baselines import SomBaseline, grid_planner
from affordance_learning.planning.experiment.goal_drawing import draw_goals
from affordance_learning.planning.experiment.settings import oracle_params
from affordance_learning.planning.experiment.simulation import (
    Outcomes,
    evaluation_env,
    feasible_at,
    reach_failure,
    reached,
)
from affordance_learning.planning.goals import Goal, Place
from affordance_learning.planning.planner import Planner
from affordance_learning.planning.results import SUCCESS_DISTANCES_M


def _decide(planner: Planner, features, goal: Goal, start, feasible, outcomes: Outcomes
            ) -> tuple[Any, bool, dict[str, Any] | None, float]:
    """The planner's choice for ``goal``, whether its action reached it, what it did, and the decision's time
    [s]; an action that failed to reach is remembered (:meth:`~.planner.Planner.note_failure`).
    """
    t = time.perf_counter()
    choice = planner.choose(features, goal, start, feasible=feasible)
    seconds = time.perf_counter() - t
    if not choice.behavior:
        return choice, False, None, seconds
    info = outcomes.run(choice.behavior, choice.params)
    if reach_failure(info):
        planner.note_failure(choice.behavior, choice.params, start)
    return choice, reached(goal, info), info, seconds


def evaluate_object(item: Mapping[str, Any], planner: Planner, shape_planners: Mapping[str, Planner],
                    som: SomBaseline | None, camera: tuple[int, int]) -> list[dict[str, Any]] | None:
    """Every policy on the goals of one object (``item``: reset ``seed``, ``rng``, ``shape``): a record per goal;
    None if the object was not seen at the start. ``shape_planners``: per shape, the planner fitted without it."""
    env = evaluation_env(camera)
    rng = np.random.default_rng(item["rng"])
    obs, info = env.reset(seed=item["seed"], options={"object_type": item["shape"]})
    if not info["visible"]:
        return None
    start = np.asarray(obs["achieved_goal"], dtype=np.float64)
    features = np.asarray(obs["observation"]["features"], dtype=np.float64)
    state = env.get_state()
    feasible = feasible_at(env, state)
    outcomes = Outcomes(env, state)
    oracle_set = oracle_params()
    tried = [(b, k, outcomes.run(b, params)) for b in BEHAVIOR_NAMES for k, params in enumerate(oracle_set)]
    # Every oracle action's P(goal) is read from its predictive outcomes, computed once for the object.
    X = np.hstack([np.repeat(features[None], len(oracle_set), axis=0), oracle_set])
    predicted = {b: planner.on_table(planner.models[b].predictive_outcomes(X), start) for b in BEHAVIOR_NAMES}
    canonical_pick = Planner(planner.models, n_candidates=1, threshold=planner.threshold, optimizer="grid")
    grid = grid_planner(planner)
    left_out = shape_planners.get(item["shape"])
    for p in (planner, grid, left_out):
        if p is not None:
            p.forget_failures()
    shape, size = info["object"]["type"], float(info["object"]["size"])
    records = []
    for j, goal in enumerate(draw_goals(start, rng)):
        record: dict[str, Any] = {"kind": goal.kind, "type": shape, "goal": goal.to_dict(), "object": item["index"],
                                  "item": {**dict(item), "goal": j}}
        choice, ok, done, seconds = _decide(planner, features, goal, start, feasible, outcomes)
        record.update(planner=ok, planner_p=choice.probability, planner_behavior=choice.behavior,
                      decision_s=seconds, planner_reach_failure=bool(done and reach_failure(done)))
        error = None if done is None else goal.placement_error(done["object"]["final_pose"][:2])
        if error is not None:  # a goal of a place
            record["placement_error"] = error
            record["placement_committed"] = not choice.abstained
        if isinstance(goal, Place):  # reached within each distance, by the planner's action and by any of the oracle's
            within = [Place(goal.target_xy, d) for d in SUCCESS_DISTANCES_M]
            record["planner_within"] = [done is not None and reached(g, done) for g in within]
            record["oracle_within"] = [any(reached(g, info) for _, _, info in tried) for g in within]
        record["planner_grid"] = _decide(grid, features, goal, start, feasible, outcomes)[1]
        if left_out is not None:
            record["planner_left_out"] = _decide(left_out, features, goal, start, feasible, outcomes)[1]
        hits = {(b, k): reached(goal, info) for b, k, info in tried}
        pick = int(rng.integers(len(BEHAVIOR_NAMES))), int(rng.integers(len(oracle_set)))
        record["random"] = hits[(BEHAVIOR_NAMES[pick[0]], pick[1])]
        record["canonical"] = {b: hits[(b, 0)] for b in BEHAVIOR_NAMES}
        best = canonical_pick.choose(features, goal, start, feasible=feasible)
        record["canonical_choice"] = bool(best.behavior and record["canonical"][best.behavior])
        if som is not None:
            record["som_categories"] = record["canonical"][som.choose(features, goal, start)[0]]
        record["oracle"] = any(hits.values())
        record["oracle_hits"] = sum(hits.values())
        record["size"] = size
        p = np.concatenate([predicted[b].probability(goal, start) for b in BEHAVIOR_NAMES])
        record["pooled"] = (p, np.array([hits[(b, k)] for b in BEHAVIOR_NAMES for k in range(len(oracle_set))]))
        records.append(record)
    return records
