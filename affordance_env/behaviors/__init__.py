"""The robot's behaviours: one module per kind, each with its plan, execution, success test and facts.

- :mod:`~affordance_env.behaviors.stroke`: ``tap``, ``tap_back``, ``push``, a straight line of the right hand
  through the object;
- :mod:`~affordance_env.behaviors.draw`: ``draw``, the right hand reaches behind the object and drags it toward
  the robot;
- :mod:`~affordance_env.behaviors.grasp`: ``grasp``, the fingered left hand takes the object from above, lifts,
  holds and puts it down beside (in the goal env: where its action asks, pick and place).

Each implements :class:`~affordance_env.behaviors.base.Behavior`, the protocol the world runs
(:class:`affordance_env.world.World`). The registry (:data:`affordance_env.registry.REGISTERED`) names every
behaviour, its arm and the module that defines it; :func:`get_behavior` loads that module when a behaviour is
first asked for, so that checking a name or an action (:mod:`~affordance_env.behaviors.action`) loads neither
MuJoCo nor Pinocchio.
"""

from __future__ import annotations

import importlib
from collections.abc import Iterator, Mapping
from typing import TYPE_CHECKING

from affordance_env.behaviors.action import ACTION_DIM, check_action
from affordance_env.behaviors.success import ROLL_THRESHOLD, SUCCESS_RULES, is_success
from affordance_env.registry import REGISTERED, check_behavior_name

if TYPE_CHECKING:
    from affordance_env.behaviors.base import Behavior


def get_behavior(name: str, goal: bool = False) -> Behavior:
    """The behaviour called ``name``, from the module the registry names for it; raises InvalidValueError listing
    the valid names.

    With ``goal``, the behaviour as a world that goes on after it runs it (the goal env), where its module defines
    one (its ``GOAL_BEHAVIORS``): the grasp then puts the object down where its action asks (pick and place).
    """
    module = importlib.import_module(f"{__name__}.{REGISTERED[check_behavior_name(name)].module}")
    if goal and name in getattr(module, "GOAL_BEHAVIORS", {}):
        return module.GOAL_BEHAVIORS[name]
    return module.BEHAVIORS[name]


class _Behaviors(Mapping):
    """Every registered behaviour by name, in the registry's order, each loaded when first asked for."""

    def __getitem__(self, name: str) -> Behavior:
        if name not in REGISTERED:
            raise KeyError(name)
        return get_behavior(name)

    def __contains__(self, name: object) -> bool:  # without loading any behaviour's module
        return name in REGISTERED

    def __iter__(self) -> Iterator[str]:
        return iter(REGISTERED)

    def __len__(self) -> int:
        return len(REGISTERED)


#: Every behaviour's object by name (:func:`get_behavior`), in the registry's order. ``BEHAVIORS`` means this
#: everywhere: a mapping from names to the behaviour objects (each module of this package has one of those it
#: defines); the names alone, and their order, are :data:`affordance_env.registry.BEHAVIOR_NAMES`.
BEHAVIORS: Mapping[str, Behavior] = _Behaviors()

__all__ = ["ACTION_DIM", "BEHAVIORS", "ROLL_THRESHOLD", "SUCCESS_RULES", "check_action", "get_behavior", "is_success"]
