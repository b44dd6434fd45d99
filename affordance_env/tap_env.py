"""TapAffordance-v2: one interaction of Akgun et al. (2009) per step."""

from __future__ import annotations

import copy
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from affordance_env.behaviors import ACTION_DIM, get_behavior
from affordance_env.camera import RangeCamera
from affordance_env.exceptions import InvalidValueError
from affordance_env.features import FEATURE_NAMES
from affordance_env.kinematics import Kinematics
from affordance_env.motion import MotionExecutor
from affordance_env.options import EnvOptions
from affordance_env.physics import TapPhysics
from affordance_env.placement import (
    PLACEMENT_CENTRE,
    PLACEMENT_HALF_WIDTH,
    RESET_OPTIONS,
    YAW_JITTER,
    draw_placement,
)
from affordance_env.results import InteractionResult, Snapshot
from affordance_env.values import restore_with_generator
from affordance_env.world import World, WorldState


@dataclass(frozen=True)
class EnvState:
    """A snapshot of :class:`TapAffordanceEnv` (:meth:`~TapAffordanceEnv.get_state`): treat it as opaque.

    Attributes:
        world: The world's state (:meth:`World.get_state <affordance_env.world.World.get_state>`).
        rng: The state of the env's random generator.
    """

    world: WorldState
    rng: dict[str, Any]


def default_reward(info: dict[str, Any]) -> float:
    """The object's displacement on the table [m]: how much the interaction changed the world."""
    return float(info["displacement"])


def observation(snapshot: Snapshot) -> dict[str, np.ndarray]:
    """TapAffordance-v2's observation of a snapshot (fresh arrays)."""
    return {"range": snapshot.ranges.copy(), "mask": snapshot.mask.copy(),
            "features": snapshot.features.values.astype(np.float32), "joints": snapshot.joints.copy()}


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
    object, then grip with their motors' full torque; the hand lifts 8 cm and holds still for 1 s. There the
    paper's grasp ends, and so the final snapshot is taken at the end of the hold: "An environmental snapshot is
    taken... Afterwards a behavior is executed. When the execution ends, another snapshot is taken" (Akgun et al.
    2009). It sees a held object lifted in the hand, the fingers in front of part of it, and an object the hand did
    not hold where the attempt left it (a median 1-2 cm from where it stood); ``object.final_pose``,
    ``displacement`` and ``tilt`` are measured then too. The world then goes on as a robot's would: a held object is
    carried 6 cm to the robot's left and lowered slowly until it meets the table; once it rests there the hand
    opens, rises straight up and goes home; an object the hand does not hold is left where it is, the hand opening
    above it (``outcome`` and ``outcome_time`` say how the object came to rest afterwards). Only the fingers'
    motors move the object (no welds, no applied forces). Whether the object fits the open hand, between the thumb
    and the fingertips, decides the outcome (``info["success"]``): nearly all small objects are held, few large ones
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

    For ``behavior="draw"``, 0 is the canonical draw (:mod:`affordance_env.behaviors.draw`):

    | index | meaning | range |
    |-------|---------|-------|
    | 0 | lateral offset of the line, across the draw direction (+y) | -2 .. +2 cm |
    | 1 | drag length: where the palm stops, past the object's centre toward the robot | -2 .. +6 cm |
    | 2 | hand speed along the line, 0.08 x 2 ** a m/s, at most what the joints' speed limits allow | 0.04 .. 0.16 m/s |

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
    table's edge; in the grasp's closed hand, once it is let go beyond the edge or its centre drops below the
    top), or ``settle_timeout`` seconds have passed since then; then the final snapshot is taken.

    ## Info
    The step's ``info`` is made from the typed result of its interaction
    (:class:`~affordance_env.results.InteractionResult`), which ``env.unwrapped.last_result`` gives; the world the
    env adapts to Gymnasium is ``env.unwrapped.world`` (:class:`~affordance_env.world.World`).
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
    its planned pose), ``"tap: ..."`` or ``"draw: ..."`` (the hand never touched the object). A grasp is invalid
    only for physics, snapshot, perception or ik: its hand meets the object on the way down, and a miss is a
    failed grasp (``success`` False), not an invalid one. The next ``reset`` recovers from any of them.

    ## Arguments

    | argument | default | meaning |
    |----------|---------|---------|
    | ``behavior`` | ``"tap"`` | ``"tap"``; ``"tap_back"`` (other side, back of hand); ``"push"`` (from the front);
      ``"draw"`` (from behind, toward the robot: :mod:`affordance_env.behaviors.draw`); ``"grasp"`` (left arm,
      fingered hand; see Description) |
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
    | ``render_mode`` | None | ``"rgb_array"``: a picture from an outside camera (headless EGL/OSMesa), drawn
      only when ``render()`` is called; ``"rgb_array_list"``: every frame of the interaction, for a video
      (Gymnasium's ``RecordVideo`` keeps one frame per step, so for one-step episodes use this mode and write the
      frames yourself); any other mode (``"human"`` too) is refused with a ValueError naming these. Pictures cost
      far more than the simulation: without a GPU (Mesa's llvmpipe through EGL, 2 cores) a 480 x 360 picture took
      0.58 s of CPU time, and an interaction with ``"rgb_array_list"`` (72 pictures for the canonical tap of seed
      0) 39 s against 0.03 s without a render mode (``python benchmarks/render_frames.py --timed 2``) |
    | ``render_width``, ``render_height`` | 480, 360 | size of those pictures [pixels]; without a GPU a smaller one
      costs nearly as much (measured as above: 0.44 s of CPU time at 240 x 180, 0.40 s at 40 x 30) |
    | ``two_arms`` | False | the scene with both arms (:data:`affordance_env.robot_model.VARIANTS` ``"two_arms"``):
      the other arm waits rigid at its home pose, and the relation features are measured to the right palm for every
      behaviour (the scene of ``TapAffordanceGoal-v2``) |

    ## Version History
    * v2: ``behavior="draw"`` is offered too (the other behaviours' interactions do not change with it). The
      grasp's final snapshot is taken where the paper's grasp ends, at the end of its hold with the object held
      (Akgun et al. 2009: "When the execution ends, another snapshot is taken"), not after the put-down that only a
      world that goes on needs (``TapAffordanceGoal-v2`` still puts the object down before its snapshot).
      Every motor has its torque-speed curve (its torque falls along its back-EMF line to zero at its no-load
      speed, ``affordance_env.motor_limits.JOINT_TORQUE_SPEED``; the wrist's pitch and yaw motors give 0.94 N m,
      not 2), and the hand's controller keeps each finger's target within its servo's reach of the finger, so a
      finger that loses the object never outruns its limit; the put-down is slower (2 cm/s). Data of v1 are not
      comparable. Fixed since its first release: an object the hand holds over the table's edge has not left the
      table (a grasp's ``outcome`` was ``"off_table"`` for an object within a centimetre of the near edge). With
      ``two_arms=True`` the grasp's inverse kinematics keeps the torso within
      ``affordance_env.robot_model.HELD_ARM_TORSO_RANGES``: further, it leaned onto the held right arm.
      ``feasible`` refuses a stroke or draw whose reach brings the arm's targets within 2 mm of the object (it
      allowed 0 mm, and the arm, a millimetre or two behind its targets, sometimes touched the object on the way
      down); the interactions are unchanged.
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
        two_arms: bool = EnvOptions.two_arms,
    ) -> None:
        options = EnvOptions(behavior=behavior, object_types=object_types, size_range=size_range,
                             camera_width=camera_width, camera_height=camera_height, camera_fovy=camera_fovy,
                             roll_threshold=roll_threshold, settle_timeout=settle_timeout,
                             range_noise=range_noise, position_range=position_range,
                             two_arms=two_arms)  # checked and normalised
        if render_mode not in (None, *self.metadata["render_modes"]):
            raise InvalidValueError(f"render_mode must be None or one of {self.metadata['render_modes']}, got "
                                    f"{render_mode!r}.")
        #: The data options, checked (:class:`~affordance_env.options.EnvOptions`).
        self.options = options
        #: The behaviour each step runs (:mod:`affordance_env.behaviors`).
        self.behavior = get_behavior(options.behavior)
        if reward_fn is not None and not callable(reward_fn):
            raise InvalidValueError(f"reward_fn must be a function of the step's info returning a number, got "
                                    f"{reward_fn!r}.")
        self.reward_fn = default_reward if reward_fn is None else reward_fn
        self.render_mode = render_mode
        #: The world the behaviour acts in: the robot, the table, the object, the camera.
        self.world = World((options.behavior,), two_arms=options.two_arms, camera_width=options.camera_width,
                           camera_height=options.camera_height, camera_fovy=options.camera_fovy,
                           range_noise=options.range_noise, roll_threshold=options.roll_threshold,
                           settle_timeout=options.settle_timeout, typical_size=float(np.mean(options.size_range)),
                           final_snapshot="paper")
        self._render_size = (render_width, render_height)
        #: With ``render_mode="rgb_array_list"``: pictures taken every 1/render_fps s of simulated time since the
        #: last ``reset`` (the whole interaction: placing, attention, the behaviour, the wait for the outcome).
        #: ``"rgb_array"`` draws only when :meth:`render` is called, so its steps cost what they cost without one.
        self.frames: list[np.ndarray] = []
        self._next_frame_time = 0.0
        if render_mode == "rgb_array_list":
            self.world.on_step(self._record_frame)
        self._last: InteractionResult | None = None

        H, W = options.camera_height, options.camera_width
        kinematics = self.world.kinematics()
        self.observation_space = spaces.Dict({
            "range": spaces.Box(0.0, self.world.camera.max_range, (H, W), np.float32),
            "mask": spaces.Box(0, 1, (H, W), np.int8),
            "features": spaces.Box(-np.inf, np.inf, (len(FEATURE_NAMES),), np.float32),
            "joints": spaces.Box(kinematics.lower.astype(np.float32) - 0.05,
                                 kinematics.upper.astype(np.float32) + 0.05, (kinematics.nq,), np.float32),
        })
        self.action_space = spaces.Box(-1.0, 1.0, (ACTION_DIM,), np.float32)

    # --- views into the world, for inspection ---------------------------------------------------------------------
    @property
    def physics(self) -> TapPhysics:
        """The world's physics (:class:`~affordance_env.physics.TapPhysics`)."""
        return self.world.physics

    @property
    def camera(self) -> RangeCamera:
        """The range camera in the head."""
        return self.world.camera

    @property
    def kinematics(self) -> Kinematics:
        """The arm's kinematics."""
        return self.world.kinematics()

    @property
    def motion(self) -> MotionExecutor:
        """The arm's motion executor."""
        return self.world.motion

    @property
    def last_result(self) -> InteractionResult | None:
        """The typed result of the last ``step`` (None before the first): what ``info`` is made from."""
        return self._last

    # --- Gymnasium ------------------------------------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        """Place a new object, let it settle, attend to it and take the initial snapshot.

        ``options`` may choose the object instead of drawing it (:data:`~affordance_env.placement.RESET_OPTIONS`):
        ``object_type``, ``size`` [m], ``position`` (x, y) on the table [m], ``yaw`` [rad] or ``object_pose``.
        """
        super().reset(seed=seed)
        o = self.options
        workspace = o.behavior if o.position_range == "workspace" else None
        placement = draw_placement(self.np_random, options, o.object_types, o.size_range, self.world.table, workspace)
        self.frames = []
        self._next_frame_time = 0.0
        seen = self.world.place(placement, self.np_random)
        return observation(seen.snapshot), seen.info()

    def step(self, action):
        """Execute the behaviour with ``action`` and take the final snapshot; the episode then terminates."""
        if self.world.seen is None:
            raise RuntimeError("step() called before reset() or after the interaction ended; call reset() first.")
        result = self._last = self.world.interact(self.behavior.name, action, self.np_random)
        if self.render_mode == "rgb_array_list":
            self.frames.append(self._picture())  # the scene as the final snapshot sees it
        if result.final is None:  # a fault: nothing of the state reaches obs
            obs = observation(self.world.blank_snapshot())
            space = self.observation_space["joints"]
            obs["joints"] = np.clip(obs["joints"], space.low, space.high).astype(np.float32)
        else:
            obs = observation(result.final)
        info = result.info()
        reward = self.reward_fn(info)
        try:
            reward = float(reward)
        except (TypeError, ValueError):
            raise InvalidValueError(f"reward_fn must return a number, returned {reward!r}.") from None
        return obs, reward, True, False, info

    def feasible(self, params: Any) -> bool:
        """Whether the arm can reach every pose of the interaction with ``params`` on the object where the last
        snapshot saw it, from the kinematics alone (:meth:`World.feasible <affordance_env.world.World.feasible>`)."""
        return self.world.feasible(self.behavior.name, params)

    def get_state(self) -> EnvState:
        """A snapshot of the world and of the episode, and the env's random generator. :meth:`set_state` puts it
        back; the same action then gives the same interaction, bit for bit (an oracle that tries several actions
        from one state does not replay the reset)."""
        return EnvState(self.world.get_state(), copy.deepcopy(self.np_random.bit_generator.state))

    def set_state(self, state: EnvState) -> None:
        """Put back the world and the episode as :meth:`get_state` saw them. The state must come from an env of
        the same robot model (IncompatibleStateError, a ValueError, otherwise): ``behavior="grasp"`` builds
        another model than the tap, tap back and push, and ``two_arms=True`` another again."""
        if not isinstance(state, EnvState):
            raise TypeError(f"state must be what get_state() returned (an EnvState), got {type(state).__name__}.")
        # the generator's state checked first: a damaged one restores nothing
        restore_with_generator(self.np_random, state.rng, lambda: self.world.set_state(state.world))

    def _record_frame(self, time: float) -> None:
        if time >= self._next_frame_time - 1e-9:
            self.frames.append(self._picture())
            period = 1.0 / self.metadata["render_fps"]
            while self._next_frame_time <= time + 1e-9:  # keep the clock: one frame per period
                self._next_frame_time += period

    def _picture(self) -> np.ndarray:
        return self.world.picture(*self._render_size)

    def render(self):
        """Pictures of the scene from the ``overview`` camera, (H, W, 3) uint8, headless.

        ``render_mode="rgb_array"``: the picture of the current state. ``"rgb_array_list"``: every picture taken
        since the last ``reset`` or ``render`` call (at ``render_fps`` of simulated time: a canonical tap is 66-104
        of them), as Gymnasium's ``rgb_array_list`` convention has it; the list is then emptied. None
        without a render mode.
        """
        if self.render_mode == "rgb_array":
            return self._picture()
        if self.render_mode == "rgb_array_list":
            frames, self.frames = self.frames, []
            return frames
        return None

    def close(self) -> None:
        self.world.close()


__all__ = ["TapAffordanceEnv", "EnvState", "default_reward", "observation", "PLACEMENT_CENTRE",
           "PLACEMENT_HALF_WIDTH", "RESET_OPTIONS", "YAW_JITTER"]
