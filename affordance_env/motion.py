"""Executing behaviours on the simulated robot: joint-space moves, the Cartesian stroke, the grasp, and waiting.

The Cartesian stroke is turned into a joint trajectory by Pinocchio IK (one solve per control tick, warm
started from the previous one) and tracked by MuJoCo's position servos, so the hand's real motion includes
the servo lag and the arm's momentum. The grasp's poses are solved by the same IK and reached by joint-space
ramps; the fingers are driven only by their servos, and only the hand's contacts move the object.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from affordance_env.behaviors import GraspPlan, StrokePlan
from affordance_env.kinematics import IKResult, Kinematics
from affordance_env.physics import TapPhysics

#: Period of the servo set-point updates [s].
CONTROL_DT = 0.01
#: Peak joint speed of a move [rad/s]: 100 deg/s, the velocity limit of the iCub's arm, torso and head joints
#: in its motor interface (the harmonic-drive joints are specified for more; the controllers cap them there).
JOINT_SPEED_LIMIT = np.radians(100.0)
#: Shortest move [s]: three control ticks, so that even a tiny correction is a smooth profile.
MIN_MOVE_TIME = 0.03
#: Minimum-jerk profile 10 t^3 - 15 t^4 + 6 t^5: its peak speed is PEAK_SPEED_FACTOR times the mean speed.
PEAK_SPEED_FACTOR = 1.875
#: Share of the shorter of two consecutive segments of a move through via points during which both run.
VIA_BLEND = 0.5
#: Duration of the way home from above the object [s]; None: as fast as JOINT_SPEED_LIMIT allows, blended with
#: the way up from the stroke.
HOME_TIME: float | None = None
#: The hand must be this close to the pre-stroke pose before the stroke starts [m], waiting at most
#: SETTLE_MAX_TIME [s] for the servos.
SETTLE_TOLERANCE, SETTLE_MAX_TIME = 0.003, 0.4
#: The robot is still when every joint is slower than HOLD_SPEED_TOLERANCE [rad/s]; it is given at most
#: HOLD_MAX_TIME [s] to get there. The servos are critically damped, so a free joint is that slow only within
#: about 1 mrad of its target; an arm blocked short of its target (resting on an object that rolled under it)
#: is still all the same.
HOLD_SPEED_TOLERANCE, HOLD_MAX_TIME = 0.01, 1.0
#: Consecutive control ticks at which the robot must be that slow to count as still.
HOLD_STILL_TICKS = 2
#: Before the first touch, the stroke checks for contact at every physics step only while the hand is within this
#: distance of the object [m]; farther away it cannot touch it before the tick ends. To cover it in the 6 steps
#: from the kinematics it is measured on (one step old) to the tick's end, hand and object would have to close
#: at 1.25 m/s, over twice the fastest stroke (0.54 m/s), while the object rests.
CONTACT_WATCH_DISTANCE = 0.015
#: Timestep [s] of a tap interaction outside its stroke: while the head turns to the object, the arm reaches the
#: pre-stroke pose, returns home, and the object rolls and comes to rest. The stroke, from its start to the end of
#: its follow-through, keeps the tap scene's 2 ms, which resolves the impact (the palm moves at most 1.1 mm a step).
#: Elsewhere the fastest dynamics are the contacts' (MuJoCo's default time constant, 20 ms) and the arm servos'
#: (25 ms and more), 4 steps or more at 5 ms where MuJoCo needs 2; the grasp variant steps at 5 ms too
#: (``scene.GRASP_TIMESTEP``). A resting object creeps no more at 5 ms than at 2 (a few micrometres in 2 s).
#: Over 300 interactions (tap, tap_back and push, half canonical, half at random actions: ``python
#: benchmarks/timestep.py --episodes 100``) the object ends a median 0.35 mm (90 % within 1.6 mm) from where it
#: ends at 2 ms throughout, 0.3 % of the travel of those that rolled over 5 cm; at 1 ms outside the stroke it ends
#: 0.16 mm (1.2 mm) from there, so 2 ms is no nearer to converged than that. 3 labels of the 300 differ, each at
#: a threshold: two pushes that moved 30 mm give or take 1.4 mm against the 3 cm of their success rule, and a
#: ball that rolled 47 cm to the table's edge went over it. A canonical tap takes 469 steps instead of 913.
FREE_TIMESTEP = 0.005
#: Spacing of the IK solutions along the stroke line [m]. Between two solutions the targets are interpolated in
#: joint space; over 2 cm the palm then stays within 1.0 mm of the line (measured over 30 canonical strokes), as
#: it does over 1 cm: what remains is the IK's own tolerance (1 mm), not the interpolation.
IK_SPACING = 0.02
#: IK tolerances for the stroke waypoints: position [m] and orientation [rad].
IK_POSITION_TOLERANCE, IK_ORIENTATION_TOLERANCE = 0.005, 0.35


@dataclass(frozen=True)
class ReachOutcome:
    """What every behaviour reports of its reach and its first touch.

    Attributes:
        ik_success: Every pose the hand was sent to was reached by the IK within tolerance.
        ik_position_error: Largest IK position error over those poses [m].
        ik_orientation_error: Largest IK orientation error over those poses [rad].
        contact: The hand touched the object.
        contact_time: Simulation time of the first touch [s] (NaN without contact).
        hand_speed: Hand speed at first touch [m/s] (0 without contact).
    """

    ik_success: bool
    ik_position_error: float
    ik_orientation_error: float
    contact: bool
    contact_time: float
    hand_speed: float


@dataclass(frozen=True)
class StrokeOutcome(ReachOutcome):
    """What happened during a stroke (:class:`ReachOutcome` over the pre-stroke pose and the stroke line; the
    first touch to the physics step).

    Attributes:
        hand_travel: Distance the palm travelled along the stroke direction [m].
        start_error: Distance of the palm from the pre-stroke pose when the stroke started [m].
        object_moved: How far the object moved before the stroke started (touched during the reach) [m].
        q_withdraw: Joint targets of the pose above the pre-stroke pose, which the way home passes through so that
            it never crosses the object; None if the plan has no such pose.
    """

    hand_travel: float
    start_error: float
    object_moved: float
    q_withdraw: np.ndarray | None


#: Grasp timing [s]: reach above the object, descend to it, keep squeezing after the closing ramp, lift, carry the
#: object beside and down to the table, open the hand, withdraw above it. Every move follows a smoothstep: the
#: open hand comes down 8 cm in 0.3 s (at most 0.4 m/s), the held object goes up 8 cm in 0.25 s and down and 6 cm
#: aside in 0.3 s, a brisk but unhurried pace for a hand. The moves of the open hand to above the object and down
#: to it lead their servos by the damping lag (velocity feedforward), so the palm keeps up with them (it ends the
#: reach within about 1 cm of its goal, not 2-3 cm behind it) and the hand closes as the descent ends: at the grasp
#: pose, or short of it where the object or the table stopped the hand. Without the lead, the palm waited 0.07 s
#: above the object and, mostly stopped short, 0.1 s before closing.
GRASP_REACH_TIME, GRASP_DESCEND_TIME, GRASP_SQUEEZE_TIME = 0.3, 0.3, 0.05
GRASP_LIFT_TIME, GRASP_PLACE_TIME, GRASP_OPEN_TIME, GRASP_RETREAT_TIME = 0.25, 0.3, 0.15, 0.15
#: Timestep [s] of the simulation while the hand carries what it has grasped: the lift, the 1 s hold and the carry
#: down to the table (the grasp scene's is 5 ms, ``scene.GRASP_TIMESTEP``). The fingers have closed and squeezed,
#: and hand and object move as one, slowly (8 cm in 0.25-0.3 s) or not at all: what can still happen, the object
#: sagging or slipping in the grip or meeting the table as it is put down, is no faster than the contacts' 20 ms
#: time constant and the arm servos' 25 ms, which 10 ms steps resolve at MuJoCo's stable minimum of two steps.
#: (MuJoCo then integrates the finger coupling's 10 ms as 20 ms: the distal joints stay within 1.6 degrees of the
#: linkage, 0.3 degree at 5 ms.) The rest of the grasp, where contacts form and break (the fingers closing on the
#: object, opening from it) and the arm moves freely, stays at 5 ms: at 10 ms throughout, two of the 90 canonical
#: grasps of ``benchmarks/grasp.py`` end differently, one of them a 4.3 cm lying cylinder no longer held. With the
#: carry alone at 10 ms, every one of those 90 grasps and of 60 at random actions is held or not as at 5 ms, its
#: object risen to within 0.1 mm of the same height (95 % of them), a held one put down 2 mm (median) from where it
#: was at 5 ms; the carry takes half the steps, a grasp 667 instead of 820.
GRASP_CARRY_TIMESTEP = 0.01


@dataclass(frozen=True)
class GraspOutcome(ReachOutcome):
    """What happened during a grasp, measured in the simulation (:class:`ReachOutcome` over every pose of the
    grasp; the first touch to the control tick).

    Attributes:
        rise: How far the object's centre had risen above its start at the end of the hold [m].
        links_holding: Hand links touching the object at the end of the hold.
        on_table: Whether the object touched the table at the end of the hold.
        release_time: Simulation time when the hand had opened again [s].
    """

    rise: float
    links_holding: tuple[str, ...]
    on_table: bool
    release_time: float


def _ik_verdict(results: list[IKResult]) -> tuple[bool, float, float]:
    """(all within IK_POSITION_TOLERANCE and IK_ORIENTATION_TOLERANCE, largest position error [m], largest
    orientation error [rad]) over IK results."""
    pos_err = max(r.position_error for r in results)
    rot_err = max(r.orientation_error for r in results)
    return pos_err <= IK_POSITION_TOLERANCE and rot_err <= IK_ORIENTATION_TOLERANCE, pos_err, rot_err


class MotionExecutor:
    """Runs strokes on ``physics`` using ``kinematics`` (both describe the same robot)."""

    def __init__(self, physics: TapPhysics, kinematics: Kinematics) -> None:
        self.physics = physics
        self.kinematics = kinematics
        self._opt = physics.model.opt  # MuJoCo's options, read at every tick: the wrapper is made once
        self._tick_timestep, self._steps_per_tick = 0.0, 1  # the last timestep seen, and its steps per tick
        #: Timestep [s] of a tap interaction outside its stroke (FREE_TIMESTEP); the scene's own (2 ms) steps the
        #: whole interaction as finely as the stroke (``benchmarks/timestep.py`` compares the two).
        self.free_timestep = FREE_TIMESTEP
        #: Where the IK of every pre-stroke pose starts (see :meth:`set_approach_posture`); None: the current
        #: servo targets.
        self.approach_posture: np.ndarray | None = None

    def set_approach_posture(self, plan: StrokePlan) -> IKResult:
        """Start the IK of every later pre-stroke pose from the arm posture that reaches ``plan``'s (solved now,
        from the current servo targets), instead of from wherever the arm is.

        The posture does not depend on the interactions run before, so neither do the data; from it a pre-stroke
        pose anywhere in the placement region is 3-8 IK iterations away instead of 11-23 from home. The postures
        found differ from those found from home only in how the redundant arm holds the same palm pose (by a few
        degrees per joint).
        """
        result = self._ik(plan.p_start, self.physics.joint_targets(), plan)
        self.approach_posture = result.q
        return result

    @property
    def steps_per_tick(self) -> int:
        """Physics steps per control tick at the model's current timestep."""
        timestep = self._opt.timestep
        if timestep != self._tick_timestep:  # asked at every tick: divided only when the timestep changes
            self._tick_timestep, self._steps_per_tick = timestep, max(1, round(CONTROL_DT / timestep))
        return self._steps_per_tick

    def _tick(self, q: np.ndarray) -> None:
        self.physics.set_joint_targets(q)
        self.physics.step(self.steps_per_tick)

    def move_joints(self, q_target: np.ndarray, duration: float | None = None) -> None:
        """Move the servo targets from their current value to ``q_target`` along a minimum-jerk profile.

        The profile starts and ends at rest, and the targets lead it by each servo's damping lag (velocity
        feedforward), so the joints follow it instead of lagging behind. ``duration`` [s] defaults to the shortest
        one in which no joint exceeds JOINT_SPEED_LIMIT (and at least MIN_MOVE_TIME).
        """
        self.move_through([q_target], duration)

    def move_through(self, waypoints: list[np.ndarray], duration: float | None = None,
                     blend: float = VIA_BLEND) -> None:
        """Move through ``waypoints`` (joint targets) to the last one, without stopping at the ones before.

        One minimum-jerk segment per waypoint; each starts ``blend`` of the shorter segment's duration before the
        previous one ends, so the joints pass near the via points at speed rather than stopping there. The
        segments are stretched so that no joint exceeds JOINT_SPEED_LIMIT; ``duration`` [s] sets the total
        instead (each segment its share of it).
        """
        q_from = self.physics.joint_targets()
        deltas = np.diff(np.vstack([q_from, *waypoints]), axis=0)
        lengths = np.maximum(MIN_MOVE_TIME, PEAK_SPEED_FACTOR * np.max(np.abs(deltas), axis=1) / JOINT_SPEED_LIMIT)
        starts = np.zeros(len(deltas))
        for k in range(1, len(deltas)):
            starts[k] = starts[k - 1] + lengths[k - 1] - blend * min(lengths[k - 1], lengths[k])
        end = float(np.max(starts + lengths))

        def profile(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            """Joint targets and velocities at times ``t`` [s] (a column) of the unstretched profile."""
            tau = np.clip((t - starts) / lengths, 0.0, 1.0)  # (ticks, segments)
            position = tau ** 3 * (10.0 + tau * (6.0 * tau - 15.0))
            rate = 30.0 * tau ** 2 * (1.0 + tau * (tau - 2.0)) / lengths
            acceleration = 60.0 * tau * (1.0 + tau * (2.0 * tau - 3.0)) / lengths ** 2
            return q_from + position @ deltas, rate @ deltas, acceleration @ deltas

        n = max(1, round(end / CONTROL_DT))
        t = (np.arange(1, n + 1) * (end / n))[:, None]
        q, qd, qdd = profile(t)
        stretch = max(1.0, float(np.max(np.abs(qd))) / JOINT_SPEED_LIMIT)  # blended segments may add up
        if duration is not None:
            stretch = duration / end
        if stretch != 1.0:
            n = max(1, round(stretch * end / CONTROL_DT))
            q, qd, qdd = profile((np.arange(1, n + 1) * (end / n))[:, None])
            qd /= stretch
            qdd /= stretch ** 2
        step_toward, n_steps = self.physics.step_toward, self.steps_per_tick
        led = q + self.physics.servo_lead * qd  # the velocity feedforward of every tick at once
        for q_tick, qdd_tick in zip(led, qdd, strict=True):
            step_toward(q_tick, qdd_tick, n_steps)  # and the inertial feedforward of the tick's configuration

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

    def _ik(self, p: np.ndarray, q_init: np.ndarray, plan: StrokePlan | GraspPlan) -> IKResult:
        """IK of a palm position with the plan's hand orientation (and joint ranges, if it has any)."""
        return self.kinematics.solve_ik(
            p, q_init, plan.R_world_hand, position_tolerance=1e-3, orientation_tolerance=IK_ORIENTATION_TOLERANCE,
            joint_ranges=getattr(plan, "joint_ranges", None),
        )

    def plan_approach(self, plan: StrokePlan) -> tuple[IKResult | None, IKResult]:
        """IK of the pose above the pre-stroke pose (None if the plan has none) and of the pre-stroke pose."""
        # The pre-stroke pose first, the pose above it from there: the two differ by a short vertical move, so
        # the descent (and the way up after the stroke) is a small joint motion, not a change of arm posture.
        q_init = self.physics.joint_targets()  # the neck and the fingers keep their targets
        if self.approach_posture is not None:
            reach = self.kinematics.reach_dofs
            q_init[reach] = self.approach_posture[reach]
        start = self._ik(plan.p_start, q_init, plan)
        above = None if plan.p_above is None else self._ik(plan.p_above, start.q, plan)
        return above, start

    def stroke(self, plan: StrokePlan) -> StrokeOutcome:
        """Reach, and stroke until contact plus follow-through (or full travel); then :meth:`go_home`."""
        physics = self.physics
        above, start = self.plan_approach(plan)
        line = StrokeLine(self, plan, start.q)
        p_object_before = physics.object_pose()[:3]
        with self.stepping(self.free_timestep):  # the object rests and the hand moves in free space
            self.move_through([start.q] if above is None else [above.q, start.q])  # through the pose above, if any
            start_error = self.settle(plan.p_start)
        object_moved = float(np.linalg.norm(physics.object_pose()[:3] - p_object_before))
        p_hand_start = physics.hand_position()
        contact, contact_time, hand_speed = False, float("nan"), 0.0
        p_contact = p_hand_start
        dt = physics.model.opt.timestep
        stopped = False
        palm = physics.data.site_xpos[physics.palm_site]  # a view: the palm position after each step
        steps_per_tick = self.steps_per_tick  # the timestep does not change during the stroke
        for i in range(len(line)):
            physics.set_joint_targets(line.target(i))
            if not contact and physics.hand_object_distance(CONTACT_WATCH_DISTANCE) >= CONTACT_WATCH_DISTANCE:
                physics.step(steps_per_tick)  # the same steps, without a check after each
                continue
            for _ in range(steps_per_tick):
                if not contact:
                    p_before = palm.copy()
                    physics.step()
                    if physics.hand_touches_object():
                        contact = True
                        contact_time = float(physics.data.time)
                        hand_speed = float(np.linalg.norm(palm - p_before) / dt)
                        p_contact = palm.copy()
                else:
                    physics.step()
                # The hand stops once the palm itself has travelled the follow-through past the first touch.
                if contact and np.dot(palm - p_contact, plan.direction) >= plan.follow_through:
                    physics.set_joint_targets(physics.joint_positions())
                    stopped = True
                    break
            if stopped:
                break
        travel = float(np.dot(physics.hand_position() - p_hand_start, plan.direction))
        # The pose above the object is a via point that only has to clear it; the stroke itself must be exact.
        return StrokeOutcome(*_ik_verdict([start, *line.results]), contact, contact_time, hand_speed, travel,
                             start_error, object_moved, None if above is None else above.q)

    def _tick_watching(self, q: np.ndarray | None, watch: dict) -> None:
        """One control tick towards ``q`` (None: keep the current targets), noting in ``watch`` the first
        hand-object touch (to the tick) and the palm's speed over that tick."""
        physics = self.physics
        if q is not None:
            physics.set_joint_targets(q)
        if watch["contact"]:  # known: nothing more to look for
            physics.step(self.steps_per_tick)
            return
        p_before = physics.hand_position()
        physics.step(self.steps_per_tick)
        if physics.hand_touches_object():
            watch.update(contact=True, time=float(physics.data.time),
                         speed=float(np.linalg.norm(physics.hand_position() - p_before) / CONTROL_DT))

    def _ramp(self, q_target: np.ndarray, duration: float, watch: dict, lead: bool = False) -> None:
        """Ramp the targets to ``q_target`` over ``duration`` [s] along a smoothstep (zero speed at both ends),
        watching for the first touch (:meth:`_tick_watching`). ``lead``: the targets lead the ramp by each servo's
        damping lag (velocity feedforward, as in :meth:`move_through`), so that the joints follow the ramp instead of
        lagging behind it and arrive when it ends; for moves through free space."""
        physics = self.physics
        q_from = physics.joint_targets()
        n = max(1, round(duration / CONTROL_DT))
        s = np.arange(1, n + 1) / n
        delta = q_target - q_from
        targets = q_from + np.outer(s * s * (3.0 - 2.0 * s), delta)  # every tick's smoothstep at once
        if lead:  # the smoothstep's rate, 6 s (1 - s) / duration, times the lead
            targets += np.outer(6.0 * s * (1.0 - s) / (n * CONTROL_DT), physics.servo_lead * delta)
        for q in targets:
            self._tick_watching(q, watch)

    def _hold(self, duration: float, watch: dict) -> None:
        """Keep the current targets for ``duration`` [s], watching for the first touch (:meth:`_tick_watching`)."""
        for _ in range(max(1, round(duration / CONTROL_DT))):
            self._tick_watching(None, watch)

    @contextmanager
    def stepping(self, timestep: float) -> Iterator[None]:
        """Simulate at ``timestep`` [s], a divisor of CONTROL_DT, inside the block; at the model's own after it."""
        steps = round(CONTROL_DT / timestep)
        if not (timestep > 0 and abs(steps * timestep - CONTROL_DT) < 1e-12):
            raise ValueError(f"timestep must divide the control period {CONTROL_DT} s, got {timestep!r}.")
        opt = self.physics.model.opt
        saved, opt.timestep = opt.timestep, timestep
        try:
            yield
        finally:
            opt.timestep = saved

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

        q_open = with_hand(physics.joint_targets(), plan.hand_open)
        results = [self._ik(plan.p_above, q_open, plan)]
        for p in (plan.p_grasp, plan.p_lift, plan.p_place, plan.p_retreat):
            results.append(self._ik(p, results[-1].q, plan))
        q_above, q_grasp, q_lift, q_place, q_retreat = (r.q for r in results)
        z_start = float(physics.object_pose()[2])
        watch = {"contact": False, "time": float("nan"), "speed": 0.0}
        self._ramp(q_above, GRASP_REACH_TIME, watch, lead=True)
        self.settle(plan.p_above, tolerance=0.01)
        self._ramp(q_grasp, GRASP_DESCEND_TIME, watch, lead=True)
        # Close as the descent ends, the fingers on a ramp: the palm is at the grasp pose, or short of it where the
        # object or the table stopped the hand (the open hand's thumb hangs 6.4 cm below the palm).
        q_arm = physics.joint_targets()
        self._ramp(with_hand(q_arm, plan.hand_closed), plan.close_time, watch)
        self._hold(GRASP_SQUEEZE_TIME, watch)
        with self.stepping(GRASP_CARRY_TIMESTEP):  # the hand carries what it holds: up, still, down
            self._ramp(with_hand(q_lift, plan.hand_closed), GRASP_LIFT_TIME, watch)
            self._hold(plan.hold_time, watch)
            rise = float(physics.object_pose()[2]) - z_start
            holding = tuple(sorted(physics.links_touching_object()))
            on_table = physics.object_touches_table()
            self._ramp(with_hand(q_place, plan.hand_closed), GRASP_PLACE_TIME, watch)
        self._ramp(with_hand(q_place, plan.hand_open), GRASP_OPEN_TIME, watch)
        release_time = float(physics.data.time)
        self._ramp(with_hand(q_retreat, plan.hand_open), GRASP_RETREAT_TIME, watch)
        return GraspOutcome(*_ik_verdict(results), watch["contact"], watch["time"], watch["speed"], rise, holding,
                            on_table, release_time)

    def go_home(self, q_home: np.ndarray, via: np.ndarray | None = None) -> bool:
        """Return to ``q_home`` through ``via`` (after :meth:`stroke`: up and back above the pre-stroke pose) and
        hold until the robot is still; returns whether it came to rest (:meth:`hold_still`)."""
        if via is None:
            self.move_joints(q_home, HOME_TIME)
        elif HOME_TIME is None:
            self.move_through([via, q_home])
        else:  # a set pace for the way home: up to ``via`` at full speed, then home in HOME_TIME
            self.move_joints(via)
            self.move_joints(q_home, HOME_TIME)
        return self.hold_still()

    def hold_still(self, max_time: float = HOLD_MAX_TIME,
                   also: Callable[[TapPhysics], bool] | None = None) -> bool:
        """Hold the current servo targets until the robot is still, so that a snapshot sees the scene from a still
        head and with a still hand: every joint slower than HOLD_SPEED_TOLERANCE at HOLD_STILL_TICKS consecutive
        control ticks (one slow sample could be the turning point of an oscillation); at most ``max_time`` [s].
        ``also(physics)``, if given, must hold too (for instance: the object is at rest). Returns whether the robot
        came to rest."""
        physics = self.physics
        q = physics.joint_targets()
        still_ticks = 0
        for tick in range(max(1, round(max_time / CONTROL_DT)) + 1):
            slow = np.max(np.abs(physics.joint_velocities())) <= HOLD_SPEED_TOLERANCE
            still_ticks = still_ticks + 1 if slow else 0
            if still_ticks >= HOLD_STILL_TICKS and (also is None or also(physics)):
                return True
            if tick * CONTROL_DT >= max_time - 1e-9:
                break
            self._tick(q)
        return still_ticks >= HOLD_STILL_TICKS


class StrokeLine:
    """The stroke's joint path: the straight stroke line at the plan's speed, one target per control tick.

    IK waypoints every IK_SPACING along the line, each warm started from the one before, are solved only when the
    hand gets there (the stroke usually stops a follow-through after contact, well before the line's end);
    between them the targets are interpolated in joint space (the deviation from the straight line is far below
    the IK tolerance over such short spans).
    """

    def __init__(self, executor: MotionExecutor, plan: StrokePlan, q_start: np.ndarray) -> None:
        self._executor, self._plan = executor, plan
        length = float(np.dot(plan.p_end - plan.p_start, plan.direction))
        self._s_ik = np.linspace(0.0, length, max(2, int(np.ceil(length / IK_SPACING)) + 1))
        self._s_tick = np.linspace(0.0, length, max(2, int(np.ceil(length / (plan.speed * CONTROL_DT))) + 1))
        self._q_ik: list[np.ndarray] = []
        self._q_start = q_start
        #: IK results of the waypoints solved so far, in order along the line.
        self.results: list[IKResult] = []

    def __len__(self) -> int:
        return len(self._s_tick)

    def _waypoint(self, k: int) -> np.ndarray:
        while len(self._q_ik) <= k:
            plan = self._plan
            # warm start: the last solution, extrapolated one spacing along the line
            q_init = (self._q_start if not self._q_ik else self._q_ik[-1] if len(self._q_ik) < 2
                      else 2.0 * self._q_ik[-1] - self._q_ik[-2])
            result = self._executor._ik(plan.p_start + self._s_ik[len(self._q_ik)] * plan.direction, q_init, plan)
            self.results.append(result)
            self._q_ik.append(result.q)
        return self._q_ik[k]

    def target(self, i: int) -> np.ndarray:
        """Joint targets of tick ``i``."""
        s = self._s_tick[i]
        k = min(int(np.searchsorted(self._s_ik, s)), len(self._s_ik) - 1)
        if k == 0:
            return self._waypoint(0)
        w = (s - self._s_ik[k - 1]) / (self._s_ik[k] - self._s_ik[k - 1])
        q0 = self._waypoint(k - 1)
        return q0 + w * (self._waypoint(k) - q0)
