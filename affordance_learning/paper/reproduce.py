"""``affordance reproduce``: the paper's experiment end to end, from the simulator to the reports.

The paper learns one model per behaviour ("a separate SOM and SVM for each behavior") and reports on tapping
and grasping. For each behaviour asked (by default :data:`DEFAULT_BEHAVIORS`), into ``out/<behavior>/``:

1. Collect (or reuse) ``episodes`` canonical interactions with :func:`affordance_env.dataset.collect` into
   ``out/<behavior>/dataset`` (or the directory given for that behaviour); the dataset is resumable, so an
   interrupted run continues where it stopped, and a finished one is reused.
2. Run the learning protocol (:func:`affordance_learning.paper.protocol.run_protocol`) over k = 2..10 clusters and
   relevancy r in {0, 0.2, 0.4, 0.6, 0.8}, ``trials`` times.
3. Write ``results.json``, the figures and ``REPORT.md``.

Beside ``results.json``, ``fingerprint.json`` pins down the first 30 interactions of the dataset bit for bit
(:func:`affordance_env.dataset.fingerprint.fingerprint`): :func:`check_fingerprint` collects them again with the
current code, so that a shipped reproduction cannot silently stop being what the code gives, and
:func:`write_reference_fingerprint` (``affordance fingerprint DIR``) rewrites it.

Then ``out/REPORT.md`` sets the behaviours side by side (:func:`affordance_learning.paper.report.write_overview`):
those just run, and any other whose results an earlier run left in ``out/<behavior>/``. Every behaviour is
checked against the environment before anything is collected, so a behaviour it does not offer stops the run
at once with a clear error.
"""

from __future__ import annotations

import json
import tempfile
import time
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

import affordance_env.behaviors as env_behaviors
from affordance_env.dataset import collect, failure_summary, load_dataset
from affordance_env.dataset.fingerprint import (
    FINGERPRINT_EPISODES,
    FingerprintCheck,
    compare_fingerprints,
    fingerprint,
)
from affordance_env.registry import BEHAVIOR_NAMES
from affordance_learning.common.behaviors import check_env_offers
from affordance_learning.common.exceptions import InvalidValueError
from affordance_learning.common.verdicts import tally_text
from affordance_learning.paper.claims import claims_scope, evaluate_claims
from affordance_learning.paper.figures import write_figures
from affordance_learning.paper.protocol import run_protocol
from affordance_learning.paper.report import HEADLINE_R, headline_accuracy, write_overview, write_report
from affordance_learning.paper.results import Results, as_results

#: The behaviours the paper reports on, run by default.
DEFAULT_BEHAVIORS = ("tap", "grasp")


def _shown_path(path: Path, out: Path) -> str:
    """``path`` relative to the output directory when it lies inside it (the report then reads the same on any
    machine), else as given."""
    try:
        return str(path.resolve().relative_to(out.resolve()))
    except ValueError:
        return str(path)


def reproduce(
    out: Path,
    *,
    behaviors: Iterable[str] = DEFAULT_BEHAVIORS,
    episodes: int = 1000,
    trials: int = 20,
    seed: int = 0,
    workers: int = 2,
    datasets: Mapping[str, Path] | None = None,
    progress: bool | None = None,
    range_noise: str | None = None,
) -> dict[str, Results]:
    """Run the whole experiment for each behaviour and write its outputs into ``out``.

    Args:
        out: Output directory: ``out/<behavior>/`` per behaviour, and ``out/REPORT.md`` over all of them.
        behaviors: Behaviours to run, each one the environment offers.
        episodes: Canonical interactions per behaviour, >= 20.
        trials: Learning trials, >= 1.
        seed: Seed of the datasets and of the trials.
        workers: Processes for the collection and the trials.
        datasets: Dataset directory per behaviour (default ``out/<behavior>/dataset``).
        progress: Draw progress bars; by default on a terminal when ``CI`` is not set, and otherwise write a
            progress line every 10 s; False: nothing.
        range_noise: Collect with the range camera's noise model on (for example ``"kinect_v1"``).

    Returns:
        The results of each behaviour run, by behaviour.
    """
    behaviors = list(behaviors)
    runnable = [b for b in behaviors if isinstance(b, str) and b in env_behaviors.BEHAVIORS] or ["tap"]
    behaviors = check_env_offers(behaviors, hint=", or run only the behaviours it offers (affordance reproduce "
                                 f"--behavior {' --behavior '.join(runnable)})")
    datasets = {b: Path(p) for b, p in (datasets or {}).items()}
    unknown = sorted(set(datasets) - set(behaviors))
    if unknown:
        raise InvalidValueError(f"datasets given for {unknown}, which are not run (behaviors {behaviors}).")
    if episodes < 20:
        raise InvalidValueError(f"episodes must be at least 20 for the protocol's splits, got {episodes!r}.")
    if trials < 1:
        raise InvalidValueError(f"trials must be at least 1, got {trials!r}.")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    runs: dict[str, Results] = {}
    for behavior in behaviors:
        runs[behavior] = _reproduce_one(
            out, behavior, datasets.get(behavior), episodes=episodes, trials=trials, seed=seed, workers=workers,
            progress=progress, range_noise=range_noise,
        )
    found: dict[str, Results] = {**_earlier_runs(out, behaviors), **runs}
    order = [b for b in BEHAVIOR_NAMES if b in found] + sorted(set(found) - set(BEHAVIOR_NAMES))
    overview = write_overview({b: found[b] for b in order}, out)
    print(f"total {time.perf_counter() - start:.1f} s")
    print()
    for behavior, results in runs.items():
        print(summary(results, out / behavior / "REPORT.md"))
    print(f"All behaviours side by side: {overview}")
    return runs


def _reproduce_one(out: Path, behavior: str, dataset: Path | None, *, episodes: int, trials: int, seed: int,
                   workers: int, progress: bool | None, range_noise: str | None) -> Results:
    """Collect, learn and report one behaviour into ``out/<behavior>``; returns its results."""
    where = out / behavior
    where.mkdir(parents=True, exist_ok=True)
    dataset = dataset if dataset is not None else where / "dataset"
    start = time.perf_counter()
    print(f"[{behavior} 1/3] collecting {episodes} canonical {behavior} interactions into {dataset} (seed {seed}, "
          f"{workers} workers; reused if present)")
    env_options: dict[str, Any] = {"behavior": behavior}
    if range_noise is not None:
        env_options["range_noise"] = range_noise
    collect(episodes=episodes, seed=seed, workers=workers, out=dataset, progress=progress, env_options=env_options)
    frame = load_dataset(dataset)
    collected = time.perf_counter()
    failures = frame.attrs["failures"]
    print(f"      {len(frame)} interactions, {len(failures)} failed and left out"
          f"{f' ({failure_summary({str(k): v for k, v in failures.items()})})' if failures else ''} "
          f"({collected - start:.1f} s)")
    print(f"[{behavior} 2/3] learning protocol: k = 2..10, r in 0.0..0.8, {trials} trials")
    results = run_protocol(frame, n_trials=trials, random_state=seed, n_jobs=workers, progress=progress,
                           behavior=behavior,
                           extra_config={"episodes": int(len(frame)), "dataset": _shown_path(dataset, where),
                                         "seed": seed, "trials": trials, "range_noise": range_noise or "none"})
    learned = time.perf_counter()
    print(f"      done ({learned - collected:.1f} s)")
    print(f"[{behavior} 3/3] writing results.json, {FINGERPRINT}, figures and REPORT.md into {where}")
    (where / "results.json").write_text(json.dumps(results.to_dict(), indent=2))
    _write_fingerprint(fingerprint(frame), where)
    figures = write_figures(results, where, progress=progress)
    write_report(results, where)
    print(f"      results.json, {len(figures)} figures and REPORT.md ({time.perf_counter() - learned:.1f} s)")
    return results


#: The file beside ``results.json`` that pins down the first interactions of its dataset.
FINGERPRINT = "fingerprint.json"


def _write_fingerprint(found: dict[str, Any], where: Path) -> Path:
    path = where / FINGERPRINT
    found = {"what": "the first interactions of the dataset behind results.json, one SHA-256 per part of each row; "
                     "`affordance fingerprint DIR --check` collects them again and compares, `affordance "
                     "fingerprint DIR` rewrites this file", **found}
    path.write_text(json.dumps(found, indent=1) + "\n")
    return path


def _reference_config(where: Path) -> tuple[str, int, dict[str, Any]]:
    """The behaviour, the seed and the whole config of the ``results.json`` in ``where``; InvalidValueError if it
    holds none of ``affordance reproduce``."""
    try:
        config = json.loads((where / "results.json").read_text())["config"]
        return config["behavior"], int(config["seed"]), config
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise InvalidValueError(f"{where} holds no results.json of `affordance reproduce` (with config.behavior and "
                                f"config.seed): {exc}; give one behaviour's directory of a reproduction "
                                "(OUT/BEHAVIOR of `affordance reproduce --out OUT`).") from None


def _collect_reference(where: Path, workers: int = 1) -> dict[str, Any]:
    """The fingerprint of the first interactions that ``affordance reproduce`` collects for the reproduction in
    ``where``, collected now (with the settings of its ``results.json``: behaviour, seed, range noise)."""
    behavior, seed, config = _reference_config(where)
    env_options: dict[str, Any] = {"behavior": behavior}
    if config.get("range_noise", "none") != "none":
        env_options["range_noise"] = config["range_noise"]
    with tempfile.TemporaryDirectory(prefix="tap-affordance-reference-") as tmp:
        dataset = Path(tmp) / "dataset"
        collect(dataset, FINGERPRINT_EPISODES, seed=seed, workers=workers, env_options=env_options,
                progress=False, max_failure_share=1.0)
        return fingerprint(load_dataset(dataset), FINGERPRINT_EPISODES)


def write_reference_fingerprint(where: str | Path, workers: int = 1) -> Path:
    """Collect the first interactions of the reproduction in ``where`` again and write its ``fingerprint.json``
    (after the simulation changed on purpose, with its results regenerated)."""
    where = Path(where)
    return _write_fingerprint(_collect_reference(where, workers), where)


def check_fingerprint(where: str | Path, workers: int = 1) -> FingerprintCheck:
    """Collect the first interactions that ``affordance reproduce`` collects for the reproduction in ``where``
    again and compare them with its ``fingerprint.json``: bit for bit where it was made with the versions and CPU
    found here, otherwise by what holds across machines
    (:func:`~affordance_env.dataset.fingerprint.compare_fingerprints`)."""
    where = Path(where)
    _reference_config(where)  # what the fingerprint is made from, before it is asked for
    try:
        expected = json.loads((where / FINGERPRINT).read_text())
    except (OSError, ValueError) as exc:
        raise InvalidValueError(f"{where / FINGERPRINT} cannot be read ({exc}); write it with `affordance fingerprint "
                         f"{where}`.") from None
    if not isinstance(expected, dict) or not isinstance(expected.get("interactions"), list):
        raise InvalidValueError(f"{where / FINGERPRINT} is not a fingerprint (an object with its 'interactions'); "
                                f"write it again with `affordance fingerprint {where}`.")
    return compare_fingerprints(expected, _collect_reference(where, workers))


def _earlier_runs(out: Path, skip: Iterable[str]) -> dict[str, Results]:
    """Results an earlier run left in ``out/<behavior>/results.json`` for behaviours not run now; only those of
    the current schema (whose config names the behaviour of their directory)."""
    found = {}
    for path in sorted(out.glob("*/results.json")):
        behavior = path.parent.name
        if behavior in skip:
            continue
        try:
            results = Results.from_dict(json.loads(path.read_text()))
        except (OSError, ValueError):  # unreadable, not JSON, or not results of a format this version reads
            continue
        if results.config.get("behavior") == behavior:
            found[behavior] = results
    return found


def summary(results: Results | Mapping[str, Any], report: Path) -> str:
    """The headline numbers of one behaviour's reproduction, and where its report is, in a few lines."""
    results = as_results(results, required=("uniformity", "svm_accuracy"))
    behavior = results.behavior
    effects = results.effects
    uniformity = {k: 100.0 * v.mean for k, v in (results.uniformity or {}).items() if v.mean is not None}
    acc = {k: v.mean for k, v in headline_accuracy(results).items() if v.mean is not None}
    claims = evaluate_claims(results)
    ks = sorted(uniformity)
    lines = [f"{behavior}: {report} (figures and results.json beside it)"]
    if effects is not None and effects.success_visible is not None:
        correlation = effects.travel_vs_seen_motion
        lines.append(f"  successes ({results.config.success_label}) whose object is seen where it stopped: "
                     f"{100 * effects.success_visible:.0f} %"
                     + ("" if correlation is None else f"; true travel vs motion seen, Spearman {correlation:.2f}"))
    paper = {"tap": " (paper: above 80 %)", "grasp": " (paper: above 70 %, and a fall at k = 3)"}.get(behavior, "")
    lines.append(f"  uniformity: {uniformity[ks[0]]:.1f} % (k = {ks[0]}) to {uniformity[ks[-1]]:.1f} % "
                 f"(k = {ks[-1]}), mean {np.mean(list(uniformity.values())):.1f} %{paper}")
    split = None if results.size_success is None else results.size_success.critical_split
    if split is not None:
        critical, below, above = split
        lines.append(f"  success by object size crosses 50 % at {100 * critical:.1f} cm (logistic "
                     f"fit): {100 * below:.0f} % below, {100 * above:.0f} % "
                     "above")
    lines.append(f"  SVM accuracy at r = {HEADLINE_R}: {100 * acc[min(acc)]:.1f} % (k = {min(acc)}) to "
                 f"{100 * acc[max(acc)]:.1f} % (k = {max(acc)})")
    lines.append(f"  the paper's claims: {tally_text(claims, 'claims')} (each verdict, its rule and, where missed, "
                 f"why in the report). {claims_scope(behavior)}")
    return "\n".join(lines)
