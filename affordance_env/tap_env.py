"""TapAffordance-v0: one interaction of Akgun et al. (2009) per step."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import gymnasium as gym
import mujoco
import numpy as np
from gymnasium import spaces

from affordance_env.attention import attend
from affordance_env.behaviors import ACTION_DIM, BEHAVIORS, check_action, get_behavior, plan_stroke
from affordance_env.camera import RangeCamera
from affordance_env.features import FEATURE_NAMES, NOT_VISIBLE_VALUES, compute_features
from affordance_env.kinematics import Kinematics
from affordance_env.motion import CONTROL_DT, MotionExecutor
from affordance_env.objects import OBJECT_TYPES, check_object_type, check_size, object_geometry
from affordance_env.physics import TapPhysics
from affordance_env.robot_model import ACTIVE_JOINTS
from affordance_env.scene import build_model

#: Region of the table where objects are placed: centre (x, y) and half-widths [m].
PLACEMENT_CENTRE = np.array([-0.30, 0.03])
PLACEMENT_HALF_WIDTH = np.array([0.03, 0.03])
#: Yaw jitter of boxes and lying cylinders [rad].
YAW_JITTER = 0.25
#: Longest time the object is given to settle after placement [s].
SETTLE_TIME = 0.5
#: The hand may start the stroke at most this far from the planned pre-stroke pose [m], and may have moved
#: the object at most this much before the stroke [m]; otherwise the interaction is marked failed.
MAX_START_ERROR, MAX_OBJECT_MOVED_BEFORE = 0.01, 0.003
#: Object at rest: linear [m/s] and angular [rad/s] speed below these.
REST_SPEED, REST_ANGULAR_SPEED = 0.01, 0.3


def _failure_reason(fault: str | None, visible_initially: bool, stroke) -> str | None:
    """Why an interaction cannot be used, or None; see the class docstring."""
    if fault is not None:
        return f"physics: {fault}"
    if not visible_initially:
        return "perception: the object was not visible in the initial snapshot"
    if not stroke.ik_success:
        return (f"ik: the stroke was not reachable (position error {stroke.ik_position_error * 1e3:.1f} mm, "
                f"orientation error {stroke.ik_orientation_error:.2f} rad)")
    if stroke.object_moved > MAX_OBJECT_MOVED_BEFORE:
        return f"reach: the arm moved the object by {stroke.object_moved * 1e3:.1f} mm before the stroke"
    if stroke.start_error > MAX_START_ERROR:
        return f"reach: the stroke started {stroke.start_error * 1e3:.1f} mm from the planned pose"
    if not stroke.contact:
        return "tap: the hand never touched the object"
    return None


#: A box or standing cylinder whose vertical axis tilted more than this has toppled over [rad].
TOPPLE_ANGLE = np.pi / 4


def _toppled(object_type: str, quat_initial: np.ndarray, quat_final: np.ndarray) -> bool:
    """Whether a box or standing cylinder fell over (its body z axis tilted by more than TOPPLE_ANGLE)."""
    if object_type not in ("box", "vertical_cylinder"):
        return False  # spheres and lying cylinders turn about horizontal axes when they roll
    axes = []
    for quat in (quat_initial, quat_final):
        R = np.empty(9)
        mujoco.mju_quat2Mat(R, np.asarray(quat, dtype=np.float64))
        axes.append(R.reshape(3, 3)[:, 2])
    return bool(np.arccos(np.clip(axes[0] @ axes[1], -1.0, 1.0)) > TOPPLE_ANGLE)


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
    servos; the stroke stops a short follow-through after the hand first touches the object.

    ## Action Space
    ``Box(-1, 1, (3,), float32)``; 0 is the paper's canonical tap.

    | index | meaning | range |
    |-------|---------|-------|
    | 0 | height of the palm above the canonical contact height | -1.5 .. +1.5 cm |
    | 1 | lateral offset of the stroke, across its direction | -2 .. +2 cm |
    | 2 | hand speed along the stroke | 0.15 .. 0.45 m/s |

    Values outside [-1, 1], NaN or a wrong shape raise ``ValueError``.

    ## Observation Space
    ``Dict`` of

    | key | shape | dtype | meaning |
    |-----|-------|-------|---------|
    | ``range`` | (H, W) | float32 | distance along each pixel's ray [m]; 0 where nothing is hit |
    | ``mask`` | (H, W) | int8 | 1 on pixels of the object of interest |
    | ``features`` | (49,) | float32 | the paper's features, named by ``affordance_env.FEATURE_NAMES`` |
    | ``joints`` | (13,) | float32 | robot joint angles [rad], order ``affordance_env.ACTIVE_JOINTS`` |

    ## Rewards
    ``reward_fn(info)``; the default is the object's displacement on the table [m]. Affordance learning does not
    use a reward: it learns from ``info["effect"]``.

    ## Starting State
    Robot at the ``home`` keyframe; object type uniform over ``object_types``, size uniform in ``size_range``,
    position uniform within +-3 cm of (-0.30, 0.03) m on the table, yaw jittered by up to 0.25 rad (boxes and
    lying cylinders; a lying cylinder's axis stays across the tap direction). All drawn from ``self.np_random``.

    ## Episode End
    The episode terminates after one interaction (``terminated=True``). The object's motion is simulated until it
    is at rest, has left the table, or ``settle_timeout`` seconds after the robot is back home and still.

    ## Info
    After ``reset``: ``object`` (``type``, ``size`` [m], ``pose`` (7,) position and quaternion), ``attention``.
    After ``step`` also: ``effect`` (49,) final minus initial features, ``initial_features``,
    ``final_features``, ``object`` with ``initial_pose`` and ``final_pose``, ``displacement`` [m], ``rolled``
    (displacement above ``roll_threshold`` without toppling; the paper's success label), ``toppled`` (a box or
    standing cylinder fell over: its vertical axis tilted by more than 45 degrees), ``outcome`` (``"rest"``,
    ``"off_table"`` or ``"timeout"``), ``contact`` (the hand touched the object), ``hand_speed`` [m/s],
    ``ik`` (``success``, ``position_error`` [m], ``orientation_error`` [rad]), ``visible`` (object seen in the
    final snapshot),
    ``failure``: None, or why the interaction is not a valid sample: ``"physics: ..."`` (MuJoCo reported an
    instability or the state became non-finite; then obs is blank, ``effect`` is zeros and ``outcome`` is
    ``"fault"``), ``"perception: ..."`` (object not visible initially), ``"ik: ..."`` (stroke not reachable),
    ``"reach: ..."`` (the arm touched the object before the stroke, or the stroke started more than 1 cm from
    its planned pose), ``"tap: ..."`` (the hand never touched the object). The next ``reset`` recovers from any of them.

    ## Arguments

    | argument | default | meaning |
    |----------|---------|---------|
    | ``behavior`` | ``"tap"`` | ``"tap"``; ``"tap_back"`` (other side, back of hand); ``"push"`` (from the front) |
    | ``object_types`` | all four | types to sample from |
    | ``size_range`` | (0.04, 0.10) | object size range [m] |
    | ``camera_width``, ``camera_height`` | 128, 128 | range image size [pixels] |
    | ``camera_fovy`` | 50 | vertical field of view [deg] |
    | ``roll_threshold`` | 0.05 | displacement above which an interaction is ``rolled`` [m] |
    | ``settle_timeout`` | 2.0 | longest simulated wait for the outcome once the robot is back home [s] |
    | ``reward_fn`` | displacement | ``callable(info) -> float`` |
    | ``render_mode`` | None | ``"rgb_array"``: a picture from an outside camera (headless EGL/OSMesa) |

    ## Version History
    * v0: initial release.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 30}

    def __init__(
        self,
        behavior: str = "tap",
        object_types: Sequence[str] = OBJECT_TYPES,
        size_range: tuple[float, float] = (0.04, 0.10),
        camera_width: int = 128,
        camera_height: int = 128,
        camera_fovy: float = 50.0,
        roll_threshold: float = 0.05,
        settle_timeout: float = 2.0,
        reward_fn: Callable[[dict[str, Any]], float] | None = None,
        render_mode: str | None = None,
        render_width: int = 480,
        render_height: int = 360,
    ) -> None:
        self.behavior = get_behavior(behavior)
        if isinstance(object_types, str) or len(object_types) == 0:
            raise ValueError(f"object_types must be a non-empty sequence of {OBJECT_TYPES}, got {object_types!r}.")
        self.object_types = tuple(check_object_type(t) for t in object_types)
        low, high = (check_size(s) for s in size_range)
        if low > high:
            raise ValueError(f"size_range must be (low, high) with low <= high, got {size_range!r}.")
        self.size_range = (low, high)
        if not roll_threshold > 0:
            raise ValueError(f"roll_threshold must be a positive distance [m], got {roll_threshold!r}.")
        if not settle_timeout > 0:
            raise ValueError(f"settle_timeout must be positive [s], got {settle_timeout!r}.")
        if render_mode not in (None, *self.metadata["render_modes"]):
            raise ValueError(
                f"render_mode must be None or one of {self.metadata['render_modes']}, got {render_mode!r}."
            )
        self.roll_threshold = float(roll_threshold)
        self.settle_timeout = float(settle_timeout)
        self.reward_fn = default_reward if reward_fn is None else reward_fn
        self.render_mode = render_mode

        self.physics = TapPhysics(build_model())
        self.kinematics = Kinematics()
        self.motion = MotionExecutor(self.physics, self.kinematics)
        self.camera = RangeCamera(self.physics.model, width=camera_width, height=camera_height, fovy_deg=camera_fovy)
        self.attention_camera = RangeCamera(self.physics.model, width=32, height=32, fovy_deg=camera_fovy)
        self._renderer = None
        self._render_size = (render_width, render_height)
        #: With ``render_mode="rgb_array"``: pictures taken every 1/render_fps s of simulated time during the
        #: last ``reset`` and ``step`` (for videos of an interaction).
        self.frames: list[np.ndarray] = []
        self._next_frame_time = 0.0
        if render_mode == "rgb_array":
            self.physics.on_step = self._record_frame

        H, W = camera_height, camera_width
        nq = len(ACTIVE_JOINTS)
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
        self._initial: dict[str, Any] | None = None
        self._q_home = np.zeros(nq)

    # ------------------------------------------------------------------------------------------------------
    def _blank_observation(self) -> dict[str, np.ndarray]:
        space = self.observation_space
        return {
            "range": np.zeros(space["range"].shape, np.float32),
            "mask": np.zeros(space["mask"].shape, np.int8),
            "features": NOT_VISIBLE_VALUES.astype(np.float32),
            "joints": np.clip(self._q_home, space["joints"].low, space["joints"].high).astype(np.float32),
        }

    def _snapshot(self) -> tuple[dict[str, np.ndarray], Any]:
        image = self.camera.capture(self.physics.data)
        mask = image.mask_of(self.physics.active_geom)
        p_world_hand = self.physics.hand_position()
        uv_hand = image.project(p_world_hand)
        if not np.all(np.isfinite(uv_hand)):  # hand behind the camera: no image position; use the image centre
            uv_hand = np.array([image.intrinsics.cx, image.intrinsics.cy])
        features = compute_features(
            image.p_world_points, image.ranges, mask, image.p_world_camera, p_world_hand, uv_hand
        )
        ranges = np.where(np.isfinite(image.ranges), image.ranges, 0.0).astype(np.float32)
        obs = {
            "range": ranges,
            "mask": mask.astype(np.int8),
            "features": features.values.astype(np.float32),
            "joints": self.physics.joint_positions().astype(np.float32),
        }
        return obs, features

    def _sample_object(self) -> tuple[str, float, np.ndarray, float]:
        rng = self.np_random
        object_type = self.object_types[int(rng.integers(len(self.object_types)))]
        size = float(rng.uniform(*self.size_range))
        xy = PLACEMENT_CENTRE + rng.uniform(-1.0, 1.0, 2) * PLACEMENT_HALF_WIDTH
        yaw = float(rng.uniform(-YAW_JITTER, YAW_JITTER))
        if object_type in ("sphere", "vertical_cylinder"):
            yaw = 0.0
        return object_type, size, xy, yaw

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        """Place a new object, let it settle, attend to it and take the initial snapshot."""
        super().reset(seed=seed)
        self.frames = []
        self._next_frame_time = 0.0
        object_type, size, xy, yaw = self._sample_object()
        physics = self.physics
        physics.reset_home()
        self._q_home = physics.joint_targets()
        geometry = object_geometry(object_type, size)
        physics.set_object(geometry, xy, yaw)
        self._settle_object()
        attention = attend(physics, self.attention_camera, self.motion.move_joints)
        self.motion.hold_still()
        self._q_home = physics.joint_targets()  # the arm's home, with the gaze on the object
        obs, features = self._snapshot()
        pose = physics.object_pose()
        self._initial = {"features": features, "pose": pose, "yaw": yaw, "geometry": geometry,
                         "visible": features.visible}
        info = {
            "object": {"type": object_type, "size": size, "pose": pose},
            "attention": {"success": attention.success, "visible": attention.visible,
                          "pixel_error": attention.pixel_error},
            "visible": features.visible,
        }
        return obs, info

    def _settle_object(self) -> None:
        """Let the freshly placed object come to rest (it is placed 0.1 mm above the table)."""
        physics = self.physics
        for _ in range(round(SETTLE_TIME / CONTROL_DT)):
            physics.step(self.motion.steps_per_tick)
            if physics.object_speed() < 1e-3 and physics.object_angular_speed() < 1e-2:
                return

    def _wait_outcome(self) -> str:
        """Simulate until the object is at rest, has left the table, or ``settle_timeout`` has passed."""
        physics = self.physics
        t_end = physics.data.time + self.settle_timeout
        rest_ticks = 0
        while True:
            if not physics.object_on_table():
                return "off_table"
            if physics.object_speed() < REST_SPEED and physics.object_angular_speed() < REST_ANGULAR_SPEED:
                rest_ticks += 1
                if rest_ticks >= 5:
                    return "rest"
            else:
                rest_ticks = 0
            if physics.data.time >= t_end:
                return "timeout"
            physics.step(self.motion.steps_per_tick)

    def step(self, action):
        """Execute the behaviour with ``action`` and take the final snapshot; the episode then terminates."""
        if self._initial is None:
            raise RuntimeError("step() called before reset() or after the interaction ended; call reset() first.")
        action = check_action(action)
        initial, self._initial = self._initial, None
        physics = self.physics
        self.frames = []
        plan = plan_stroke(self.behavior, initial["geometry"], initial["pose"][:3], initial["yaw"],
                           physics.table_top, action)
        stroke = self.motion.stroke(plan)
        self.motion.go_home(self._q_home)
        outcome = self._wait_outcome()
        fault = physics.unstable()
        if fault is None:
            obs, features = self._snapshot()
            final_features = features.values
            final_pose = physics.object_pose()
            visible = features.visible
        else:  # the state is not to be trusted: nothing of it reaches obs or info
            obs = self._blank_observation()
            final_features = NOT_VISIBLE_VALUES
            final_pose = np.full(7, np.nan)
            visible = False
        failure = _failure_reason(fault, initial["visible"], stroke)
        displacement = 0.0 if fault else float(np.linalg.norm(final_pose[:2] - initial["pose"][:2]))
        toppled = (not fault) and _toppled(initial["geometry"].object_type, initial["pose"][3:], final_pose[3:])
        effect = (
            np.zeros(len(FEATURE_NAMES), np.float32)
            if fault
            else (final_features - initial["features"].values).astype(np.float32)
        )
        info = {
            "object": {"type": initial["geometry"].object_type, "size": initial["geometry"].size,
                       "initial_pose": initial["pose"], "final_pose": final_pose},
            "initial_features": initial["features"].values,
            "final_features": final_features,
            "effect": effect,
            "displacement": displacement,
            "rolled": displacement > self.roll_threshold and not toppled,
            "toppled": toppled,
            "outcome": "fault" if fault else outcome,
            "contact": stroke.contact,
            "hand_speed": stroke.hand_speed,
            "ik": {"success": stroke.ik_success, "position_error": stroke.ik_position_error,
                   "orientation_error": stroke.ik_orientation_error},
            "visible": visible,
            "behavior": self.behavior.name,
            "failure": failure,
        }
        reward = float(self.reward_fn(info))
        return obs, reward, True, False, info

    def _record_frame(self, physics: TapPhysics) -> None:
        if physics.data.time >= self._next_frame_time:
            self.frames.append(self.render())
            self._next_frame_time = physics.data.time + 1.0 / self.metadata["render_fps"]

    def render(self):
        """An RGB picture (H, W, 3) uint8 of the scene from the ``overview`` camera, if ``render_mode='rgb_array'``."""
        if self.render_mode != "rgb_array":
            return None
        if self._renderer is None:
            from affordance_env.rendering import SceneRenderer

            self._renderer = SceneRenderer(self.physics.model, *self._render_size)
        return self._renderer.render(self.physics.data)

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


__all__ = ["TapAffordanceEnv", "default_reward", "BEHAVIORS"]
