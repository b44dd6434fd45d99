"""The draw (pull): the right hand reaches behind the object and drags it toward the robot (+x).

Draw is one of the iCub's four standard actions in affordance learning (tapFromRight, tapFromLeft, draw, push:
Dehban et al., 2016; Saponaro et al., ICDL-EpiRob 2017). In their module the hand starts 10 cm behind the object
(on its far side), 3 cm above the table, and sweeps 10 cm past the object's centre toward the body in 1.3 s; it
works only with a curled hand: a straight hand passes over the object (it moved objects -0.4 cm on average, 0 of 20
over 2 cm), an arched one moved them 5.4 cm (18 of 20), a bent one 4.4 cm (17 of 20).

The right hand here is the V2.5 model's rigid hand, which cannot curl. The draw holds it as a rake
(:func:`draw_orientation`): the fingers across, to the robot's left, the palm facing the robot and tilted 50
degrees toward the table, so that the palm is the curled hand's inner face and presses the object toward the robot
and onto the table rather than riding over it. It is executed as a stroke
(:func:`~affordance_env.behaviors.stroke.run_stroke`: through the pose above the start, so that the arm never sweeps
across the object; the IK of every pose solved before any move; joint speeds capped at their motors' limits), but
the line does not stop at the first touch: the palm drags the object to the line's end and stops there at rest;
the way home then rises straight up from there.

Two departures from Saponaro's module, both set by this scene:

- the hand starts DRAW_GAP (5 cm) beyond the object's far side, not 10 cm beyond its centre: the arm reaches this
  hand 42 cm in front of the robot at most, and the far side of the placement region's largest objects lies 38 cm
  out;
- the canonical drag is shorter and slower (the palm stops 2 cm past the object's centre, at 8 cm/s): the table's
  near edge is 14 cm in front of the placement centre, and what is dragged further or faster goes over it (objects
  placed as the paper's, seeds 0-29: the canonical draw leaves none off the table; 6 cm past at 8 cm/s, 6 of 29;
  6 cm past at 16 cm/s, 10 of 29: a ball rolls on at the hand's speed when the hand stops).

Over 200 canonical draws (``python benchmarks/draw.py``) 4 fail (2 %, all "reach": boxes of 9.6-10 cm that the arm
nudges 3.2-3.9 mm on its way behind them, over the 3 mm a stroke allows); the others move the object a median 9.2 cm
toward the robot (5.0 cm for the smallest third of sizes, 10.3 for the largest), 99.5 % of them at least 2 cm,
and 0.6 cm across; one ball rolled on over the table's edge. Balls of 4-5.5 cm move only 1.7-3.0 cm: the palm, tilted
toward the table and 4 cm above it at least, rides over them once they are under its lower edge.

The action is three numbers in [-1, 1]; 0 is the canonical draw:

==========  ===============================================================  ======================
index       meaning                                                          range
==========  ===============================================================  ======================
0           lateral offset of the line, across the draw direction (+y)       -2 .. +2 cm
1           drag length: where the palm stops, past the object's centre      -2 .. +6 cm
2           hand speed along the line, 0.08 m/s x 2 ** action[2], at most     0.04 .. 0.16 m/s
            what the arm's joint speed limits allow
==========  ===============================================================  ======================

The palm centre is a little above the object's centre (DRAW_HEIGHT), and at least DRAW_MIN_PALM_HEIGHT (4 cm)
above the table, where the tilted hand's lowest point clears it by 4 mm. An object moves
about as far as the palm travels after touching it: the drag length plus its own half size and the palm's
thickness (5-8 cm for the canonical draw), plus what it rolls on.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from affordance_env.behaviors.action import check_action
from affordance_env.behaviors.base import palm_rotation
from affordance_env.behaviors.stroke import (
    CROSSING_CLEARANCE,
    FOREARM_RAISED,
    HAND_BELOW_PALM,
    MIN_PALM_HEIGHT,
    StrokeOutcome,
    StrokePlan,
    canonical_posture,
    half_extent_along,
    reach_failure,
    run_stroke,
    stroke_reachable,
)
from affordance_env.behaviors.success import is_success
from affordance_env.linalg import matmul
from affordance_env.motion import HandTarget, MotionExecutor
from affordance_env.objects import ObjectGeometry
from affordance_env.outcome import Labels

#: The draw's hand (:func:`draw_orientation`) [rad]: the palm tilted down from upright, turned about its normal, and
#: turned about the vertical.
DRAW_HAND_TILT, DRAW_HAND_ROLL, DRAW_HAND_TURN = np.radians(50.0), np.radians(30.0), np.radians(5.0)
#: The joint ranges the draw's IK keeps to [rad]: the strokes' raised forearm, and the torso leaning forward at most
#: 35 degrees. Free, the IK reaches behind the farthest objects by leaning 50-70 degrees over the table, which
#: brings the other arm, held at its home pose, down onto it (the scene with both arms).
DRAW_JOINT_RANGES: dict[str, tuple[float, float]] = {**FOREARM_RAISED, "torso_pitch": (-0.35, np.radians(35.0))}
#: The draw's direction in the world x-y plane: toward the robot.
DRAW_DIRECTION = np.array([1.0, 0.0])
#: Distance from the palm frame's origin to the palm's surface [m], which leads the draw (the tap's palm).
PALM_OFFSET = 0.012
#: The palm centre's height above the table, in half heights of the object (and at least MIN_PALM_HEIGHT): above
#: the object's centre, so that the forearm, sloping up from the wrist over the object toward the robot, clears the
#: top of the tallest objects (at 1.0, 4 of 80 canonical draws touch the object on the way there, all of objects
#: 9-10 cm tall; at 1.4, 1). A ball is taken at its centre's height: the palm, facing the table too, would press it
#: down from above its equator instead of pulling it (at 1.4, balls moved a median 3.6 cm instead of 9).
DRAW_HEIGHT = 1.4
#: The palm centre's lowest height above the table [m]: the strokes' 4 cm. The tilted hand's lowest point is then
#: 4 mm above the table (its servo targets; 3.6 cm below the palm centre). Lower, the targets go into the table:
#: at 2.5 cm, 8-11 mm, and the hand drags on it (which the reach's table check refuses).
DRAW_MIN_PALM_HEIGHT = MIN_PALM_HEIGHT
#: The palm starts this far beyond the object's far side [m].
DRAW_GAP = 0.05
#: The canonical line ends with the palm centre this far past the object's centre toward the robot [m].
DRAW_PAST = 0.02
#: Change of the end point at action[1] = +-1 [m]: the drag ends 2 cm short of to 6 cm past the object's centre.
DRAW_PAST_RANGE = 0.04
#: Lateral offset of the line at action[0] = +-1 [m].
DRAW_LATERAL_RANGE = 0.02
#: Hand speed of the canonical draw [m/s], and the factor by which action[2] = +-1 multiplies or divides it.
DRAW_SPEED, DRAW_SPEED_FACTOR = 0.08, 2.0
#: The way home rises this far [m] from where the draw stopped before it turns home.
DRAW_RETREAT_HEIGHT = 0.06
#: The draw's line reaches its speed in this time [s] from rest, and comes to rest in as long.
DRAW_RAMP = 0.1


def plan_draw(behavior: DrawBehavior, geometry: ObjectGeometry, p_world_object: np.ndarray, yaw: float,
              table_top: float, action: np.ndarray) -> StrokePlan:
    """Plan the draw of an object resting on the table: a pure function.

    Args:
        behavior: The draw.
        geometry: The object's geometry.
        p_world_object: Object centre [m], (3,).
        yaw: Object yaw [rad].
        table_top: Height of the table top [m].
        action: (3,) in [-1, 1]; see the module documentation.
    """
    a = check_action(action)
    d = np.array([DRAW_DIRECTION[0], DRAW_DIRECTION[1], 0.0])
    across = np.array([-DRAW_DIRECTION[1], DRAW_DIRECTION[0], 0.0])
    share = 1.0 if geometry.object_type == "sphere" else DRAW_HEIGHT
    height = max(share * geometry.half_height, DRAW_MIN_PALM_HEIGHT)
    centre = np.array([p_world_object[0], p_world_object[1], table_top + height]) + a[0] * DRAW_LATERAL_RANGE * across
    half = half_extent_along(geometry, yaw, DRAW_DIRECTION)
    p_start = centre - d * (half + PALM_OFFSET + DRAW_GAP)
    p_end = centre + d * (DRAW_PAST + a[1] * DRAW_PAST_RANGE)
    p_above = np.array([p_start[0], p_start[1],
                        table_top + 2 * geometry.half_height + HAND_BELOW_PALM + behavior.approach_clearance])
    return StrokePlan(
        p_above=p_above,
        p_start=p_start,
        p_end=p_end,
        direction=d,
        speed=DRAW_SPEED * DRAW_SPEED_FACTOR ** a[2],
        R_world_hand=behavior.R_world_hand,
        follow_through=np.inf,  # the palm drags the object to the line's end
        joint_ranges=behavior.joint_ranges,
        to_rest=True,
        ramp=DRAW_RAMP,
    )


@dataclass(frozen=True)
class DrawBehavior:
    """Reach behind the object, drag it toward the robot along a straight line, stop at rest (see the module).

    Attributes:
        name: Identifier used by ``behavior=`` of the environment.
        R_world_hand: Orientation of the palm frame during the draw (columns: fingers, thumb side, palm normal).
        description: One line for the documentation.
        approach_clearance: Clearance between the hand's lowest point and the object's top at the pose above the
            start, which the hand passes through on its way there and back [m].
        joint_ranges: Narrower joint ranges the IK keeps to for every pose (see
            :data:`~affordance_env.behaviors.stroke.FOREARM_RAISED`).
        success_rule: What makes a draw a success (:func:`~affordance_env.behaviors.success.is_success`):
            ``"moved"``, the object's centre travelled more than the threshold on the table.
        robot: The robot variant it needs.
    """

    name: str
    R_world_hand: np.ndarray
    description: str
    approach_clearance: float = CROSSING_CLEARANCE
    joint_ranges: Mapping[str, tuple[float, float]] = field(default_factory=lambda: dict(DRAW_JOINT_RANGES))
    success_rule: str = "moved"
    robot: str = "tap"
    kind: ClassVar[str] = "draw"

    @property
    def direction(self) -> np.ndarray:
        """The draw's direction in the world x-y plane, (2,): toward the robot (+x)."""
        return DRAW_DIRECTION.copy()

    def prepare(self, motion: MotionExecutor, placement_centre: np.ndarray, size: float) -> np.ndarray:
        return canonical_posture(self, motion, placement_centre, size)

    def plan(self, geometry: ObjectGeometry, p_object: np.ndarray, yaw: float, table_top: float,
             action: np.ndarray) -> StrokePlan:
        return plan_draw(self, geometry, p_object, yaw, table_top, action)

    def execute(self, motion: MotionExecutor, plan: StrokePlan, posture: np.ndarray | None,
                at_end: Callable[[], None] | None = None) -> StrokeOutcome:
        # The draw ends as the paper would measure it once the drawn object rests: after the plan.
        outcome = run_stroke(motion, plan, posture)
        # The way home rises first, straight up from where the hand stopped, not back across the object.
        p_up = motion.palm.copy() + np.array([0.0, 0.0, DRAW_RETREAT_HEIGHT])
        up = motion.ik(p_up, motion.physics.joint_targets(), HandTarget(plan.R_world_hand, plan.joint_ranges))
        return dataclasses.replace(outcome, q_withdraw=up.q)

    def reachable(self, motion: MotionExecutor, plan: StrokePlan, posture: np.ndarray | None) -> bool:
        return stroke_reachable(motion, plan, posture)

    def via_home(self, outcome: StrokeOutcome) -> np.ndarray | None:
        return outcome.q_withdraw

    def awaited_since(self, outcome: StrokeOutcome, now: float) -> float:
        return now  # the hand stopped at the line's end, at rest: the object is awaited from there

    def failure(self, outcome: StrokeOutcome) -> str | None:
        reach = reach_failure(outcome, "draw")
        if reach is not None:
            return reach
        if not outcome.contact:
            return "draw: the hand never touched the object"
        return None

    def success(self, outcome: StrokeOutcome, labels: Labels, displacement: float, threshold: float) -> bool:
        return bool(is_success(self.success_rule, labels.rolled, displacement, threshold))

    def facts(self, outcome: StrokeOutcome) -> Mapping[str, Any]:
        return {"stroke_speed": outcome.speed}


def draw_orientation() -> np.ndarray:
    """The palm's orientation during the draw, (3, 3) (columns: fingers, thumb side, palm normal).

    From the push's fingers-across hand with the palm facing the robot (+x), turned DRAW_HAND_TILT down about the
    fingers' axis (the palm faces the robot and the table, as a rake), DRAW_HAND_ROLL about the palm's normal
    (the fingertips lower than the wrist) and DRAW_HAND_TURN about the vertical (the fingers a little forward). The
    arm's joints reach this hand 6-42 cm in front of the robot over the placement region's width; with the palm
    upright (facing +x, fingers level), not beyond 30 cm, short of the far side of the placement region (the IK's
    error 15-100 mm beyond it).
    """
    upright = palm_rotation((0.0, -1.0, 0.0), (1.0, 0.0, 0.0))
    turn = matmul(matmul(_rotation_z(-DRAW_HAND_TURN), _rotation_y(DRAW_HAND_TILT)), _rotation_x(DRAW_HAND_ROLL))
    return matmul(turn, upright)


def _rotation_x(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _rotation_y(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _rotation_z(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


#: The draw's object, by name (:mod:`affordance_env.registry` lists it).
BEHAVIORS: Mapping[str, DrawBehavior] = {
    "draw": DrawBehavior(
        "draw", draw_orientation(),
        "draw (pull): the palm reaches behind the object and drags it toward the robot (+x)",
    ),
}
