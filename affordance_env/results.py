"""What the world saw and what an interaction did: frozen, typed records.

:class:`~affordance_env.world.World` returns them; the environments turn them into Gymnasium observations and
``info`` dicts (:meth:`Observation.info`, :meth:`InteractionResult.info`), and the dataset writer reads them
directly (:func:`affordance_env.dataset.format.interaction_row`). Their arrays are read-only.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from affordance_env.features import NOT_VISIBLE_VALUES, Features
from affordance_env.objects import ObjectGeometry

if TYPE_CHECKING:  # the records are light: reading them needs no simulator
    from affordance_env.attention import AttentionResult


def frozen_array(values: np.ndarray) -> np.ndarray:
    """``values`` made read-only (the array itself, not a copy)."""
    values.flags.writeable = False
    return values


@dataclass(frozen=True)
class Snapshot:
    """One picture of the range camera in the head, with the robot's joints then.

    Attributes:
        ranges: Distance along each pixel's ray [m], (H, W) float32; 0 where nothing is hit.
        mask: 1 on pixels of the object of interest, (H, W) int8.
        features: The paper's 49 features of the object.
        joints: The robot's joint angles [rad], float32, in the order of the robot variant's active joints.
        object_points: The points of the object the camera saw [m], world frame, (k, 3) (k = the mask's pixels,
            row-major); (0, 3) when not seen. :func:`affordance_env.centre.object_centre` places the object from
            them.
    """

    ranges: np.ndarray
    mask: np.ndarray
    features: Features
    joints: np.ndarray
    object_points: np.ndarray

    @property
    def visible(self) -> bool:
        """Whether the object had at least one pixel."""
        return self.features.visible


@dataclass(frozen=True)
class InitialSnapshot:
    """What an interaction's initial snapshot saw, and what its plan is made from.

    Attributes:
        snapshot: The picture.
        pose: The object's pose then, ``(x, y, z, qw, qx, qy, qz)`` [m] (read-only).
        yaw: The object's yaw for the plan [rad].
        geometry: The object's geometry as it rests (a cylinder lying or standing).
        still: Whether the robot and the object were still.
    """

    snapshot: Snapshot
    pose: np.ndarray
    yaw: float
    geometry: ObjectGeometry
    still: bool

    @property
    def features(self) -> Features:
        return self.snapshot.features

    @property
    def visible(self) -> bool:
        return self.snapshot.visible


@dataclass(frozen=True)
class Observation:
    """The world observed with the robot at home and the gaze on the object (:meth:`World.observe`).

    Attributes:
        initial: The snapshot, and the object as the next interaction plans for it.
        object_type: The object's type (:data:`affordance_env.objects.OBJECT_TYPES`).
        size: Its size [m].
        attention: How the head turned to the object.
    """

    initial: InitialSnapshot
    object_type: str
    size: float
    attention: AttentionResult

    @property
    def snapshot(self) -> Snapshot:
        return self.initial.snapshot

    @property
    def visible(self) -> bool:
        return self.initial.visible

    def info(self) -> dict[str, Any]:
        """The ``info`` of TapAffordance-v2's ``reset``: ``object``, ``attention``, ``visible``, ``still``."""
        attention = self.attention
        return {
            "object": {"type": self.object_type, "size": self.size, "pose": self.initial.pose.copy()},
            "attention": {"success": attention.success, "visible": attention.visible,
                          "pixel_error": attention.pixel_error},
            "visible": self.visible,
            "still": self.initial.still,
        }


@dataclass(frozen=True)
class IKReport:
    """How well the IK reached every pose the hand was sent to.

    Attributes:
        success: Every pose within the IK's tolerances.
        position_error: The largest position error [m].
        orientation_error: The largest orientation error [rad].
    """

    success: bool
    position_error: float
    orientation_error: float


@dataclass(frozen=True)
class InteractionResult:
    """One interaction of a behaviour, from its initial snapshot to its final one (:meth:`World.interact`).

    Attributes:
        behavior: The behaviour's name.
        action: Its parameters, (3,) in [-1, 1].
        object_type: The object's type.
        size: Its size [m].
        initial: The initial snapshot (and the object's pose then).
        final: The final snapshot; None when the simulation faulted (``outcome == "fault"``): nothing of its
            state is to be trusted.
        final_pose: The object's pose at the final snapshot (NaN after a fault).
        effect: Final minus initial features, (49,) float32 (zeros after a fault).
        displacement: Horizontal travel of the object's centre on the table [m]: to where it rests, or to where it
            left the table.
        rolling_distance: The part of it covered rolling [m].
        rolled: ``rolling_distance`` above the roll threshold.
        success: The paper's success/fail label (one rule per behaviour); always False for a failed interaction.
        toppled: Tilted more than 45 degrees after the centre rose over an edge.
        tilt: How far the initially vertical body axis turned [rad].
        outcome: ``"rest"``, ``"off_table"``, ``"timeout"``, or ``"fault"`` (the simulation became unstable).
        outcome_time: When, after the first touch, the object came to rest or left the table [s].
        contact: The hand touched the object.
        hand_speed: Palm speed at the first touch [m/s].
        ik: How well the IK reached every pose.
        failure: None, or why the interaction is not a valid sample (see TapAffordance-v2's Info).
        facts: The behaviour's own facts (``stroke_speed``; for the grasp also ``grasp``).
    """

    behavior: str
    action: np.ndarray
    object_type: str
    size: float
    initial: InitialSnapshot
    final: Snapshot | None
    final_pose: np.ndarray
    effect: np.ndarray
    displacement: float
    rolling_distance: float
    rolled: bool
    success: bool
    toppled: bool
    tilt: float
    outcome: str
    outcome_time: float
    contact: bool
    hand_speed: float
    ik: IKReport
    failure: str | None
    facts: Mapping[str, Any]

    @property
    def final_features(self) -> np.ndarray:
        """The final snapshot's 49 features (the not-visible values after a fault)."""
        return NOT_VISIBLE_VALUES if self.final is None else self.final.features.values

    @property
    def visible(self) -> bool:
        """Whether the final snapshot saw the object."""
        return self.final is not None and self.final.visible

    def info(self) -> dict[str, Any]:
        """The ``info`` of TapAffordance-v2's ``step`` (fresh arrays: a restored state steps again)."""
        return {
            "object": {"type": self.object_type, "size": self.size,
                       "pose": self.final_pose.copy(), "initial_pose": self.initial.pose.copy(),
                       "final_pose": self.final_pose.copy()},
            "initial_features": self.initial.features.values.copy(),
            "final_features": np.array(self.final_features),
            "effect": self.effect.copy(),
            "displacement": self.displacement,
            "rolling_distance": self.rolling_distance,
            "rolled": self.rolled,
            "success": self.success,
            "toppled": self.toppled,
            "tilt": self.tilt,
            "outcome": self.outcome,
            "outcome_time": self.outcome_time,
            "contact": self.contact,
            "hand_speed": self.hand_speed,
            "ik": {"success": self.ik.success, "position_error": self.ik.position_error,
                   "orientation_error": self.ik.orientation_error},
            "visible": self.visible,
            "behavior": self.behavior,
            "failure": self.failure,
            **self.facts,
        }
