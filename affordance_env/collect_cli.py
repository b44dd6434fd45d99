"""``affordance collect``: interactions into a dataset, in parallel and resumably (see :mod:`.dataset`)."""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import math
import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from affordance_env.exceptions import InvalidValueError
from affordance_env.objects import OBJECT_TYPES, SIZE_LIMITS
from affordance_env.options import POSITION_RANGES, EnvOptions
from affordance_env.range_noise import RANGE_NOISE_MODELS
from affordance_env.registry import BEHAVIOR_NAMES, ENV_ID, ENV_IDS, GOAL_ENV_ID
from affordance_env.values import DASK_PROTOCOLS, check_dask_address

#: Command-line flags that are env options, and the env keyword each one sets.
#: The environment options a collection takes on the command line: every field of EnvOptions, one flag each.
_ENV_FLAGS = tuple(f.name for f in dataclasses.fields(EnvOptions))


# --- argparse types: a value that cannot be used is refused as the command line is parsed --------------------
def int_at_least(low: int) -> Callable[[str], int]:
    """An argparse ``type``: an integer >= ``low``; any other value is an error that names it and the bound."""
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = None
        if value is None or value < low:
            raise argparse.ArgumentTypeError(f"expected an integer >= {low}, got {text!r}")
        return value

    parse.__name__ = f"integer >= {low}"
    return parse


#: Counts of something (interactions, trials, workers, ...) and seeds.
positive_int, non_negative_int = int_at_least(1), int_at_least(0)


def real_within(low: float, high: float = math.inf, *, open_low: bool = False,
                expected: str | None = None) -> Callable[[str], float]:
    """An argparse ``type``: a finite number in ``[low, high]`` (``(low, high]`` with ``open_low``); any other value
    is an error that names it and ``expected`` (by default the interval)."""
    if expected is None:
        expected = f"a number in {'(' if open_low else '['}{low:g}, {high:g}]"

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and (value > low if open_low else value >= low) and value <= high):
            raise argparse.ArgumentTypeError(f"expected {expected}, got {text!r}")
        return value

    parse.__name__ = expected
    return parse


def dask_address(text: str) -> str:
    """An argparse ``type``: a Dask scheduler's address, ``[PROTOCOL://]HOST:PORT``; any other form is an error."""
    try:
        return check_dask_address(text)
    except InvalidValueError:
        raise argparse.ArgumentTypeError(f"expected PROTOCOL://HOST:PORT with PROTOCOL one of "
                                         f"{', '.join(DASK_PROTOCOLS)} (e.g. tcp://scheduler:8786), got "
                                         f"{text!r}") from None


dask_address.__name__ = "Dask scheduler address"

#: A share, as of failed interactions: 0 to 1.
share = real_within(0.0, 1.0, expected="a share in [0, 1]")


def check_writable(path: Path, what: str, *, directory: bool = True) -> None:
    """Refuse, before any work, a path that a command cannot write: a ``directory`` to make or write into, or (not
    ``directory``) a file to write, whose folder must be one. InvalidValueError whose message starts with ``what``,
    the option and the path given (``--out taps``). What the check makes (folders, a probe file) is removed again."""
    if not directory and path.is_dir():
        raise InvalidValueError(f"{what} is a directory, not a file.")
    folder = path if directory else path.parent
    blocker = next((p for p in (folder, *folder.parents) if p.exists() and not p.is_dir()), None)
    if blocker == path:
        raise InvalidValueError(f"{what} is a file, not a directory.")
    if blocker is not None:
        raise InvalidValueError(f"{what} cannot be written: {blocker} is a file, not a directory.")
    missing = [d for d in (folder, *folder.parents) if not d.exists()]
    probe = folder / f".affordance-write-test-{os.getpid()}"
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with open(probe, "w"):
            pass
    except OSError as exc:
        raise InvalidValueError(f"{what} cannot be written: {folder} ({exc.strerror}).") from None
    finally:
        with contextlib.suppress(OSError):
            probe.unlink(missing_ok=True)
        for made in missing:  # deepest first: only what the check made, and only if still empty
            with contextlib.suppress(OSError):
                made.rmdir()


def add_collect_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``collect`` subcommand to ``subparsers``; it runs :func:`run_collect` via ``args.func``."""
    parser = subparsers.add_parser(
        "collect", help="collect interactions into a dataset (parallel, resumable, deterministic)",
        description="Collect interactions into a dataset directory of Parquet chunks. Interaction i depends "
                    "only on (--seed, i), so the data do not depend on --workers or the scheduler. Rerunning "
                    "the same command resumes an interrupted collection, or extends it with a larger "
                    "--episodes; other settings on an existing dataset are refused.",
    )
    parser.add_argument("--episodes", type=positive_int, required=True,
                        help="how many to collect: interactions of TapAffordance-v2, episodes (of several "
                        "interactions each) of TapAffordanceGoal-v2")
    parser.add_argument("--out", type=Path, required=True, help="dataset directory (resumed if it exists)")
    parser.add_argument("--seed", type=non_negative_int, default=0, help="dataset seed (default 0)")
    parser.add_argument("--workers", type=positive_int, default=1,
                        help="worker processes, or workers of the local Dask cluster (default 1): at most one "
                             "per chunk to collect and, without --oversubscribe, one per core")
    parser.add_argument("--oversubscribe", action="store_true",
                        help="start --workers processes even where they are more than this machine's cores")
    parser.add_argument("--env", default=ENV_ID, choices=ENV_IDS,
                        dest="env_id",
                        help="TapAffordance-v2: one interaction per episode; TapAffordanceGoal-v2: goal episodes of "
                             "up to 5 interactions, a reachable behaviour and parameters drawn at each, one row per "
                             "interaction with 'step' and the goal's columns (default TapAffordance-v2)")
    parser.add_argument("--action", default="canonical", choices=("canonical", "random"),
                        help="the paper's canonical tap, or uniform random actions from (seed, i) "
                             "(default canonical)")
    parser.add_argument("--save-images", action="store_true",
                        help="also store range images (float16) and object masks (bit-packed), compressed")
    parser.add_argument("--max-failure-share", type=share, default=0.2, metavar="SHARE",
                        help="stop once more than this share of the interactions failed (the environment's "
                             "failure reasons are listed); 1 accepts any (default 0.2)")
    parser.add_argument("--chunk-size", type=positive_int, default=50,
                        help="interactions per file, the most a crash loses per worker (default 50)")
    parser.add_argument("--scheduler", choices=("joblib", "dask"), default=None,
                        help="joblib: processes on this machine (default); dask: Dask distributed, a local "
                             "cluster of --workers processes or the one at --dask-address")
    parser.add_argument("--dask-address", type=dask_address, default=None, metavar="ADDRESS",
                        help="Dask scheduler to run on (e.g. tcp://host:8786); implies --scheduler dask. Its "
                             "workers must see --out and have the same tap-affordance version")
    low, high = SIZE_LIMITS
    env = parser.add_argument_group("environment options (default: the environment's own)")
    env.add_argument("--behavior", default=None, help=" | ".join(BEHAVIOR_NAMES))
    env.add_argument("--object-types", nargs="+", default=None, metavar="TYPE",
                     help=f"object types to sample from: {' '.join(OBJECT_TYPES)}")
    env.add_argument("--size-range", nargs=2, default=None, metavar=("LOW", "HIGH"),
                     type=real_within(low, high, expected=f"a size in metres in [{low:g}, {high:g}] (what the "
                                      "hand can tap)"),
                     help=f"object size range [m], LOW <= HIGH, both within {low:g}-{high:g}")
    env.add_argument("--camera-width", type=int_at_least(2), default=None, help="range image width [pixels]")
    env.add_argument("--camera-height", type=int_at_least(2), default=None, help="range image height [pixels]")
    env.add_argument("--camera-fovy", type=real_within(1.0, 170.0, expected="a field of view in [1, 170] degrees"),
                     default=None, help="vertical field of view [deg]")
    env.add_argument("--roll-threshold", default=None,
                     type=real_within(0.0, open_low=True, expected="a positive distance in metres"),
                     help="rolling distance above which an interaction is 'rolled' [m]; for push, the "
                          "displacement above which it is a 'success'")
    env.add_argument("--settle-timeout", default=None,
                     type=real_within(0.0, open_low=True, expected="a positive duration in seconds"),
                     help="longest simulated wait for the outcome after the first touch [s]")
    env.add_argument("--range-noise", default=None, choices=RANGE_NOISE_MODELS,
                     help="depth noise of the range camera (default: none)")
    env.add_argument("--position-range", default=None, choices=POSITION_RANGES,
                     help="where objects are placed: within +-3 cm of the paper's spot (canonical), or uniformly "
                          "over the behaviour's workspace (workspace; for TapAffordanceGoal-v2, the workspace of a "
                          "behaviour drawn uniformly) (default canonical)")
    env.add_argument("--two-arms", action="store_const", const=True, default=None,
                     help="the scene with both arms, the other arm rigid at its home pose (the scene of "
                          f"{GOAL_ENV_ID}; default: the acting arm alone)")
    parser.set_defaults(func=run_collect)
    return parser


def env_options_from_args(args: argparse.Namespace) -> dict[str, Any]:
    """The env options given on the command line; the others keep the environment's defaults."""
    options = {name: getattr(args, name) for name in _ENV_FLAGS if getattr(args, name) is not None}
    if "size_range" in options:
        options["size_range"] = tuple(options["size_range"])
    return options


def check_collect_args(args: argparse.Namespace) -> None:
    """What the options of ``affordance collect`` say together, and its ``--out`` (a dataset or a new directory,
    which can be written: :func:`check_writable`), checked without the simulator and before anything is built or
    written: ValueError naming the options. (Each value alone is checked as it is parsed.)"""

    if args.scheduler == "joblib" and args.dask_address is not None:
        raise InvalidValueError("--dask-address runs on Dask: drop --scheduler joblib (or use --scheduler dask).")
    if args.size_range is not None and args.size_range[0] > args.size_range[1]:
        low, high = args.size_range
        raise InvalidValueError(f"--size-range {low:g} {high:g}: expected LOW <= HIGH (equal for a single size).")
    if args.env_id == GOAL_ENV_ID and args.behavior is not None:
        raise InvalidValueError(f"--env {GOAL_ENV_ID} chooses among all the behaviours at every step: drop --behavior "
                         f"{args.behavior}.")
    try:
        EnvOptions.checked(**env_options_from_args(args))
    except ValueError as exc:
        flags = {name: "--" + name.replace("_", "-") for name in _ENV_FLAGS}
        message = str(exc)
        for name, flag in flags.items():  # name the options as they were given
            message = message.replace(f"{name} must", f"{flag} must")
        raise InvalidValueError(message) from None
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise InvalidValueError(f"--out {out} is a file, not a dataset directory.")
    if out.is_dir():
        from affordance_env.dataset.format import MANIFEST

        if not (out / MANIFEST).exists() and any(p.name != ".lock" for p in out.iterdir()):
            raise InvalidValueError(f"--out {out} exists and is not a TapAffordance dataset (no {MANIFEST}): choose an "
                             "empty or new directory, or a dataset to resume or extend.")
    check_writable(out, f"--out {out}")


def run_collect(args: argparse.Namespace) -> int:
    """Run ``affordance collect``; bad options or a dataset made with other settings raise ValueError."""
    check_collect_args(args)
    from affordance_env.dataset import MANIFEST, collect, failure_summary, read_manifest

    scheduler = args.scheduler or ("dask" if args.dask_address else "joblib")
    start = time.perf_counter()
    out = collect(args.out, args.episodes, seed=args.seed, workers=args.workers, action=args.action,
                  env_options=env_options_from_args(args), chunk_size=args.chunk_size, scheduler=scheduler,
                  dask_address=args.dask_address, save_images=args.save_images,
                  max_failure_share=args.max_failure_share, env_id=args.env_id,
                  oversubscribe=args.oversubscribe)
    elapsed = time.perf_counter() - start
    manifest = read_manifest(out)
    failures = manifest["failures"]
    details = ""
    if failures["count"]:
        details = f" ({failure_summary(failures['episodes'])}; all reasons in {out / MANIFEST})"
    if manifest["settings"].get("env_id") == GOAL_ENV_ID:
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
    """Run ``affordance export``; a malformed id is refused first, before Minari is imported."""
    from affordance_env.dataset.minari_export import check_dataset_id_form

    check_dataset_id_form(args.minari)
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

