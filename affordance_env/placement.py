"""Where the next object goes: drawn from the env's random generator, or chosen by ``reset``'s options.

A pure function of the generator, the options and the table: no simulator. The draws are made whether or not an
option replaces them, so the rest of an episode's randomness does not depend on which options were given.
"""

from __future__ import annotations

import numbers
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from affordance_env.exceptions import InvalidValueError
from affordance_env.linalg import norm
from affordance_env.objects import ObjectGeometry, check_object_type, check_size, object_geometry
from affordance_env.workspace import sample_in_workspace

#: Region of the table where objects are placed: centre (x, y) and half-widths [m].
PLACEMENT_CENTRE = np.array([-0.30, 0.03])
PLACEMENT_HALF_WIDTH = np.array([0.03, 0.03])
#: Keys of ``reset(options=...)`` that choose the object instead of drawing it.
RESET_OPTIONS = ("object_type", "size", "position", "yaw", "object_pose")
#: Yaw jitter of boxes and lying cylinders [rad].
YAW_JITTER = 0.25


@dataclass(frozen=True)
class Table:
    """The table top: its corners (x, y) [m] and its height [m]."""

    low: np.ndarray
    high: np.ndarray
    top: float

    def check_position(self, value: Any, name: str = "position") -> np.ndarray:
        """``value`` as (x, y) on the table top [m]; raises InvalidValueError naming the table's extent."""
        try:
            xy = np.asarray(value, dtype=np.float64)
        except (TypeError, ValueError):
            xy = np.full(1, np.nan)
        low, high = self.low, self.high
        if xy.shape != (2,) or not np.all(np.isfinite(xy)) or np.any(xy < low) or np.any(xy > high):
            raise InvalidValueError(
                f"{name} must be (x, y) on the table top, x in [{low[0]:.2f}, {high[0]:.2f}] and "
                f"y in [{low[1]:.2f}, {high[1]:.2f}] m, got {value!r}.")
        return xy


@dataclass(frozen=True)
class Placement:
    """The next object and where it goes.

    Attributes:
        geometry: The object's type and size.
        xy: Its position on the table [m].
        yaw: Its yaw [rad] (0 for spheres and standing cylinders).
        pose: Any pose ``(x, y, z, qw, qx, qy, qz)`` instead of ``xy`` and ``yaw``, from which it settles; None.
    """

    geometry: ObjectGeometry
    xy: np.ndarray
    yaw: float
    pose: np.ndarray | None = None


def check_pose(value: Any, geometry: ObjectGeometry, table: Table) -> np.ndarray:
    """``value`` as an object pose over the table, its quaternion normalised; raises InvalidValueError."""
    try:
        pose = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        pose = np.full(1, np.nan)
    low, high, top = table.low, table.high, table.top
    ok = pose.shape == (7,) and bool(np.all(np.isfinite(pose)))
    if ok:
        ok = (bool(np.all(pose[:2] >= low) and np.all(pose[:2] <= high))
              and top + 0.5 * geometry.half_height <= pose[2] <= top + 3.0 * geometry.rbound
              and norm(pose[3:]) > 1e-6)
    if not ok:
        raise InvalidValueError(
            f"object_pose must be (x, y, z, qw, qx, qy, qz): x in [{low[0]:.2f}, {high[0]:.2f}] and "
            f"y in [{low[1]:.2f}, {high[1]:.2f}] m on the table, z [m] the object's centre above the "
            f"table top ({top:.3f} m) by {0.5 * geometry.half_height:.3f} to "
            f"{3.0 * geometry.rbound:.3f} m, and a non-zero quaternion; got {value!r}.")
    pose[3:] /= norm(pose[3:])
    return pose


def draw_placement(rng: np.random.Generator, options: Mapping[str, Any] | None, object_types: Sequence[str],
                   size_range: tuple[float, float], table: Table, workspace: str | None = None) -> Placement:
    """The next object: type uniform over ``object_types``, size uniform in ``size_range`` [m], position uniform
    within PLACEMENT_HALF_WIDTH of PLACEMENT_CENTRE (or over the workspace of behaviour ``workspace``, if given),
    yaw within YAW_JITTER; then replaced by any given in ``options`` (keys :data:`RESET_OPTIONS`)."""
    object_type = object_types[int(rng.integers(len(object_types)))]
    size = float(rng.uniform(*size_range))
    xy = PLACEMENT_CENTRE + rng.uniform(-1.0, 1.0, 2) * PLACEMENT_HALF_WIDTH
    yaw = float(rng.uniform(-YAW_JITTER, YAW_JITTER))
    if workspace is not None:
        xy = sample_in_workspace(workspace, rng)
    if options is not None and not isinstance(options, Mapping):
        raise InvalidValueError(f"options must be a dict with keys among {RESET_OPTIONS}, got {options!r}.")
    options = dict(options or {})
    unknown = sorted(set(options) - set(RESET_OPTIONS))
    if unknown:
        raise InvalidValueError(f"Unknown reset option(s) {unknown}. Valid options: {', '.join(RESET_OPTIONS)}.")
    if "object_type" in options:
        object_type = check_object_type(options["object_type"])
    if "size" in options:
        try:
            size = check_size(options["size"])
        except ValueError as exc:
            raise InvalidValueError(f"reset option 'size': {exc}") from None
    if object_type in ("sphere", "vertical_cylinder"):
        yaw = 0.0
    if "position" in options:
        xy = table.check_position(options["position"])
    if "yaw" in options:
        real = isinstance(options["yaw"], numbers.Real) and not isinstance(options["yaw"], bool)
        yaw = float(options["yaw"]) if real else float("nan")
        if not np.isfinite(yaw):
            raise InvalidValueError(f"yaw must be a finite angle [rad], got {options['yaw']!r}.")
    geometry = object_geometry(object_type, size)
    pose = None
    if "object_pose" in options:
        if "position" in options or "yaw" in options:
            raise InvalidValueError(
                "reset options 'object_pose' and 'position' or 'yaw' exclude each other: the pose gives both.")
        pose = check_pose(options["object_pose"], geometry, table)
    return Placement(geometry, xy, yaw, pose)
