"""Gymnasium registration of the TapAffordance environments (the one place ids are defined)."""

from __future__ import annotations

import gymnasium as gym

ENV_ID = "TapAffordance-v0"


def register_envs() -> None:
    """Register ``TapAffordance-v0`` (idempotent)."""
    if ENV_ID not in gym.registry:
        gym.register(id=ENV_ID, entry_point="affordance_env.tap_env:TapAffordanceEnv")
