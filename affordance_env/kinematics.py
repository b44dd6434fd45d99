"""Forward and inverse kinematics of the iCub's right hand and head with Pinocchio.

The model is built from the same URDF as the simulation (:func:`affordance_env.robot_model.icub_urdf`) and
reduced to :data:`~affordance_env.robot_model.ACTIVE_JOINTS`; configurations are vectors in that joint order.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from affordance_env.robot_model import ACTIVE_JOINTS, HAND_FRAME, HEAD_FRAME, REACH_JOINTS, icub_urdf


@dataclass(frozen=True)
class IKResult:
    """Outcome of :meth:`Kinematics.solve_ik`.

    Attributes:
        q: Joint configuration reached, in :data:`ACTIVE_JOINTS` order [rad]; within the joint limits (and the
            ``joint_ranges`` asked for).
        success: Whether both errors are within the requested tolerances.
        position_error: Distance between reached and target hand position [m].
        orientation_error: Angle between reached and target hand orientation [rad] (0 if none was asked).
        iterations: Iterations used.
    """

    q: np.ndarray
    success: bool
    position_error: float
    orientation_error: float
    iterations: int


class Kinematics:
    """Pinocchio model of the iCub reduced to the joints the project moves.

    Args:
        hand_frame: Name of the end-effector frame.
        head_frame: Name of the head frame (camera mount).
    """

    def __init__(self, hand_frame: str = HAND_FRAME, head_frame: str = HEAD_FRAME) -> None:
        full = pin.buildModelFromXML(icub_urdf())
        locked = [full.getJointId(name) for name in full.names[1:] if name not in ACTIVE_JOINTS]
        self.model = pin.buildReducedModel(full, locked, pin.neutral(full))
        self.data = self.model.createData()
        names = list(self.model.names[1:])
        order = [names.index(name) for name in ACTIVE_JOINTS]
        if order != list(range(len(ACTIVE_JOINTS))):
            raise RuntimeError(f"Pinocchio joint order {names} differs from ACTIVE_JOINTS {ACTIVE_JOINTS}.")
        for frame in (hand_frame, head_frame):
            if not self.model.existFrame(frame):
                available = sorted({f.name for f in self.model.frames})
                raise ValueError(f"Frame {frame!r} does not exist in the model. Available frames: {available}")
        self.hand_frame_id = self.model.getFrameId(hand_frame)
        self.head_frame_id = self.model.getFrameId(head_frame)
        self.lower = self.model.lowerPositionLimit.copy()
        self.upper = self.model.upperPositionLimit.copy()
        self.reach_dofs = np.array([ACTIVE_JOINTS.index(name) for name in REACH_JOINTS])

    @property
    def nq(self) -> int:
        """Number of joints (len(ACTIVE_JOINTS))."""
        return self.model.nq

    def _check_q(self, q: np.ndarray) -> np.ndarray:
        q = np.asarray(q, dtype=float)
        if q.shape != (self.nq,) or not np.all(np.isfinite(q)):
            raise ValueError(f"q must be {self.nq} finite joint angles in ACTIVE_JOINTS order, got {q!r}.")
        return q

    def frame_pose(self, q: np.ndarray, frame_id: int) -> pin.SE3:
        """World pose of frame ``frame_id`` at configuration ``q``."""
        pin.framesForwardKinematics(self.model, self.data, self._check_q(q))
        return self.data.oMf[frame_id].copy()

    def hand_pose(self, q: np.ndarray) -> pin.SE3:
        """``T_world_hand``: world pose of the palm frame at ``q``."""
        return self.frame_pose(q, self.hand_frame_id)

    def head_pose(self, q: np.ndarray) -> pin.SE3:
        """``T_world_head``: world pose of the head frame at ``q``."""
        return self.frame_pose(q, self.head_frame_id)

    def joint_limits(
        self, joint_ranges: Mapping[str, tuple[float, float]] | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """(lower, upper) joint limits [rad], ACTIVE_JOINTS order: the model's, narrowed by ``joint_ranges``.

        Args:
            joint_ranges: ``{joint name: (low, high)}`` for joints of REACH_JOINTS; each range is intersected with
                the model's. None or empty: the model's limits themselves (the arrays, not copies).
        """
        if not joint_ranges:
            return self.lower, self.upper
        lower, upper = self.lower.copy(), self.upper.copy()
        for name, (low, high) in joint_ranges.items():
            if name not in REACH_JOINTS:
                raise ValueError(f"joint_ranges: {name!r} is not a joint the IK moves; those are {REACH_JOINTS}.")
            j = ACTIVE_JOINTS.index(name)
            lower[j], upper[j] = max(lower[j], float(low)), min(upper[j], float(high))
            if not lower[j] <= upper[j]:
                raise ValueError(f"joint_ranges: {name!r} range ({low}, {high}) misses the joint's limits "
                                 f"({self.lower[j]:.3f}, {self.upper[j]:.3f}) rad.")
        return lower, upper

    def solve_ik(
        self,
        p_world_target: np.ndarray,
        q_init: np.ndarray,
        R_world_target: np.ndarray | None = None,
        *,
        orientation_weight: float = 0.3,
        position_tolerance: float = 1e-3,
        orientation_tolerance: float = 0.15,
        max_iterations: int = 150,
        damping: float = 1e-4,
        joint_ranges: Mapping[str, tuple[float, float]] | None = None,
    ) -> IKResult:
        """Damped least-squares IK of the palm over the torso and right-arm joints.

        The neck keeps its value from ``q_init``. Every iterate is clipped to the joint limits (narrowed by
        ``joint_ranges``), so the returned configuration is always feasible; ``success`` tells whether it reaches
        the target.

        Args:
            p_world_target: Target palm position in the world frame [m], shape (3,).
            q_init: Initial configuration [rad], shape (nq,).
            R_world_target: Optional target palm orientation (3x3 rotation matrix).
            orientation_weight: Weight of the orientation error against the position error [m/rad].
            position_tolerance: Position error accepted as success [m].
            orientation_tolerance: Orientation error accepted as success [rad].
            max_iterations: Iteration budget.
            damping: Levenberg-Marquardt damping of the least-squares step.
            joint_ranges: Narrower ranges for some joints, ``{name: (low, high)}`` [rad] (see :meth:`joint_limits`):
                a posture the solution must keep, e.g. a wrist angle that holds the forearm off the table.
        """
        p_target = np.asarray(p_world_target, dtype=float)
        if p_target.shape != (3,) or not np.all(np.isfinite(p_target)):
            raise ValueError(f"p_world_target must be 3 finite coordinates [m], got {p_world_target!r}.")
        if R_world_target is not None:
            R_world_target = np.asarray(R_world_target, dtype=float)
            if R_world_target.shape != (3, 3) or np.abs(R_world_target @ R_world_target.T - np.eye(3)).max() > 1e-6:
                raise ValueError(f"R_world_target must be a 3x3 rotation matrix, got {R_world_target!r}.")
        lower, upper = self.joint_limits(joint_ranges)
        q = np.clip(self._check_q(q_init).copy(), lower, upper)
        dofs = self.reach_dofs
        lower, upper = lower[dofs], upper[dofs]
        model, data, frame = self.model, self.data, self.hand_frame_id
        n_error = 3 if R_world_target is None else 6
        regulariser = damping * np.eye(n_error)
        error = np.empty(n_error)
        pos_err = rot_err = np.inf
        iteration = 0
        for iteration in range(1, max_iterations + 1):  # noqa: B007 (the count is returned)
            # computeFrameJacobian runs the forward kinematics and places the hand frame (data.oMf[frame]).
            J = pin.computeFrameJacobian(model, data, q, frame, pin.LOCAL_WORLD_ALIGNED)
            T_world_hand = data.oMf[frame]
            error[:3] = p_target - T_world_hand.translation
            pos_err = float(np.linalg.norm(error[:3]))
            jac = J[:n_error, dofs]
            if R_world_target is None:
                rot_err = 0.0
            else:
                e_rot = pin.log3(R_world_target @ T_world_hand.rotation.T)
                rot_err = float(np.linalg.norm(e_rot))
                error[3:] = orientation_weight * e_rot
                jac[3:] *= orientation_weight
            if pos_err <= position_tolerance and rot_err <= orientation_tolerance * 0.5:
                break
            step = jac.T @ np.linalg.solve(jac @ jac.T + regulariser, error)
            q[dofs] = np.minimum(np.maximum(q[dofs] + step, lower), upper)
        else:
            pin.framesForwardKinematics(model, data, q)
            T_world_hand = data.oMf[frame]
            pos_err = float(np.linalg.norm(p_target - T_world_hand.translation))
            if R_world_target is not None:
                rot_err = float(np.linalg.norm(pin.log3(R_world_target @ T_world_hand.rotation.T)))
        success = pos_err <= position_tolerance and rot_err <= orientation_tolerance
        return IKResult(q, bool(success), pos_err, rot_err, iteration)
