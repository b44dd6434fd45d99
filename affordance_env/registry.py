"""The one place the package's names are defined: the environments' ids, and the behaviours with the arm that
does each and the module that defines it. The environments, the dataset code, the command line and the learning
package read them here; adding a behaviour is one module of :mod:`affordance_env.behaviors` that defines it and one
line in :data:`REGISTERED`.

It imports nothing heavy, so that a command can check a name before it loads the simulator.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

from affordance_env.exceptions import InvalidValueError

#: One interaction per episode (Gymnasium's registration: :mod:`affordance_env.registration`).
ENV_ID = "TapAffordance-v2"
#: Goal episodes of several interactions on one object, with both arms.
GOAL_ENV_ID = "TapAffordanceGoal-v2"
#: The environments, as datasets record them.
ENV_IDS: tuple[str, ...] = (ENV_ID, GOAL_ENV_ID)

#: The arms, as the behaviours name them.
ARMS = ("right", "left")


@dataclass(frozen=True)
class Registered:
    """A behaviour, as the registry lists it.

    Attributes:
        arm: The arm that does it, one of :data:`ARMS`.
        module: The module of :mod:`affordance_env.behaviors` that defines it (in its ``BEHAVIORS``).
    """

    arm: str
    module: str


#: The behaviours, in the order of the goal env's ``behavior`` index.
REGISTERED: Mapping[str, Registered] = MappingProxyType({
    "tap": Registered("right", "stroke"),
    "tap_back": Registered("right", "stroke"),
    "push": Registered("right", "stroke"),
    "grasp": Registered("left", "grasp"),
    "draw": Registered("right", "draw"),
})
#: The arm that does each behaviour.
BEHAVIOR_ARMS: Mapping[str, str] = MappingProxyType({name: entry.arm for name, entry in REGISTERED.items()})
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


__all__ = ["ARMS", "BEHAVIOR_ARMS", "BEHAVIOR_NAMES", "ENV_ID", "ENV_IDS", "GOAL_ENV_ID", "REGISTERED", "Registered",
           "check_behavior_name", "check_env_id"]
