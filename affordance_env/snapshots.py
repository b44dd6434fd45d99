"""Snapshots of a wrapped goal env that keep its time limit: trying actions from a snapshot costs no steps.

``gym.make("TapAffordanceGoal-v2")`` wraps the env in Gymnasium's ``TimeLimit``, which counts the steps since the
reset in the wrapper (``_elapsed_steps``), out of the env's reach: ``env.unwrapped.set_state(state)`` puts the
world and the episode back but not that count, so each action tried from one snapshot would bring the truncation
one step nearer. :func:`set_state` restores the env and puts every ``TimeLimit`` around it back to the steps the
snapshot was taken at (``state.steps``); :func:`get_state` is ``env.unwrapped.get_state()``, for symmetry::

    env = gym.make("TapAffordanceGoal-v2")
    env.reset(seed=0)
    state = snapshots.get_state(env)
    for action in candidates:
        snapshots.set_state(env, state)  # the world, the episode and the TimeLimit's count
        obs, reward, terminated, truncated, info = env.step(action)

(A wrapper of its own over the ``TimeLimit`` cannot do this for ``gym.make``: Gymnasium refuses a registered
wrapper on an env with a vector entry point, which this one has.)
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym


def get_state(env: gym.Env) -> Any:
    """The snapshot of the env inside ``env`` (its wrappers, if any): ``env.unwrapped.get_state()``, which records
    the steps since the reset."""
    return env.unwrapped.get_state()


def set_state(env: gym.Env, state: Any) -> None:
    """Put the env inside ``env`` back as ``state`` has it (``env.unwrapped.set_state(state)``) and every
    ``TimeLimit`` wrapper of ``env`` to the steps the snapshot was taken at: the episode is truncated at the
    same step as it would have been from there."""
    env.unwrapped.set_state(state)
    wrapper = env
    while isinstance(wrapper, gym.Wrapper):
        if isinstance(wrapper, gym.wrappers.TimeLimit):
            wrapper._elapsed_steps = int(state.steps)  # TimeLimit keeps its count there, with no setter
        wrapper = wrapper.env


__all__ = ["get_state", "set_state"]
