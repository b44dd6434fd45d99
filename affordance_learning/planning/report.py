"""The report and figures of ``affordance plan``: its results set beside the targets, and why a target is missed.

The targets and their verdicts are :mod:`affordance_learning.planning.targets`; this module renders the verdicts it
is given beside the tables of the numbers they are computed from, read through
:class:`~affordance_learning.planning.results.PlanResults`.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from affordance_learning.common.exceptions import InvalidValueError
from affordance_learning.common.verdicts import Verdict
from affordance_learning.planning.experiment import GOAL_KINDS, MULTI_POLICIES, POLICIES, share_text, wilson
from affordance_learning.planning.results import SUCCESS_DISTANCES_M, PlanResults, Share
from affordance_learning.planning.targets import (
    MIN_CALIBRATION_ACTIONS,
    MIN_DECISIONS,
    MIN_EPISODES,
    MIN_FEASIBLE_GOALS,
    MIN_FEASIBLE_PER_SHAPE,
    MIN_PLACEMENTS,
    MIN_TOWARD_ROBOT,
    evaluate_targets,
    policy_outcome,
    share_cell,
    success_within,
    within_cell,
)


def write_plan_report(results: PlanResults | Mapping[str, Any], out: str | os.PathLike) -> Path:
    """Write ``REPORT.md`` into ``out``.

    Raises:
        InvalidValueError: ``results`` are not those of ``affordance plan`` (naming what they lack).
    """
    results = PlanResults.from_dict(results)
    out = Path(out)
    lines = ["# Using the affordances: planning with action-conditioned effect models", ""]
    lines += [f"Seed {results.seed}; training interactions per behaviour: "
              + ", ".join(f"{b} {n}" for b, n in results.training.items())
              + f" (random actions from {results.episodes} goal episodes, objects over the workspaces). "
              f"Total time {results.total_time_s / 60:.1f} min.", ""]
    if results.settings.get("quick"):
        lines += ["**A quick run** (`affordance plan --quick`): the whole pipeline on few data, to see that it runs "
                  "and what it writes. Its numbers are not the experiment's: wherever n is below a target's minimum "
                  "the verdict reads *too few data*.", ""]
    oracle = results.oracle
    if oracle:
        lines += [f"Single step: {oracle.get('objects')} held-out objects ("
                  + ", ".join(f"{n} {s}" for s, n in oracle.get("objects_per_shape", {}).items())
                  + f"), {sum(oracle.get('goals_per_object', {}).values())} goals each ("
                  + ", ".join(f"{n} {k}" for k, n in oracle.get("goals_per_object", {}).items())
                  + f"). The oracle runs {oracle.get('actions_per_behavior')} actions per behaviour on every object "
                  f"from its snapshot, the same fixed set for all (the canonical action and the grid of levels "
                  f"{oracle.get('levels')} along each parameter), and every goal of the object is judged against "
                  "those outcomes: a goal is *feasible* when one of them reached it. The goals of one object are "
                  "not independent; the intervals treat them as if they were.", ""]
    lines += ["## Targets", "",
              "A target is judged only on enough data, else it is *too few* (a share of nothing is *not measured*): "
              f"at least {MIN_FEASIBLE_GOALS} feasible single-step goals, {MIN_FEASIBLE_PER_SHAPE} feasible goals "
              f"of each left-out shape, {MIN_PLACEMENTS} place goals acted on, {MIN_CALIBRATION_ACTIONS} chosen "
              f"actions for the calibration, {MIN_EPISODES} multi-step episodes ({MIN_TOWARD_ROBOT} toward the "
              f"robot) and {MIN_DECISIONS} decisions. Shares carry their Wilson 95 % interval and n.", "",
              *target_rows(evaluate_targets(results).values())]
    within = success_within(results)
    if within:
        lines += ["", "## Within 1, 3 and 5 cm of the target", "",
                  "The share that came to rest on the table within each distance of its target (5 cm is the success "
                  "threshold of FetchPush and Meta-World, 3 cm the place goals' and the goal env's tolerance). A "
                  "multi-step episode ends within 3 cm or after its last interaction, so its 1 cm share counts where "
                  "the object came to rest, not what a policy aiming at 1 cm would reach. A measure, not a target: "
                  f"read on at least {MIN_PLACEMENTS} place goals or {MIN_EPISODES} episodes, else *too few data*.",
                  "", "| cases | " + " | ".join(f"within {100 * d:.0f} cm [95 % CI]" for d in SUCCESS_DISTANCES_M)
                  + " |", "|---|" + "---|" * len(SUCCESS_DISTANCES_M)]
        lines += [f"| {row.name} | " + " | ".join(within_cell(share, row.unit, row.minimum) for share in row.shares)
                  + " |" for row in within]
    single = results.single_step
    lines += ["", f"## Single step ({policy_outcome(single, 'planner', 'single-step').reached.n} goals; "
              f"{policy_outcome(single, 'oracle', 'single-step').feasible.n} feasible)", "",
              "| policy | success [95 % CI] | on feasible goals [95 % CI] | on goals the oracle or the planner "
              "reached [95 % CI] |", "|---|---|---|---|"]
    for p in POLICIES:
        r = policy_outcome(single, p, "single-step")
        lines.append(f"| {p} | {share_cell(r.reached)} | {share_cell(r.feasible)} | {share_cell(r.reached_any)} |")
    lines += ["", "Per goal kind (success [95 % CI]):", "", "| goal | " + " | ".join(POLICIES) + " |",
              "|---|" + "---|" * len(POLICIES)]
    for kind, by in results.single_step_by_goal.items():
        lines.append(f"| {kind} | " + " | ".join(share_cell(policy_outcome(by, p, kind).reached) for p in POLICIES)
                     + " |")
    lines += ["", f"Best fixed behaviour per goal kind: {dict(results.best_fixed_behavior)}.", ""]
    lines += ["## Leaving each shape out", "", "Models refitted without the shape, judged on goals for it only.", "",
              "| shape | planner on feasible [95 % CI] | best fixed on feasible [95 % CI] | random [95 % CI] |",
              "|---|---|---|---|"]
    for shape, r in results.leave_one_shape_out.items():
        lines.append(f"| {shape} | {share_cell(r['planner'].feasible)} | "
                     f"{share_cell(r['best_fixed'].feasible)} | {share_cell(r['random'].reached)} |")
    lines += ["", "## Multi-step", "", "| policy | targets reached [95 % CI] | toward the robot [95 % CI] | reach "
              "failures per interaction [95 % CI] | median final distance |", "|---|---|---|---|---|"]
    for p in MULTI_POLICIES:
        r = results.multi_step.policy(p)
        lines.append(f"| {p} | {share_cell(r.reached, unit='episodes')} | "
                     f"{share_cell(r.toward_robot, unit='episodes')} | "
                     + share_text(r.reach_failures, r.interactions, wilson(r.reach_failure_count, r.interactions),
                                  "interactions", digits=1)
                     + f" | {100 * r.median_final_distance_m:.1f} cm (n={r.reached.n} episodes) |")
    cal = results.calibration
    lines += ["", "## Calibration", "", f"On {cal.basis} ({cal.n}): {_calibration_text(cal)}."]
    if cal.pooled is not None:
        lines += ["", f"Pooled over {cal.pooled.basis} ({cal.pooled.n}), most of them at P near 0: "
                  f"{_calibration_text(cal.pooled)}. The pooled figure says how well the model ranks actions in "
                  "general; the chosen actions' says whether the planner's P(goal) can be believed."]
    if cal.curve:
        lines += ["", "| predicted P | observed | n |", "|---|---|---|"]
        lines += [f"| {c.p:.2f} | {c.observed:.2f} | {c.n} |" for c in cal.curve]
    times = results.decision_seconds
    if times.n:
        lines += ["", "## Decision time", "",
                  f"{times.n} decisions (single step and multi-step, ``feasible``'s calls included, measured in the "
                  f"workers of the run): median {1000 * times.median:.0f} ms, 99th percentile "
                  f"{1000 * times.p99:.0f} ms."]
    lines += ["", "![success](success.png)", "![reliability](reliability.png)", "![episode](episode.png)", ""]
    (out / "REPORT.md").write_text("\n".join(lines))
    return out / "REPORT.md"


def target_rows(verdicts: Iterable[Verdict]) -> list[str]:
    """The targets' table: each with its bound, the measured value, the verdict with its n and, where missed, why."""
    return ["| target | bound | measured | verdict | why not |", "|---|---|---|---|---|",
            *(f"| {v.topic} | {v.rule} | {v.ours} | **{v.text}** | {v.why or ''} |" for v in verdicts)]


def _calibration_text(cal) -> str:
    ece = "-" if cal.ece is None else f"{cal.ece:.3f}"
    auroc = "-" if cal.auroc is None else f"{cal.auroc:.3f}"
    return f"ECE {ece}, AUROC {auroc}"


def write_plan_figures(results: PlanResults | Mapping[str, Any], out: str | os.PathLike,
                       episode_frames: list[tuple[str, np.ndarray]] | None = None) -> list[Path]:
    """``success.png`` (success per goal kind and policy, Wilson 95 % intervals), ``reliability.png`` and, given
    the frames of an episode, ``episode.png``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    results = PlanResults.from_dict(results)
    out = Path(out)
    written = []
    fig, ax = plt.subplots(figsize=(10, 4))
    width = 0.8 / len(POLICIES)
    for j, p in enumerate(POLICIES):
        values = [policy_outcome(_goal_kind(results, k), p, k).reached for k in GOAL_KINDS]
        x = np.arange(len(GOAL_KINDS)) + (j - len(POLICIES) / 2 + 0.5) * width
        y = np.array([np.nan if v.value is None else v.value for v in values])  # nothing measured: no bar
        lo = y - np.array([_interval(v)[0] for v in values])
        hi = np.array([_interval(v)[1] for v in values]) - y
        ax.bar(x, 100 * y, width, yerr=100 * np.vstack([lo, hi]), capsize=2, label=p)
    ax.set_xticks(np.arange(len(GOAL_KINDS)), GOAL_KINDS)
    ax.set_ylabel("goals reached [%]")
    ax.set_title("Single step, per goal kind (Wilson 95 % intervals)")
    ax.legend(fontsize=8, ncol=3)
    fig.tight_layout()
    fig.savefig(out / "success.png", dpi=100)
    plt.close(fig)
    written.append(out / "success.png")

    fig, ax = plt.subplots(figsize=(4.5, 4.5))
    curve = results.calibration.curve
    ax.plot([0, 1], [0, 1], "k--", lw=1)
    ax.scatter([c.p for c in curve], [c.observed for c in curve], s=[10 + c.n / 2 for c in curve])
    ax.set_xlabel("predicted P(goal)")
    ax.set_ylabel("observed share reached")
    ax.set_title(f"Reliability on chosen actions ({_calibration_text(results.calibration)})")
    fig.tight_layout()
    fig.savefig(out / "reliability.png", dpi=100)
    plt.close(fig)
    written.append(out / "reliability.png")

    if episode_frames:
        fig, axes = plt.subplots(1, len(episode_frames), figsize=(3 * len(episode_frames), 2.6))
        for ax, (title, image) in zip(np.atleast_1d(axes), episode_frames, strict=True):
            ax.imshow(image)
            ax.set_title(title, fontsize=9)
            ax.axis("off")
        fig.tight_layout()
        fig.savefig(out / "episode.png", dpi=90)
        plt.close(fig)
        written.append(out / "episode.png")
    return written


def _goal_kind(results: PlanResults, kind: str) -> Mapping[str, Any]:
    """Each policy's single-step outcome on goals of ``kind``; InvalidValueError when the results hold none."""
    if kind not in results.single_step_by_goal:
        raise InvalidValueError(f"the plan results hold no single-step outcomes of goal kind {kind!r}, only of "
                                f"{', '.join(results.single_step_by_goal)}.")
    return results.single_step_by_goal[kind]


def _interval(share: Share) -> tuple[float, float]:
    """The Wilson 95 % interval of a share; InvalidValueError when the results hold none."""
    if share.ci is None:
        raise InvalidValueError(f"a share of {share.n} in the plan results has no Wilson interval (success_ci).")
    return share.ci


__all__ = ["target_rows", "write_plan_report", "write_plan_figures"]
