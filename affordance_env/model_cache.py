"""A cache of compiled scene models on disk, keyed by everything the model is built from.

Compiling the scene (:func:`affordance_env.scene.build_model`) takes about half a second, most of it MuJoCo
processing the iCub's meshes; loading the same model from MuJoCo's binary format (MJB) takes a tenth of that. Each
new process that builds an env pays the compile once: every worker of a collection, every command-line run. This
cache keeps the compiled model of each robot variant in a file named by a hash of all its inputs:

- the MuJoCo version, the robot variant;
- the source of the ``affordance_env`` package (the code that builds the scene: its ``.py`` files) and the
  shipped ``assets/``, each file by its contents and its path within the package, so that a source checkout and
  an installed copy of the same version, wherever they are, share their models;
- the two URDFs of ``icub-models`` and every mesh file they name (their contents, not their dates; the URDFs
  name the meshes by their installed paths, which the compiled model keeps).

Any change to any of these gives another name, so a cached model is always the one that compiling would give
(``tests/test_model_cache.py`` checks byte for byte). A file that cannot be read is compiled again and replaced;
a directory that cannot be written to only means compiling every time: a warning names it once, and the cache is
turned off for the rest of the process and the processes it starts (:func:`check_cache`, which a process calls
before it starts workers, so that they do not each say it again).

The directory is ``$TAP_AFFORDANCE_CACHE``, else ``$XDG_CACHE_HOME/tap-affordance``, else
``~/.cache/tap-affordance``; ``TAP_AFFORDANCE_CACHE=off`` turns the cache off. A model takes 45-55 MB. The cache
stays bounded: after a model is written, the least recently used ones (a model read from the cache counts as
used) are removed beyond :data:`KEEP` per variant and beyond :data:`MAX_BYTES` in all, never the one just
written.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import re
import time
import warnings
from collections.abc import Callable
from pathlib import Path

import mujoco
import numpy as np

from affordance_env.assets_path import assets_dir
from affordance_env.fileio import write_atomically

#: Environment variable naming the cache directory (``off``: no cache).
CACHE_ENV = "TAP_AFFORDANCE_CACHE"
#: Cached models kept per variant (older ones are removed when a new one is written): the current one and one
#: other (of another version of the package or of MuJoCo in use beside it).
KEEP = 2
#: Bytes of cached models kept in all: the four variants' current models (about 205 MB) and little more.
MAX_BYTES = 256 * 2**20
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
    # The package's code without its assets (an installed package holds them in affordance_env/assets, a checkout
    # beside it: hashed once, below), and the assets; by their paths relative to their folder, not where it is.
    sources = [p for p in _PACKAGE.rglob("*.py") if p.relative_to(_PACKAGE).parts[0] != "assets"]
    assets = [p for p in assets_dir().rglob("*") if p.is_file() and "__pycache__" not in p.parts]
    for label, root, paths in (("package", _PACKAGE, sources), ("assets", assets_dir(), assets)):
        for path in sorted(paths, key=lambda p: p.relative_to(root).as_posix()):
            add(f"{label}/{path.relative_to(root).as_posix()}", path.read_bytes())
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
            model = mujoco.MjModel.from_binary_path(str(path))
        except Exception:  # noqa: BLE001 (truncated or corrupt: compile it again and replace it)
            pass
        else:
            with contextlib.suppress(OSError):  # used now: the last to be evicted (a read-only cache stays as it is)
                os.utime(path)
            return model
    model = compile_model()
    try:
        _store(model, path)
    except OSError as exc:  # read-only or full: the cache only saves time
        _turn_off(directory, exc)
    return model


def check_cache() -> Path | None:
    """The cache directory if a model can be written there (it is made if missing); else None, after a warning
    that names it and with the cache turned off for this process and the ones it starts from now on. A process
    calls it before starting workers that build environments: they inherit the setting, and compile without
    trying the cache or saying so again."""
    directory = cache_dir()
    if directory is None:
        return None
    probe = directory / f".write-test-{os.getpid()}.tmp"
    try:
        directory.mkdir(parents=True, exist_ok=True)
        probe.write_bytes(b"")
    except OSError as exc:
        _turn_off(directory, exc)
        return None
    finally:
        with contextlib.suppress(OSError):
            probe.unlink(missing_ok=True)
    return directory


def _turn_off(directory: Path, exc: OSError) -> None:
    """Say that ``directory`` cannot be written, and set :data:`CACHE_ENV` to ``off`` in this process's
    environment: its later envs, and the processes it starts, compile without trying the cache again."""
    os.environ[CACHE_ENV] = "off"
    warnings.warn(f"the model cache {directory} cannot be written ({exc.strerror or exc}): it is off for this "
                  "process and the ones it starts, which compile the scene instead; set "
                  f"{CACHE_ENV} to a directory that can be written, or to off", stacklevel=3)


def _store(model: mujoco.MjModel, path: Path) -> None:
    """Write ``model`` to ``path`` atomically (a reader sees the whole file or none), then evict (:func:`evict`)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    buffer = np.empty(mujoco.mj_sizeModel(model), dtype=np.uint8)
    mujoco.mj_saveModel(model, None, buffer)
    write_atomically(path, buffer.tofile)
    evict(path.parent, keep=path)


def evict(directory: Path, keep: Path | None = None) -> list[Path]:
    """Remove the least recently used models of ``directory`` (oldest modification time first; a read refreshes
    it) beyond :data:`KEEP` per variant and beyond :data:`MAX_BYTES` in all, never ``keep``; returns those
    removed. A file another process removes meanwhile is skipped."""
    entries = []
    for path in directory.glob("model-*.mjb"):
        with contextlib.suppress(OSError):
            stat = path.stat()
            entries.append((stat.st_mtime, path.name, path, stat.st_size))
    entries.sort(reverse=True)  # newest first; the one just written leads whatever the clocks say
    entries.sort(key=lambda e: e[2] != keep)
    removed, total, per_variant = [], 0, {}
    for _, name, path, size in entries:
        variant = name.split("-")[1]
        if path != keep and (per_variant.get(variant, 0) >= KEEP or total + size > MAX_BYTES):
            with contextlib.suppress(OSError):
                path.unlink()
                removed.append(path)
            continue
        per_variant[variant] = per_variant.get(variant, 0) + 1
        total += size
    for left in directory.glob(".model-*.tmp"):  # of writes killed midway (a write takes a tenth of a second)
        with contextlib.suppress(OSError):
            if time.time() - left.stat().st_mtime > STALE_TMP_AGE:
                left.unlink()
    return removed
