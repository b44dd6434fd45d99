"""TapAffordance environment: an iCub in MuJoCo taps objects and sees the effect through a range camera.

``import affordance_env`` registers ``TapAffordance-v2`` (one interaction of one behaviour per episode) and
``TapAffordanceGoal-v2`` (bring the object to a goal, choosing among the five behaviours) with Gymnasium::

    import gymnasium as gym
    import affordance_env  # noqa: F401

    env = gym.make("TapAffordance-v2")
    goal_env = gym.make("TapAffordanceGoal-v2")

or, without the import, ``gym.make("affordance_env:TapAffordance-v2")``.
"""

import importlib
import importlib.metadata as _metadata
import importlib.util

from affordance_env.features import FEATURE_GROUPS, FEATURE_NAMES
from affordance_env.objects import OBJECT_TYPES
from affordance_env.registration import register_envs
from affordance_env.robot_model import ACTIVE_JOINTS

register_envs()

try:  # the version has one source, the package's metadata (pyproject.toml)
    __version__ = _metadata.version("tap-affordance")
except _metadata.PackageNotFoundError:  # a source tree that was never installed
    __version__ = "0+unknown"


def __getattr__(name: str):
    # The dataset reader needs pandas and pyarrow; an env alone does not, so they are imported when first asked.
    if name == "load_dataset":
        from affordance_env.dataset.load import load_dataset

        return load_dataset
    # A submodule (affordance_env.tap_env, affordance_env.workspace, ...) is loaded when first named, so that
    # ``help(affordance_env.tap_env.TapAffordanceEnv)`` works after ``import affordance_env`` alone.
    if not name.startswith("_") and importlib.util.find_spec(f"{__name__}.{name}") is not None:
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

__all__ = [
    "ACTIVE_JOINTS",
    "FEATURE_GROUPS",
    "FEATURE_NAMES",
    "OBJECT_TYPES",
    "load_dataset",
    "register_envs",
    "__version__",
]
