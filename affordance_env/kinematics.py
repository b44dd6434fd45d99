"""Forward and inverse kinematics of the iCub's hand and head with Pinocchio.

The model is built from the same URDF as the simulation (:func:`affordance_env.robot_model.icub_urdf`) and
reduced to the active joints of a robot variant (:data:`~affordance_env.robot_model.VARIANTS`): for ``"tap"``
(the default) :data:`~affordance_env.robot_model.ACTIVE_JOINTS`, torso, neck and right arm; for ``"grasp"``
torso, neck and left arm, with the ``left_hand_mk3`` hand model appended at ``l_hand_dh_frame`` as in the
simulation. Configurations are vectors in the variant's ``active_joints`` order; Pinocchio's own joint order
(depth first through its tree, the appended hand's joints after the arm's) is mapped to it by name.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from affordance_env.exceptions import InvalidValueError
from affordance_env.linalg import matmul, matmul_f64, norm, norm_f64, solve_spd
from affordance_env.robot_model import (
    HAND_MOUNT_FRAME,
    HAND_MOUNT_POS,
    HEAD_FRAME,
    get_variant,
    hand_urdf,
    icub_urdf,
)

#: At most this many distinct joint ranges (and dampings) are kept by a :class:`Kinematics` between IK calls.
MAX_CACHED_RANGES = 32
#: :meth:`Kinematics.solve_ik` with ``give_up_beyond`` gives up on a target once its error has stood still beyond
#: what the caller accepts: over the last STALL_WINDOW + 1 iterations the error (the larger of the position and the
#: orientation error, each over the solver's tolerance) varied by less than STALL_SPREAD of itself, and the position
#: or the orientation error is more than STALL_MARGIN times the caller's. A target beyond the arm's reach ends so
#: (the arm stretched towards it, or a joint at its limit) and used the whole budget of 150 iterations: in a
#: goal-episode collection, 36 % of the time, in the checks of candidate actions. Of the 6894 calls of 50 goal
#: episodes, those whose whole budget ends within the caller's tolerances (5 mm, 0.35 rad) never varied by less than
#: 0.44 % over 21 iterations beyond them (one stood at 33 mm for 40 iterations, then fell to 3 mm): a spread of
#: 0.1 % keeps a margin of 4 (a window of 11 iterations would leave none). Those that give up save 23 % of all
#: iterations. (Measured before the left arm's torso was bounded in the scene with both arms,
#: ``affordance_env.robot_model.HELD_ARM_TORSO_RANGES``: the bounded grasp IK slides along the bound before its error
#: stands still, and gives up later.)
STALL_WINDOW, STALL_SPREAD, STALL_MARGIN = 20, 1e-3, 1.05


@dataclass(frozen=True)
class IKResult:
    """Outcome of :meth:`Kinematics.solve_ik`.

    Attributes:
        q: Joint configuration reached, in the variant's active-joint order [rad]; within the joint limits the IK
            keeps to (:meth:`Kinematics.joint_limits`: the variant's ``ik_ranges`` and the ``joint_ranges`` asked
            for).
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


def _build_model(variant: str) -> pin.Model:
    """The Pinocchio model of robot ``variant``: the URDF reduced to its active joints, with the mk3 hand."""
    robot = get_variant(variant)
    full = pin.buildModelFromXML(icub_urdf())
    locked = [full.getJointId(name) for name in full.names[1:] if name not in robot.active_joints]
    q_locked = pin.neutral(full)  # locked at zero, or where the variant holds them (the other arm at home)
    for name, angle in robot.held.items():
        if full.existJointName(name):
            q_locked[full.joints[full.getJointId(name)].idx_q] = angle
    model = pin.buildReducedModel(full, locked, q_locked)
    if robot.fingered:
        # The palm link (the hand model's root) at HAND_MOUNT_POS in HAND_MOUNT_FRAME, unrotated, as in MuJoCo.
        T_mount_palm = pin.SE3(np.eye(3), np.array(HAND_MOUNT_POS))
        model = pin.appendModel(model, pin.buildModelFromXML(hand_urdf()), model.getFrameId(HAND_MOUNT_FRAME),
                                T_mount_palm)
    return model


def _stall_test(give_up_beyond: tuple[float, float] | None, position_tolerance: float, orientation_tolerance: float
                ) -> tuple[bool, float, float, float]:
    """Whether :meth:`Kinematics.solve_ik` runs the stall test (with ``give_up_beyond``; none with a zero
    tolerance), and its scale and bounds: the factor that puts the orientation error in units of the position
    tolerance (each iteration's error is over its tolerance), and the position [m] and orientation [rad] errors
    beyond which a target whose error stands still is given up (:data:`STALL_MARGIN` times the caller's); the
    three are NaN without the test."""
    if not (give_up_beyond is not None and position_tolerance > 0 and orientation_tolerance > 0):
        return False, np.nan, np.nan, np.nan
    rot_scale = position_tolerance / (0.5 * orientation_tolerance)  # in units of the position tolerance
    return True, rot_scale, STALL_MARGIN * give_up_beyond[0], STALL_MARGIN * give_up_beyond[1]


class Kinematics:
    """Pinocchio model of the iCub reduced to the joints the project moves.

    Args:
        hand_frame: Name of the end-effector frame; by default the variant's palm frame.
        head_frame: Name of the head frame (camera mount).
        variant: Robot variant (:data:`~affordance_env.robot_model.VARIANTS`): ``"tap"`` or ``"grasp"``.
    """

    def __init__(self, hand_frame: str | None = None, head_frame: str = HEAD_FRAME, *, variant: str = "tap") -> None:
        self.variant = get_variant(variant)
        self.joint_names = self.variant.active_joints
        self._last_rotation = np.full((3, 3), np.nan)  # the last target orientation found to be a rotation
        hand_frame = self.variant.hand_frame if hand_frame is None else hand_frame
        self.model = _build_model(self.variant.name)
        self.data = self.model.createData()
        names = list(self.model.names[1:])
        if sorted(names) != sorted(self.joint_names) or self.model.nq != len(names):
            raise RuntimeError(f"Pinocchio joints {names} differ from the active joints {self.joint_names}.")
        #: q_pinocchio = q[self._to_pin] and q = q_pinocchio[self._from_pin] (every joint is a 1-dof revolute).
        self._to_pin = np.array([self.joint_names.index(name) for name in names])
        self._from_pin = np.array([names.index(name) for name in self.joint_names])
        for frame in (hand_frame, head_frame):
            if not self.model.existFrame(frame):
                available = sorted({f.name for f in self.model.frames})
                raise InvalidValueError(f"Frame {frame!r} does not exist in the model. Available frames: {available}")
        self.hand_frame_id = self.model.getFrameId(hand_frame)
        self.head_frame_id = self.model.getFrameId(head_frame)
        #: The model's (URDF) joint limits [rad] in active-joint order; the IK keeps to ``ik_lower`` and ``ik_upper``.
        self.lower = self.model.lowerPositionLimit[self._from_pin].copy()
        self.upper = self.model.upperPositionLimit[self._from_pin].copy()
        #: Indices of the reach joints in Pinocchio's order (the IK works in that order).
        self._reach_pin = np.array([names.index(name) for name in self.variant.reach_joints])
        #: Indices of the reach joints in active-joint order.
        self.reach_dofs = np.array([self.joint_names.index(name) for name in self.variant.reach_joints])
        #: The limits every IK keeps to [rad]: the joints' own, narrowed by the variant's ``ik_ranges`` (what the
        #: scene forbids); the same arrays as ``lower`` and ``upper`` where it has none.
        self.ik_lower, self.ik_upper = self._narrowed(self.lower, self.upper, self.variant.ik_ranges, "ik_ranges")
        #: What :meth:`solve_ik` derives from its arguments alone, kept across calls (a line of the palm asks for
        #: the same joint ranges and damping at every waypoint): limits by joint ranges, regularisers by damping.
        self._limits: dict[tuple, tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = {}
        self._regularisers: dict[tuple[float, int], np.ndarray] = {}

    @property
    def nq(self) -> int:
        """Number of joints (the variant's active joints)."""
        return self.model.nq

    def _check_q(self, q: np.ndarray) -> np.ndarray:
        q = np.asarray(q, dtype=float)
        if q.shape != (self.model.nq,) or not np.logical_and.reduce(np.isfinite(q)):  # .all(), without its layer
            raise InvalidValueError(f"q must be {self.nq} finite joint angles in the {self.variant.name!r} variant's "
                             f"active-joint order, got {q!r}.")
        return q

    def frame_pose(self, q: np.ndarray, frame_id: int) -> pin.SE3:
        """World pose of frame ``frame_id`` at configuration ``q``."""
        pin.framesForwardKinematics(self.model, self.data, self._check_q(q)[self._to_pin])
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
        """(lower, upper) joint limits [rad] the IK keeps to, in the variant's active-joint order: the model's,
        narrowed by the variant's ``ik_ranges`` and by ``joint_ranges``.

        Args:
            joint_ranges: ``{joint name: (low, high)}`` for joints of the variant's reach joints; each range is
                intersected with the limits. None or empty: ``(ik_lower, ik_upper)`` themselves (the arrays, not
                copies).
        """
        return self._narrowed(self.ik_lower, self.ik_upper, joint_ranges, "joint_ranges")

    def _narrowed(self, lower: np.ndarray, upper: np.ndarray, joint_ranges: Mapping[str, tuple[float, float]] | None,
                  what: str) -> tuple[np.ndarray, np.ndarray]:
        """``(lower, upper)`` intersected with ``joint_ranges`` (reach joints only; ``what`` names them in errors);
        the arrays themselves if none."""
        if not joint_ranges:
            return lower, upper
        base_lower, base_upper = lower, upper
        lower, upper = lower.copy(), upper.copy()
        reach = self.variant.reach_joints
        for name, (low, high) in joint_ranges.items():
            if name not in reach:
                raise InvalidValueError(f"{what}: {name!r} is not a joint the IK moves; those are {reach}.")
            j = self.joint_names.index(name)
            lower[j], upper[j] = max(lower[j], float(low)), min(upper[j], float(high))
            if not lower[j] <= upper[j]:
                raise InvalidValueError(f"{what}: {name!r} range ({low}, {high}) misses the limits the IK keeps to "
                                 f"({base_lower[j]:.3f}, {base_upper[j]:.3f}) rad.")
        return lower, upper

    def _ik_limits(self, joint_ranges: Mapping[str, tuple[float, float]] | None
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(lower, upper) of :meth:`joint_limits` in Pinocchio's order, and of its reach joints: read-only arrays,
        computed once per distinct ``joint_ranges`` (by value)."""
        key = tuple(joint_ranges.items()) if joint_ranges else ()
        try:
            limits = self._limits.get(key)
            cacheable = True
        except TypeError:  # ranges that cannot be a key (lists): derived at every call
            limits, cacheable = None, False
        if limits is None:
            lower, upper = self.joint_limits(joint_ranges)
            lower, upper = lower[self._to_pin], upper[self._to_pin]
            limits = (lower, upper, lower[self._reach_pin], upper[self._reach_pin])
            for array in limits:
                array.flags.writeable = False
            if cacheable:
                if len(self._limits) >= MAX_CACHED_RANGES:
                    self._limits.clear()
                self._limits[key] = limits
        return limits

    def _regulariser(self, damping: float, n: int) -> np.ndarray:
        """``damping`` times the ``n`` x ``n`` identity, read-only, made once per (damping, n)."""
        regulariser = self._regularisers.get((damping, n))
        if regulariser is None:
            if len(self._regularisers) >= MAX_CACHED_RANGES:
                self._regularisers.clear()
            regulariser = self._regularisers[(damping, n)] = damping * np.eye(n)
            regulariser.flags.writeable = False
        return regulariser

    def _checked_target(self, p_world_target: np.ndarray, R_world_target: np.ndarray | None
                        ) -> tuple[np.ndarray, np.ndarray | None]:
        """The target of :meth:`solve_ik` as float arrays: its position, and its orientation or None;
        InvalidValueError unless they are 3 finite coordinates and a 3x3 rotation matrix."""
        p_target = np.asarray(p_world_target, dtype=float)
        if p_target.shape != (3,) or not np.logical_and.reduce(np.isfinite(p_target)):
            raise InvalidValueError(f"p_world_target must be 3 finite coordinates [m], got {p_world_target!r}.")
        if R_world_target is not None:
            R_world_target = np.asarray(R_world_target, dtype=float)
            # a stroke asks for one orientation many times: the last one checked need not be checked again
            # (elementwise equality of two 3x3 arrays: np.array_equal's answer, without its checks)
            if not (R_world_target.shape == (3, 3) and (R_world_target == self._last_rotation).all()):
                if (R_world_target.shape != (3, 3)
                        or np.abs(matmul(R_world_target, R_world_target.T) - np.eye(3)).max() > 1e-6):
                    raise InvalidValueError(f"R_world_target must be a 3x3 rotation matrix, got {R_world_target!r}.")
                self._last_rotation = R_world_target.copy()
        return p_target, R_world_target

    def _clipped_start(self, q_init: np.ndarray, joint_ranges: Mapping[str, tuple[float, float]] | None
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``q_init`` in Pinocchio's order, clipped to the limits :meth:`solve_ik` keeps to (a new array), and the
        reach joints' (lower, upper) limits in that order (:meth:`_ik_limits`)."""
        lower_all, upper_all, lower, upper = self._ik_limits(joint_ranges)
        q = np.minimum(np.maximum(self._check_q(q_init)[self._to_pin], lower_all), upper_all)
        return q, lower, upper

    def _errors_at(self, q: np.ndarray, p_target: np.ndarray, R_world_target: np.ndarray | None, rot_err: float
                   ) -> tuple[float, float]:
        """(position, orientation) errors of the palm at ``q`` (Pinocchio's order) from the target; the
        orientation error is ``rot_err`` when no orientation is asked."""
        pin.framesForwardKinematics(self.model, self.data, q)
        T_world_hand = self.data.oMf[self.hand_frame_id]
        pos_err = norm(p_target - T_world_hand.translation)
        if R_world_target is not None:
            rot_err = norm(pin.log3(matmul(R_world_target, T_world_hand.rotation.T)))
        return pos_err, rot_err

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
        give_up_beyond: tuple[float, float] | None = None,
    ) -> IKResult:
        """Damped least-squares IK of the palm over the variant's reach joints (torso and arm).

        The neck and the fingers keep their values from ``q_init``. Every iterate is clipped to
        :meth:`joint_limits` (the variant's ``ik_ranges``, narrowed by ``joint_ranges``), so the returned
        configuration is always feasible; ``success`` tells whether it reaches the target.

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
            give_up_beyond: The position [m] and orientation [rad] errors the caller accepts, if it needs only to
                know whether they are met (a feasibility check), not the closest configuration: the solver gives up
                once its error stands still beyond them (:data:`STALL_WINDOW`) rather than spend the whole budget.
        """
        p_target, R_world_target = self._checked_target(p_world_target, R_world_target)
        # In Pinocchio's order from here on; the reach joints' limits apart.
        q, lower, upper = self._clipped_start(q_init, joint_ranges)
        dofs = self._reach_pin
        model, data, frame = self.model, self.data, self.hand_frame_id
        n_error = 3 if R_world_target is None else 6
        regulariser = self._regulariser(damping, n_error)
        error = np.empty(n_error)
        error_position, error_rotation = error[:3], error[3:]  # views, made once
        pos_err = rot_err = np.inf
        iteration = 0
        stall_test, rot_scale, pos_beyond, rot_beyond = _stall_test(give_up_beyond, position_tolerance,
                                                                    orientation_tolerance)
        errors: list[float] = []  # each iteration's error over its tolerance, for the stall test
        # Pinocchio's functions and the frames' placements bound once: the loop below runs a few times per call.
        jacobian, log3, placements = pin.computeFrameJacobian, pin.log3, data.oMf
        world_aligned = pin.LOCAL_WORLD_ALIGNED
        for iteration in range(1, max_iterations + 1):  # noqa: B007 (the count is returned)
            # computeFrameJacobian runs the forward kinematics and places the hand frame (data.oMf[frame]).
            J = jacobian(model, data, q, frame, world_aligned)
            T_world_hand = placements[frame]
            np.subtract(p_target, T_world_hand.translation, out=error_position)
            # linalg's norm and matmul on the float64 arrays made here, without their conversions (the same bits)
            pos_err = norm_f64(error_position)
            jac = J[:n_error, dofs]  # (its memory order, Fortran, decides einsum's loops below: kept as it is)
            if R_world_target is None:
                rot_err = 0.0
            else:
                e_rot = log3(matmul_f64(R_world_target, T_world_hand.rotation.T))
                rot_err = norm_f64(e_rot)
                np.multiply(orientation_weight, e_rot, out=error_rotation)
                jac[3:] *= orientation_weight
            if pos_err <= position_tolerance and rot_err <= orientation_tolerance * 0.5:
                break
            if stall_test:
                errors.append(max(pos_err, rot_err * rot_scale))
                if iteration > STALL_WINDOW and (pos_err > pos_beyond or rot_err > rot_beyond):
                    last = errors[-STALL_WINDOW - 1:]
                    if max(last) - min(last) < STALL_SPREAD * errors[-1]:
                        break  # stood still: q is where the errors were measured
            step = matmul_f64(solve_spd(matmul_f64(jac, jac.T) + regulariser, error), jac)
            q[dofs] = np.minimum(np.maximum(q[dofs] + step, lower), upper)
        else:
            pos_err, rot_err = self._errors_at(q, p_target, R_world_target, rot_err)
        return self._result(q, pos_err, rot_err, iteration, position_tolerance, orientation_tolerance)

    def _result(self, q: np.ndarray, pos_err: float, rot_err: float, iterations: int, position_tolerance: float,
                orientation_tolerance: float) -> IKResult:
        """The :class:`IKResult` of ``q`` (Pinocchio's order) with its errors: a success when both are within their
        tolerances."""
        success = pos_err <= position_tolerance and rot_err <= orientation_tolerance
        return IKResult(q[self._from_pin], bool(success), pos_err, rot_err, iterations)
