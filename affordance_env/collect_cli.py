"""``affordance collect``: interactions into a dataset, in parallel and resumably (see :mod:`.dataset`)."""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

#: Command-line flags that are env options, and the env keyword each one sets.
_ENV_FLAGS = ("behavior", "object_types", "size_range", "camera_width", "camera_height", "camera_fovy",
              "roll_threshold", "settle_timeout", "range_noise", "position_range")


def add_collect_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``collect`` subcommand to ``subparsers``; it runs :func:`run_collect` via ``args.func``."""
    parser = subparsers.add_parser(
        "collect", help="collect interactions into a dataset (parallel, resumable, deterministic)",
        description="Collect interactions into a dataset directory of Parquet chunks. Interaction i depends "
                    "only on (--seed, i), so the data do not depend on --workers or the scheduler. Rerunning "
                    "the same command resumes an interrupted collection, or extends it with a larger "
                    "--episodes; other settings on an existing dataset are refused.",
    )
    parser.add_argument("--episodes", type=int, required=True, help="number of interactions")
    parser.add_argument("--out", type=Path, required=True, help="dataset directory (resumed if it exists)")
    parser.add_argument("--seed", type=int, default=0, help="dataset seed (default 0)")
    parser.add_argument("--workers", type=int, default=1,
                        help="worker processes, or workers of the local Dask cluster (default 1)")
    parser.add_argument("--env", default="TapAffordance-v1", choices=("TapAffordance-v1", "TapAffordanceGoal-v0"),
                        dest="env_id",
                        help="TapAffordance-v1: one interaction per episode; TapAffordanceGoal-v0: goal episodes of "
                             "up to 5 interactions, a reachable behaviour and parameters drawn at each, one row per "
                             "interaction with 'step' and the goal's columns (default TapAffordance-v1)")
    parser.add_argument("--action", default="canonical", choices=("canonical", "random"),
                        help="the paper's canonical tap, or uniform random actions from (seed, i) "
                             "(default canonical)")
    parser.add_argument("--save-images", action="store_true",
                        help="also store range images (float16) and object masks (bit-packed), compressed")
    parser.add_argument("--max-failure-share", type=float, default=0.2, metavar="SHARE",
                        help="stop once more than this share of the interactions failed (the environment's "
                             "failure reasons are listed); 1 accepts any (default 0.2)")
    parser.add_argument("--chunk-size", type=int, default=50,
                        help="interactions per file, the most a crash loses per worker (default 50)")
    parser.add_argument("--scheduler", choices=("joblib", "dask"), default=None,
                        help="joblib: processes on this machine (default); dask: Dask distributed, a local "
                             "cluster of --workers processes or the one at --dask-address")
    parser.add_argument("--dask-address", default=None, metavar="ADDRESS",
                        help="Dask scheduler to run on (e.g. tcp://host:8786); implies --scheduler dask. Its "
                             "workers must see --out and have the same tap-affordance version")
    env = parser.add_argument_group("environment options (default: the environment's own)")
    env.add_argument("--behavior", default=None, help="tap | tap_back | push | grasp")
    env.add_argument("--object-types", nargs="+", default=None, metavar="TYPE",
                     help="object types to sample from: sphere box horizontal_cylinder vertical_cylinder")
    env.add_argument("--size-range", nargs=2, type=float, default=None, metavar=("LOW", "HIGH"),
                     help="object size range [m]")
    env.add_argument("--camera-width", type=int, default=None, help="range image width [pixels]")
    env.add_argument("--camera-height", type=int, default=None, help="range image height [pixels]")
    env.add_argument("--camera-fovy", type=float, default=None, help="vertical field of view [deg]")
    env.add_argument("--roll-threshold", type=float, default=None,
                     help="rolling distance above which an interaction is 'rolled' [m]; for push, the "
                          "displacement above which it is a 'success'")
    env.add_argument("--settle-timeout", type=float, default=None,
                     help="longest simulated wait for the outcome after the first touch [s]")
    env.add_argument("--range-noise", default=None, choices=("kinect_v1",),
                     help="depth noise of the range camera (default: none)")
    env.add_argument("--position-range", default=None, choices=("canonical", "workspace"),
                     help="where objects are placed: within +-3 cm of the paper's spot (canonical), or uniformly "
                          "over the behaviour's workspace (workspace; for TapAffordanceGoal-v0, the union of the "
                          "four) (default canonical)")
    parser.set_defaults(func=run_collect)
    return parser


def env_options_from_args(args: argparse.Namespace) -> dict[str, Any]:
    """The env options given on the command line; the others keep the environment's defaults."""
    options = {name: getattr(args, name) for name in _ENV_FLAGS if getattr(args, name) is not None}
    if "size_range" in options:
        options["size_range"] = tuple(options["size_range"])
    return options


def run_collect(args: argparse.Namespace) -> int:
    """Run ``affordance collect``; bad options or a dataset made with other settings raise ValueError."""
    from affordance_env.dataset import MANIFEST, collect, failure_summary, read_manifest

    if args.scheduler == "joblib" and args.dask_address is not None:
        raise ValueError("--dask-address runs on Dask: drop --scheduler joblib (or use --scheduler dask).")
    scheduler = args.scheduler or ("dask" if args.dask_address else "joblib")
    start = time.perf_counter()
    out = collect(args.out, args.episodes, seed=args.seed, workers=args.workers, action=args.action,
                  env_options=env_options_from_args(args), chunk_size=args.chunk_size, scheduler=scheduler,
                  dask_address=args.dask_address, save_images=args.save_images,
                  max_failure_share=args.max_failure_share, env_id=args.env_id)
    elapsed = time.perf_counter() - start
    manifest = read_manifest(out)
    failures = manifest["failures"]
    details = ""
    if failures["count"]:
        details = f" ({failure_summary(failures['episodes'])}; all reasons in {out / MANIFEST})"
    if manifest["settings"].get("env_id") == "TapAffordanceGoal-v0":
        print(f"{out}: {manifest['episodes']} goal episodes, {manifest['rows']} interactions written; "
              f"{failures['count']} episodes ended at a failed interaction, left out{details}; {elapsed:.1f} s")
    else:
        print(f"{out}: {manifest['rows']} interactions written, {failures['count']} failed and left "
              f"out{details}; {elapsed:.1f} s")
    return 0


def add_export_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``export`` subcommand: a collected dataset into another format (Minari)."""
    parser = subparsers.add_parser(
        "export", help="write a collected dataset as a Minari dataset (pip install 'tap-affordance[minari]')",
        description="Write a collected dataset as a Minari dataset, one episode per interaction, stored where "
                    "Minari keeps its datasets (MINARI_DATASETS_PATH, by default ~/.minari/datasets). The "
                    "Parquet dataset stays the source of truth.",
    )
    parser.add_argument("dataset", type=Path, help="the dataset directory (made by `affordance collect`)")
    parser.add_argument("--minari", required=True, metavar="DATASET_ID",
                        help="Minari dataset id, e.g. tap-affordance/canonical-taps-v0")
    parser.add_argument("--data-format", choices=("arrow", "hdf5"), default="arrow",
                        help="Minari storage format (default arrow; hdf5 needs h5py)")
    parser.add_argument("--author", default="tap-affordance", help="recorded in the Minari metadata")
    parser.add_argument("--author-email", default=None, help="recorded in the Minari metadata (default: none)")
    parser.add_argument("--code-permalink", default=None, metavar="URL",
                        help="link to the versioned code that made the data, recorded in the Minari metadata "
                             "(default: none)")
    parser.set_defaults(func=run_export)
    return parser


def run_export(args: argparse.Namespace) -> int:
    """Run ``affordance export``."""
    from affordance_env.dataset import read_manifest
    from affordance_env.dataset.minari_export import export_minari, left_out

    start = time.perf_counter()
    exported = export_minari(args.dataset, args.minari, data_format=args.data_format, author=args.author,
                             author_email=args.author_email, code_permalink=args.code_permalink)
    print(f"{args.dataset} -> Minari dataset {args.minari!r}: {exported.total_episodes} episodes in "
          f"{time.perf_counter() - start:.1f} s; load it with minari.load_dataset({args.minari!r})")
    dropped = left_out(bool(read_manifest(args.dataset)["settings"].get("save_images")))
    print("  observations: the environment's without " + "; ".join(f"{k} ({why})" for k, why in dropped.items())
          + "; infos: each interaction's ground truth (type, size, success, ...)")
    return 0

