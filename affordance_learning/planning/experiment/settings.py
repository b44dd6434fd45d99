"""The settings of ``affordance plan``: its sizes, the goals drawn per object, the oracle's actions, the policies
and the seeds of the evaluation's items.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from affordance_env.objects import OBJECT_TYPES

GOAL_KINDS = ("roll", "lift", "move", "place")


POLICIES = ("planner", "random", "best_fixed", "canonical_choice", "som_categories", "oracle")


MULTI_POLICIES = ("planner", "direction", "random")


#: Goals: Move's distance [m], Place's distance from the object [m] and tolerance [m].
MOVE_DISTANCE, PLACE_DISTANCE, PLACE_TOLERANCE = 0.05, (0.05, 0.15), 0.03


#: The goals drawn for every object of the single-step evaluation, in this order: one roll, one lift, a move in
#: each of the 8 directions (every 45 degrees), and places 5-15 cm away in uniform directions (:func:`place_target`).
GOALS_PER_OBJECT: dict[str, int] = {"roll": 1, "lift": 1, "move": 8, "place": 10}


#: Seeds of the evaluation's objects: SeedSequence([seed, EVAL_STREAM, part, i]), apart from the training's.
EVAL_STREAM = 7919


#: The levels of the oracle's grid along each parameter: 4 x 4 x 4 = 64 actions per behaviour, with the canonical.
ORACLE_LEVELS = (-0.75, -0.25, 0.25, 0.75)


def oracle_params() -> np.ndarray:
    """(65, 3) the oracle's actions, the same for every behaviour and object: the canonical action (zeros), then
    the 4 x 4 x 4 grid of :data:`ORACLE_LEVELS` (each parameter's range cut in four, at the quarters' centres),
    in lexicographic order. Not the planner's candidates (a Sobol sequence), so that the oracle says what the
    actions can do, not what the planner's own candidates can."""
    grid = np.array(list(itertools.product(ORACLE_LEVELS, repeat=3)), dtype=np.float64)
    return np.vstack([np.zeros((1, 3)), grid])


@dataclass(frozen=True)
class PlanSettings:
    """The sizes of an ``affordance plan`` run.

    Attributes:
        episodes: Goal episodes collected at first; the collection is extended in rounds until every behaviour
            has ``max_per_behavior`` interactions, up to ``max_episodes``.
        max_per_behavior: Training interactions per behaviour (the first of each).
        max_episodes: The most goal episodes collected.
        objects: Held-out objects of the single-step evaluation, the shapes in turn; each gets
            :data:`GOALS_PER_OBJECT` goals, judged against the oracle's 65 actions per behaviour.
        multi_episodes: Multi-step episodes per policy.
        candidates: The planner's parameter vectors per behaviour.
        threshold: The planner abstains below this P(goal).
        som_clusters: Effect categories of the ``som_categories`` baseline.
        trees: Trees of each behaviour's effect model (its forest's ``n_estimators``).
        quick: A quick run (:data:`QUICK`): the whole pipeline on too few data for the targets' verdicts, which
            then read "too few data" wherever n is below a target's minimum; the console and the report say so.

    Sizing (TapAffordanceGoal-v2, five behaviours, one core each): an object's single step costs 18-57 s (seed 0),
    most of it the oracle (65 actions x 5 behaviours; a grasp 0.2-0.5 s, a stroke or a draw 0.02-0.06 s); a
    multi-step episode about a second; a collected goal-episode interaction about 0.14 s (``feasible`` draws
    included), a top-up one about 0.1 s. The
    grasp gets about a fifth of the goal episodes' interactions: 1000 of them take about 1500 episodes, the
    collection's largest part. Half of the goals were feasible in a reduced run (a third of a box's): 24 objects
    give about 240 feasible goals, 6 objects of each shape.
    """

    episodes: int = 1500
    max_per_behavior: int = 1000
    max_episodes: int = 1800
    objects: int = 24
    multi_episodes: int = 64
    candidates: int = 64
    threshold: float = 0.5
    som_clusters: int = 6
    trees: int = 200
    quick: bool = False

    @property
    def goals(self) -> int:
        """Single-step goals: :data:`GOALS_PER_OBJECT` per object."""
        return self.objects * sum(GOALS_PER_OBJECT.values())


def evaluation_items(seed: int, part: int, n: int) -> list[dict]:
    """The evaluation's items of ``part`` (0: the single step's objects, 9: the multi-step episodes): per item its
    reset ``seed``, the seed of its own generator (``rng``), its ``index`` and the object type it asks for (the
    types in turn), from ``SeedSequence([seed, EVAL_STREAM, part, i])``, apart from the training's seeds."""
    items = []
    for i in range(n):
        ss = np.random.SeedSequence([seed, EVAL_STREAM, part, i])
        env_seed, rng_seed = (int(v) for v in ss.generate_state(2))
        items.append({"seed": env_seed, "rng": rng_seed, "index": i, "shape": OBJECT_TYPES[i % len(OBJECT_TYPES)]})
    return items


#: The sizes of ``affordance plan --quick``: the whole pipeline in a few minutes, to see that it runs and what it
#: writes, not to judge the targets (every n stays below their minimum). 60 goal episodes give each behaviour
#: 25-35 interactions (about 0.45 grasps an episode), the rest topped up to 60; one held-out object of each shape;
#: 6 multi-step episodes per policy; 25 trees instead of 200 (fit and prediction take about an eighth as long).
QUICK = PlanSettings(episodes=60, max_per_behavior=60, max_episodes=60, objects=4, multi_episodes=6, candidates=32,
                     som_clusters=4, trees=25, quick=True)
