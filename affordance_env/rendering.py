"""Headless OpenGL for ``render_mode="rgb_array"``: choose EGL or OSMesa before MuJoCo is imported.

MuJoCo picks its OpenGL backend from ``MUJOCO_GL`` once, when ``mujoco`` is first imported. On a machine
without a display the default (GLFW) cannot open a context, so :func:`select_gl_backend` sets ``MUJOCO_GL`` to
the first of EGL and OSMesa whose library is installed, unless the user has set it already. The range camera
never needs OpenGL; only the RGB pictures do.
"""

from __future__ import annotations

import ctypes.util
import os

_LIBRARIES = {"egl": "EGL", "osmesa": "OSMesa"}


def select_gl_backend() -> str | None:
    """Set ``MUJOCO_GL`` (and ``PYOPENGL_PLATFORM``) for headless rendering if needed; return the choice."""
    if os.environ.get("MUJOCO_GL"):
        return os.environ["MUJOCO_GL"]
    if os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        return None
    for backend, library in _LIBRARIES.items():
        if ctypes.util.find_library(library):
            os.environ["MUJOCO_GL"] = backend
            os.environ.setdefault("PYOPENGL_PLATFORM", backend)
            return backend
    return None


class SceneRenderer:
    """RGB pictures of the scene from a named camera, rendered offscreen.

    Args:
        model: The compiled model.
        width, height: Picture size [pixels].
        camera: Name of the MuJoCo camera to render from.
    """

    def __init__(self, model, width: int = 480, height: int = 360, camera: str = "overview") -> None:
        import mujoco

        self.camera = camera
        try:
            self._renderer = mujoco.Renderer(model, height=height, width=width)
        except Exception as exc:  # the GL backends raise many different types
            raise RuntimeError(
                "Could not create an OpenGL context for render_mode='rgb_array' "
                f"(MUJOCO_GL={os.environ.get('MUJOCO_GL', '<unset>')!r}). On a headless machine install EGL "
                "(Debian: libegl1) or OSMesa (Debian: libosmesa6) and set MUJOCO_GL=egl or MUJOCO_GL=osmesa before "
                "importing affordance_env. The range camera does not need OpenGL."
            ) from exc

    def render(self, data) -> np.ndarray:  # noqa: F821
        """An (height, width, 3) uint8 picture of the current state."""
        self._renderer.update_scene(data, camera=self.camera)
        return self._renderer.render()

    def close(self) -> None:
        self._renderer.close()
