"""Gymnasium registration of the TapAffordance environments (the one place ids are defined)."""

from __future__ import annotations

from typing import Any

import gymnasium as gym

ENV_ID = "TapAffordance-v1"


def make_tap_env(**kwargs: Any) -> gym.Env:
    """``TapAffordanceEnv(**kwargs)``: the entry point of ``TapAffordance-v1``.

    A function, not the class, so that ``gym.make`` hands the env every ``render_mode`` as asked: with the class,
    it reads the class's render modes and turns ``"human"`` into the ``HumanRendering`` wrapper (which fails
    without pygame); this way the env refuses a mode it does not have, naming the ones it has.
    """
    from affordance_env.tap_env import TapAffordanceEnv

    return TapAffordanceEnv(**kwargs)


def register_envs() -> None:
    """Register ``TapAffordance-v1`` (idempotent)."""
    if ENV_ID not in gym.registry:
        gym.register(id=ENV_ID, entry_point="affordance_env.registration:make_tap_env")
