"""TapAffordance-v1: one interaction of Akgun et al. (2009) per step."""

from __future__ import annotations

import copy
import numbers
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from affordance_env.attention import attend
from affordance_env.behaviors import ACTION_DIM, BEHAVIORS, check_action
from affordance_env.camera import RangeCamera
from affordance_env.exceptions import IncompatibleStateError, InvalidValueError
from affordance_env.features import FEATURE_NAMES, NOT_VISIBLE_VALUES, Features, compute_features, effect_features
from affordance_env.interactions import Interaction, get_interaction
from affordance_env.kinematics import Kinematics
from affordance_env.linalg import norm
from affordance_env.motion import HOLD_MAX_TIME, HOLD_SPEED_TOLERANCE, MotionExecutor, ReachOutcome
from affordance_env.objects import ObjectGeometry, as_resting, check_object_type, check_size, object_geometry
from affordance_env.options import EnvOptions
from affordance_env.outcome import REST_DURATION, ObjectMonitor, outcome_labels
from affordance_env.physics import TapPhysics
from affordance_env.range_noise import add_kinect_noise
from affordance_env.scene import build_model
from affordance_env.workspace import sample_in_workspace

#: Region of the table where objects are placed: centre (x, y) and half-widths [m].
PLACEMENT_CENTRE = np.array([-0.30, 0.03])
PLACEMENT_HALF_WIDTH = np.array([0.03, 0.03])
#: Keys of ``reset(options=...)`` that choose the object instead of drawing it.
RESET_OPTIONS = ("object_type", "size", "position", "yaw", "object_pose")
#: Depth of the object's top, whose centre is where the object is seen on the table [m].
TOP_DEPTH = 0.003
#: Yaw jitter of boxes and lying cylinders [rad].
YAW_JITTER = 0.25
#: The placed object is at rest for the initial snapshot when slower than these [m/s], [rad/s].
REST_SPEED, REST_ANGULAR_SPEED = 1e-3, 1e-2

def _failure_reason(fault: str | None, visible_initially: bool, outcome: ReachOutcome, still: tuple[bool, bool],
                    touched_on_way_home: bool, interaction: Interaction) -> str | None:
    """Why an interaction cannot be used, or None; see the class docstring. ``outcome``: what the interaction
    reported; ``still``: whether the robot was still for the initial and for the final snapshot;
    ``touched_on_way_home``: the arm touched the object again after it had been clear of it."""
    if fault is not None:
        return f"physics: {fault}"
    for snapshot, was_still in zip(("initial", "final"), still, strict=True):
        if not was_still:
            return (f"snapshot: the robot was still moving at the {snapshot} snapshot (a joint faster than "
                    f"{HOLD_SPEED_TOLERANCE:g} rad/s after {HOLD_MAX_TIME:g} s of holding still)")
    if not visible_initially:
        return "perception: the object was not visible in the initial snapshot"
    if not outcome.ik_success:
        return (f"ik: the {interaction.kind} was not reachable (position error "
                f"{outcome.ik_position_error * 1e3:.1f} mm, orientation error {outcome.ik_orientation_error:.2f} rad)")
    if touched_on_way_home:
        return "home: the arm touched the object on its way home"
    return interaction.failure(outcome)


@dataclass(frozen=True)
class InitialSnapshot:
    """What an interaction's initial snapshot saw, and what its plan is made from.

    Attributes:
        features: The 49 features of the object as the range camera saw it.
        pose: The object's pose then, ``(x, y, z, qw, qx, qy, qz)`` [m] (read-only).
        yaw: The object's yaw for the plan [rad].
        geometry: The object's geometry as it rests (a cylinder lying or standing).
        visible: Whether the camera saw the object.
        still: Whether the robot and the object were still.
    """

    features: Features
    pose: np.ndarray
    yaw: float
    geometry: ObjectGeometry
    visible: bool
    still: bool


@dataclass(frozen=True)
class EnvState:
    """A snapshot of :class:`TapAffordanceEnv` (:meth:`~TapAffordanceEnv.get_state`): treat it as opaque.

    Attributes:
        physics: The object's geometry and MuJoCo's integration state.
        initial: What the episode's initial snapshot saw (None between episodes).
        q_home: The arm's home targets, with the gaze on the object.
        rng: The state of the env's random generator.
        robot: The robot variant of the env's model (``TapPhysics.variant``); a state restores only into an env
            of the same one.
        behavior: The behaviour the env ran.
    """

    physics: tuple[Any, np.ndarray]
    initial: InitialSnapshot | None
    q_home: np.ndarray
    rng: dict[str, Any]
    robot: str
    behavior: str


def _object_still(physics: TapPhysics) -> bool:
    """Still enough for a snapshot: REST_SPEED and REST_ANGULAR_SPEED, ten and thirty times stricter than the
    outcome's rest (:func:`affordance_env.motion.object_at_rest`)."""
    return physics.object_speed() < REST_SPEED and physics.object_angular_speed() < REST_ANGULAR_SPEED


def default_reward(info: dict[str, Any]) -> float:
    """The object's displacement on the table [m]: how much the interaction changed the world."""
    return float(info["displacement"])


class TapAffordanceEnv(gym.Env):
    """An iCub taps one object on a table and sees, through a range camera, what changed.

    ## Description
    The simulated iCub of the paper "Unsupervised Learning of Affordance Relations on a Humanoid Robot" (Akgun,
    Dag, Bilal, Atil, Sahin, 2009): the real kinematics and meshes of ``icub-models`` in MuJoCo, a table, and one
    object of four types (sphere, box, lying cylinder, standing cylinder) of a size drawn from ``size_range``.
    One episode is one interaction: ``reset`` places the object, lets it settle, turns the head so that the object
    is at the image centre, and takes the initial snapshot; ``step`` executes the behaviour (default: the paper's
    tap) and takes the final snapshot. The hand is driven by Pinocchio inverse kinematics and MuJoCo position
    servos with the iCub's motor limits (``affordance_env.motor_limits``: every motor's torque is limited, gravity
    compensation included; every move is planned within the joints' speed limits, 100 degrees per second for the
    arm, torso and neck): the arm and head move along minimum-jerk profiles with velocity and inertial feedforward,
    so the robot is still again as soon as a move ends; the stroke moves the palm in a straight line at the
    action's speed (or as fast as the joints allow) and stops a short follow-through after the hand first touches
    the object. The way home watches the object: an arm that comes within 1.5 cm of it waits for it to rest and
    goes over it, and a touch after the arm was clear of it makes the interaction a failure. Contacts are stiff
    (nothing sinks into anything by more than 1-2 mm) and the palm returns 0.3 of a struck object's speed
    (``affordance_env.scene.PALM_RESTITUTION``).

    ``behavior="grasp"`` is the paper's grasp, by the left arm with the fingered iCub hand of ``icub-models``
    (``left_hand_mk3``: 11 finger joints driven by 7 motors of 0.3 N m each, each distal joint coupled to its
    proximal one as on the real hand; the right arm then hangs still), done as a careful robot does it: palm down
    over the object, the open hand descends slowly (4 cm/s) towards just above the object's top and stops there or
    at the first touch; the fingers and the opposed thumb close with a light touch until each has stalled on the
    object, then grip with their motors' full torque; the hand lifts 8 cm and holds still for 1 s. A held object
    is carried 6 cm to the robot's left and lowered slowly until it meets the table; once it rests there the hand
    opens, rises straight up and goes home. An object the hand does not hold is left where it is: the hand opens
    above it. The final snapshot sees the object where it was put down (a held object moved about 6 cm) or where
    the attempt left it (a failed grasp moves it a median 1-2 cm). Only the fingers' motors move the object (no
    welds, no applied forces). Whether the object fits the open hand, between the thumb and the fingertips,
    decides the outcome (``info["success"]``): nearly all small objects are held, few large ones
    (``python benchmarks/physics_audit.py --behavior grasp``).
    A tap's stroke, from its start to the end of its follow-through, is simulated at 2 ms, which resolves the
    impact; the rest of a tap interaction (the head turning, the reach, the way home, the object rolling to rest)
    at 5 ms (``affordance_env.motion.FREE_TIMESTEP``). The grasp variant of the scene integrates at 5 ms
    (``affordance_env.scene.GRASP_TIMESTEP``).

    The world: a 60 x 100 cm wooden lab table whose top is what objects rest on and roll on (rolling resistance of
    wood on wood, see ``assets/README.md``); past its edges an object falls to the floor. The range camera in the
    head has the iCub eye camera's field of view (57 x 72 degrees at the default 4:3 image). The head keeps the
    gaze of the initial snapshot until the final one, so both snapshots see the table from the same pose: a
    moderate tap rolls a ball 8-26 cm, and it is seen where it stops. 3-D features (``mean_x``, ``hand_dx``, ...)
    are in the robot's root frame, which is fixed (the robot does not walk), so final minus initial is the
    object's motion; image features are in the head camera's image, also unmoved between the two snapshots.

    ``get_state()`` and ``set_state(state)`` snapshot and restore the world and the episode (0.4 and 0.02 ms,
    ``benchmarks/state.py``): the same action after a restore gives the same interaction, bit for bit. A vector
    env (``gym.make_vec``) resets each env in the step that ends its episode, so every vector step is an
    interaction.

    ## Action Space
    ``Box(-1, 1, (3,), float32)``; 0 is the paper's canonical tap.

    | index | meaning | range |
    |-------|---------|-------|
    | 0 | height of the palm above the canonical contact height | -1.5 .. +1.5 cm |
    | 1 | lateral offset of the stroke, across its direction | -2 .. +2 cm |
    | 2 | hand speed along the stroke, 0.18 x 3 ** a m/s, at most what the joints' speed limits allow
      (``info["stroke_speed"]``; the hardest tap reaches 0.29-0.54 m/s, the hardest push 0.18-0.35) | 0.06 .. 0.54 m/s |

    For ``behavior="grasp"``, 0 is the canonical grasp:

    | index | meaning | range |
    |-------|---------|-------|
    | 0 | height of the palm above the object's top when the hand closes | -0.5 .. +1.5 cm |
    | 1 | offset of the object across the hand, towards the little finger | -1.5 .. +1.5 cm |
    | 2 | speed of the closing fingers, 0.75 + 0.25 a of their motors' speed limit (180 deg/s) | 0.5 .. 1 |

    Values outside [-1, 1], NaN or a wrong shape raise ``ValueError``.

    ## Observation Space
    ``Dict`` of

    | key | shape | dtype | meaning |
    |-----|-------|-------|---------|
    | ``range`` | (H, W) | float32 | distance along each pixel's ray [m]; 0 where nothing is hit |
    | ``mask`` | (H, W) | int8 | 1 on pixels of the object of interest |
    | ``features`` | (49,) | float32 | the paper's features, named by ``affordance_env.FEATURE_NAMES`` |
    | ``joints`` | (13,) | float32 | robot joint angles [rad], order ``affordance_env.ACTIVE_JOINTS``; for the grasp
      (24,): torso, neck, left arm and the 11 finger joints, order ``affordance_env.robot_model.VARIANTS["grasp"]
      .active_joints`` |

    ## Rewards
    ``reward_fn(info)``; the default is the object's displacement on the table [m]. Affordance learning does not
    use a reward: it learns from ``info["effect"]``.

    ## Starting State
    Robot at the ``home`` keyframe; object type uniform over ``object_types``, size uniform in ``size_range``,
    position uniform within +-3 cm of (-0.30, 0.03) m on the table (``position_range="canonical"``) or over the
    behaviour's workspace (``"workspace"``), yaw jittered by up to 0.25 rad (boxes and lying cylinders; a lying
    cylinder's axis stays across the tap direction). All drawn from ``self.np_random``.
    ``reset(options={...})`` may set any of them instead: ``object_type``, ``size`` [m], ``position`` (x, y) on
    the table [m], ``yaw`` [rad], or ``object_pose`` (x, y, z [m], qw, qx, qy, qz): any pose, a toppled
    standing cylinder too, from which the object settles; the behaviour then plans for the object as it rests
    (:func:`affordance_env.objects.as_resting`: a toppled cylinder is struck or gripped as a lying one). Another key
    raises ``ValueError`` listing these.

    ## Episode End
    The episode terminates after one interaction (``terminated=True``). The object is followed at every control
    tick from the start of the step, whatever the arm is doing (:mod:`affordance_env.outcome`). Once the arm is
    back home and still, the simulation goes on until the object is at rest (still for 50 ms after the first
    touch; for the grasp, after the hand opened), has left the table (detected the moment its centre crosses the
    table's edge), or ``settle_timeout`` seconds have passed since then; then the final snapshot is taken.

    ## Info
    After ``reset``: ``object`` (``type``, ``size`` [m], ``pose`` (7,) position and quaternion), ``attention``,
    ``visible`` (object seen in the initial snapshot), ``still`` (the robot was still for it).
    After ``step`` also: ``effect`` (49,) final minus initial features, ``initial_features``,
    ``final_features``, ``object`` with ``initial_pose`` and ``final_pose``, ``displacement`` [m] (horizontal
    travel of the centre on the table: to where it rests, or to where it left the table),
    ``rolling_distance`` [m] (the part of the travel covered rolling: contact point at rest, centre at constant
    height), ``rolled`` (``rolling_distance`` above ``roll_threshold``), ``success`` (the paper's success/fail
    label, one rule per behaviour: for ``tap`` and ``tap_back`` it is ``rolled``; for ``push`` the object moved,
    ``displacement`` above ``roll_threshold`` (3 cm by default), rolling or sliding; always False for a failed
    interaction, see ``failure``), ``tilt`` [rad] (how far the initially vertical body axis turned),
    ``toppled`` (tilt above 45 degrees after the centre rose over an edge), ``outcome`` (``"rest"``,
    ``"off_table"`` or ``"timeout"``), ``outcome_time`` [s] (when, after the first touch, the object came to rest
    or left the table), ``contact`` (the hand touched the object), ``hand_speed`` [m/s],
    ``ik`` (``success``, ``position_error`` [m], ``orientation_error`` [rad]), ``visible`` (object seen in the
    final snapshot),
    for the grasp only: ``success`` (the grasp held the object: at the end of the 1 s hold its centre had risen at
    least 5 cm, ``affordance_env.outcome.GRASP_LIFT_THRESHOLD``, and it touched the hand and not the table; held
    objects rise 6-9 cm, the others stay within millimetres of the table), ``grasp`` (``rise`` [m] at the end
    of the hold, ``links_holding``: names of the hand links touching the object then, ``on_table``),
    ``failure``: None, or why the interaction is not a valid sample: ``"physics: ..."`` (MuJoCo reported an
    instability or the state became non-finite; then obs is blank, ``effect`` is zeros and ``outcome`` is
    ``"fault"``), ``"snapshot: ..."`` (the robot's head or arm still moved when a snapshot was taken),
    ``"perception: ..."`` (object not visible initially), ``"ik: ..."`` (stroke or grasp not reachable),
    ``"reach: ..."`` (the arm touched the object before the stroke, or the stroke started more than 1 cm from
    its planned pose), ``"tap: ..."`` (the hand never touched the object). A grasp is invalid only for physics,
    snapshot, perception or ik: its hand meets the object on the way down, and a miss is a failed grasp
    (``success`` False), not an invalid one. The next ``reset`` recovers from any of them.

    ## Arguments

    | argument | default | meaning |
    |----------|---------|---------|
    | ``behavior`` | ``"tap"`` | ``"tap"``; ``"tap_back"`` (other side, back of hand); ``"push"`` (from the front);
      ``"grasp"`` (left arm, fingered hand; see Description) |
    | ``object_types`` | all four | types to sample from |
    | ``size_range`` | (0.04, 0.10) | object size range [m]; for the grasp it straddles the critical size (about 7 cm;
      spheres, which the fingers wrap, are held up to 10 cm, not at 11): both outcomes occur |
    | ``camera_width``, ``camera_height`` | 160, 120 | range image size [pixels] (the iCub eye camera's 4:3) |
    | ``camera_fovy`` | 57.4 | vertical field of view [deg]; the iCub eye camera's (fy = 219 px at 320 x 240) |
    | ``roll_threshold`` | 0.03 | rolling distance above which an interaction is ``rolled`` [m]; for ``push``, the
      displacement above which it is a ``success`` |
    | ``settle_timeout`` | 3.0 | longest simulated wait for the outcome after the first touch [s] |
    | ``range_noise`` | None | ``"kinect_v1"``: the axial depth noise of a structured-light camera (Nguyen, Izadi
      and Lovell 2012, :mod:`affordance_env.range_noise`), drawn from ``self.np_random``; None: exact ranges |
    | ``position_range`` | ``"canonical"`` | where objects are placed: within +-3 cm of the paper's spot, or
      ``"workspace"``: uniform over the behaviour's workspace (:mod:`affordance_env.workspace`, where its canonical
      action is within the arm's reach for every type and size), to learn how the place changes the effect |
    | ``reward_fn`` | displacement | ``callable(info) -> float`` |
    | ``render_mode`` | None | ``"rgb_array"``: a picture from an outside camera (headless EGL/OSMesa);
      ``"rgb_array_list"``: every frame of the interaction, for a video (Gymnasium's ``RecordVideo`` keeps one
      frame per step, so for one-step episodes use this mode and write the frames yourself); any other mode
      (``"human"`` too) is refused with a ValueError naming these |
    | ``two_arms`` | False | the scene with both arms (:data:`affordance_env.robot_model.VARIANTS` ``"two_arms"``):
      the other arm waits rigid at its home pose, and the relation features are measured to the right palm for every
      behaviour (the scene of ``TapAffordanceGoal-v0``) |

    ## Version History
    * v1: the iCub's motor limits (joint speeds planned within 100 deg/s for the arm, torso and neck and 180 deg/s
      for the fingers, motor torques limited, gravity compensation included), stiff contacts (10 ms, impedance
      0.995), the palm's restitution 0.3, every move one minimum-jerk or line trajectory with feedforward, the
      hardest strokes capped at the speed the joints allow (``info["stroke_speed"]``), a home pose that holds the
      forearm 15 cm above the table, a way home that watches the object (a touch is a failure, ``"home: ..."``), and
      a careful grasp: a slow guarded descent, fingers that close with a light touch and grip with their motors'
      torque, a held object put down at rest, an unheld one left where it is. Data of v0 are not comparable.
    * v0: initial release.
    """

    metadata = {"render_modes": ["rgb_array", "rgb_array_list"], "render_fps": 30,
                # one interaction per episode: a vector env resets it within the step that ends it
                "autoreset_mode": gym.vector.AutoresetMode.SAME_STEP}

    def __init__(
        self,
        behavior: str = EnvOptions.behavior,
        object_types: Sequence[str] = EnvOptions.object_types,
        size_range: tuple[float, float] = EnvOptions.size_range,
        camera_width: int = EnvOptions.camera_width,
        camera_height: int = EnvOptions.camera_height,
        camera_fovy: float = EnvOptions.camera_fovy,
        roll_threshold: float = EnvOptions.roll_threshold,
        settle_timeout: float = EnvOptions.settle_timeout,
        range_noise: str | None = EnvOptions.range_noise,
        position_range: str = EnvOptions.position_range,
        reward_fn: Callable[[dict[str, Any]], float] | None = None,
        render_mode: str | None = None,
        render_width: int = 480,
        render_height: int = 360,
        two_arms: bool = False,
    ) -> None:
        options = EnvOptions(behavior=behavior, object_types=object_types, size_range=size_range,
                             camera_width=camera_width, camera_height=camera_height, camera_fovy=camera_fovy,
                             roll_threshold=roll_threshold, settle_timeout=settle_timeout,
                             range_noise=range_noise, position_range=position_range)  # checked and normalised
        self._check_render_mode(render_mode)
        #: The interaction of the behaviour (:mod:`affordance_env.interactions`).
        self.interaction = get_interaction(options.behavior)
        self.behavior = self.interaction.behavior
        self.object_types = options.object_types
        self.size_range = options.size_range
        self.roll_threshold = options.roll_threshold
        self.range_noise = options.range_noise
        self.position_range = options.position_range
        self.settle_timeout = options.settle_timeout
        self.reward_fn = default_reward if reward_fn is None else reward_fn
        self.render_mode = render_mode

        # The behaviour's arm; with two_arms, in the scene with both arms (the other one held at home).
        robot = {"tap": "two_arms", "grasp": "two_arms_left"}[self.behavior.robot] if two_arms else self.behavior.robot
        self.physics = TapPhysics(build_model(robot), robot)
        self.kinematics = Kinematics(variant=robot)
        self.motion = MotionExecutor(self.physics, self.kinematics)
        self.camera = RangeCamera(self.physics.model, width=camera_width, height=camera_height, fovy_deg=camera_fovy,
                                  support="table_top")
        self.attention_camera = RangeCamera(self.physics.model, width=40, height=30, fovy_deg=camera_fovy,
                                            support="table_top")
        posture = self.interaction.prepare(self.motion, PLACEMENT_CENTRE, float(np.mean(self.size_range)))
        #: The approach posture of each behaviour prepared (see :meth:`prepare_behaviors`).
        self._postures = {self.behavior.name: posture}
        self._renderer = None
        self._render_size = (render_width, render_height)
        #: With a render mode: pictures taken every 1/render_fps s of simulated time since the last ``reset``
        #: (the whole interaction: placing, attention, the behaviour, the wait for the outcome).
        self.frames: list[np.ndarray] = []
        #: Where the last snapshot saw the object on the table: the centre (x, y) [m] of its top, the visible points
        #: within TOP_DEPTH of its highest one (NaN when not seen). Every object's top lies over its centre.
        self.seen_position = np.full(2, np.nan)
        self._next_frame_time = 0.0
        if render_mode is not None:
            self.physics.on_step = self._record_frame

        H, W = camera_height, camera_width
        nq = self.kinematics.nq
        self.observation_space = spaces.Dict(
            {
                "range": spaces.Box(0.0, self.camera.max_range, (H, W), np.float32),
                "mask": spaces.Box(0, 1, (H, W), np.int8),
                "features": spaces.Box(-np.inf, np.inf, (len(FEATURE_NAMES),), np.float32),
                "joints": spaces.Box(
                    self.kinematics.lower.astype(np.float32) - 0.05,
                    self.kinematics.upper.astype(np.float32) + 0.05,
                    (nq,),
                    np.float32,
                ),
            }
        )
        self.action_space = spaces.Box(-1.0, 1.0, (ACTION_DIM,), np.float32)
        self._initial: InitialSnapshot | None = None
        self._q_home = np.zeros(nq)

    @classmethod
    def _check_render_mode(cls, render_mode: str | None) -> None:
        if render_mode not in (None, *cls.metadata["render_modes"]):
            raise InvalidValueError(f"render_mode must be None or one of {cls.metadata['render_modes']}, got "
                             f"{render_mode!r}.")

    def _blank_observation(self) -> dict[str, np.ndarray]:
        space = self.observation_space
        return {
            "range": np.zeros(space["range"].shape, np.float32),
            "mask": np.zeros(space["mask"].shape, np.int8),
            "features": NOT_VISIBLE_VALUES.astype(np.float32),
            "joints": np.clip(self._q_home, space["joints"].low, space["joints"].high).astype(np.float32),
        }

    def _snapshot(self) -> tuple[dict[str, np.ndarray], Any]:
        image = self.camera.capture(self.physics.data, normals=self.range_noise is not None,
                                    occluded=self.physics.active_geom)
        if self.range_noise is not None:
            image = add_kinect_noise(image, self.np_random)
        mask = image.mask_of(self.physics.active_geom)
        p_world_hand = self.physics.hand_position()
        uv_hand = image.project(p_world_hand)
        if not np.all(np.isfinite(uv_hand)):  # hand behind the camera: no image position; use the image centre
            uv_hand = np.array([image.intrinsics.cx, image.intrinsics.cy])
        features = compute_features(
            image.p_world_points, image.ranges, mask, image.p_world_camera, p_world_hand, uv_hand
        )
        points = image.p_world_points[mask]
        top = points[points[:, 2] >= points[:, 2].max() - TOP_DEPTH] if len(points) else points
        self.seen_position = top[:, :2].mean(axis=0) if len(top) else np.full(2, np.nan)
        ranges = np.where(np.isfinite(image.ranges), image.ranges, 0.0).astype(np.float32)
        obs = {
            "range": ranges,
            "mask": mask.astype(np.int8),
            "features": features.values.astype(np.float32),
            "joints": self.physics.joint_positions().astype(np.float32),
        }
        return obs, features

    def _sample_object(self, options: dict[str, Any] | None
                       ) -> tuple[str, float, np.ndarray, float, np.ndarray | None]:
        """Type, size, position and yaw of the next object: drawn from ``self.np_random``, then replaced by any
        given in ``options`` (the draws are made either way, so the rest of the episode's randomness is the same)."""
        rng = self.np_random
        object_type = self.object_types[int(rng.integers(len(self.object_types)))]
        size = float(rng.uniform(*self.size_range))
        xy = PLACEMENT_CENTRE + rng.uniform(-1.0, 1.0, 2) * PLACEMENT_HALF_WIDTH
        yaw = float(rng.uniform(-YAW_JITTER, YAW_JITTER))
        if self.position_range == "workspace":
            xy = sample_in_workspace(self.behavior.name, rng)
        if options is not None and not isinstance(options, Mapping):
            raise InvalidValueError(f"options must be a dict with keys among {RESET_OPTIONS}, got {options!r}.")
        options = dict(options or {})
        unknown = sorted(set(options) - set(RESET_OPTIONS))
        if unknown:
            raise InvalidValueError(f"Unknown reset option(s) {unknown}. Valid options: {', '.join(RESET_OPTIONS)}.")
        if "object_type" in options:
            object_type = check_object_type(options["object_type"])
        if "size" in options:
            try:
                size = check_size(options["size"])
            except ValueError as exc:
                raise InvalidValueError(f"reset option 'size': {exc}") from None
        if object_type in ("sphere", "vertical_cylinder"):
            yaw = 0.0
        if "position" in options:
            xy = np.asarray(options["position"], dtype=np.float64)
            low, high = self.physics.table_extent()
            if xy.shape != (2,) or not np.all(np.isfinite(xy)) or np.any(xy < low) or np.any(xy > high):
                raise InvalidValueError(
                    f"position must be (x, y) on the table top, x in [{low[0]:.2f}, {high[0]:.2f}] and "
                                 f"y in [{low[1]:.2f}, {high[1]:.2f}] m, got {options['position']!r}.")
        if "yaw" in options:
            real = isinstance(options["yaw"], numbers.Real) and not isinstance(options["yaw"], bool)
            yaw = float(options["yaw"]) if real else float("nan")
            if not np.isfinite(yaw):
                raise InvalidValueError(f"yaw must be a finite angle [rad], got {options['yaw']!r}.")
        pose = None
        if "object_pose" in options:
            if "position" in options or "yaw" in options:
                raise InvalidValueError(
                    "reset options 'object_pose' and 'position' or 'yaw' exclude each other: the pose "
                                 "gives both.")
            pose = self._check_pose(options["object_pose"], object_geometry(object_type, size))
        return object_type, size, xy, yaw, pose

    def _check_pose(self, value: Any, geometry: Any) -> np.ndarray:
        try:
            pose = np.asarray(value, dtype=np.float64)
        except (TypeError, ValueError):
            pose = np.full(1, np.nan)
        low, high = self.physics.table_extent()
        top = self.physics.table_top
        ok = pose.shape == (7,) and bool(np.all(np.isfinite(pose)))
        if ok:
            ok = (bool(np.all(pose[:2] >= low) and np.all(pose[:2] <= high))
                  and top + 0.5 * geometry.half_height <= pose[2] <= top + 3.0 * geometry.rbound
                  and norm(pose[3:]) > 1e-6)
        if not ok:
            raise InvalidValueError(
                f"object_pose must be (x, y, z, qw, qx, qy, qz): x in [{low[0]:.2f}, {high[0]:.2f}] and "
                             f"y in [{low[1]:.2f}, {high[1]:.2f}] m on the table, z [m] the object's centre above the "
                             f"table top ({top:.3f} m) by {0.5 * geometry.half_height:.3f} to "
                             f"{3.0 * geometry.rbound:.3f} m, and a non-zero quaternion; got {value!r}.")
        pose[3:] /= norm(pose[3:])
        return pose

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        """Place a new object, let it settle, attend to it and take the initial snapshot.

        ``options`` may choose the object instead of drawing it: ``object_type`` (one of
        ``affordance_env.OBJECT_TYPES``), ``size`` [m], ``position`` (x, y) on the table [m] and ``yaw`` [rad].
        """
        super().reset(seed=seed)
        object_type, size, xy, yaw, pose = self._sample_object(options)
        self.frames = []
        self._next_frame_time = 0.0
        physics = self.physics
        physics.reset_home()
        self._q_home = physics.joint_targets()
        geometry = object_geometry(object_type, size)
        physics.set_object(geometry, xy, yaw)  # 0.1 mm above the table: it settles while the head turns
        if pose is not None:  # any pose: it settles too, and the plan reads its geometry from where it rests
            physics.set_object_pose(pose)
        return self._observe(None if pose is not None else (geometry, yaw))

    def _observe(self, plan_geometry: tuple[Any, float] | None = None) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        """Attend to the object where it is, wait until the robot (and the object) are still, and take the initial
        snapshot. ``plan_geometry``: the geometry and yaw the interaction plans for; None: read from how the
        object rests (a toppled cylinder lies)."""
        physics = self.physics
        with self.interaction.free_stepping(self.motion):
            attention = attend(physics, self.attention_camera, self.motion.move_joints)
            still = self.motion.hold_still(also=_object_still)
        self._q_home = physics.joint_targets()  # the arm's home, with the gaze on the object
        obs, features = self._snapshot()
        pose = physics.object_pose()
        geometry, yaw = as_resting(physics.geometry, pose[3:]) if plan_geometry is None else plan_geometry
        seen = pose.copy()
        seen.flags.writeable = False
        self._initial = InitialSnapshot(features, seen, yaw, geometry, features.visible, still)
        info = {
            "object": {"type": physics.geometry.object_type, "size": physics.geometry.size, "pose": pose.copy()},
            "attention": {"success": attention.success, "visible": attention.visible,
                          "pixel_error": attention.pixel_error},
            "visible": features.visible,
            "still": still,
        }
        return obs, info

    def prepare_behaviors(self, names: Sequence[str]) -> None:
        """Make the env able to run the behaviours ``names`` too (:meth:`use_behavior`): those of the same arm.
        Call it before ``reset``: it puts the robot at home."""
        for name in names:
            interaction = get_interaction(name)
            if interaction.behavior.robot != self.behavior.robot:
                raise InvalidValueError(
                    f"behavior {name!r} needs the {interaction.behavior.robot!r} arm; this env has the "
                                 f"{self.behavior.robot!r} arm.")
            if name not in self._postures:
                self._postures[name] = interaction.prepare(self.motion, PLACEMENT_CENTRE,
                                                           float(np.mean(self.size_range)))

    def use_behavior(self, name: str) -> None:
        """Run the behaviour ``name`` (prepared by :meth:`prepare_behaviors`) from the next ``step`` on."""
        if name not in self._postures:
            raise InvalidValueError(
                f"behavior {name!r} is not prepared in this env; prepared: {', '.join(self._postures)}.")
        self.interaction = get_interaction(name)
        self.behavior = self.interaction.behavior

    @property
    def approach_posture(self) -> np.ndarray | None:
        """The arm posture the IK of the current behaviour's approaches starts from (its interaction's
        ``prepare``); None: the current servo targets."""
        return self._postures[self.behavior.name]

    def observe(self) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        """Look at the object again where it is now, without placing a new one: attend to it, wait until the robot
        and the object are still and take the initial snapshot of the next ``step``. Returns ``(obs, info)`` as
        ``reset`` does (TapAffordanceGoal-v0 calls it after every interaction: the object stays)."""
        return self._observe()

    def take_over(self, other: TapAffordanceEnv) -> None:
        """Continue the world of ``other``, an env of the same scene with another arm acting
        (:meth:`TapPhysics.adopt <affordance_env.physics.TapPhysics.adopt>`: the object's state bit for bit, the
        shared joints', the time), and its initial snapshot: the next ``step`` here acts on what ``other`` saw;
        ``other`` needs a ``reset`` or a ``take_over`` before its next ``step``."""
        self.physics.adopt(other.physics)
        self._q_home = self.physics.joint_targets()
        self._initial, other._initial = other._initial, None

    def forget(self) -> None:
        """Forget the object: the next ``step`` needs a ``reset`` (or :meth:`take_over`) first."""
        self._initial = None

    def feasible(self, params: Any, behavior: str | None = None, seen_by: TapAffordanceEnv | None = None) -> bool:
        """Whether the arm can reach every pose of the interaction with ``params`` (``behavior``, one prepared in
        this env, by default the current one) on the object where the last snapshot saw it (of ``seen_by``, an env
        of the same scene, if given: this env then takes over its world, as :meth:`take_over` would), from the
        kinematics alone: no physics step. False: ``step`` would fail with ``"ik: ..."``, or a stroke's reach would
        sweep the arm into the object (``"reach: ..."``)."""
        a = check_action(params)
        name = self.behavior.name if behavior is None else behavior
        if name not in self._postures:
            raise InvalidValueError(
                f"behavior {name!r} is not prepared in this env; prepared: {', '.join(self._postures)}.")
        initial = (self if seen_by is None else seen_by)._initial
        if initial is None:
            raise RuntimeError("feasible() needs an object: call reset() first.")
        if seen_by is not None and seen_by is not self:  # the world as it is, as a take_over would continue it
            self.physics.adopt(seen_by.physics)
        interaction = get_interaction(name)
        plan = interaction.plan(initial.geometry, initial.pose[:3], initial.yaw, self.physics.table_top, a)
        return bool(interaction.reachable(self.motion, plan, self._postures[name]))

    def get_state(self) -> EnvState:
        """A snapshot of the world and of the episode: the object and MuJoCo's state, what the initial snapshot
        saw, and the env's random generator. :meth:`set_state` puts it back; the same action then gives the same
        interaction, bit for bit (an oracle that tries several actions from one state does not replay the reset)."""
        initial = self._initial  # frozen: shared, not copied
        return EnvState(self.physics.get_state(), initial, self._q_home.copy(),
                        copy.deepcopy(self.np_random.bit_generator.state), self.physics.variant.name,
                        self.behavior.name)

    def set_state(self, state: EnvState) -> None:
        """Put back the world and the episode as :meth:`get_state` saw them. The state must come from an env of
        the same robot model (ValueError otherwise): ``behavior="grasp"`` builds another model than the tap,
        tap back and push, and ``two_arms=True`` another again."""
        if not isinstance(state, EnvState):
            raise TypeError(f"state must be what get_state() returned (an EnvState), got {type(state).__name__}.")
        if state.robot != self.physics.variant.name:
            raise IncompatibleStateError(
                f"the state was made by an env of behavior {state.behavior!r} with the {state.robot!r} "
                             f"robot model; this env (behavior {self.behavior.name!r}) has the "
                             f"{self.physics.variant.name!r} robot model: a state restores only into an env of the "
                             "same robot model.")
        self.physics.set_state(state.physics)
        self._initial = state.initial
        self._q_home = state.q_home.copy()
        self.np_random.bit_generator.state = copy.deepcopy(state.rng)

    def _wait_outcome(self, monitor: ObjectMonitor, since: float) -> tuple[str, float]:
        """Simulate until the object has left the table, has been at rest since ``since`` [s] or later, or
        ``settle_timeout`` has passed since ``since``; the monitor has followed it all along.

        Returns the outcome and when it happened, in seconds after ``since``: the moment the object left the
        table, or the moment it had been still for ``REST_DURATION``, which may lie before the arm was back.
        """
        physics = self.physics
        t_end = since + self.settle_timeout
        steps_per_tick = self.motion.steps_per_tick
        while True:
            if monitor.left_table:
                return "off_table", monitor.exit_time - since
            if monitor.at_rest(physics.data.time, since):
                return "rest", max(monitor.still_since, since) + REST_DURATION - since
            if physics.data.time >= t_end - 1e-9:
                return "timeout", self.settle_timeout
            physics.step(steps_per_tick)

    def step(self, action):
        """Execute the behaviour with ``action`` and take the final snapshot; the episode then terminates."""
        if self._initial is None:
            raise RuntimeError("step() called before reset() or after the interaction ended; call reset() first.")
        action = check_action(action)
        initial, self._initial = self._initial, None
        physics = self.physics
        interaction = self.interaction
        plan = interaction.plan(initial.geometry, initial.pose[:3], initial.yaw, physics.table_top, action)
        monitor = physics.start_monitor()  # from now on, whatever the arm does
        try:
            done = interaction.execute(self.motion, plan, self._postures[self.behavior.name])
            with interaction.free_stepping(self.motion):
                home = self.motion.go_home(self._q_home, via=interaction.via_home(done))
                since = interaction.awaited_since(done, float(physics.data.time))
                outcome, outcome_time = self._wait_outcome(monitor, since)
        finally:
            physics.monitor = None
        if self.render_mode is not None:
            self.frames.append(self._picture())  # the scene as the final snapshot sees it
        fault = physics.unstable()
        if fault is None:
            obs, features = self._snapshot()
            final_features = features.values
            final_pose = physics.object_pose()
            visible = features.visible
        else:  # the state is not to be trusted: nothing of it reaches obs or info
            obs = self._blank_observation()
            final_features = NOT_VISIBLE_VALUES.copy()
            final_pose = np.full(7, np.nan)
            visible = False
        failure = _failure_reason(fault, initial.visible, done, (initial.still, home.still), home.touched,
                                  interaction)
        # Travel on the table: to where the object rests, or to where it left the table (not where it fell).
        p_end = monitor.exit_position if monitor.left_table else final_pose
        displacement = 0.0 if fault else norm(p_end[:2] - initial.pose[:2])
        labels = None if fault else outcome_labels(monitor, initial.pose[3:], final_pose[3:],
                                                   self.roll_threshold)
        effect = (
            np.zeros(len(FEATURE_NAMES), np.float32)
            if fault
            else effect_features(initial.features.values, final_features)
        )
        # The success label: a failed interaction is no sample, so no success either.
        success = failure is None and labels is not None and interaction.success(done, labels, displacement,
                                                                                 self.roll_threshold)
        info = {
            "object": {"type": initial.geometry.object_type, "size": initial.geometry.size,
                       "initial_pose": initial.pose.copy(), "final_pose": final_pose},
            "initial_features": initial.features.values.copy(),  # fresh: a restored state steps again
            "final_features": final_features,
            "effect": effect,
            "displacement": displacement,
            "rolling_distance": 0.0 if fault else monitor.rolling_distance,
            "rolled": labels is not None and labels.rolled,
            "success": bool(success),
            "toppled": labels is not None and labels.toppled,
            "tilt": 0.0 if fault else labels.tilt,
            "outcome": "fault" if fault else outcome,
            "outcome_time": 0.0 if fault else float(outcome_time),
            "contact": done.contact,
            "hand_speed": done.hand_speed,
            "ik": {"success": done.ik_success, "position_error": done.ik_position_error,
                   "orientation_error": done.ik_orientation_error},
            "visible": visible,
            "behavior": self.behavior.name,
            "failure": failure,
            **interaction.info(done),
        }
        reward = float(self.reward_fn(info))
        return obs, reward, True, False, info

    def _record_frame(self, physics: TapPhysics) -> None:
        if physics.data.time >= self._next_frame_time - 1e-9:
            self.frames.append(self._picture())
            period = 1.0 / self.metadata["render_fps"]
            while self._next_frame_time <= physics.data.time + 1e-9:  # keep the clock: one frame per period
                self._next_frame_time += period

    def _picture(self) -> np.ndarray:
        if self._renderer is None:
            from affordance_env.rendering import SceneRenderer

            self._renderer = SceneRenderer(self.physics.model, *self._render_size)
        return self._renderer.render(self.physics.data)

    def render(self):
        """Pictures of the scene from the ``overview`` camera, (H, W, 3) uint8, headless.

        ``render_mode="rgb_array"``: the picture of the current state. ``"rgb_array_list"``: every picture taken
        since the last ``reset`` or ``render`` call (at ``render_fps`` of simulated time: a whole interaction is
        some 90 of them), as Gymnasium's ``rgb_array_list`` convention has it; the list is then emptied. None
        without a render mode.
        """
        if self.render_mode == "rgb_array":
            return self._picture()
        if self.render_mode == "rgb_array_list":
            frames, self.frames = self.frames, []
            return frames
        return None

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


__all__ = ["TapAffordanceEnv", "EnvState", "InitialSnapshot", "default_reward", "BEHAVIORS"]
