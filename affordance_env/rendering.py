"""RGB pictures of the scene, offscreen, with an OpenGL backend chosen when the first picture is asked for.

MuJoCo's own ``mujoco.Renderer`` takes its OpenGL backend from ``MUJOCO_GL`` once, when ``mujoco`` is first
imported; on a machine without a display its default (GLFW) cannot open a context. Rather than set process-wide
variables at import, :class:`SceneRenderer` makes its own offscreen context (MuJoCo's ``mujoco.egl``,
``mujoco.osmesa`` or ``mujoco.glfw`` ``GLContext``) when it is created: with the backend the user named in
``MUJOCO_GL`` if any, else GLFW on a display, else the first of EGL and OSMesa whose library is installed
(:func:`choose_gl_backend`). Importing ``mujoco.egl`` or ``mujoco.osmesa`` sets ``PYOPENGL_PLATFORM`` if it is
unset, as PyOpenGL needs; that happens then, not at ``import affordance_env``. The range camera never needs
OpenGL; only these pictures do.
"""

from __future__ import annotations

import ctypes.util
import os

import mujoco
import numpy as np

from affordance_env.exceptions import InvalidValueError

#: Headless backends tried in this order when the user named none, with the library each needs.
HEADLESS_BACKENDS = {"egl": "EGL", "osmesa": "OSMesa"}
_GLFW_NAMES = ("glfw", "enable", "enabled", "on", "true", "1")


def choose_gl_backend() -> str | None:
    """The OpenGL backend for offscreen pictures; sets nothing.

    ``MUJOCO_GL`` if the user set it; else ``"glfw"`` when a display is available; else the first of ``"egl"``
    and ``"osmesa"`` whose library is installed; else None.
    """
    named = os.environ.get("MUJOCO_GL", "").strip().lower()
    if named:
        return named
    if os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        return "glfw"
    for backend, library in HEADLESS_BACKENDS.items():
        if ctypes.util.find_library(library):
            return backend
    return None


def _gl_context_class(backend: str):
    if backend == "egl":
        from mujoco.egl import GLContext
    elif backend == "osmesa":
        from mujoco.osmesa import GLContext
    elif backend in _GLFW_NAMES:
        from mujoco.glfw import GLContext
    else:
        raise InvalidValueError(f"unknown OpenGL backend MUJOCO_GL={backend!r}; expected egl, osmesa or glfw.")
    return GLContext


class SceneRenderer:
    """RGB pictures of the scene from a named camera, rendered offscreen.

    Args:
        model: The compiled model (its offscreen buffer, ``visual/global offwidth, offheight``, bounds the size).
        width, height: Picture size [pixels].
        camera: Name of the MuJoCo camera to render from.
        backend: OpenGL backend (``"egl"``, ``"osmesa"``, ``"glfw"``); by default :func:`choose_gl_backend`.

    Raises:
        RuntimeError: No OpenGL context could be created; the message says what to install or set.
    """

    def __init__(self, model: mujoco.MjModel, width: int = 480, height: int = 360, camera: str = "overview",
                 backend: str | None = None) -> None:
        camera_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, camera)
        if camera_id < 0:
            names = [model.camera(i).name for i in range(model.ncam)]
            raise InvalidValueError(f"Camera {camera!r} does not exist in the model. Available cameras: {names}")
        limit = (model.vis.global_.offwidth, model.vis.global_.offheight)
        if not (0 < width <= limit[0] and 0 < height <= limit[1]):
            raise InvalidValueError(
                f"picture size {width} x {height} must be positive and within the model's offscreen "
                             f"buffer, {limit[0]} x {limit[1]} pixels.")
        backend = backend or choose_gl_backend()
        self.backend = backend
        self._context = None
        try:
            if backend is None:
                raise RuntimeError("no display, and neither the EGL nor the OSMesa library is installed")
            self._context = _gl_context_class(backend)(width, height)
            self._context.make_current()
            self._mjr = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_150)
        except Exception as exc:  # the GL backends raise many different types
            self.close()
            raise RuntimeError(
                f"Could not create an OpenGL context for render_mode='rgb_array' (backend {backend!r}: {exc}). "
                "On a headless machine install EGL (Debian: libegl1) or OSMesa (Debian: libosmesa6), or name a "
                "backend that works here with MUJOCO_GL=egl or MUJOCO_GL=osmesa. The range camera does not need "
                "OpenGL."
            ) from exc
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self._mjr)
        self._model = model
        self._scene = mujoco.MjvScene(model, maxgeom=10_000)
        self._option = mujoco.MjvOption()
        self._camera = mujoco.MjvCamera()
        self._camera.type = mujoco.mjtCamera.mjCAMERA_FIXED
        self._camera.fixedcamid = camera_id
        self._rect = mujoco.MjrRect(0, 0, width, height)
        self._pixels = np.empty((height, width, 3), dtype=np.uint8)

    def render(self, data: mujoco.MjData) -> np.ndarray:
        """An (height, width, 3) uint8 picture of the current state."""
        self._context.make_current()
        mujoco.mjv_updateScene(self._model, data, self._option, None, self._camera, mujoco.mjtCatBit.mjCAT_ALL,
                               self._scene)
        mujoco.mjr_render(self._rect, self._scene, self._mjr)
        mujoco.mjr_readPixels(self._pixels, None, self._rect, self._mjr)
        return np.flipud(self._pixels).copy()  # OpenGL's rows run bottom-up

    def close(self) -> None:
        """Free the OpenGL context (the renderer cannot be used afterwards)."""
        if self._context is not None:
            self._mjr = None
            self._context.free()
            self._context = None
