"""How each behaviour's success and failure read in figures and reports.

The behaviours' names and their order are :data:`affordance_env.registry.BEHAVIOR_NAMES`; the environment
(``affordance_env.behaviors``) defines what a behaviour does and what its ``success`` label measures; this module
only words them for people. The paper learns one model per behaviour ("a separate SOM
and SVM for each behavior"), so every result, report and default model belongs to one of these.
"""

from __future__ import annotations

from collections.abc import Iterable

from affordance_env.registry import check_behavior_name
from affordance_learning.common.exceptions import InvalidValueError

#: Per behaviour, how its success and its failure read: ``(success, failure)``.
OUTCOME_WORDS: dict[str, tuple[str, str]] = {
    "tap": ("rolled", "did not roll"),
    "tap_back": ("rolled", "did not roll"),
    "push": ("moved", "did not move"),
    "grasp": ("lifted and held", "not held"),
    "draw": ("moved", "did not move"),
}
#: How the ``rolled`` label reads: the label of a frame that has no ``success`` column.
ROLLED_WORDS = ("rolled", "did not roll")
#: The behaviours whose success is ``rolled``: only their frames may stand in ``rolled`` for a missing ``success``.
ROLLED_IS_SUCCESS = ("tap", "tap_back")
#: How the success/fail label of a behaviour this module does not know reads.
GENERIC_WORDS = ("success", "fail")


def check_behavior(behavior: str) -> str:
    """``behavior`` if it is one of :data:`affordance_env.registry.BEHAVIOR_NAMES`; raises InvalidValueError naming
    the valid ones otherwise."""
    return check_behavior_name(behavior)


def check_env_offers(behaviors: Iterable[str], hint: str = "") -> list[str]:
    """The behaviours, each checked to be offered by the installed environment (whose interactions can then be
    collected); raises ValueError otherwise, before any work, with ``hint`` appended to the message.

    The environment's behaviours are read from ``affordance_env.behaviors.BEHAVIORS`` (the behaviour objects it
    defines, by name) when called.
    """
    import affordance_env.behaviors as env_behaviors

    behaviors = list(behaviors)
    if not behaviors or any(not isinstance(b, str) for b in behaviors):
        raise InvalidValueError(f"behaviors must be one or more behaviour names, got {behaviors!r}.")
    if len(set(behaviors)) != len(behaviors):
        raise InvalidValueError(f"behaviors must not repeat a name, got {behaviors!r}.")
    offered = list(env_behaviors.BEHAVIORS)
    for behavior in behaviors:
        if behavior not in offered:
            raise InvalidValueError(
                f"the environment has no {behavior!r} behaviour (it offers {', '.join(offered)}), so its "
                f"interactions cannot be collected: install an affordance_env that has it{hint}."
            )
    return behaviors


def outcome_words(behavior: str, label: str = "success") -> tuple[str, str]:
    """How a success and a failure of ``behavior`` read, when evaluated against the frame's ``label`` column.

    Args:
        behavior: A behaviour name (``"tap"``, ``"grasp"``, ...); one not in :data:`OUTCOME_WORDS` reads
            "success" / "fail".
        label: The column the outcomes come from: ``"success"``, or ``"rolled"`` (a frame without
            ``success``), which reads "rolled" / "did not roll" whatever the behaviour.
    """
    if label == "rolled":
        return ROLLED_WORDS
    if label != "success":
        raise InvalidValueError(f"label must be 'success' or 'rolled', got {label!r}.")
    return OUTCOME_WORDS.get(behavior, GENERIC_WORDS)
