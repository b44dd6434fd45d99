"""The behaviours the learning side knows, and how each one's success and failure read in figures and reports.

The environment (``affordance_env.behaviors``) defines what a behaviour does and what its ``success`` label
measures; this module only names them for people. The paper learns one model per behaviour ("a separate SOM
and SVM for each behavior"), so every result, report and default model belongs to one of these.
"""

from __future__ import annotations

#: Per behaviour, how its success and its failure read: ``(success, failure)``.
OUTCOME_WORDS: dict[str, tuple[str, str]] = {
    "tap": ("rolled", "did not roll"),
    "grasp": ("lifted and held", "not held"),
    "tap_back": ("rolled", "did not roll"),
    "push": ("moved", "did not move"),
}
#: The behaviours of the environment, in the order reports list them: the paper's two, then the others.
BEHAVIORS: tuple[str, ...] = tuple(OUTCOME_WORDS)
#: How the ``rolled`` label reads: the label of a frame that has no ``success`` column.
ROLLED_WORDS = ("rolled", "did not roll")
#: How the success/fail label of a behaviour this module does not know reads.
GENERIC_WORDS = ("success", "fail")


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
        raise ValueError(f"label must be 'success' or 'rolled', got {label!r}.")
    return OUTCOME_WORDS.get(behavior, GENERIC_WORDS)
