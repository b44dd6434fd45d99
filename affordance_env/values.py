"""Values a caller gives (an action, a position, a goal, a saved random state): read, or refused with an error that
names the value and what was expected, never numpy's own conversion error or a silently dropped imaginary part."""

from __future__ import annotations

import copy
import numbers
import re
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from affordance_env.exceptions import InvalidValueError

#: numpy's kinds of real numbers: signed and unsigned integers, floating point. Not booleans, complex numbers,
#: strings, bytes or objects.
_REAL_KINDS = "iuf"
#: The longest value a message shows [characters]: a whole feature vector or batch would bury the message.
_SHOWN = 120


def _shown(value: Any) -> str:
    """``repr(value)``, cut to :data:`_SHOWN` characters."""
    shown = repr(value)
    return shown if len(shown) <= _SHOWN else shown[: _SHOWN - 3] + "..."


#: The protocols of a Dask scheduler's address that reach another process.
DASK_PROTOCOLS = ("tcp", "tls", "ws", "wss", "ucx")
_DASK_ADDRESS = re.compile(r"(?:(?P<protocol>[a-z]+)://)?(?P<host>\[[0-9A-Fa-f:.]+\]|[^\s:/\[\]]+):(?P<port>[0-9]+)")


def check_dask_address(address: Any) -> str:
    """``address`` if it has the form of a Dask scheduler's address, ``[PROTOCOL://]HOST:PORT`` (``tcp://host:8786``,
    ``tls://10.0.0.1:8786``, ``[::1]:8786``; tcp when no protocol is given); otherwise InvalidValueError saying the
    form. Whether a scheduler answers there is found when it is reached."""
    match = _DASK_ADDRESS.fullmatch(address) if isinstance(address, str) else None
    if (match is None or (match["protocol"] is not None and match["protocol"] not in DASK_PROTOCOLS)
            or not 0 < int(match["port"]) < 65536):
        raise InvalidValueError(f"dask_address must be a Dask scheduler's address, PROTOCOL://HOST:PORT with PROTOCOL "
                                f"one of {', '.join(DASK_PROTOCOLS)} (e.g. tcp://scheduler:8786), got "
                                f"{_shown(address)}.")
    return address


def is_integer(value: Any) -> bool:
    """Whether ``value`` is an integer, Python's or numpy's; not a boolean, which Python counts as one."""
    return isinstance(value, int | np.integer) and not isinstance(value, bool)


def float_array(name: str, value: Any, shape: tuple[int, ...] | None = None, *, expected: str | None = None,
                finite: bool = True, error: type[Exception] = InvalidValueError) -> np.ndarray:
    """``value`` as a float64 array, refused (``error``, a message naming ``name``, the value and ``expected``) unless
    its entries are real numbers (integers or floats, also in an array of objects such as a pandas row of mixed
    columns; not booleans, complex numbers or strings), of ``shape`` (if given) and, with ``finite``, finite.

    Args:
        name: What the value is, as the message names it (``"action"``, ``"start_xy"``).
        value: The value given.
        shape: The shape it must have; None: any.
        expected: What it must be, in words (default: from ``shape`` and ``finite``).
        finite: Whether NaN and infinities are refused.
        error: The exception raised.
    """
    def refused(got: str = "") -> Exception:  # the message is made only when it is raised
        what = expected
        if what is None:
            kind = "finite real" if finite else "real"
            what = (f"a {kind} number" if shape == () else f"{kind} numbers" if shape is None
                    else f"{kind} numbers of shape {shape}")
        return error(f"{name} must be {what}, got {got}{_shown(value)}.")

    if isinstance(value, str | bytes | Mapping | set | frozenset):
        raise refused()
    try:
        array = np.asarray(value)
    except (ValueError, TypeError):  # ragged sequences, objects numpy cannot read as an array
        raise refused() from None
    if array.dtype.kind == "O":  # numbers held as objects: each must be a real number
        if not all(isinstance(v, numbers.Real) and not isinstance(v, bool | np.bool_) for v in array.flat):
            raise refused()
        array = array.astype(np.float64)
    elif array.dtype.kind not in _REAL_KINDS:
        raise refused()
    array = array.astype(np.float64, copy=False)
    if shape is not None and array.shape != shape:
        raise refused(f"shape {array.shape}: ")
    if finite and not np.all(np.isfinite(array)):
        raise refused()
    return array


def set_generator_state(generator: np.random.Generator, state: Any) -> None:
    """Put ``generator`` (Gymnasium's ``np_random``) in the saved bit-generator ``state`` (a copy of it), or raise
    InvalidValueError, the generator as it was, if ``state`` is not one of its kind."""
    try:
        generator.bit_generator.state = copy.deepcopy(state)
    except (TypeError, ValueError, KeyError):
        raise InvalidValueError(f"the state is damaged: its random generator's state is {_shown(state)}.") from None


def restore_with_generator(generator: np.random.Generator, state: Any, restore: Callable[[], None]) -> None:
    """Put ``generator`` in the saved bit-generator ``state`` (:func:`set_generator_state`, checked first), then call
    ``restore()`` (the rest of a snapshot); if that raises, the generator is put back as it was."""
    before = generator.bit_generator.state
    set_generator_state(generator, state)
    try:
        restore()
    except Exception:
        generator.bit_generator.state = before
        raise
