"""Named access to the simulated scene: the robot's joints, the hand, the object and the table.

In the manner of dm_control's ``Physics`` helpers: every index into MuJoCo's arrays is looked up once, by name
(:mod:`affordance_env.scene_index`), and the rest of the project asks geometric questions (``hand_position()``,
``object_pose()``) instead of indexing ``MjData`` itself. :class:`TapPhysics` holds the model and its simulated
state, answers the named queries of the robot and the table, steps the simulation (with the outcome monitor's
hook) and takes and restores snapshots; it owns one helper per other job:

- :class:`~affordance_env.servo.Servo`: the position servos and their controller (feedforward, torque limits);
- :class:`~affordance_env.contacts.ContactQueries`: contacts and clearances of the robot, the object and the table;
- :class:`~affordance_env.object_slot.ObjectSlot`: swapping the object in the model, placing it, where it is.

Positions are in the world frame [m], joint angles [rad], time [s].
"""

from __future__ import annotations

import copy
from collections.abc import Callable

import mujoco
import numpy as np

from affordance_env.contacts import ContactQueries
from affordance_env.exceptions import IncompatibleStateError, InvalidValueError
from affordance_env.object_slot import ObjectSlot
from affordance_env.objects import ObjectGeometry
from affordance_env.outcome import ObjectMonitor
from affordance_env.robot_model import get_variant
from affordance_env.scene_index import SceneIndex
from affordance_env.servo import Servo

#: The monitor samples the object at most this often [s]: every control tick.
MONITOR_PERIOD = 0.01
#: MuJoCo's warnings that mean the simulation has failed (:meth:`TapPhysics.unstable`), in the order checked.
FAULT_WARNINGS = (mujoco.mjtWarning.mjWARN_BADQACC, mujoco.mjtWarning.mjWARN_BADQVEL, mujoco.mjtWarning.mjWARN_BADQPOS,
                  mujoco.mjtWarning.mjWARN_CONTACTFULL, mujoco.mjtWarning.mjWARN_CNSTRFULL)


#: The parts of MuJoCo's data that a step integrates from (mjSTATE_INTEGRATION): a snapshot's must be finite.
_STATE_FIELDS = ("time", "qpos", "qvel", "act", "qacc_warmstart", "ctrl", "qfrc_applied", "xfrc_applied", "mocap_pos",
                "mocap_quat", "userdata", "plugin_state")


def _not_finite(data: mujoco.MjData) -> list[str]:
    """The fields of :data:`_STATE_FIELDS` in ``data`` that hold NaN or an infinity."""
    return [name for name in _STATE_FIELDS if not np.all(np.isfinite(getattr(data, name)))]


class TapPhysics:
    """The model and data of the tap scene with named queries.

    Args:
        model: A model built by :func:`affordance_env.scene.build_model`. It is modified in place when the
            object changes (sizes, masses), so give each ``TapPhysics`` its own model.
        variant: The robot variant the model was built with (``"tap"`` or ``"grasp"``).

    Robot joint vectors (positions, velocities, servo targets) are in the variant's ``active_joints`` order.

    The servo's commands (``set_joint_targets``, ...), the contact queries (``hand_touches_object``, ...) and the
    object's (``object_pose``, ...) are the helpers' bound methods, made attributes of this object once
    (:meth:`_bind_helpers`): the calls of every control tick and physics step go straight to them.
    """

    def __init__(self, model: mujoco.MjModel, variant: str = "tap") -> None:
        self.variant = get_variant(variant)
        self.model = model
        self.data = mujoco.MjData(model)
        #: Data for side computations (kinematics of other configurations); never the simulated state.
        self.scratch = mujoco.MjData(model)
        #: The scene's named elements, looked up once; those that callers read are attributes of this object too.
        index = self.index = SceneIndex.of(model, self.variant)
        self.object_body, self.object_geoms = index.object_body, index.object_geoms
        self.object_qpos, self.object_qvel = index.object_qpos, index.object_qvel
        self.robot_qpos, self.robot_qvel, self.actuators = index.robot_qpos, index.robot_qvel, index.actuators
        self.palm_site, self.table_geom, self.home_key = index.palm_site, index.table_geom, index.home_key
        self._qpos, self._qvel = index.qpos, index.qvel  # slices where the indices run in order: views
        # The table is static: its top height and extent are fixed once.
        mujoco.mj_kinematics(model, self.scratch)
        centre = self.scratch.geom_xpos[self.table_geom]
        half = model.geom_size[self.table_geom]
        self.table_top = float(centre[2] + half[2])
        self.table_low, self.table_high = centre[:2] - half[:2], centre[:2] + half[:2]
        self.servo = Servo(model, self.data, index)
        self.contacts = ContactQueries(model, self.data, self.scratch, index)
        self.object_slot = ObjectSlot(model, self.data, self.scratch, index, self.table_top, self.table_low,
                                      self.table_high)
        self._bind_helpers()
        data = self.data
        self._object_p = data.qpos[self.object_qpos : self.object_qpos + 3]
        self._object_v = data.qvel[self.object_qvel : self.object_qvel + 3]
        self._object_w = data.cvel[self.object_body, :3]
        #: Follows the object through an interaction (:mod:`affordance_env.outcome`): while set, sampled after
        #: the :meth:`step` calls that end a MONITOR_PERIOD (every control tick).
        self.monitor: ObjectMonitor | None = None
        self._next_sample = 0.0
        #: Called as ``on_step(physics)`` after every :meth:`step` call, if set (used to record video frames).
        self.on_step: Callable[[TapPhysics], None] | None = None

    def _bind_helpers(self) -> None:
        """Make the helpers' arrays and methods that callers use attributes of this object: the same arrays
        (:class:`~affordance_env.servo.Servo`'s, read and written in place) and the same bound methods, so a call
        costs no more than it did on this class."""
        servo, contacts = self.servo, self.contacts
        #: Per active joint: motor torque limit [N m], servo stiffness kp [N m/rad] and velocity lead kv / kp [s].
        self.torque_limit, self.servo_kp, self.servo_lead = servo.torque_limit, servo.kp, servo.lead
        #: A finger's target's largest distance from the finger [rad]; the servos' target ranges [rad].
        self.finger_reach, self.ctrl_low, self.ctrl_high = servo.finger_reach, servo.ctrl_low, servo.ctrl_high
        self.limit_torques, self.set_joint_targets = servo.limit_torques, servo.set_joint_targets
        self.joint_targets, self.set_targets_toward = servo.joint_targets, servo.set_targets_toward
        self.tick_accelerations, self.set_targets_toward_rows = servo.tick_accelerations, servo.set_targets_toward_rows
        #: The robot's geoms that touch the world (hand, fingers, wrist, forearm).
        self.hand_geoms, self.sweep_clearance = contacts.hand_geoms, contacts.sweep_clearance
        self.hand_touches_object, self.hand_touches_table = contacts.hand_touches_object, contacts.hand_touches_table
        self.object_touches_table = contacts.object_touches_table
        self.links_touching_object, self.links_touching_table = (contacts.links_touching_object,
                                                                 contacts.links_touching_table)
        self.hand_object_distance, self.arm_object_distance = (contacts.hand_object_distance,
                                                               contacts.arm_object_distance)
        self.arm_near_object, self.arm_near_or_touching = contacts.arm_near_object, contacts.arm_near_or_touching
        slot = self.object_slot
        self.set_object_pose, self.object_pose, self.object_on_table = slot.set_pose, slot.pose, slot.on_table
        self.object_speed, self.object_angular_speed, self.object_bottom = slot.speed, slot.angular_speed, slot.bottom

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

    def hand_position(self) -> np.ndarray:
        """``p_world_hand``: palm centre in the world frame [m]."""
        return self.data.site_xpos[self.palm_site].copy()

    # --- the object ------------------------------------------------------------------------------------------
    @property
    def active_geom(self) -> int:
        """The object's active primitive (a geom id)."""
        return self.object_slot.active_geom

    @property
    def geometry(self) -> ObjectGeometry | None:
        """The object's geometry (None until :meth:`set_object`)."""
        return self.object_slot.geometry

    def set_object(self, geometry: ObjectGeometry, xy: np.ndarray, yaw: float) -> None:
        """Make ``geometry`` the object of interest and place it at rest on the table.

        Args:
            geometry: From :func:`affordance_env.objects.object_geometry`.
            xy: Position of the object's centre on the table, world x and y [m].
            yaw: Rotation about the vertical axis [rad].
        """
        self._make_object(geometry)
        self.object_slot.place(geometry, xy, yaw)

    def _make_object(self, geometry: ObjectGeometry) -> None:
        """Make ``geometry`` the object of interest in the model (its primitive, size, mass and inertia), without
        touching the state; the contact queries then ask about it."""
        self.contacts.active_geom = self.object_slot.make(geometry)

    # --- snapshots of the world ------------------------------------------------------------------------------
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
        bad = _not_finite(data)
        if bad:  # the next step would fail, and until then the world would answer questions about NaN
            raise InvalidValueError(f"the state is damaged: its MuJoCo data are not finite in {', '.join(bad)}; "
                                    "nothing was restored.")
        current = self.geometry
        if geometry is not None and (current is None or (geometry.object_type, geometry.size)
                                     != (current.object_type, current.size)):
            self._make_object(geometry)
        try:
            mujoco.mj_copyData(self.data, self.model, data)  # into the same arrays: the views into them stay valid
        except mujoco.FatalError as exc:  # buffers of another size: data of another model
            raise IncompatibleStateError(f"the snapshot's MuJoCo data was made for another model ({exc}).") from None

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

    def step_toward(self, q: np.ndarray, qdd: np.ndarray, n: int) -> None:
        """One control tick: :meth:`set_targets_toward` ``q`` with the inertial lead of ``qdd``, then :meth:`step`
        ``n`` times."""
        self.set_targets_toward(q, qdd)
        self.step(n)

    def start_monitor(self) -> ObjectMonitor:
        """Start following the object (:class:`~affordance_env.outcome.ObjectMonitor`) from now on."""
        self.monitor = ObjectMonitor(self.table_top, self.table_low, self.table_high, self.object_pose()[:3],
                                     self.data.time)
        self._next_sample = self.data.time
        return self.monitor

    def unstable(self) -> str | None:
        """A description of a simulation fault (MuJoCo warning, non-finite state), or None if healthy."""
        counts = self.data.warning.number  # every kind's count at once
        for kind in FAULT_WARNINGS:
            if counts[kind] > 0:
                return f"MuJoCo warning {kind.name}"
        if not (np.isfinite(self.data.qpos).all() and np.isfinite(self.data.qvel).all()):
            return "non-finite state"
        return None
