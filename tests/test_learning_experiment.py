"""The paper's protocol, figures and report on data with a known answer; predict_effect's shipped model."""

import json

import numpy as np
import pandas as pd
import pytest

from affordance_env.features import FEATURE_NAMES
from affordance_learning.experiment import run_protocol
from affordance_learning.figures import write_figures
from affordance_learning.report import write_report


def synthetic_frame(n=120, seed=0) -> pd.DataFrame:
    """Rolling objects (sphere-like shape features) move far; others barely: a miniature of the tap data."""
    rng = np.random.default_rng(seed)
    types = rng.choice(["sphere", "box", "horizontal_cylinder", "vertical_cylinder"], n)
    rolls = np.isin(types, ["sphere", "horizontal_cylinder"])
    initial = rng.normal(size=(n, len(FEATURE_NAMES)))
    initial[:, 3] += 3.0 * rolls  # a shape feature tells rolling objects apart
    effect = rng.normal(scale=0.1, size=(n, len(FEATURE_NAMES)))
    effect[:, 24:28] += np.where(rolls, -5.0, 0.0)[:, None]  # they leave the view: size features collapse
    frame = pd.DataFrame(initial, columns=[f"initial_{f}" for f in FEATURE_NAMES])
    frame[[f"effect_{f}" for f in FEATURE_NAMES]] = effect
    frame["type"], frame["rolled"], frame["size"] = types, rolls, rng.uniform(0.04, 0.1, n)
    return frame


@pytest.fixture(scope="module")
def results():
    return run_protocol(synthetic_frame(), ks=(2, 3, 4, 5), n_trials=3, random_state=1, n_jobs=1)


def test_results_schema(results):
    assert set(results["uniformity"]) == {"2", "3", "4", "5"}
    for key in ("svm_accuracy", "shape_fraction", "n_selected"):
        assert set(results[key]) == {"0.0", "0.2", "0.4", "0.6", "0.8"}
        assert set(results[key]["0.4"]) == {"2", "3", "4", "5"}
        assert set(results[key]["0.4"]["2"]) == {"mean", "std"}
    assert set(results["case_studies"]) == {"2", "4"}
    cluster = results["case_studies"]["2"][0]
    assert set(cluster) == {"cluster", "rolled", "not_rolled", "types", "sizes"}
    assert sum(c["rolled"] + c["not_rolled"] for c in results["case_studies"]["2"]) == 120
    json.dumps(results)  # JSON-ready


def test_protocol_finds_the_planted_structure(results):
    assert results["uniformity"]["2"]["mean"] > 95
    assert results["shape_fraction"]["0.8"]["2"]["mean"] == 1.0  # the one planted shape feature wins
    assert results["svm_accuracy"]["0.8"]["2"]["mean"] > 0.9
    counts = [results["n_selected"][r]["2"]["mean"] for r in ("0.0", "0.4", "0.8")]
    assert counts[0] >= counts[1] >= counts[2]


def test_protocol_does_not_depend_on_n_jobs(results):
    again = run_protocol(synthetic_frame(), ks=(2, 3, 4, 5), n_trials=3, random_state=1, n_jobs=2)
    assert json.dumps(again, sort_keys=True) == json.dumps(results, sort_keys=True)


def test_figures_and_report_are_written(results, tmp_path):
    paths = write_figures(results, tmp_path)
    assert {p.name for p in paths} == {"uniformity.png", "selected_features.png", "case_study_k2.png",
                                       "case_study_k4.png", "svm_accuracy.png"}
    for path in paths:
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and path.stat().st_size > 10_000
    report = write_report(results, tmp_path).read_text()
    assert "| the paper | this reproduction | agrees |" in report
    assert "Uniformity" in report and "uniformity.png" in report


def test_bad_frames():
    frame = synthetic_frame()
    with pytest.raises(ValueError, match="rolled"):
        run_protocol(frame.drop(columns="rolled"), n_trials=1)
    with pytest.raises(ValueError, match="effect_"):
        run_protocol(frame.drop(columns=f"effect_{FEATURE_NAMES[0]}"), n_trials=1)
    broken = frame.copy()
    broken.iloc[0, 0] = np.nan
    with pytest.raises(ValueError, match="finite"):
        run_protocol(broken, n_trials=1)
    with pytest.raises(ValueError, match="relevancies"):
        run_protocol(frame, relevancies=(0.5, 1.5), n_trials=1)


@pytest.mark.slow
def test_relieff_equals_skrebate_on_real_taps():
    """The fast ReliefF gives skrebate's weights on real data from the environment."""
    skrebate = pytest.importorskip("skrebate")
    from affordance_env.tap_env import TapAffordanceEnv
    from affordance_learning.model import AffordanceModel
    from affordance_learning.relieff import relieff_weights

    env = TapAffordanceEnv(camera_width=48, camera_height=48)
    initial, effect = [], []
    for seed in range(120):
        env.reset(seed=seed)
        info = env.step(np.zeros(3))[4]
        initial.append(info["initial_features"])
        effect.append(info["effect"])
    X, E = np.array(initial, dtype=np.float64), np.array(effect, dtype=np.float64)
    labels = AffordanceModel(n_clusters=3, random_state=0).fit(X, E).labels_
    expected = skrebate.ReliefF(n_neighbors=10).fit(X, labels).feature_importances_
    np.testing.assert_allclose(relieff_weights(X, labels, n_neighbors=10), expected, atol=1e-6)
