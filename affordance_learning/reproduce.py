"""``affordance reproduce``: the paper's experiment end to end, from the simulator to the report.

1. Collect (or reuse) ``episodes`` canonical taps with :func:`affordance_env.dataset.collect`; the dataset is
   resumable, so an interrupted run continues where it stopped.
2. Run the learning protocol (:func:`affordance_learning.experiment.run_protocol`) over k = 2..10 clusters and
   relevancy r in {0, 0.2, 0.4, 0.6, 0.8}, ``trials`` times.
3. Write ``results.json``, the figures and ``REPORT.md`` into ``out``.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np


def _jsonable(value):
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    return value


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
    episodes: int = 1000,
    trials: int = 20,
    seed: int = 0,
    workers: int = 2,
    dataset: Path | None = None,
    progress: bool | None = None,
    range_noise: str | None = None,
) -> dict:
    """Run the whole experiment and write its outputs into ``out``; returns the results dict.

    ``range_noise`` (for example ``"kinect_v1"``) collects the taps with the range camera's noise model on.
    """
    from affordance_env.dataset import collect, failure_summary, load_dataset, show_progress
    from affordance_learning.experiment import run_protocol
    from affordance_learning.figures import write_figures
    from affordance_learning.report import write_report

    if episodes < 20:
        raise ValueError(f"episodes must be at least 20 for the protocol's splits, got {episodes!r}.")
    if trials < 1:
        raise ValueError(f"trials must be at least 1, got {trials!r}.")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    dataset = Path(dataset) if dataset is not None else out / "dataset"
    start = time.perf_counter()
    print(f"[1/3] collecting {episodes} taps into {dataset} (seed {seed}, {workers} workers; reused if present)")
    env_options = {} if range_noise is None else {"range_noise": range_noise}
    collect(episodes=episodes, seed=seed, workers=workers, out=dataset, progress=progress, env_options=env_options)
    frame = load_dataset(dataset)
    collected = time.perf_counter()
    failures = frame.attrs["failures"]
    print(f"      {len(frame)} interactions, {len(failures)} failed and left out"
          f"{f' ({failure_summary({str(k): v for k, v in failures.items()})})' if failures else ''} "
          f"({collected - start:.1f} s)")
    print(f"[2/3] learning protocol: k = 2..10, r in 0.0..0.8, {trials} trials")
    bars = show_progress(progress)
    results = run_protocol(frame, n_trials=trials, random_state=seed, n_jobs=workers, progress=bars)
    results.setdefault("config", {}).update(
        {"episodes": int(len(frame)), "dataset": _shown_path(dataset, out), "seed": seed, "trials": trials,
         "range_noise": range_noise or "none"}
    )
    learned = time.perf_counter()
    print(f"      done ({learned - collected:.1f} s)")
    print(f"[3/3] writing results.json, figures and REPORT.md into {out}")
    (out / "results.json").write_text(json.dumps(_jsonable(results), indent=2))
    figures = write_figures(results, out, progress=bars)
    report = write_report(results, out)
    print(f"      results.json, {len(figures)} figures and REPORT.md ({time.perf_counter() - learned:.1f} s)")
    print(f"total {time.perf_counter() - start:.1f} s")
    print()
    print(summary(results, report))
    return results


def summary(results: dict, report: Path) -> str:
    """The headline numbers of a reproduction, and where its report is, in a few lines."""
    from affordance_learning.report import AGREES, evaluate_claims

    effects = results.get("effects", {})
    uniformity = {int(k): v["mean"] for k, v in results["uniformity"].items() if v["mean"] is not None}
    accuracy = results["svm_accuracy"].get("0.4") or next(iter(results["svm_accuracy"].values()))
    acc = {int(k): v["mean"] for k, v in accuracy.items() if v["mean"] is not None}
    claims = evaluate_claims(results)
    ks = sorted(uniformity)
    lines = [f"Report: {report} (figures and results.json beside it)"]
    if effects.get("success_visible") is not None:
        label = results.get("config", {}).get("success_label", "success")
        correlation = effects.get("travel_vs_seen_motion")
        lines.append(f"  successes ({label}) whose object is seen where it stopped: "
                     f"{100 * effects['success_visible']:.0f} %"
                     + ("" if correlation is None else f"; true travel vs motion seen, Spearman {correlation:.2f}"))
    lines.append(f"  uniformity: {uniformity[ks[0]]:.1f} % (k = {ks[0]}) to {uniformity[ks[-1]]:.1f} % "
                 f"(k = {ks[-1]}), mean {np.mean(list(uniformity.values())):.1f} % (paper: above 80 %)")
    lines.append(f"  SVM accuracy at r = 0.4: {100 * acc[min(acc)]:.1f} % (k = {min(acc)}) to "
                 f"{100 * acc[max(acc)]:.1f} % (k = {max(acc)})")
    lines.append(f"  the paper's claims: {sum(c.verdict == AGREES for c in claims)} of {len(claims)} agree "
                 "(each verdict and its rule in the report)")
    return "\n".join(lines)
