"""The robot's behaviours: where the hand goes, how it moves and how fast, for one action.

Two kinds of behaviour. A stroke (``tap``, ``tap_back``, ``push``) is a straight hand stroke along a horizontal
direction, with a fixed hand orientation and a contact surface on the hand; :func:`plan_stroke` turns (behaviour,
object, action) into Cartesian waypoints. The ``grasp`` (:class:`GraspBehavior`) takes the object from above
with the fingered left hand, lifts it, holds it and puts it down beside where it was; :func:`plan_grasp` plans
it. Both are pure functions; :mod:`affordance_env.motion` executes the plans on the simulated robot.

The action is three numbers in [-1, 1]; for a stroke, 0 is the paper's canonical tap:

==========  ===============================================================  ======================
index       meaning                                                          range
==========  ===============================================================  ======================
0           height of the palm centre above the canonical contact height     -1.5 .. +1.5 cm
1           lateral offset of the stroke, across the stroke direction        -2 .. +2 cm
2           hand speed along the stroke, 0.18 m/s x 3 ** action[2], at most  0.06 .. 0.54 m/s
            what the arm's joint speed limits allow
==========  ===============================================================  ======================

The arm's joints (100 deg/s, :mod:`affordance_env.motor_limits`) cap the hard strokes: where the stroke line
would turn a joint faster than that, the palm moves as fast as the slowest-allowed joint lets it
(``info["stroke_speed"]``). Over 40 placements at action[2] = +1, the tap then reaches 0.29-0.54 m/s (median
0.34), tap_back 0.43-0.50 and the push 0.18-0.35 (its forearm, across the body, turns the shoulder fastest); the
canonical stroke (0.18 m/s) and the gentle ones are never capped.

The canonical tap is moderate (the paper: "moderately hitting an object from its side"): at 0.18 m/s a ball or a
lying cylinder rolls some 5 to 25 cm on the table and stays in view of the head camera; the speed scale is
geometric, because the distance a struck object rolls grows with the square of its speed: at the gentlest tap (-1)
rolling objects move 2-3 cm, at the hardest (+1, as fast as the joints allow) many roll off the 1 m wide table
(see ``assets/README.md``).

For the grasp, 0 is the canonical grasp:

==========  ===============================================================  ======================
index       meaning                                                          range
==========  ===============================================================  ======================
0           height of the palm above the object's top when the hand closes   -0.5 .. +1.5 cm
1           offset of the object across the hand (towards the little finger) -1.5 .. +1.5 cm
2           finger speed while closing, 0.75 + 0.25 action[2] of the motors'  0.5 .. 1 of 180 deg/s
            speed limit
==========  ===============================================================  ======================

The grasp: palm down above the object, fingers pointing forward and to the right (60 degrees right of straight
ahead; turned with the object's yaw), the thumb opposed (under the palm, on the robot's side) and the fingers
open; the palm descends slowly towards just above the object's top and stops there or at the first touch, the
fingers and the thumb close until their motors' torque holds what they meet, the palm rises LIFT_HEIGHT and
holds still for HOLD_TIME; a held object is then carried PLACE_SHIFT to the robot's left and lowered until it
rests on the table, and the hand opens (an object not held is left where it is: the hand opens above it). An
object fits the open hand if it passes between the thumb, which hangs 6.4 cm below the palm, and the
fingertips: larger objects meet the thumb on the way down and are not enclosed, which makes a critical size.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from affordance_env.exceptions import InvalidValueError
from affordance_env.linalg import matmul
from affordance_env.objects import ObjectGeometry
from affordance_env.registry import check_behavior_name
from affordance_env.robot_model import HAND_OPEN

ACTION_DIM = 3
HEIGHT_RANGE = 0.015  # [m]
LATERAL_RANGE = 0.02  # [m]
#: Hand speed of the canonical tap [m/s], and the factor by which action[2] = +-1 multiplies or divides it.
SPEED_CANONICAL, SPEED_FACTOR = 0.18, 3.0
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
        robot: The robot variant it needs (:data:`affordance_env.robot_model.VARIANTS`).
    """

    name: str
    direction: np.ndarray
    R_world_hand: np.ndarray
    contact_offset: float
    description: str
    approach_clearance: float | None = APPROACH_CLEARANCE
    joint_ranges: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    success_rule: str = "rolled"
    robot: str = "tap"

    def __post_init__(self) -> None:
        if self.success_rule not in SUCCESS_RULES:
            raise InvalidValueError(f"success_rule must be one of {SUCCESS_RULES}, got {self.success_rule!r}.")


@dataclass(frozen=True)
class GraspBehavior:
    """Grasp from above with the fingered left hand, lift, hold, put down beside (see the module docstring).

    Attributes:
        name: Identifier used by ``behavior=`` of the environment.
        R_world_hand: Orientation of the palm frame (``l_hand_dh_frame``: x along the fingers, the palm facing -z)
            for an object at zero yaw, (3, 3).
        description: One line for the documentation.
        robot: The robot variant it needs.
    """

    name: str
    R_world_hand: np.ndarray
    description: str
    robot: str = "grasp"


def _rotation(fingers: tuple[float, float, float], palm_normal: tuple[float, float, float]) -> np.ndarray:
    x = np.asarray(fingers, dtype=float)
    z = np.asarray(palm_normal, dtype=float)
    return np.column_stack([x, np.cross(z, x), z])


#: The grasp's fingers point this far [rad] from world +x (forward is -x, the robot's left -y), turned with the
#: object's yaw: 120 degrees, forward and to the right, a direction the left arm reaches palm down over the whole
#: placement region (at 180, straight ahead, a third of it is out of reach).
GRASP_FINGERS_YAW = 2 * np.pi / 3


def grasp_orientation(yaw: float) -> np.ndarray:
    """Palm orientation of the grasp for an object at ``yaw`` [rad]: palm down, fingers at GRASP_FINGERS_YAW + yaw.

    The left palm faces -z of its frame, so that axis points up."""
    angle = GRASP_FINGERS_YAW + yaw
    return _rotation((np.cos(angle), np.sin(angle), 0.0), (0.0, 0.0, 1.0))


BEHAVIORS: dict[str, Behavior | GraspBehavior] = {
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
    "grasp": GraspBehavior(
        "grasp", grasp_orientation(0.0),
        "grasp from above with the fingered left hand, lift 8 cm, hold 1 s, put down 6 cm to the robot's left",
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
        raise InvalidValueError(f"rule must be one of {SUCCESS_RULES}, got {rule!r}.")
    return bool(label) if label.ndim == 0 else label


def get_behavior(name: str) -> Behavior | GraspBehavior:
    """The behaviour called ``name``; raises InvalidValueError listing the valid names."""
    return BEHAVIORS[check_behavior_name(name)]


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
        raise InvalidValueError(f"action must have shape ({ACTION_DIM},), got shape {a.shape}: {action!r}.")
    if not np.all(np.isfinite(a)):
        raise InvalidValueError(f"action must be finite, got {action!r}.")
    if np.any(np.abs(a) > 1.0 + 1e-6):
        raise InvalidValueError(f"action must lie in [-1, 1] in every dimension, got {action!r}.")
    return np.clip(a, -1.0, 1.0)


def half_extent_along(geometry: ObjectGeometry, yaw: float, direction: np.ndarray) -> float:
    """Half of the object's horizontal extent along ``direction`` (unit, world x-y) at ``yaw`` [m]."""
    r = geometry.geom_size[0]
    if geometry.object_type in ("sphere", "vertical_cylinder"):
        return float(r)
    c, s = np.cos(yaw), np.sin(yaw)
    axes = np.array([[c, s], [-s, c]])  # the body's x and y axes in the world plane
    return float(np.sum(r * np.abs(matmul(axes, direction))))


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


# --- the grasp -----------------------------------------------------------------------------------------------
#: Where the object's vertical axis passes through the hand when it closes, in the palm frame [m]: along the
#: fingers (x) and towards the little finger (y). The opposed thumb hangs under the palm, 4 cm to the thumb side
#: (-y), and the fingers curl in from 10 cm out, pushing the object back towards the thumb: 3 cm out and 2.5 cm
#: to the thumb side the object lies between the thumb and the index and middle fingers. Over the 90 canonical
#: grasps of ``benchmarks/grasp.py`` (100, 53 and 7 % held per third of sizes), this point moved by 5 mm along
#: either axis holds 93-100 % of the smallest third, 47-80 % of the middle one and 7-13 % of the largest: it sets
#: where in the middle third the critical size falls.
GRASP_CENTRE_HAND = (0.03, -0.025)
#: Gap between the palm and the object's top when the hand closes [m], and the change action[0] = +-1 makes.
GRASP_GAP, GRASP_HEIGHT_RANGE = 0.005, 0.01
#: Shift of the object across the hand (along the palm's y axis) at action[1] = +-1 [m].
GRASP_LATERAL_RANGE = 0.015
#: The fingers close at this share of their motors' speed limit at action[2] = 0, and action[2] = +-1 adds or takes
#: CLOSE_SPEED_RANGE of it.
CLOSE_SPEED_CANONICAL, CLOSE_SPEED_RANGE = 0.75, 0.25
#: How far the open hand's lowest point, the thumb's tip, hangs below the palm [m].
OPEN_HAND_DEPTH = 0.058
#: Clearance between the open hand's lowest point and the object's top at the approach pose [m], from which the
#: hand descends slowly: nothing can touch before.
GRASP_GUARD_CLEARANCE = 0.01
#: Height of the retreat above where the hand opened [m].
GRASP_RETREAT_HEIGHT = 0.08
#: The palm rises this much [m] with the closed hand, and holds still there for HOLD_TIME [s].
LIFT_HEIGHT, HOLD_TIME = 0.08, 1.0
#: Where the object is put down, relative to where it was [m] (world x, y): to the robot's left, towards the
#: arm, so that a grasped object ends 6 cm from where it stood: the final snapshot shows the grasp's effect.
PLACE_SHIFT = (0.0, -0.06)
#: The palm lowers the object to this height above the grasp pose [m] before the hand opens: a held object that
#: has not slipped is released a few millimetres above the table.
PLACE_CLEARANCE = 0.004
#: Driven finger joints [rad] of the closed hand: the open hand's (HAND_OPEN: the thumb opposed to the straight
#: fingers) with each flexion joint at its upper limit, so that the servos squeeze whatever stops the fingers
#: short of it, and the thumb turned further under the palm (opposition 1.3 rad of its 1.4), towards the fingers.
HAND_CLOSED: dict[str, float] = {
    **HAND_OPEN,
    "l_hand_metacarpus_joint": 1.3,
    "l_hand_thumb_proximal_joint": 1.4835,
    "l_hand_index_proximal_joint": 1.6581,
    "l_hand_medium_proximal_joint": 1.6581,
    "l_hand_pinky_proximal_joint": 1.6581,
}


#: Driven finger joints [rad] of the hand that lets go: the open hand's, with the thumb turned out from under the
#: object (opposition 0.3 rad: its tip 6.5 cm from the object's axis instead of 4.3), so that the hand rises from an
#: object it has put down without touching it.
HAND_RELEASE: dict[str, float] = {**HAND_OPEN, "l_hand_metacarpus_joint": 0.3}


@dataclass(frozen=True)
class GraspPlan:
    """Cartesian plan of one grasp: palm positions (``l_hand_dh_frame`` origin, world frame) [m].

    Attributes:
        p_above: Above the grasp pose, the open hand's lowest point GRASP_GUARD_CLEARANCE above the object's top;
            reached first, and the slow descent starts there.
        p_grasp: Where the hand closes: the palm just above the object's top.
        p_lift: Where the closed hand holds the object: LIFT_HEIGHT above ``p_grasp``.
        p_place: Where the hand opens: PLACE_SHIFT beside ``p_grasp`` and PLACE_CLEARANCE above it.
        p_retreat: GRASP_RETREAT_HEIGHT above ``p_place``: the open hand withdraws upward this far before going
            home.
        R_world_hand: Palm orientation throughout.
        close_speed: Speed of the closing fingers, a share of their motors' speed limit.
        hold_time: How long the lifted object is held still [s].
        hand_open, hand_closed, hand_release: Targets of the driven finger joints [rad], by joint name: the
            open hand of the approach, the closed hand, and the hand that lets go.
    """

    p_above: np.ndarray
    p_grasp: np.ndarray
    p_lift: np.ndarray
    p_place: np.ndarray
    p_retreat: np.ndarray
    R_world_hand: np.ndarray
    close_speed: float
    hold_time: float
    hand_open: dict[str, float]
    hand_closed: dict[str, float]
    hand_release: dict[str, float]


def plan_grasp(
    behavior: GraspBehavior, geometry: ObjectGeometry, p_world_object: np.ndarray, yaw: float, table_top: float,
    action: np.ndarray,
) -> GraspPlan:
    """Plan the grasp of an object resting on the table.

    Args:
        behavior: The grasp behaviour.
        geometry: The object's geometry (the paper takes shape, size and position from the simulator).
        p_world_object: Object centre [m], (3,).
        yaw: Object yaw [rad]; the hand turns with it (boxes and lying cylinders are then gripped across faces).
        table_top: Height of the table top [m].
        action: (3,) in [-1, 1]; see the module documentation.
    """
    a = check_action(action)
    R = grasp_orientation(yaw)
    top = float(p_world_object[2]) + geometry.half_height
    if top <= table_top:
        raise InvalidValueError(f"the object's top ({top:.3f} m) must be above the table top ({table_top:.3f} m).")
    centre_hand = np.array([GRASP_CENTRE_HAND[0], GRASP_CENTRE_HAND[1] + a[1] * GRASP_LATERAL_RANGE, 0.0])
    p_grasp = np.array([p_world_object[0], p_world_object[1], 0.0]) - matmul(R, centre_hand)
    p_grasp[2] = top + GRASP_GAP + a[0] * GRASP_HEIGHT_RANGE
    p_place = p_grasp + np.array([PLACE_SHIFT[0], PLACE_SHIFT[1], PLACE_CLEARANCE])
    return GraspPlan(
        p_above=np.array([p_grasp[0], p_grasp[1], max(p_grasp[2], top + OPEN_HAND_DEPTH + GRASP_GUARD_CLEARANCE)]),
        p_grasp=p_grasp,
        p_lift=p_grasp + np.array([0.0, 0.0, LIFT_HEIGHT]),
        p_place=p_place,
        p_retreat=p_place + np.array([0.0, 0.0, GRASP_RETREAT_HEIGHT]),
        R_world_hand=R,
        close_speed=float(CLOSE_SPEED_CANONICAL + CLOSE_SPEED_RANGE * a[2]),
        hold_time=HOLD_TIME,
        hand_open=dict(HAND_OPEN),
        hand_closed=dict(HAND_CLOSED),
        hand_release=dict(HAND_RELEASE),
    )
