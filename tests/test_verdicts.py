"""Verdicts are given only on enough data and carry their n: the paper's claims and the planner's targets, on small
synthetic results (no simulator)."""

from __future__ import annotations

import copy
import re
from pathlib import Path

import numpy as np
import pytest

from affordance_env.objects import OBJECT_TYPES
from affordance_learning.common.statistics import wilson_interval
from affordance_learning.common.verdicts import MET, MISSED, NOT_MEASURED, TOO_FEW
from affordance_learning.paper.claims import (
    MIN_INTERACTIONS,
    MIN_TRIALS,
    STRADDLE_MAX_SIZE,
    STRADDLE_MIN_SIZE,
    evaluate_claims,
)
from affordance_learning.paper.report import render_report
from affordance_learning.planning.experiment import MULTI_POLICIES, POLICIES, share_text, summarize
from affordance_learning.planning.report import write_plan_report
from affordance_learning.planning.results import PlanResults
from affordance_learning.planning.targets import (
    MIN_CALIBRATION_ACTIONS,
    MIN_EPISODES,
    MIN_FEASIBLE_GOALS,
    MIN_FEASIBLE_PER_SHAPE,
    MIN_PLACEMENTS,
    evaluate_targets,
    measured_targets,
)

STRADDLE = "1 x 3 map: a category straddles the critical size"
SHAPE_TARGET = "each left-out shape, success on its feasible goals"
SINGLE_TARGET = "single-step success on feasible goals"
MULTI_TARGET = "multi-step targets reached"


# --- the Wilson interval ---------------------------------------------------------------------------------------
def test_wilson_interval_matches_the_formula_and_its_edges() -> None:
    # 45 of 50: the Wilson score interval, by hand (z = 1.96)
    low, high = wilson_interval(45, 50)
    assert low == pytest.approx(0.786398, abs=1e-6) and high == pytest.approx(0.956524, abs=1e-6)
    # it stays within [0, 1] and does not collapse at 0 of n or n of n, where p +- z sqrt(p (1 - p) / n) would
    assert wilson_interval(0, 20)[0] == 0.0 and wilson_interval(0, 20)[1] == pytest.approx(0.161125, abs=1e-6)
    assert wilson_interval(20, 20)[1] == 1.0 and wilson_interval(20, 20)[0] == pytest.approx(0.838875, abs=1e-6)
    # symmetric in successes and failures, and nothing known of 0 of 0
    for k in range(0, 31, 5):
        low, high = wilson_interval(k, 30)
        assert (1 - high, 1 - low) == pytest.approx(wilson_interval(30 - k, 30))
        assert low <= k / 30 <= high
    assert wilson_interval(0, 0) == (0.0, 1.0)
    with pytest.raises(ValueError, match="successes <= n"):
        wilson_interval(3, 2)


def test_wilson_interval_agrees_with_scipy() -> None:
    from scipy.stats import binomtest

    for n in (1, 7, 30, 200):
        for k in range(0, n + 1, max(1, n // 6)):
            ci = binomtest(k, n).proportion_ci(0.95, method="wilson")
            assert wilson_interval(k, n) == pytest.approx((ci.low, ci.high), abs=1e-12)


def test_a_share_of_nothing_is_not_measured_and_every_share_shows_its_n() -> None:
    assert share_text(None, 0) == "not measured (n=0)"
    assert share_text(0.0, 0, unit="feasible") == "not measured (n=0 feasible)"  # 0 of 0, never "0 %"
    assert share_text(0.0, 12) == "0 % (n=12)"  # 0 of 12 is a rate
    assert share_text(0.8, 35, (0.62, 0.91), "feasible goals", digits=1) == "80.0 % [62, 91] (n=35 feasible goals)"


# --- the planner's targets -------------------------------------------------------------------------------------
def _records(n: int, feasible: int, reached: int, policies=POLICIES) -> list[dict]:
    """``n`` goals of which ``feasible`` are feasible (the oracle reached them); every policy but the oracle reaches
    the first ``reached`` feasible ones."""
    out = []
    for i in range(n):
        row = {p: i < reached for p in policies}
        row["oracle"] = i < feasible
        out.append(row)
    return out


def _plan_results(shape_goals: dict[str, tuple[int, int, int]] | None = None, single: tuple[int, int, int] = (
        300, 250, 240), episodes: tuple[int, int] = (80, 75)) -> dict:
    """Plan results: ``single`` = (goals, feasible, reached by the planner), ``shape_goals`` per left-out shape,
    ``episodes`` = (multi-step episodes, reached)."""
    shape_goals = shape_goals or {s: (60, 50, 45) for s in OBJECT_TYPES}
    records = _records(*single)
    n, k = episodes
    multi = {p: {"success": k / n if n else None, "success_ci": wilson_interval(k, n), "n": n,
                 "reach_failures": 0.01, "interactions": 3 * n, "gave_up": 0, "median_final_distance_m": 0.02}
             for p in MULTI_POLICIES}
    multi["planner"].update(by_type={"sphere": {"n": n, "success": k / n if n else None}}, episodes=[],
                            within_reach={"n": 0, "success": None})
    return {
        "seed": 0, "settings": {"episodes": 1000}, "training": {"tap": 1000}, "timings_s": {"total": 60.0},
        "single_step": summarize(records, POLICIES),
        "single_step_by_goal": {"roll": summarize(records, POLICIES), "lift": summarize([], POLICIES)},
        "best_fixed_behavior": {"roll": "tap"},
        "planner_over_oracle": single[2] / single[1],
        "leave_one_shape_out": {s: summarize(_records(*g), ("planner", "best_fixed", "random", "oracle"))
                                for s, g in shape_goals.items()},
        "multi_step": {**multi, "step_reach_p90_m": {}, "max_interactions": 5, "tolerance_m": 0.03},
        "placement_error_median_m": 0.015, "placement_error_n": 40,
        "calibration": {"ece": 0.03, "auroc": 0.97, "n": 2000, "curve": []},
        "goals": [],
    }


def test_a_left_out_shape_judged_on_one_goal_is_too_few_not_met() -> None:
    results = _plan_results({**{s: (60, 50, 45) for s in OBJECT_TYPES}, "box": (3, 1, 1)})  # box: 1 of 1 feasible
    measured, verdict = measured_targets(results)[SHAPE_TARGET], evaluate_targets(results)[SHAPE_TARGET]
    assert verdict.word == TOO_FEW and verdict.met is None
    assert measured.n == 1 and "box" in measured.unit and verdict.n == 1
    # with enough feasible goals of every shape the same shares are met
    enough = _plan_results({**{s: (60, 50, 45) for s in OBJECT_TYPES}, "box": (40, MIN_FEASIBLE_PER_SHAPE, 30)})
    assert evaluate_targets(enough)[SHAPE_TARGET].word == MET


def test_a_left_out_shape_missed_on_enough_goals_misses_whatever_the_others() -> None:
    results = _plan_results({"sphere": (60, 50, 20), "box": (3, 0, 0), "horizontal_cylinder": (60, 50, 45),
                             "vertical_cylinder": (60, 50, 45)})
    measured = measured_targets(results)[SHAPE_TARGET]
    assert evaluate_targets(results)[SHAPE_TARGET].word == MISSED and measured.value == pytest.approx(0.4)
    assert measured.n == 50 and "sphere" in measured.unit


def test_single_step_and_multi_step_need_their_minimum_n() -> None:
    few = _plan_results(single=(200, MIN_FEASIBLE_GOALS - 1, MIN_FEASIBLE_GOALS - 1),
                        episodes=(MIN_EPISODES - 1, MIN_EPISODES - 1))
    targets = evaluate_targets(few)
    assert targets[SINGLE_TARGET].word == TOO_FEW  # 100 % of 199
    assert targets[MULTI_TARGET].word == TOO_FEW  # 100 % of 59
    enough = evaluate_targets(_plan_results(single=(300, MIN_FEASIBLE_GOALS, 150),
                                            episodes=(MIN_EPISODES, MIN_EPISODES)))
    assert enough[SINGLE_TARGET].word == MISSED  # 75 % of 200
    assert enough[MULTI_TARGET].word == MET
    # nothing measured is no verdict
    none = evaluate_targets(_plan_results(episodes=(0, 0)))
    assert none[MULTI_TARGET].word == NOT_MEASURED and none[MULTI_TARGET].met is None


def test_placement_and_calibration_need_their_minimum_n() -> None:
    placement, within, ece = ("place goals the oracle reaches: median error [m]",
                              "place goals the oracle reaches: within 3 cm", "calibration ECE")
    results = _plan_results()
    place = _goal(kind="place", placement_error=0.004)
    results["goals"] = [place] * (MIN_PLACEMENTS - 1) + [_goal(kind="place", oracle=False, planner=False,
                                                               placement_error=0.2)] * 40
    results["calibration"]["n"] = MIN_CALIBRATION_ACTIONS - 1
    targets = evaluate_targets(results)
    assert targets[placement].word == targets[within].word == targets[ece].word == TOO_FEW
    results["goals"].append(place)
    results["calibration"]["n"] = MIN_CALIBRATION_ACTIONS
    targets = evaluate_targets(results)
    assert targets[placement].word == targets[within].word == targets[ece].word == MET
    assert measured_targets(results)[placement].n == MIN_PLACEMENTS  # the goals the oracle missed are not counted
    # a goal the planner named no action for is missed by any distance: half of them move the median past 1 cm
    results["goals"] += [_goal(kind="place", planner=False, planner_behavior=None, planner_p=0.0)] * MIN_PLACEMENTS
    measured = measured_targets(results)
    assert measured[placement].value == np.inf and measured[within].value == pytest.approx(0.5)
    assert evaluate_targets(results)[placement].word == MISSED
    # results written before the goals' errors: not measured, not met
    results["goals"] = [{k: v for k, v in g.items() if k != "placement_error"} for g in results["goals"]]
    assert evaluate_targets(results)[placement].word == NOT_MEASURED


def test_an_episode_stopped_with_no_action_misses_only_where_the_oracle_found_a_feasible_one() -> None:
    target = "multi-step episodes ended with no action while one was feasible"
    results = _plan_results()
    episode = {"type": "box", "start_xy": [-0.4, 0.0], "target_xy": [-0.3, 0.0], "success": False,
               "gave_up": True, "within_reach": True, "feasible_at_stop": 0}
    results["multi_step"]["planner"]["episodes"] = [episode] * 2 + [{**episode, "gave_up": False,
                                                                     "feasible_at_stop": None}] * 78
    assert evaluate_targets(results)[target].word == MET  # nothing could act where it stopped
    results["multi_step"]["planner"]["episodes"][0] = {**episode, "feasible_at_stop": 12}
    verdict = evaluate_targets(results)[target]
    assert verdict.word == MISSED and "in 1 of them the oracle found feasible actions (12" in verdict.why
    results["multi_step"]["planner"]["episodes"][1] = {**episode, "feasible_at_stop": None}  # not recorded
    assert evaluate_targets(results)[target].word == NOT_MEASURED


def _goal(**fields) -> dict:
    """A single-step goal's record as results.json holds it: a move of a box, chosen with a push at P 0.9 and
    reached; ``fields`` change it."""
    return {"kind": "move", "type": "box", "object": 0, "size": 0.06, "goal": {"kind": "move"}, "planner": True,
            "planner_p": 0.9, "planner_behavior": "push", "oracle": True, "oracle_hits": 40,
            "planner_left_out": True, **fields}


def _missed_target_row(results: dict, target: str, tmp_path: Path) -> str:
    return next(line for line in write_plan_report(results, tmp_path).read_text().splitlines()
                if line.startswith(f"| {target} |"))


def test_missed_feasible_goals_are_explained_by_how_many_oracle_actions_reached_them(tmp_path: Path) -> None:
    results = _plan_results(single=(300, 250, 200))  # 80 % of the feasible goals: missed
    results["oracle"] = {"actions_per_behavior": 65}
    results["goals"] = ([_goal(oracle_hits=30)] * 8 + [_goal(planner=False, oracle_hits=2, kind="place")] * 3
                        + [_goal(planner=False, oracle_hits=5, planner_p=0.2)]
                        + [_goal(planner=False, oracle_hits=9, object=7, size=0.071, planner_behavior="grasp")] * 2
                        + [_goal(oracle=False, oracle_hits=0, planner=False)] * 5)
    row = _missed_target_row(results, SINGLE_TARGET, tmp_path)
    assert ("the 6 feasible goals it missed were reached by a median of 3.5 of the oracle's 65 actions, the 8 it "
            "reached by 30; 3 of the missed by at most 3 (narrow goals: place 3); of the missed it chose 1 at P "
            "below its threshold 0.5 (it expected to miss) and 5 at P >= 0.5, 5 of those on 2 objects (box of 6.00 "
            "cm 3, box of 7.10 cm 2)") in row
    # a goal where nothing it asked about was feasible: no choice, not one at P below the threshold
    results["goals"][8] = _goal(planner=False, oracle_hits=2, kind="place", planner_behavior=None, planner_p=0.0)
    assert ("of the missed it chose 1 at P below its threshold 0.5 (it expected to miss) and 4 at P >= 0.5 and "
            "nothing for 1 (none of the candidates it asked about was feasible)") in _missed_target_row(
        results, SINGLE_TARGET, tmp_path)
    # results written before the oracle's hits were recorded: the gap to the oracle per goal kind, as before
    results["goals"] = [{k: v for k, v in goal.items() if k != "oracle_hits"} for goal in results["goals"]]
    assert "the gap to the oracle is largest for" in _missed_target_row(results, SINGLE_TARGET, tmp_path)


def test_a_missed_calibration_names_the_most_overconfident_objects_and_the_ece_without_them(tmp_path: Path) -> None:
    results = _plan_results()
    results["calibration"].update(ece=0.09, n=MIN_CALIBRATION_ACTIONS)
    honest = [_goal(object=o, planner_p=p, planner=bool(k < round(10 * p)))
              for o, p in enumerate((0.1, 0.3, 0.5, 0.7, 0.9), start=1) for k in range(10)]
    boxes = [_goal(object=9, size=0.0707, planner_p=0.95, planner=False, planner_behavior="grasp")] * 9
    results["goals"] = honest + boxes + [_goal(object=9, size=0.0707, planner_p=0.95, planner=False)]
    row = _missed_target_row(results, "calibration ECE", tmp_path)
    assert ("The most overconfident object: box of 7.07 cm: 10 actions (grasp 9, push 1) at a mean P 0.95, 0 "
            "reached; without it the ECE is 0.000 (n=50 chosen actions)") in row


def test_a_missed_left_out_shape_is_set_beside_the_same_goals_with_the_shape_in_training(tmp_path: Path) -> None:
    results = _plan_results({"sphere": (60, 50, 20), **{s: (60, 50, 45) for s in OBJECT_TYPES if s != "sphere"}})
    results["goals"] = [_goal(type=s, planner=k < 45, planner_left_out=k < (20 if s == "sphere" else 45))
                        for s in OBJECT_TYPES for k in range(50)]
    row = _missed_target_row(results, SHAPE_TARGET, tmp_path)
    assert ("sphere: 40.0 % [28, 54] (n=50 feasible) left out, 90.0 % [79, 96] (n=50 feasible) with spheres in "
            "the training data (best fixed") in row


def test_the_plan_report_shows_n_beside_every_rate_and_no_zero_for_nothing(tmp_path: Path) -> None:
    results = _plan_results({**{s: (60, 50, 45) for s in OBJECT_TYPES}, "box": (4, 0, 0)})
    text = write_plan_report(results, tmp_path).read_text()
    box = next(line for line in text.splitlines() if line.startswith("| box |"))
    assert box == "| box | not measured (n=0) | not measured (n=0) | 0.0 % [0, 49] (n=4) |"  # 0 of 0, but 0 of 4
    assert (f"**{TOO_FEW} (n=0 feasible goals of box; at least {MIN_FEASIBLE_PER_SHAPE} feasible goals of box "
            "needed)**") in text
    assert "| lift | not measured (n=0) |" in text  # a goal kind without goals
    rows = [line for line in text.splitlines() if line.startswith("| ")]
    assert len(rows) > 20
    for cell in (cell for line in rows for cell in line.split("|")):
        rates = re.findall(r"\d\.\d %", cell)  # a measured rate (the bounds are whole percents)
        assert cell.count("n=") >= len(rates), cell


def test_shares_within_1_3_and_5_cm_carry_their_n_and_read_too_few_below_the_minimum(tmp_path: Path) -> None:
    from affordance_learning.common.typed_json import to_json
    from affordance_learning.planning.experiment import within_shares
    from affordance_learning.planning.targets import success_within

    results = _plan_results(episodes=(MIN_EPISODES, 50))
    # 40 place goals: 8 within 1 cm, 20 within 3 cm, 30 within 5 cm; the oracle every one within 5 cm
    planner = [[i < 8, i < 20, i < 30] for i in range(40)]
    results["place_success_within"] = {"planner": within_shares(planner),
                                       "oracle": within_shares([[i < 20, i < 35, True] for i in range(40)])}
    for policy in MULTI_POLICIES:  # each policy's episodes: 6 of 10 within 5 cm, too few for a verdict
        results["multi_step"][policy]["success_within"] = within_shares([[False, i < 3, i < 6] for i in range(10)])
    read = PlanResults.from_dict(to_json(PlanResults.from_dict(results)))  # results.json keeps them
    assert read.place_within("planner", 0.05).value == 0.75 and read.place_within("planner", 0.01).n == 40
    assert read.place_within("planner", 0.05).ci == wilson_interval(30, 40)
    assert read.multi_step.policy("direction").within(0.03).value == 0.3
    rows = {row.name: row for row in success_within(read)}
    assert list(rows) == ["single-step place goals, planner", "single-step place goals, oracle",
                          "multi-step targets, planner", "multi-step targets, direction", "multi-step targets, random"]
    text = write_plan_report(read, tmp_path).read_text()
    assert ("| single-step place goals, planner | 20.0 % [10, 35] (n=40 place goals) | 50.0 % [35, 65] (n=40 place "
            "goals) | 75.0 % [60, 86] (n=40 place goals) |") in text
    assert (f"| multi-step targets, planner | 0.0 % [0, 28] (n=10 episodes): {TOO_FEW} | 30.0 % [11, 60] (n=10 "
            f"episodes): {TOO_FEW} | 60.0 % [31, 83] (n=10 episodes): {TOO_FEW} |") in text
    # results written before these were recorded: no section, and nothing is made up
    older = _plan_results()
    assert success_within(older) == [] and "Within 1, 3 and 5 cm" not in write_plan_report(older, tmp_path).read_text()
    assert PlanResults.from_dict(older).place_within("planner", 0.05).value is None


def test_a_quick_run_says_so_in_its_report(tmp_path: Path) -> None:
    results = _plan_results()
    assert "quick run" not in write_plan_report(results, tmp_path).read_text()
    plan_time = "affordance plan's time [min]"
    assert evaluate_targets(results)[plan_time].word == MET  # 1 min of a full run
    results["settings"] = {**results["settings"], "quick": True}
    assert "**A quick run** (`affordance plan --quick`)" in write_plan_report(results, tmp_path).read_text()
    assert evaluate_targets(results)[plan_time].word == TOO_FEW  # a quick run's time is not a full run's


# --- the paper's claims ----------------------------------------------------------------------------------------
def _grasp_results(straddle: list[tuple[int, int, list[float]]], trials: int = 20, rows: int = 1000) -> dict:
    """Grasp results with a critical size of 6 cm, a 1 x 3 map of (successes, failures, sizes) and a uniformity
    curve, as ``trials`` trials of ``rows`` interactions."""
    u = {2: 0.66, 3: 0.60, 4: 0.70, 5: 0.72, 6: 0.75, 7: 0.78, 8: 0.80, 9: 0.84, 10: 0.90}
    return {
        "results_format": 2,
        "config": {"behavior": "grasp", "n_trials": trials, "n_rows": rows},
        "uniformity": {str(k): {"mean": v, "std": 0.05} for k, v in u.items()},
        "size_success": {"bins": [{"low": 0.03, "high": 0.06, "n": rows // 2, "success": 0.9},
                                  {"low": 0.06, "high": 0.09, "n": rows - rows // 2, "success": 0.1}],
                         "logistic": {"intercept": 18.0, "slope": -300.0}, "critical_size": 0.06,
                         "below": {"n": rows // 2, "success": 0.9}, "above": {"n": rows - rows // 2, "success": 0.1}},
        "case_studies": {"3": [{"cluster": c, "success": s, "fail": f, "types": {}, "sizes": sizes}
                               for c, (s, f, sizes) in enumerate(straddle)]},
    }


SMALL, BOTH, LARGE = [0.03, 0.04, 0.05], [0.05, 0.055, 0.062, 0.068], [0.07, 0.08, 0.09]


def _verdict(results: dict, topic: str) -> str:
    return next(c.word for c in evaluate_claims(results) if c.topic == topic)


def test_a_straddling_category_must_be_a_minority() -> None:
    # the paper's picture: a success and a fail category, and a minority between them, with some of each
    good = _grasp_results([(400, 20, SMALL), (120, 80, BOTH), (20, 460, LARGE)])
    assert _verdict(good, STRADDLE) == MET
    # what the shipped grasp shows: the category with objects and outcomes on both sides holds 97 % of everything
    bulk = _grasp_results([(553, 414, [0.04, 0.07, 0.1]), (0, 29, [0.071, 0.093]), (0, 4, [0.083, 0.085])])
    assert _verdict(bulk, STRADDLE) == MISSED
    claim = next(c for c in evaluate_claims(bulk) if c.topic == STRADDLE)
    assert "holds 97 % of the interactions" in claim.ours and f"{100 * STRADDLE_MAX_SIZE:.0f} %" in claim.rule
    # a majority, with two fair categories beside it, is still the bulk of the map
    majority = _grasp_results([(200, 20, SMALL), (330, 270, BOTH), (20, 160, LARGE)])
    assert _verdict(majority, STRADDLE) == MISSED


def test_the_categories_a_straddling_one_steals_from_hold_enough_of_both_outcomes() -> None:
    # a category of 5 % beside the straddling one: not one of the two it steals from
    handful = _grasp_results([(630, 20, SMALL), (180, 120, BOTH), (5, 45, LARGE)])
    assert 50 / 1000 < STRADDLE_MIN_SIZE and _verdict(handful, STRADDLE) == MISSED
    # two success categories beside it: there is no fail category to steal from
    no_fail = _grasp_results([(400, 20, SMALL), (120, 80, BOTH), (300, 80, LARGE)])
    assert _verdict(no_fail, STRADDLE) == MISSED


def test_claims_judged_on_too_few_data_say_so_with_their_n() -> None:
    straddle = [(400, 20, SMALL), (120, 80, BOTH), (20, 460, LARGE)]
    few_trials = _grasp_results(straddle, trials=MIN_TRIALS - 1)
    claims = {c.topic: c for c in evaluate_claims(few_trials)}
    assert claims["Fall at k = 3"].word == TOO_FEW and claims["Fall at k = 3"].n == MIN_TRIALS - 1
    assert claims["Fall at k = 3"].text.startswith(f"too few data (n={MIN_TRIALS - 1} trials of 1000 interactions")
    assert claims[STRADDLE].word == MET  # a map of the first trial does not depend on the trials
    assert _verdict(_grasp_results(straddle, trials=MIN_TRIALS), "Fall at k = 3") == MET
    few_rows = _grasp_results(straddle, rows=MIN_INTERACTIONS - 1)
    assert _verdict(few_rows, "Fall at k = 3") == TOO_FEW and _verdict(few_rows, "Critical size") == TOO_FEW
    small_map = _grasp_results([(80, 4, SMALL), (24, 16, BOTH), (4, 70, LARGE)])  # 198 interactions
    claim = next(c for c in evaluate_claims(small_map) if c.topic == STRADDLE)
    assert claim.word == TOO_FEW and claim.n == 198 and "198 interactions in the 1 x 3 map" in claim.text
    # results that do not say how many trials they hold get no verdict
    unknown = copy.deepcopy(few_trials)
    del unknown["config"]["n_trials"]
    fall = next(c for c in evaluate_claims(unknown) if c.topic == "Fall at k = 3")
    assert fall.word == NOT_MEASURED and fall.text == "not measured (n unknown)"


def test_every_claim_carries_its_n_in_the_report() -> None:
    results = _grasp_results([(400, 20, SMALL), (120, 80, BOTH), (20, 460, LARGE)])
    claims = evaluate_claims(results)
    for c in claims:
        assert re.search(r"\(n=\d+ ", c.text) or c.word == NOT_MEASURED, c
    text = render_report(results)
    rows = [line for line in text.splitlines() if any(line.startswith(f"| {c.topic} |") for c in claims)]
    assert len(rows) == len(claims)
    for row, c in zip(rows, claims, strict=True):
        assert row.endswith(f"**{c.word}** ({c.n_text}) |")
    assert "had too few data" in text and f"at least {MIN_TRIALS} trials of {MIN_INTERACTIONS}" in text
    few = render_report({**results, "config": {**results["config"], "n_trials": 3}})
    assert "**too few data** (n=3 trials of 1000 interactions; at least" in few


def test_a_missed_target_toward_the_robot_says_where_the_draw_could_not_reach(tmp_path: Path) -> None:
    results = _plan_results()
    planner = results["multi_step"]["planner"]
    planner.update(success_toward_robot=0.4, success_toward_robot_ci=list(wilson_interval(8, 20)),
                   n_toward_robot=20)

    def episode(x: float, pulls: dict | None, success: bool = False) -> dict:
        return {"type": "box", "start_xy": [x, 0.0], "target_xy": [x + 0.15, 0.0], "success": success,
                "within_reach": True, "gave_up": False, "toward_robot": True, "pulls_at_start": pulls}

    planner["episodes"] = [episode(-0.47, {"draw": False, "grasp": False}),
                           episode(-0.45, {"draw": False, "grasp": True}),
                           episode(-0.30, {"draw": True, "grasp": True}), episode(-0.30, None, success=True)]
    row = next(line for line in write_plan_report(results, tmp_path).read_text().splitlines()
               if line.startswith("| multi-step targets toward the robot"))
    assert ("of the 3 missed, 2 started where the draw, the one behaviour that pulls, cannot reach behind the "
            "object (the nearest 45 cm in front of the robot), 1 of them out of the grasp's reach too") in row
    assert "could act on the object at the start" not in row  # not recorded for the episode that reached it
    # Recorded for every episode toward the robot: the share reached where the draw or the grasp could act at first
    planner["episodes"][3] = episode(-0.30, {"draw": True, "grasp": False}, success=True)
    row = next(line for line in write_plan_report(results, tmp_path).read_text().splitlines()
               if line.startswith("| multi-step targets toward the robot"))
    assert ("where the draw could act on the object at the start, the planner reached 50.0 % [9, 91] (n=2 "
            "episodes), where the draw or the grasp could, 33.3 % [6, 79] (n=3 episodes)") in row
    read = PlanResults.from_dict(results).multi_step.policy("planner").episodes[1]
    assert read.pulls_at_start == {"draw": False, "grasp": True} and hash(read)
    with pytest.raises(TypeError):
        read.pulls_at_start["draw"] = True  # type: ignore[index]  # a read-only view, as the rest of the results
