"""The interactions: one object per behaviour, with one protocol, registered in one table.

The environment wires an interaction into its episode and never asks which behaviour it runs. An interaction

- plans, from the object the robot sees and the action (:mod:`affordance_env.behaviors`, pure functions);
- executes the plan on the robot (:mod:`affordance_env.motion`) and reports what happened (a
  :class:`~affordance_env.motion.ReachOutcome`);
- says through which pose the way home passes, and from when the object's outcome is awaited;
- says why a sample is not valid beyond what every interaction checks, and what its success is;
- adds its own keys to ``info``.

:data:`INTERACTIONS` holds one per behaviour of :data:`~affordance_env.behaviors.BEHAVIORS`.
"""

from __future__ import annotations

import contextlib
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from affordance_env.behaviors import (
    ACTION_DIM,
    BEHAVIORS,
    Behavior,
    GraspBehavior,
    GraspPlan,
    StrokePlan,
    is_success,
    plan_grasp,
    plan_stroke,
)
from affordance_env.exceptions import InvalidValueError
from affordance_env.grasping import GraspOutcome, grasp_reachable, run_grasp
from affordance_env.motion import MotionExecutor, ReachOutcome
from affordance_env.objects import ObjectGeometry, object_geometry
from affordance_env.outcome import Labels, grasp_success
from affordance_env.stroke import StrokeOutcome, approach_posture, run_stroke, stroke_reachable

#: The hand may start the stroke at most this far from the planned pre-stroke pose [m], and may have moved
#: the object at most this much before the stroke [m]; otherwise the interaction is marked failed.
MAX_START_ERROR, MAX_OBJECT_MOVED_BEFORE = 0.01, 0.003


class Interaction(Protocol):
    """What the environment asks of a behaviour's interaction."""

    #: The behaviour it executes.
    behavior: Behavior | GraspBehavior
    #: What it is, for messages: ``"stroke"`` or ``"grasp"``.
    kind: str

    def prepare(self, motion: MotionExecutor, placement_centre: np.ndarray, size: float) -> np.ndarray | None:
        """What does not depend on the object, solved once when the environment is built: the arm posture the IK of
        every approach starts from (None: the current servo targets), which the environment hands back to
        :meth:`execute` and :meth:`reachable`."""

    def free_stepping(self, motion: MotionExecutor) -> contextlib.AbstractContextManager:
        """The timestep of the interaction while the hand moves in free space and the object comes to rest."""

    def plan(self, geometry: ObjectGeometry, p_object: np.ndarray, yaw: float, table_top: float,
             action: np.ndarray) -> StrokePlan | GraspPlan:
        """The plan of the interaction with the object at ``p_object`` [m] and ``yaw`` [rad]."""

    def execute(self, motion: MotionExecutor, plan: StrokePlan | GraspPlan, posture: np.ndarray | None
                ) -> ReachOutcome:
        """Run the plan on the robot up to the way home, the IK starting from ``posture`` (:meth:`prepare`)."""

    def reachable(self, motion: MotionExecutor, plan: StrokePlan | GraspPlan, posture: np.ndarray | None) -> bool:
        """Whether the arm can reach every pose of the plan (kinematics only: no physics step)."""

    def via_home(self, outcome: ReachOutcome) -> np.ndarray | None:
        """Joint targets the way home passes through first, or None."""

    def awaited_since(self, outcome: ReachOutcome, now: float) -> float:
        """Simulation time [s] from which the object's outcome is awaited."""

    def failure(self, outcome: ReachOutcome) -> str | None:
        """Why the interaction is not a valid sample, beyond what every interaction checks; None if valid."""

    def success(self, outcome: ReachOutcome, labels: Labels, displacement: float, threshold: float) -> bool:
        """The success/fail label of a valid interaction."""

    def info(self, outcome: ReachOutcome) -> dict[str, Any]:
        """The interaction's own keys of ``info``."""


@dataclass(frozen=True)
class StrokeInteraction:
    """A horizontal stroke of the hand (tap, tap_back, push): reach, stroke until contact and follow-through."""

    behavior: Behavior
    kind: str = "stroke"
    #: The hand may start the stroke at most this far from its planned pose [m] ...
    max_start_error: float = MAX_START_ERROR
    #: ... and may have moved the object at most this much before the stroke [m].
    max_object_moved: float = MAX_OBJECT_MOVED_BEFORE

    def prepare(self, motion: MotionExecutor, placement_centre: np.ndarray, size: float) -> np.ndarray:
        # Every approach's IK starts from one posture: that of the canonical stroke of a sphere of the given size
        # at the centre of the placement region.
        table_top = motion.physics.table_top
        geometry = object_geometry("sphere", size)
        centre = np.array([*placement_centre, table_top + geometry.half_height])
        motion.physics.reset_home()
        return approach_posture(motion, self.plan(geometry, centre, 0.0, table_top, np.zeros(ACTION_DIM)))

    def free_stepping(self, motion: MotionExecutor) -> contextlib.AbstractContextManager:
        return motion.stepping(motion.free_timestep)  # the stroke itself keeps the scene's 2 ms

    def plan(self, geometry: ObjectGeometry, p_object: np.ndarray, yaw: float, table_top: float,
             action: np.ndarray) -> StrokePlan:
        return plan_stroke(self.behavior, geometry, p_object, yaw, table_top, action)

    def execute(self, motion: MotionExecutor, plan: StrokePlan, posture: np.ndarray | None) -> StrokeOutcome:
        return run_stroke(motion, plan, posture)

    def reachable(self, motion: MotionExecutor, plan: StrokePlan, posture: np.ndarray | None) -> bool:
        return stroke_reachable(motion, plan, posture)

    def via_home(self, outcome: StrokeOutcome) -> np.ndarray | None:
        return outcome.q_withdraw

    def awaited_since(self, outcome: StrokeOutcome, now: float) -> float:
        return outcome.contact_time if outcome.contact else now  # from the first touch

    def failure(self, outcome: StrokeOutcome) -> str | None:
        if outcome.object_moved > self.max_object_moved:
            return f"reach: the arm moved the object by {outcome.object_moved * 1e3:.1f} mm before the stroke"
        if outcome.start_error > self.max_start_error:
            return f"reach: the stroke started {outcome.start_error * 1e3:.1f} mm from the planned pose"
        if not outcome.contact:
            return "tap: the hand never touched the object"
        return None

    def success(self, outcome: StrokeOutcome, labels: Labels, displacement: float, threshold: float) -> bool:
        return bool(is_success(self.behavior.success_rule, labels.rolled, displacement, threshold))

    def info(self, outcome: StrokeOutcome) -> dict[str, Any]:
        return {"stroke_speed": outcome.speed}


@dataclass(frozen=True)
class GraspInteraction:
    """The grasp with the fingered left hand: grasp, lift, hold, put down beside, let go."""

    behavior: GraspBehavior
    kind: str = "grasp"

    def prepare(self, motion: MotionExecutor, placement_centre: np.ndarray, size: float) -> None:
        return None  # each grasp's IK starts from where the arm is

    def free_stepping(self, motion: MotionExecutor) -> contextlib.AbstractContextManager:
        return contextlib.nullcontext()  # the grasp scene's own timestep throughout

    def plan(self, geometry: ObjectGeometry, p_object: np.ndarray, yaw: float, table_top: float,
             action: np.ndarray) -> GraspPlan:
        return plan_grasp(self.behavior, geometry, p_object, yaw, table_top, action)

    def execute(self, motion: MotionExecutor, plan: GraspPlan, posture: np.ndarray | None) -> GraspOutcome:
        return run_grasp(motion, plan)

    def reachable(self, motion: MotionExecutor, plan: GraspPlan, posture: np.ndarray | None) -> bool:
        return grasp_reachable(motion, plan)

    def via_home(self, outcome: GraspOutcome) -> np.ndarray | None:
        return outcome.q_retreat

    def awaited_since(self, outcome: GraspOutcome, now: float) -> float:
        return outcome.release_time  # from when the hand let go

    def failure(self, outcome: GraspOutcome) -> str | None:
        return None  # the hand meets the object on its way down, and may miss it: that is the grasp's outcome

    def success(self, outcome: GraspOutcome, labels: Labels, displacement: float, threshold: float) -> bool:
        return grasp_success(outcome.rise, outcome.links_holding, outcome.on_table)  # lifted and held

    def info(self, outcome: GraspOutcome) -> dict[str, Any]:
        return {"stroke_speed": 0.0,
                "grasp": {"rise": outcome.rise, "links_holding": outcome.links_holding,
                          "on_table": outcome.on_table}}


def _interaction(behavior: Behavior | GraspBehavior) -> Interaction:
    return GraspInteraction(behavior) if isinstance(behavior, GraspBehavior) else StrokeInteraction(behavior)


#: One interaction per behaviour, by name.
INTERACTIONS: Mapping[str, Interaction] = {name: _interaction(b) for name, b in BEHAVIORS.items()}


def get_interaction(name: str) -> Interaction:
    """The interaction of the behaviour called ``name``; raises ValueError listing the valid names."""
    if name not in INTERACTIONS:
        raise InvalidValueError(f"Unknown behavior {name!r}. Valid behaviors: {', '.join(INTERACTIONS)}.")
    return INTERACTIONS[name]
