"""The table top's extent, read from ``assets/scene.xml`` as XML: no MuJoCo, no compiled scene.

:func:`affordance_env.scene.table_extent` compiles the table scene to read it; code that needs where the table is
but not the simulator (a planner choosing actions from its effect models) reads the same numbers here: the
``table_top`` geom's position (its bodies' positions plus its own) and half-sizes. The scene places the table
without rotating it; a rotation anywhere on the way is an error here, not a different answer.
"""

from __future__ import annotations

import functools
import xml.etree.ElementTree as ElementTree

import numpy as np

from affordance_env.assets_path import assets_dir
from affordance_env.exceptions import InvalidValueError

#: The name of the table top's geom in ``assets/scene.xml``.
TABLE_GEOM = "table_top"
_ROTATIONS = ("quat", "axisangle", "euler", "xyaxes", "zaxis")


def _vector(element: ElementTree.Element, name: str, default: str) -> np.ndarray:
    return np.array([float(v) for v in element.get(name, default).split()], dtype=np.float64)


@functools.cache
def table_extent() -> tuple[tuple[float, float], tuple[float, float]]:
    """The (lower, upper) corners (x, y) [m] of the table top of ``assets/scene.xml`` in the robot's root frame:
    what :func:`affordance_env.scene.table_extent` gives, read from the XML (once per process)."""
    path = assets_dir() / "scene.xml"
    root = ElementTree.parse(path).getroot()
    parents = {child: parent for parent in root.iter() for child in parent}
    geom = root.find(f".//worldbody//geom[@name='{TABLE_GEOM}']")
    if geom is None or geom.get("type") != "box" or geom.get("size") is None:
        raise InvalidValueError(f"{path} has no box geom {TABLE_GEOM!r} with its size: read the table with "
                         "affordance_env.scene.table_extent.")
    chain = [geom]
    while parents[chain[-1]].tag != "worldbody":
        chain.append(parents[chain[-1]])
    rotated = [f"{e.tag} {e.get('name')!r}" for e in chain if any(e.get(r) is not None for r in _ROTATIONS)]
    if rotated:
        raise InvalidValueError(f"{path}: {', '.join(rotated)} rotated; read the table with "
                         "affordance_env.scene.table_extent.")
    centre = np.zeros(3)
    for element in reversed(chain):  # the world's outermost body first, as MuJoCo composes the positions
        centre = centre + _vector(element, "pos", "0 0 0")
    half = _vector(geom, "size", "")
    return tuple(map(float, centre[:2] - half[:2])), tuple(map(float, centre[:2] + half[:2]))


__all__ = ["TABLE_GEOM", "table_extent"]
