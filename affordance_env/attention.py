"""Attention: turn the head until the object's image centroid sits at the image centre.

Closed loop on the image, as in the paper: look, find the object's pixels, move the neck by a Newton step on
the centroid's pixel error (image Jacobian from the model's kinematics), let the servos settle, look again.
An object out of view is first searched for: the head looks in the directions of :data:`SEARCH_GAZES` in turn
until it sees it.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from affordance_env.camera import RangeCamera, project
from affordance_env.linalg import lstsq, norm
from affordance_env.physics import TapPhysics

#: Neck joints used for gaze: pitch (image rows) and yaw (image columns).
GAZE_JOINTS = ("neck_pitch", "neck_yaw")
#: Where the head looks for an object it does not see: (pitch, yaw) offsets [rad] from its current gaze, nearest
#: first, each clipped to the neck's range. The eye camera sees +-37 degrees across and +-29 up and down (57.4
#: degrees vertical field of view at 4:3), so yaw steps of 0.5 rad (29 degrees) and a pitch step of 0.15 rad
#: overlap the view they leave and cover the table beside and in front of the robot; the last three look up
#: (positive pitch), over the far part of the table, where an object pushed away from a gaze that looks down at
#: the near part lies above the view of every other gaze.
SEARCH_GAZES = ((0.0, 0.5), (0.0, -0.5), (-0.15, 0.5), (-0.15, -0.5), (-0.15, 0.0), (0.0, 0.9), (0.0, -0.9),
                (0.3, 0.0), (0.3, 0.5), (0.3, -0.5))


def _gaze_indices(physics: TapPhysics) -> np.ndarray:
    """Positions of GAZE_JOINTS in the robot's joint vector."""
    return np.array([physics.variant.active_joints.index(n) for n in GAZE_JOINTS])


@dataclass(frozen=True)
class AttentionResult:
    """Outcome of :func:`attend`.

    Attributes:
        success: The centroid ended within ``tolerance`` pixels of the image centre.
        visible: The object was seen at all.
        pixel_error: Final distance of the centroid from the image centre [pixels of the attention camera].
        iterations: Look-move cycles used.
    """

    success: bool
    visible: bool
    pixel_error: float
    iterations: int


def _centroid(camera: RangeCamera, physics: TapPhysics) -> tuple[np.ndarray, np.ndarray] | None:
    """The object's pixel centroid (u, v) [pixels] and mean point in the world frame [m] in ``camera``'s image
    now; None if it is not seen."""
    # Only where it may be: the pixels and points of capture(occluded=geom, window=True)'s mask, without the image
    pixels, points = camera.locate(physics.data, physics.active_geom)
    if not pixels.size:
        return None
    v, u = np.divmod(pixels, camera.intrinsics.width)  # as np.nonzero(mask) gives them
    # What u.mean(), v.mean() and points.mean(axis=0) compute (the same sums, in float64, of the same arrays,
    # divided by the count), without np.mean's Python layers.
    n = pixels.size
    uv = np.array([np.add.reduce(u, dtype=np.float64) / n, np.add.reduce(v, dtype=np.float64) / n])
    return uv, np.add.reduce(points, axis=0) / n


def _image_jacobian(
    camera: RangeCamera, physics: TapPhysics, p_world: np.ndarray, scratch: mujoco.MjData,
    gaze: np.ndarray | None = None,
) -> np.ndarray:
    """d(u, v)/d(neck_pitch, neck_yaw) [pixels/rad] of the world point ``p_world`` [m] at the current
    configuration, by central differences on ``scratch``; ``gaze``: :func:`_gaze_indices` if already known."""
    K = camera.intrinsics
    scratch.qpos[:] = physics.data.qpos
    jac = np.empty((2, 2))
    eps = 1e-4
    p_world = np.asarray(p_world, dtype=float)
    for j, joint in enumerate(_gaze_indices(physics) if gaze is None else gaze):
        address = physics.robot_qpos[joint]
        q = physics.data.qpos[address]
        uv = []
        for sign in (1.0, -1.0):
            scratch.qpos[address] = q + sign * eps
            mujoco.mj_kinematics(physics.model, scratch)
            mujoco.mj_camlight(physics.model, scratch)
            p_cam, R_cam = scratch.cam_xpos[camera.camera_id], scratch.cam_xmat[camera.camera_id].reshape(3, 3)
            uv.append(project(p_world, p_cam, R_cam, K))
        scratch.qpos[address] = q
        jac[:, j] = (uv[0] - uv[1]) / (2 * eps)
    return jac


def _search(physics: TapPhysics, camera: RangeCamera, move_joints, move_time: float | None, hold_time: float
            ) -> tuple[np.ndarray, np.ndarray] | None:
    """Look in the directions of SEARCH_GAZES until the object is seen: its centroid; or None, the head back at
    its first gaze."""
    gaze = _gaze_indices(physics)
    q_start = physics.joint_targets()
    low, high = np.array([physics.model.joint(name).range for name in GAZE_JOINTS]).T
    for offset in SEARCH_GAZES:
        q = q_start.copy()
        q[gaze] = np.clip(q_start[gaze] + offset, low, high)
        move_joints(q, move_time)
        move_joints(q, hold_time)
        seen = _centroid(camera, physics)
        if seen is not None:
            return seen
    move_joints(q_start, move_time)  # not found: back to where the head looked
    move_joints(q_start, hold_time)
    return None


def attend(
    physics: TapPhysics,
    camera: RangeCamera,
    move_joints,
    *,
    max_iterations: int = 6,
    tolerance: float = 0.5,
    move_time: float | None = None,
    hold_time: float = 0.02,
) -> AttentionResult:
    """Centre the object of interest in ``camera``'s image by moving the neck.

    Args:
        physics: The scene.
        camera: A (typically low-resolution) range camera on the head used for looking.
        move_joints: ``move_joints(q_target, duration)`` of :class:`~affordance_env.motion.MotionExecutor`.
        max_iterations: Look-move cycles at most.
        tolerance: Accepted centroid error [pixels of ``camera``].
        move_time: Duration of each neck move [s]; None: as fast as the neck's speed limit allows.
        hold_time: Time the servos are given to settle before the next look [s].
    """
    K = camera.intrinsics
    centre = np.array([K.cx, K.cy])
    scratch = physics.scratch
    gaze = _gaze_indices(physics)  # the same joints every iteration
    seen = _centroid(camera, physics)
    if seen is None:
        seen = _search(physics, camera, move_joints, move_time, hold_time)
    if seen is None:
        return AttentionResult(False, False, float("inf"), 0)
    for iteration in range(1, max_iterations + 1):
        uv, p_world = seen
        error = uv - centre
        if norm(error) <= tolerance:
            return AttentionResult(True, True, norm(error), iteration - 1)
        jac = _image_jacobian(camera, physics, p_world, scratch, gaze)
        q = physics.joint_targets()
        q[gaze] -= lstsq(jac, error)
        move_joints(q, move_time)
        move_joints(q, hold_time)
        seen = _centroid(camera, physics)
        if seen is None:
            return AttentionResult(False, False, float("inf"), iteration)
    error = norm(seen[0] - centre)
    return AttentionResult(error <= tolerance, True, error, max_iterations)
