"""The world both environments act in: the iCub, the table and one object, sensed by the range camera in the head.

A :class:`World` owns, for each arm it has, the arm's physics, kinematics, motion and cameras, and runs the
behaviours of :mod:`affordance_env.behaviors` on them. Its queries:

- :meth:`World.place` puts a new object on the table and observes it; :meth:`World.observe` looks at it again;
- :meth:`World.interact` runs one behaviour with its parameters and returns a typed
  :class:`~affordance_env.results.InteractionResult`;
- :meth:`World.feasible` answers from the kinematics alone whether an interaction can reach every pose;
- :meth:`World.get_state` and :meth:`World.set_state` snapshot and restore it, bit for bit.

With both arms, the world lives in one model per arm (each the scene with both arms, the other arm held rigid at
home); it passes from one to the other when a behaviour of the other arm acts
(:meth:`TapPhysics.adopt <affordance_env.physics.TapPhysics.adopt>`): a private detail, the same world goes on.
Randomness comes from the caller's generator (the env's ``np_random``), passed to the calls that draw.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from affordance_env.attention import attend
from affordance_env.behaviors import ACTION_DIM, check_action, get_behavior
from affordance_env.behaviors.base import Behavior
from affordance_env.camera import RangeCamera
from affordance_env.exceptions import IncompatibleStateError, InvalidValueError
from affordance_env.features import FEATURE_NAMES, NOT_VISIBLE_VALUES, Features, effect_features, object_features
from affordance_env.kinematics import Kinematics
from affordance_env.linalg import norm
from affordance_env.motion import HOLD_MAX_TIME, HOLD_SPEED_TOLERANCE, MotionExecutor, ReachOutcome
from affordance_env.objects import as_resting
from affordance_env.outcome import REST_DURATION, ObjectMonitor, outcome_labels
from affordance_env.physics import TapPhysics
from affordance_env.placement import PLACEMENT_CENTRE, Placement, Table
from affordance_env.range_noise import add_kinect_noise
from affordance_env.registry import ARMS, BEHAVIOR_ARMS, check_behavior_name
from affordance_env.results import IKReport, InitialSnapshot, InteractionResult, Observation, Snapshot, frozen_array
from affordance_env.robot_model import HAND_JOINTS
from affordance_env.scene import build_model

#: The placed object is at rest for the initial snapshot when slower than these [m/s], [rad/s]: ten and thirty
#: times stricter than the outcome's rest (:func:`affordance_env.motion.object_at_rest`).
REST_SPEED, REST_ANGULAR_SPEED = 1e-3, 1e-2
#: When an interaction's final snapshot is taken: ``"paper"``, where the behaviour ends as the paper measures it
#: (Akgun et al. 2009: "When the execution ends, another snapshot is taken"): the grasp at the end of its hold,
#: the object held, a stroke once the struck object has come to rest; ``"rest"``, once the whole interaction is
#: over and the object rests (a held object put down), as a world that goes on needs it.
FINAL_SNAPSHOTS = ("paper", "rest")
#: The robot variant of each arm's model: alone, or in the scene with both arms.
ONE_ARM_VARIANT = {"right": "tap", "left": "grasp"}
TWO_ARMS_VARIANT = {"right": "two_arms", "left": "two_arms_left"}


def _object_still(physics: TapPhysics) -> bool:
    """Still enough for a snapshot (REST_SPEED, REST_ANGULAR_SPEED)."""
    return physics.object_speed() < REST_SPEED and physics.object_angular_speed() < REST_ANGULAR_SPEED


def failure_reason(fault: str | None, initial: InitialSnapshot, outcome: ReachOutcome, home_still: bool,
                   touched_on_way_home: bool, behavior: Behavior) -> str | None:
    """Why an interaction cannot be used, or None (TapAffordance-v2's ``info["failure"]``). ``outcome``: what the
    behaviour reported; ``home_still``: the robot was still for the final snapshot; ``touched_on_way_home``: the
    arm touched the object again after it had been clear of it."""
    if fault is not None:
        return f"physics: {fault}"
    for snapshot, was_still in (("initial", initial.still), ("final", home_still)):
        if not was_still:
            return (f"snapshot: the robot was still moving at the {snapshot} snapshot (a joint faster than "
                    f"{HOLD_SPEED_TOLERANCE:g} rad/s after {HOLD_MAX_TIME:g} s of holding still)")
    if not initial.visible:
        return "perception: the object was not visible in the initial snapshot"
    if not outcome.ik_success:
        return (f"ik: the {behavior.kind} was not reachable (position error "
                f"{outcome.ik_position_error * 1e3:.1f} mm, orientation error {outcome.ik_orientation_error:.2f} rad)")
    if touched_on_way_home:
        return "home: the arm touched the object on its way home"
    return behavior.failure(outcome)


@dataclass(frozen=True)
class WorldState:
    """A snapshot of a :class:`World` (:meth:`World.get_state`): treat it as opaque.

    Attributes:
        arm: The arm whose model holds the world.
        variant: That model's robot variant; a state restores only into a world that has it.
        physics: The object's geometry and MuJoCo's integration state.
        initial: What the last observation saw (None when no interaction can start from it).
        q_home: The acting arm's home targets, with the gaze on the object.
    """

    arm: str
    variant: str
    physics: tuple[Any, Any]
    initial: InitialSnapshot | None
    q_home: np.ndarray


@dataclass(frozen=True)
class _Final:
    """The final snapshot (None: a fault), the object's pose then, whether the robot was still, and whether the
    object had left the table."""

    snapshot: Snapshot | None
    pose: np.ndarray
    still: bool
    left_table: bool


class _Arm:
    """One arm's model of the world, and what acts in it: physics, kinematics, motion, cameras, the approach
    posture of each of its behaviours."""

    def __init__(self, variant: str, camera_size: tuple[int, int], camera_fovy: float) -> None:
        self.variant = variant
        self.physics = TapPhysics(build_model(variant), variant)
        self.kinematics = Kinematics(variant=variant)
        self.motion = MotionExecutor(self.physics, self.kinematics)
        width, height = camera_size
        self.camera = RangeCamera(self.physics.model, width=width, height=height, fovy_deg=camera_fovy,
                                  support="table_top")
        self.attention_camera = RangeCamera(self.physics.model, width=40, height=30, fovy_deg=camera_fovy,
                                            support="table_top")
        #: The joints that carry the camera and the hand (all but the fingers), by index of the active joints.
        self.body_joints = np.array([i for i, name in enumerate(self.kinematics.joint_names)
                                     if name not in HAND_JOINTS])
        self.postures: dict[str, np.ndarray | None] = {}
        self.renderer: Any = None


class World:
    """The iCub, the table and one object; the behaviours ``behaviors`` act in it.

    Args:
        behaviors: The behaviours the world runs (names of :data:`affordance_env.registry.BEHAVIOR_NAMES`); it
            builds the model of each arm they need.
        two_arms: Every arm's model is the scene with both arms (the other arm rigid at home), so every behaviour
            sees the same robot; required for behaviours of both arms.
        camera_width, camera_height: Range image size [pixels].
        camera_fovy: Vertical field of view [deg].
        range_noise: ``"kinect_v1"``: the range camera's noise model; None: exact ranges.
        roll_threshold: Rolling distance above which an interaction ``rolled`` [m].
        settle_timeout: Longest simulated wait for the outcome after the first touch [s].
        typical_size: Object size [m] for which the approach postures are solved (the mean of the size range).
        final_snapshot: When the final snapshot is taken, one of :data:`FINAL_SNAPSHOTS`.
    """

    def __init__(self, behaviors: Sequence[str], *, two_arms: bool = False, camera_width: int = 160,
                 camera_height: int = 120, camera_fovy: float = 57.4, range_noise: str | None = None,
                 roll_threshold: float = 0.03, settle_timeout: float = 3.0, typical_size: float = 0.07,
                 final_snapshot: str = "rest") -> None:
        names = [check_behavior_name(name) for name in behaviors]
        if final_snapshot not in FINAL_SNAPSHOTS:
            raise InvalidValueError(f"final_snapshot must be one of {FINAL_SNAPSHOTS}, got {final_snapshot!r}.")
        self.final_snapshot = final_snapshot
        if not names:
            raise InvalidValueError("a world needs at least one behaviour, got none.")
        arms = [arm for arm in ARMS if any(BEHAVIOR_ARMS[name] == arm for name in names)]
        if len(arms) > 1 and not two_arms:
            raise InvalidValueError(f"behaviours {names} need both arms: make the world with two_arms=True.")
        self.behaviors: tuple[str, ...] = tuple(names)
        self.range_noise = range_noise
        self.roll_threshold = float(roll_threshold)
        self.settle_timeout = float(settle_timeout)
        self._arms: dict[str, _Arm] = {}
        for arm_name in arms:
            variant = (TWO_ARMS_VARIANT if two_arms else ONE_ARM_VARIANT)[arm_name]
            arm = self._arms[arm_name] = _Arm(variant, (camera_width, camera_height), camera_fovy)
            for name in names:
                if BEHAVIOR_ARMS[name] == arm_name:
                    arm.postures[name] = self._behavior(name).prepare(arm.motion, PLACEMENT_CENTRE, typical_size)
        self._acting = self._arms[arms[0]]
        self._initial: InitialSnapshot | None = None
        self._q_home = np.zeros(self._acting.kinematics.nq)
        physics = self._acting.physics
        low, high = physics.table_extent()
        #: The table top.
        self.table = Table(low, high, physics.table_top)

    def _behavior(self, name: str) -> Behavior:
        """The behaviour ``name`` as this world runs it: a world whose final snapshot is taken at rest goes on after
        each interaction (the goal env), and runs the behaviours' goal versions (the grasp: pick and place)."""
        return get_behavior(name, goal=self.final_snapshot == "rest")

    # --- what it is ----------------------------------------------------------------------------------------------
    @property
    def physics(self) -> TapPhysics:
        """The physics of the model that holds the world now (the acting arm's)."""
        return self._acting.physics

    @property
    def motion(self) -> MotionExecutor:
        """The motion executor of the acting arm."""
        return self._acting.motion

    @property
    def camera(self) -> RangeCamera:
        """The range camera in the head (of the acting arm's model)."""
        return self._acting.camera

    def kinematics(self, behavior: str | None = None) -> Kinematics:
        """The kinematics of the arm of ``behavior`` (default: the acting arm)."""
        return self._acting.kinematics if behavior is None else self._arm_of(behavior).kinematics

    def approach_posture(self, behavior: str) -> np.ndarray | None:
        """The arm posture the IK of ``behavior``'s approaches starts from (None: the current servo targets)."""
        return self._arm_of(behavior).postures[behavior]

    @property
    def home_joints(self) -> np.ndarray:
        """The acting arm's home targets [rad], with the gaze on the object (a copy)."""
        return self._q_home.copy()

    def object_pose(self) -> np.ndarray:
        """The object's true pose now, ``(x, y, z, qw, qx, qy, qz)`` [m] (a copy)."""
        return self._acting.physics.object_pose()

    @property
    def seen(self) -> InitialSnapshot | None:
        """What the last observation saw, from which the next interaction starts; None: nothing to act on."""
        return self._initial

    def _arm_of(self, behavior: str) -> _Arm:
        name = check_behavior_name(behavior)
        arm = self._arms.get(BEHAVIOR_ARMS[name])
        if arm is None or name not in arm.postures:
            raise InvalidValueError(f"behavior {name!r} is not one of this world's: {', '.join(self.behaviors)}.")
        return arm

    def _world_to(self, arm: _Arm) -> None:
        """Bring the world into ``arm``'s model, as it is in the acting one."""
        if arm is not self._acting:
            arm.physics.adopt(self._acting.physics)

    # --- sensing -------------------------------------------------------------------------------------------------
    def look(self, rng: np.random.Generator) -> Snapshot:
        """A picture of the range camera as the world is now, with the joints (no attention, no wait); the range
        noise, if any, drawn from ``rng``."""
        physics, camera = self._acting.physics, self._acting.camera
        noise = self.range_noise is not None
        # Without noise only the object's points are needed: the camera leaves the others uncomputed.
        image = camera.capture(physics.data, normals=noise, occluded=physics.active_geom, points=noise)
        if noise:
            image = add_kinect_noise(image, rng)
        mask = image.mask_of(physics.active_geom)
        p_world_hand = physics.hand_position()
        uv_hand = image.project(p_world_hand)
        if not np.all(np.isfinite(uv_hand)):  # hand behind the camera: no image position; use the image centre
            uv_hand = np.array([image.intrinsics.cx, image.intrinsics.cy])
        # The object's pixels and their points ((3, k), as p_world_points[mask].T, the same bits): the features
        # of compute_features(p_world_points, ranges, mask, ...), from them alone
        pixels = mask.ravel().nonzero()[0]
        p_world_obj = image.points_of(pixels)
        features = object_features(pixels, mask.shape[1], p_world_obj, image.ranges.reshape(-1).take(pixels),
                                   image.p_world_camera, p_world_hand, uv_hand)
        points = p_world_obj.T.copy()  # p_world_points[mask]: (k, 3), row-major
        ranges = np.where(np.isfinite(image.ranges), image.ranges, 0.0).astype(np.float32)
        return Snapshot(frozen_array(ranges), frozen_array(mask.astype(np.int8)), features,
                        frozen_array(physics.joint_positions().astype(np.float32)), frozen_array(points))

    def blank_snapshot(self) -> Snapshot:
        """What nothing seen looks like: no ranges, no object, the not-visible features, the joints at home."""
        camera = self._acting.camera
        shape = (camera.intrinsics.height, camera.intrinsics.width)
        features = Features(NOT_VISIBLE_VALUES.copy(), False, 0)
        return Snapshot(frozen_array(np.zeros(shape, np.float32)), frozen_array(np.zeros(shape, np.int8)), features,
                        frozen_array(self._q_home.astype(np.float32)), frozen_array(np.empty((0, 3))))

    def place(self, placement: Placement, rng: np.random.Generator) -> Observation:
        """Put the robot at home and the object where ``placement`` says, let it settle, and observe it."""
        self._acting = next(iter(self._arms.values()))
        physics = self._acting.physics
        physics.reset_home()
        self._q_home = physics.joint_targets()
        physics.set_object(placement.geometry, placement.xy, placement.yaw)  # 0.1 mm above the table: it settles
        if placement.pose is not None:  # any pose: it settles too, and the plan reads its geometry from its rest
            physics.set_object_pose(placement.pose)
            return self.observe(rng)
        return self.observe(rng, (placement.geometry, placement.yaw))

    def observe(self, rng: np.random.Generator, plan_geometry: tuple[Any, float] | None = None) -> Observation:
        """Look at the object where it is: attend to it, wait until the robot (and the object) are still, and take
        the snapshot the next interaction starts from. ``plan_geometry``: the geometry and yaw the interaction
        plans for; None: read from how the object rests (a toppled cylinder lies)."""
        arm = self._acting
        physics, motion = arm.physics, arm.motion
        with motion.stepping(motion.free_timestep):
            attention = attend(physics, arm.attention_camera, motion.move_joints)
            still = motion.hold_still(also=_object_still)
        self._q_home = physics.joint_targets()  # the arm's home, with the gaze on the object
        snapshot = self.look(rng)
        pose = physics.object_pose()
        geometry, yaw = as_resting(physics.geometry, pose[3:]) if plan_geometry is None else plan_geometry
        self._initial = InitialSnapshot(snapshot, frozen_array(pose.copy()), yaw, geometry, still)
        return Observation(self._initial, physics.geometry.object_type, physics.geometry.size, attention)

    # --- acting --------------------------------------------------------------------------------------------------
    def feasible(self, behavior: str, params: Any) -> bool:
        """Whether the arm can reach every pose of ``behavior`` with ``params`` on the object where the last
        observation saw it, from the kinematics alone (no physics step). False: the interaction would fail with
        ``"ik: ..."``, a stroke's reach would sweep the arm into the object (``"reach: ..."``), or a pick and place
        would put the object down off the table."""
        a = check_action(params)
        arm = self._arm_of(behavior)
        initial = self._initial
        if initial is None:
            raise RuntimeError("feasible() needs an object: place one first (the env's reset()).")
        self._world_to(arm)  # the world as it is, as an interaction would continue it
        b = self._behavior(behavior)
        plan = b.plan(initial.geometry, initial.pose[:3], initial.yaw, arm.physics.table_top, a)
        return bool(b.reachable(arm.motion, plan, arm.postures[behavior]))

    def interact(self, behavior: str, params: Any, rng: np.random.Generator) -> InteractionResult:
        """Run ``behavior`` with ``params`` on the object the last observation saw, wait for the object's outcome
        and take the final snapshot. The world then needs another observation before the next interaction."""
        action = check_action(params)
        arm = self._arm_of(behavior)
        if self._initial is None:
            raise RuntimeError("interact() needs an observed object: place or observe one first (the env's reset()).")
        if arm is not self._acting:
            self._world_to(arm)
            self._acting = arm
            self._q_home = arm.physics.joint_targets()
        initial, self._initial = self._initial, None
        b = self._behavior(behavior)
        physics, motion = arm.physics, arm.motion
        plan = b.plan(initial.geometry, initial.pose[:3], initial.yaw, physics.table_top, action)
        ended: list[_Final] = []  # the final snapshot, if taken where the behaviour ends as the paper measures it

        def at_end() -> None:
            # The head and the arm must be still for the snapshot; the fingers squeezing what they hold may creep
            # (an object slipping slowly in the grip is the grasp's outcome, not a blur).
            speeds = np.abs(physics.joint_velocities()[arm.body_joints])
            still = float(np.max(speeds)) <= HOLD_SPEED_TOLERANCE
            ended.append(_Final(None if physics.unstable() else self.look(rng), physics.object_pose(), still,
                                monitor.left_table))

        monitor = physics.start_monitor()  # from now on, whatever the arm does
        try:
            done = b.execute(motion, plan, arm.postures[behavior], at_end if self.final_snapshot == "paper" else None)
            with motion.stepping(motion.free_timestep):
                home = motion.go_home(self._q_home, via=b.via_home(done))
                since = b.awaited_since(done, float(physics.data.time))
                outcome, outcome_time = self._wait_outcome(monitor, since)
        finally:
            physics.monitor = None
        if not ended:  # the final snapshot where the object has come to rest
            ended.append(_Final(None if physics.unstable() else self.look(rng), physics.object_pose(), home.still,
                                monitor.left_table))
        return self._result(b, action, initial, done, ended[0], home.touched, monitor, outcome, outcome_time)

    def _result(self, b: Behavior, action: np.ndarray, initial: InitialSnapshot, done: ReachOutcome,
                end: _Final, touched: bool, monitor: ObjectMonitor, outcome: str,
                outcome_time: float) -> InteractionResult:
        physics = self._acting.physics
        fault = physics.unstable()
        final = None if fault else end.snapshot  # after a fault the state is not to be trusted
        final_pose = np.full(7, np.nan) if fault else end.pose
        failure = failure_reason(fault, initial, done, end.still, touched, b)
        # Travel on the table: to where the object rests, or to where it left the table (not where it fell; for an
        # object in the grasp's hand beyond the edge, where its centre dropped below the top or the hand let go).
        p_end = monitor.exit_position if end.left_table else final_pose
        displacement = 0.0 if fault else norm(p_end[:2] - initial.pose[:2])
        labels = None if fault else outcome_labels(monitor, initial.pose[3:], final_pose[3:], self.roll_threshold)
        effect = (np.zeros(len(FEATURE_NAMES), np.float32) if final is None
                  else effect_features(initial.features.values, final.features.values))
        # The success label: a failed interaction is no sample, so no success either.
        success = failure is None and labels is not None and b.success(done, labels, displacement,
                                                                       self.roll_threshold)
        return InteractionResult(
            behavior=b.name, action=frozen_array(action), object_type=initial.geometry.object_type,
            size=initial.geometry.size, initial=initial, final=final, final_pose=frozen_array(final_pose),
            effect=frozen_array(effect), displacement=displacement,
            rolling_distance=0.0 if fault else monitor.rolling_distance,
            rolled=labels is not None and labels.rolled, success=bool(success),
            toppled=labels is not None and labels.toppled, tilt=0.0 if fault else labels.tilt,
            outcome="fault" if fault else outcome, outcome_time=0.0 if fault else float(outcome_time),
            contact=done.contact, hand_speed=done.hand_speed,
            ik=IKReport(done.ik_success, done.ik_position_error, done.ik_orientation_error),
            failure=failure, facts=b.facts(done))

    def _wait_outcome(self, monitor: ObjectMonitor, since: float) -> tuple[str, float]:
        """Simulate until the object has left the table, has been at rest since ``since`` [s] or later, or
        ``settle_timeout`` has passed since ``since``; the monitor has followed it all along.

        Returns the outcome and when it happened, in seconds after ``since``: the moment the object left the
        table, or the moment it had been still for ``REST_DURATION``, which may lie before the arm was back.
        """
        physics = self._acting.physics
        t_end = since + self.settle_timeout
        steps_per_tick = self._acting.motion.steps_per_tick
        while True:
            if monitor.left_table:
                return "off_table", monitor.exit_time - since
            if monitor.at_rest(physics.data.time, since):
                return "rest", max(monitor.still_since, since) + REST_DURATION - since
            if physics.data.time >= t_end - 1e-9:
                return "timeout", self.settle_timeout
            physics.step(steps_per_tick)

    # --- snapshots -----------------------------------------------------------------------------------------------
    def get_state(self) -> WorldState:
        """A snapshot of the world: the object and MuJoCo's state, what the last observation saw; :meth:`set_state`
        puts it back, and the same interaction then follows, bit for bit."""
        arm = next(name for name, a in self._arms.items() if a is self._acting)
        return WorldState(arm, self._acting.variant, self._acting.physics.get_state(), self._initial,
                          self._q_home.copy())

    def set_state(self, state: WorldState) -> None:
        """Put the world back as :meth:`get_state` saw it. The state must come from a world with the same model of
        that arm (IncompatibleStateError otherwise)."""
        if not isinstance(state, WorldState):
            raise TypeError(f"state must be what get_state() returned (a WorldState), got {type(state).__name__}.")
        arm = self._arms.get(state.arm) if isinstance(state.arm, str) else None
        if arm is None or arm.variant != state.variant:
            have = ", ".join(f"{name} arm: {a.variant!r}" for name, a in self._arms.items())
            raise IncompatibleStateError(
                f"the state was made with the {state.variant!r} robot model of the {state.arm} arm; this world has "
                f"{have}: a state restores only into a world of the same robot model (behavior='grasp' builds "
                "another model than the strokes, and two_arms=True another again).")
        q_home = np.asarray(state.q_home) if isinstance(state.q_home, np.ndarray) else None
        if (q_home is None or q_home.shape != arm.physics.joint_positions().shape or q_home.dtype.kind != "f"
                or not np.all(np.isfinite(q_home))):
            raise InvalidValueError(f"the state is damaged: its home posture is {state.q_home!r:.80}, not the "
                                    "arm's joint angles.")
        if state.initial is not None and not isinstance(state.initial, InitialSnapshot):
            raise InvalidValueError(f"the state is damaged: its observation is {state.initial!r:.80}.")
        arm.physics.set_state(state.physics)
        self._acting = arm
        self._initial = state.initial
        self._q_home = q_home.copy()

    # --- pictures ------------------------------------------------------------------------------------------------
    def on_step(self, callback: Callable[[float], None] | None) -> None:
        """Call ``callback(time)`` after every physics step call of every arm's model (None: stop)."""
        for arm in self._arms.values():
            arm.physics.on_step = None if callback is None else (lambda physics: callback(physics.data.time))

    def picture(self, width: int, height: int) -> np.ndarray:
        """A picture of the scene as it is, from the ``overview`` camera, (height, width, 3) uint8, headless."""
        arm = self._acting
        if arm.renderer is None:
            from affordance_env.rendering import SceneRenderer  # needs an OpenGL context: only when drawing

            arm.renderer = SceneRenderer(arm.physics.model, width, height)
        return arm.renderer.render(arm.physics.data)

    def close(self) -> None:
        """Release the renderers."""
        for arm in self._arms.values():
            if arm.renderer is not None:
                arm.renderer.close()
                arm.renderer = None


__all__ = ["ACTION_DIM", "World", "WorldState", "failure_reason"]
