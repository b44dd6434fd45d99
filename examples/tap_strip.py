"""Save a picture strip and a video of one tap, rendered headless (EGL or OSMesa, chosen automatically).

    python examples/tap_strip.py [--seed 4] [--object sphere] [--out tap]

Writes ``<out>.png`` (six frames of the interaction side by side, with the range image and object mask of the
initial and final snapshots) and, if imageio with ffmpeg is installed, ``<out>.mp4``.
"""

from __future__ import annotations

import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from affordance_env.tap_env import TapAffordanceEnv  # noqa: E402
from affordance_learning.common.behaviors import outcome_words  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seed", type=int, default=4)
    parser.add_argument("--object", default="sphere")
    parser.add_argument("--behavior", default="tap")
    parser.add_argument("--out", default="tap")
    args = parser.parse_args()

    env = TapAffordanceEnv(render_mode="rgb_array_list", object_types=(args.object,), behavior=args.behavior)
    obs0, info0 = env.reset(seed=args.seed)
    obs1, _, _, _, info = env.step(np.zeros(3))
    frames = env.render()
    picks = np.linspace(0, len(frames) - 1, 6).round().astype(int)

    fig, axes = plt.subplots(2, 6, figsize=(18, 6))
    for ax, k in zip(axes[0], picks, strict=True):
        ax.imshow(frames[k])
        ax.set_title(f"t = {k / env.metadata['render_fps']:.2f} s")
    for ax, (title, image) in zip(
        axes[1][:4],
        [("initial range [m]", obs0["range"]), ("initial mask", obs0["mask"]), ("final range [m]", obs1["range"]),
         ("final mask", obs1["mask"])],
        strict=True,
    ):
        shown = ax.imshow(np.where(image > 0, image, np.nan) if "range" in title else image)
        if "range" in title:
            fig.colorbar(shown, ax=ax, fraction=0.046)
        ax.set_title(title)
    axes[1, 4].bar(range(49), info["effect"])
    axes[1, 4].set_title("effect (final - initial features)")
    axes[1, 5].axis("off")
    axes[1, 5].text(0, 0.5, f"{info['object']['type']}, {info['object']['size'] * 100:.1f} cm\n"
                    f"moved {info['displacement'] * 100:.1f} cm ({info['outcome']})\nrolled: {info['rolled']}"
                    f"\nsuccess ({outcome_words(args.behavior)[0]}): {info['success']}",
                    fontsize=12)
    for ax in axes.flat[:10]:
        ax.set_xticks([])
        ax.set_yticks([])
    fig.tight_layout()
    fig.savefig(f"{args.out}.png", dpi=80)
    print(f"wrote {args.out}.png ({len(frames)} frames recorded)")
    try:
        import imageio.v3 as iio

        iio.imwrite(f"{args.out}.mp4", np.stack(frames), fps=env.metadata["render_fps"])
        print(f"wrote {args.out}.mp4")
    except Exception as exc:  # imageio or its ffmpeg plugin missing: the strip is enough
        print(f"no video ({exc.__class__.__name__}: {exc})")
    env.close()


if __name__ == "__main__":
    main()
