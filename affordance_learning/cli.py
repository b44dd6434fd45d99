"""The ``affordance`` command line.

The arguments are parsed and checked before anything heavy (the simulator, the learning models) is imported, so
that a command-line mistake is a one-line error at once, before any work starts and before anything is written.
"""

from __future__ import annotations

import atexit
import os
import signal
import sys
import threading

#: Exit status of a run stopped by Ctrl-C (128 + SIGINT), as a shell reports it.
INTERRUPTED = 130
#: What Ctrl-C says, at whatever moment of a command it comes: that it stopped, and what the command leaves.
INTERRUPTED_LINE = "affordance: interrupted"
#: What a command that collects leaves when Ctrl-C stops it, and what one that does not leaves.
INTERRUPTED_KEPT = "what was finished is kept (the same command resumes a collection from its last finished chunk)"
INTERRUPTED_LEFT = {"export": "an unfinished export leaves no Minari dataset"}
#: The commands that collect interactions into a dataset, which the same command resumes.
COLLECTING = ("collect", "reproduce", "plan", "train-default")


def _was_interrupted(exc: BaseException) -> bool:
    """Whether ``exc`` is Ctrl-C's KeyboardInterrupt, or an error raised because of one (a compiled module whose
    initialisation it interrupted raises ImportError("initialization failed") from it)."""
    seen: set[int] = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False


def _say_interrupted(command: str | None = None) -> None:
    """The line of Ctrl-C, with what ``command`` leaves (before the command is known, nothing has been done)."""
    left = INTERRUPTED_KEPT if command in COLLECTING else INTERRUPTED_LEFT.get(command or "")
    print(INTERRUPTED_LINE + (f"; {left}" if left else ""), file=sys.stderr, flush=True)


try:  # Ctrl-C while the command's own modules load is the same one line, not a traceback
    import argparse
    import contextlib
    import json
    import time
    import warnings
    from pathlib import Path
    from typing import TYPE_CHECKING, NoReturn

    from affordance_env.collect_cli import (
        add_collect_parser,
        add_export_parser,
        check_writable,
        int_at_least,
        non_negative_int,
        positive_int,
    )
    from affordance_env.registry import BEHAVIOR_NAMES, ENV_ID
    from affordance_learning.common.exceptions import AffordanceError, InvalidValueError
    from affordance_learning.planning.results import PLAN_RESULTS_FORMAT
except BaseException as exc:
    if not _was_interrupted(exc):
        raise
    _say_interrupted()
    raise SystemExit(INTERRUPTED) from None

if TYPE_CHECKING:
    from affordance_learning.paper.results import Results

#: The sizes of ``affordance plan`` (:class:`~affordance_learning.planning.experiment.PlanSettings`' defaults), for its
#: help; an option not given keeps PlanSettings' own default.
PLAN_DEFAULTS = {"episodes": 1500, "objects": 24, "multi_episodes": 64}
#: What ``affordance plan`` writes into its ``--out``: its goal episodes in this directory, and its results
#: (of the format :data:`~affordance_learning.planning.results.PLAN_RESULTS_FORMAT`), report and figures beside it.
PLAN_DATASET = "dataset"


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line: what is wrong with which argument, and where the options are
    listed."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {' '.join(message.split())} (see {self.prog} --help)\n")


def _check_demo(args: argparse.Namespace) -> None:
    from affordance_env.objects import check_object_type
    from affordance_env.registry import check_behavior_name

    check_behavior_name(args.behavior)
    if args.object:
        check_object_type(args.object)


def _demo(args: argparse.Namespace) -> int:
    _check_demo(args)
    import gymnasium as gym
    import numpy as np

    import affordance_env  # noqa: F401  (registers the environment)

    kwargs = {"behavior": args.behavior}
    if args.object:
        kwargs["object_types"] = (args.object,)
    env = gym.make(ENV_ID, **kwargs)
    print(f"TapAffordance-v2, behavior={args.behavior!r}: {args.episodes} interaction(s) from seed {args.seed}")
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


def _datasets(items: list[str], behaviors: list[str]) -> dict[str, Path]:
    """``--dataset`` values, ``BEHAVIOR=PATH`` or (with one behaviour) ``PATH``, as a directory per behaviour.

    Text before an ``=`` that could be a name (no path separator) is a behaviour, which must be one the
    environment has, and its PATH must not be empty: ``kick=taps`` or ``=taps`` is refused, not taken for a
    folder of that name (a path that holds ``=`` is given as ``./kick=taps``)."""
    datasets: dict[str, Path] = {}
    known = sorted({*behaviors, *BEHAVIOR_NAMES})
    for item in items:
        name, equals, path = item.partition("=")
        if equals and "/" not in name and os.sep not in name:
            if name not in known:
                raise InvalidValueError(
                    f"--dataset {item}: {'no behaviour before =' if not name else f'unknown behaviour {name!r}'}; "
                    f"give BEHAVIOR=PATH with BEHAVIOR one of {', '.join(known)} (a path that holds '=' is "
                    "given as ./PATH).")
            if not path:
                raise InvalidValueError(f"--dataset {item}: no PATH after '{name}='; give {name}=PATH.")
        else:  # a bare path
            if len(behaviors) != 1:
                raise InvalidValueError(
                    f"--dataset {item}: say whose dataset it is, as BEHAVIOR=PATH with BEHAVIOR one "
                    f"of {', '.join(behaviors)} (a bare PATH is for a single --behavior).")
            name, path = behaviors[0], item
        if name in datasets:
            raise InvalidValueError(f"--dataset given twice for {name!r}.")
        datasets[name] = Path(path)
    return datasets


def _reproduce(args: argparse.Namespace) -> int:
    check_writable(args.out, f"--out {args.out}")
    from affordance_learning.paper.reproduce import DEFAULT_BEHAVIORS, reproduce

    behaviors = args.behavior or list(DEFAULT_BEHAVIORS)
    reproduce(args.out, behaviors=behaviors, episodes=args.episodes, trials=args.trials, seed=args.seed,
              workers=args.workers, datasets=_datasets(args.dataset, behaviors), range_noise=args.range_noise,
              progress=args.progress)
    return 0


def _train_action_models(args: argparse.Namespace) -> int:
    """``affordance train-default --action-conditioned``: goal episodes with random actions (collected into
    ``--dataset`` or reused from there) until every behaviour has 1000 interactions, then an action-conditioned
    model per behaviour."""
    from affordance_learning.user_models import DATA_ENV, user_model_dir

    dataset = args.dataset or Path("default-actions")
    out = args.out or user_model_dir()
    check_writable(out, f"--out {out}" if args.out else f"the models' directory {out} (set it with --out or "
                   f"${DATA_ENV})")
    check_writable(dataset, f"--dataset {dataset}")
    from affordance_learning.default_model import ACTION_INTERACTIONS, train_action_models
    from affordance_learning.planning.experiment import PlanSettings, collect_training

    settings = PlanSettings(max_per_behavior=ACTION_INTERACTIONS)
    frame = collect_training(dataset, settings, seed=0, workers=args.workers, camera=(160, 120))
    written = train_action_models(frame, out)
    print(f"action-conditioned default models of {', '.join(written)} written to {out} "
          f"({', '.join(f'{b} {int((frame.behavior == b).sum())}' for b in written)} interactions collected)")
    return 0


def _train_default(args: argparse.Namespace) -> int:
    if args.action_conditioned:
        return _train_action_models(args)
    from affordance_learning.common.behaviors import check_behavior, check_env_offers
    from affordance_learning.user_models import DATA_ENV, user_model_path

    behavior = check_behavior(args.behavior)
    dataset = args.dataset or Path("default-taps" if behavior == "tap" else f"default-{behavior}")
    out = args.out or user_model_path(behavior)
    what = f"--out {out}" if args.out else f"the model's place {out} (set it with --out or ${DATA_ENV})"
    if out.is_dir():
        raise InvalidValueError(f"{what} is a directory, not a model file.")
    check_writable(out, what, directory=False)
    check_writable(dataset, f"--dataset {dataset}")
    from affordance_env.dataset.format import MANIFEST, read_manifest

    if (dataset / MANIFEST).exists():  # say so plainly, before the collection refuses its other settings
        found = read_manifest(dataset)["settings"].get("env_options", {}).get("behavior", "tap")
        if found != behavior:
            raise InvalidValueError(f"{dataset} holds {found!r} interactions, not {behavior!r} ones: give --dataset a "
                             f"dataset of {behavior} interactions, or a new directory to collect them into.")
    check_env_offers([behavior])
    from affordance_env.dataset import collect, load_dataset
    from affordance_learning.default_model import train_default_model

    collect(dataset, 1000, seed=0, workers=args.workers, env_options={"behavior": behavior})
    model = train_default_model(load_dataset(dataset), out, behavior=behavior)
    print(f"default {behavior} model ({model.n_clusters} categories, {len(model.selected_features_)} features "
          f"selected: {', '.join(model.selected_feature_names_)}) written to {out}")
    return 0


def _fingerprint(args: argparse.Namespace) -> int:
    from affordance_learning.paper.reproduce import check_fingerprint, write_reference_fingerprint

    drifted = 0
    for where in args.reproduction:
        if not args.check:
            print(f"{write_reference_fingerprint(where, args.workers)} written")
            continue
        check = check_fingerprint(where, args.workers)
        drifted += not check.ok
        print(f"{where}: {check.summary()}")
        for problem in check.problems:
            print(f"  {problem}")
    return 1 if drifted else 0


def _compare(args: argparse.Namespace) -> int:
    from affordance_learning.paper.agreement import UNSTABLE_SPREAD, compare_results

    found = [_results_of(where) for where in (args.reference, args.found)]
    comparisons = compare_results(*found)
    outside = [c for c in comparisons if not c.ok]
    held = [c for c in comparisons if c.held]
    print(f"{args.found} against {args.reference}: {len(held) - len(outside)} of {len(held)} numbers within their "
          f"tolerances; {len(comparisons) - len(held)} whose trials spread by more than "
          f"{100 * UNSTABLE_SPREAD:.0f} points are shown, not held to one")
    for comparison in comparisons:
        print(f"  {comparison}")
    return 1 if outside else 0


def _results_of(where: Path) -> Results:
    """The learning results in ``where`` (a reproduction's directory, or its ``results.json``)."""
    from affordance_learning.paper.results import Results

    results = _read_json(where / "results.json" if where.is_dir() else where)
    if not isinstance(results, dict) or "config" not in results:
        raise InvalidValueError(f"{where} holds no results.json of `affordance reproduce`.")
    return Results.from_dict(results)


def _read_json(path: Path) -> object:
    """The JSON value in ``path``; None if it cannot be read as JSON."""
    try:
        return json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, ValueError):
        return None


def _dataset_kind(manifest: object) -> str:
    """What a dataset's manifest says the dataset holds, for a person."""
    from affordance_env.dataset.format import FORMAT, MANIFEST

    if not isinstance(manifest, dict) or manifest.get("format") != FORMAT:
        return f"a {MANIFEST} that is not a TapAffordance dataset's"
    settings = manifest.get("settings") if isinstance(manifest.get("settings"), dict) else {}
    env_id = settings.get("env_id", ENV_ID)
    options = settings.get("env_options") if isinstance(settings.get("env_options"), dict) else {}
    what = f"{options.get('behavior', 'tap')} interactions" if env_id == ENV_ID else "episodes"
    return (f"a {env_id} dataset of {manifest.get('episodes', '?')} {what} with {settings.get('action', '?')} "
            f"actions, seed {settings.get('seed', '?')}")


def _check_plan_out(out: Path, seed: int) -> None:
    """Refuse an ``--out`` of ``affordance plan`` that holds anything but an earlier plan's output (its dataset is
    resumed, its results rewritten), before anything is written."""
    check_writable(out, f"--out {out}")
    if not out.exists():
        return
    from affordance_env.dataset.format import GOAL_ENV_ID, MANIFEST

    hint = (f"affordance plan writes its goal episodes into OUT/{PLAN_DATASET} and results.json, REPORT.md and "
            "figures beside it: give a new or empty directory, or an earlier plan's to resume it")
    if (out / MANIFEST).exists():
        raise InvalidValueError(
            f"--out {out} is a dataset directory ({_dataset_kind(_read_json(out / MANIFEST))}), not a "
                         f"plan's: {hint}.")
    own = False
    dataset = out / PLAN_DATASET
    if dataset.exists() and not dataset.is_dir():
        raise InvalidValueError(f"--out {out} holds a file {PLAN_DATASET}, not the plan's dataset directory: {hint}.")
    if (dataset / MANIFEST).exists():
        manifest = _read_json(dataset / MANIFEST)
        settings = manifest.get("settings") if isinstance(manifest, dict) else None
        if not (isinstance(settings, dict) and settings.get("env_id") == GOAL_ENV_ID
                and settings.get("action") == "random"):
            raise InvalidValueError(f"{dataset} holds {_dataset_kind(manifest)}, not the plan's {GOAL_ENV_ID} episodes "
                             f"with random actions: {hint}.")
        if settings.get("seed") != seed:
            raise InvalidValueError(
                f"{dataset} holds the plan's episodes of seed {settings.get('seed')!r}, not of --seed "
                             f"{seed}: give --seed {settings.get('seed')!r} to resume that plan, or another --out.")
        own = True
    elif dataset.is_dir() and any(p.name != ".lock" for p in dataset.iterdir()):
        raise InvalidValueError(f"{dataset} holds files but no {MANIFEST}, so it is not a dataset the plan can resume: "
                         f"{hint}.")
    results = out / "results.json"
    if results.exists():
        found = _read_json(results)
        if not (isinstance(found, dict) and found.get("format") == PLAN_RESULTS_FORMAT):
            what = f"of format {found.get('format')!r}" if isinstance(found, dict) else "that is not a plan's"
            raise InvalidValueError(f"--out {out} holds a results.json {what}, not a plan's ({PLAN_RESULTS_FORMAT}): "
                             f"{hint}.")
        own = True
    others = sorted(p.name for p in out.iterdir() if not p.name.startswith(".") and p.name != PLAN_DATASET)
    if others and not own:
        listed = ", ".join(others[:3]) + (", ..." if len(others) > 3 else "")
        raise InvalidValueError(f"--out {out} is not empty ({listed}) and holds no earlier plan's results or dataset: "
                         f"{hint}.")


def _plan(args: argparse.Namespace) -> int:
    _check_plan_out(args.out, args.seed)
    from dataclasses import replace

    from affordance_learning.common.verdicts import tally_text
    from affordance_learning.planning.experiment import QUICK, PlanSettings, record_episode, run_plan
    from affordance_learning.planning.report import write_plan_figures, write_plan_report
    from affordance_learning.planning.targets import evaluate_targets

    settings = replace(QUICK if args.quick else PlanSettings(),
                       **{name: getattr(args, name) for name in PLAN_DEFAULTS if getattr(args, name) is not None})
    if settings.quick:
        print("a quick run: the whole pipeline on few data (--quick), so its targets' verdicts read \"too few data\" "
              "where n is below a target's minimum")
    plan = run_plan(args.out, seed=args.seed, workers=args.workers, settings=settings)
    frames = record_episode(args.out, plan, seed=args.seed)
    write_plan_figures(plan, args.out, frames)
    report = write_plan_report(plan, args.out)
    verdicts = list(evaluate_targets(plan).values())
    quick = " of a quick run, on too few data for most verdicts" if settings.quick else ""
    print(f"{tally_text(verdicts, 'targets')}{quick} (a verdict only on enough data); {report} gives each with its n "
          f"and why a missed one is missed; {args.out / 'results.json'} holds every number "
          f"({plan.total_time_s / 60:.1f} min)")
    return 0


def _add_demo_parser(sub: argparse._SubParsersAction) -> None:
    """The ``demo`` subcommand: tap a few objects and print what happened."""
    demo = sub.add_parser("demo", help="tap a few objects with the canonical tap and print what happened")
    demo.add_argument("--episodes", type=positive_int, default=8, help="number of interactions (default 8)")
    demo.add_argument("--seed", type=non_negative_int, default=0, help="seed of the first interaction (default 0)")
    demo.add_argument("--behavior", default="tap", help=" | ".join(BEHAVIOR_NAMES) + " (default tap)")
    demo.add_argument("--object", default=None, help="only this object type (default: all four)")
    demo.set_defaults(func=_demo)


def _add_reproduce_parser(sub: argparse._SubParsersAction) -> None:
    """The ``reproduce`` subcommand: the paper's experiment per behaviour."""
    reproduce = sub.add_parser(
        "reproduce", help="the paper's experiment per behaviour (tap and grasp): collect, learn, write "
        "results.json, figures and a report for each, and a report over all of them",
        description="For each behaviour: collect (or reuse) its canonical interactions into OUT/BEHAVIOR/dataset, "
        "run the learning protocol, write OUT/BEHAVIOR/results.json, figures and REPORT.md; then OUT/REPORT.md "
        "over the behaviours.",
    )
    reproduce.add_argument("--behavior", action="append", default=None, metavar="NAME",
                           help="run this behaviour; repeat for several (default: tap and grasp, the paper's)")
    reproduce.add_argument("--episodes", type=int_at_least(20), default=1000,
                           help="interactions per behaviour, at least 20 for the protocol's splits (default 1000)")
    reproduce.add_argument("--trials", type=positive_int, default=20, help="learning trials per setting (default 20)")
    reproduce.add_argument("--seed", type=non_negative_int, default=0,
                           help="seed of the dataset and the trials (default 0)")
    reproduce.add_argument("--workers", type=positive_int, default=2, help="worker processes (default 2)")
    reproduce.add_argument("--dataset", action="append", default=[], metavar="[BEHAVIOR=]PATH",
                           help="a behaviour's dataset directory, collected there or reused (default "
                           "OUT/BEHAVIOR/dataset); repeatable; a bare PATH when one behaviour runs")
    reproduce.add_argument("--out", type=Path, default=Path("reproduction"),
                           help="output directory (default reproduction)")
    reproduce.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                           help="progress bars (default: on a terminal, unless CI is set)")
    reproduce.add_argument("--range-noise", default=None, choices=("kinect_v1",),
                           help="collect with the range camera's depth noise model (default: exact ranges)")
    reproduce.set_defaults(func=_reproduce)


def _add_fingerprint_parser(sub: argparse._SubParsersAction) -> None:
    """The ``fingerprint`` subcommand: pin down (or check) the interactions behind a reproduction."""
    fingerprint = sub.add_parser(
        "fingerprint", help="pin down (or check) the first interactions behind a reproduction's results.json",
        description="For each reproduction directory (one behaviour's, holding results.json, e.g. "
        "docs/reproduction/tap), collect again the first 30 interactions that `affordance reproduce` collects for "
        "it (its behaviour, seed and range noise) and write their fingerprint.json (a SHA-256 per part of each "
        "row, and the versions and CPU it was made with), or with --check compare them with it (exit status 1 if "
        "they differ): bit for bit where the versions and the CPU are those it records, by the interactions' "
        "outcome labels elsewhere; the first line says which check was made. Rewrite the fingerprints whenever "
        "the results are regenerated: affordance fingerprint docs/reproduction/*/",
    )
    fingerprint.add_argument("reproduction", nargs="+", type=Path, metavar="DIR",
                             help="a behaviour's reproduction directory, e.g. docs/reproduction/tap")
    fingerprint.add_argument("--check", action="store_true", help="compare instead of writing")
    fingerprint.add_argument("--workers", type=positive_int, default=1, help="worker processes (default 1)")
    fingerprint.set_defaults(func=_fingerprint)


def _add_compare_parser(sub: argparse._SubParsersAction) -> None:
    """The ``compare`` subcommand: a reproduction's numbers beside a reference's."""
    compare = sub.add_parser(
        "compare", help="set a reproduction's numbers beside a reference's, with the tolerances they must keep",
        description="Compare two reproductions of one behaviour (directories holding results.json of `affordance "
        "reproduce` with the same settings, e.g. docs/reproduction/tap and reproduction/tap): every uniformity, "
        "SVM accuracy and the share of successes, each with the tolerance a reproduction keeps across machines and "
        "versions (README, Reproducibility). Exit status 1 if a number lies outside its tolerance.",
    )
    compare.add_argument("reference", type=Path, metavar="REFERENCE", help="the reference, e.g. docs/reproduction/tap")
    compare.add_argument("found", type=Path, metavar="DIR", help="the reproduction to check, e.g. reproduction/tap")
    compare.set_defaults(func=_compare)


def _add_plan_parser(sub: argparse._SubParsersAction) -> None:
    """The ``plan`` subcommand: learn the behaviours' effects, then plan to reach goals."""
    plan = sub.add_parser(
        "plan", help="learn what each behaviour does to objects, then choose behaviours to reach goals, against "
        "baselines (results.json, REPORT.md, figures)",
        description="Collect goal episodes with random actions (objects over the workspaces), fit an "
        "action-conditioned effect model per behaviour, and evaluate a planner on held-out objects (single step, "
        "leaving each shape out, multi-step episodes) against random, fixed, canonical, the paper's categories and "
        "an oracle that tries actions in simulation. Writes OUT/results.json, OUT/REPORT.md and figures.",
    )
    plan.add_argument("--out", type=Path, required=True,
                      help="output directory: new, empty or an earlier plan's (whose dataset is resumed)")
    plan.add_argument("--seed", type=non_negative_int, default=0,
                      help="seed of the data and of the evaluation (default 0)")
    plan.add_argument("--workers", type=positive_int, default=2, help="worker processes (default 2)")
    plan.add_argument("--episodes", type=positive_int, default=None,
                      help="goal episodes collected for training at first, extended until every behaviour has 1000 "
                      f"interactions (default {PLAN_DEFAULTS['episodes']})")
    plan.add_argument("--objects", type=positive_int, default=None,
                      help="held-out objects of the single-step evaluation, 20 goals each (default "
                      f"{PLAN_DEFAULTS['objects']})")
    plan.add_argument("--multi-episodes", type=positive_int, default=None,
                      help=f"multi-step episodes per policy (default {PLAN_DEFAULTS['multi_episodes']})")
    plan.add_argument("--quick", action="store_true",
                      help="a quick run: the whole pipeline on few data (few episodes, objects and trees) in a few "
                      "minutes, its verdicts on too few data; --episodes, --objects, --multi-episodes still apply")
    plan.set_defaults(func=_plan)


def _add_train_default_parser(sub: argparse._SubParsersAction) -> None:
    """The ``train-default`` subcommand: rebuild a behaviour's default model."""
    train = sub.add_parser("train-default", help="rebuild a behaviour's default model behind predict_effect")
    train.add_argument("--behavior", default="tap", metavar="NAME",
                       help="whose model: tap (default) or grasp (both shipped), tap_back, push or draw")
    train.add_argument("--dataset", type=Path, default=None,
                       help="where the behaviour's 1000 canonical interactions (seed 0) are collected, or reused "
                       "(default ./default-taps for the tap, ./default-BEHAVIOR otherwise)")
    train.add_argument("--workers", type=positive_int, default=2, help="worker processes (default 2)")
    train.add_argument("--out", type=Path, default=None,
                       help="model file (default: BEHAVIOR_model.joblib in the user's data directory, "
                       "$TAP_AFFORDANCE_DATA, $XDG_DATA_HOME/tap-affordance or ~/.local/share/tap-affordance, "
                       "where predict_effect finds it); "
                       "with --action-conditioned the directory of the models")
    train.add_argument("--action-conditioned", action="store_true",
                       help="build every behaviour's action-conditioned model (predict_effect(..., action=...)) "
                       "from goal episodes with random actions, collected into --dataset (default "
                       "./default-actions) until every behaviour has 1000 interactions")
    train.set_defaults(func=_train_default)


def build_parser() -> argparse.ArgumentParser:
    """The parser of every subcommand; each value is checked as it is parsed (counts, seeds, shares, sizes)."""
    from affordance_learning import __version__

    parser = _Parser(prog="affordance", description=__doc__)
    parser.add_argument("--version", action="version", version=f"%(prog)s (tap-affordance) {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    _add_demo_parser(sub)
    add_collect_parser(sub)
    add_export_parser(sub)
    _add_reproduce_parser(sub)
    _add_fingerprint_parser(sub)
    _add_compare_parser(sub)
    _add_plan_parser(sub)
    _add_train_default_parser(sub)
    return parser


def _one_line(exc: BaseException) -> str:
    """What went wrong, for a person, on one line: a file system error names the path and the reason."""
    if isinstance(exc, OSError) and exc.strerror and exc.filename is not None:
        return f"{exc.filename}: {exc.strerror}"
    return " ".join(str(exc).split()) or type(exc).__name__


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``affordance`` console script.

    A user error (a bad option, a path that cannot be used or written, a dataset that cannot be read or
    extended, a missing optional package: an error of the packages' ``exceptions`` modules or an ``OSError``) is
    one line on stderr and exit status 2; a command-line mistake is
    found before any work starts (a value that cannot be used at all raises SystemExit(2) as it is parsed, the
    others are checked before the subcommand imports what it runs). Ctrl-C is one line and status 130 at any
    moment, the imports of the command's modules included; the line says what the command leaves (a command that
    collects keeps the dataset's finished chunks, and the same command resumes it). A warning is one line too
    (``affordance: warning: ...``). Anything else is a bug and keeps its traceback. Run as the command (``argv`` None),
    a Ctrl-C after the command's work, as the process ends, is that line and status 130 too, or, once the
    interpreter tears its modules down, nothing: the process ends as it would have.
    """
    if argv is None and threading.current_thread() is threading.main_thread():
        # registered before the command's work loads modules that register their own: called after theirs, once
        # no Python code of the command is left to run, and before the interpreter puts back the default handling
        # of SIGINT (an exit by the signal, without a word)
        atexit.register(signal.signal, signal.SIGINT, signal.SIG_IGN)
    command = None
    try:
        args = build_parser().parse_args(argv)
        command = args.command
        return _run(args)
    except BaseException as exc:
        if not _was_interrupted(exc):
            raise
        _say_interrupted(command)
        return INTERRUPTED
    finally:
        if argv is None:
            _interrupt_ends_the_process(command)


def _one_line_warning(message: Warning | str, category: type[Warning], filename: str, lineno: int,
                      file: object = None, line: str | None = None) -> None:
    """``warnings.showwarning`` of the command: a warning is one line on stderr, as its notes and errors are, not
    the source line that raised it."""
    print(f"affordance: warning: {' '.join(str(message).split())}", file=sys.stderr, flush=True)


def _run(args: argparse.Namespace) -> int:
    # joblib's resource tracker, a process of its own that inherits this environment, lists on Ctrl-C the
    # semaphores of the workers it stopped as it cleans them up: two warnings after the line below, not for people
    tracker = "ignore::UserWarning:joblib.externals.loky.backend.resource_tracker"
    if tracker not in os.environ.get("PYTHONWARNINGS", ""):
        os.environ["PYTHONWARNINGS"] = ",".join(w for w in (os.environ.get("PYTHONWARNINGS"), tracker) if w)
    with warnings.catch_warnings():
        warnings.showwarning = _one_line_warning  # put back as the block ends
        # joblib's note, on Ctrl-C, that the chunks its workers held were cancelled: the line below says it
        warnings.filterwarnings("ignore", message=".*tasks which were still being processed by the workers",
                                category=UserWarning)
        try:
            return args.func(args)
        except (AffordanceError, OSError) as exc:  # FileNotFoundError: an OSError
            if _was_interrupted(exc):
                raise
            print(f"affordance: error: {_one_line(exc)}", file=sys.stderr)
            return 2


def _interrupt_ends_the_process(command: str | None) -> None:
    """From now on Ctrl-C ends this process at once with the one line of ``command`` and status 130: the command's
    work is over and only the interpreter's shutdown (its threads, its exit handlers) is left, where a
    KeyboardInterrupt would be a traceback."""
    def stop(signum: int, frame: object) -> None:
        with contextlib.suppress(Exception):
            sys.stdout.flush()
        _say_interrupted(command)
        os._exit(INTERRUPTED)

    if (threading.current_thread() is threading.main_thread()
            and signal.getsignal(signal.SIGINT) is signal.default_int_handler):
        signal.signal(signal.SIGINT, stop)


if __name__ == "__main__":
    raise SystemExit(main())
