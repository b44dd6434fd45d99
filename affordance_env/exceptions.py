"""The errors both packages raise on purpose, each naming the value it was given and what it expects.

All derive from :class:`AffordanceError`: those of the environment from :class:`AffordanceEnvError`, those of
``affordance_learning`` from :class:`AffordanceLearningError` (the learning package adds its own below it, in
``affordance_learning.common.exceptions``, which re-exports these). A value that cannot be used is one error
wherever it is refused, :class:`InvalidValueError`, under both packages' bases and ``ValueError`` (as scikit-learn's
estimators raise); a missing optional package is also an ``ImportError``; so that code written against either
package's base, or against the built-in types, still catches them. An exception of another type that escapes the
packages is a bug, and the ``affordance`` command keeps its traceback.

The learning package's base is defined here, below the environment, because the one ``InvalidValueError`` derives
from it; the environment raises nothing else of the learning package's.
"""

from __future__ import annotations


class AffordanceError(Exception):
    """Base of the errors ``affordance_env`` and ``affordance_learning`` raise on purpose."""


class AffordanceEnvError(AffordanceError):
    """Base of the errors ``affordance_env`` raises on purpose."""


class AffordanceLearningError(AffordanceError):
    """Base of the errors ``affordance_learning`` raises on purpose."""


class InvalidValueError(AffordanceEnvError, AffordanceLearningError, ValueError):
    """A value that cannot be taken: an option, an action, a pose, a name, features, a goal, results."""


class IncompatibleStateError(InvalidValueError):
    """A state restored into an environment of another kind (another robot model)."""


class DatasetError(InvalidValueError):
    """A dataset that cannot be read or extended, with the reason."""


class MissingDependencyError(AffordanceEnvError, ImportError):
    """An optional package a feature needs is not installed; the message says how to install it."""


__all__ = ["AffordanceEnvError", "AffordanceError", "AffordanceLearningError", "DatasetError",
           "IncompatibleStateError", "InvalidValueError", "MissingDependencyError"]
