"""RGB pictures, headless: the OpenGL backend chosen when a picture is first asked for, never at import."""

import os
import subprocess
import sys

import numpy as np
import pytest

from affordance_env.rendering import SceneRenderer, choose_gl_backend
from affordance_env.tap_env import TapAffordanceEnv

needs_gl = pytest.mark.skipif(choose_gl_backend() is None, reason="no OpenGL backend on this machine")


def test_import_leaves_the_process_environment_alone():
    env = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "PYOPENGL_PLATFORM")}
    code = ("import os, gymnasium as gym, affordance_env; e = gym.make('TapAffordance-v2', camera_width=32, "
            "camera_height=24); e.reset(seed=0); "
            "print(os.environ.get('MUJOCO_GL'), os.environ.get('PYOPENGL_PLATFORM'))")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["None", "None"]


def test_the_backend_the_user_names_is_used(monkeypatch):
    monkeypatch.setenv("MUJOCO_GL", "osmesa")
    assert choose_gl_backend() == "osmesa"
    monkeypatch.delenv("MUJOCO_GL")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert choose_gl_backend() in ("egl", "osmesa", None)


@needs_gl
@pytest.mark.slow
def test_rgb_array_pictures_and_frames_of_a_tap():
    env = TapAffordanceEnv(render_mode="rgb_array", render_width=160, render_height=120,
                           camera_width=32, camera_height=32)
    env.reset(seed=4)
    picture = env.render()
    assert picture.shape == (120, 160, 3) and picture.dtype == np.uint8
    assert picture.std() > 10  # not a blank image
    sky, floor = picture[:10].mean(), picture[-10:].mean()
    assert floor > sky  # upright: the lit floor and table are at the bottom, the dark background on top
    env.step(np.zeros(3))
    assert env.frames == []  # rgb_array draws only when asked
    after = env.render()
    assert after.shape == (120, 160, 3) and not np.array_equal(picture, after)  # the arm moved
    env.close()


class CountingWorld:
    """Counts the pictures the env asks its world for, and draws a plain one (no OpenGL needed)."""

    def __init__(self, env):
        self.calls = 0

        def picture(width, height):
            self.calls += 1
            value = int(env.physics.data.time * 1000) % 256  # of the current scene: changes as it moves
            return np.full((height, width, 3), value, np.uint8)

        env.world.picture = picture


def test_rgb_array_draws_only_when_render_is_called():
    # rgb_array once drew a picture every 1/30 s of every reset and step, as rgb_array_list does: a reset and a
    # step took about 20 s instead of 0.013 s without OpenGL hardware.
    env = TapAffordanceEnv(render_mode="rgb_array", render_width=64, render_height=48, camera_width=32,
                           camera_height=24)
    counter = CountingWorld(env)
    env.reset(seed=0)
    env.step(np.zeros(3))
    assert counter.calls == 0 and env.frames == []
    picture = env.render()
    assert counter.calls == 1 and picture.shape == (48, 64, 3) and picture.dtype == np.uint8
    assert picture[0, 0, 0] == int(env.physics.data.time * 1000) % 256  # the scene as it is now
    env.close()


def test_rgb_array_list_still_records_the_frames_of_the_interaction():
    env = TapAffordanceEnv(render_mode="rgb_array_list", camera_width=32, camera_height=24)
    counter = CountingWorld(env)
    env.reset(seed=0)
    env.step(np.zeros(3))
    frames = env.render()
    assert counter.calls == len(frames) > 10 and len({f[0, 0, 0] for f in frames}) > 10
    env.close()


def test_render_without_render_mode_returns_none():
    env = TapAffordanceEnv(camera_width=32, camera_height=32)
    env.reset(seed=0)
    assert env.render() is None


def test_missing_opengl_gives_a_clear_error(model):
    with pytest.raises(RuntimeError, match="MUJOCO_GL=egl or MUJOCO_GL=osmesa"):
        SceneRenderer(model, backend="osmesa-that-is-not-there")
    with pytest.raises(ValueError, match="Available cameras"):
        SceneRenderer(model, camera="eyes")
    with pytest.raises(ValueError, match="offscreen buffer"):
        SceneRenderer(model, width=4000)


@needs_gl
@pytest.mark.slow
def test_rgb_array_list_returns_every_frame_of_the_interaction():
    env = TapAffordanceEnv(render_mode="rgb_array_list", render_width=96, render_height=72,
                           camera_width=32, camera_height=24)
    env.reset(seed=4, options={"object_type": "sphere"})
    env.step(np.zeros(3))
    simulated = env.physics.data.time
    frames = env.render()
    # one frame per 1/30 s of simulated time, from the reset (t = 0) on, and the final scene
    assert abs(len(frames) - (simulated * env.metadata["render_fps"] + 2)) <= 1 + 1e-6
    assert all(f.shape == (72, 96, 3) and f.dtype == np.uint8 for f in frames)
    assert not np.array_equal(frames[0], frames[len(frames) // 2])  # the arm moved, the ball rolled
    assert np.mean(np.abs(np.diff(np.stack(frames).astype(np.int16), axis=0)).sum(axis=(1, 2, 3)) > 0) > 0.5
    assert env.render() == []  # emptied: the next call returns only what came after
    env.close()
