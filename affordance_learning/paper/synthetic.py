"""Frames in the dataset schema made without the simulator, for tests, benchmarks and demonstrations: taps, where
spheres and lying cylinders roll and boxes and standing cylinders do not, or grasps, where objects smaller than a
critical size are held and larger ones are not."""

from __future__ import annotations

import numbers
from typing import Any

import numpy as np
import pandas as pd

from affordance_learning.common.exceptions import InvalidValueError
from affordance_learning.common.schema import OBJECT_TYPES

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
    if isinstance(n_rows, bool) or not isinstance(n_rows, numbers.Integral) or n_rows < 8:
        raise InvalidValueError(f"n_rows must be an integer >= 8, got {n_rows!r}.")
    if behavior not in SYNTHETIC_SIZE_RANGES:
        raise InvalidValueError(f"behavior must be one of {tuple(SYNTHETIC_SIZE_RANGES)}, got {behavior!r}.")
    grasp = behavior == "grasp"
    try:
        from affordance_env.features import FEATURE_NAMES

        names = list(FEATURE_NAMES)
    except ImportError:
        names = [f"f{i:02d}" for i in range(49)]
    rng = np.random.default_rng(random_state)
    types = np.array(OBJECT_TYPES)[np.arange(n_rows) % 4]
    rng.shuffle(types)
    size = rng.uniform(*SYNTHETIC_SIZE_RANGES[behavior], n_rows)
    if grasp:
        held = rng.random(n_rows) < 1.0 / (1.0 + np.exp((size - SYNTHETIC_CRITICAL_SIZE) / SYNTHETIC_GRASP_SPREAD))
        rolled = np.zeros(n_rows, dtype=bool)
    else:
        rollable = np.isin(types, ("sphere", "horizontal_cylinder"))
        held, rolled = None, np.where(rollable, rng.random(n_rows) < 0.95, rng.random(n_rows) < 0.03)
    initial, pixels = _initial_features(rng, types, size)
    travel, off_table = _travel(rng, types, held, rolled)
    final, effect = _effects(rng, initial, pixels, travel, types, rolled, off_table)

    columns: dict[str, Any] = {}
    for prefix, values in (("initial_", initial), ("final_", final), ("effect_", effect)):
        columns.update({f"{prefix}{n}": values[:, j] for j, n in enumerate(names)})
    columns.update({"behavior": np.full(n_rows, behavior), "type": types, "size": size, "rolled": rolled,
                    "success": held if grasp else rolled, "displacement": np.abs(travel),
                    "rolling_distance": np.where(rolled, np.abs(travel), 0.0), "visible_final": ~off_table,
                    "outcome": np.where(off_table, "off_table", "rest")})
    return pd.DataFrame(columns)


def _initial_features(rng: np.random.Generator, types: np.ndarray, size: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The 49 initial features of each object, and its pixel count: shape features (a latitude and a longitude
    histogram per type, 12 bins each, perturbed and renormalised) by type, size features by size, relation
    features as jitter."""
    n_rows = len(types)
    kind = np.searchsorted(np.array(sorted(OBJECT_TYPES)), types)  # 0 box, 1 horizontal, 2 sphere, 3 vertical
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

    shape = np.hstack([histogram(lat_profiles), histogram(lon_profiles)])
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
    size_features = np.column_stack([mean_xyz, mean_range, pixels, orientation, extents])
    relation = rng.normal(0.0, 1.0, (n_rows, 7)) * np.array([5, 5, 7, 0.02, 0.02, 0.02, 0.03])
    return np.hstack([shape, size_features, relation]), pixels


def _travel(rng: np.random.Generator, types: np.ndarray, held: np.ndarray | None,
            rolled: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """How far each object travels [m], and whether it left the table. A grasp (``held`` given): put down 6 cm
    away when held, nudged by half a centimetre otherwise. A tap: along the tap direction for rolling objects, 3 %
    of which leave the table, a 1.5 cm slide otherwise."""
    n_rows = len(types)
    if held is not None:
        travel = np.where(held, rng.normal(0.06, 0.004, n_rows), np.abs(rng.normal(0.005, 0.003, n_rows)))
        return travel, np.zeros(n_rows, dtype=bool)
    roll = np.where(types == "sphere", rng.uniform(0.10, 0.22, n_rows), rng.uniform(0.05, 0.20, n_rows))
    travel = np.where(rolled, roll, rng.normal(0.015, 0.003, n_rows))
    return travel, rolled & (rng.random(n_rows) < 0.03)


def _effects(rng: np.random.Generator, initial: np.ndarray, pixels: np.ndarray, travel: np.ndarray,
             types: np.ndarray, rolled: np.ndarray, off_table: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The final features and the effects: noise, the travel seen in position, range, pixel count, image offsets
    and the hand's relation, a lying cylinder's spin in its longitude histogram; an object off the table is not
    seen (final features all zeros, its effect minus its initial features)."""
    n_rows = len(types)
    effect = rng.normal(0.0, 1.0, initial.shape) * 0.01 * (np.abs(initial).mean(axis=0) + 1e-3)
    effect[:, 24] += 0.1 * travel  # mean_x
    effect[:, 25] += travel  # mean_y
    effect[:, 27] += 0.6 * travel  # mean_range
    effect[:, 28] -= pixels * 0.8 * travel  # pixel_count: seen from a little further away
    effect[:, 42:45] += np.column_stack([10, 300, 300]).ravel() * travel[:, None]  # image offsets [pixels]
    effect[:, 46] += travel  # hand_dy
    effect[:, 48] += travel  # hand_distance
    spin = np.where(types == "horizontal_cylinder", 1.0, 0.0) * rolled
    effect[:, 12:24] += 0.05 * spin[:, None] * rng.normal(0.0, 1.0, (n_rows, 12))
    final = initial + effect
    final[off_table] = 0.0  # not visible: the documented zeros
    effect[off_table] = -initial[off_table]
    return final, effect
