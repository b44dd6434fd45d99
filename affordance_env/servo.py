"""The robot's position servos and their controller: targets, feedforward, torque limits.

Each actuated joint has a MuJoCo position actuator (stiffness kp [N m/rad]) and a second actuator for its motor's
back-EMF (:data:`affordance_env.scene.BACK_EMF`); the motor's torque is limited by the joint's
``actfrcrange`` [N m]. Joint vectors (targets [rad], accelerations [rad/s^2], torques [N m]) are in the robot
variant's ``active_joints`` order; the controls in MuJoCo's ``ctrl`` are in ``actuated_joints`` order.
"""

from __future__ import annotations

import mujoco
import numpy as np

from affordance_env.robot_model import HAND_DRIVEN_JOINTS, coupled_position
from affordance_env.scene import BACK_EMF
from affordance_env.scene_index import SceneIndex, lookup


class Servo:
    """The servo targets of the simulated robot in ``data``, with velocity and acceleration feedforward.

    Args:
        model: The scene's model (its torque limits are changed by :meth:`limit_torques`).
        data: The simulated state, whose ``ctrl`` this writes.
        index: The scene's named elements.
    """

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, index: SceneIndex) -> None:
        self.model, self.data = model, data
        joints, actuated = index.variant.active_joints, index.variant.actuated_joints
        self.actuators = index.actuators
        self._joint_ids, self._actuated, self._coupled = index.joint_ids, index.actuated, index.coupled
        self._qpos, self._qvel, self._act = index.qpos, index.qvel, index.act
        #: Torque limit of each active joint's motor [N m] (inf for a joint without a motor of its own).
        ids = self._joint_ids
        self.torque_limit = np.where(model.jnt_actfrclimited[ids], model.jnt_actfrcrange[ids, 1], np.inf)
        #: Servo stiffness kp [N m/rad] and kv / kp [s] per active joint (a coupled joint has no servo: infinite
        #: stiffness, no lead). A target led by kv / kp times the reference velocity cancels the servo's damping
        #: lag, so the joint follows a moving reference (velocity feedforward).
        actuated_index = slice(None) if self._actuated is None else self._actuated
        self.kp = np.full(len(joints), np.inf)
        self.kp[actuated_index] = model.actuator_gainprm[self.actuators, 0]
        self.lead = np.zeros(len(joints))
        # The servo's damping is its own and its motor's back-EMF's, which another actuator applies (scene.BACK_EMF).
        emf = np.array([lookup(model, mujoco.mjtObj.mjOBJ_ACTUATOR, f"{n}{BACK_EMF}") for n in actuated])
        damping = -model.actuator_biasprm[self.actuators, 2] - model.actuator_biasprm[emf, 2]
        self.lead[actuated_index] = damping / self.kp[actuated_index]
        self._qacc, self._torque = np.zeros(model.nv), np.zeros(model.nv)  # only the robot's part of qacc is set
        self._target = np.empty(len(joints))
        #: The hand's controller keeps each finger's servo target within this distance [rad] of where the finger
        #: is, the error at which its servo presses with its motor's full torque: a finger held back by what it
        #: touches presses with that torque, and moves on at its servo's pace when let go, instead of racing to a
        #: target far beyond at its motor's no-load speed (an impedance grasp). Empty without fingers.
        fingers = [i for i, n in enumerate(actuated) if n in HAND_DRIVEN_JOINTS]
        self._fingers = np.array(fingers) if fingers else None
        self._finger_qpos = np.array(
            [model.jnt_qposadr[lookup(model, mujoco.mjtObj.mjOBJ_JOINT, actuated[i])] for i in fingers], dtype=int)
        finger_joints = [joints.index(actuated[i]) for i in fingers]
        self.finger_reach = self.torque_limit[finger_joints] / model.actuator_gainprm[self.actuators[fingers], 0] \
            if fingers else np.zeros(0)
        #: Each servo's target range [rad], in ``actuated_joints`` order.
        self.ctrl_low = model.actuator_ctrlrange[self.actuators, 0].copy()
        self.ctrl_high = model.actuator_ctrlrange[self.actuators, 1].copy()
        self._ctrl = np.empty(len(self.actuators))
        # Views into the data, made once: a control tick reads and writes them without building new arrays.
        self._ctrl_view = data.ctrl[self._act] if isinstance(self._act, slice) else None
        #: Where every active joint has a servo and every index runs in order (the tap robot), the robot's parts of
        #: qacc and of M qacc and its controls as views: a control tick is then a few numpy calls on them
        #: (:meth:`set_targets_toward`). None otherwise.
        self._tick_views: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        if self._actuated is None and self._ctrl_view is not None and isinstance(self._qvel, slice) \
                and self._fingers is None:
            self._tick_views = (self._qacc[self._qvel], self._torque[self._qvel], self._ctrl_view)

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
        return np.divide(self._torque[self._qvel], self.kp, out=out)

    def set_targets_toward(self, q: np.ndarray, qdd: np.ndarray) -> None:
        """Servo targets ``q`` [rad] plus the :meth:`inertial_lead` of ``qdd`` [rad/s^2] (active-joint order),
        clipped to the joint ranges: the same as ``set_joint_targets(q + inertial_lead(qdd))``, with less Python."""
        target, views = self._target, self._tick_views
        if views is None:
            self.inertial_lead(qdd, out=target)
            np.add(q, target, out=target)
            self.set_joint_targets(target)
            return
        # The same arithmetic as those calls, in the same order, on views made once: M qdd / kp, plus q, clipped
        # to the control range, into the data's ctrl. This runs at every control tick.
        qacc_robot, torque_robot, ctrl = views
        qacc_robot[:] = qdd
        mujoco.mj_mulM(self.model, self.data, self._torque, self._qacc)
        np.divide(torque_robot, self.kp, out=target)
        np.add(q, target, out=target)
        np.minimum(np.maximum(target, self.ctrl_low, out=target), self.ctrl_high, out=ctrl)

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
        target = self._target
        mujoco.mj_mulM(self.model, self.data, self._torque, qacc)
        np.divide(torque_robot, self.kp, out=target)
        np.add(q, target, out=target)
        np.minimum(np.maximum(target, self.ctrl_low, out=target), self.ctrl_high, out=ctrl)

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
