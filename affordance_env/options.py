"""The options of TapAffordance-v2 that decide its data: their defaults, and their checks.

Checking them builds nothing and imports neither MuJoCo nor Pinocchio, so a collection checks its options in its
coordinating process, in milliseconds, before it starts the workers that build the environments.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from affordance_env.behaviors.success import ROLL_THRESHOLD
from affordance_env.exceptions import InvalidValueError
from affordance_env.objects import OBJECT_TYPES, check_object_type, check_size
from affordance_env.pinhole import Intrinsics
from affordance_env.range_noise import check_range_noise
from affordance_env.registry import check_behavior_name

#: Where objects are placed: ``"canonical"``, uniform within +-3 cm of the paper's spot in front of the robot;
#: ``"workspace"``, uniform over the workspace of the behaviour (:mod:`affordance_env.workspace`; in
#: TapAffordanceGoal-v2, the workspace of a behaviour drawn uniformly).
POSITION_RANGES = ("canonical", "workspace")


@dataclass(frozen=True)
class EnvOptions:
    """The data options of :class:`~affordance_env.tap_env.TapAffordanceEnv` (its constructor's defaults are
    these), checked and normalised when made: a bad value raises ValueError naming it and what was expected.

    Sequences become tuples, sizes and distances floats, so that equal settings compare equal.
    """

    behavior: str = "tap"
    object_types: Sequence[str] = OBJECT_TYPES
    size_range: tuple[float, float] = (0.04, 0.10)
    camera_width: int = 160
    camera_height: int = 120
    camera_fovy: float = 57.4
    roll_threshold: float = ROLL_THRESHOLD
    settle_timeout: float = 3.0
    range_noise: str | None = None
    position_range: str = "canonical"
    two_arms: bool = False

    def __post_init__(self) -> None:
        check_behavior_name(self.behavior)
        types = self.object_types
        if isinstance(types, str) or not isinstance(types, Sequence) or len(types) == 0:
            raise InvalidValueError(f"object_types must be a non-empty sequence of {OBJECT_TYPES}, got {types!r}.")
        normalised: dict[str, Any] = {"object_types": tuple(check_object_type(t) for t in types)}
        size_range = self.size_range
        if isinstance(size_range, str) or not isinstance(size_range, Sequence) or len(size_range) != 2:
            raise InvalidValueError(f"size_range must be (low, high) in metres, got {size_range!r}.")
        try:
            low, high = (check_size(s) for s in size_range)
        except ValueError as exc:
            raise InvalidValueError(f"size_range must be (low, high) in metres, got {size_range!r}: {exc}") from None
        if low > high:
            raise InvalidValueError(f"size_range must be (low, high) with low <= high, got {size_range!r}.")
        normalised["size_range"] = (low, high)
        if isinstance(self.camera_fovy, bool) or not isinstance(self.camera_fovy, numbers.Real):
            raise InvalidValueError(
                f"camera_fovy must be a vertical field of view in degrees, got {self.camera_fovy!r}.")
        Intrinsics.from_fovy(self.camera_width, self.camera_height, self.camera_fovy)
        for name in ("roll_threshold", "settle_timeout"):
            value = getattr(self, name)
            real = isinstance(value, numbers.Real) and not isinstance(value, bool)
            if not (real and math.isfinite(value) and value > 0):
                unit = "distance [m]" if name == "roll_threshold" else "duration [s]"
                raise InvalidValueError(f"{name} must be a positive {unit}, got {value!r}.")
            normalised[name] = float(value)
        normalised["camera_width"], normalised["camera_height"] = int(self.camera_width), int(self.camera_height)
        normalised["camera_fovy"] = float(self.camera_fovy)
        check_range_noise(self.range_noise)
        if self.position_range not in POSITION_RANGES:
            raise InvalidValueError(f"position_range must be one of {POSITION_RANGES}, got {self.position_range!r}.")
        if not isinstance(self.two_arms, bool):
            raise InvalidValueError(f"two_arms must be True or False, got {self.two_arms!r}.")
        for name, value in normalised.items():
            object.__setattr__(self, name, value)

    @classmethod
    def checked(cls, **options: Any) -> EnvOptions:
        """The options from keyword arguments; an unknown name raises ValueError listing the known ones."""
        known = [f.name for f in dataclasses.fields(cls)]
        unknown = sorted(set(options) - set(known))
        if unknown:
            raise InvalidValueError(
                f"unknown or unsupported env options {unknown}; the data options of TapAffordance-v2 "
                             f"(what a dataset records) are {known}.")
        return cls(**options)
