"""Named access to the simulated scene: the robot's joints, the hand, the object and the table.

In the manner of dm_control's ``Physics`` helpers: every index into MuJoCo's arrays is looked up once, by name,
here, and the rest of the project asks geometric questions (``hand_position()``, ``object_pose()``) instead of
indexing ``MjData`` itself.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable

import mujoco
import numpy as np

from affordance_env.exceptions import IncompatibleStateError, InvalidValueError
from affordance_env.linalg import dot, norm
from affordance_env.objects import PRIMITIVES, ObjectGeometry
from affordance_env.outcome import ObjectMonitor
from affordance_env.robot_model import HAND_COUPLINGS, HAND_DRIVEN_JOINTS, coupled_position, get_variant
from affordance_env.scene import BACK_EMF, ROBOT_CONAFFINITY, ROBOT_CONTYPE

#: Geom group that hides the scene's inactive object primitives from the range camera and the renderer.
HIDDEN_GEOM_GROUP = 3
OBJECT_RGBA = np.array([0.85, 0.2, 0.15, 1.0])
#: The monitor samples the object at most this often [s]: every control tick.
MONITOR_PERIOD = 0.01
#: Collision bits of the active object (assets/scene.xml): type 1, takes surfaces (1) and the hand (2).
OBJECT_CONTYPE, OBJECT_CONAFFINITY = 1, 3
#: MuJoCo's warnings that mean the simulation has failed (:meth:`TapPhysics.unstable`), in the order checked.
FAULT_WARNINGS = (mujoco.mjtWarning.mjWARN_BADQACC, mujoco.mjtWarning.mjWARN_BADQVEL, mujoco.mjtWarning.mjWARN_BADQPOS,
                  mujoco.mjtWarning.mjWARN_CONTACTFULL, mujoco.mjtWarning.mjWARN_CNSTRFULL)


def _id(model: mujoco.MjModel, kind: mujoco.mjtObj, name: str) -> int:
    index = mujoco.mj_name2id(model, kind, name)
    if index < 0:
        raise InvalidValueError(f"The model has no {kind.name.removeprefix('mjOBJ_').lower()} named {name!r}.")
    return index


def _as_slice(indices: np.ndarray) -> slice | np.ndarray:
    """``indices`` as a slice if they are consecutive and increasing, else unchanged."""
    if indices.size and np.array_equal(indices, np.arange(indices[0], indices[0] + indices.size)):
        return slice(int(indices[0]), int(indices[0]) + indices.size)
    return indices


class TapPhysics:
    """The model and data of the tap scene with named queries.

    Args:
        model: A model built by :func:`affordance_env.scene.build_model`. It is modified in place when the
            object changes (sizes, masses), so give each ``TapPhysics`` its own model.
        variant: The robot variant the model was built with (``"tap"`` or ``"grasp"``).

    Robot joint vectors (positions, velocities, servo targets) are in the variant's ``active_joints`` order.
    """

    def __init__(self, model: mujoco.MjModel, variant: str = "tap") -> None:
        self.variant = get_variant(variant)
        joints = self.variant.active_joints
        self.model = model
        self.data = mujoco.MjData(model)
        #: Data for side computations (kinematics of other configurations); never the simulated state.
        self.scratch = mujoco.MjData(model)
        obj = mujoco.mjtObj
        self.object_body = _id(model, obj.mjOBJ_BODY, "object")
        self.object_geoms = {p: _id(model, obj.mjOBJ_GEOM, f"object_{p}") for p in PRIMITIVES}
        joint = _id(model, obj.mjOBJ_JOINT, "object_free")
        self.object_qpos = int(model.jnt_qposadr[joint])
        self.object_qvel = int(model.jnt_dofadr[joint])
        self._joint_ids = np.array([_id(model, obj.mjOBJ_JOINT, n) for n in joints])
        self.robot_qpos = np.array([model.jnt_qposadr[_id(model, obj.mjOBJ_JOINT, n)] for n in joints])
        self.robot_qvel = np.array([model.jnt_dofadr[_id(model, obj.mjOBJ_JOINT, n)] for n in joints])
        actuated = self.variant.actuated_joints
        self.actuators = np.array([_id(model, obj.mjOBJ_ACTUATOR, n) for n in actuated])
        #: Positions of the actuated joints in the active-joint vector (None when every active joint has a servo).
        self._actuated = None if actuated == joints else np.array([joints.index(n) for n in actuated])
        #: Coupled joints without a servo: (index, index of the joint they follow, its name) in active order.
        self._coupled = [(joints.index(d), joints.index(p), d) for d, (p, _) in HAND_COUPLINGS.items()
                         if d in joints]
        # Index with slices where the indices run in order (they do in the built scenes): a slice is a view,
        # cheaper than fancy indexing at every control tick.
        self._qpos = _as_slice(self.robot_qpos)
        self._qvel = _as_slice(self.robot_qvel)
        self._act = _as_slice(self.actuators)
        self.palm_site = _id(model, obj.mjOBJ_SITE, "palm")
        self.head_site = _id(model, obj.mjOBJ_SITE, "head")
        self.table_geom = _id(model, obj.mjOBJ_GEOM, "table_top")
        self.home_key = _id(model, obj.mjOBJ_KEY, "home")
        # The robot's geoms that touch the world: those of its contact links, of an arm held still too (fused into
        # the body it hangs from).
        self.hand_geoms = np.array([g for g in range(model.ngeom) if model.geom_bodyid[g] != self.object_body
                                    and (model.geom_contype[g], model.geom_conaffinity[g])
                                    == (ROBOT_CONTYPE, ROBOT_CONAFFINITY)])
        self._is_hand_geom = np.zeros(model.ngeom, dtype=bool)
        self._is_hand_geom[self.hand_geoms] = True
        self._hand_geom_list = self.hand_geoms.tolist()
        self._hand_geom_set = frozenset(self._hand_geom_list)
        self._hand_rows = _as_slice(self.hand_geoms)  # their rows of geom_xpos: a view where consecutive
        #: Bounding-sphere radius of each of them [m], as Python floats: the distance checks of every control
        #: tick run in plain Python over a handful of geoms, cheaper than numpy's per-call overhead.
        self._hand_rbound = model.geom_rbound[self.hand_geoms].tolist()
        #: The largest distance [m] at which MuJoCo may make a contact between bounding spheres: their margin
        #: (of a geom, or of an explicit pair); infinite if one of those geoms has no bounding sphere, which
        #: MuJoCo's test then skips (:meth:`arm_near_or_touching`).
        margins = [*model.geom_margin.tolist(), *model.pair_margin.tolist()]
        self._contact_margin = max(margins) if all(r > 0 for r in self._hand_rbound) else math.inf
        #: Torque limit of each active joint's motor [N m] (inf for a joint without a motor of its own).
        ids = self._joint_ids
        self.torque_limit = np.where(model.jnt_actfrclimited[ids], model.jnt_actfrcrange[ids, 1], np.inf)
        #: Servo stiffness kp [N m/rad] and kv / kp [s] per active joint (a coupled joint has no servo: infinite
        #: stiffness, no lead). A target led by kv / kp times the reference velocity cancels the servo's damping
        #: lag, so the joint follows a moving reference (velocity feedforward).
        actuated_index = slice(None) if self._actuated is None else self._actuated
        self.servo_kp = np.full(len(joints), np.inf)
        self.servo_kp[actuated_index] = model.actuator_gainprm[self.actuators, 0]
        self.servo_lead = np.zeros(len(joints))
        # The servo's damping is its own and its motor's back-EMF's, which another actuator applies (scene.BACK_EMF).
        emf = np.array([_id(model, obj.mjOBJ_ACTUATOR, f"{n}{BACK_EMF}") for n in actuated])
        damping = -model.actuator_biasprm[self.actuators, 2] - model.actuator_biasprm[emf, 2]
        self.servo_lead[actuated_index] = damping / self.servo_kp[actuated_index]
        self._qacc, self._torque = np.zeros(model.nv), np.zeros(model.nv)  # only the robot's part of qacc is set
        self._lead = np.empty(len(joints))
        #: The hand's controller keeps each finger's servo target within this distance [rad] of where the finger
        #: is, the error at which its servo presses with its motor's full torque: a finger held back by what it
        #: touches presses with that torque, and moves on at its servo's pace when let go, instead of racing to a
        #: target far beyond at its motor's no-load speed (an impedance grasp). Empty without fingers.
        fingers = [i for i, n in enumerate(actuated) if n in HAND_DRIVEN_JOINTS]
        self._fingers = np.array(fingers) if fingers else None
        self._finger_qpos = np.array([model.jnt_qposadr[_id(model, obj.mjOBJ_JOINT, actuated[i])] for i in fingers],
                                     dtype=int)
        finger_joints = [joints.index(actuated[i]) for i in fingers]
        self.finger_reach = self.torque_limit[finger_joints] / model.actuator_gainprm[self.actuators[fingers], 0] \
            if fingers else np.zeros(0)
        self.ctrl_low = model.actuator_ctrlrange[self.actuators, 0].copy()
        self.ctrl_high = model.actuator_ctrlrange[self.actuators, 1].copy()
        self._ctrl = np.empty(len(self.actuators))
        # Views into the data, made once: a control tick reads and writes them without building new arrays.
        data = self.data
        self._ctrl_view = data.ctrl[self._act] if isinstance(self._act, slice) else None
        #: Where every active joint has a servo and every index runs in order (the tap robot), the robot's parts of
        #: qacc and of M qacc and its controls as views: a control tick is then a few numpy calls on them
        #: (:meth:`set_targets_toward`). None otherwise.
        self._tick_views: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        if self._actuated is None and self._ctrl_view is not None and isinstance(self._qvel, slice) \
                and self._fingers is None:
            self._tick_views = (self._qacc[self._qvel], self._torque[self._qvel], self._ctrl_view)
        #: geom_xpos of the simulated state and every geom's bounding radius: views, current whatever the state
        #: (set_state copies into the same arrays) or the object (set_object writes into the model's)
        self._geom_xpos, self._geom_rbound = data.geom_xpos, model.geom_rbound
        self._object_p = data.qpos[self.object_qpos : self.object_qpos + 3]
        self._object_v = data.qvel[self.object_qvel : self.object_qvel + 3]
        self._object_w = data.cvel[self.object_body, :3]
        self.body_names = [model.body(b).name for b in range(model.nbody)]
        # The table is static: its top height and extent are fixed once.
        mujoco.mj_kinematics(model, self.scratch)
        centre = self.scratch.geom_xpos[self.table_geom]
        half = model.geom_size[self.table_geom]
        self.table_top = float(centre[2] + half[2])
        self.table_low, self.table_high = centre[:2] - half[:2], centre[:2] + half[:2]
        # Inactive primitives keep these sizes, so the model never depends on earlier objects.
        self._hidden_size = {p: model.geom_size[g].copy() for p, g in self.object_geoms.items()}
        self._hidden_aabb = {p: model.geom_aabb[g].copy() for p, g in self.object_geoms.items()}
        self._hidden_rbound = {p: float(model.geom_rbound[g]) for p, g in self.object_geoms.items()}
        self.active_geom = self.object_geoms["sphere"]
        self.geometry: ObjectGeometry | None = None
        #: Follows the object through an interaction (:mod:`affordance_env.outcome`): while set, sampled after
        #: the :meth:`step` calls that end a MONITOR_PERIOD (every control tick).
        self.monitor: ObjectMonitor | None = None
        self._next_sample = 0.0
        #: Called as ``on_step(physics)`` after every :meth:`step` call, if set (used to record video frames).
        self.on_step: Callable[[TapPhysics], None] | None = None

    # --- the table -------------------------------------------------------------------------------------------
    def table_extent(self) -> tuple[np.ndarray, np.ndarray]:
        """(lower, upper) corners of the table top in world x, y [m]."""
        return self.table_low.copy(), self.table_high.copy()

    # --- the robot -------------------------------------------------------------------------------------------
    def reset_home(self) -> None:
        """Reset the whole state to the ``home`` keyframe and recompute derived quantities."""
        mujoco.mj_resetDataKeyframe(self.model, self.data, self.home_key)
        mujoco.mj_forward(self.model, self.data)

    def joint_positions(self) -> np.ndarray:
        """Robot joint angles in active-joint order [rad]."""
        return self.data.qpos[self._qpos].copy()

    def joint_velocities(self) -> np.ndarray:
        """Robot joint velocities in active-joint order [rad/s]."""
        return self.data.qvel[self._qvel].copy()

    def max_joint_speed(self) -> float:
        """Largest speed of the robot's joints [rad/s] (of :meth:`joint_velocities`, without copying them)."""
        return float(np.maximum.reduce(np.abs(self.data.qvel[self._qvel])))  # .max(), without its Python layer

    def joint_torques(self) -> np.ndarray:
        """Motor torques at the robot's joints in active-joint order [N m], gravity compensation included (the
        actuators carry it)."""
        return self.data.qfrc_actuator[self._qvel].copy()

    def limit_torques(self, joints: np.ndarray, limit: np.ndarray | float | None) -> None:
        """Let the motors of ``joints`` (indices in active-joint order) give at most ``limit`` [N m], at most their
        own limits (a current limit set by the controller); None: their own limits again."""
        ids = self._joint_ids[joints]
        own = self.torque_limit[joints]
        value = own if limit is None else np.minimum(own, limit)
        self.model.jnt_actfrcrange[ids, 0] = -value
        self.model.jnt_actfrcrange[ids, 1] = value

    def set_joint_targets(self, q: np.ndarray) -> None:
        """Command the position servos to ``q`` [rad] (active-joint order), clipped to the joint ranges; the values
        of coupled joints, which have no servo, are ignored. A finger's target is kept within
        :attr:`finger_reach` of where the finger is (the hand's controller: see there)."""
        if self._actuated is not None:
            q = np.asarray(q)[self._actuated]  # a new array
        elif self._fingers is not None:
            q = np.array(q)  # the caller's stays as it was
        if self._fingers is not None:
            where = self.data.qpos[self._finger_qpos]
            q[self._fingers] = np.minimum(np.maximum(q[self._fingers], where - self.finger_reach),
                                          where + self.finger_reach)
        # np.minimum/np.maximum into the control vector: np.clip's wrapper costs more than the clipping
        if self._ctrl_view is not None:
            np.minimum(np.maximum(q, self.ctrl_low, out=self._ctrl), self.ctrl_high, out=self._ctrl_view)
            return
        np.minimum(np.maximum(q, self.ctrl_low, out=self._ctrl), self.ctrl_high, out=self._ctrl)
        self.data.ctrl[self._act] = self._ctrl

    def inertial_lead(self, qdd: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """Servo target offsets [rad] whose spring torques accelerate the robot's joints at ``qdd`` [rad/s^2]
        (active-joint order) in the current configuration: M qdd / kp (acceleration feedforward; 0 for coupled
        joints, which have no servo), into ``out`` if given."""
        self._qacc[self._qvel] = qdd
        mujoco.mj_mulM(self.model, self.data, self._torque, self._qacc)
        return np.divide(self._torque[self._qvel], self.servo_kp, out=out)

    def set_targets_toward(self, q: np.ndarray, qdd: np.ndarray) -> None:
        """Servo targets ``q`` [rad] plus the :meth:`inertial_lead` of ``qdd`` [rad/s^2] (active-joint order),
        clipped to the joint ranges: the same as ``set_joint_targets(q + inertial_lead(qdd))``, with less Python."""
        lead, views = self._lead, self._tick_views
        if views is None:
            self.inertial_lead(qdd, out=lead)
            np.add(q, lead, out=lead)
            self.set_joint_targets(lead)
            return
        # The same arithmetic as those calls, in the same order, on views made once: M qdd / kp, plus q, clipped
        # to the control range, into the data's ctrl. This runs at every control tick.
        qacc_robot, torque_robot, ctrl = views
        qacc_robot[:] = qdd
        mujoco.mj_mulM(self.model, self.data, self._torque, self._qacc)
        np.divide(torque_robot, self.servo_kp, out=lead)
        np.add(q, lead, out=lead)
        np.minimum(np.maximum(lead, self.ctrl_low, out=lead), self.ctrl_high, out=ctrl)

    def tick_accelerations(self, qdd: np.ndarray) -> np.ndarray | None:
        """The accelerations ``qdd`` [rad/s^2] of a trajectory's ticks ((ticks, active joints)) as rows of the model's
        whole acceleration vector ((ticks, nv), zero outside the robot's joints), for
        :meth:`set_targets_toward_rows`; None where a control tick cannot take them so (see ``_tick_views``)."""
        if self._tick_views is None:
            return None
        rows = np.zeros((len(qdd), self.model.nv))
        rows[:, self._qvel] = qdd
        return rows

    def set_targets_toward_rows(self, q: np.ndarray, qacc: np.ndarray) -> None:
        """:meth:`set_targets_toward` ``q`` with the inertial lead of a row of :meth:`tick_accelerations`: the same
        arithmetic on the same numbers (the row is the vector set_targets_toward fills: the robot's part, zeros
        elsewhere), without copying the accelerations into it at every tick."""
        _, torque_robot, ctrl = self._tick_views
        lead = self._lead
        mujoco.mj_mulM(self.model, self.data, self._torque, qacc)
        np.divide(torque_robot, self.servo_kp, out=lead)
        np.add(q, lead, out=lead)
        np.minimum(np.maximum(lead, self.ctrl_low, out=lead), self.ctrl_high, out=ctrl)

    def step_toward(self, q: np.ndarray, qdd: np.ndarray, n: int) -> None:
        """One control tick: :meth:`set_targets_toward` ``q`` with the inertial lead of ``qdd``, then :meth:`step`
        ``n`` times."""
        self.set_targets_toward(q, qdd)
        self.step(n)

    def joint_targets(self) -> np.ndarray:
        """Current servo targets [rad] in active-joint order; a coupled joint's is where its coupling puts it at
        the target of the joint it follows."""
        if self._actuated is None:
            return self.data.ctrl[self._act].copy()
        q = self.data.qpos[self._qpos].copy()
        q[self._actuated] = self.data.ctrl[self.actuators]
        for i, j, name in self._coupled:
            q[i] = coupled_position(name, q[j])
        return q

    def hand_position(self) -> np.ndarray:
        """``p_world_hand``: palm centre in the world frame [m]."""
        return self.data.site_xpos[self.palm_site].copy()

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

    def hand_touches_table(self) -> bool:
        """Whether any contact joins the hand (or wrist, forearm, fingers) and the table top."""
        table, hand = self.table_geom, self._hand_geom_set
        for g1, g2 in self.data.contact.geom.tolist():  # data.contact holds the ncon contacts
            if (g1 == table and g2 in hand) or (g2 == table and g1 in hand):
                return True
        return False

    def object_bottom(self) -> float:
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

    def object_touches_table(self) -> bool:
        """Whether any contact joins the object and the table top."""
        obj, table = self.active_geom, self.table_geom  # two different geoms
        for g1, g2 in self.data.contact.geom.tolist():  # asked at every control tick of a grasp's put-down
            if (g1 == obj and g2 == table) or (g1 == table and g2 == obj):
                return True
        return False

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

    # --- the object ------------------------------------------------------------------------------------------
    def set_object(self, geometry: ObjectGeometry, xy: np.ndarray, yaw: float) -> None:
        """Make ``geometry`` the object of interest and place it at rest on the table.

        Args:
            geometry: From :func:`affordance_env.objects.object_geometry`.
            xy: Position of the object's centre on the table, world x and y [m].
            yaw: Rotation about the vertical axis [rad].
        """
        self._make_object(geometry)
        m = self.model
        quat_yaw = np.array([np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2)])
        quat = np.empty(4)
        mujoco.mju_mulQuat(quat, quat_yaw, geometry.quat_rest)
        a = self.object_qpos
        self.data.qpos[a : a + 3] = [xy[0], xy[1], self.table_top + geometry.half_height + 1e-4]
        self.data.qpos[a + 3 : a + 7] = quat
        self.data.qvel[self.object_qvel : self.object_qvel + 6] = 0.0
        mujoco.mj_forward(m, self.data)

    def set_object_pose(self, pose: np.ndarray) -> None:
        """Put the object at ``pose`` (x, y, z [m], unit quaternion w, x, y, z), at rest."""
        a = self.object_qpos
        self.data.qpos[a : a + 7] = pose
        self.data.qvel[self.object_qvel : self.object_qvel + 6] = 0.0
        mujoco.mj_forward(self.model, self.data)

    def adopt(self, other: TapPhysics) -> None:
        """Take over the world of ``other``, a model of the same scene with another arm acting: its object
        (geometry, pose and velocity, bit for bit), its time, and the joints both move (torso and neck: positions,
        velocities and servo targets); every other joint at home. The same world then goes on in this model."""
        mujoco.mj_resetDataKeyframe(self.model, self.data, self.home_key)
        theirs, mine = other.geometry, self.geometry
        if theirs is not None and (mine is None or (theirs.object_type, theirs.size) != (mine.object_type, mine.size)):
            self._make_object(theirs)
        a, b = self.object_qpos, other.object_qpos
        self.data.qpos[a : a + 7] = other.data.qpos[b : b + 7]
        av, bv = self.object_qvel, other.object_qvel
        self.data.qvel[av : av + 6] = other.data.qvel[bv : bv + 6]
        for name in set(self.variant.actuated_joints) & set(other.variant.actuated_joints):
            mine, theirs = self.model.joint(name), other.model.joint(name)
            self.data.qpos[mine.qposadr[0]] = other.data.qpos[theirs.qposadr[0]]
            self.data.qvel[mine.dofadr[0]] = other.data.qvel[theirs.dofadr[0]]
            self.data.ctrl[self.model.actuator(name).id] = other.data.ctrl[other.model.actuator(name).id]
        self.data.time = other.data.time
        mujoco.mj_forward(self.model, self.data)

    def _make_object(self, geometry: ObjectGeometry) -> None:
        """Make ``geometry`` the object of interest in the model (its primitive, size, mass and inertia), without
        touching the state."""
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

    # --- snapshots of the world --------------------------------------------------------------------------------
    def get_state(self) -> tuple[ObjectGeometry | None, mujoco.MjData]:
        """The world as it is: the object's geometry and a copy of MuJoCo's data, state and derived quantities
        alike (what the last step computed, which the next one reads before it computes them anew)."""
        return self.geometry, copy.copy(self.data)

    def set_state(self, snapshot: tuple[ObjectGeometry | None, mujoco.MjData]) -> None:
        """Put the world back as :meth:`get_state` saw it: the same steps then follow, bit for bit."""
        geometry, data = snapshot if isinstance(snapshot, tuple) and len(snapshot) == 2 else (None, None)
        if not isinstance(data, mujoco.MjData) or not (geometry is None or isinstance(geometry, ObjectGeometry)):
            raise TypeError(f"snapshot must be what get_state() returned, got {snapshot!r:.80}.")
        if (data.qpos.shape, data.qvel.shape, data.act.shape) != (self.data.qpos.shape, self.data.qvel.shape,
                                                                    self.data.act.shape):
            raise IncompatibleStateError(
                f"the snapshot's MuJoCo data has {data.qpos.size} positions, {data.qvel.size} velocities and "
                f"{data.act.size} actuator states, this model {self.model.nq}, {self.model.nv} and {self.model.na}: "
                "it was taken of another model.")
        current = self.geometry
        if geometry is not None and (current is None or (geometry.object_type, geometry.size)
                                     != (current.object_type, current.size)):
            self._make_object(geometry)
        try:
            mujoco.mj_copyData(self.data, self.model, data)  # into the same arrays: the views into them stay valid
        except mujoco.FatalError as exc:  # buffers of another size: data of another model
            raise IncompatibleStateError(f"the snapshot's MuJoCo data was made for another model ({exc}).") from None

    def object_pose(self) -> np.ndarray:
        """Object pose: position [m] and orientation quaternion (w, x, y, z), (7,)."""
        a = self.object_qpos
        return self.data.qpos[a : a + 7].copy()

    def object_speed(self) -> float:
        """Linear speed of the object [m/s]."""
        v = self.data.qvel[self.object_qvel : self.object_qvel + 3]
        return norm(v)

    def object_angular_speed(self) -> float:
        """Angular speed of the object [rad/s]."""
        w = self.data.qvel[self.object_qvel + 3 : self.object_qvel + 6]
        return norm(w)

    def object_on_table(self) -> bool:
        """Whether the object's centre is above the table top and within its extent."""
        p = self.data.qpos[self.object_qpos : self.object_qpos + 3]
        return bool(p[2] > self.table_top and np.all(p[:2] >= self.table_low) and np.all(p[:2] <= self.table_high))

    def start_monitor(self) -> ObjectMonitor:
        """Start following the object (:class:`~affordance_env.outcome.ObjectMonitor`) from now on."""
        self.monitor = ObjectMonitor(self.table_top, self.table_low, self.table_high, self.object_pose()[:3],
                                     self.data.time)
        self._next_sample = self.data.time
        return self.monitor

    # --- stepping --------------------------------------------------------------------------------------------
    def step(self, n: int = 1) -> None:
        """Advance the simulation by ``n`` timesteps."""
        data = self.data
        mujoco.mj_step(self.model, data, n)
        monitor = self.monitor
        if monitor is not None:
            time = data.time
            if time >= self._next_sample - 1e-9:  # every 10 ms at least
                # qvel's linear part is the centre's world velocity (the body origin is its centre of mass); cvel's
                # rotational part is the angular velocity in world axes (computed at the start of the last step).
                # Sampled here rather than in a method of its own: this runs at every control tick.
                monitor.sample(time, self._object_p.tolist(), self._object_v.tolist(), self._object_w.tolist())
                self._next_sample = time + MONITOR_PERIOD
        if self.on_step is not None:
            self.on_step(self)

    def unstable(self) -> str | None:
        """A description of a simulation fault (MuJoCo warning, non-finite state), or None if healthy."""
        counts = self.data.warning.number  # every kind's count at once
        for kind in FAULT_WARNINGS:
            if counts[kind] > 0:
                return f"MuJoCo warning {kind.name}"
        if not (np.isfinite(self.data.qpos).all() and np.isfinite(self.data.qvel).all()):
            return "non-finite state"
        return None
