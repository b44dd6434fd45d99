"""Snapshots per second: range image + object mask + the 49 features, on one core.

    python benchmarks/snapshot.py [--width W] [--height H] [--n 500]

Prints the time per snapshot split into ray casting (``mj_multiRay``), the rest of the capture (points, mask)
and the features, with the object of interest in view at the image centre (after attention).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from affordance_env.features import compute_features
from affordance_env.tap_env import TapAffordanceEnv


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--width", type=int, default=None, help="range image width (default: the env's)")
    parser.add_argument("--height", type=int, default=None, help="range image height (default: the env's)")
    parser.add_argument("--n", type=int, default=500)
    args = parser.parse_args()

    size = {k: v for k, v in (("camera_width", args.width), ("camera_height", args.height)) if v is not None}
    env = TapAffordanceEnv(**size)
    width, height = env.camera.intrinsics.width, env.camera.intrinsics.height
    capture_s = features_s = 0.0
    pixels = []
    for i in range(args.n):
        if i % 50 == 0:
            env.reset(seed=i)
        data = env.physics.data
        start = time.perf_counter()
        image = env.camera.capture(data, occluded=env.physics.active_geom)  # as the env captures
        mask = image.mask_of(env.physics.active_geom)
        p_hand = env.physics.hand_position()
        uv_hand = image.project(p_hand)
        middle = time.perf_counter()
        compute_features(image.p_world_points, image.ranges, mask, image.p_world_camera, p_hand, uv_hand)
        end = time.perf_counter()
        capture_s += middle - start
        features_s += end - middle
        pixels.append(mask.sum())
    total = capture_s + features_s
    print(f"{args.n} snapshots at {width}x{height} ({np.mean(pixels):.0f} object pixels on average)")
    print(f"  per snapshot: {1e3 * total / args.n:.2f} ms  ({args.n / total:.0f} snapshots per second)")
    print(f"    capture (ray casting, points, mask): {1e3 * capture_s / args.n:.2f} ms")
    print(f"    49 features                        : {1e3 * features_s / args.n:.2f} ms")


if __name__ == "__main__":
    main()
