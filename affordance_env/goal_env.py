"""TapAffordanceGoal-v2: bring the object to a place on the table, choosing among the five behaviours."""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from affordance_env.behaviors import ACTION_DIM, check_action
from affordance_env.centre import object_centre
from affordance_env.exceptions import InvalidValueError
from affordance_env.features import FEATURE_NAMES
from affordance_env.options import EnvOptions
from affordance_env.placement import RESET_OPTIONS, draw_placement
from affordance_env.registry import BEHAVIOR_NAMES, check_behavior_name
from affordance_env.results import InteractionResult, Snapshot
from affordance_env.values import float_array, is_integer, restore_with_generator
from affordance_env.workspace import WORKSPACES, in_any_workspace, sample_in_workspace
from affordance_env.world import World, WorldState

#: Keys of ``reset(options=...)``.
GOAL_RESET_OPTIONS = ("goal", *RESET_OPTIONS)
#: Goals are drawn this far from the object [m] ...
GOAL_DISTANCE = (0.10, 0.25)
#: ... and at least this far inside the table's edges [m].
GOAL_TABLE_MARGIN = 0.05


def draw_target(xy: np.ndarray, rng: np.random.Generator, low, high, distance: tuple[float, float] = GOAL_DISTANCE,
                angles: tuple[float, float] = (-np.pi, np.pi), draws: int = 1000) -> np.ndarray | None:
    """A point ``distance`` [m] from ``xy`` in a direction uniform over ``angles`` [rad] (from +x), where the goal env
    puts its goals: at least GOAL_TABLE_MARGIN inside the table top ``low`` .. ``high`` (x, y) [m] and in some
    behaviour's workspace; None if ``draws`` draws find none. A pure function of ``rng``'s draws."""
    inner_low, inner_high = np.asarray(low) + GOAL_TABLE_MARGIN, np.asarray(high) - GOAL_TABLE_MARGIN
    for _ in range(draws):
        angle = rng.uniform(*angles)
        target = xy + rng.uniform(*distance) * np.array([np.cos(angle), np.sin(angle)])
        if np.all(target >= inner_low) and np.all(target <= inner_high) and in_any_workspace(target):
            return target
    return None


def _behavior_index(behavior: Any) -> int:
    """A behaviour given by number: its index (an integer, or a float with an integer value), else -1."""
    value = np.asarray(behavior) if not isinstance(behavior, Mapping | set | frozenset) else np.asarray(None)
    if value.ndim != 0 or value.dtype.kind not in "iuf":  # not booleans, strings, None, complex numbers
        return -1
    number = float(value)
    return int(number) if np.isfinite(number) and number == int(number) else -1


def goal_distance(achieved_goal: np.ndarray, desired_goal: np.ndarray) -> np.ndarray:
    """Distance on the table [m] between achieved and desired goals, (..., 2) -> (...)."""
    return np.linalg.norm(np.asarray(achieved_goal, dtype=float) - np.asarray(desired_goal, dtype=float), axis=-1)


@dataclass(frozen=True)
class GoalEnvState:
    """A snapshot of :class:`TapAffordanceGoalEnv` (:meth:`~TapAffordanceGoalEnv.get_state`): treat it as opaque.

    Attributes:
        world: The world's state.
        rng: The state of the env's random generator.
        goal: The episode's goal (x, y) [m].
        obs: The last observation, or None once the episode ended.
        steps: The interactions since the episode's reset; :func:`affordance_env.snapshots.set_state` puts
            Gymnasium's ``TimeLimit`` wrappers back to it.
    """

    world: WorldState
    rng: dict[str, Any]
    goal: np.ndarray
    obs: dict[str, Any] | None
    steps: int = 0


class TapAffordanceGoalEnv(gym.Env):
    """The iCub moves one object to a goal on the table, one interaction per step, choosing the behaviour.

    ## Description
    The world of ``TapAffordance-v2`` with both arms in one scene: the right arm with the V2.5 hand taps, taps
    back, pushes and draws, the left arm with the fingered ``left_hand_mk3`` hand picks and places (grasps, lifts,
    holds and puts the object down where its action asks); the arm that does not act waits rigid at its home pose,
    where it is in every scene of this env, so every behaviour sees the same robot and measures the relation
    features to the same (right) palm.
    ``reset`` places an object and draws a goal; each ``step`` runs one interaction with the behaviour and its
    parameters that the action chooses. The object stays exactly where the interaction left it, at rest (the
    interaction ends once it rests, has left the table, or ``settle_timeout`` passed); then the head turns to it
    again and the next observation is taken. A goal-conditioned env in the style of Gymnasium-Robotics' Fetch
    envs (a ``Dict`` observation with ``achieved_goal`` and ``desired_goal``, ``compute_reward``).

    ## Frame
    Positions are (x, y) [m] in the robot's root frame, on the table top: **+x points toward the robot** (the
    table's near edge is at x = -0.16, objects stand around x = -0.30), +y to the robot's right, -y to its left.
    ``tap`` moves objects toward -y, ``tap_back`` toward +y, ``push`` toward -x (away), ``draw`` toward +x (toward
    the robot), and ``grasp`` wherever its action asks.

    ## Action Space
    ``Dict(behavior=Discrete(5), params=Box(-1, 1, (3,), float32))``: the behaviour, named by
    ``env.unwrapped.behaviors`` (``tap``, ``tap_back``, ``push``, ``grasp``, ``draw``), and its parameters, those of
    ``TapAffordance-v2``'s action for that behaviour (0 is the canonical action), except the grasp's: it is pick and
    place, ``params[0]`` and ``params[1]`` name where the held object is put down, ``PLACE_RANGE`` (0.2 m) times
    them along x and y from where it stood (the hand takes it as the canonical grasp does), and ``params[2]`` is
    the fingers' closing speed as in TapAffordance-v2. :class:`FlatActionWrapper` gives a ``Box(-1, 1, (8,))``
    action (one score per behaviour, the highest chosen, then the parameters) for libraries that need one.
    Out-of-range parameters, NaN, a wrong shape or an unknown behaviour raise ``ValueError``.

    ## Observation Space
    ``Dict`` of

    | key | shape | meaning |
    |-----|-------|---------|
    | ``observation`` | ``Dict(features (49,), range (H, W), mask (H, W))`` | the range camera's view of the object,
      as in TapAffordance-v2, taken with the robot at home and the gaze on the object |
    | ``achieved_goal`` | (2,) | the object's perceived position on the table, root frame [m]: where the range
      camera sees it stand, the centre of its shape class (sphere, cube, cylinder standing or lying) resting on the
      table, with its size and yaw, fitted to the object's visible points (:func:`affordance_env.centre.object_centre`):
      within 1.5 mm of the true centre for every object seen whole (107 of 150 placed over the workspaces, with the
      ``kinect_v1`` noise; 0.4 mm without, ``python benchmarks/achieved_goal.py``). An object partly hidden (by an
      arm, or by the image's edge) is placed by the part in view: within 1 cm for 42 of those 43, 3.3-3.5 cm off for a
      lying cylinder of which a sliver was seen. An object not seen at all (hidden behind an arm, or out of every
      view of the head): its true position (an object that left the table: the nearest point of the table's edge) |
    | ``desired_goal`` | (2,) | the goal, root frame [m] |

    ## Rewards
    ``compute_reward(achieved_goal, desired_goal, info)``, vectorised over leading dimensions: with
    ``reward_type="sparse"`` (default) 0 within ``goal_tolerance`` of the goal and -1 elsewhere; ``"dense"``: minus
    the distance [m]. ``step`` returns the same value.

    ## Starting State
    As TapAffordance-v2 (object type, size, position, yaw drawn from ``self.np_random``, or given by ``reset``'s
    ``options``: ``object_type``, ``size``, ``position``, ``yaw``, ``object_pose``). The goal is drawn
    ``GOAL_DISTANCE`` (10-25 cm) from the object's perceived position, in a uniform direction, at least
    ``GOAL_TABLE_MARGIN`` inside the table's edges and inside the union of the behaviours' workspaces
    (:mod:`affordance_env.workspace`); ``options={"goal": (x, y)}`` sets it.

    ## Episode End
    Terminated when the object is within ``goal_tolerance`` of the goal (``info["is_success"]``), when it left the
    table, or when the simulation became unstable (``info["failure"]`` starts with ``"physics:"``). Truncated
    after ``max_episode_steps`` interactions (5 by default, set at registration through Gymnasium's
    ``TimeLimit``).

    ## Info
    After ``reset``: ``object``, ``visible``, ``attention``, ``still`` as TapAffordance-v2, ``distance`` and
    ``true_position``: where the object's centre is (x, y) [m], root frame (``achieved_goal`` is where it is seen).
    After ``step``: every key of TapAffordance-v2's step info for the interaction (``effect``, ``object`` with
    ``pose`` (where it is now, as after ``reset``), ``initial_pose`` and ``final_pose``, ``displacement``,
    ``success``, ``failure``, ...), and ``behavior``,
    ``distance`` [m] to the goal and ``is_success`` (both of ``achieved_goal``, where the object is seen),
    ``true_position`` as after ``reset``; ``attention`` (the head turning to the object again, as after
    ``reset``; None when the episode ended without looking) and ``observation_visible``: whether the returned
    observation sees the object, as ``visible`` after ``reset``. Where it does not (the object lies hidden behind an
    arm, or out of every view of the head), the next interaction would fail with ``"perception: ..."``.

    ## Arguments
    ``object_types``, ``size_range``, ``camera_width``, ``camera_height``, ``camera_fovy``, ``roll_threshold``,
    ``settle_timeout``, ``range_noise``: as TapAffordance-v2. ``position_range``: ``"canonical"`` (as
    TapAffordance-v2) or ``"workspace"``: objects placed uniformly over the workspace of a behaviour drawn
    uniformly, so that each behaviour can act on as many of them.
    ``goal_tolerance`` (0.03 m): the goal is reached
    within it. ``reward_type``: ``"sparse"`` or ``"dense"``. ``render_mode``: ``"rgb_array"`` or None.

    ## Snapshots
    ``get_state()`` and ``set_state(state)``: the world (both arms' scenes and which one acts), the episode's goal
    and observation, the interactions since the reset and the random generator; the same action after a restore
    gives the same interaction, bit for bit. Through ``gym.make``'s env, whose ``TimeLimit`` wrapper counts the
    steps out of the env's reach, ``affordance_env.snapshots.set_state(env, state)`` also puts that count back, so
    that actions tried from one snapshot do not bring the truncation nearer (``env.unwrapped.set_state(state)``
    leaves the count where it was). ``feasible(behavior, params, state=None)``: whether the arm can reach every
    pose of that interaction with the object where it is (or where it is in ``state``, a snapshot of
    ``get_state()``, the env left as it was), from the kinematics alone (no physics step).

    ## Version History
    * v2: five behaviours: ``draw`` (the right hand drags the object toward the robot) is new, and the grasp is pick
      and place (its first two parameters name where the object is put down). Goals may lie toward the robot (the
      draw's workspace joins the union goals are drawn in); ``position_range="workspace"`` places objects in the
      workspace of a behaviour drawn uniformly (not uniformly over the union). Data of v1 are not comparable.
      Fixed since its first release: an object the hand holds over the table's edge has not left the table
      (``outcome`` ``"off_table"`` only once it is let go, or falls, there); a grasp of an object within a centimetre
      of the near edge was labelled off the table, wherever it was put down. The left arm's inverse kinematics keeps
      the torso within ``affordance_env.robot_model.HELD_ARM_TORSO_RANGES`` (pitch at most 35 degrees, roll at
      least -20): unbounded, grasps 38-42 cm in front of the robot leaned it onto the held right arm, whose forearm
      met the table and held the torso up, and the hand closed above the object. ``feasible`` checks the carry's
      end where it will be (the held object hangs 1-2 cm from where the grasp aimed it, and the carry brings it
      over the place), not the nominal pose, where 9 of 122 pick and place grasps it accepted failed to reach; and a
      stroke's or a draw's reach must keep its targets 2 mm from the object (they were let through down to 0 mm, and
      the arm, following them a millimetre or two behind, touched the object on the way down in 1-2 % of the
      planner's interactions). The interactions are unchanged; goal datasets collected before are not resumed.
      ``achieved_goal`` is where the camera sees the object stand (its shape class fitted to its visible points),
      not the centre of its visible top: that was up to 4.4 cm off (median 9 mm) for the objects an arm hides in
      part, 43 of 150 placed over the workspaces, and the success flag followed it. Goals are drawn from it, so a
      seed draws slightly other goals. ``info["true_position"]`` is new.
    * v1: the motors of TapAffordance-v2 (each with its torque-speed curve) and its hand's controller (a finger's
      target kept within its servo's reach of the finger); the put-down lowers a held object at 2 cm/s, carries it
      along a straight line to above where it goes, and stops where fingertips under it meet the table first. Data
      of v0 are not comparable.
    * v0: initial release.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 30,
                # a vector env resets it within the step that ends its episode: every vector step is an interaction
                "autoreset_mode": gym.vector.AutoresetMode.SAME_STEP}

    def __init__(
        self,
        object_types: Sequence[str] = EnvOptions.object_types,
        size_range: tuple[float, float] = EnvOptions.size_range,
        camera_width: int = EnvOptions.camera_width,
        camera_height: int = EnvOptions.camera_height,
        camera_fovy: float = EnvOptions.camera_fovy,
        roll_threshold: float = EnvOptions.roll_threshold,
        settle_timeout: float = EnvOptions.settle_timeout,
        range_noise: str | None = EnvOptions.range_noise,
        position_range: str = EnvOptions.position_range,
        goal_tolerance: float = 0.03,
        reward_type: str = "sparse",
        render_mode: str | None = None,
        render_width: int = 480,
        render_height: int = 360,
    ) -> None:
        if not (isinstance(goal_tolerance, (int, float)) and np.isfinite(goal_tolerance) and goal_tolerance > 0):
            raise InvalidValueError(f"goal_tolerance must be a positive distance [m], got {goal_tolerance!r}.")
        if reward_type not in ("sparse", "dense"):
            raise InvalidValueError(f"reward_type must be 'sparse' or 'dense', got {reward_type!r}.")
        if render_mode not in (None, *self.metadata["render_modes"]):
            raise InvalidValueError(f"render_mode must be None or one of {self.metadata['render_modes']}, got "
                             f"{render_mode!r}.")
        options = EnvOptions(object_types=object_types, size_range=size_range, camera_width=camera_width,
                             camera_height=camera_height, camera_fovy=camera_fovy, roll_threshold=roll_threshold,
                             settle_timeout=settle_timeout, range_noise=range_noise,
                             position_range=position_range, two_arms=True)  # checked and normalised
        #: The data options, checked (:class:`~affordance_env.options.EnvOptions`; ``behavior`` is not used, and
        #: both arms are always in the scene).
        self.options = options
        #: Where objects are placed: ``"canonical"`` as in TapAffordance-v2, or ``"workspace"``: uniform over the
        #: workspace of a behaviour drawn uniformly (:func:`~affordance_env.workspace.sample_in_workspace`).
        self.position_range = options.position_range
        #: The world, with both arms: every behaviour acts in it.
        self.world = World(BEHAVIOR_NAMES, two_arms=True, camera_width=options.camera_width,
                           camera_height=options.camera_height, camera_fovy=options.camera_fovy,
                           range_noise=options.range_noise, roll_threshold=options.roll_threshold,
                           settle_timeout=options.settle_timeout, typical_size=float(np.mean(options.size_range)))
        self._render_size = (render_width, render_height)
        #: The behaviours, named by the action's ``behavior`` index.
        self.behaviors = BEHAVIOR_NAMES
        self.goal_tolerance = float(goal_tolerance)
        self.reward_type = reward_type
        self.render_mode = render_mode
        H, W = options.camera_height, options.camera_width
        table = self.world.table
        self.observation_space = spaces.Dict({
            "observation": spaces.Dict({
                "features": spaces.Box(-np.inf, np.inf, (len(FEATURE_NAMES),), np.float32),
                "range": spaces.Box(0.0, self.world.camera.max_range, (H, W), np.float32),
                "mask": spaces.Box(0, 1, (H, W), np.int8),
            }),
            "achieved_goal": spaces.Box(table.low, table.high, (2,), np.float64),
            "desired_goal": spaces.Box(table.low, table.high, (2,), np.float64),
        })
        self.action_space = spaces.Dict({"behavior": spaces.Discrete(len(BEHAVIOR_NAMES)),
                                         "params": spaces.Box(-1.0, 1.0, (ACTION_DIM,), np.float32)})
        self._goal = np.zeros(2)
        self._obs: dict[str, Any] | None = None
        self._steps = 0  # interactions since the reset
        self._last: InteractionResult | None = None

    @property
    def last_result(self) -> InteractionResult | None:
        """The typed result of the last ``step``'s interaction (None before the first): what ``info`` is made
        from, beside the goal's keys."""
        return self._last

    # --- the goal ----------------------------------------------------------------------------------------------
    def compute_reward(self, achieved_goal: np.ndarray, desired_goal: np.ndarray, info: Any) -> np.ndarray | float:
        """The reward of reaching ``achieved_goal`` when ``desired_goal`` is wanted, (..., 2) each; ``info`` is
        not used. Vectorised: a batch of goals gives a batch of rewards."""
        achieved, desired = (float_array(name, goal, finite=False, expected="positions on the table, (..., 2) [m]")
                             for name, goal in (("achieved_goal", achieved_goal), ("desired_goal", desired_goal)))
        if achieved.shape[-1:] != (2,) or desired.shape[-1:] != (2,):
            raise InvalidValueError(f"achieved_goal and desired_goal must be positions on the table, (..., 2) [m], got "
                                    f"shapes {achieved.shape} and {desired.shape}.")
        try:
            d = goal_distance(achieved, desired)
        except ValueError:  # batches that do not broadcast
            raise InvalidValueError(f"achieved_goal and desired_goal must be batches of the same length, got shapes "
                                    f"{achieved.shape} and {desired.shape}.") from None
        # a NaN distance (a goal without a position) is not within the tolerance: not d <= tolerance
        reward = -(~(d <= self.goal_tolerance)).astype(np.float64) if self.reward_type == "sparse" else -d
        return float(reward) if np.ndim(reward) == 0 else reward

    def _check_goal(self, goal: Any) -> np.ndarray:
        return self.world.table.check_position(goal, "goal")

    def _draw_goal(self, xy: np.ndarray) -> np.ndarray:
        """A goal GOAL_DISTANCE from ``xy``, on the table and in some behaviour's workspace (:func:`draw_target`)."""
        goal = draw_target(xy, self.np_random, self.world.table.low, self.world.table.high)
        if goal is not None:
            return goal
        raise RuntimeError(f"No goal {GOAL_DISTANCE} m from the object at {xy} lies on the table and in a workspace; "
                           "place the object inside the workspaces (affordance_env.workspace).")

    # --- observing ---------------------------------------------------------------------------------------------
    def _observation(self, snapshot: Snapshot, visible: bool) -> dict[str, Any]:
        table = self.world.table
        if visible and len(snapshot.object_points):  # where the camera sees it stand
            seen = object_centre(snapshot.object_points, self.world.physics.geometry.primitive, table.top)
        else:  # not seen: where it is
            seen = self.world.object_pose()[:2]
        # a resting object's centre is over the table; one that left it: the nearest point of the table's edge
        achieved = np.clip(seen, table.low, table.high)
        observation = {"features": snapshot.features.values.astype(np.float32), "range": snapshot.ranges.copy(),
                       "mask": snapshot.mask.copy()}
        return {"observation": observation, "achieved_goal": achieved, "desired_goal": self._goal.copy()}

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        """Place an object, attend to it, draw the goal (or take ``options["goal"]``) and observe."""
        super().reset(seed=seed)
        if options is not None and not isinstance(options, Mapping):
            raise InvalidValueError(f"options must be a dict with keys among {GOAL_RESET_OPTIONS}, got {options!r}.")
        options = dict(options or {})
        unknown = sorted(set(options) - set(GOAL_RESET_OPTIONS))
        if unknown:
            raise InvalidValueError(
                f"Unknown reset option(s) {unknown}. Valid options: {', '.join(GOAL_RESET_OPTIONS)}.")
        goal = options.pop("goal", None)
        goal = None if goal is None else self._check_goal(goal)
        if self.position_range == "workspace" and not {"position", "object_pose"} & set(options):
            options["position"] = sample_in_workspace(None, self.np_random)
        o = self.options
        placement = draw_placement(self.np_random, options, o.object_types, o.size_range, self.world.table)
        seen = self.world.place(placement, self.np_random)
        info = seen.info()
        obs = self._observation(seen.snapshot, seen.visible)
        self._goal = self._draw_goal(obs["achieved_goal"]) if goal is None else goal
        obs["desired_goal"] = self._goal.copy()
        info["distance"] = float(goal_distance(obs["achieved_goal"], self._goal))
        info["true_position"] = self.world.object_pose()[:2].copy()
        self._obs, self._steps = obs, 0
        return obs, info

    def _check_action(self, action: Any) -> tuple[str, np.ndarray]:
        if not isinstance(action, Mapping) or set(action) != {"behavior", "params"}:
            raise InvalidValueError(f"action must be a dict with keys 'behavior' (an index into {list(BEHAVIOR_NAMES)} "
                                    f"or a name) and 'params' (3 values in [-1, 1]), got {action!r}.")
        behavior = action["behavior"]
        if isinstance(behavior, str):
            name = check_behavior_name(behavior)
        else:
            index = _behavior_index(behavior)
            if not 0 <= index < len(BEHAVIOR_NAMES):
                raise InvalidValueError(f"action 'behavior' must be an index in 0..{len(BEHAVIOR_NAMES) - 1} "
                                 f"({', '.join(BEHAVIOR_NAMES)}), got {behavior!r}.")
            name = BEHAVIOR_NAMES[index]
        return name, check_action(action["params"])

    def feasible(self, behavior: int | str, params: Any, state: GoalEnvState | None = None) -> bool:
        """Whether the arm can reach every pose of ``behavior`` with ``params`` on the object where it is now (or
        where it is in ``state``, a snapshot of :meth:`get_state`: the env is left as it was), from the kinematics
        alone (no physics step); False: the interaction would fail with ``"ik: ..."``, a stroke's reach would
        sweep the arm into the object (``"reach: ..."``), or the grasp would put the object down off the table."""
        name, a = self._check_action({"behavior": behavior, "params": params})
        if state is not None:
            if not isinstance(state, GoalEnvState):
                raise TypeError(f"state must be what get_state() returned (a GoalEnvState), got "
                                f"{type(state).__name__}.")
            if state.obs is None:
                raise RuntimeError("feasible() needs an object: the state is of an episode that ended.")
            now = self.get_state()
            self.set_state(state)
            try:
                return self.world.feasible(name, a)
            finally:
                self.set_state(now)
        if self._obs is None:
            raise RuntimeError("feasible() needs an object: call reset() first.")
        return self.world.feasible(name, a)

    def outcome(self, behavior: int | str, params: Any, state: GoalEnvState | None = None) -> dict[str, Any]:
        """What one interaction of ``behavior`` with ``params`` does to the object where it is now (or where it is
        in ``state``, a snapshot of :meth:`get_state`), without the observation after it: :meth:`step`'s ``info``
        but for the keys that come of that observation and the goal (``distance``, ``is_success``,
        ``observation_visible``, ``attention``, ``true_position``: ``info["object"]["final_pose"]`` is where the
        interaction left the object), bit for bit the same; the env is then put back as it was. For an
        oracle that tries many actions from one snapshot and reads only what they did: the head's turn to the object
        and its fit after every interaction, about a tenth of a stroke's time, are not spent."""
        name, a = self._check_action({"behavior": behavior, "params": params})
        if state is not None and not isinstance(state, GoalEnvState):
            raise TypeError(f"state must be what get_state() returned (a GoalEnvState), got {type(state).__name__}.")
        if (self._obs if state is None else state.obs) is None:
            raise RuntimeError("outcome() needs an object: call reset() first (or give the state of an episode "
                               "that has not ended).")
        now = self.get_state()
        if state is not None:
            self.set_state(state)
        try:
            info = self.world.interact(name, a, self.np_random).info()
            info["behavior"] = name
            return info
        finally:
            self.set_state(now)

    def step(self, action):
        """Run one interaction with the chosen behaviour and parameters; the object stays where it ends."""
        if self._obs is None:
            raise RuntimeError("step() called before reset() or after the episode ended; call reset() first.")
        name, params = self._check_action(action)
        result = self._last = self.world.interact(name, params, self.np_random)
        info = result.info()
        seen = None
        if result.final is None or result.outcome == "off_table":  # nothing more to see: the episode ends on the
            obs = self._observation(result.final or self.world.blank_snapshot(), False)  # interaction's own view
        else:  # the head turns to the object where it rests, for the next interaction
            seen = self.world.observe(self.np_random)
            obs = self._observation(seen.snapshot, seen.visible)
        distance = float(goal_distance(obs["achieved_goal"], self._goal))
        attention = None if seen is None else seen.info()["attention"]
        info.update(behavior=name, distance=distance, is_success=bool(distance <= self.goal_tolerance),
                    true_position=self.world.object_pose()[:2].copy(),
                    observation_visible=seen is not None and seen.visible, attention=attention)
        reward = self.compute_reward(obs["achieved_goal"], self._goal, info)
        terminated = bool(info["is_success"] or result.outcome in ("off_table", "fault"))
        self._obs = None if terminated else obs
        self._steps += 1
        return obs, float(reward), terminated, False, info

    # --- snapshots -----------------------------------------------------------------------------------------------
    def get_state(self) -> GoalEnvState:
        """A snapshot of the world and the episode; :meth:`set_state` puts it back (treat it as opaque)."""
        return GoalEnvState(self.world.get_state(), copy.deepcopy(self.np_random.bit_generator.state),
                            self._goal.copy(), self._obs, self._steps)

    def set_state(self, state: GoalEnvState) -> None:
        """Put back the world and the episode as :meth:`get_state` saw them."""
        if not isinstance(state, GoalEnvState):
            raise TypeError(f"state must be what get_state() returned (a GoalEnvState), got {type(state).__name__}.")
        goal = float_array("the state's goal", state.goal, (2,), expected="a place on the table (x, y) [m]")
        if state.obs is not None and not isinstance(state.obs, Mapping):
            raise InvalidValueError(f"the state is damaged: its observation is {state.obs!r:.80}.")
        if not is_integer(state.steps) or state.steps < 0:
            raise InvalidValueError(f"the state is damaged: its step count is {state.steps!r:.80}, not the "
                                    "interactions since the reset (an integer >= 0).")
        # the generator's state checked first: a damaged one restores nothing
        restore_with_generator(self.np_random, state.rng, lambda: self.world.set_state(state.world))
        self._goal = goal.copy()
        self._obs, self._steps = state.obs, int(state.steps)

    def render(self):
        """A picture of the scene from the ``overview`` camera (``render_mode="rgb_array"``), else None."""
        return self.world.picture(*self._render_size) if self.render_mode == "rgb_array" else None

    def close(self) -> None:
        self.world.close()


class FlatActionWrapper(gym.ActionWrapper):
    """``Box(-1, 1, (8,), float32)`` actions for TapAffordanceGoal-v2: one score per behaviour (the highest one's
    behaviour is run, ties to the first) and the three parameters."""

    def __init__(self, env: gym.Env) -> None:
        super().__init__(env)
        self.action_space = spaces.Box(-1.0, 1.0, (len(BEHAVIOR_NAMES) + ACTION_DIM,), np.float32)

    def action(self, action: Any) -> dict[str, Any]:
        a = float_array("action", action, self.action_space.shape,
                        expected=f"{self.action_space.shape[0]} finite values ({len(BEHAVIOR_NAMES)} behaviour scores, "
                                 "3 parameters in [-1, 1])")
        n = len(BEHAVIOR_NAMES)
        return {"behavior": int(np.argmax(a[:n])), "params": a[n:].astype(np.float32)}


__all__ = ["TapAffordanceGoalEnv", "GoalEnvState", "FlatActionWrapper", "goal_distance", "WORKSPACES"]
