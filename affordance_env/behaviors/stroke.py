"""The strokes (``tap``, ``tap_back``, ``push``): a straight line of the hand through the object.

A stroke is a straight hand stroke along a horizontal direction, with a fixed hand orientation and a contact
surface on the hand. :func:`plan_stroke` turns (behaviour, object, action) into Cartesian waypoints, a pure
function; :func:`run_stroke` executes them: the reach goes through the pose above the pre-stroke pose (when the
plan has one), so the arm never sweeps across the object; the stroke is a Cartesian line turned into a joint
trajectory by the arm's IK (:class:`~affordance_env.motion.LinePath`), its speed capped where a joint would exceed
its velocity limit, and it is watched for the first touch at every physics step near the object. Its IK is solved
before any move, so :func:`stroke_reachable` answers from the kinematics alone.

The action is three numbers in [-1, 1]; 0 is the paper's canonical tap:

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
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from affordance_env.behaviors.action import ACTION_DIM, check_action
from affordance_env.behaviors.base import palm_rotation
from affordance_env.behaviors.success import SUCCESS_RULES, is_success
from affordance_env.exceptions import InvalidValueError
from affordance_env.kinematics import IKResult
from affordance_env.linalg import dot, matmul, norm
from affordance_env.motion import (
    CONTROL_DT,
    MIN_MOVE_TIME,
    HandTarget,
    LinePath,
    MotionExecutor,
    ReachOutcome,
    ik_verdict,
)
from affordance_env.objects import ObjectGeometry, object_geometry
from affordance_env.outcome import Labels
from affordance_env.trajectory import JointTrajectory, minimum_jerk

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
#: Approach clearance of tap_back [m]: its hand crosses over the object, from home on the object's right to its
#: left, and the forearm, trailing behind and below the hand, swept the top of objects 9-10 cm tall with the
#: ``APPROACH_CLEARANCE`` of the other behaviours.
CROSSING_CLEARANCE = 0.08
#: The hand may start the stroke at most this far from the planned pre-stroke pose [m], and may have moved
#: the object at most this much before the stroke [m]; otherwise the interaction is marked failed.
MAX_START_ERROR, MAX_OBJECT_MOVED_BEFORE = 0.01, 0.003

#: The stroke reaches its speed in this time [s] from rest, within the first 3 cm (the clearance before the
#: object) even at its fastest.
STROKE_RAMP = 0.1


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
        joint_ranges: The behaviour's joint ranges for the IK (:attr:`StrokeBehavior.joint_ranges`).
        to_rest: Whether the line ends at rest (the draw, which drags the object to its end); else at speed (the
            strokes, which stop ``follow_through`` past the first touch).
        ramp: Time [s] in which the line reaches its speed from rest (and comes to rest, with ``to_rest``).
    """

    p_above: np.ndarray | None
    p_start: np.ndarray
    p_end: np.ndarray
    direction: np.ndarray
    speed: float
    R_world_hand: np.ndarray
    follow_through: float
    joint_ranges: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    to_rest: bool = False
    ramp: float = STROKE_RAMP


def half_extent_along(geometry: ObjectGeometry, yaw: float, direction: np.ndarray) -> float:
    """Half of the object's horizontal extent along ``direction`` (unit, world x-y) at ``yaw`` [m]."""
    r = geometry.geom_size[0]
    if geometry.object_type in ("sphere", "vertical_cylinder"):
        return float(r)
    c, s = np.cos(yaw), np.sin(yaw)
    axes = np.array([[c, s], [-s, c]])  # the body's x and y axes in the world plane
    return float(np.sum(r * np.abs(matmul(axes, direction))))


def plan_stroke(
    behavior: StrokeBehavior, geometry: ObjectGeometry, p_world_object: np.ndarray, yaw: float, table_top: float,
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


#: The reach's servo targets must keep the arm's geoms (hand, fingers, wrist, forearm) at least this far from the
#: object [m] (checked every REACH_SWEEP_STRIDE control ticks), else the stroke is not feasible: an arm that sweeps
#: into the object moves it before the stroke (a "reach" failure). The arm follows its targets to within a
#: millimetre or two on the way down (servo lag at the reach's speed), so targets that pass nearer than that may
#: touch. Over 599 strokes and draws at random actions (``python benchmarks/reach_clearance.py``), of the 570 that
#: the other checks accept, 2 moved the object before the stroke, their targets 0.1 and 0.7 mm from it; so did 2 of
#: the 150 interactions of ``affordance plan``'s multi-step episodes at seed 0 (0.6 and 1.3 mm, moving it 3 and 15
#: mm), where the planner chose actions at the edge of their range. 2 mm refuses those and 6 of the 570 that work
#: (1 %); 1 mm lets one through, 1 cm refuses 48 that work.
REACH_CLEARANCE, REACH_SWEEP_STRIDE = 0.002, 5
#: The reach's servo targets may put the arm's geoms at most this far into the table [m] (checked at the same
#: samples and at the pre-stroke pose), else the stroke is not feasible: the forearm then rests on the table and
#: holds the hand off its pre-stroke pose. Over 375 random tap_backs that passed the checks above (objects over its
#: workspace, the scene with both arms), the 2 whose targets went 6.2 and 8.5 mm into the table started 12-15 mm
#: off their pose (a "reach" failure); none of the others, down to 4.9 mm; pushes go at most 1.5 mm in.
REACH_TABLE_PENETRATION = 0.005


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
        speed: Cruise speed of the palm along the stroke [m/s]: the plan's, or lower where a joint would have
            exceeded its velocity limit.
    """

    hand_travel: float
    start_error: float
    object_moved: float
    q_withdraw: np.ndarray | None
    speed: float


def hand_target(plan: StrokePlan) -> HandTarget:
    """How the IK holds the hand along the stroke: the plan's orientation and the behaviour's joint ranges."""
    return HandTarget(plan.R_world_hand, plan.joint_ranges)


def approach_posture(motion: MotionExecutor, plan: StrokePlan) -> np.ndarray:
    """The arm posture that reaches ``plan``'s pre-stroke pose, solved from the current servo targets: where the IK
    of every later pre-stroke pose of the behaviour starts (:func:`plan_approach`), instead of from wherever the arm
    is.

    The posture does not depend on the interactions run before, so neither do the data; from it a pre-stroke pose
    anywhere in the placement region is 3-8 IK iterations away instead of 11-23 from home.
    """
    return motion.ik(plan.p_start, motion.physics.joint_targets(), hand_target(plan)).q


def approach_start(motion: MotionExecutor, plan: StrokePlan, posture: np.ndarray | None, *, check: bool = False
                   ) -> IKResult:
    """IK of the pre-stroke pose from the arm's ``posture`` (:func:`approach_posture`; None: the current servo
    targets); ``check``: see :meth:`~affordance_env.motion.MotionExecutor.ik`."""
    q_init = motion.physics.joint_targets()  # the neck and the fingers keep their targets
    if posture is not None:
        reach = motion.kinematics.reach_dofs
        q_init[reach] = posture[reach]
    return motion.ik(plan.p_start, q_init, hand_target(plan), check=check)


def approach_above(motion: MotionExecutor, plan: StrokePlan, start: IKResult) -> IKResult | None:
    """IK of the pose above the pre-stroke pose ``start`` (None if the plan has none), from ``start``: the two
    differ by a short vertical move, so the descent (and the way up after the stroke) is a small joint motion,
    not a change of arm posture. A via point that only has to clear the object: its configuration is used even
    where it misses the pose."""
    return None if plan.p_above is None else motion.ik(plan.p_above, start.q, hand_target(plan))


def plan_approach(motion: MotionExecutor, plan: StrokePlan, posture: np.ndarray | None
                  ) -> tuple[IKResult | None, IKResult]:
    """IK of the pose above the pre-stroke pose (None if the plan has none) and of the pre-stroke pose, from the
    arm's ``posture`` (:func:`approach_start`, :func:`approach_above`)."""
    start = approach_start(motion, plan, posture)
    return approach_above(motion, plan, start), start


def stroke_line(motion: MotionExecutor, plan: StrokePlan, start: IKResult, *, check: bool = False) -> LinePath:
    """The stroke's line from the pre-stroke pose ``start``, every waypoint's IK solved (the joint speeds along
    the whole line cap the stroke's speed); ``check``: see :class:`~affordance_env.motion.LinePath`."""
    length = dot(plan.p_end - plan.p_start, plan.direction)
    return LinePath(motion, plan.p_start, plan.direction, length, hand_target(plan), plan.speed, start.q,
                    ramp=plan.ramp, to_rest=plan.to_rest, check=check)


def plan_stroke_path(motion: MotionExecutor, plan: StrokePlan, posture: np.ndarray | None
                     ) -> tuple[IKResult | None, IKResult, LinePath]:
    """The stroke's IK, solved before any move: the poses of :func:`plan_approach` and the stroke's line."""
    above, start = plan_approach(motion, plan, posture)
    return above, start, stroke_line(motion, plan, start)


def reach_trajectory(motion: MotionExecutor, above: IKResult | None, start: IKResult) -> JointTrajectory:
    """The joint targets of the reach to the pre-stroke pose (through the pose above it, if any), from where the
    arm is now: what :func:`run_stroke` follows."""
    waypoints = [start.q] if above is None else [above.q, start.q]
    return minimum_jerk(motion.physics.joint_targets(), waypoints, motion.planned_speed, CONTROL_DT,
                        min_duration=MIN_MOVE_TIME)


def stroke_reachable(motion: MotionExecutor, plan: StrokePlan, posture: np.ndarray | None) -> bool:
    """Whether :func:`run_stroke` will find every pose of ``plan`` within the IK's tolerances, and its reach keeps
    the arm ``REACH_CLEARANCE`` from the object and out of the table beyond ``REACH_TABLE_PENETRATION``;
    kinematics only. The IK of a pose whose miss decides the answer gives up once it stands still (``check``):
    the same answers, a pose out of reach found sooner."""
    start = approach_start(motion, plan, posture, check=True)
    if not ik_verdict([start])[0]:  # out of reach already at the pre-stroke pose: the line is not solved
        return False
    if not ik_verdict(stroke_line(motion, plan, start, check=True).results)[0]:
        return False
    above = approach_above(motion, plan, start)  # a via point, used as it is: solved in full
    samples = reach_trajectory(motion, above, start).q[::REACH_SWEEP_STRIDE]
    # one kinematic pass over the reach for the object and the table, then the pre-stroke pose for the table
    physics = motion.physics
    clearance, table = physics.sweep_clearance(samples, REACH_CLEARANCE, 0.0)
    if clearance < REACH_CLEARANCE:
        return False
    return physics.sweep_clearance(start.q, None, table)[1] >= -REACH_TABLE_PENETRATION


def run_stroke(motion: MotionExecutor, plan: StrokePlan, posture: np.ndarray | None) -> StrokeOutcome:
    """Reach, and stroke until contact plus follow-through (or full travel); not the way home. The IK starts from
    ``posture`` (:func:`plan_approach`)."""
    physics = motion.physics
    above, start, path = plan_stroke_path(motion, plan, posture)
    p_object_before = physics.object_pose()[:3]
    motion.phase = "reach"
    with motion.stepping(motion.free_timestep):  # the object rests and the hand moves in free space
        motion.follow(reach_trajectory(motion, above, start))  # through the pose above, if any
        start_error = motion.settle(plan.p_start)
    object_moved = norm(physics.object_pose()[:3] - p_object_before)
    p_hand_start = motion.palm.copy()
    motion.phase = "stroke"
    result = motion.follow_line(path, physics.hand_touches_object, per_step=True,
                              follow_through=plan.follow_through)
    travel = dot(motion.palm.copy() - p_hand_start, plan.direction)
    # The pose above the object is a via point that only has to clear it; the stroke itself must be exact.
    return StrokeOutcome(*ik_verdict([start, *path.results]), result.touched, result.time, result.speed,
                         travel, start_error, object_moved, None if above is None else above.q, path.speed)


def canonical_posture(behavior: Any, motion: MotionExecutor, placement_centre: np.ndarray, size: float
                      ) -> np.ndarray:
    """The posture every approach's IK of a line behaviour (a stroke, the draw) starts from: that of its canonical
    action on a sphere of ``size`` [m] at the centre of the placement region (:func:`approach_posture`)."""
    table_top = motion.physics.table_top
    geometry = object_geometry("sphere", size)
    centre = np.array([*placement_centre, table_top + geometry.half_height])
    motion.physics.reset_home()
    return approach_posture(motion, behavior.plan(geometry, centre, 0.0, table_top, np.zeros(ACTION_DIM)))


def reach_failure(outcome: StrokeOutcome, what: str) -> str | None:
    """Why the reach to the line's start makes the interaction invalid (the arm moved the object before the line,
    or the line started too far from its pose), naming the line ``what``; None if it did not."""
    if outcome.object_moved > MAX_OBJECT_MOVED_BEFORE:
        return f"reach: the arm moved the object by {outcome.object_moved * 1e3:.1f} mm before the {what}"
    if outcome.start_error > MAX_START_ERROR:
        return f"reach: the {what} started {outcome.start_error * 1e3:.1f} mm from the planned pose"
    return None


@dataclass(frozen=True)
class StrokeBehavior:
    """A horizontal hand stroke: reach, stroke until contact and follow-through.

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
        success_rule: What makes an interaction a success, one of
            :data:`~affordance_env.behaviors.success.SUCCESS_RULES` (see
            :func:`~affordance_env.behaviors.success.is_success`).
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
    kind: ClassVar[str] = "stroke"

    def __post_init__(self) -> None:
        if self.success_rule not in SUCCESS_RULES:
            raise InvalidValueError(f"success_rule must be one of {SUCCESS_RULES}, got {self.success_rule!r}.")

    def prepare(self, motion: MotionExecutor, placement_centre: np.ndarray, size: float) -> np.ndarray:
        return canonical_posture(self, motion, placement_centre, size)

    def plan(self, geometry: ObjectGeometry, p_object: np.ndarray, yaw: float, table_top: float,
             action: np.ndarray) -> StrokePlan:
        return plan_stroke(self, geometry, p_object, yaw, table_top, action)

    def execute(self, motion: MotionExecutor, plan: StrokePlan, posture: np.ndarray | None,
                at_end: Callable[[], None] | None = None) -> StrokeOutcome:
        # A stroke ends as the paper measures it when the struck object has come to rest: after the plan.
        return run_stroke(motion, plan, posture)

    def reachable(self, motion: MotionExecutor, plan: StrokePlan, posture: np.ndarray | None) -> bool:
        return stroke_reachable(motion, plan, posture)

    def via_home(self, outcome: StrokeOutcome) -> np.ndarray | None:
        return outcome.q_withdraw

    def awaited_since(self, outcome: StrokeOutcome, now: float) -> float:
        return outcome.contact_time if outcome.contact else now  # from the first touch

    def failure(self, outcome: StrokeOutcome) -> str | None:
        reach = reach_failure(outcome, "stroke")
        if reach is not None:
            return reach
        if not outcome.contact:
            return "tap: the hand never touched the object"
        return None

    def success(self, outcome: StrokeOutcome, labels: Labels, displacement: float, threshold: float) -> bool:
        return bool(is_success(self.success_rule, labels.rolled, displacement, threshold))

    def facts(self, outcome: StrokeOutcome) -> Mapping[str, Any]:
        return {"stroke_speed": outcome.speed}


#: The strokes' objects, by name (:mod:`affordance_env.registry` lists them).
BEHAVIORS: Mapping[str, StrokeBehavior] = {
    "tap": StrokeBehavior(
        "tap", np.array([0.0, -1.0]), palm_rotation((-1, 0, 0), (0, -1, 0)), 0.012,
        "the paper's tap: the palm hits the object from its right side, moving to the robot's left (-y)",
        approach_clearance=None, joint_ranges=FOREARM_RAISED,
    ),
    "tap_back": StrokeBehavior(
        "tap_back", np.array([0.0, 1.0]), palm_rotation((-1, 0, 0), (0, -1, 0)), 0.039,
        "tap from the other side: the back of the hand hits the object from its left, moving right (+y)",
        approach_clearance=CROSSING_CLEARANCE, joint_ranges=FOREARM_RAISED,
    ),
    "push": StrokeBehavior(
        "push", np.array([-1.0, 0.0]),
        palm_rotation((-np.sin(PUSH_HAND_TURN), -np.cos(PUSH_HAND_TURN), 0),
                      (np.cos(PUSH_HAND_TURN), -np.sin(PUSH_HAND_TURN), 0)),
        0.039,
        "push from the front: the back of the hand pushes the object's near face away from the robot (-x)",
        joint_ranges=FOREARM_RAISED, success_rule="moved",
    ),
}
