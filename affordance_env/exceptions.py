"""The errors ``affordance_env`` raises on purpose, each naming the value it was given and what it expects.

All derive from :class:`AffordanceEnvError`; those for a value that cannot be used also from ``ValueError``, and a
missing optional package from ``ImportError``, so that code written against the built-in types still catches them.
An exception of another type that escapes the package is a bug, and the ``affordance`` command keeps its traceback.
"""

from __future__ import annotations


class AffordanceEnvError(Exception):
    """Base of the errors ``affordance_env`` raises on purpose."""


class InvalidValueError(AffordanceEnvError, ValueError):
    """A value the environment, a behaviour or a dataset cannot take: an option, an action, a pose, a name."""


class IncompatibleStateError(InvalidValueError):
    """A state restored into an environment of another kind (another robot model)."""


class DatasetError(InvalidValueError):
    """A dataset that cannot be read or extended, with the reason."""


class MissingDependencyError(AffordanceEnvError, ImportError):
    """An optional package a feature needs is not installed; the message says how to install it."""


__all__ = ["AffordanceEnvError", "DatasetError", "IncompatibleStateError", "InvalidValueError",
           "MissingDependencyError"]
