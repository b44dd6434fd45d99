"""The report and figures of ``affordance plan``: its results set beside the targets, and why a target is missed.

:data:`TARGETS` holds each target once; the check and the report's text both read it.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from affordance_learning.plan_experiment import GOAL_KINDS, MULTI_POLICIES, POLICIES, SHAPES

#: The targets of the planner, each a (direction, value): ">=" or "<=".
TARGETS: dict[str, tuple[str, float]] = {
    "single-step success on feasible goals": (">=", 0.92),
    "single-step success over the oracle's": (">=", 0.95),
    "median placement error [m]": ("<=", 0.02),
    "each left-out shape, success on its feasible goals": (">=", 0.75),
    "calibration ECE": ("<=", 0.05),
    "calibration AUROC": (">=", 0.95),
    "multi-step targets reached": (">=", 0.85),
    "multi-step reach failures per interaction": ("<=", 0.02),
}


def _pct(value: float | None) -> str:
    return "-" if value is None else f"{100 * value:.1f} %"


def _ci(ci) -> str:
    return f"[{100 * ci[0]:.0f}, {100 * ci[1]:.0f}]"


def measured_targets(results: Mapping[str, Any]) -> dict[str, float | None]:
    """The value of every target in ``results`` (the worst left-out shape for the shape target)."""
    shapes = [results["leave_one_shape_out"][s]["planner"]["success_feasible"] for s in results["leave_one_shape_out"]]
    return {
        "single-step success on feasible goals": results["single_step"]["planner"]["success_feasible"],
        "single-step success over the oracle's": results["planner_over_oracle"],
        "median placement error [m]": results["placement_error_median_m"],
        "each left-out shape, success on its feasible goals": min((s for s in shapes if s is not None), default=None),
        "calibration ECE": results["calibration"]["ece"],
        "calibration AUROC": results["calibration"]["auroc"],
        "multi-step targets reached": results["multi_step"]["planner"]["success"],
        "multi-step reach failures per interaction": results["multi_step"]["planner"]["reach_failures"],
    }


def target_met(name: str, value: float | None) -> bool | None:
    if value is None:
        return None
    direction, bound = TARGETS[name]
    return value >= bound if direction == ">=" else value <= bound


def _why(name: str, results: Mapping[str, Any]) -> str:
    """Why a target is missed, from the data."""
    single = results["single_step_by_goal"]
    if name.startswith("single-step"):
        gaps = sorted(((single[k]["oracle"]["success"] or 0) - (single[k]["planner"]["success"] or 0), k)
                      for k in GOAL_KINDS if single.get(k))
        worst = ", ".join(f"{k}: planner {_pct(single[k]['planner']['success'])} vs oracle "
                          f"{_pct(single[k]['oracle']['success'])}" for _, k in reversed(gaps[-2:]))
        return f"the gap to the oracle is largest for {worst}"
    if name.startswith("median placement"):
        place = single.get("place", {})
        return (f"place goals are reached in {_pct(place.get('oracle', {}).get('success'))} of cases even by the "
                "oracle: most targets 5-15 cm away are beyond what one interaction does to the object")
    if name.startswith("each left-out"):
        loso = results["leave_one_shape_out"]
        parts = [f"{s}: {_pct(loso[s]['planner']['success_feasible'])} of {loso[s]['planner']['n_feasible']} "
                 f"feasible (best fixed {_pct(loso[s]['best_fixed']['success_feasible'])})" for s in loso]
        return "; ".join(parts)
    if name.startswith("calibration"):
        curve = results["calibration"]["curve"]
        off = max(curve, key=lambda c: abs(c["p"] - c["observed"]) * c["n"]) if curve else None
        return ("" if off is None else f"the largest miscalibration is at P = {off['p']:.2f}: observed "
                f"{off['observed']:.2f} over {off['n']} actions")
    multi = results["multi_step"]["planner"]
    if name.startswith("multi-step reach"):
        kinds: dict[str, int] = {}
        for e in multi.get("episodes", []):
            for failure in e.get("failures", []):
                kind = _FAILURE_KINDS.get(failure.split(" by ")[0].split(" (")[0], failure.split(":")[0])
                kinds[kind] = kinds.get(kind, 0) + 1
        listed = ", ".join(f"{n} {kind}" for kind, n in sorted(kinds.items(), key=lambda item: -item[1]))
        return (f"{round(multi['reach_failures'] * multi['interactions'])} of {multi['interactions']} "
                f"interactions failed to reach although the kinematics said they would: {listed}")
    return multi_step_why(results)


#: What an interaction's failure message (up to its measure) says, for the report.
_FAILURE_KINDS = {
    "reach: the arm moved the object": "where the arm moved the object before the stroke",
    "reach: the stroke started": "where the stroke started more than 1 cm from its pose",
    "ik: the grasp was not reachable": "where a grasp's pose was out of reach once the hand had touched",
    "ik: the stroke was not reachable": "where a stroke's pose was out of reach",
}


def multi_step_why(results: Mapping[str, Any]) -> str:
    """Why multi-step episodes miss their targets: per object type, success and how far one interaction moves it;
    how many missed targets lay beyond what the episode's interactions can do (:func:`within_reach`), and the
    planner's success on the others."""
    multi = results["multi_step"]["planner"]
    reach = results["multi_step"].get("step_reach_p90_m", {})
    most = results["multi_step"]["max_interactions"]
    missed = [e for e in multi.get("episodes", []) if not e["success"]]
    beyond = [e for e in missed if not e["within_reach"]]
    per_type = "; ".join(
        f"{t}: {_pct(r['success'])} of {r['n']} (9 in 10 interactions move it at most "
        + ", ".join(f"{100 * v:.1f}" for v in reach.get(t, {}).values()) + " cm along +x, -x, +y, -y)"
        for t, r in multi.get("by_type", {}).items())
    towards = sum(e["target_xy"][0] - e["start_xy"][0] > reach.get(e["type"], {}).get("+x", 0.0) * most
                  for e in beyond)
    inside = multi.get("within_reach", {})
    gave_up = sum(e["gave_up"] for e in missed)
    return (f"{_pct(multi['success'])} of episodes reach the target (median final distance "
            f"{100 * multi['median_final_distance_m']:.1f} cm). By type: {per_type}. {len(beyond)} of the "
            f"{len(missed)} missed targets lay further along an axis than {most} such interactions take the object "
            f"({towards} of them towards the robot, where only rolling brings an object); on the "
            f"{inside.get('n', 0)} targets within that reach the planner reached {_pct(inside.get('success'))}. In "
            f"{gave_up} missed episodes the object ended where no candidate action was reachable")


def write_plan_report(results: Mapping[str, Any], out: str | os.PathLike) -> Path:
    """Write ``REPORT.md`` into ``out``."""
    out = Path(out)
    lines = ["# Using the affordances: planning with action-conditioned effect models", ""]
    s = results["settings"]
    lines += [f"Seed {results['seed']}; training interactions per behaviour: "
              + ", ".join(f"{b} {n}" for b, n in results["training"].items())
              + f" (random actions from {s['episodes']} goal episodes, objects over the workspaces). "
              f"Total time {results['timings_s']['total'] / 60:.1f} min.", ""]
    lines += ["## Targets", "", "| target | bound | measured | met | why not |", "|---|---|---|---|---|"]
    for name, value in measured_targets(results).items():
        direction, bound = TARGETS[name]
        met = target_met(name, value)
        shown = ("-" if value is None else f"{100 * value:.1f} cm" if "[m]" in name
                 else f"{value:.3f}" if name.startswith("calibration") else _pct(value))
        bound_text = f"{100 * bound:.0f} cm" if "[m]" in name else (f"{bound}" if name.startswith("calibration")
                                                                     else f"{100 * bound:.0f} %")
        lines.append(f"| {name} | {direction} {bound_text} | {shown} | {'yes' if met else 'no'} | "
                     f"{'' if met else _why(name, results)} |")
    single = results["single_step"]
    lines += ["", f"## Single step ({single['planner']['n']} held-out objects, one goal each; "
              f"{single['oracle']['n_feasible']} feasible)", "",
              "| policy | success [95 % CI] | on feasible goals [95 % CI] |", "|---|---|---|"]
    for p in POLICIES:
        r = single[p]
        lines.append(f"| {p} | {_pct(r['success'])} {_ci(r['success_ci'])} | {_pct(r['success_feasible'])} "
                     f"{_ci(r['success_feasible_ci'])} |")
    lines += ["", "Per goal kind (success):", "", "| goal | n | " + " | ".join(POLICIES) + " |",
              "|---|---|" + "---|" * len(POLICIES)]
    for kind, by in results["single_step_by_goal"].items():
        lines.append(f"| {kind} | {by['planner']['n']} | " + " | ".join(_pct(by[p]["success"]) for p in POLICIES)
                     + " |")
    lines += ["", f"Best fixed behaviour per goal kind: {results['best_fixed_behavior']}.", ""]
    lines += ["## Leaving each shape out", "", "Models refitted without the shape, judged on goals for it only.", "",
              "| shape | n (feasible) | planner on feasible | best fixed on feasible | random |",
              "|---|---|---|---|---|"]
    for shape, r in results["leave_one_shape_out"].items():
        lines.append(f"| {shape} | {r['planner']['n']} ({r['planner']['n_feasible']}) | "
                     f"{_pct(r['planner']['success_feasible'])} | {_pct(r['best_fixed']['success_feasible'])} | "
                     f"{_pct(r['random']['success'])} |")
    lines += ["", "## Multi-step", "", "| policy | targets reached [95 % CI] | reach failures per interaction | "
              "median final distance |", "|---|---|---|---|"]
    for p in MULTI_POLICIES:
        r = results["multi_step"][p]
        lines.append(f"| {p} | {_pct(r['success'])} {_ci(r['success_ci'])} | {_pct(r['reach_failures'])} | "
                     f"{100 * r['median_final_distance_m']:.1f} cm |")
    cal = results["calibration"]
    auroc = "-" if cal["auroc"] is None else f"{cal['auroc']:.3f}"
    lines += ["", "## Calibration", "",
              f"Over the {cal['n']} actions executed in the single-step evaluation: ECE {cal['ece']:.3f}, AUROC "
              f"{auroc}.", "",
              "![success](success.png)", "![reliability](reliability.png)", "![episode](episode.png)", ""]
    (out / "REPORT.md").write_text("\n".join(lines))
    return out / "REPORT.md"


def write_plan_figures(results: Mapping[str, Any], out: str | os.PathLike,
                       episode_frames: list[tuple[str, np.ndarray]] | None = None) -> list[Path]:
    """``success.png`` (success per goal kind and policy, Wilson 95 % intervals), ``reliability.png`` and, given
    the frames of an episode, ``episode.png``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out)
    written = []
    fig, ax = plt.subplots(figsize=(10, 4))
    width = 0.8 / len(POLICIES)
    for j, p in enumerate(POLICIES):
        values = [results["single_step_by_goal"][k][p] for k in GOAL_KINDS]
        x = np.arange(len(GOAL_KINDS)) + (j - len(POLICIES) / 2 + 0.5) * width
        y = np.array([v["success"] or 0.0 for v in values])
        lo = y - np.array([v["success_ci"][0] for v in values])
        hi = np.array([v["success_ci"][1] for v in values]) - y
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
    curve = results["calibration"]["curve"]
    ax.plot([0, 1], [0, 1], "k--", lw=1)
    ax.scatter([c["p"] for c in curve], [c["observed"] for c in curve], s=[10 + c["n"] / 2 for c in curve])
    ax.set_xlabel("predicted P(goal)")
    ax.set_ylabel("observed share reached")
    ax.set_title(f"Reliability (ECE {results['calibration']['ece']:.3f})")
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


__all__ = ["TARGETS", "measured_targets", "target_met", "write_plan_report", "write_plan_figures", "SHAPES",
           "MULTI_POLICIES"]
