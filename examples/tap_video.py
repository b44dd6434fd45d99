"""Write a video of whole interactions: every frame, from placing the object to its rest, rendered headless.

    python examples/tap_video.py [--episodes 3] [--seed 0] [--action 0 0 0] [--out taps.mp4]

Uses ``render_mode="rgb_array_list"`` (all the frames of the last interaction) and imageio with ffmpeg
(``pip install "tap-affordance[examples]"``). Gymnasium's ``RecordVideo`` wrapper keeps one frame per ``step``,
and one step here is a whole interaction, so it would keep one picture of it: collect the frames as below.
"""

from __future__ import annotations

import argparse
import sys

#: What writing the video needs, beyond the package itself.
INSTALL = 'pip install "tap-affordance[examples]"'


def _video_writer():
    """imageio's v3 API, with its ffmpeg plugin; without them, one line naming the install and exit status 2, before
    anything is rendered."""
    try:
        import imageio.v3 as iio
        import imageio_ffmpeg  # noqa: F401  (the mp4 writer imageio uses)
    except ImportError as exc:
        print(f"tap_video.py: error: writing the video needs imageio with ffmpeg ({exc.name} is missing): "
              f"{INSTALL}", file=sys.stderr)
        raise SystemExit(2) from None
    return iio


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--episodes", type=int, default=3)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--action", type=float, nargs=3, default=(0.0, 0.0, 0.0), metavar=("HEIGHT", "OFFSET", "SPEED"))
    parser.add_argument("--out", default="taps.mp4")
    args = parser.parse_args()
    iio = _video_writer()
    import gymnasium as gym
    import numpy as np

    import affordance_env  # noqa: F401  (registers TapAffordance-v2)

    env = gym.make("TapAffordance-v2", render_mode="rgb_array_list", render_width=640, render_height=480)
    frames = []
    for i in range(args.episodes):
        env.reset(seed=args.seed + i)
        *_, info = env.step(np.asarray(args.action, dtype=np.float32))
        frames += env.render()
        print(f"seed {args.seed + i}: {info['object']['type']}, moved {100 * info['displacement']:.1f} cm "
              f"({info['outcome']}), rolled={info['rolled']}")
    env.close()
    fps = env.metadata["render_fps"]
    iio.imwrite(args.out, np.stack(frames), fps=fps, codec="libx264", macro_block_size=16)
    print(f"wrote {args.out}: {len(frames)} frames, {len(frames) / fps:.1f} s at {fps} fps")


if __name__ == "__main__":
    main()
