"""What the simulator says in the evaluation: each worker's goal env, an interaction's measured outcome and
whether it reached a goal, ``feasible`` of a snapshot, and the outcomes of one object's interactions, each run
once from its snapshot.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from affordance_env.registry import GOAL_ENV_ID
from affordance_env.workers import worker_env
from affordance_learning.planning.goals import Goal


def evaluation_env(camera: tuple[int, int]):
    """This worker's goal env of the evaluation (objects over the workspaces, a ``camera`` of (width, height)
    pixels), built once per process (:func:`affordance_env.workers.worker_env`)."""
    return worker_env(GOAL_ENV_ID, {"camera_width": camera[0], "camera_height": camera[1],
                                    "position_range": "workspace"})


def measured_outcome(info: Mapping[str, Any]) -> dict[str, np.ndarray]:
    """The outcome (:mod:`affordance_learning.planning.outcomes`) of one interaction from its step ``info``: one row."""
    obj = info["object"]
    start, end = np.asarray(obj["initial_pose"]), np.asarray(obj["final_pose"])
    return {"dx": np.array([end[0] - start[0]]), "dy": np.array([end[1] - start[1]]),
            "rolled": np.array([bool(info["rolled"])]), "off_table": np.array([info["outcome"] == "off_table"]),
            "lifted": np.array([info.get("behavior") == "grasp" and bool(info["success"])]),
            "effect": np.asarray(info["effect"], dtype=np.float64)[None]}


def reached(goal: Goal, info: Mapping[str, Any]) -> bool:
    """Whether an interaction (its step ``info``) reached ``goal``; a failed interaction never does."""
    if info["failure"] is not None:
        return False
    return bool(goal.reached(measured_outcome(info), np.asarray(info["object"]["initial_pose"])[:2])[0])


def reach_failure(info: Mapping[str, Any]) -> bool:
    """Whether an interaction failed to reach (``"ik: ..."`` or ``"reach: ..."``): what ``feasible`` promised."""
    return bool(info["failure"]) and info["failure"].split(":")[0] in ("ik", "reach")


def feasible_at(env, state) -> Callable[[str, np.ndarray], bool]:
    """``feasible(behavior, params)`` of the world in snapshot ``state``, whatever the env ran since (the env's
    ``feasible(..., state=state)``, which leaves the env as it is)."""
    return lambda behavior, params: bool(env.feasible(behavior, params, state=state))


def _trimmed(info: Mapping[str, Any]) -> dict[str, Any]:
    """What the evaluation reads of a step's ``info`` (:func:`measured_outcome`, :func:`reached`)."""
    obj = info["object"]
    return {"failure": info["failure"], "rolled": info["rolled"], "outcome": info["outcome"],
            "behavior": info.get("behavior"), "success": info["success"],
            "effect": np.asarray(info["effect"], dtype=np.float64),
            "object": {"initial_pose": np.asarray(obj["initial_pose"]), "final_pose": np.asarray(obj["final_pose"])}}


class Outcomes:
    """The interactions run on one object from one snapshot, each once: ``run(behavior, params)`` runs it the
    first time and returns what it did (a trimmed step ``info``, from the env's ``outcome``: no observation after
    it) every time after (the env repeats an interaction bit for bit from a snapshot)."""

    def __init__(self, env, state) -> None:
        self.env, self.state = env, state
        self.done: dict[tuple[str, bytes], dict[str, Any]] = {}

    def run(self, behavior: str, params: np.ndarray) -> dict[str, Any]:
        params = np.asarray(params, dtype=np.float32)
        key = (behavior, params.tobytes())
        if key not in self.done:  # what it did, without the observation after it (the env's outcome())
            self.done[key] = _trimmed(self.env.outcome(behavior, params, state=self.state))
        return self.done[key]
