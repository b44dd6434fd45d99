"""The typed, read-only view of the learning results (:class:`Results`) and of the plan's (:class:`PlanResults`),
and the claims specified as :class:`Spec`: read from the shipped reproductions, checked, upgraded from format
1, and the same reports whether given a dict or the view."""

from __future__ import annotations

import copy
import dataclasses
import json
from pathlib import Path

import pytest

from affordance_learning.common.exceptions import InvalidValueError
from affordance_learning.common.verdicts import Spec, judge
from affordance_learning.paper.claims import CLAIM_SETS, METHOD_CLAIMS, evaluate_claims
from affordance_learning.paper.report import render_report
from affordance_learning.paper.results import RESULTS_FORMAT, Results, Stat, k_key, r_key
from affordance_learning.planning.results import NOTHING, PlanResults

ROOT = Path(__file__).resolve().parent.parent
TAP = ROOT / "docs" / "reproduction" / "tap" / "results.json"
REPRODUCTIONS = sorted(p.parent for p in (ROOT / "docs" / "reproduction").glob("*/results.json"))


@pytest.fixture(scope="module")
def raw() -> dict:
    return json.loads(TAP.read_text())


def _format_1(results: dict) -> dict:
    """``results`` as format 1 wrote them: no results_format, the uniformity in percent."""
    older = copy.deepcopy(results)
    del older["results_format"]
    for entry in older["uniformity"].values():
        entry["mean"], entry["std"] = 100 * entry["mean"], 100 * entry["std"]
    return older


# --- reading -----------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("where", REPRODUCTIONS, ids=[p.name for p in REPRODUCTIONS])
def test_a_shipped_results_json_round_trips(where: Path) -> None:
    text = (where / "results.json").read_text()
    found = json.loads(text)
    results = Results.from_dict(found)
    assert results.to_dict() == found  # nothing of the file is lost or changed
    assert json.dumps(results.to_dict(), indent=2) == text  # written back as it was, key order and floats
    assert Results.from_dict(results.to_dict()) == results
    assert json.loads(json.dumps(results.to_dict())) == found


def test_the_queries_give_the_numbers_of_the_file(raw: dict) -> None:
    results = Results.from_dict(raw)
    assert results.results_format == RESULTS_FORMAT
    assert results.ks == tuple(range(2, 11)) and results.rs == (0.0, 0.2, 0.4, 0.6, 0.8)
    assert results.behavior == raw["config"]["behavior"] == "tap"
    assert results.success_share == raw["config"]["success_fraction"]
    for k in results.ks:
        assert results.uniformity[k] == Stat(**raw["uniformity"][str(k)])
    assert results.accuracy(0.4)[3] == Stat(**raw["svm_accuracy"]["0.4"]["3"])
    assert results.accuracy(0.5) == {}  # an r that was not run
    assert results.n_selected[0.8][10].mean == raw["n_selected"]["0.8"]["10"]["mean"]
    clusters = results.clusters(2)
    assert [(c.index, c.success, c.fail, c.left_view) for c in clusters] == [
        (c["cluster"], c["success"], c["fail"], c["left_view"]) for c in raw["case_studies"]["2"]]
    first = raw["case_studies"]["2"][0]
    assert clusters[0].sizes == tuple(first["sizes"]) and clusters[0].n == first["success"] + first["fail"]
    assert results.clusters(7) == ()  # no case study of that map
    assert results.size_success.test.depends_on_size is False and results.size_success.critical_size is None
    assert results.effects.by_type["sphere"].n == raw["effects"]["by_type"]["sphere"]["n"]
    assert results.feature_names == tuple(raw["feature_names"]) and len(results.prototypes[4]) == 4
    assert dict(results.config.items()) == raw["config"] and results.config.n_trials == 20
    assert (k_key(3), r_key(0.4), r_key(0)) == ("3", "0.4", "0.0")


def test_the_view_is_read_only_and_apart_from_the_dict(raw: dict) -> None:
    mine = copy.deepcopy(raw)
    results = Results.from_dict(mine)
    with pytest.raises(dataclasses.FrozenInstanceError):
        results.uniformity = {}  # type: ignore[misc]
    with pytest.raises(TypeError):
        results.uniformity[2] = Stat(0.0, 0.0)  # type: ignore[index]
    with pytest.raises(TypeError):
        results.clusters(2)[0].types["sphere"] = 0  # type: ignore[index]
    mine["uniformity"]["2"]["mean"] = 0.0
    mine["config"]["ks"].append(11)
    results.config.get("ks").append(12)
    assert results.uniformity[2].mean == raw["uniformity"]["2"]["mean"]
    assert results.config.get("ks") == raw["config"]["ks"]


def test_partial_results_are_read_with_the_sections_they_hold() -> None:
    partial = Results.from_dict({"results_format": 2, "uniformity": {"2": {"mean": 0.9, "std": 0.0}}})
    assert partial.ks == (2,) and partial.svm_accuracy is None and partial.rs == () and partial.clusters(2) == ()
    assert partial.missing(["uniformity", "svm_accuracy", "case_studies"]) == ["svm_accuracy", "case_studies"]
    assert partial.behavior == "tap" and partial.config.n_trials is None  # written before they were recorded


# --- what is refused ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize(("edit", "named"), [
    (lambda r: r["uniformity"]["3"].pop("std"), r"results\['uniformity'\]\['3'\] lacks 'std'"),
    (lambda r: r["svm_accuracy"]["0.4"]["5"].pop("mean"), r"results\['svm_accuracy'\]\['0.4'\]\['5'\] lacks 'mean'"),
    (lambda r: r["case_studies"]["2"][1].pop("fail"), r"results\['case_studies'\]\['2'\]\[1\] lacks 'fail'"),
    (lambda r: r["size_success"]["bins"][0].pop("n"), r"results\['size_success'\]\['bins'\]\[0\] lacks 'n'"),
    (lambda r: r["effects"]["by_type"]["box"].pop("rest"), r"results\['effects'\]\['by_type'\]\['box'\] lacks 'rest'"),
    (lambda r: r["uniformity"].update(two={"mean": 0.5, "std": 0.0}), r"the key 'two', which is not a map size k"),
    (lambda r: r["n_selected"].update(high={}), r"the key 'high', which is not a relevancy threshold r"),
    (lambda r: r["uniformity"]["4"].update(mean="90 %"), r"results\['uniformity'\]\['4'\]\['mean'\] must be a number"),
    (lambda r: r["case_studies"]["4"][0].update(success=2.5), r"\['success'\] must be a count .* got 2.5"),
    (lambda r: r.update(case_studies=[]), r"results\['case_studies'\] must be a mapping, got list"),
])
def test_a_missing_key_or_a_value_not_of_the_format_is_named(raw: dict, edit, named: str) -> None:
    broken = copy.deepcopy(raw)
    edit(broken)
    with pytest.raises(InvalidValueError, match=named):
        Results.from_dict(broken)


def test_required_sections_are_named_when_missing(raw: dict) -> None:
    without = {k: v for k, v in raw.items() if k not in ("svm_accuracy", "case_studies")}
    with pytest.raises(InvalidValueError, match=r"results lack \['svm_accuracy', 'case_studies'\]; expected the "
                       r"results of run_protocol \(Results.to_dict\(\)"):
        Results.from_dict(without, required=("uniformity", "svm_accuracy", "case_studies"))
    results = Results.from_dict(without)  # the view of what they hold, and then the check
    with pytest.raises(InvalidValueError, match=r"lack \['svm_accuracy'\]"):
        Results.from_dict(results, required=("svm_accuracy",))
    with pytest.raises(InvalidValueError, match="no results section 'svm'; the sections are uniformity"):
        results.missing(["svm"])
    for value in (None, [1, 2], "results.json"):
        with pytest.raises(InvalidValueError, match=f"results must be a mapping.*got {type(value).__name__}"):
            Results.from_dict(value)  # type: ignore[arg-type]


# --- older and newer formats -------------------------------------------------------------------------------------
def test_format_1_is_read_as_the_current_format(raw: dict) -> None:
    older = _format_1(raw)
    upgraded = Results.from_dict(older)
    current = Results.from_dict(raw)
    assert upgraded.results_format == RESULTS_FORMAT
    for k in current.ks:  # format 1 gave the uniformity in percent, the current one a fraction
        assert upgraded.uniformity[k].mean == pytest.approx(current.uniformity[k].mean, rel=1e-12)
        assert upgraded.uniformity[k].std == pytest.approx(current.uniformity[k].std, rel=1e-12)
    assert upgraded.svm_accuracy == current.svm_accuracy and upgraded.case_studies == current.case_studies
    assert upgraded.to_dict()["results_format"] == RESULTS_FORMAT and "results_format" not in older  # not changed
    assert render_report(older) == render_report(raw)
    with pytest.raises(InvalidValueError, match="results of format 3; this tap-affordance reads formats 1 to 2"):
        Results.from_dict({**raw, "results_format": 3})


# --- the claims --------------------------------------------------------------------------------------------------
def test_claims_are_specified_once_each_as_a_spec(raw: dict) -> None:
    specs = [spec for claims in (*CLAIM_SETS.values(), METHOD_CLAIMS) for spec in claims]
    assert specs and all(isinstance(spec, Spec) for spec in specs)
    assert all(spec.topic and spec.statement and spec.rule and callable(spec.judge) and callable(spec.basis)
               for spec in specs)
    with pytest.raises(dataclasses.FrozenInstanceError):
        specs[0].rule = "anything goes"  # type: ignore[misc]
    results = Results.from_dict(raw)
    assert evaluate_claims(results) == evaluate_claims(raw) == [judge(spec, results) for spec in CLAIM_SETS["tap"]]
    assert render_report(results) == render_report(raw)


# --- the plan's results ------------------------------------------------------------------------------------------
def _plan() -> dict:
    """Plan results in the format of run_plan, small."""
    outcome = {"success": 0.5, "success_ci": [0.3, 0.7], "n": 20, "success_feasible": 0.625,
               "success_feasible_ci": [0.4, 0.8], "n_feasible": 16}
    policies = ("planner", "random", "best_fixed", "som_categories", "canonical", "oracle")
    multi = {p: {"success": 0.4, "success_ci": [0.2, 0.6], "n": 10, "reach_failures": 0.1, "interactions": 30,
                 "gave_up": 0, "median_final_distance_m": 0.05} for p in ("planner", "direction", "random")}
    multi["planner"].update(by_type={"box": {"n": 10, "success": 0.4}}, within_reach={"n": 6, "success": 0.5},
                            episodes=[{"type": "box", "start_xy": [-0.3, 0.0], "target_xy": [-0.2, 0.1],
                                       "success": False, "within_reach": True, "gave_up": False,
                                       "failures": ["reach: the stroke started 2 cm away"]}])
    return {
        "format": "tap-affordance-plan-results", "version": 1, "seed": 0, "settings": {"episodes": 100},
        "training": {"tap": 100}, "timings_s": {"total": 90.0}, "single_step": {p: outcome for p in policies},
        "single_step_by_goal": {"roll": {p: outcome for p in policies}}, "best_fixed_behavior": {"roll": "tap"},
        "planner_over_oracle": 0.8, "leave_one_shape_out": {"box": {p: outcome for p in policies}},
        "multi_step": {**multi, "step_reach_p90_m": {"box": {"+x": 0.01, "-x": 0.02, "+y": 0.03, "-y": 0.04}},
                       "max_interactions": 5, "tolerance_m": 0.03},
        "placement_error_median_m": 0.04, "placement_error_n": 7,
        "calibration": {"ece": 0.02, "auroc": None, "n": 50, "curve": [{"p": 0.5, "observed": 0.4, "n": 50}]},
        "goals": [],
    }


def test_plan_results_are_read_typed() -> None:
    plan = PlanResults.from_dict(_plan())
    planner = plan.single_step["planner"]
    assert (planner.reached.value, planner.reached.n, planner.reached.ci) == (0.5, 20, (0.3, 0.7))
    assert (planner.feasible.value, planner.feasible.n) == (0.625, 16)
    multi = plan.multi_step.policy("planner")
    assert multi.reach_failure_count == 3 and multi.within_reach.n == 6 and multi.by_type["box"].value == 0.4
    assert multi.episodes[0].target_xy == (-0.2, 0.1) and multi.episodes[0].failures[0].startswith("reach:")
    assert plan.multi_step.policy("random").within_reach == NOTHING  # only the planner's episodes are described
    assert set(plan.multi_step.policies) == {"planner", "direction", "random"}  # not its settings
    assert plan.multi_step.step_reach_p90_m["box"]["-y"] == 0.04 and plan.multi_step.max_interactions == 5
    assert plan.calibration.auroc is None and plan.calibration.curve[0].n == 50
    assert (plan.total_time_s, plan.episodes, plan.placement_error_n) == (90.0, 100, 7)
    assert PlanResults.from_dict(plan) is plan
    with pytest.raises(InvalidValueError, match="no multi-step outcome of policy 'oracle', only of planner"):
        plan.multi_step.policy("oracle")


def test_plan_results_count_placements_from_the_goals_when_older() -> None:
    older = _plan()
    del older["placement_error_n"]
    # goals as results written before these were recorded: without the object's size, the oracle's hits, the
    # left-out planner's outcome
    goal = {"kind": "place", "type": "box", "object": 0, "goal": {"kind": "place", "target_xy": [-0.3, 0.0]},
            "planner": False, "planner_p": 0.1, "planner_behavior": "push", "oracle": False}
    older["goals"] = [goal] * 3 + [{**goal, "planner_behavior": None}]
    read = PlanResults.from_dict(older)
    assert read.placement_error_n == 3
    assert read.goals[0].oracle_hits is None and read.goals[0].size is None and read.goals[3].planner_behavior is None


@pytest.mark.parametrize(("edit", "named"), [
    (lambda r: r.pop("calibration"), r"plan results lacks 'calibration'"),
    (lambda r: r["single_step"]["planner"].pop("n_feasible"), r"plan results\['single_step'\]\['planner'\] lacks "
                                                              "'n_feasible'"),
    (lambda r: r["multi_step"]["planner"]["episodes"][0].pop("target_xy"), r"\['episodes'\]\[0\] lacks 'target_xy'"),
    (lambda r: r["calibration"].update(ece="low"), r"plan results\['calibration'\]\['ece'\] must be a number"),
    (lambda r: r.update(goals=[{"kind": "place"}]), r"plan results\['goals'\]\[0\] lacks 'type', 'object'"),
    (lambda r: r.update(goals=[{"kind": "place", "type": "box", "object": 0, "planner": "false", "planner_p": 0.1,
                                "planner_behavior": "push", "oracle": False}]),
     r"plan results\['goals'\]\[0\]\['planner'\] must be true or false, got 'false'"),
    (lambda r: r.update(format="tap-affordance-results"), "results of format 'tap-affordance-results', not "
                                                          "'tap-affordance-plan-results'"),
    (lambda r: r.update(version=3), "plan results of version 3; this tap-affordance reads versions 1 to 2 of "
                                    "'tap-affordance-plan-results': upgrade the package"),
])
def test_plan_results_name_what_is_missing_or_wrong(edit, named: str) -> None:
    broken = _plan()
    edit(broken)
    with pytest.raises(InvalidValueError, match=named):
        PlanResults.from_dict(broken)
