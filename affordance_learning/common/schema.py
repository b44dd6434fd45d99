"""The dataset schema as the learning package reads it: feature names and groups, the label, the behaviour.

A frame of ``affordance_env.load_dataset`` (or one built like it) holds, for each feature name, the columns
``initial_<name>``, ``final_<name>`` and ``effect_<name>``, the ``behavior`` and the ground truth (``type``,
``size``, ``success``, ...). These functions find them, and say what is missing when they cannot.
"""

from __future__ import annotations

from collections.abc import Sequence

import pandas as pd

from affordance_env.objects import OBJECT_TYPES, ROLLING_TYPES
from affordance_learning.common.exceptions import InvalidValueError

#: The object types (:data:`affordance_env.objects.OBJECT_TYPES`) in the order figures and case studies list them:
#: the rolling ones first, as the paper does.
TYPE_ORDER: tuple[str, ...] = tuple(sorted(OBJECT_TYPES, key=lambda t: t not in ROLLING_TYPES))
#: Feature groups and their sizes in the order of ``FEATURE_NAMES`` (paper, section III.B).
GROUP_SIZES = (("shape", 24), ("size", 18), ("relation", 7))
#: Columns a frame's success/fail label can come from, in order of preference.
LABEL_COLUMNS = ("success", "rolled")


def feature_names(frame: pd.DataFrame) -> list[str]:
    """Names of the features of a dataset frame.

    ``affordance_env.features.FEATURE_NAMES`` when the frame has ``initial_<name>`` and ``effect_<name>``
    for all of them; otherwise every name with both columns, in the frame's column order.
    """
    columns = set(frame.columns)
    try:
        from affordance_env.features import FEATURE_NAMES
    except ImportError:
        FEATURE_NAMES = ()
    if FEATURE_NAMES and all(f"initial_{n}" in columns and f"effect_{n}" in columns for n in FEATURE_NAMES):
        return list(FEATURE_NAMES)
    names = [
        c.removeprefix("initial_") for c in frame.columns if isinstance(c, str) and c.startswith("initial_")
    ]
    if not names:
        raise InvalidValueError(
            "the frame has no initial_<name> columns; expected the dataset schema (initial_, final_, effect_ "
            f"columns per feature), got columns {list(frame.columns)[:8]}..."
        )
    missing = [f"effect_{n}" for n in names if f"effect_{n}" not in columns]
    if missing:
        raise InvalidValueError(f"the frame lacks effect columns {missing[:5]} for its initial_ columns.")
    return names


def feature_groups(names: Sequence[str]) -> list[str]:
    """Group ("shape", "size" or "relation") of every feature name.

    From ``affordance_env.features.FEATURE_GROUPS`` when it knows every name; otherwise, for 49 features, by
    position (the first 24 shape, the next 18 size, the last 7 relation, as in the paper).
    """
    try:
        from affordance_env.features import FEATURE_GROUPS
    except ImportError:
        FEATURE_GROUPS = {}
    if all(n in FEATURE_GROUPS for n in names):
        return [FEATURE_GROUPS[n] for n in names]
    total = sum(size for _, size in GROUP_SIZES)
    if len(names) != total:
        unknown = [n for n in names if n not in FEATURE_GROUPS]
        raise InvalidValueError(
            f"cannot tell the group of features {unknown[:5]}: they are not in affordance_env's "
            f"FEATURE_GROUPS and there are {len(names)} features, not the paper's {total} (24 shape, "
            "18 size, 7 relation)."
        )
    return [group for group, size in GROUP_SIZES for _ in range(size)]


def label_column(frame: pd.DataFrame) -> str:
    """The column of a frame that holds its success/fail labels: ``success``, else ``rolled`` (frames made
    before the label existed); raises ValueError when it has neither."""
    for column in LABEL_COLUMNS:
        if column in frame.columns:
            return column
    raise InvalidValueError(
        "the frame has no 'success' column (nor 'rolled', the tap's label in frames without it): the "
        "success/fail labels the protocol evaluates against."
    )


def frame_behavior(frame: pd.DataFrame, behavior: str | None = None) -> str:
    """The one behaviour of a frame's interactions, from its ``behavior`` column.

    Args:
        frame: A dataset frame.
        behavior: The behaviour the caller expects; needed when the frame has no ``behavior`` column, and
            checked against it when it has one.

    Raises:
        ValueError: The frame mixes behaviours, holds another behaviour than ``behavior``, or has no
            ``behavior`` column and ``behavior`` is None.
    """
    if behavior is not None and (not isinstance(behavior, str) or not behavior):
        raise InvalidValueError(f"behavior must be a behaviour name such as 'tap', got {behavior!r}.")
    if "behavior" not in frame.columns:
        if behavior is None:
            raise InvalidValueError(
                "the frame has no 'behavior' column; pass the behaviour of its interactions (behavior='tap', "
                "'grasp', ...)."
            )
        return behavior
    found = sorted(pd.unique(frame["behavior"].astype(str)).tolist())
    if len(found) != 1:
        raise InvalidValueError(
            f"the frame mixes the behaviours {found}; the model learns one behaviour at a time (a separate "
            "map and SVM per behaviour): select one, e.g. frame[frame['behavior'] == 'tap']."
        )
    if behavior is not None and found[0] != behavior:
        raise InvalidValueError(f"the frame holds {found[0]!r} interactions, not {behavior!r} ones.")
    return found[0]
