"""Pinhole camera geometry without the simulator: intrinsics, rays, and projecting world points to pixels.

Image conventions: ``u`` is the column, ``v`` the row, pixel centres at integer indices. MuJoCo cameras look
along their -z axis with +x to the right of the image and +y up. A camera's pose is ``p_world_camera`` (its centre
in the world frame [m]) and ``R_world_camera`` (its x, y, z axes in the world frame as columns).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from affordance_env.exceptions import InvalidValueError
from affordance_env.linalg import matmul
from affordance_env.values import is_integer

#: The widest and tallest image [pixels]: 4096, six times a Kinect's 640 x 480 on either side; the camera keeps a few
#: arrays of 8 to 24 bytes per pixel (rays, distances, points), 1.2 GB at 4096 x 4096.
MAX_RESOLUTION = 4096


@dataclass(frozen=True)
class Intrinsics:
    """Pinhole intrinsics in pixels: focal lengths ``fx, fy`` and principal point ``cx, cy``."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float

    @classmethod
    def from_fovy(cls, width: int, height: int, fovy_deg: float) -> Intrinsics:
        """Square pixels with vertical field of view ``fovy_deg`` [deg], principal point at the image centre."""
        if (not (is_integer(width) and is_integer(height))
                or min(width, height) < 2 or max(width, height) > MAX_RESOLUTION):
            raise InvalidValueError(f"camera resolution must be integers in 2..{MAX_RESOLUTION}, got width={width!r}, "
                                    f"height={height!r}.")
        if not 1.0 <= float(fovy_deg) <= 170.0:
            raise InvalidValueError(f"fovy_deg must be within [1, 170] degrees, got {fovy_deg!r}.")
        f = 0.5 * height / np.tan(np.deg2rad(fovy_deg) / 2.0)
        return cls(int(width), int(height), float(f), float(f), (width - 1) / 2.0, (height - 1) / 2.0)

    def ray_directions(self) -> np.ndarray:
        """Unit ray directions in the camera frame (MuJoCo convention), shape (height, width, 3)."""
        u, v = np.meshgrid(np.arange(self.width), np.arange(self.height))
        d = np.stack([(u - self.cx) / self.fx, -(v - self.cy) / self.fy, -np.ones(u.shape)], axis=-1)
        return d / np.linalg.norm(d, axis=-1, keepdims=True)


def project(p_world: np.ndarray, p_world_camera: np.ndarray, R_world_camera: np.ndarray, K: Intrinsics) -> np.ndarray:
    """Pinhole projection of a world point [m] to (u, v) pixels (NaN when the point is behind the camera)."""
    p_world = np.asarray(p_world, dtype=float)
    if p_world.shape == (3,):  # one point, as the callers pass it: in Python floats, the same bits (to_camera)
        x, y, z = to_camera(*p_world.tolist(), np.asarray(p_world_camera, dtype=float).tolist(),
                            np.asarray(R_world_camera, dtype=float).ravel().tolist())
    else:
        p_camera = matmul(p_world - p_world_camera, R_world_camera)
        x, y, z = p_camera[0], p_camera[1], p_camera[2]
    depth = -z
    if depth <= 1e-9:
        return np.array([np.nan, np.nan])
    return np.array([K.cx + K.fx * x / depth, K.cy - K.fy * y / depth])


# Small products in Python floats. A handful of 3-vectors (a box's 8 corners, a sphere's centre, a point to
# project) cost a dozen array calls each through linalg.matmul, for a few dozen multiplications: this module and
# the camera's culling (affordance_env.culling) do some of them in Python floats instead, in the same IEEE
# operations in the same order, so with the same bits (tests/test_camera.py holds them to linalg.matmul). That
# order is einsum's, the loops linalg.matmul runs (numpy's baseline build, the same on every x86-64 CPU):
#
# - a point times the camera's rotation, ``matmul(p, R)`` of one point (``"i,ij->j"``) or of a box's 8 corners
#   (``"...ij,jk->...ik"``, (8, 3) by (3, 3)): each output adds its three products one after another,
#   (a0 + a1) + a2;
# - three contiguous products reduced to one number: a rotation's row times a vector (``"gij,gcj->gci"``), a
#   squared length (``"i,i->"`` of linalg.norm), a ray's direction times an axis (``"...ij,j->...i"``): the
#   two-lane loop adds the third product to the first, then the second, (a0 + a2) + a1.
#
# einsum starts every sum from +0, which the ``+ 0.0`` in these sums stands for: it turns a -0 into +0, and changes
# nothing else.


def to_camera(x: float, y: float, z: float, p_world_camera: list[float],
              R_world_camera: list[float]) -> tuple[float, float, float]:
    """``matmul(p - p_world_camera, R_world_camera)`` of one world point ``p = (x, y, z)`` [m] (the camera's
    position [m], its orientation row-major, 9 floats): the point in the camera frame [m], bit for bit."""
    d0, d1, d2 = x - p_world_camera[0], y - p_world_camera[1], z - p_world_camera[2]
    R = R_world_camera
    return (((d0 * R[0] + d1 * R[3]) + d2 * R[6]) + 0.0, ((d0 * R[1] + d1 * R[4]) + d2 * R[7]) + 0.0,
            ((d0 * R[2] + d1 * R[5]) + d2 * R[8]) + 0.0)
