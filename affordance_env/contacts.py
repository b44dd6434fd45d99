"""Contacts and clearances between the robot, the object and the table top.

The robot's geoms that touch the world (hand, fingers, wrist, forearm, and an arm held still fused into the body
it hangs from) against the object's active primitive and the table top: which of them touch (MuJoCo's contacts of
the last step) and how far apart they are (MuJoCo's ``mj_geomDistance``) [m], in the world frame.

Several of these are asked at every control tick or physics step of a stroke near the object: they loop in plain
Python over a handful of geoms and contacts, cheaper there than numpy's per-call overhead, and give the same
answers, bit for bit, as the numpy expressions their docstrings name.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from affordance_env.scene import ROBOT_CONAFFINITY, ROBOT_CONTYPE
from affordance_env.scene_index import SceneIndex, as_slice


class ContactQueries:
    """Contact and distance queries of the simulated state ``data`` (and of ``scratch``, for other configurations).

    Args:
        model: The scene's model.
        data: The simulated state.
        scratch: Data for kinematics of other configurations (:meth:`sweep_clearance`); never the simulated state.
        index: The scene's named elements.

    :attr:`active_geom` is the object's geom the queries ask about; whoever changes the object sets it.
    """

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, scratch: mujoco.MjData, index: SceneIndex) -> None:
        self.model, self.data, self.scratch = model, data, scratch
        self.robot_qpos, self.table_geom, self.body_names = index.robot_qpos, index.table_geom, index.body_names
        #: The object's active primitive (a geom id).
        self.active_geom = index.object_geoms["sphere"]
        # The robot's geoms that touch the world: those of its contact links, of an arm held still too (fused into
        # the body it hangs from).
        self.hand_geoms = np.array([g for g in range(model.ngeom) if model.geom_bodyid[g] != index.object_body
                                    and (model.geom_contype[g], model.geom_conaffinity[g])
                                    == (ROBOT_CONTYPE, ROBOT_CONAFFINITY)])
        self._is_hand_geom = np.zeros(model.ngeom, dtype=bool)
        self._is_hand_geom[self.hand_geoms] = True
        self._hand_geom_list = self.hand_geoms.tolist()
        self._hand_geom_set = frozenset(self._hand_geom_list)
        self._hand_rows = as_slice(self.hand_geoms)  # their rows of geom_xpos: a view where consecutive
        #: Bounding-sphere radius of each of them [m], as Python floats: the distance checks of every control
        #: tick run in plain Python over a handful of geoms, cheaper than numpy's per-call overhead.
        self._hand_rbound = model.geom_rbound[self.hand_geoms].tolist()
        #: The largest distance [m] at which MuJoCo may make a contact between bounding spheres: their margin
        #: (of a geom, or of an explicit pair); infinite if one of those geoms has no bounding sphere, which
        #: MuJoCo's test then skips (:meth:`arm_near_or_touching`).
        margins = [*model.geom_margin.tolist(), *model.pair_margin.tolist()]
        self._contact_margin = max(margins) if all(r > 0 for r in self._hand_rbound) else math.inf
        #: geom_xpos of the simulated state and every geom's bounding radius: views, current whatever the state
        #: (set_state copies into the same arrays) or the object (set_object writes into the model's)
        self._geom_xpos, self._geom_rbound = data.geom_xpos, model.geom_rbound

    # --- contacts of the last step ------------------------------------------------------------------------------
    def hand_touches_object(self) -> bool:
        """Whether any contact joins the hand (or wrist, forearm) and the object."""
        data = self.data
        if data.ncon == 0:
            return False
        obj, hand = self.active_geom, self._hand_geom_set
        # a few contacts (data.contact holds the ncon of them): plain Python and a set are fastest, asked at every
        # physics step of a stroke near the object
        for g1, g2 in data.contact.geom.tolist():
            if (g1 == obj and g2 in hand) or (g2 == obj and g1 in hand):
                return True
        return False

    def hand_touches_table(self) -> bool:
        """Whether any contact joins the hand (or wrist, forearm, fingers) and the table top."""
        table, hand = self.table_geom, self._hand_geom_set
        for g1, g2 in self.data.contact.geom.tolist():  # data.contact holds the ncon contacts
            if (g1 == table and g2 in hand) or (g2 == table and g1 in hand):
                return True
        return False

    def object_touches_table(self) -> bool:
        """Whether any contact joins the object and the table top."""
        obj, table = self.active_geom, self.table_geom  # two different geoms
        for g1, g2 in self.data.contact.geom.tolist():  # asked at every control tick of a grasp's put-down
            if (g1 == obj and g2 == table) or (g1 == table and g2 == obj):
                return True
        return False

    def links_touching_object(self) -> set[str]:
        """Names of the robot links (of the variant's contact links) in contact with the object."""
        return self._links_touching(self.active_geom)

    def links_touching_table(self) -> set[str]:
        """Names of the robot links (of the variant's contact links) in contact with the table top."""
        return self._links_touching(self.table_geom)

    def _links_touching(self, geom: int) -> set[str]:
        """Names of the robot links (of the variant's contact links) in contact with ``geom``."""
        links = set()
        hand = self._is_hand_geom
        for g1, g2 in self.data.contact.geom[: self.data.ncon].tolist():
            if g1 == geom and hand[g2]:
                links.add(self.body_names[self.model.geom_bodyid[g2]])
            elif g2 == geom and hand[g1]:
                links.add(self.body_names[self.model.geom_bodyid[g1]])
        return links

    # --- distances ----------------------------------------------------------------------------------------------
    def hand_object_distance(self, max_distance: float) -> float:
        """Smallest distance between the hand (wrist, forearm) and the object [m], from the kinematics of the last
        step (MuJoCo's ``mj_geomDistance``); ``max_distance`` if they are at least that far apart."""
        model, data, obj = self.model, self.data, self.active_geom
        return min(mujoco.mj_geomDistance(model, data, g, obj, max_distance, None) for g in self._hand_geom_list)

    def arm_object_distance(self, max_distance: float, data: mujoco.MjData | None = None) -> float:
        """Smallest distance between the robot's geoms that touch the world (hand, fingers, wrist, forearm) and
        the object [m] (in ``data``, by default the simulated state); ``max_distance`` if they are at least that far
        apart. Geoms whose bounding spheres are that far from the object's are not measured further."""
        data = self.data if data is None else data
        near = self._hand_geoms_near(data, max_distance)
        if not near:
            return max_distance
        model, obj = self.model, self.active_geom
        return min(mujoco.mj_geomDistance(model, data, g, obj, max_distance, None) for g in near)

    def arm_near_object(self, max_distance: float) -> bool:
        """Whether :meth:`arm_object_distance` (of the simulated state) is below ``max_distance`` [m]: the same
        answer, measuring only until a geom is found that near."""
        return self._any_nearer(self._hand_geoms_near(self.data, max_distance), max_distance)

    def arm_near_or_touching(self, max_distance: float) -> tuple[bool, bool]:
        """``(arm_near_object(max_distance), hand_touches_object())``, the contacts read only where they can be.

        MuJoCo makes no contact between two geoms whose bounding spheres are farther apart than their margin, so
        while no geom's bounding sphere is within ``max_distance`` of the object's (and ``max_distance`` exceeds
        every margin of the model), the hand cannot touch the object: both answers are False without reading the
        contacts. What watches the arm at every control tick asks this."""
        near = self._hand_geoms_near(self.data, max_distance)
        if not near and max_distance > self._contact_margin:
            return False, False
        return self._any_nearer(near, max_distance), self.hand_touches_object()

    def _any_nearer(self, geoms: list[int], max_distance: float) -> bool:
        """Whether ``min`` of the distances [m] between ``geoms`` and the object (``mj_geomDistance`` up to
        ``max_distance``) is below ``max_distance``: the same answer, measuring only until a geom is that near."""
        model, data, obj = self.model, self.data, self.active_geom
        nearest = None
        for g in geoms:
            distance = mujoco.mj_geomDistance(model, data, g, obj, max_distance, None)
            # min()'s running minimum: the first distance, then any smaller one
            if nearest is None or distance < nearest:
                nearest = distance
            if nearest < max_distance:  # later distances can only lower it
                return True
            if nearest != nearest:  # a NaN first: min() keeps it to the end, and NaN < max_distance is False
                return False
        return False

    def _hand_geoms_near(self, data: mujoco.MjData, max_distance: float) -> list[int]:
        """The robot's geoms that touch the world whose bounding spheres are nearer the object's than
        ``max_distance`` [m] in ``data``, in increasing id order.

        Plain Python floats, for the few geoms of an arm: the same operations in the same order as numpy's
        ``norm(p_geoms - p_object, axis=1) - rbound_geoms - rbound_object`` (each row's squares summed left to right,
        then the correctly rounded square root), so the same bits, at a fraction of numpy's per-call cost."""
        obj = self.active_geom
        xpos = self._geom_xpos if data is self.data else data.geom_xpos
        ox, oy, oz = xpos[obj].tolist()
        r_object = self._geom_rbound.item(obj)  # a Python float, as float() of the element
        near = []
        for g, (x, y, z), r_geom in zip(self._hand_geom_list, xpos[self._hand_rows].tolist(), self._hand_rbound,
                                        strict=True):
            dx, dy, dz = x - ox, y - oy, z - oz
            if math.sqrt(dx * dx + dy * dy + dz * dz) - r_geom - r_object < max_distance:
                near.append(g)
        return near

    def sweep_clearance(self, path: np.ndarray, max_object: float | None, max_table: float | None = None
                        ) -> tuple[float | None, float | None]:
        """Smallest distances [m] between the robot's geoms that touch the world and the object, and the table top,
        over the joint configurations ``path`` ((k, active joints) [rad]), everything else as it is now: kinematics
        only, on the scratch data, one pass over ``path``. Each is its ``max_`` if never nearer, and None (not
        measured) where its ``max_`` is None."""
        scratch, model, table = self.scratch, self.model, self.table_geom
        scratch.qpos[:] = self.data.qpos
        nearest, nearest_table = max_object, max_table
        for q in np.atleast_2d(path):
            scratch.qpos[self.robot_qpos] = q
            mujoco.mj_kinematics(model, scratch)
            if nearest is not None:
                nearest = min(nearest, self.arm_object_distance(nearest, scratch))
            if nearest_table is not None:
                for g in self.hand_geoms:
                    nearest_table = min(nearest_table, mujoco.mj_geomDistance(model, scratch, g, table, nearest_table,
                                                                              None))
        return nearest, nearest_table
