"""How far the canonical draw brings objects toward the robot, per object type and size, and how often it fails.

    python benchmarks/draw.py [--episodes 200] [--action canonical|random]

Runs ``TapAffordance-v2`` with ``behavior="draw"`` at seeds 0 .. episodes - 1 (objects placed as the paper's, types
and sizes drawn by the env), the canonical action (or random ones, drawn from seed 0), and prints, over the valid
interactions, the object's travel toward the robot (+x) and across (y): the median, the share moved at least 2 cm
toward the robot, per type and per third of the size range; then the failures by kind.
"""

from __future__ import annotations

import argparse
from collections import Counter

import gymnasium as gym
import numpy as np

import affordance_env  # noqa: F401 (registers the envs)
from affordance_env.registry import ENV_ID

#: An object counts as drawn when it came at least this far toward the robot [m].
DRAWN = 0.02


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=200)
    parser.add_argument("--action", choices=("canonical", "random"), default="canonical")
    args = parser.parse_args()
    env = gym.make(ENV_ID, behavior="draw")
    rng = np.random.default_rng(0)
    rows, failures = [], Counter()
    for seed in range(args.episodes):
        _, info = env.reset(seed=seed)
        action = np.zeros(3) if args.action == "canonical" else rng.uniform(-1.0, 1.0, 3)
        _, _, _, _, info = env.step(action.astype(np.float32))
        if info["failure"]:
            failures[info["failure"].split(":")[0]] += 1
            continue
        moved = np.asarray(info["object"]["final_pose"][:2]) - np.asarray(info["object"]["initial_pose"][:2])
        rows.append((info["object"]["type"], info["object"]["size"], moved[0], moved[1], info["outcome"]))
    env.close()
    types = np.array([r[0] for r in rows])
    sizes = np.array([r[1] for r in rows])
    dx, dy = np.array([r[2] for r in rows]), np.array([r[3] for r in rows])

    def line(label: str, sel: np.ndarray) -> str:
        return (f"{label:22s} n={sel.sum():4d}  toward the robot: median {100 * np.median(dx[sel]):5.1f} cm, "
                f"{100 * np.mean(dx[sel] >= DRAWN):5.1f} % >= {100 * DRAWN:.0f} cm; across: median |y| "
                f"{100 * np.median(np.abs(dy[sel])):4.1f} cm")

    print(f"{args.action} draws, seeds 0-{args.episodes - 1}: {len(rows)} valid, "
          f"{sum(failures.values())} failed ({100 * sum(failures.values()) / args.episodes:.1f} %): "
          + (", ".join(f"{k} {v}" for k, v in failures.items()) or "none"))
    print(line("all", np.ones(len(rows), bool)))
    for t in sorted(set(types)):
        print(line(t, types == t))
    edges = np.quantile(sizes, [0, 1 / 3, 2 / 3, 1])
    for i in range(3):
        sel = (sizes >= edges[i]) & ((sizes < edges[i + 1]) if i < 2 else (sizes <= edges[i + 1]))
        print(line(f"size {100 * edges[i]:.1f}-{100 * edges[i + 1]:.1f} cm", sel))
    print("outcomes:", dict(Counter(r[4] for r in rows)))


if __name__ == "__main__":
    main()
