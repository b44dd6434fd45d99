"""Where ``affordance train-default`` puts the default models it builds: the user's data directory.

Only paths, so that the command line can check them before it loads the learning models (see
:mod:`affordance_learning.default_model`, which finds the models there before the package's).
"""

from __future__ import annotations

import os
from pathlib import Path

from affordance_learning.common.behaviors import check_behavior

#: Environment variable naming the user's data directory, where rebuilt default models go.
DATA_ENV = "TAP_AFFORDANCE_DATA"


def user_model_dir() -> Path:
    """The user's directory of default models: ``$TAP_AFFORDANCE_DATA``, else ``$XDG_DATA_HOME/tap-affordance``,
    else ``~/.local/share/tap-affordance`` (the XDG convention for a user's application data)."""
    setting = os.environ.get(DATA_ENV)
    if setting:
        return Path(setting).expanduser()
    base = os.environ.get("XDG_DATA_HOME") or Path.home() / ".local" / "share"
    return Path(base) / "tap-affordance"


def user_model_path(behavior: str = "tap") -> Path:
    """Where ``affordance train-default`` stores the default model of ``behavior`` (:func:`user_model_dir`)."""
    return user_model_dir() / f"{check_behavior(behavior)}_model.joblib"


__all__ = ["DATA_ENV", "user_model_dir", "user_model_path"]
