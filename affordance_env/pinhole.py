"""Pinhole camera intrinsics: pixel geometry only, without the simulator.

Image conventions: ``u`` is the column, ``v`` the row, pixel centres at integer indices. MuJoCo cameras look
along their -z axis with +x to the right of the image and +y up.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from affordance_env.exceptions import InvalidValueError
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
