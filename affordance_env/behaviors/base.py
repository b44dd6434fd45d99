"""What the world asks of a behaviour: the protocol every kind of behaviour implements.

The world (:class:`affordance_env.world.World`) runs a behaviour through these calls and never asks which one it
is. A behaviour

- prepares, once, what does not depend on the object: the arm posture its IK starts from;
- plans, from the object the robot saw and the action (a pure function);
- executes the plan on the robot (:mod:`affordance_env.motion`) and reports what happened (a
  :class:`~affordance_env.motion.ReachOutcome`), or answers from the kinematics alone whether it could;
- says through which pose the way home passes, and from when the object's outcome is awaited;
- says why a sample is not valid beyond what every interaction checks, what its success is, and which of its own
  facts the interaction's result carries.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, ClassVar, Protocol

import numpy as np

from affordance_env.motion import MotionExecutor, ReachOutcome
from affordance_env.objects import ObjectGeometry
from affordance_env.outcome import Labels


class Behavior(Protocol):
    """A behaviour of the robot, as the world runs it."""

    #: Its name: ``behavior=`` of the environments, and the registry's key (:mod:`affordance_env.registry`).
    name: str
    #: The robot variant it needs (:data:`affordance_env.robot_model.VARIANTS`).
    robot: str
    #: One line for the documentation.
    description: str
    #: What it is, for messages: ``"stroke"`` or ``"grasp"``.
    kind: ClassVar[str]

    def prepare(self, motion: MotionExecutor, placement_centre: np.ndarray, size: float) -> np.ndarray | None:
        """The arm posture the IK of every approach starts from (None: the current servo targets), solved once when
        the world is built, which the world hands back to :meth:`execute` and :meth:`reachable`."""

    def plan(self, geometry: ObjectGeometry, p_object: np.ndarray, yaw: float, table_top: float,
             action: np.ndarray) -> Any:
        """The plan of the interaction with the object at ``p_object`` [m] and ``yaw`` [rad]: a pure function."""

    def execute(self, motion: MotionExecutor, plan: Any, posture: np.ndarray | None,
                at_end: Callable[[], None] | None = None) -> ReachOutcome:
        """Run the plan on the robot up to the way home, the IK starting from ``posture`` (:meth:`prepare`).
        ``at_end``, if given, is called where the behaviour ends as the paper measures it, if that is before the
        plan's end (the grasp: at the end of the hold, the object held); the world takes its final snapshot
        there."""

    def reachable(self, motion: MotionExecutor, plan: Any, posture: np.ndarray | None) -> bool:
        """Whether the arm can reach every pose of the plan (kinematics only: no physics step)."""

    def via_home(self, outcome: ReachOutcome) -> np.ndarray | None:
        """Joint targets the way home passes through first, or None."""

    def awaited_since(self, outcome: ReachOutcome, now: float) -> float:
        """Simulation time [s] from which the object's outcome is awaited."""

    def failure(self, outcome: ReachOutcome) -> str | None:
        """Why the interaction is not a valid sample, beyond what every interaction checks; None if valid."""

    def success(self, outcome: ReachOutcome, labels: Labels, displacement: float, threshold: float) -> bool:
        """The success/fail label of a valid interaction."""

    def facts(self, outcome: ReachOutcome) -> Mapping[str, Any]:
        """The behaviour's own facts of the interaction (its keys of the env's ``info``)."""


def palm_rotation(fingers: tuple[float, float, float], palm_normal: tuple[float, float, float]) -> np.ndarray:
    """The palm frame's orientation, (3, 3): columns along the fingers, towards the thumb side, the palm normal."""
    x = np.asarray(fingers, dtype=float)
    z = np.asarray(palm_normal, dtype=float)
    return np.column_stack([x, np.cross(z, x), z])
