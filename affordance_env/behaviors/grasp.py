"""The grasp: take the object from above with the fingered left hand, lift it, hold it, put it down beside.

:func:`plan_grasp` plans it, a pure function; :func:`run_grasp` executes it: reach above the object with the open
hand, descend until it touches, close, lift and hold; put down a held object beside and open the hand once it
rests. Every move is a trajectory of :mod:`affordance_env.trajectory` played by the servo loop of
:class:`~affordance_env.motion.MotionExecutor`; the hand's driven finger joints close under a light current limit
until they hold, then squeeze with their motors' full torque. Its poses' IK is solved before any move, so
:func:`grasp_reachable` answers from the kinematics alone.

The action is three numbers in [-1, 1]; 0 is the canonical grasp:

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

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from affordance_env.behaviors.action import check_action
from affordance_env.behaviors.base import palm_rotation
from affordance_env.exceptions import InvalidValueError
from affordance_env.kinematics import IKResult
from affordance_env.linalg import matmul
from affordance_env.motion import (
    CONTROL_DT,
    MIN_MOVE_TIME,
    HandTarget,
    MotionExecutor,
    ReachOutcome,
    ik_verdict,
    object_at_rest,
)
from affordance_env.objects import ObjectGeometry
from affordance_env.outcome import Labels, grasp_success
from affordance_env.robot_model import HAND_OPEN
from affordance_env.trajectory import minimum_jerk

#: The grasp's fingers point this far [rad] from world +x (forward is -x, the robot's left -y), turned with the
#: object's yaw: 120 degrees, forward and to the right, a direction the left arm reaches palm down over the whole
#: placement region (at 180, straight ahead, a third of it is out of reach).
GRASP_FINGERS_YAW = 2 * np.pi / 3


def grasp_orientation(yaw: float) -> np.ndarray:
    """Palm orientation of the grasp for an object at ``yaw`` [rad]: palm down, fingers at GRASP_FINGERS_YAW + yaw.

    The left palm faces -z of its frame, so that axis points up."""
    angle = GRASP_FINGERS_YAW + yaw
    return palm_rotation((np.cos(angle), np.sin(angle), 0.0), (0.0, 0.0, 1.0))


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
#: Pick and place: where the object goes at action[0] = +-1 (along x) and action[1] = +-1 (along y) [m], from
#: where it stood.
PLACE_RANGE = 0.2
#: The palm lowers the object to this height above the grasp pose [m] before the hand opens: a held object that
#: has not slipped is released a few millimetres above the table.
PLACE_CLEARANCE = 0.004
#: Pick and place: where the carry is expected to bring the palm, relative to the plan's nominal put-down pose
#: (``p_place`` PLACE_APPROACH above the grasp's height), in the hand's frame [m], by object type. The closing
#: fingers move the object in the hand: it hangs 1-2 cm from where the grasp aimed it (GRASP_CENTRE_HAND), and for
#: all but balls 0.5-1.4 cm lower below the palm, and the carry brings the object, as it hangs, over the place
#: asked and PLACE_APPROACH above the table, so that the palm ends this far from the nominal pose. The means over
#: 48-55 held objects of each type, 4-7 cm, 20-36 cm in front of the robot, at actions within +-0.6; their spread
#: is 2-5 mm (11 mm in height for boxes, 9 mm across the hand for balls, which roll in it). ``feasible`` checks
#: the carry's end there: checking the nominal pose, 9 of 122 pick and place grasps it accepted (200 random draws
#: over the left arm's reach) failed, the carry's last pose out of reach; checking this one, 1 of 226 (two such
#: sets of draws).
PUT_DOWN_OFFSET_HAND: dict[str, tuple[float, float, float]] = {
    "sphere": (0.020, -0.001, 0.0),
    "box": (0.010, 0.0, 0.014),
    "horizontal_cylinder": (0.015, 0.0, 0.005),
    "vertical_cylinder": (0.014, 0.003, 0.009),
}
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
        p_put_down: Where the carry is expected to bring the palm, PLACE_APPROACH above the grasp's height over
            ``p_place`` (pick and place: PUT_DOWN_OFFSET_HAND from there): what :func:`grasp_reachable` checks.
            The carry itself ends where the object, as it hangs, is PLACE_APPROACH above the table.
        R_world_hand: Palm orientation throughout.
        close_speed: Speed of the closing fingers, a share of their motors' speed limit.
        hold_time: How long the lifted object is held still [s].
        hand_open, hand_closed, hand_release: Targets of the driven finger joints [rad], by joint name: the
            open hand of the approach, the closed hand, and the hand that lets go.
        object_place: Where the held object's centre is put down (x, y) [m], the carry aiming the object there
            as it hangs in the hand (pick and place); None: the hand carries to ``p_place``.
    """

    p_above: np.ndarray
    p_grasp: np.ndarray
    p_lift: np.ndarray
    p_place: np.ndarray
    p_retreat: np.ndarray
    p_put_down: np.ndarray
    R_world_hand: np.ndarray
    close_speed: float
    hold_time: float
    hand_open: dict[str, float]
    hand_closed: dict[str, float]
    hand_release: dict[str, float]
    object_place: np.ndarray | None = None


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
    if behavior.places:  # pick and place: the hand takes the object as the canonical grasp does
        shift, height, lateral = PLACE_RANGE * a[:2], 0.0, 0.0
    else:
        shift, height, lateral = np.array(PLACE_SHIFT), a[0], a[1]
    centre_hand = np.array([GRASP_CENTRE_HAND[0], GRASP_CENTRE_HAND[1] + lateral * GRASP_LATERAL_RANGE, 0.0])
    p_grasp = np.array([p_world_object[0], p_world_object[1], 0.0]) - matmul(R, centre_hand)
    p_grasp[2] = top + GRASP_GAP + height * GRASP_HEIGHT_RANGE
    p_place = p_grasp + np.array([shift[0], shift[1], PLACE_CLEARANCE])
    p_put_down = np.array([p_place[0], p_place[1], p_grasp[2] + PLACE_APPROACH])
    if behavior.places:
        p_put_down += matmul(R, np.array(PUT_DOWN_OFFSET_HAND[geometry.object_type]))
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
        object_place=(np.array([p_world_object[0], p_world_object[1]]) + shift) if behavior.places else None,
        p_put_down=p_put_down,
    )


#: Speed of the grasp's guarded move [m/s]: the hand's final approach to the object, with its lowest point
#: within GUARD_CLEARANCE of the object's top. A careful robot's speed near what it touches: the first touch is at
#: most this fast, and stops the move (the fingertips' and palm's tactile skin of the mk3 hand sense it).
GUARDED_SPEED = 0.04
#: Speed of the put-down [m/s], slower still: a held object meets the table at this speed, plus what it slips in
#: the grip as the fingertips under a small one meet the table first (the touch is sensed as the load leaving the
#: arm, through the iCub's force-torque sensors).
PLACE_SPEED = 0.02
#: Speed of the carry of a held object to above where it is put down [m/s]: gentle, so that the largest objects
#: the hand holds, gripped near their equator, do not slip out as it starts and stops.
CARRY_SPEED = 0.04
#: How far the hand rises again [m] when the fingertips under a small object meet the table before it does:
#: enough to take the table's push off them.
PLACE_BACK_OFF = 0.001
#: Speed of the grasp's free lines [m/s]: the lift of a held object and the retreat of the open hand.
LIFT_SPEED = 0.1
#: A closing finger joint has stalled when slower than FINGER_STALL_SPEED [rad/s] and within FINGER_ARRIVED [rad]
#: of its target or pressing with its motor's full torque.
FINGER_STALL_SPEED, FINGER_ARRIVED = 0.05, 0.02
#: The closing fingers press with at most this torque [N m] until every one has stalled on the object or
#: arrived (a current limit of the hand's controller, a third of its motors' limit): a light touch that finds the
#: object without sweeping it away. Then they squeeze with their motors' full torque.
CLOSING_TORQUE = 0.1
#: Share of their speed limit at which the fingers open to let down an object that does not touch the table yet.
RELEASE_SPEED_SHARE = 0.05
#: Once the closing fingers hold, their grip rises to the motors' full torque over this time [s].
GRASP_SQUEEZE_TIME = 0.1
#: The carry brings a held object to this height above where it would touch the table [m]; the guarded
#: put-down goes on from there until it does (or PLACE_OVERTRAVEL lower).
PLACE_APPROACH = 0.02
PLACE_OVERTRAVEL = 0.02


@dataclass(frozen=True)
class GraspOutcome(ReachOutcome):
    """What happened during a grasp, measured in the simulation (:class:`ReachOutcome` over every pose of the
    grasp; the first touch to the control tick).

    Attributes:
        rise: How far the object's centre had risen above its start at the end of the hold [m].
        links_holding: Hand links touching the object at the end of the hold.
        on_table: Whether the object touched the table at the end of the hold.
        release_time: Simulation time when the hand had opened again [s].
        placed: Whether the held object was put down on the table before the hand opened (False for a grasp
            that did not hold it: the hand then opens where it is, above the table).
        q_retreat: Joint targets of the pose straight above where the hand let go, through which the way home
            passes.
    """

    rise: float
    links_holding: tuple[str, ...]
    on_table: bool
    release_time: float
    placed: bool
    q_retreat: np.ndarray


def with_hand(motion: MotionExecutor, q: np.ndarray, hand: Mapping[str, float]) -> np.ndarray:
    q = q.copy()
    joints = motion.kinematics.joint_names
    for name, value in hand.items():
        q[joints.index(name)] = value
    return q


def move_fingers(motion: MotionExecutor, hand: Mapping[str, float], speed_scale: float = 1.0,
                 until_held: bool = False) -> None:
    """Move the driven finger joints to ``hand`` [rad] at ``speed_scale`` of their velocity limits, the arm
    holding its targets. A finger that meets the object stops there and presses with its motor's torque; with
    ``until_held`` the move ends once every driven finger joint is still and either there or pressing with
    its motor's full torque (the closing of a hand that has stalled on what it holds)."""
    physics = motion.physics
    fingers = np.array([motion.kinematics.joint_names.index(name) for name in hand])
    # The move starts where the fingers are, not where their targets are: a finger held back by what it touches
    # would otherwise spring towards its target as the move lets it go.
    q_from = physics.joint_targets()
    q_from[fingers] = physics.joint_positions()[fingers]
    q_to = with_hand(motion, q_from, hand)
    trajectory = minimum_jerk(q_from, [q_to], motion.planned_speed * speed_scale, CONTROL_DT,
                              min_duration=MIN_MOVE_TIME)
    target = q_to[fingers]
    limit = np.minimum(physics.torque_limit[fingers], CLOSING_TORQUE)

    def held() -> bool:
        q, qd, torque = physics.joint_positions(), physics.joint_velocities(), physics.joint_torques()
        there = np.abs(q[fingers] - target) < FINGER_ARRIVED
        pressing = np.abs(torque[fingers]) >= 0.98 * limit
        return bool(np.all(np.abs(qd[fingers]) < FINGER_STALL_SPEED) and np.all(there | pressing))

    if not until_held:
        motion.follow(trajectory)
        return
    physics.limit_torques(fingers, CLOSING_TORQUE)  # a light touch while the fingers close ...
    try:
        motion.follow(trajectory, held)
        # ... then the grip rises to the motors' full torque over GRASP_SQUEEZE_TIME, without a jolt. The grip is
        # an impedance: each finger's target lies just so far beyond where it stopped that its servo presses with
        # that torque, so a finger that loses what it holds moves no further than that (at its servo's pace, not
        # at its motor's no-load speed, as a target far beyond the object would let it).
        motion.phase = "squeeze"
        physics.limit_torques(fingers, None)
        full = physics.torque_limit[fingers]
        stiffness = physics.servo_kp[fingers]
        n = max(1, round(GRASP_SQUEEZE_TIME / CONTROL_DT))
        q_stopped = physics.joint_positions()[fingers]
        towards = q_to[fingers] - q_stopped
        for k in range(1, n + 1):
            press = (CLOSING_TORQUE + (full - CLOSING_TORQUE) * k / n) / stiffness  # [rad] beyond where it stopped
            q = physics.joint_targets()
            q[fingers] = q_stopped + np.sign(towards) * np.minimum(np.abs(towards), press)
            physics.set_joint_targets(q)
            motion.hold(CONTROL_DT)
    finally:
        physics.limit_torques(fingers, None)


def hand_target(plan: GraspPlan) -> HandTarget:
    """How the IK holds the hand through the grasp: the plan's palm orientation, the joints' own ranges."""
    return HandTarget(plan.R_world_hand)


def grasp_poses(motion: MotionExecutor, plan: GraspPlan, *, check: bool = False) -> list[IKResult]:
    """IK of the grasp's poses above the object, at the grasp and lifted, the hand open; ``check``: see
    :meth:`~affordance_env.motion.MotionExecutor.ik`."""
    hand = hand_target(plan)
    q_open = with_hand(motion, motion.physics.joint_targets(), plan.hand_open)
    results = [motion.ik(plan.p_above, q_open, hand, check=check)]
    for p in (plan.p_grasp, plan.p_lift):
        results.append(motion.ik(p, results[-1].q, hand, check=check))
    return results


def grasp_reachable(motion: MotionExecutor, plan: GraspPlan) -> bool:
    """Whether :func:`run_grasp` will find its poses within the IK's tolerances (above, at and down to the grasp,
    the lift, and where the carry is expected to end, ``p_put_down``); kinematics only. The descent stops at the
    first touch, anywhere between the pose above and the grasp pose, and the lift rises from there: the lifts from
    both ends are checked.
    Every pose and line decides the answer by whether it is reached: each IK gives up once it stands still
    (``check``). The carry's and the put-down's lines are not checked: of 200 random pick and place draws, those
    lines refused 3 whose poses were all reachable, and 2 of those reached (the third, whose object the head had
    not seen at the start, did not)."""
    above, at, lifted = grasp_poses(motion, plan, check=True)
    hand = hand_target(plan)
    place = motion.ik(plan.p_put_down, lifted.q, hand, check=True)
    if not ik_verdict([above, at, lifted, place])[0]:  # a pose out of reach: the lines are not solved
        return False
    descent = motion.line(plan.p_above, plan.p_grasp, hand, GUARDED_SPEED, q_start=above.q, check=True)
    lift = motion.line(plan.p_grasp, plan.p_lift, hand, LIFT_SPEED, q_start=at.q, check=True)
    high_lift = motion.line(plan.p_above, plan.p_above + (plan.p_lift - plan.p_grasp), hand, LIFT_SPEED,
                            q_start=above.q, check=True)
    return ik_verdict([*descent.results, *lift.results, *high_lift.results])[0]


def finger_of(name: str) -> str:
    """The finger a hand link or joint belongs to: ``l_hand_pinky_fingertip_link`` and
    ``l_hand_pinky_proximal_joint`` to ``pinky`` (the thumb's opposition, ``metacarpus``, counts apart)."""
    return name.removeprefix("l_hand_").split("_")[0]


def put_down(motion: MotionExecutor, plan: GraspPlan) -> bool:
    """Lower the held object until it meets the table (sensed as the arm's load leaving it); returns whether it
    did. A finger curled under the hand beside the object may meet the table first, a millimetre or two before
    the object would: it holds nothing, so it opens out of the way (its tip rises towards the palm) and the hand
    goes on down. If a finger under the object meets the table first, the hand stops there and backs off
    PLACE_BACK_OFF, the object about a millimetre above the table; the hand then opens slowly (:func:`run_grasp`)."""
    physics = motion.physics
    hand = hand_target(plan)
    joints = motion.kinematics.joint_names
    p_low = motion.palm - np.array([0.0, 0.0, PLACE_APPROACH + PLACE_OVERTRAVEL])
    opened: set[str] = set()
    while True:
        grip = physics.joint_targets()  # the fingers' targets: just beyond where they press, their squeeze
        down = motion.line(motion.palm.copy(), p_low, hand, PLACE_SPEED)
        touched = motion.follow_line(down, lambda: physics.object_touches_table()
                                     or physics.hand_touches_table()).touched
        if touched and physics.object_touches_table():
            return True
        # The arm stops where it is, and the fingers go on squeezing: stopping them too (their targets where they
        # are) would leave the object held by nothing, to drop the last millimetres onto the table.
        squeeze = {name: grip[joints.index(name)] for name in plan.hand_closed}
        physics.set_joint_targets(with_hand(motion, physics.joint_targets(), squeeze))
        idle = {finger_of(link) for link in physics.links_touching_table() - physics.links_touching_object()}
        out_of_way = {name: value for name, value in plan.hand_open.items() if finger_of(name) in idle - opened}
        if not touched or not out_of_way:  # a finger under the object met the table: off it again
            p_hand = motion.palm.copy()
            motion.follow_line(motion.line(p_hand, p_hand + np.array([0.0, 0.0, PLACE_BACK_OFF]), hand, PLACE_SPEED))
            return False
        move_fingers(motion, out_of_way)
        opened |= idle


def run_grasp(motion: MotionExecutor, plan: GraspPlan, at_end: Callable[[], None] | None = None) -> GraspOutcome:
    """Reach above the object with the open hand, descend slowly until the hand touches it or is at the grasp
    pose, close the hand, lift, hold; if the object is held, carry it beside and put it down until it rests on
    the table; open the hand once the object rests. Not the way home, which rises first (``q_retreat``).
    ``at_end`` is called at the end of the hold: where the paper's grasp ends."""
    physics = motion.physics
    hand = hand_target(plan)
    results = grasp_poses(motion, plan)
    z_start = float(physics.object_pose()[2])
    # Reach: to above the object, fast, the hand open.
    motion.phase = "reach"
    motion.move_through([results[0].q])
    motion.settle(plan.p_above, tolerance=0.005)
    # Descend: slowly, stopping at the first touch.
    motion.phase = "descend"
    descent = motion.line(plan.p_above, plan.p_grasp, hand, GUARDED_SPEED)
    results += descent.results
    touch = motion.follow_line(descent, physics.hand_touches_object)
    # Close: the fingers at the plan's share of their speed limit, until their motors' torque holds the object.
    motion.phase = "close"
    monitor = physics.monitor  # in the hand from its closing until it has opened and the object rests
    if monitor is not None:
        monitor.held = True
    move_fingers(motion, plan.hand_closed, plan.close_speed, until_held=True)
    motion.phase = "lift"
    p_from = motion.palm.copy()
    lift = motion.line(p_from, p_from + (plan.p_lift - plan.p_grasp), hand, LIFT_SPEED)
    results += lift.results
    motion.follow_line(lift)
    motion.phase = "hold"
    motion.hold(plan.hold_time)
    rise = float(physics.object_pose()[2]) - z_start
    holding = tuple(sorted(physics.links_touching_object()))
    on_table = physics.object_touches_table()
    if at_end is not None:
        at_end()
    held = rise > 0.5 * (plan.p_lift[2] - plan.p_grasp[2]) and bool(holding) and not on_table
    placed = False
    if held:  # carry it to above where it is put down: as high above the table as it was lifted
        motion.phase = "carry"
        # Where the palm is when the object's lowest point (as it hangs in the hand now) is PLACE_APPROACH above
        # the table; there along a straight line, which never dips towards the table.
        z_touch = float(motion.palm[2]) - (physics.object_bottom() - physics.table_top)
        p_carry = np.array([plan.p_place[0], plan.p_place[1], z_touch + PLACE_APPROACH])
        if plan.object_place is not None:  # the object, as it hangs in the hand now, over the place asked
            p_carry[:2] = plan.object_place + (motion.palm[:2] - physics.object_pose()[:2])
        carry = motion.line(motion.palm.copy(), p_carry, hand, CARRY_SPEED)
        results += carry.results
        motion.follow_line(carry)
        # Place: down until the object meets the table, then still until it rests.
        motion.phase = "place"
        placed = put_down(motion, plan)
        motion.hold_still(also=object_at_rest)
    motion.phase = "open"
    # A held object the hand could not set down (a finger under a small one met the table first) is let down
    # slowly: the fingers open at RELEASE_SPEED_SHARE of their speed, and it slides down them onto the table.
    move_fingers(motion, plan.hand_release, 1.0 if placed or not held else RELEASE_SPEED_SHARE)
    motion.hold_still(also=object_at_rest)
    if monitor is not None:
        monitor.held = False
    release_time = float(physics.data.time)
    # The way home rises first: straight up from where the hand let go.
    p_up = motion.palm.copy() + np.array([0.0, 0.0, plan.p_retreat[2] - plan.p_place[2]])
    retreat = motion.ik(p_up, physics.joint_targets(), hand)
    return GraspOutcome(*ik_verdict(results), touch.touched, touch.time, touch.speed, rise, holding,
                        on_table, release_time, placed, retreat.q)


@dataclass(frozen=True)
class GraspBehavior:
    """Grasp from above with the fingered left hand, lift, hold, put down beside (see the module docstring).

    Attributes:
        name: Identifier used by ``behavior=`` of the environment.
        R_world_hand: Orientation of the palm frame (``l_hand_dh_frame``: x along the fingers, the palm facing -z)
            for an object at zero yaw, (3, 3).
        description: One line for the documentation.
        robot: The robot variant it needs.
        places: Pick and place: action[0] and action[1] name where the held object is put down, PLACE_RANGE
            times them from where it stood along x and y (the hand takes it as the canonical grasp does), instead
            of the grasp's height and lateral offset (the object then goes down PLACE_SHIFT beside).
    """

    name: str
    R_world_hand: np.ndarray
    description: str
    robot: str = "grasp"
    places: bool = False
    kind: ClassVar[str] = "grasp"

    def prepare(self, motion: MotionExecutor, placement_centre: np.ndarray, size: float) -> None:
        return None  # each grasp's IK starts from where the arm is

    def plan(self, geometry: ObjectGeometry, p_object: np.ndarray, yaw: float, table_top: float,
             action: np.ndarray) -> GraspPlan:
        return plan_grasp(self, geometry, p_object, yaw, table_top, action)

    def execute(self, motion: MotionExecutor, plan: GraspPlan, posture: np.ndarray | None,
                at_end: Callable[[], None] | None = None) -> GraspOutcome:
        return run_grasp(motion, plan, at_end)

    def reachable(self, motion: MotionExecutor, plan: GraspPlan, posture: np.ndarray | None) -> bool:
        if plan.object_place is not None:  # pick and place puts the object down on the table, or not at all
            low, high = motion.physics.table_extent()
            if np.any(plan.object_place < low) or np.any(plan.object_place > high):
                return False
        return grasp_reachable(motion, plan)

    def via_home(self, outcome: GraspOutcome) -> np.ndarray | None:
        return outcome.q_retreat

    def awaited_since(self, outcome: GraspOutcome, now: float) -> float:
        return outcome.release_time  # from when the hand let go

    def failure(self, outcome: GraspOutcome) -> str | None:
        return None  # the hand meets the object on its way down, and may miss it: that is the grasp's outcome

    def success(self, outcome: GraspOutcome, labels: Labels, displacement: float, threshold: float) -> bool:
        return grasp_success(outcome.rise, outcome.links_holding, outcome.on_table)  # lifted and held

    def facts(self, outcome: GraspOutcome) -> Mapping[str, Any]:
        return {"stroke_speed": 0.0,
                "grasp": {"rise": outcome.rise, "links_holding": outcome.links_holding,
                          "on_table": outcome.on_table}}


#: The grasp's object, by name (:mod:`affordance_env.registry` lists it).
BEHAVIORS: Mapping[str, GraspBehavior] = {
    "grasp": GraspBehavior(
        "grasp", grasp_orientation(0.0),
        "grasp from above with the fingered left hand, lift 8 cm, hold 1 s, put down 6 cm to the robot's left",
    ),
}
#: The grasp as a world that goes on runs it (the goal env): pick and place, the held object put down where the
#: action asks (:attr:`GraspBehavior.places`).
GOAL_BEHAVIORS: Mapping[str, GraspBehavior] = {
    "grasp": GraspBehavior(
        "grasp", grasp_orientation(0.0),
        "pick and place: grasp from above with the fingered left hand, lift 8 cm, hold 1 s, put down where asked",
        places=True,
    ),
}
