"""Multi-step episodes: a policy re-planning after each interaction until the goal env's episode ends, and how far
one interaction moves each object type (what a target within reach means).
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from typing import Any

import numpy as np
import pandas as pd

from affordance_env.objects import OBJECT_TYPES
from affordance_env.registry import BEHAVIOR_NAMES
from affordance_learning.planning.experiment.baselines import direction_heuristic
from affordance_learning.planning.experiment.goal_drawing import episode_start, toward_robot
from affordance_learning.planning.experiment.settings import oracle_params
from affordance_learning.planning.experiment.simulation import evaluation_env, feasible_at, reach_failure
from affordance_learning.planning.planner import FAILURE_RADIUS, Planner

#: The behaviours that bring an object toward the robot: the draw, and the grasp that puts it down there. A
#: planner's episode toward the robot records whether each could act on the object where it started (``pulls_at_start``:
#: ``feasible`` of its canonical action).
PULLING = ("draw", "grasp")


def evaluate_episode(item: Mapping[str, Any], planner: Planner, policy: str, camera: tuple[int, int],
                     frames: list | None = None, env=None) -> dict[str, Any]:
    """One multi-step episode of ``policy`` from reset seed ``item["seed"]``: reached, interactions, reach
    failures, the final distance [m] and whether the object ended off the table, the planner's decision times [s],
    whether it stopped with no action and how many of the oracle's actions were feasible there;
    ``frames``, if given, gets a labelled picture of the start and after each interaction. ``env``: the goal env to
    run it in (default: this worker's, :func:`~.simulation.evaluation_env`)."""
    from affordance_env.registration import GOAL_MAX_EPISODE_STEPS

    env = evaluation_env(camera) if env is None else env
    rng = np.random.default_rng(item["rng"])
    obs, info = episode_start(env, item, rng)
    initial_state = env.get_state()
    tolerance = env.goal_tolerance
    steps, failures, success, gave_up, decisions, feasible_at_stop = 0, [], False, False, [], None
    distance = initial = float(info["distance"])
    start_xy, target_xy = (np.asarray(obs[key], dtype=float).tolist() for key in ("achieved_goal", "desired_goal"))
    if frames is not None:
        frames.append((f"start: {100 * distance:.1f} cm to go", env.render()))
    planner.forget_failures()
    for step in range(GOAL_MAX_EPISODE_STEPS):
        start, target = obs["achieved_goal"], obs["desired_goal"]
        if policy == "planner":
            state = env.get_state()
            t = time.perf_counter()
            choice = planner.toward(obs["observation"]["features"], start, target, tolerance,
                                    feasible=feasible_at(env, state), steps_left=GOAL_MAX_EPISODE_STEPS - step)
            decisions.append(time.perf_counter() - t)
            env.set_state(state)  # feasible may have put it back: the same state, to be sure
            if choice.behavior is None:  # none of the actions asked about is reachable: stop rather than fail
                gave_up = True
                # the oracle's judgement of that stop: how many of its actions, every behaviour's, were feasible
                feasible_at_stop = sum(bool(feasible_at(env, state)(b, params)) for b in BEHAVIOR_NAMES
                                       for params in oracle_params())
                break
            behavior, params = choice.behavior, choice.params
        elif policy == "direction":
            behavior, params = direction_heuristic(start, target), np.zeros(3)
        else:
            behavior, params = BEHAVIOR_NAMES[int(rng.integers(len(BEHAVIOR_NAMES)))], rng.uniform(-1, 1, 3)
        obs, _, terminated, _, info = env.step({"behavior": behavior, "params": np.asarray(params, np.float32)})
        steps += 1
        if reach_failure(info):
            failures.append(info["failure"])
        # An action that failed to reach, or left the object where it was, would do so again from there: noted
        moved = float(np.linalg.norm(np.asarray(obs["achieved_goal"]) - np.asarray(start)))
        if policy == "planner" and (reach_failure(info) or (not terminated and moved < FAILURE_RADIUS)):
            # a grasp that held nothing would hold nothing wherever it was to put the object down
            held_nothing = behavior == "grasp" and not reach_failure(info) and not info["success"]
            planner.note_failure(behavior, None if held_nothing else params, start)
        distance = float(info["distance"])
        if frames is not None:
            frames.append((f"{behavior}: {100 * distance:.1f} cm to go", env.render()))
        if terminated:
            success = bool(info["is_success"])
            break
    toward = toward_robot(start_xy, target_xy)
    # What could bring the object toward the robot from where it started, for such a target
    pulls = ({name: bool(feasible_at(env, initial_state)(name, np.zeros(3))) for name in PULLING}
             if policy == "planner" and toward else None)
    return {"policy": policy, "success": success, "steps": steps, "reach_failures": len(failures), "failures": failures,
            "final_distance": distance, "off_table": info.get("outcome") == "off_table", "gave_up": gave_up,
            "feasible_at_stop": feasible_at_stop,
            "type": info["object"]["type"],
            "initial_distance": initial, "start_xy": start_xy, "target_xy": target_xy, "tolerance": tolerance,
            "toward_robot": toward, "pulls_at_start": pulls, "decision_s": decisions}


#: The directions of :func:`step_reach`: world +x (towards the robot), -x (away), +y (to its right), -y (left).
DIRECTIONS = ("+x", "-x", "+y", "-y")


def step_reach(frame: pd.DataFrame, quantile: float = 0.9) -> dict[str, dict[str, float]]:
    """Per object type and direction (:data:`DIRECTIONS`), how far one interaction moves the object that way [m]:
    the ``quantile`` of the displacement's component along it (0 for a move the other way) over the interactions
    of a dataset frame that stayed on the table, whatever the behaviour and action."""
    dx = (frame["true_final_x"] - frame["true_initial_x"]).to_numpy(np.float64)
    dy = (frame["true_final_y"] - frame["true_initial_y"]).to_numpy(np.float64)
    kept = (frame["outcome"].astype(str) != "off_table").to_numpy()
    types = frame["type"].astype(str).to_numpy()
    out = {}
    for shape in OBJECT_TYPES:
        rows = kept & (types == shape)
        if rows.any():
            parts = dict(zip(DIRECTIONS, (dx[rows], -dx[rows], dy[rows], -dy[rows]), strict=True))
            out[shape] = {d: float(np.quantile(np.maximum(v, 0.0), quantile)) for d, v in parts.items()}
    return out


def within_reach(start_xy, target_xy, reach: Mapping[str, float], tolerance: float, interactions: int) -> bool:
    """Whether ``interactions`` that each move the object ``reach`` [m] along a direction (one type's
    :func:`step_reach`) can bring it from ``start_xy`` to within ``tolerance`` of ``target_xy`` along both axes: a
    generous bound (each axis gets the whole tolerance and every interaction the 90th percentile)."""
    need = np.asarray(target_xy, dtype=float) - np.asarray(start_xy, dtype=float)
    cap = np.array([reach["+x"] if need[0] > 0 else reach["-x"], reach["+y"] if need[1] > 0 else reach["-y"]])
    return bool(np.all(np.maximum(np.abs(need) - tolerance, 0.0) <= interactions * cap))
