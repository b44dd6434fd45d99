"""Time :func:`affordance_env.features.compute_features` on a synthetic 128 x 128 range image of a sphere.

Run ``python benchmarks/features.py`` (from the repository root, with the package installed or on
``PYTHONPATH``); prints the mean time per call over 1000 calls [ms]. No simulator: the
image comes from an analytic ray-sphere intersection of a pinhole camera.
"""

from __future__ import annotations

import time

import numpy as np

from affordance_env.features import compute_features

#: Image size [pixels], focal length [pixels], sphere radius and distance from the camera [m].
WIDTH = HEIGHT = 128
FOCAL_PX = 120.0
RADIUS_M = 0.05
DISTANCE_M = 0.25
N_CALLS = 1000


def sphere_snapshot() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Points (H, W, 3) [m], ranges (H, W) [m], mask (H, W), camera centre (3,) [m] of a sphere seen along +x.

    The camera sits at the world origin looking along +x with image right = -y and image down = -z.
    """
    v, u = np.mgrid[0:HEIGHT, 0:WIDTH].astype(float)
    x_image, y_image = (u - (WIDTH - 1) / 2) / FOCAL_PX, (v - (HEIGHT - 1) / 2) / FOCAL_PX
    d_camera = np.stack([x_image, y_image, np.ones_like(u)], axis=-1)
    d_camera /= np.linalg.norm(d_camera, axis=-1, keepdims=True)
    R_world_camera = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    d_world = d_camera @ R_world_camera.T
    p_world_camera = np.zeros(3)
    p_world_centre = np.array([DISTANCE_M, 0.0, 0.0])
    b = d_world @ (p_world_centre - p_world_camera)
    disc = b**2 - (p_world_centre @ p_world_centre - RADIUS_M**2)
    mask = disc >= 0.0
    ranges = np.where(mask, b - np.sqrt(np.where(mask, disc, 0.0)), np.inf)
    p_world_hits = p_world_camera + d_world * np.where(mask, ranges, 0.0)[..., None]
    p_world_points = np.where(mask[..., None], p_world_hits, np.nan)
    return p_world_points, ranges.astype(np.float32), mask, p_world_camera


def main() -> None:
    """Print the mean time per call of ``compute_features`` [ms]."""
    p_world_points, ranges, mask, p_world_camera = sphere_snapshot()
    p_world_hand = np.array([0.2, 0.1, 0.0])
    uv_hand = np.array([10.0, 70.0])
    compute_features(p_world_points, ranges, mask, p_world_camera, p_world_hand, uv_hand)  # warm-up
    start = time.perf_counter()
    for _ in range(N_CALLS):
        compute_features(p_world_points, ranges, mask, p_world_camera, p_world_hand, uv_hand)
    elapsed = time.perf_counter() - start
    print(
        f"compute_features: {1e3 * elapsed / N_CALLS:.3f} ms per call "
        f"({int(mask.sum())} object pixels in a {HEIGHT}x{WIDTH} grid, mean over {N_CALLS} calls)"
    )


if __name__ == "__main__":
    main()
