"""Picture of the mk3 hand's mount: the fingered hand over the V2.5 hand mesh it replaces, in three views.

    python examples/hand_mount.py [--out hand_mount.png] [--offset X Y Z]

Run from anywhere; it writes ``hand_mount.png`` in the current directory by default (the repository's
``docs/hand_mount.png`` is this picture: ``--out docs/hand_mount.png`` from the repository root redraws it).

The V2.5 model's left hand mesh (blue) and the ``left_hand_mk3`` hand (orange) with its palm link at ``--offset``
(default: :data:`affordance_env.robot_model.HAND_MOUNT_POS`) in ``l_hand_dh_frame``, both half transparent,
seen orthographically from the back of the hand (+z of the frame: the left palm faces -z), from the thumb's side
(-y) and from the fingertips (+x); the frame's axes are drawn red (x), green (y) and blue (z), 3 cm long.

It also prints where the two hands' fingers lie along z (the palm normal) over the finger region, the
coordinate the views are least sure of: the mesh vertices with x from 3 to 10 cm and |y| < 2.5 cm.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import mujoco
import numpy as np

from affordance_env.rendering import SceneRenderer
from affordance_env.robot_model import HAND_MOUNT_FRAME, HAND_MOUNT_POS, HAND_ROOT_LINK, icub_urdf
from affordance_env.scene import hand_spec

SIZE = 420
#: View name: camera position in l_hand_dh_frame [m], and the image's x and y axes in that frame.
VIEWS = {
    "from +z (back of the hand)": ((0.01, -0.025, 0.31), (1, 0, 0), (0, 1, 0)),
    "from -y (thumb side)": ((0.01, -0.325, 0.01), (1, 0, 0), (0, 0, 1)),
    "from +x (fingertips)": ((0.31, -0.025, 0.01), (0, 1, 0), (0, 0, 1)),
}
V25_RGBA, MK3_RGBA = (0.25, 0.5, 1.0, 0.45), (0.95, 0.45, 0.1, 0.6)


def overlay_model(offset: np.ndarray) -> mujoco.MjModel:
    """The V2.5 robot, frozen, showing only its left hand, with the mk3 hand mounted at ``offset``."""
    spec = mujoco.MjSpec.from_string(icub_urdf())
    spec.compiler.fusestatic = False
    spec.compiler.discardvisual = False  # keep the phalanges' meshes, which collide with nothing (their capsules do)
    spec.visual.global_.offwidth = spec.visual.global_.offheight = SIZE
    for joint in list(spec.joints):
        spec.delete(joint)
    for body in spec.bodies:
        for geom in body.geoms:
            geom.rgba = V25_RGBA if body.name == "l_hand" else (0.0, 0.0, 0.0, 0.0)
    hand = hand_spec()
    for geom in hand.geoms:
        geom.rgba = MK3_RGBA
    mount = spec.body(HAND_MOUNT_FRAME)
    mount.add_frame(pos=list(offset)).attach_body(hand.body(HAND_ROOT_LINK), "mk3:", "")
    for axis, rgba in enumerate(((1, 0, 0, 1), (0, 1, 0, 1), (0, 0, 1, 1))):
        end = np.zeros(3)
        end[axis] = 0.03
        mount.add_geom(type=mujoco.mjtGeom.mjGEOM_CAPSULE, fromto=[0, 0, 0, *end], size=[0.001, 0, 0], rgba=rgba,
                       contype=0, conaffinity=0)
    for name, (position, x, y) in VIEWS.items():
        R = np.column_stack([x, y, np.cross(x, y)]).astype(float)
        quat = np.empty(4)
        mujoco.mju_mat2Quat(quat, R.reshape(-1))
        camera = mount.add_camera(name=name, pos=list(position), quat=quat)
        camera.proj = mujoco.mjtProjection.mjPROJ_ORTHOGRAPHIC
        camera.fovy = 0.2  # the picture's height [m]
    return spec.compile()


def finger_band(model: mujoco.MjModel, data: mujoco.MjData) -> dict[str, tuple[float, float]]:
    """z extent [m] in l_hand_dh_frame of each hand's mesh vertices over the finger region."""
    frame = model.body(HAND_MOUNT_FRAME).id
    p_world_frame, R_world_frame = data.xpos[frame], data.xmat[frame].reshape(3, 3)
    vertices = {"V2.5": [], "mk3": []}
    for g in range(model.ngeom):
        mesh = model.geom_dataid[g]
        if model.geom_type[g] != mujoco.mjtGeom.mjGEOM_MESH or model.geom_rgba[g, 3] == 0:
            continue
        start, count = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
        p_world = data.geom_xpos[g] + model.mesh_vert[start : start + count] @ data.geom_xmat[g].reshape(3, 3).T
        hand = "mk3" if model.body(model.geom_bodyid[g]).name.startswith("mk3:") else "V2.5"
        vertices[hand].append((p_world - p_world_frame) @ R_world_frame)
    band = {}
    for hand, chunks in vertices.items():
        p = np.vstack(chunks)
        z = p[(p[:, 0] >= 0.03) & (p[:, 0] <= 0.10) & (np.abs(p[:, 1]) < 0.025), 2]
        band[hand] = (float(z.min()), float(z.max()))
    return band


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=Path("hand_mount.png"),
                        help="picture to write (default ./hand_mount.png); its directory is created")
    parser.add_argument("--offset", type=float, nargs=3, default=HAND_MOUNT_POS, metavar=("X", "Y", "Z"),
                        help="palm link position in l_hand_dh_frame [m]")
    args = parser.parse_args()

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    model = overlay_model(np.array(args.offset))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    for hand, (low, high) in finger_band(model, data).items():
        print(f"{hand} fingers: z from {low * 1e3:.1f} to {high * 1e3:.1f} mm (middle {(low + high) * 500:.1f} mm)")
    fig, axes = plt.subplots(1, len(VIEWS), figsize=(4 * len(VIEWS), 4.4))
    for ax, name in zip(axes, VIEWS, strict=True):
        renderer = SceneRenderer(model, SIZE, SIZE, camera=name)
        ax.imshow(renderer.render(data))
        renderer.close()
        ax.set_title(name, fontsize=10)
        ax.set_axis_off()
    x, y, z = (1e3 * v for v in args.offset)
    fig.suptitle(f"left_hand_mk3 (orange) over the V2.5 left hand (blue): palm link at ({x:.1f}, {y:.1f}, {z:.1f}) mm "
                 "in l_hand_dh_frame, unrotated; 20 cm views", fontsize=10)
    fig.tight_layout()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=80)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
