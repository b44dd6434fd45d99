"""Gymnasium registration of the TapAffordance environments (their ids: :mod:`affordance_env.registry`)."""

from __future__ import annotations

from typing import Any

import gymnasium as gym

from affordance_env.exceptions import InvalidValueError
from affordance_env.registry import ENV_ID, GOAL_ENV_ID
from affordance_env.values import is_integer

#: Interactions per episode of the goal env, after which it is truncated.
GOAL_MAX_EPISODE_STEPS = 5


def make_tap_env(**kwargs: Any) -> gym.Env:
    """``TapAffordanceEnv(**kwargs)``: the entry point of ``TapAffordance-v2``.

    A function, not the class, so that ``gym.make`` hands the env every ``render_mode`` as asked: with the class,
    it reads the class's render modes and turns ``"human"`` into the ``HumanRendering`` wrapper (which fails
    without pygame); this way the env refuses a mode it does not have, naming the ones it has.
    """
    from affordance_env.tap_env import TapAffordanceEnv

    return TapAffordanceEnv(**kwargs)


def make_tap_vector_env(num_envs: int = 1, **kwargs: Any) -> gym.vector.VectorEnv:
    """``gym.make_vec("TapAffordance-v2", num_envs)``: environments side by side in this process, each reset in the
    same vector step that ends its episode (Gymnasium's ``AutoresetMode.SAME_STEP``, which the env declares in its
    metadata), so that every vector step is an interaction. With Gymnasium's default, the next step, every
    second step of a one-interaction episode would be a reset with reward 0. ``vectorization_mode="async"``
    with ``vector_kwargs={"autoreset_mode": gym.vector.AutoresetMode.SAME_STEP}`` gives worker processes."""
    if not is_integer(num_envs) or num_envs < 1:
        raise InvalidValueError(f"num_envs must be an integer >= 1, got {num_envs!r}.")
    kwargs.pop("max_episode_steps", None)  # one interaction per episode: the env terminates it
    return gym.vector.SyncVectorEnv([lambda: make_tap_env(**kwargs) for _ in range(num_envs)],
                                    autoreset_mode=gym.vector.AutoresetMode.SAME_STEP)


def make_goal_env(**kwargs: Any) -> gym.Env:
    """``TapAffordanceGoalEnv(**kwargs)``: the entry point of ``TapAffordanceGoal-v2`` (a function for the reason
    given at :func:`make_tap_env`)."""
    from affordance_env.goal_env import TapAffordanceGoalEnv

    return TapAffordanceGoalEnv(**kwargs)


def make_goal_vector_env(num_envs: int = 1, max_episode_steps: int = GOAL_MAX_EPISODE_STEPS,
                         **kwargs: Any) -> gym.vector.VectorEnv:
    """``gym.make_vec("TapAffordanceGoal-v2", num_envs)``: environments side by side in this process, each
    truncated after ``max_episode_steps`` interactions and reset in the same vector step that ends its episode
    (``AutoresetMode.SAME_STEP``, declared in the env's metadata; the episode's last observation and info are in
    ``infos["final_obs"]`` and ``infos["final_info"]``), so that every vector step is an interaction."""
    if not is_integer(num_envs) or num_envs < 1:
        raise InvalidValueError(f"num_envs must be an integer >= 1, got {num_envs!r}.")

    def make() -> gym.Env:
        return gym.wrappers.TimeLimit(make_goal_env(**kwargs), max_episode_steps)

    return gym.vector.SyncVectorEnv([make for _ in range(num_envs)], autoreset_mode=gym.vector.AutoresetMode.SAME_STEP)


def register_envs() -> None:
    """Register ``TapAffordance-v2`` and ``TapAffordanceGoal-v2`` (idempotent)."""
    if GOAL_ENV_ID not in gym.registry:
        gym.register(id=GOAL_ENV_ID, entry_point="affordance_env.registration:make_goal_env",
                     vector_entry_point="affordance_env.registration:make_goal_vector_env",
                     max_episode_steps=GOAL_MAX_EPISODE_STEPS)
    if ENV_ID not in gym.registry:
        gym.register(id=ENV_ID, entry_point="affordance_env.registration:make_tap_env",
                     vector_entry_point="affordance_env.registration:make_tap_vector_env")
