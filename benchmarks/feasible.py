"""How often ``feasible()`` of TapAffordanceGoal-v2 agrees with what the interaction then does: its own IK verdict,
and whether its reach left the object where it was (no ``"reach: ..."`` failure).

    python benchmarks/feasible.py [--draws 400] [--seed 0]

Each draw places an object at a uniform position over the part of the table within the arms' reach, picks a
behaviour and params at random, asks ``feasible`` (kinematics only) and then runs the interaction: it reached when
``info["ik"]["success"]`` (measured whatever else happens) and it did not fail with ``"reach: ..."``. Prints the
agreement and the table of (behaviour, feasible, reached) counts; then the time of ``feasible`` on the same draws
against the same calls with every IK spending its whole budget (as an interaction solves it: no giving up once the
error stands still, :data:`affordance_env.kinematics.STALL_WINDOW`), taking turns, with the share of answers they
agree on.
"""

from __future__ import annotations

import argparse
import time
from collections import Counter

import numpy as np

from affordance_env.goal_env import TapAffordanceGoalEnv
from affordance_env.motion import MotionExecutor

#: The part of the table the arms can reach at all (x, y) [m]: a margin around every workspace.
REACH_LOW, REACH_HIGH = np.array([-0.52, -0.38]), np.array([-0.16, 0.38])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--draws", type=int, default=400)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    env = TapAffordanceGoalEnv()
    rng = np.random.default_rng(args.seed)
    counts: Counter = Counter()
    draws = []
    for i in range(args.draws):
        env.reset(seed=args.seed * 100_000 + i, options={"position": tuple(rng.uniform(REACH_LOW, REACH_HIGH))})
        behavior, params = int(rng.integers(len(env.behaviors))), rng.uniform(-1, 1, 3).astype(np.float32)
        draws.append((env.get_state(), behavior, params))
        feasible = env.feasible(behavior, params)
        _, _, _, _, info = env.step({"behavior": behavior, "params": params})
        reached = bool(info["ik"]["success"]) and not str(info["failure"] or "").startswith("reach")
        counts[env.behaviors[behavior], feasible, reached] += 1
    agree = sum(n for (_, feasible, reached), n in counts.items() if feasible == reached)
    print(f"agreement: {agree} of {args.draws} ({agree / args.draws:.1%})")
    for (behavior, feasible, reached), n in sorted(counts.items()):
        print(f"  {behavior:8s} feasible={feasible!s:5s} reached={reached!s:5s} {n}")
    _time_checks(env, draws)
    env.close()


def _time_checks(env: TapAffordanceGoalEnv, draws: list, rounds: int = 3) -> None:
    """``feasible`` on every draw's snapshot, as it is and with the IK's whole budget, taking turns."""
    ik = MotionExecutor.ik

    def in_full(self, p, q_init, hand, check=False):  # every IK as an interaction solves it
        return ik(self, p, q_init, hand)

    seconds: dict[str, list[float]] = {"feasible": [], "whole budget": []}
    answers: dict[str, list[bool]] = {}
    try:
        for _ in range(rounds):
            for name in seconds:
                MotionExecutor.ik = ik if name == "feasible" else in_full
                start = time.perf_counter()
                answers[name] = [bool(env.feasible(b, p, state=state)) for state, b, p in draws]
                seconds[name].append(time.perf_counter() - start)
    finally:
        MotionExecutor.ik = ik
    same = sum(a == b for a, b in zip(*answers.values(), strict=True))
    fast, full = (float(np.median(seconds[name])) / len(draws) * 1e3 for name in seconds)
    print(f"feasible(): {fast:.1f} ms per call against {full:.1f} ms with the whole IK budget ({full / fast:.2f} x, "
          f"medians of {rounds} rounds); the same answer for {same} of {len(draws)}")


if __name__ == "__main__":
    main()
