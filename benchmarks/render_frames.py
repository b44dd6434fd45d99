"""How many pictures ``render_mode="rgb_array_list"`` gives per canonical tap (one per 1/30 s of simulated time), and,
with ``--timed N``, what pictures cost: one ``render()`` with ``render_mode="rgb_array"``, and an interaction with
``"rgb_array_list"`` against one without a render mode.

    python benchmarks/render_frames.py [--episodes 200] [--timed 5] [--width 480 --height 360]

Runs ``TapAffordance-v2`` at seeds 0 .. episodes - 1, the canonical tap, and counts the pictures ``render()`` returns
after each interaction; the pictures themselves are not drawn (``World.picture`` is replaced by a 1 x 1 one), so the
count costs what the interactions cost. ``--timed N`` then draws them (headless: EGL or OSMesa, as
:mod:`affordance_env.rendering` chooses, or ``MUJOCO_GL``): N pictures of the state after a reset (after a first one,
which makes the OpenGL context and is timed apart), and the interactions of seeds 0 .. N - 1 (reset and step) with
each render mode, in turns.
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import gymnasium as gym
import numpy as np

import affordance_env  # noqa: F401 (registers the envs)
from affordance_env.registry import ENV_ID


def _count(episodes: int) -> None:
    env = gym.make(ENV_ID, render_mode="rgb_array_list")
    env.unwrapped.world.picture = lambda width, height: np.zeros((1, 1, 3), np.uint8)  # count, not draw
    counts = []
    for seed in range(episodes):
        env.reset(seed=seed)
        env.step(np.zeros(3, np.float32))
        counts.append(len(env.render()))
    env.close()
    c = np.array(counts)
    print(f"canonical taps, seeds 0-{episodes - 1}: pictures per interaction: min {c.min()}, median "
          f"{np.median(c):.0f}, max {c.max()} (seed 0: {counts[0]})")


def _timed(call) -> tuple[float, float]:
    """``call()``'s wall-clock time and the CPU time of this process over it (all its threads: a software OpenGL
    renderer draws with several), in seconds."""
    wall, cpu = time.perf_counter(), time.process_time()
    call()
    return time.perf_counter() - wall, time.process_time() - cpu


def _time(n: int, width: int, height: int) -> None:
    from affordance_env.rendering import choose_gl_backend

    size: dict[str, Any] = {"render_width": width, "render_height": height}
    env = gym.make(ENV_ID, render_mode="rgb_array", **size)
    env.reset(seed=0)
    first, _ = _timed(env.render)
    pictures = np.array([_timed(env.render) for _ in range(n)])
    from OpenGL import GL  # the context of the pictures is still current: which renderer drew them

    drawn_by = GL.glGetString(GL.GL_RENDERER).decode()
    env.close()
    wall, cpu = 1000 * np.median(pictures, axis=0)
    print(f"render_mode='rgb_array', {width} x {height}, {choose_gl_backend()} ({drawn_by}): the first picture "
          f"{1000 * first:.0f} ms (it makes the OpenGL context), then {wall:.0f} ms each, {cpu:.0f} ms of CPU time "
          f"(medians of {n})")
    envs = {mode: gym.make(ENV_ID, render_mode=mode, **size) for mode in (None, "rgb_array_list")}
    costs: dict[str | None, list[tuple[float, float]]] = {mode: [] for mode in envs}
    frames = []
    for seed in range(n):
        for mode, env in envs.items():  # in turns, so that a change of the machine's load touches both
            costs[mode].append(_timed(lambda env=env, seed=seed: (env.reset(seed=seed),
                                                                  env.step(np.zeros(3, np.float32)))))
            if mode == "rgb_array_list":
                pictures_of_it = env.render()
                assert isinstance(pictures_of_it, list)
                frames.append(len(pictures_of_it))
    for env in envs.values():
        env.close()
    (plain_wall, plain_cpu), (listed_wall, listed_cpu) = (np.median(costs[mode], axis=0) for mode in envs)
    print(f"an interaction (reset and canonical tap, seeds 0-{n - 1}, medians): {plain_wall:.2f} s ({plain_cpu:.2f} s "
          f"of CPU time) without a render mode, {listed_wall:.2f} s ({listed_cpu:.2f} s) with 'rgb_array_list' and its "
          f"{np.median(frames):.0f} pictures")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=200)
    parser.add_argument("--timed", type=int, default=0, metavar="N",
                        help="also time N pictures and N interactions per render mode (default 0: no timing)")
    parser.add_argument("--width", type=int, default=480, help="picture width [pixels] (default: the env's, 480)")
    parser.add_argument("--height", type=int, default=360, help="picture height [pixels] (default: the env's, 360)")
    args = parser.parse_args()
    _count(args.episodes)
    if args.timed:
        _time(args.timed, args.width, args.height)


if __name__ == "__main__":
    main()
