"""Executing behaviours on the simulated robot: every move is a trajectory followed by the position servos.

Every move, the reach, the stroke, the grasp's descent, closing, lift, carry, put-down and opening, the retreat
and the way home, is a trajectory of :mod:`affordance_env.trajectory` planned within the joints' velocity limits
(:mod:`affordance_env.motor_limits`), and :meth:`MotionExecutor.follow` is the one servo loop that plays it: at
every control tick the servo targets lead the trajectory by each servo's damping lag (velocity feedforward) plus
the offset whose spring torque gives the trajectory's acceleration (inertial feedforward), so the joints follow
it instead of lagging behind. Straight moves of the palm (the stroke, the grasp's descents, lift and retreat) are
Cartesian lines turned into joint trajectories by Pinocchio IK; their speed is lowered where a joint would
exceed its limit. The motors' torques are limited in the simulation itself (:mod:`affordance_env.scene`), so what
the hand does to an object is bounded by what its motors give.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from affordance_env.exceptions import InvalidValueError
from affordance_env.kinematics import IKResult, Kinematics
from affordance_env.linalg import dot, norm
from affordance_env.motor_limits import velocity_limits
from affordance_env.outcome import REST_ANGULAR_SPEED, REST_SPEED
from affordance_env.physics import TapPhysics
from affordance_env.trajectory import JointTrajectory, line_profile, minimum_jerk

#: Period of the servo set-point updates [s].
CONTROL_DT = 0.01
#: Moves are planned for this share of the joints' velocity limits: the servos follow a plan to within a few per
#: cent, and overshoot it by up to 5 % where a move starts, stops or meets contact (``benchmarks/physics_audit.py``).
PLANNED_SPEED_SHARE = 0.95
#: Shortest move [s]: three control ticks, so that even a tiny correction is a smooth profile.
MIN_MOVE_TIME = 0.03
#: The hand must be this close to the pre-stroke pose before the stroke starts [m], waiting at most
#: SETTLE_MAX_TIME [s] for the servos.
SETTLE_TOLERANCE, SETTLE_MAX_TIME = 0.003, 0.4
#: The robot is still when every joint is slower than HOLD_SPEED_TOLERANCE [rad/s]; it is given at most
#: HOLD_MAX_TIME [s] to get there. The servos are critically damped, so a free joint is that slow only within
#: about 1 mrad of its target; an arm blocked short of its target (resting on an object) is still all the same.
HOLD_SPEED_TOLERANCE, HOLD_MAX_TIME = 0.01, 1.0
#: Consecutive control ticks at which the robot must be that slow to count as still.
HOLD_STILL_TICKS = 2
#: Before the first touch, a line checks for contact at every physics step only while the hand is within this
#: distance of the object [m]; farther away it cannot touch it before the tick ends. To cover it in the 6 steps
#: from the kinematics it is measured on (one step old) to the tick's end, hand and object would have to close
#: at 1.25 m/s, over twice the fastest stroke, while the object rests.
CONTACT_WATCH_DISTANCE = 0.015
#: Timestep [s] of a tap interaction outside its stroke: while the head turns to the object, the arm reaches the
#: pre-stroke pose, returns home, and the object rolls and comes to rest. The stroke, from its start to the end of
#: its follow-through, keeps the tap scene's 2 ms, which resolves the impact (the palm moves at most 1 mm a step).
#: Elsewhere the fastest dynamics are the contacts' (10 ms, ``scene.CONTACT_SOLREF``) and the arm servos' (25 ms
#: and more), 2 steps or more at 5 ms, MuJoCo's stable minimum; the grasp variant steps at 5 ms too
#: (``scene.GRASP_TIMESTEP``). ``python benchmarks/timestep.py`` compares it with 2 ms throughout.
FREE_TIMESTEP = 0.005
#: Spacing of the IK solutions along a line of the palm [m]. Between two solutions the targets are interpolated in
#: joint space; over 2 cm the palm then stays within 1.0 mm of the line, the IK's own tolerance.
IK_SPACING = 0.02
#: IK tolerances for the poses of a behaviour: position [m] and orientation [rad].
IK_POSITION_TOLERANCE, IK_ORIENTATION_TOLERANCE = 0.005, 0.35
#: A line of the palm starting from rest reaches its speed, and one ending at rest leaves it, in this time [s].
LINE_RAMP = 0.1
#: Way home: the arm that comes within HOME_CLEARANCE [m] of the object stops and waits for the object to
#: come to rest (at most HOME_WAIT [s]), then goes home through a pose HOME_RAISE [m] higher above it.
HOME_CLEARANCE, HOME_WAIT, HOME_RAISE = 0.015, 3.0, 0.06


@dataclass(frozen=True)
class ReachOutcome:
    """What every behaviour reports of its reach and its first touch.

    Attributes:
        ik_success: Every pose the hand was sent to was reached by the IK within tolerance.
        ik_position_error: Largest IK position error over those poses [m].
        ik_orientation_error: Largest IK orientation error over those poses [rad].
        contact: The hand touched the object.
        contact_time: Simulation time of the first touch [s] (NaN without contact).
        hand_speed: Palm speed at first touch [m/s] (0 without contact).
    """

    ik_success: bool
    ik_position_error: float
    ik_orientation_error: float
    contact: bool
    contact_time: float
    hand_speed: float


@dataclass(frozen=True)
class HomeOutcome:
    """How the way home went.

    Attributes:
        still: The robot came to rest at home.
        touched: The arm touched the object after it had been clear of it.
        waited: The arm stopped short of the object and waited for it to come to rest.
    """

    still: bool
    touched: bool
    waited: bool


@dataclass(frozen=True)
class LineResult:
    """What happened along a line of the palm (:meth:`MotionExecutor.follow_line`).

    Attributes:
        touched: The watched touch happened.
        time: Simulation time of that touch [s] (NaN without).
        speed: Palm speed at that touch [m/s] (0 without).
        p_touch: Palm position at that touch [m] (the position at the start without).
    """

    touched: bool
    time: float
    speed: float
    p_touch: np.ndarray


def ik_verdict(results: list[IKResult]) -> tuple[bool, float, float]:
    """(all within IK_POSITION_TOLERANCE and IK_ORIENTATION_TOLERANCE, largest position error [m], largest
    orientation error [rad]) over IK results."""
    pos_err = max(r.position_error for r in results)
    rot_err = max(r.orientation_error for r in results)
    return pos_err <= IK_POSITION_TOLERANCE and rot_err <= IK_ORIENTATION_TOLERANCE, pos_err, rot_err


@dataclass(frozen=True)
class HandTarget:
    """How the inverse kinematics holds the hand on a move, whatever the behaviour: the palm's orientation and the
    joint ranges the solution keeps to.

    Attributes:
        R_world_hand: Palm orientation in the world frame (3x3 rotation matrix).
        joint_ranges: Narrower ranges for some joints, ``{name: (low, high)}`` [rad]; None: the joints' own,
            narrowed by the robot variant's ``ik_ranges``.
    """

    R_world_hand: np.ndarray
    joint_ranges: Mapping[str, tuple[float, float]] | None = None


class LinePath:
    """A straight line of the palm as joint targets, one per control tick, along a speed profile.

    IK waypoints every IK_SPACING along the line, each warm started from the one before, are solved when the hand
    gets there (a stroke usually stops a follow-through after contact, well before the line's end); between them
    the targets are interpolated in joint space. The cruise speed is lowered to what the joints' velocity limits
    allow over the first ``check_waypoints`` spans.

    Args:
        executor: Solves the IK.
        p_start: Start of the palm [m], (3,).
        direction: Unit direction of the line, (3,).
        length: Length [m].
        hand: Palm orientation along the line and the joint ranges the IK keeps to.
        speed: Cruise speed [m/s].
        q_start: Joint targets at the start.
        ramp: Time to reach the speed from rest [s].
        to_rest: The line ends at rest (else at speed).
        check_waypoints: Spans whose joint speeds cap the cruise speed; None: all of them (solved now).
        check: Only whether every waypoint is reached matters (a feasibility check): see :meth:`MotionExecutor.ik`.
    """

    def __init__(self, executor: MotionExecutor, p_start: np.ndarray, direction: np.ndarray, length: float,
                 hand: HandTarget, speed: float, q_start: np.ndarray, *, ramp: float = LINE_RAMP,
                 to_rest: bool = True, check_waypoints: int | None = None, check: bool = False) -> None:
        self._executor, self._hand, self._check = executor, hand, check
        self.p_start, self.direction = np.asarray(p_start, dtype=float), np.asarray(direction, dtype=float)
        self._s_ik = np.linspace(0.0, length, max(2, int(np.ceil(length / IK_SPACING - 1e-9)) + 1))
        self._q_ik: list[np.ndarray] = [np.asarray(q_start, dtype=float)]
        #: IK results of the waypoints solved so far, in order along the line (the start is given).
        self.results: list[IKResult] = []
        spans = len(self._s_ik) - 1 if check_waypoints is None else min(check_waypoints, len(self._s_ik) - 1)
        self._waypoint(spans)  # solves the waypoints up to the last checked one, in order
        q_ik = np.array(self._q_ik[: spans + 1])
        # Joint rates per metre of the palm [rad/m] over each span, all spans at once (elementwise, the same
        # numbers as span by span; the smallest of the spans' minima is the minimum over all of them).
        rates = np.abs(q_ik[1:] - q_ik[:-1]) / (self._s_ik[1 : spans + 1] - self._s_ik[:spans])[:, None]
        cap = float(np.minimum.reduce(executor.planned_speed / np.maximum(rates, 1e-12), axis=None))  # np.min
        #: Cruise speed of the palm [m/s]: the one asked for, or the most the joints allow.
        self.speed = min(float(speed), cap)
        profile = line_profile(length, self.speed, CONTROL_DT, ramp=ramp, to_rest=to_rest)
        self._s, self._v = profile[:, 0], profile[:, 1]
        # the palm's acceleration along the line [m/s^2]: np.diff(v, prepend=0.0), its subtraction written out
        v0 = np.concatenate(((0.0,), self._v))
        self._a = (v0[1:] - v0[:-1]) / CONTROL_DT
        self._trajectory: JointTrajectory | None = None

    def __len__(self) -> int:
        return len(self._s)

    def _waypoint(self, k: int) -> np.ndarray:
        while len(self._q_ik) <= k:
            n = len(self._q_ik)
            q_init = self._q_ik[-1] if n < 2 else 2.0 * self._q_ik[-1] - self._q_ik[-2]  # extrapolated one spacing
            result = self._executor.ik(self.p_start + self._s_ik[n] * self.direction, q_init, self._hand,
                                       check=self._check)
            self.results.append(result)
            self._q_ik.append(result.q)
        return self._q_ik[k]

    def trajectory(self) -> JointTrajectory | None:
        """The :meth:`target` of every tick at once, bit for bit, once every waypoint is solved (None before: a
        line that checks only its first spans solves the others when the hand gets there, and may stop first)."""
        if self._trajectory is None and len(self._q_ik) == len(self._s_ik):
            # target(i) for every i, vectorised: the same elementwise operations in the same order.
            s, s_ik = self._s, self._s_ik
            k = np.minimum(np.maximum(np.searchsorted(s_ik, s), 1), len(s_ik) - 1)
            q_ik = np.array(self._q_ik)
            q0, s0 = q_ik[k - 1], s_ik[k - 1]
            rate = (q_ik[k] - q0) / (s_ik[k] - s0)[:, None]
            self._trajectory = JointTrajectory(q0 + (s - s0)[:, None] * rate, rate * self._v[:, None],
                                               rate * self._a[:, None], CONTROL_DT)
        return self._trajectory

    def target(self, i: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Joint targets [rad], velocities [rad/s] and accelerations [rad/s^2] of tick ``i``."""
        s = self._s[i]
        k = min(max(int(np.searchsorted(self._s_ik, s)), 1), len(self._s_ik) - 1)
        q0, q1 = self._waypoint(k - 1), self._waypoint(k)
        span = self._s_ik[k] - self._s_ik[k - 1]
        rate = (q1 - q0) / span
        return q0 + (s - self._s_ik[k - 1]) * rate, rate * self._v[i], rate * self._a[i]


class MotionExecutor:
    """Runs moves on ``physics`` using ``kinematics`` (both describe the same robot).

    Args:
        physics: The scene.
        kinematics: The same robot's kinematics.
        free_timestep: Timestep [s] of a tap interaction outside its stroke (FREE_TIMESTEP).
    """

    def __init__(self, physics: TapPhysics, kinematics: Kinematics, free_timestep: float = FREE_TIMESTEP) -> None:
        self.physics = physics
        self.kinematics = kinematics
        #: The palm of the arm that ``kinematics`` moves (in the scene with both arms, either arm's).
        self.palm_site = int(physics.model.site(kinematics.variant.palm_site).id)
        self.palm = physics.data.site_xpos[self.palm_site]  # a view: the palm's position after each step
        self._opt = physics.model.opt  # MuJoCo's options, read at every tick: the wrapper is made once
        self._tick_timestep, self._steps_per_tick = 0.0, 1  # the last timestep seen, and its steps per tick
        #: Velocity limit of every active joint [rad/s] (:mod:`affordance_env.motor_limits`) ...
        self.velocity_limit = velocity_limits(physics.variant.active_joints)
        #: ... and the speeds moves are planned for [rad/s]: PLANNED_SPEED_SHARE of it.
        self.planned_speed = PLANNED_SPEED_SHARE * self.velocity_limit
        #: Timestep [s] of a tap interaction outside its stroke (FREE_TIMESTEP); the scene's own (2 ms) steps the
        #: whole interaction as finely as the stroke (``benchmarks/timestep.py`` compares the two).
        self.free_timestep = free_timestep
        #: What the robot is doing now ("reach", "stroke", "descend", "close", "lift", "hold", "carry", "place",
        #: "open", "retreat", "home", ...): for diagnostics and pictures.
        self.phase = "idle"

    @property
    def steps_per_tick(self) -> int:
        """Physics steps per control tick at the model's current timestep."""
        timestep = self._opt.timestep
        if timestep != self._tick_timestep:  # asked at every tick: divided only when the timestep changes
            self._tick_timestep, self._steps_per_tick = timestep, max(1, round(CONTROL_DT / timestep))
        return self._steps_per_tick

    @contextmanager
    def stepping(self, timestep: float) -> Iterator[None]:
        """Simulate at ``timestep`` [s], a divisor of CONTROL_DT, inside the block; at the model's own after it."""
        steps = round(CONTROL_DT / timestep)
        if not (timestep > 0 and abs(steps * timestep - CONTROL_DT) < 1e-12):
            raise InvalidValueError(f"timestep must divide the control period {CONTROL_DT} s, got {timestep!r}.")
        opt = self.physics.model.opt
        saved, opt.timestep = opt.timestep, timestep
        try:
            yield
        finally:
            opt.timestep = saved

    # --- the one servo loop ------------------------------------------------------------------------------------
    def follow(self, trajectory: JointTrajectory, until: Callable[[], bool] | None = None) -> bool:
        """Play ``trajectory`` on the servos, one control tick per sample, with velocity and inertial
        feedforward. ``until``, if given, is asked after every tick; the move stops (the targets stay where the
        joints are) as soon as it answers True. Returns whether it did."""
        physics = self.physics
        # physics.step_toward's two calls, bound once: this loop runs every control tick of every move
        aim, step, n_steps = physics.set_targets_toward, physics.step, self.steps_per_tick
        led = trajectory.q + physics.servo_lead * trajectory.qd  # the velocity feedforward of every tick
        accelerations = physics.tick_accelerations(trajectory.qdd)  # every tick's, as MuJoCo's vectors, at once
        if accelerations is None:
            accelerations = trajectory.qdd
        else:
            aim = physics.set_targets_toward_rows
        for q_tick, qdd_tick in zip(led, accelerations, strict=True):
            aim(q_tick, qdd_tick)  # and the inertial feedforward of the tick's configuration
            step(n_steps)
            if until is not None and until():
                self.stop()
                return True
        return False

    def stop(self) -> None:
        """Stop where the joints are: the servo targets become the joint positions."""
        self.physics.set_joint_targets(self.physics.joint_positions())

    def move_joints(self, q_target: np.ndarray, duration: float | None = None) -> None:
        """Move the servo targets to ``q_target`` along a minimum-jerk profile within the velocity limits, starting
        and ending at rest; ``duration`` [s] lengthens it (never shortens it below what the limits allow)."""
        self.move_through([q_target], duration)

    def move_through(self, waypoints: list[np.ndarray], duration: float | None = None,
                     until: Callable[[], bool] | None = None) -> bool:
        """Move through ``waypoints`` (joint targets) to the last one, without stopping at the ones before
        (:func:`~affordance_env.trajectory.minimum_jerk`); see :meth:`follow` for ``until``."""
        trajectory = minimum_jerk(self.physics.joint_targets(), waypoints, self.planned_speed, CONTROL_DT,
                                  duration=duration, min_duration=MIN_MOVE_TIME)
        return self.follow(trajectory, until)

    def hold(self, duration: float, until: Callable[[], bool] | None = None) -> bool:
        """Keep the current targets for ``duration`` [s] (whole ticks); see :meth:`follow` for ``until``."""
        q = self.physics.joint_targets()
        n = max(1, round(duration / CONTROL_DT))
        zeros = np.zeros((n, len(q)))
        return self.follow(JointTrajectory(np.tile(q, (n, 1)), zeros, zeros, CONTROL_DT), until)

    def hold_still(self, max_time: float = HOLD_MAX_TIME,
                   also: Callable[[TapPhysics], bool] | None = None) -> bool:
        """Hold the current servo targets until the robot is still, so that a snapshot sees the scene from a still
        head and with a still hand: every joint slower than HOLD_SPEED_TOLERANCE at HOLD_STILL_TICKS consecutive
        control ticks (one slow sample could be the turning point of an oscillation); at most ``max_time`` [s].
        ``also(physics)``, if given, must hold too (for instance: the object is at rest). Returns whether the robot
        came to rest."""
        physics = self.physics
        still_ticks = 0

        def still() -> bool:
            nonlocal still_ticks
            slow = physics.max_joint_speed() <= HOLD_SPEED_TOLERANCE
            still_ticks = still_ticks + 1 if slow else 0
            return still_ticks >= HOLD_STILL_TICKS and (also is None or also(physics))

        if still():
            return True
        q = physics.joint_targets()
        n_steps = self.steps_per_tick
        for _ in range(max(1, round(max_time / CONTROL_DT))):
            physics.set_joint_targets(q)
            physics.step(n_steps)
            if still():
                return True
        return still_ticks >= HOLD_STILL_TICKS

    def settle(self, p_world_target: np.ndarray, tolerance: float = SETTLE_TOLERANCE,
               max_time: float = SETTLE_MAX_TIME) -> float:
        """Hold the servo targets until the palm is within ``tolerance`` [m] of ``p_world_target``.

        Returns the remaining distance [m] (larger than ``tolerance`` if ``max_time`` [s] ran out).
        """
        def arrived() -> bool:
            return norm(self.palm - p_world_target) <= tolerance

        if not arrived():
            q = self.physics.joint_targets()
            for _ in range(max(1, round(max_time / CONTROL_DT))):
                self.physics.set_joint_targets(q)
                self.physics.step(self.steps_per_tick)
                if arrived():
                    break
        return norm(self.palm - p_world_target)

    def ik(self, p: np.ndarray, q_init: np.ndarray, hand: HandTarget, *, check: bool = False) -> IKResult:
        """IK of a palm position [m] with the hand's orientation and joint ranges, from ``q_init``. ``check``: only
        whether the pose is within IK_POSITION_TOLERANCE and IK_ORIENTATION_TOLERANCE matters (a feasibility
        check): the solver gives up once its error stands still beyond them
        (:data:`~affordance_env.kinematics.STALL_WINDOW`)."""
        return self.kinematics.solve_ik(
            p, q_init, hand.R_world_hand, position_tolerance=1e-3, orientation_tolerance=IK_ORIENTATION_TOLERANCE,
            joint_ranges=hand.joint_ranges,
            give_up_beyond=(IK_POSITION_TOLERANCE, IK_ORIENTATION_TOLERANCE) if check else None,
        )

    # --- lines of the palm -------------------------------------------------------------------------------------
    def follow_line(self, path: LinePath, touched: Callable[[], bool] | None = None, *, per_step: bool = False,
                    follow_through: float = 0.0) -> LineResult:
        """Move the palm along ``path``, with velocity feedforward, until its end, or ``follow_through`` [m] past
        the first ``touched()`` if one is given (then the targets stay where the joints are).

        ``touched`` is asked after every control tick, or with ``per_step`` after every physics step while the
        hand is within CONTACT_WATCH_DISTANCE of the object (the stroke: its first touch to the step).
        """
        physics = self.physics
        palm = self.palm  # a view: the palm position after each step
        p_start = palm.copy()
        trajectory = path.trajectory()
        if touched is None and trajectory is not None:  # nothing to watch: the one servo loop
            self.follow(trajectory)
            return LineResult(False, float("nan"), 0.0, p_start)
        n_steps = self.steps_per_tick
        dt = physics.model.opt.timestep
        direction = path.direction
        e0, e1, e2 = direction.tolist()
        p_touch, time, speed = p_start, float("nan"), 0.0
        t0 = t1 = t2 = 0.0  # p_touch as Python floats, once touched
        touched_yet = False
        aim, ticks = physics.set_targets_toward, self._line_ticks(path)
        if trajectory is not None:  # every tick's accelerations as MuJoCo's vectors at once (see follow)
            accelerations = physics.tick_accelerations(trajectory.qdd)
            if accelerations is not None:
                aim = physics.set_targets_toward_rows
                ticks = zip(trajectory.q + physics.servo_lead * trajectory.qd, accelerations, strict=True)
        for q_led, qdd in ticks:
            if touched is None:
                aim(q_led, qdd)  # physics.step_toward
                physics.step(n_steps)
                continue
            aim(q_led, qdd)
            # hand_object_distance(d) < d, answered as arm_near_object does: the geoms whose bounding spheres are
            # farther than d from the object's are not measured, and the first one nearer than d ends the search
            if per_step and (touched_yet or physics.arm_near_object(CONTACT_WATCH_DISTANCE)):
                # step by step: the touch and the follow-through, to the step
                for _ in range(n_steps):
                    if not touched_yet:
                        p_before = palm.copy()
                    physics.step()
                    if not touched_yet and touched():
                        touched_yet, time, p_touch = True, float(physics.data.time), palm.copy()
                        speed = norm(palm - p_before) / dt
                        t0, t1, t2 = p_touch.tolist()
                    if touched_yet:
                        # dot(palm - p_touch, direction) in Python floats, bit for bit: the differences, then
                        # einsum's sum of three contiguous products, (x + z) + y, from +0 (see pinhole.to_camera)
                        a0, a1, a2 = palm.tolist()
                        if (((a0 - t0) * e0 + (a2 - t2) * e2) + (a1 - t1) * e1) + 0.0 >= follow_through:
                            self.stop()
                            return LineResult(True, time, speed, p_touch)
                continue  # past the touch, the last step's follow-through was just measured: short of it
            p_before = palm.copy()  # whole ticks: the touch to the tick
            physics.step(n_steps)
            if not touched_yet and touched():
                touched_yet, time, p_touch = True, float(physics.data.time), palm.copy()
                speed = norm(palm - p_before) / (n_steps * dt)
            if touched_yet and dot(palm - p_touch, direction) >= follow_through:
                self.stop()
                break
        return LineResult(touched_yet, time, speed, p_touch)

    def _line_ticks(self, path: LinePath) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        """The servo targets led by the velocity feedforward [rad] and the accelerations [rad/s^2] of every tick of
        ``path``: all at once when its waypoints are solved, else tick by tick as the hand gets there."""
        lead = self.physics.servo_lead
        trajectory = path.trajectory()
        if trajectory is not None:
            yield from zip(trajectory.q + lead * trajectory.qd, trajectory.qdd, strict=True)
            return
        for i in range(len(path)):
            q, qd, qdd = path.target(i)
            yield q + lead * qd, qdd

    def line(self, p_from: np.ndarray, p_to: np.ndarray, hand: HandTarget, speed: float,
             q_start: np.ndarray | None = None, **kwargs) -> LinePath:
        """The :class:`LinePath` from ``p_from`` to ``p_to`` [m] at ``speed`` [m/s], from ``q_start`` (default: the
        current servo targets)."""
        delta = np.asarray(p_to, dtype=float) - np.asarray(p_from, dtype=float)
        length = norm(delta)
        q0 = self.physics.joint_targets() if q_start is None else q_start
        return LinePath(self, p_from, delta / length, length, hand, speed, q0, **kwargs)

    # --- the way home ------------------------------------------------------------------------------------------
    def go_home(self, q_home: np.ndarray, via: np.ndarray | None = None) -> HomeOutcome:
        """Return to ``q_home`` through ``via`` (after :meth:`stroke`: up and back above the pre-stroke pose; after
        :meth:`grasp`: straight up from where the hand let go) and hold until the robot is still.

        The arm watches the object on its way: once it has been clear of it, coming within HOME_CLEARANCE of it
        stops the arm; it waits for the object to come to rest, then goes home through a pose above where the
        object rests, HOME_RAISE higher than the hand is. A touch after the arm was clear is reported.
        """
        physics = self.physics
        self.phase = "home"
        state = {"clear": physics.arm_object_distance(HOME_CLEARANCE) >= HOME_CLEARANCE, "touched": False}

        def watch(stop_near: bool) -> Callable[[], bool]:
            def near() -> bool:
                if not state["clear"]:
                    state["clear"] = physics.arm_object_distance(HOME_CLEARANCE) >= HOME_CLEARANCE
                    return False
                # once clear, only whether the arm is that near counts, and only if it stops the move
                near, touching = physics.arm_near_or_touching(HOME_CLEARANCE)
                state["touched"] = state["touched"] or touching
                return stop_near and near
            return near

        waited = self.move_through([q_home] if via is None else [via, q_home], until=watch(True))
        if waited:  # wait for the object to rest, then home through a pose above it
            self.phase = "wait"
            self.hold(HOME_WAIT, until=lambda: object_at_rest(physics) or not physics.object_on_table())
            self.phase = "home"
            q_now = physics.joint_targets()
            R_world_hand = self.kinematics.hand_pose(q_now).rotation  # straight up, the hand turned as it is
            p_up = self.palm.copy() + np.array([0.0, 0.0, HOME_RAISE])
            q_up = self.kinematics.solve_ik(p_up, q_now, R_world_hand,
                                            orientation_tolerance=IK_ORIENTATION_TOLERANCE).q
            self.move_through([q_up, q_home], until=watch(False))
        still = self.hold_still()
        touched = state["touched"] or (state["clear"] and physics.hand_touches_object())
        return HomeOutcome(still, touched, waited)


def object_at_rest(physics: TapPhysics) -> bool:
    """The object is still (:data:`~affordance_env.outcome.REST_SPEED`, ``REST_ANGULAR_SPEED``)."""
    return physics.object_speed() < REST_SPEED and physics.object_angular_speed() < REST_ANGULAR_SPEED
