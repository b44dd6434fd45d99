"""A cache of compiled scene models on disk, keyed by everything the model is built from.

Compiling the scene (:func:`affordance_env.scene.build_model`) takes about half a second, most of it MuJoCo
processing the iCub's meshes; loading the same model from MuJoCo's binary format (MJB) takes a tenth of that. Each
new process that builds an env pays the compile once: every worker of a collection, every command-line run. This
cache keeps the compiled model of each robot variant in a file named by a hash of all its inputs:

- the MuJoCo version, the robot variant;
- the source of the ``affordance_env`` package (the code that builds the scene) and the shipped ``assets/``;
- the two URDFs of ``icub-models`` and every mesh file they name (their contents, not their dates).

Any change to any of these gives another name, so a cached model is always the one that compiling would give
(``tests/test_scene.py`` checks byte for byte). A file that cannot be read is compiled again and replaced; a
directory that cannot be written to only means compiling every time.

The directory is ``$TAP_AFFORDANCE_CACHE``, else ``$XDG_CACHE_HOME/tap-affordance``, else
``~/.cache/tap-affordance``; ``TAP_AFFORDANCE_CACHE=off`` turns the cache off. A model takes about 45 MB; the
newest :data:`KEEP` files of each variant are kept.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import re
import time
from collections.abc import Callable
from pathlib import Path

import mujoco
import numpy as np

from affordance_env.assets_path import assets_dir
from affordance_env.fileio import write_atomically

#: Environment variable naming the cache directory (``off``: no cache).
CACHE_ENV = "TAP_AFFORDANCE_CACHE"
#: Cached models kept per variant (older ones are removed when a new one is written).
KEEP = 3
#: A temporary file older than this [s] is what a killed write left: removed when the next model is written.
STALE_TMP_AGE = 600.0
_PACKAGE = Path(__file__).resolve().parent
_MESH_FILE = re.compile(r'filename="([^"]+)"')


def cache_dir() -> Path | None:
    """The cache directory (see the module docstring), or None if the cache is off."""
    setting = os.environ.get(CACHE_ENV)
    if setting is not None:
        return None if setting.strip().lower() in ("", "off", "0", "false", "no") else Path(setting).expanduser()
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "tap-affordance"


def fingerprint(variant: str, urdfs: tuple[str, ...]) -> str:
    """Hex digest of everything the compiled model of ``variant`` depends on (``urdfs``: the robot's URDF texts,
    whose mesh files are hashed too)."""
    digest = hashlib.sha256()

    def add(label: str, content: bytes) -> None:
        digest.update(f"{label}\0{len(content)}\0".encode())
        digest.update(content)

    add("mujoco", mujoco.__version__.encode())
    add("variant", variant.encode())
    for root in (_PACKAGE, assets_dir()):
        for path in sorted(p for p in root.rglob("*") if p.is_file() and "__pycache__" not in p.parts
                           and p.suffix != ".pyc"):
            add(str(path.relative_to(root)), path.read_bytes())
    for text in urdfs:
        add("urdf", text.encode())
        for mesh in sorted(set(_MESH_FILE.findall(text))):
            path = Path(mesh)
            if path.is_file():  # the URDFs also name Gazebo plugins, which are no files
                add(mesh, path.read_bytes())
    return digest.hexdigest()


def cached_model(variant: str, urdfs: tuple[str, ...], compile_model: Callable[[], mujoco.MjModel]
                 ) -> mujoco.MjModel:
    """The model of ``variant`` from the cache if it holds it, else ``compile_model()``, stored for next time."""
    directory = cache_dir()
    if directory is None:
        return compile_model()
    path = directory / f"model-{variant}-{fingerprint(variant, urdfs)[:32]}.mjb"
    if path.is_file():
        try:
            return mujoco.MjModel.from_binary_path(str(path))
        except Exception:  # noqa: BLE001 (truncated or corrupt: compile it again and replace it)
            pass
    model = compile_model()
    try:
        _store(model, path)
    except OSError:  # read-only or full: the cache only saves time
        pass
    return model


def _store(model: mujoco.MjModel, path: Path) -> None:
    """Write ``model`` to ``path`` atomically (a reader sees the whole file or none), then keep only the newest
    KEEP models of its variant."""
    path.parent.mkdir(parents=True, exist_ok=True)
    buffer = np.empty(mujoco.mj_sizeModel(model), dtype=np.uint8)
    mujoco.mj_saveModel(model, None, buffer)
    write_atomically(path, buffer.tofile)
    variant = path.name.split("-")[1]
    older = sorted(path.parent.glob(f"model-{variant}-*.mjb"), key=lambda p: p.stat().st_mtime, reverse=True)
    for stale in older[KEEP:]:
        stale.unlink(missing_ok=True)
    for left in path.parent.glob(".model-*.tmp"):  # of writes killed midway (a write takes a tenth of a second)
        with contextlib.suppress(OSError):
            if time.time() - left.stat().st_mtime > STALE_TMP_AGE:
                left.unlink()
