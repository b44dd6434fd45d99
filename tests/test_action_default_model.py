"""The action-conditioned default models behind ``predict_effect(features, behavior, action=...)``: trained on a
small synthetic goal-episode frame, stored, found in the user's data directory and checked on loading."""

from __future__ import annotations

import joblib
import numpy as np
import pandas as pd
import pytest

from affordance_env.features import FEATURE_NAMES
from affordance_learning.default_model import (
    ActionEffectPrediction,
    DefaultModelError,
    DefaultModelMissingError,
    action_model_path,
    predict_effect,
    train_action_models,
)
from affordance_learning.planning.effect_model import BEHAVIOR_FLAG_WEIGHTS, FLAG_WEIGHT
from affordance_learning.planning.experiment import fit_models

N = len(FEATURE_NAMES)


def goal_frame(n: int = 240, seed: int = 0) -> pd.DataFrame:
    """Goal-episode rows of tap and push: a push moves the object dx = -0.1 a0 [m] (away for a0 > 0), a tap
    dy = -0.1 a0; the perceptual effect's first feature follows dx."""
    rng = np.random.default_rng(seed)
    behavior = np.array(["tap", "push"])[np.arange(n) % 2]
    a = rng.uniform(-1, 1, (n, 3))
    move = -0.1 * a[:, 0]
    dx, dy = np.where(behavior == "push", move, 0.0), np.where(behavior == "tap", move, 0.0)
    x0, y0 = rng.uniform(-0.4, -0.25, n), rng.uniform(-0.1, 0.1, n)
    frame = {"episode": np.arange(n) // 2, "step": np.arange(n) % 2, "behavior": behavior,
             **{f"action_{j}": a[:, j] for j in range(3)},
             "true_initial_x": x0, "true_initial_y": y0, "true_final_x": x0 + dx, "true_final_y": y0 + dy,
             "rolled": np.zeros(n, bool), "outcome": ["rest"] * n, "success": np.zeros(n, bool)}
    features = rng.normal(size=(n, N))
    effects = np.zeros((n, N))
    effects[:, 0] = dx
    frame.update({f"initial_{name}": features[:, i] for i, name in enumerate(FEATURE_NAMES)})
    frame.update({f"effect_{name}": effects[:, i] for i, name in enumerate(FEATURE_NAMES)})
    return pd.DataFrame(frame)


@pytest.fixture(scope="module")
def user_dir(tmp_path_factory):
    directory = tmp_path_factory.mktemp("data")
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("TAP_AFFORDANCE_DATA", str(directory))
        written = train_action_models(goal_frame(), n_estimators=30)
        assert set(written) == {"tap", "push"} and all(p.parent == directory for p in written.values())
        yield directory


def test_an_action_conditioned_prediction_follows_the_action(user_dir, monkeypatch):
    monkeypatch.setenv("TAP_AFFORDANCE_DATA", str(user_dir))
    assert action_model_path("push") == user_dir / "push_action_model.joblib"
    features = np.zeros(N)
    far = predict_effect(features, "push", action=[0.9, 0.0, 0.0])
    back = predict_effect(features, "push", action=[-0.9, 0.0, 0.0])
    assert isinstance(far, ActionEffectPrediction) and far.effect.shape == (N,) and far.displacement.shape == (2,)
    assert far.displacement[0] < -0.05 < 0.05 < back.displacement[0]  # pushed away, or toward the robot
    # the displacement is the neighbours' moved to this action, the perceptual effect theirs as they were
    assert abs(far.displacement[1]) < 0.01 and far.effect[0] == pytest.approx(far.displacement[0], abs=0.02)
    assert 0.0 <= far.rolled <= 1.0 and far.lifted == 0.0
    tap = predict_effect(np.zeros((3, N)), "tap", action=np.array([[0.9, 0, 0], [0, 0, 0], [-0.9, 0, 0]]))
    assert tap.displacement.shape == (3, 2) and tap.displacement[0, 1] < tap.displacement[1, 1] < tap.displacement[2, 1]
    assert predict_effect(np.zeros(N), "tap").category is not None  # without an action: the canonical model


def test_bad_actions_missing_and_foreign_models_are_refused_with_the_rebuild_command(user_dir, monkeypatch, tmp_path):
    monkeypatch.setenv("TAP_AFFORDANCE_DATA", str(user_dir))
    with pytest.raises(ValueError, match=r"action must be the behaviour's 3 parameters in \[-1, 1\]"):
        predict_effect(np.zeros(N), "push", action=[2.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="2 actions for 3 objects"):
        predict_effect(np.zeros((3, N)), "push", action=np.zeros((2, 3)))
    import affordance_learning.default_model as default_model

    with monkeypatch.context() as without_shipped:  # neither the user's nor the package's model of the grasp
        without_shipped.setattr(default_model, "MODEL_DIR", tmp_path / "no-package-models")
        with pytest.raises(DefaultModelMissingError, match="affordance train-default --action-conditioned"):
            predict_effect(np.zeros(N), "grasp", action=np.zeros(3))
    wrong = tmp_path / "push_action_model.joblib"
    bundle = joblib.load(user_dir / "tap_action_model.joblib")
    joblib.dump(bundle, wrong)
    with pytest.raises(DefaultModelError, match="holds a 'tap' model, not a 'push' one"):
        predict_effect(np.zeros(N), "push", action=np.zeros(3), path=wrong)
    joblib.dump({**bundle, "versions": {**bundle["versions"], "scikit-learn": "0.1"}}, wrong)
    with pytest.raises(DefaultModelError, match="other library versions"):
        predict_effect(np.zeros(N), "tap", action=np.zeros(3), path=wrong)
    earlier = bundle["model"]
    del earlier.kinds_  # as a model fitted before the local slopes has none
    joblib.dump(bundle, wrong)
    with pytest.raises(DefaultModelError, match="earlier ActionEffectModel"):
        predict_effect(np.zeros(N), "tap", action=np.zeros(3), path=wrong)


def test_the_shipped_models_predict_each_behaviours_way(monkeypatch, tmp_path):
    # After install, with no model of the user's: the package's, one per behaviour, each moving the object its way.
    import gymnasium as gym

    import affordance_env  # noqa: F401 (registers the envs)

    monkeypatch.setenv("TAP_AFFORDANCE_DATA", str(tmp_path / "nothing-here"))
    env = gym.make("TapAffordanceGoal-v2", camera_width=160, camera_height=120)
    obs, _ = env.reset(seed=0, options={"object_type": "box", "size": 0.05, "position": (-0.30, 0.03)})
    features = obs["observation"]["features"]
    moved = {b: predict_effect(features, b, action=np.zeros(3)).displacement for b in ("tap", "tap_back", "draw")}
    assert moved["tap"][1] < -0.005 and moved["tap_back"][1] > 0.005 and moved["draw"][0] > 0.03
    placed = predict_effect(features, "grasp", action=[0.5, -0.5, 0.0])  # pick and place: 10 cm +x, 10 cm -y
    assert placed.lifted > 0.5 and placed.displacement[0] > 0.04 and placed.displacement[1] < -0.04
    env.close()


def test_the_plan_and_the_shipped_models_fit_each_behaviour_with_its_flag_weight(tmp_path):

    frame = goal_frame(120)
    frame["behavior"] = np.where(frame["behavior"] == "push", "grasp", "tap")  # the grasp's flags weigh more
    written = train_action_models(frame, tmp_path, n_estimators=5)
    shipped = {b: joblib.load(path)["model"] for b, path in written.items()}
    planned = fit_models({b: frame[frame["behavior"] == b] for b in ("tap", "grasp")}, random_state=0)
    assert BEHAVIOR_FLAG_WEIGHTS["grasp"] != FLAG_WEIGHT
    for models in (shipped, planned):
        assert models["grasp"].flag_weight == BEHAVIOR_FLAG_WEIGHTS["grasp"]
        assert models["tap"].flag_weight == FLAG_WEIGHT
