"""Property-based tests: random inputs either work or fail with a clear error, never a crash or garbage."""

import json

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from affordance_env.dataset import FORMAT, SCHEMA_VERSION, DatasetError, load_dataset
from affordance_learning import AffordanceModel
from affordance_learning.paper.relieff import relieff_weights

finite = st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    n=st.integers(1, 30),
    d=st.integers(1, 6),
    e=st.integers(1, 4),
    k=st.integers(1, 5),
    relevancy=st.floats(0, 1),
    data=st.data(),
)
def test_model_fits_any_finite_data_and_refuses_one_cluster(n, d, e, k, relevancy, data):
    X = data.draw(arrays(np.float64, (n, d), elements=finite))
    E = data.draw(arrays(np.float64, (n, e), elements=finite))
    model = AffordanceModel(n_clusters=k, relevancy=relevancy, som_iterations=50, random_state=0)
    if k == 1:  # the one invalid setting in this space: a clear error naming it
        with pytest.raises(ValueError, match="n_clusters must be an integer in"):
            model.fit(X, E)
        return
    model.fit(X, E)  # any finite data of any shape, constant or not, is learned from
    prediction = model.predict_effect(X)
    assert prediction.category.shape == (n,)
    assert np.all(np.isfinite(prediction.effect))
    assert len(model.selected_features_) >= 1
    assert np.all(np.isfinite(model.feature_weights_))


@settings(max_examples=30, deadline=None)
@given(data=st.data(), n=st.integers(3, 40), d=st.integers(1, 5), classes=st.integers(2, 4))
def test_relieff_weights_are_finite(data, n, d, classes):
    X = data.draw(arrays(np.float64, (n, d), elements=finite))
    y = data.draw(arrays(np.int64, n, elements=st.integers(0, classes - 1)))
    if len(np.unique(y)) < 2:
        with pytest.raises(ValueError, match="at least 2 classes"):
            relieff_weights(X, y)
        return
    weights = relieff_weights(X, y, n_neighbors=3)
    # finite; not bounded by 1: with classes smaller than n_neighbors, skrebate's multiclass weights exceed 1
    assert weights.shape == (d,) and np.all(np.isfinite(weights))


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(manifest=st.binary(max_size=200), chunk=st.binary(max_size=200))
def test_load_dataset_on_random_bytes_raises_clearly(tmp_path, manifest, chunk):
    (tmp_path / "manifest.json").write_bytes(manifest)
    (tmp_path / "chunk-00000.parquet").write_bytes(chunk)
    with pytest.raises((DatasetError, FileNotFoundError)):
        load_dataset(tmp_path)
    # a valid manifest with a random chunk: the chunk is read, and refused by name
    good = {"format": FORMAT, "schema_version": SCHEMA_VERSION, "episodes": 4, "settings": {"chunk_size": 4}}
    (tmp_path / "manifest.json").write_text(json.dumps(good))
    with pytest.raises(DatasetError, match="chunk-00000.parquet"):
        load_dataset(tmp_path)
