"""The ``affordance`` command line."""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np


def _demo(args: argparse.Namespace) -> int:
    import gymnasium as gym

    import affordance_env  # noqa: F401  (registers the environment)

    kwargs = {"behavior": args.behavior}
    if args.object:
        kwargs["object_types"] = (args.object,)
    env = gym.make("TapAffordance-v0", **kwargs)
    print(f"TapAffordance-v0, behavior={args.behavior!r}: {args.episodes} interaction(s) from seed {args.seed}")
    start = time.perf_counter()
    for i in range(args.episodes):
        _, info0 = env.reset(seed=args.seed + i)
        obs, reward, _, _, info = env.step(np.zeros(env.action_space.shape, dtype=np.float32))
        obj = info["object"]
        print(
            f"  seed {args.seed + i}: {obj['type']:<19} {obj['size'] * 100:4.1f} cm  "
            f"contact={info['contact']!s:<5} hand {info['hand_speed']:.2f} m/s  "
            f"moved {info['displacement'] * 100:5.1f} cm "
            f"({info['outcome']})  rolled={info['rolled']!s:<5}  object pixels {int(obs['mask'].sum())}  "
            f"|effect|={np.linalg.norm(info['effect']):.3g}"
        )
    elapsed = time.perf_counter() - start
    print(f"{args.episodes} interaction(s) in {elapsed:.2f} s ({args.episodes / elapsed:.1f} per second)")
    env.close()
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="affordance", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    demo = sub.add_parser("demo", help="tap a few objects with the canonical tap and print what happened")
    demo.add_argument("--episodes", type=int, default=8, help="number of interactions (default 8)")
    demo.add_argument("--seed", type=int, default=0, help="seed of the first interaction (default 0)")
    demo.add_argument("--behavior", default="tap", help="tap | tap_back | push (default tap)")
    demo.add_argument("--object", default=None, help="only this object type (default: all four)")
    demo.set_defaults(func=_demo)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``affordance`` console script."""
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except ValueError as exc:
        print(f"affordance: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    raise SystemExit(main())
