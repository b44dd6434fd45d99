"""What an interaction did to the object, as the planner reasons about it: its outcome.

An outcome is one row of numbers per interaction, read from a dataset frame (:func:`outcome_table`):

| column | meaning |
|---|---|
| ``dx``, ``dy`` | how far the object's centre moved on the table [m], root frame (to where it rests, or to
  where it left the table) |
| ``rolled`` | it rolled further than the behaviour's roll threshold (``rolled``) |
| ``off_table`` | it left the table |
| ``lifted`` | a grasp lifted and held it (the grasp's ``success``; False for the other behaviours) |
| ``effect_<f>`` | the paper's perceptual effect: final minus initial features, the 49 of ``FEATURE_NAMES`` |

The motion comes from the simulator's ground truth (``true_initial_x`` ... ``true_final_y``): what a planner is
judged on, and what it learns to predict. The planner's inputs are never ground truth: the initial features, the
action's parameters and where the robot sees the object. Pure functions of a frame: nothing here needs the
simulator.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from affordance_learning.common.exceptions import InvalidValueError
from affordance_learning.common.schema import feature_names

#: The motion columns of an outcome table, in order; the effect columns follow.
MOTION_COLUMNS = ("dx", "dy", "rolled", "off_table", "lifted")
#: The action's columns in a dataset frame.
ACTION_COLUMNS = ("action_0", "action_1", "action_2")


def outcome_table(frame: pd.DataFrame) -> pd.DataFrame:
    """The outcome of every interaction of a dataset frame (see the module's table), with the frame's index.

    Raises:
        ValueError: the frame lacks a column the outcome is read from, naming it.
    """
    needed = ("true_initial_x", "true_initial_y", "true_final_x", "true_final_y", "rolled", "outcome", "success",
              "behavior")
    missing = [c for c in needed if c not in frame.columns]
    if missing:
        raise InvalidValueError(f"the frame lacks {missing}: an outcome is read from the ground truth of a frame of "
                         "affordance_env.load_dataset (schema version 5 or later names).")
    names = feature_names(frame)
    table = pd.DataFrame(index=frame.index)
    table["dx"] = frame["true_final_x"].to_numpy(np.float64) - frame["true_initial_x"].to_numpy(np.float64)
    table["dy"] = frame["true_final_y"].to_numpy(np.float64) - frame["true_initial_y"].to_numpy(np.float64)
    table["rolled"] = frame["rolled"].to_numpy(bool)
    table["off_table"] = (frame["outcome"].astype(str) == "off_table").to_numpy()
    table["lifted"] = ((frame["behavior"].astype(str) == "grasp") & frame["success"].astype(bool)).to_numpy()
    effects = frame[[f"effect_{n}" for n in names]].to_numpy(np.float64)
    return pd.concat([table, pd.DataFrame(effects, index=frame.index, columns=[f"effect_{n}" for n in names])],
                     axis=1)


def model_inputs(frame: pd.DataFrame) -> np.ndarray:
    """The inputs of an action-conditioned effect model, (n, 52): the 49 initial features and the 3 action
    parameters of every interaction of a dataset frame."""
    names = feature_names(frame)
    missing = [c for c in ACTION_COLUMNS if c not in frame.columns]
    if missing:
        raise InvalidValueError(
            f"the frame lacks the action columns {missing} (a frame of affordance_env.load_dataset).")
    return np.hstack([frame[[f"initial_{n}" for n in names]].to_numpy(np.float64),
                      frame[list(ACTION_COLUMNS)].to_numpy(np.float64)])
