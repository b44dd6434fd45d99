"""The one place the package's names are defined: the environments' ids, and the behaviours with the arm that
does each. The environments, the dataset code, the command line and the learning package read them here; adding a
behaviour adds its line to :data:`BEHAVIOR_ARMS` (and its module to :mod:`affordance_env.behaviors`).

It imports nothing heavy, so that a command can check a name before it loads the simulator.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

from affordance_env.exceptions import InvalidValueError

#: One interaction per episode (Gymnasium's registration: :mod:`affordance_env.registration`).
ENV_ID = "TapAffordance-v1"
#: Goal episodes of several interactions on one object, with both arms.
GOAL_ENV_ID = "TapAffordanceGoal-v0"
#: The environments, as datasets record them.
ENV_IDS: tuple[str, ...] = (ENV_ID, GOAL_ENV_ID)

#: The behaviours, in the order of the goal env's ``behavior`` index, and the arm that does each.
BEHAVIOR_ARMS: Mapping[str, str] = MappingProxyType({"tap": "right", "tap_back": "right", "push": "right",
                                                     "grasp": "left"})
#: The behaviours' names, in that order.
BEHAVIOR_NAMES: tuple[str, ...] = tuple(BEHAVIOR_ARMS)


def check_behavior_name(name: object) -> str:
    """``name`` if it names a behaviour; raises InvalidValueError listing the behaviours otherwise."""
    if not isinstance(name, str) or name not in BEHAVIOR_ARMS:
        raise InvalidValueError(f"Unknown behavior {name!r}. Valid behaviors: {', '.join(BEHAVIOR_NAMES)}.")
    return name


def check_env_id(env_id: object) -> str:
    """``env_id`` if it names one of the package's environments; raises InvalidValueError otherwise."""
    if env_id not in ENV_IDS:
        raise InvalidValueError(f"Unknown environment {env_id!r}. Valid ids: {', '.join(ENV_IDS)}.")
    return env_id  # type: ignore[return-value]


__all__ = ["BEHAVIOR_ARMS", "BEHAVIOR_NAMES", "ENV_ID", "ENV_IDS", "GOAL_ENV_ID", "check_behavior_name",
           "check_env_id"]
