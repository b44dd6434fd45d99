"""The learning model: metrics, SOM, ReliefF (against skrebate), the estimator, and the default model."""

from __future__ import annotations

import joblib
import numpy as np
import pandas as pd
import pytest
from minisom import MiniSom
from sklearn.base import clone
from sklearn.preprocessing import StandardScaler
from sklearn.utils import estimator_checks
from sklearn.utils.estimator_checks import parametrize_with_checks

from affordance_learning import (
    AffordanceModel,
    DefaultModelError,
    DefaultModelMissingError,
    ReliefF,
    ReliefFScorer,
    SOMClustering,
    adjusted_rand,
    cluster_purity,
    load_default_model,
    predict_effect,
    relieff_weights,
    select_features,
    svm_cv_accuracy,
    train_default_model,
    uniformity,
)
from affordance_learning import default_model as default_model_module
from affordance_learning.paper.metrics import size_success
from affordance_learning.paper.results import SizeSuccess
from affordance_learning.paper.synthetic import make_synthetic_frame

# --------------------------------------------------------------------------------------------- fixtures


def three_classes(n: int = 600, seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """10 initial features; features 2 and 7 decide one of 3 classes; effect = class centre + noise."""
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(n, 10))
    classes = np.where(X[:, 2] > 0.5, 0, np.where(X[:, 7] > 0.0, 1, 2))
    centres = np.array([[5.0, 0.0, 0.0, 1.0], [0.0, 5.0, 0.0, -1.0], [0.0, 0.0, 5.0, 0.0]])
    E = centres[classes] + rng.normal(scale=0.3, size=(n, 4))
    return X, E, classes


def mixed_data(n: int, n_classes: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Continuous and discrete features, labels from a noisy mix of both, classes of equal size."""
    rng = np.random.default_rng(seed)
    X = np.hstack([rng.normal(size=(n, 5)), rng.integers(0, 4, size=(n, 3)).astype(float)])
    score = X[:, 0] + 0.5 * X[:, 6] + 0.5 * rng.normal(size=n)
    y = np.digitize(score, np.quantile(score, np.linspace(0, 1, n_classes + 1)[1:-1]))
    return X, y


# ---------------------------------------------------------------------------------------------- metrics


def test_uniformity_hand_made_cases() -> None:
    assert uniformity([0, 0, 1, 1], [True, True, False, False]) == 100.0
    assert uniformity([0, 0, 1, 1], [True, False, True, False]) == 0.0
    # cluster 0: 2 rolled, 1 not -> |2 - 1| = 1; cluster 1: 1 not rolled -> 1; U = 100 * 2 / 4
    assert uniformity([0, 0, 0, 1], [True, True, False, False]) == pytest.approx(50.0)
    assert uniformity(np.array(["a", "b", "a"]), np.array([1, 1, 1])) == 100.0
    assert uniformity([5, 5, 5, 5, 5], [1, 0, 1, 0, 1]) == pytest.approx(20.0)


@pytest.mark.parametrize(
    ("clusters", "success", "match"),
    [
        ([0, 1], [0, 2], "boolean"),
        ([0, 1, 1], [True, False], "same length"),
        ([], [], "non-empty"),
        ([0.0, np.nan], [True, False], "NaN"),
    ],
)
def test_uniformity_refuses_bad_input(clusters: list, success: list, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        uniformity(clusters, success)


def test_purity_rand_and_cross_validated_svm() -> None:
    assert cluster_purity([0, 0, 1, 1], ["a", "a", "b", "a"]) == 0.75
    assert adjusted_rand([0, 0, 1, 1], ["x", "x", "y", "y"]) == 1.0
    assert adjusted_rand([1, 1, 0, 0], ["x", "x", "y", "y"]) == 1.0
    X, _, classes = three_classes(300)
    assert svm_cv_accuracy(X[:, [2, 7]], classes) > 0.9
    with pytest.raises(ValueError, match="at least 2 classes"):
        svm_cv_accuracy(X, np.zeros(300))


def intercept_over_slope(found: SizeSuccess) -> float:
    """Where the logistic fit crosses 50 % [m] (with the sign of intercept / slope)."""
    return found.logistic.intercept / found.logistic.slope


def test_size_success_finds_where_success_turns_to_failure() -> None:
    rng = np.random.default_rng(0)
    sizes = rng.uniform(0.03, 0.09, 2000)
    held = rng.random(2000) < 1 / (1 + np.exp((sizes - 0.055) / 0.004))
    found = size_success(sizes, held, n_bins=6)
    assert found.critical_size == pytest.approx(0.055, abs=0.002) and found.logistic.slope < 0
    assert [b.n for b in found.bins] and sum(b.n for b in found.bins) == 2000
    assert found.bins[0].success > 0.95 and found.bins[-1].success < 0.05
    below, above = found.below, found.above
    assert below.n + above.n == 2000 and below.success > 0.8 and above.success < 0.2
    # success independent of size (90 % everywhere): a fit, but no crossing of 50 % among the sizes seen
    coin = size_success(sizes, rng.random(2000) < 0.9)
    assert coin.logistic is not None and coin.critical_size is None and coin.below is None
    assert found.test.depends_on_size and found.test.p_value < 1e-10 and found.test.span < -0.9
    # a drift that crosses 50 % within the sizes, as the tap's rolled share from 47 % to 56 %: significant
    # perhaps, but success does not depend on size, so no critical size
    drift = size_success(sizes, rng.random(2000) < 0.45 + 0.12 * (sizes - 0.03) / 0.06)
    assert drift.logistic is not None and not drift.test.depends_on_size
    assert 0.03 < -intercept_over_slope(drift) < 0.09 and drift.critical_size is None and drift.below is None
    # one outcome only: nothing to fit
    always = size_success(sizes, np.ones(2000, dtype=bool))
    assert always.logistic is None and always.critical_size is None
    assert all(b.success == 1.0 for b in always.bins)
    with pytest.raises(ValueError, match="same length"):
        size_success(sizes, held[:5])


# -------------------------------------------------------------------------------------------------- SOM


def test_som_trains_exactly_as_minisom_with_its_seed() -> None:
    X, E, _ = three_classes(200)
    som = SOMClustering(n_clusters=4, n_iterations=700, sigma=1.2, learning_rate=0.4, random_state=11).fit(E)
    reference = MiniSom(1, 4, E.shape[1], sigma=1.2, learning_rate=0.4, random_seed=11)
    reference.train(E, 700, random_order=True)
    np.testing.assert_array_equal(som.cluster_centers_, reference.get_weights()[0])
    winners = np.array([reference.winner(e)[1] for e in E])
    np.testing.assert_array_equal(som.labels_, winners)
    np.testing.assert_array_equal(som.predict(E), som.labels_)
    assert som.cluster_centers_.shape == (4, 4) and som.labels_.dtype == np.int64


def test_som_clones_and_repeats_with_the_same_seed() -> None:
    _, E, classes = three_classes(300)
    a = SOMClustering(n_clusters=3, random_state=5)
    b = clone(a)
    assert b.get_params() == a.get_params() and not hasattr(b, "labels_")
    np.testing.assert_array_equal(a.fit_predict(E), b.fit(E).labels_)
    assert adjusted_rand(a.labels_, classes) >= 0.9
    with pytest.raises(ValueError, match="sigma"):
        SOMClustering(sigma=0.0).fit(E)
    with pytest.raises(ValueError, match="n_iterations"):
        SOMClustering(n_iterations=2.5).fit(E)


def test_som_n_init_keeps_the_map_of_lowest_quantization_error() -> None:
    _, E, _ = three_classes(200)
    runs = [SOMClustering(n_clusters=4, n_iterations=60, random_state=20 + i).fit(E) for i in range(6)]
    errors = [run.quantization_error_ for run in runs]
    assert len(set(errors)) == 6  # the seeds give different maps, so the choice matters
    best = int(np.argmin(errors))
    assert best != 0
    kept = SOMClustering(n_clusters=4, n_iterations=60, random_state=20, n_init=6).fit(E)
    assert kept.seed_ == 20 + best and kept.quantization_error_ == errors[best]
    np.testing.assert_array_equal(kept.cluster_centers_, runs[best].cluster_centers_)
    np.testing.assert_array_equal(kept.labels_, runs[best].labels_)
    np.testing.assert_array_equal(kept.predict(E), kept.labels_)
    # n_init=1 is the single map of the seed; a generator draws its seeds, the same each time from the same state
    single = SOMClustering(n_clusters=4, n_iterations=60, random_state=20).fit(E)
    assert single.seed_ == 20 and single.quantization_error_ == errors[0]
    drawn = [SOMClustering(n_clusters=4, n_iterations=60, random_state=np.random.default_rng(3), n_init=4).fit(E)
             for _ in range(2)]
    np.testing.assert_array_equal(drawn[0].cluster_centers_, drawn[1].cluster_centers_)
    with pytest.raises(ValueError, match="n_init must be an integer >= 1, got 0"):
        SOMClustering(n_init=0).fit(E)
    # the model hands it to its map, which it trains on the standardised effects
    model = AffordanceModel(n_clusters=4, som_iterations=60, som_n_init=6, random_state=20).fit(E, E)
    expected = SOMClustering(n_clusters=4, n_iterations=60, random_state=20, n_init=6).fit(
        StandardScaler().fit_transform(E))
    assert model.som_.seed_ == expected.seed_
    np.testing.assert_array_equal(model.labels_, expected.labels_)


# ---------------------------------------------------------------------------------------------- ReliefF


@pytest.mark.parametrize(("n_classes", "seed"), [(2, 0), (4, 1)])
def test_relieff_equals_skrebate_on_mixed_data(n_classes: int, seed: int) -> None:
    skrebate = pytest.importorskip("skrebate")
    X, y = mixed_data(150, n_classes, seed)
    expected = skrebate.ReliefF(n_neighbors=10).fit(X, y).feature_importances_
    np.testing.assert_allclose(relieff_weights(X, y, n_neighbors=10), expected, rtol=0, atol=1e-6)


@pytest.mark.parametrize(
    "case", ["continuous, 3 classes", "discrete only, many tied distances", "small classes (<= k members)"]
)
def test_relieff_equals_skrebate_on_other_branches(case: str) -> None:
    skrebate = pytest.importorskip("skrebate")
    rng = np.random.default_rng(7)
    if case.startswith("continuous"):
        X = rng.normal(size=(120, 6))
        y = np.digitize(X[:, 3] + 0.3 * rng.normal(size=120), [-0.5, 0.5])
    elif case.startswith("discrete"):
        X = rng.integers(0, 3, size=(150, 6)).astype(float)
        y = (X[:, 0] + rng.integers(0, 2, 150) > 1).astype(int)
    else:
        X, y = mixed_data(60, 5, 3)
        y[:52] = np.minimum(y[:52], 3)  # class 4 keeps only a few members, fewer than n_neighbors
    expected = skrebate.ReliefF(n_neighbors=10).fit(X, y).feature_importances_
    np.testing.assert_allclose(relieff_weights(X, y), expected, rtol=0, atol=1e-6)


def test_relieff_equals_skrebate_on_600_rows_of_49_features() -> None:
    # about 2 s, most of it skrebate
    skrebate = pytest.importorskip("skrebate")
    rng = np.random.default_rng(3)
    X = rng.normal(size=(600, 49))
    X[:, 40:] = rng.integers(0, 3, size=(600, 9))
    score = X[:, 0] + X[:, 1] + 0.3 * rng.normal(size=600)
    y = np.digitize(score, np.quantile(score, [0.25, 0.5, 0.75]))
    expected = skrebate.ReliefF(n_neighbors=10).fit(X, y).feature_importances_
    np.testing.assert_allclose(relieff_weights(X, y), expected, rtol=0, atol=1e-6)


def test_constant_columns_get_weight_zero_and_keep_continuous_data_continuous() -> None:
    # Invisible-normal latitude bins are constant in real data: in skrebate they make the data "mixed", where a
    # continuous difference above one standard deviation counts as 1 and the top weights saturate.
    skrebate = pytest.importorskip("skrebate")
    rng = np.random.default_rng(11)
    varying = rng.normal(size=(150, 6))
    y = np.digitize(varying[:, 1] + 0.4 * rng.normal(size=150), [-0.3, 0.6])
    X = np.column_stack([np.zeros(150), varying[:, :3], np.full(150, 2.5), varying[:, 3:]])
    scorer = ReliefFScorer(X)
    assert scorer.data_type == "continuous"
    weights = scorer.weights(y)
    assert weights[0] == 0.0 and weights[4] == 0.0
    expected = skrebate.ReliefF(n_neighbors=10).fit(varying, y).feature_importances_
    np.testing.assert_allclose(np.delete(weights, [0, 4]), expected, rtol=0, atol=1e-9)
    # skrebate itself, on the same data, has switched mode: its weights are not the continuous ones
    switched = skrebate.ReliefF(n_neighbors=10).fit(X, y).feature_importances_
    assert np.abs(np.delete(switched, [0, 4]) - expected).max() > 0.05
    np.testing.assert_array_equal(relieff_weights(np.ones((10, 3)), np.arange(10) % 2), np.zeros(3))


def test_relieff_matches_skrebate_where_its_multiclass_weights_exceed_one() -> None:
    skrebate = pytest.importorskip("skrebate")
    # class 2 has a single member, so the misses of classes 0 and 1 come mostly from one far class
    X = np.column_stack(
        [np.r_[np.linspace(0, 0.01, 10), np.linspace(20, 20.01, 10), [10.0]], np.arange(21.0)]
    )
    y = np.r_[[0] * 10, [1] * 10, [2]]
    weights = relieff_weights(X, y, n_neighbors=3)
    np.testing.assert_allclose(
        weights, skrebate.ReliefF(n_neighbors=3).fit(X, y).feature_importances_, atol=1e-6
    )
    assert weights[0] > 1.0


def test_relieff_wrapper_and_refusals() -> None:
    X, y = mixed_data(100, 3, 2)
    fitted = ReliefF().fit(pd.DataFrame(X, columns=[f"c{i}" for i in range(8)]), y)
    np.testing.assert_array_equal(fitted.feature_importances_, relieff_weights(X, y))
    assert fitted.top_features_[0] == int(np.argmax(fitted.feature_importances_))
    X_nan = X.copy()
    X_nan[4, 1] = np.nan
    for args, match in [
        ((X_nan, y), "non-finite"),
        ((X, np.zeros(100)), "at least 2 classes"),
        ((X, np.arange(100) % 11), "11 classes"),
        ((X, y[:-1]), "one label per row"),
        ((X[:, 0], y), "2-D"),
    ]:
        with pytest.raises(ValueError, match=match):
            relieff_weights(*args)
    with pytest.raises(ValueError, match="n_neighbors"):
        relieff_weights(X, y, n_neighbors=0.1)


def test_select_features_rule() -> None:
    w = np.array([0.10, -0.02, 0.05, 0.0, 0.041])
    np.testing.assert_array_equal(select_features(w, 0.0), [0, 2, 4])
    np.testing.assert_array_equal(select_features(w, 0.4), [0, 2, 4])
    np.testing.assert_array_equal(select_features(w, 0.45), [0, 2])
    np.testing.assert_array_equal(select_features(w, 1.0), [0])
    np.testing.assert_array_equal(select_features(-np.abs(w) - 0.01, 0.4), [3])
    with pytest.raises(ValueError, match="relevancy"):
        select_features(w, 1.2)


# ------------------------------------------------------------------------------------ the estimator

# These checks force n_clusters = 1 (a 1 x 1 map, a single effect category) before fitting. The model refuses
# n_clusters < 2 by design; test_checks_that_force_one_cluster_pass_with_two runs the same five checks with
# the map floored at 2 nodes, so what they test is still tested.
_FORCE_ONE_CLUSTER = (
    "check_dont_overwrite_parameters",
    "check_methods_subset_invariance",
    "check_fit2d_1sample",
    "check_fit2d_1feature",
    "check_fit2d_predict1d",
)


def _expected_failed_checks(estimator: object) -> dict[str, str]:
    if isinstance(estimator, AffordanceModel):
        return {
            name: "sets n_clusters=1, which AffordanceModel refuses by design (a 1 x 1 map has one effect "
            "category and nothing to learn); rerun with 2 clusters by "
            "test_checks_that_force_one_cluster_pass_with_two"
            for name in _FORCE_ONE_CLUSTER
        }
    return {}


@parametrize_with_checks(
    [AffordanceModel(som_iterations=200, random_state=0), SOMClustering(n_iterations=200, random_state=0)],
    expected_failed_checks=_expected_failed_checks,
    xfail_strict=True,
)
def test_scikit_learn_estimator_checks(estimator: object, check: object) -> None:
    check(estimator)


class _AtLeastTwoClusters(AffordanceModel):
    """AffordanceModel whose n_clusters is raised to 2 when a check sets it to 1."""

    def __setattr__(self, name: str, value: object) -> None:
        if name == "n_clusters" and value == 1:
            value = 2
        super().__setattr__(name, value)


@pytest.mark.parametrize("check_name", _FORCE_ONE_CLUSTER)
def test_checks_that_force_one_cluster_pass_with_two(check_name: str) -> None:
    getattr(estimator_checks, check_name)(
        "AffordanceModel", _AtLeastTwoClusters(som_iterations=200, random_state=0)
    )


def test_recovers_known_classes_and_their_two_features() -> None:
    X, E, classes = three_classes()
    model = AffordanceModel(n_clusters=3, relevancy=0.5, random_state=0).fit(X, E)
    assert adjusted_rand(model.labels_, classes) >= 0.9
    assert set(np.argsort(model.feature_weights_)[-2:].tolist()) == {2, 7}
    assert {2, 7} <= set(model.selected_features_.tolist())
    X_new, E_new, _ = three_classes(seed=1)
    assert model.score(X_new, E_new) > 0.9
    assert adjusted_rand(model.predict(X_new), model.categorize_effects(E_new)) > 0.8


def test_dataframes_give_names_and_prototypes_in_effect_units() -> None:
    X, E, _ = three_classes()
    Xf = pd.DataFrame(X, columns=[f"feat{i}" for i in range(10)])
    Ef = pd.DataFrame(E, columns=["dx", "dy", "dz", "spin"])
    model = AffordanceModel(n_clusters=3, relevancy=0.5, random_state=0).fit(Xf, Ef)
    assert {"feat2", "feat7"} <= set(model.selected_feature_names_)
    assert list(model.feature_names_in_) == list(Xf.columns)
    assert list(model.effect_names_) == ["dx", "dy", "dz", "spin"] and model.n_effects_ == 4
    prediction = model.predict_effect(Xf.iloc[:20])
    assert prediction.category.shape == (20,) and prediction.category.dtype == np.int64
    assert prediction.effect.shape == (20, 4)
    np.testing.assert_array_equal(prediction.effect, model.cluster_effects_[prediction.category])
    # prototypes are means of member effects, in effect units: each near one class centre (5 on one axis)
    np.testing.assert_allclose(np.sort(model.cluster_effects_[:, :3].max(axis=1)), 5.0, atol=0.3)
    plain = AffordanceModel(n_clusters=3, relevancy=0.5, random_state=0).fit(X, E)
    assert not hasattr(plain, "effect_names_") and not hasattr(plain, "feature_names_in_")
    assert set(plain.selected_feature_names_) >= {"x2", "x7"}


def test_one_dimensional_effect_is_one_column_and_constant_columns_stay_finite() -> None:
    X, E, _ = three_classes(200)
    a = AffordanceModel(n_clusters=3, random_state=1).fit(X, E[:, 0])
    b = AffordanceModel(n_clusters=3, random_state=1).fit(X, E[:, :1])
    np.testing.assert_array_equal(a.labels_, b.labels_)
    np.testing.assert_array_equal(a.predict(X), b.predict(X))
    assert a.cluster_effects_.shape == (3, 1)
    named = AffordanceModel(n_clusters=3, random_state=1).fit(X, pd.Series(E[:, 0], name="dx"))
    assert list(named.effect_names_) == ["dx"]
    E_const = np.column_stack([E, np.full(200, 3.0)])
    model = AffordanceModel(n_clusters=3, random_state=1).fit(X, E_const)
    assert np.all(np.isfinite(model.cluster_effects_)) and np.all(
        model.cluster_effects_[:, -1][model.cluster_sizes_ > 0] == 3.0
    )


def test_same_seed_same_model_and_joblib_round_trip(tmp_path: pytest.TempPathFactory) -> None:
    X, E, _ = three_classes()
    a = AffordanceModel(n_clusters=4, som_iterations=2000, random_state=7).fit(X, E)
    b = clone(a).fit(X, E)
    for name in ("labels_", "feature_weights_", "selected_features_", "cluster_effects_"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    np.testing.assert_array_equal(a.predict(X), b.predict(X))
    joblib.dump(a, tmp_path / "model.joblib")
    loaded = joblib.load(tmp_path / "model.joblib")
    np.testing.assert_array_equal(loaded.predict(X), a.predict(X))
    np.testing.assert_array_equal(loaded.predict_effect(X).effect, a.predict_effect(X).effect)


@pytest.mark.parametrize(
    ("params", "match"),
    [
        ({"relevancy": 1.5}, "relevancy"),
        ({"relevancy": -0.1}, "relevancy"),
        ({"relevancy": "0.4"}, "relevancy"),
        ({"n_clusters": 1}, "n_clusters"),
        ({"n_clusters": 0}, "n_clusters"),
        ({"n_clusters": 11}, "n_clusters"),
        ({"n_neighbors": 0}, "n_neighbors"),
        ({"som_iterations": 0}, "som_iterations"),
        ({"som_n_init": 0}, "som_n_init"),
        ({"svm_C": 0.0}, "svm_C"),
        ({"svm_gamma": "wide"}, "svm_gamma"),
    ],
)
def test_bad_parameters_name_the_value(params: dict, match: str) -> None:
    X, E, _ = three_classes(n=50)
    with pytest.raises(ValueError, match=match) as error:
        AffordanceModel(**params).fit(X, E)
    assert repr(next(iter(params.values()))) in str(error.value)


def test_bad_data() -> None:
    X, E, _ = three_classes(n=50)
    X_nan = X.copy()
    X_nan[3, 2] = np.nan
    E_nan = E.copy()
    E_nan[1, 0] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        AffordanceModel().fit(X_nan, E)
    with pytest.raises(ValueError, match="NaN"):
        AffordanceModel().fit(X, E_nan)
    with pytest.raises(ValueError, match="inconsistent numbers of samples"):
        AffordanceModel().fit(X, E[:-1])
    with pytest.raises(ValueError, match="2D array"):
        AffordanceModel().fit(X[:, 0], E)
    model = AffordanceModel(random_state=0).fit(X, E)
    with pytest.raises(ValueError, match="X has 5 features, but AffordanceModel is expecting 10"):
        model.predict(X[:, :5])
    with pytest.raises(ValueError, match="NaN"):
        model.predict(X_nan)
    with pytest.raises(ValueError, match="4 column"):
        model.categorize_effects(E[:, :2])


def test_a_single_category_predicts_it() -> None:
    X, _, _ = three_classes(n=40)
    E = np.ones((40, 3))  # every interaction had the same effect
    model = AffordanceModel(n_clusters=2, random_state=0).fit(X, E)
    assert np.unique(model.labels_).size == 1 and model.classifier_ is None
    np.testing.assert_array_equal(model.predict(X), np.full(40, model.labels_[0]))
    assert np.all(model.feature_weights_ == 0)
    np.testing.assert_array_equal(model.selected_features_, [0])  # the rule's one feature, unused
    np.testing.assert_allclose(model.predict_effect(X[:3]).effect, np.ones((3, 3)))


# ---------------------------------------------------------------------------------------- default model


@pytest.fixture(scope="module")
def stored_model(tmp_path_factory: pytest.TempPathFactory) -> tuple:
    path = tmp_path_factory.mktemp("model") / "tap_model.joblib"
    frame = make_synthetic_frame(240, random_state=2)
    model = train_default_model(frame, path)
    return path, model, frame


def test_default_model_predicts_one_and_many(stored_model: tuple) -> None:
    path, model, frame = stored_model
    features = frame[[c for c in frame.columns if c.startswith("initial_")]].to_numpy()
    many = predict_effect(features[:5], path=path)
    assert many.category.shape == (5,) and many.effect.shape == (5, 49)
    one = predict_effect(features[3], path=path)
    assert isinstance(one.category, int) and one.category == many.category[3]
    np.testing.assert_array_equal(one.effect, many.effect[3])
    as_frame = pd.DataFrame(features[:5], columns=model.feature_names_in_).iloc[:, ::-1]
    np.testing.assert_array_equal(predict_effect(as_frame, path=path).category, many.category)
    assert load_default_model(path) is load_default_model(path)  # cached
    expected = model.predict(pd.DataFrame(features[:5], columns=model.feature_names_in_))
    np.testing.assert_array_equal(many.category, expected)


@pytest.mark.parametrize(
    ("features", "match"),
    [
        (np.zeros(48), r"\(49,\) or \(n, 49\)"),
        (np.zeros((2, 3, 49)), "shape"),
        (np.zeros((0, 49)), "n >= 1"),
        (np.full(49, np.nan), "finite; row 0, feature 0 is nan"),
        (np.array(["a"] * 49), "real numbers"),
    ],
)
def test_default_model_refuses_bad_features(stored_model: tuple, features: np.ndarray, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        predict_effect(features, path=stored_model[0])


def test_default_model_refuses_missing_corrupt_and_stale_files(stored_model: tuple, tmp_path: object) -> None:
    with pytest.raises(DefaultModelMissingError, match="missing.*affordance train-default") as missing:
        load_default_model(tmp_path / "nothing.joblib")
    assert isinstance(missing.value, FileNotFoundError) and isinstance(missing.value, RuntimeError)
    corrupt = tmp_path / "corrupt.joblib"
    corrupt.write_bytes(b"not a pickle at all")
    with pytest.raises(DefaultModelError, match="could not be read.*affordance train-default"):
        predict_effect(np.zeros(49), path=corrupt)
    bundle = joblib.load(stored_model[0])
    bundle["versions"]["scikit-learn"] = "0.0.1"
    stale = tmp_path / "stale.joblib"
    joblib.dump(bundle, stale)
    with pytest.raises(
        DefaultModelError,
        match=r"scikit-learn 0\.0\.1 \(model\) vs .* \(installed\).*affordance train-default",
    ):
        load_default_model(stale)
    joblib.dump({"model": "something else"}, stale)
    with pytest.raises(DefaultModelError, match="not a default model bundle"):
        load_default_model(stale)


def test_default_models_are_the_packages_until_the_user_rebuilds_one(tmp_path, monkeypatch) -> None:
    assert default_model_module.DEFAULT_MODEL_PATH.parent.name == "data"
    assert default_model_module.DEFAULT_MODEL_PATH.parent.parent.name == "affordance_learning"
    monkeypatch.setenv("TAP_AFFORDANCE_DATA", str(tmp_path / "mine"))
    assert default_model_module.model_path() == default_model_module.DEFAULT_MODEL_PATH
    assert default_model_module.model_path("grasp") == default_model_module.MODEL_DIR / "grasp_model.joblib"
    assert default_model_module.user_model_path("push") == tmp_path / "mine" / "push_model.joblib"
    assert default_model_module.model_path("push") == tmp_path / "mine" / "push_model.joblib"  # none shipped
    monkeypatch.delenv("TAP_AFFORDANCE_DATA")
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "xdg"))
    assert default_model_module.user_model_dir() == tmp_path / "xdg" / "tap-affordance"
    monkeypatch.delenv("XDG_DATA_HOME")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert default_model_module.user_model_dir() == tmp_path / "home" / ".local" / "share" / "tap-affordance"


def test_each_behaviour_has_its_own_default_model(tmp_path: object, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(default_model_module, "MODEL_DIR", tmp_path / "package")  # shipping no model
    monkeypatch.setenv("TAP_AFFORDANCE_DATA", str(tmp_path))  # the user's data directory
    grasps = make_synthetic_frame(160, random_state=5, behavior="grasp")
    features = grasps[[c for c in grasps.columns if c.startswith("initial_")]].to_numpy()
    # not built yet: the error says how to build it
    with pytest.raises(DefaultModelMissingError, match=r"grasp model .* missing.*affordance train-default "
                                                        r"--behavior grasp.*1000 canonical grasp interactions.*"
                                                        r"user's data directory"):
        predict_effect(features[:2], "grasp")
    model = train_default_model(grasps, behavior="grasp")  # into the behaviour's file, the user's
    assert not (tmp_path / "package").exists()
    assert joblib.load(tmp_path / "grasp_model.joblib")["behavior"] == "grasp"
    prediction = predict_effect(features[:5], "grasp")
    np.testing.assert_array_equal(
        prediction.category, model.predict(pd.DataFrame(features[:5], columns=model.feature_names_in_)))
    assert load_default_model(behavior="grasp") is load_default_model(tmp_path / "grasp_model.joblib",
                                                                      behavior="grasp")
    # a model is used only for its own behaviour
    with pytest.raises(DefaultModelError, match="holds a 'grasp' model, not a 'tap' one.*affordance train-default"):
        predict_effect(features[:2], path=tmp_path / "grasp_model.joblib")
    # a bundle stored before the behaviour was recorded is the tap's
    bundle = joblib.load(tmp_path / "grasp_model.joblib")
    del bundle["behavior"]
    joblib.dump(bundle, tmp_path / "old.joblib")
    assert predict_effect(features[:2], path=tmp_path / "old.joblib").category.shape == (2,)
    with pytest.raises(DefaultModelError, match="holds a 'tap' model, not a 'grasp' one"):
        load_default_model(tmp_path / "old.joblib", behavior="grasp")


def test_default_models_refuse_unknown_behaviours_and_other_behaviours_data(tmp_path: object) -> None:
    with pytest.raises(ValueError, match="Unknown behavior 'juggle'. Valid behaviors: tap, tap_back, push, grasp"):
        predict_effect(np.zeros(49), "juggle")
    with pytest.raises(ValueError, match="Unknown behavior 'juggle'"):
        load_default_model(behavior="juggle")
    taps = make_synthetic_frame(40, random_state=5)
    with pytest.raises(ValueError, match="holds 'tap' interactions, not 'grasp' ones"):
        train_default_model(taps, tmp_path / "m.joblib", behavior="grasp")
    with pytest.raises(ValueError, match="Unknown behavior 'juggle'"):
        train_default_model(taps, tmp_path / "m.joblib", behavior="juggle")
    assert not (tmp_path / "m.joblib").exists()
