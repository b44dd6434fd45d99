"""``affordance plan``: learn what the behaviours do, then use it to reach goals, against baselines in one run.

1. Collect goal episodes of TapAffordanceGoal-v1 with random actions, objects spread over the workspaces
   (:func:`affordance_env.dataset.collect`, resumable), and keep at most ``max_per_behavior`` interactions of each
   behaviour for training.
2. Fit an :class:`~affordance_learning.effect_model.ActionEffectModel` per behaviour, and the paper's model
   (:class:`~affordance_learning.model.AffordanceModel`, its effect categories) per behaviour for the
   ``som_categories`` baseline.
3. Single step, on held-out objects (reset seeds disjoint from the training episodes): one goal per object, the
   kinds in turn (:mod:`affordance_learning.goals`: roll, lift, move 5 cm in one of 8 directions, place within
   3 cm of a point 5-15 cm away). Every policy acts from the same snapshot (``get_state`` / ``set_state``):

   - ``planner``: :meth:`~affordance_learning.planner.Planner.choose`, with ``feasible`` ruling out reach failures;
   - ``random``: a uniform behaviour and uniform parameters;
   - ``best_fixed``: per goal kind, the behaviour whose canonical action reached that kind most often (chosen
     after the fact over all objects: an upper bound for a fixed choice);
   - ``canonical_choice``: the planner's choice of behaviour with the canonical action only;
   - ``som_categories``: the paper's categories as a planner: the behaviour whose predicted effect category
     reached the goal most often in training, at the canonical action;
   - ``oracle``: tries the canonical action of every behaviour, then ``oracle_candidates`` parameter vectors per
     behaviour, in simulation, until one reaches the goal. A goal it reaches is *feasible*.

4. Leaving each shape out in turn: the effect models refitted without that object type, judged on the goals of
   step 3 whose object is of that type, from the same start (the oracle's verdict says which are feasible).
5. Multi-step: episodes of TapAffordanceGoal-v1 (targets 10-25 cm away, 3 cm tolerance, at most 5
   interactions), re-planning after each interaction with a search over two interactions
   (:meth:`~affordance_learning.planner.Planner.toward`, the behaviours' workspaces saying where a second one can
   act), against random actions and a direction heuristic. Where no candidate is feasible the planner stops
   (``gave_up``) rather than run an interaction it knows would fail.
6. Calibration of P(goal) over every action executed in step 3 (expected calibration error over 10 bins, AUROC).

Every number is measured in this run; fractions are in [0, 1], distances in metres.
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from affordance_env.registry import BEHAVIOR_NAMES, GOAL_ENV_ID
from affordance_learning.effect_model import ActionEffectModel
from affordance_learning.goals import Goal, Lift, Move, Place, Roll, goal_from_dict
from affordance_learning.outcomes import model_inputs, outcome_table
from affordance_learning.planner import Planner, candidate_params

BEHAVIORS = BEHAVIOR_NAMES
GOAL_KINDS = ("roll", "lift", "move", "place")
SHAPES = ("sphere", "box", "horizontal_cylinder", "vertical_cylinder")
POLICIES = ("planner", "random", "best_fixed", "canonical_choice", "som_categories", "oracle")
MULTI_POLICIES = ("planner", "direction", "random")
#: Goals: Move's distance [m], Place's distance from the object [m] and tolerance [m].
MOVE_DISTANCE, PLACE_DISTANCE, PLACE_TOLERANCE = 0.05, (0.05, 0.15), 0.03
#: Seeds of the evaluation's objects: SeedSequence([seed, EVAL_STREAM, part, i]), apart from the training's.
EVAL_STREAM = 7919


@dataclass(frozen=True)
class PlanSettings:
    """The sizes of an ``affordance plan`` run (the defaults fit in 10 minutes on 2 cores). ``oracle_candidates``:
    parameter vectors per behaviour the oracle tries after the canonical actions."""

    episodes: int = 1000
    max_per_behavior: int = 1000
    goals: int = 160
    multi_episodes: int = 40
    oracle_candidates: int = 8
    candidates: int = 64
    threshold: float = 0.5
    som_clusters: int = 6


# --- outcomes measured by the simulator ------------------------------------------------------------------------
def measured_outcome(info: Mapping[str, Any]) -> dict[str, np.ndarray]:
    """The outcome (:mod:`affordance_learning.outcomes`) of one interaction from its step ``info``: one row."""
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


def draw_goal(kind: str, start_xy: np.ndarray, rng: np.random.Generator) -> Goal:
    """A goal of ``kind`` for an object seen at ``start_xy``."""
    if kind == "roll":
        return Roll()
    if kind == "lift":
        return Lift()
    angle = rng.integers(8) * np.pi / 4 if kind == "move" else rng.uniform(-np.pi, np.pi)
    direction = np.array([np.cos(angle), np.sin(angle)])
    if kind == "move":
        return Move(tuple(np.round(direction, 12)), MOVE_DISTANCE)
    return Place(tuple(start_xy + rng.uniform(*PLACE_DISTANCE) * direction), PLACE_TOLERANCE)


# --- training --------------------------------------------------------------------------------------------------
def training_frames(frame: pd.DataFrame, max_per_behavior: int, exclude_type: str | None = None
                    ) -> dict[str, pd.DataFrame]:
    """Each behaviour's rows of a goal-episode frame, at most ``max_per_behavior`` (the first, by episode and step),
    without the objects of ``exclude_type``."""
    if exclude_type is not None:
        frame = frame[frame["type"] != exclude_type]
    frame = frame.sort_values(["episode", "step"])
    return {b: frame[frame["behavior"] == b].head(max_per_behavior) for b in BEHAVIORS}


def fit_models(frames: Mapping[str, pd.DataFrame], random_state: int, n_jobs: int | None = None
               ) -> dict[str, ActionEffectModel]:
    """An effect model per behaviour."""
    return {b: ActionEffectModel(random_state=random_state, n_jobs=n_jobs).fit(model_inputs(f), outcome_table(f))
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
        from affordance_learning.model import AffordanceModel

        models, outcomes, labels = {}, {}, {}
        for b, f in frames.items():
            X, E, _ = learning_data(f, b)
            models[b] = AffordanceModel(n_clusters=n_clusters, relevancy=0.4, random_state=random_state).fit(X, E)
            outcomes[b], labels[b] = outcome_table(f), models[b].labels_
        return cls(models, outcomes, labels)

    def choose(self, features: np.ndarray, goal: Goal, start_xy: np.ndarray) -> tuple[str, float]:
        """The behaviour whose predicted category reached ``goal`` most often in training, and that share."""
        best = ("tap", -1.0)
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
        from affordance_env.goal_env import TapAffordanceGoalEnv

        _worker.env = TapAffordanceGoalEnv(camera_width=camera[0], camera_height=camera[1],
                                           position_range="workspace")
    return _worker.env


def _feasible_from(env, state) -> Callable[[str, np.ndarray], bool]:
    """``feasible(behavior, params)`` of the world in ``state``, whatever the env ran since."""
    def feasible(behavior: str, params: np.ndarray) -> bool:
        env.set_state(state)
        return env.feasible(behavior, params)
    return feasible


def _run(env, state, behavior: str, params: np.ndarray) -> dict[str, Any]:
    env.set_state(state)
    *_, info = env.step({"behavior": behavior, "params": np.asarray(params, dtype=np.float32)})
    return info


def evaluate_single(item: Mapping[str, Any], planner: Planner, som: SomBaseline | None, settings: PlanSettings,
                    camera: tuple[int, int]) -> dict[str, Any] | None:
    """Every policy on one object and goal (``item``: reset ``seed``, ``kind``, ``options``); None if the object was
    not seen at the start."""
    env = _env(camera)
    rng = np.random.default_rng(item["rng"])
    obs, info = env.reset(seed=item["seed"], options=item.get("options"))
    if not info["visible"]:
        return None
    start = np.asarray(obs["achieved_goal"], dtype=np.float64)
    features = np.asarray(obs["observation"]["features"], dtype=np.float64)
    goal = draw_goal(item["kind"], start, rng)
    state = env.get_state()

    feasible = _feasible_from(env, state)

    executed: list[tuple[float, bool]] = []  # (model P, reached) of every action run: the calibration's data

    def act(behavior: str, params: np.ndarray) -> tuple[bool, dict[str, Any]]:
        info = _run(env, state, behavior, params)
        ok = reached(goal, info)
        x = np.hstack([features, params])[None]
        executed.append((float(planner.models[behavior].goal_probability(x, goal, start)[0]), ok))
        return ok, info

    record: dict[str, Any] = {"kind": item["kind"], "type": info["object"]["type"], "goal": goal.to_dict(),
                              "item": dict(item)}
    choice = planner.choose(features, goal, start, feasible=feasible)
    record["planner"], record["planner_p"], record["planner_behavior"] = False, choice.probability, choice.behavior
    if choice.behavior:
        record["planner"], done = act(choice.behavior, choice.params)
        if isinstance(goal, Place):
            end = np.asarray(done["object"]["final_pose"][:2])
            record["placement_error"] = float(np.linalg.norm(end - np.asarray(goal.target_xy)))
    record["random"] = act(BEHAVIORS[int(rng.integers(4))], rng.uniform(-1, 1, 3))[0]
    record["canonical"] = {b: act(b, np.zeros(3))[0] for b in BEHAVIORS}
    pick = Planner(planner.models, n_candidates=1, threshold=planner.threshold).choose(features, goal, start,
                                                                                        feasible=feasible)
    record["canonical_choice"] = bool(pick.behavior and record["canonical"][pick.behavior])
    if som is not None:
        record["som_categories"] = record["canonical"][som.choose(features, goal, start)[0]]
    oracle = any(record["canonical"].values()) or record["planner"]
    candidates = candidate_params(settings.oracle_candidates + 1, item["seed"] % 2**31)[1:]
    for b in BEHAVIORS:
        for params in candidates:
            if oracle:
                break
            if feasible(b, params):
                oracle = act(b, params)[0]
    record["oracle"] = bool(oracle)
    record["executed"] = executed
    return record


def evaluate_planner(record: Mapping[str, Any], planner: Planner, camera: tuple[int, int]) -> bool:
    """Whether ``planner`` reaches the goal of an evaluated ``record`` from the same start (the same reset)."""
    env = _env(camera)
    obs, _ = env.reset(seed=record["item"]["seed"], options=record["item"].get("options"))
    goal = goal_from_dict(record["goal"])
    start = np.asarray(obs["achieved_goal"], dtype=np.float64)
    state = env.get_state()

    feasible = _feasible_from(env, state)

    choice = planner.choose(obs["observation"]["features"], goal, start, feasible=feasible)
    return bool(choice.behavior) and reached(goal, _run(env, state, choice.behavior, choice.params))


def _direction_heuristic(start: np.ndarray, target: np.ndarray) -> str:
    """The behaviour that moves an object the way the target lies: push away (-x), tap to -y, tap back to +y."""
    d = target - start
    if -d[0] > abs(d[1]):
        return "push"
    return "tap" if d[1] < 0 else "tap_back"


def evaluate_episode(item: Mapping[str, Any], planner: Planner, policy: str, camera: tuple[int, int],
                     frames: list | None = None) -> dict[str, Any]:
    """One multi-step episode of ``policy`` from reset seed ``item["seed"]``: reached, interactions, reach
    failures, the final distance [m]."""
    from affordance_env.registration import GOAL_MAX_EPISODE_STEPS
    from affordance_env.workspace import in_workspace

    env = _env(camera)
    rng = np.random.default_rng(item["rng"])
    obs, info = env.reset(seed=item["seed"])
    tolerance = env.goal_tolerance
    steps, failures, success, gave_up = 0, [], False, False
    distance = initial = float(info["distance"])
    start_xy, target_xy = (np.asarray(obs[key], dtype=float).tolist() for key in ("achieved_goal", "desired_goal"))
    for step in range(GOAL_MAX_EPISODE_STEPS):
        start, target = obs["achieved_goal"], obs["desired_goal"]
        if policy == "planner":
            choice = planner.toward(obs["observation"]["features"], start, target, tolerance,
                                    feasible=lambda b, p: env.feasible(b, p),
                                    steps_left=GOAL_MAX_EPISODE_STEPS - step, reachable=in_workspace)
            if choice.behavior is None:  # no candidate the arms reach: stop rather than run a failing one
                gave_up = True
                break
            behavior, params = choice.behavior, choice.params
        elif policy == "direction":
            behavior, params = _direction_heuristic(start, target), np.zeros(3)
        else:
            behavior, params = BEHAVIORS[int(rng.integers(4))], rng.uniform(-1, 1, 3)
        obs, _, terminated, _, info = env.step({"behavior": behavior, "params": np.asarray(params, np.float32)})
        steps += 1
        if info["failure"] and info["failure"].split(":")[0] in ("ik", "reach"):
            failures.append(info["failure"])
        distance = float(info["distance"])
        if frames is not None:
            frames.append((f"{behavior}: {100 * distance:.1f} cm to go", env.render()))
        if terminated:
            success = bool(info["is_success"])
            break
    return {"policy": policy, "success": success, "steps": steps, "reach_failures": len(failures), "failures": failures,
            "final_distance": distance, "gave_up": gave_up, "type": info["object"]["type"],
            "initial_distance": initial, "start_xy": start_xy, "target_xy": target_xy, "tolerance": tolerance}


#: The directions of :func:`step_reach`: world +x (towards the robot), -x (away), +y (to its left), -y.
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
    for shape in SHAPES:
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
    """Wilson 95 % interval of a share (:func:`~affordance_learning.metrics.wilson_interval`); (0, 1) for 0 of 0."""
    from affordance_learning.metrics import wilson_interval

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


def summarize(records: Sequence[Mapping[str, Any]], policies: Sequence[str]) -> dict[str, Any]:
    """Success, success on feasible goals (those the oracle reached) and n, per policy, with Wilson intervals."""
    feasible = np.array([r["oracle"] for r in records], dtype=bool)
    out = {}
    for policy in policies:
        values = np.array([bool(r.get(policy, False)) for r in records], dtype=bool)
        n, k = len(values), int(values.sum())
        nf, kf = int(feasible.sum()), int(values[feasible].sum())
        out[policy] = {"success": k / n if n else None, "success_ci": wilson(k, n),
                       "success_feasible": kf / nf if nf else None, "success_feasible_ci": wilson(kf, nf), "n": n,
                       "n_feasible": nf}
    return out


def best_fixed(records: list[dict[str, Any]]) -> dict[str, str]:
    """Per goal kind, the behaviour whose canonical action reached it most often; sets ``best_fixed`` in each
    record."""
    choice = {}
    for kind in GOAL_KINDS:
        rows = [r for r in records if r["kind"] == kind]
        if rows:
            choice[kind] = max(BEHAVIORS, key=lambda b: sum(r["canonical"][b] for r in rows))
    for r in records:
        r["best_fixed"] = r["canonical"][choice[r["kind"]]]
    return choice


# --- the run ---------------------------------------------------------------------------------------------------
def _items(seed: int, part: int, n: int, options: Callable[[int], dict | None] = lambda i: None) -> list[dict]:
    items = []
    for i in range(n):
        ss = np.random.SeedSequence([seed, EVAL_STREAM, part, i])
        env_seed, rng_seed = (int(v) for v in ss.generate_state(2))
        items.append({"seed": env_seed, "rng": rng_seed, "kind": GOAL_KINDS[i % len(GOAL_KINDS)],
                      "options": options(i)})
    return items


def _parallel(function, items: list, workers: int, **kwargs) -> list:
    from joblib import Parallel, delayed

    chunks = [items[i::workers] for i in range(workers)]
    if workers == 1:
        results = [[function(item, **kwargs) for item in chunks[0]]]
    else:
        results = Parallel(n_jobs=workers)(delayed(_chunk)(function, chunk, kwargs) for chunk in chunks)
    merged = [None] * len(items)
    for w, chunk_results in enumerate(results):
        for j, r in enumerate(chunk_results):
            merged[w + j * workers] = r
    return merged


def _chunk(function, chunk: list, kwargs: dict) -> list:
    return [function(item, **kwargs) for item in chunk]


def run_plan(out: str | os.PathLike, seed: int = 0, workers: int = 2, settings: PlanSettings | None = None,
             camera: tuple[int, int] = (160, 120), say: Callable[[str], None] = print) -> dict[str, Any]:
    """Run the whole experiment into ``out`` (``dataset/``, ``results.json``); returns the results."""
    from affordance_env.dataset import collect, load_dataset
    from affordance_env.goal_env import TapAffordanceGoalEnv  # noqa: F401  (fails early without the simulator)
    from affordance_env.registration import GOAL_MAX_EPISODE_STEPS

    settings = settings or PlanSettings()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    timings: dict[str, float] = {}
    start = time.perf_counter()
    say(f"[1/5] collecting {settings.episodes} goal episodes with random actions into {out / 'dataset'}")
    collect(out / "dataset", settings.episodes, seed=seed, workers=workers, action="random",
            env_id=GOAL_ENV_ID,
            env_options={"position_range": "workspace", "camera_width": camera[0], "camera_height": camera[1]},
            max_failure_share=1.0, chunk_size=25)
    frame = load_dataset(out / "dataset")
    frames = training_frames(frame, settings.max_per_behavior)
    timings["collect"] = time.perf_counter() - start
    say("      " + ", ".join(f"{b} {len(f)}" for b, f in frames.items()) + " interactions for training")

    t = time.perf_counter()
    models = fit_models(frames, seed, n_jobs=workers)
    planner = Planner(models, n_candidates=settings.candidates, threshold=settings.threshold, random_state=seed)
    som = SomBaseline.fit(frames, settings.som_clusters, seed)
    timings["fit"] = time.perf_counter() - t
    say(f"[2/5] fitted the effect models and the paper's categories ({timings['fit']:.1f} s)")

    t = time.perf_counter()
    items = _items(seed, 0, settings.goals)
    records = [r for r in _parallel(evaluate_single, items, workers, planner=planner, som=som,
                                    settings=settings, camera=camera) if r is not None]
    fixed_choice = best_fixed(records)
    timings["single_step"] = time.perf_counter() - t
    single = summarize(records, POLICIES)
    say(f"[3/5] single step on {len(records)} held-out objects ({timings['single_step']:.0f} s): "
        + ", ".join(f"{p} {share_text(single[p]['success'], single[p]['n'], single[p]['success_ci'])}"
                    for p in POLICIES)
        + f"; {single['oracle']['n_feasible']} goals feasible")

    t = time.perf_counter()
    loso: dict[str, Any] = {}
    for shape in SHAPES:
        shape_records = [dict(r) for r in records if r["type"] == shape]
        shape_planner = Planner(fit_models(training_frames(frame, settings.max_per_behavior, exclude_type=shape),
                                           seed, n_jobs=workers),
                                n_candidates=settings.candidates, threshold=settings.threshold, random_state=seed)
        outcomes = _parallel(evaluate_planner, shape_records, workers, planner=shape_planner, camera=camera)
        for r, ok in zip(shape_records, outcomes, strict=True):
            r["planner"] = ok
        loso[shape] = summarize(shape_records, ("planner", "best_fixed", "random", "oracle"))
    timings["leave_one_shape_out"] = time.perf_counter() - t
    say(f"[4/5] leaving each shape out ({timings['leave_one_shape_out']:.0f} s): "
        + ", ".join(f"{s} " + share_text(loso[s]["planner"]["success_feasible"], loso[s]["planner"]["n_feasible"],
                                         loso[s]["planner"]["success_feasible_ci"], "feasible") for s in SHAPES))

    t = time.perf_counter()
    multi_items = _items(seed, 9, settings.multi_episodes)
    multi: dict[str, Any] = {}
    for policy in MULTI_POLICIES:
        episodes = _parallel(evaluate_episode, multi_items, workers, planner=planner, policy=policy,
                             camera=camera)
        if policy == "planner":
            planner_episodes = episodes
        n = len(episodes)
        k = sum(e["success"] for e in episodes)
        interactions = sum(e["steps"] for e in episodes)
        multi[policy] = {"success": k / n if n else None, "success_ci": wilson(k, n), "n": n,
                         "reach_failures": sum(e["reach_failures"] for e in episodes) / max(interactions, 1),
                         "interactions": interactions, "gave_up": sum(e["gave_up"] for e in episodes),
                         "median_final_distance_m": float(np.median([e["final_distance"] for e in episodes]))}
    timings["multi_step"] = time.perf_counter() - t
    say(f"[5/5] multi-step on {settings.multi_episodes} episodes ({timings['multi_step']:.0f} s): "
        + ", ".join(f"{p} {share_text(multi[p]['success'], multi[p]['n'], multi[p]['success_ci'])}"
                    for p in MULTI_POLICIES))

    multi["planner"]["by_type"] = {
        shape: {"n": len(eps), "success": sum(e["success"] for e in eps) / len(eps)}
        for shape in SHAPES if (eps := [e for e in planner_episodes if e["type"] == shape])}
    reach, tolerance = step_reach(frame), planner_episodes[0]["tolerance"]  # the goal env's
    multi["step_reach_p90_m"], multi["tolerance_m"], multi["max_interactions"] = (reach, tolerance,
                                                                                  GOAL_MAX_EPISODE_STEPS)
    multi["planner"]["episodes"] = [
        {**{k: e[k] for k in ("type", "start_xy", "target_xy", "initial_distance", "final_distance", "steps",
                              "success", "gave_up", "reach_failures", "failures")},
         "within_reach": e["type"] in reach and within_reach(e["start_xy"], e["target_xy"], reach[e["type"]],
                                                             tolerance, GOAL_MAX_EPISODE_STEPS)}
        for e in planner_episodes]
    inside = [e for e in multi["planner"]["episodes"] if e["within_reach"]]
    multi["planner"]["within_reach"] = {"n": len(inside), "success": (sum(e["success"] for e in inside) / len(inside)
                                                                      if inside else None)}
    executed = [e for r in records for e in r["executed"]]
    placement = [r["placement_error"] for r in records if "placement_error" in r]
    oracle = single["oracle"]["success"] or 0.0
    results = {
        "format": "tap-affordance-plan-results", "version": 1, "seed": seed, "settings": asdict(settings),
        "units": {"fractions": "[0, 1]", "distances": "m", "times": "s"},
        "training": {b: len(f) for b, f in frames.items()},
        "single_step": single,
        "single_step_by_goal": {kind: summarize([r for r in records if r["kind"] == kind], POLICIES)
                                for kind in GOAL_KINDS},
        "best_fixed_behavior": fixed_choice,
        "planner_over_oracle": (single["planner"]["success"] / oracle) if oracle else None,
        "leave_one_shape_out": loso,
        "multi_step": multi,
        "placement_error_median_m": float(np.median(placement)) if placement else None,
        "placement_error_n": len(placement),  # the place goals the planner acted on: the median's n
        "calibration": calibration([p for p, _ in executed], [y for _, y in executed]),
        "timings_s": {**timings, "total": time.perf_counter() - start},
        "goals": [{k: r[k] for k in ("kind", "type", "goal", "planner", "planner_p", "planner_behavior", "oracle")}
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
    from affordance_env.goal_env import TapAffordanceGoalEnv

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
        _, info = env.reset(seed=item["seed"])
        start = [(f"start: {100 * info['distance']:.1f} cm to go", env.render())]
        evaluate_episode(item, planner, "planner", (160, 120), frames=pictures)
        return start + pictures
    finally:
        _worker.env = previous
        env.close()


__all__ = ["PlanSettings", "run_plan", "record_episode", "measured_outcome", "reached", "calibration", "wilson",
           "share_text"]
