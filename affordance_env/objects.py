"""The objects of the paper: sphere, box, lying ("horizontal") and standing ("vertical") cylinder.

Pure geometry: the primitive, its MuJoCo size vector, its orientation and its mass properties for an object of
one type and one size. The simulator side (:mod:`affordance_env.physics`) applies these to the model.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from affordance_env.exceptions import InvalidValueError
from affordance_env.linalg import norm

#: Object types, as named in the paper.
OBJECT_TYPES: tuple[str, ...] = ("sphere", "box", "horizontal_cylinder", "vertical_cylinder")
#: The types that roll when tapped (a sphere, a cylinder lying across the stroke); the others rest. The paper's
#: tap affordance, which the learning reads as ground truth.
ROLLING_TYPES: tuple[str, ...] = ("sphere", "horizontal_cylinder")
#: Which primitive geom of the scene's ``object`` body each type uses.
PRIMITIVE_OF_TYPE: dict[str, str] = {
    "sphere": "sphere",
    "box": "box",
    "horizontal_cylinder": "cylinder",
    "vertical_cylinder": "cylinder",
}
PRIMITIVES: tuple[str, ...] = ("sphere", "box", "cylinder")
#: Density of every object [kg/m^3] (light wood).
DENSITY = 300.0
#: Sizes the iCub hand can tap [m]: the characteristic size is the sphere's diameter, the box's edge and the
#: cylinder's diameter (its length equals its diameter).
SIZE_LIMITS = (0.02, 0.15)


def check_object_type(object_type: str) -> str:
    """Return ``object_type`` if it is one of :data:`OBJECT_TYPES`, else raise a ValueError listing them."""
    if object_type not in OBJECT_TYPES:
        raise InvalidValueError(f"Unknown object type {object_type!r}. Valid types: {', '.join(OBJECT_TYPES)}.")
    return object_type


def check_size(size: float) -> float:
    """Return ``size`` [m] as float if it is finite and within :data:`SIZE_LIMITS`, else raise ValueError."""
    try:
        size_f = float(size)
    except (TypeError, ValueError):
        size_f = float("nan")
    if isinstance(size, bool | str) or not np.isfinite(size_f) or size_f <= 0:
        raise InvalidValueError(f"Object size must be a positive length in metres, got {size!r}.")
    if not SIZE_LIMITS[0] <= size_f <= SIZE_LIMITS[1]:
        raise InvalidValueError(
            f"Object size {size_f} m is outside the range the hand can tap, {SIZE_LIMITS[0]}-{SIZE_LIMITS[1]} m."
        )
    return size_f


@dataclass(frozen=True)
class ObjectGeometry:
    """Geometry of one object.

    Attributes:
        object_type: One of :data:`OBJECT_TYPES`.
        size: Characteristic size [m].
        primitive: ``sphere``, ``box`` or ``cylinder``.
        geom_size: MuJoCo ``size`` of the primitive [m] (radius / half-extents / radius and half-length), (3,).
        quat_rest: Orientation of the object body at zero yaw (w, x, y, z); the primitive's own axes are the
            body's, so a lying cylinder is a standing one turned by 90 degrees about world y.
        half_height: Height of the object's centre above the table when resting [m].
        half_width: Half of the object's extent along the tap direction (world y at zero yaw) [m].
        mass: [kg].
        inertia: Principal moments of inertia about the geom axes [kg m^2], (3,).
        rbound: Bounding-sphere radius [m].
    """

    object_type: str
    size: float
    primitive: str
    geom_size: np.ndarray
    quat_rest: np.ndarray
    half_height: float
    half_width: float
    mass: float
    inertia: np.ndarray
    rbound: float


def object_geometry(object_type: str, size: float) -> ObjectGeometry:
    """Geometry of an object of ``object_type`` with characteristic ``size`` [m]."""
    object_type = check_object_type(object_type)
    size = check_size(size)
    r = size / 2.0
    identity = np.array([1.0, 0.0, 0.0, 0.0])
    if object_type == "sphere":
        mass = DENSITY * 4.0 / 3.0 * np.pi * r**3
        inertia = np.full(3, 0.4 * mass * r**2)
        return ObjectGeometry(object_type, size, "sphere", np.array([r, 0.0, 0.0]), identity, r, r, mass,
                              inertia, r)
    if object_type == "box":
        mass = DENSITY * size**3
        inertia = np.full(3, mass * (2 * r**2) / 3.0)
        return ObjectGeometry(object_type, size, "box", np.array([r, r, r]), identity, r, r, mass, inertia,
                              float(np.sqrt(3) * r))
    # Cylinders: radius r, half-length r (length equals diameter).
    mass = DENSITY * np.pi * r**2 * size
    i_axis = 0.5 * mass * r**2
    i_across = mass * (3 * r**2 + size**2) / 12.0
    inertia = np.array([i_across, i_across, i_axis])
    if object_type == "horizontal_cylinder":
        # Axis along world x: across the tap direction (the hand moves along -y), so the cylinder can roll.
        quat = np.array([np.sqrt(0.5), 0.0, np.sqrt(0.5), 0.0])
    else:
        quat = identity
    return ObjectGeometry(object_type, size, "cylinder", np.array([r, r, 0.0]), quat, r, r, mass, inertia,
                          float(np.sqrt(2) * r))


#: An object whose primitive axis is within this angle of the vertical stands [rad]; beyond it, it lies.
STANDING_TILT = np.pi / 4


def as_resting(geometry: ObjectGeometry, quat: np.ndarray) -> tuple[ObjectGeometry, float]:
    """The geometry and yaw [rad] that a plan should use for ``geometry`` resting in orientation ``quat`` (w, x, y,
    z): a standing cylinder that toppled is planned for as a lying one, along the axis it lies on, and a box by the
    yaw of its faces. The shapes are such that the height above the table does not change (cylinders as long as
    they are wide, boxes cubes); what changes is the extent across a stroke and the hand's turn over a grasp."""
    q = np.asarray(quat, dtype=float)
    if q.shape != (4,) or not np.all(np.isfinite(q)) or norm(q) == 0.0:
        raise InvalidValueError(f"quat must be a finite, non-zero quaternion (w, x, y, z), got {quat!r}.")
    w, x, y, z = q / norm(q)
    R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                  [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                  [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    if geometry.primitive == "sphere":
        return geometry, 0.0
    if geometry.primitive == "box":  # the body axis nearest the horizontal plane gives the faces' yaw
        axis = R[:, int(np.argmin(np.abs(R[2])))]
        return geometry, float(np.arctan2(axis[1], axis[0]))
    axis = R[:, 2]  # a cylinder's axis is its primitive's z
    if abs(axis[2]) >= np.cos(STANDING_TILT):
        return (geometry if geometry.object_type == "vertical_cylinder"
                else object_geometry("vertical_cylinder", geometry.size)), 0.0
    lying = geometry if geometry.object_type == "horizontal_cylinder" else object_geometry("horizontal_cylinder",
                                                                                            geometry.size)
    # At zero yaw a lying cylinder's axis is along world x.
    return lying, float(np.arctan2(axis[1], axis[0]))
