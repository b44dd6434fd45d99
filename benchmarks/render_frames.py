"""How many pictures ``render_mode="rgb_array_list"`` gives per canonical tap (one per 1/30 s of simulated time).

    python benchmarks/render_frames.py [--episodes 200]

Runs ``TapAffordance-v2`` at seeds 0 .. episodes - 1, the canonical tap, and counts the pictures ``render()`` returns
after each interaction; the pictures themselves are not drawn (``World.picture`` is replaced by a 1 x 1 one), so the
count costs what the interactions cost.
"""

from __future__ import annotations

import argparse

import gymnasium as gym
import numpy as np

import affordance_env  # noqa: F401 (registers the envs)
from affordance_env.registry import ENV_ID


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=200)
    args = parser.parse_args()
    env = gym.make(ENV_ID, render_mode="rgb_array_list")
    env.unwrapped.world.picture = lambda width, height: np.zeros((1, 1, 3), np.uint8)  # count, not draw
    counts = []
    for seed in range(args.episodes):
        env.reset(seed=seed)
        env.step(np.zeros(3, np.float32))
        counts.append(len(env.render()))
    c = np.array(counts)
    print(f"canonical taps, seeds 0-{args.episodes - 1}: pictures per interaction: min {c.min()}, median "
          f"{np.median(c):.0f}, max {c.max()} (seed 0: {counts[0]})")


if __name__ == "__main__":
    main()
