"""The paper's protocol on a dataset frame, its figures and its report."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from affordance_learning import run_protocol, write_figures, write_report
from affordance_learning.common.schema import feature_groups, feature_names
from affordance_learning.common.typed_json import to_json
from affordance_learning.common.verdicts import MET, MISSED, NOT_MEASURED, WORDS
from affordance_learning.paper.report import evaluate_claims, write_overview
from affordance_learning.paper.results import Results
from affordance_learning.paper.synthetic import make_synthetic_frame

KS = (2, 3, 4)
RS = (0.0, 0.4)
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def frame() -> pd.DataFrame:
    return make_synthetic_frame(240, random_state=1)


@pytest.fixture(scope="module")
def typed(frame: pd.DataFrame) -> Results:
    return run_protocol(frame, ks=KS, relevancies=RS, n_trials=3, random_state=4, n_jobs=1, som_iterations=600)


@pytest.fixture(scope="module")
def results(typed: Results) -> dict:
    """The results as results.json holds them."""
    return typed.to_dict()


def test_synthetic_frame_has_the_dataset_schema(frame: pd.DataFrame) -> None:
    names = feature_names(frame)
    assert len(names) == 49
    for prefix in ("initial_", "final_", "effect_"):
        assert all(f"{prefix}{n}" in frame.columns for n in names)
    np.testing.assert_allclose(
        frame[[f"final_{n}" for n in names]].to_numpy() - frame[[f"initial_{n}" for n in names]].to_numpy(),
        frame[[f"effect_{n}" for n in names]].to_numpy(),
        atol=1e-9,
    )
    assert set(frame["type"]) == {"sphere", "box", "horizontal_cylinder", "vertical_cylinder"}
    assert frame["rolled"].dtype == bool and frame["size"].between(0.04, 0.10).all()
    assert frame["success"].equals(frame["rolled"]) and set(frame["behavior"]) == {"tap"}
    assert feature_groups(names).count("shape") == 24


def test_results_follow_the_schema(results: dict, frame: pd.DataFrame) -> None:
    k_keys = [str(k) for k in KS]
    r_keys = ["0.0", "0.4"]
    assert list(results["uniformity"]) == k_keys
    for key in ("svm_accuracy", "shape_fraction", "size_fraction", "n_selected"):
        assert list(results[key]) == r_keys
        for r in r_keys:
            assert list(results[key][r]) == k_keys
            assert all(set(v) == {"mean", "std"} for v in results[key][r].values())
    for key in ("uniformity", "purity", "adjusted_rand", "n_categories", "svm_baseline", "feature_weights"):
        assert list(results[key]) == k_keys
    # one unit for every share: a fraction in [0, 1], as config["units"] says
    assert results["results_format"] == 2 and "fractions in [0, 1]" in results["config"]["units"]
    assert all(0.0 <= v["mean"] <= 1.0 for v in results["uniformity"].values())
    assert all(0.0 <= v["mean"] <= 1.0 for v in results["purity"].values())
    assert all(0.0 <= v["mean"] <= 1.0 for r in r_keys for v in results["svm_accuracy"][r].values())
    assert all(1 <= v["mean"] <= 49 for r in r_keys for v in results["n_selected"][r].values())
    assert list(results["case_studies"]) == ["2", "3", "4"]
    for k, clusters in results["case_studies"].items():
        assert [c["cluster"] for c in clusters] == list(range(int(k)))
        assert all(set(c) == {"cluster", "success", "fail", "types", "sizes", "left_view"} for c in clusters)
        assert sum(c["left_view"] for c in clusters) == (~frame["visible_final"]).sum()
        assert sum(c["success"] + c["fail"] for c in clusters) == len(frame)
        assert sum(c["success"] for c in clusters) == frame["success"].sum()
        assert sum(len(c["sizes"]) for c in clusters) == len(frame)
        assert sum(sum(c["types"].values()) for c in clusters) == len(frame)
    config = results["config"]
    assert config["n_trials"] == 3 and config["ks"] == list(KS) and config["relevancies"] == list(RS)
    assert config["feature_groups"] == {"shape": 24, "size": 18, "relation": 7}
    assert config["behavior"] == "tap" and config["label"] == "success"
    assert (config["success_label"], config["fail_label"]) == ("rolled", "did not roll")
    assert config["success_fraction"] == pytest.approx(frame["success"].mean())
    assert config["case_study_ks"] == [2, 3, 4]
    assert set(results["size_success"]) == {"bins", "logistic", "test", "critical_size", "below", "above"}
    assert sum(b["n"] for b in results["size_success"]["bins"]) == len(frame)
    assert set(results["effects"]["by_type"]["sphere"]) >= {"success", "visible_final"}
    assert json.loads(json.dumps(results, allow_nan=False)) == results


def test_the_protocol_builds_the_results_that_its_dict_reads_back_as(typed: Results, results: dict) -> None:
    assert isinstance(typed, Results) and Results.from_dict(results) == typed
    assert typed.uniformity[3].mean == results["uniformity"]["3"]["mean"] and typed.clusters(2)[0].left_view >= 0
    with pytest.raises(TypeError):
        typed.config.entries["behavior"] = "grasp"  # type: ignore[index]


def test_protocol_finds_the_papers_structure_in_synthetic_taps(results: dict) -> None:
    # the synthetic taps roll by shape: clusters follow rolled/not rolled, and shape features are chosen
    assert results["uniformity"]["3"]["mean"] > 0.70
    assert results["shape_fraction"]["0.4"]["3"]["mean"] > 0.8
    assert results["n_selected"]["0.4"]["2"]["mean"] < results["n_selected"]["0.0"]["2"]["mean"]
    assert results["svm_accuracy"]["0.4"]["2"]["mean"] > results["svm_baseline"]["2"]["mean"]
    # the shares count shape (size) features only: never more of them than the 24 (18) there are
    for r, per_k in results["shape_fraction"].items():
        for k, share in per_k.items():
            size = results["size_fraction"][r][k]["mean"]
            assert share["mean"] * results["n_selected"][r][k]["mean"] <= 24.5, (r, k)
            assert size * results["n_selected"][r][k]["mean"] <= 18.5 and share["mean"] + size <= 1.0 + 1e-9


def test_results_do_not_depend_on_n_jobs(frame: pd.DataFrame, results: dict) -> None:
    parallel = run_protocol(
        frame, ks=KS, relevancies=RS, n_trials=3, random_state=4, n_jobs=2, som_iterations=600
    )
    assert json.dumps(parallel.to_dict(), sort_keys=True) == json.dumps(results, sort_keys=True)
    other = run_protocol(frame, ks=(4,), relevancies=RS, n_trials=3, random_state=4, som_iterations=600)
    assert other.to_dict()["uniformity"]["4"] == results["uniformity"]["4"]  # seeds per (trial, k), not position


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"ks": (1, 2)}, "ks must be integers in"),
        ({"ks": (2, 11)}, "ks must be integers in"),
        ({"relevancies": (0.0, 1.2)}, "relevancies"),
        ({"n_trials": 0}, "n_trials"),
        ({"random_state": None}, "random_state"),
        ({"test_size": 1.0}, "test_size"),
        ({"n_neighbors": 0}, "n_neighbors"),
        ({"extra_config": {"ks": [2]}}, r"extra_config restates the protocol's own settings \['ks'\]"),
    ],
)
def test_protocol_refuses_bad_arguments(frame: pd.DataFrame, kwargs: dict, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        run_protocol(frame, **kwargs)


def test_protocol_refuses_bad_frames(frame: pd.DataFrame) -> None:
    with pytest.raises(ValueError, match="no 'success' column .nor 'rolled'"):
        run_protocol(frame.drop(columns=["success", "rolled"]))
    with pytest.raises(ValueError, match="no initial_"):
        run_protocol(frame[["type", "size", "success"]])
    with pytest.raises(ValueError, match="no 'behavior' column; pass the behaviour"):
        run_protocol(frame.drop(columns="behavior"))
    mixed = frame.assign(behavior=np.where(np.arange(len(frame)) % 2, "tap", "grasp"))
    with pytest.raises(ValueError, match=r"mixes the behaviours \['grasp', 'tap'\]"):
        run_protocol(mixed)
    with pytest.raises(ValueError, match="holds 'tap' interactions, not 'grasp'"):
        run_protocol(frame, behavior="grasp")
    broken = frame.copy()
    broken.loc[5, "effect_mean_x"] = np.nan
    with pytest.raises(ValueError, match="row 5, column effect_mean_x"):
        run_protocol(broken)
    with pytest.raises(ValueError, match="expected at least 2 of each"):
        run_protocol(frame.iloc[:5], test_size=0.1)


def test_the_label_is_success_or_else_rolled(frame: pd.DataFrame) -> None:
    # a label that differs from rolled: uniformity and the case study follow success, not rolled
    flipped = frame.assign(success=~frame["rolled"], behavior="push")
    kwargs = {"ks": (2, 3), "relevancies": (0.4,), "n_trials": 1, "som_iterations": 200}
    ours = run_protocol(flipped, **kwargs).to_dict()
    assert ours["config"]["label"] == "success" and ours["config"]["behavior"] == "push"
    assert (ours["config"]["success_label"], ours["config"]["fail_label"]) == ("moved", "did not move")
    assert sum(c["success"] for c in ours["case_studies"]["2"]) == (~frame["rolled"]).sum()
    # a frame without success (made before the label existed) is evaluated against rolled, and says so
    old = run_protocol(frame.drop(columns=["success", "behavior"]), behavior="tap", **kwargs).to_dict()
    assert old["config"]["label"] == "rolled" and old["config"]["success_label"] == "rolled"
    assert sum(c["success"] for c in old["case_studies"]["2"]) == frame["rolled"].sum()
    assert old["uniformity"] == ours["uniformity"]  # |S - F| is the same with the labels swapped
    # but rolled is not the success of a grasp or a push: no silent stand-in
    for behavior in ("grasp", "push"):
        with pytest.raises(ValueError, match=f"no 'success' column, and the success of '{behavior}' is not"):
            run_protocol(frame.drop(columns=["success"]).assign(behavior=behavior), **kwargs)


def test_synthetic_grasps_have_a_critical_size() -> None:
    grasps = make_synthetic_frame(400, random_state=3, behavior="grasp")
    assert set(grasps["behavior"]) == {"grasp"} and grasps["size"].between(0.03, 0.09).all()
    results = run_protocol(grasps, ks=(2, 3, 4), relevancies=(0.4,), n_trials=1, som_iterations=300).to_dict()
    config = results["config"]
    assert config["behavior"] == "grasp"
    assert (config["success_label"], config["fail_label"]) == ("lifted and held", "not held")
    assert results["size_success"]["critical_size"] == pytest.approx(0.06, abs=0.004)
    assert results["size_success"]["logistic"]["slope"] < 0
    assert results["size_fraction"]["0.4"]["2"]["mean"] > 0.5  # held or not is decided by size
    with pytest.raises(ValueError, match="behavior must be one of"):
        make_synthetic_frame(40, behavior="juggle")


def test_a_frame_too_small_to_stratify_gets_a_random_split(frame: pd.DataFrame) -> None:
    lonely = frame.copy()
    lonely.loc[0, "type"] = "cone"
    results = run_protocol(lonely, ks=(2,), relevancies=(0.4,), n_trials=1, som_iterations=200).to_dict()
    assert (
        "random, not stratified" in results["config"]["split"] and "'cone': 1" in results["config"]["split"]
    )
    assert (
        "stratified by object type"
        in run_protocol(frame, ks=(2,), n_trials=1, som_iterations=200).config.get("split")
    )


def test_feature_groups_fall_back_to_the_papers_order() -> None:
    groups = feature_groups([f"f{i}" for i in range(49)])
    assert (
        groups[:24] == ["shape"] * 24 and groups[24:42] == ["size"] * 18 and groups[42:] == ["relation"] * 7
    )
    with pytest.raises(ValueError, match="cannot tell the group"):
        feature_groups(["a", "b"])


def test_figures_and_report_are_written(results: dict, tmp_path: Path) -> None:
    paths = write_figures(results, tmp_path)
    names = {p.name for p in paths}
    assert {
        "uniformity.png",
        "selected_features.png",
        "case_study_k2.png",
        "case_study_k3.png",
        "case_study_k4.png",
        "svm_accuracy.png",
        "prototypes.png",
        "size_success.png",
    } <= names
    for path in paths:
        data = path.read_bytes()
        assert data.startswith(PNG_MAGIC) and len(data) > 10_000, path
    report = write_report(results, tmp_path)
    text = report.read_text()
    assert report.name == "REPORT.md"
    assert "uniformity.png" in text and "| Uniformity on average |" in text
    assert "# Reproduction of Akgun et al. 2009, tap:" in text and "| cluster | rolled | did not roll |" in text
    assert "## Success by object size" in text and "![size_success](size_success.png)" in text
    assert sum(text.count(f"**{v}**") for v in WORDS) == 14
    again = write_report(json.loads(json.dumps(results)), tmp_path / "again").read_text()
    assert again.split("## Configuration")[0] == text.split("## Figures")[0]  # same numbers from the JSON


def _paper_like(results: dict) -> dict:
    """The results edited to say what the paper says, claim by claim."""
    good = copy.deepcopy(results)
    good["config"] = {**good["config"], "n_trials": 20, "n_rows": 1000}  # as many as the maps below hold
    ks = [str(k) for k in range(2, 11)]
    rs = ["0.0", "0.2", "0.4", "0.6", "0.8"]
    good["uniformity"] = {k: {"mean": 0.80 + 0.015 * i, "std": 0.01} for i, k in enumerate(ks)}
    good["shape_fraction"] = {
        r: {k: {"mean": 0.45 + 0.1 * j, "std": 0.0} for k in ks} for j, r in enumerate(rs)
    }
    good["n_selected"] = {r: {k: {"mean": 30.0 - 6 * j, "std": 0.0} for k in ks} for j, r in enumerate(rs)}
    accuracy = {2: 0.95, 3: 0.85, 4: 0.88, 5: 0.8, 6: 0.75, 7: 0.7, 8: 0.66, 9: 0.62, 10: 0.6}
    drop = {"0.0": 0.0, "0.2": 0.002, "0.4": 0.004, "0.6": 0.03, "0.8": 0.06}
    good["svm_accuracy"] = {
        r: {str(k): {"mean": a - drop[r], "std": 0.01} for k, a in accuracy.items()} for r in rs
    }
    sizes = [0.04, 0.07, 0.1]
    good["case_studies"] = {
        "2": [
            {
                "cluster": 0,
                "success": 480,
                "fail": 20,
                "types": {"sphere": 250, "horizontal_cylinder": 240, "box": 5, "vertical_cylinder": 5},
                "sizes": sizes,
            },
            {
                "cluster": 1,
                "success": 10,
                "fail": 490,
                "types": {"sphere": 0, "horizontal_cylinder": 10, "box": 245, "vertical_cylinder": 245},
                "sizes": sizes,
            },
        ],
        "4": [
            {"cluster": c, "success": r, "fail": n, "types": {}, "sizes": sizes}
            for c, (r, n) in enumerate([(240, 5), (230, 20), (5, 245), (10, 245)])
        ],
    }
    return good


def test_report_verdicts_are_computed_from_the_numbers(results: dict) -> None:
    good = _paper_like(results)
    verdicts = {c.topic: c.word for c in evaluate_claims(good)}
    assert set(verdicts.values()) == {MET}, verdicts
    bad = copy.deepcopy(good)
    bad["uniformity"] = {k: {"mean": 0.60 - 0.01 * i, "std": 0.01} for i, k in enumerate(good["uniformity"])}
    bad["svm_accuracy"]["0.4"] = {k: {"mean": 0.5, "std": 0.0} for k in good["svm_accuracy"]["0.4"]}
    bad["case_studies"]["2"][0]["types"]["sphere"], bad["case_studies"]["2"][1]["types"]["sphere"] = 0, 250
    verdicts = {c.topic: c.word for c in evaluate_claims(bad)}
    for topic in (
        "Uniformity on average",
        "Uniformity rises with k",
        "Uniformity peak",
        "1 x 2 map: object types",
        "r = 0.4 best",
        "r = 0, 0.2, 0.4 alike",
    ):
        assert verdicts[topic] == MISSED, topic
    # the other eight claims, each driven the other way
    worse = copy.deepcopy(good)
    rs = sorted(good["shape_fraction"], key=float)
    ks = sorted(good["shape_fraction"][rs[0]], key=int)
    worse["shape_fraction"] = {r: {k: {"mean": 0.45 - 0.1 * j, "std": 0.0} for k in ks} for j, r in enumerate(rs)}
    worse["n_selected"] = {r: {k: {"mean": (5.0 + 3 * j) * (1 + int(k) % 2), "std": 0.0} for k in ks}
                           for j, r in enumerate(rs)}
    rising = {2: 0.6, 3: 0.65, 4: 0.55, 5: 0.7, 6: 0.72, 7: 0.75, 8: 0.78, 9: 0.8, 10: 0.82}
    worse["svm_accuracy"] = {r: {str(k): {"mean": a, "std": 0.0} for k, a in rising.items()} for r in rs}
    worse["case_studies"]["2"][0]["sizes"], worse["case_studies"]["2"][1]["sizes"] = [0.04, 0.05], [0.09, 0.1]
    worse["case_studies"]["4"][2]["success"], worse["case_studies"]["4"][2]["fail"] = 200, 5
    verdicts = {c.topic: c.word for c in evaluate_claims(worse)}
    for topic in (
        "Shape features dominate",
        "Shape share and r",
        "Fewer features as r rises",
        "Number constant in k",
        "1 x 2 map: sizes",
        "1 x 4 map: success/fail",
        "SVM accuracy falls with k",
        "Bump at k = 4",
    ):
        assert verdicts[topic] == MISSED, topic
    partial = {"results_format": 2, "uniformity": good["uniformity"], "config": {"n_trials": 20, "n_rows": 1000}}
    verdicts = {c.topic: c.word for c in evaluate_claims(partial)}
    assert verdicts["Uniformity on average"] == MET and verdicts["Bump at k = 4"] == NOT_MEASURED


def _grasp_like(results: dict) -> dict:
    """The results edited to say what the paper says of the grasp, claim by claim."""
    good = _paper_like(results)
    good["config"] = {**good["config"], "behavior": "grasp", "success_label": "lifted and held",
                      "fail_label": "not held"}
    u = {2: 66.0, 3: 60.0, 4: 70.0, 5: 72.0, 6: 75.0, 7: 78.0, 8: 80.0, 9: 84.0, 10: 90.0}  # mean 75 %
    good["uniformity"] = {str(k): {"mean": v / 100, "std": 0.01} for k, v in u.items()}
    good["size_fraction"] = {r: {k: {"mean": 0.7, "std": 0.0} for k in per_k}
                             for r, per_k in good["shape_fraction"].items()}
    good["size_success"] = {
        "bins": [{"low": 0.03, "high": 0.06, "n": 500, "success": 0.9}, {"low": 0.06, "high": 0.09, "n": 500,
                                                                          "success": 0.1}],
        "logistic": {"intercept": 18.0, "slope": -300.0}, "critical_size": 0.06,
        "below": {"n": 500, "success": 0.9}, "above": {"n": 500, "success": 0.1},
    }
    good["case_studies"]["3"] = [
        {"cluster": 0, "success": 400, "fail": 20, "types": {}, "sizes": [0.03, 0.04, 0.05]},
        {"cluster": 1, "success": 120, "fail": 80, "types": {}, "sizes": [0.05, 0.055, 0.062, 0.068]},
        {"cluster": 2, "success": 20, "fail": 460, "types": {}, "sizes": [0.07, 0.08, 0.09]},
    ]
    return good


GRASP_TOPICS = ("Uniformity on average", "Fall at k = 3", "Critical size",
                "1 x 3 map: a category straddles the critical size", "Size features dominate")


def test_grasp_claims_are_computed_from_the_numbers(results: dict) -> None:
    good = _grasp_like(results)
    verdicts = {c.topic: c.word for c in evaluate_claims(good)}
    assert list(verdicts) == [
        "Uniformity on average", "Uniformity rises with k", "Uniformity peak", "Fall at k = 3", "Critical size",
        "1 x 3 map: a category straddles the critical size", "Size features dominate",
        "Fewer features as r rises", "Number constant in k", "SVM accuracy falls with k"]
    assert set(verdicts.values()) == {MET}, verdicts
    bad = copy.deepcopy(good)
    bad["uniformity"] = {k: {"mean": (84.0 + int(k)) / 100, "std": 0.01} for k in good["uniformity"]}  # >80 %
    bad["size_fraction"] = {r: {k: {"mean": 0.3, "std": 0.0} for k in per_k}
                            for r, per_k in good["size_fraction"].items()}
    bad["size_success"]["below"]["success"], bad["size_success"]["above"]["success"] = 0.6, 0.4  # too soft
    bad["case_studies"]["3"][1]["success"], bad["case_studies"]["3"][1]["fail"] = 95, 5  # nearly all held
    verdicts = {c.topic: c.word for c in evaluate_claims(bad)}
    for topic in GRASP_TOPICS:
        assert verdicts[topic] == MISSED, topic
    # the average must be above 70 %, and not above the tap's 80 %
    low = copy.deepcopy(good)
    low["uniformity"] = {k: {"mean": v["mean"] - 0.10, "std": 0.01} for k, v in good["uniformity"].items()}
    assert {c.topic: c.word for c in evaluate_claims(low)}["Uniformity on average"] == MISSED
    # the straddling cluster must hold objects on both sides of the critical size, not just both outcomes
    one_side = copy.deepcopy(good)
    one_side["case_studies"]["3"][1]["sizes"] = [0.061, 0.065, 0.068, 0.07]
    assert {c.topic: c.word for c in evaluate_claims(one_side)}[GRASP_TOPICS[3]] == MISSED
    # ... and be a category, not a handful of objects (here 5 of 905 interactions)
    handful = copy.deepcopy(good)
    handful["case_studies"]["3"][1].update(success=3, fail=2)
    assert {c.topic: c.word for c in evaluate_claims(handful)}[GRASP_TOPICS[3]] == MISSED
    # success rising with size is not the grasp's critical size
    rising = copy.deepcopy(good)
    rising["size_success"]["logistic"]["slope"] = 300.0
    assert {c.topic: c.word for c in evaluate_claims(rising)}["Critical size"] == MISSED
    # no crossing within the sizes seen: the critical size disagrees, the straddling cannot be computed
    none = copy.deepcopy(good)
    none["size_success"].update(critical_size=None, below=None, above=None)
    verdicts = {c.topic: c.word for c in evaluate_claims(none)}
    assert verdicts["Critical size"] == MISSED and verdicts[GRASP_TOPICS[3]] == NOT_MEASURED
    single = copy.deepcopy(none)
    single["size_success"]["logistic"] = None
    assert {c.topic: c.word for c in evaluate_claims(single)}["Critical size"] == MISSED
    partial = {"results_format": 2, "uniformity": good["uniformity"],
               "config": {"behavior": "grasp", "n_trials": 20, "n_rows": 1000}}
    verdicts = {c.topic: c.word for c in evaluate_claims(partial)}
    assert verdicts["Fall at k = 3"] == MET and verdicts["Critical size"] == NOT_MEASURED


def test_each_behaviour_gets_its_own_claims(results: dict, tmp_path: Path) -> None:
    tap = [c.topic for c in evaluate_claims(results)]
    assert len(tap) == 14 and not set(GRASP_TOPICS[1:]) & set(tap)
    assert [c.topic for c in evaluate_claims(results, behavior="grasp")][:4] == [
        "Uniformity on average", "Uniformity rises with k", "Uniformity peak", "Fall at k = 3"]
    push = copy.deepcopy(results)
    push["config"]["behavior"] = "push"
    assert [c.topic for c in evaluate_claims(push)] == [
        "Uniformity rises with k", "Fewer features as r rises", "Number constant in k", "SVM accuracy falls with k"]
    text = write_report(push, tmp_path).read_text()
    assert "# Reproduction of Akgun et al. 2009, push:" in text and "tapping and grasping only" in text
    assert sum(text.count(f"**{v}**") for v in WORDS) == 4


def test_the_overview_sets_the_behaviours_side_by_side(results: dict, tmp_path: Path) -> None:
    grasp = _grasp_like(results)
    (tmp_path / "grasp").mkdir()
    (tmp_path / "grasp" / "uniformity.png").write_bytes(PNG_MAGIC)
    text = write_overview({"tap": results, "grasp": grasp}, tmp_path).read_text()
    assert text.startswith("# Reproduction of Akgun et al. 2009: tap, grasp")
    assert "| [tap](tap/REPORT.md) | 240 |" in text and "| [grasp](grasp/REPORT.md) |" in text
    assert "6.0 cm (90 % below, 10 % above)" in text  # the grasp's critical size in the headline table
    assert "[uniformity](grasp/uniformity.png)" in text and "## tap" in text and "## grasp" in text
    assert "| Fall at k = 3 |" in text and "| 1 x 2 map: object types |" in text
    assert sum(text.count(f"**{v}**") for v in WORDS) == 14 + 10
    with pytest.raises(ValueError, match="runs must map each behaviour"):
        write_overview({}, tmp_path)


def test_reports_define_uniformity_and_read_older_results_in_percent(results: dict, tmp_path: Path) -> None:
    from affordance_learning.paper.report import render_overview, render_report

    text = render_report(results)
    assert "U = sum over clusters c of |S_c - F_c| / T" in text and "fractions in [0, 1]" in text
    assert "U = sum over clusters c of |S_c - F_c| / T" in render_overview({"tap": results})
    u3 = 100 * results["uniformity"]["3"]["mean"]
    assert f"| uniformity [%] | {100 * results['uniformity']['2']['mean']:.1f} ±" in text
    older = copy.deepcopy(results)  # format 1: the uniformity in percent, no results_format
    del older["results_format"]
    for entry in older["uniformity"].values():
        entry["mean"], entry["std"] = 100 * entry["mean"], 100 * entry["std"]
    assert render_report(older) == text
    assert [c.ours for c in evaluate_claims(older)] == [c.ours for c in evaluate_claims(results)]
    assert f"{u3:.1f}" in next(c.ours for c in evaluate_claims(results) if c.topic == "Uniformity on average")
    with pytest.raises(ValueError, match="results of format 3"):
        render_report({**results, "results_format": 3})


def test_no_critical_size_where_success_does_not_depend_on_size(results: dict, tmp_path: Path) -> None:
    from affordance_learning.paper.metrics import size_success
    from affordance_learning.paper.report import render_overview, render_report

    rng = np.random.default_rng(3)
    sizes = rng.uniform(0.04, 0.10, 1000)  # the tap's rolled share drifts from 47 % to 56 % across the sizes
    drift = copy.deepcopy(results)
    drift["size_success"] = to_json(size_success(sizes, rng.random(1000) < 0.47 + 0.09 * (sizes - 0.04) / 0.06))
    assert drift["size_success"]["critical_size"] is None
    text = render_report(drift)
    assert "Success does not depend on object size" in text and "crosses 50 % at" not in text
    overview_row = next(line for line in render_overview({"tap": drift}).splitlines() if line.startswith("| [tap]"))
    assert overview_row.split(" | ")[6] == "-"  # the critical size column


def test_prototypes_mark_categories_whose_objects_left_the_view(results: dict, tmp_path: Path, monkeypatch) -> None:
    import affordance_learning.paper.figures as figures

    drawn = {}
    monkeypatch.setattr(figures, "_save", lambda fig, path: drawn.setdefault(path.name, fig) and path)
    gone = copy.deepcopy(results)
    clusters = gone["case_studies"]["2"]
    clusters[1]["left_view"] = clusters[1]["success"] + clusters[1]["fail"]  # every object of cluster 1 left
    clusters[0]["left_view"] = 0
    figures.write_figures(gone, tmp_path)
    ax_move = drawn["prototypes.png"].axes[0]  # the 1 x 2 map's motion of the mean point
    assert [t.get_text() for t in ax_move.texts] == ["object left\nthe view:\nno motion\nseen"]
    bars = [bar for container in ax_move.containers for bar in container]
    assert bars and all(abs(bar.get_x() + bar.get_width() / 2) < 0.5 for bar in bars)  # cluster 0's only
    legend = [t.get_text() for t in drawn["prototypes.png"].axes[3].get_legend().get_texts()]
    assert legend[1].endswith(f"{clusters[1]['left_view']} left the view") and "left" not in legend[0]
    case = drawn["case_study_k2.png"].axes[0]
    assert case.get_title() == "(a) outcomes measured by the simulator"
