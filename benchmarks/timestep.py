"""Does the timestep outside the stroke change what a tap interaction does?

    python benchmarks/timestep.py [--episodes 40] [--behavior tap tap_back push] [--timesteps 0.005 0.002 0.001]

A tap interaction steps at the scene's 2 ms during its stroke, which resolves the impact, and at
``motion.FREE_TIMESTEP`` (5 ms) everywhere else: the head turning to the object, the reach, the way home and the
wait for the object to come to rest. This runs the same interactions (seeds 0 .. episodes-1 of each behaviour,
half canonical, half at random actions) with each of ``--timesteps`` outside the stroke, and compares every one
with the first 2 ms run: the outcome labels (rolled, toppled, success, how the wait ended) that differ, and how
far apart the object ends on the table; a finer timestep (1 ms) shows how far 2 ms itself is from converged.
It also prints the physics steps and wall time per interaction of each.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from affordance_env.tap_env import TapAffordanceEnv

LABELS = ("rolled", "toppled", "success", "outcome")


def run(behavior: str, timestep: float, episodes: int) -> tuple[list[dict], float, float]:
    """(per interaction: labels, end position and rolling distance; steps and seconds per interaction)."""
    env = TapAffordanceEnv(behavior=behavior)
    env.motion.free_timestep = timestep
    steps = 0
    step = env.physics.step

    def counted_step(n: int = 1) -> None:
        nonlocal steps
        steps += n
        step(n)

    env.physics.step = counted_step
    rng = np.random.default_rng(0)
    actions = [np.zeros(3) if i < episodes // 2 else rng.uniform(-1.0, 1.0, 3) for i in range(episodes)]
    rows = []
    start = time.perf_counter()
    for seed, action in enumerate(actions):
        env.reset(seed=seed)
        info = env.step(action)[4]
        rows.append({**{k: info[k] for k in LABELS}, "failure": info["failure"], "name": f"{behavior} seed {seed}",
                     "position": info["object"]["final_pose"][:2], "displacement": info["displacement"],
                     "rolling": info["rolling_distance"]})
    return rows, steps / episodes, (time.perf_counter() - start) / episodes


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--episodes", type=int, default=40, help="interactions per behaviour")
    parser.add_argument("--behavior", nargs="+", default=["tap", "tap_back", "push"])
    parser.add_argument("--timesteps", type=float, nargs="+", default=[0.005, 0.001],
                        help="timesteps outside the stroke [s], each compared with 2 ms")
    args = parser.parse_args()

    runs = {}
    for timestep in [0.002, *args.timesteps]:
        rows, cost = [], []
        for behavior in args.behavior:
            r, steps, seconds = run(behavior, timestep, args.episodes)
            rows += r
            cost.append((steps, seconds))
        runs[timestep] = (rows, np.mean(cost, axis=0))
    reference, (steps, seconds) = runs[0.002]
    n = len(reference)
    print(f"{n} interactions ({', '.join(args.behavior)}; {args.episodes} each, half canonical, half random actions)")
    print(f"  2 ms throughout: {steps:.0f} physics steps, {1e3 * seconds:.1f} ms per interaction")
    for timestep in args.timesteps:
        rows, (steps, seconds) = runs[timestep]
        both = [(a, b) for a, b in zip(reference, rows, strict=True) if a["failure"] is None and b["failure"] is None]
        differ = {k: sum(a[k] != b[k] for a, b in both) for k in LABELS}
        failed = sum((a["failure"] is None) != (b["failure"] is None) for a, b in zip(reference, rows, strict=True))
        apart = np.array([np.linalg.norm(a["position"] - b["position"]) for a, b in both])
        moved = np.array([a["displacement"] for a, _ in both])
        rolled = moved > 0.05
        print(f"  {1e3 * timestep:g} ms outside the stroke: {steps:.0f} physics steps, {1e3 * seconds:.1f} ms per "
              f"interaction")
        print(f"    labels that differ from 2 ms ({len(both)} valid in both): "
              + ", ".join(f"{k} {v}" for k, v in differ.items()) + f"; valid in one only: {failed}")
        print(f"    where the object ends, apart from 2 ms [mm]: median {1e3 * np.median(apart):.2f}, 90th percentile "
              f"{1e3 * np.percentile(apart, 90):.2f}, largest {1e3 * apart.max():.2f}; over the "
              f"{rolled.sum()} that travelled more than 5 cm, median "
              f"{100 * np.median(apart[rolled] / moved[rolled]):.1f} % of their travel")
        for a, b in both:
            if any(a[k] != b[k] for k in LABELS):
                print(f"    {a['name']}: " + ", ".join(f"{k} {a[k]} -> {b[k]}" for k in LABELS if a[k] != b[k])
                      + f" (travel {1e3 * a['displacement']:.1f} -> {1e3 * b['displacement']:.1f} mm, rolling "
                      f"{1e3 * a['rolling']:.1f} -> {1e3 * b['rolling']:.1f} mm)")


if __name__ == "__main__":
    main()
