"""TapAffordance environment: an iCub in MuJoCo taps objects and sees the effect through a range camera.

``import affordance_env`` registers ``TapAffordance-v0`` with Gymnasium::

    import gymnasium as gym
    import affordance_env  # noqa: F401

    env = gym.make("TapAffordance-v0")

or, without the import, ``gym.make("affordance_env:TapAffordance-v0")``.
"""

from affordance_env.rendering import select_gl_backend

select_gl_backend()  # before anything imports mujoco: headless RGB rendering needs EGL or OSMesa

from affordance_env.dataset import load_dataset  # noqa: E402
from affordance_env.features import FEATURE_GROUPS, FEATURE_NAMES  # noqa: E402
from affordance_env.objects import OBJECT_TYPES  # noqa: E402
from affordance_env.registration import register_envs  # noqa: E402
from affordance_env.robot_model import ACTIVE_JOINTS  # noqa: E402

register_envs()

__version__ = "0.2.0"

__all__ = [
    "ACTIVE_JOINTS",
    "FEATURE_GROUPS",
    "FEATURE_NAMES",
    "OBJECT_TYPES",
    "load_dataset",
    "register_envs",
    "__version__",
]
