"""Every index into MuJoCo's arrays that the tap scene's physics uses, looked up once, by name.

In the manner of dm_control's named indexing: the robot's joints (their ``qpos`` and ``qvel`` addresses, in the
variant's ``active_joints`` order), its servos, the object's body, free joint and primitives, the palm and head
sites, the table top and the ``home`` keyframe. The servo (:mod:`affordance_env.servo`), the object slot
(:mod:`affordance_env.object_slot`), the contact queries (:mod:`affordance_env.contacts`) and
:class:`~affordance_env.physics.TapPhysics` read them from one :class:`SceneIndex`.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from affordance_env.exceptions import InvalidValueError
from affordance_env.objects import PRIMITIVES
from affordance_env.robot_model import HAND_COUPLINGS, RobotVariant


def lookup(model: mujoco.MjModel, kind: mujoco.mjtObj, name: str) -> int:
    """The id of the element ``name`` of type ``kind`` in ``model``; :class:`InvalidValueError` if there is none."""
    index = mujoco.mj_name2id(model, kind, name)
    if index < 0:
        raise InvalidValueError(f"The model has no {kind.name.removeprefix('mjOBJ_').lower()} named {name!r}.")
    return index


def as_slice(indices: np.ndarray) -> slice | np.ndarray:
    """``indices`` as a slice if they are consecutive and increasing, else unchanged.

    A slice indexes a view, cheaper than fancy indexing at every control tick; the built scenes' robot indices
    run in order."""
    if indices.size and np.array_equal(indices, np.arange(indices[0], indices[0] + indices.size)):
        return slice(int(indices[0]), int(indices[0]) + indices.size)
    return indices


@dataclass(frozen=True, eq=False)
class SceneIndex:
    """Ids and addresses of the tap scene's named elements (build with :meth:`of`).

    Robot joint vectors are in the variant's ``active_joints`` order; ``qpos``, ``qvel`` and ``act`` are
    ``robot_qpos``, ``robot_qvel`` and ``actuators`` as slices where they run in order (:func:`as_slice`).
    """

    variant: RobotVariant
    #: The object's body, its primitives' geoms (by primitive name) and its free joint's qpos and qvel addresses.
    object_body: int
    object_geoms: dict[str, int]
    object_qpos: int
    object_qvel: int
    #: Joint ids, qpos and qvel addresses of the active joints.
    joint_ids: np.ndarray
    robot_qpos: np.ndarray
    robot_qvel: np.ndarray
    #: The servos (position actuators) of the actuated joints, in ``actuated_joints`` order.
    actuators: np.ndarray
    #: Positions of the actuated joints in the active-joint vector (None when every active joint has a servo).
    actuated: np.ndarray | None
    #: Coupled joints without a servo: (index, index of the joint they follow, its name) in active order.
    coupled: list[tuple[int, int, str]]
    qpos: slice | np.ndarray
    qvel: slice | np.ndarray
    act: slice | np.ndarray
    palm_site: int
    head_site: int
    table_geom: int
    home_key: int
    #: Every body's name, by body id.
    body_names: list[str]

    @classmethod
    def of(cls, model: mujoco.MjModel, variant: RobotVariant) -> SceneIndex:
        """Look up the elements of a model built by :func:`affordance_env.scene.build_model` for ``variant``."""
        obj = mujoco.mjtObj
        joints, actuated = variant.active_joints, variant.actuated_joints
        # looked up in this order: a model that lacks several names is told about the first
        object_body = lookup(model, obj.mjOBJ_BODY, "object")
        object_geoms = {p: lookup(model, obj.mjOBJ_GEOM, f"object_{p}") for p in PRIMITIVES}
        joint = lookup(model, obj.mjOBJ_JOINT, "object_free")
        joint_ids = np.array([lookup(model, obj.mjOBJ_JOINT, n) for n in joints])
        robot_qpos = np.array([model.jnt_qposadr[lookup(model, obj.mjOBJ_JOINT, n)] for n in joints])
        robot_qvel = np.array([model.jnt_dofadr[lookup(model, obj.mjOBJ_JOINT, n)] for n in joints])
        actuators = np.array([lookup(model, obj.mjOBJ_ACTUATOR, n) for n in actuated])
        return cls(
            variant=variant,
            object_body=object_body,
            object_geoms=object_geoms,
            object_qpos=int(model.jnt_qposadr[joint]),
            object_qvel=int(model.jnt_dofadr[joint]),
            joint_ids=joint_ids,
            robot_qpos=robot_qpos,
            robot_qvel=robot_qvel,
            actuators=actuators,
            actuated=None if actuated == joints else np.array([joints.index(n) for n in actuated]),
            coupled=[(joints.index(d), joints.index(p), d) for d, (p, _) in HAND_COUPLINGS.items() if d in joints],
            qpos=as_slice(robot_qpos),
            qvel=as_slice(robot_qvel),
            act=as_slice(actuators),
            palm_site=lookup(model, obj.mjOBJ_SITE, "palm"),
            head_site=lookup(model, obj.mjOBJ_SITE, "head"),
            table_geom=lookup(model, obj.mjOBJ_GEOM, "table_top"),
            home_key=lookup(model, obj.mjOBJ_KEY, "home"),
            body_names=[model.body(b).name for b in range(model.nbody)],
        )
