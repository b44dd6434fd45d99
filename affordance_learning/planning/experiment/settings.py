"""The settings of ``affordance plan``: its sizes, the goals drawn per object, the oracle's actions, the policies
and the seeds of the evaluation's items.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from affordance_env.objects import OBJECT_TYPES

GOAL_KINDS = ("roll", "lift", "move", "place")


#: The single step's policies: ``planner_grid`` is the planner with its fixed candidates instead of the search
#: (:func:`~.baselines.grid_planner`), at the search's time.
POLICIES = ("planner", "planner_grid", "random", "best_fixed", "canonical_choice", "som_categories", "oracle")


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
        trees: Trees of each behaviour's effect model (its forest's ``n_estimators``): 100, as the shipped
            action-conditioned models have (``affordance_learning.default_model.ACTION_TREES``). A decision's time
            is mostly the forests' (the search's cheap scores walk every tree): with the shipped models of 100 trees
            a single step's median decision took 44 ms, ``feasible`` included (120 goals of 6 held-out objects, seed
            0), where ``affordance plan``'s models of 200 trees took about 105 ms.
        quick: A quick run (:data:`QUICK`): the whole pipeline on too few data for the targets' verdicts, which
            then read "too few data" wherever n is below a target's minimum; the console and the report say so.

    Sizing (TapAffordanceGoal-v2, five behaviours, the run's 160 x 120 camera; CPU seconds on one core of a 2-core
    machine, measured in one process): a goal episode 0.79 (25 episodes of 96 interactions, the ``feasible`` draws
    included; 0.7-0.9 grasps an episode), a top-up interaction 0.06 (the strokes) or 0.10 (the draw); an effect
    model 2.5 on 1000 interactions with 200 trees (about half with 100), five of them per planner and five planners
    (one, and one without each shape); an object's single step 56 and 75 (seed 0's first two, a sphere and a box,
    with models of about 100 interactions per behaviour; profiled on the box: 86 % the oracle's 325 interactions,
    94 % with the policies' own, 58 % the grasps, 64 % MuJoCo's steps, 9 % the head's observations after each,
    which the oracle now skips (the env's ``outcome``), 4 % the planners' choices); a multi-step episode 0.9
    (planner), 0.4 (direction), 0.6 (random). At these defaults ``affordance plan --seed 0`` took 15.2, 15.2 and
    12.7 min on two cores (the machine's speed varies from day to day): collecting 5.6-6.7 min (1595 goal
    episodes), fitting 0.2, evaluating 7.0-9.1 (the processes' own 17.7 CPU minutes, 16.2 with the oracle's
    observations skipped on the same machine); ``--seed 1`` 12.3 min. The evaluation
    cannot be cut much without its n falling below the targets' minimum (400 chosen actions need 20 objects of 20
    goals). The grasp gets about a fifth of the goal episodes' interactions: 1000 of them take about 1600 episodes,
    the collection's largest part. Half of the goals were feasible in a reduced run (a third of a box's): 24
    objects give about 240 feasible goals, 6 objects of each shape.
    """

    episodes: int = 1500
    max_per_behavior: int = 1000
    max_episodes: int = 1800
    objects: int = 24
    multi_episodes: int = 64
    candidates: int = 64
    threshold: float = 0.5
    som_clusters: int = 6
    trees: int = 100
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
#: writes, not to judge the targets (every n stays below their minimum). 60 goal episodes give 41 grasps, about 50
#: interactions of each stroke and 30 draws (seed 0), topped up to 60; two held-out objects (a sphere and a box: an
#: object's single step is most of a quick run, 56 and 75 CPU seconds for the first two of seed 0); 4 multi-step
#: episodes per policy; 25 trees instead of 200 (a fit's time grows with the trees: 10.1 CPU seconds for 200, 5.3 for
#: 100, on 4 behaviours of 1000 interactions).
QUICK = PlanSettings(episodes=60, max_per_behavior=60, max_episodes=60, objects=2, multi_episodes=4, candidates=32,
                     som_clusters=4, trees=25, quick=True)
