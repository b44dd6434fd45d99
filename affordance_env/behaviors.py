"""The robot's behaviours: where the hand starts, which way it moves and how fast, for one action.

A behaviour is a straight hand stroke along a horizontal direction, with a fixed hand orientation and a
contact surface on the hand. :func:`plan_stroke` turns (behaviour, object, action) into Cartesian waypoints;
it is a pure function, and :mod:`affordance_env.motion` executes the plan on the simulated robot.

The action is three numbers in [-1, 1]; 0 is the paper's canonical tap:

==========  ===============================================================  ======================
index       meaning                                                          range
==========  ===============================================================  ======================
0           height of the palm centre above the canonical contact height     -1.5 .. +1.5 cm
1           lateral offset of the stroke, across the stroke direction        -2 .. +2 cm
2           hand speed along the stroke, 0.2 m/s x 3 ** action[2]            0.067 .. 0.6 m/s
==========  ===============================================================  ======================

The canonical tap is moderate (the paper: "moderately hitting an object from its side"): at 0.2 m/s a ball or a
lying cylinder rolls some 5 to 25 cm on the table and stays in view; the speed scale is geometric, because the
distance a struck object rolls grows with the square of its speed: at the gentlest tap (-1) rolling objects
move 2-3 cm, at the hardest (+1) four in five roll off the 1 m wide table (see ``assets/README.md``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from affordance_env.objects import ObjectGeometry

ACTION_DIM = 3
HEIGHT_RANGE = 0.015  # [m]
LATERAL_RANGE = 0.02  # [m]
#: Hand speed of the canonical tap [m/s], and the factor by which action[2] = +-1 multiplies or divides it.
SPEED_CANONICAL, SPEED_FACTOR = 0.2, 3.0
#: Gap between hand surface and object before the stroke [m].
CLEARANCE = 0.03
#: Distance the hand keeps moving after it first touches the object [m].
FOLLOW_THROUGH = 0.012
#: Clearance between the lowest point of the hand (3.3 cm below the palm centre) and the top of the object
#: when the hand passes above it on its way to the pre-stroke pose [m].
APPROACH_CLEARANCE = 0.06
HAND_BELOW_PALM = 0.033
#: Lowest palm-centre height above the table [m]: the hand reaches 3.3 cm below the palm centre.
MIN_PALM_HEIGHT = 0.04
#: Joint range the IK keeps to for every stroke (the fingers level, the palm 4 cm above the table, a low tap
#: 2.5 cm): the wrist's yaw within 3 degrees of its lower limit
#: (-20 degrees), which bends the forearm up from the hand and holds it at least 5 mm (typically 9 mm) clear of the
#: table. With the wrist free, the IK's solutions put the forearm into the table (up to 8 mm for tap_back, 34 mm for
#: push, and for a fifth of the taps at random actions): the arm then rests on it, and the hand stops 1-6 cm short
#: of the pre-stroke pose.
FOREARM_RAISED: dict[str, tuple[float, float]] = {"r_wrist_yaw": (-0.35, -0.30)}
#: The push's hand is turned by this angle about the vertical from straight across [rad]: the fingers point to the
#: robot's left and a little forward, and the back of the hand faces a little to the right of straight ahead. With
#: the fingers straight across, the forearm lies across the body and the hand reaches 30-35 cm in front of the
#: robot (the less, the further right), short of the stroke's far end for large objects right of centre; turned,
#: it reaches 36-39 cm. Pushed balls move within 2 degrees of straight ahead (6 degrees with the fingers across).
PUSH_HAND_TURN = np.radians(15.0)
#: Default distance [m] beyond which an interaction succeeds (the env's ``roll_threshold``): see :func:`is_success`.
ROLL_THRESHOLD = 0.03
#: What a behaviour's success is (:attr:`Behavior.success_rule`): ``"rolled"``, the object rolled more than the
#: threshold (the paper's label for the tap); ``"moved"``, its centre travelled more than the threshold on the table.
SUCCESS_RULES = ("rolled", "moved")
#: Approach clearance of tap_back [m]: its hand crosses over the object, from home on the object's right to its
#: left, and the forearm, trailing behind and below the hand, swept the top of objects 9-10 cm tall with the
#: ``APPROACH_CLEARANCE`` of the other behaviours.
CROSSING_CLEARANCE = 0.08


@dataclass(frozen=True)
class Behavior:
    """A horizontal hand stroke.

    Attributes:
        name: Identifier used by ``behavior=`` of the environment.
        direction: Unit stroke direction in the world x-y plane, (2,).
        R_world_hand: Orientation of the palm frame during the stroke (columns: fingers, thumb side, palm
            normal), (3, 3).
        contact_offset: Distance from the palm frame origin to the hand surface that leads the stroke [m].
        description: One line for the documentation.
        approach_clearance: Clearance between the hand's lowest point and the object's top at the pose above the
            pre-stroke pose, which the hand passes through on its way there and back [m]; None: the hand goes
            straight between home and the pre-stroke pose (the tap: home is on the side it strikes from, so the
            way never crosses the object).
        joint_ranges: Narrower joint ranges ``{name: (low, high)}`` [rad] that the IK keeps to for every pose of
            the stroke: a posture of the arm (see :data:`FOREARM_RAISED`). Empty: the robot's joint limits.
        success_rule: What makes an interaction a success, one of :data:`SUCCESS_RULES` (see :func:`is_success`).
    """

    name: str
    direction: np.ndarray
    R_world_hand: np.ndarray
    contact_offset: float
    description: str
    approach_clearance: float | None = APPROACH_CLEARANCE
    joint_ranges: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    success_rule: str = "rolled"

    def __post_init__(self) -> None:
        if self.success_rule not in SUCCESS_RULES:
            raise ValueError(f"success_rule must be one of {SUCCESS_RULES}, got {self.success_rule!r}.")


def _rotation(fingers: tuple[float, float, float], palm_normal: tuple[float, float, float]) -> np.ndarray:
    x = np.asarray(fingers, dtype=float)
    z = np.asarray(palm_normal, dtype=float)
    return np.column_stack([x, np.cross(z, x), z])


BEHAVIORS: dict[str, Behavior] = {
    "tap": Behavior(
        "tap", np.array([0.0, -1.0]), _rotation((-1, 0, 0), (0, -1, 0)), 0.012,
        "the paper's tap: the palm hits the object from its right side, moving to the robot's left (-y)",
        approach_clearance=None, joint_ranges=FOREARM_RAISED,
    ),
    "tap_back": Behavior(
        "tap_back", np.array([0.0, 1.0]), _rotation((-1, 0, 0), (0, -1, 0)), 0.039,
        "tap from the other side: the back of the hand hits the object from its left, moving right (+y)",
        approach_clearance=CROSSING_CLEARANCE, joint_ranges=FOREARM_RAISED,
    ),
    "push": Behavior(
        "push", np.array([-1.0, 0.0]),
        _rotation((-np.sin(PUSH_HAND_TURN), -np.cos(PUSH_HAND_TURN), 0),
                  (np.cos(PUSH_HAND_TURN), -np.sin(PUSH_HAND_TURN), 0)),
        0.039,
        "push from the front: the back of the hand pushes the object's near face away from the robot (-x)",
        joint_ranges=FOREARM_RAISED, success_rule="moved",
    ),
}


def is_success(rule: str, rolled: bool | np.ndarray, displacement: float | np.ndarray,
               threshold: float = ROLL_THRESHOLD) -> bool | np.ndarray:
    """The success/fail label of interactions by a behaviour whose :attr:`~Behavior.success_rule` is ``rule``.

    ``"rolled"`` (tap, tap_back: the paper's label): ``rolled``, the object rolled more than ``threshold``;
    ``"moved"`` (push): ``displacement > threshold``, the object's centre travelled more than ``threshold`` [m] on
    the table, rolling or sliding. Scalars give a bool, arrays an array.
    """
    if rule == "rolled":
        label = np.asarray(rolled, dtype=bool)
    elif rule == "moved":
        label = np.asarray(displacement, dtype=np.float64) > threshold
    else:
        raise ValueError(f"rule must be one of {SUCCESS_RULES}, got {rule!r}.")
    return bool(label) if label.ndim == 0 else label


def get_behavior(name: str) -> Behavior:
    """The behaviour called ``name``; raises ValueError listing the valid names."""
    if name not in BEHAVIORS:
        raise ValueError(f"Unknown behavior {name!r}. Valid behaviors: {', '.join(BEHAVIORS)}.")
    return BEHAVIORS[name]


@dataclass(frozen=True)
class StrokePlan:
    """Cartesian plan of one stroke (world frame, metres).

    Attributes:
        p_above: Palm position above the pre-stroke pose, high enough to clear the object, which the hand passes
            through on its way there and back; None: the hand goes straight.
        p_start: Pre-stroke palm position, ``CLEARANCE`` from the object.
        p_end: Palm position at maximum travel (the stroke stops earlier on contact).
        direction: Unit stroke direction (3,).
        speed: Hand speed along the stroke [m/s].
        R_world_hand: Hand orientation during the stroke.
        follow_through: Travel after first contact [m].
        joint_ranges: The behaviour's joint ranges for the IK (:attr:`Behavior.joint_ranges`).
    """

    p_above: np.ndarray | None
    p_start: np.ndarray
    p_end: np.ndarray
    direction: np.ndarray
    speed: float
    R_world_hand: np.ndarray
    follow_through: float
    joint_ranges: Mapping[str, tuple[float, float]] = field(default_factory=dict)


def check_action(action: np.ndarray) -> np.ndarray:
    """Return ``action`` as a float64 (3,) array, or raise ValueError naming the problem."""
    a = np.asarray(action, dtype=np.float64)
    if a.shape != (ACTION_DIM,):
        raise ValueError(f"action must have shape ({ACTION_DIM},), got shape {a.shape}: {action!r}.")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"action must be finite, got {action!r}.")
    if np.any(np.abs(a) > 1.0 + 1e-6):
        raise ValueError(f"action must lie in [-1, 1] in every dimension, got {action!r}.")
    return np.clip(a, -1.0, 1.0)


def half_extent_along(geometry: ObjectGeometry, yaw: float, direction: np.ndarray) -> float:
    """Half of the object's horizontal extent along ``direction`` (unit, world x-y) at ``yaw`` [m]."""
    r = geometry.geom_size[0]
    if geometry.object_type in ("sphere", "vertical_cylinder"):
        return float(r)
    c, s = np.cos(yaw), np.sin(yaw)
    axes = np.array([[c, s], [-s, c]])  # the body's x and y axes in the world plane
    return float(np.sum(r * np.abs(axes @ direction)))


def plan_stroke(
    behavior: Behavior, geometry: ObjectGeometry, p_world_object: np.ndarray, yaw: float, table_top: float,
    action: np.ndarray,
) -> StrokePlan:
    """Plan the stroke of ``behavior`` against an object resting on the table.

    Args:
        behavior: The behaviour.
        geometry: The object's geometry (the paper takes shape, size and position from the simulator).
        p_world_object: Object centre [m], (3,).
        yaw: Object yaw [rad].
        table_top: Height of the table top [m].
        action: (3,) in [-1, 1]; see the module documentation.
    """
    a = check_action(action)
    d2 = behavior.direction
    d = np.array([d2[0], d2[1], 0.0])
    across = np.array([-d2[1], d2[0], 0.0])
    height = max(geometry.half_height, MIN_PALM_HEIGHT) + a[0] * HEIGHT_RANGE
    height = max(height, MIN_PALM_HEIGHT - HEIGHT_RANGE / 2)
    half = half_extent_along(geometry, yaw, d2)
    centre = np.array([p_world_object[0], p_world_object[1], table_top + height]) + a[1] * LATERAL_RANGE * across
    p_start = centre - d * (half + behavior.contact_offset + CLEARANCE)
    # Without contact the hand travels through where the object was, then stops.
    p_end = centre + d * (half - behavior.contact_offset + FOLLOW_THROUGH)
    p_above = None if behavior.approach_clearance is None else np.array(
        [p_start[0], p_start[1], table_top + 2 * geometry.half_height + HAND_BELOW_PALM + behavior.approach_clearance])
    return StrokePlan(
        p_above=p_above,
        p_start=p_start,
        p_end=p_end,
        direction=d,
        speed=SPEED_CANONICAL * SPEED_FACTOR ** a[2],
        R_world_hand=behavior.R_world_hand,
        follow_through=FOLLOW_THROUGH,
        joint_ranges=behavior.joint_ranges,
    )
