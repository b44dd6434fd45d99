"""The errors ``affordance_learning`` raises on purpose, each naming the value it was given and what it expects.

All derive from :class:`AffordanceLearningError`, which with :class:`InvalidValueError` (a value that cannot be
used, also a ``ValueError`` as scikit-learn's estimators raise) is defined once for both packages in
:mod:`affordance_env.exceptions` and re-exported here; the default models' errors are the learning package's own.
An exception of another type that escapes the package is a bug, and the ``affordance`` command keeps its traceback.
"""

from __future__ import annotations

from affordance_env.exceptions import AffordanceError, AffordanceLearningError, InvalidValueError


class DefaultModelError(AffordanceLearningError, RuntimeError):
    """A default model is unusable: unreadable, of another format or behaviour, or of other library versions."""


class DefaultModelMissingError(DefaultModelError, FileNotFoundError):
    """A default model file does not exist; the message gives the command that builds it."""


__all__ = ["AffordanceError", "AffordanceLearningError", "DefaultModelError", "DefaultModelMissingError",
           "InvalidValueError"]
