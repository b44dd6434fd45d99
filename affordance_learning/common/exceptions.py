"""The errors ``affordance_learning`` raises on purpose, each naming the value it was given and what it expects.

All derive from :class:`AffordanceLearningError`; those for a value that cannot be used also from ``ValueError``
(as scikit-learn's estimators raise), so that code written against the built-in types still catches them. An
exception of another type that escapes the package is a bug, and the ``affordance`` command keeps its traceback.
"""

from __future__ import annotations


class AffordanceLearningError(Exception):
    """Base of the errors ``affordance_learning`` raises on purpose."""


class InvalidValueError(AffordanceLearningError, ValueError):
    """A value the learning, the planner, a report or a command cannot take: features, goals, results, names."""


class DefaultModelError(AffordanceLearningError, RuntimeError):
    """A default model is unusable: unreadable, of another format or behaviour, or of other library versions."""


class DefaultModelMissingError(DefaultModelError, FileNotFoundError):
    """A default model file does not exist; the message gives the command that builds it."""


__all__ = ["AffordanceLearningError", "DefaultModelError", "DefaultModelMissingError", "InvalidValueError"]
