"""The stroke of tap, tap_back and push: reach the pre-stroke pose, then a line of the palm through the object.

The reach goes through the pose above the pre-stroke pose (when the plan has one), so the arm never sweeps across
the object; the stroke is a Cartesian line turned into a joint trajectory by the arm's IK
(:class:`~affordance_env.motion.LinePath`), its speed capped where a joint would exceed its velocity limit, and it
is watched for the first touch at every physics step near the object. Its IK is solved before any move, so
:func:`stroke_reachable` answers from the kinematics alone.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from affordance_env.behaviors import StrokePlan
from affordance_env.kinematics import IKResult
from affordance_env.linalg import dot, norm
from affordance_env.motion import (
    CONTROL_DT,
    MIN_MOVE_TIME,
    HandTarget,
    LinePath,
    MotionExecutor,
    ReachOutcome,
    ik_verdict,
)
from affordance_env.trajectory import JointTrajectory, minimum_jerk

#: The stroke reaches its speed in this time [s] from rest, within the first 3 cm (the clearance before the
#: object) even at its fastest.
STROKE_RAMP = 0.1
#: The reach's servo targets must keep the arm's geoms (hand, fingers, wrist, forearm) at least this far from the
#: object [m] (checked every REACH_SWEEP_STRIDE control ticks), else the stroke is not feasible: an arm that sweeps
#: into the object moves it before the stroke (a "reach" failure). Over 150 random strokes per behaviour at
#: positions over the workspaces, no penetration (0 m) flags 4 of 4 such failures of tap (and 4 strokes that would
#: have moved the object less than the 3 mm allowed), 11 of 15 of tap_back (none wrongly; of the other 4, 3 started
#: the stroke more than 1 cm from its pose and 1 passed 0.8 mm from the object on its targets) and 4 of 4 of push
#: (1 wrongly); a 1 cm margin would refuse 8, 17 and 11 strokes that work.
REACH_CLEARANCE, REACH_SWEEP_STRIDE = 0.0, 5


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


def plan_approach(motion: MotionExecutor, plan: StrokePlan, posture: np.ndarray | None
                  ) -> tuple[IKResult | None, IKResult]:
    """IK of the pose above the pre-stroke pose (None if the plan has none) and of the pre-stroke pose, from the
    arm's ``posture`` (:func:`approach_posture`; None: the current servo targets)."""
    # The pre-stroke pose first, the pose above it from there: the two differ by a short vertical move, so
    # the descent (and the way up after the stroke) is a small joint motion, not a change of arm posture.
    q_init = motion.physics.joint_targets()  # the neck and the fingers keep their targets
    if posture is not None:
        reach = motion.kinematics.reach_dofs
        q_init[reach] = posture[reach]
    hand = hand_target(plan)
    start = motion.ik(plan.p_start, q_init, hand)
    above = None if plan.p_above is None else motion.ik(plan.p_above, start.q, hand)
    return above, start


def plan_stroke_path(motion: MotionExecutor, plan: StrokePlan, posture: np.ndarray | None
                     ) -> tuple[IKResult | None, IKResult, LinePath]:
    """The stroke's IK, solved before any move: the poses of :func:`plan_approach` and the stroke's line."""
    above, start = plan_approach(motion, plan, posture)
    length = dot(plan.p_end - plan.p_start, plan.direction)
    # The joint speeds along the whole line cap the stroke's speed.
    path = LinePath(motion, plan.p_start, plan.direction, length, hand_target(plan), plan.speed, start.q,
                    ramp=STROKE_RAMP,
                    to_rest=False)
    return above, start, path


def reach_trajectory(motion: MotionExecutor, above: IKResult | None, start: IKResult) -> JointTrajectory:
    """The joint targets of the reach to the pre-stroke pose (through the pose above it, if any), from where the
    arm is now: what :func:`run_stroke` follows."""
    waypoints = [start.q] if above is None else [above.q, start.q]
    return minimum_jerk(motion.physics.joint_targets(), waypoints, motion.planned_speed, CONTROL_DT,
                        min_duration=MIN_MOVE_TIME)


def stroke_reachable(motion: MotionExecutor, plan: StrokePlan, posture: np.ndarray | None) -> bool:
    """Whether :func:`run_stroke` will find every pose of ``plan`` within the IK's tolerances, and its reach keeps
    the arm ``REACH_CLEARANCE`` from the object; kinematics only."""
    above, start, path = plan_stroke_path(motion, plan, posture)
    if not ik_verdict([start, *path.results])[0]:
        return False
    samples = reach_trajectory(motion, above, start).q[::REACH_SWEEP_STRIDE]
    return motion.physics.sweep_clearance(samples, REACH_CLEARANCE) >= REACH_CLEARANCE


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
