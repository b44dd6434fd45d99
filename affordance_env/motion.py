"""Executing behaviours on the simulated robot: joint-space moves, the Cartesian stroke, the grasp, and waiting.

The Cartesian stroke is turned into a joint trajectory by Pinocchio IK (one solve per control tick, warm
started from the previous one) and tracked by MuJoCo's position servos, so the hand's real motion includes
the servo lag and the arm's momentum. The grasp's poses are solved by the same IK and reached by joint-space
ramps; the fingers are driven only by their servos, and only the hand's contacts move the object.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from affordance_env.behaviors import GraspPlan, StrokePlan
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


#: Grasp timing [s]: reach above the object, descend to it, keep squeezing after the closing ramp, lift, carry the
#: object beside and down to the table, open the hand, withdraw above it. Every move follows a smoothstep: the
#: open hand comes down 8 cm in 0.3 s (at most 0.4 m/s), the held object goes up 8 cm in 0.25 s and down and 6 cm
#: aside in 0.3 s, a brisk but unhurried pace for a hand.
GRASP_REACH_TIME, GRASP_DESCEND_TIME, GRASP_SQUEEZE_TIME = 0.3, 0.3, 0.05
GRASP_LIFT_TIME, GRASP_PLACE_TIME, GRASP_OPEN_TIME, GRASP_RETREAT_TIME = 0.25, 0.3, 0.15, 0.15
#: The palm waits at most this long [s] to come within SETTLE_TOLERANCE of the grasp pose before the hand closes:
#: a large object or the table may stop it short (the thumb of the open hand hangs 6.4 cm below the palm).
GRASP_SETTLE_MAX_TIME = 0.1
#: Time to return home after a grasp [s], along a smoothstep.
GRASP_HOME_TIME = 0.4


@dataclass(frozen=True)
class GraspOutcome:
    """What happened during a grasp, measured in the simulation.

    Attributes:
        ik_success: Every pose of the grasp was reached by the IK within tolerance.
        ik_position_error: Largest IK position error over the poses [m].
        ik_orientation_error: Largest IK orientation error over the poses [rad].
        contact: The hand touched the object.
        contact_time: Simulation time of the first touch [s], to the control tick (NaN without contact).
        hand_speed: Palm speed over the control tick of the first touch [m/s] (0 without contact).
        rise: How far the object's centre had risen above its start at the end of the hold [m].
        links_holding: Hand links touching the object at the end of the hold.
        on_table: Whether the object touched the table at the end of the hold.
        release_time: Simulation time when the hand had opened again [s].
    """

    ik_success: bool
    ik_position_error: float
    ik_orientation_error: float
    contact: bool
    contact_time: float
    hand_speed: float
    rise: float
    links_holding: tuple[str, ...]
    on_table: bool
    release_time: float


def _smoothstep(s: float) -> float:
    """3 s^2 - 2 s^3: from 0 to 1 as s goes from 0 to 1, with zero slope at both ends."""
    return s * s * (3.0 - 2.0 * s)


class MotionExecutor:
    """Runs strokes on ``physics`` using ``kinematics`` (both describe the same robot)."""

    def __init__(self, physics: TapPhysics, kinematics: Kinematics) -> None:
        self.physics = physics
        self.kinematics = kinematics
        self.steps_per_tick = max(1, round(CONTROL_DT / physics.model.opt.timestep))

    def _tick(self, q: np.ndarray) -> None:
        self.physics.set_joint_targets(q)
        self.physics.step(self.steps_per_tick)

    def move_joints(self, q_target: np.ndarray, duration: float, smooth: bool = False) -> None:
        """Ramp the servo targets from their current value to ``q_target`` over ``duration`` [s]: linearly, or with
        ``smooth`` along a smoothstep (zero speed at both ends, so the servos end with little lag)."""
        q_from = self.physics.joint_targets()
        n = max(1, round(duration / CONTROL_DT))
        for k in range(1, n + 1):
            self._tick(q_from + (q_target - q_from) * (_smoothstep(k / n) if smooth else k / n))

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
            p, q_init, plan.R_world_hand, position_tolerance=1e-3, orientation_tolerance=IK_ORIENTATION_TOLERANCE
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

    def _tick_watching(self, q: np.ndarray, watch: dict) -> None:
        """One control tick towards ``q``, noting in ``watch`` the first hand-object touch (to the tick) and the
        palm's speed over that tick."""
        physics = self.physics
        physics.set_joint_targets(q)
        if watch["contact"]:
            physics.step(self.steps_per_tick)
            return
        p_before = physics.hand_position()
        physics.step(self.steps_per_tick)
        if physics.hand_touches_object():
            watch.update(contact=True, time=float(physics.data.time),
                         speed=float(np.linalg.norm(physics.hand_position() - p_before) / CONTROL_DT))

    def _ramp(self, q_target: np.ndarray, duration: float, watch: dict) -> None:
        """:meth:`move_joints` with ``smooth`` that watches for the first touch (:meth:`_tick_watching`)."""
        q_from = self.physics.joint_targets()
        n = max(1, round(duration / CONTROL_DT))
        for k in range(1, n + 1):
            self._tick_watching(q_from + (q_target - q_from) * _smoothstep(k / n), watch)

    def grasp(self, plan: GraspPlan) -> GraspOutcome:
        """Reach above the object with the open hand, descend, close the hand on a ramp, lift, hold, carry the
        object beside and down to the table and open the hand; not the return home."""
        physics, kinematics = self.physics, self.kinematics
        joints = kinematics.joint_names

        def with_hand(q: np.ndarray, hand: dict[str, float]) -> np.ndarray:
            q = q.copy()
            for name, value in hand.items():
                q[joints.index(name)] = value
            return q

        def ik(p: np.ndarray, q_init: np.ndarray) -> IKResult:
            return kinematics.solve_ik(p, q_init, plan.R_world_hand, position_tolerance=1e-3,
                                       orientation_tolerance=IK_ORIENTATION_TOLERANCE)

        q_open = with_hand(physics.joint_targets(), plan.hand_open)
        results = [ik(plan.p_above, q_open)]
        for p in (plan.p_grasp, plan.p_lift, plan.p_place, plan.p_retreat):
            results.append(ik(p, results[-1].q))
        pos_err = max(r.position_error for r in results)
        rot_err = max(r.orientation_error for r in results)
        ik_ok = pos_err <= IK_POSITION_TOLERANCE and rot_err <= IK_ORIENTATION_TOLERANCE
        q_above, q_grasp, q_lift, q_place, q_retreat = (r.q for r in results)
        z_start = float(physics.object_pose()[2])
        watch = {"contact": False, "time": float("nan"), "speed": 0.0}
        self._ramp(q_above, GRASP_REACH_TIME, watch)
        self.settle(plan.p_above, tolerance=0.01)
        self._ramp(q_grasp, GRASP_DESCEND_TIME, watch)
        for _ in range(max(1, round(GRASP_SETTLE_MAX_TIME / CONTROL_DT))):
            if np.linalg.norm(physics.hand_position() - plan.p_grasp) <= SETTLE_TOLERANCE:
                break
            self._tick_watching(q_grasp, watch)
        # Close from where the arm stands (short of the grasp pose if something stopped it), the fingers on a ramp.
        q_arm = physics.joint_targets()
        self._ramp(with_hand(q_arm, plan.hand_closed), plan.close_time, watch)
        self._ramp(with_hand(q_arm, plan.hand_closed), GRASP_SQUEEZE_TIME, watch)
        self._ramp(with_hand(q_lift, plan.hand_closed), GRASP_LIFT_TIME, watch)
        self._ramp(with_hand(q_lift, plan.hand_closed), plan.hold_time, watch)
        rise = float(physics.object_pose()[2]) - z_start
        holding = tuple(sorted(physics.links_touching_object()))
        on_table = physics.object_touches_table()
        self._ramp(with_hand(q_place, plan.hand_closed), GRASP_PLACE_TIME, watch)
        self._ramp(with_hand(q_place, plan.hand_open), GRASP_OPEN_TIME, watch)
        release_time = float(physics.data.time)
        self._ramp(with_hand(q_retreat, plan.hand_open), GRASP_RETREAT_TIME, watch)
        return GraspOutcome(ik_ok, pos_err, rot_err, watch["contact"], watch["time"], watch["speed"], rise,
                            holding, on_table, release_time)

    def go_home(self, q_home: np.ndarray, duration: float = HOME_TIME, smooth: bool = False) -> bool:
        """Return to ``q_home`` (after :meth:`stroke` or :meth:`grasp`, from above the object) in ``duration`` [s]
        (:meth:`move_joints`) and hold until the robot is still; returns whether it came to rest
        (:meth:`hold_still`)."""
        self.move_joints(q_home, duration, smooth)
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
