"""RGB pictures, headless: EGL or OSMesa chosen automatically, a clear error when neither works."""

import os

import mujoco
import numpy as np
import pytest

from affordance_env.rendering import SceneRenderer, select_gl_backend
from affordance_env.tap_env import TapAffordanceEnv

needs_gl = pytest.mark.skipif(
    os.environ.get("MUJOCO_GL") not in ("egl", "osmesa", "glfw"), reason="no OpenGL backend on this machine"
)


def test_backend_is_chosen_before_mujoco_renders():
    # affordance_env was imported (by conftest), so the choice is made: kept if the user set it.
    assert select_gl_backend() == os.environ.get("MUJOCO_GL")


@needs_gl
@pytest.mark.slow
def test_rgb_array_pictures_and_frames_of_a_tap():
    env = TapAffordanceEnv(render_mode="rgb_array", render_width=160, render_height=120,
                           camera_width=32, camera_height=32)
    env.reset(seed=4)
    picture = env.render()
    assert picture.shape == (120, 160, 3) and picture.dtype == np.uint8
    assert picture.std() > 10  # not a blank image
    env.step(np.zeros(3))
    assert len(env.frames) > 10
    assert not np.array_equal(env.frames[0], env.frames[-1])  # the arm moved
    env.close()


def test_render_without_render_mode_returns_none():
    env = TapAffordanceEnv(camera_width=32, camera_height=32)
    env.reset(seed=0)
    assert env.render() is None


def test_missing_opengl_gives_a_clear_error(monkeypatch, model):
    def broken(*args, **kwargs):
        raise RuntimeError("gladLoadGL error")

    monkeypatch.setattr(mujoco, "Renderer", broken)
    with pytest.raises(RuntimeError, match="MUJOCO_GL=egl or MUJOCO_GL=osmesa"):
        SceneRenderer(model)
