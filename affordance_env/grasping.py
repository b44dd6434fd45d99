"""The grasp: reach above the object with the open hand, descend until it touches, close, lift and hold; put
down a held object beside and open the hand once it rests.

Every move is a trajectory of :mod:`affordance_env.trajectory` played by the servo loop of
:class:`~affordance_env.motion.MotionExecutor`; the hand's driven finger joints close under a light current limit
until they hold, then squeeze with their motors' full torque. Its poses' IK is solved before any move, so
:func:`grasp_reachable` answers from the kinematics alone.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from affordance_env.behaviors import GraspPlan
from affordance_env.kinematics import IKResult
from affordance_env.motion import (
    CONTROL_DT,
    MIN_MOVE_TIME,
    HandTarget,
    MotionExecutor,
    ReachOutcome,
    ik_verdict,
    object_at_rest,
)
from affordance_env.trajectory import minimum_jerk

#: Speed of the grasp's guarded moves [m/s]: the hand's final approach to the object, with its lowest point
#: within GUARD_CLEARANCE of the object's top, and the put-down of a held object. A careful robot's speed near
#: what it touches: the first touch is at most this fast, and stops the move (the fingertips' and palm's tactile
#: skin of the mk3 hand sense it; the put-down's touch of the table is sensed as the load leaving the arm, through
#: the iCub's force-torque sensors).
GUARDED_SPEED = 0.04
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
RELEASE_SPEED_SHARE = 0.25
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
    q_to = with_hand(motion, physics.joint_targets(), hand)
    trajectory = minimum_jerk(physics.joint_targets(), [q_to], motion.planned_speed * speed_scale,
                              CONTROL_DT, min_duration=MIN_MOVE_TIME)
    fingers = np.array([motion.kinematics.joint_names.index(name) for name in hand])
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
        # ... then the grip rises to the motors' full torque over GRASP_SQUEEZE_TIME, without a jolt
        motion.phase = "squeeze"
        full = physics.torque_limit[fingers]
        n = max(1, round(GRASP_SQUEEZE_TIME / CONTROL_DT))
        for k in range(1, n + 1):
            physics.limit_torques(fingers, CLOSING_TORQUE + (full - CLOSING_TORQUE) * k / n)
            motion.hold(CONTROL_DT)
    finally:
        physics.limit_torques(fingers, None)


def hand_target(plan: GraspPlan) -> HandTarget:
    """How the IK holds the hand through the grasp: the plan's palm orientation, the joints' own ranges."""
    return HandTarget(plan.R_world_hand)


def grasp_poses(motion: MotionExecutor, plan: GraspPlan) -> list[IKResult]:
    """IK of the grasp's poses above the object, at the grasp and lifted, the hand open."""
    hand = hand_target(plan)
    q_open = with_hand(motion, motion.physics.joint_targets(), plan.hand_open)
    results = [motion.ik(plan.p_above, q_open, hand)]
    for p in (plan.p_grasp, plan.p_lift):
        results.append(motion.ik(p, results[-1].q, hand))
    return results


def grasp_reachable(motion: MotionExecutor, plan: GraspPlan) -> bool:
    """Whether :func:`run_grasp` will find its poses within the IK's tolerances (above, at and down to the grasp,
    the lift and the put-down beside); kinematics only. The descent stops at the first touch, anywhere between
    the pose above and the grasp pose, and the lift rises from there: the lifts from both ends are checked."""
    above, at, lifted = grasp_poses(motion, plan)
    hand = hand_target(plan)
    descent = motion.line(plan.p_above, plan.p_grasp, hand, GUARDED_SPEED, q_start=above.q)
    lift = motion.line(plan.p_grasp, plan.p_lift, hand, LIFT_SPEED, q_start=at.q)
    high_lift = motion.line(plan.p_above, plan.p_above + (plan.p_lift - plan.p_grasp), hand, LIFT_SPEED,
                            q_start=above.q)
    place = motion.ik(np.array([plan.p_place[0], plan.p_place[1], plan.p_grasp[2] + PLACE_APPROACH]), lifted.q,
                      hand)
    return ik_verdict([above, at, lifted, *descent.results, *lift.results, *high_lift.results, place])[0]


def run_grasp(motion: MotionExecutor, plan: GraspPlan) -> GraspOutcome:
    """Reach above the object with the open hand, descend slowly until the hand touches it or is at the grasp
    pose, close the hand, lift, hold; if the object is held, carry it beside and put it down until it rests on
    the table; open the hand once the object rests. Not the way home, which rises first (``q_retreat``)."""
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
    held = rise > 0.5 * (plan.p_lift[2] - plan.p_grasp[2]) and bool(holding) and not on_table
    placed = False
    if held:  # carry it to above where it is put down: as high above the table as it was lifted
        motion.phase = "carry"
        # where the object would touch the table, from how far it has risen with the hand
        z_touch = float(motion.palm[2]) - (float(physics.object_pose()[2]) - z_start)
        p_carry = np.array([plan.p_place[0], plan.p_place[1], z_touch + PLACE_APPROACH])
        carry = motion.ik(p_carry, physics.joint_targets(), hand)
        results.append(carry)
        motion.move_through([carry.q])
        # Place: down until the object meets the table (sensed as the arm's load leaving it), then still until
        # it rests. Fingertips curled under a small object meet the table first: the grip loosens to the
        # closing's light touch, and the fingers yield and spread on the table as the hand goes on down.
        motion.phase = "place"
        p_hand = motion.palm.copy()
        p_low = p_hand - np.array([0.0, 0.0, PLACE_APPROACH + PLACE_OVERTRAVEL])
        down = motion.line(p_hand, p_low, hand, GUARDED_SPEED)
        placed = motion.follow_line(down, lambda: physics.object_touches_table()
                                  or physics.hand_touches_table()).touched and physics.object_touches_table()
        if not placed:  # the fingers under the object met the table: they loosen and yield as the hand goes on
            fingers = np.array([motion.kinematics.joint_names.index(name) for name in plan.hand_closed])
            physics.limit_torques(fingers, CLOSING_TORQUE)
            p_hand = motion.palm.copy()
            on_down = motion.line(p_hand, p_hand - np.array([0.0, 0.0, PLACE_OVERTRAVEL]), hand, GUARDED_SPEED)
            placed = motion.follow_line(on_down, physics.object_touches_table).touched
            physics.limit_torques(fingers, None)
        motion.hold_still(also=object_at_rest)
    motion.phase = "open"
    # A held object the hand could not set down (the thumb under a small one met the table first) is let down
    # slowly: the fingers open at a quarter of their speed, and it slides down them onto the table.
    move_fingers(motion, plan.hand_release, 1.0 if placed or not held else RELEASE_SPEED_SHARE)
    motion.hold_still(also=object_at_rest)
    release_time = float(physics.data.time)
    # The way home rises first: straight up from where the hand let go.
    p_up = motion.palm.copy() + np.array([0.0, 0.0, plan.p_retreat[2] - plan.p_place[2]])
    retreat = motion.ik(p_up, physics.joint_targets(), hand)
    return GraspOutcome(*ik_verdict(results), touch.touched, touch.time, touch.speed, rise, holding,
                        on_table, release_time, placed, retreat.q)
