"""The scene's one object slot: which primitive is the object, its size, mass and inertia, and where it is.

The scene holds one body ``object`` with a free joint and one geom per primitive (sphere, box, cylinder,
:data:`affordance_env.objects.PRIMITIVES`). Making an object (:class:`~affordance_env.objects.ObjectGeometry`)
turns its primitive on (collisions, the default geom group, colour), sizes it and gives the body its mass [kg] and
inertia [kg m^2] about its centre; the other primitives are hidden in :data:`HIDDEN_GEOM_GROUP` at the sizes they
were built with, so the model never depends on earlier objects. Poses are in the world frame: position [m],
orientation quaternion (w, x, y, z).
"""

from __future__ import annotations

import mujoco
import numpy as np

from affordance_env.linalg import dot, norm
from affordance_env.objects import ObjectGeometry
from affordance_env.scene_index import SceneIndex

#: Geom group that hides the scene's inactive object primitives from the range camera and the renderer.
HIDDEN_GEOM_GROUP = 3
OBJECT_RGBA = np.array([0.85, 0.2, 0.15, 1.0])
#: Collision bits of the active object (assets/scene.xml): type 1, takes surfaces (1) and the hand (2).
OBJECT_CONTYPE, OBJECT_CONAFFINITY = 1, 3


class ObjectSlot:
    """Swaps the object in ``model``, places it in ``data`` and tells where it is.

    Args:
        model: The scene's model, changed in place by :meth:`make`.
        data: The simulated state.
        scratch: Data that :meth:`make` may reset (``mj_setConst`` resets the state it is given); never the
            simulated state.
        index: The scene's named elements.
        table_top: Height of the table top [m].
        table_low: Lower corner of the table top in world x, y [m].
        table_high: Upper corner of the table top in world x, y [m].
    """

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, scratch: mujoco.MjData, index: SceneIndex,
                 table_top: float, table_low: np.ndarray, table_high: np.ndarray) -> None:
        self.model, self.data, self.scratch = model, data, scratch
        self.object_body, self.object_geoms = index.object_body, index.object_geoms
        self.object_qpos, self.object_qvel = index.object_qpos, index.object_qvel
        self.table_top, self.table_low, self.table_high = table_top, table_low, table_high
        #: The object's active primitive (a geom id) and its geometry (None until :meth:`make`).
        self.active_geom = self.object_geoms["sphere"]
        self.geometry: ObjectGeometry | None = None
        # Inactive primitives keep these sizes, so the model never depends on earlier objects.
        self._hidden_size = {p: model.geom_size[g].copy() for p, g in self.object_geoms.items()}
        self._hidden_aabb = {p: model.geom_aabb[g].copy() for p, g in self.object_geoms.items()}
        self._hidden_rbound = {p: float(model.geom_rbound[g]) for p, g in self.object_geoms.items()}

    def make(self, geometry: ObjectGeometry) -> int:
        """Make ``geometry`` the object in the model (its primitive, size, mass and inertia), without touching the
        state; returns its primitive's geom id."""
        m = self.model
        for primitive, g in self.object_geoms.items():
            active = primitive == geometry.primitive
            m.geom_contype[g] = OBJECT_CONTYPE if active else 0
            m.geom_conaffinity[g] = OBJECT_CONAFFINITY if active else 0
            m.geom_group[g] = 0 if active else HIDDEN_GEOM_GROUP
            m.geom_rgba[g] = OBJECT_RGBA if active else 0.0
            if not active:
                m.geom_size[g] = self._hidden_size[primitive]
                m.geom_aabb[g] = self._hidden_aabb[primitive]
                m.geom_rbound[g] = self._hidden_rbound[primitive]
        g = self.object_geoms[geometry.primitive]
        m.geom_size[g] = geometry.geom_size
        m.geom_rbound[g] = geometry.rbound
        half = geometry.geom_size if geometry.primitive == "box" else (
            np.full(3, geometry.geom_size[0]) if geometry.primitive == "sphere"
            else np.array([geometry.geom_size[0], geometry.geom_size[0], geometry.geom_size[1]])
        )
        m.geom_aabb[g] = np.concatenate([np.zeros(3), half])
        m.body_mass[self.object_body] = geometry.mass
        m.body_inertia[self.object_body] = geometry.inertia
        m.body_ipos[self.object_body] = 0.0
        m.body_iquat[self.object_body] = [1.0, 0.0, 0.0, 0.0]
        self.active_geom = g
        self.geometry = geometry
        mujoco.mj_setConst(m, self.scratch)  # on scratch data: it resets the state it is given to qpos0
        return g

    def place(self, geometry: ObjectGeometry, xy: np.ndarray, yaw: float) -> None:
        """Put the object made of ``geometry`` at rest on the table, 0.1 mm above it, and recompute the derived
        quantities (``mj_forward``).

        Args:
            geometry: The object's geometry (:meth:`make` made it the object).
            xy: Position of the object's centre on the table, world x and y [m].
            yaw: Rotation about the vertical axis [rad], after the geometry's resting orientation.
        """
        quat_yaw = np.array([np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2)])
        quat = np.empty(4)
        mujoco.mju_mulQuat(quat, quat_yaw, geometry.quat_rest)
        a = self.object_qpos
        self.data.qpos[a : a + 3] = [xy[0], xy[1], self.table_top + geometry.half_height + 1e-4]
        self.data.qpos[a + 3 : a + 7] = quat
        self.data.qvel[self.object_qvel : self.object_qvel + 6] = 0.0
        mujoco.mj_forward(self.model, self.data)

    def set_pose(self, pose: np.ndarray) -> None:
        """Put the object at ``pose`` (x, y, z [m], unit quaternion w, x, y, z), at rest, and recompute the derived
        quantities (``mj_forward``)."""
        a = self.object_qpos
        self.data.qpos[a : a + 7] = pose
        self.data.qvel[self.object_qvel : self.object_qvel + 6] = 0.0
        mujoco.mj_forward(self.model, self.data)

    # --- where it is -----------------------------------------------------------------------------------------
    def pose(self) -> np.ndarray:
        """Object pose: position [m] and orientation quaternion (w, x, y, z), (7,)."""
        a = self.object_qpos
        return self.data.qpos[a : a + 7].copy()

    def speed(self) -> float:
        """Linear speed of the object [m/s]."""
        v = self.data.qvel[self.object_qvel : self.object_qvel + 3]
        return norm(v)

    def angular_speed(self) -> float:
        """Angular speed of the object [rad/s]."""
        w = self.data.qvel[self.object_qvel + 3 : self.object_qvel + 6]
        return norm(w)

    def on_table(self) -> bool:
        """Whether the object's centre is above the table top and within its extent."""
        p = self.data.qpos[self.object_qpos : self.object_qpos + 3]
        return bool(p[2] > self.table_top and np.all(p[:2] >= self.table_low) and np.all(p[:2] <= self.table_high))

    def bottom(self) -> float:
        """Height of the object's lowest point [m], from its primitive's size and its orientation now."""
        g, geometry = self.active_geom, self.geometry
        R = self.data.geom_xmat[g].reshape(3, 3)
        size, z = geometry.geom_size, float(self.data.geom_xpos[g, 2])
        if geometry.primitive == "sphere":
            return z - float(size[0])
        if geometry.primitive == "box":
            return z - dot(np.abs(R[2]), size)
        axis_z = abs(float(R[2, 2]))  # a cylinder: its axis's vertical part, and its rim's
        return z - axis_z * float(size[1]) - float(size[0]) * float(np.sqrt(max(0.0, 1.0 - axis_z * axis_z)))
