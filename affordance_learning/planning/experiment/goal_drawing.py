"""The goals the evaluation sets: a single step's goals per object, and the multi-step episodes' starts and targets
(toward the robot every few episodes).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from affordance_env.goal_env import GOAL_TABLE_MARGIN, draw_target
from affordance_env.scene import table_extent
from affordance_learning.planning.experiment.settings import (
    GOALS_PER_OBJECT,
    MOVE_DISTANCE,
    PLACE_DISTANCE,
    PLACE_TOLERANCE,
)
from affordance_learning.planning.goals import Goal, Lift, Move, Place, Roll


def place_target(start_xy: np.ndarray, rng: np.random.Generator, draws: int = 1000) -> np.ndarray:
    """A place ``PLACE_DISTANCE`` from ``start_xy`` [m] in a uniform direction, where the goal env puts its goals:
    at least ``GOAL_TABLE_MARGIN`` inside the table top's edges and in some behaviour's workspace (a place beyond
    the edge is no place an object can be put). Raises RuntimeError if ``draws`` draws find none."""
    target = draw_target(start_xy, rng, *table_extent(), PLACE_DISTANCE, draws=draws)
    if target is not None:
        return target
    raise RuntimeError(f"No place {PLACE_DISTANCE} m from the object at {np.asarray(start_xy).tolist()} lies "
                       f"{GOAL_TABLE_MARGIN} m inside the table and in a workspace after {draws} draws.")


def draw_goal(kind: str, start_xy: np.ndarray, rng: np.random.Generator, direction: int | None = None) -> Goal:
    """A goal of ``kind`` for an object seen at ``start_xy``; a move goes along ``direction`` (0-7, every 45
    degrees from +x), else one drawn; a place is drawn by :func:`place_target`."""
    if kind == "roll":
        return Roll()
    if kind == "lift":
        return Lift()
    if kind == "move":
        angle = (rng.integers(8) if direction is None else direction) * np.pi / 4
        return Move(tuple(np.round(np.array([np.cos(angle), np.sin(angle)]), 12)), MOVE_DISTANCE)
    return Place(tuple(place_target(np.asarray(start_xy, dtype=np.float64), rng)), PLACE_TOLERANCE)


def draw_goals(start_xy: np.ndarray, rng: np.random.Generator) -> list[Goal]:
    """The goals of one object of the single-step evaluation (:data:`GOALS_PER_OBJECT`)."""
    goals = []
    for kind, n in GOALS_PER_OBJECT.items():
        goals += [draw_goal(kind, start_xy, rng, i if kind == "move" else None) for i in range(n)]
    return goals


#: Every this many multi-step episodes, the target is drawn toward the robot (:func:`goal_toward_robot`), as
#: the env draws its goals but within 45 degrees of +x: drawn uniformly in direction, a goal lies toward the robot
#: in a tenth of the episodes only, the table's near edge being 14 cm in front of the objects.
TOWARD_ROBOT_EVERY = 4


#: Objects drawn at most for an episode toward the robot: one within about 28-30 cm of the robot leaves no room (or
#: little) for a target 10 cm or more toward it, within 45 degrees of straight ahead and 5 cm inside the table's
#: near edge, so the episode takes the next object drawn that does (on the first alone, seeds 0-3 gave 13, 16, 13
#: and 11 such episodes of 16).
TOWARD_ROBOT_OBJECTS = 20


def goal_toward_robot(start_xy, env, rng: np.random.Generator) -> list[float] | None:
    """A target as the goal env draws its goals (``GOAL_DISTANCE`` from the object, ``GOAL_TABLE_MARGIN`` inside
    the table, in some behaviour's workspace) but toward the robot (within 45 degrees of +x), from ``rng``; None
    if 200 draws find none."""
    table = env.world.table
    goal = draw_target(np.asarray(start_xy, dtype=float), rng, table.low, table.high, angles=(-np.pi / 4, np.pi / 4),
                       draws=200)
    return None if goal is None else goal.tolist()


def toward_robot(start_xy, target_xy) -> bool:
    """Whether the target lies toward the robot from the object: within 45 degrees of +x."""
    need = np.asarray(target_xy, dtype=float) - np.asarray(start_xy, dtype=float)
    return bool(need[0] > abs(need[1]))


def episode_start(env, item: Mapping[str, Any], rng: np.random.Generator) -> tuple[dict, dict]:
    """``env.reset`` for the multi-step episode ``item``: the goal env's object and target from reset seed
    ``item["seed"]``; every ``TOWARD_ROBOT_EVERY``-th episode a target toward the robot (:func:`goal_toward_robot`),
    on the first of ``TOWARD_ROBOT_OBJECTS`` objects (the item's, then reset seeds from ``rng``) that the table leaves
    room for one in front of. Returns reset's observation and info."""
    seed = item["seed"]
    obs, info = env.reset(seed=seed)
    if item["index"] % TOWARD_ROBOT_EVERY:
        return obs, info
    for _ in range(TOWARD_ROBOT_OBJECTS):
        goal = goal_toward_robot(obs["achieved_goal"], env, rng)
        if goal is not None:
            return env.reset(seed=seed, options={"goal": goal})  # the same object, this target
        seed = int(rng.integers(2**31))
        obs, info = env.reset(seed=seed)
    return obs, info
