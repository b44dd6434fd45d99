"""``affordance plan``: learn what the behaviours do, then use it to reach goals, against baselines in one run.

1. Collect goal episodes of the goal env (:data:`affordance_env.registry.GOAL_ENV_ID`) with random actions,
   objects spread over the workspaces (:func:`affordance_env.dataset.collect`, resumable), extending the dataset
   in rounds until every behaviour has ``max_per_behavior`` interactions (or ``max_episodes`` were collected), and
   keep the first ``max_per_behavior`` of each behaviour for training.
2. Fit an :class:`~.effect_model.ActionEffectModel` per behaviour, the same without each shape
   (step 4), and the paper's model (:class:`~affordance_learning.paper.model.AffordanceModel`, its effect categories)
   per behaviour for the ``som_categories`` baseline.
3. Single step, on held-out objects (reset seeds disjoint from the training episodes, ``objects`` of them, the
   shapes in turn). On each object every behaviour's :func:`oracle_params` (the canonical action and a 4 x 4 x 4
   grid, 65 per behaviour, the same for every object) is run from the same snapshot (``get_state`` /
   ``set_state``), once; then :data:`GOALS_PER_OBJECT` goals (:mod:`.goals`: roll, lift, move
   5 cm in each of 8 directions, and places within 3 cm of points 5-15 cm away, on the table as the goal env's
   targets are: :func:`place_target`) are each judged against those outcomes. Policies, all from that snapshot
   (an action run once is not run again: the env repeats an interaction bit for bit from a snapshot):

   - ``planner``: :meth:`~affordance_learning.planning.planner.Planner.choose`, with ``feasible`` ruling out reach
     failures, remembering the actions that failed on this object (:meth:`~affordance_learning.planning.planner.Planner.
     note_failure`); the time of each decision is measured, ``feasible``'s calls included;
   - ``random``: a uniform behaviour and a uniform action of the oracle's set;
   - ``best_fixed``: per goal kind, the behaviour whose canonical action reached that kind most often (chosen
     after the fact over all objects: an upper bound for a fixed choice);
   - ``canonical_choice``: the planner's choice of behaviour with the canonical action only;
   - ``som_categories``: the paper's categories as a planner: the behaviour whose predicted effect category
     reached the goal most often in training, at the canonical action;
   - ``oracle``: whether any action of the oracle's set reached the goal. A goal it reaches is *feasible*.

   Success is reported on every goal, on the feasible goals, and on the goals the oracle or the planner reached.
4. Leaving each shape out: on the goals of step 3 whose object is of that shape, the planner of the models fitted
   without it, from the same snapshot (the oracle's verdict says which goals are feasible).
5. Multi-step: episodes of the goal env (its targets, its tolerance, at most ``GOAL_MAX_EPISODE_STEPS``
   interactions), re-planning after each interaction with :meth:`~affordance_learning.planning.planner.Planner.toward`'s
   defaults (a search over two interactions, the behaviours' workspaces saying where a second one can act),
   against random actions and a direction heuristic. Where no candidate is feasible the planner stops
   (``gave_up``) rather than run an interaction it knows would fail; an action that failed to reach is not chosen
   again from where it failed. Targets toward the robot (within 45 degrees of +x from the object) are counted
   apart; every ``TOWARD_ROBOT_EVERY``-th episode has one, on an object that leaves room for it
   (:func:`episode_start`).
6. Calibration of P(goal) on the planner's chosen actions of step 3 (expected calibration error over 10 bins,
   AUROC), and, beside it, pooled over every action of the oracle's set for every goal.

The goals of one object are judged against the same outcomes, so they are not independent: the Wilson intervals
treat them as if they were, and the report gives the number of objects beside them. Every number is measured in
this run; fractions are in [0, 1], distances in metres, times in seconds.
"""

from __future__ import annotations

import itertools
import math
import os
import pickle
import tempfile
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from affordance_env.goal_env import GOAL_TABLE_MARGIN, TapAffordanceGoalEnv, draw_target
from affordance_env.objects import OBJECT_TYPES
from affordance_env.registry import BEHAVIOR_NAMES, GOAL_ENV_ID
from affordance_env.scene import table_extent
from affordance_learning.planning.effect_model import ActionEffectModel, behavior_model
from affordance_learning.planning.goals import Goal, Lift, Move, Place, Roll
from affordance_learning.planning.outcomes import model_inputs, outcome_table
from affordance_learning.planning.planner import FAILURE_RADIUS, Planner

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

    @property
    def goals(self) -> int:
        """Single-step goals: :data:`GOALS_PER_OBJECT` per object."""
        return self.objects * sum(GOALS_PER_OBJECT.values())


# --- outcomes measured by the simulator ------------------------------------------------------------------------
def measured_outcome(info: Mapping[str, Any]) -> dict[str, np.ndarray]:
    """The outcome (:mod:`affordance_learning.planning.outcomes`) of one interaction from its step ``info``: one row."""
    obj = info["object"]
    start, end = np.asarray(obj["initial_pose"]), np.asarray(obj["final_pose"])
    return {"dx": np.array([end[0] - start[0]]), "dy": np.array([end[1] - start[1]]),
            "rolled": np.array([bool(info["rolled"])]), "off_table": np.array([info["outcome"] == "off_table"]),
            "lifted": np.array([info.get("behavior") == "grasp" and bool(info["success"])]),
            "effect": np.asarray(info["effect"], dtype=np.float64)[None]}


def reached(goal: Goal, info: Mapping[str, Any]) -> bool:
    """Whether an interaction (its step ``info``) reached ``goal``; a failed interaction never does."""
    if info["failure"] is not None:
        return False
    return bool(goal.reached(measured_outcome(info), np.asarray(info["object"]["initial_pose"])[:2])[0])


def reach_failure(info: Mapping[str, Any]) -> bool:
    """Whether an interaction failed to reach (``"ik: ..."`` or ``"reach: ..."``): what ``feasible`` promised."""
    return bool(info["failure"]) and info["failure"].split(":")[0] in ("ik", "reach")


def place_target(start_xy: np.ndarray, rng: np.random.Generator, draws: int = 1000) -> np.ndarray:
    """A place ``PLACE_DISTANCE`` from ``start_xy`` [m] in a uniform direction, where the goal env puts its goals:
    at least ``GOAL_TABLE_MARGIN`` inside the table top's edges and in some behaviour's workspace (a place beyond
    the edge is no place an object can be put). Raises RuntimeError if ``draws`` draws find none."""
    target = draw_target(start_xy, rng, *table_extent(), PLACE_DISTANCE, draws=draws)
    if target is not None:
        return target
    raise RuntimeError(f"No place {PLACE_DISTANCE} m from the object at {np.asarray(start_xy).tolist()} lies "
                       f"{GOAL_TABLE_MARGIN} m inside the table and in a workspace after {draws} draws.")


def draw_goal(kind: str, start_xy: np.ndarray, rng: np.random.Generator, direction: int | None = None) -> Goal:
    """A goal of ``kind`` for an object seen at ``start_xy``; a move goes along ``direction`` (0-7, every 45
    degrees from +x), else one drawn; a place is drawn by :func:`place_target`."""
    if kind == "roll":
        return Roll()
    if kind == "lift":
        return Lift()
    if kind == "move":
        angle = (rng.integers(8) if direction is None else direction) * np.pi / 4
        return Move(tuple(np.round(np.array([np.cos(angle), np.sin(angle)]), 12)), MOVE_DISTANCE)
    return Place(tuple(place_target(np.asarray(start_xy, dtype=np.float64), rng)), PLACE_TOLERANCE)


def draw_goals(start_xy: np.ndarray, rng: np.random.Generator) -> list[Goal]:
    """The goals of one object of the single-step evaluation (:data:`GOALS_PER_OBJECT`)."""
    goals = []
    for kind, n in GOALS_PER_OBJECT.items():
        goals += [draw_goal(kind, start_xy, rng, i if kind == "move" else None) for i in range(n)]
    return goals


# --- training --------------------------------------------------------------------------------------------------
def training_frames(frame: pd.DataFrame, max_per_behavior: int, exclude_type: str | None = None
                    ) -> dict[str, pd.DataFrame]:
    """Each behaviour's rows of a goal-episode frame, at most ``max_per_behavior`` (the first, by episode and step),
    without the objects of ``exclude_type``."""
    if exclude_type is not None:
        frame = frame[frame["type"] != exclude_type]
    frame = frame.sort_values(["episode", "step"])
    return {b: frame[frame["behavior"] == b].head(max_per_behavior) for b in BEHAVIOR_NAMES}


def fit_models(frames: Mapping[str, pd.DataFrame], random_state: int, n_jobs: int | None = None
               ) -> dict[str, ActionEffectModel]:
    """An effect model per behaviour (:func:`~affordance_learning.planning.effect_model.behavior_model`)."""
    return {b: behavior_model(b, random_state=random_state, n_jobs=n_jobs).fit(model_inputs(f), outcome_table(f))
            for b, f in frames.items()}


@dataclass
class SomBaseline:
    """The paper's categories as a planner: per behaviour, its fitted AffordanceModel and the training outcomes
    with their categories."""

    models: dict[str, Any]
    outcomes: dict[str, pd.DataFrame]
    labels: dict[str, np.ndarray]

    @classmethod
    def fit(cls, frames: Mapping[str, pd.DataFrame], n_clusters: int, random_state: int) -> SomBaseline:
        from affordance_env.dataset import learning_data
        from affordance_learning.paper.model import AffordanceModel

        models, outcomes, labels = {}, {}, {}
        for b, f in frames.items():
            X, E, _ = learning_data(f, b)
            models[b] = AffordanceModel(n_clusters=n_clusters, relevancy=0.4, random_state=random_state).fit(X, E)
            outcomes[b], labels[b] = outcome_table(f), models[b].labels_
        return cls(models, outcomes, labels)

    def choose(self, features: np.ndarray, goal: Goal, start_xy: np.ndarray) -> tuple[str, float]:
        """The behaviour whose predicted category reached ``goal`` most often in training, and that share."""
        best = (next(iter(self.models)), -1.0)
        for b, model in self.models.items():
            x = pd.DataFrame(np.asarray(features, dtype=np.float64)[None], columns=model.feature_names_in_)
            category = int(model.predict(x)[0])
            members = self.labels[b] == category
            if not members.any():
                continue
            share = float(goal.reached(self.outcomes[b][members], start_xy).mean())
            if share > best[1]:
                best = (b, share)
        return best


# --- the evaluation's worker: a goal env per thread -----------------------------------------------------------
_worker = threading.local()


def _env(camera: tuple[int, int]):
    if getattr(_worker, "env", None) is None:
        _worker.env = TapAffordanceGoalEnv(camera_width=camera[0], camera_height=camera[1],
                                           position_range="workspace")
    return _worker.env


def feasible_at(env, state) -> Callable[[str, np.ndarray], bool]:
    """``feasible(behavior, params)`` of the world in snapshot ``state``, whatever the env ran since (the env's
    ``feasible(..., state=state)``, which leaves the env as it is)."""
    return lambda behavior, params: bool(env.feasible(behavior, params, state=state))


def _trimmed(info: Mapping[str, Any]) -> dict[str, Any]:
    """What the evaluation reads of a step's ``info`` (:func:`measured_outcome`, :func:`reached`)."""
    obj = info["object"]
    return {"failure": info["failure"], "rolled": info["rolled"], "outcome": info["outcome"],
            "behavior": info.get("behavior"), "success": info["success"],
            "effect": np.asarray(info["effect"], dtype=np.float64),
            "object": {"initial_pose": np.asarray(obj["initial_pose"]), "final_pose": np.asarray(obj["final_pose"])}}


class Outcomes:
    """The interactions run on one object from one snapshot, each once: ``run(behavior, params)`` runs it the
    first time and returns what it did (a trimmed step ``info``) every time after (the env repeats an interaction
    bit for bit from a snapshot)."""

    def __init__(self, env, state) -> None:
        self.env, self.state = env, state
        self.done: dict[tuple[str, bytes], dict[str, Any]] = {}

    def run(self, behavior: str, params: np.ndarray) -> dict[str, Any]:
        params = np.asarray(params, dtype=np.float32)
        key = (behavior, params.tobytes())
        if key not in self.done:
            self.env.set_state(self.state)
            *_, info = self.env.step({"behavior": behavior, "params": params})
            self.done[key] = _trimmed(info)
        return self.done[key]


def _decide(planner: Planner, features, goal: Goal, start, feasible, outcomes: Outcomes
            ) -> tuple[Any, bool, dict[str, Any] | None, float]:
    """The planner's choice for ``goal``, whether its action reached it, what it did, and the decision's time
    [s]; an action that failed to reach is remembered (:meth:`~.planner.Planner.note_failure`).
    """
    t = time.perf_counter()
    choice = planner.choose(features, goal, start, feasible=feasible)
    seconds = time.perf_counter() - t
    if not choice.behavior:
        return choice, False, None, seconds
    info = outcomes.run(choice.behavior, choice.params)
    if reach_failure(info):
        planner.note_failure(choice.behavior, choice.params, start)
    return choice, reached(goal, info), info, seconds


def evaluate_object(item: Mapping[str, Any], planner: Planner, shape_planners: Mapping[str, Planner],
                    som: SomBaseline | None, camera: tuple[int, int]) -> list[dict[str, Any]] | None:
    """Every policy on the goals of one object (``item``: reset ``seed``, ``rng``, ``shape``): a record per goal;
    None if the object was not seen at the start. ``shape_planners``: per shape, the planner fitted without it."""
    env = _env(camera)
    rng = np.random.default_rng(item["rng"])
    obs, info = env.reset(seed=item["seed"], options={"object_type": item["shape"]})
    if not info["visible"]:
        return None
    start = np.asarray(obs["achieved_goal"], dtype=np.float64)
    features = np.asarray(obs["observation"]["features"], dtype=np.float64)
    state = env.get_state()
    feasible = feasible_at(env, state)
    outcomes = Outcomes(env, state)
    oracle_set = oracle_params()
    tried = [(b, k, outcomes.run(b, params)) for b in BEHAVIOR_NAMES for k, params in enumerate(oracle_set)]
    # Every oracle action's P(goal) is read from its predictive outcomes, computed once for the object.
    X = np.hstack([np.repeat(features[None], len(oracle_set), axis=0), oracle_set])
    predicted = {b: planner.on_table(planner.models[b].predictive_outcomes(X), start) for b in BEHAVIOR_NAMES}
    canonical_pick = Planner(planner.models, n_candidates=1, threshold=planner.threshold)
    left_out = shape_planners.get(item["shape"])
    for p in (planner, left_out):
        if p is not None:
            p.forget_failures()
    shape, size = info["object"]["type"], float(info["object"]["size"])
    records = []
    for j, goal in enumerate(draw_goals(start, rng)):
        record: dict[str, Any] = {"kind": goal.kind, "type": shape, "goal": goal.to_dict(), "object": item["index"],
                                  "item": {**dict(item), "goal": j}}
        choice, ok, done, seconds = _decide(planner, features, goal, start, feasible, outcomes)
        record.update(planner=ok, planner_p=choice.probability, planner_behavior=choice.behavior,
                      decision_s=seconds, planner_reach_failure=bool(done and reach_failure(done)))
        if done is not None and isinstance(goal, Place):
            end = np.asarray(done["object"]["final_pose"][:2])
            record["placement_error"] = float(np.linalg.norm(end - np.asarray(goal.target_xy)))
            record["placement_committed"] = not choice.abstained
        if left_out is not None:
            record["planner_left_out"] = _decide(left_out, features, goal, start, feasible, outcomes)[1]
        hits = {(b, k): reached(goal, info) for b, k, info in tried}
        pick = int(rng.integers(len(BEHAVIOR_NAMES))), int(rng.integers(len(oracle_set)))
        record["random"] = hits[(BEHAVIOR_NAMES[pick[0]], pick[1])]
        record["canonical"] = {b: hits[(b, 0)] for b in BEHAVIOR_NAMES}
        best = canonical_pick.choose(features, goal, start, feasible=feasible)
        record["canonical_choice"] = bool(best.behavior and record["canonical"][best.behavior])
        if som is not None:
            record["som_categories"] = record["canonical"][som.choose(features, goal, start)[0]]
        record["oracle"] = any(hits.values())
        record["oracle_hits"] = sum(hits.values())
        record["size"] = size
        p = np.concatenate([predicted[b].probability(goal, start) for b in BEHAVIOR_NAMES])
        record["pooled"] = (p, np.array([hits[(b, k)] for b in BEHAVIOR_NAMES for k in range(len(oracle_set))]))
        records.append(record)
    return records


def _evaluate(task: tuple[str | None, Mapping[str, Any]], planner: Planner, shape_planners: Mapping[str, Planner],
              som: SomBaseline | None, camera: tuple[int, int]):
    """One task of the evaluation: ``(None, item)`` an object of the single step (:func:`evaluate_object`),
    ``(policy, item)`` a multi-step episode of that policy (:func:`evaluate_episode`)."""
    policy, item = task
    if policy is None:
        return evaluate_object(item, planner, shape_planners, som, camera)
    return evaluate_episode(item, planner, policy, camera)


def _direction_heuristic(start: np.ndarray, target: np.ndarray) -> str:
    """The behaviour that moves an object the way the target lies: push away (-x), draw toward the robot (+x)
    where the env has it, tap to -y, tap back to +y."""
    d = target - start
    if -d[0] > abs(d[1]) and "push" in BEHAVIOR_NAMES:
        return "push"
    if d[0] > abs(d[1]) and "draw" in BEHAVIOR_NAMES:
        return "draw"
    return "tap" if d[1] < 0 else "tap_back"


#: Every this many multi-step episodes, the target is drawn toward the robot (:func:`goal_toward_robot`), as
#: the env draws its goals but within 45 degrees of +x: drawn uniformly in direction, a goal lies toward the robot
#: in a tenth of the episodes only, the table's near edge being 14 cm in front of the objects.
TOWARD_ROBOT_EVERY = 4
#: The behaviours that bring an object toward the robot: the draw, and the grasp that puts it down there. A
#: planner's episode toward the robot records whether each could act on the object where it started (``pulls_at_start``:
#: ``feasible`` of its canonical action).
PULLING = ("draw", "grasp")
#: Objects drawn at most for an episode toward the robot: one within about 28-30 cm of the robot leaves no room (or
#: little) for a target 10 cm or more toward it, within 45 degrees of straight ahead and 5 cm inside the table's
#: near edge, so the episode takes the next object drawn that does (on the first alone, seeds 0-3 gave 13, 16, 13
#: and 11 such episodes of 16).
TOWARD_ROBOT_OBJECTS = 20


def goal_toward_robot(start_xy, env, rng: np.random.Generator) -> list[float] | None:
    """A target as the goal env draws its goals (``GOAL_DISTANCE`` from the object, ``GOAL_TABLE_MARGIN`` inside
    the table, in some behaviour's workspace) but toward the robot (within 45 degrees of +x), from ``rng``; None
    if 200 draws find none."""
    table = env.world.table
    goal = draw_target(np.asarray(start_xy, dtype=float), rng, table.low, table.high, angles=(-np.pi / 4, np.pi / 4),
                       draws=200)
    return None if goal is None else goal.tolist()


def toward_robot(start_xy, target_xy) -> bool:
    """Whether the target lies toward the robot from the object: within 45 degrees of +x."""
    need = np.asarray(target_xy, dtype=float) - np.asarray(start_xy, dtype=float)
    return bool(need[0] > abs(need[1]))


def episode_start(env, item: Mapping[str, Any], rng: np.random.Generator) -> tuple[dict, dict]:
    """``env.reset`` for the multi-step episode ``item``: the goal env's object and target from reset seed
    ``item["seed"]``; every ``TOWARD_ROBOT_EVERY``-th episode a target toward the robot (:func:`goal_toward_robot`),
    on the first of ``TOWARD_ROBOT_OBJECTS`` objects (the item's, then reset seeds from ``rng``) that the table leaves
    room for one in front of. Returns reset's observation and info."""
    seed = item["seed"]
    obs, info = env.reset(seed=seed)
    if item["index"] % TOWARD_ROBOT_EVERY:
        return obs, info
    for _ in range(TOWARD_ROBOT_OBJECTS):
        goal = goal_toward_robot(obs["achieved_goal"], env, rng)
        if goal is not None:
            return env.reset(seed=seed, options={"goal": goal})  # the same object, this target
        seed = int(rng.integers(2**31))
        obs, info = env.reset(seed=seed)
    return obs, info


def evaluate_episode(item: Mapping[str, Any], planner: Planner, policy: str, camera: tuple[int, int],
                     frames: list | None = None) -> dict[str, Any]:
    """One multi-step episode of ``policy`` from reset seed ``item["seed"]``: reached, interactions, reach
    failures, the final distance [m], the planner's decision times [s]; ``frames``, if given, gets a labelled picture
    of the start and after each interaction."""
    from affordance_env.registration import GOAL_MAX_EPISODE_STEPS

    env = _env(camera)
    rng = np.random.default_rng(item["rng"])
    obs, info = episode_start(env, item, rng)
    initial_state = env.get_state()
    tolerance = env.goal_tolerance
    steps, failures, success, gave_up, decisions = 0, [], False, False, []
    distance = initial = float(info["distance"])
    start_xy, target_xy = (np.asarray(obs[key], dtype=float).tolist() for key in ("achieved_goal", "desired_goal"))
    if frames is not None:
        frames.append((f"start: {100 * distance:.1f} cm to go", env.render()))
    planner.forget_failures()
    for step in range(GOAL_MAX_EPISODE_STEPS):
        start, target = obs["achieved_goal"], obs["desired_goal"]
        if policy == "planner":
            state = env.get_state()
            t = time.perf_counter()
            choice = planner.toward(obs["observation"]["features"], start, target, tolerance,
                                    feasible=feasible_at(env, state), steps_left=GOAL_MAX_EPISODE_STEPS - step)
            decisions.append(time.perf_counter() - t)
            env.set_state(state)  # feasible may have put it back: the same state, to be sure
            if choice.behavior is None:  # none of the candidates asked is reachable: stop rather than fail
                gave_up = True
                break
            behavior, params = choice.behavior, choice.params
        elif policy == "direction":
            behavior, params = _direction_heuristic(start, target), np.zeros(3)
        else:
            behavior, params = BEHAVIOR_NAMES[int(rng.integers(len(BEHAVIOR_NAMES)))], rng.uniform(-1, 1, 3)
        obs, _, terminated, _, info = env.step({"behavior": behavior, "params": np.asarray(params, np.float32)})
        steps += 1
        if reach_failure(info):
            failures.append(info["failure"])
        # An action that failed to reach, or left the object where it was, would do so again from there: noted
        moved = float(np.linalg.norm(np.asarray(obs["achieved_goal"]) - np.asarray(start)))
        if policy == "planner" and (reach_failure(info) or (not terminated and moved < FAILURE_RADIUS)):
            planner.note_failure(behavior, params, start)
        distance = float(info["distance"])
        if frames is not None:
            frames.append((f"{behavior}: {100 * distance:.1f} cm to go", env.render()))
        if terminated:
            success = bool(info["is_success"])
            break
    toward = toward_robot(start_xy, target_xy)
    # What could bring the object toward the robot from where it started, for such a target
    pulls = ({name: bool(feasible_at(env, initial_state)(name, np.zeros(3))) for name in PULLING}
             if policy == "planner" and toward else None)
    return {"policy": policy, "success": success, "steps": steps, "reach_failures": len(failures), "failures": failures,
            "final_distance": distance, "gave_up": gave_up, "type": info["object"]["type"],
            "initial_distance": initial, "start_xy": start_xy, "target_xy": target_xy, "tolerance": tolerance,
            "toward_robot": toward, "pulls_at_start": pulls, "decision_s": decisions}


#: The directions of :func:`step_reach`: world +x (towards the robot), -x (away), +y (to its right), -y (left).
DIRECTIONS = ("+x", "-x", "+y", "-y")


def step_reach(frame: pd.DataFrame, quantile: float = 0.9) -> dict[str, dict[str, float]]:
    """Per object type and direction (:data:`DIRECTIONS`), how far one interaction moves the object that way [m]:
    the ``quantile`` of the displacement's component along it (0 for a move the other way) over the interactions
    of a dataset frame that stayed on the table, whatever the behaviour and action."""
    dx = (frame["true_final_x"] - frame["true_initial_x"]).to_numpy(np.float64)
    dy = (frame["true_final_y"] - frame["true_initial_y"]).to_numpy(np.float64)
    kept = (frame["outcome"].astype(str) != "off_table").to_numpy()
    types = frame["type"].astype(str).to_numpy()
    out = {}
    for shape in OBJECT_TYPES:
        rows = kept & (types == shape)
        if rows.any():
            parts = dict(zip(DIRECTIONS, (dx[rows], -dx[rows], dy[rows], -dy[rows]), strict=True))
            out[shape] = {d: float(np.quantile(np.maximum(v, 0.0), quantile)) for d, v in parts.items()}
    return out


def within_reach(start_xy, target_xy, reach: Mapping[str, float], tolerance: float, interactions: int) -> bool:
    """Whether ``interactions`` that each move the object ``reach`` [m] along a direction (one type's
    :func:`step_reach`) can bring it from ``start_xy`` to within ``tolerance`` of ``target_xy`` along both axes: a
    generous bound (each axis gets the whole tolerance and every interaction the 90th percentile)."""
    need = np.asarray(target_xy, dtype=float) - np.asarray(start_xy, dtype=float)
    cap = np.array([reach["+x"] if need[0] > 0 else reach["-x"], reach["+y"] if need[1] > 0 else reach["-y"]])
    return bool(np.all(np.maximum(np.abs(need) - tolerance, 0.0) <= interactions * cap))


# --- statistics ------------------------------------------------------------------------------------------------
def wilson(successes: int, n: int) -> tuple[float, float]:
    """Wilson 95 % interval of a share (:func:`~affordance_learning.paper.metrics.wilson_interval`);
    (0, 1) for 0 of 0."""
    from affordance_learning.paper.metrics import wilson_interval

    return wilson_interval(int(successes), int(n))


def share_text(value: float | None, n: int, ci: Sequence[float] | None = None, unit: str = "",
               digits: int = 0) -> str:
    """A share as the console and the report show it: ``"80 % [62, 91] (n=35 feasible goals)"``, the Wilson 95 %
    interval when given; "not measured (n=0)" for a share of nothing (0 of 0 is no rate, not 0 %)."""
    count = f"n={n}" + (f" {unit}" if unit else "")
    if value is None or n == 0:
        return f"not measured ({count})"
    interval = "" if ci is None else f" [{100 * ci[0]:.0f}, {100 * ci[1]:.0f}]"
    return f"{100 * value:.{digits}f} %{interval} ({count})"


def calibration(p: np.ndarray, y: np.ndarray, bins: int = 10) -> dict[str, Any]:
    """Expected calibration error over ``bins`` equal-width bins, AUROC, and the reliability curve."""
    from sklearn.metrics import roc_auc_score

    p, y = np.asarray(p, dtype=float), np.asarray(y, dtype=bool)
    if not len(p):
        return {"ece": None, "auroc": None, "n": 0, "curve": []}
    index = np.clip((p * bins).astype(int), 0, bins - 1)
    curve, ece = [], 0.0
    for b in range(bins):
        members = index == b
        if members.any():
            ece += members.mean() * abs(p[members].mean() - y[members].mean())
            curve.append({"p": float(p[members].mean()), "observed": float(y[members].mean()),
                          "n": int(members.sum())})
    auroc = float(roc_auc_score(y, p)) if 0 < y.mean() < 1 else None
    return {"ece": float(ece), "auroc": auroc, "n": int(len(p)), "curve": curve}


def calibrations(records: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """The calibration of P(goal) on the planner's chosen actions (each goal it acted on: ``planner_p`` against
    ``planner``), and beside it (``pooled``) over every action of the oracle's set for every goal (``pooled``: P
    and reached per action)."""
    acted = [r for r in records if r["planner_behavior"]]
    pooled_p = np.concatenate([r["pooled"][0] for r in records]) if records else np.zeros(0)
    pooled_y = np.concatenate([r["pooled"][1] for r in records]) if records else np.zeros(0, bool)
    return {**calibration([r["planner_p"] for r in acted], [r["planner"] for r in acted]),
            "basis": "the planner's chosen actions",
            "pooled": {**calibration(pooled_p, pooled_y), "basis": "every action of the oracle's set, for every goal"}}


def summarize(records: Sequence[Mapping[str, Any]], policies: Sequence[str]) -> dict[str, Any]:
    """Per policy, with Wilson intervals: success on every goal, on the feasible goals (those the oracle reached),
    and on the goals the oracle or the planner reached (``success_reached``)."""
    feasible = np.array([r["oracle"] for r in records], dtype=bool)
    either = feasible | np.array([bool(r.get("planner", False)) for r in records], dtype=bool)
    out = {}
    for policy in policies:
        values = np.array([bool(r.get(policy, False)) for r in records], dtype=bool)
        n, k = len(values), int(values.sum())
        nf, kf = int(feasible.sum()), int(values[feasible].sum())
        ne, ke = int(either.sum()), int(values[either].sum())
        out[policy] = {"success": k / n if n else None, "success_ci": wilson(k, n),
                       "success_feasible": kf / nf if nf else None, "success_feasible_ci": wilson(kf, nf), "n": n,
                       "n_feasible": nf, "success_reached": ke / ne if ne else None,
                       "success_reached_ci": wilson(ke, ne), "n_reached": ne}
    return out


def best_fixed(records: list[dict[str, Any]]) -> dict[str, str]:
    """Per goal kind, the behaviour whose canonical action reached it most often; sets ``best_fixed`` in each
    record."""
    choice = {}
    for kind in GOAL_KINDS:
        rows = [r for r in records if r["kind"] == kind]
        if rows:
            choice[kind] = max(BEHAVIOR_NAMES, key=lambda b: sum(r["canonical"][b] for r in rows))
    for r in records:
        r["best_fixed"] = r["canonical"][choice[r["kind"]]]
    return choice


def seconds_summary(seconds: Sequence[float]) -> dict[str, Any]:
    """Median, 99th percentile and the most of decision times [s], and their n; None for no decision."""
    s = np.asarray(seconds, dtype=float)
    if not len(s):
        return {"median": None, "p99": None, "max": None, "n": 0}
    return {"median": float(np.median(s)), "p99": float(np.quantile(s, 0.99)), "max": float(s.max()), "n": len(s)}


# --- the run ---------------------------------------------------------------------------------------------------
def _items(seed: int, part: int, n: int) -> list[dict]:
    items = []
    for i in range(n):
        ss = np.random.SeedSequence([seed, EVAL_STREAM, part, i])
        env_seed, rng_seed = (int(v) for v in ss.generate_state(2))
        items.append({"seed": env_seed, "rng": rng_seed, "index": i, "shape": OBJECT_TYPES[i % len(OBJECT_TYPES)]})
    return items


def _parallel(function, items: list, workers: int, **kwargs) -> list:
    """``[function(item, **kwargs) for item in items]`` on ``workers`` processes. The items go one at a time to
    the first process free, so that none is left idle while another works through its costlier objects (a grasp's
    oracle costs 4-20 times a stroke's); ``kwargs`` (the planners: about 300 MB) are written once to a temporary
    file and read once per process, and the processes (with the env each has built) serve every call. Each call
    depends on its item and ``kwargs`` alone, so the results are the same for any number of processes.

    The processes are new ones, not those joblib keeps from earlier work (the collection's): joblib's process pool
    measures a process's memory after its first call and restarts it, with a warning, once it holds 300 MB more,
    as a process that served the collection first does once it has read the planners. So this shuts down the
    process pool joblib keeps for the calling process (``get_reusable_executor``), whoever started it."""
    if workers == 1 or len(items) <= 1:
        return [function(item, **kwargs) for item in items]
    from joblib import Parallel, delayed
    from joblib.externals.loky import get_reusable_executor

    get_reusable_executor().shutdown(wait=True)  # the next Parallel starts new processes
    with tempfile.TemporaryDirectory(prefix="affordance-plan-") as tmp:
        task = Path(tmp) / "task.pickle"
        task.write_bytes(pickle.dumps((function, kwargs), protocol=pickle.HIGHEST_PROTOCOL))
        return Parallel(n_jobs=workers, batch_size=1)(delayed(_call)(str(task), item) for item in items)


def _call(task: str, item):
    """One item of :func:`_parallel` in a worker process: ``task``'s function and keyword arguments, read from its
    file the first time this process meets it."""
    if getattr(_worker, "task_file", None) != task:
        _worker.task, _worker.task_file = pickle.loads(Path(task).read_bytes()), task
    function, kwargs = _worker.task
    return function(item, **kwargs)


#: Top-up interactions are collected this many times what is missing (some fail, and are not rows) ...
TOP_UP_MARGIN = 1.15
#: ... and numbered from this episode on, after every goal episode.
TOP_UP_EPISODES = 1_000_000


def collect_training(out: Path, settings: PlanSettings, seed: int, workers: int, camera: tuple[int, int],
                     say: Callable[[str], None] = print) -> pd.DataFrame:
    """Goal episodes with random actions in ``out``, extended in rounds until the grasp (every behaviour that only
    the goal env runs as it does) has ``settings.max_per_behavior`` interactions or ``settings.max_episodes``
    episodes were collected; each round asks for as many more episodes as the scarcest such behaviour's share so
    far says it needs (and 5 % more), in whole chunks. A behaviour TapAffordance-v2 runs as the goal env does (the
    strokes, the draw) that is still short is topped up with random interactions of TapAffordance-v2 in the
    scene with both arms, objects over its workspace (in ``out`` beside the goal episodes, named after it): the
    draw, which reaches only objects near the robot, gets a tenth of the goal episodes' interactions. The frame of
    both."""
    from affordance_env.behaviors import get_behavior
    from affordance_env.dataset import MANIFEST, collect, load_dataset, read_manifest

    episodes, chunk = settings.episodes, 25
    if (out / MANIFEST).exists():  # an earlier collection, perhaps extended: resumed as far as it went
        episodes = max(episodes, int(read_manifest(out)["episodes"]))
    camera_options = {"camera_width": camera[0], "camera_height": camera[1]}
    # The behaviours TapAffordance-v2 runs as the goal env does (all but the grasp, which the goal env runs as pick
    # and place): their interactions in its scene with both arms are the goal env's, and cost no goal episode.
    same = [b for b in BEHAVIOR_NAMES if get_behavior(b) is get_behavior(b, goal=True)]
    while True:
        collect(out, episodes, seed=seed, workers=workers, action="random", env_id=GOAL_ENV_ID,
                env_options={"position_range": "workspace", **camera_options}, max_failure_share=1.0,
                chunk_size=chunk)
        frame = load_dataset(out)
        counts = {b: int((frame["behavior"] == b).sum()) for b in BEHAVIOR_NAMES}
        short = min(n for b, n in counts.items() if b not in same)
        if short >= settings.max_per_behavior or episodes >= settings.max_episodes:
            break
        wanted = episodes * settings.max_per_behavior / max(short, 1) * 1.05
        episodes = min(settings.max_episodes, max(episodes + chunk, math.ceil(wanted / chunk) * chunk))
        say(f"      {', '.join(f'{b} {n}' for b, n in counts.items())} interactions: extending to {episodes} "
            "episodes")
    for behavior in same:  # topped up with single interactions over the behaviour's own workspace
        missing = settings.max_per_behavior - counts[behavior]
        if missing <= 0:
            continue
        wanted = math.ceil(missing * TOP_UP_MARGIN / chunk) * chunk
        say(f"      {behavior}: {counts[behavior]} interactions in the goal episodes, {wanted} more of "
            f"TapAffordance-v2 in the same scene")
        collect(top_up_path(out, behavior), wanted, seed=seed, workers=workers, action="random",
                env_options={"behavior": behavior, "two_arms": True, "position_range": "workspace",
                             **camera_options}, max_failure_share=1.0, chunk_size=chunk)
    return load_training(out)


def top_up_path(out: Path, behavior: str) -> Path:
    """Where :func:`collect_training` tops up ``behavior``'s interactions of the goal episodes in ``out``."""
    return out.parent / f"{out.name}-{behavior}"


def load_training(out: str | os.PathLike) -> pd.DataFrame:
    """The training frame :func:`collect_training` collected into ``out`` (``affordance plan``'s
    ``OUT/dataset``): its goal episodes, then each behaviour's top-up beside it (each interaction an episode of
    one step, numbered from ``TOP_UP_EPISODES``)."""
    from affordance_env.dataset import MANIFEST, load_dataset

    out = Path(out)
    frames = [load_dataset(out)]
    for behavior in BEHAVIOR_NAMES:
        path = top_up_path(out, behavior)
        if (path / MANIFEST).exists():
            extra = load_dataset(path)
            frames.append(extra.assign(episode=extra["episode"] + TOP_UP_EPISODES, step=0))
    return pd.concat(frames, ignore_index=True)


def run_plan(out: str | os.PathLike, seed: int = 0, workers: int = 2, settings: PlanSettings | None = None,
             camera: tuple[int, int] = (160, 120), say: Callable[[str], None] = print) -> dict[str, Any]:
    """Run the whole experiment into ``out`` (``dataset/``, ``results.json``); returns the results."""
    from affordance_env.registration import GOAL_MAX_EPISODE_STEPS

    settings = settings or PlanSettings()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    timings: dict[str, float] = {}
    start = time.perf_counter()
    say(f"[1/5] collecting goal episodes with random actions into {out / 'dataset'} until every behaviour has "
        f"{settings.max_per_behavior} interactions (at most {settings.max_episodes} episodes)")
    frame = collect_training(out / "dataset", settings, seed, workers, camera, say)
    frames = training_frames(frame, settings.max_per_behavior)
    timings["collect"] = time.perf_counter() - start
    say(f"      {frame['episode'].nunique()} episodes ({timings['collect']:.0f} s); "
        + ", ".join(f"{b} {len(f)}" for b, f in frames.items()) + " interactions for training")

    t = time.perf_counter()
    models = fit_models(frames, seed, n_jobs=workers)
    planner = Planner(models, n_candidates=settings.candidates, threshold=settings.threshold, random_state=seed)
    som = SomBaseline.fit(frames, settings.som_clusters, seed)
    shape_planners = {
        shape: Planner(fit_models(training_frames(frame, settings.max_per_behavior, exclude_type=shape), seed,
                                  n_jobs=workers),
                       n_candidates=settings.candidates, threshold=settings.threshold, random_state=seed)
        for shape in OBJECT_TYPES}
    timings["fit"] = time.perf_counter() - t
    say(f"[2/5] fitted the effect models, each shape's without it, and the paper's categories "
        f"({timings['fit']:.1f} s)")

    t = time.perf_counter()
    items = _items(seed, 0, settings.objects)
    multi_items = _items(seed, 9, settings.multi_episodes)
    # Steps 3 and 5 in one queue: the objects first (20-60 s each, most of it the grasp's oracle), then the
    # multi-step episodes (about a second each), so that no process waits while the other finishes its last object.
    done = _parallel(_evaluate, [(None, item) for item in items]
                     + [(policy, item) for policy in MULTI_POLICIES for item in multi_items],
                     workers, planner=planner, shape_planners=shape_planners, som=som, camera=camera)
    objects, multi_done = done[: len(items)], done[len(items):]
    timings["evaluate"] = time.perf_counter() - t
    records = [r for rs in objects if rs is not None for r in rs]
    fixed_choice = best_fixed(records)
    single = summarize(records, POLICIES)
    n_objects = sum(rs is not None for rs in objects)
    say(f"[3/5] single step: {len(records)} goals on {n_objects} held-out objects (with step 5: "
        f"{timings['evaluate']:.0f} s): "
        + ", ".join(f"{p} {share_text(single[p]['success'], single[p]['n'], single[p]['success_ci'])}"
                    for p in POLICIES)
        + f"; {single['oracle']['n_feasible']} goals feasible")

    loso: dict[str, Any] = {}
    for shape in OBJECT_TYPES:
        shape_records = [{**r, "planner": r.get("planner_left_out", False)} for r in records if r["type"] == shape]
        loso[shape] = summarize(shape_records, ("planner", "best_fixed", "random", "oracle"))
    say("[4/5] leaving each shape out (judged in step 3): "
        + ", ".join(f"{s} " + share_text(loso[s]["planner"]["success_feasible"], loso[s]["planner"]["n_feasible"],
                                         loso[s]["planner"]["success_feasible_ci"], "feasible") for s in OBJECT_TYPES))

    multi: dict[str, Any] = {}
    for i, policy in enumerate(MULTI_POLICIES):
        episodes = multi_done[i * len(multi_items): (i + 1) * len(multi_items)]
        if policy == "planner":
            planner_episodes = episodes
        n = len(episodes)
        k = sum(e["success"] for e in episodes)
        toward = [e for e in episodes if e["toward_robot"]]
        kt = sum(e["success"] for e in toward)
        interactions = sum(e["steps"] for e in episodes)
        multi[policy] = {"success": k / n if n else None, "success_ci": wilson(k, n), "n": n,
                         "reach_failures": sum(e["reach_failures"] for e in episodes) / max(interactions, 1),
                         "interactions": interactions, "gave_up": sum(e["gave_up"] for e in episodes),
                         "median_final_distance_m": float(np.median([e["final_distance"] for e in episodes])),
                         "success_toward_robot": kt / len(toward) if toward else None,
                         "success_toward_robot_ci": wilson(kt, len(toward)), "n_toward_robot": len(toward)}
    say(f"[5/5] multi-step on {settings.multi_episodes} episodes (with step 3): "
        + ", ".join(f"{p} {share_text(multi[p]['success'], multi[p]['n'], multi[p]['success_ci'])}"
                    for p in MULTI_POLICIES)
        + "; toward the robot: planner " + share_text(multi["planner"]["success_toward_robot"],
                                                       multi["planner"]["n_toward_robot"],
                                                       multi["planner"]["success_toward_robot_ci"]))

    multi["planner"]["by_type"] = {
        shape: {"n": len(eps), "success": sum(e["success"] for e in eps) / len(eps)}
        for shape in OBJECT_TYPES if (eps := [e for e in planner_episodes if e["type"] == shape])}
    reach, tolerance = step_reach(frame), planner_episodes[0]["tolerance"]  # the goal env's
    multi["step_reach_p90_m"], multi["tolerance_m"], multi["max_interactions"] = (reach, tolerance,
                                                                                  GOAL_MAX_EPISODE_STEPS)
    multi["planner"]["episodes"] = [
        {**{k: e[k] for k in ("type", "start_xy", "target_xy", "initial_distance", "final_distance", "steps",
                              "success", "gave_up", "reach_failures", "failures", "toward_robot", "pulls_at_start")},
         "within_reach": e["type"] in reach and within_reach(e["start_xy"], e["target_xy"], reach[e["type"]],
                                                             tolerance, GOAL_MAX_EPISODE_STEPS)}
        for e in planner_episodes]
    inside = [e for e in multi["planner"]["episodes"] if e["within_reach"]]
    multi["planner"]["within_reach"] = {"n": len(inside), "success": (sum(e["success"] for e in inside) / len(inside)
                                                                      if inside else None)}
    acted = [r for r in records if r["planner_behavior"]]
    placement = [r["placement_error"] for r in records if "placement_error" in r]
    committed = [r["placement_error"] for r in records if r.get("placement_committed")]
    oracle = single["oracle"]["success"] or 0.0
    choose_s = [r["decision_s"] for r in records]
    toward_s = [s for e in planner_episodes for s in e["decision_s"]]
    timings["total"] = time.perf_counter() - start
    results = {
        "format": "tap-affordance-plan-results", "version": 2, "seed": seed, "settings": asdict(settings),
        "units": {"fractions": "[0, 1]", "distances": "m", "times": "s"},
        "training": {b: len(f) for b, f in frames.items()},
        "training_episodes": int(frame["episode"].nunique()),
        "workers": workers, "cpu_count": os.cpu_count(),
        "oracle": {"actions_per_behavior": len(oracle_params()), "levels": list(ORACLE_LEVELS),
                   "objects": n_objects, "goals_per_object": dict(GOALS_PER_OBJECT),
                   "objects_per_shape": {s: len({r["object"] for r in records if r["type"] == s})
                                         for s in OBJECT_TYPES}},
        "single_step": single,
        "single_step_by_goal": {kind: summarize([r for r in records if r["kind"] == kind], POLICIES)
                                for kind in GOAL_KINDS},
        "best_fixed_behavior": fixed_choice,
        "planner_over_oracle": (single["planner"]["success"] / oracle) if oracle else None,
        "single_step_reach_failures": {"n": len(acted),
                                       "failures": sum(r["planner_reach_failure"] for r in acted)},
        "leave_one_shape_out": loso,
        "multi_step": multi,
        "placement_error_median_m": float(np.median(placement)) if placement else None,
        "placement_error_n": len(placement),  # the place goals the planner acted on: the median's n
        # the same over the place goals it acted on without abstaining (P(goal) >= its threshold)
        "placement_error_committed_median_m": float(np.median(committed)) if committed else None,
        "placement_error_committed_n": len(committed),
        "calibration": calibrations(records),
        "decision_seconds": {**seconds_summary(choose_s + toward_s), "choose": seconds_summary(choose_s),
                             "toward": seconds_summary(toward_s)},
        "timings_s": timings,
        "goals": [{k: r.get(k) for k in ("kind", "type", "object", "size", "goal", "planner", "planner_p",
                                         "planner_behavior", "oracle", "oracle_hits", "planner_left_out")}
                  for r in records],
    }
    import json

    (out / "results.json").write_text(json.dumps(results, indent=1, default=float))
    return results


def record_episode(out: str | os.PathLike, results: Mapping[str, Any], seed: int = 0
                   ) -> list[tuple[str, np.ndarray]]:
    """Pictures of one multi-step planner episode (the first of the evaluation's), with the models refitted from
    ``out/dataset``: the start, then the scene after each interaction, titled with the behaviour."""
    from affordance_env.dataset import load_dataset

    settings = PlanSettings(**results["settings"])
    frames = training_frames(load_dataset(Path(out) / "dataset"), settings.max_per_behavior)
    planner = Planner(fit_models(frames, seed), n_candidates=settings.candidates, threshold=settings.threshold,
                      random_state=seed)
    env = TapAffordanceGoalEnv(position_range="workspace", render_mode="rgb_array", render_width=320,
                               render_height=240)
    previous = getattr(_worker, "env", None)
    _worker.env = env
    try:
        item = _items(seed, 9, 1)[0]
        pictures: list[tuple[str, np.ndarray]] = []
        evaluate_episode(item, planner, "planner", (160, 120), frames=pictures)
        return pictures
    finally:
        _worker.env = previous
        env.close()


__all__ = ["PlanSettings", "run_plan", "record_episode", "measured_outcome", "reached", "calibration", "wilson",
           "share_text", "oracle_params", "feasible_at", "seconds_summary"]
