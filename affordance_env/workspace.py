"""Where on the table each behaviour can act: its workspace, a set of grid cells of object positions.

Measured by ``python benchmarks/workspace.py`` in the scene with both arms: a cell (``SPACING`` square) is in a
behaviour's workspace when the canonical action of the behaviour is reachable by the arm's inverse kinematics for
every object type at the smallest and the largest size (4 and 10 cm) and at the yaws the env draws (0, +-0.25 rad),
and the head, attending, sees each of them there. Whether a stroke's reach sweeps the arm through a particular
object is not part of it: ``feasible()`` asks that per object and action. Each workspace is stored as runs of cells
along y. Pure geometry: nothing here needs the simulator.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping

import numpy as np

from affordance_env.exceptions import InvalidValueError

#: The side of a cell [m].
SPACING = 0.025
#: Each behaviour's workspace: runs of cells (x, y_first, y_last), the centres [m] (root frame) of the run's cells
#: along y at that x.
WORKSPACES: Mapping[str, tuple[tuple[float, float, float], ...]] = {
    "tap": (  # 209 cells
        (-0.4975, -0.0625, 0.0625), (-0.4725, -0.1125, 0.1125), (-0.4475, -0.1375, 0.1625), (-0.4225, -0.1625, 0.1875),
        (-0.3975, -0.1875, 0.1875), (-0.3725, -0.2125, 0.2125), (-0.3475, -0.2125, 0.2375), (-0.3225, -0.2375, 0.2375),
        (-0.2975, -0.2375, 0.2375), (-0.2725, -0.2125, 0.2125), (-0.2475, -0.1875, 0.2125), (-0.2225, -0.1375, 0.1875),
        (-0.1975, -0.0875, 0.1875), (-0.1725, -0.0625, 0.1875),
    ),
    "tap_back": (  # 191 cells
        (-0.4975, 0.0125, 0.1375), (-0.4725, -0.0375, 0.1875), (-0.4475, -0.0625, 0.2375), (-0.4225, -0.0875, 0.2375),
        (-0.3975, -0.1125, 0.2625), (-0.3725, -0.1375, 0.2875), (-0.3475, -0.1625, 0.2875), (-0.3225, -0.1625, 0.2625),
        (-0.2975, -0.1875, 0.2375), (-0.2725, -0.1625, 0.2125), (-0.2475, -0.1375, 0.2125), (-0.2225, -0.0625, 0.1875),
        (-0.1975, -0.0125, 0.1875), (-0.1725, 0.0125, 0.1875),
    ),
    "push": (  # 114 cells
        (-0.3725, -0.1875, -0.0125), (-0.3475, -0.2375, 0.0375), (-0.3225, -0.2625, 0.0625), (-0.2975, -0.2375, 0.0875),
        (-0.2725, -0.2125, 0.1125), (-0.2475, -0.2125, 0.1125), (-0.2225, -0.1875, 0.1125), (-0.1975, -0.1875, 0.1125),
        (-0.1725, -0.1875, 0.0875),
    ),
    "grasp": (  # 81 cells
        (-0.3975, 0.0875, 0.0875), (-0.3725, 0.0375, 0.1875), (-0.3475, 0.0125, 0.2375), (-0.3225, 0.0125, 0.2625),
        (-0.2975, 0.0125, 0.2375), (-0.2725, 0.0125, 0.2125), (-0.2475, -0.0125, 0.2125), (-0.2225, -0.0125, 0.1875),
        (-0.1975, -0.0125, 0.1625), (-0.1725, 0.0125, 0.1375),
    ),
    "draw": (  # 91 cells
        (-0.3475, -0.0625, -0.0625), (-0.3225, -0.1625, 0.0375), (-0.2975, -0.1875, 0.1125), (-0.2725, -0.2125, 0.1375),
        (-0.2475, -0.2125, 0.1625), (-0.2225, -0.1375, 0.1625), (-0.1975, -0.1125, 0.1875), (-0.1725, -0.0625, 0.1875),
    ),
}


def _check_name(name: str) -> None:
    if name not in WORKSPACES:
        raise InvalidValueError(f"Unknown behavior {name!r}. Valid behaviors: {', '.join(WORKSPACES)}.")


@functools.cache
def _rectangles(names: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray]:
    """The lower and upper corners (R, 2) of the rectangles the runs of the workspaces ``names`` cover."""
    runs = np.array([run for name in names for run in WORKSPACES[name]])
    low = np.stack([runs[:, 0], runs[:, 1]], axis=1) - SPACING / 2
    high = np.stack([runs[:, 0], runs[:, 2]], axis=1) + SPACING / 2
    return low, high


def _inside(names: tuple[str, ...], xy: np.ndarray) -> np.ndarray | bool:
    low, high = _rectangles(names)
    p = np.asarray(xy, dtype=float)[..., None, :]
    inside = np.any(np.all((p >= low) & (p <= high), axis=-1), axis=-1)
    return bool(inside) if inside.ndim == 0 else inside


def in_workspace(name: str, xy: np.ndarray) -> np.ndarray | bool:
    """Whether the points ``xy`` [m], (2,) or (N, 2), lie in the workspace of the behaviour ``name``."""
    _check_name(name)
    return _inside((name,), xy)


def in_any_workspace(xy: np.ndarray) -> np.ndarray | bool:
    """Whether the points ``xy`` [m] lie in the workspace of at least one behaviour."""
    return _inside(tuple(WORKSPACES), xy)


def sample_in_workspace(name: str | None, rng: np.random.Generator) -> np.ndarray:
    """A point (x, y) [m] uniform in the workspace of the behaviour ``name``, drawn from ``rng``; None: in the
    workspace of a behaviour drawn uniformly, so that every behaviour can act on as many of the objects placed so
    (the draw's workspace, near the robot, is a third of the union)."""
    if name is None:
        name = tuple(WORKSPACES)[int(rng.integers(len(WORKSPACES)))]
    _check_name(name)
    low, high = _rectangles((name,))
    area = np.prod(high - low, axis=1)
    k = int(rng.choice(len(area), p=area / area.sum()))  # a run by its area, a point in it
    return rng.uniform(low[k], high[k])
