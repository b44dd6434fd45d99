"""The learning model: SOM -> ReliefF -> SVM, against known structure, skrebate, and scikit-learn's checks."""

import joblib
import numpy as np
import pandas as pd
import pytest
from sklearn.base import clone
from sklearn.utils.estimator_checks import parametrize_with_checks

from affordance_learning import (
    AffordanceModel,
    SOMClustering,
    adjusted_rand,
    cluster_purity,
    relieff_weights,
    uniformity,
)


@parametrize_with_checks([AffordanceModel(som_iterations=200, random_state=0), SOMClustering(n_iterations=200,
                                                                                               random_state=0)])
def test_scikit_learn_estimator_checks(estimator, check):
    check(estimator)


def synthetic(n=600, seed=0):
    """Effects from 3 classes decided by initial features 2 and 7 of 10; the rest is noise."""
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(n, 10))
    classes = np.where(X[:, 2] > 0.5, 0, np.where(X[:, 7] > 0.0, 1, 2))
    centres = np.array([[5.0, 0.0, 0.0, 1.0], [0.0, 5.0, 0.0, -1.0], [0.0, 0.0, 5.0, 0.0]])
    E = centres[classes] + rng.normal(scale=0.3, size=(n, 4))
    return X, E, classes


def test_uniformity_hand_made_cases():
    assert uniformity([0, 0, 1, 1], [True, True, False, False]) == 100.0
    assert uniformity([0, 0, 1, 1], [True, False, True, False]) == 0.0
    assert uniformity([0, 0, 0, 1], [True, True, False, False]) == pytest.approx(50.0)
    assert uniformity(np.array(["a", "b", "a"]), np.array([1, 1, 1])) == 100.0
    with pytest.raises(ValueError, match="boolean"):
        uniformity([0, 1], [0, 2])
    with pytest.raises(ValueError, match="same length"):
        uniformity([0, 1, 1], [True, False])


def test_purity_and_rand():
    assert cluster_purity([0, 0, 1, 1], ["a", "a", "b", "a"]) == 0.75
    assert adjusted_rand([0, 0, 1, 1], ["x", "x", "y", "y"]) == 1.0


def test_recovers_known_classes_and_features():
    X, E, classes = synthetic()
    model = AffordanceModel(n_clusters=3, relevancy=0.5, random_state=0).fit(X, E)
    assert adjusted_rand(model.labels_, classes) >= 0.9
    assert set(np.argsort(model.feature_weights_)[-2:]) == {2, 7}
    assert set(model.selected_features_) >= {2, 7}
    X_test, E_test, _ = synthetic(seed=1)
    assert model.score(X_test, E_test) > 0.9


def test_relieff_equals_skrebate():
    skrebate = pytest.importorskip("skrebate")
    rng = np.random.default_rng(3)
    X = rng.normal(size=(120, 7))
    X[:, 1] = rng.integers(0, 3, 120)  # discrete columns make the data "mixed", skrebate's other branch
    for y in (X[:, 0] + X[:, 2] > 0, np.digitize(X[:, 0] + 0.5 * X[:, 1], [-1.0, 0.0, 1.0])):
        y = y.astype(int)
        expected = skrebate.ReliefF(n_neighbors=10).fit(X, y).feature_importances_
        np.testing.assert_allclose(relieff_weights(X, y, n_neighbors=10), expected, atol=1e-9)
    Xc = rng.normal(size=(120, 5))
    yc = np.digitize(Xc[:, 3], [-0.5, 0.5])
    expected = skrebate.ReliefF(n_neighbors=10).fit(Xc, yc).feature_importances_
    np.testing.assert_allclose(relieff_weights(Xc, yc), expected, atol=1e-9)


def test_dataframes_give_names_and_prototype_effects_in_units():
    X, E, _ = synthetic()
    Xf = pd.DataFrame(X, columns=[f"feat{i}" for i in range(10)])
    Ef = pd.DataFrame(E, columns=["dx", "dy", "dz", "spin"])
    model = AffordanceModel(n_clusters=3, relevancy=0.5, random_state=0).fit(Xf, Ef)
    assert {"feat2", "feat7"} <= set(model.selected_feature_names_)
    assert model.effect_names_ == ["dx", "dy", "dz", "spin"]
    prediction = model.predict_effect(Xf.iloc[:20])
    assert prediction.category.shape == (20,) and prediction.effect.shape == (20, 4)
    # prototypes are in the effect's units: near the class centres (5 on one axis)
    assert np.allclose(np.sort(model.cluster_effects_[:, :3].max(axis=1)), 5.0, atol=0.3)


def test_same_seed_same_model_and_joblib_round_trip(tmp_path):
    X, E, _ = synthetic()
    a = AffordanceModel(n_clusters=4, random_state=7).fit(X, E)
    b = clone(a).fit(X, E)
    np.testing.assert_array_equal(a.labels_, b.labels_)
    np.testing.assert_array_equal(a.feature_weights_, b.feature_weights_)
    joblib.dump(a, tmp_path / "model.joblib")
    loaded = joblib.load(tmp_path / "model.joblib")
    np.testing.assert_array_equal(loaded.predict(X), a.predict(X))
    np.testing.assert_array_equal(loaded.predict_effect(X).effect, a.predict_effect(X).effect)


@pytest.mark.parametrize(
    "params, match",
    [({"relevancy": 1.5}, "relevancy"), ({"relevancy": -0.1}, "relevancy"), ({"n_clusters": 0}, "n_clusters"),
     ({"n_neighbors": 0}, "n_neighbors")],
)
def test_bad_parameters(params, match):
    X, E, _ = synthetic(n=50)
    with pytest.raises(ValueError, match=match):
        AffordanceModel(**params).fit(X, E)


def test_bad_data():
    X, E, _ = synthetic(n=50)
    X_nan = X.copy()
    X_nan[3, 2] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        AffordanceModel().fit(X_nan, E)
    with pytest.raises(ValueError, match="inconsistent numbers of samples"):
        AffordanceModel().fit(X, E[:-1])
    model = AffordanceModel(random_state=0).fit(X, E)
    with pytest.raises(ValueError, match="features"):
        model.predict(X[:, :5])


def test_a_single_category_predicts_it():
    X, _, _ = synthetic(n=40)
    E = np.ones((40, 3))  # every interaction had the same effect
    model = AffordanceModel(n_clusters=2, random_state=0).fit(X, E)
    assert model.n_categories_ == 1
    assert np.all(model.predict(X) == model.labels_[0])
