"""How often ``feasible()`` of TapAffordanceGoal-v2 agrees with what the interaction then does: its own IK verdict,
and whether its reach left the object where it was (no ``"reach: ..."`` failure).

    python benchmarks/feasible.py [--draws 400] [--seed 0]

Each draw places an object at a uniform position over the part of the table within the arms' reach, picks a
behaviour and params at random, asks ``feasible`` (kinematics only) and then runs the interaction. It reached when
the behaviour's own outcome says so, whatever failure ``info["failure"]`` names first (an object the head did not
see, a touch on the way home): every pose the IK was asked for within its tolerances, and no ``"reach: ..."``
failure of the behaviour; a pick and place also put the held object down over the table (``feasible`` refuses a
place off it). A grasp that did not hold its object never tried its carry and put-down, which ``feasible`` answers
for too: it is counted apart (``reached=untried``). Prints the agreement, the table of (behaviour, feasible,
reached) counts, per behaviour how many of those that reached it refused and how many of those that failed it
accepted, and every draw on which they disagree; then the time of ``feasible`` on the same draws against the same
calls with every IK spending its whole budget (as an interaction solves it: no giving up once the error stands
still, :data:`affordance_env.kinematics.STALL_WINDOW`), taking turns, with the share of answers they agree on, and
the median time of a call per behaviour.
"""

from __future__ import annotations

import argparse
import time
from collections import Counter
from typing import Any

import numpy as np

import affordance_env.world as world_module
from affordance_env.behaviors.grasp import LIFT_HEIGHT
from affordance_env.goal_env import TapAffordanceGoalEnv
from affordance_env.motion import MotionExecutor
from affordance_env.placement import Table

#: The part of the table the arms can reach at all (x, y) [m]: a margin around every workspace.
REACH_LOW, REACH_HIGH = np.array([-0.52, -0.38]), np.array([-0.16, 0.38])


def reached(behavior: Any, outcome: Any, initial: Any, action: np.ndarray, table: Table) -> bool | None:
    """Whether the interaction reached what ``feasible`` answers for, from the behaviour's ``outcome`` (whatever
    failure the interaction names first); None: a grasp that did not hold its object, whose carry and put-down
    were never tried. ``initial``: the interaction's initial snapshot; ``table``: the world's table."""
    if not outcome.ik_success or str(behavior.failure(outcome) or "").startswith("reach"):
        return False
    if behavior.kind != "grasp":
        return True
    if not (outcome.rise > 0.5 * LIFT_HEIGHT and outcome.links_holding and not outcome.on_table):  # run_grasp's
        return None
    plan = behavior.plan(initial.geometry, initial.pose[:3], initial.yaw, table.top, action)
    return plan.object_place is None or bool(np.all(plan.object_place >= table.low)
                                             and np.all(plan.object_place <= table.high))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--draws", type=int, default=400)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    env = TapAffordanceGoalEnv()
    rng = np.random.default_rng(args.seed)
    counts: Counter = Counter()
    draws, disagreements = [], []
    seen: dict[str, Any] = {}
    failure_reason = world_module.failure_reason

    def watched(fault, initial, outcome, home_still, touched, behavior):  # the behaviour's own outcome
        seen.update(initial=initial, outcome=outcome, behavior=behavior)
        return failure_reason(fault, initial, outcome, home_still, touched, behavior)

    world_module.failure_reason = watched
    try:
        for i in range(args.draws):
            position = tuple(rng.uniform(REACH_LOW, REACH_HIGH))
            env.reset(seed=args.seed * 100_000 + i, options={"position": position})
            behavior, params = int(rng.integers(len(env.behaviors))), rng.uniform(-1, 1, 3).astype(np.float32)
            draws.append((env.get_state(), behavior, params))
            feasible = env.feasible(behavior, params)
            seen.clear()
            _, _, _, _, info = env.step({"behavior": behavior, "params": params})
            verdict = reached(seen["behavior"], seen["outcome"], seen["initial"], params.astype(float),
                              env.world.table) if seen else False
            name = env.behaviors[behavior]
            counts[name, feasible, "untried" if verdict is None else verdict] += 1
            if verdict is not None and feasible != verdict:
                disagreements.append(
                    f"  draw {i}: {name} {info['object']['type']} {info['object']['size'] * 100:.1f} cm at "
                    f"({position[0]:.4f}, {position[1]:.4f}), params {[round(float(x), 4) for x in params]}: "
                    f"feasible={feasible}, reached={verdict} (failure: {info['failure']})")
    finally:
        world_module.failure_reason = failure_reason
    _report(counts, disagreements, args.draws)
    _time_checks(env, draws)
    env.close()


def _report(counts: Counter, disagreements: list[str], n: int) -> None:
    tried = sum(k for (_, _, verdict), k in counts.items() if verdict != "untried")
    agree = sum(k for (_, feasible, verdict), k in counts.items() if feasible == verdict)
    print(f"agreement: {agree} of {tried} ({agree / max(tried, 1):.1%}); {n - tried} grasps did not hold their "
          "object (their carry and put-down untried)")
    for (behavior, feasible, verdict), k in sorted(counts.items(), key=lambda item: tuple(map(str, item[0]))):
        print(f"  {behavior:8s} feasible={feasible!s:5s} reached={verdict!s:7s} {k}")
    print("per behaviour: refused of those that reached, accepted of those that failed")
    for behavior in sorted({name for name, _, _ in counts}):
        refused, accepted = (f"{counts[behavior, not verdict, verdict]} of "
                             f"{counts[behavior, True, verdict] + counts[behavior, False, verdict]}"
                             for verdict in (True, False))
        print(f"  {behavior:8s} refused {refused:>9s}, accepted {accepted}")
    print(f"disagreements: {len(disagreements)}")
    for line in disagreements:
        print(line)


def _time_checks(env: TapAffordanceGoalEnv, draws: list, rounds: int = 3) -> None:
    """``feasible`` on every draw's snapshot, as it is and with the IK's whole budget, taking turns; then the median
    over the draws of each behaviour of a call's time as it is (the least of its rounds)."""
    ik = MotionExecutor.ik

    def in_full(self, p, q_init, hand, check=False):  # every IK as an interaction solves it
        return ik(self, p, q_init, hand)

    seconds: dict[str, list[float]] = {"feasible": [], "whole budget": []}
    answers: dict[str, list[bool]] = {}
    calls = np.full((rounds, len(draws)), np.inf)  # each call's time as it is [s]
    try:
        for r in range(rounds):
            for name in seconds:
                MotionExecutor.ik = ik if name == "feasible" else in_full
                answers[name] = []
                start = time.perf_counter()
                for k, (state, b, p) in enumerate(draws):
                    before = time.perf_counter()
                    answers[name].append(bool(env.feasible(b, p, state=state)))
                    if name == "feasible":
                        calls[r, k] = time.perf_counter() - before
                seconds[name].append(time.perf_counter() - start)
    finally:
        MotionExecutor.ik = ik
    same = sum(a == b for a, b in zip(*answers.values(), strict=True))
    fast, full = (float(np.median(seconds[name])) / len(draws) * 1e3 for name in seconds)
    print(f"feasible(): {fast:.1f} ms per call against {full:.1f} ms with the whole IK budget ({full / fast:.2f} x, "
          f"medians of {rounds} rounds); the same answer for {same} of {len(draws)}")
    least = calls.min(axis=0)
    behaviors = np.array([env.behaviors[b] for _, b, _ in draws])
    print("median per call (with the state's restore), the least of its rounds: " + ", ".join(
        f"{name} {np.median(least[behaviors == name]) * 1e3:.1f} ms (n={int(np.sum(behaviors == name))})"
        for name in env.behaviors if np.any(behaviors == name)))


if __name__ == "__main__":
    main()
