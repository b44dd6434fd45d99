"""Frames in the dataset schema made without the simulator, for tests, benchmarks and demonstrations: taps, where
spheres and lying cylinders roll and boxes and standing cylinders do not, or grasps, where objects smaller than a
critical size are held and larger ones are not."""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd

from affordance_env.objects import OBJECT_TYPES, ROLLING_TYPES
from affordance_env.values import is_integer
from affordance_learning.common.exceptions import InvalidValueError
from affordance_learning.common.schema import TYPE_ORDER

#: Behaviours :func:`make_synthetic_frame` can imitate, with their object size ranges [m].
SYNTHETIC_SIZE_RANGES = {"tap": (0.04, 0.10), "grasp": (0.03, 0.09)}
#: Size [m] at which a synthetic grasp holds the object half of the time, and the width of the transition [m].
SYNTHETIC_CRITICAL_SIZE, SYNTHETIC_GRASP_SPREAD = 0.06, 0.003


def make_synthetic_frame(n_rows: int = 1000, random_state: int = 0, behavior: str = "tap") -> pd.DataFrame:
    """A dataset frame in the project's schema with tapping- or grasping-like structure, made without the
    simulator.

    Objects of the four types. Shape features (normal histograms, fractions) depend on the type, size features
    on the size, relation features are jitter.

    - ``"tap"``: sizes uniform in [0.04, 0.10] m. Spheres and lying cylinders roll (95 %), boxes and standing
      cylinders do not (97 %); ``success`` is ``rolled``. As on the simulated table, a rolled object travels
      5-22 cm and is seen where it stops: its effect moves its position, range, pixel count and image offsets
      by its travel; 3 % of the rolled objects leave the table instead (``outcome == "off_table"``,
      ``visible_final`` False, final features all zeros, so their effect is minus their initial features); a
      resting object slides about 1.5 cm.
    - ``"grasp"``: sizes uniform in [0.03, 0.09] m. Whatever its type, an object is held with probability
      ``1 / (1 + exp((size - 0.06 m) / 3 mm))``: the critical size is 6 cm. A held object is put down about
      6 cm from where it stood; one not held is nudged by about half a centimetre. Nothing rolls.

    Feature names are ``affordance_env.features.FEATURE_NAMES`` when available, else ``f00`` ... ``f48``.

    Args:
        n_rows: Interactions, >= 8.
        random_state: Seed.
        behavior: ``"tap"`` or ``"grasp"`` (the ``behavior`` column).
    """
    _check_arguments(n_rows, behavior)
    grasp = behavior == "grasp"
    names = _feature_names()
    rng = np.random.default_rng(random_state)
    types, kind, size, held, rolled = _objects(rng, n_rows, behavior)
    shape = _shape_features(rng, kind, n_rows)
    size_features, pixels = _size_features(rng, size, n_rows)
    relation = rng.normal(0.0, 1.0, (n_rows, 7)) * np.array([5, 5, 7, 0.02, 0.02, 0.02, 0.03])
    initial = np.hstack([shape, size_features, relation])
    travel, off_table = _travel(rng, types, held, rolled, grasp)
    final, effect = _final_and_effect(rng, initial, pixels, travel, off_table, types, rolled)
    columns: dict[str, Any] = {}
    for prefix, values in (("initial_", initial), ("final_", final), ("effect_", effect)):
        columns.update({f"{prefix}{n}": values[:, j] for j, n in enumerate(names)})
    columns.update({"behavior": np.full(n_rows, behavior), "type": types, "size": size, "rolled": rolled,
                    "success": held if grasp else rolled, "displacement": np.abs(travel),
                    "rolling_distance": np.where(rolled, np.abs(travel), 0.0), "visible_final": ~off_table,
                    "outcome": np.where(off_table, "off_table", "rest")})
    return pd.DataFrame(columns)


def _check_arguments(n_rows: int, behavior: str) -> None:
    """InvalidValueError unless ``n_rows`` is an integer >= 8 and ``behavior`` one :func:`make_synthetic_frame`
    imitates."""
    if not is_integer(n_rows) or n_rows < 8:
        raise InvalidValueError(f"n_rows must be an integer >= 8, got {n_rows!r}.")
    if behavior not in SYNTHETIC_SIZE_RANGES:
        raise InvalidValueError(f"behavior must be one of {tuple(SYNTHETIC_SIZE_RANGES)}, got {behavior!r}.")


def _feature_names() -> list[str]:
    """``affordance_env.features.FEATURE_NAMES`` when available, else ``f00`` ... ``f48``."""
    try:
        from affordance_env.features import FEATURE_NAMES

        return list(FEATURE_NAMES)
    except ImportError:
        return [f"f{i:02d}" for i in range(49)]


def _objects(rng: np.random.Generator, n_rows: int, behavior: str
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None, np.ndarray]:
    """``(types, kind, size, held, rolled)`` of ``n_rows`` objects, the four types equally often in a random
    order: ``kind`` numbers the types (0 box, 1 horizontal, 2 sphere, 3 vertical), ``size`` [m] is uniform in the
    behaviour's range; for a grasp ``held`` (by the critical size) and nothing rolled, for a tap ``held`` None and
    ``rolled`` the rolling objects (95 %) and a few others (3 %)."""
    types = np.array(TYPE_ORDER)[np.arange(n_rows) % 4]  # dealt out in that order, then shuffled
    rng.shuffle(types)
    kind = np.searchsorted(np.array(sorted(OBJECT_TYPES)), types)  # 0 box, 1 horizontal, 2 sphere, 3 vertical
    size = rng.uniform(*SYNTHETIC_SIZE_RANGES[behavior], n_rows)
    held = None
    if behavior == "grasp":
        held = rng.random(n_rows) < 1.0 / (1.0 + np.exp((size - SYNTHETIC_CRITICAL_SIZE) / SYNTHETIC_GRASP_SPREAD))
        rolled = np.zeros(n_rows, dtype=bool)
    else:
        rollable = np.isin(types, ROLLING_TYPES)
        rolled = np.where(rollable, rng.random(n_rows) < 0.95, rng.random(n_rows) < 0.03)
    return types, kind, size, held, rolled


def _shape_features(rng: np.random.Generator, kind: np.ndarray, n_rows: int) -> np.ndarray:
    """(n_rows, 24) shape features: a latitude and a longitude histogram per type, 12 bins each, perturbed and
    renormalised."""
    bins = np.arange(12)
    lat_profiles = np.stack(
        [
            np.exp(-0.5 * ((bins - 11) / 0.8) ** 2)
            + np.exp(-0.5 * ((bins - 6) / 0.5) ** 2),  # box: top + sides
            np.exp(-0.5 * ((bins - 8) / 2.5) ** 2),  # lying cylinder: a band of latitudes
            np.exp(-0.5 * ((bins - 8) / 3.5) ** 2),  # sphere: every latitude facing the camera
            np.exp(-0.5 * ((bins - 6) / 0.6) ** 2)
            + 0.6 * np.exp(-0.5 * ((bins - 11) / 0.6) ** 2),  # standing
        ]
    )
    lon_profiles = np.stack(
        [
            np.exp(-0.5 * ((bins - 6) / 0.7) ** 2),
            np.exp(-0.5 * ((bins - 6) / 0.9) ** 2) + 0.3,
            np.exp(-0.5 * ((bins - 6) / 3.0) ** 2),
            np.exp(-0.5 * ((bins - 6) / 2.5) ** 2),
        ]
    )

    def histogram(profiles: np.ndarray) -> np.ndarray:
        h = profiles[kind] * rng.gamma(20.0, 1 / 20.0, (n_rows, 12))
        return h / h.sum(axis=1, keepdims=True)

    return np.hstack([histogram(lat_profiles), histogram(lon_profiles)])


def _size_features(rng: np.random.Generator, size: np.ndarray, n_rows: int) -> tuple[np.ndarray, np.ndarray]:
    """(n_rows, 18) features that depend on the size (mean position, range, pixel count, orientation, extents),
    and the pixel counts among them."""
    jitter = rng.normal(0.0, 0.02, (n_rows, 3))
    mean_xyz = np.column_stack([-0.30 + jitter[:, 0], 0.05 + jitter[:, 1], size / 2 + jitter[:, 2] * 0.1])
    mean_range = np.linalg.norm(mean_xyz - [0.0, 0.0, 0.35], axis=1)
    pixels = 2.0e4 * size**2 / mean_range**2 * rng.normal(1.0, 0.03, n_rows)
    orientation = rng.uniform(-np.pi / 2, np.pi / 2, n_rows)
    extents = (
        size[:, None]
        * rng.normal(1.0, 0.05, (n_rows, 12))
        * np.array([0.7, 0.7, 0.5, 1.0, 0.3] * 2 + [40, 40])
    )
    return np.column_stack([mean_xyz, mean_range, pixels, orientation, extents]), pixels


def _travel(rng: np.random.Generator, types: np.ndarray, held: np.ndarray | None, rolled: np.ndarray, grasp: bool
            ) -> tuple[np.ndarray, np.ndarray]:
    """How far [m] each object travels, and which leave the table."""
    n_rows = len(types)
    if grasp:  # Effects: put down 6 cm away when held, nudged by half a centimetre otherwise.
        travel = np.where(held, rng.normal(0.06, 0.004, n_rows), np.abs(rng.normal(0.005, 0.003, n_rows)))
        off_table = np.zeros(n_rows, dtype=bool)
    else:  # Effects: travel along the tap direction for rolling objects, a 1.5 cm slide otherwise.
        roll = np.where(types == "sphere", rng.uniform(0.10, 0.22, n_rows), rng.uniform(0.05, 0.20, n_rows))
        travel = np.where(rolled, roll, rng.normal(0.015, 0.003, n_rows))
        off_table = rolled & (rng.random(n_rows) < 0.03)
    return travel, off_table


def _final_and_effect(rng: np.random.Generator, initial: np.ndarray, pixels: np.ndarray, travel: np.ndarray,
                      off_table: np.ndarray, types: np.ndarray, rolled: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(final, effect)`` features: jitter, the travel's moves of the position, range, pixel count, image offsets
    and hand relation, a rolling lying cylinder's changed histogram; an object off the table is not visible, its
    final features the documented zeros."""
    effect = rng.normal(0.0, 1.0, initial.shape) * 0.01 * (np.abs(initial).mean(axis=0) + 1e-3)
    effect[:, 24] += 0.1 * travel  # mean_x
    effect[:, 25] += travel  # mean_y
    effect[:, 27] += 0.6 * travel  # mean_range
    effect[:, 28] -= pixels * 0.8 * travel  # pixel_count: seen from a little further away
    effect[:, 42:45] += np.column_stack([10, 300, 300]).ravel() * travel[:, None]  # image offsets [pixels]
    effect[:, 46] += travel  # hand_dy
    effect[:, 48] += travel  # hand_distance
    spin = np.where(types == "horizontal_cylinder", 1.0, 0.0) * rolled
    effect[:, 12:24] += 0.05 * spin[:, None] * rng.normal(0.0, 1.0, (len(types), 12))
    final = initial + effect
    final[off_table] = 0.0  # not visible: the documented zeros
    effect[off_table] = -initial[off_table]
    return final, effect
