"""``predict_effect(features)`` with the default tap model shipped in the package.

The model is an :class:`AffordanceModel` (1 x 4 map, r = 0.4, the paper's case-study setting) trained by
``affordance train-default`` on 1000 canonical taps of ``TapAffordance-v0`` (seed 0). It is stored with the
versions of scikit-learn, NumPy and this package it was trained with; a model that was trained under other
versions, or a file that is missing or corrupt, is refused with a message that says how to rebuild it.
"""

from __future__ import annotations

import functools
from pathlib import Path

import joblib
import numpy as np
import pandas as pd

from affordance_learning.model import AffordanceModel, EffectPrediction

DEFAULT_MODEL_PATH = Path(__file__).resolve().parent / "data" / "tap_model.joblib"
DEFAULT_N_CLUSTERS = 4
DEFAULT_RELEVANCY = 0.4
REBUILD = "rebuild it with `affordance train-default` (about a minute)"


def _versions() -> dict[str, str]:
    """Versions a pickled model depends on: scikit-learn exactly (it warns on any other), NumPy's major."""
    import sklearn

    from affordance_learning import __version__

    return {"scikit-learn": sklearn.__version__, "numpy": np.__version__.split(".")[0], "tap-affordance": __version__}


def train_default_model(frame: pd.DataFrame, path: Path = DEFAULT_MODEL_PATH) -> AffordanceModel:
    """Fit the default model on a dataset (columns ``initial_<name>``, ``effect_<name>``) and save it."""
    from affordance_env.features import FEATURE_NAMES

    missing = [n for n in FEATURE_NAMES if f"initial_{n}" not in frame or f"effect_{n}" not in frame]
    if missing:
        raise ValueError(f"the dataset lacks initial_/effect_ columns for {missing[:5]}.")
    X = frame[[f"initial_{n}" for n in FEATURE_NAMES]].set_axis(list(FEATURE_NAMES), axis=1)
    E = frame[[f"effect_{n}" for n in FEATURE_NAMES]].set_axis(list(FEATURE_NAMES), axis=1)
    model = AffordanceModel(n_clusters=DEFAULT_N_CLUSTERS, relevancy=DEFAULT_RELEVANCY, random_state=0).fit(X, E)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp")
    joblib.dump({"model": model, "versions": _versions(), "feature_names": list(FEATURE_NAMES),
                 "n_interactions": int(len(frame))}, tmp, compress=3)
    tmp.replace(path)
    load_default_model.cache_clear()
    return model


@functools.cache
def load_default_model(path: Path = DEFAULT_MODEL_PATH) -> AffordanceModel:
    """The shipped model, checked against the installed library versions (cached)."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"The default tap model {path} is missing; {REBUILD}.")
    try:
        stored = joblib.load(path)
    except Exception as exc:  # unpickling errors come in many types
        raise RuntimeError(f"The default tap model {path} could not be read ({exc!r}); {REBUILD}.") from exc
    if not isinstance(stored, dict) or not isinstance(stored.get("model"), AffordanceModel):
        raise RuntimeError(f"{path} does not hold a TapAffordance model; {REBUILD}.")
    installed = _versions()
    changed = {k: (v, installed.get(k)) for k, v in stored.get("versions", {}).items() if installed.get(k) != v}
    if changed:
        details = ", ".join(f"{k} {old} (model) vs {new} (installed)" for k, (old, new) in changed.items())
        raise RuntimeError(f"The default tap model was trained under other library versions: {details}; {REBUILD}.")
    return stored["model"]


def predict_effect(features) -> EffectPrediction:
    """Predict the tap's effect category, and what that effect looks like, from the object's initial look.

    Args:
        features: One (49,) or many (n, 49) feature vectors in the order of ``affordance_env.FEATURE_NAMES``
            (``obs["features"]`` of ``TapAffordance-v0``), or a DataFrame with those columns.

    Returns:
        ``.category`` (n,) effect categories and ``.effect`` (n, 49) their prototype effects (final minus
        initial features, in feature units). A single vector gives arrays of length 1.
    """
    from affordance_env.features import FEATURE_NAMES

    if isinstance(features, pd.DataFrame):
        missing = [n for n in FEATURE_NAMES if n not in features.columns]
        if missing:
            raise ValueError(f"features DataFrame lacks the columns {missing[:5]} (expected FEATURE_NAMES).")
        X = features[list(FEATURE_NAMES)].to_numpy(np.float64)
    else:
        X = np.asarray(features, dtype=np.float64)
        if X.ndim == 1:
            X = X[None, :]
    if X.ndim != 2 or X.shape[1] != len(FEATURE_NAMES) or X.shape[0] == 0:
        raise ValueError(
            f"features must have shape ({len(FEATURE_NAMES)},) or (n, {len(FEATURE_NAMES)}), got {np.shape(features)}."
        )
    if not np.all(np.isfinite(X)):
        rows = np.flatnonzero(~np.all(np.isfinite(X), axis=1))
        raise ValueError(f"features must be finite; rows {rows[:10].tolist()} hold NaN or inf.")
    model = load_default_model()
    return model.predict_effect(pd.DataFrame(X, columns=list(FEATURE_NAMES)))
