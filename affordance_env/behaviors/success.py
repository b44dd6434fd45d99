"""The strokes' success labels, from what the object did: pure functions of the ground truth.

A stroke behaviour names its rule (:attr:`~affordance_env.behaviors.stroke.StrokeBehavior.success_rule`); the
dataset reader derives the label of older datasets, which did not store it, by the same rule. The grasp's label
is measured while it holds the object (:func:`affordance_env.outcome.grasp_success`).
"""

from __future__ import annotations

import numpy as np

from affordance_env.exceptions import InvalidValueError

#: Default distance [m] beyond which an interaction succeeds (the env's ``roll_threshold``): see :func:`is_success`.
ROLL_THRESHOLD = 0.03
#: What a stroke's success is: ``"rolled"``, the object rolled more than the threshold (the paper's label for the
#: tap); ``"moved"``, its centre travelled more than the threshold on the table.
SUCCESS_RULES = ("rolled", "moved")


def is_success(rule: str, rolled: bool | np.ndarray, displacement: float | np.ndarray,
               threshold: float = ROLL_THRESHOLD) -> bool | np.ndarray:
    """The success/fail label of interactions by a behaviour whose success rule is ``rule``.

    ``"rolled"`` (tap, tap_back: the paper's label): ``rolled``, the object rolled more than ``threshold``;
    ``"moved"`` (push): ``displacement > threshold``, the object's centre travelled more than ``threshold`` [m] on
    the table, rolling or sliding. Scalars give a bool, arrays an array.
    """
    if rule == "rolled":
        label = np.asarray(rolled, dtype=bool)
    elif rule == "moved":
        label = np.asarray(displacement, dtype=np.float64) > threshold
    else:
        raise InvalidValueError(f"rule must be one of {SUCCESS_RULES}, got {rule!r}.")
    return bool(label) if label.ndim == 0 else label
