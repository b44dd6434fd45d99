"""The training data of ``affordance plan`` and the effect models fitted on them: goal episodes with random
actions, topped up per behaviour, resumable.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable, Mapping
from pathlib import Path

import pandas as pd

from affordance_env.behaviors import get_behavior
from affordance_env.dataset import MANIFEST, collect, load_dataset, read_manifest
from affordance_env.registry import BEHAVIOR_NAMES, GOAL_ENV_ID
from affordance_learning.planning.effect_model import ActionEffectModel, behavior_model
from affordance_learning.planning.experiment.settings import PlanSettings
from affordance_learning.planning.outcomes import model_inputs, outcome_table


def training_frames(frame: pd.DataFrame, max_per_behavior: int, exclude_type: str | None = None
                    ) -> dict[str, pd.DataFrame]:
    """Each behaviour's rows of a goal-episode frame, at most ``max_per_behavior`` (the first, by episode and step),
    without the objects of ``exclude_type``."""
    if exclude_type is not None:
        frame = frame[frame["type"] != exclude_type]
    frame = frame.sort_values(["episode", "step"])
    return {b: frame[frame["behavior"] == b].head(max_per_behavior) for b in BEHAVIOR_NAMES}


def fit_models(frames: Mapping[str, pd.DataFrame], random_state: int, n_jobs: int | None = None,
               n_estimators: int = 200) -> dict[str, ActionEffectModel]:
    """An effect model per behaviour (:func:`~affordance_learning.planning.effect_model.behavior_model`) of
    ``n_estimators`` trees."""
    return {b: behavior_model(b, random_state=random_state, n_jobs=n_jobs, n_estimators=n_estimators)
            .fit(model_inputs(f), outcome_table(f)) for b, f in frames.items()}


#: Top-up interactions are collected this many times what is missing (some fail, and are not rows) ...
TOP_UP_MARGIN = 1.15


#: ... and numbered from this episode on, after every goal episode.
TOP_UP_EPISODES = 1_000_000


def collect_training(out: Path, settings: PlanSettings, seed: int, workers: int, camera: tuple[int, int],
                     say: Callable[[str], None] = print, timings: dict[str, float] | None = None) -> pd.DataFrame:
    """Goal episodes with random actions in ``out``, extended in rounds until the grasp (every behaviour that only
    the goal env runs as it does) has ``settings.max_per_behavior`` interactions or ``settings.max_episodes``
    episodes were collected; each round asks for as many more episodes as the scarcest such behaviour's share so
    far says it needs (and 5 % more), in whole chunks. A behaviour TapAffordance-v2 runs as the goal env does (the
    strokes, the draw) that is still short is topped up with random interactions of TapAffordance-v2 in the
    scene with both arms, objects over its workspace (in ``out`` beside the goal episodes, named after it): the
    draw, which reaches only objects near the robot, gets a tenth of the goal episodes' interactions. The frame of
    both. ``timings``, if given, gets the seconds of each part: ``collect_goal_episodes`` and
    ``collect_top_up_<behaviour>`` (a resumed part takes only the time to read it)."""
    episodes, chunk = settings.episodes, 25
    if (out / MANIFEST).exists():  # an earlier collection, perhaps extended: resumed as far as it went
        episodes = max(episodes, int(read_manifest(out)["episodes"]))
    camera_options = {"camera_width": camera[0], "camera_height": camera[1]}
    # The behaviours TapAffordance-v2 runs as the goal env does (all but the grasp, which the goal env runs as pick
    # and place): their interactions in its scene with both arms are the goal env's, and cost no goal episode.
    same = [b for b in BEHAVIOR_NAMES if get_behavior(b) is get_behavior(b, goal=True)]
    timings = {} if timings is None else timings
    start = time.perf_counter()
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
    timings["collect_goal_episodes"] = time.perf_counter() - start
    for behavior in same:  # topped up with single interactions over the behaviour's own workspace
        missing = settings.max_per_behavior - counts[behavior]
        if missing <= 0:
            continue
        wanted = math.ceil(missing * TOP_UP_MARGIN / chunk) * chunk
        say(f"      {behavior}: {counts[behavior]} interactions in the goal episodes, {wanted} more of "
            f"TapAffordance-v2 in the same scene")
        start = time.perf_counter()
        collect(top_up_path(out, behavior), wanted, seed=seed, workers=workers, action="random",
                env_options={"behavior": behavior, "two_arms": True, "position_range": "workspace",
                             **camera_options}, max_failure_share=1.0, chunk_size=chunk)
        timings[f"collect_top_up_{behavior}"] = time.perf_counter() - start
    return load_training(out)


def top_up_path(out: Path, behavior: str) -> Path:
    """Where :func:`collect_training` tops up ``behavior``'s interactions of the goal episodes in ``out``."""
    return out.parent / f"{out.name}-{behavior}"


def load_training(out: str | os.PathLike) -> pd.DataFrame:
    """The training frame :func:`collect_training` collected into ``out`` (``affordance plan``'s
    ``OUT/dataset``): its goal episodes, then each behaviour's top-up beside it (each interaction an episode of
    one step, numbered from ``TOP_UP_EPISODES``)."""
    out = Path(out)
    frames = [load_dataset(out)]
    for behavior in BEHAVIOR_NAMES:
        path = top_up_path(out, behavior)
        if (path / MANIFEST).exists():
            extra = load_dataset(path)
            frames.append(extra.assign(episode=extra["episode"] + TOP_UP_EPISODES, step=0))
    return pd.concat(frames, ignore_index=True)
