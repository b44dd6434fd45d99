"""The planner's decisions on place goals: their time, and how near the place the chosen action puts the object,
for the cross-entropy search (the default) and the fixed grid of candidates, the grid also at the search's time.

    python benchmarks/planner.py [--objects 12] [--goals 3] [--seed 0] [--execute] [--spread 0 1]
                                 [--search-only] [--toward 0]

Objects are drawn by ``TapAffordanceGoal-v2`` (reset seeds ``seed * 1000 + i``, objects anywhere in the
behaviours' workspaces) and each gets ``--goals`` places 5-15 cm away, drawn as the plan experiment draws them
(:func:`affordance_learning.planning.experiment.draw_goal`); the planners use the shipped action models
(:func:`affordance_learning.default_model.load_action_model`). Per planner it prints the decision time (median,
p99 [ms] of the process's CPU time, one thread, ``feasible`` not asked: on a machine others share, CPU time is
what one core spends, where the wall clock also counts the waits) and, over the goals, the model's expected
distance of the chosen action to the place (the mean of its predictive outcomes) and its P(within 3 cm). The grid
at equal time has as many candidates as fit in the search's median time (64 times the ratio of the two's medians
on the first goals). With ``--execute`` each planner's choice, asked with the env's ``feasible``, is run in the
simulator from the object's snapshot, and the distance from where the object rests to the place is printed
(median, share within 3 cm; a choice that names no action or fails to reach counts as the start's distance),
also over the goals where the choice's P reached the planner's threshold (it did not abstain).
``--spread`` adds a planner beside the default for each spread weight given
(:data:`affordance_learning.planning.planner.SPREAD_WEIGHT`), to measure it; ``--search-only`` leaves the grid out.
First it prints the CPU time of 1000 queries over every behaviour, scored on their whole predictive outcomes
and by the search's per-kind moments. ``--toward N`` also times
:meth:`~affordance_learning.planning.planner.Planner.toward` (the workspaces' default ``reachable``, more
interactions to follow) toward the first N goals' places.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from threadpoolctl import threadpool_limits

from affordance_env.goal_env import TapAffordanceGoalEnv
from affordance_env.registry import BEHAVIOR_NAMES
from affordance_learning.default_model import load_action_model
from affordance_learning.planning import planner as planning
from affordance_learning.planning.experiment import draw_goal
from affordance_learning.planning.goals import Place
from affordance_learning.planning.planner import Planner


def _expected(planner: Planner, features, goal: Place, start, choice) -> tuple[float, float]:
    """The model's mean distance [m] of the choice's predicted outcomes to the place, and its P(goal)."""
    if choice.behavior is None:
        return float(np.linalg.norm(np.asarray(goal.target_xy) - start)), 0.0
    X = np.hstack([np.asarray(features, dtype=np.float64), choice.params])[None]
    outcomes = planner.on_table(planner.models[choice.behavior].predictive_outcomes(X), start)
    return float(-outcomes.share(goal.progress(outcomes, start))[0]), float(outcomes.probability(goal, start)[0])


def _decide(planner: Planner, spread: float | None, *args, **kwargs):
    saved = planning.SPREAD_WEIGHT
    if spread is not None:
        planning.SPREAD_WEIGHT = spread
    try:
        t = time.process_time()
        choice = planner.choose(*args, **kwargs)
        return choice, time.process_time() - t
    finally:
        planning.SPREAD_WEIGHT = saved


def _evaluation_times(models, features) -> None:
    """Print the CPU time of 1000 queries' whole predictive outcomes and of their per-kind moments, over every
    behaviour (the features of one object, actions drawn uniformly), the best of 3."""
    X = np.hstack([np.repeat(np.asarray(features, dtype=np.float64)[None], 1000, axis=0),
                   np.random.default_rng(0).uniform(-1, 1, (1000, 3))])
    for model in models.values():
        model.kind_moments(X[:2])  # the leaves' sums are made at the first call
    for label, method in (("predictive_outcomes", "predictive_outcomes"), ("kind_moments", "kind_moments")):
        best = np.inf
        for _ in range(3):
            t = time.process_time()
            for model in models.values():
                getattr(model, method)(X)
            best = min(best, time.process_time() - t)
        print(f"{label}: {1000 * best:.0f} ms for 1000 queries over the {len(models)} behaviours")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--objects", type=int, default=12)
    parser.add_argument("--goals", type=int, default=3, help="place goals per object")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--execute", action="store_true", help="run each choice in the simulator")
    parser.add_argument("--spread", type=float, nargs="*", default=[],
                        help="spread weights to compare with the default's")
    parser.add_argument("--search-only", action="store_true", help="leave the grid out")
    parser.add_argument("--toward", type=int, default=0, help="time toward on the first this many goals too")
    args = parser.parse_args()
    models = {b: load_action_model(b) for b in BEHAVIOR_NAMES}
    env = TapAffordanceGoalEnv(position_range="workspace")
    rng = np.random.default_rng(args.seed)
    cases = []
    for i in range(args.objects):
        obs, info = env.reset(seed=args.seed * 1000 + i)
        if not info["visible"]:
            continue
        start = np.asarray(obs["achieved_goal"], dtype=np.float64)
        features = np.asarray(obs["observation"]["features"], dtype=np.float64)
        cases += [(i, features, start, draw_goal("place", start, rng), env.get_state()) for _ in range(args.goals)]
    planners: dict[str, tuple[Planner, float | None]] = {
        "cem": (Planner(models), None), "grid (64)": (Planner(models, optimizer="grid"), None)}
    for weight in args.spread:
        planners[f"cem, spread {weight:g}"] = (Planner(models), weight)
    with threadpool_limits(1):
        _evaluation_times(models, cases[0][1])
        for planner, _ in planners.values():  # warm up: the leaves' sums are made at the first call
            planner.choose(cases[0][1], cases[0][3], cases[0][2])
        cem_time, grid_time = (np.median([_decide(planners[k][0], None, f, g, s)[1] for _, f, s, g, _ in cases[:6]])
                               for k in ("cem", "grid (64)"))
        n = int(round(64 * cem_time / grid_time))  # a grid decision's time grows with its candidates
        if n > 64:
            planners[f"grid ({n}, equal time)"] = (Planner(models, n_candidates=n, optimizer="grid"), None)
        if args.search_only:
            planners = {k: v for k, v in planners.items() if not k.startswith("grid")}
        print(f"{len(cases)} place goals on {len({c[0] for c in cases})} objects; the search's median "
              f"{1000 * cem_time:.0f} ms fits a grid of {n} candidates")
        for label, (planner, spread) in planners.items():
            times, expected, p_goal, landed, committed = [], [], [], [], []
            for _, features, start, goal, state in cases:
                choice, seconds = _decide(planner, spread, features, goal, start)
                times.append(seconds)
                e, p = _expected(planner, features, goal, start, choice)
                expected.append(e)
                p_goal.append(p)
                if args.execute:
                    env.set_state(state)
                    choice, _ = _decide(planner, spread, features, goal, start,
                                        feasible=lambda b, a, state=state: env.feasible(b, a, state=state))
                    end = start
                    if choice.behavior is not None:
                        env.set_state(state)
                        *_, info = env.step({"behavior": choice.behavior,
                                             "params": choice.params.astype(np.float32)})
                        if info["failure"] is None or not info["failure"].startswith(("ik", "reach")):
                            end = np.asarray(info["object"]["final_pose"][:2])
                    landed.append(goal.placement_error(end))
                    committed.append(choice.behavior is not None and not choice.abstained)
                planner.forget_failures()
            toward = []  # a multi-step episode's decision toward the same place, more interactions to follow
            for _, features, start, goal, _ in cases[: args.toward]:
                saved = planning.SPREAD_WEIGHT
                planning.SPREAD_WEIGHT = saved if spread is None else spread
                t = time.process_time()
                planner.toward(features, start, goal.target_xy, goal.tolerance)
                toward.append(time.process_time() - t)
                planning.SPREAD_WEIGHT = saved
            t = 1000 * np.array(times)
            line = (f"{label:>22}: {np.median(t):6.1f} ms median, {np.quantile(t, 0.99):6.1f} ms p99; expected "
                    f"distance {100 * np.median(expected):.1f} cm median, {100 * np.mean(expected):.1f} cm mean, "
                    f"P(within 3 cm) {np.mean(p_goal):.2f} mean")
            if toward:
                line += (f"; toward: {1000 * np.median(toward):.1f} ms median, "
                         f"{1000 * np.quantile(toward, 0.99):.1f} ms p99")
            if landed:
                landed_cm = 100 * np.array(landed)
                sure = np.array(committed)
                line += (f"; landed {np.median(landed_cm):.1f} cm median from the place, "
                         f"{np.mean(landed_cm <= 100 * goal.tolerance):.0%} within 3 cm; where P >= the threshold "
                         f"({sure.sum()} goals) {np.median(landed_cm[sure]) if sure.any() else np.nan:.1f} cm median, "
                         f"{np.mean(landed_cm[sure] <= 100 * goal.tolerance) if sure.any() else np.nan:.0%} within")
            print(line)


if __name__ == "__main__":
    main()
