"""Executing behaviours on the simulated robot: joint-space moves, the Cartesian stroke, and waiting.

The Cartesian stroke is turned into a joint trajectory by Pinocchio IK (one solve per control tick, warm
started from the previous one) and tracked by MuJoCo's position servos, so the hand's real motion includes
the servo lag and the arm's momentum.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from affordance_env.behaviors import StrokePlan
from affordance_env.kinematics import IKResult, Kinematics
from affordance_env.physics import TapPhysics

#: Period of the servo set-point updates [s].
CONTROL_DT = 0.01
#: Time to move from home to above the object, and from there down to the pre-stroke pose [s].
REACH_TIME, DESCEND_TIME = 0.35, 0.15
#: Time to back off after the stroke, to lift the hand above the object, and to return home [s].
BACKOFF_TIME, LIFT_TIME, HOME_TIME = 0.12, 0.15, 0.3
#: The hand must be this close to the pre-stroke pose before the stroke starts [m], waiting at most
#: SETTLE_MAX_TIME [s] for the servos.
SETTLE_TOLERANCE, SETTLE_MAX_TIME = 0.003, 0.4
#: The robot is still when every joint is slower than HOLD_SPEED_TOLERANCE [rad/s]; it is given at most
#: HOLD_MAX_TIME [s] to get there. The servos are critically damped, so a free joint is that slow only within
#: about 1 mrad of its target; an arm blocked short of its target (resting on an object that rolled under it)
#: is still all the same.
HOLD_SPEED_TOLERANCE, HOLD_MAX_TIME = 0.01, 1.0
#: Spacing of the IK solutions along the stroke line [m].
IK_SPACING = 0.01
#: IK tolerances for the stroke waypoints: position [m] and orientation [rad].
IK_POSITION_TOLERANCE, IK_ORIENTATION_TOLERANCE = 0.005, 0.35


@dataclass(frozen=True)
class StrokeOutcome:
    """What happened during a stroke.

    Attributes:
        ik_success: Every waypoint of the stroke (pre-stroke pose and the stroke line) was reached by the IK
            within tolerance.
        ik_position_error: Largest IK position error over the waypoints [m].
        ik_orientation_error: Largest IK orientation error over the waypoints [rad].
        contact: The hand touched the object.
        contact_time: Simulation time of the first touch [s] (NaN without contact).
        hand_speed: Hand speed at first touch [m/s] (0 without contact).
        hand_travel: Distance the palm travelled along the stroke direction [m].
        start_error: Distance of the palm from the pre-stroke pose when the stroke started [m].
        object_moved: How far the object moved before the stroke started (touched during the reach) [m].
    """

    ik_success: bool
    ik_position_error: float
    ik_orientation_error: float
    contact: bool
    contact_time: float
    hand_speed: float
    hand_travel: float
    start_error: float
    object_moved: float


class MotionExecutor:
    """Runs strokes on ``physics`` using ``kinematics`` (both describe the same robot)."""

    def __init__(self, physics: TapPhysics, kinematics: Kinematics) -> None:
        self.physics = physics
        self.kinematics = kinematics
        self.steps_per_tick = max(1, round(CONTROL_DT / physics.model.opt.timestep))

    def _tick(self, q: np.ndarray) -> None:
        self.physics.set_joint_targets(q)
        self.physics.step(self.steps_per_tick)

    def move_joints(self, q_target: np.ndarray, duration: float) -> None:
        """Ramp the servo targets linearly from their current value to ``q_target`` over ``duration`` [s]."""
        q_from = self.physics.joint_targets()
        n = max(1, round(duration / CONTROL_DT))
        for k in range(1, n + 1):
            self._tick(q_from + (q_target - q_from) * (k / n))

    def settle(self, p_world_target: np.ndarray, tolerance: float = SETTLE_TOLERANCE,
               max_time: float = SETTLE_MAX_TIME) -> float:
        """Hold the servo targets until the palm is within ``tolerance`` [m] of ``p_world_target``.

        Returns the remaining distance [m] (larger than ``tolerance`` if ``max_time`` [s] ran out).
        """
        q = self.physics.joint_targets()
        for _ in range(max(1, round(max_time / CONTROL_DT))):
            error = float(np.linalg.norm(self.physics.hand_position() - p_world_target))
            if error <= tolerance:
                return error
            self._tick(q)
        return float(np.linalg.norm(self.physics.hand_position() - p_world_target))

    def _ik(self, p: np.ndarray, q_init: np.ndarray, plan: StrokePlan) -> IKResult:
        return self.kinematics.solve_ik(
            p, q_init, plan.R_world_hand, position_tolerance=1e-3, orientation_tolerance=IK_ORIENTATION_TOLERANCE,
            joint_ranges=plan.joint_ranges,
        )

    def plan_joint_path(self, plan: StrokePlan) -> tuple[list[IKResult], np.ndarray]:
        """IK of the approach poses and of the stroke line sampled every control tick.

        Returns the IK results (above, start, then every stroke point) and the stroke's joint path (n, nq).
        """
        q = self.physics.joint_targets()
        above = self._ik(plan.p_above, q, plan)
        start = self._ik(plan.p_start, above.q, plan)
        length = float(np.dot(plan.p_end - plan.p_start, plan.direction))
        # IK on waypoints every IK_SPACING along the line; joint-space interpolation between them per tick
        # (the deviation from the straight line is far below the IK tolerance over such short spans).
        n_ik = max(2, int(np.ceil(length / IK_SPACING)) + 1)
        s_ik = np.linspace(0.0, length, n_ik)
        q_ik = np.empty((n_ik, self.kinematics.nq))
        results = [above, start]
        q_prev = start.q
        for k, s in enumerate(s_ik):
            res = self._ik(plan.p_start + s * plan.direction, q_prev, plan)
            results.append(res)
            q_ik[k] = q_prev = res.q
        n = max(2, int(np.ceil(length / (plan.speed * CONTROL_DT))) + 1)
        s_tick = np.linspace(0.0, length, n)
        path = np.column_stack([np.interp(s_tick, s_ik, q_ik[:, j]) for j in range(q_ik.shape[1])])
        return results, path

    def stroke(self, plan: StrokePlan) -> StrokeOutcome:
        """Reach, stroke until contact plus follow-through (or full travel), back off and lift; not the return home."""
        physics = self.physics
        results, path = self.plan_joint_path(plan)
        # The pose above the object is a via point that only has to clear it; the stroke itself must be exact.
        stroke_results = results[1:]
        pos_err = max(r.position_error for r in stroke_results)
        rot_err = max(r.orientation_error for r in stroke_results)
        ik_ok = pos_err <= IK_POSITION_TOLERANCE and rot_err <= IK_ORIENTATION_TOLERANCE
        p_object_before = physics.object_pose()[:3]
        self.move_joints(results[0].q, REACH_TIME)
        self.settle(plan.p_above, tolerance=0.01)
        self.move_joints(results[1].q, DESCEND_TIME)
        start_error = self.settle(plan.p_start)
        object_moved = float(np.linalg.norm(physics.object_pose()[:3] - p_object_before))
        p_hand_start = physics.hand_position()
        contact, contact_time, hand_speed = False, float("nan"), 0.0
        p_contact = p_hand_start
        dt = physics.model.opt.timestep
        stopped = False
        for q_tick in path:
            physics.set_joint_targets(q_tick)
            for _ in range(self.steps_per_tick):
                p_before = physics.hand_position()
                physics.step()
                p_hand = physics.hand_position()
                if not contact and physics.hand_touches_object():
                    contact = True
                    contact_time = float(physics.data.time)
                    hand_speed = float(np.linalg.norm(p_hand - p_before) / dt)
                    p_contact = p_hand
                # The hand stops once the palm itself has travelled the follow-through past the first touch.
                if contact and np.dot(p_hand - p_contact, plan.direction) >= plan.follow_through:
                    physics.set_joint_targets(physics.joint_positions())
                    stopped = True
                    break
            if stopped:
                break
        travel = float(np.dot(physics.hand_position() - p_hand_start, plan.direction))
        # Back off to the pre-stroke pose and lift above the object, so that the way home never crosses it.
        self.move_joints(results[1].q, BACKOFF_TIME)
        self.move_joints(results[0].q, LIFT_TIME)
        return StrokeOutcome(ik_ok, pos_err, rot_err, contact, contact_time, hand_speed, travel, start_error,
                             object_moved)

    def go_home(self, q_home: np.ndarray) -> bool:
        """Return to ``q_home`` (after :meth:`stroke`, from above the object) and hold until the robot is still;
        returns whether it came to rest (:meth:`hold_still`)."""
        self.move_joints(q_home, HOME_TIME)
        return self.hold_still()

    def hold_still(self, max_time: float = HOLD_MAX_TIME) -> bool:
        """Hold the current servo targets until every joint is slower than HOLD_SPEED_TOLERANCE, so that a snapshot
        sees the scene from a still head and with a still hand; at most ``max_time`` [s]. Returns whether the
        robot came to rest."""
        physics = self.physics
        q = physics.joint_targets()
        for _ in range(max(1, round(max_time / CONTROL_DT))):
            if np.max(np.abs(physics.joint_velocities())) <= HOLD_SPEED_TOLERANCE:
                return True
            self._tick(q)
        return False
