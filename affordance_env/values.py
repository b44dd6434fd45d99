"""Values a caller gives (an action, a position, a goal, a saved random state): read, or refused with an error that
names the value and what was expected, never numpy's own conversion error or a silently dropped imaginary part."""

from __future__ import annotations

import copy
from collections.abc import Mapping
from typing import Any

import numpy as np

from affordance_env.exceptions import InvalidValueError

#: numpy's kinds of real numbers: signed and unsigned integers, floating point. Not booleans, complex numbers,
#: strings, bytes or objects.
_REAL_KINDS = "iuf"


def float_array(name: str, value: Any, shape: tuple[int, ...] | None = None, *, expected: str | None = None,
                finite: bool = True, error: type[Exception] = InvalidValueError) -> np.ndarray:
    """``value`` as a float64 array, refused (``error``, a message naming ``name``, the value and ``expected``) unless
    its entries are real numbers (integers or floats, not booleans, complex numbers or strings), of ``shape`` (if
    given) and, with ``finite``, finite.

    Args:
        name: What the value is, as the message names it (``"action"``, ``"start_xy"``).
        value: The value given.
        shape: The shape it must have; None: any.
        expected: What it must be, in words (default: from ``shape``).
        finite: Whether NaN and infinities are refused.
        error: The exception raised (a package's own ``InvalidValueError``).
    """
    def refused(got: str = "") -> Exception:  # the message is made only when it is raised
        what = expected
        if what is None:
            what = "a finite number" if shape == () else (f"{shape[0]} finite numbers" if shape and len(shape) == 1
                                                         else f"finite numbers of shape {shape}")
        return error(f"{name} must be {what}, got {got}{value!r}.")

    if isinstance(value, str | bytes | Mapping | set | frozenset):
        raise refused()
    try:
        array = np.asarray(value)
    except (ValueError, TypeError):  # ragged sequences, objects numpy cannot read as an array
        raise refused() from None
    if array.dtype.kind not in _REAL_KINDS:
        raise refused()
    array = array.astype(np.float64, copy=False)
    if shape is not None and array.shape != shape:
        raise refused(f"shape {array.shape}: ")
    if finite and not np.all(np.isfinite(array)):
        raise refused()
    return array


def restored_generator(state: Any) -> np.random.Generator:
    """A PCG64 generator (Gymnasium's ``np_random``) in the saved bit-generator ``state`` (a copy of it), or
    InvalidValueError if ``state`` is not one."""
    rng = np.random.Generator(np.random.PCG64())
    try:
        rng.bit_generator.state = copy.deepcopy(state)
    except (TypeError, ValueError, KeyError):
        raise InvalidValueError(f"the state is damaged: its random generator's state is {state!r:.80}.") from None
    return rng
