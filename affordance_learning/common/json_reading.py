"""Reading a results dict (as ``json.load`` gives it) with errors that say where a value is wrong.

:mod:`affordance_learning.planning.results` reads its dicts through a :class:`Reader`: each check returns the value
in the type asked for, or raises InvalidValueError naming its place (``plan results['calibration'] lacks 'ece'``)
and what the reader expected. The paper's results are read from their types by
:mod:`affordance_learning.common.typed_json`.
"""

from __future__ import annotations

import numbers
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from affordance_learning.common.exceptions import InvalidValueError

#: Where a value lies in the dict: its keys from the top, ("uniformity", "3", "mean").
Path = tuple[Any, ...]


def is_number(value: Any) -> bool:
    """A real number that is not a bool."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


@dataclass(frozen=True)
class Reader:
    """Checks for one kind of dict.

    Attributes:
        name: What the dict is called in messages (``"results"``, ``"plan results"``).
        expected: What a caller should have passed, for the end of each message.
    """

    name: str
    expected: str

    def where(self, path: Path) -> str:
        """``results['uniformity']['3']['mean']`` for the path ("uniformity", "3", "mean")."""
        return self.name + "".join(f"[{part!r}]" for part in path)

    def mapping(self, value: Any, path: Path) -> Mapping[Any, Any]:
        if not isinstance(value, Mapping):
            raise InvalidValueError(
                f"{self.where(path)} must be a mapping, got {type(value).__name__}; {self.expected}.")
        return value

    def list(self, value: Any, path: Path) -> list[Any] | tuple[Any, ...]:
        if not isinstance(value, list | tuple):
            raise InvalidValueError(f"{self.where(path)} must be a list, got {type(value).__name__}; {self.expected}.")
        return value

    def entry(self, value: Any, path: Path, keys: Iterable[str]) -> Mapping[str, Any]:
        """``value`` as a mapping that holds every one of ``keys``."""
        entry = self.mapping(value, path)
        missing = [key for key in keys if key not in entry]
        if missing:
            raise InvalidValueError(
                f"{self.where(path)} lacks {', '.join(repr(k) for k in missing)}; {self.expected}.")
        return entry

    def number(self, value: Any, path: Path, optional: bool = False) -> Any:
        """``value`` as a float (None when ``optional`` and None)."""
        if value is None and optional:
            return None
        if not is_number(value):
            what = "a number or None" if optional else "a number"
            raise InvalidValueError(f"{self.where(path)} must be {what}, got {value!r}; {self.expected}.")
        return float(value)

    def count(self, value: Any, path: Path) -> int:
        """``value`` as a whole number."""
        if not is_number(value) or not float(value).is_integer():
            raise InvalidValueError(
                f"{self.where(path)} must be a count (a whole number), got {value!r}; {self.expected}.")
        return int(value)
