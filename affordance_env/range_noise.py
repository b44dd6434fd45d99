"""Range-sensor noise: the axial noise of a structured-light camera (Kinect v1), as a pure function.

Nguyen, Izadi and Lovell, "Modeling Kinect Sensor Noise for Improved 3D Reconstruction and Tracking" (3DIMPVT
2012), measured the standard deviation of a Kinect's depth along its optical axis as a function of the depth
``z`` [m] and of the angle ``theta`` between the surface normal and the viewing ray:

    sigma_z(z, theta) = 0.0012 + 0.0019 (z - 0.4)^2 + (0.0001 / sqrt(z)) theta^2 / (pi/2 - theta)^2   [m]

about 1.2 mm at the 0.3-0.6 m at which the iCub's head sees the table, growing quadratically with depth and
steeply at grazing angles. :func:`kinect_axial_sigma` is that formula; :func:`add_kinect_noise` perturbs each
pixel's depth by a Gaussian of that deviation and moves its point along its ray. Lateral noise (edge jitter of
about one pixel in the same paper) is not modelled: the object mask stays the simulator's.
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

import numpy as np

from affordance_env.exceptions import InvalidValueError
from affordance_env.linalg import matmul

if TYPE_CHECKING:  # only for annotations: importing the camera would import MuJoCo
    from affordance_env.camera import RangeImage

#: Noise models the environment offers (``range_noise=``).
RANGE_NOISE_MODELS: tuple[str, ...] = ("kinect_v1",)
#: Incidence angles are clipped to this [rad] (80 deg): the model diverges at grazing incidence, where a real
#: sensor returns no depth at all.
MAX_INCIDENCE = np.deg2rad(80.0)


def check_range_noise(name: str | None) -> str | None:
    """Return ``name`` if it is None or one of :data:`RANGE_NOISE_MODELS`, else raise ValueError listing them."""
    if name is not None and name not in RANGE_NOISE_MODELS:
        raise InvalidValueError(
            f"Unknown range_noise {name!r}. Valid: None (no noise), {', '.join(RANGE_NOISE_MODELS)}.")
    return name


def kinect_axial_sigma(depth: np.ndarray, incidence: np.ndarray) -> np.ndarray:
    """Standard deviation of a Kinect v1 depth reading [m] (Nguyen et al. 2012).

    Args:
        depth: Depth along the optical axis [m], > 0.
        incidence: Angle between the surface normal and the viewing ray [rad], in [0, pi/2]; clipped to
            :data:`MAX_INCIDENCE`.
    """
    z = np.asarray(depth, dtype=np.float64)
    theta = np.minimum(np.asarray(incidence, dtype=np.float64), MAX_INCIDENCE)
    return 0.0012 + 0.0019 * (z - 0.4) ** 2 + 0.0001 / np.sqrt(z) * theta**2 / (np.pi / 2 - theta) ** 2


def add_kinect_noise(image: RangeImage, rng: np.random.Generator) -> RangeImage:
    """``image`` with every hit pixel's depth perturbed by the Kinect v1 axial noise; needs ``image.normals``.

    The depth ``z`` of a pixel is its range times the cosine between its ray and the optical axis; the noisy
    depth ``z + N(0, sigma_z)`` moves the point along the same ray. Pixels that hit nothing stay so.
    """
    if image.normals is None:
        raise InvalidValueError("add_kinect_noise needs surface normals: capture the image with normals=True.")
    hit = np.isfinite(image.ranges)
    ranges = image.ranges.astype(np.float64)
    r = ranges[hit]
    rays = (image.p_world_points[hit] - image.p_world_camera) / r[:, None]  # unit rays, world frame
    cos_axis = -matmul(rays, image.R_world_camera[:, 2])  # the camera looks along its -z axis
    depth = r * cos_axis
    incidence = np.arccos(np.clip(np.abs(np.sum(image.normals[hit] * rays, axis=1)), 0.0, 1.0))
    noisy = np.maximum(depth + rng.normal(size=depth.shape) * kinect_axial_sigma(depth, incidence), 1e-3)
    r_noisy = noisy / cos_axis
    ranges[hit] = r_noisy
    points = image.p_world_points.copy()
    points[hit] = image.p_world_camera + rays * r_noisy[:, None]
    return dataclasses.replace(image, ranges=ranges.astype(np.float32), p_world_points=points)
