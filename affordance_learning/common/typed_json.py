"""Frozen dataclasses to and from JSON: one writer and one reader for every results file, driven by the types.

:func:`to_json` turns a dataclass, and all it holds, into plain JSON values; :func:`from_json` reads them back into
the dataclass, checking each value against the type of its field, and raises InvalidValueError naming where a value
is wrong and what was expected: ``results['uniformity']['3'] lacks 'std'; expected ...``.

The types a field may have:

- ``int``, ``float``, ``str``, ``bool`` and ``None``: a float reads any JSON number, an int a whole one, a bool
  only true or false;
- ``X | None``;
- ``tuple[X, ...]`` and ``tuple[X, Y]``: JSON lists;
- ``Mapping[K, V]`` with K ``int``, ``float`` or ``str``: JSON objects, whose keys are strings: an int k is keyed
  ``str(int(k))`` ("2"), a float r ``str(float(r))`` ("0.4", "0.0"); read back as a read-only mapping in the
  order held;
- a dataclass;
- ``Any``: plain JSON (mappings, lists, numbers, strings), copied as it is;
- ``Annotated[X, "what it is"]``: X, named in messages as what it is ("a map size k", "a count").

What a field says of its JSON (``field(metadata=json_options(...))``):

- ``key``: its name in the JSON (by default the field's name);
- ``omit_none``: it is left out when None (a section the results lack);
- ``inline``: the dataclass, of that one field, is written as the field's value (a wrapper that gives a mapping
  typed queries).

A field with a default may be missing from the JSON; one without must be there. Keys no field names are skipped.
Fields are written in the order the dataclass declares them (``kw_only`` lets a required field follow one with a
default, to keep a file's order). Where a dataclass is expected, an instance of it is taken as it is.
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import numbers
import types
import typing
from collections.abc import Mapping
from typing import Annotated, Any, NoReturn, TypeVar, get_args, get_origin

from affordance_learning.common.exceptions import InvalidValueError

T = TypeVar("T")

#: Where a value lies in the JSON: its keys and indices from the top, ("uniformity", "3", "mean").
Path = tuple[Any, ...]

_KEY, _OMIT_NONE, _INLINE = "json_key", "json_omit_none", "json_inline"
#: What each plain type is called in messages, and how a mapping writes a key of it.
_NAMES = {int: "a whole number", float: "a number", str: "a text", bool: "true or false", type(None): "None"}
_KEYS_WRITTEN = {int: "str(int(key))", float: "str(float(key))", str: "a text"}


def json_options(key: str | None = None, omit_none: bool = False, inline: bool = False) -> dict[str, Any]:
    """The metadata of a field (``field(metadata=json_options(key="cluster"))``): its name in the JSON, whether it
    is left out when None, whether it is the one field of a wrapper written as its value (module docstring)."""
    return {_KEY: key, _OMIT_NONE: omit_none, _INLINE: inline}


def to_json(obj: Any) -> Any:
    """``obj`` (a dataclass, or a value of a supported type) as plain JSON values: dicts, lists, numbers, strings,
    booleans and None, for ``json.dumps``."""
    return _write(type(obj) if dataclasses.is_dataclass(obj) else Any, obj)


def from_json(cls: type[T], data: Any, *, name: str = "value", expected: str = "") -> T:
    """``data`` (JSON values, as ``json.load`` gives them) read as ``cls``, a dataclass.

    Args:
        cls: The dataclass to build.
        data: Its JSON.
        name: What ``data`` is called in messages (``"results"``, ``"plan results"``).
        expected: What a caller should have passed, for the end of each message.

    Raises:
        InvalidValueError: A value does not have the type of its field, or a field without a default is missing;
            the message names where (``results['case_studies']['2'][1] lacks 'fail'``).
    """
    return _read(cls, data, (), _Reading(name, expected))


# --- the fields of a dataclass ---------------------------------------------------------------------------------
@dataclasses.dataclass(frozen=True)
class _Field:
    name: str
    key: str
    hint: Any
    omit_none: bool
    required: bool


@functools.cache
def _fields(cls: type) -> tuple[tuple[_Field, ...], bool]:
    """The fields of dataclass ``cls`` that its constructor takes, with their resolved types; and whether ``cls`` is
    a wrapper written inline."""
    hints = typing.get_type_hints(cls, include_extras=True)
    found = tuple(
        _Field(f.name, f.metadata.get(_KEY) or f.name, hints[f.name], bool(f.metadata.get(_OMIT_NONE)),
               f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING)
        for f in dataclasses.fields(cls) if f.init)
    inline = [f for f in dataclasses.fields(cls) if f.metadata.get(_INLINE)]
    if inline and len(found) != 1:
        raise TypeError(f"{cls.__name__} is written inline, so it must have exactly one field.")
    return found, bool(inline)


def _unwrapped(hint: Any) -> tuple[Any, str | None]:
    """``hint`` without ``Annotated``, and what the annotation calls it (None without one)."""
    if get_origin(hint) is Annotated:
        base, *extras = get_args(hint)
        return base, next((e for e in extras if isinstance(e, str)), None)
    return hint, None


def _optional(hint: Any) -> Any | None:
    """X of ``X | None``; None when ``hint`` is no such union."""
    if get_origin(hint) not in (typing.Union, types.UnionType):
        return None
    rest = [a for a in get_args(hint) if a is not type(None)]
    if len(rest) != 1 or len(rest) == len(get_args(hint)):
        raise TypeError(f"unsupported union {hint!r}: only X | None")
    return rest[0]


# --- writing ---------------------------------------------------------------------------------------------------
def _write(hint: Any, value: Any) -> Any:
    hint, _ = _unwrapped(hint)
    if value is None:
        return None
    if (inner := _optional(hint)) is not None:
        return _write(inner, value)
    if dataclasses.is_dataclass(hint):
        found, inline = _fields(hint)
        if inline:
            return _write(found[0].hint, getattr(value, found[0].name))
        return {f.key: _write(f.hint, getattr(value, f.name)) for f in found
                if not (f.omit_none and getattr(value, f.name) is None)}
    origin, args = get_origin(hint), get_args(hint)
    if origin is tuple:
        items = args[:1] * len(value) if len(args) == 2 and args[1] is Ellipsis else args
        return [_write(item, v) for item, v in zip(items, value, strict=True)]
    if origin is not None and issubclass(origin, Mapping):
        key_type, value_type = (_unwrapped(a)[0] for a in args)
        return {str(key_type(k)): _write(value_type, v) for k, v in value.items()}
    if hint in (int, float, str, bool):
        return hint(value)
    return _plain(value)


def _plain(value: Any) -> Any:
    """A value of ``Any`` as plain JSON values."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return to_json(value)
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    if isinstance(value, bool | str) or value is None:
        return value
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real):
        return float(value)
    return value


# --- reading ---------------------------------------------------------------------------------------------------
@dataclasses.dataclass(frozen=True)
class _Reading:
    name: str
    expected: str

    def fail(self, path: Path, what: str) -> NoReturn:
        where = self.name + "".join(f"[{part!r}]" for part in path)
        raise InvalidValueError(f"{where} {what}{f'; {self.expected}' if self.expected else ''}.")


def _read(hint: Any, value: Any, path: Path, reading: _Reading, optional: bool = False) -> Any:
    hint, called = _unwrapped(hint)
    if (inner := _optional(hint)) is not None:
        return None if value is None else _read(inner, value, path, reading, optional=True)
    if dataclasses.is_dataclass(hint):
        return _read_dataclass(hint, value, path, reading)
    origin, args = get_origin(hint), get_args(hint)
    if origin is tuple:
        return _read_tuple(args, value, path, reading)
    if origin is not None and issubclass(origin, Mapping):
        return _read_mapping(args, value, path, reading)
    if hint is Any:
        return copy.deepcopy(value)
    if hint in _NAMES:
        return _read_plain(hint, called, value, path, reading, optional)
    raise TypeError(f"{hint!r} is not a type typed_json reads")


def _read_dataclass(cls: type, value: Any, path: Path, reading: _Reading) -> Any:
    if isinstance(value, cls):  # already built (a producer's part in a dict of JSON values)
        return value
    found, inline = _fields(cls)
    if inline:
        return cls(**{found[0].name: _read(found[0].hint, value, path, reading)})
    entry = _mapping(value, path, reading)
    missing = [f.key for f in found if f.required and f.key not in entry]
    if missing:
        reading.fail(path, f"lacks {', '.join(repr(key) for key in missing)}")
    return cls(**{f.name: _read(f.hint, entry[f.key], (*path, f.key), reading) for f in found if f.key in entry})


def _read_tuple(args: tuple[Any, ...], value: Any, path: Path, reading: _Reading) -> tuple[Any, ...]:
    if not isinstance(value, list | tuple):
        reading.fail(path, f"must be a list, got {type(value).__name__}")
    if len(args) == 2 and args[1] is Ellipsis:
        args = args[:1] * len(value)
    elif len(value) != len(args):
        reading.fail(path, f"must be a list of {len(args)} values, got {value!r}")
    return tuple(_read(item, v, (*path, i), reading) for i, (item, v) in enumerate(zip(args, value, strict=True)))


def _read_mapping(args: tuple[Any, ...], value: Any, path: Path, reading: _Reading) -> Mapping[Any, Any]:
    section = _mapping(value, path, reading)
    (key_type, called), value_type = _unwrapped(args[0]), args[1]
    return types.MappingProxyType({_read_key(key_type, called, key, path, reading):
                                   _read(value_type, item, (*path, key), reading) for key, item in section.items()})


def _read_key(key_type: type, called: str | None, key: Any, path: Path, reading: _Reading) -> Any:
    """A key of a JSON object as ``key_type`` (int, float or str)."""
    try:
        if key_type is str and not isinstance(key, str):
            raise TypeError(key)
        return key_type(key)
    except (TypeError, ValueError):
        written = f"written as {_KEYS_WRITTEN[key_type]}"
        what = f"{called} ({_NAMES[key_type]}, {written})" if called else f"{_NAMES[key_type]} ({written})"
        reading.fail(path, f"holds the key {key!r}, which is not {what}")


def _mapping(value: Any, path: Path, reading: _Reading) -> Mapping[Any, Any]:
    if not isinstance(value, Mapping):
        reading.fail(path, f"must be a mapping, got {type(value).__name__}")
    return value


def _is_number(value: Any) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _read_plain(hint: type, called: str | None, value: Any, path: Path, reading: _Reading, optional: bool) -> Any:
    if hint is bool and isinstance(value, bool):
        return value
    if hint is float and _is_number(value):
        return float(value)
    if hint is int and _is_number(value) and float(value).is_integer():
        return int(value)
    if hint is str and isinstance(value, str):
        return value
    if hint is type(None) and value is None:
        return None
    what = f"{called} ({_NAMES[hint]})" if called else _NAMES[hint]
    reading.fail(path, f"must be {what}{' or None' if optional else ''}, got {value!r}")


__all__ = ["Path", "from_json", "json_options", "to_json"]
