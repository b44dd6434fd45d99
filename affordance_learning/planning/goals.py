"""Goals: what a robot wants an interaction to do to an object, as small JSON-serialisable objects.

Each goal says, for outcomes (:mod:`.outcomes`), whether they reach it: ``goal.reached(outcomes,
start_xy)`` takes an outcome table (or a dict of its columns as arrays, one row per sample) and where the object
was [m], and returns a boolean per row. A planner estimates P(goal) as the share of an effect model's predictive
samples that reach it; an evaluation asks the same of the outcome the simulator measured. A goal with a distance
(:attr:`Goal.has_distance`) also says how far each outcome goes towards it (``goal.progress(outcomes, start_xy)``),
and a goal names what a planner must know of it (:class:`Goal`), so that nothing that uses goals asks which kind
one is.

- :class:`Roll`: the object rolls (further than the behaviour's roll threshold).
- :class:`Lift`: a grasp lifts and holds it.
- :class:`Move`: its centre moves at least ``min_distance`` [m] along ``direction`` (a unit vector on the table,
  root frame), and it stays on the table.
- :class:`Place`: it comes to rest within ``tolerance`` [m] of ``target_xy``, on the table.
- :class:`Percept`: the perceptual effect is within ``tolerance`` of ``target_effect`` (imitation: an effect
  shown on one object, reproduced on another), measured as the root-mean-square of the effect difference in
  units of ``scale`` (the effects' spread in the training data, per feature).

``goal.to_dict()`` and :func:`goal_from_dict` round-trip through JSON.

Distances and positions are metres in the robot's root frame, on the scene's table
(:func:`affordance_env.table.table_extent`): a goal refuses what cannot be that (a distance longer than the table's
diagonal, a place further from the table top than its tolerance, a tolerance of 0 or of more than
:data:`MAX_TOLERANCE`), naming the value and the unit expected, so that ``Move((1, 0), 5)`` meant as 5 cm is not
taken for 5 m.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from affordance_env.table import table_extent
from affordance_env.values import float_array
from affordance_learning.common.exceptions import InvalidValueError

#: An outcome that leaves the table counts as this far from any place [m] when outcomes are ranked by how far they
#: go towards a goal (:meth:`Goal.progress`).
OFF_TABLE_DISTANCE = 1.0


#: The most a place's tolerance may be [m]: half the table's 1 m width (``assets/scene.xml``); a tolerance beyond it
#: takes in most of the table top, so that nearly anywhere places the object, and is a unit mistake (centimetres or
#: millimetres given as metres) far more likely than a goal.
MAX_TOLERANCE = 0.5


def _table() -> tuple[tuple[float, float], tuple[float, float]]:
    """The table top's (lower, upper) corners (x, y) [m] (:func:`affordance_env.table.table_extent`, read once)."""
    return table_extent()


def table_diagonal() -> float:
    """The table top's diagonal [m]: the longest move an object can make on it."""
    (x0, y0), (x1, y1) = _table()
    return float(np.hypot(x1 - x0, y1 - y0))


def _check_distance(name: str, value: Any, distance: float) -> float:
    """``distance`` [m] if positive and no longer than the table's diagonal, else InvalidValueError naming it."""
    longest = table_diagonal()
    if not 0 < distance <= longest:
        raise InvalidValueError(f"{name} must be a distance in metres on the table, in (0, {longest:.2f}] m (the "
                                f"table's diagonal), got {value!r}.")
    return distance


def _check_tolerance(value: Any, tolerance: float) -> float:
    """A place's ``tolerance`` [m] if in (0, :data:`MAX_TOLERANCE`], else InvalidValueError naming it."""
    if not 0 < tolerance <= MAX_TOLERANCE:
        raise InvalidValueError(f"tolerance must be a distance in metres, in (0, {MAX_TOLERANCE}] m, got {value!r}.")
    return tolerance


def _check_on_table(name: str, value: Any, xy: np.ndarray, tolerance: float) -> None:
    """InvalidValueError naming ``value`` where ``xy`` [m] lies further than ``tolerance`` [m] from the table top
    (no object resting on the table could be within ``tolerance`` of it)."""
    (x0, y0), (x1, y1) = _table()
    off = np.hypot(max(x0 - xy[0], 0.0, xy[0] - x1), max(y0 - xy[1], 0.0, xy[1] - y1))
    if off > tolerance:
        raise InvalidValueError(f"{name} must be (x, y) [m] on the table top, x in [{x0:.2f}, {x1:.2f}] and y in "
                                f"[{y0:.2f}, {y1:.2f}] (the robot's root frame; within the tolerance {tolerance:g} m "
                                f"of it), got {value!r}: {100 * off:.0f} cm off the table.")


def _column(outcomes: Any, name: str) -> np.ndarray:
    try:
        return np.asarray(outcomes[name])
    except (KeyError, IndexError):
        raise InvalidValueError(
            f"the outcomes lack {name!r} (an outcome table of affordance_learning.planning.outcomes)") from None


def _finite(name: str, value: Any, shape: tuple[int, ...] | None = ()) -> np.ndarray:
    """``value`` as a float array of ``shape`` (a number by default; None: any), finite, else InvalidValueError
    naming it."""
    expected = "a finite number" if shape == () else ("finite values" if shape is None else f"{shape} finite values")
    return float_array(name, value, shape, expected=expected, error=InvalidValueError)


class Goal:
    """What every goal answers, whatever its kind.

    Attributes:
        kind: The goal's name in JSON (:func:`goal_from_dict`).
        needs_start: Judging it needs where the object was (``start_xy``): a place is relative to it.
        has_distance: It has a distance: :meth:`progress` says how far an outcome goes towards it (else None).
        ranks_by_progress: Among actions of nearly the same P(goal), the one that goes further towards it is the
            better (a planner ranks P in coarse steps, then by progress): for a place, a nearer expected end is a
            real difference where the last few per cent of P are its noise.
    """

    kind: ClassVar[str]
    needs_start: ClassVar[bool] = False
    has_distance: ClassVar[bool] = False
    ranks_by_progress: ClassVar[bool] = False

    def reached(self, outcomes: Any, start_xy: Any = None) -> np.ndarray:
        """Per row of ``outcomes``, whether it reaches the goal from ``start_xy`` [m]."""
        raise NotImplementedError

    def progress(self, outcomes: Any, start_xy: Any = None) -> np.ndarray | None:
        """Per row of ``outcomes``, how far it goes towards the goal from ``start_xy`` [m] (higher is better; an
        outcome off the table counts as :data:`OFF_TABLE_DISTANCE` away); None for a goal without a distance."""
        return None

    def positions(self) -> dict[str, tuple[float, float]]:
        """The places on the table the goal names, (x, y) [m] by field: each must lie on the table top."""
        return {}

    def placement_error(self, end_xy: Any) -> float | None:
        """How far [m] an object that ended at ``end_xy`` is from where the goal wants it; None for a goal of no
        place."""
        return None

    def to_dict(self) -> dict[str, Any]:
        raise NotImplementedError


@dataclass(frozen=True)
class Roll(Goal):
    """The object rolls."""

    kind = "roll"

    def reached(self, outcomes: Any, start_xy: Any = None) -> np.ndarray:
        return _column(outcomes, "rolled").astype(bool) & ~_column(outcomes, "off_table").astype(bool)

    def to_dict(self) -> dict[str, Any]:
        return {"kind": self.kind}


@dataclass(frozen=True)
class Lift(Goal):
    """A grasp lifts and holds the object."""

    kind = "lift"

    def reached(self, outcomes: Any, start_xy: Any = None) -> np.ndarray:
        return _column(outcomes, "lifted").astype(bool)

    def to_dict(self) -> dict[str, Any]:
        return {"kind": self.kind}


@dataclass(frozen=True)
class Move(Goal):
    """The object's centre moves at least ``min_distance`` [m] along ``direction`` (normalised) and stays on the
    table; ``min_distance`` in (0, the table's diagonal] (:func:`table_diagonal`)."""

    direction: tuple[float, float]
    min_distance: float = 0.05
    kind = "move"
    has_distance = True

    def __post_init__(self) -> None:
        d = _finite("direction", self.direction, (2,))
        if np.linalg.norm(d) < 1e-9:
            raise InvalidValueError(f"direction must be a non-zero (x, y) vector, got {self.direction!r}.")
        object.__setattr__(self, "direction", tuple(float(v) for v in d / np.linalg.norm(d)))
        distance = _check_distance("min_distance", self.min_distance, float(_finite("min_distance",
                                                                                      self.min_distance)))
        object.__setattr__(self, "min_distance", distance)

    def reached(self, outcomes: Any, start_xy: Any = None) -> np.ndarray:
        along = _column(outcomes, "dx") * self.direction[0] + _column(outcomes, "dy") * self.direction[1]
        return (along >= self.min_distance) & ~_column(outcomes, "off_table").astype(bool)

    def progress(self, outcomes: Any, start_xy: Any = None) -> np.ndarray:
        """How far [m] each outcome moves the object along the direction; -:data:`OFF_TABLE_DISTANCE` off the
        table."""
        off = _column(outcomes, "off_table").astype(bool)
        along = _column(outcomes, "dx") * self.direction[0] + _column(outcomes, "dy") * self.direction[1]
        return np.where(off, -OFF_TABLE_DISTANCE, along)

    def to_dict(self) -> dict[str, Any]:
        return {"kind": self.kind, "direction": list(self.direction), "min_distance": self.min_distance}


def check_start(start_xy: Any) -> np.ndarray:
    """``start_xy``, where the object was (x, y) [m], (2,) or (n, 2), as a float array; raises ValueError naming
    the value given otherwise (None included: a :class:`Place` goal cannot be judged without it)."""
    if start_xy is None:
        raise InvalidValueError("a Place goal needs start_xy, where the object is (x, y) [m]; got None.")
    try:
        start = float_array("start_xy", start_xy, finite=False, error=InvalidValueError)
    except InvalidValueError:
        start = np.full(1, np.nan)
    if start.ndim not in (1, 2) or start.shape[-1] != 2 or not np.all(np.isfinite(start)):
        raise InvalidValueError(f"start_xy must be where the object is, finite (x, y) [m] ((2,) or (n, 2)), got "
                         f"{np.array2string(start, threshold=6) if start.size > 6 else start_xy!r} "
                         f"(shape {start.shape}).")
    return start


@dataclass(frozen=True)
class Place(Goal):
    """The object comes to rest within ``tolerance`` [m] of ``target_xy`` [m], on the table: ``target_xy`` in the
    robot's root frame, at most ``tolerance`` from the table top, and ``tolerance`` in (0, :data:`MAX_TOLERANCE`]."""

    target_xy: tuple[float, float]
    tolerance: float = 0.03
    kind = "place"
    needs_start = True
    has_distance = True
    ranks_by_progress = True

    def __post_init__(self) -> None:
        target = _finite("target_xy", self.target_xy, (2,))
        tolerance = _check_tolerance(self.tolerance, float(_finite("tolerance", self.tolerance)))
        _check_on_table("target_xy", self.target_xy, target, tolerance)
        object.__setattr__(self, "target_xy", tuple(float(v) for v in target))
        object.__setattr__(self, "tolerance", tolerance)

    def reached(self, outcomes: Any, start_xy: Any = None) -> np.ndarray:
        start = check_start(start_xy)
        x = start[..., 0] + _column(outcomes, "dx")
        y = start[..., 1] + _column(outcomes, "dy")
        near = np.hypot(x - self.target_xy[0], y - self.target_xy[1]) <= self.tolerance
        return near & ~_column(outcomes, "off_table").astype(bool)

    def progress(self, outcomes: Any, start_xy: Any = None) -> np.ndarray:
        """Minus how far [m] each outcome leaves the object from the target (:data:`OFF_TABLE_DISTANCE` off the
        table)."""
        off = _column(outcomes, "off_table").astype(bool)
        end = check_start(start_xy) + np.column_stack([_column(outcomes, "dx"), _column(outcomes, "dy")])
        return -np.where(off, OFF_TABLE_DISTANCE, np.linalg.norm(end - np.asarray(self.target_xy), axis=1))

    def positions(self) -> dict[str, tuple[float, float]]:
        return {"target_xy": self.target_xy}

    def placement_error(self, end_xy: Any) -> float:
        return float(np.linalg.norm(np.asarray(end_xy) - np.asarray(self.target_xy)))

    def to_dict(self) -> dict[str, Any]:
        return {"kind": self.kind, "target_xy": list(self.target_xy), "tolerance": self.tolerance}


@dataclass(frozen=True)
class Percept(Goal):
    """The perceptual effect comes within ``tolerance`` of ``target_effect``: the root-mean-square over features
    of the difference, each in units of ``scale`` (default 1: the features' own units)."""

    target_effect: tuple[float, ...]
    tolerance: float = 0.5
    scale: tuple[float, ...] | None = field(default=None)
    kind = "percept"

    def __post_init__(self) -> None:
        target = _finite("target_effect", self.target_effect, None)
        if target.ndim != 1 or target.size == 0:
            raise InvalidValueError(f"target_effect must be a vector of effect features, got shape {target.shape}.")
        object.__setattr__(self, "target_effect", tuple(float(v) for v in target))
        if self.scale is not None:
            scale = _finite("scale", self.scale, target.shape)
            if np.any(scale <= 0):
                raise InvalidValueError("scale must be positive for every feature.")
            object.__setattr__(self, "scale", tuple(float(v) for v in scale))
        tolerance = float(_finite("tolerance", self.tolerance))
        if tolerance <= 0:
            raise InvalidValueError(f"tolerance must be positive, got {self.tolerance!r}.")
        object.__setattr__(self, "tolerance", tolerance)

    def distance(self, effects: np.ndarray) -> np.ndarray:
        """RMS distance of effects (..., d) to the target, in units of ``scale``."""
        scale = np.ones(len(self.target_effect)) if self.scale is None else np.asarray(self.scale)
        diff = (np.asarray(effects, dtype=np.float64) - np.asarray(self.target_effect)) / scale
        return np.sqrt(np.mean(diff**2, axis=-1))

    def reached(self, outcomes: Any, start_xy: Any = None) -> np.ndarray:
        if isinstance(outcomes, Mapping):
            effects = np.asarray(outcomes["effect"]) if "effect" in outcomes else None
        else:
            columns = [c for c in outcomes.columns if str(c).startswith("effect_")]
            effects = outcomes[columns].to_numpy(np.float64) if columns else None
        if effects is None or effects.shape[-1] != len(self.target_effect):
            raise InvalidValueError(f"the outcomes lack the {len(self.target_effect)} effect columns the target has.")
        return self.distance(effects) <= self.tolerance

    def to_dict(self) -> dict[str, Any]:
        return {"kind": self.kind, "target_effect": list(self.target_effect), "tolerance": self.tolerance,
                "scale": None if self.scale is None else list(self.scale)}


#: Goal classes by ``kind``.
GOAL_KINDS: dict[str, type] = {cls.kind: cls for cls in (Roll, Lift, Move, Place, Percept)}


def check_goal(goal: Any) -> Goal:
    """``goal`` if it is one of the goal classes (:data:`GOAL_KINDS`); raises TypeError naming them otherwise."""
    if not isinstance(goal, tuple(GOAL_KINDS.values())):
        names = ", ".join(cls.__name__ for cls in GOAL_KINDS.values())
        hint = " (goal_from_dict makes one from a dict)" if isinstance(goal, Mapping) else ""
        raise TypeError(f"goal must be one of {names} (affordance_learning.planning.goals){hint}, got {goal!r} "
                        f"({type(goal).__name__}).")
    return goal


def goal_from_dict(data: Mapping[str, Any]) -> Goal:
    """The goal ``goal.to_dict()`` wrote; an unknown kind or a wrong field raises ValueError naming it."""
    if not isinstance(data, Mapping) or not isinstance(data.get("kind"), str) or data["kind"] not in GOAL_KINDS:
        raise InvalidValueError(f"a goal must be a dict with 'kind' one of {sorted(GOAL_KINDS)}, got {data!r}.")
    fields = {k: v for k, v in data.items() if k != "kind"}
    try:
        return GOAL_KINDS[data["kind"]](**fields)
    except TypeError as exc:
        raise InvalidValueError(f"bad fields for a {data['kind']!r} goal: {exc}") from None


def describe(goal: Goal) -> str:
    """A short text for reports: ``"move 5 cm toward -y"`` ..."""
    if isinstance(goal, Move):
        return f"move >= {100 * goal.min_distance:.0f} cm along ({goal.direction[0]:+.2f}, {goal.direction[1]:+.2f})"
    if isinstance(goal, Place):
        return f"place within {100 * goal.tolerance:.0f} cm of ({goal.target_xy[0]:.2f}, {goal.target_xy[1]:.2f})"
    if isinstance(goal, Percept):
        return f"reproduce an effect (RMS within {goal.tolerance:g})"
    return goal.kind


__all__: Sequence[str] = ["MAX_TOLERANCE", "OFF_TABLE_DISTANCE", "Goal", "Lift", "Move", "Percept", "Place", "Roll",
                          "check_goal", "describe", "goal_from_dict", "table_diagonal"]
