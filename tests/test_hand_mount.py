"""examples/hand_mount.py draws the mk3 hand as the simulation has it: every link's mesh, the phalanges' too."""

import importlib.util
from pathlib import Path

import mujoco
import numpy as np

from affordance_env.robot_model import HAND_LINKS, HAND_MOUNT_POS


def _example():
    path = Path(__file__).resolve().parents[1] / "examples" / "hand_mount.py"
    spec = importlib.util.spec_from_file_location("hand_mount_example", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_overlay_keeps_every_mk3_links_mesh_the_phalanges_included():
    # The phalanges collide through capsules and keep their meshes only to be seen, colliding with nothing: a
    # compiler that discards such geoms drew a hand without fingers.
    model = _example().overlay_model(np.array(HAND_MOUNT_POS))
    meshed = {model.body(model.geom_bodyid[g]).name.removeprefix("mk3:") for g in range(model.ngeom)
              if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH and model.geom_rgba[g, 3] > 0}
    missing = [link for link in HAND_LINKS if link not in meshed]
    assert not missing, f"links drawn without their mesh: {missing}"
