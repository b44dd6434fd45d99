"""Where on the table each behaviour can act: its workspace, a convex polygon of object positions.

Measured by ``python benchmarks/workspace.py``: the canonical action of the behaviour is reachable by the arm's
inverse kinematics for every object type at the smallest and the largest size (4 and 10 cm) at every grid cell
(2.5 cm) inside the polygon. Pure geometry: nothing here needs the simulator.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

#: Vertices (x, y) [m], root frame, of each behaviour's workspace, counter-clockwise.
WORKSPACES: Mapping[str, tuple[tuple[float, float], ...]] = {
    "tap": (  # 233 cells
        (-0.172, -0.062), (-0.172, 0.263), (-0.297, 0.263), (-0.397, 0.213), (-0.472, 0.138), (-0.497, 0.088),
        (-0.497, -0.062), (-0.472, -0.112), (-0.422, -0.187), (-0.397, -0.212), (-0.297, -0.262), (-0.247, -0.212),
    ),
    "tap_back": (  # 235 cells
        (-0.172, 0.013), (-0.172, 0.313), (-0.197, 0.338), (-0.272, 0.338), (-0.347, 0.313), (-0.397, 0.288),
        (-0.472, 0.213), (-0.497, 0.163), (-0.497, 0.013), (-0.447, -0.087), (-0.372, -0.162), (-0.322, -0.187),
        (-0.272, -0.187),
    ),
    "push": (  # 144 cells
        (-0.172, -0.237), (-0.172, 0.088), (-0.222, 0.138), (-0.247, 0.138), (-0.297, 0.113), (-0.322, 0.088),
        (-0.372, 0.013), (-0.397, -0.062), (-0.397, -0.112), (-0.372, -0.212), (-0.272, -0.312), (-0.222, -0.312),
        (-0.197, -0.287),
    ),
    "grasp": (  # 182 cells
        (-0.422, 0.238), (-0.497, 0.113), (-0.472, 0.063), (-0.422, -0.012), (-0.397, -0.037), (-0.347, -0.062),
        (-0.197, -0.062), (-0.172, -0.037), (-0.172, 0.288), (-0.222, 0.363), (-0.272, 0.363), (-0.322, 0.338),
    ),
}


def _check_name(name: str) -> None:
    if name not in WORKSPACES:
        raise ValueError(f"Unknown behavior {name!r}. Valid behaviors: {', '.join(WORKSPACES)}.")


def in_workspace(name: str, xy: np.ndarray) -> np.ndarray | bool:
    """Whether the points ``xy`` [m], (2,) or (N, 2), lie in the workspace of the behaviour ``name``."""
    _check_name(name)
    p = np.asarray(xy, dtype=float)
    polygon = np.asarray(WORKSPACES[name])
    edges = np.roll(polygon, -1, axis=0) - polygon
    rel = p[..., None, :] - polygon  # (..., V, 2)
    cross = edges[:, 0] * rel[..., 1] - edges[:, 1] * rel[..., 0]
    inside = np.all(cross >= -1e-12, axis=-1)
    return bool(inside) if inside.ndim == 0 else inside


def in_any_workspace(xy: np.ndarray) -> np.ndarray | bool:
    """Whether the points ``xy`` [m] lie in the workspace of at least one behaviour."""
    inside = np.any([in_workspace(name, xy) for name in WORKSPACES], axis=0)
    return bool(inside) if np.ndim(inside) == 0 else inside


def sample_in_workspace(name: str, rng: np.random.Generator) -> np.ndarray:
    """A point (x, y) [m] uniform in the workspace of the behaviour ``name``, drawn from ``rng``."""
    _check_name(name)
    polygon = np.asarray(WORKSPACES[name])
    low, high = polygon.min(axis=0), polygon.max(axis=0)
    while True:  # rejection from the bounding box: the polygons fill half of it or more
        xy = rng.uniform(low, high)
        if in_workspace(name, xy):
            return xy
